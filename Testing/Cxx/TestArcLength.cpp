// The arc-length rule (Core/ArcLength.h) against analytic lengths: helices with uneven
// parametrisations, a curve with a kink, a B-spline through hundreds of points of a
// circle (against the circle and against a fine integration of its own knot spans), pieces
// of a closed carrier across its seam; and against the rule it replaced (5-point Gauss on
// 512 equal pieces), which the new one must beat.
#include "ArcLength.h"
#include "BSpline.h"
#include "CarrierGeometry.h"
#include "Carriers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace blockforge;

namespace
{
constexpr double Pi = 3.14159265358979323846;
const double GaussX[5] = { -0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
  0.9061798459386640 };
const double GaussW[5] = { 0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
  0.4786286704993665, 0.2369268850561891 };

/// 5-point Gauss on `pieces` equal pieces of [a, b]: the old rule (512 pieces of [0, 1]),
/// and with many pieces inside smooth spans an independent reference.
double compositeGauss(const Curve& curve, double a, double b, int pieces)
{
  double total = 0.0;
  for (int k = 0; k < pieces; ++k)
  {
    const double lo = a + (b - a) * k / pieces, hi = a + (b - a) * (k + 1) / pieces;
    const double half = 0.5 * (hi - lo), centre = 0.5 * (hi + lo);
    double sum = 0.0;
    for (int g = 0; g < 5; ++g)
    {
      sum += GaussW[g] * curve.derivative(centre + half * GaussX[g], 1).norm();
    }
    total += sum * half;
  }
  return total;
}

/// Length from 0 to u of a B-spline: 64 Gauss pieces in every knot span (where it is a
/// polynomial), so accurate to rounding.
double splineLength(const BSplineCurve& curve, double u)
{
  std::vector<double> ends{ 0.0 };
  for (const double knot : curve.breakpoints())
  {
    ends.push_back(knot);
  }
  ends.push_back(1.0);
  double total = 0.0;
  for (std::size_t k = 0; k + 1 < ends.size() && ends[k] < u; ++k)
  {
    total += compositeGauss(curve, ends[k], std::min(u, ends[k + 1]), 64);
  }
  return total;
}

/// A helix of radius R and pitch c per radian on the uneven parameter
/// phi(t) = W (t + a sin(2 pi t) / (2 pi)) (a < 1): speed sqrt(R^2 + c^2) phi'(t), so the
/// length from 0 to t is sqrt(R^2 + c^2) phi(t). With `kink`, phi gains W (t - kink)^2
/// past t = kink: the speed stays continuous, its slope jumps (as at a B-spline's knot,
/// only more), announced as a breakpoint when `announce`.
class UnevenHelix : public Curve
{
public:
  UnevenHelix(double radius, double pitch, double turns, double wobble, double kink = -1.0,
    bool announce = true)
    : R(radius), C(pitch), W(2.0 * Pi * turns), A(wobble), Kink(kink), Announce(announce)
  {
  }
  double phi(double t) const
  {
    const double smooth = W * (t + A * std::sin(2.0 * Pi * t) / (2.0 * Pi));
    return Kink >= 0.0 && t > Kink ? smooth + W * (t - Kink) * (t - Kink) : smooth;
  }
  double phiSlope(double t) const
  {
    const double slope = W * (1.0 + A * std::cos(2.0 * Pi * t));
    return Kink >= 0.0 && t > Kink ? slope + 2.0 * W * (t - Kink) : slope;
  }
  double lengthAt(double t) const { return std::sqrt(R * R + C * C) * phi(t); }
  Vec3 point(double t) const override
  {
    const double p = phi(t);
    return Vec3(R * std::cos(p), R * std::sin(p), C * p);
  }
  Vec3 derivative(double t, int order) const override
  {
    const double p = phi(t), d = phiSlope(t);
    if (order == 1)
    {
      return d * Vec3(-R * std::sin(p), R * std::cos(p), C);
    }
    return Vec3::Zero(); // not needed here
  }
  std::vector<double> breakpoints() const override
  {
    return Kink >= 0.0 && Announce ? std::vector<double>{ Kink } : std::vector<double>{};
  }

private:
  double R, C, W, A, Kink;
  bool Announce;
};

/// A cubic B-spline through `count` points of a circle of radius `radius` about the
/// origin, crowded towards angle 0 (spacing growing 30-fold round the circle), closed.
std::shared_ptr<BSplineCurve> splineCircle(int count, double radius)
{
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
  {
    const double x = static_cast<double>(i) / (count - 1);
    const double angle = 2.0 * Pi * (x + 3.0 * x * x) / 4.0;
    points.emplace_back(radius * std::cos(angle), radius * std::sin(angle), 0.0);
  }
  points.back() = points.front();
  return std::make_shared<BSplineCurve>(BSplineCurve::interpolate(points, 3));
}

/// Fractions 0, 1/n, ..., 1 of a table and the lengths at their parameters, checked
/// against `exact` (the length from 0 at a parameter); returns the largest error.
template <typename Exact>
double worstNodeError(const ArcLength& table, const Exact& exact, int n)
{
  double worst = 0.0;
  for (int i = 0; i <= n; ++i)
  {
    const double fraction = static_cast<double>(i) / n;
    const double t = table.parameterAtFraction(fraction);
    worst = std::max(worst, std::abs(exact(t) - fraction * table.totalLength()));
  }
  return worst;
}
} // namespace

