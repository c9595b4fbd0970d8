// Closest-point projection onto curves and surfaces and arc-length parametrisation,
// checked against analytic foot points and lengths.
#include "BSpline.h"
#include "ArcLength.h"
#include "Projection.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

using namespace blockforge;

namespace
{
constexpr double Pi = 3.14159265358979323846;

double maxError(const Vec3& a, const Vec3& b)
{
  return (a - b).cwiseAbs().maxCoeff();
}

double clamp(double x, double lo, double hi)
{
  return std::min(std::max(x, lo), hi);
}

/// Parabola (x, x^2, 0), x = 2u - 1, interpolated exactly by a uniform cubic B-spline.
std::shared_ptr<BSplineCurve> parabola()
{
  std::vector<Vec3> points;
  for (int i = 0; i < 10; ++i)
  {
    const double x = 2.0 * i / 9.0 - 1.0;
    points.emplace_back(x, x * x, 0.0);
  }
  return std::make_shared<BSplineCurve>(
    BSplineCurve::interpolate(points, 3, ParameterMethod::Uniform));
}

/// Cylinder sector x^2 + y^2 = R^2, angle in [0, sweep], z in [0, height], as a Coons
/// patch of two arcs and two generators (exact, see TestBSpline).
struct CylinderSector
{
  double radius = 1.0, sweep = Pi / 2, height = 3.0;
  Vec3 at(double phi, double z) const
  {
    return Vec3(radius * std::cos(phi), radius * std::sin(phi), z);
  }
  SurfacePtr patch() const
  {
    auto bottom = std::make_shared<ArcCurve>(ArcCurve::fromCentre(at(0, 0), at(sweep, 0),
      Vec3::Zero()));
    auto top = std::make_shared<ArcCurve>(ArcCurve::fromCentre(at(0, height), at(sweep, height),
      Vec3(0, 0, height)));
    return std::make_shared<CoonsPatch>(bottom,
      std::make_shared<LineCurve>(at(sweep, 0), at(sweep, height)), top,
      std::make_shared<LineCurve>(at(0, 0), at(0, height)));
  }
};
} // namespace

// ---------------------------------------------------------------------------------------
// Curves

TEST(CurveProjection, StraightLineIncludingClampedEnds)
{
  const Vec3 a(1, 2, 3), b(4, -2, 3);
  const CurveProjector projector(std::make_shared<LineCurve>(a, b));
  const Vec3 direction = (b - a) / (b - a).squaredNorm();
  const Vec3 normal = Vec3(4, 3, 0).normalized(); // orthogonal to b - a = (3, -4, 0)
  for (double t : { -3.0, -1e-3, 0.0, 1e-9, 0.3, 0.5, 0.999, 1.0, 1.2, 50.0 })
  {
    for (double offset : { 0.0, 1e-6, 0.7, 1e4 })
    {
      const Vec3 p = a + t * (b - a) + offset * normal + 0.5 * offset * Vec3::UnitZ();
      const CurveProjection r = projector.project(p);
      const double expectedT = clamp((p - a).dot(direction), 0.0, 1.0);
      const Vec3 expected = a + expectedT * (b - a);
      EXPECT_NEAR(r.t, expectedT, 1e-12) << t << " " << offset;
      EXPECT_LT(maxError(r.point, expected), 1e-11 * (1 + offset));
      EXPECT_NEAR(r.distance, (p - expected).norm(), 1e-9 * (1 + offset));
    }
  }
}

