#include "BSpline.h"
#include "CoreSupport.h"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace
{
using bspline::MaxDegree;
constexpr int MaxBasis = MaxDegree + 1;

using core::clampUnit;
using core::isFinite;
using core::format;

void requireDegree(int degree, const char* what)
{
  if (degree < 1 || degree > MaxDegree)
  {
    throw GeometryError(std::string(what) + ": degree " + std::to_string(degree) +
      " is outside the supported range 1.." + std::to_string(MaxDegree));
  }
}

void requireFinitePoints(const std::vector<Vec3>& points, const char* what)
{
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    if (!isFinite(points[i]))
    {
      throw GeometryError(std::string(what) + ": point " + std::to_string(i) +
        " has a non-finite coordinate " + format(points[i]));
    }
  }
}

/// Checks a clamped knot vector for `count` control points and maps it onto [0, 1]
/// (an affine change of parameter does not change the shape).
void validateKnots(int degree, std::vector<double>& knots, int count, const char* what)
{
  if (count < degree + 1)
  {
    throw GeometryError(std::string(what) + ": " + std::to_string(count) +
      " control points are too few for degree " + std::to_string(degree));
  }
  if (static_cast<int>(knots.size()) != count + degree + 1)
  {
    throw GeometryError(std::string(what) + ": expected " +
      std::to_string(count + degree + 1) + " knots for " + std::to_string(count) +
      " control points of degree " + std::to_string(degree) + ", got " +
      std::to_string(knots.size()));
  }
  for (std::size_t i = 0; i < knots.size(); ++i)
  {
    if (!std::isfinite(knots[i]))
    {
      throw GeometryError(std::string(what) + ": knot " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && knots[i] < knots[i - 1])
    {
      throw GeometryError(std::string(what) + ": the knots must not decrease (knot " +
        std::to_string(i) + ")");
    }
  }
  const double first = knots.front(), last = knots.back();
  if (!(last > first))
  {
    throw GeometryError(std::string(what) + ": all knots are equal");
  }
  for (int i = 1; i <= degree; ++i)
  {
    if (knots[i] != first || knots[knots.size() - 1 - i] != last)
    {
      throw GeometryError(std::string(what) +
        ": the knot vector must be clamped (first and last knots repeated degree+1 times)");
    }
  }
  for (int i = degree + 1; i < count; ++i)
  {
    int multiplicity = 1;
    while (i + multiplicity < count && knots[i + multiplicity] == knots[i])
    {
      ++multiplicity;
    }
    if (multiplicity > degree)
    {
      throw GeometryError(std::string(what) + ": interior knot " + format(knots[i]) +
        " is repeated more than degree times, which would break the curve");
    }
  }
  if (first != 0.0 || last != 1.0)
  {
    const double span = last - first;
    for (double& knot : knots)
    {
      knot = (knot - first) / span;
    }
    for (int i = 0; i <= degree; ++i)
    {
      knots[i] = 0.0;
      knots[knots.size() - 1 - i] = 1.0;
    }
  }
}

/**
 * Solves the collocation system N_j(params_k) x_j = rhs_k of global interpolation
 * (NURBS book A9.1). The matrix is banded (degree+1 non-zeros a row); a sparse LU keeps
 * the cost linear in the point count, and one step of iterative refinement recovers the
 * last digits lost to pivoting growth.
 */
Eigen::MatrixXd solveCollocation(const std::vector<double>& params,
  const std::vector<double>& knots, int degree, const Eigen::MatrixXd& rhs, const char* what)
{
  const int n = static_cast<int>(params.size());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(n) * (degree + 1));
  double basis[MaxBasis];
  for (int k = 0; k < n; ++k)
  {
    const int span = bspline::findSpan(degree, knots, n, params[k]);
    bspline::basisFunctions(span, params[k], degree, knots, basis);
    for (int j = 0; j <= degree; ++j)
    {
      if (basis[j] != 0.0)
      {
        entries.emplace_back(k, span - degree + j, basis[j]);
      }
    }
  }
  Eigen::SparseMatrix<double> matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  matrix.makeCompressed();

  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> solver;
  solver.compute(matrix);
  if (solver.info() != Eigen::Success)
  {
    throw GeometryError(std::string(what) +
      ": the interpolation system is singular (points too close together?)");
  }
  Eigen::MatrixXd solution = solver.solve(rhs);
  const Eigen::MatrixXd residual = rhs - matrix * solution;
  solution += solver.solve(residual);
  if (!solution.allFinite())
  {
    throw GeometryError(std::string(what) + ": the interpolation system could not be solved");
  }
  return solution;
}

