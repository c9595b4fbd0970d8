/**
 * @file Carriers.h
 * @brief Carrier geometry built from point data (paper section 2.2): surfaces of
 * revolution, Gordon surfaces through curve networks or sections (Lagrange or spline
 * blending, paper eqs. 4-5), curves in the (s, t) space of a surface, and the
 * intersection of a surface with a surface of revolution (blade with hub or shroud).
 *
 * Carriers are what control points slide on (the optimizer) and what faces and edges of
 * blocks lie on (the mesher): every point they return lies on them up to rounding.
 */
#pragma once

#include "BSpline.h"
#include "Projection.h"
#include "Surface.h"
#include "WorkBudget.h"

#include <Eigen/Core>

#include <functional>

namespace blockforge
{
/**
 * @class SurfaceOfRevolution
 * @brief A meridional contour swept about the machine axis.
 *
 * s runs along the contour (its own parameter, [0, 1]); t in [0, 1] maps linearly to the
 * rotation angle from angleStart to angleEnd (radians, right-hand rule about axisDirection):
 * P(s, t) = rotateAboutAxis(contour(s), angleStart + t (angleEnd - angleStart)). The
 * contour is any space curve (usually in one meridional half-plane); angle 0 is the
 * contour itself. Points are exact rotations of contour points, so their distance to the
 * axis is the contour's radius to rounding. t outside [0, 1] rotates further (periodic);
 * s is passed to the contour as is (B-spline contours clamp it).
 * Throws GeometryError for a missing contour, a zero or non-finite axis direction, or a
 * zero or non-finite sweep.
 */
class SurfaceOfRevolution : public Surface
{
public:
  SurfaceOfRevolution(CurvePtr contour, const Vec3& axisPoint, const Vec3& axisDirection,
    double angleStart, double angleEnd);
  Vec3 point(double s, double t) const override;
  void derivatives(double s, double t, SurfaceDerivatives& out) const override;
  void firstDerivatives(double s, double t, Vec3& P, Vec3& Ps, Vec3& Pt) const override;
  void crossPoints(double s, double sPlus, double sMinus, double t, double tPlus, double tMinus,
    Vec3 out[5]) const override;
  /// The contour's breakpoints in s; none in t.
  std::vector<double> breakpoints(bool tDirection) const override;

  const Vec3& axisPoint() const { return AxisPoint; }
  const Vec3& axisDirection() const { return AxisDirection; } ///< unit vector
  const CurvePtr& contour() const { return Contour; }
  double angleStart() const { return AngleStart; }
  double angleEnd() const { return AngleEnd; }

