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

#include <cmath>

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

double smallestMinAngle(const double* xyz, int ni, int nj, int nk)
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
