// Carrier geometry (paper section 2.2): surfaces of revolution, Gordon surfaces (eqs. 4-5)
// with Lagrange and spline blending, curves in (s, t) space and blade/hub intersections,
// checked against analytic surfaces.
#include "Carriers.h"
#include "Projection.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <new>
#include <string>

using namespace blockforge;

// Counting global allocation: evaluation of carriers must not touch the heap.
namespace
{
std::atomic<long> AllocationCount{ 0 };
}
void* operator new(std::size_t size)
{
  ++AllocationCount;
  if (void* p = std::malloc(size ? size : 1))
  {
    return p;
  }
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept
{
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept
{
  std::free(p);
}

namespace
{
constexpr double Pi = 3.14159265358979323846;

double maxError(const Vec3& a, const Vec3& b)
{
  return (a - b).cwiseAbs().maxCoeff();
}

/// Largest maxError between `surface` and the analytic `f(s, t, 0, 0)` on a 21 x 21 grid.
template <typename Function>
double worstOnGrid(const Surface& surface, const Function& f)
{
  double worst = 0;
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = 0; j <= 20; ++j)
    {
      const double s = i / 20.0, t = j / 20.0;
      worst = std::max(worst, maxError(surface.point(s, t), f(s, t, 0, 0)));
    }
  }
  return worst;
}

/// A curve given by a function of (t, derivative order): exact analytic sections.
class FunctionCurve : public Curve
{
public:
  using Function = std::function<Vec3(double, int)>;
  explicit FunctionCurve(Function f)
    : F(std::move(f))
  {
  }
  Vec3 point(double t) const override { return F(t, 0); }
  Vec3 derivative(double t, int order = 1) const override { return F(t, order); }

private:
  Function F;
};

/// Analytic surface f(s, t) with partial derivatives d^ds/ds d^dt/dt (ds, dt <= 2).
using AnalyticSurface = std::function<Vec3(double s, double t, int ds, int dt)>;

CurvePtr sCurveOf(const AnalyticSurface& f, double t)
{
  return std::make_shared<FunctionCurve>([f, t](double s, int k) { return f(s, t, k, 0); });
}

CurvePtr tCurveOf(const AnalyticSurface& f, double s)
{
  return std::make_shared<FunctionCurve>([f, s](double t, int k) { return f(s, t, 0, k); });
}

/// Polynomial surface: coordinate c is sum_ab coefficients[c][a][b] s^a t^b (a, b <= 3).
AnalyticSurface polynomialSurface(const std::array<std::array<std::array<double, 4>, 4>, 3>& c)
{
  auto power = [](double x, int a, int d) {
    // d-th derivative of x^a
    if (d > a)
    {
      return 0.0;
    }
    double factor = 1.0;
    for (int k = 0; k < d; ++k)
    {
      factor *= (a - k);
    }
    return factor * std::pow(x, a - d);
  };
  return [c, power](double s, double t, int ds, int dt) {
    Vec3 r = Vec3::Zero();
    for (int coord = 0; coord < 3; ++coord)
    {
      for (int a = 0; a < 4; ++a)
      {
        for (int b = 0; b < 4; ++b)
        {
          r[coord] += c[coord][a][b] * power(s, a, ds) * power(t, b, dt);
        }
      }
    }
    return r;
  };
}

/// Distance of p from the line through a along unit k.
double distanceToAxis(const Vec3& p, const Vec3& a, const Vec3& k)
{
  return (p - a).cross(k).norm();
}

/// Central differences of a surface's point and first derivatives against derivatives().
void expectDerivativesMatch(const Surface& surface, double s, double t, double tolerance,
  const std::string& what)
{
  const double h = 1e-5;
  SurfaceDerivatives d, sp, sm, tp, tm;
  surface.derivatives(s, t, d);
  surface.derivatives(s + h, t, sp);
  surface.derivatives(s - h, t, sm);
  surface.derivatives(s, t + h, tp);
  surface.derivatives(s, t - h, tm);
  const double scale = std::max(1.0, d.P.norm());
  EXPECT_LT(maxError(d.P, surface.point(s, t)), 1e-13 * scale) << what;
  EXPECT_LT(maxError(d.Ps, (surface.point(s + h, t) - surface.point(s - h, t)) / (2 * h)),
    tolerance * scale)
    << what << " Ps at " << s << ", " << t;
  EXPECT_LT(maxError(d.Pt, (surface.point(s, t + h) - surface.point(s, t - h)) / (2 * h)),
    tolerance * scale)
    << what << " Pt at " << s << ", " << t;
  EXPECT_LT(maxError(d.Pss, (sp.Ps - sm.Ps) / (2 * h)), tolerance * scale)
    << what << " Pss at " << s << ", " << t;
  EXPECT_LT(maxError(d.Ptt, (tp.Pt - tm.Pt) / (2 * h)), tolerance * scale)
    << what << " Ptt at " << s << ", " << t;
  EXPECT_LT(maxError(d.Pst, (tp.Ps - tm.Ps) / (2 * h)), tolerance * scale)
    << what << " Pst (d/dt Ps) at " << s << ", " << t;
  EXPECT_LT(maxError(d.Pst, (sp.Pt - sm.Pt) / (2 * h)), tolerance * scale)
    << what << " Pst (d/ds Pt) at " << s << ", " << t;
}

/// Tilted machine axis used by the revolution tests, with an orthonormal frame.
struct Frame
{
  Vec3 a{ 0.3, -0.2, 0.5 };
  Vec3 k = Vec3(1.0, 2.0, 2.0).normalized();
  Vec3 e1 = k.unitOrthogonal();
  Vec3 e2 = k.cross(e1);
  /// Point at axial coordinate x, radius r, angle phi from e1.
  Vec3 at(double x, double r, double phi = 0.0) const
  {
    return a + x * k + r * (std::cos(phi) * e1 + std::sin(phi) * e2);
  }
};

/// Hyperbolic paraboloid blade (twisted, ruled): lines at span t, radial along x.
/// P(s, t) = (1 - t) L0(s) + t L1(s), machine axis z.
Vec3 twistedBlade(double s, double t)
{
  const Vec3 l0a(0.5, -0.1, -0.2), l0b(0.5, 0.1, 0.2);
  const Vec3 l1a(1.0, 0.2, -0.2), l1b(1.0, -0.2, 0.3);
  const Vec3 l0 = (1 - s) * l0a + s * l0b, l1 = (1 - s) * l1a + s * l1b;
  return (1 - t) * l0 + t * l1;
}

std::shared_ptr<const GordonSurface> twistedBladeLoft(GordonSurface::Blending blending)
{
  std::vector<CurvePtr> sections;
  std::vector<double> spans = { 0.0, 0.3, 0.7, 1.0 };
  for (double t : spans)
  {
    sections.push_back(std::make_shared<LineCurve>(twistedBlade(0, t), twistedBlade(1, t)));
  }
  return std::make_shared<GordonSurface>(GordonSurface::fromSections(sections, spans, blending));
}

/// Hub/shroud contour in the (x, z) half-plane x > 0 about the z axis: radius r(z) linear.
std::shared_ptr<SurfaceOfRevolution> coneAboutZ(double r0, double z0, double r1, double z1)
{
  return std::make_shared<SurfaceOfRevolution>(
    std::make_shared<LineCurve>(Vec3(r0, 0, z0), Vec3(r1, 0, z1)), Vec3::Zero(), Vec3::UnitZ(),
    -Pi / 4, Pi / 4);
}

double radiusAboutZ(const Vec3& p)
{
  return std::hypot(p.x(), p.y());
}
} // namespace

// ---------------------------------------------------------------------------------------
// Rotation

TEST(RotateAboutAxis, QuarterTurnAndZeroAngle)
{
  const Vec3 r = rotateAboutAxis(Vec3(1, 0, 0), Vec3::Zero(), Vec3::UnitZ(), Pi / 2);
  EXPECT_LT(maxError(r, Vec3(0, 1, 0)), 1e-16);
  const Vec3 p(0.3, -4.0, 2.5);
  EXPECT_EQ(rotateAboutAxis(p, Vec3(1, 2, 3), Vec3(0, 1, 0), 0.0), p);
  // The direction is normalised: a longer vector gives the same rotation.
  const Vec3 a = rotateAboutAxis(p, Vec3(1, 2, 3), Vec3(1, 1, 0), 0.4);
  const Vec3 b = rotateAboutAxis(p, Vec3(1, 2, 3), Vec3(7, 7, 0), 0.4);
  EXPECT_LT(maxError(a, b), 1e-15);
  EXPECT_THROW(rotateAboutAxis(p, Vec3::Zero(), Vec3::Zero(), 0.1), GeometryError);
}

