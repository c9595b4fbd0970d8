/**
 * @file QualityMeasures.cpp
 * @brief The quality measures of one cell or one face (the public single-element
 * functions of Quality.h, through the same kernels as the grid pass: QualityKernels.h)
 * and the paper's MinAngle classes that summarise a grid.
 *
 * Split from Quality.cpp, which keeps the grid pass over whole multiblock grids.
 */
#include "Quality.h"
#include "QualityInterfaces.h"
#include "QualityKernels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace blockforge
{
using namespace quality;

namespace
{
inline void loadCorners(const std::array<Vec3, 8>& corners, P3 (&c)[8])
{
  for (int v = 0; v < 8; ++v)
  {
    c[v] = toP3(corners[v]);
  }
}

inline void loadFace(const std::array<Vec3, 4>& corners, P3 (&q)[4])
{
  for (int v = 0; v < 4; ++v)
  {
    q[v] = toP3(corners[v]);
  }
}
} // namespace

void hexFaceAngles(const std::array<Vec3, 8>& corners, double& minAngle, double& maxAngle)
{
  P3 c[8];
  loadCorners(corners, c);
  const CellShape shape = evaluateCellShape(c);
  minAngle = shape.minAngle;
  maxAngle = shape.maxAngle;
}

namespace
{
/// Cell by cell, as hexFaceAngles: what smallestMinAngle falls back to when a node is not
/// finite (the order of comparisons with NaN then decides, and this is the order).
double smallestMinAngleByCells(const double* xyz, int ni, int nj, int nk)
{
  // hexFaceAngles' minAngle is angleFromCosine(largest corner cosine) for a cell without
  // collapsed edges: the largest cosine over the block gives the smallest of those angles.
  double largestCosine = -1.0, smallestCollapsed = 180.0;
  const BlockView block(StructuredBlock{ xyz, ni, nj, nk });
  for (int k = 0; k < block.ck; ++k)
  {
    for (int j = 0; j < block.cj; ++j)
    {
      for (int i = 0; i < block.ci; ++i)
      {
        P3 c[8];
        block.cellCorners(i, j, k, c);
        // As evaluateCellShape: edge vectors, lengths, the corners' cosines.
        P3 e[12];
        double length2[12], inverseLength[12];
        cellEdges(c, e, length2, inverseLength);
        CornerAccumulator<double> corners{ e, inverseLength, 1.0, -1.0, verdictMax };
        corners.all();
        double shortest2 = length2[0], longest2 = length2[0];
        for (int n = 0; n < 12; ++n)
        {
          shortest2 = vmin(shortest2, length2[n]);
          longest2 = vmax(longest2, length2[n]);
        }
        const double collapsedLength2 = collapsedEdgeFraction * collapsedEdgeFraction * longest2;
        if (shortest2 > collapsedLength2)
        {
          largestCosine = std::max(largestCosine, corners.maxCos);
        }
        else
        {
          double minAngle = 0.0, maxAngle = 0.0;
          collapsedCellAngles(c, collapsedLength2, minAngle, maxAngle);
          smallestCollapsed = std::min(smallestCollapsed, minAngle);
        }
      }
    }
  }
  return block.cellCount > 0 ? std::min(angleFromCosine(largestCosine), smallestCollapsed)
                             : 180.0;
}

/// Edge vectors, squared lengths and inverse lengths of one direction's grid edges, as
/// cellEdges computes them for a cell (a grid edge has the same vector in all its cells),
/// i fastest, in buffers kept by the thread (no allocation once they have their size).
struct GridEdges
{
  std::vector<P3> vector;
  std::vector<double> length2, inverseLength;
  double shortest2 = 0.0, longest2 = 0.0; ///< over all these edges
  bool usable = true; ///< every squared length finite, and 0 or not below 1e-290
};

/// The grid edges from node (i, j, k) to (i + di, j + dj, k + dk). Not usable when a
/// squared length is not finite or so small (but not 0) that a product of inverse lengths
/// could overflow: a cosine could then be NaN, and the order of comparisons would matter.
void gridEdges(const BlockView& block, int di, int dj, int dk, GridEdges& edges)
{
  const int ei = block.ni - di, ej = block.nj - dj, ek = block.nk - dk;
  const std::size_t count = static_cast<std::size_t>(ei) * ej * ek;
  if (edges.vector.size() < count)
  {
    edges.vector.resize(count);
    edges.length2.resize(count);
    edges.inverseLength.resize(count);
  }
  const long step = 3 * (di + static_cast<long>(block.ni) * (dj + static_cast<long>(block.nj) * dk));
  double shortest2 = std::numeric_limits<double>::infinity(), longest2 = 0.0;
  bool unusable = false;
  std::size_t n = 0;
  for (int k = 0; k < ek; ++k)
  {
    for (int j = 0; j < ej; ++j)
    {
      const double* from = block.node(0, j, k);
      for (int i = 0; i < ei; ++i, ++n, from += 3)
      {
        const P3 e = load(from + step) - load(from);
        const double length2 = dot(e, e);
        unusable |= !(length2 <= std::numeric_limits<double>::max()) || (length2 > 0.0 && length2 < 1e-290);
        shortest2 = std::min(shortest2, length2);
        longest2 = std::max(longest2, length2);
        edges.vector[n] = e;
        edges.length2[n] = length2;
        edges.inverseLength[n] = length2 > 0.0 ? 1.0 / std::sqrt(length2) : 0.0;
      }
    }
  }
  edges.shortest2 = shortest2;
  edges.longest2 = longest2;
  edges.usable = !unusable;
}

/**
 * Largest corner cosine of one grid face: its edges along its first direction at indices
 * a0 (bottom, from its first corner) and a1 (top), along its second at b0 (left) and b1
 * (right). Each cosine is the product CornerAccumulator forms for that corner in either
 * cell of the face (the same pair of edges and sign; dot and products commute), so the
 * same bits.
 */
inline double faceLargestCosine(const GridEdges& a, std::size_t a0, std::size_t a1, const GridEdges& b,
  std::size_t b0, std::size_t b1)
{
  const P3 &bottom = a.vector[a0], &top = a.vector[a1], &left = b.vector[b0], &right = b.vector[b1];
  const double ib = a.inverseLength[a0], it = a.inverseLength[a1];
  const double il = b.inverseLength[b0], ir = b.inverseLength[b1];
  const double c0 = dot(bottom, left) * (ib * il);
  const double c1 = -1.0 * dot(bottom, right) * (ib * ir);
  const double c2 = dot(top, right) * (it * ir);
  const double c3 = -1.0 * dot(top, left) * (it * il);
  return std::max(std::max(c0, c1), std::max(c2, c3));
}
} // namespace

double smallestMinAngle(const double* xyz, int ni, int nj, int nk)
{
  // hexFaceAngles' minAngle is angleFromCosine(largest corner cosine) for a cell without
  // collapsed edges: the largest cosine over the block gives the smallest of those angles.
  // Every grid edge and every corner angle of a grid face is computed once (a pass cell by
  // cell computes each edge four times and each angle twice); a face's angles count when
  // a cell on either side of it has no collapsed edge. The largest of the same values is
  // the same bits in any order as long as none is NaN: where one could be, cell by cell.
  const BlockView block(StructuredBlock{ xyz, ni, nj, nk });
  if (block.cellCount <= 0)
  {
    return 180.0;
  }
  const int ci = block.ci, cj = block.cj, ck = block.ck;
  thread_local GridEdges ei, ej, ek; // along i, j, k
  gridEdges(block, 1, 0, 0, ei);
  gridEdges(block, 0, 1, 0, ej);
  gridEdges(block, 0, 0, 1, ek);
  if (!ei.usable || !ej.usable || !ek.usable)
  {
    return smallestMinAngleByCells(xyz, ni, nj, nk);
  }
  // Edge indices: i fastest, rows of ci (along i) or ni (along j, k) edges.
  auto at = [](int rowLength, int rows, int i, int j, int k) {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(rowLength) * (j + static_cast<std::size_t>(rows) * k);
  };
  // Cells with a collapsed edge (shorter than collapsedEdgeFraction of their longest) have
  // their angles from collapsedCellAngles. None when the shortest edge of the block is
  // not collapsed against its longest (then neither against a cell's longest).
  const double shortest2 = std::min(ei.shortest2, std::min(ej.shortest2, ek.shortest2));
  const double longest2 = std::max(ei.longest2, std::max(ej.longest2, ek.longest2));
  const bool allRegular = shortest2 > collapsedEdgeFraction * collapsedEdgeFraction * longest2;
  thread_local std::vector<char> regular;
  double smallestCollapsed = 180.0;
  if (!allRegular)
  {
    regular.assign(static_cast<std::size_t>(block.cellCount), 1);
    for (int k = 0; k < ck; ++k)
    {
      for (int j = 0; j < cj; ++j)
      {
        for (int i = 0; i < ci; ++i)
        {
          const double length2[12] = { ei.length2[at(ci, nj, i, j, k)],
            ej.length2[at(ni, cj, i + 1, j, k)], ei.length2[at(ci, nj, i, j + 1, k)],
            ej.length2[at(ni, cj, i, j, k)], ei.length2[at(ci, nj, i, j, k + 1)],
            ej.length2[at(ni, cj, i + 1, j, k + 1)], ei.length2[at(ci, nj, i, j + 1, k + 1)],
            ej.length2[at(ni, cj, i, j, k + 1)], ek.length2[at(ni, nj, i, j, k)],
            ek.length2[at(ni, nj, i + 1, j, k)], ek.length2[at(ni, nj, i + 1, j + 1, k)],
            ek.length2[at(ni, nj, i, j + 1, k)] };
          double cellShortest2 = length2[0], cellLongest2 = length2[0];
          for (int n = 0; n < 12; ++n)
          {
            cellShortest2 = vmin(cellShortest2, length2[n]);
            cellLongest2 = vmax(cellLongest2, length2[n]);
          }
          const double collapsedLength2 = collapsedEdgeFraction * collapsedEdgeFraction * cellLongest2;
          if (!(cellShortest2 > collapsedLength2))
          {
            regular[block.cell(i, j, k)] = 0;
            P3 c[8];
            block.cellCorners(i, j, k, c);
            double minAngle = 0.0, maxAngle = 0.0;
            collapsedCellAngles(c, collapsedLength2, minAngle, maxAngle);
            smallestCollapsed = std::min(smallestCollapsed, minAngle);
          }
        }
      }
    }
  }
  // A face counts when a cell on either side of it (the cell at its first corner, or the
  // one before it across the face) is regular.
  auto counts = [&](int i, int j, int k, int di, int dj, int dk) {
    if (allRegular)
    {
      return true;
    }
    const bool here = i < ci && j < cj && k < ck && regular[block.cell(i, j, k)];
    const bool before = i >= di && j >= dj && k >= dk && regular[block.cell(i - di, j - dj, k - dk)];
    return here || before;
  };
  double largestCosine = -1.0;
  // Faces across k (edges along i and j), across j (along i and k), across i (j and k).
  for (int k = 0; k < nk; ++k)
  {
    for (int j = 0; j < cj; ++j)
    {
      const std::size_t a = at(ci, nj, 0, j, k), b = at(ni, cj, 0, j, k);
      for (int i = 0; i < ci; ++i)
      {
        if (counts(i, j, k, 0, 0, 1))
        {
          largestCosine = std::max(largestCosine, faceLargestCosine(ei, a + i, a + i + ci, ej, b + i, b + i + 1));
        }
      }
    }
  }
  const std::size_t iLayer = static_cast<std::size_t>(ci) * nj, jLayer = static_cast<std::size_t>(ni) * cj;
  for (int k = 0; k < ck; ++k)
  {
    for (int j = 0; j < nj; ++j)
    {
      const std::size_t a = at(ci, nj, 0, j, k), b = at(ni, nj, 0, j, k);
      for (int i = 0; i < ci; ++i)
      {
        if (counts(i, j, k, 0, 1, 0))
        {
          largestCosine = std::max(largestCosine, faceLargestCosine(ei, a + i, a + i + iLayer, ek, b + i, b + i + 1));
        }
      }
    }
  }
  for (int k = 0; k < ck; ++k)
  {
    for (int j = 0; j < cj; ++j)
    {
      const std::size_t a = at(ni, cj, 0, j, k), b = at(ni, nj, 0, j, k);
      for (int i = 0; i < ni; ++i)
      {
        if (counts(i, j, k, 1, 0, 0))
        {
          largestCosine = std::max(largestCosine, faceLargestCosine(ej, a + i, a + i + jLayer, ek, b + i, b + i + ni));
        }
      }
    }
  }
  return std::min(angleFromCosine(largestCosine), smallestCollapsed);
}

double hexScaledJacobian(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).scaledJacobian;
}

