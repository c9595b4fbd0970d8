/**
 * @file Curve.h
 * @brief Parametric space curves on t in [0, 1]: straight lines, circular arcs and the
 * abstract interface the B-spline curves, projections and Coons patches work with.
 */
#pragma once

#include "Types.h"

#include <memory>
#include <vector>

namespace blockforge
{
/**
 * @class Curve
 * @brief A C1 space curve parametrised on t in [0, 1].
 *
 * point(0) and point(1) are the curve's end points. derivative() returns dP/dt
 * (order 1) or d2P/dt2 (order 2); higher orders may return zero for curves that
 * do not need them.
 */
class Curve
{
public:
  virtual ~Curve() = default;
  virtual Vec3 point(double t) const = 0;
  virtual Vec3 derivative(double t, int order = 1) const = 0;
  /**
   * point(t), derivative(t, 1) and derivative(t, 2) into out[0..2], the same bits as the
   * three calls. Curves whose derivatives share their work (one basis evaluation gives
   * both) override it: a Newton step of a projection needs all three.
   */
  virtual void jet(double t, Vec3 out[3]) const
  {
    out[0] = point(t);
    out[1] = derivative(t, 1);
    out[2] = derivative(t, 2);
  }
  /**
   * Parameters in (0, 1), increasing, at which a derivative of the curve may jump (the
   * interior knots of a B-spline). Arc-length tables end pieces there (ArcLength.h): a
   * quadrature rule across a kink of the speed converges slowly. None by default.
   */
  virtual std::vector<double> breakpoints() const { return {}; }
};

using CurvePtr = std::shared_ptr<const Curve>;

/// Straight segment from a to b.
class LineCurve : public Curve
{
public:
  LineCurve(const Vec3& a, const Vec3& b);
  Vec3 point(double t) const override;
  Vec3 derivative(double t, int order = 1) const override;

private:
  Vec3 A, B;
};

/**
 * @class ArcCurve
 * @brief Circular arc from `start` to `end`, parametrised proportionally to arc length.
 *
 * Built either from a centre (the arc is the shorter one of the circle through start and
 * end about that centre, unless `longWay`) or through a third point on the arc
 * (blockMesh's convention). Start and end must be at the same distance from the centre
 * (relative mismatch below 1e-6) or a GeometryError is thrown. The points are
 * evaluated as centre + R (cos(phi) e1 + sin(phi) e2), so every point lies at radius R
 * up to rounding.
 */
class ArcCurve : public Curve
{
public:
  static ArcCurve fromCentre(const Vec3& start, const Vec3& end, const Vec3& centre,
    bool longWay = false);
  static ArcCurve throughPoint(const Vec3& start, const Vec3& through, const Vec3& end);

  Vec3 point(double t) const override;
  Vec3 derivative(double t, int order = 1) const override;

  const Vec3& centre() const { return Centre; }
  double radius() const { return Radius; }
  double sweepAngle() const { return Sweep; } ///< radians, in (0, 2*pi)

private:
  ArcCurve() = default;
  Vec3 Centre, E1, E2; // E1 points to the start, E2 completes the arc's plane
  double Radius = 0.0, Sweep = 0.0;
  Vec3 Start, End;     // returned exactly at t = 0 and t = 1
};
} // namespace blockforge
