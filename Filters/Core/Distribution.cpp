#include "Distribution.h"
#include "RootFinding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace blockforge
{
namespace
{
/// Relative slack for comparing lengths that the user computed by hand (h * cells == L).
constexpr double LengthSlack = 1e-12;

std::string toString(double value)
{
  std::ostringstream s;
  s.precision(10);
  s << value;
  return s.str();
}

std::vector<double> uniform(int nodeCount)
{
  const int cells = nodeCount - 1;
  std::vector<double> s(nodeCount);
  for (int i = 0; i < nodeCount; ++i)
  {
    s[i] = static_cast<double>(i) / cells;
  }
  s.back() = 1.0;
  return s;
}

/// Neumaier's compensated sum: node positions then carry rounding errors of the final
/// division only, independent of the number of cells.
class CompensatedSum
{
public:
  void add(double x)
  {
    const double t = Sum + x;
    Compensation += std::abs(Sum) >= std::abs(x) ? (Sum - t) + x : (x - t) + Sum;
    Sum = t;
  }
  double value() const { return Sum + Compensation; }

private:
  double Sum = 0.0, Compensation = 0.0;
};

/// Smallest cell, as a fraction of its edge: below it the nodes of a cell coincide once
/// they are placed on the edge's coordinates (rounding), and the cell has no volume.
constexpr double MinCellFraction = 1e-12;

void requireStrictlyIncreasing(const std::vector<double>& s, const char* lawName)
{
  for (std::size_t i = 1; i < s.size(); ++i)
  {
    if (!(s[i] - s[i - 1] >= MinCellFraction))
    {
      throw GeometryError(std::string(lawName) + " distribution: with " +
        std::to_string(s.size()) + " nodes the smallest cells become too small to " +
        "represent (below 1e-12 of the edge); reduce the expansion ratio or the number of " +
        "nodes");
    }
  }
}

/// Node positions from relative cell sizes: cumulative sum divided by the total, with the
/// ends forced to exactly 0 and 1.
std::vector<double> fromCellSizes(const std::vector<double>& sizes, const char* lawName)
{
  std::vector<double> s(sizes.size() + 1);
  CompensatedSum total;
  for (double size : sizes)
  {
    total.add(size);
  }
  const double sum = total.value();
  if (!(sum > 0.0) || !std::isfinite(sum))
  {
    throw GeometryError(std::string(lawName) +
      " distribution: the cell sizes cannot be represented; reduce the expansion ratio or "
      "the number of nodes");
  }
  CompensatedSum running;
  s[0] = 0.0;
  for (std::size_t i = 0; i + 1 < sizes.size(); ++i)
  {
    running.add(sizes[i]);
    s[i + 1] = running.value() / sum;
  }
  s.back() = 1.0;
  requireStrictlyIncreasing(s, lawName);
  return s;
}

void requirePositiveRatio(double k, const char* lawName)
{
  if (!(k > 0.0) || !std::isfinite(k))
  {
    throw GeometryError(std::string(lawName) + " distribution: the expansion ratio must be a "
      "positive number, got " + toString(k));
  }
}

/// Cells k^i, i = 0..cells-1 (paper eq. 7), scaled so that the largest is 1: the ratio of
/// successive cells is then exact to rounding and no power overflows. Summing the cells
/// directly (instead of (k^n - 1)/(k - 1)) has no cancellation for k close to 1.
std::vector<double> geometric(double k, int nodeCount)
{
  requirePositiveRatio(k, "geometric");
  if (k == 1.0)
  {
    return uniform(nodeCount);
  }
  const int cells = nodeCount - 1;
  const int largest = k > 1.0 ? cells - 1 : 0;
  std::vector<double> sizes(cells);
  for (int i = 0; i < cells; ++i)
  {
    sizes[i] = std::pow(k, i - largest);
  }
  return fromCellSizes(sizes, "geometric");
}

/// Cells proportional to k^min(i, cells-1-i), built from the first half and mirrored, so
/// that s_i + s_(n-1-i) == 1 up to the rounding of one subtraction.
std::vector<double> twoSided(double k, int nodeCount)
{
  requirePositiveRatio(k, "two-sided");
  if (k == 1.0)
  {
    return uniform(nodeCount);
  }
  const int cells = nodeCount - 1;
  const int halfCells = cells / 2;       // cells strictly in the lower half
  const int largestExponent = (cells - 1) / 2;
  const int scaleExponent = k > 1.0 ? largestExponent : 0;
  CompensatedSum lowerHalf;
  std::vector<double> cumulative(halfCells + 1, 0.0);
  for (int i = 0; i < halfCells; ++i)
  {
    lowerHalf.add(std::pow(k, i - scaleExponent));
    cumulative[i + 1] = lowerHalf.value();
  }
  const double half = lowerHalf.value();
  const double middle = cells % 2 == 1 ? std::pow(k, largestExponent - scaleExponent) : 0.0;
  const double total = 2.0 * half + middle;
  if (!(total > 0.0) || !std::isfinite(total))
  {
    throw GeometryError("two-sided distribution: the cell sizes cannot be represented; "
      "reduce the expansion ratio or the number of nodes");
  }
  std::vector<double> s(nodeCount);
  for (int i = 0; i <= halfCells; ++i)
  {
    s[i] = cumulative[i] / total;
    s[nodeCount - 1 - i] = 1.0 - s[i];
  }
  if (cells % 2 == 0)
  {
    s[halfCells] = 0.5;
  }
  s.front() = 0.0;
  s.back() = 1.0;
  requireStrictlyIncreasing(s, "two-sided");
  return s;
}

/// First cell h, growing geometrically by k with k solved from h (1 + k + ... + k^(m-1)) = L.
std::vector<double> firstCellSolvedRatio(double h, double length, int nodeCount)
{
  const int cells = nodeCount - 1;
  const double q = length / h;
  if (!(q > 1.0))
  {
    throw GeometryError("first-cell distribution: the first cell size " + toString(h) +
      " must be smaller than the edge length " + toString(length));
  }
  if (std::abs(q - cells) <= LengthSlack * cells)
  {
    return uniform(nodeCount);
  }
  auto sumOfPowers = [cells](double k) {
    double sum = 1.0;
    for (int i = 1; i < cells; ++i)
    {
      sum = 1.0 + k * sum; // Horner: no cancellation near k = 1
    }
    return sum;
  };
  // sumOfPowers increases with k; it is below `cells` for k < 1 and at least k^(cells-1)
  // for k > 1, which brackets the root. Bisection down to adjacent doubles is
  // deterministic and as accurate as double allows.
  double lo, hi;
  if (q < cells)
  {
    lo = 0.0;
    hi = 1.0;
  }
  else
  {
    lo = 1.0;
    hi = std::max(1.0, std::pow(q, 1.0 / (cells - 1))) * (1.0 + 1e-12);
  }
  bisect([&](double k) { return sumOfPowers(k) < q; }, lo, hi, 0.0, 2000);
  const double k = std::abs(sumOfPowers(lo) - q) <= std::abs(sumOfPowers(hi) - q) ? lo : hi;
  if (!(k > 0.0))
  {
    throw GeometryError("first-cell distribution: the first cell size " + toString(h) +
      " is too large for " + std::to_string(cells) + " cells on an edge of length " +
      toString(length));
  }
  std::vector<double> sizes(cells);
  const int largest = k > 1.0 ? cells - 1 : 0;
  for (int i = 0; i < cells; ++i)
  {
    sizes[i] = std::pow(k, i - largest);
  }
  return fromCellSizes(sizes, "first-cell");
}

/// First cell h, each cell at most r times the previous one: cells h r^i up to a cap c,
/// then c, with c such that the cells fill the edge exactly.
std::vector<double> firstCellCapped(double h, double r, double length, int nodeCount)
{
  const int cells = nodeCount - 1;
  if (h * cells > length * (1.0 + LengthSlack))
  {
    throw GeometryError("first-cell distribution: " + std::to_string(cells) +
      " cells of at least the first cell size " + toString(h) + " need a length of " +
      toString(h * cells) + ", more than the edge length " + toString(length) +
      "; reduce the first cell size or the number of nodes");
  }
  if (h * cells >= length * (1.0 - LengthSlack))
  {
    return uniform(nodeCount);
  }
  // The total F(c) = sum min(h r^i, c) is piecewise linear and increasing in c, so the cap
  // is found exactly by locating the first cell j that is capped: with cells 0..j-1 free,
  // c_j = (L - sum_{i<j} h r^i) / (cells - j), and j is the first index with c_j <= h r^j.
  std::vector<double> sizes(cells);
  double grown = 0.0; // sum of the free cells
  int capped = cells;
  double cap = 0.0;
  for (int j = 1; j < cells; ++j)
  {
    const double previous = h * std::pow(r, j - 1);
    grown += previous;
    const double candidate = (length - grown) / (cells - j);
    const double next = h * std::pow(r, j);
    if (candidate <= next)
    {
      capped = j;
      cap = std::max(candidate, previous);
      break;
    }
  }
  if (capped == cells)
  {
    const double reach = grown + h * std::pow(r, cells - 1);
    if (reach < length * (1.0 - LengthSlack))
    {
      throw GeometryError("first-cell distribution: " + std::to_string(cells) +
        " cells growing from the first cell size " + toString(h) + " by at most " +
        toString(r) + " reach only a length of " + toString(reach) + " of the edge length " +
        toString(length) + "; increase the expansion ratio, the first cell size or the "
        "number of nodes");
    }
  }
  for (int i = 0; i < cells; ++i)
  {
    sizes[i] = i < capped ? h * std::pow(r, i) : cap;
  }
  return fromCellSizes(sizes, "first-cell");
}

std::vector<double> firstCell(const DistributionLaw& law, int nodeCount, double length)
{
  const double h = law.firstCellSize;
  const double r = law.expansionRatio;
  if (!(length > 0.0) || !std::isfinite(length))
  {
    throw GeometryError("first-cell distribution: the edge length must be positive, got " +
      toString(length));
  }
  if (!(h > 0.0) || !std::isfinite(h))
  {
    throw GeometryError("first-cell distribution: the first cell size must be positive, "
      "got " + toString(h));
  }
  if (!std::isfinite(r) || (r != 0.0 && r < 1.0))
  {
    throw GeometryError("first-cell distribution: the maximum expansion ratio must be at "
      "least 1 (or 0 to compute it from the first cell size), got " + toString(r));
  }
  if (nodeCount == 2)
  {
    if (std::abs(h - length) > 1e-9 * length)
    {
      throw GeometryError("first-cell distribution: with 2 nodes the only cell is the whole "
        "edge (length " + toString(length) + "), so it cannot have the first cell size " +
        toString(h) + "; use more nodes");
    }
    return uniform(nodeCount);
  }
  return r == 0.0 ? firstCellSolvedRatio(h, length, nodeCount)
                  : firstCellCapped(h, r, length, nodeCount);
}
} // namespace

/**
 * Cells whose logarithmic sizes run linearly from ln(first) to ln(last) across the edge
 * plus a bump beta * 4 xi (1 - xi) that makes them fill it: cell i (xi = i / (cells - 1))
 * has size mean * exp(A(xi)), with beta found by bisection so that the sizes add up to the
 * edge (the sum grows with beta). The ends are then exactly first and last times the
 * mean, and neighbour cells differ by a smooth factor. With too few cells to fill the edge
 * that way (1 or 2, or ends too large for the count) the shape is scaled to fit instead.
 * flatness k != 1: the bump is beta (1 - |2 xi - 1|^(2k)) (k = 1 is the same function,
 * kept in its own arithmetic so that default grids keep their bits).
 */
std::vector<double> endSizes(double first, double last, int nodeCount, double flatness = 1.0)
{
  if (!(flatness >= 1.0) || !std::isfinite(flatness))
  {
    throw GeometryError("ends distribution: the flatness of the bump must be a number of "
                        "at least 1");
  }
  if (!(first > 0.0) || !(last > 0.0) || !std::isfinite(first) || !std::isfinite(last))
  {
    throw GeometryError("ends distribution: the end cell sizes (relative to the mean cell) "
                        "must be positive numbers");
  }
  if (first == 1.0 && last == 1.0)
  {
    return uniform(nodeCount); // the same nodes, bit for bit, as the uniform law
  }
  const int cells = nodeCount - 1;
  auto sizes = [&](double beta) {
    std::vector<double> h(cells);
    for (int i = 0; i < cells; ++i)
    {
      const double xi = cells > 1 ? static_cast<double>(i) / (cells - 1) : 0.5;
      const double bump = flatness == 1.0
        ? 4.0 * beta * xi * (1.0 - xi)
        : beta * (1.0 - std::pow(std::abs(2.0 * xi - 1.0), 2.0 * flatness));
      h[i] = std::exp((1.0 - xi) * std::log(first) + xi * std::log(last) + bump);
    }
    return h;
  };
  auto mean = [&](const std::vector<double>& h) {
    CompensatedSum sum;
    for (double v : h)
    {
      sum.add(v);
    }
    return sum.value() / cells;
  };
  std::vector<double> h = sizes(0.0);
  if (cells >= 3)
  {
    double low = -60.0, high = 60.0;
    if (mean(sizes(low)) <= 1.0 && mean(sizes(high)) >= 1.0)
    {
      bisect([&](double beta) { return mean(sizes(beta)) < 1.0; }, low, high, 1e-13, 200);
      h = sizes(0.5 * (low + high));
    }
  }
  CompensatedSum total;
  for (double v : h)
  {
    total.add(v);
  }
  std::vector<double> s(nodeCount);
  CompensatedSum running;
  s[0] = 0.0;
  for (int i = 0; i < cells; ++i)
  {
    running.add(h[i]);
    s[i + 1] = running.value() / total.value();
  }
  s[nodeCount - 1] = 1.0;
  return s;
}

namespace
{
/// Cell i growing from the given ends by r: min(first r^i, last r^(cells-1-i)), free ends
/// (<= 0) left out; +inf when both are free.
double grownCell(double first, double last, double r, int i, int cells)
{
  double size = std::numeric_limits<double>::infinity();
  if (first > 0.0)
  {
    size = std::min(size, first * std::pow(r, i));
  }
  if (last > 0.0)
  {
    size = std::min(size, last * std::pow(r, cells - 1 - i));
  }
  return size;
}

double grownLength(double first, double last, double r, int cells)
{
  CompensatedSum sum;
  for (int i = 0; i < cells; ++i)
  {
    sum.add(grownCell(first, last, r, i, cells));
  }
  return sum.value();
}
} // namespace

namespace
{
/// The largest ratio of neighbour cells (either way) of relative node positions.
double largestStep(const std::vector<double>& s)
{
  double largest = 1.0;
  for (std::size_t i = 2; i < s.size(); ++i)
  {
    const double before = s[i - 1] - s[i - 2], after = s[i] - s[i - 1];
    largest = std::max(largest, std::max(before / after, after / before));
  }
  return largest;
}

/// Cells grown from the given ends by `r` (grownCell) and the uniform cap c with
/// sum(min(grown_i, c)) = length: the total is piecewise linear and increasing in c, found
/// exactly from the sorted cells (c is the largest cell when even that total falls short).
std::vector<double> grownCells(double first, double last, double r, double length, int cells,
  double& cap)
{
  std::vector<double> grown(cells);
  for (int i = 0; i < cells; ++i)
  {
    grown[i] = grownCell(first, last, r, i, cells);
  }
  std::vector<double> sorted = grown;
  std::sort(sorted.begin(), sorted.end());
  double below = 0.0;
  cap = sorted.back();
  for (int k = 0; k < cells; ++k)
  {
    const double candidate = (length - below) / (cells - k);
    if (candidate <= sorted[k])
    {
      cap = candidate;
      break;
    }
    below += sorted[k];
  }
  return grown;
}

/// Whether cells grown from both given ends by at most `ratio` (raised when too few to
/// fill the edge) and capped by a uniform middle keep both end cells: the cap that makes
/// them fill the edge is at least as large as either end.
bool grownKeepsEnds(double first, double last, double length, int cells, double ratio)
{
  if (grownLength(first, last, ratio, cells) < length)
  {
    return true; // the ratio is raised until they fill it: the cap is then the largest cell
  }
  double cap = 0.0;
  grownCells(first, last, ratio, length, cells, cap);
  return cap >= std::max(first, last);
}
} // namespace

std::vector<double> matchedNodes(double first, double last, double length, int nodeCount,
  double ratio, double flatness)
{
  if (nodeCount < 2)
  {
    throw GeometryError("an edge needs at least 2 nodes (1 cell), got " +
      std::to_string(nodeCount));
  }
  if (!(ratio > 1.0) || !std::isfinite(ratio))
  {
    throw GeometryError("match distribution: the growth ratio must be above 1, got " +
      toString(ratio));
  }
  if (!(length >= 0.0) || !std::isfinite(length))
  {
    throw GeometryError("match distribution: the edge length must be a length, got " +
      toString(length));
  }
  const int cells = nodeCount - 1;
  first = std::isfinite(first) ? first : 0.0;
  last = std::isfinite(last) ? last : 0.0;
  if ((first <= 0.0 && last <= 0.0) || cells == 1 || length == 0.0)
  {
    return uniform(nodeCount);
  }
  if (flatness != 0.0)
  {
    if (!(flatness >= 1.0) || !std::isfinite(flatness))
    {
      throw GeometryError("match distribution: the flatness of the bump must be at least 1, "
        "got " + toString(flatness));
    }
    const double mean = length / cells;
    return endSizes(first > 0.0 ? first / mean : 1.0, last > 0.0 ? last / mean : 1.0,
      nodeCount, flatness);
  }
  // An end cell larger than the mean cell: cells shrink from it towards the other end or
  // the middle, with both ends exact (log-linear sizes plus a bump, as the Ends law) --
  // unless both ends are given and cells grown from them to a uniform middle keep them
  // (the other end small enough): then those, so that the nodes do not jump when an end
  // cell passes the mean cell (two edges across a periodic pair of nearly equal means
  // sharing one end cell, one of them always a little above its mean).
  const double mean = length / cells;
  if ((first > mean || last > mean) &&
    !(first > 0.0 && last > 0.0 && grownKeepsEnds(first, last, length, cells, ratio)))
  {
    if (first <= 0.0 || last <= 0.0)
    {
      // one end given: cells shrink geometrically from it towards the free end, by at
      // most the ratio to the fourth (an end cell near the whole edge would leave the
      // others no room)
      const double q = std::pow(ratio, -4.0);
      const double largest = length * (1.0 - q) / (1.0 - std::pow(q, cells));
      const std::vector<double> s =
        firstCellSolvedRatio(std::min(std::max(first, last), largest), length, nodeCount);
      if (first > 0.0)
      {
        return s;
      }
      std::vector<double> reversed(s.size());
      for (std::size_t i = 0; i < s.size(); ++i)
      {
        reversed[i] = 1.0 - s[s.size() - 1 - i];
      }
      reversed.front() = 0.0;
      reversed.back() = 1.0;
      return reversed;
    }
    const double a = first / mean, b = last / mean;
    std::vector<double> s = endSizes(a, b, nodeCount);
    // Both end cells above the mean on an edge with few cells: the middle cells between
    // them shrink hard (a wake block's outlet edge of 5 cells at density 0.5 with ends 2.2
    // times its mean: 1.6e-3, 1.5e-4, 7e-5 m, long thin cells that fail checkMesh's face
    // tets). The cells then change by at most ratio^2 from one to the next: the end cells
    // are lowered towards the mean (a^t, b^t, the largest t in [0, 1] found by bisection,
    // t = 0 being uniform) until they do. ratio^2, not ratio: the end cells are the
    // neighbours' across the interface, whose ratio grows as they are lowered (ratio: 1.53
    // on the distributor at density 0.5, ratio^2: 1.33).
    const double limit = ratio * ratio;
    if (a > 1.0 && b > 1.0 && largestStep(s) > limit)
    {
      double low = 0.0, high = 1.0;
      for (int iteration = 0; iteration < 60; ++iteration)
      {
        const double t = 0.5 * (low + high);
        (largestStep(endSizes(std::pow(a, t), std::pow(b, t), nodeCount)) > limit ? high : low) = t;
      }
      s = endSizes(std::pow(a, low), std::pow(b, low), nodeCount);
    }
    return s;
  }
  // Cells grown by the ratio must reach the length, else the ratio is raised (bisection
  // on the growing total, deterministic).
  double r = ratio;
  if (grownLength(first, last, r, cells) < length)
  {
    double low = r, high = 2.0 * r;
    for (int iteration = 0; iteration < 200 && grownLength(first, last, high, cells) < length;
         ++iteration)
    {
      low = high;
      high *= 2.0;
    }
    bisect([&](double x) { return grownLength(first, last, x, cells) < length; }, low, high, 0.0, 200);
    r = high;
  }
  double cap = 0.0;
  const std::vector<double> grown = grownCells(first, last, r, length, cells, cap);
  std::vector<double> sizes(cells);
  for (int i = 0; i < cells; ++i)
  {
    sizes[i] = std::min(grown[i], cap);
  }
  return fromCellSizes(sizes, "match");
}

std::vector<double> distributeNodes(const DistributionLaw& law, int nodeCount,
  double edgeLength)
{
  if (nodeCount < 2)
  {
    throw GeometryError("an edge needs at least 2 nodes (1 cell), got " +
      std::to_string(nodeCount));
  }
  switch (law.kind)
  {
    case DistributionLaw::Kind::Uniform:
      return uniform(nodeCount);
    case DistributionLaw::Kind::Geometric:
      return geometric(law.expansionRatio, nodeCount);
    case DistributionLaw::Kind::TwoSided:
      return twoSided(law.expansionRatio, nodeCount);
    case DistributionLaw::Kind::FirstCell:
      return firstCell(law, nodeCount, edgeLength);
    case DistributionLaw::Kind::Ends:
      return endSizes(law.firstCellSize, law.lastCellSize, nodeCount, law.endsFlatness);
    case DistributionLaw::Kind::Match:
      return matchedNodes(law.firstCellSize, law.lastCellSize, edgeLength, nodeCount,
        law.expansionRatio, law.matchFlatness);
    case DistributionLaw::Kind::ProjectFrom:
      throw GeometryError("the nodes of a project_from edge are the projections of another "
                          "edge's nodes, which only the mesher knows");
  }
  throw GeometryError("unknown distribution law");
}

DistributionLaw reversedLaw(const DistributionLaw& law)
{
  DistributionLaw reversed = law;
  switch (law.kind)
  {
    case DistributionLaw::Kind::Geometric:
      requirePositiveRatio(law.expansionRatio, "geometric");
      reversed.expansionRatio = 1.0 / law.expansionRatio;
      return reversed;
    case DistributionLaw::Kind::FirstCell:
      throw GeometryError("a first-cell distribution cannot be reversed into another "
        "first-cell law; reverse its node parameters instead");
    case DistributionLaw::Kind::ProjectFrom:
      std::swap(reversed.fadeStart, reversed.fadeEnd);
      return reversed;
    case DistributionLaw::Kind::Ends:
    case DistributionLaw::Kind::Match:
      std::swap(reversed.firstCellSize, reversed.lastCellSize);
      return reversed;
    default:
      return reversed; // Uniform and TwoSided are symmetric
  }
}
} // namespace blockforge
