// Surfaces of revolution (hub and shroud): a meridional contour swept about the axis.
// Split from Carriers.cpp by surface kind; GordonSurface.cpp holds the blade surface.
#include "Carriers.h"
#include "CoreSupport.h"

#include <Eigen/Geometry>

#include <cmath>

namespace blockforge
{
namespace
{
using core::format;
using core::isFinite;

// ---------------------------------------------------------------------------------------
/// The contour in the meridional half-plane: (axial, radius, 0). Its closest point to a
/// point's (axial, radius) is the meridional foot point on the surface of revolution.
class MeridionalCurve : public Curve
{
public:
  MeridionalCurve(CurvePtr contour, const Vec3& axisPoint, const Vec3& axisDirection)
    : Contour(std::move(contour))
    , Spline(dynamic_cast<const BSplineCurve*>(Contour.get()))
    , AxisPoint(axisPoint)
    , Axis(axisDirection)
  {
  }

  Vec3 point(double s) const override { return meridionalPoint(Contour->point(s)); }

  Vec3 derivative(double s, int order = 1) const override
  {
    if (order <= 0)
    {
      return point(s);
    }
    if (order > 2)
    {
      return Vec3::Zero();
    }
    Vec3 c[3], d[2];
    contourJet(s, order, c);
    meridionalDerivatives(c, order, d);
    return d[order - 1];
  }

  /// One contour evaluation for both derivatives (a projection's Newton step needs the
  /// point and both): the same bits as point(), derivative(s, 1) and derivative(s, 2).
  void jet(double s, Vec3 out[3]) const override
  {
    Vec3 c[3];
    contourJet(s, 2, c);
    // A B-spline's derivatives() gives its point() bit for bit (basisDerivatives), so the point
    // comes from the same evaluation.
    out[0] = Spline ? meridionalPoint(c[0]) : point(s);
    meridionalDerivatives(c, 2, out + 1);
  }

private:
  Vec3 meridionalPoint(const Vec3& contourPoint) const
  {
    const Vec3 v = contourPoint - AxisPoint;
    const double axial = Axis.dot(v);
    return Vec3(axial, (v - axial * Axis).norm(), 0.0);
  }

  void contourJet(double s, int order, Vec3 c[3]) const
  {
    if (Spline)
    {
      Spline->derivatives(s, 2, c);
    }
    else
    {
      c[0] = Contour->point(s);
      c[1] = Contour->derivative(s, 1);
      c[2] = order == 2 ? Contour->derivative(s, 2) : Vec3::Zero();
    }
  }

  /// (axial, radius, 0)' and, for order 2, '' from the contour's jet c.
  void meridionalDerivatives(const Vec3 c[3], int order, Vec3 d[2]) const
  {
    const Vec3 v = c[0] - AxisPoint;
    const Vec3 w = v - Axis.dot(v) * Axis; // radial vector
    const double r = w.norm();
    const double axial1 = Axis.dot(c[1]);
    const Vec3 w1 = c[1] - axial1 * Axis;
    // r = |w|: r' = w.w'/r. On the axis (r = 0) the one-sided limit |w'| is used.
    const double r1 = r > 0.0 ? w.dot(w1) / r : w1.norm();
    d[0] = Vec3(axial1, r1, 0.0);
    if (order < 2)
    {
      return;
    }
    const double axial2 = Axis.dot(c[2]);
    const Vec3 w2 = c[2] - axial2 * Axis;
    // From r r' = w.w': r'^2 + r r'' = w'.w' + w.w''.
    const double r2 = r > 0.0 ? (w1.squaredNorm() + w.dot(w2) - r1 * r1) / r : 0.0;
    d[1] = Vec3(axial2, r2, 0.0);
  }

