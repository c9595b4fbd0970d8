/**
 * @file TestTurboInputs.h
 * @brief Turbomachinery point sets read from disk, handed to the template engine the way
 * vtkBlockTemplate hands on the reader's output (metres, machine data). For tests that
 * link BlockForgeIO.
 */
#pragma once

#include "Template.h"
#include "TurboPointSets.h"

#include <string>

namespace blockforge
{
namespace test
{
inline model::TemplateInputs readTemplateInputs(const std::string& descriptionFile)
{
  const io::TurboPointSets sets = io::readTurboPointSets(descriptionFile);
  model::TemplateInputs inputs;
  auto curve = [&](const io::PointSet& set) {
    model::InputCurve result;
    result.name = set.name;
    for (const Eigen::Vector3d& p : set.points)
    {
      result.points.push_back(p * sets.scale);
    }
    return result;
  };
  model::InputPointSet hub, shroud, profiles;
  hub.name = "Hub";
  hub.curves.push_back(curve(sets.hub));
  shroud.name = "Shroud";
  shroud.curves.push_back(curve(sets.shroud));
  profiles.name = "Profiles";
  profiles.isList = true;
  for (const io::ProfileSection& section : sets.profiles)
  {
    profiles.curves.push_back(curve(section));
    profiles.curves.back().span = section.spanPercent / 100.0;
  }
  inputs.pointSets = { hub, shroud, profiles };
  inputs.hasMachine = true;
  inputs.axis = sets.axis;
  inputs.bladeCount = sets.bladeCount;
  return inputs;
}
} // namespace test
} // namespace blockforge
