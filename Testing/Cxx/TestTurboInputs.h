/**
 * @file TestTurboInputs.h
 * @brief Turbomachinery point sets read from disk, handed to the template engine the way
 * vtkBlockTemplate hands on the reader's output (metres, machine data). For tests that
 * link BlockForgeIO.
 */
#pragma once

#include "TurboTemplateInputs.h"

#include <algorithm>
#include <string>

namespace blockforge
{
namespace test
{
inline model::TemplateInputs readTemplateInputs(const std::string& descriptionFile)
{
  return io::templateInputs(io::readTurboPointSets(descriptionFile), descriptionFile);
}

/// The largest distance between two points of the first blade section (point set 2,
/// curve 0): the chord the passage tests scale their tolerances by.
inline double chordOf(const model::TemplateInputs& inputs)
{
  const auto& p = inputs.pointSets[2].curves[0].points;
  double chord = 0.0;
  for (const auto& a : p)
    for (const auto& b : p)
      chord = std::max(chord, (a - b).norm());
  return chord;
}
} // namespace test
} // namespace blockforge
