/**
 * @file Errors.h
 * @brief The error type of the model layer, at its bottom: every part of the model
 * (template reader, model document, carriers, topology, mesher) reports a problem in a
 * template or model as a TemplateError that names where it is.
 */
#pragma once

#include <stdexcept>
#include <string>

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

/**
 * @class FoldError
 * @brief A block whose grid folds at the node counts meshed: the first cells at one of
 * its corners are inverted (the mesher's corner check). Unlike other TemplateErrors it
 * may depend on the cell counts alone: a coarse preview can fold where the grid does not.
 */
class FoldError : public TemplateError
{
public:
  using TemplateError::TemplateError;
};
} // namespace model
} // namespace blockforge
