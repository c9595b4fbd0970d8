// Gordon surfaces (the blade): a transfinite blend of section curves and, for a network,
// of cross curves. Split from Carriers.cpp by surface kind.
#include "Carriers.h"
#include "CoreSupport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace blockforge
{
namespace
{
using core::clampUnit;
using core::format;

/// Blend values per direction kept on the stack during one evaluation; networks with
/// more nodes recompute them on the fly (still without allocating).
constexpr int StackNodes = 64;

// ---------------------------------------------------------------------------------------
// Curves continued beyond [0, 1] by their end tangent line. Carriers are extrapolated
// (blade past hub/shroud); B-spline curves clamp their parameter, which would leave a
// kink and a flat piece, whereas the tangent line keeps the surface C1.

/// Point of the curve, continued linearly outside [0, 1]. Inside, exactly curve.point(u).
Vec3 extendedCurvePoint(const Curve& curve, double u)
{
  const double inside = clampUnit(u);
  if (inside == u)
  {
    return curve.point(u);
  }
  return curve.point(inside) + (u - inside) * curve.derivative(inside, 1);
}

/// Point, first and (order 2) second derivative of the continued curve; B-splines from
/// one basis evaluation. The point and first derivative do not depend on `order`.
void extendedCurveJet(
  const Curve& curve, const BSplineCurve* spline, double u, Vec3 jet[3], int order = 2)
{
  const double inside = clampUnit(u);
  if (spline)
  {
    spline->derivatives(inside, order, jet);
  }
  else
  {
    jet[0] = curve.point(inside);
    jet[1] = curve.derivative(inside, 1);
    jet[2] = order >= 2 ? curve.derivative(inside, 2) : Vec3::Zero();
  }
  if (inside != u)
  {
    jet[0] += (u - inside) * jet[1];
    jet[2].setZero();
  }
}

// ---------------------------------------------------------------------------------------
// Blend functions.

/// Node interval of x: -1 left of the first node, n-1 at or right of the last node,
/// otherwise k with x_k <= x < x_{k+1}. Binary search, no allocation.
int locateInterval(const std::vector<double>& nodes, double x)
{
  const int n = static_cast<int>(nodes.size());
  if (x < nodes.front())
  {
    return -1;
  }
  if (x >= nodes.back())
  {
    return n - 1;
  }
  return static_cast<int>(std::upper_bound(nodes.begin(), nodes.end(), x) - nodes.begin()) - 1;
}

/// Lagrange polynomial L_i (paper eq. 5) at x and, for Order 2, its first two
/// derivatives (jet[0..Order]). The factors (x - x_k) / (x_i - x_k) are exactly 1 at
/// x = x_i and exactly 0 at the other nodes, so the surface passes through its curves bit
/// for bit. The value takes the same operations for either order (the same bits), so
/// point() and derivatives() agree; Order 0 skips the derivatives' work. Inline: point()
/// calls Order 0 per section, and a call costs as much as the value.
template <int Order>
inline void lagrangeJet(const std::vector<double>& nodes, int i, double x, double jet[])
{
  static_assert(Order == 0 || Order == 2, "values, or values and two derivatives");
  double p = 1.0, p1 = 0.0, p2 = 0.0;
  const double xi = nodes[i];
  for (int k = 0; k < static_cast<int>(nodes.size()); ++k)
  {
    if (k == i)
    {
      continue;
    }
    const double d = xi - nodes[k];
    const double q = (x - nodes[k]) / d;
    if (Order == 2)
    {
      // Product rule on (p, p', p'') * (q, q', 0); update from the highest order down.
      const double q1 = 1.0 / d;
      p2 = p2 * q + 2.0 * p1 * q1;
      p1 = p1 * q + p * q1;
    }
    p = p * q;
  }
  jet[0] = p;
  if (Order == 2)
  {
    jet[1] = p1;
    jet[2] = p2;
  }
}

/**
 * Natural cubic spline through (x_k, delta_jk): coefficients (a, b, c, d) per interval,
 * then the slope at the last node. Natural end conditions (zero second derivative) make
 * the linear continuation C2 and reproduce linear data exactly; the tridiagonal system is
 * diagonally dominant, so the Thomas algorithm is stable without pivoting.
 */
std::vector<double> naturalCardinalSpline(const std::vector<double>& x, int j)
{
  const int n = static_cast<int>(x.size());
  std::vector<double> y(n, 0.0), m(n, 0.0);
  y[j] = 1.0;
  if (n > 2)
  {
    const int unknowns = n - 2;
    std::vector<double> diagonal(unknowns), upper(unknowns), rhs(unknowns);
    for (int k = 1; k <= n - 2; ++k)
    {
      const double h0 = x[k] - x[k - 1], h1 = x[k + 1] - x[k];
      diagonal[k - 1] = 2.0 * (h0 + h1);
      upper[k - 1] = h1;
      rhs[k - 1] = 6.0 * ((y[k + 1] - y[k]) / h1 - (y[k] - y[k - 1]) / h0);
    }
    // Forward elimination (sub-diagonal entry of row k is h_{k-1} = x[k] - x[k-1]).
    for (int r = 1; r < unknowns; ++r)
    {
      const double lower = x[r + 1] - x[r];
      const double factor = lower / diagonal[r - 1];
      diagonal[r] -= factor * upper[r - 1];
      rhs[r] -= factor * rhs[r - 1];
    }
    m[n - 2] = rhs[unknowns - 1] / diagonal[unknowns - 1];
    for (int r = unknowns - 2; r >= 0; --r)
    {
      m[r + 1] = (rhs[r] - upper[r] * m[r + 2]) / diagonal[r];
    }
  }
  std::vector<double> coefficients(4 * (n - 1) + 1);
  for (int k = 0; k + 1 < n; ++k)
  {
    const double h = x[k + 1] - x[k];
    coefficients[4 * k + 0] = y[k]; // exactly 0 or 1: the blend is exact at the nodes
    coefficients[4 * k + 1] = (y[k + 1] - y[k]) / h - h * (2.0 * m[k] + m[k + 1]) / 6.0;
    coefficients[4 * k + 2] = 0.5 * m[k];
    coefficients[4 * k + 3] = (m[k + 1] - m[k]) / (6.0 * h);
  }
  const double h = x[n - 1] - x[n - 2];
  coefficients[4 * (n - 1)] = (y[n - 1] - y[n - 2]) / h + h * (m[n - 2] + 2.0 * m[n - 1]) / 6.0;
  return coefficients;
}

/// Cardinal spline j at x in node interval k (from locateInterval), linear beyond the
/// ends: jet[0..Order] = value and, for Order 2, its first two derivatives. The value takes
/// the same operations for either order (the same bits).
template <int Order>
inline void splineJet(const std::vector<double>& nodes, const std::vector<double>& coefficients,
  int j, int k, double x, double jet[])
{
  static_assert(Order == 0 || Order == 2, "values, or values and two derivatives");
  const int n = static_cast<int>(nodes.size());
  if (k < 0 || k >= n - 1)
  {
    const bool left = k < 0;
    const double value = (left ? j == 0 : j == n - 1) ? 1.0 : 0.0;
    const double slope = left ? coefficients[1] : coefficients[4 * (n - 1)];
    jet[0] = value + slope * (x - (left ? nodes.front() : nodes.back()));
    if (Order == 2)
    {
      jet[1] = slope;
      jet[2] = 0.0;
    }
    return;
  }
  const double* c = &coefficients[4 * k];
  const double h = x - nodes[k];
  jet[0] = c[0] + h * (c[1] + h * (c[2] + h * c[3]));
  if (Order == 2)
  {
    jet[1] = c[1] + h * (2.0 * c[2] + 3.0 * h * c[3]);
    jet[2] = 2.0 * c[2] + 6.0 * h * c[3];
  }
}

/**
 * One direction's blend functions bound to an evaluation point: the interval search is
 * done once, the values of up to StackNodes functions are cached on the stack. Order 0
 * keeps the values alone (point() and crossPoints(): a third of the cost), Order 2 the
 * values and two derivatives (derivatives()); the values are the same bits in both.
 */
template <int Order>
class BlendAt
{
public:
  static constexpr int Width = Order + 1; ///< doubles per blend function

  BlendAt(GordonSurface::Blending blending, const std::vector<double>& nodes,
    const std::vector<std::vector<double>>& coefficients, double x)
    : Blending(blending)
    , Nodes(nodes)
    , Coefficients(coefficients)
    , X(x)
    , Interval(nodes.empty() ? 0 : locateInterval(nodes, x))
    , Cached(static_cast<int>(nodes.size()) <= StackNodes)
  {
    if (Cached)
    {
      for (int i = 0; i < static_cast<int>(nodes.size()); ++i)
      {
        compute(i, &Values[Width * i]);
      }
    }
  }

  /// out[0..Order] = value and (Order 2) first and second derivative of blend i.
  void jet(int i, double out[]) const
  {
    if (Cached)
    {
      std::copy_n(&Values[Width * i], Width, out);
    }
    else
    {
      compute(i, out);
    }
  }
  double value(int i) const
  {
    if (Cached)
    {
      return Values[Width * i];
    }
    double out[Width];
    compute(i, out);
    return out[0];
  }

private:
  void compute(int i, double out[]) const
  {
    if (Blending == GordonSurface::Blending::Lagrange)
    {
      lagrangeJet<Order>(Nodes, i, X, out);
    }
    else
    {
      splineJet<Order>(Nodes, Coefficients[i], i, Interval, X, out);
    }
  }

  GordonSurface::Blending Blending;
  const std::vector<double>& Nodes;
  const std::vector<std::vector<double>>& Coefficients;
  double X;
  int Interval;
  bool Cached;
  std::array<double, Width * StackNodes> Values;
};
using BlendValues = BlendAt<0>;
using BlendJets = BlendAt<2>;
} // namespace

namespace
{
void requireNodes(const std::vector<double>& nodes, const char* what)
{
  for (std::size_t k = 0; k < nodes.size(); ++k)
  {
    if (!std::isfinite(nodes[k]))
    {
      throw GeometryError(std::string("Gordon surface: ") + what + " " + std::to_string(k) +
        " is not finite");
    }
    if (k > 0 && !(nodes[k] > nodes[k - 1]))
    {
      throw GeometryError(std::string("Gordon surface: ") + what + "s must increase strictly (" +
        what + " " + std::to_string(k - 1) + " = " + format(nodes[k - 1]) + ", " + what + " " +
        std::to_string(k) + " = " + format(nodes[k]) + ")");
    }
  }
}

void requireCurves(const std::vector<CurvePtr>& curves, const char* what)
{
  for (std::size_t k = 0; k < curves.size(); ++k)
  {
    if (!curves[k])
    {
      throw GeometryError(std::string("Gordon surface: ") + what + " " + std::to_string(k) +
        " is missing");
    }
  }
}
} // namespace

GordonSurface GordonSurface::fromSections(std::vector<CurvePtr> sections,
  std::vector<double> sectionParameters, Blending blending)
{
  if (sections.size() < 2)
  {
    throw GeometryError("Gordon surface: lofting needs at least 2 sections, got " +
      std::to_string(sections.size()));
  }
  if (sections.size() != sectionParameters.size())
  {
    throw GeometryError("Gordon surface: " + std::to_string(sections.size()) + " sections but " +
      std::to_string(sectionParameters.size()) + " section parameters");
  }
  requireCurves(sections, "section");
  requireNodes(sectionParameters, "section parameter");
  const double first = sectionParameters.front(), last = sectionParameters.back();
  if (first != 0.0 || last != 1.0)
  {
    for (double& t : sectionParameters)
    {
      t = (t - first) / (last - first);
    }
    sectionParameters.front() = 0.0;
    sectionParameters.back() = 1.0;
    requireNodes(sectionParameters, "section parameter"); // still distinct after scaling
  }
  GordonSurface surface;
  surface.SCurves = std::move(sections);
  surface.TNodes = std::move(sectionParameters);
  surface.TheBlending = blending;
  surface.prepare();
  return surface;
}

GordonSurface GordonSurface::fromNetwork(std::vector<CurvePtr> sCurves,
  std::vector<double> tNodes, std::vector<CurvePtr> tCurves, std::vector<double> sNodes,
  Blending blending)
{
  if (sCurves.size() < 2 || tCurves.size() < 2)
  {
    throw GeometryError("Gordon surface: a network needs at least 2 curves in each direction, "
                        "got " +
      std::to_string(sCurves.size()) + " s-curves and " + std::to_string(tCurves.size()) +
      " t-curves");
  }
  if (sCurves.size() != tNodes.size() || tCurves.size() != sNodes.size())
  {
    throw GeometryError("Gordon surface: every s-curve needs one t node and every t-curve one s "
                        "node (" +
      std::to_string(sCurves.size()) + " s-curves, " + std::to_string(tNodes.size()) +
      " t nodes, " + std::to_string(tCurves.size()) + " t-curves, " +
      std::to_string(sNodes.size()) + " s nodes)");
  }
  requireCurves(sCurves, "s-curve");
  requireCurves(tCurves, "t-curve");
  requireNodes(tNodes, "t node");
  requireNodes(sNodes, "s node");
  // The nodes are parameters of the crossing curves, so they cannot be rescaled.
  for (const std::vector<double>* nodes : { &tNodes, &sNodes })
  {
    if (nodes->front() < 0.0 || nodes->back() > 1.0)
    {
      throw GeometryError(std::string("Gordon surface: the ") +
        (nodes == &tNodes ? "t" : "s") + " nodes must lie in [0, 1] (they are parameters of "
        "the crossing curves), got " + format(nodes->front()) + " .. " + format(nodes->back()));
    }
  }

  GordonSurface surface;
  surface.SCurves = std::move(sCurves);
  surface.TCurves = std::move(tCurves);
  surface.TNodes = std::move(tNodes);
  surface.SNodes = std::move(sNodes);
  surface.TheBlending = blending;
  surface.prepare();

  // Compatibility: C_j(s_i) must be D_i(t_j); the tolerance is relative to the network's
  // size (as for Coons patches).
  const int m = static_cast<int>(surface.SNodes.size());
  const int n = static_cast<int>(surface.TNodes.size());
  Vec3 lower = surface.NodePoints.front(), upper = lower;
  for (const Vec3& q : surface.NodePoints)
  {
    lower = lower.cwiseMin(q);
    upper = upper.cwiseMax(q);
  }
  const double size = (upper - lower).norm();
  const double tolerance = 1e-9 * (size > 0.0 ? size : 1.0);
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < m; ++i)
    {
      const Vec3 fromT = extendedCurvePoint(*surface.TCurves[i], surface.TNodes[j]);
      const double gap = (fromT - surface.NodePoints[i + j * m]).norm();
      if (!(gap <= tolerance))
      {
        std::ostringstream s;
        s.precision(6);
        s << "Gordon surface: s-curve " << j << " (t = " << surface.TNodes[j] << ") and t-curve "
          << i << " (s = " << surface.SNodes[i] << ") do not meet: mismatch " << gap
          << " (tolerance " << tolerance << ")";
        throw GeometryError(s.str());
      }
    }
  }
  return surface;
}