/// Parameters of one row of points; false when the row has zero length (a collapsed
/// grid line, e.g. at a pole), which then must not take part in averaging.
bool rowParameters(const std::vector<Vec3>& points, ParameterMethod method,
  std::vector<double>& params)
{
  const std::size_t n = points.size();
  params.assign(n, 0.0);
  if (method == ParameterMethod::Uniform)
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      params[i] = static_cast<double>(i) / static_cast<double>(n - 1);
    }
    params[n - 1] = 1.0;
    return true;
  }
  double total = 0.0;
  for (std::size_t i = 1; i < n; ++i)
  {
    double step = (points[i] - points[i - 1]).norm();
    if (method == ParameterMethod::Centripetal)
    {
      step = std::sqrt(step);
    }
    total += step;
    params[i] = total;
  }
  if (!(total > 0.0))
  {
    return false;
  }
  for (std::size_t i = 1; i + 1 < n; ++i)
  {
    params[i] /= total;
  }
  params[n - 1] = 1.0;
  return true;
}
} // namespace

// =======================================================================================
namespace bspline
{
int findSpan(int degree, const std::vector<double>& knots, int controlPointCount, double t)
{
  const int n = controlPointCount - 1;
  if (t >= knots[n + 1])
  {
    return n;
  }
  if (t <= knots[degree])
  {
    return degree;
  }
  // knots[degree] < t < knots[n + 1]: exactly one span k has knots[k] <= t < knots[k + 1],
  // so any search finds the same one. Interpolated curves have nearly even knots: a guess
  // from t's place between the end knots is mostly right or one off (a binary search
  // costs a mispredicted branch per halving, a tenth of the evaluation of a cubic).
  const double first = knots[degree], range = knots[n + 1] - first;
  const double place = (t - first) / range * (n + 1 - degree);
  if (place >= 0.0 && place < n + 1 - degree)
  {
    int guess = degree + static_cast<int>(place);
    for (int step = 0; step < 3; ++step)
    {
      if (t < knots[guess])
      {
        --guess; // t > knots[degree]: stays >= degree
      }
      else if (t >= knots[guess + 1])
      {
        ++guess; // t < knots[n + 1]: stays <= n
      }
      else
      {
        return guess;
      }
    }
  }
  int low = degree, high = n + 1;
  int mid = (low + high) / 2;
  while (t < knots[mid] || t >= knots[mid + 1])
  {
    if (t < knots[mid])
    {
      high = mid;
    }
    else
    {
      low = mid;
    }
    mid = (low + high) / 2;
  }
  return mid;
}

/// At the ends of a clamped knot vector the triangular scheme yields 1 only up to
/// rounding (x * (1/x)); the exact value makes curves start and end exactly on their
/// first and last control points, which joins neighbouring entities without gaps.
static bool exactEndBasis(int span, double t, int degree, const std::vector<double>& knots,
  double* values)
{
  const int count = static_cast<int>(knots.size()) - degree - 1;
  if (span == degree && t <= knots[degree] && knots[0] == knots[degree])
  {
    std::fill(values, values + degree + 1, 0.0);
    values[0] = 1.0;
    return true;
  }
  if (span == count - 1 && t >= knots[count] && knots[count] == knots.back())
  {
    std::fill(values, values + degree + 1, 0.0);
    values[degree] = 1.0;
    return true;
  }
  return false;
}

namespace
{
/// Piegl & Tiller's algorithm A2.2; FixedDegree > 0 makes the degree a compile-time
/// constant (unrolled loops, the same operations in the same order, the same bits).
template <int FixedDegree>
void basisFunctionsOf(int span, double t, int degree, const std::vector<double>& knots,
  double* values)
{
  if (FixedDegree > 0)
  {
    degree = FixedDegree;
  }
  double left[MaxBasis], right[MaxBasis];
  values[0] = 1.0;
  for (int j = 1; j <= degree; ++j)
  {
    left[j] = t - knots[span + 1 - j];
    right[j] = knots[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r)
    {
      const double temp = values[r] / (right[r + 1] + left[j - r]);
      values[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    values[j] = saved;
  }
}
} // namespace

void basisFunctions(int span, double t, int degree, const std::vector<double>& knots,
  double* values)
{
  if (exactEndBasis(span, t, degree, knots, values))
  {
    return;
  }
  if (degree == 3)
  {
    basisFunctionsOf<3>(span, t, degree, knots, values);
  }
  else
  {
    basisFunctionsOf<0>(span, t, degree, knots, values);
  }
}

namespace
{
/**
 * Piegl & Tiller's algorithm A2.3. With FixedDegree > 0 the degree (FixedOrder > 0: the
 * order too) is a compile-time constant, so the compiler unrolls the loops (cubic
 * carriers are most of the evaluations of a template); the operations and their order
 * are the same, so are the results, bit for bit.
 */
template <int FixedDegree, int FixedOrder = 0, bool Inside = false>
void basisDerivativesOf(int span, double t, int degree, int order,
  const std::vector<double>& knots, double* ders)
{
  const int p = FixedDegree > 0 ? FixedDegree : degree;
  if (FixedOrder > 0)
  {
    order = FixedOrder;
  }
  const int width = p + 1;
  // ndu holds the basis functions (upper triangle) and knot differences (lower triangle).
  double ndu[MaxBasis][MaxBasis];
  double left[MaxBasis], right[MaxBasis];
  double a[2][MaxBasis];

  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j)
  {
    left[j] = t - knots[span + 1 - j];
    right[j] = knots[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r)
    {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j)
  {
    ders[j] = ndu[j][p];
  }

  const int computed = std::min(order, p);
  for (int r = 0; r <= p; ++r)
  {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= computed; ++k)
    {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k)
      {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j)
      {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk)
      {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k * width + r] = d;
      std::swap(s1, s2);
    }
  }
  double factor = p;
  for (int k = 1; k <= computed; ++k)
  {
    for (int j = 0; j <= p; ++j)
    {
      ders[k * width + j] *= factor;
    }
    factor *= (p - k);
  }
  for (int k = computed + 1; k <= order; ++k)
  {
    std::fill(ders + k * width, ders + (k + 1) * width, 0.0);
  }
  // Same exact end values as basisFunctions(), so point and derivatives agree bit for bit
  // (none strictly inside the end knots: Inside says the caller knows t is there).
  if (!Inside)
  {
    exactEndBasis(span, t, degree, knots, ders);
  }
}
} // namespace

void basisDerivatives(int span, double t, int degree, int order,
  const std::vector<double>& knots, double* ders)
{
  if (degree == 3 && order == 1)
  {
    basisDerivativesOf<3, 1>(span, t, degree, order, knots, ders); // arc lengths, tangents
  }
  else if (degree == 3 && order == 2)
  {
    basisDerivativesOf<3, 2>(span, t, degree, order, knots, ders); // projections' Newton steps
  }
  else if (degree == 3)
  {
    basisDerivativesOf<3>(span, t, degree, order, knots, ders);
  }
  else if (degree == 2 && order == 1)
  {
    basisDerivativesOf<2, 1>(span, t, degree, order, knots, ders); // curves through 3 points
  }
  else if (degree == 2 && order == 2)
  {
    basisDerivativesOf<2, 2>(span, t, degree, order, knots, ders);
  }
  else if (degree == 1 && order == 1)
  {
    basisDerivativesOf<1, 1>(span, t, degree, order, knots, ders); // lines in (s, t)
  }
  else
  {
    basisDerivativesOf<0>(span, t, degree, order, knots, ders);
  }
}

std::vector<double> interpolationParameters(const std::vector<Vec3>& points,
  ParameterMethod method)
{
  if (points.size() < 2)
  {
    throw GeometryError("interpolation needs at least 2 points, got " +
      std::to_string(points.size()));
  }
  requireFinitePoints(points, "interpolation");
  std::vector<double> params;
  if (!rowParameters(points, method, params))
  {
    throw GeometryError("interpolation: all " + std::to_string(points.size()) +
      " points coincide");
  }
  return params;
}

std::vector<double> averagedKnots(const std::vector<double>& parameters, int degree)
{
  requireDegree(degree, "knot averaging");
  const int n = static_cast<int>(parameters.size()) - 1;
  if (n < degree)
  {
    throw GeometryError("knot averaging: " + std::to_string(parameters.size()) +
      " parameters are too few for degree " + std::to_string(degree));
  }
  std::vector<double> knots(parameters.size() + degree + 1, 0.0);
  for (int j = 1; j <= n - degree; ++j)
  {
    // Summing each window afresh (instead of a sliding sum) keeps every knot accurate
    // to rounding, independent of its position.
    double sum = 0.0;
    for (int i = j; i < j + degree; ++i)
    {
      sum += parameters[i];
    }
    knots[j + degree] = sum / degree;
  }
  for (int i = 0; i <= degree; ++i)
  {
    knots[n + 1 + i] = 1.0;
  }
  return knots;
}
} // namespace bspline

