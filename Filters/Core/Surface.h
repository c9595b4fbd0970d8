/**
 * @file Surface.h
 * @brief Parametric surfaces on (s, t) in [0, 1]^2: the interface of B-spline surfaces,
 * Coons patches and (later) surfaces of revolution and Gordon surfaces.
 */
#pragma once

#include "Curve.h"

namespace blockforge
{
/// Point and partial derivatives of a surface at (s, t).
struct SurfaceDerivatives
{
  Vec3 P, Ps, Pt, Pss, Pst, Ptt;
};

class Surface
{
public:
  virtual ~Surface() = default;
  virtual Vec3 point(double s, double t) const = 0;
  virtual void derivatives(double s, double t, SurfaceDerivatives& out) const = 0;
  /// Point and first derivatives only, the same bits as derivatives() gives for them;
  /// surfaces where the second derivatives cost much (Gordon) skip computing them.
  virtual void firstDerivatives(double s, double t, Vec3& P, Vec3& Ps, Vec3& Pt) const
  {
    SurfaceDerivatives d;
    derivatives(s, t, d);
    P = d.P;
    Ps = d.Ps;
    Pt = d.Pt;
  }
  /**
   * The points at (s, t), (sPlus, t), (sMinus, t), (s, tPlus) and (s, tMinus), the same
   * bits as point() at each (central differences around a point): surfaces whose points
   * are sums over curves in s and in t (Gordon) evaluate each curve once per parameter.
   */
  virtual void crossPoints(double s, double sPlus, double sMinus, double t, double tPlus,
    double tMinus, Vec3 out[5]) const
  {
    out[0] = point(s, t);
    out[1] = point(sPlus, t);
    out[2] = point(sMinus, t);
    out[3] = point(s, tPlus);
    out[4] = point(s, tMinus);
  }
  /**
   * Values of s (or of t, with `tDirection`) at which a derivative of the surface may
   * jump (knots of its curves, nodes of its blends), increasing: a curve on the surface
   * ends its arc-length pieces where it crosses them (ArcLength.h). None by default.
   */
  virtual std::vector<double> breakpoints(bool tDirection) const
  {
    (void)tDirection;
    return {};
  }
};

using SurfacePtr = std::shared_ptr<const Surface>;

/**
 * @class CoonsPatch
 * @brief Bilinearly blended Coons patch (paper eq. 3) from four boundary curves.
 *
 * bottom = P(s, 0), top = P(s, 1), left = P(0, t), right = P(1, t); every curve runs in
 * the direction of increasing s or t. Corners are taken from bottom/top; the constructor
 * throws GeometryError when the curves do not meet (gap above 1e-9 of the patch size).
 */
class CoonsPatch : public Surface
{
public:
  CoonsPatch(CurvePtr bottom, CurvePtr right, CurvePtr top, CurvePtr left);
  Vec3 point(double s, double t) const override;
  void derivatives(double s, double t, SurfaceDerivatives& out) const override;

private:
  CurvePtr Bottom, Right, Top, Left;
  Vec3 C00, C10, C01, C11;
};
} // namespace blockforge
