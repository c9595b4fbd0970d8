// Feet bunched on a convex corner inside a projected edge (a cap's corner): the outer nodes
// on the O curve's arc round the corner all have their normal feet on it, a fan of lines
// whose wall cells are slivers. spreadFootBunches spreads them round the corner;
// spreadBunchLocally, where too few cells lie there to grade, between their neighbours.
// Called by projectEdgeParameters (ProjectedEdges.cpp) on every projected edge.
#include "MeshInternals.h"

#include "../Core/RootFinding.h"

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace model
{
namespace
{
/// A run of feet inside an edge narrower each than this fraction of both cells beside it
/// is a bunch on a corner (spreadFootBunches; the turbine's cap corners 0.01-0.06) ...
constexpr double bunchFloor = 0.2;
/// ... spread round its middle node (the corner): the cells grow from it by at most this
/// from one to the next (issue 8's neighbour ratio) until they meet the projected ones.
constexpr double bunchGrowth = 1.5;

/// The largest ratio of neighbouring cells (i, i + 1), first <= i < last, of `params`.
double worstJump(const std::vector<double>& params, int first, int last)
{
  double worst = 1.0;
  for (int i = first; i < last; ++i)
  {
    const double a = params[i + 1] - params[i], b = params[i + 2] - params[i + 1];
    worst = std::max(worst, std::max(a / b, b / a));
  }
  return worst;
}

/// spreadBunchLocally: kept where the worst neighbour ratio among the cells it moves and
/// the one beyond either end can be brought to this, and moved only as far as that takes
/// (checkMesh's interpolation weight fails between cells whose centres lie 19 times as far
/// from their face; the spread feet lean the lines: the turbine's cap at density 1, spread
/// to ratios 3.3 / 4 / 5 / 6 / 8: O_te's smallest angle 37.9 / 39.5 / 41.8 / 44.0 / 47.5
/// deg, optimizer end 36.76 (3.25) / - / 40.78 / 41.18 / 40.42 deg, checkMesh's weight
/// 0.171 / - / 0.171 / 0.157 / - placed, 0.161 / - / 0.148 / 0.148 / - optimized).
constexpr double localMost = 5.0;

} // namespace

void spreadBunchLocally(std::vector<double>& params, int s, int e, int middle)
{
  const int cells = static_cast<int>(params.size()) - 1;
  const std::vector<double> projected = params;
  // the ratios that count: the run's cells, the one either side and the one beyond it
  const int first = std::max(s - 2, 0), last = std::min(e + 2, cells - 1);
  const double before = worstJump(params, first, last);
  // each free node in turn to where the worst ratio of the cells beside it is least
  // (golden sections between its neighbours), sweeping until the nodes settle
  const auto local = [&](int i, double x) {
    const double keep = params[i];
    params[i] = x;
    const double worst = worstJump(params, std::max(i - 2, 0), std::min(i + 1, cells - 1));
    params[i] = keep;
    return worst;
  };
  const auto spread = [&](int fixed) {
    params = projected;
    for (int sweep = 0; sweep < 40; ++sweep)
    {
      for (int i = s; i <= e + 1; ++i)
      {
        if (i == fixed)
        {
          continue;
        }
        const double gap = params[i + 1] - params[i - 1];
        const double a = params[i - 1] + 1e-3 * gap, b = params[i + 1] - 1e-3 * gap;
        // (40 golden sections: the bracket shrinks to 4.4e-9 of its width)
        const double x =
          goldenSectionMinimum([&](double t) { return local(i, t); }, a, b, 5e-9 * (b - a));
        if (local(i, x) < local(i, params[i]))
        {
          params[i] = x;
        }
      }
    }
    return worstJump(params, first, last);
  };
  // the node kept on the corner: the bisector's (middle) unless another of the run's
  // nodes leaves the cells nearer alike (the turbine's cap: both ends of its 0.003 mm cell
  // lie on the corner, the one on the bisector has the cap's 0.8 mm cell after it)
  double best = spread(middle);
  int kept = middle;
  for (int i = s; i <= e + 1; ++i)
  {
    if (i != middle)
    {
      const double worst = spread(i);
      if (worst < best)
      {
        best = worst;
        kept = i;
      }
    }
  }
  if (best <= localMost && best < 0.5 * before)
  {
    spread(kept);
    // moved from the projected feet no farther than brings the worst ratio to localMost
    const std::vector<double> spreadOut = params;
    const auto at = [&](double t) {
      for (int i = s; i <= e + 1; ++i)
      {
        params[i] = projected[i] + t * (spreadOut[i] - projected[i]);
      }
      return worstJump(params, first, last);
    };
    if (at(1.0) < localMost)
    {
      double low = 0.0, high = 1.0;
      for (int round = 0; round < 50; ++round)
      {
        const double t = 0.5 * (low + high);
        (at(t) > localMost ? low : high) = t;
      }
      at(high);
    }
    else
    {
      params = spreadOut;
    }
  }
  else
  {
    params = projected;
  }
}

void spreadFootBunches(std::vector<double>& params, const std::vector<Vec3>& feet,
  const std::vector<Vec3>& outer)
{
  const int cells = static_cast<int>(params.size()) - 1;
  if (cells < 4)
  {
    return;
  }
  const auto width = [&](int i) { return params[i + 1] - params[i]; };
  const double k = bunchGrowth - 1.0; // the cell size grows by k times the distance
  for (int s = 1; s + 1 < cells;)
  {
    const double before = width(s - 1);
    if (!(width(s) < bunchFloor * before))
    {
      ++s;
      continue;
    }
    int e = s;
    double widest = width(s);
    while (e + 2 < cells && width(e + 1) < bunchFloor * before)
    {
      ++e;
      widest = std::max(widest, width(e));
    }
    if (!(widest < bunchFloor * width(e + 1)))
    {
      ++s; // a narrower run may start inside it (a valley within a valley)
      continue;
    }
    // The corner: the run's node whose line (foot to outer node) lies most nearly along
    // the corner's bisector (the fan's middle line; the run's middle node without feet and
    // outer nodes) stays on it, the ones before it go before it. Cell sizes d + k |x -
    // corner| from it, where they are below the projected cells: from the last node on
    // either side whose projected cell (away from the corner) is still within them, or the
    // edge's end.
    int middle = s + (e - s + 1) / 2;
    if (feet.size() == params.size() && outer.size() == params.size())
    {
      const Vec3 at = feet[middle];
      const Vec3 back = (feet[s - 1] - at).normalized(), ahead = (feet[e + 2] - at).normalized();
      double least = 2.0;
      for (int i = s; i <= e + 1; ++i)
      {
        const Vec3 line = (outer[i] - feet[i]).normalized();
        const double lean = std::abs(line.dot(back) - line.dot(ahead));
        if (lean < least)
        {
          least = lean;
          middle = i;
        }
      }
    }
    const double corner = params[middle];
    const auto size = [&](double d, double x) { return d + k * std::abs(x - corner); };
    const auto landings = [&](double d, int& left, int& right) {
      right = e + 2; // past the run on either side
      while (right < cells && width(right) > size(d, params[right]))
      {
        ++right;
      }
      left = s - 1;
      while (left > 0 && width(left - 1) > size(d, params[left]))
      {
        --left;
      }
    };
    // Either side from the corner, at the distance u of its length D: the sizes d + k u,
    // and towards the landing no more than the landing's next cell w (0 at the edge's end:
    // none) plus k times the distance to it. `cellsTo` counts the cells they give from the
    // corner to u, `distanceAt` is its inverse.
    struct Side
    {
      double D, w, split, top, atSplit;
    };
    const auto sideOf = [&](double d, double D, double w) {
      Side side{ D, w, D, d + k * D, 0.0 };
      if (w > 0.0)
      {
        side.split = std::min(std::max((w - d + k * D) / (2.0 * k), 0.0), D);
        side.top = std::min(d + k * side.split, w + k * (D - side.split));
      }
      side.atSplit = std::log((d + k * side.split) / d) / k;
      return side;
    };
    const auto cellsTo = [&](double d, const Side& side, double u) {
      if (u <= side.split)
      {
        return std::log((d + k * u) / d) / k;
      }
      return side.atSplit + std::log(side.top / (side.w + k * (side.D - u))) / k;
    };
    const auto distanceAt = [&](double d, const Side& side, double n) {
      if (n <= side.atSplit)
      {
        return d * (std::exp(k * n) - 1.0) / k;
      }
      return side.D - (side.top * std::exp(-k * (n - side.atSplit)) - side.w) / k;
    };
    const auto sides = [&](double d, int left, int right, Side& before, Side& after) {
      before = sideOf(d, corner - params[left], left > 0 ? width(left - 1) : 0.0);
      after = sideOf(d, params[right] - corner, right < cells ? width(right) : 0.0);
    };
    // the corner cell d for which the sizes give as many cells as the nodes span
    double low = 1e-9 * (params[cells] - params[0]), high = std::max(before, width(e + 1));
    for (int round = 0; round < 100; ++round)
    {
      const double d = std::sqrt(low * high);
      int left = 0, right = 0;
      landings(d, left, right);
      Side back{}, ahead{};
      sides(d, left, right, back, ahead);
      const double n = cellsTo(d, back, back.D) + cellsTo(d, ahead, ahead.D);
      (n > right - left ? low : high) = d;
    }
    const double d = high;
    int left = 0, right = 0;
    landings(d, left, right);
    Side back{}, ahead{};
    sides(d, left, right, back, ahead);
    // each side's nodes spaced evenly in the sizes' count from the corner (which stays)
    const std::vector<double> projected = params;
    const double start = params[left], end = params[right];
    const double nBack = cellsTo(d, back, back.D), nAhead = cellsTo(d, ahead, ahead.D);
    for (int i = left + 1; i < right; ++i)
    {
      if (i == middle)
      {
        continue;
      }
      const double x = i < middle
        ? corner - distanceAt(d, back, nBack * (middle - i) / (middle - left))
        : corner + distanceAt(d, ahead, nAhead * (i - middle) / (right - middle));
      params[i] = std::min(std::max(x, start), end);
    }
    // Too few cells to grade from the corner out to the projected ones (the turbine's cap
    // at density 1: 0.058 mm of flank, 0.003 mm on the corner, 0.8 mm across the cap in
    // three cells): where the spread cells still differ by more than FanSideGrowth from one
    // to the next, the run is spread within the nodes next to it instead
    // (spreadBunchLocally), the corner staying.
    if (!(worstJump(params, std::max(left - 1, 0), std::min(right, cells - 1)) <= FanSideGrowth))
    {
      params = projected;
      spreadBunchLocally(params, s, e, middle);
      s = e + 1;
      continue;
    }
    s = std::max(right, s + 1);
  }
}

} // namespace model
} // namespace blockforge
