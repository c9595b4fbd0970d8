/**
 * @file BSpline.h
 * @brief B-spline curves and tensor-product surfaces of any degree (paper eqs. 1-2),
 * with derivatives and global interpolation through ordered points.
 *
 * Knot vectors are clamped and normalised to [0, 1]. Basis functions follow the
 * Cox-de Boor recursion (paper eq. 2), evaluated with the numerically stable triangular
 * scheme of Piegl & Tiller (The NURBS Book, A2.2/A2.3).
 */
#pragma once

#include "Curve.h"
#include "Surface.h"

#include <atomic>

namespace blockforge
{
/// How interpolation parameters are assigned to the data points.
enum class ParameterMethod
{
  Uniform,     ///< equally spaced
  ChordLength, ///< proportional to the distance between successive points
  Centripetal  ///< proportional to the square root of that distance (Lee 1989)
};

namespace bspline
{
/// Highest supported degree: evaluation uses fixed-size stack buffers of this size + 1.
constexpr int MaxDegree = 15;

/// Index of the knot span containing t (p <= span <= n), with t = 1 in the last span.
int findSpan(int degree, const std::vector<double>& knots, int controlPointCount, double t);
/// The degree+1 non-zero basis functions at t in knot span `span`.
void basisFunctions(int span, double t, int degree, const std::vector<double>& knots,
  double* values);
/// Basis functions and their derivatives up to `order`: ders[k][j], k = 0..order,
/// j = 0..degree, stored row-major in `ders` ((order+1) x (degree+1)).
void basisDerivatives(int span, double t, int degree, int order,
  const std::vector<double>& knots, double* ders);
/// Parameters in [0, 1] for interpolating `points` (first 0, last 1, non-decreasing).
std::vector<double> interpolationParameters(const std::vector<Vec3>& points, ParameterMethod);
/// Clamped knot vector by averaging the parameters (NURBS book eq. 9.8).
std::vector<double> averagedKnots(const std::vector<double>& parameters, int degree);
} // namespace bspline

/**
 * @class BSplineCurve
 * @brief Non-rational B-spline curve of arbitrary degree, t in [0, 1].
 */
class BSplineCurve : public Curve
{
public:
  BSplineCurve(int degree, std::vector<double> knots, std::vector<Vec3> controlPoints);

  /**
   * Global interpolation: the curve passes through every point, in order, at the
   * parameters of `method`. The degree is lowered to points.size()-1 when there are too
   * few points. Throws GeometryError for fewer than 2 points, non-finite coordinates or
   * coincident consecutive points.
   */
  static BSplineCurve interpolate(const std::vector<Vec3>& points, int degree = 3,
    ParameterMethod method = ParameterMethod::ChordLength);

  /**
   * Global interpolation at given parameters: the curve passes through points[k] at
   * parameters[k] (strictly increasing from 0 to 1, one per point). Used to give curves a
   * common parametrisation (blade sections with the leading edge at 0.25 and the
   * trailing edge at 0.75). Throws GeometryError as interpolate() does, and for parameters that are
   * not one per point, not strictly increasing or not from 0 to 1.
   */
  static BSplineCurve interpolateAt(const std::vector<Vec3>& points,
    const std::vector<double>& parameters, int degree = 3);

  Vec3 point(double t) const override;
  /// point() at three parameters (a point and its neighbours in a finite difference), the
  /// same bits, with the span looked up once where they share it.
  void points(const double t[3], Vec3 out[3]) const;
  Vec3 derivative(double t, int order = 1) const override;
  /// Point and derivatives up to `order`: out[0] = P(t), out[k] = d^k P / dt^k.
  void derivatives(double t, int order, Vec3* out) const;
  /// The distinct interior knots.
  std::vector<double> breakpoints() const override;

  int degree() const { return Degree; }
  const std::vector<double>& knots() const { return Knots; }
  const std::vector<Vec3>& controlPoints() const { return ControlPoints; }
  /// Parameters at which interpolate() put the data points (empty otherwise).
  const std::vector<double>& dataParameters() const { return DataParameters; }

private:
  /// findSpan(Degree, Knots, count, t), from SpanTable: the same result, faster.
  int span(double t) const;
  /// A cubic strictly inside its end knots, where no basis value is an exact end value
  /// (exactEndBasis): the cubic basis can be evaluated directly, the same bits.
  bool cubicInside(double t) const
  {
    return Degree == 3 && t > Knots[3] && t < Knots[ControlPoints.size()];
  }
  int Degree;
  std::vector<double> Knots;
  /// The span at the start of each of SpanTable.size() - 1 equal bins of
  /// [Knots[Degree], Knots[count]] (spans of curves on blades are uneven: crowded at the edges).
  std::vector<int> SpanTable;
  double BinScale = 0.0; ///< bins per unit of t
  std::vector<Vec3> ControlPoints;
  std::vector<double> DataParameters;
  /**
   * The span of the last evaluation, tried first: evaluations come in runs along the
   * curve (arc-length tables, projections). Only a hint, shared by threads without order
   * (relaxed atomic), written only when it changes: the span found is the same either
   * way. On a cache line of its own: threads of a chunked loop evaluating different parts
   * of one curve write it in turn, and with the curve's data on the same line every
   * such write made the other threads fetch the data again.
   */
  struct alignas(64) SpanHint
  {
    SpanHint() = default;
    SpanHint(const SpanHint& other) : Span(other.Span.load(std::memory_order_relaxed)) {}
    SpanHint& operator=(const SpanHint& other)
    {
      Span.store(other.Span.load(std::memory_order_relaxed), std::memory_order_relaxed);
      return *this;
    }
    mutable std::atomic<int> Span{ -1 };
  };
  SpanHint LastSpan;
};

/**
 * @class BSplineSurface
 * @brief Tensor-product B-spline surface P(s, t) (paper eq. 1), any degree in each
 * direction. Control points are stored with s varying fastest: index i + j * countS.
 */
class BSplineSurface : public Surface
{
public:
  BSplineSurface(int degreeS, int degreeT, std::vector<double> knotsS,
    std::vector<double> knotsT, int countS, int countT, std::vector<Vec3> controlPoints);

  /**
   * Interpolates a grid of points (countS x countT, s fastest): first each row in s, then
   * the resulting control points in t, with parameters averaged over rows/columns.
   */
  static BSplineSurface interpolate(const std::vector<Vec3>& grid, int countS, int countT,
    int degreeS = 3, int degreeT = 3, ParameterMethod method = ParameterMethod::ChordLength);

  Vec3 point(double s, double t) const override;
  void derivatives(double s, double t, SurfaceDerivatives& out) const override;

  int degreeS() const { return DegreeS; }
  int degreeT() const { return DegreeT; }
  int countS() const { return CountS; }
  int countT() const { return CountT; }
  const std::vector<double>& knotsS() const { return KnotsS; }
  const std::vector<double>& knotsT() const { return KnotsT; }
  const std::vector<Vec3>& controlPoints() const { return ControlPoints; }

private:
  int DegreeS, DegreeT;
  std::vector<double> KnotsS, KnotsT;
  int CountS, CountT;
  std::vector<Vec3> ControlPoints;
};
} // namespace blockforge