void GordonSurface::prepare()
{
  if (TheBlending != Blending::Lagrange && TheBlending != Blending::Spline)
  {
    throw GeometryError("Gordon surface: unknown blending");
  }
  SSplines.clear();
  TSplines.clear();
  for (const CurvePtr& c : SCurves)
  {
    SSplines.push_back(dynamic_cast<const BSplineCurve*>(c.get()));
  }
  for (const CurvePtr& c : TCurves)
  {
    TSplines.push_back(dynamic_cast<const BSplineCurve*>(c.get()));
  }
  TBlendCoefficients.clear();
  SBlendCoefficients.clear();
  if (TheBlending == Blending::Spline)
  {
    for (int j = 0; j < static_cast<int>(TNodes.size()); ++j)
    {
      TBlendCoefficients.push_back(naturalCardinalSpline(TNodes, j));
    }
    for (int i = 0; i < static_cast<int>(SNodes.size()); ++i)
    {
      SBlendCoefficients.push_back(naturalCardinalSpline(SNodes, i));
    }
  }
  // Breakpoints: the blend nodes and the ends. Not the knots of the curves: the sections
  // of a blade each have their own (Rotor 37: 6 x 298), and a curve across the blade
  // would be cut at all of them; where one matters, the arc-length table halves the piece.
  for (const bool tDirection : { false, true })
  {
    std::vector<double> points{ 0.0, 1.0 };
    if (TheBlending == Blending::Spline)
    {
      const std::vector<double>& nodes = tDirection ? TNodes : SNodes;
      points.insert(points.end(), nodes.begin(), nodes.end());
    }
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
    (tDirection ? TBreakpoints : SBreakpoints) = std::move(points);
  }
  // Same evaluation as in point(), so that C_j(s_i) - Q_ij vanishes exactly at s = s_i.
  NodePoints.clear();
  for (std::size_t j = 0; j < SCurves.size(); ++j)
  {
    for (double s : SNodes)
    {
      NodePoints.push_back(extendedCurvePoint(*SCurves[j], s));
    }
  }
}

