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
 *
 * And they tell which block-side faces are internal or coupled for checkMesh's cell
 * determinant (Core's hexCellDeterminant, GridQuality's CellDeterminant; failed below
 * 1e-3): BlockCells counts the failing cells, exactly checkMesh's count (the four OH
 * passages at density 1, placed and optimized: 638, 309, 942, 362 and 474, 311, 1036, 388
 * on both). The optimizer refuses a configuration with more of them than its start: its
 * moves raised the count on Rotor 37 (309 -> 311, U_R 0 -> 27), the compressor (942 ->
 * 1036) and the turbine (362 -> 388) at density 1. It also counts those that are not
 * wall-layer cells (failingAwayFromWalls; on axial_passage_oh the H blocks' cells, 171 /
 * 32 / 180 / 21 placed), which its second search drives down (OptimizerSettings::
 * cellSearchAllowance).
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
/// checkMesh's limits (polyMesh::checkFaceWeight, checkVolRatio, checkCellDeterminant).
constexpr double MinimumFaceWeight = 0.05;
constexpr double MinimumVolumeRatio = 0.01;
constexpr double MinimumCellDeterminant = 1.0e-3;
/// A failing cell whose mean edge along a direction that runs to a wall side of its block
/// is under this fraction of its longest mean edge is a wall-layer cell (BlockCells).
constexpr double WallLayerRatio = 0.1;

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

/**
 * OpenFOAM's cell centres and volumes of one block grid, and how many faces between its
 * own cells fail (weakFace). With `boundarySides` (one entry per cell, i fastest: the bits
 * 1 << side, 0..5 = i0 i1 j0 j1 k0 k1, of the cell's faces on the true boundary, as
 * InterfaceFaces::boundarySides gives them), also how many cells fail checkMesh's cell
 * determinant (Core's hexCellDeterminant with those faces left out, as GridQuality's
 * CellDeterminant: below MinimumCellDeterminant).
 */
class BlockCells
{
public:
  /// `wallSides`: the bits 1 << side of the block's sides on wall patches; a failing cell
  /// whose mean edge along a direction that runs to such a side is under WallLayerRatio of
  /// its longest is a wall-layer cell (thin because the template clusters its cells to
  /// that wall).
  explicit BlockCells(const BlockGrid& grid, const std::vector<unsigned char>* boundarySides = nullptr,
    unsigned char wallSides = 0);
  const std::vector<Vec3>& centres() const { return Centres; }
  const std::vector<double>& volumes() const { return Volumes; }
  long long weakFaces() const { return Weak; }
  /// Cells failing the cell determinant (0 without boundarySides).
  long long failingCells() const { return Failing; }
  /// Of failingCells(), those that are not wall-layer cells (see the constructor).
  long long failingAwayFromWalls() const { return FailingAway; }

private:
  std::vector<Vec3> Centres;
  std::vector<double> Volumes;
  long long Weak = 0;
  long long Failing = 0;
  long long FailingAway = 0;
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
  /// Per cell of block `block` (i fastest), the bits 1 << side of its faces on the true
  /// boundary: block sides not paired here (GridQuality's pairing: the faces its cell
  /// determinant leaves out).
  const std::vector<unsigned char>& boundarySides(int block) const;

private:
  struct Pairs;
  std::unique_ptr<Pairs> P;
};

/// Faces of the whole grid that fail (within blocks and between them).
long long weakFaceCount(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic);

/// Cells of the whole grid that fail checkMesh's cell determinant (GridQuality's
/// CellDeterminant below MinimumCellDeterminant).
long long failingCellCount(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic);
} // namespace optimize
} // namespace blockforge