  /// Axial coordinate and radius of p about the axis.
  void axialRadial(const Vec3& p, double& axial, double& radius) const;
  /**
   * Signed distance of p from the surface measured in p's meridional plane: positive on
   * the side the contour's left normal points to in the (axial, radius) plane (for a
   * contour running in +axial direction: positive = larger radius). Exact closest point
   * on the contour (sampled, then Newton to 1e-14 in s), so its zero set is the full
   * 360-degree surface, whatever angleStart/angleEnd. When the closest point is an end of
   * the contour, the distance is to that end point and the sign is that of the end's
   * normal (it flips across the end's normal line: not a zero of the surface).
   */
  double signedMeridionalDistance(const Vec3& p) const;
  /// Parameter s of the closest contour point to p's (axial, radius) position.
  double contourParameter(const Vec3& p) const;

private:
  /// Point and derivatives of the contour at s up to `order` (1 or 2).
  void contourJet(double s, int order, Vec3 (&c)[3]) const;
  /// Point and first derivatives from the contour's jet, with the rotation at t.
  void firstOrder(const Vec3 (&c)[3], double t, Vec3& P, Vec3& Ps, Vec3& Pt, double& cs,
    double& sn, Vec3& arm) const;
  CurvePtr Contour;
  const BSplineCurve* ContourSpline = nullptr; ///< Contour when it is a B-spline (one basis evaluation per jet)
  Vec3 AxisPoint, AxisDirection;
  double AngleStart, AngleEnd;
  // The contour mapped to (axial, radius, 0) and its projector: the closest meridional
  // point is the closest point of this plane curve.
  CurvePtr Meridional;
  std::shared_ptr<const CurveProjector> MeridionalProjector;
  CurveProjection projectMeridional(const Vec3& p) const;
};

/// Rotation of p about the axis through axisPoint along axisDirection (normalised here) by
/// angle (radians, right-hand rule), Rodrigues' formula. Used for periodic images;
/// deterministic; angle 0 returns p bit for bit. Throws GeometryError for a zero or
/// non-finite direction or angle.
Vec3 rotateAboutAxis(const Vec3& p, const Vec3& axisPoint, const Vec3& axisDirection,
  double angle);

/**
 * @class GordonSurface
 * @brief Surface through a network of curves (paper eq. 4), or through a family of
 * sections only (lofting: the second family is empty).
 *
 * P(s, t) = sum_j C_j(s) B_j(t) + sum_i D_i(t) A_i(s) - sum_i sum_j C_j(s_i) A_i(s) B_j(t),
 * where C_j are the s-curves at t_j, D_i the t-curves at s_i, and A_i / B_j blend
 * functions: Lagrange polynomials (paper eq. 5) or cubic spline cardinal functions
 * (interpolating spline through the values at the nodes: no Runge oscillation). With
 * sections only, P(s, t) = sum_j C_j(s) B_j(t).
 *
 * Blending: Lagrange = paper eq. 5 (exact for surfaces polynomial of degree < node count,
 * but oscillates for many nodes). Spline = cardinal functions of the *natural* cubic
 * spline interpolant through the nodes (B_j = the natural spline through the unit vector
 * e_j): reproduces constants and linear functions exactly (partition of unity), C2.
 *
 * Extrapolation: point() and derivatives() accept s and t outside [0, 1]. Lagrange
 * blends are polynomials and simply continue; spline blends continue linearly beyond
 * the end nodes with the end slope (the natural spline has zero second derivative there,
 * so the extension is C2 and, unlike the end cubic pieces, cannot bend away). Curves are
 * evaluated on [0, 1] only and continued by their end tangent line beyond (C1), so
 * every B-spline curve extends instead of clamping. This is how a blade surface is
 * extended past hub and shroud when its sections stop short: a surface linear in t (a
 * ruled surface) extends exactly. `extendedPoint` is the same as point().
 *
 * Evaluation does not allocate (blend values of up to 64 nodes per direction are kept on
 * the stack; more nodes are recomputed on the fly).
 */
class GordonSurface : public Surface
{
public:
  enum class Blending
  {
    Lagrange,
    Spline
  };

  /// Lofted surface through sections C_j(s) at parameters t_j (strictly increasing;
  /// mapped affinely to [0, 1] if the first is not 0 or the last not 1). At least 2
  /// sections. P(s, t_j) == C_j(s) bit for bit.
  static GordonSurface fromSections(std::vector<CurvePtr> sections,
    std::vector<double> sectionParameters, Blending blending);

  /// Full Gordon surface through a compatible network: sCurves[j] = P(s, t_j),
  /// tCurves[i] = P(s_i, t); at least 2 curves in each family; nodes strictly increasing
  /// in [0, 1] (they are curve parameters, so not normalised); intersections must agree
  /// to 1e-9 of the network size (GeometryError otherwise, with the mismatch distance).
  /// P(s_i, t) == D_i(t) bit for bit; P(s, t_j) == C_j(s) to rounding.
  static GordonSurface fromNetwork(std::vector<CurvePtr> sCurves, std::vector<double> tNodes,
    std::vector<CurvePtr> tCurves, std::vector<double> sNodes, Blending blending);