void GordonSurface::blend(bool tDirection, int index, double x, double jet[3]) const
{
  const std::vector<double>& nodes = tDirection ? TNodes : SNodes;
  if (index < 0 || index >= static_cast<int>(nodes.size()))
  {
    throw GeometryError("Gordon surface: blend function " + std::to_string(index) +
      " does not exist");
  }
  if (TheBlending == Blending::Lagrange)
  {
    lagrangeJet<2>(nodes, index, x, jet);
  }
  else
  {
    splineJet<2>(nodes, (tDirection ? TBlendCoefficients : SBlendCoefficients)[index], index,
      locateInterval(nodes, x), x, jet);
  }
}

// The network form is evaluated grouped as
//   P = sum_j B_j(t) [C_j(s) - sum_i A_i(s) Q_ij] + sum_i A_i(s) D_i(t),
// which equals eq. 4 and makes the bracket vanish exactly at s = s_i (A_i = delta), so
// the surface reproduces its t-curves bit for bit (as the Coons patch does its sides).
// For lofts there are no t-curves and P = sum_j B_j(t) C_j(s).
Vec3 GordonSurface::point(double s, double t) const
{
  const int n = static_cast<int>(TNodes.size());
  const int m = static_cast<int>(SNodes.size());
  const BlendValues b(TheBlending, TNodes, TBlendCoefficients, t);
  const BlendValues a(TheBlending, SNodes, SBlendCoefficients, s);
  Vec3 result = Vec3::Zero();
  for (int j = 0; j < n; ++j)
  {
    const double bj = b.value(j);
    if (bj == 0.0)
    {
      continue; // at a node: the other sections do not contribute at all
    }
    Vec3 bracket = extendedCurvePoint(*SCurves[j], s);
    for (int i = 0; i < m; ++i)
    {
      bracket -= a.value(i) * NodePoints[i + j * m];
    }
    result += bj * bracket;
  }
  for (int i = 0; i < m; ++i)
  {
    const double ai = a.value(i);
    if (ai != 0.0)
    {
      result += ai * extendedCurvePoint(*TCurves[i], t);
    }
  }
  return result;
}

