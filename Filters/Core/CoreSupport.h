/**
 * @file CoreSupport.h
 * @brief Private to the .cpp files of the numerical core (no public header includes it):
 * the small helpers that several of them had each kept a copy of, so that error messages
 * print numbers alike and parameters are clamped alike everywhere.
 */
#pragma once

#include "Types.h"

#include <cmath>
#include <sstream>
#include <string>

namespace blockforge
{
namespace core
{
/// A number in an error message: 10 significant digits, enough to tell two close ones apart.
inline std::string format(double value)
{
  std::ostringstream s;
  s.precision(10);
  s << value;
  return s.str();
}

/// A point in an error message: "(x, y, z)", each coordinate as format(double).
inline std::string format(const Vec3& v)
{
  return "(" + format(v.x()) + ", " + format(v.y()) + ", " + format(v.z()) + ")";
}

inline bool isFinite(const Vec3& v)
{
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

/// u clamped to [0, 1]; u itself (the same bits) inside.
inline double clampUnit(double u)
{
  return u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
}
} // namespace core
} // namespace blockforge
