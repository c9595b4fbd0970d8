/**
 * @file TestHelpers.h
 * @brief Small helpers shared by the C++ tests of the model and the template engine.
 */
#pragma once

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace blockforge
{
namespace test
{
constexpr double Pi = 3.14159265358979323846;

/// A file of the source tree, e.g. sourcePath("Templates/cylinder_in_box.yaml").
inline std::string sourcePath(const std::string& relative)
{
  return std::string(BLOCKFORGE_SOURCE_DIR) + "/" + relative;
}

/// A template of Templates/, by file name.
inline std::string templatePath(const std::string& fileName)
{
  return sourcePath("Templates/" + fileName);
}

/// The parameter-only example templates.
inline const std::vector<std::string>& exampleTemplates()
{
  static const std::vector<std::string> names = { "cylinder_in_box.yaml",
    "annular_sector.yaml", "wedge_sector.yaml" };
  return names;
}

/// 1-based number of the first line of `text` containing `needle` (a test failure if none).
inline int lineContaining(const std::string& text, const std::string& needle)
{
  std::istringstream stream(text);
  int number = 0;
  for (std::string line; std::getline(stream, line);)
  {
    ++number;
    if (line.find(needle) != std::string::npos)
    {
      return number;
    }
  }
  ADD_FAILURE() << "no line contains " << needle;
  return 0;
}
} // namespace test
} // namespace blockforge