TEST(RotateAboutAxis, ComposesAndClosesAfterOneTurn)
{
  const Frame f;
  const Vec3 p(1.1, 0.4, -0.7);
  for (double a : { 0.3, -1.2, 2.0 })
  {
    for (double b : { 0.7, 1.9, -0.25 })
    {
      const Vec3 twice = rotateAboutAxis(rotateAboutAxis(p, f.a, f.k, a), f.a, f.k, b);
      const Vec3 once = rotateAboutAxis(p, f.a, f.k, a + b);
      EXPECT_LT(maxError(twice, once), 1e-14) << a << " + " << b;
      // Radius and axial position are kept.
      EXPECT_NEAR(distanceToAxis(once, f.a, f.k), distanceToAxis(p, f.a, f.k), 1e-15);
      EXPECT_NEAR((once - f.a).dot(f.k), (p - f.a).dot(f.k), 1e-15);
    }
  }
  for (int n : { 2, 3, 5, 7, 12, 17 })
  {
    Vec3 q = p;
    for (int i = 0; i < n; ++i)
    {
      q = rotateAboutAxis(q, f.a, f.k, 2 * Pi / n);
    }
    EXPECT_LT(maxError(q, p), 1e-14) << n << " pitches";
  }
}

// ---------------------------------------------------------------------------------------
// Surfaces of revolution

TEST(SurfaceOfRevolution, CylinderPointsAtExactRadiusAndAngle)
{
  const Frame f;
  const double radius = 0.8, x0 = -0.5, x1 = 1.5, a0 = 0.2, a1 = 1.5;
  const SurfaceOfRevolution cylinder(
    std::make_shared<LineCurve>(f.at(x0, radius), f.at(x1, radius)), f.a, f.k * 3.0, a0, a1);
  EXPECT_LT(maxError(cylinder.axisDirection(), f.k), 1e-16);
  double worstRadius = 0, worstAxial = 0, worstAngle = 0;
  for (int i = 0; i <= 10; ++i)
  {
    for (int j = 0; j <= 10; ++j)
    {
      const double s = i / 10.0, t = j / 10.0;
      const Vec3 p = cylinder.point(s, t);
      worstRadius = std::max(worstRadius, std::abs(distanceToAxis(p, f.a, f.k) / radius - 1));
      worstAxial = std::max(worstAxial, std::abs((p - f.a).dot(f.k) - (x0 + s * (x1 - x0))));
      const double angle = std::atan2((p - f.a).dot(f.e2), (p - f.a).dot(f.e1));
      worstAngle = std::max(worstAngle, std::abs(angle - (a0 + t * (a1 - a0))));
      double axial, r;
      cylinder.axialRadial(p, axial, r);
      EXPECT_NEAR(r, radius, 1e-15);
    }
  }
  EXPECT_LT(worstRadius, 1e-12);
  EXPECT_LT(worstAxial, 1e-14);
  EXPECT_LT(worstAngle, 1e-14);
}

TEST(SurfaceOfRevolution, DerivativesMatchFiniteDifferences)
{
  const Frame f;
  // Straight generator (cone) and a curved B-spline contour.
  std::vector<Vec3> points;
  for (int i = 0; i <= 8; ++i)
  {
    const double x = i / 8.0;
    points.push_back(f.at(x, 0.6 + 0.3 * std::sin(2.0 * x) + 0.1 * x * x));
  }
  const CurvePtr contours[] = { std::make_shared<LineCurve>(f.at(0, 0.5), f.at(1, 1.2)),
    std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points)) };
  for (const CurvePtr& contour : contours)
  {
    const SurfaceOfRevolution surface(contour, f.a, f.k, -0.4, 2.1);
    for (double s : { 0.1, 0.37, 0.8 })
    {
      for (double t : { 0.05, 0.5, 0.93 })
      {
        expectDerivativesMatch(surface, s, t, 1e-8, "revolution");
      }
    }
  }
}

TEST(SurfaceOfRevolution, ConeRadiusAndSignedDistance)
{
  const Frame f;
  const double x0 = -1.0, r0 = 0.5, x1 = 2.0, r1 = 1.5;
  const SurfaceOfRevolution cone(
    std::make_shared<LineCurve>(f.at(x0, r0), f.at(x1, r1)), f.a, f.k, 0.0, 2 * Pi);
  const double length = std::hypot(x1 - x0, r1 - r0);
  const double tx = (x1 - x0) / length, tr = (r1 - r0) / length;
  double worst = 0;
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = 0; j <= 20; ++j)
    {
      const double s = i / 20.0, t = j / 20.0;
      const double expected = r0 + s * (r1 - r0);
      worst = std::max(worst, std::abs(distanceToAxis(cone.point(s, t), f.a, f.k) / expected - 1));
    }
  }
  EXPECT_LT(worst, 1e-12);
  // Points at (axial x, radius r) whose foot is inside the generator: the signed distance
  // is the offset along the left normal (-tr, tx) = outward (larger radius) here.
  for (double x : { -0.5, 0.3, 1.2 })
  {
    for (double offset : { -0.3, -1e-4, 0.0, 2e-7, 0.25, 0.4 })
    {
      const double footX = x, footR = r0 + (x - x0) / (x1 - x0) * (r1 - r0);
      const double px = footX - tr * offset, pr = footR + tx * offset;
      for (double phi : { 0.0, 1.0, 4.0 })
      {
        const Vec3 p = f.at(px, pr, phi);
        EXPECT_NEAR(cone.signedMeridionalDistance(p), offset, 1e-12) << x << " " << offset;
        EXPECT_NEAR(cone.contourParameter(p), (x - x0) / (x1 - x0), 1e-12);
      }
    }
  }
  // A contour running the other way flips the sign.
  const SurfaceOfRevolution reversed(
    std::make_shared<LineCurve>(f.at(x1, r1), f.at(x0, r0)), f.a, f.k, 0.0, 1.0);
  EXPECT_NEAR(reversed.signedMeridionalDistance(f.at(0.5, 1.5, 2.0)),
    -cone.signedMeridionalDistance(f.at(0.5, 1.5, 2.0)), 1e-14);
}

TEST(SurfaceOfRevolution, CylinderInsideOutside)
{
  // Cylinder r = 2 about the z axis, contour along +z: outside positive.
  const SurfaceOfRevolution cylinder(std::make_shared<LineCurve>(Vec3(2, 0, 0), Vec3(2, 0, 3)),
    Vec3::Zero(), Vec3::UnitZ(), 0.0, Pi / 3);
  for (double r : { 0.0, 0.5, 1.999, 2.0, 2.001, 3.5 })
  {
    for (double z : { 0.1, 1.5, 2.9 })
    {
      for (double phi : { 0.0, 1.0, -2.5 })
      {
        const Vec3 p(r * std::cos(phi), r * std::sin(phi), z);
        EXPECT_NEAR(cylinder.signedMeridionalDistance(p), r - 2.0, 1e-12) << r << " " << z;
        EXPECT_NEAR(cylinder.contourParameter(p), z / 3.0, 1e-12);
      }
    }
  }
}

TEST(SurfaceOfRevolution, TorusFromArcContourSignedDistance)
{
  // Contour: circular arc (centre c, radius a) in the meridional plane, counter-clockwise
  // in (axial, radius): its left normal points to the centre, so inside is positive.
  const Frame f;
  const double cx = 0.5, cr = 2.0, a = 0.6;
  auto meridional = [&](double angle, double rho) {
    return f.at(cx + rho * std::cos(angle), cr + rho * std::sin(angle));
  };
  const auto arc = std::make_shared<ArcCurve>(
    ArcCurve::fromCentre(meridional(-Pi / 3, a), meridional(Pi / 3, a), f.at(cx, cr)));
  const SurfaceOfRevolution torus(arc, f.a, f.k, 0.0, Pi);
  for (double angle : { -0.9, -0.3, 0.0, 0.4, 1.0 })
  {
    for (double rho : { 0.2, 0.55, 0.6, 0.61, 1.1 })
    {
      for (double phi : { 0.0, 2.0 })
      {
        const Vec3 p = f.a + (cx + rho * std::cos(angle)) * f.k +
          (cr + rho * std::sin(angle)) * (std::cos(phi) * f.e1 + std::sin(phi) * f.e2);
        EXPECT_NEAR(torus.signedMeridionalDistance(p), a - rho, 1e-12) << angle << " " << rho;
        EXPECT_NEAR(torus.contourParameter(p), (angle + Pi / 3) / (2 * Pi / 3), 1e-11);
      }
    }
  }
  for (int i = 0; i <= 10; ++i)
  {
    const Vec3 p = torus.point(i / 10.0, 0.37);
    EXPECT_LT(std::abs(torus.signedMeridionalDistance(p)), 1e-14);
  }
}

