// Geometry of the numerical core against analytic shapes: B-spline basis, curves and
// surfaces, lines and arcs, Coons patches.
#include "BSpline.h"
#include "Curve.h"
#include "Surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

using namespace blockforge;

namespace
{
constexpr double Pi = 3.14159265358979323846;
const double NaN = std::numeric_limits<double>::quiet_NaN();

double maxError(const Vec3& a, const Vec3& b)
{
  return (a - b).cwiseAbs().maxCoeff();
}

/// A smooth non-planar test curve with unevenly spaced samples.
std::vector<Vec3> helixPoints(int count)
{
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
  {
    const double u = std::pow(static_cast<double>(i) / (count - 1), 1.3) * 3.0;
    points.emplace_back(std::cos(u) * (1.0 + 0.2 * u), std::sin(u), 0.4 * u * u);
  }
  return points;
}

/// A cubic polynomial space curve and its derivatives in its own parameter u.
struct CubicCurve
{
  Vec3 a{ 0.3, -1.0, 2.0 }, b{ 1.5, 0.5, -0.7 }, c{ -2.0, 1.25, 0.4 }, d{ 0.8, -0.6, 1.1 };
  Vec3 point(double u) const { return a + u * (b + u * (c + u * d)); }
  Vec3 first(double u) const { return b + u * (2.0 * c + 3.0 * u * d); }
  Vec3 second(double u) const { return 2.0 * c + 6.0 * u * d; }
  Vec3 third() const { return 6.0 * d; }
};
} // namespace

// ---------------------------------------------------------------------------------------
// Basis functions

TEST(BSplineBasis, HandComputedValuesNurbsBookExample)
{
  // The NURBS Book, ex. 2.3/2.4: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2.
  const std::vector<double> knots = { 0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5 };
  const int count = 8;
  EXPECT_EQ(bspline::findSpan(2, knots, count, 2.5), 4);
  EXPECT_EQ(bspline::findSpan(2, knots, count, 0.0), 2);
  EXPECT_EQ(bspline::findSpan(2, knots, count, 5.0), 7);
  EXPECT_EQ(bspline::findSpan(2, knots, count, 4.0), 7);
  EXPECT_EQ(bspline::findSpan(2, knots, count, 3.999), 5);

  double values[3];
  bspline::basisFunctions(4, 2.5, 2, knots, values);
  EXPECT_NEAR(values[0], 1.0 / 8.0, 1e-15);
  EXPECT_NEAR(values[1], 6.0 / 8.0, 1e-15);
  EXPECT_NEAR(values[2], 1.0 / 8.0, 1e-15);

  double ders[3 * 3];
  bspline::basisDerivatives(4, 2.5, 2, 2, knots, ders);
  const double expected[3][3] = { { 0.125, 0.75, 0.125 }, { -0.5, 0.0, 0.5 },
    { 1.0, -2.0, 1.0 } };
  for (int k = 0; k < 3; ++k)
  {
    for (int j = 0; j < 3; ++j)
    {
      EXPECT_NEAR(ders[k * 3 + j], expected[k][j], 1e-14) << "k=" << k << " j=" << j;
    }
  }
}

TEST(BSplineBasis, PartitionOfUnityAndNonNegative)
{
  for (int degree = 1; degree <= 7; ++degree)
  {
    // Clamped, uneven, with a double interior knot.
    std::vector<double> knots(degree + 1, 0.0);
    for (double k : { 0.1, 0.15, 0.4, 0.4, 0.77, 0.9 })
    {
      knots.push_back(k);
    }
    knots.insert(knots.end(), degree + 1, 1.0);
    const int count = static_cast<int>(knots.size()) - degree - 1;
    for (int i = 0; i <= 1000; ++i)
    {
      const double t = i / 1000.0;
      const int span = bspline::findSpan(degree, knots, count, t);
      ASSERT_GE(span, degree);
      ASSERT_LT(span, count);
      ASSERT_LE(knots[span], t);
      double values[bspline::MaxDegree + 1];
      bspline::basisFunctions(span, t, degree, knots, values);
      double sum = 0.0;
      for (int j = 0; j <= degree; ++j)
      {
        EXPECT_GE(values[j], 0.0);
        sum += values[j];
      }
      EXPECT_NEAR(sum, 1.0, 1e-14) << "degree " << degree << " t " << t;

      // The derivative rows of a partition of unity sum to zero.
      double ders[3 * (bspline::MaxDegree + 1)];
      bspline::basisDerivatives(span, t, degree, 2, knots, ders);
      double d1 = 0.0, d2 = 0.0;
      for (int j = 0; j <= degree; ++j)
      {
        EXPECT_NEAR(ders[j], values[j], 1e-15);
        d1 += ders[(degree + 1) + j];
        d2 += ders[2 * (degree + 1) + j];
      }
      EXPECT_NEAR(d1, 0.0, 1e-10);
      EXPECT_NEAR(d2, 0.0, 1e-7);
    }
  }
}