TEST(CurveProjection, CircularArcNearFarAndBeyondEnds)
{
  const Vec3 centre(0.5, -0.25, 1.0);
  const double radius = 2.0, sweep = 1.5 * Pi; // three quarters of a circle
  auto at = [&](double phi, double rho) {
    return Vec3(centre + rho * Vec3(std::cos(phi), std::sin(phi), 0.0));
  };
  auto arc = std::make_shared<ArcCurve>(ArcCurve::throughPoint(at(0, radius),
    at(0.5 * sweep, radius), at(sweep, radius)));
  ASSERT_NEAR(arc->sweepAngle(), sweep, 1e-14);
  const CurveProjector projector(arc);
  for (double phi : { 1e-7, 0.01, 0.4, 1.0, 2.5, 3.3, 4.7 })
  {
    for (double rho : { 0.05, 0.5, 1.9, 2.0, 2.0001, 3.0, 1000.0 })
    {
      for (double z : { 0.0, 0.3 })
      {
        const Vec3 p = at(phi, rho) + Vec3(0, 0, z);
        const CurveProjection r = projector.project(p);
        EXPECT_NEAR(r.t, phi / sweep, 1e-12) << phi << " " << rho;
        EXPECT_LT(maxError(r.point, at(phi, radius)), 1e-12) << phi << " " << rho;
        EXPECT_NEAR(r.distance, std::hypot(rho - radius, z), 1e-9) << phi << " " << rho;
      }
    }
  }
  // Beyond the ends, in the gap of the missing quarter: the nearest end point wins.
  for (double phi : { -0.1, -0.7, 1.5 * Pi + 0.2, 1.5 * Pi + 0.7 })
  {
    for (double rho : { 0.5, 2.0, 4.0, 100.0 })
    {
      const Vec3 p = at(phi, rho);
      const CurveProjection r = projector.project(p);
      const Vec3 start = arc->point(0.0), end = arc->point(1.0);
      const bool startCloser = (p - start).norm() < (p - end).norm();
      EXPECT_EQ(r.t, startCloser ? 0.0 : 1.0) << phi << " " << rho;
      EXPECT_EQ(r.point, startCloser ? start : end);
      EXPECT_NEAR(r.distance, std::min((p - start).norm(), (p - end).norm()), 1e-12);
    }
  }
}

TEST(CurveProjection, ParabolaBSplineAnalyticFootPoint)
{
  // Points on the convex side along the normal at u0 have the unique foot point C(u0).
  const auto curve = parabola();
  const CurveProjector projector(curve);
  for (double u0 : { 0.02, 0.2, 0.5, 0.61, 0.9, 0.995 })
  {
    const double x = 2 * u0 - 1;
    const Vec3 foot(x, x * x, 0);
    const Vec3 outward = Vec3(2 * x, -1, 0).normalized();
    for (double d : { 0.0, 1e-8, 1e-3, 0.7, 5.0, 1e3 })
    {
      const CurveProjection r = projector.project(foot + d * outward);
      EXPECT_NEAR(r.t, u0, 1e-12) << u0 << " " << d;
      EXPECT_LT(maxError(r.point, foot), 1e-12) << u0 << " " << d;
      EXPECT_NEAR(r.distance, d, 1e-9 * std::max(1.0, d)) << u0 << " " << d;
    }
    // Just inside (concave side, closer than the radius of curvature): still C(u0).
    const CurveProjection inner = projector.project(foot - 0.1 * outward);
    EXPECT_NEAR(inner.t, u0, 1e-12);
    EXPECT_NEAR(inner.distance, 0.1, 1e-12);
  }
  // Off the ends: clamped.
  const CurveProjection left = projector.project(Vec3(-3, 0.5, 0));
  EXPECT_EQ(left.t, 0.0);
  EXPECT_EQ(left.point, Vec3(-1, 1, 0));
  const CurveProjection right = projector.project(Vec3(1.5, 5, 2));
  EXPECT_EQ(right.t, 1.0);
}

