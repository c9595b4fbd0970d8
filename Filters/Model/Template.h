/**
 * @file Template.h
 * @brief The template engine: reads a BlockForge template (format version 1, YAML
 * syntax, the paper's "macro file"), evaluates its parameter expressions and builds the
 * BlockModel. The format is documented in Templates/README.md.
 */
#pragma once

#include "BlockModel.h"

#include <stdexcept>

namespace blockforge
{
namespace model
{
/**
 * @class TemplateError
 * @brief A problem in a template or model, located: "file:line: entity: message".
 */
class TemplateError : public std::runtime_error
{
public:
  TemplateError(const std::string& file, int line, const std::string& entity,
    const std::string& message);
  const std::string& file() const { return File; }
  int line() const { return Line; }
  const std::string& entity() const { return Entity; }

private:
  std::string File, Entity;
  int Line;
};

/// Parameter overrides: name -> expression (may use other parameters).
using ParameterOverrides = std::map<std::string, std::string>;

/// Reads and applies a template file. Throws TemplateError (missing file, YAML syntax
/// error, bad expression, unknown name, wrong count of vertices, ...).
BlockModel loadTemplate(const std::string& path, const ParameterOverrides& overrides = {});

/// Same, from text; `fileName` is used in messages only.
BlockModel parseTemplate(const std::string& text, const std::string& fileName,
  const ParameterOverrides& overrides = {});

/// A template parameter as declared (for GUIs and --help style listings).
struct ParameterInfo
{
  std::string name;
  std::string expression; ///< as written in the template
  double value = 0.0;     ///< evaluated with the overrides
  std::string comment;    ///< trailing comment (units), may be empty
};
std::vector<ParameterInfo> templateParameters(const std::string& path,
  const ParameterOverrides& overrides = {});
} // namespace model
} // namespace blockforge