TEST(BSplineBasis, ExactAtClampedEnds)
{
  const std::vector<double> knots = { 0, 0, 0, 0, 0.3, 0.7, 1, 1, 1, 1 };
  double values[4];
  bspline::basisFunctions(3, 0.0, 3, knots, values);
  EXPECT_EQ(values[0], 1.0);
  EXPECT_EQ(values[3], 0.0);
  bspline::basisFunctions(5, 1.0, 3, knots, values);
  EXPECT_EQ(values[3], 1.0);
  EXPECT_EQ(values[0], 0.0);
}

TEST(BSplineBasis, AveragedKnotsAndParameters)
{
  const std::vector<Vec3> points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 4, 0),
    Vec3(1, 4, 9) };
  const auto chord = bspline::interpolationParameters(points, ParameterMethod::ChordLength);
  ASSERT_EQ(chord.size(), 4u);
  EXPECT_EQ(chord[0], 0.0);
  EXPECT_NEAR(chord[1], 1.0 / 14.0, 1e-16);
  EXPECT_NEAR(chord[2], 5.0 / 14.0, 1e-16);
  EXPECT_EQ(chord[3], 1.0);
  const auto centripetal =
    bspline::interpolationParameters(points, ParameterMethod::Centripetal);
  EXPECT_NEAR(centripetal[1], 1.0 / 6.0, 1e-16);
  EXPECT_NEAR(centripetal[2], 3.0 / 6.0, 1e-16);
  const auto uniform = bspline::interpolationParameters(points, ParameterMethod::Uniform);
  EXPECT_NEAR(uniform[1], 1.0 / 3.0, 1e-16);

  // NURBS book eq. 9.8 with p = 2 on 6 parameters: knots 0,0,0,(u1+u2)/2,(u2+u3)/2,...
  const std::vector<double> params = { 0.0, 0.1, 0.3, 0.6, 0.8, 1.0 };
  const auto knots = bspline::averagedKnots(params, 2);
  const std::vector<double> expected = { 0, 0, 0, 0.2, 0.45, 0.7, 1, 1, 1 };
  ASSERT_EQ(knots.size(), expected.size());
  for (std::size_t i = 0; i < knots.size(); ++i)
  {
    EXPECT_NEAR(knots[i], expected[i], 1e-16) << i;
  }
  EXPECT_THROW(bspline::averagedKnots(params, 6), GeometryError);
}

// ---------------------------------------------------------------------------------------
// Curves

TEST(BSplineCurve, InterpolationPassesThroughEveryPoint)
{
  const std::vector<Vec3> points = helixPoints(17);
  for (ParameterMethod method :
    { ParameterMethod::Uniform, ParameterMethod::ChordLength, ParameterMethod::Centripetal })
  {
    for (int degree = 1; degree <= 5; ++degree)
    {
      const BSplineCurve curve = BSplineCurve::interpolate(points, degree, method);
      ASSERT_EQ(curve.degree(), degree);
      const auto& params = curve.dataParameters();
      ASSERT_EQ(params.size(), points.size());
      EXPECT_EQ(curve.point(0.0), points.front()); // exact, bit for bit
      EXPECT_EQ(curve.point(1.0), points.back());
      for (std::size_t i = 0; i < points.size(); ++i)
      {
        EXPECT_LT(maxError(curve.point(params[i]), points[i]), 1e-12)
          << "degree " << degree << " method " << static_cast<int>(method) << " point " << i;
      }
    }
  }
}

TEST(BSplineCurve, DerivativesGivePointAndLowerOrdersBitForBit)
{
  // Projections take the point and both derivatives from one derivatives(t, 2) call
  // (Curve::jet); the grids keep their bits only if that point is point(t) and the first
  // derivative is derivative(t, 1), at the ends and at knots too.
  const std::vector<Vec3> points = helixPoints(23);
  for (int degree = 1; degree <= 5; ++degree)
  {
    const BSplineCurve curve = BSplineCurve::interpolate(points, degree, ParameterMethod::ChordLength);
    std::vector<double> at = curve.dataParameters();
    for (int i = 0; i <= 997; ++i)
    {
      at.push_back(i / 997.0);
    }
    for (const double t : at)
    {
      Vec3 jet[3];
      curve.derivatives(t, 2, jet);
      EXPECT_EQ(jet[0], curve.point(t)) << "degree " << degree << " t " << t;
      EXPECT_EQ(jet[1], curve.derivative(t, 1)) << "degree " << degree << " t " << t;
      Vec3 generic[3];
      curve.Curve::jet(t, generic);
      EXPECT_EQ(generic[0], jet[0]);
      EXPECT_EQ(generic[1], jet[1]);
      EXPECT_EQ(generic[2], jet[2]);
    }
  }
}

