#include "Template.h"

#include "Mesher.h"
#include "TemplateReader.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <limits>
#include <locale>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <sys/stat.h>

namespace blockforge
{
namespace model
{
using detail::TemplateReader;

namespace
{
/// Templates are a few kilobytes; this bound keeps /dev/zero or a grid picked by mistake
/// from being read until memory runs out.
constexpr std::size_t MaxTemplateBytes = 16u << 20;

/// The template's text with line ends made "\n" (Windows "\r\n" and old Mac lone "\r",
/// which YAML would otherwise read as one long line).
std::string readFile(const std::string& path)
{
  struct stat status;
  if (::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode))
  {
    throw TemplateError(path, 0, "", "'" + path + "' is a folder, not a template file");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    const int error = errno;
    throw TemplateError(path, 0, "",
      "cannot open template file '" + path + "'" +
        (error ? std::string(": ") + std::strerror(error) : std::string()));
  }
  // Read in pieces up to one byte past the limit: a buffer of the whole limit would be
  // zero-filled on every read (16 MB, tens of milliseconds on a virtual machine).
  std::string text;
  char piece[1 << 16];
  while (text.size() <= MaxTemplateBytes && stream)
  {
    stream.read(piece, static_cast<std::streamsize>(
      std::min(sizeof(piece), MaxTemplateBytes + 1 - text.size())));
    text.append(piece, static_cast<std::size_t>(stream.gcount()));
  }
  if (stream.bad() || (stream.fail() && !stream.eof()))
  {
    const int error = errno;
    throw TemplateError(path, 0, "",
      "cannot read template file '" + path + "'" +
        (error ? std::string(": ") + std::strerror(error) : std::string()));
  }
  if (text.size() > MaxTemplateBytes)
  {
    throw TemplateError(path, 0, "",
      "'" + path + "' is larger than " + std::to_string(MaxTemplateBytes >> 20) +
        " MB: not a template file");
  }
  std::string normalized;
  normalized.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    if (text[i] == '\r')
    {
      normalized += '\n';
      if (i + 1 < text.size() && text[i + 1] == '\n')
      {
        ++i;
      }
      continue;
    }
    normalized += text[i];
  }
  return normalized;
}
} // namespace

BlockModel parseTemplate(const std::string& text, const std::string& fileName,
  const ParameterOverrides& overrides, const TemplateInputs* inputs, CarrierGeometry* carriers)
{
  TemplateReader reader(text, fileName, overrides, inputs);
  BlockModel model = reader.readModel();
  // Topology and geometry problems are template errors too: report them now, with the
  // template's lines, rather than when the mesher runs.
  checkModel(model, reader.geometry());
  if (carriers)
  {
    *carriers = reader.geometry();
  }
  return model;
}

BlockModel loadTemplate(const std::string& path, const ParameterOverrides& overrides,
  const TemplateInputs* inputs, CarrierGeometry* carriers)
{
  return parseTemplate(readFile(path), path, overrides, inputs, carriers);
}

std::vector<ParameterInfo> templateParameters(const std::string& path,
  const ParameterOverrides& overrides, const TemplateInputs* inputs)
{
  const std::string text = readFile(path);
  TemplateReader reader(text, path, overrides, inputs);
  return reader.readParameterInfos();
}
} // namespace model
} // namespace blockforge
