#include "TemplateParameters.h"

#include "Errors.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

namespace blockforge
{
namespace model
{
namespace
{
std::string trimmed(const std::string& text)
{
  const std::size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos)
  {
    return {};
  }
  const std::size_t last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

/// The comment of a YAML line: the text after the first '#' that is outside quotes and
/// starts the line or follows a blank.
std::string commentOf(const std::string& line)
{
  char quote = 0;
  for (std::size_t n = 0; n < line.size(); ++n)
  {
    const char c = line[n];
    if (quote)
    {
      quote = c == quote ? 0 : quote;
    }
    else if (c == '"' || c == '\'')
    {
      quote = c;
    }
    else if (c == '#' && (n == 0 || line[n - 1] == ' ' || line[n - 1] == '\t'))
    {
      return trimmed(line.substr(n + 1));
    }
  }
  return {};
}
} // namespace

std::vector<TemplateParameterInfo> readTemplateParameters(const std::string& path)
{
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    throw TemplateError(path, 0, "", "cannot open the template");
  }
  std::ostringstream buffer;
  buffer << stream.rdbuf();
  const std::string text = buffer.str();
  std::vector<std::string> lines;
  {
    std::istringstream lineStream(text);
    for (std::string line; std::getline(lineStream, line);)
    {
      lines.push_back(line);
    }
  }
  YAML::Node root;
  try
  {
    root = YAML::Load(text);
  }
  catch (const YAML::Exception& error)
  {
    throw TemplateError(path, error.mark.line + 1, "", "not YAML: " + error.msg);
  }
  std::vector<TemplateParameterInfo> result;
  const YAML::Node parameters = root.IsMap() ? root["parameters"] : YAML::Node();
  if (!parameters || !parameters.IsMap())
  {
    return result;
  }
  for (const auto& entry : parameters)
  {
    TemplateParameterInfo info;
    info.name = entry.first.as<std::string>("");
    if (entry.second.IsScalar())
    {
      info.defaultExpression = entry.second.Scalar();
    }
    const int line = entry.first.Mark().line;
    std::string comment =
      line >= 0 && line < static_cast<int>(lines.size()) ? commentOf(lines[line]) : "";
    const std::size_t open = comment.rfind('[');
    const std::size_t close = comment.rfind(']');
    if (open != std::string::npos && close != std::string::npos && close > open)
    {
      info.unit = trimmed(comment.substr(open + 1, close - open - 1));
      comment = trimmed(comment.substr(0, open) + comment.substr(close + 1));
    }
    info.description = comment;
    result.push_back(info);
  }
  return result;
}
} // namespace model
} // namespace blockforge