TEST(BSplineCurve, DegreeLoweredForFewPoints)
{
  const std::vector<Vec3> points = { Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(2, 0, 1) };
  const BSplineCurve curve = BSplineCurve::interpolate(points, 3);
  EXPECT_EQ(curve.degree(), 2);
  EXPECT_LT(maxError(curve.point(curve.dataParameters()[1]), points[1]), 1e-14);
  const BSplineCurve line = BSplineCurve::interpolate({ Vec3(0, 0, 0), Vec3(2, 4, 6) }, 3);
  EXPECT_EQ(line.degree(), 1);
  EXPECT_LT(maxError(line.point(0.25), Vec3(0.5, 1.0, 1.5)), 1e-15);
}

TEST(BSplineCurve, DegreeOneIsThePolyline)
{
  const std::vector<Vec3> points = helixPoints(9);
  const BSplineCurve curve =
    BSplineCurve::interpolate(points, 1, ParameterMethod::ChordLength);
  const auto& params = curve.dataParameters();
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    EXPECT_LT(maxError(curve.controlPoints()[i], points[i]), 1e-14);
  }
  for (std::size_t i = 0; i + 1 < points.size(); ++i)
  {
    for (double w : { 0.25, 0.5, 0.9 })
    {
      const double t = (1.0 - w) * params[i] + w * params[i + 1];
      const Vec3 expected = (1.0 - w) * points[i] + w * points[i + 1];
      EXPECT_LT(maxError(curve.point(t), expected), 1e-13) << i << " " << w;
    }
    // Constant speed on each segment.
    const Vec3 slope = (points[i + 1] - points[i]) / (params[i + 1] - params[i]);
    EXPECT_LT(maxError(curve.derivative(0.5 * (params[i] + params[i + 1])), slope),
      1e-11 * slope.norm());
  }
}

TEST(BSplineCurve, CubicReproducesCubicPolynomialExactly)
{
  const CubicCurve cubic;
  std::vector<Vec3> points;
  const int count = 11;
  for (int i = 0; i < count; ++i)
  {
    points.push_back(cubic.point(static_cast<double>(i) / (count - 1)));
  }
  for (int degree : { 3, 4, 5 })
  {
    const BSplineCurve curve =
      BSplineCurve::interpolate(points, degree, ParameterMethod::Uniform);
    double pointError = 0.0, firstError = 0.0, secondError = 0.0, thirdError = 0.0;
    for (int i = 0; i <= 1000; ++i)
    {
      const double u = i / 1000.0;
      Vec3 d[4];
      curve.derivatives(u, 3, d);
      pointError = std::max(pointError, maxError(curve.point(u), cubic.point(u)));
      pointError = std::max(pointError, maxError(d[0], cubic.point(u)));
      firstError = std::max(firstError, maxError(d[1], cubic.first(u)));
      secondError = std::max(secondError, maxError(d[2], cubic.second(u)));
      thirdError = std::max(thirdError, maxError(d[3], cubic.third()));
      EXPECT_LT(maxError(curve.derivative(u, 2), d[2]), 1e-14);
    }
    EXPECT_LT(pointError, 1e-12) << "degree " << degree;
    EXPECT_LT(firstError, 1e-10) << "degree " << degree;
    EXPECT_LT(secondError, 1e-9) << "degree " << degree;
    EXPECT_LT(thirdError, 1e-7) << "degree " << degree;
  }
  // Above the degree all derivatives vanish.
  const BSplineCurve cubicCurve = BSplineCurve::interpolate(points, 3, ParameterMethod::Uniform);
  EXPECT_EQ(cubicCurve.derivative(0.3, 4), Vec3::Zero());
}

TEST(BSplineCurve, DerivativesMatchCentralDifferences)
{
  const std::vector<Vec3> points = helixPoints(14);
  for (int degree = 2; degree <= 5; ++degree)
  {
    const BSplineCurve curve =
      BSplineCurve::interpolate(points, degree, ParameterMethod::Centripetal);
    const double h = 1e-5;
    for (double t : { 0.013, 0.21, 0.5, 0.777, 0.98 })
    {
      const Vec3 fd1 = (curve.point(t + h) - curve.point(t - h)) / (2 * h);
      const Vec3 d1 = curve.derivative(t, 1);
      EXPECT_LT(maxError(d1, fd1), 1e-7 * (1.0 + d1.norm())) << degree << " " << t;
      const Vec3 fd2 = (curve.derivative(t + h, 1) - curve.derivative(t - h, 1)) / (2 * h);
      const Vec3 d2 = curve.derivative(t, 2);
      if (degree >= 3) // the second derivative of a quadratic jumps at knots
      {
        EXPECT_LT(maxError(d2, fd2), 1e-6 * (1.0 + d2.norm())) << degree << " " << t;
      }
    }
  }
}