// =======================================================================================
BSplineCurve::BSplineCurve(int degree, std::vector<double> knots,
  std::vector<Vec3> controlPoints)
  : Degree(degree)
  , Knots(std::move(knots))
  , ControlPoints(std::move(controlPoints))
{
  requireDegree(degree, "B-spline curve");
  validateKnots(degree, Knots, static_cast<int>(ControlPoints.size()), "B-spline curve");
  requireFinitePoints(ControlPoints, "B-spline curve control points");
  const int count = static_cast<int>(ControlPoints.size());
  const int bins = 4 * count;
  const double first = Knots[Degree], range = Knots[count] - first;
  SpanTable.resize(bins + 1);
  BinScale = bins / range;
  for (int bin = 0; bin <= bins; ++bin)
  {
    SpanTable[bin] = bspline::findSpan(Degree, Knots, count, first + range * bin / bins);
  }
}

int BSplineCurve::span(double t) const
{
  const int count = static_cast<int>(ControlPoints.size());
  const int n = count - 1;
  if (!(t > Knots[Degree] && t < Knots[n + 1]))
  {
    return bspline::findSpan(Degree, Knots, count, t); // ends, NaN
  }
  // Inside, exactly one span k has Knots[k] <= t < Knots[k + 1], the one the bisection
  // finds: the last one found if it still holds, else between the spans at the start of
  // t's bin and of the next bin (a step outside them only when rounding put t in a
  // neighbouring bin), by bisection between them (usually one or two spans).
  const int last = LastSpan.Span.load(std::memory_order_relaxed);
  if (last >= Degree && last <= n && Knots[last] <= t && t < Knots[last + 1])
  {
    return last;
  }
  const int bins = static_cast<int>(SpanTable.size()) - 1;
  const int bin = std::max(0, std::min(bins - 1, static_cast<int>((t - Knots[Degree]) * BinScale)));
  int low = SpanTable[bin], high = SpanTable[bin + 1];
  while (t < Knots[low])
  {
    --low;
  }
  while (t >= Knots[high + 1])
  {
    ++high;
  }
  while (low < high)
  {
    const int middle = (low + high + 1) / 2;
    if (Knots[middle] <= t)
    {
      low = middle;
    }
    else
    {
      high = middle - 1;
    }
  }
  LastSpan.Span.store(low, std::memory_order_relaxed);
  return low;
}