TEST(SurfaceOfRevolution, InvalidInputThrows)
{
  const auto line = std::make_shared<LineCurve>(Vec3(1, 0, 0), Vec3(1, 0, 1));
  EXPECT_THROW(SurfaceOfRevolution(nullptr, Vec3::Zero(), Vec3::UnitZ(), 0, 1), GeometryError);
  EXPECT_THROW(SurfaceOfRevolution(line, Vec3::Zero(), Vec3::Zero(), 0, 1), GeometryError);
  EXPECT_THROW(SurfaceOfRevolution(line, Vec3::Zero(), Vec3::UnitZ(), 1, 1), GeometryError);
}

// ---------------------------------------------------------------------------------------
// Gordon surfaces: lofting

TEST(GordonLoft, PassesThroughEverySectionExactly)
{
  // Curved, twisted B-spline sections at uneven heights z (not normalised).
  const std::vector<double> heights = { 0.1, 0.5, 0.8, 1.6, 2.0 };
  std::vector<CurvePtr> sections;
  for (std::size_t j = 0; j < heights.size(); ++j)
  {
    std::vector<Vec3> points;
    const double twist = 0.4 * heights[j];
    for (int i = 0; i <= 12; ++i)
    {
      const double u = i / 12.0;
      const double x = u - 0.5, y = 0.15 * std::sin(Pi * u) + 0.05 * static_cast<double>(j);
      points.emplace_back(x * std::cos(twist) - y * std::sin(twist),
        x * std::sin(twist) + y * std::cos(twist), heights[j]);
    }
    sections.push_back(std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points)));
  }
  for (auto blending : { GordonSurface::Blending::Lagrange, GordonSurface::Blending::Spline })
  {
    const GordonSurface loft = GordonSurface::fromSections(sections, heights, blending);
    ASSERT_EQ(loft.tNodes().size(), heights.size());
    for (std::size_t j = 0; j < heights.size(); ++j)
    {
      EXPECT_NEAR(loft.tNodes()[j], (heights[j] - 0.1) / 1.9, 1e-16);
      for (int i = 0; i <= 50; ++i)
      {
        const double s = i / 50.0;
        // Bit for bit: the other blends are exactly 0 at the node, this one exactly 1.
        EXPECT_EQ(loft.point(s, loft.tNodes()[j]), sections[j]->point(s)) << j << " " << s;
      }
    }
    // Between sections the surface is at the interpolated height: z is linear in the
    // normalised t, reproduced by both blendings.
    for (double t : { -0.1, 0.13, 0.5, 0.77, 1.15 })
    {
      EXPECT_NEAR(loft.point(0.3, t).z(), 0.1 + 1.9 * t, 1e-13);
    }
    for (double s : { 0.2, 0.6 })
    {
      for (double t : { 0.1, 0.45, 0.9, -0.15, 1.18 })
      {
        expectDerivativesMatch(loft, s, t, 1e-7, "loft");
      }
    }
  }
}

TEST(GordonLoft, LagrangeReproducesCubicInT)
{
  // P(s, t) = (s, t + 0.5 s t^2, t^3 - 2 t s + 1): linear in s (line sections), cubic in t.
  auto exact = [](double s, double t) {
    return Vec3(s, t + 0.5 * s * t * t, t * t * t - 2 * t * s + 1);
  };
  const std::vector<double> nodes = { 0.0, 0.2, 0.7, 1.0 };
  std::vector<CurvePtr> sections;
  for (double t : nodes)
  {
    sections.push_back(std::make_shared<LineCurve>(exact(0, t), exact(1, t)));
  }
  const GordonSurface loft =
    GordonSurface::fromSections(sections, nodes, GordonSurface::Blending::Lagrange);
  double worst = 0;
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = -4; j <= 24; ++j) // includes extrapolation to t in [-0.2, 1.2]
    {
      const double s = i / 20.0, t = j / 20.0;
      worst = std::max(worst, maxError(loft.point(s, t), exact(s, t)));
      EXPECT_EQ(loft.point(s, t), loft.extendedPoint(s, t));
    }
  }
  EXPECT_LT(worst, 1e-14);
  // Natural-spline blending reproduces surfaces linear in t, also extrapolated.
  auto ruled = [](double s, double t) { return Vec3(s, t * (1 + s), 2 * t - s * s); };
  std::vector<CurvePtr> ruledSections;
  for (double t : nodes)
  {
    ruledSections.push_back(std::make_shared<FunctionCurve>([ruled, t](double s, int k) {
      return k == 0 ? ruled(s, t) : (k == 1 ? Vec3(1, t, -2 * s) : Vec3(0, 0, -2));
    }));
  }
  const GordonSurface spline =
    GordonSurface::fromSections(ruledSections, nodes, GordonSurface::Blending::Spline);
  worst = 0;
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = -4; j <= 24; ++j)
    {
      const double s = i / 20.0, t = j / 20.0;
      worst = std::max(worst, maxError(spline.point(s, t), ruled(s, t)));
    }
  }
  EXPECT_LT(worst, 1e-14);
}

TEST(GordonLoft, SplineBlendingDoesNotOscillateOnRungeData)
{
  // 11 equally spaced sections of z = 1 / (1 + 25 y^2), y = 2t - 1 in [-1, 1].
  auto runge = [](double y) { return 1.0 / (1.0 + 25.0 * y * y); };
  std::vector<CurvePtr> sections;
  std::vector<double> nodes;
  for (int j = 0; j <= 10; ++j)
  {
    const double t = j / 10.0, y = 2 * t - 1;
    nodes.push_back(t);
    sections.push_back(std::make_shared<LineCurve>(Vec3(0, y, runge(y)), Vec3(1, y, runge(y))));
  }
  double deviation[2] = { 0, 0 }, yError[2] = { 0, 0 };
  int b = 0;
  for (auto blending : { GordonSurface::Blending::Lagrange, GordonSurface::Blending::Spline })
  {
    const GordonSurface loft = GordonSurface::fromSections(sections, nodes, blending);
    for (int j = 0; j <= 4000; ++j)
    {
      const double t = j / 4000.0;
      const Vec3 p = loft.point(0.5, t);
      deviation[b] = std::max(deviation[b], std::abs(p.z() - runge(2 * t - 1)));
      yError[b] = std::max(yError[b], std::abs(p.y() - (2 * t - 1)));
    }
    ++b;
  }
  // Lagrange of degree 10 on equidistant nodes: the classical Runge error 1.9156.
  EXPECT_NEAR(deviation[0], 1.9156, 1e-3);
  // The natural cubic spline stays within about 2% (0.021974).
  EXPECT_NEAR(deviation[1], 0.02197, 2e-4);
  // Both reproduce the linear coordinate y.
  EXPECT_LT(yError[0], 1e-12);
  EXPECT_LT(yError[1], 1e-14);
  std::printf("Runge max deviation: Lagrange %.6f, spline %.6f\n", deviation[0], deviation[1]);
}