TEST(ArcLength, UnevenHelixLengthsAndNodesToRounding)
{
  const auto helix = std::make_shared<UnevenHelix>(0.7, 0.15, 3.0, 0.8);
  const ArcLength table(helix);
  const double exact = helix->lengthAt(1.0);
  EXPECT_NEAR(table.totalLength(), exact, 1e-13 * exact);
  for (int i = 0; i <= 200; ++i)
  {
    const double t = i / 200.0;
    EXPECT_NEAR(table.lengthAt(t), helix->lengthAt(t), 1e-13 * exact) << t;
  }
  EXPECT_LT(worstNodeError(table, [&](double t) { return helix->lengthAt(t); }, 97), 1e-13 * exact);
  EXPECT_EQ(table.parameterAtFraction(0.0), 0.0);
  EXPECT_EQ(table.parameterAtFraction(1.0), 1.0);
  // the old rule on the same helix (its speed varies 9-fold): good here too, it is smooth
  EXPECT_NEAR(compositeGauss(*helix, 0.0, 1.0, 512), exact, 1e-11 * exact);
}

TEST(ArcLength, KinkAtABreakpointIsExactAndAnUnannouncedOneConverges)
{
  // 1/3 is never near the end of a halved piece: a kink within 0.8 % of a piece's end
  // lies outside all its nodes and is seen by no rule that samples the speed
  const double kink = 1.0 / 3.0;
  const auto announced = std::make_shared<UnevenHelix>(1.3, -0.4, 2.0, 0.5, kink, true);
  const auto hidden = std::make_shared<UnevenHelix>(1.3, -0.4, 2.0, 0.5, kink, false);
  const double exact = announced->lengthAt(1.0);
  const ArcLength atBreakpoint(announced), adaptive(hidden);
  EXPECT_NEAR(atBreakpoint.totalLength(), exact, 1e-13 * exact);
  EXPECT_NEAR(adaptive.totalLength(), exact, 1e-12 * exact);
  // pieces: the breakpoint costs one more; the hidden kink is found by halving
  EXPECT_LT(atBreakpoint.pieceCount(), adaptive.pieceCount());
  EXPECT_LT(adaptive.pieceCount(), 200);
  auto exactAt = [&](double t) { return announced->lengthAt(t); };
  EXPECT_LT(worstNodeError(atBreakpoint, exactAt, 61), 1e-13 * exact);
  EXPECT_LT(worstNodeError(adaptive, exactAt, 61), 1e-12 * exact);
  // the old rule: a kink inside one of its 512 pieces
  const double oldError = std::abs(compositeGauss(*hidden, 0.0, 1.0, 512) - exact);
  EXPECT_GT(oldError, 1e3 * std::abs(adaptive.totalLength() - exact));
}

TEST(ArcLength, SplineThroughACircleWithHundredsOfKnots)
{
  const double radius = 0.25;
  const auto circle = splineCircle(601, radius);
  ASSERT_GT(circle->breakpoints().size(), 500u);
  const ArcLength table(circle);
  // the spline is the circle to about 1e-9 of its radius
  EXPECT_NEAR(table.totalLength(), 2.0 * Pi * radius, 1e-8 * radius);
  // its own length: to rounding, against 64 Gauss pieces per knot span
  const double exact = splineLength(*circle, 1.0);
  EXPECT_NEAR(table.totalLength(), exact, 1e-13 * exact);
  for (const double t : { 0.013, 0.25, 0.5, 0.7071, 0.99 })
  {
    EXPECT_NEAR(table.lengthAt(t), splineLength(*circle, t), 1e-13 * exact) << t;
  }
  EXPECT_LT(worstNodeError(table, [&](double t) { return splineLength(*circle, t); }, 23),
    1e-12 * exact);
  // one piece per knot span: the cost follows the knots, not a fixed count
  EXPECT_LE(table.pieceCount(), static_cast<int>(circle->breakpoints().size()) + 1 + 16);
  // the old rule errs by orders of magnitude more (kinks of the speed inside its pieces)
  const double oldError = std::abs(compositeGauss(*circle, 0.0, 1.0, 512) - exact);
  EXPECT_GT(oldError, 1e3 * std::abs(table.totalLength() - exact));
}