namespace
{
void requireInterpolationInput(const std::vector<Vec3>& points, int degree)
{
  if (points.size() < 2)
  {
    throw GeometryError("curve interpolation needs at least 2 points, got " +
      std::to_string(points.size()));
  }
  requireDegree(degree, "curve interpolation");
  requireFinitePoints(points, "curve interpolation");
}
} // namespace

BSplineCurve BSplineCurve::interpolate(const std::vector<Vec3>& points, int degree,
  ParameterMethod method)
{
  requireInterpolationInput(points, degree);
  const int count = static_cast<int>(points.size());

  // Coincidence is judged relative to the size of the point set, so that the check works
  // the same in metres and millimetres.
  Vec3 lower = points[0], upper = points[0];
  for (const Vec3& q : points)
  {
    lower = lower.cwiseMin(q);
    upper = upper.cwiseMax(q);
  }
  const double size = (upper - lower).norm();
  for (int i = 1; i < count; ++i)
  {
    const double gap = (points[i] - points[i - 1]).norm();
    if (!(gap > 1e-12 * size))
    {
      throw GeometryError("curve interpolation: points " + std::to_string(i - 1) + " and " +
        std::to_string(i) + " coincide at " + format(points[i]) +
        "; remove the duplicate point");
    }
  }

  return interpolateAt(points, bspline::interpolationParameters(points, method), degree);
}