TEST(GordonLoft, SplineBlendFunctionsAreCardinalC2AndLinearBeyondTheEnds)
{
  std::vector<CurvePtr> sections;
  const std::vector<double> nodes = { 0.0, 0.15, 0.5, 0.6, 1.0 };
  for (double t : nodes)
  {
    sections.push_back(std::make_shared<LineCurve>(Vec3(0, t, 0), Vec3(1, t, 0)));
  }
  const GordonSurface loft =
    GordonSurface::fromSections(sections, nodes, GordonSurface::Blending::Spline);
  double jet[3], left[3], right[3];
  for (int j = 0; j < 5; ++j)
  {
    for (int k = 0; k < 5; ++k)
    {
      loft.blend(true, j, nodes[k], jet);
      EXPECT_EQ(jet[0], j == k ? 1.0 : 0.0);
      // Continuity of value, slope and curvature across the interior nodes.
      loft.blend(true, j, nodes[k] - 1e-11, left);
      loft.blend(true, j, nodes[k] + 1e-11, right);
      EXPECT_NEAR(left[0], right[0], 1e-9);
      EXPECT_NEAR(left[1], right[1], 1e-8);
      EXPECT_NEAR(left[2], right[2], 1e-7);
    }
    // Natural ends: zero curvature, then straight.
    loft.blend(true, j, 1.0 - 1e-9, left);
    EXPECT_NEAR(left[2], 0.0, 1e-6);
    loft.blend(true, j, 1.0, jet);
    loft.blend(true, j, 1.2, right);
    EXPECT_NEAR(right[0], jet[0] + 0.2 * jet[1], 1e-15);
    EXPECT_EQ(right[2], 0.0);
  }
  // Partition of unity everywhere, also extrapolated.
  for (double t : { -0.3, 0.07, 0.55, 0.99, 1.3 })
  {
    double sum = 0;
    for (int j = 0; j < 5; ++j)
    {
      loft.blend(true, j, t, jet);
      sum += jet[0];
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
  }
}

TEST(GordonLoft, InvalidInputThrows)
{
  const CurvePtr a = std::make_shared<LineCurve>(Vec3(0, 0, 0), Vec3(1, 0, 0));
  const CurvePtr b = std::make_shared<LineCurve>(Vec3(0, 1, 0), Vec3(1, 1, 0));
  const auto spline = GordonSurface::Blending::Spline;
  EXPECT_THROW(GordonSurface::fromSections({ a }, { 0.0 }, spline), GeometryError);
  EXPECT_THROW(GordonSurface::fromSections({ a, b }, { 0.0 }, spline), GeometryError);
  EXPECT_THROW(GordonSurface::fromSections({ a, b }, { 1.0, 1.0 }, spline), GeometryError);
  EXPECT_THROW(GordonSurface::fromSections({ a, nullptr }, { 0.0, 1.0 }, spline), GeometryError);
  EXPECT_NO_THROW(GordonSurface::fromSections({ a, b }, { 3.0, 7.0 }, spline));
}

// ---------------------------------------------------------------------------------------
// Gordon surfaces: networks (eq. 4)

TEST(GordonNetwork, LagrangeReproducesBiquadraticAndPassesThroughAllCurves)
{
  std::array<std::array<std::array<double, 4>, 4>, 3> c{};
  c[0][1][0] = 1.0;  // x = s + 0.2 t^2 + 0.1 s^2 t
  c[0][0][2] = 0.2;
  c[0][2][1] = 0.1;
  c[1][0][1] = 1.0;  // y = t + 0.3 s^2 - 0.4 s t^2
  c[1][2][0] = 0.3;
  c[1][1][2] = -0.4;
  c[2][2][2] = 0.5;  // z = 0.5 s^2 t^2 + s t - 0.2 s^2
  c[2][1][1] = 1.0;
  c[2][2][0] = -0.2;
  const AnalyticSurface f = polynomialSurface(c);
  const std::vector<double> sNodes = { 0.0, 0.4, 1.0 }, tNodes = { 0.1, 0.5, 0.9 };
  std::vector<CurvePtr> sCurves, tCurves;
  for (double t : tNodes)
  {
    sCurves.push_back(sCurveOf(f, t));
  }
  for (double s : sNodes)
  {
    tCurves.push_back(tCurveOf(f, s));
  }
  const GordonSurface gordon = GordonSurface::fromNetwork(
    sCurves, tNodes, tCurves, sNodes, GordonSurface::Blending::Lagrange);
  EXPECT_LT(worstOnGrid(gordon, f), 1e-14);
  for (int k = 0; k <= 40; ++k)
  {
    const double u = k / 40.0;
    for (std::size_t j = 0; j < tNodes.size(); ++j)
    {
      EXPECT_LT(maxError(gordon.point(u, tNodes[j]), sCurves[j]->point(u)), 1e-15);
    }
    for (std::size_t i = 0; i < sNodes.size(); ++i)
    {
      EXPECT_EQ(gordon.point(sNodes[i], u), tCurves[i]->point(u)); // bit for bit
    }
  }
  for (double s : { 0.15, 0.5, 0.85 })
  {
    for (double t : { 0.05, 0.5, 0.95 })
    {
      expectDerivativesMatch(gordon, s, t, 1e-8, "Lagrange network");
      SurfaceDerivatives d;
      gordon.derivatives(s, t, d);
      EXPECT_LT(maxError(d.Ps, f(s, t, 1, 0)), 1e-13);
      EXPECT_LT(maxError(d.Pt, f(s, t, 0, 1)), 1e-13);
      EXPECT_LT(maxError(d.Pss, f(s, t, 2, 0)), 1e-13);
      EXPECT_LT(maxError(d.Pst, f(s, t, 1, 1)), 1e-13);
      EXPECT_LT(maxError(d.Ptt, f(s, t, 0, 2)), 1e-13);
    }
  }
}

TEST(GordonNetwork, SplineReproducesTransfiniteSurface)
{
  // f = A(s) + B(t) + M s t: the boolean sum of any two blendings that reproduce linear
  // functions is exact for it, whatever A and B (here not polynomial).
  const AnalyticSurface f = [](double s, double t, int ds, int dt) -> Vec3 {
    auto dsin = [](double w, double x, int k) {
      const double p = std::pow(w, k);
      switch (k % 4)
      {
        case 0: return p * std::sin(w * x);
        case 1: return p * std::cos(w * x);
        case 2: return -p * std::sin(w * x);
        default: return -p * std::cos(w * x);
      }
    };
    auto dcos = [&](double w, double x, int k) { return dsin(w, x + Pi / (2 * w), k); };
    auto mono = [](double x, int a, int k) { // d^k x^a, a <= 3
      double factor = 1;
      for (int i = 0; i < k; ++i)
      {
        factor *= (a - i);
      }
      return k > a ? 0.0 : factor * std::pow(x, a - k);
    };
    Vec3 r = Vec3::Zero();
    if (dt == 0)
    {
      r += Vec3(mono(s, 1, ds), 0.2 * dcos(2, s, ds), dsin(2, s, ds));
    }
    if (ds == 0)
    {
      r += Vec3(0.3 * dsin(3, t, dt), mono(t, 1, dt), mono(t, 3, dt));
    }
    r.z() += 0.5 * mono(s, 1, ds) * mono(t, 1, dt);
    return r;
  };
  const std::vector<double> sNodes = { 0.0, 0.3, 0.55, 1.0 }, tNodes = { 0.0, 0.25, 0.6, 0.8, 1.0 };
  std::vector<CurvePtr> sCurves, tCurves;
  for (double t : tNodes)
  {
    sCurves.push_back(sCurveOf(f, t));
  }
  for (double s : sNodes)
  {
    tCurves.push_back(tCurveOf(f, s));
  }
  for (auto blending : { GordonSurface::Blending::Spline, GordonSurface::Blending::Lagrange })
  {
    const GordonSurface gordon =
      GordonSurface::fromNetwork(sCurves, tNodes, tCurves, sNodes, blending);
    EXPECT_LT(worstOnGrid(gordon, f), 1e-14);
    for (double s : { 0.1, 0.5, 0.9 })
    {
      for (double t : { 0.1, 0.42, 0.9 })
      {
        expectDerivativesMatch(gordon, s, t, 1e-8, "spline network");
      }
    }
  }
}

TEST(GordonNetwork, BilinearExtendsExactlyAndMismatchThrows)
{
  // Bilinear surface from straight curves: exact also beyond [0, 1] in s and t.
  const Vec3 p00(0, 0, 0), p10(2, 0.3, 0.1), p01(0.2, 1, 0.5), p11(1.8, 1.4, -0.3);
  auto bilinear = [&](double s, double t) {
    return (1 - s) * (1 - t) * p00 + s * (1 - t) * p10 + (1 - s) * t * p01 + s * t * p11;
  };
  const std::vector<double> nodes = { 0.0, 0.5, 1.0 };
  std::vector<CurvePtr> sCurves, tCurves;
  for (double u : nodes)
  {
    sCurves.push_back(std::make_shared<LineCurve>(bilinear(0, u), bilinear(1, u)));
    tCurves.push_back(std::make_shared<LineCurve>(bilinear(u, 0), bilinear(u, 1)));
  }
  for (auto blending : { GordonSurface::Blending::Spline, GordonSurface::Blending::Lagrange })
  {
    const GordonSurface gordon =
      GordonSurface::fromNetwork(sCurves, nodes, tCurves, nodes, blending);
    double worst = 0;
    for (int i = -4; i <= 24; ++i)
    {
      for (int j = -4; j <= 24; ++j)
      {
        const double s = i / 20.0, t = j / 20.0;
        worst = std::max(worst, maxError(gordon.point(s, t), bilinear(s, t)));
      }
    }
    EXPECT_LT(worst, 1e-14);
    expectDerivativesMatch(gordon, -0.1, 1.15, 1e-8, "extended network");
  }
  std::vector<CurvePtr> bad = tCurves;
  bad[1] = std::make_shared<LineCurve>(bilinear(0.5, 0) + Vec3(0, 0, 1e-6), bilinear(0.5, 1));
  try
  {
    GordonSurface::fromNetwork(sCurves, nodes, bad, nodes, GordonSurface::Blending::Spline);
    FAIL() << "mismatched network accepted";
  }
  catch (const GeometryError& e)
  {
    EXPECT_NE(std::string(e.what()).find("do not meet"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mismatch 1e-06"), std::string::npos) << e.what();
  }
  EXPECT_THROW(GordonSurface::fromNetwork(sCurves, { 0.0, 0.5, 1.5 }, tCurves, nodes,
                 GordonSurface::Blending::Spline),
    GeometryError);
}

// ---------------------------------------------------------------------------------------
// Curves in (s, t) space

TEST(SurfaceCurve, LiesOnTheSurfaceWithChainRuleDerivatives)
{
  const auto loft = twistedBladeLoft(GordonSurface::Blending::Spline);
  // Curved sections too: a lofted surface of B-spline arcs.
  std::vector<CurvePtr> sections;
  for (double z : { 0.0, 0.4, 1.0 })
  {
    std::vector<Vec3> points;
    for (int i = 0; i <= 10; ++i)
    {
      const double u = i / 10.0;
      points.emplace_back(std::cos(2 * u + z), std::sin(2 * u + z) * (1 + 0.2 * z), z);
    }
    sections.push_back(std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points)));
  }
  const auto curved = std::make_shared<GordonSurface>(GordonSurface::fromSections(
    sections, { 0.0, 0.4, 1.0 }, GordonSurface::Blending::Lagrange));
  const std::vector<Eigen::Vector2d> st = { { 0.05, 0.1 }, { 0.3, 0.35 }, { 0.5, 0.3 },
    { 0.7, 0.6 }, { 0.95, 0.9 } };
  for (const SurfacePtr& surface : { SurfacePtr(loft), SurfacePtr(curved) })
  {
    const SurfaceCurve curve(surface, st);
    const SurfaceProjector projector(surface);
    ASSERT_EQ(curve.nodeParameters().size(), st.size());
    for (std::size_t k = 0; k < st.size(); ++k)
    {
      EXPECT_LT((curve.parameters(curve.nodeParameters()[k]) - st[k]).norm(), 1e-15);
    }
    double worst = 0;
    for (int i = 0; i <= 100; ++i)
    {
      const Vec3 p = curve.point(i / 100.0);
      worst = std::max(worst, projector.project(p).distance);
    }
    EXPECT_LT(worst, 1e-9);
    const double h = 1e-5;
    for (double u : { 0.1, 0.45, 0.8 })
    {
      EXPECT_LT(maxError(curve.derivative(u, 1),
                  (curve.point(u + h) - curve.point(u - h)) / (2 * h)),
        1e-8);
      EXPECT_LT(maxError(curve.derivative(u, 2),
                  (curve.derivative(u + h, 1) - curve.derivative(u - h, 1)) / (2 * h)),
        1e-6);
    }
  }
  // Two points: a straight line in parameter space.
  const SurfaceCurve line(loft, { { 0.1, 0.2 }, { 0.9, 0.6 } });
  EXPECT_LT((line.parameters(0.25) - Eigen::Vector2d(0.3, 0.3)).norm(), 1e-15);
  EXPECT_THROW(SurfaceCurve(loft, { { 0.1, 0.2 } }), GeometryError);
  EXPECT_THROW(SurfaceCurve(nullptr, st), GeometryError);
  EXPECT_THROW(SurfaceCurve(loft, { { 0.1, 0.2 }, { 0.1, 0.2 } }), GeometryError);
}

// ---------------------------------------------------------------------------------------
// Blade with hub and shroud

TEST(IntersectWithRevolution, TwistedBladeWithCylindersAndCone)
{
  for (auto blending : { GordonSurface::Blending::Spline, GordonSurface::Blending::Lagrange })
  {
    const auto blade = twistedBladeLoft(blending);
    struct Case
    {
      std::shared_ptr<SurfaceOfRevolution> revolution;
      std::function<double(double)> radiusAtZ; // expected radius of the surface at z
      const char* name;
      int extrapolation; // -1 below the first section, 0 inside, +1 beyond the last
    };
    const Case cases[] = {
      { coneAboutZ(0.75, -1, 0.75, 1), [](double) { return 0.75; }, "cylinder r=0.75", 0 },
      { coneAboutZ(0.42, -1, 0.42, 1), [](double) { return 0.42; }, "hub cylinder r=0.42", -1 },
      { coneAboutZ(1.1, -1, 1.1, 1), [](double) { return 1.1; }, "shroud cylinder r=1.1", 1 },
      { coneAboutZ(0.55, -1, 0.75, 1), [](double z) { return 0.65 + 0.1 * z; }, "cone", 0 },
    };
    for (const Case& c : cases)
    {
      const auto curve = intersectWithRevolution(blade, *c.revolution);
      double worstRadius = 0, worstOnBlade = 0, tLow = 1e9, tHigh = -1e9;
      for (int i = 0; i <= 2000; ++i)
      {
        const double u = i / 2000.0;
        const Vec3 p = curve->point(u);
        const Eigen::Vector2d st = curve->parameters(u);
        const double expected = c.radiusAtZ(p.z());
        worstRadius = std::max(worstRadius, std::abs(radiusAboutZ(p) / expected - 1));
        // The blade is ruled, so its extension is the analytic hyperbolic paraboloid.
        worstOnBlade = std::max(worstOnBlade, maxError(p, twistedBlade(st.x(), st.y())));
        tLow = std::min(tLow, st.y());
        tHigh = std::max(tHigh, st.y());
      }
      EXPECT_LT(worstRadius, 1e-9) << c.name;
      EXPECT_LT(worstOnBlade, 1e-14) << c.name;
      EXPECT_NEAR(curve->parameters(0).x(), 0.0, 1e-15);
      EXPECT_NEAR(curve->parameters(1).x(), 1.0, 1e-15);
      if (c.extrapolation < 0)
      {
        EXPECT_LT(tHigh, 0.0) << c.name;
      }
      else if (c.extrapolation > 0)
      {
        EXPECT_GT(tLow, 1.0) << c.name;
      }
      else
      {
        EXPECT_GT(tLow, 0.0) << c.name;
        EXPECT_LT(tHigh, 1.0) << c.name;
      }
      std::printf("%s: %zu nodes, t in [%.4f, %.4f], radius error %.2e\n", c.name,
        curve->parameterPoints().size(), tLow, tHigh, worstRadius);
    }
  }
}

TEST(IntersectWithRevolution, ClosedTwistedSectionsShortOfTheHub)
{
  // Elliptic closed profiles (starting and ending at the trailing edge), stacked radially
  // along x from 0.5 to 1.1 with twist and lean; hub r = 0.45 (below the first section:
  // extrapolation) and a conical shroud crossing the last sections.
  std::vector<CurvePtr> sections;
  std::vector<double> spans;
  for (int j = 0; j < 4; ++j)
  {
    const double x = 0.5 + 0.2 * j, twist = 0.3 * j, lean = 0.03 * j * j;
    std::vector<Vec3> points;
    for (int i = 0; i <= 32; ++i)
    {
      const double phi = 2 * Pi * i / 32.0;
      const double chordwise = 0.2 * std::cos(phi), thickness = 0.04 * std::sin(phi);
      points.emplace_back(x, lean + chordwise * std::sin(twist) + thickness * std::cos(twist),
        chordwise * std::cos(twist) - thickness * std::sin(twist));
    }
    points.back() = points.front(); // closed exactly
    sections.push_back(std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points)));
    spans.push_back(x);
  }
  const auto blade = std::make_shared<GordonSurface>(
    GordonSurface::fromSections(sections, spans, GordonSurface::Blending::Spline));
  const SurfaceProjector projector(blade, 64, 32);

  struct Case
  {
    std::shared_ptr<SurfaceOfRevolution> revolution;
    double r0, z0, r1, z1;
    bool inside; // within the sections: check against the projection onto the blade
  };
  const Case cases[] = {
    { coneAboutZ(0.45, -1, 0.45, 1), 0.45, -1, 0.45, 1, false },
    { coneAboutZ(0.62, -1, 0.62, 1), 0.62, -1, 0.62, 1, true },
    { coneAboutZ(0.9, -1, 1.15, 1), 0.9, -1, 1.15, 1, true },
  };
  for (const Case& c : cases)
  {
    const auto curve = intersectWithRevolution(blade, *c.revolution);
    EXPECT_EQ(curve->point(0.0), curve->point(1.0)) << "closes at the trailing edge";
    double worstRadius = 0, worstOnBlade = 0, tLow = 1e9;
    for (int i = 0; i <= 3000; ++i)
    {
      const Vec3 p = curve->point(i / 3000.0);
      const double expected = c.r0 + (p.z() - c.z0) / (c.z1 - c.z0) * (c.r1 - c.r0);
      worstRadius = std::max(worstRadius, std::abs(radiusAboutZ(p) / expected - 1));
      tLow = std::min(tLow, curve->parameters(i / 3000.0).y());
      if (c.inside && i % 30 == 0)
      {
        worstOnBlade = std::max(worstOnBlade, projector.project(p).distance);
      }
    }
    EXPECT_LT(worstRadius, 1e-9);
    if (c.inside)
    {
      EXPECT_LT(worstOnBlade, 1e-9);
    }
    else
    {
      EXPECT_LT(tLow, -0.05); // the blade was extended below its first section
    }
    std::printf("closed blade, r0 = %.2f: %zu nodes, radius error %.2e, t min %.4f\n", c.r0,
      curve->parameterPoints().size(), worstRadius, tLow);
  }
}

