#include "Surface.h"
#include "CoreSupport.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace blockforge
{
using core::format;

CoonsPatch::CoonsPatch(CurvePtr bottom, CurvePtr right, CurvePtr top, CurvePtr left)
  : Bottom(std::move(bottom))
  , Right(std::move(right))
  , Top(std::move(top))
  , Left(std::move(left))
{
  if (!Bottom || !Right || !Top || !Left)
  {
    throw GeometryError("Coons patch: one of the four boundary curves is missing");
  }
  C00 = Bottom->point(0.0);
  C10 = Bottom->point(1.0);
  C01 = Top->point(0.0);
  C11 = Top->point(1.0);

  const Vec3 lower = C00.cwiseMin(C10).cwiseMin(C01).cwiseMin(C11);
  const Vec3 upper = C00.cwiseMax(C10).cwiseMax(C01).cwiseMax(C11);
  const double size = (upper - lower).norm();
  const double tolerance = 1e-9 * (size > 0.0 ? size : 1.0);
  auto requireMeet = [&](const Vec3& corner, const Vec3& other, const char* where) {
    const double gap = (corner - other).norm();
    if (!(gap <= tolerance))
    {
      std::ostringstream s;
      s.precision(6);
      s << "Coons patch: the boundary curves do not meet at the " << where << " corner "
        << format(corner) << " (gap " << gap << ")";
      throw GeometryError(s.str());
    }
  };
  requireMeet(C00, Left->point(0.0), "(s=0, t=0)");
  requireMeet(C01, Left->point(1.0), "(s=0, t=1)");
  requireMeet(C10, Right->point(0.0), "(s=1, t=0)");
  requireMeet(C11, Right->point(1.0), "(s=1, t=1)");
}

Vec3 CoonsPatch::point(double s, double t) const
{
  // Grouping each bottom/top curve with the corners it contains makes the bracket vanish
  // exactly on s = 0 and s = 1, so the patch reproduces the left/right curves bit for bit
  // there (shared edges of neighbouring faces then coincide).
  const Vec3 bottomDeviation = Bottom->point(s) - ((1.0 - s) * C00 + s * C10);
  const Vec3 topDeviation = Top->point(s) - ((1.0 - s) * C01 + s * C11);
  return (1.0 - s) * Left->point(t) + s * Right->point(t) + (1.0 - t) * bottomDeviation +
    t * topDeviation;
}

void CoonsPatch::derivatives(double s, double t, SurfaceDerivatives& out) const
{
  const Vec3 bottom = Bottom->point(s), top = Top->point(s);
  const Vec3 left = Left->point(t), right = Right->point(t);
  const Vec3 bottomS = Bottom->derivative(s, 1), topS = Top->derivative(s, 1);
  const Vec3 leftT = Left->derivative(t, 1), rightT = Right->derivative(t, 1);

  const Vec3 bottomDeviation = bottom - ((1.0 - s) * C00 + s * C10);
  const Vec3 topDeviation = top - ((1.0 - s) * C01 + s * C11);
  out.P = (1.0 - s) * left + s * right + (1.0 - t) * bottomDeviation + t * topDeviation;

  // d/ds and d/dt of the grouped form above.
  const Vec3 bottomDeviationS = bottomS - (C10 - C00);
  const Vec3 topDeviationS = topS - (C11 - C01);
  out.Ps = right - left + (1.0 - t) * bottomDeviationS + t * topDeviationS;
  out.Pt = (1.0 - s) * leftT + s * rightT + topDeviation - bottomDeviation;
  out.Pss = (1.0 - t) * Bottom->derivative(s, 2) + t * Top->derivative(s, 2);
  out.Ptt = (1.0 - s) * Left->derivative(t, 2) + s * Right->derivative(t, 2);
  out.Pst = rightT - leftT + topDeviationS - bottomDeviationS;
}
} // namespace blockforge