BSplineCurve BSplineCurve::interpolateAt(const std::vector<Vec3>& points,
  const std::vector<double>& parameters, int degree)
{
  requireInterpolationInput(points, degree);
  const int count = static_cast<int>(points.size());
  if (parameters.size() != points.size())
  {
    throw GeometryError("curve interpolation: " + std::to_string(parameters.size()) +
      " parameters for " + std::to_string(count) + " points");
  }
  if (parameters.front() != 0.0 || parameters.back() != 1.0)
  {
    throw GeometryError("curve interpolation: the parameters must run from 0 to 1");
  }
  for (int i = 1; i < count; ++i)
  {
    if (!(parameters[i] > parameters[i - 1]))
    {
      throw GeometryError("curve interpolation: the parameters must increase strictly (" +
        std::to_string(parameters[i - 1]) + " then " + std::to_string(parameters[i]) + ")");
    }
  }
  const int usedDegree = std::min(degree, count - 1);
  std::vector<double> params = parameters;
  std::vector<double> knots = bspline::averagedKnots(params, usedDegree);

  Eigen::MatrixXd rhs(count, 3);
  for (int i = 0; i < count; ++i)
  {
    rhs.row(i) = points[i].transpose();
  }
  const Eigen::MatrixXd solution =
    solveCollocation(params, knots, usedDegree, rhs, "curve interpolation");
  std::vector<Vec3> control(count);
  for (int i = 0; i < count; ++i)
  {
    control[i] = solution.row(i).transpose();
  }
  control.front() = points.front();
  control.back() = points.back();

  BSplineCurve curve(usedDegree, std::move(knots), std::move(control));
  curve.DataParameters = std::move(params);
  return curve;
}

namespace
{
/// sum_j weights[j] * points[j], j = 0 .. degree, in that order (FixedDegree > 0: unrolled,
/// the same operations, the same bits).
template <int FixedDegree>
inline Vec3 weightedSum(const double* weights, const Vec3* points, int degree)
{
  if (FixedDegree > 0)
  {
    degree = FixedDegree;
  }
  Vec3 sum = Vec3::Zero();
  for (int j = 0; j <= degree; ++j)
  {
    sum += weights[j] * points[j];
  }
  return sum;
}
} // namespace