TEST(IntersectWithRevolution, NoIntersectionThrowsNamingS)
{
  const auto blade = twistedBladeLoft(GordonSurface::Blending::Spline);
  const auto farAway = coneAboutZ(5.0, -1, 5.0, 1);
  try
  {
    intersectWithRevolution(blade, *farAway);
    FAIL() << "no intersection expected";
  }
  catch (const GeometryError& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("s = 0 "), std::string::npos) << message;
    EXPECT_NE(message.find("[-0.5, 1.5]"), std::string::npos) << message;
  }
  // The extension range matters: r = 0.38 needs t down to -0.37.
  const auto hub = coneAboutZ(0.38, -1, 0.38, 1);
  EXPECT_THROW(intersectWithRevolution(blade, *hub, -0.2, 1.2), GeometryError);
  EXPECT_NO_THROW(intersectWithRevolution(blade, *hub, -0.8, 1.2));
  EXPECT_THROW(intersectWithRevolution(blade, *hub, 1.0, 0.0), GeometryError);
  EXPECT_THROW(intersectWithRevolution(nullptr, *hub), GeometryError);
}

// ---------------------------------------------------------------------------------------
TEST(Carriers, EvaluationDoesNotAllocate)
{
  const auto blade = twistedBladeLoft(GordonSurface::Blending::Spline);
  const auto lagrange = twistedBladeLoft(GordonSurface::Blending::Lagrange);
  const auto cone = coneAboutZ(0.55, -1, 0.75, 1);
  const auto hub = intersectWithRevolution(blade, *cone);
  std::vector<CurvePtr> sCurves, tCurves;
  const std::vector<double> nodes = { 0.0, 0.5, 1.0 };
  for (double u : nodes)
  {
    sCurves.push_back(std::make_shared<LineCurve>(twistedBlade(0, u), twistedBlade(1, u)));
    tCurves.push_back(std::make_shared<LineCurve>(twistedBlade(u, 0), twistedBlade(u, 1)));
  }
  const GordonSurface network =
    GordonSurface::fromNetwork(sCurves, nodes, tCurves, nodes, GordonSurface::Blending::Spline);
  SurfaceDerivatives d;
  double sink = cone->signedMeridionalDistance(Vec3(1, 1, 0)); // warms up the scratch
  {
    const long start = AllocationCount.load();
    const auto probe = std::make_shared<int>(1); // the counter does see allocations
    EXPECT_GT(AllocationCount.load() - start, 0);
    sink += *probe;
  }
  const long before = AllocationCount.load();
  for (int i = 0; i < 200; ++i)
  {
    const double s = i / 199.0, t = 1.4 * s - 0.2;
    sink += blade->point(s, t).x() + lagrange->point(s, t).y() + network.point(s, t).z();
    blade->derivatives(s, t, d);
    sink += d.Ptt.x();
    network.derivatives(s, t, d);
    sink += d.Pst.y();
    cone->derivatives(s, t, d);
    sink += cone->point(s, t).z() + d.Pt.x();
    sink += cone->signedMeridionalDistance(blade->point(s, t));
    sink += hub->point(s).x() + hub->derivative(s, 2).y();
    sink += rotateAboutAxis(Vec3(s, t, 1), Vec3::Zero(), Vec3::UnitZ(), t).x();
  }
  EXPECT_EQ(AllocationCount.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

// ---------------------------------------------------------------------------------------
// Offsets of curves within a surface

namespace
{
/// Full ellipse (a cos phi, b sin phi, 0) about the origin, phi = 2 pi direction u
/// (direction -1: clockwise). u is wrapped into [0, 1) first, so P(1) == P(0) bit for bit.
class EllipseCurve : public Curve
{
public:
  EllipseCurve(double a, double b, double direction = 1.0, double phase = 0.0)
    : A(a)
    , B(b)
    , Omega(2 * Pi * direction)
    , Phase(phase)
  {
  }
  Vec3 point(double u) const override
  {
    const double phi = angle(u);
    return Vec3(A * std::cos(phi), B * std::sin(phi), 0.0);
  }
  Vec3 derivative(double u, int order = 1) const override
  {
    const double phi = angle(u);
    switch (order)
    {
      case 1:
        return Omega * Vec3(-A * std::sin(phi), B * std::cos(phi), 0.0);
      case 2:
        return Omega * Omega * Vec3(-A * std::cos(phi), -B * std::sin(phi), 0.0);
      default:
        return Vec3::Zero();
    }
  }
  double angle(double u) const { return Omega * (u - std::floor(u)) + Phase; }

private:
  double A, B, Omega, Phase;
};

/// The square [-2, 2]^2 of the plane z = 0 as a Coons patch: P(s, t) = (4s - 2, 4t - 2, 0).
std::shared_ptr<const CoonsPatch> squarePlane()
{
  const Vec3 c00(-2, -2, 0), c10(2, -2, 0), c01(-2, 2, 0), c11(2, 2, 0);
  return std::make_shared<CoonsPatch>(std::make_shared<LineCurve>(c00, c10),
    std::make_shared<LineCurve>(c10, c11), std::make_shared<LineCurve>(c01, c11),
    std::make_shared<LineCurve>(c00, c01));
}

Eigen::Vector2d squarePlaneParameters(const Vec3& p)
{
  return Eigen::Vector2d((p.x() + 2) / 4, (p.y() + 2) / 4);
}

/// Distance of q (in z = 0) from the ellipse (a cos phi, b sin phi): dense sampling, then
/// Newton on (E(phi) - q) . E'(phi) = 0.
double distanceToEllipse(const Vec3& q, double a, double b)
{
  auto e = [&](double phi) { return Vec3(a * std::cos(phi), b * std::sin(phi), 0.0); };
  const int n = 4096;
  double phi = 0, best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i)
  {
    const double trial = 2 * Pi * i / n;
    const double d = (e(trial) - q).norm();
    if (d < best)
    {
      best = d;
      phi = trial;
    }
  }
  for (int iteration = 0; iteration < 50; ++iteration)
  {
    const Vec3 d1(-a * std::sin(phi), b * std::cos(phi), 0.0);
    const Vec3 d2(-a * std::cos(phi), -b * std::sin(phi), 0.0);
    const Vec3 r = e(phi) - q;
    const double step = r.dot(d1) / (d1.dot(d1) + r.dot(d2));
    phi -= step;
    if (std::abs(step) < 1e-15)
    {
      break;
    }
  }
  return std::min(best, (e(phi) - q).norm());
}

/// Largest angle (degrees) between consecutive chords of a polyline of (s, t) points.
double largestChordTurn(const std::vector<Eigen::Vector2d>& st)
{
  double worst = 0;
  for (std::size_t k = 2; k < st.size(); ++k)
  {
    const Eigen::Vector2d a = st[k - 1] - st[k - 2], b = st[k] - st[k - 1];
    const double c = std::clamp(a.dot(b) / (a.norm() * b.norm()), -1.0, 1.0);
    worst = std::max(worst, std::acos(c) * 180 / Pi);
  }
  return worst;
}

/// Signed area of a closed polyline of (s, t) points (> 0: counterclockwise).
double signedArea(const std::vector<Eigen::Vector2d>& st)
{
  double area = 0;
  for (std::size_t k = 1; k < st.size(); ++k)
  {
    area += st[k - 1].x() * st[k].y() - st[k].x() * st[k - 1].y();
  }
  return 0.5 * area;
}
} // namespace

TEST(OffsetOnSurface, CircleOnPlaneOutwardWhateverOrientationAndInward)
{
  const auto plane = squarePlane();
  for (double direction : { 1.0, -1.0 })
  {
    const EllipseCurve circle(1.0, 1.0, direction);
    ASSERT_EQ(circle.point(0.0), circle.point(1.0));
    for (double distance : { 0.2, -0.2 })
    {
      const double expected = 1.0 + distance; // > 0 outwards for closed curves
      const auto st =
        offsetOnSurface(circle, true, *plane, squarePlaneParameters, distance);
      // The normal turns by 360/512 degrees per step: no refinement, one point per step.
      ASSERT_EQ(st.size(), 513u) << direction << ", " << distance;
      EXPECT_EQ(st.front(), st.back()) << "the loop closes exactly";
      double worstRadius = 0, worstPoint = 0;
      for (std::size_t k = 0; k < st.size(); ++k)
      {
        const Vec3 p = plane->point(st[k].x(), st[k].y());
        worstRadius = std::max(worstRadius, std::abs(radiusAboutZ(p) - expected));
        // In the order of u: the k-th sample of the circle pushed along its radius.
        const double phi = circle.angle(k / 512.0);
        const Vec3 exact(expected * std::cos(phi), expected * std::sin(phi), 0.0);
        worstPoint = std::max(worstPoint, maxError(p, exact));
      }
      EXPECT_LT(worstRadius, 1e-9 * expected) << direction << ", " << distance;
      EXPECT_LT(worstPoint, 1e-9) << direction << ", " << distance;
      // Same orientation as the curve (the plane maps (x, y) to (s, t) preserving it).
      EXPECT_GT(signedArea(st) * direction, 0.0);
      std::printf("circle direction %+.0f, distance %+.1f: %zu points, radius error %.2e, "
                  "point error %.2e\n",
        direction, distance, st.size(), worstRadius, worstPoint);
    }
  }
}

TEST(OffsetOnSurface, SurfaceCurveThroughCircleOffsetKeepsTheRadius)
{
  const auto plane = squarePlane();
  const EllipseCurve circle(1.0, 1.0);
  const SurfaceCurve curve(
    plane, offsetOnSurface(circle, true, *plane, squarePlaneParameters, 0.2));
  for (double u : { 0.1, 0.37, 0.8 })
  {
    EXPECT_NEAR(radiusAboutZ(curve.point(u)), 1.2, 1e-6) << u;
    EXPECT_EQ(curve.point(u).z(), 0.0);
  }
  double worst = 0;
  for (int i = 0; i <= 4000; ++i)
  {
    worst = std::max(worst, std::abs(radiusAboutZ(curve.point(i / 4000.0)) - 1.2));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(curve.point(0.0), curve.point(1.0));
  std::printf("surface curve through the offset circle: radius error %.2e\n", worst);
}

TEST(OffsetOnSurface, CircularArcOnCylinderMovesAxially)
{
  const double radius = 0.5, z0 = 0.3;
  const SurfaceOfRevolution cylinder(
    std::make_shared<LineCurve>(Vec3(radius, 0, -1), Vec3(radius, 0, 1)), Vec3::Zero(),
    Vec3::UnitZ(), -Pi, Pi);
  const SurfaceParameterFunction toParameters = [&cylinder](const Vec3& p) {
    return Eigen::Vector2d(
      cylinder.contourParameter(p), (std::atan2(p.y(), p.x()) + Pi) / (2 * Pi));
  };
  for (double sense : { 1.0, -1.0 })
  {
    // The arc theta = sense * (2u - 1) at z = 0.3 (open).
    const FunctionCurve arc([=](double u, int order) {
      const double theta = sense * (2 * u - 1), w = 2 * sense;
      switch (order)
      {
        case 0:
          return Vec3(radius * std::cos(theta), radius * std::sin(theta), z0);
        case 1:
          return Vec3(-w * radius * std::sin(theta), w * radius * std::cos(theta), 0.0);
        default:
          return Vec3(-w * w * radius * std::cos(theta), -w * w * radius * std::sin(theta), 0.0);
      }
    });
    // n = N x T with N = Ps x Pt, at the middle of the arc: axial, its sign is the side.
    const Vec3 middle = arc.point(0.5);
    const Eigen::Vector2d stMiddle = toParameters(middle);
    EXPECT_LT(maxError(cylinder.point(stMiddle.x(), stMiddle.y()), middle), 1e-12);
    SurfaceDerivatives d;
    cylinder.derivatives(stMiddle.x(), stMiddle.y(), d);
    const Vec3 n = d.Ps.cross(d.Pt).cross(arc.derivative(0.5)).normalized();
    EXPECT_LT(maxError(n, Vec3(0, 0, n.z() > 0 ? 1 : -1)), 1e-14);
    for (double distance : { 0.2, -0.2, 0.05 })
    {
      const double expectedZ = z0 + distance * n.z();
      const auto st = offsetOnSurface(arc, false, cylinder, toParameters, distance);
      ASSERT_EQ(st.size(), 513u); // 2 rad in 512 steps: no refinement
      double worstZ = 0, worstRadius = 0, worstAngle = 0;
      for (std::size_t k = 0; k < st.size(); ++k)
      {
        const Vec3 p = cylinder.point(st[k].x(), st[k].y());
        worstZ = std::max(worstZ, std::abs(p.z() - expectedZ));
        worstRadius = std::max(worstRadius, std::abs(radiusAboutZ(p) - radius));
        // Straight up or down: the angle of the k-th sample of the arc.
        const double theta = sense * (2 * (k / 512.0) - 1);
        worstAngle = std::max(worstAngle, std::abs(std::atan2(p.y(), p.x()) - theta));
      }
      EXPECT_LT(worstZ, 1e-9) << sense << ", " << distance;
      EXPECT_LT(worstRadius, 1e-9 * radius) << sense << ", " << distance;
      EXPECT_LT(worstAngle, 1e-9) << sense << ", " << distance;
      std::printf("cylinder arc sense %+.0f, distance %+.2f (n.z %+.0f): z error %.2e, radius "
                  "error %.2e, angle error %.2e\n",
        sense, distance, n.z(), worstZ, worstRadius, worstAngle);
    }
  }
}

TEST(OffsetOnSurface, EllipseOffsetIsAtTheDistanceAndRefinedAtTheEnds)
{
  const auto plane = squarePlane();
  struct Case
  {
    double b, distance;
  };
  // b = 0.3: the normal turns by at most (a/b) 360/512 = 2.3 degrees per step (no
  // refinement needed); b = 0.1: 7 degrees at the ends, where steps are halved.
  for (const Case c : { Case{ 0.3, 0.05 }, Case{ 0.3, -0.05 }, Case{ 0.1, 0.05 } })
  {
    const EllipseCurve ellipse(1.0, c.b);
    const auto st = offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, c.distance);
    EXPECT_EQ(st.front(), st.back());
    double worst = 0;
    bool allOutside = true, allInside = true;
    for (const Eigen::Vector2d& x : st)
    {
      const Vec3 p = plane->point(x.x(), x.y());
      worst = std::max(worst, std::abs(distanceToEllipse(p, 1.0, c.b) - std::abs(c.distance)));
      const double level = std::pow(p.x(), 2) + std::pow(p.y() / c.b, 2);
      allOutside = allOutside && level > 1;
      allInside = allInside && level < 1;
    }
    EXPECT_LT(worst, 1e-9) << c.b << ", " << c.distance;
    EXPECT_TRUE(c.distance > 0 ? allOutside : allInside) << c.b << ", " << c.distance;
    // Consecutive offset chords turn as the normal does: within about 3 degrees.
    const double turn = largestChordTurn(st);
    EXPECT_LT(turn, 3.0) << c.b << ", " << c.distance;
    if (c.b < 0.2)
    {
      EXPECT_GT(st.size(), 513u) << "refined at the sharp ends";
    }
    else
    {
      EXPECT_EQ(st.size(), 513u);
    }
    std::printf("ellipse b = %.1f, distance %+.2f: %zu points, distance error %.2e, largest "
                "chord turn %.2f deg\n",
      c.b, c.distance, st.size(), worst, turn);
  }
}

TEST(OffsetOnSurface, InvalidDistanceAndFoldingBackThrow)
{
  const auto plane = squarePlane();
  const EllipseCurve ellipse(1.0, 0.3);
  for (double distance : { 0.0, -0.0, std::numeric_limits<double>::quiet_NaN(),
         std::numeric_limits<double>::infinity() })
  {
    EXPECT_THROW(offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, distance),
      GeometryError)
      << distance;
  }
  // Inwards by 0.35, more than the half-width 0.3: nothing is left of the inside, the
  // offset folds back everywhere near the ends and crosses itself nowhere near.
  try
  {
    offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, -0.35);
    FAIL() << "folding back expected";
  }
  catch (const GeometryError& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("folds back"), std::string::npos) << message;
    EXPECT_NE(message.find("u = "), std::string::npos) << message;
  }
  EXPECT_NO_THROW(offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, 0.2));
}

