// Curves on surfaces (SurfaceCurve). The surfaces themselves are in
// SurfaceOfRevolution.cpp and GordonSurface.cpp.
#include "Carriers.h"

#include "RootFinding.h"

#include <algorithm>

namespace blockforge
{

// =======================================================================================
SurfaceCurve::SurfaceCurve(SurfacePtr surface, std::vector<Eigen::Vector2d> parameterPoints)
  : TheSurface(std::move(surface))
  , ParameterPoints(std::move(parameterPoints))
{
  if (!TheSurface)
  {
    throw GeometryError("surface curve: no surface given");
  }
  if (ParameterPoints.size() < 2)
  {
    throw GeometryError("surface curve needs at least 2 (s, t) points, got " +
      std::to_string(ParameterPoints.size()));
  }
  std::vector<Vec3> points;
  points.reserve(ParameterPoints.size());
  for (const Eigen::Vector2d& st : ParameterPoints)
  {
    points.emplace_back(st.x(), st.y(), 0.0);
  }
  try
  {
    // Degree min(3, n - 1) (interpolate lowers it), chord length in (s, t).
    ParameterCurve = std::make_shared<const BSplineCurve>(
      BSplineCurve::interpolate(points, 3, ParameterMethod::ChordLength));
  }
  catch (const GeometryError& e)
  {
    throw GeometryError(std::string("surface curve (in (s, t) space): ") + e.what());
  }
}

Eigen::Vector2d SurfaceCurve::parameters(double u) const
{
  const Vec3 q = ParameterCurve->point(u);
  return Eigen::Vector2d(q.x(), q.y());
}

std::vector<double> SurfaceCurve::breakpoints() const
{
  std::vector<double> ends = ParameterCurve->breakpoints();
  ends.insert(ends.begin(), 0.0);
  ends.push_back(1.0);
  std::vector<double> result(ends.begin() + 1, ends.end() - 1);
  for (const bool tDirection : { false, true })
  {
    const std::vector<double> across = TheSurface->breakpoints(tDirection);
    if (across.empty())
    {
      continue;
    }
    const int k = tDirection ? 1 : 0;
    Vec3 previous = ParameterCurve->point(ends[0]);
    for (std::size_t span = 0; span + 1 < ends.size(); ++span)
    {
      const Vec3 next = ParameterCurve->point(ends[span + 1]);
      const double low = std::min(previous[k], next[k]), high = std::max(previous[k], next[k]);
      for (auto at = std::upper_bound(across.begin(), across.end(), low);
           at != across.end() && *at < high; ++at)
      {
        const double value = *at;
        NewtonStop stop;
        stop.iterations = 60;
        stop.stepTolerance = 1e-15;
        const double sign = next[k] > previous[k] ? 1.0 : -1.0;
        Vec3 jet[2];
        const double u = newtonInBracket(
          [&](double x) {
            ParameterCurve->derivatives(x, 1, jet);
            return sign * (jet[0][k] - value);
          },
          [&](double) { return sign * jet[1][k]; }, ends[span], ends[span + 1],
          ends[span] + (value - previous[k]) / (next[k] - previous[k]) * (ends[span + 1] - ends[span]),
          stop);
        result.push_back(u);
      }
      previous = next;
    }
  }
  std::sort(result.begin(), result.end());
  return result;
}

Vec3 SurfaceCurve::point(double u) const
{
  const Vec3 q = ParameterCurve->point(u);
  return TheSurface->point(q.x(), q.y());
}

Vec3 SurfaceCurve::derivative(double u, int order) const
{
  if (order <= 0)
  {
    return point(u);
  }
  if (order > 2)
  {
    return Vec3::Zero();
  }
  Vec3 q[3];
  if (order == 1)
  {
    ParameterCurve->derivatives(u, 1, q);
    Vec3 P, Ps, Pt;
    TheSurface->firstDerivatives(q[0].x(), q[0].y(), P, Ps, Pt);
    return q[1].x() * Ps + q[1].y() * Pt;
  }
  ParameterCurve->derivatives(u, 2, q);
  SurfaceDerivatives d;
  TheSurface->derivatives(q[0].x(), q[0].y(), d);
  const double s1 = q[1].x(), t1 = q[1].y();
  // Chain rule: d2/du2 S(s(u), t(u)).
  return s1 * s1 * d.Pss + 2.0 * s1 * t1 * d.Pst + t1 * t1 * d.Ptt + q[2].x() * d.Ps +
    q[2].y() * d.Pt;
}
} // namespace blockforge
