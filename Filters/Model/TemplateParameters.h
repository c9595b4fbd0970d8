/**
 * @file TemplateParameters.h
 * @brief The parameters a template declares, as a user sees them in the file: name, default
 * expression, unit and description from the comment on the parameter's line
 * (`R: 0.5  # cylinder radius [m]`). What the ParaView panel lists before any run.
 */
#pragma once

#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
struct TemplateParameterInfo
{
  std::string name;
  std::string defaultExpression; ///< as written in the template
  std::string unit;              ///< the last [...] of the comment, without brackets
  std::string description;       ///< the comment without the unit
};

/**
 * The `parameters:` of the template file at `path`, in file order. Throws TemplateError
 * naming the file (and line) when it cannot be read or is not YAML; a template without
 * parameters gives an empty list.
 */
std::vector<TemplateParameterInfo> readTemplateParameters(const std::string& path);
} // namespace model
} // namespace blockforge