TEST(OffsetOnSurface, SwallowtailsAreCutAtTheCrossing)
{
  // The smallest radius of curvature is b^2 / a = 0.09 (at phi = 0 and pi): inwards by 0.2
  // the raw offset folds back in two swallowtails. What is left is the boundary of the
  // points 0.2 inside: every point at least 0.2 from the ellipse, those on the normals at
  // exactly 0.2, the two cut points (on the major axis) farther, and no step backwards.
  // (The seam at phi = pi/2, away from the swallowtails: one across the seam of a closed
  // curve is an error.)
  const auto plane = squarePlane();
  const EllipseCurve ellipse(1.0, 0.3, 1.0, Pi / 2);
  const auto st = offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, -0.2);
  int exact = 0, farther = 0;
  for (const auto& p : st)
  {
    const Vec3 q(4 * p[0] - 2, 4 * p[1] - 2, 0);
    const double d = distanceToEllipse(q, 1.0, 0.3);
    EXPECT_GT(d, 0.2 - 1e-9);
    (d < 0.2 + 1e-9 ? exact : farther) += 1;
    EXPECT_LT(q.x() * q.x() / 1.0 + q.y() * q.y() / 0.09, 1.0); // inside
  }
  EXPECT_GE(farther, 2);
  EXPECT_LE(farther, 4);
  EXPECT_GT(exact, 100);
  // The loop runs one way: chords turn by less than 90 degrees except at the two cuts,
  // where the two sides meet at a corner.
  int corners = 0;
  for (std::size_t k = 2; k < st.size(); ++k)
  {
    const Eigen::Vector2d a = st[k - 1] - st[k - 2], b = st[k] - st[k - 1];
    corners += a.dot(b) < 0.0;
  }
  EXPECT_EQ(corners, 2);

  // A lens with sharp tips (two circular arcs meeting at 60 degrees), offset outwards by
  // more than it is thick: the tips are fans, nothing folds, every point is at the
  // distance from the lens.
  class Lens : public Curve
  {
  public:
    Vec3 point(double u) const override
    {
      const double a = 2 * Pi * (u - std::floor(u)) * 2; // two arcs
      const double w = std::fmod(a, 2 * Pi) / (2 * Pi);   // 0..1 along one arc
      const double phi = Pi / 3 * (w - 0.5) * 2;          // -60 .. 60 degrees of arc
      const double sign = a < 2 * Pi ? 1.0 : -1.0;
      // arc of radius 1 centred at (0, -sign * 0.5), from x = -sin 60 to +sin 60
      return Vec3(sign * std::sin(phi), sign * (std::cos(phi) - 0.5), 0.0);
    }
    Vec3 derivative(double u, int order = 1) const override
    {
      const double h = 1e-7;
      if (order != 1)
        return Vec3::Zero();
      return (point(std::min(1.0, u + h)) - point(std::max(0.0, u - h))) /
        (std::min(1.0, u + h) - std::max(0.0, u - h));
    }
  };
  const Lens lens;
  const auto fan = offsetOnSurface(lens, true, *plane, squarePlaneParameters, 0.3);
  for (const auto& p : fan)
  {
    const Vec3 q(4 * p[0] - 2, 4 * p[1] - 2, 0);
    double nearest = 1e300;
    for (int k = 0; k <= 20000; ++k)
    {
      nearest = std::min(nearest, (q - lens.point(k / 20000.0)).norm());
    }
    EXPECT_NEAR(nearest, 0.3, 2e-3);
  }
}