TEST(CurveProjection, InterpolatedCircleBSpline)
{
  // A B-spline through 60 points of 3/4 of a circle: projections are orthogonal,
  // globally nearest, and agree with the exact circle to within the interpolation error.
  const double radius = 1.5, sweep = 1.5 * Pi;
  std::vector<Vec3> points;
  for (int i = 0; i < 60; ++i)
  {
    const double phi = sweep * i / 59.0;
    points.emplace_back(radius * std::cos(phi), radius * std::sin(phi), 0.0);
  }
  auto curve = std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points));
  const CurveProjector projector(curve);

  // Outward offsets from the spline's own points: the foot point is known exactly.
  for (double t0 : { 0.001, 0.05, 0.3333, 0.5, 0.8, 0.999 })
  {
    const Vec3 foot = curve->point(t0);
    const Vec3 tangent = curve->derivative(t0);
    const Vec3 outward = Vec3(tangent.y(), -tangent.x(), 0).normalized();
    ASSERT_GT(outward.dot(foot), 0.0);
    for (double d : { 1e-6, 0.2, 3.0, 500.0 })
    {
      const CurveProjection r = projector.project(foot + d * outward);
      EXPECT_NEAR(r.t, t0, 1e-11) << t0 << " " << d;
      EXPECT_LT(maxError(r.point, foot), 1e-12) << t0 << " " << d;
      EXPECT_NEAR(r.distance, d, 1e-9 * std::max(1.0, d));
    }
  }
  // Arbitrary points: distance to the analytic circle within the spline's deviation,
  // and no sampled point of the curve is closer.
  for (double phi : { 0.3, 1.7, 4.0 })
  {
    for (double rho : { 0.4, 1.4, 2.0, 40.0 })
    {
      const Vec3 p(rho * std::cos(phi), rho * std::sin(phi), 0.25);
      const CurveProjection r = projector.project(p);
      EXPECT_NEAR(r.distance, std::hypot(rho - radius, 0.25), 1e-6);
      EXPECT_LT(std::abs((p - r.point).dot(curve->derivative(r.t))), 1e-12 * (1 + rho) * 10);
      double sampled = std::numeric_limits<double>::infinity();
      for (int i = 0; i <= 20000; ++i)
      {
        sampled = std::min(sampled, (curve->point(i / 20000.0) - p).norm());
      }
      EXPECT_LE(r.distance, sampled + 1e-14);
    }
  }
}

TEST(CurveProjection, WigglyCurveGlobalMinimum)
{
  // Several local minima per sample interval in places: the result must never be farther
  // than the best of a dense sample of the curve.
  std::vector<Vec3> points;
  for (int i = 0; i < 40; ++i)
  {
    const double u = i / 39.0 * 6.0;
    points.emplace_back(u, std::sin(3 * u), 0.3 * std::cos(5 * u));
  }
  auto curve = std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points, 3));
  const CurveProjector projector(curve);
  std::vector<Vec3> dense;
  for (int i = 0; i <= 50000; ++i)
  {
    dense.push_back(curve->point(i / 50000.0));
  }
  std::vector<Vec3> queries = {
    // Closest point just inside the end, with a second local minimum at the end itself.
    Vec3(6.5722023778056009, -0.63193537034704317, -0.54732655616416293)
  };
  unsigned long long state = 12345;
  auto next = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int k = 0; k < 60; ++k)
  {
    queries.emplace_back(next() * 8 - 1, next() * 4 - 2, next() * 2 - 1);
  }
  for (const Vec3& p : queries)
  {
    const CurveProjection r = projector.project(p);
    double sampled = std::numeric_limits<double>::infinity();
    for (const Vec3& q : dense)
    {
      sampled = std::min(sampled, (q - p).norm());
    }
    EXPECT_LE(r.distance, sampled + 1e-13) << p.transpose();
    EXPECT_NEAR(r.distance, (curve->point(r.t) - p).norm(), 1e-15);
    if (r.t > 0.0 && r.t < 1.0)
    {
      // g = (C - p) . C' vanishes; its size relative to |C'|^2 is the parameter error.
      const Vec3 tangent = curve->derivative(r.t);
      EXPECT_LT(std::abs((r.point - p).dot(tangent)) / tangent.squaredNorm(), 1e-13);
    }
  }
}

// ---------------------------------------------------------------------------------------
// Surfaces