std::vector<double> BSplineCurve::breakpoints() const
{
  std::vector<double> inner;
  for (std::size_t i = Degree + 1; i + Degree + 1 < Knots.size(); ++i)
  {
    if (Knots[i] > Knots[Degree] && Knots[i] < Knots[Knots.size() - 1 - Degree] &&
      (inner.empty() || Knots[i] > inner.back()))
    {
      inner.push_back(Knots[i]);
    }
  }
  return inner;
}

Vec3 BSplineCurve::point(double t) const
{
  t = clampUnit(t);
  const int span = this->span(t);
  double basis[MaxBasis];
  if (cubicInside(t))
  {
    // strictly inside the end knots no end value is exact (exactEndBasis): the cubic
    // directly, as basisFunctions() would compute it (most evaluations of a template)
    bspline::basisFunctionsOf<3>(span, t, Degree, Knots, basis);
  }
  else
  {
    bspline::basisFunctions(span, t, Degree, Knots, basis);
  }
  const Vec3* points = &ControlPoints[span - Degree];
  return Degree == 3 ? weightedSum<3>(basis, points, Degree) : weightedSum<0>(basis, points, Degree);
}

void BSplineCurve::points(const double t[3], Vec3 out[3]) const
{
  int span = -1;
  for (int k = 0; k < 3; ++k)
  {
    const double x = clampUnit(t[k]);
    if (!cubicInside(x))
    {
      out[k] = point(t[k]);
      continue;
    }
    // inside, the one span k with Knots[k] <= x < Knots[k + 1] (span()'s answer)
    if (span < 0 || !(Knots[span] <= x && x < Knots[span + 1]))
    {
      span = this->span(x);
    }
    double basis[MaxBasis];
    bspline::basisFunctionsOf<3>(span, x, Degree, Knots, basis);
    out[k] = weightedSum<3>(basis, &ControlPoints[span - Degree], Degree);
  }
}

Vec3 BSplineCurve::derivative(double t, int order) const
{
  if (order <= 0)
  {
    return point(t);
  }
  if (order > Degree)
  {
    return Vec3::Zero();
  }
  Vec3 values[MaxBasis];
  derivatives(t, order, values);
  return values[order];
}

void BSplineCurve::derivatives(double t, int order, Vec3* out) const
{
  t = clampUnit(t);
  const int span = this->span(t);
  const int computed = std::min(order, Degree);
  double ders[MaxBasis * MaxBasis];
  if (computed == 1 && cubicInside(t))
  {
    // strictly inside the end knots (no exact end values): the unrolled cubic directly
    bspline::basisDerivativesOf<3, 1, true>(span, t, Degree, computed, Knots, ders);
  }
  else if (computed == 2 && cubicInside(t))
  {
    bspline::basisDerivativesOf<3, 2, true>(span, t, Degree, computed, Knots, ders);
  }
  else
  {
    bspline::basisDerivatives(span, t, Degree, computed, Knots, ders);
  }
  const int width = Degree + 1;
  const Vec3* points = &ControlPoints[span - Degree];
  for (int k = 0; k <= computed; ++k)
  {
    out[k] = Degree == 3 ? weightedSum<3>(ders + k * width, points, Degree)
                         : weightedSum<0>(ders + k * width, points, Degree);
  }
  for (int k = computed + 1; k <= order; ++k)
  {
    out[k] = Vec3::Zero();
  }
}

// =======================================================================================
BSplineSurface::BSplineSurface(int degreeS, int degreeT, std::vector<double> knotsS,
  std::vector<double> knotsT, int countS, int countT, std::vector<Vec3> controlPoints)
  : DegreeS(degreeS)
  , DegreeT(degreeT)
  , KnotsS(std::move(knotsS))
  , KnotsT(std::move(knotsT))
  , CountS(countS)
  , CountT(countT)
  , ControlPoints(std::move(controlPoints))
{
  requireDegree(degreeS, "B-spline surface (s direction)");
  requireDegree(degreeT, "B-spline surface (t direction)");
  if (countS < 2 || countT < 2 ||
    static_cast<long long>(countS) * countT != static_cast<long long>(ControlPoints.size()))
  {
    throw GeometryError("B-spline surface: " + std::to_string(ControlPoints.size()) +
      " control points do not form a " + std::to_string(countS) + " x " +
      std::to_string(countT) + " grid");
  }
  validateKnots(degreeS, KnotsS, countS, "B-spline surface (s direction)");
  validateKnots(degreeT, KnotsT, countT, "B-spline surface (t direction)");
  requireFinitePoints(ControlPoints, "B-spline surface control points");
}