TEST(OffsetOnSurface, Deterministic)
{
  const auto plane = squarePlane();
  const EllipseCurve ellipse(1.0, 0.1, -1.0);
  const auto first = offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, 0.05);
  const auto second = offsetOnSurface(ellipse, true, *plane, squarePlaneParameters, 0.05);
  ASSERT_EQ(first.size(), second.size());
  EXPECT_TRUE(first == second);
  EXPECT_GT(first.size(), 513u);
}

TEST(OffsetOnSurface, OpenCurveCalledClosedIsAnError)
{
  // Three quarters of a circle: its ends are sqrt(2) apart, so "closed" is wrong.
  class ThreeQuarters : public Curve
  {
  public:
    Vec3 point(double u) const override
    {
      return Vec3(std::cos(1.5 * Pi * u), std::sin(1.5 * Pi * u), 0.0);
    }
    Vec3 derivative(double u, int = 1) const override
    {
      return 1.5 * Pi * Vec3(-std::sin(1.5 * Pi * u), std::cos(1.5 * Pi * u), 0.0);
    }
  } arc;
  const auto plane = squarePlane();
  try
  {
    offsetOnSurface(arc, true, *plane, squarePlaneParameters, 0.1);
    FAIL() << "an open curve passed as closed must be refused";
  }
  catch (const GeometryError& e)
  {
    EXPECT_NE(std::string(e.what()).find("ends do not meet"), std::string::npos) << e.what();
  }
  const auto open = offsetOnSurface(arc, false, *plane, squarePlaneParameters, 0.1);
  for (const Eigen::Vector2d& st : open)
  {
    const double r = std::hypot(4 * st[0] - 2, 4 * st[1] - 2);
    EXPECT_TRUE(std::abs(r - 1.1) < 1e-12 || std::abs(r - 0.9) < 1e-12) << r;
  }
}