TEST(SurfaceProjection, WavySurfaceGlobalMinimum)
{
  const int ns = 20, nt = 15;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    for (int i = 0; i < ns; ++i)
    {
      const double u = i / (ns - 1.0) * 3, v = j / (nt - 1.0) * 2;
      grid.emplace_back(u, v, 0.4 * std::sin(2 * u) * std::cos(3 * v));
    }
  }
  auto surface = std::make_shared<BSplineSurface>(BSplineSurface::interpolate(grid, ns, nt));
  const SurfaceProjector projector(surface);
  const int N = 300;
  std::vector<Vec3> dense;
  for (int j = 0; j <= N; ++j)
  {
    for (int i = 0; i <= N; ++i)
    {
      dense.push_back(surface->point(static_cast<double>(i) / N, static_cast<double>(j) / N));
    }
  }
  unsigned long long state = 777;
  auto next = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int k = 0; k < 25; ++k)
  {
    const Vec3 p(next() * 4 - 0.5, next() * 3 - 0.5, next() * 2 - 1);
    const SurfaceProjection r = projector.project(p);
    double sampled = std::numeric_limits<double>::infinity();
    for (const Vec3& q : dense)
    {
      sampled = std::min(sampled, (q - p).norm());
    }
    EXPECT_LE(r.distance, sampled + 1e-13) << p.transpose();
    // Stationarity in every free direction.
    SurfaceDerivatives d;
    surface->derivatives(r.s, r.t, d);
    EXPECT_LT(maxError(d.P, r.point), 1e-15);
    if (r.s > 0.0 && r.s < 1.0)
    {
      EXPECT_LT(std::abs((d.P - p).dot(d.Ps)), 1e-13);
    }
    if (r.t > 0.0 && r.t < 1.0)
    {
      EXPECT_LT(std::abs((d.P - p).dot(d.Pt)), 1e-13);
    }
  }
}

TEST(SurfaceProjection, PlaneRectangleWithClamping)
{
  // P(s, t) = (2 s, t, 0) built from four straight edges.
  const Vec3 c00(0, 0, 0), c10(2, 0, 0), c01(0, 1, 0), c11(2, 1, 0);
  auto patch = std::make_shared<CoonsPatch>(std::make_shared<LineCurve>(c00, c10),
    std::make_shared<LineCurve>(c10, c11), std::make_shared<LineCurve>(c01, c11),
    std::make_shared<LineCurve>(c00, c01));
  const SurfaceProjector projector(patch);
  for (double x : { -5.0, -1e-9, 0.0, 0.3, 1.0, 1.97, 2.0, 2.5, 1e3 })
  {
    for (double y : { -2.0, 0.0, 0.01, 0.5, 0.999, 1.3 })
    {
      for (double z : { -1e3, -0.5, 0.0, 1e-7, 2.0 })
      {
        const Vec3 p(x, y, z);
        const SurfaceProjection r = projector.project(p);
        const Vec3 expected(clamp(x, 0, 2), clamp(y, 0, 1), 0);
        EXPECT_NEAR(r.s, expected.x() / 2, 1e-12) << p.transpose();
        EXPECT_NEAR(r.t, expected.y(), 1e-12) << p.transpose();
        EXPECT_LT(maxError(r.point, expected), 1e-12) << p.transpose();
        EXPECT_NEAR(r.distance, (p - expected).norm(), 1e-9) << p.transpose();
      }
    }
  }
}

TEST(SurfaceProjection, TiltedPlaneBSpline)
{
  const Vec3 origin(1, -1, 0.5), eu(1.0, 0.5, 0.25), ev(-0.2, 0.8, 0.6);
  const int ns = 6, nt = 5;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    for (int i = 0; i < ns; ++i)
    {
      grid.push_back(origin + eu * (double(i) / (ns - 1)) + ev * (double(j) / (nt - 1)));
    }
  }
  auto surface = std::make_shared<BSplineSurface>(
    BSplineSurface::interpolate(grid, ns, nt, 3, 3, ParameterMethod::Uniform));
  const SurfaceProjector projector(surface, 16, 16);
  const Vec3 normal = eu.cross(ev).normalized();
  for (double u : { 0.0, 0.15, 0.5, 0.93, 1.0 })
  {
    for (double v : { 0.0, 0.02, 0.6, 1.0 })
    {
      for (double d : { -100.0, -0.3, 0.0, 1e-5, 2.0 })
      {
        const Vec3 foot = origin + u * eu + v * ev;
        const SurfaceProjection r = projector.project(foot + d * normal);
        EXPECT_NEAR(r.s, u, 1e-11);
        EXPECT_NEAR(r.t, v, 1e-11);
        EXPECT_NEAR(r.distance, std::abs(d), 1e-9 * std::max(1.0, std::abs(d)));
        EXPECT_LT(maxError(r.point, foot), 1e-11);
      }
    }
  }
}