double hexAspectRatio(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).aspectRatio;
}

Vec3 hexCentre(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return toVec3(cellCentroid(c));
}

double cellDeterminant(const std::vector<Vec3>& faceAreas)
{
  std::vector<P3> areas;
  std::vector<double> lengths;
  double sum = 0.0;
  for (const Vec3& area : faceAreas)
  {
    areas.push_back(toP3(area));
    lengths.push_back(area.norm());
    sum += lengths.back();
  }
  if (areas.empty() || sum < vSmall)
  {
    return 0.0;
  }
  return cellDeterminantKernel(areas.data(), lengths.data(), static_cast<int>(areas.size()));
}

double hexCellDeterminant(const std::array<Vec3, 8>& corners, const std::array<bool, 6>& counted)
{
  P3 c[8];
  loadCorners(corners, c);
  FaceGeometry<double> faces[6];
  hexFaceGeometry(c, faces);
  int mask = 0;
  for (int f = 0; f < 6; ++f)
  {
    mask |= counted[f] ? 1 << f : 0;
  }
  return cellDeterminantOfFaces(faces, mask);
}

void quadAreaAndCentre(
  const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, Vec3& area, Vec3& centre)
{
  const P3 q[4] = { toP3(a), toP3(b), toP3(c), toP3(d) };
  const FaceGeometry<double> face = scalarFace(q);
  area = toVec3(face.area);
  centre = toVec3(face.centre);
}