TEST(BSplineCurve, ExplicitConstructionNormalisesKnots)
{
  // A quadratic Bezier on knots [2, 4]: the knots are mapped onto [0, 1].
  const BSplineCurve curve(2, { 2, 2, 2, 4, 4, 4 },
    { Vec3(0, 0, 0), Vec3(1, 2, 0), Vec3(2, 0, 0) });
  EXPECT_EQ(curve.knots().front(), 0.0);
  EXPECT_EQ(curve.knots().back(), 1.0);
  EXPECT_LT(maxError(curve.point(0.5), Vec3(1.0, 1.0, 0.0)), 1e-15);
  EXPECT_LT(maxError(curve.derivative(0.0), Vec3(2.0, 4.0, 0.0)), 1e-14);
  EXPECT_LT(maxError(curve.derivative(0.7, 2), Vec3(0.0, -8.0, 0.0)), 1e-13);
}

TEST(BSplineCurve, InvalidInputThrows)
{
  EXPECT_THROW(BSplineCurve::interpolate({ Vec3(0, 0, 0) }), GeometryError);
  EXPECT_THROW(BSplineCurve::interpolate({}), GeometryError);
  EXPECT_THROW(
    BSplineCurve::interpolate({ Vec3(0, 0, 0), Vec3(NaN, 0, 0), Vec3(1, 1, 1) }),
    GeometryError);
  EXPECT_THROW(
    BSplineCurve::interpolate({ Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0), Vec3(2, 1, 0) }),
    GeometryError);
  EXPECT_THROW(BSplineCurve::interpolate({ Vec3(0, 0, 0), Vec3(1, 0, 0) }, 0), GeometryError);
  // Wrong knot count, unclamped, decreasing knots.
  const std::vector<Vec3> control = { Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(2, 0, 0) };
  EXPECT_THROW(BSplineCurve(2, { 0, 0, 0, 1, 1 }, control), GeometryError);
  EXPECT_THROW(BSplineCurve(2, { 0, 0, 0.5, 1, 1, 1 }, control), GeometryError);
  EXPECT_THROW(BSplineCurve(1, { 0, 0, 0.7, 0.5, 1 }, { Vec3(0, 0, 0), Vec3(1, 1, 0),
                                                       Vec3(2, 0, 0) }),
    GeometryError);
  try
  {
    BSplineCurve::interpolate({ Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0) });
    FAIL() << "coincident points accepted";
  }
  catch (const GeometryError& e)
  {
    EXPECT_NE(std::string(e.what()).find("coincide"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------
// Surfaces

TEST(BSplineSurface, BilinearGridIsReproducedExactly)
{
  // P(u, v) = (u, v, u v + 0.5 u - v) lies in the spline space of every degree >= 1.
  auto exact = [](double u, double v) { return Vec3(u, v, u * v + 0.5 * u - v); };
  const int ns = 7, nt = 5;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    for (int i = 0; i < ns; ++i)
    {
      grid.push_back(exact(static_cast<double>(i) / (ns - 1), static_cast<double>(j) / (nt - 1)));
    }
  }
  for (int degree = 1; degree <= 4; ++degree)
  {
    const BSplineSurface surface =
      BSplineSurface::interpolate(grid, ns, nt, degree, degree, ParameterMethod::Uniform);
    EXPECT_EQ(surface.degreeS(), degree);
    EXPECT_EQ(surface.degreeT(), degree);
    double error = 0.0, derivativeError = 0.0;
    for (int j = 0; j <= 40; ++j)
    {
      for (int i = 0; i <= 40; ++i)
      {
        const double u = i / 40.0, v = j / 40.0;
        error = std::max(error, maxError(surface.point(u, v), exact(u, v)));
        SurfaceDerivatives d;
        surface.derivatives(u, v, d);
        derivativeError = std::max({ derivativeError, maxError(d.P, exact(u, v)),
          maxError(d.Ps, Vec3(1, 0, v + 0.5)), maxError(d.Pt, Vec3(0, 1, u - 1)),
          maxError(d.Pst, Vec3(0, 0, 1)), maxError(d.Pss, Vec3::Zero()),
          maxError(d.Ptt, Vec3::Zero()) });
      }
    }
    EXPECT_LT(error, 1e-13) << "degree " << degree;
    EXPECT_LT(derivativeError, 1e-10) << "degree " << degree;
  }
}

TEST(BSplineSurface, PlaneWithUnevenGridChordLength)
{
  // Linear map of (u, v): chord-length parameters equal u and v exactly, so the cubic
  // interpolant is the plane itself, parametrised by (u, v).
  const Vec3 origin(1, 2, 3), eu(2, 0.5, -1), ev(-0.3, 1.5, 0.8);
  auto exact = [&](double u, double v) { return Vec3(origin + u * eu + v * ev); };
  const int ns = 9, nt = 6;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    const double v = std::pow(static_cast<double>(j) / (nt - 1), 1.5);
    for (int i = 0; i < ns; ++i)
    {
      const double u = std::pow(static_cast<double>(i) / (ns - 1), 2.0);
      grid.push_back(exact(u, v));
    }
  }
  const BSplineSurface surface = BSplineSurface::interpolate(grid, ns, nt, 3, 3);
  double error = 0.0;
  for (int j = 0; j <= 25; ++j)
  {
    for (int i = 0; i <= 25; ++i)
    {
      const double u = i / 25.0, v = j / 25.0;
      error = std::max(error, maxError(surface.point(u, v), exact(u, v)));
    }
  }
  EXPECT_LT(error, 1e-12);
  EXPECT_EQ(surface.point(0, 0), grid.front());
  EXPECT_EQ(surface.point(1, 1), grid.back());
}

TEST(BSplineSurface, CylinderInterpolationPassesThroughData)
{
  const double radius = 1.5, height = 2.0, sweep = Pi;
  const int ns = 13, nt = 5;
  std::vector<Vec3> grid;
  for (int j = 0; j < nt; ++j)
  {
    for (int i = 0; i < ns; ++i)
    {
      const double phi = sweep * i / (ns - 1);
      grid.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * j / (nt - 1));
    }
  }
  for (ParameterMethod method :
    { ParameterMethod::Uniform, ParameterMethod::ChordLength, ParameterMethod::Centripetal })
  {
    const BSplineSurface surface = BSplineSurface::interpolate(grid, ns, nt, 3, 3, method);
    // Equal chords: the averaged parameters are uniform for every method.
    for (int j = 0; j < nt; ++j)
    {
      for (int i = 0; i < ns; ++i)
      {
        const double s = static_cast<double>(i) / (ns - 1), t = static_cast<double>(j) / (nt - 1);
        EXPECT_LT(maxError(surface.point(s, t), grid[i + j * ns]), 1e-12) << i << " " << j;
      }
    }
    // In between, the cubic stays close to the cylinder and is exact in z.
    for (double s : { 0.03, 0.31, 0.5, 0.96 })
    {
      for (double t : { 0.1, 0.6 })
      {
        const Vec3 p = surface.point(s, t);
        EXPECT_NEAR(std::hypot(p.x(), p.y()), radius, 2e-4);
        EXPECT_NEAR(p.z(), height * t, 1e-12);
        SurfaceDerivatives d;
        surface.derivatives(s, t, d);
        const double h = 1e-5;
        const Vec3 fdS = (surface.point(s + h, t) - surface.point(s - h, t)) / (2 * h);
        const Vec3 fdT = (surface.point(s, t + h) - surface.point(s, t - h)) / (2 * h);
        SurfaceDerivatives dp, dm;
        surface.derivatives(s + h, t, dp);
        surface.derivatives(s - h, t, dm);
        EXPECT_LT(maxError(d.Ps, fdS), 1e-7 * d.Ps.norm());
        EXPECT_LT(maxError(d.Pt, fdT), 1e-7 * (1 + d.Pt.norm()));
        EXPECT_LT(maxError(d.Pss, (dp.Ps - dm.Ps) / (2 * h)), 1e-5 * d.Pss.norm());
        EXPECT_LT(maxError(d.Pst, (dp.Pt - dm.Pt) / (2 * h)), 1e-6);
      }
    }
  }
}

