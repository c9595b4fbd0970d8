/**
 * @file Types.h
 * @brief Basic types of the BlockForge numerical core (Eigen only, no VTK).
 *
 * Everything under Filters/Core is plain C++17 + Eigen so it can be unit-tested
 * without VTK; the vtkAlgorithm classes in Filters/ only translate to and from VTK.
 */
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

namespace blockforge
{
using Vec3 = Eigen::Vector3d;

/// Raised by the numerical core for invalid arguments (too few points, NaN, ...).
/// The message is meant for an end user; callers add file/line/entity context.
class GeometryError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};
} // namespace blockforge