BSplineSurface BSplineSurface::interpolate(const std::vector<Vec3>& grid, int countS,
  int countT, int degreeS, int degreeT, ParameterMethod method)
{
  if (countS < 2 || countT < 2)
  {
    throw GeometryError("surface interpolation needs at least 2 x 2 points, got " +
      std::to_string(countS) + " x " + std::to_string(countT));
  }
  if (static_cast<long long>(countS) * countT != static_cast<long long>(grid.size()))
  {
    throw GeometryError("surface interpolation: " + std::to_string(grid.size()) +
      " points do not form a " + std::to_string(countS) + " x " + std::to_string(countT) +
      " grid");
  }
  requireDegree(degreeS, "surface interpolation (s direction)");
  requireDegree(degreeT, "surface interpolation (t direction)");
  requireFinitePoints(grid, "surface interpolation");

  // Parameters averaged over all grid lines (NURBS book A9.4); collapsed lines, such as
  // a row shrunk to a pole, carry no information and are left out.
  auto averagedParameters = [&](int count, int lines, bool alongS) {
    std::vector<double> sum(count, 0.0), params;
    std::vector<Vec3> line(count);
    int used = 0;
    for (int l = 0; l < lines; ++l)
    {
      for (int i = 0; i < count; ++i)
      {
        line[i] = alongS ? grid[i + l * countS] : grid[l + i * countS];
      }
      if (rowParameters(line, method, params))
      {
        for (int i = 0; i < count; ++i)
        {
          sum[i] += params[i];
        }
        ++used;
      }
    }
    const char* direction = alongS ? "s" : "t";
    if (used == 0)
    {
      throw GeometryError(std::string("surface interpolation: every grid line in ") +
        direction + " has zero length");
    }
    for (int i = 1; i + 1 < count; ++i)
    {
      sum[i] /= used;
    }
    sum[0] = 0.0;
    sum[count - 1] = 1.0;
    for (int i = 1; i < count; ++i)
    {
      if (!(sum[i] > sum[i - 1]))
      {
        throw GeometryError(std::string("surface interpolation: grid lines ") +
          std::to_string(i - 1) + " and " + std::to_string(i) + " in " + direction +
          " coincide everywhere; remove the duplicate line");
      }
    }
    return sum;
  };
  const std::vector<double> paramsS = averagedParameters(countS, countT, true);
  const std::vector<double> paramsT = averagedParameters(countT, countS, false);
  const int usedDegreeS = std::min(degreeS, countS - 1);
  const int usedDegreeT = std::min(degreeT, countT - 1);
  std::vector<double> knotsS = bspline::averagedKnots(paramsS, usedDegreeS);
  std::vector<double> knotsT = bspline::averagedKnots(paramsT, usedDegreeT);

  // First every row in s (one right-hand side column per row and coordinate)...
  Eigen::MatrixXd rowsRhs(countS, 3 * countT);
  for (int j = 0; j < countT; ++j)
  {
    for (int i = 0; i < countS; ++i)
    {
      rowsRhs.block<1, 3>(i, 3 * j) = grid[i + j * countS].transpose();
    }
  }
  const Eigen::MatrixXd rows = solveCollocation(
    paramsS, knotsS, usedDegreeS, rowsRhs, "surface interpolation (s direction)");

  // ... then the resulting control points column by column in t.
  Eigen::MatrixXd columnsRhs(countT, 3 * countS);
  for (int j = 0; j < countT; ++j)
  {
    for (int i = 0; i < countS; ++i)
    {
      columnsRhs.block<1, 3>(j, 3 * i) = rows.block<1, 3>(i, 3 * j);
    }
  }
  const Eigen::MatrixXd columns = solveCollocation(
    paramsT, knotsT, usedDegreeT, columnsRhs, "surface interpolation (t direction)");

  std::vector<Vec3> control(grid.size());
  for (int j = 0; j < countT; ++j)
  {
    for (int i = 0; i < countS; ++i)
    {
      control[i + j * countS] = columns.block<1, 3>(j, 3 * i).transpose();
    }
  }
  // The corners are interpolated exactly by construction; keep them bit-identical.
  control[0] = grid[0];
  control[countS - 1] = grid[countS - 1];
  control[(countT - 1) * countS] = grid[(countT - 1) * countS];
  control[grid.size() - 1] = grid.back();

  return BSplineSurface(usedDegreeS, usedDegreeT, std::move(knotsS), std::move(knotsT),
    countS, countT, std::move(control));
}

