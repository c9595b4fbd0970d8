/**
 * @file TurboTemplateInputs.h
 * @brief Turbomachinery point sets as the template engine takes them: what vtkBlockTemplate
 * makes of the TurboPointSetsReader's output (point sets Hub, Shroud and the list
 * Profiles with span fractions, in metres; the machine's axis and blade count), without
 * VTK. Used by the native command line and the C++ tests; header-only, for targets that
 * link BlockForgeIO and BlockForgeModel.
 */
#pragma once

#include "Template.h"
#include "TurboPointSets.h"

namespace blockforge
{
namespace io
{
inline model::TemplateInputs templateInputs(const TurboPointSets& sets, const std::string& origin)
{
  auto curve = [&](const PointSet& set) {
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
  if (!sets.hub.points.empty())
  {
    hub.curves.push_back(curve(sets.hub));
  }
  shroud.name = "Shroud";
  if (!sets.shroud.points.empty())
  {
    shroud.curves.push_back(curve(sets.shroud));
  }
  profiles.name = "Profiles";
  profiles.isList = true;
  for (const ProfileSection& section : sets.profiles)
  {
    profiles.curves.push_back(curve(section));
    profiles.curves.back().span = section.spanPercent / 100.0;
  }
  model::TemplateInputs inputs;
  inputs.pointSets = { hub, shroud, profiles };
  inputs.hasMachine = true;
  inputs.axis = sets.axis.normalized();
  inputs.bladeCount = sets.bladeCount;
  inputs.origin = origin;
  return inputs;
}
} // namespace io
} // namespace blockforge