TEST(BSplineSurface, InvalidInputThrows)
{
  std::vector<Vec3> grid(6, Vec3::Zero());
  EXPECT_THROW(BSplineSurface::interpolate(grid, 4, 2), GeometryError); // 8 != 6
  EXPECT_THROW(BSplineSurface::interpolate(grid, 6, 1), GeometryError);
  EXPECT_THROW(BSplineSurface::interpolate(grid, 3, 2), GeometryError); // all coincide
  std::vector<Vec3> good = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, NaN) };
  EXPECT_THROW(BSplineSurface::interpolate(good, 2, 2), GeometryError);
}

// ---------------------------------------------------------------------------------------
// Lines and arcs

TEST(LineCurve, EndsAndDerivatives)
{
  const Vec3 a(1, -2, 3), b(0.1, 0.7, -5);
  const LineCurve line(a, b);
  EXPECT_EQ(line.point(0.0), a);
  EXPECT_EQ(line.point(1.0), b);
  EXPECT_LT(maxError(line.point(0.25), a + 0.25 * (b - a)), 1e-15);
  EXPECT_EQ(line.derivative(0.4), b - a);
  EXPECT_EQ(line.derivative(0.4, 2), Vec3::Zero());
  EXPECT_THROW(LineCurve(a, Vec3(NaN, 0, 0)), GeometryError);
}