// point() at the five parameters, each section and t-curve evaluated once per parameter
// it is needed at; every sum runs in point()'s order, so the bits are point()'s.
void GordonSurface::crossPoints(double s, double sPlus, double sMinus, double t, double tPlus,
  double tMinus, Vec3 out[5]) const
{
  const int n = static_cast<int>(TNodes.size());
  const int m = static_cast<int>(SNodes.size());
  const double sAt[3] = { s, sPlus, sMinus };
  const double tAt[3] = { t, tPlus, tMinus };
  const bool inside = sAt[0] >= 0.0 && sAt[0] <= 1.0 && sAt[1] >= 0.0 && sAt[1] <= 1.0 &&
    sAt[2] >= 0.0 && sAt[2] <= 1.0;
  if (m == 0 && inside && TheBlending == Blending::Spline && n <= StackNodes)
  {
    // A loft of sections (a blade) at s inside [0, 1]: the sums below in the same order
    // (section j's three points, each t's blends), the node interval of t found once for
    // the three t when they share it (locateInterval's answer, the interval holding t).
    double blend[3][StackNodes];
    int interval = -1;
    for (int q = 0; q < 3; ++q)
    {
      const double x = tAt[q];
      if (!(q > 0 && interval >= 0 && interval < n - 1 && TNodes[interval] <= x &&
            x < TNodes[interval + 1]))
      {
        interval = locateInterval(TNodes, x);
      }
      for (int j = 0; j < n; ++j)
      {
        splineJet<0>(TNodes, TBlendCoefficients[j], j, interval, x, &blend[q][j]);
      }
    }
    for (int k = 0; k < 5; ++k)
    {
      out[k].setZero();
    }
    for (int j = 0; j < n; ++j)
    {
      Vec3 section[3];
      if (SSplines[j])
      {
        SSplines[j]->points(sAt, section);
      }
      else
      {
        for (int q = 0; q < 3; ++q)
        {
          section[q] = SCurves[j]->point(sAt[q]); // extendedCurvePoint inside [0, 1]
        }
      }
      const double b0 = blend[0][j], b1 = blend[1][j], b2 = blend[2][j];
      if (b0 != 0.0)
      {
        out[0] += b0 * section[0];
        out[1] += b0 * section[1];
        out[2] += b0 * section[2];
      }
      if (b1 != 0.0)
      {
        out[3] += b1 * section[0];
      }
      if (b2 != 0.0)
      {
        out[4] += b2 * section[0];
      }
    }
    return;
  }
  const BlendValues b[3] = { { TheBlending, TNodes, TBlendCoefficients, t },
    { TheBlending, TNodes, TBlendCoefficients, tPlus },
    { TheBlending, TNodes, TBlendCoefficients, tMinus } };
  const BlendValues a[3] = { { TheBlending, SNodes, SBlendCoefficients, s },
    { TheBlending, SNodes, SBlendCoefficients, sPlus },
    { TheBlending, SNodes, SBlendCoefficients, sMinus } };
  static const int at[5][2] = { { 0, 0 }, { 1, 0 }, { 2, 0 }, { 0, 1 }, { 0, 2 } }; // (s, t)
  for (int k = 0; k < 5; ++k)
  {
    out[k].setZero();
  }
  for (int j = 0; j < n; ++j)
  {
    Vec3 bracket[3];
    bool have[3] = { false, false, false };
    // A B-spline section inside [0, 1]: its three points at once (extendedCurvePoint is
    // its point() there; one not needed below is computed and left).
    Vec3 section[3];
    const bool together = inside && SSplines[j];
    if (together)
    {
      SSplines[j]->points(sAt, section);
    }
    for (int k = 0; k < 5; ++k)
    {
      const int si = at[k][0];
      const double bj = b[at[k][1]].value(j);
      if (bj == 0.0)
      {
        continue;
      }
      if (!have[si])
      {
        bracket[si] = together ? section[si] : extendedCurvePoint(*SCurves[j], sAt[si]);
        for (int i = 0; i < m; ++i)
        {
          bracket[si] -= a[si].value(i) * NodePoints[i + j * m];
        }
        have[si] = true;
      }
      out[k] += bj * bracket[si];
    }
  }
  for (int i = 0; i < m; ++i)
  {
    Vec3 curve[3];
    bool have[3] = { false, false, false };
    for (int k = 0; k < 5; ++k)
    {
      const int ti = at[k][1];
      const double ai = a[at[k][0]].value(i);
      if (ai == 0.0)
      {
        continue;
      }
      if (!have[ti])
      {
        curve[ti] = extendedCurvePoint(*TCurves[i], tAt[ti]);
        have[ti] = true;
      }
      out[k] += ai * curve[ti];
    }
  }
}

