/**
 * @file FaceChecks.h
 * @brief Two of OpenFOAM checkMesh's face checks (-allGeometry) on the optimizer's grids:
 * the interpolation weight and the volume ratio of every face between two cells. The
 * optimizer refuses a configuration that fails more faces than the template placed
 * (ControlProblem): a control point the search moves can leave a wall cell beside one 20
 * to 80 times its width (the compressor's fan corners moved off the tip's arc while their
 * feet stay on it: 36 faces at density 1; the turbine's capped trailing edge: a corner
 * moved onto the cap corner's fan, 12), which its smallest angle does not see.
 *
 * OpenFOAM's definitions (polyMeshTools::faceWeights, volRatio; checkMesh's limits): with
 * face area vector S, face centre f and cell centres o, n (primitiveMesh's volume
 * centroids), the weight is min(dO, dN) / (dO + dN), dO = |S.(f - o)|, dN = |S.(n - f)|,
 * failed below 0.05; the volume ratio min(vO, vN) / max(vO, vN), failed below 0.01. Faces
 * between blocks are paired by coincident corners, periodic sides through their rotation
 * (as GridQuality pairs them).
 *
 * The same pairs give the neighbour size ratio across block interfaces (issue 8's
 * measure, InterfaceRatio), which the optimizer holds to a bound: the checks above fail
 * only at a jump of 19, while a jump of 3 to 5 already spoils a solver's gradients.
 */
#pragma once

#include "GridObjective.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

namespace blockforge
{
namespace optimize
{
/// checkMesh's limits (polyMesh::checkFaceWeight, checkVolRatio).
constexpr double MinimumFaceWeight = 0.05;
constexpr double MinimumVolumeRatio = 0.01;

/// Whether a face fails the interpolation weight or the volume ratio (area vector, face
/// centre, the two cells' centres and volumes).
inline bool weakFace(const Vec3& area, const Vec3& centre, const Vec3& owner, const Vec3& neighbour,
  double ownerVolume, double neighbourVolume)
{
  constexpr double vSmall = 1.0e-300; // OpenFOAM's VSMALL
  const double toOwner = std::abs(area.dot(centre - owner));
  const double toNeighbour = std::abs(area.dot(neighbour - centre));
  return std::min(toOwner, toNeighbour) < MinimumFaceWeight * (toOwner + toNeighbour + vSmall) ||
    std::min(ownerVolume, neighbourVolume) <
    MinimumVolumeRatio * (std::max(ownerVolume, neighbourVolume) + vSmall);
}

/// OpenFOAM's cell centres and volumes of one block grid, and how many faces between its
/// own cells fail (weakFace).
class BlockCells
{
public:
  explicit BlockCells(const BlockGrid& grid);
  const std::vector<Vec3>& centres() const { return Centres; }
  const std::vector<double>& volumes() const { return Volumes; }
  long long weakFaces() const { return Weak; }

private:
  std::vector<Vec3> Centres;
  std::vector<double> Volumes;
  long long Weak = 0;
};

/**
 * The neighbour size ratio across one face between blocks: the larger over the smaller
 * of the two cells' widths across it (the distance between the centres of a cell's face
 * on the interface and of its opposite face; TestGridFitness's and
 * Benchmark/interface_ratios.py's measure), and the two cells (block, cell i, j, k).
 */
struct InterfaceRatio
{
  double ratio = 1.0;
  int ownerBlock = -1, neighbourBlock = -1;
  std::array<int, 3> ownerCell{ { -1, -1, -1 } }, neighbourCell{ { -1, -1, -1 } };
};

/**
 * The faces between blocks (coincident corners, found on the grid given to the
 * constructor, which fixes the pairing: the optimizer moves nodes, not the topology) and
 * between periodic sides. weakFaces() counts those that fail on a grid with the same
 * block sizes.
 */
class InterfaceFaces
{
public:
  InterfaceFaces(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic);
  ~InterfaceFaces();
  long long weakFaces(
    const std::vector<BlockGrid>& blocks, const std::vector<const BlockCells*>& cells) const;
  /// The worst neighbour size ratio across the faces between blocks (periodic sides
  /// included) on a grid with the same block sizes: where it is and how large.
  InterfaceRatio largestRatio(const std::vector<BlockGrid>& blocks) const;

private:
  struct Pairs;
  std::unique_ptr<Pairs> P;
};

/// Faces of the whole grid that fail (within blocks and between them).
long long weakFaceCount(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic);
} // namespace optimize
} // namespace blockforge