TEST(ArcCurve, FromCentreLiesOnCircle)
{
  const Vec3 centre(1, 2, -1);
  const double radius = 2.5;
  // In a tilted plane spanned by orthonormal u, w.
  const Vec3 u = Vec3(1, 1, 0).normalized(), w = Vec3(-1, 1, 1).normalized();
  auto onCircle = [&](double phi) {
    return Vec3(centre + radius * (std::cos(phi) * u + std::sin(phi) * w));
  };
  const double phi0 = 0.3, phi1 = 2.2;
  const ArcCurve arc = ArcCurve::fromCentre(onCircle(phi0), onCircle(phi1), centre);
  EXPECT_NEAR(arc.radius(), radius, 1e-15 * radius);
  EXPECT_NEAR(arc.sweepAngle(), phi1 - phi0, 1e-14);
  EXPECT_EQ(arc.point(0.0), onCircle(phi0));
  EXPECT_EQ(arc.point(1.0), onCircle(phi1));
  for (int i = 0; i <= 100; ++i)
  {
    const double t = i / 100.0;
    const Vec3 p = arc.point(t);
    EXPECT_NEAR((p - centre).norm(), radius, 4e-16 * radius * 4);
    EXPECT_LT(maxError(p, onCircle(phi0 + t * (phi1 - phi0))), 1e-14);
    // Constant speed R * sweep, analytic derivatives.
    const double h = 1e-5;
    const Vec3 d1 = arc.derivative(t, 1);
    EXPECT_NEAR(d1.norm(), radius * arc.sweepAngle(), 1e-13);
    const Vec3 d2 = arc.derivative(t, 2);
    const Vec3 fd2 = (arc.derivative(t + h, 1) - arc.derivative(t - h, 1)) / (2 * h);
    EXPECT_LT(maxError(d2, fd2), 1e-8);
    EXPECT_LT(maxError(d2, -std::pow(arc.sweepAngle(), 2) * (p - centre)), 1e-13);
  }

  const ArcCurve longArc = ArcCurve::fromCentre(onCircle(phi0), onCircle(phi1), centre, true);
  EXPECT_NEAR(longArc.sweepAngle(), 2 * Pi - (phi1 - phi0), 1e-14);
  EXPECT_LT(maxError(longArc.point(0.5), onCircle(phi0 - 0.5 * longArc.sweepAngle())), 1e-14);
  EXPECT_EQ(longArc.point(1.0), onCircle(phi1));
}

TEST(ArcCurve, InvalidArcsThrow)
{
  const Vec3 c(0, 0, 0);
  EXPECT_THROW(ArcCurve::fromCentre(Vec3(1, 0, 0), Vec3(0, 1.001, 0), c), GeometryError);
  EXPECT_NO_THROW(ArcCurve::fromCentre(Vec3(1, 0, 0), Vec3(0, 1 + 1e-8, 0), c));
  EXPECT_THROW(ArcCurve::fromCentre(Vec3(1, 0, 0), Vec3(-1, 0, 0), c), GeometryError);
  EXPECT_THROW(ArcCurve::fromCentre(Vec3(1, 0, 0), Vec3(1, 0, 0), c), GeometryError);
  EXPECT_THROW(ArcCurve::fromCentre(Vec3(0, 0, 0), Vec3(1, 0, 0), c), GeometryError);
  EXPECT_THROW(ArcCurve::fromCentre(Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(NaN, 0, 0)),
    GeometryError);
  EXPECT_THROW(ArcCurve::throughPoint(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)),
    GeometryError);
  EXPECT_THROW(ArcCurve::throughPoint(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(2, 2, 2)),
    GeometryError);
}

TEST(ArcCurve, ThroughPointFindsCircumcircle)
{
  const Vec3 centre(-0.5, 3.0, 2.0);
  const double radius = 0.75;
  const Vec3 u = Vec3(0, 0, 1), w = Vec3(1, 1, 0).normalized();
  auto onCircle = [&](double phi) {
    return Vec3(centre + radius * (std::cos(phi) * u + std::sin(phi) * w));
  };
  // More than half a circle, through a point near the end.
  const double phi0 = -0.4, phiThrough = 3.5, phi1 = 3.9;
  const ArcCurve arc =
    ArcCurve::throughPoint(onCircle(phi0), onCircle(phiThrough), onCircle(phi1));
  EXPECT_LT(maxError(arc.centre(), centre), 1e-14);
  EXPECT_NEAR(arc.radius(), radius, 1e-14);
  EXPECT_NEAR(arc.sweepAngle(), phi1 - phi0, 1e-13);
  const double tThrough = (phiThrough - phi0) / (phi1 - phi0);
  EXPECT_LT(maxError(arc.point(tThrough), onCircle(phiThrough)), 1e-14);
  EXPECT_EQ(arc.point(0.0), onCircle(phi0));
  EXPECT_EQ(arc.point(1.0), onCircle(phi1));

  // The same end points through a point on the other side give the complementary arc.
  const ArcCurve other =
    ArcCurve::throughPoint(onCircle(phi0), onCircle(phi0 - 0.5), onCircle(phi1));
  EXPECT_NEAR(other.sweepAngle(), 2 * Pi - (phi1 - phi0), 1e-13);
  EXPECT_LT(maxError(other.point(0.5), onCircle(phi0 - 0.5 * other.sweepAngle())), 1e-14);
}