TEST(SurfaceProjection, CylinderSectorAnalyticFootPoint)
{
  const CylinderSector cylinder;
  const SurfaceProjector projector(cylinder.patch());
  for (double phi : { 0.0, 1e-6, 0.3, 0.785, 1.2, cylinder.sweep })
  {
    for (double rho : { 0.3, 0.9, 1.0, 1.1, 5.0, 1000.0 })
    {
      for (double z : { 0.0, 0.01, 1.7, 3.0 })
      {
        const Vec3 p(rho * std::cos(phi), rho * std::sin(phi), z);
        const SurfaceProjection r = projector.project(p);
        EXPECT_NEAR(r.s, phi / cylinder.sweep, 1e-12) << phi << " " << rho << " " << z;
        EXPECT_NEAR(r.t, z / cylinder.height, 1e-12) << phi << " " << rho << " " << z;
        EXPECT_LT(maxError(r.point, cylinder.at(phi, z)), 1e-12);
        EXPECT_NEAR(r.distance, std::abs(rho - cylinder.radius), 1e-9);
      }
    }
  }
  // Beyond the edges: above the top, below the bottom, past the generator at phi = 0.
  for (double zOut : { -2.0, 4.5 })
  {
    const Vec3 p(2.0 * std::cos(0.5), 2.0 * std::sin(0.5), zOut);
    const SurfaceProjection r = projector.project(p);
    const double zFoot = clamp(zOut, 0, cylinder.height);
    EXPECT_NEAR(r.t, zFoot / cylinder.height, 1e-12);
    EXPECT_NEAR(r.s, 0.5 / cylinder.sweep, 1e-12);
    EXPECT_NEAR(r.distance, (p - cylinder.at(0.5, zFoot)).norm(), 1e-9);
  }
  {
    const double phi = -0.2, rho = 2.0;
    const Vec3 p(rho * std::cos(phi), rho * std::sin(phi), 1.0);
    const SurfaceProjection r = projector.project(p);
    EXPECT_EQ(r.s, 0.0);
    EXPECT_NEAR(r.t, 1.0 / 3.0, 1e-12);
    EXPECT_NEAR(r.distance, (p - cylinder.at(0.0, 1.0)).norm(), 1e-9);
  }
}

TEST(SurfaceProjection, InterpolatedCylinderBSpline)
{
  const double radius = 0.8, sweep = 2.5, height = 1.2;
  const int ns = 25, nt = 4;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    for (int i = 0; i < ns; ++i)
    {
      const double phi = sweep * i / (ns - 1);
      grid.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * j / (nt - 1));
    }
  }
  auto surface = std::make_shared<BSplineSurface>(BSplineSurface::interpolate(grid, ns, nt));
  const SurfaceProjector projector(surface);
  // Outward normal offsets from the surface's own points: known foot point.
  for (double s0 : { 0.004, 0.25, 0.5, 0.77, 0.996 })
  {
    for (double t0 : { 0.0, 0.3, 0.999 })
    {
      SurfaceDerivatives d;
      surface->derivatives(s0, t0, d);
      Vec3 normal = d.Ps.cross(d.Pt).normalized();
      if (normal.dot(Vec3(d.P.x(), d.P.y(), 0)) < 0)
      {
        normal = -normal;
      }
      for (double offset : { 1e-7, 0.1, 2.0, 300.0 })
      {
        const SurfaceProjection r = projector.project(d.P + offset * normal);
        EXPECT_NEAR(r.s, s0, 1e-11) << s0 << " " << t0 << " " << offset;
        EXPECT_NEAR(r.t, t0, 1e-11) << s0 << " " << t0 << " " << offset;
        EXPECT_NEAR(r.distance, offset, 1e-9 * std::max(1.0, offset));
      }
    }
  }
  // Against the analytic cylinder, within the interpolation error.
  for (double phi : { 0.2, 1.3, 2.4 })
  {
    for (double rho : { 0.2, 0.7, 3.0 })
    {
      const Vec3 p(rho * std::cos(phi), rho * std::sin(phi), 0.5);
      const SurfaceProjection r = projector.project(p);
      EXPECT_NEAR(r.distance, std::abs(rho - radius), 2e-6);
      EXPECT_NEAR(r.point.z(), 0.5, 1e-9);
    }
  }
}