TEST(GordonSurface, CrossPointsArePointsBitForBit)
{
  // crossPoints() (a closest-point search's five points: the loft's shortcut and the
  // general sums) gives point()'s bits: B-spline and straight sections, both blendings,
  // inside, at section heights (blends exactly 0 and 1), at and beyond the ends.
  std::vector<CurvePtr> sections;
  const std::vector<double> heights = { 0.0, 0.25, 0.6, 1.0 };
  for (std::size_t j = 0; j < heights.size(); ++j)
  {
    std::vector<Vec3> points;
    for (int i = 0; i <= 12; ++i)
    {
      const double u = i / 12.0;
      points.emplace_back(u - 0.5, 0.15 * std::sin(Pi * u) + 0.05 * static_cast<double>(j), heights[j]);
    }
    sections.push_back(std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points)));
  }
  std::vector<std::shared_ptr<const GordonSurface>> surfaces;
  for (auto blending : { GordonSurface::Blending::Lagrange, GordonSurface::Blending::Spline })
  {
    surfaces.push_back(std::make_shared<GordonSurface>(GordonSurface::fromSections(sections, heights, blending)));
    surfaces.push_back(twistedBladeLoft(blending));
  }
  for (const auto& surface : surfaces)
  {
    for (const double s : { 0.0, 1e-7, 0.31, 0.5, 0.9999995, 1.0, -0.01 })
    {
      for (const double t : { 0.0, 0.25, 0.3, 0.41, 1.0, 1.02 })
      {
        const double h = 1e-6;
        Vec3 out[5];
        surface->crossPoints(s, s + h, s - h, t, t + h, t - h, out);
        const Vec3 expected[5] = { surface->point(s, t), surface->point(s + h, t),
          surface->point(s - h, t), surface->point(s, t + h), surface->point(s, t - h) };
        for (int k = 0; k < 5; ++k)
        {
          EXPECT_TRUE(out[k].x() == expected[k].x() && out[k].y() == expected[k].y() &&
            out[k].z() == expected[k].z())
            << "s " << s << " t " << t << " point " << k;
        }
      }
    }
  }
}