// ---------------------------------------------------------------------------------------
// Coons patches (paper eq. 3)

TEST(CoonsPatch, StraightEdgesGiveBilinearPatch)
{
  const Vec3 c00(0, 0, 0), c10(2, 0.2, 0.5), c01(-0.3, 1.5, 0.1), c11(1.8, 1.7, -0.6);
  const CoonsPatch patch(std::make_shared<LineCurve>(c00, c10),
    std::make_shared<LineCurve>(c10, c11), std::make_shared<LineCurve>(c01, c11),
    std::make_shared<LineCurve>(c00, c01));
  for (int j = 0; j <= 20; ++j)
  {
    for (int i = 0; i <= 20; ++i)
    {
      const double s = i / 20.0, t = j / 20.0;
      const Vec3 bilinear =
        (1 - s) * (1 - t) * c00 + s * (1 - t) * c10 + (1 - s) * t * c01 + s * t * c11;
      EXPECT_LT(maxError(patch.point(s, t), bilinear), 1e-15);
      SurfaceDerivatives d;
      patch.derivatives(s, t, d);
      EXPECT_LT(maxError(d.P, bilinear), 1e-15);
      EXPECT_LT(maxError(d.Ps, (1 - t) * (c10 - c00) + t * (c11 - c01)), 1e-15);
      EXPECT_LT(maxError(d.Pt, (1 - s) * (c01 - c00) + s * (c11 - c10)), 1e-15);
      EXPECT_LT(maxError(d.Pst, c11 - c10 - c01 + c00), 1e-15);
      EXPECT_EQ(d.Pss, Vec3::Zero());
      EXPECT_EQ(d.Ptt, Vec3::Zero());
    }
  }
}

TEST(CoonsPatch, ArcsAndGeneratorsGiveExactCylinder)
{
  const double radius = 1.25, height = 3.0;
  const Vec3 axisPoint(0.5, -1, 0);
  auto at = [&](double phi, double z) {
    return Vec3(axisPoint + Vec3(radius * std::cos(phi), radius * std::sin(phi), z));
  };
  const double phi0 = 0.2, phi1 = 1.9;
  auto bottom = std::make_shared<ArcCurve>(
    ArcCurve::fromCentre(at(phi0, 0), at(phi1, 0), axisPoint));
  auto top = std::make_shared<ArcCurve>(
    ArcCurve::fromCentre(at(phi0, height), at(phi1, height), axisPoint + Vec3(0, 0, height)));
  const CoonsPatch patch(bottom, std::make_shared<LineCurve>(at(phi1, 0), at(phi1, height)),
    top, std::make_shared<LineCurve>(at(phi0, 0), at(phi0, height)));
  for (int j = 0; j <= 10; ++j)
  {
    for (int i = 0; i <= 10; ++i)
    {
      const double s = i / 10.0, t = j / 10.0;
      const Vec3 expected = at(phi0 + s * (phi1 - phi0), t * height);
      const Vec3 p = patch.point(s, t);
      EXPECT_LT(maxError(p, expected), 1e-14);
      SurfaceDerivatives d;
      patch.derivatives(s, t, d);
      const Vec3 radial = expected - axisPoint - Vec3(0, 0, t * height);
      const double w = phi1 - phi0;
      EXPECT_LT(maxError(d.Ps, w * Vec3(-radial.y(), radial.x(), 0)), 1e-13);
      EXPECT_LT(maxError(d.Pt, Vec3(0, 0, height)), 1e-14);
      EXPECT_LT(maxError(d.Pss, -w * w * radial), 1e-13);
      EXPECT_LT(maxError(d.Pst, Vec3::Zero()), 1e-14);
      EXPECT_LT(maxError(d.Ptt, Vec3::Zero()), 1e-14);
    }
  }
}