TEST(Projection, InvalidInputThrows)
{
  EXPECT_THROW(CurveProjector(nullptr), GeometryError);
  EXPECT_THROW(SurfaceProjector(nullptr), GeometryError);
  const CurveProjector projector(std::make_shared<LineCurve>(Vec3(0, 0, 0), Vec3(1, 0, 0)));
  EXPECT_THROW(projector.project(Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)),
    GeometryError);
}

// ---------------------------------------------------------------------------------------
// Arc length

TEST(ArcLength, CircularArcIsRadiusTimesAngle)
{
  const Vec3 centre(1, 1, 1);
  const double radius = 3.7;
  const Vec3 start = centre + radius * Vec3(1, 0, 0);
  const Vec3 end = centre + radius * Vec3(std::cos(2.2), 0, std::sin(2.2));
  auto arc = std::make_shared<ArcCurve>(ArcCurve::fromCentre(start, end, centre));
  const ArcLength length(arc);
  const double expected = radius * 2.2;
  EXPECT_NEAR(length.totalLength(), expected, 1e-12 * expected);
  for (int i = 0; i <= 100; ++i)
  {
    const double f = i / 100.0;
    EXPECT_NEAR(length.lengthAt(f), f * expected, 1e-12 * expected) << f;
    EXPECT_NEAR(length.parameterAtFraction(f), f, 1e-12) << f;
  }
  EXPECT_EQ(length.parameterAtFraction(0.0), 0.0);
  EXPECT_EQ(length.parameterAtFraction(1.0), 1.0);
}

TEST(ArcLength, ParabolaClosedFormAndInverse)
{
  // Length of y = x^2 on [-1, 1]: sqrt(5) + asinh(2) / 2.
  const auto curve = parabola();
  const ArcLength length(curve);
  const double expected = std::sqrt(5.0) + 0.5 * std::asinh(2.0);
  EXPECT_NEAR(length.totalLength(), expected, 1e-12 * expected);
  auto exactLength = [](double u) {
    auto primitive = [](double x) {
      return 0.5 * x * std::sqrt(1 + 4 * x * x) + 0.25 * std::asinh(2 * x);
    };
    return primitive(2 * u - 1) - primitive(-1.0);
  };
  for (double u : { 0.0, 0.013, 0.25, 0.5, 0.5001, 0.9, 1.0 })
  {
    EXPECT_NEAR(length.lengthAt(u), exactLength(u), 1e-12 * expected) << u;
  }
  for (int i = 0; i <= 50; ++i)
  {
    const double f = i / 50.0;
    const double t = length.parameterAtFraction(f);
    EXPECT_NEAR(exactLength(t), f * expected, 1e-12 * expected) << f;
    if (i > 0)
    {
      EXPECT_GT(t, length.parameterAtFraction((i - 1) / 50.0));
    }
  }
}

TEST(ArcLength, InterpolatedCurveInverseRoundTrip)
{
  std::vector<Vec3> points;
  for (int i = 0; i < 12; ++i)
  {
    const double u = i * i / 121.0 * 4.0;
    points.emplace_back(std::cos(u), std::sin(2 * u), 0.3 * u);
  }
  auto curve = std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points, 3));
  const ArcLength length(curve);
  for (int i = 0; i <= 40; ++i)
  {
    const double f = i / 40.0;
    EXPECT_NEAR(length.lengthAt(length.parameterAtFraction(f)), f * length.totalLength(),
      1e-12 * length.totalLength());
  }
}
