#include "VtkXml.h"

#include "StagedOutput.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <stdio.h>
#include <sys/stat.h>

namespace blockforge
{
namespace exporting
{
namespace
{
const char* const PiecesMark = ".pieces-";

/// The target's name without its extension: the stem of the pieces folder's name.
std::string stemOf(const std::string& name)
{
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

std::string escapeXml(const std::string& text)
{
  std::string escaped;
  for (const char c : text)
  {
    switch (c)
    {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      case '\'': escaped += "&apos;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

std::string unescapeXml(const std::string& text)
{
  static const std::pair<const char*, char> entities[] = { { "&amp;", '&' }, { "&lt;", '<' },
    { "&gt;", '>' }, { "&quot;", '"' }, { "&apos;", '\'' } };
  std::string plain;
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    bool replaced = false;
    for (const auto& entity : entities)
    {
      const std::size_t length = std::strlen(entity.first);
      if (text.compare(i, length, entity.first) == 0)
      {
        plain += entity.second;
        i += length - 1;
        replaced = true;
        break;
      }
    }
    if (!replaced)
    {
      plain += text[i];
    }
  }
  return plain;
}

/// The folders beside `vtm` that its DataSet entries reference (first components of the
/// relative file="..." paths); empty when it is missing.
std::vector<std::string> referencedFolders(const std::string& vtm)
{
  std::ifstream stream(vtm, std::ios::binary);
  std::stringstream content;
  content << stream.rdbuf();
  const std::string text = content.str();
  std::vector<std::string> folders;
  const std::string key = "file=\"";
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1))
  {
    const std::size_t begin = at + key.size();
    const std::size_t end = text.find('"', begin);
    if (end == std::string::npos)
    {
      break;
    }
    const std::string reference = unescapeXml(text.substr(begin, end - begin));
    const std::size_t slash = reference.find('/');
    if (reference.empty() || reference[0] == '/' || slash == std::string::npos || slash == 0)
    {
      continue;
    }
    const std::string first = reference.substr(0, slash);
    if (first != "." && first != "..")
    {
      folders.push_back(first);
    }
  }
  return folders;
}

/// Removes the pieces folders "STEM.pieces-<pid>-<token>" in `folder` that killed runs
/// left: of processes that no longer run and not in `inUse` (as blockforge.output does).
void removeStalePieces(
  const std::string& folder, const std::string& stem, const std::vector<std::string>& inUse)
{
  for (const std::string& path : staleEntries(folder, stem + PiecesMark, ""))
  {
    struct stat status;
    if (std::find(inUse.begin(), inUse.end(), nameOf(path)) == inUse.end() &&
      ::lstat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode))
    {
      removeTree(path);
    }
  }
}

/// One block as an XML structured grid: its points, Float64, raw appended.
void writePiece(const GridBlock& block, const std::string& path)
{
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  if (first != 1)
  {
    throw std::runtime_error("could not write " + path + ": the .vtm writer needs a "
                             "little-endian machine");
  }
  const std::string extent = "0 " + std::to_string(block.nodes[0] - 1) + " 0 " +
    std::to_string(block.nodes[1] - 1) + " 0 " + std::to_string(block.nodes[2] - 1);
  const std::string header = "<?xml version=\"1.0\"?>\n"
                             "<VTKFile type=\"StructuredGrid\" version=\"1.0\" "
                             "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                             "  <StructuredGrid WholeExtent=\"" + extent + "\">\n"
                             "    <Piece Extent=\"" + extent + "\">\n"
                             "      <PointData>\n      </PointData>\n"
                             "      <CellData>\n      </CellData>\n"
                             "      <Points>\n"
                             "        <DataArray type=\"Float64\" Name=\"Points\" "
                             "NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n"
                             "      </Points>\n"
                             "    </Piece>\n"
                             "  </StructuredGrid>\n"
                             "  <AppendedData encoding=\"raw\">\n   _";
  const std::uint64_t bytes = static_cast<std::uint64_t>(block.nodeCount()) * 3 * sizeof(double);
  CheckedFile file(path);
  file.write(header);
  file.write(&bytes, sizeof(bytes));
  file.write(block.xyz, static_cast<std::size_t>(bytes));
  file.write(std::string("\n  </AppendedData>\n</VTKFile>\n"));
  file.close();
}
} // namespace

void writeVtkMultiBlock(const ExportGrid& grid, const std::string& path)
{
  // The staging folder holds the pieces folder and the .vtm until they are published.
  StagedOutput staged(path, StagedOutput::Kind::Directory);
  const std::string folder = folderOf(path);
  const std::string stem = stemOf(nameOf(path));
  // The pieces take the staging folder's token, as blockforge.output's fresh companion
  // names do.
  const std::vector<std::string> referenced = referencedFolders(path);
  removeStalePieces(folder, stem, referenced);
  const std::string pieces = stem + PiecesMark + staged.token();
  const std::string stagedPieces = staged.path() + "/" + pieces;
  if (::mkdir(stagedPieces.c_str(), 0777) != 0)
  {
    throw std::runtime_error("could not write " + path + ": " + std::strerror(errno));
  }
  std::string vtm = "<?xml version=\"1.0\"?>\n"
                    "<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" "
                    "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                    "  <vtkMultiBlockDataSet>\n";
  for (std::size_t b = 0; b < grid.blocks.size(); ++b)
  {
    const std::string piece = pieces + "_" + std::to_string(b) + ".vts";
    writePiece(grid.blocks[b], stagedPieces + "/" + piece);
    vtm += "    <DataSet index=\"" + std::to_string(b) + "\" name=\"" +
      escapeXml(grid.blocks[b].name) + "\" file=\"" + escapeXml(pieces + "/" + piece) + "\">\n"
      "    </DataSet>\n";
  }
  vtm += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
  const std::string stagedMain = staged.path() + "/" + pieces + ".vtm";
  {
    CheckedFile file(stagedMain);
    file.write(vtm);
    file.close();
  }
  // What the older grid references, removed only once the new one is in place.
  std::vector<std::string> old;
  for (const std::string& name : referenced)
  {
    if (name == stem || name.compare(0, stem.size() + std::strlen(PiecesMark),
                          stem + PiecesMark) == 0)
    {
      old.push_back(folder + "/" + name);
    }
  }
  const std::string publishedPieces = folder + "/" + pieces;
  if (::rename(stagedPieces.c_str(), publishedPieces.c_str()) != 0)
  {
    throw std::runtime_error("could not write " + path + ": " + std::strerror(errno));
  }
  if (::rename(stagedMain.c_str(), path.c_str()) != 0)
  {
    const int error = errno;
    removeTree(publishedPieces);
    throw std::runtime_error("could not write " + path + ": " + std::strerror(error));
  }
  for (const std::string& folderPath : old)
  {
    if (folderPath != publishedPieces)
    {
      removeTree(folderPath);
    }
  }
  // The emptied staging folder goes with `staged`.
}
} // namespace exporting
} // namespace blockforge