void GordonSurface::derivatives(double s, double t, SurfaceDerivatives& out) const
{
  const int n = static_cast<int>(TNodes.size());
  const int m = static_cast<int>(SNodes.size());
  const BlendJets b(TheBlending, TNodes, TBlendCoefficients, t);
  const BlendJets a(TheBlending, SNodes, SBlendCoefficients, s);
  out.P = out.Ps = out.Pt = out.Pss = out.Pst = out.Ptt = Vec3::Zero();
  Vec3 c[3];
  double bj[3], ai[3];
  for (int j = 0; j < n; ++j)
  {
    b.jet(j, bj);
    extendedCurveJet(*SCurves[j], SSplines[j], s, c);
    for (int i = 0; i < m; ++i)
    {
      a.jet(i, ai);
      const Vec3& q = NodePoints[i + j * m];
      c[0] -= ai[0] * q;
      c[1] -= ai[1] * q;
      c[2] -= ai[2] * q;
    }
    out.P += bj[0] * c[0];
    out.Ps += bj[0] * c[1];
    out.Pss += bj[0] * c[2];
    out.Pt += bj[1] * c[0];
    out.Ptt += bj[2] * c[0];
    out.Pst += bj[1] * c[1];
  }
  for (int i = 0; i < m; ++i)
  {
    a.jet(i, ai);
    extendedCurveJet(*TCurves[i], TSplines[i], t, c);
    out.P += ai[0] * c[0];
    out.Ps += ai[1] * c[0];
    out.Pss += ai[2] * c[0];
    out.Pt += ai[0] * c[1];
    out.Ptt += ai[0] * c[2];
    out.Pst += ai[1] * c[1];
  }
}