double faceNonOrthogonality(
  const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea)
{
  return angleFromCosine(
    orthogonalityCosine(toP3(neighbourCentre) - toP3(ownerCentre), toP3(faceArea)));
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea,
  const Vec3& faceCentre)
{
  const P3 owner = toP3(ownerCentre);
  const P3 d = toP3(neighbourCentre) - owner;
  const P3 area = toP3(faceArea);
  const P3 ownerToFace = toP3(faceCentre) - owner;
  const P3 sv = ownerToFace - (dot(area, ownerToFace) / (dot(area, d) + rootVSmall)) * d;
  return std::sqrt(dot(sv, sv)) / (std::sqrt(dot(d, d)) + rootVSmall);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea, const Vec3& faceCentre)
{
  const Vec3 normal = faceArea / (faceArea.norm() + rootVSmall);
  const Vec3 mirrored = ownerCentre + 2.0 * normal * normal.dot(faceCentre - ownerCentre);
  return faceSkewness(ownerCentre, mirrored, faceArea, faceCentre);
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea,
  const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners)
{
  P3 q[4];
  loadFace(faceCorners, q);
  const P3 owner = toP3(ownerCentre);
  return skewness(owner, toP3(neighbourCentre) - owner, 0.2, toP3(faceArea), toP3(faceCentre), q);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea, const Vec3& faceCentre,
  const std::array<Vec3, 4>& faceCorners)
{
  P3 q[4];
  loadFace(faceCorners, q);
  return boundarySkewness(toP3(ownerCentre), toP3(faceArea), toP3(faceCentre), q);
}

std::array<long long, 5> minAngleClasses(const double* minAngles, std::size_t count)
{
  std::array<long long, 5> counts{};
  for (std::size_t c = 0; c < count; ++c)
  {
    // Comparisons rather than a cast so that a NaN cannot index out of range.
    const double angle = minAngles[c];
    ++counts[(angle >= 20.0) + (angle >= 40.0) + (angle >= 60.0) + (angle >= 80.0)];
  }
  return counts;
}

std::array<long long, 5> minAngleClasses(const std::vector<CellQualityArrays>& quality)
{
  std::array<long long, 5> counts{};
  for (const CellQualityArrays& block : quality)
  {
    const auto blockCounts = minAngleClasses(block.minAngle.data(), block.minAngle.size());
    for (int c = 0; c < 5; ++c)
    {
      counts[c] += blockCounts[c];
    }
  }
  return counts;
}
} // namespace blockforge
