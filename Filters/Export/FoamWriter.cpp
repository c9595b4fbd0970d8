// Writing an OpenFOAM case: constant/polyMesh in OpenFOAM's own binary or ASCII layout.
#include "PolyMesh.h"

#include "PolyMeshFaces.h"
#include "StagedOutput.h"

#include <charconv>
#include <memory>
#include <cstdio>
#include <stdexcept>

namespace blockforge
{
namespace exporting
{
namespace
{
std::string header(const char* className, const char* object, bool binary,
  const std::string& note = std::string())
{
  std::string text = "/*--------------------------------*- C++ -*----------------------------------*\\\n"
                     "  Written by BlockForge (block-structured grids from templates)\n"
                     "\\*---------------------------------------------------------------------------*/\n"
                     "FoamFile\n{\n    version     2.0;\n    format      ";
  text += binary ? "binary" : "ascii";
  text += ";\n    class       ";
  text += className;
  text += ";\n";
  if (binary)
  {
    text += "    arch        \"LSB;label=32;scalar=64\";\n";
  }
  if (!note.empty())
  {
    text += "    note        \"" + note + "\";\n";
  }
  text += "    location    \"constant/polyMesh\";\n    object      ";
  text += object;
  text += ";\n}\n// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //\n\n";
  return text;
}

const char* const Footer =
  "\n\n// ************************************************************************* //\n";

/// Text gathered in a buffer and written in large pieces.
class TextBuffer
{
public:
  explicit TextBuffer(CheckedFile& file)
    : File(file)
  {
    Data.reserve(Capacity + 64);
  }
  void put(const char* text, std::size_t size)
  {
    Data.append(text, size);
    flushIfFull();
  }
  void put(char c)
  {
    Data.push_back(c);
    flushIfFull();
  }
  void put(long long value)
  {
    char buffer[24];
    const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
    put(buffer, static_cast<std::size_t>(end - buffer));
  }
  /// Shortest text that reads back to the same double.
  void put(double value)
  {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
    put(buffer, static_cast<std::size_t>(end - buffer));
  }
  void flush()
  {
    File.write(Data);
    Data.clear();
  }

private:
  void flushIfFull()
  {
    if (Data.size() >= Capacity)
    {
      flush();
    }
  }
  static constexpr std::size_t Capacity = 1 << 20;
  CheckedFile& File;
  std::string Data;
};

/// OpenFOAM's binary list: its length (in entries of `perEntry` values), then raw bytes.
template <typename T>
void binaryList(CheckedFile& file, const T* values, std::size_t count, std::size_t perEntry = 1)
{
  file.write(std::to_string(count) + "\n(");
  file.write(values, count * perEntry * sizeof(T));
  file.write(")");
}

void labelList(CheckedFile& file, const LargeVector<int>& values, bool binary)
{
  if (binary)
  {
    binaryList(file, values.data(), values.size());
    return;
  }
  TextBuffer text(file);
  const std::string count = std::to_string(values.size()) + "\n(\n";
  text.put(count.data(), count.size());
  for (int value : values)
  {
    text.put(static_cast<long long>(value));
    text.put('\n');
  }
  text.put(')');
  text.flush();
}

void writePoints(const std::string& path, const PolyMesh& mesh, bool binary)
{
  CheckedFile file(path);
  file.write(header("vectorField", "points", binary));
  const std::size_t count = static_cast<std::size_t>(mesh.pointCount());
  if (binary)
  {
    binaryList(file, mesh.points.data(), count, 3);
  }
  else
  {
    TextBuffer text(file);
    const std::string size = std::to_string(count) + "\n(\n";
    text.put(size.data(), size.size());
    for (std::size_t p = 0; p < count; ++p)
    {
      text.put('(');
      text.put(mesh.points[3 * p]);
      text.put(' ');
      text.put(mesh.points[3 * p + 1]);
      text.put(' ');
      text.put(mesh.points[3 * p + 2]);
      text.put(")\n", 2);
    }
    text.put(')');
    text.flush();
  }
  file.write(Footer);
  file.close();
}

void writeFaces(const std::string& path, const PolyMesh& mesh, bool binary)
{
  CheckedFile file(path);
  if (binary)
  {
    // faceCompactList: the offsets, then every face's points.
    file.write(header("faceCompactList", "faces", true));
    binaryList(file, mesh.faceOffsets.data(), mesh.faceOffsets.size());
    file.write("\n\n");
    binaryList(file, mesh.faceNodes.data(), mesh.faceNodes.size());
  }
  else
  {
    file.write(header("faceList", "faces", false));
    TextBuffer text(file);
    const std::string size = std::to_string(mesh.faceCount()) + "\n(\n";
    text.put(size.data(), size.size());
    for (int f = 0; f < mesh.faceCount(); ++f)
    {
      const int begin = mesh.faceOffsets[f], end = mesh.faceOffsets[f + 1];
      text.put(static_cast<long long>(end - begin));
      text.put('(');
      for (int n = begin; n < end; ++n)
      {
        if (n > begin)
        {
          text.put(' ');
        }
        text.put(static_cast<long long>(mesh.faceNodes[n]));
      }
      text.put(")\n", 2);
    }
    text.put(')');
    text.flush();
  }
  file.write(Footer);
  file.close();
}

void writeLabels(const std::string& path, const char* object, const LargeVector<int>& values,
  const PolyMesh& mesh, bool binary)
{
  CheckedFile file(path);
  const std::string note = "nPoints:" + std::to_string(mesh.pointCount()) +
    "  nCells:" + std::to_string(mesh.cellCount) + "  nFaces:" + std::to_string(mesh.faceCount()) +
    "  nInternalFaces:" + std::to_string(mesh.internalFaceCount());
  file.write(header("labelList", object, binary, note));
  labelList(file, values, binary);
  file.write(Footer);
  file.close();
}

std::string vectorText(const Vec3& v)
{
  char buffer[128];
  std::snprintf(buffer, sizeof(buffer), "(%.17g %.17g %.17g)", v.x(), v.y(), v.z());
  return buffer;
}

void writeBoundary(const std::string& path, const PolyMesh& mesh)
{
  CheckedFile file(path);
  std::string text = header("polyBoundaryMesh", "boundary", false);
  text += std::to_string(mesh.patches.size()) + "\n(\n";
  for (const FoamPatch& patch : mesh.patches)
  {
    text += "    " + patch.name + "\n    {\n";
    text += "        type            " + patch.type + ";\n";
    if (patch.type != "patch")
    {
      text += "        inGroups        List<word> 1(" + patch.type + ");\n";
    }
    text += "        nFaces          " + std::to_string(patch.faceCount) + ";\n";
    text += "        startFace       " + std::to_string(patch.startFace) + ";\n";
    if (patch.type == "cyclic")
    {
      char angle[64];
      std::snprintf(angle, sizeof(angle), "%.17g", patch.rotationAngle);
      text += "        matchTolerance  0.0001;\n";
      text += "        transform       rotational;\n";
      text += "        rotationAxis    " + vectorText(patch.rotationAxis) + ";\n";
      text += "        rotationCentre  " + vectorText(patch.rotationCentre) + ";\n";
      text += "        // rotation onto " + patch.neighbourPatch + ": " + angle + " degrees\n";
      text += "        neighbourPatch  " + patch.neighbourPatch + ";\n";
    }
    text += "    }\n";
  }
  text += ")\n";
  file.write(text);
  file.write(Footer);
  file.close();
}

/// A system/ dictionary, unless the case has one (a solver set-up is never touched).
void writeSystemFileIfAbsent(const std::string& caseDir, const char* object, const char* body)
{
  const std::string system = caseDir + "/system";
  const std::string path = system + "/" + object;
  if (std::FILE* existing = std::fopen(path.c_str(), "rb"))
  {
    std::fclose(existing);
    return;
  }
  makeDirectories(system);
  StagedOutput staged(path, StagedOutput::Kind::File);
  CheckedFile file(staged.path());
  std::string text = header("dictionary", object, false);
  text.replace(text.find("\"constant/polyMesh\""), 19, "\"system\"");
  file.write(text + body);
  file.write(Footer);
  file.close();
  staged.publish();
}

/// Minimal system/ files so that OpenFOAM's tools (checkMesh, simpleFoam) open the case.
void writeSystemFilesIfAbsent(const std::string& caseDir)
{
  writeSystemFileIfAbsent(caseDir, "controlDict",
    "application     simpleFoam;\nstartFrom       latestTime;\nstartTime       0;\n"
    "stopAt          endTime;\nendTime         100;\ndeltaT          1;\n"
    "writeControl    timeStep;\nwriteInterval   100;\nwriteFormat     binary;\n"
    "writePrecision  17;\nwriteCompression off;\ntimeFormat      general;\n"
    "runTimeModifiable false;\n");
  writeSystemFileIfAbsent(caseDir, "fvSchemes",
    "ddtSchemes { default steadyState; }\ngradSchemes { default Gauss linear; }\n"
    "divSchemes { default none; div(phi,U) bounded Gauss linearUpwind grad(U); "
    "div(phi,k) bounded Gauss upwind; div(phi,epsilon) bounded Gauss upwind; "
    "div(phi,omega) bounded Gauss upwind; div((nuEff*dev2(T(grad(U))))) Gauss linear; }\n"
    "laplacianSchemes { default Gauss linear corrected; }\n"
    "interpolationSchemes { default linear; }\nsnGradSchemes { default corrected; }\n"
    "wallDist { method meshWave; }\n");
  writeSystemFileIfAbsent(caseDir, "fvSolution",
    "solvers\n{\n    p { solver GAMG; smoother GaussSeidel; tolerance 1e-7; relTol 0.1; }\n"
    "    \"(U|k|epsilon|omega)\" { solver smoothSolver; smoother symGaussSeidel; "
    "tolerance 1e-8; relTol 0.1; }\n}\n"
    "SIMPLE { nNonOrthogonalCorrectors 0; consistent yes; }\n"
    "relaxationFactors { equations { U 0.9; \".*\" 0.9; } }\n");
}

/// The case folder with its NAME.foam and system/ files, and the staged polyMesh folder.
std::unique_ptr<StagedOutput> prepareCase(const std::string& foamFile)
{
  const std::string caseDir = folderOf(foamFile);
  const std::string constant = caseDir + "/constant";
  makeDirectories(constant);
  // The empty NAME.foam first: harmless if the mesh fails, kept as it is when present.
  if (std::FILE* marker = std::fopen(foamFile.c_str(), "ab"))
  {
    std::fclose(marker);
  }
  else
  {
    CheckedFile failing(foamFile); // throws with the reason
  }
  writeSystemFilesIfAbsent(caseDir);
  return std::make_unique<StagedOutput>(constant + "/polyMesh", StagedOutput::Kind::Directory);
}

/// Counts the faces and collects the patches of a walk.
struct CountingSink
{
  std::vector<FoamPatch> patches;
  void internalFace(int, int, const int*, int) {}
  void boundaryFace(int, const int*, int) {}
  void patch(const FoamPatch& entry) { patches.push_back(entry); }
};

/// Streams the faces into the faces, owner and neighbour files, each list at its offset.
struct FileSink
{
  PositionalFile::Region offsets, corners, owner, neighbour;
  int cornerTotal = 0;
  void internalFace(int cell, int across, const int* nodes, int count)
  {
    boundaryFace(cell, nodes, count);
    neighbour.put(across);
  }
  void boundaryFace(int cell, const int* nodes, int count)
  {
    cornerTotal += count;
    offsets.put(cornerTotal);
    corners.put(nodes, sizeof(int) * static_cast<std::size_t>(count));
    owner.put(cell);
  }
  void patch(const FoamPatch&) {}
  void flush()
  {
    offsets.flush();
    corners.flush();
    owner.flush();
    neighbour.flush();
  }
};

/// A binary list's opening ("N\n(") and closing (")") around `bytes` of data at `at`;
/// returns the offset of the data.
unsigned long long binaryListFrame(PositionalFile& file, unsigned long long at,
  std::size_t count, std::size_t bytes, const std::string& after)
{
  const std::string opening = std::to_string(count) + "\n(";
  file.writeAt(at, opening.data(), opening.size());
  const unsigned long long data = at + opening.size();
  const std::string closing = ")" + after;
  file.writeAt(data + bytes, closing.data(), closing.size());
  return data;
}
} // namespace

FoamSummary writeFoamCase(const ExportGrid& grid, const std::string& foamFile,
  const FoamWriteOptions& options)
{
  auto progress = [&](double fraction) {
    if (options.progress)
    {
      options.progress(fraction);
    }
  };
  FoamSummary summary;
  if (!options.binary)
  {
    const PolyMesh mesh = buildPolyMesh(grid);
    writeFoamCase(mesh, foamFile, options);
    summary = { mesh.pointCount(), mesh.cellCount, mesh.faceCount(), mesh.internalFaceCount(),
      mesh.triangleFaces, mesh.patches };
    return summary;
  }
  polymesh::FaceWalker walker(grid);
  CountingSink counting;
  walker.walk(counting);
  summary = { walker.points(), static_cast<int>(walker.cells()), walker.faceCount,
    walker.internalFaceCount, walker.triangleCount, counting.patches };
  progress(0.2);
  const std::unique_ptr<StagedOutput> staged = prepareCase(foamFile);
  const std::string dir = staged->path() + "/";
  {
    CheckedFile points(dir + "points");
    points.write(header("vectorField", "points", true));
    points.write(std::to_string(summary.points) + "\n(");
    std::vector<double> buffer;
    buffer.reserve(3 << 16);
    walker.forEachPoint([&](const double* xyz) {
      buffer.insert(buffer.end(), xyz, xyz + 3);
      if (buffer.size() >= (3 << 16))
      {
        points.write(buffer.data(), buffer.size() * sizeof(double));
        buffer.clear();
      }
    });
    points.write(buffer.data(), buffer.size() * sizeof(double));
    points.write(")");
    points.write(Footer);
    points.close();
  }
  progress(0.4);
  const std::string note = "nPoints:" + std::to_string(summary.points) +
    "  nCells:" + std::to_string(summary.cells) + "  nFaces:" + std::to_string(summary.faces) +
    "  nInternalFaces:" + std::to_string(summary.internalFaces);
  PositionalFile faces(dir + "faces"), owner(dir + "owner"), neighbour(dir + "neighbour");
  const std::string facesHeader = header("faceCompactList", "faces", true);
  faces.writeAt(0, facesHeader.data(), facesHeader.size());
  const std::size_t offsetBytes = sizeof(int) * (static_cast<std::size_t>(summary.faces) + 1);
  const unsigned long long offsetsAt =
    binaryListFrame(faces, facesHeader.size(), summary.faces + 1, offsetBytes, "\n\n");
  const std::size_t cornerBytes = sizeof(int) * static_cast<std::size_t>(walker.cornerCount);
  const unsigned long long cornersAt = binaryListFrame(faces, offsetsAt + offsetBytes + 3,
    static_cast<std::size_t>(walker.cornerCount), cornerBytes, Footer);
  const std::string ownerHeader = header("labelList", "owner", true, note);
  owner.writeAt(0, ownerHeader.data(), ownerHeader.size());
  const unsigned long long ownerAt = binaryListFrame(owner, ownerHeader.size(), summary.faces,
    sizeof(int) * static_cast<std::size_t>(summary.faces), Footer);
  const std::string neighbourHeader = header("labelList", "neighbour", true, note);
  neighbour.writeAt(0, neighbourHeader.data(), neighbourHeader.size());
  const unsigned long long neighbourAt = binaryListFrame(neighbour, neighbourHeader.size(),
    summary.internalFaces, sizeof(int) * static_cast<std::size_t>(summary.internalFaces), Footer);
  FileSink sink{ { faces, offsetsAt }, { faces, cornersAt }, { owner, ownerAt },
    { neighbour, neighbourAt } };
  sink.offsets.put(0);
  walker.walk(sink);
  sink.flush();
  faces.close();
  owner.close();
  neighbour.close();
  progress(0.9);
  PolyMesh boundaryOnly;
  boundaryOnly.patches = summary.patches;
  writeBoundary(dir + "boundary", boundaryOnly);
  staged->publish();
  progress(1.0);
  return summary;
}

void writeFoamCase(const PolyMesh& mesh, const std::string& foamFile, const FoamWriteOptions& options)
{
  const std::unique_ptr<StagedOutput> staged = prepareCase(foamFile);
  const std::string dir = staged->path() + "/";
  const bool binary = options.binary;
  auto progress = [&](double fraction) {
    if (options.progress)
    {
      options.progress(fraction);
    }
  };
  progress(0.0);
  writePoints(dir + "points", mesh, binary);
  progress(0.25);
  writeFaces(dir + "faces", mesh, binary);
  progress(0.6);
  writeLabels(dir + "owner", "owner", mesh.owner, mesh, binary);
  progress(0.8);
  writeLabels(dir + "neighbour", "neighbour", mesh.neighbour, mesh, binary);
  writeBoundary(dir + "boundary", mesh);
  staged->publish();
  progress(1.0);
}
} // namespace exporting
} // namespace blockforge