// The same sums as derivatives() without the second-order ones.
void GordonSurface::firstDerivatives(double s, double t, Vec3& P, Vec3& Ps, Vec3& Pt) const
{
  const int n = static_cast<int>(TNodes.size());
  const int m = static_cast<int>(SNodes.size());
  const BlendJets b(TheBlending, TNodes, TBlendCoefficients, t);
  const BlendJets a(TheBlending, SNodes, SBlendCoefficients, s);
  P = Ps = Pt = Vec3::Zero();
  Vec3 c[3];
  double bj[3], ai[3];
  for (int j = 0; j < n; ++j)
  {
    b.jet(j, bj);
    extendedCurveJet(*SCurves[j], SSplines[j], s, c, 1);
    for (int i = 0; i < m; ++i)
    {
      a.jet(i, ai);
      const Vec3& q = NodePoints[i + j * m];
      c[0] -= ai[0] * q;
      c[1] -= ai[1] * q;
    }
    P += bj[0] * c[0];
    Ps += bj[0] * c[1];
    Pt += bj[1] * c[0];
  }
  for (int i = 0; i < m; ++i)
  {
    a.jet(i, ai);
    extendedCurveJet(*TCurves[i], TSplines[i], t, c, 1);
    P += ai[0] * c[0];
    Ps += ai[1] * c[0];
    Pt += ai[0] * c[1];
  }
}
} // namespace blockforge