TEST(ArcLength, PieceOfAClosedCarrierAcrossItsSeamBothWays)
{
  const double radius = 2.0;
  const auto circle = splineCircle(301, radius);
  const auto carrier = std::make_shared<const ArcLength>(circle);
  const double turn = carrier->totalLength();
  // 0.8 -> 1.3 runs over the seam; 1.3 -> 0.8 is the same piece backwards
  const ArcLength forward(carrier, 0.8, 1.3, true), backward(carrier, 1.3, 0.8, true);
  const double exact = (turn - splineLength(*circle, 0.8)) + splineLength(*circle, 0.3);
  EXPECT_NEAR(forward.totalLength(), exact, 1e-13 * turn);
  EXPECT_NEAR(backward.totalLength(), exact, 1e-13 * turn);
  // the piece as an edge sees it: model::SubCurve, parameter t in [0, 1]
  const model::SubCurve edge(circle, 0.8, 1.3, true);
  auto edgeLength = [&](double t) {
    const double u = 0.8 + 0.5 * t;
    return u <= 1.0 ? splineLength(*circle, u) - splineLength(*circle, 0.8)
                    : turn - splineLength(*circle, 0.8) + splineLength(*circle, u - 1.0);
  };
  for (int i = 0; i <= 20; ++i)
  {
    const double fraction = i / 20.0;
    const double t = forward.parameterAtFraction(fraction);
    EXPECT_NEAR(edgeLength(t), fraction * exact, 1e-12 * exact) << fraction;
    // backwards: the same point at the mirrored fraction
    const double back = backward.parameterAtFraction(1.0 - fraction);
    EXPECT_NEAR((circle->point(model::wrapUnit(1.3 - 0.5 * back)) - edge.point(t)).norm(), 0.0,
      1e-12 * radius)
      << fraction;
  }
  EXPECT_EQ(forward.parameterAtFraction(1.0), 1.0);
  // an open carrier clamps: the piece 0.9 -> 1.2 is 0.9 -> 1
  const ArcLength clamped(carrier, 0.9, 1.2, false);
  EXPECT_NEAR(clamped.totalLength(), turn - splineLength(*circle, 0.9), 1e-13 * turn);
}

TEST(ArcLength, SurfaceLinesEndPiecesWhereTheyCrossTheContourKnots)
{
  // a hub: a B-spline contour with 40 knots, revolved; a line in (s, t) across it
  std::vector<Vec3> contour;
  for (int i = 0; i < 44; ++i)
  {
    const double x = i / 43.0;
    contour.emplace_back(x, 0.0, 1.0 + 0.3 * std::sin(3.0 * x) + 0.05 * x * x * x);
  }
  auto spline = std::make_shared<BSplineCurve>(BSplineCurve::interpolate(contour, 3));
  auto hub = std::make_shared<SurfaceOfRevolution>(
    spline, Vec3::Zero(), Vec3(1, 0, 0), 0.0, 0.8);
  const auto line = std::make_shared<model::ParameterLineCurve>(
    hub, Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.9, 0.7), false, false);
  const std::vector<double> crossings = line->breakpoints();
  ASSERT_GT(crossings.size(), 25u);
  for (const double u : crossings)
  {
    // each is where s = 0.1 + 0.8 u is a knot of the contour
    const double s = 0.1 + 0.8 * u;
    double nearest = 1.0;
    for (const double knot : spline->breakpoints())
    {
      nearest = std::min(nearest, std::abs(knot - s));
    }
    EXPECT_LT(nearest, 1e-15);
  }
  const ArcLength table(line);
  EXPECT_EQ(table.pieceCount(), static_cast<int>(crossings.size()) + 1);
  // against 64 Gauss pieces between crossings
  std::vector<double> ends{ 0.0 };
  ends.insert(ends.end(), crossings.begin(), crossings.end());
  ends.push_back(1.0);
  double exact = 0.0;
  for (std::size_t k = 0; k + 1 < ends.size(); ++k)
  {
    exact += compositeGauss(*line, ends[k], ends[k + 1], 64);
  }
  EXPECT_NEAR(table.totalLength(), exact, 1e-13 * exact);
}

TEST(ArcLength, SameBitsEveryTime)
{
  const auto circle = splineCircle(200, 1.0);
  const ArcLength a(circle), b(circle);
  EXPECT_EQ(a.totalLength(), b.totalLength());
  for (int i = 0; i <= 10; ++i)
  {
    EXPECT_EQ(a.parameterAtFraction(i / 10.0), b.parameterAtFraction(i / 10.0));
  }
}