TEST(CoonsPatch, FourArcsInterpolateTheirBoundaries)
{
  // A quadrilateral on a sphere bounded by four great-circle arcs: the patch lies on the
  // sphere along its boundary and reproduces every edge.
  const Vec3 centre(0.1, 0.2, 0.3);
  const double radius = 2.0;
  auto onSphere = [&](double lon, double lat) {
    return Vec3(centre +
      radius * Vec3(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)));
  };
  const Vec3 c00 = onSphere(0.0, -0.4), c10 = onSphere(0.9, -0.3), c01 = onSphere(0.1, 0.5),
             c11 = onSphere(1.0, 0.6);
  auto arc = [&](const Vec3& a, const Vec3& b) {
    return std::make_shared<ArcCurve>(ArcCurve::fromCentre(a, b, centre));
  };
  auto bottom = arc(c00, c10), right = arc(c10, c11), top = arc(c01, c11), left = arc(c00, c01);
  const CoonsPatch patch(bottom, right, top, left);
  for (int i = 0; i <= 50; ++i)
  {
    const double u = i / 50.0;
    const Vec3 edges[4] = { patch.point(u, 0), patch.point(1, u), patch.point(u, 1),
      patch.point(0, u) };
    const Vec3 expected[4] = { bottom->point(u), right->point(u), top->point(u), left->point(u) };
    for (int e = 0; e < 4; ++e)
    {
      EXPECT_LT(maxError(edges[e], expected[e]), 1e-14) << "edge " << e << " u " << u;
      EXPECT_NEAR((edges[e] - centre).norm(), radius, 1e-14);
    }
    EXPECT_EQ(patch.point(0, u), left->point(u)); // bit for bit on s = 0 and s = 1
    EXPECT_EQ(patch.point(1, u), right->point(u));
  }
  // Derivatives against central differences inside.
  const double h = 1e-5;
  for (double s : { 0.2, 0.5, 0.85 })
  {
    for (double t : { 0.1, 0.45, 0.9 })
    {
      SurfaceDerivatives d, sp, sm, tp, tm;
      patch.derivatives(s, t, d);
      patch.derivatives(s + h, t, sp);
      patch.derivatives(s - h, t, sm);
      patch.derivatives(s, t + h, tp);
      patch.derivatives(s, t - h, tm);
      EXPECT_LT(maxError(d.Ps, (sp.P - sm.P) / (2 * h)), 1e-8);
      EXPECT_LT(maxError(d.Pt, (tp.P - tm.P) / (2 * h)), 1e-8);
      EXPECT_LT(maxError(d.Pss, (sp.Ps - sm.Ps) / (2 * h)), 1e-8);
      EXPECT_LT(maxError(d.Ptt, (tp.Pt - tm.Pt) / (2 * h)), 1e-8);
      EXPECT_LT(maxError(d.Pst, (tp.Ps - tm.Ps) / (2 * h)), 1e-8);
    }
  }
}

TEST(CoonsPatch, OpenBoundaryThrows)
{
  const Vec3 c00(0, 0, 0), c10(1, 0, 0), c01(0, 1, 0), c11(1, 1, 0);
  auto line = [](const Vec3& a, const Vec3& b) { return std::make_shared<LineCurve>(a, b); };
  EXPECT_THROW(CoonsPatch(line(c00, c10), line(c10, c11 + Vec3(0, 0, 1e-6)), line(c01, c11),
                 line(c00, c01)),
    GeometryError);
  EXPECT_THROW(CoonsPatch(line(c00, c10), nullptr, line(c01, c11), line(c00, c01)),
    GeometryError);
}

TEST(BSplineCurve, ThreePointsAtOnceArePointsBitForBit)
{
  // points() (a finite difference's three points, the span looked up once) gives point()'s
  // bits: inside a span, across a knot, at and beyond the ends, cubic and quadratic.
  std::vector<Vec3> through;
  for (int k = 0; k < 9; ++k)
  {
    through.emplace_back(std::cos(0.4 * k), std::sin(0.7 * k), 0.1 * k * k);
  }
  const BSplineCurve cubic = BSplineCurve::interpolate(through, 3);
  const BSplineCurve quadratic =
    BSplineCurve::interpolate({ through[0], through[3], through[8] }, 3); // degree 2
  const double knot = cubic.knots()[5];
  for (const BSplineCurve* curve : { &cubic, &quadratic })
  {
    for (const double s : { 0.0, 1e-7, 0.3, knot, std::nextafter(knot, 0.0), 0.999999, 1.0 })
    {
      for (const double h : { 1e-6, 0.2 })
      {
        const double t[3] = { s, s + h, s - h };
        Vec3 out[3];
        curve->points(t, out);
        for (int k = 0; k < 3; ++k)
        {
          const Vec3 expected = curve->point(t[k]);
          EXPECT_EQ(out[k].x(), expected.x()) << s << " " << h << " " << k;
          EXPECT_EQ(out[k].y(), expected.y());
          EXPECT_EQ(out[k].z(), expected.z());
        }
      }
    }
  }
}
