/**
 * @file TestTurboInputs.h
 * @brief Turbomachinery point sets read from disk, handed to the template engine the way
 * vtkBlockTemplate hands on the reader's output (metres, machine data). For tests that
 * link BlockForgeIO.
 */
#pragma once

#include "TurboTemplateInputs.h"

#include <string>

namespace blockforge
{
namespace test
{
inline model::TemplateInputs readTemplateInputs(const std::string& descriptionFile)
{
  return io::templateInputs(io::readTurboPointSets(descriptionFile), descriptionFile);
}
} // namespace test
} // namespace blockforge