Vec3 BSplineSurface::point(double s, double t) const
{
  s = clampUnit(s);
  t = clampUnit(t);
  const int spanS = bspline::findSpan(DegreeS, KnotsS, CountS, s);
  const int spanT = bspline::findSpan(DegreeT, KnotsT, CountT, t);
  double basisS[MaxBasis], basisT[MaxBasis];
  bspline::basisFunctions(spanS, s, DegreeS, KnotsS, basisS);
  bspline::basisFunctions(spanT, t, DegreeT, KnotsT, basisT);
  Vec3 result = Vec3::Zero();
  for (int l = 0; l <= DegreeT; ++l)
  {
    const Vec3* row = &ControlPoints[(spanS - DegreeS) + (spanT - DegreeT + l) * CountS];
    Vec3 rowSum = Vec3::Zero();
    for (int k = 0; k <= DegreeS; ++k)
    {
      rowSum += basisS[k] * row[k];
    }
    result += basisT[l] * rowSum;
  }
  return result;
}

void BSplineSurface::derivatives(double s, double t, SurfaceDerivatives& out) const
{
  s = clampUnit(s);
  t = clampUnit(t);
  const int spanS = bspline::findSpan(DegreeS, KnotsS, CountS, s);
  const int spanT = bspline::findSpan(DegreeT, KnotsT, CountT, t);
  // Rows beyond the degree are zero, so order 2 is always safe to request.
  double dersS[3 * MaxBasis], dersT[3 * MaxBasis];
  bspline::basisDerivatives(spanS, s, DegreeS, 2, KnotsS, dersS);
  bspline::basisDerivatives(spanT, t, DegreeT, 2, KnotsT, dersT);
  const int widthS = DegreeS + 1, widthT = DegreeT + 1;

  Vec3 d[3][3]; // d[a][b] = d^(a+b) P / ds^a dt^b, a + b <= 2
  for (auto& row : d)
  {
    for (Vec3& v : row)
    {
      v.setZero();
    }
  }
  for (int l = 0; l <= DegreeT; ++l)
  {
    const Vec3* row = &ControlPoints[(spanS - DegreeS) + (spanT - DegreeT + l) * CountS];
    Vec3 rowSum[3] = { Vec3::Zero(), Vec3::Zero(), Vec3::Zero() };
    for (int k = 0; k <= DegreeS; ++k)
    {
      for (int a = 0; a < 3; ++a)
      {
        rowSum[a] += dersS[a * widthS + k] * row[k];
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      for (int b = 0; a + b < 3; ++b)
      {
        d[a][b] += dersT[b * widthT + l] * rowSum[a];
      }
    }
  }
  out.P = d[0][0];
  out.Ps = d[1][0];
  out.Pt = d[0][1];
  out.Pss = d[2][0];
  out.Pst = d[1][1];
  out.Ptt = d[0][2];
}
} // namespace blockforge