  CurvePtr Contour;
  const BSplineCurve* Spline;
  Vec3 AxisPoint, Axis;
};

/// Rotation of a direction (no translation) about the unit axis k: the part along k is
/// kept, the perpendicular part turned in its plane, so the radius is kept to rounding.
Vec3 rotateVector(const Vec3& v, const Vec3& k, double c, double s)
{
  const Vec3 along = k.dot(v) * k;
  const Vec3 perpendicular = v - along;
  return along + c * perpendicular + s * k.cross(perpendicular);
}
} // namespace

// =======================================================================================
Vec3 rotateAboutAxis(const Vec3& p, const Vec3& axisPoint, const Vec3& axisDirection,
  double angle)
{
  if (angle == 0.0)
  {
    return p; // exactly: unrotated images coincide with their source bit for bit
  }
  const double norm = axisDirection.norm();
  if (!(norm > 0.0) || !std::isfinite(norm) || !std::isfinite(angle))
  {
    throw GeometryError("rotation about an axis: the axis direction is zero or not finite, "
                        "or the angle is not finite");
  }
  // Rodrigues' formula in the split form v_par + cos v_perp + sin k x v_perp.
  const Vec3 k = axisDirection / norm;
  return axisPoint + rotateVector(p - axisPoint, k, std::cos(angle), std::sin(angle));
}

// =======================================================================================
SurfaceOfRevolution::SurfaceOfRevolution(CurvePtr contour, const Vec3& axisPoint,
  const Vec3& axisDirection, double angleStart, double angleEnd)
  : Contour(std::move(contour))
  , AxisPoint(axisPoint)
  , AngleStart(angleStart)
  , AngleEnd(angleEnd)
{
  if (!Contour)
  {
    throw GeometryError("surface of revolution: no contour given");
  }
  const double norm = axisDirection.norm();
  if (!isFinite(axisPoint) || !(norm > 0.0) || !std::isfinite(norm))
  {
    throw GeometryError("surface of revolution: the axis point is not finite or the axis "
                        "direction is zero or not finite");
  }
  if (!std::isfinite(angleStart) || !std::isfinite(angleEnd) || angleStart == angleEnd)
  {
    throw GeometryError("surface of revolution: the sweep from " + format(angleStart) +
      " to " + format(angleEnd) + " rad is empty or not finite");
  }
  AxisDirection = axisDirection / norm;
  ContourSpline = dynamic_cast<const BSplineCurve*>(Contour.get());
  Meridional = std::make_shared<MeridionalCurve>(Contour, AxisPoint, AxisDirection);
  // 256 samples: hub/shroud contours are smooth; candidates are refined by Newton anyway.
  MeridionalProjector = std::make_shared<CurveProjector>(Meridional, 256);
}

std::vector<double> SurfaceOfRevolution::breakpoints(bool tDirection) const
{
  return tDirection ? std::vector<double>() : Contour->breakpoints();
}

Vec3 SurfaceOfRevolution::point(double s, double t) const
{
  const double angle = AngleStart + t * (AngleEnd - AngleStart);
  if (angle == 0.0)
  {
    return Contour->point(s);
  }
  return AxisPoint +
    rotateVector(Contour->point(s) - AxisPoint, AxisDirection, std::cos(angle), std::sin(angle));
}

// point() at the five parameters: three contour points and three angles, each once.
void SurfaceOfRevolution::crossPoints(double s, double sPlus, double sMinus, double t,
  double tPlus, double tMinus, Vec3 out[5]) const
{
  Vec3 contour[3];
  const double along[3] = { s, sPlus, sMinus };
  if (ContourSpline)
  {
    ContourSpline->points(along, contour); // point()'s bits, the span looked up once
  }
  else
  {
    for (int k = 0; k < 3; ++k)
    {
      contour[k] = Contour->point(along[k]);
    }
  }
  double angle[3], cs[3], sn[3];
  const double at[3] = { t, tPlus, tMinus };
  for (int k = 0; k < 3; ++k)
  {
    angle[k] = AngleStart + at[k] * (AngleEnd - AngleStart);
    cs[k] = std::cos(angle[k]);
    sn[k] = std::sin(angle[k]);
  }
  auto rotated = [&](int c, int a) {
    return angle[a] == 0.0
      ? contour[c]
      : Vec3(AxisPoint + rotateVector(contour[c] - AxisPoint, AxisDirection, cs[a], sn[a]));
  };
  out[0] = rotated(0, 0);
  out[1] = rotated(1, 0);
  out[2] = rotated(2, 0);
  out[3] = rotated(0, 1);
  out[4] = rotated(0, 2);
}

void SurfaceOfRevolution::contourJet(double s, int order, Vec3 (&c)[3]) const
{
  if (ContourSpline)
  {
    ContourSpline->derivatives(s, order, c);
    return;
  }
  c[0] = Contour->point(s);
  c[1] = Contour->derivative(s, 1);
  c[2] = order >= 2 ? Contour->derivative(s, 2) : Vec3::Zero();
}

void SurfaceOfRevolution::derivatives(double s, double t, SurfaceDerivatives& out) const
{
  Vec3 c[3], arm;
  contourJet(s, 2, c);
  double cs = 0.0, sn = 0.0;
  firstOrder(c, t, out.P, out.Ps, out.Pt, cs, sn, arm);
  const double sweep = AngleEnd - AngleStart;
  const Vec3& k = AxisDirection;
  out.Pss = rotateVector(c[2], k, cs, sn);
  out.Ptt = sweep * sweep * k.cross(k.cross(arm));
  out.Pst = sweep * k.cross(out.Ps);
}

void SurfaceOfRevolution::firstDerivatives(double s, double t, Vec3& P, Vec3& Ps, Vec3& Pt) const
{
  Vec3 c[3], arm;
  contourJet(s, 1, c);
  double cs = 0.0, sn = 0.0;
  firstOrder(c, t, P, Ps, Pt, cs, sn, arm);
}

void SurfaceOfRevolution::firstOrder(const Vec3 (&c)[3], double t, Vec3& P, Vec3& Ps, Vec3& Pt,
  double& cs, double& sn, Vec3& arm) const
{
  const double sweep = AngleEnd - AngleStart;
  const double angle = AngleStart + t * sweep;
  cs = std::cos(angle);
  sn = std::sin(angle);
  const Vec3& k = AxisDirection;
  arm = angle == 0.0 ? Vec3(c[0] - AxisPoint) : rotateVector(c[0] - AxisPoint, k, cs, sn);
  P = angle == 0.0 ? c[0] : Vec3(AxisPoint + arm);
  Ps = rotateVector(c[1], k, cs, sn);
  // d/dangle of a rotation is k x (rotated vector).
  Pt = sweep * k.cross(arm);
}

void SurfaceOfRevolution::axialRadial(const Vec3& p, double& axial, double& radius) const
{
  const Vec3 v = p - AxisPoint;
  axial = AxisDirection.dot(v);
  radius = (v - axial * AxisDirection).norm();
}

CurveProjection SurfaceOfRevolution::projectMeridional(const Vec3& p) const
{
  double axial, radius;
  axialRadial(p, axial, radius);
  return MeridionalProjector->project(Vec3(axial, radius, 0.0));
}

double SurfaceOfRevolution::signedMeridionalDistance(const Vec3& p) const
{
  double axial, radius;
  axialRadial(p, axial, radius);
  const CurveProjection foot = MeridionalProjector->project(Vec3(axial, radius, 0.0));
  const Vec3 tangent = Meridional->derivative(foot.t, 1);
  // Left normal of the tangent (axial', radius') is (-radius', axial').
  const double side =
    (axial - foot.point.x()) * -tangent.y() + (radius - foot.point.y()) * tangent.x();
  return side < 0.0 ? -foot.distance : foot.distance;
}

double SurfaceOfRevolution::contourParameter(const Vec3& p) const
{
  return projectMeridional(p).t;
}
} // namespace blockforge