  Vec3 point(double s, double t) const override;
  void derivatives(double s, double t, SurfaceDerivatives& out) const override;
  void firstDerivatives(double s, double t, Vec3& P, Vec3& Ps, Vec3& Pt) const override;
  void crossPoints(double s, double sPlus, double sMinus, double t, double tPlus, double tMinus,
    Vec3 out[5]) const override;
  /// Same as point() (which extrapolates too); kept as the explicit name for callers.
  Vec3 extendedPoint(double s, double t) const { return point(s, t); }
  /// The nodes of this direction's spline blends, with 0 and 1 (where the surface
  /// continues past its curves).
  std::vector<double> breakpoints(bool tDirection) const override
  {
    return tDirection ? TBreakpoints : SBreakpoints;
  }

  Blending blending() const { return TheBlending; }
  const std::vector<CurvePtr>& sCurves() const { return SCurves; } ///< sections
  const std::vector<double>& tNodes() const { return TNodes; }     ///< normalised
  const std::vector<CurvePtr>& tCurves() const { return TCurves; } ///< empty for lofts
  const std::vector<double>& sNodes() const { return SNodes; }
  /// Blend function `index` of the t (or s) direction at x, with its first and second
  /// derivatives (jet[0..2]); exposed for tests and diagnostics.
  void blend(bool tDirection, int index, double x, double jet[3]) const;

private:
  GordonSurface() = default;
  std::vector<CurvePtr> SCurves, TCurves;
  std::vector<double> TNodes, SNodes;
  Blending TheBlending = Blending::Spline;
  // Natural-spline cardinal functions: per node, 4 coefficients (a, b, c, d) per node
  // interval (a + b h + c h^2 + d h^3, h = x - x_k), then the slope at the last node.
  std::vector<std::vector<double>> TBlendCoefficients, SBlendCoefficients;
  // Network corner points Q[i + j * SNodes.size()] = C_j(s_i).
  std::vector<Vec3> NodePoints;
  // Curves that are B-splines get point and derivatives from one basis evaluation.
  std::vector<const BSplineCurve*> SSplines, TSplines;
  std::vector<double> SBreakpoints, TBreakpoints;
  void prepare();
};

/**
 * @class SurfaceCurve
 * @brief A curve defined in the (s, t) parameter space of a surface: a cubic B-spline (or
 * straight line for two points; degree min(3, n-1)) through parameter-space points, with
 * chord-length parameters in (s, t), mapped onto the surface. Every point lies on the
 * surface up to rounding. Throws GeometryError for a missing surface, fewer than 2
 * points or coincident consecutive points.
 */
class SurfaceCurve : public Curve
{
public:
  SurfaceCurve(SurfacePtr surface, std::vector<Eigen::Vector2d> parameterPoints);
  Vec3 point(double u) const override;
  Vec3 derivative(double u, int order = 1) const override;
  /// The knots of the curve in (s, t) and the parameters at which it crosses the
  /// surface's breakpoints (found span by span of the curve in (s, t) where its ends
  /// straddle one; a crossing inside a span that turns back is not found).
  std::vector<double> breakpoints() const override;
  /// (s, t) on the surface at curve parameter u.
  Eigen::Vector2d parameters(double u) const;
  const SurfacePtr& surface() const { return TheSurface; }
  const std::vector<Eigen::Vector2d>& parameterPoints() const { return ParameterPoints; }
  /// Curve parameter u of parameterPoints()[k] (chord length in (s, t)).
  const std::vector<double>& nodeParameters() const { return ParameterCurve->dataParameters(); }

private:
  SurfacePtr TheSurface;
  std::vector<Eigen::Vector2d> ParameterPoints;
  std::shared_ptr<const BSplineCurve> ParameterCurve; // (s, t, 0) in parameter space
};

/**
 * Intersection of `surface` (e.g. a blade, GordonSurface, evaluated with extrapolation in
 * t) with a surface of revolution (hub or shroud): for each s of `samples` equally spaced
 * values in [0, 1], the t where the surface point lies on the revolution surface (root of
 * signedMeridionalDistance: 16 sub-intervals of [tMin, tMax] scanned for sign changes,
 * then Brent to |dt| < 1e-13; of several roots the one nearest [0, 1] wins, ties going to
 * the one nearest the previous sample's root), searched in [tMin, tMax] (which may exceed
 * [0, 1]: the surface is extended). Returns the curve as a SurfaceCurve in the parameter
 * space of the surface (so it lies on the blade exactly).
 *
 * `samples` (>= 2) is the initial count: where the interpolated curve strays from the
 * revolution surface between two nodes by more than 1e-10 of the curve's size (checked
 * at the midpoint), the exact root there is inserted, until none does (at most 4096
 * nodes), so every curve point is on the revolution surface, not only the nodes.
 * Closed sections (P(0, t) == P(1, t)) get the same t at s = 0 and s = 1, so the curve
 * closes exactly. Throws GeometryError naming the s where no intersection exists in the
 * range.
 *
 * The whole search is bounded: every curve evaluation of the meridional projections and
 * every evaluation of the distance is charged to `budget` (default: a fresh one of
 * IntersectionWorkLimit units per 64 initial samples, over 6 times what the Rotor 37 and
 * distributor blades need), and a GeometryError ends it when the budget is spent, so
 * kinked or spiky input fails in a fraction of a second.
 */
std::shared_ptr<SurfaceCurve> intersectWithRevolution(std::shared_ptr<const GordonSurface> surface,
  const SurfaceOfRevolution& revolution, double tMin = -0.5, double tMax = 1.5,
  int samples = 64, WorkBudget* budget = nullptr);

/// Work units intersectWithRevolution may spend by default (see there).
constexpr std::size_t IntersectionWorkLimit = 1000000;

/// Closest point of a surface to p, as its parameters (s, t): how offsetOnSurface maps the
/// offset points back onto the surface.
using SurfaceParameterFunction = std::function<Eigen::Vector2d(const Vec3& p)>;

/**
 * The offset of a curve lying on a surface, within that surface (the outer boundary of an
 * O-grid around a blade section on the hub): for each sample u of the curve, the point
 * P(u) + distance * n(u), where n = N x T / |N x T| is the unit normal of the curve in the
 * surface's tangent plane (N the surface normal Ps x Pt at P, T the curve tangent),
 * mapped back onto the surface by `toParameters`. The distance is thus measured in the
 * tangent plane: on a surface curved across the curve (a hub of radius r offset along
 * theta) the offset lies r atan(distance / r) away along the surface, 1 % short for
 * distance = r / 6. Returns the offset as (s, t) points of
 * the surface, in the order of u, to be interpolated (SurfaceCurve).
 *
 * `closed` curves (P(0) == P(1)) are offset outwards for distance > 0, whatever their
 * orientation (the sign of the flux of p - centroid through the loop along n decides, which
 * a sharp edge cannot fool), and the returned loop closes exactly (the seam normal is the
 * mean of the normals at u = 0 and 1). Open curves are offset towards +n.
 *
 * Where the curve bends with a radius of curvature below |distance| on the side it is
 * offset to (a sharp leading edge, the wiggles of a spline through a capped trailing
 * edge), the raw offset folds back in a swallowtail; the loop is cut out at the offset's
 * crossing, as the boundary of the region within the distance has it. Everywhere else
 * the offset points stay on the curve's normals.
 *
 * Sampling starts with 512 equal steps of u and halves every step across which the normal
 * turns by more than 3 degrees, so a leading edge whose radius is 1e-3 of the curve's
 * length is followed closely (up to 16 halvings per step and about 65536 samples in all;
 * past that the remaining steps are not refined). Deterministic.
 *
 * Throws GeometryError when |distance| is zero or not finite, when a `closed` curve's ends
 * do not meet, when the offset folds back without crossing itself nearby (the distance
 * is larger than the curve is wide: an inward offset past the middle), naming the
 * parameter u where it folds, when the tangent or the surface normal vanish, and when
 * the projections of the samples (`toParameters`, charged to the current WorkBudget)
 * need more than OffsetWorkLimit curve evaluations in all.
 */
std::vector<Eigen::Vector2d> offsetOnSurface(const Curve& curve, bool closed,
  const Surface& surface, const SurfaceParameterFunction& toParameters, double distance);

/// Work units offsetOnSurface may spend (see there).
constexpr std::size_t OffsetWorkLimit = 500000;
} // namespace blockforge
