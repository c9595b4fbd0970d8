/**
 * @file SurfaceFaceGrid.cpp
 * @brief Face grids on parametric surfaces: projected TFI guarded by an even-metric
 * parameter TFI (see SurfaceFaceGrid.h).
 */
#include "SurfaceFaceGrid.h"

#include "Parallel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace blockforge
{
void ParametricSurface::crossPoints(double s, double t, double h, Vec3 out[5]) const
{
  out[0] = point(s, t);
  out[1] = point(s + h, t);
  out[2] = point(s - h, t);
  out[3] = point(s, t + h);
  out[4] = point(s, t - h);
}

void closestNear(const ParametricSurface& surface, const Vec3& target, double& s, double& t,
  Vec3& start, Vec3* tangentS, Vec3* tangentT)
{
  const double h = 1e-6, largest = 0.02;
  for (int iteration = 0; iteration < 8; ++iteration)
  {
    Vec3 around[5];
    surface.crossPoints(s, t, h, around);
    const Vec3& p = around[0];
    if (iteration == 0)
    {
      start = p;
    }
    const Vec3 ps = (around[1] - around[2]) / (2 * h);
    const Vec3 pt = (around[3] - around[4]) / (2 * h);
    if (tangentS)
    {
      *tangentS = ps;
      *tangentT = pt;
    }
    const Vec3 r = target - p;
    const double a = ps.dot(ps), b = ps.dot(pt), c = pt.dot(pt);
    const double det = a * c - b * b;
    if (!(det > 0.0) || !std::isfinite(det))
    {
      return;
    }
    double ds = (c * ps.dot(r) - b * pt.dot(r)) / det;
    double dt = (a * pt.dot(r) - b * ps.dot(r)) / det;
    const double step = std::max(std::abs(ds), std::abs(dt));
    if (!std::isfinite(step))
    {
      return;
    }
    if (step > largest)
    {
      ds *= largest / step;
      dt *= largest / step;
    }
    s += ds;
    t = std::clamp(t + dt, surface.tMin(), surface.tMax());
    if (step < 1e-13)
    {
      return;
    }
  }
}

namespace
{
/// Cell corners whose scaled Jacobian is below this are nearly flat or folded: there the
/// projected TFI gives way to the parameter grid (about 6 degrees between cell sides).
constexpr double NearlyFlat = 0.1;

/// A cell side more than SizeTrigger times longer or shorter than the parameter grid's side
/// there: the projected TFI nodes of the face have slid along the surface (below,
/// SideMeasure); its nodes then step back until every side is within SizeJump. Why two: round a sharp tip's fan the
/// projected and the parameter grid space the nodes next to the fan's end differently by up
/// to 1.5 where neither slid (the compressor optimized at density 4: moved there, 19
/// concave cells); Rotor 37's slid cells are 2.5-6 times off, and held only to 2 its
/// O_te|O_b stays 1.47-1.56.
constexpr double SizeTrigger = 2.0;
constexpr double SizeJump = 1.5;

/**
 * A monotone map of one parameter to the arc length along an iso-line of the other,
 * piecewise linear on a sample fine enough for the face's cells.
 */
class EvenMetric
{
public:
  /// Along s at t = fixed (alongS) or along t at s = fixed.
  EvenMetric(const ParametricSurface& surface, bool alongS, double from, double to,
    double fixed, int intervals)
    : From(from), To(to), Arc(intervals + 1, 0.0)
  {
    auto at = [&](int k) {
      const double u = from + (to - from) * k / intervals;
      return alongS ? surface.point(u, fixed) : surface.point(fixed, u);
    };
    Vec3 previous = at(0);
    std::vector<double> chords(intervals);
    double total = 0.0;
    for (int k = 1; k <= intervals; ++k)
    {
      const Vec3 next = at(k);
      chords[k - 1] = (next - previous).norm();
      total += chords[k - 1];
      previous = next;
    }
    // a floor keeps the map strictly increasing where the iso-line degenerates (a pole)
    const double floor = total > 0.0 ? 1e-6 * total / intervals : 1.0;
    for (int k = 1; k <= intervals; ++k)
    {
      Arc[k] = Arc[k - 1] + chords[k - 1] + floor;
    }
  }

  double forward(double u) const
  {
    const int intervals = static_cast<int>(Arc.size()) - 1;
    if (!(To > From))
    {
      return u;
    }
    const double x = (u - From) / (To - From) * intervals;
    const int k = std::clamp(static_cast<int>(std::floor(x)), 0, intervals - 1);
    return Arc[k] + (x - k) * (Arc[k + 1] - Arc[k]);
  }

  double backward(double arc) const
  {
    const int intervals = static_cast<int>(Arc.size()) - 1;
    if (!(To > From))
    {
      return arc;
    }
    const auto upper = std::upper_bound(Arc.begin() + 1, Arc.end() - 1, arc);
    const int k = static_cast<int>(upper - Arc.begin()) - 1;
    const double x = k + (arc - Arc[k]) / (Arc[k + 1] - Arc[k]);
    return From + (To - From) * x / intervals;
  }

private:
  double From, To;
  std::vector<double> Arc;
};

/// Loop index of each boundary node of an na x nb face (bottom, right, top, left).
struct LoopIndex
{
  int na, nb;
  int size() const { return 2 * (na - 1) + 2 * (nb - 1); }
  int bottom(int a) const { return a; }
  int right(int b) const { return (na - 1) + b; }
  int top(int a) const { return (na - 1) + (nb - 1) + (na - 1 - a); }
  int left(int b) const { return (2 * (na - 1) + (nb - 1) + (nb - 1 - b)) % size(); }
};

/// TFI of the boundary's (u, v) (two numbers per loop node) with the edges' parameters.
std::vector<double> parameterTfi(const std::vector<Eigen::Vector2d>& uv, const LoopIndex& loop,
  const EdgeNodes& bottom, const EdgeNodes& top, const EdgeNodes& left, const EdgeNodes& right,
  std::array<Blending, 2> blending)
{
  auto fill = [&](int count, auto index) {
    std::vector<double> xyz(3 * count);
    for (int i = 0; i < count; ++i)
    {
      const Eigen::Vector2d& p = uv[index(i)];
      xyz[3 * i] = p[0];
      xyz[3 * i + 1] = p[1];
      xyz[3 * i + 2] = 0.0;
    }
    return xyz;
  };
  const int na = loop.na, nb = loop.nb;
  const std::vector<double> pb = fill(na, [&](int a) { return loop.bottom(a); });
  const std::vector<double> pr = fill(nb, [&](int b) { return loop.right(b); });
  const std::vector<double> pt = fill(na, [&](int a) { return loop.top(a); });
  const std::vector<double> pl = fill(nb, [&](int b) { return loop.left(b); });
  std::vector<double> grid(3 * static_cast<std::size_t>(na) * nb);
  transfiniteFace(EdgeNodes{ pb.data(), bottom.params, na }, EdgeNodes{ pt.data(), top.params, na },
    EdgeNodes{ pl.data(), left.params, nb }, EdgeNodes{ pr.data(), right.params, nb }, grid.data(),
    blending);
  return grid;
}

/// The node indices of cell (a, b)'s corners in a grid na nodes wide, counter-clockwise.
void cellCorners(int na, int a, int b, std::size_t corner[4])
{
  corner[0] = static_cast<std::size_t>(b) * na + a;
  corner[1] = corner[0] + 1;
  corner[3] = static_cast<std::size_t>(b + 1) * na + a;
  corner[2] = corner[3] + 1;
}

/// Length of the parameter step e in the first fundamental form g = (ps.ps, ps.pt, pt.pt).
double metricLength(const Eigen::Vector3d& g, const Eigen::Vector2d& e)
{
  return std::sqrt(std::max(0.0, g[0] * e[0] * e[0] + 2 * g[1] * e[0] * e[1] + g[2] * e[1] * e[1]));
}

/// Scaled Jacobians of the four corners of every cell in (s, t), measured with the first
/// fundamental form `metric` of the cell (a = ps.ps, b = ps.pt, c = pt.pt) and oriented
/// by `orientation` (+1 or -1: the sign of the boundary loop's area in (s, t)).
struct CornerMeasure
{
  int na, nb;
  double orientation;
  const std::vector<Eigen::Vector3d>& metric; // per cell

  void operator()(const std::vector<Eigen::Vector2d>& st, int a, int b, double out[4]) const
  {
    std::size_t corner[4];
    cellCorners(na, a, b, corner);
    const Eigen::Vector3d& g = metric[static_cast<std::size_t>(b) * (na - 1) + a];
    const double area = std::sqrt(std::max(0.0, g[0] * g[2] - g[1] * g[1]));
    auto length = [&](const Eigen::Vector2d& e) { return metricLength(g, e); };
    for (int k = 0; k < 4; ++k)
    {
      const Eigen::Vector2d e1 = st[corner[(k + 1) % 4]] - st[corner[k]];
      const Eigen::Vector2d e2 = st[corner[(k + 3) % 4]] - st[corner[k]];
      const double lengths = length(e1) * length(e2);
      // a collapsed side (a degenerate face) or a degenerate metric says nothing
      out[k] = lengths > 0.0 && area > 0.0
        ? orientation * (e1[0] * e2[1] - e1[1] * e2[0]) * area / lengths
        : 1.0;
    }
  }
};
/// Lengths of the four sides of every cell in (s, t) (bottom, right, top, left), measured
/// with the cell's first fundamental form as CornerMeasure does. Why: near a thin edge of
/// the surface (a blade's trailing edge, its radius far below the face's size) a 3-D TFI
/// node off the surface by the chord of the bowed face (the spanwise sides bow differently,
/// and TFI blends their bows with the weights of the far side) lands, projected, on the
/// edge's round at a very different place along it: Rotor 37's trailing edge block's blade
/// cells next to the corner came out 6 times shorter at mid-span than at hub and shroud,
/// unfolded, so the corner test above did not see it. The parameter grid in the even metric
/// interpolates the boundary's distributions without that slide.
struct SideMeasure
{
  int na, nb;
  const std::vector<Eigen::Vector3d>& metric; // per cell

  void operator()(const std::vector<Eigen::Vector2d>& st, int a, int b, double out[4]) const
  {
    std::size_t corner[4];
    cellCorners(na, a, b, corner);
    const Eigen::Vector3d& g = metric[static_cast<std::size_t>(b) * (na - 1) + a];
    for (int k = 0; k < 4; ++k)
    {
      const Eigen::Vector2d e = st[corner[(k + 1) % 4]] - st[corner[k]];
      out[k] = metricLength(g, e);
    }
  }
};
} // namespace

void surfaceFaceGrid(const ParametricSurface& surface, const std::vector<Eigen::Vector2d>& loopST,
  const EdgeNodes& bottom, const EdgeNodes& top, const EdgeNodes& left, const EdgeNodes& right,
  double* out, SurfaceFaceMethod method, SurfaceFaceReport* report, std::array<Blending, 2> blending)
{
  const int na = bottom.count, nb = left.count;
  const LoopIndex loop{ na, nb };
  if (static_cast<int>(loopST.size()) != loop.size())
  {
    throw GeometryError("surface face: the boundary loop has " + std::to_string(loopST.size()) +
      " nodes where a face of " + std::to_string(na) + " x " + std::to_string(nb) + " has " +
      std::to_string(loop.size()));
  }
  const std::size_t count = static_cast<std::size_t>(na) * nb;
  // EndWidths measures widths: not in (s, t), whose scales differ (the guard's even grid
  // below, and the 3-D targets, keep them); the targets' search starts from the linear grid
  const auto parameterBlending = [](Blending b) {
    return b == Blending::EndWidths ? Blending::Linear : b;
  };
  std::vector<double> parameters = parameterTfi(loopST, loop, bottom, top, left, right,
    { parameterBlending(blending[0]), parameterBlending(blending[1]) });
  std::vector<double> targets(3 * count);
  transfiniteFace(bottom, top, left, right, targets.data(), blending);
  // Every node's (s, t): boundary nodes from the loop, interior nodes placed below.
  std::vector<Eigen::Vector2d> st(count);
  for (std::size_t i = 0; i < count; ++i)
  {
    st[i] = Eigen::Vector2d(parameters[3 * i], parameters[3 * i + 1]);
  }
  // Tangents at the interior nodes (the surface's metric there), for the guard.
  std::vector<Vec3> tangentS(count, Vec3::Zero()), tangentT(count, Vec3::Zero());
  forEachChunk(std::max(0, nb - 2), [&](long row) {
    const int b = static_cast<int>(row) + 1;
    for (int a = 1; a + 1 < na; ++a)
    {
      const std::size_t i = static_cast<std::size_t>(b) * na + a;
      const Vec3 target(targets[3 * i], targets[3 * i + 1], targets[3 * i + 2]);
      double s = st[i][0], t = st[i][1];
      Vec3 p0;
      closestNear(surface, target, s, t, p0, &tangentS[i], &tangentT[i]); // p0 at (s0, t0)
      Vec3 p = surface.point(s, t);
      if (!((p - target).norm() <= (p0 - target).norm()))
      {
        p = p0; // no better than the (s, t) node: keep that
      }
      else
      {
        st[i] = Eigen::Vector2d(s, t);
      }
      std::copy_n(p.data(), 3, out + 3 * i);
    }
  });
  auto copyBoundary = [&]() {
    for (int a = 0; a < na; ++a)
    {
      std::copy_n(bottom.xyz + 3 * a, 3, out + 3 * static_cast<std::size_t>(a));
      std::copy_n(top.xyz + 3 * a, 3, out + 3 * (static_cast<std::size_t>(nb - 1) * na + a));
    }
    for (int b = 0; b < nb; ++b)
    {
      std::copy_n(left.xyz + 3 * b, 3, out + 3 * (static_cast<std::size_t>(b) * na));
      std::copy_n(right.xyz + 3 * b, 3, out + 3 * (static_cast<std::size_t>(b) * na + na - 1));
    }
  };
  copyBoundary();
  if (method == SurfaceFaceMethod::ProjectedTfi || na < 3 || nb < 3)
  {
    return;
  }

  // The guard. Orientation of the face in (s, t): the sign of its boundary loop's area.
  double loopArea = 0.0;
  for (int k = 0; k < loop.size(); ++k)
  {
    const Eigen::Vector2d& p = loopST[k];
    const Eigen::Vector2d& q = loopST[(k + 1) % loop.size()];
    loopArea += p[0] * q[1] - p[1] * q[0];
  }
  if (!(std::abs(loopArea) > 0.0))
  {
    return;
  }
  // The metric of each cell: the first fundamental form at its first interior corner.
  std::vector<Eigen::Vector3d> metric(static_cast<std::size_t>(na - 1) * (nb - 1));
  for (int b = 0; b + 1 < nb; ++b)
  {
    for (int a = 0; a + 1 < na; ++a)
    {
      const std::size_t j = static_cast<std::size_t>(std::max(b, 1)) * na + std::max(a, 1);
      const Vec3& ps = tangentS[j];
      const Vec3& pt = tangentT[j];
      metric[static_cast<std::size_t>(b) * (na - 1) + a] =
        Eigen::Vector3d(ps.dot(ps), ps.dot(pt), pt.dot(pt));
    }
  }
  const CornerMeasure measure{ na, nb, loopArea > 0.0 ? 1.0 : -1.0, metric };
  const std::size_t cells = metric.size();

  // The parameter grid in the even metric.
  double sLow = loopST[0][0], sHigh = sLow, tLow = loopST[0][1], tHigh = tLow;
  for (const Eigen::Vector2d& p : loopST)
  {
    sLow = std::min(sLow, p[0]);
    sHigh = std::max(sHigh, p[0]);
    tLow = std::min(tLow, p[1]);
    tHigh = std::max(tHigh, p[1]);
  }
  const int intervals = 4 * std::max(na, nb) + 32;
  const double tMiddle = std::clamp(0.5 * (tLow + tHigh), surface.tMin(), surface.tMax());
  const EvenMetric sigma(surface, true, sLow, sHigh, tMiddle, intervals);
  const EvenMetric tau(surface, false, tLow, tHigh, 0.5 * (sLow + sHigh), intervals);
  std::vector<Eigen::Vector2d> even(loopST.size());
  for (std::size_t k = 0; k < loopST.size(); ++k)
  {
    even[k] = Eigen::Vector2d(sigma.forward(loopST[k][0]), tau.forward(loopST[k][1]));
  }
  // linear: the grid that does not fold; with the widths EndWidths keeps beside its sides,
  // so that the guard does not take them back to the linear grid's narrow cells
  const auto safeBlending = [](Blending b) {
    return b == Blending::EndWidths ? Blending::EndWidths : Blending::Linear;
  };
  const std::vector<double> evenGrid = parameterTfi(even, loop, bottom, top, left, right,
    { safeBlending(blending[0]), safeBlending(blending[1]) });
  std::vector<Eigen::Vector2d> safe(st);
  for (int b = 1; b + 1 < nb; ++b)
  {
    for (int a = 1; a + 1 < na; ++a)
    {
      const std::size_t i = static_cast<std::size_t>(b) * na + a;
      safe[i] = Eigen::Vector2d(sigma.backward(evenGrid[3 * i]), tau.backward(evenGrid[3 * i + 1]));
    }
  }
  // Each corner must be at least as good as the bound or the parameter grid's corner, and
  // each side within SizeJump of the parameter grid's side (same cell metric).
  const SideMeasure sides{ na, nb, metric };
  // whether a side of cell (a, b) of `grid` is more than `factor` times longer or shorter
  // than the parameter grid's
  auto sideBeyond = [&](const std::vector<Eigen::Vector2d>& grid, int a, int b, double factor) {
    double length[4], reference[4];
    sides(grid, a, b, length);
    sides(safe, a, b, reference);
    for (int k = 0; k < 4; ++k)
    {
      if (reference[k] > 0.0 && (length[k] > factor * reference[k] || reference[k] > factor * length[k]))
      {
        return true;
      }
    }
    return false;
  };
  // a face where some cell side slid beyond SizeTrigger holds every side within SizeJump
  bool slid = false;
  for (int b = 0; b + 1 < nb && !slid; ++b)
  {
    for (int a = 0; a + 1 < na && !slid; ++a)
    {
      slid = sideBeyond(st, a, b, SizeTrigger);
    }
  }
  auto cellFails = [&](const std::vector<Eigen::Vector2d>& grid, int a, int b, const double* bound) {
    double j[4];
    measure(grid, a, b, j);
    if (j[0] < bound[0] || j[1] < bound[1] || j[2] < bound[2] || j[3] < bound[3])
    {
      return true;
    }
    return slid && sideBeyond(grid, a, b, SizeJump);
  };
  std::vector<double> least(4 * cells);
  for (int b = 0; b + 1 < nb; ++b)
  {
    for (int a = 0; a + 1 < na; ++a)
    {
      double j[4];
      measure(safe, a, b, j);
      for (int k = 0; k < 4; ++k)
      {
        least[4 * (static_cast<std::size_t>(b) * (na - 1) + a) + k] = std::min(NearlyFlat, j[k]);
      }
    }
  }
  bool anyFails = false;
  for (int b = 0; b + 1 < nb && !anyFails; ++b)
  {
    for (int a = 0; a + 1 < na && !anyFails; ++a)
    {
      anyFails = cellFails(st, a, b, &least[4 * (static_cast<std::size_t>(b) * (na - 1) + a)]);
    }
  }
  if (!anyFails)
  {
    return; // the projected TFI as it is
  }
  // Halve the step from the parameter grid to the projected node at the corners of every
  // failing cell (after eight halvings, take the parameter grid's node) until none fails.
  const std::vector<Eigen::Vector2d> projected(st);
  std::vector<double> weight(count, 1.0);
  int rounds = 0;
  for (bool failing = true; failing && rounds < 64; ++rounds)
  {
    failing = false;
    std::vector<char> moved(count, 0);
    for (int b = 0; b + 1 < nb; ++b)
    {
      for (int a = 0; a + 1 < na; ++a)
      {
        if (!cellFails(st, a, b, &least[4 * (static_cast<std::size_t>(b) * (na - 1) + a)]))
        {
          continue;
        }
        failing = true;
        for (const std::size_t i : { static_cast<std::size_t>(b) * na + a,
               static_cast<std::size_t>(b) * na + a + 1, static_cast<std::size_t>(b + 1) * na + a,
               static_cast<std::size_t>(b + 1) * na + a + 1 })
        {
          moved[i] = 1;
        }
      }
    }
    for (int b = 1; b + 1 < nb; ++b)
    {
      for (int a = 1; a + 1 < na; ++a)
      {
        const std::size_t i = static_cast<std::size_t>(b) * na + a;
        if (moved[i])
        {
          weight[i] = rounds < 8 ? 0.5 * weight[i] : 0.0;
          st[i] = weight[i] > 0.0 ? Eigen::Vector2d(safe[i] + weight[i] * (projected[i] - safe[i]))
                                  : safe[i];
        }
      }
    }
  }
  int guarded = 0;
  for (int b = 1; b + 1 < nb; ++b)
  {
    for (int a = 1; a + 1 < na; ++a)
    {
      const std::size_t i = static_cast<std::size_t>(b) * na + a;
      if (weight[i] < 1.0)
      {
        const Vec3 p = surface.point(st[i][0], st[i][1]);
        std::copy_n(p.data(), 3, out + 3 * i);
        ++guarded;
      }
    }
  }
  if (report)
  {
    report->guardedNodes = guarded;
    report->rounds = rounds - 1;
  }
}
} // namespace blockforge
