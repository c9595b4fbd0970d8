#include "InvertedCells.h"

#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace blockforge
{
namespace
{
struct P
{
  double x, y, z;
};
inline P operator-(const P& a, const P& b)
{
  return { a.x - b.x, a.y - b.y, a.z - b.z };
}
inline P operator+(const P& a, const P& b)
{
  return { a.x + b.x, a.y + b.y, a.z + b.z };
}
inline double dot(const P& a, const P& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double triple(const P& a, const P& b, const P& c)
{
  return a.x * (b.y * c.z - b.z * c.y) + a.y * (b.z * c.x - b.x * c.z) +
    a.z * (b.x * c.y - b.y * c.x);
}

// Verdict's corner frames (VTK hexahedron order): the three neighbours of each corner in
// right-handed order.
constexpr int neighbours[8][3] = { { 1, 3, 4 }, { 2, 0, 5 }, { 3, 1, 6 }, { 0, 2, 7 },
  { 7, 5, 0 }, { 4, 6, 1 }, { 5, 7, 2 }, { 6, 4, 3 } };

/// The 9 Jacobian frames of a cell: 8 corners and the centre (principal axes).
struct Frames
{
  P a[9], b[9], c[9];
};

inline void cellFrames(const P (&c)[8], Frames& f)
{
  for (int v = 0; v < 8; ++v)
  {
    f.a[v] = c[neighbours[v][0]] - c[v];
    f.b[v] = c[neighbours[v][1]] - c[v];
    f.c[v] = c[neighbours[v][2]] - c[v];
  }
  f.a[8] = (c[1] - c[0]) + (c[2] - c[3]) + ((c[5] - c[4]) + (c[6] - c[7]));
  f.b[8] = (c[3] - c[0]) + (c[2] - c[1]) + ((c[7] - c[4]) + (c[6] - c[5]));
  f.c[8] = (c[4] - c[0]) + (c[5] - c[1]) + ((c[6] - c[2]) + (c[7] - c[3]));
}

/**
 * Smallest normalised Jacobian of the frames whose raw determinant is not positive,
 * skipping frames with a collapsed vector (shorter than 1e-14 of the cell's longest
 * frame vector). +1 when none is measurable and negative.
 */
double smallestScaledJacobian(const Frames& f)
{
  double longest2 = 0.0;
  for (int v = 0; v < 8; ++v)
  {
    longest2 = std::max({ longest2, dot(f.a[v], f.a[v]), dot(f.b[v], f.b[v]),
      dot(f.c[v], f.c[v]) });
  }
  double smallest = 1.0;
  for (int v = 0; v < 9; ++v)
  {
    // The centre's vectors are sums of four edges.
    const double floor2 = (v == 8 ? 16.0 : 1.0) * 1.0e-28 * longest2;
    const double a2 = dot(f.a[v], f.a[v]), b2 = dot(f.b[v], f.b[v]),
                 c2 = dot(f.c[v], f.c[v]);
    if (a2 <= floor2 || b2 <= floor2 || c2 <= floor2 || longest2 <= 0.0)
    {
      continue;
    }
    smallest = std::min(smallest, triple(f.a[v], f.b[v], f.c[v]) / std::sqrt(a2 * b2 * c2));
  }
  return smallest;
}

/**
 * The smallest raw Jacobian determinant of the cell at node n0: at each corner the triple
 * product of the three grid edges leaving it along +i, +j, +k (the derivatives of the
 * trilinear map there), at the centre that of the sums of the four parallel edges. Same
 * signs as Verdict's frames; branch-free, so a row of cells pipelines well.
 */
inline double smallestRawJacobian(const double* xyz, std::size_t n0, std::size_t sj,
  std::size_t sk)
{
  auto at = [xyz](std::size_t n) { return P{ xyz[3 * n], xyz[3 * n + 1], xyz[3 * n + 2] }; };
  const P c0 = at(n0), c1 = at(n0 + 1), c3 = at(n0 + sj), c2 = at(n0 + 1 + sj);
  const P c4 = at(n0 + sk), c5 = at(n0 + 1 + sk), c7 = at(n0 + sj + sk),
          c6 = at(n0 + 1 + sj + sk);
  // Edges along +i at (j, k) = (0,0), (1,0), (0,1), (1,1); along +j at (i, k); along +k
  // at (i, j).
  const P i00 = c1 - c0, i10 = c2 - c3, i01 = c5 - c4, i11 = c6 - c7;
  const P j00 = c3 - c0, j10 = c2 - c1, j01 = c7 - c4, j11 = c6 - c5;
  const P k00 = c4 - c0, k10 = c5 - c1, k01 = c7 - c3, k11 = c6 - c2;
  double m = triple(i00, j00, k00);       // corner (0, 0, 0)
  m = std::min(m, triple(i00, j10, k10)); // (1, 0, 0)
  m = std::min(m, triple(i10, j00, k01)); // (0, 1, 0)
  m = std::min(m, triple(i10, j10, k11)); // (1, 1, 0)
  m = std::min(m, triple(i01, j01, k00)); // (0, 0, 1)
  m = std::min(m, triple(i01, j11, k10)); // (1, 0, 1)
  m = std::min(m, triple(i11, j01, k01)); // (0, 1, 1)
  m = std::min(m, triple(i11, j11, k11)); // (1, 1, 1)
  const P xi = (i00 + i10) + (i01 + i11), eta = (j00 + j10) + (j01 + j11),
          zeta = (k00 + k10) + (k01 + k11);
  // NaN when a node is NaN or infinite (the axes sum all 8 nodes): the cell then fails
  // the caller's positive test, whatever std::min made of the NaN determinants.
  const double finite = 0.0 * ((xi.x + xi.y + xi.z) + (eta.x + eta.y + eta.z) +
                                (zeta.x + zeta.y + zeta.z));
  return std::min(m, triple(xi, eta, zeta)) + finite;
}

/// findInvertedCells over the cell layers k0 <= k < k1.
InvertedCells findInLayers(
  const double* xyz, int ni, int nj, int k0, int k1, double tolerance)
{
  InvertedCells found;
  const std::size_t strideJ = static_cast<std::size_t>(ni);
  const std::size_t strideK = strideJ * static_cast<std::size_t>(nj);
  auto node = [xyz](std::size_t n) {
    return P{ xyz[3 * n], xyz[3 * n + 1], xyz[3 * n + 2] };
  };
  std::vector<double> smallest(static_cast<std::size_t>(ni - 1));
  Frames frames;
  for (int k = k0; k < k1; ++k)
  {
    for (int j = 0; j + 1 < nj; ++j)
    {
      const std::size_t row = strideJ * j + strideK * k;
      for (int i = 0; i + 1 < ni; ++i)
      {
        smallest[i] = smallestRawJacobian(xyz, row + i, strideJ, strideK);
      }
      for (int i = 0; i + 1 < ni; ++i)
      {
        // Most cells: every determinant positive (a NaN fails this too).
        if (smallest[i] > 0.0)
        {
          continue;
        }
        const std::size_t n0 = row + i;
        const P c[8] = { node(n0), node(n0 + 1), node(n0 + 1 + strideJ), node(n0 + strideJ),
          node(n0 + strideK), node(n0 + 1 + strideK), node(n0 + 1 + strideJ + strideK),
          node(n0 + strideJ + strideK) };
        cellFrames(c, frames);
        bool finiteNodes = true;
        for (const P& corner : c)
        {
          finiteNodes = finiteNodes && std::isfinite(corner.x) && std::isfinite(corner.y) &&
            std::isfinite(corner.z);
        }
        // NaN or infinite nodes fail every comparison above: report them as such.
        const double scaled = finiteNodes ? smallestScaledJacobian(frames)
                                          : std::numeric_limits<double>::quiet_NaN();
        const bool finite = std::isfinite(scaled);
        if (finite && scaled >= -tolerance)
        {
          continue;
        }
        if (!finite)
        {
          ++found.nonFinite; // a NaN or infinite node: as unusable as an inverted cell
        }
        const std::array<int, 3> cell{ i, j, k };
        if (found.count == 0)
        {
          found.lowest = found.highest = found.worstCell = cell;
        }
        for (int d = 0; d < 3; ++d)
        {
          found.lowest[d] = std::min(found.lowest[d], cell[d]);
          found.highest[d] = std::max(found.highest[d], cell[d]);
        }
        if (finite && scaled < found.worstScaledJacobian)
        {
          found.worstScaledJacobian = scaled;
          found.worstCell = cell;
        }
        ++found.count;
      }
    }
  }
  return found;
}
} // namespace

InvertedCells findInvertedCells(const double* xyz, int ni, int nj, int nk, double tolerance)
{
  if (ni < 2 || nj < 2 || nk < 2)
  {
    return InvertedCells();
  }
  // k-layer chunks on threads (Core/Parallel.h), merged in layer order: the same result
  // as one pass, bit for bit, whatever the threads.
  const long layerCells = static_cast<long>(ni - 1) * (nj - 1);
  const long chunks = chunkCount(layerCells * (nk - 1), 1L << 18, nk - 1);
  std::vector<InvertedCells> partial(static_cast<std::size_t>(chunks));
  forEachChunk(chunks, [&](long chunk) {
    const int k0 = static_cast<int>((nk - 1) * chunk / chunks);
    const int k1 = static_cast<int>((nk - 1) * (chunk + 1) / chunks);
    partial[static_cast<std::size_t>(chunk)] = findInLayers(xyz, ni, nj, k0, k1, tolerance);
  });
  InvertedCells found;
  for (const InvertedCells& part : partial)
  {
    if (part.count == 0)
    {
      continue;
    }
    if (found.count == 0)
    {
      found.lowest = part.lowest;
      found.highest = part.highest;
      found.worstCell = part.worstCell;
      found.worstScaledJacobian = part.worstScaledJacobian;
    }
    else
    {
      for (int d = 0; d < 3; ++d)
      {
        found.lowest[d] = std::min(found.lowest[d], part.lowest[d]);
        found.highest[d] = std::max(found.highest[d], part.highest[d]);
      }
      // The first cell with the most negative Jacobian, as in one pass in cell order.
      if (part.worstScaledJacobian < found.worstScaledJacobian)
      {
        found.worstScaledJacobian = part.worstScaledJacobian;
        found.worstCell = part.worstCell;
      }
    }
    found.count += part.count;
    found.nonFinite += part.nonFinite;
  }
  return found;
}
} // namespace blockforge
