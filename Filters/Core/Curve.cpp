#include "Curve.h"
#include "CoreSupport.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace blockforge
{
namespace
{
constexpr double Pi = 3.14159265358979323846;

using core::format;
using core::isFinite;

void requireFinite(const Vec3& v, const char* what, const char* curveKind)
{
  if (!isFinite(v))
  {
    throw GeometryError(std::string(curveKind) + ": " + what + " point has a non-finite coordinate " +
      format(v));
  }
}

/// k-th derivative of centre + R (cos(t S) e1 + sin(t S) e2): each derivative rotates the
/// (cos, sin) pair by a quarter turn; the switch avoids the rounding of cos(phi + pi/2).
Vec3 arcDerivative(const Vec3& e1, const Vec3& e2, double radius, double sweep, double t,
  int order)
{
  if (order <= 0)
  {
    return Vec3::Zero();
  }
  const double phi = t * sweep;
  const double c = std::cos(phi), s = std::sin(phi);
  const double factor = radius * std::pow(sweep, order);
  switch (order % 4)
  {
    case 1:
      return factor * (-s * e1 + c * e2);
    case 2:
      return factor * (-c * e1 - s * e2);
    case 3:
      return factor * (s * e1 - c * e2);
    default:
      return factor * (c * e1 + s * e2);
  }
}
} // namespace

// ---------------------------------------------------------------------------------------
LineCurve::LineCurve(const Vec3& a, const Vec3& b)
  : A(a)
  , B(b)
{
  requireFinite(a, "start", "straight line");
  requireFinite(b, "end", "straight line");
}

Vec3 LineCurve::point(double t) const
{
  // This form returns A and B bit for bit at t = 0 and t = 1, so neighbouring entities
  // built from the same vertices share identical coordinates.
  return (1.0 - t) * A + t * B;
}

Vec3 LineCurve::derivative(double, int order) const
{
  return order == 1 ? Vec3(B - A) : Vec3(Vec3::Zero());
}

// ---------------------------------------------------------------------------------------
ArcCurve ArcCurve::fromCentre(const Vec3& start, const Vec3& end, const Vec3& centre,
  bool longWay)
{
  requireFinite(start, "start", "arc");
  requireFinite(end, "end", "arc");
  requireFinite(centre, "centre", "arc");

  const Vec3 toStart = start - centre;
  const Vec3 toEnd = end - centre;
  const double r0 = toStart.norm();
  const double r1 = toEnd.norm();
  if (!(r0 > 0.0) || !(r1 > 0.0))
  {
    throw GeometryError("arc: the centre " + format(centre) +
      " coincides with an end point of the arc");
  }
  if (std::abs(r0 - r1) > 1e-6 * std::max(r0, r1))
  {
    std::ostringstream s;
    s.precision(10);
    s << "arc: start " << format(start) << " and end " << format(end)
      << " are not at the same distance from the centre " << format(centre) << " (" << r0
      << " vs " << r1 << ")";
    throw GeometryError(s.str());
  }

  ArcCurve arc;
  arc.Centre = centre;
  arc.Start = start;
  arc.End = end;
  arc.Radius = 0.5 * (r0 + r1);
  arc.E1 = toStart / r0;
  // Gram-Schmidt against E1 fixes the arc's plane; it is undefined when the end points
  // are identical or diametrically opposite, because then infinitely many arcs qualify.
  Vec3 inPlane = toEnd / r1 - (toEnd / r1).dot(arc.E1) * arc.E1;
  const double inPlaneNorm = inPlane.norm();
  if (inPlaneNorm < 1e-10)
  {
    throw GeometryError("arc: start " + format(start) + " and end " + format(end) +
      " are identical or diametrically opposite about the centre " + format(centre) +
      ", so the arc's plane is undefined; use an arc through a point instead");
  }
  arc.E2 = inPlane / inPlaneNorm;
  const double shortSweep = std::atan2(toEnd.dot(arc.E2), toEnd.dot(arc.E1)); // in (0, pi)
  if (longWay)
  {
    arc.E2 = -arc.E2;
    arc.Sweep = 2.0 * Pi - shortSweep;
  }
  else
  {
    arc.Sweep = shortSweep;
  }
  return arc;
}

ArcCurve ArcCurve::throughPoint(const Vec3& start, const Vec3& through, const Vec3& end)
{
  requireFinite(start, "start", "arc");
  requireFinite(through, "intermediate", "arc");
  requireFinite(end, "end", "arc");

  // Circumcentre relative to `through`, in the form that stays accurate for thin triangles:
  // c = ((|a|^2 b - |b|^2 a) x (a x b)) / (2 |a x b|^2).
  const Vec3 a = start - through;
  const Vec3 b = end - through;
  const Vec3 normal = a.cross(b);
  const double scale = std::max({ a.norm(), b.norm(), (end - start).norm() });
  if (!(scale > 0.0) || normal.norm() <= 1e-12 * scale * scale)
  {
    throw GeometryError("arc: the points " + format(start) + ", " + format(through) +
      " and " + format(end) + " are collinear or coincide, so no circle passes through them");
  }
  const Vec3 offset =
    (a.squaredNorm() * b - b.squaredNorm() * a).cross(normal) / (2.0 * normal.squaredNorm());

  ArcCurve arc;
  arc.Centre = through + offset;
  arc.Start = start;
  arc.End = end;
  const Vec3 toStart = start - arc.Centre;
  arc.Radius = toStart.norm();
  arc.E1 = toStart / arc.Radius;
  // Traversing start -> through -> end is counter-clockwise about the triangle normal
  // (through - start) x (end - start), so E2 = n x E1 points along the arc.
  const Vec3 orientation = (through - start).cross(end - start).normalized();
  arc.E2 = orientation.cross(arc.E1).normalized();
  const Vec3 toEnd = end - arc.Centre;
  double sweep = std::atan2(toEnd.dot(arc.E2), toEnd.dot(arc.E1));
  if (sweep <= 0.0)
  {
    sweep += 2.0 * Pi;
  }
  arc.Sweep = sweep;
  return arc;
}

Vec3 ArcCurve::point(double t) const
{
  if (t == 0.0)
  {
    return Start;
  }
  if (t == 1.0)
  {
    return End;
  }
  const double phi = t * Sweep;
  return Centre + Radius * (std::cos(phi) * E1 + std::sin(phi) * E2);
}

Vec3 ArcCurve::derivative(double t, int order) const
{
  return arcDerivative(E1, E2, Radius, Sweep, t, order);
}
} // namespace blockforge
