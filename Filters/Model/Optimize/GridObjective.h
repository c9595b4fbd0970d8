/**
 * @file GridObjective.h
 * @brief What the block optimizer measures on the final cells (paper section 2.4): the
 * smallest element angle of every cell, a smooth aggregate of the worst of them, the
 * neighbour size ratio along grid lines and, optionally, OpenFOAM's non-orthogonality.
 *
 * The smallest of a cell's 24 face corner angles is the arc cosine of the largest corner
 * cosine, so the kernel takes dot products of unit edge vectors (every grid edge is
 * normalised once and shared by the cells around it) and one acos per cell. Cells with a
 * collapsed edge (wedges and fans written as hexahedra) take Core's hexFaceAngles, the
 * definition GridQuality reports, so both agree: it leaves out a prism's apex at the
 * collapsed edge (the compressor's fans share the tip's turn among 5-20 cells per layer:
 * counted, the objective would sit on a constant of 13 to 3 degrees).
 */
#pragma once

#include "../../Core/Quality.h"

#include <array>
#include <string>
#include <vector>

namespace blockforge
{
namespace optimize
{
/// What the optimizer improves.
enum class ObjectiveKind
{
  MinAngle,            ///< maximise the smallest element angle (the paper's criterion)
  NonOrthogonality,    ///< minimise the largest OpenFOAM non-orthogonality
  MinAngleAndSizeRatio ///< the smallest angle, less a weighted neighbour size ratio
};

/// "MinAngle", "NonOrthogonality", "MinAngleAndSizeRatio".
const char* objectiveName(ObjectiveKind kind);
/// The kind of a name above; throws std::invalid_argument naming the choices otherwise.
ObjectiveKind objectiveFromName(const std::string& name);

struct ObjectiveSettings
{
  ObjectiveKind kind = ObjectiveKind::MinAngle;
  /// Sharpness of the smooth minimum of the cell angles, per degree: cells more than a
  /// few 1/sharpness degrees above the worst hardly count.
  double angleSharpness = 1.0;
  /// MinAngleAndSizeRatio: degrees of smallest angle worth one unit of neighbour size
  /// ratio above sizeRatioLimit (a ratio of 2 costs 0.5 * weight degrees).
  double sizeRatioWeight = 10.0;
  /// MinAngleAndSizeRatio: neighbour size ratios up to this cost nothing (1.5, the ratio
  /// the templates' `match` grading keeps). A penalty from 1 traded angle for ratios the
  /// templates' own grading sets (1.15-1.7 on the passage templates): 29.4 against 30.4
  /// degrees on the distributor's OH grid (Benchmark/OPTIMIZER.md).
  double sizeRatioLimit = 1.5;
  /// A configuration whose neighbour size ratio across the faces between blocks
  /// (FaceChecks.h InterfaceRatio) exceeds the larger of this and the start's is
  /// infeasible (ControlProblem); 0 or less: not held. Issue 8: unguarded, the optimized
  /// axial_passage_oh grids at density 1 jumped 3.58 (Rotor 37, U_M|U_R at the inlet),
  /// 2.50 (distributor), 4.70 (turbine). Smallest angle at density 1 (Rotor 37 /
  /// distributor) against this bound: 1.5: 43.86 / 45.22; 1.55: 47.42 / 47.10 (628
  /// trials on the distributor instead of 427); 1.6: 47.40 / 47.12 (the same trial counts);
  /// 1.7 and 2.0: 47.29 / 47.22 (unguarded 47.29 / 47.22).
  double maximumInterfaceRatio = 1.6;
  /// Issue 10: degrees of objective per cell failing checkMesh's cell determinant (the
  /// count failingCellsAwayFromWalls selects, less the start's), added to the angle
  /// objective; 0: the count is only refused above the start's. The optimizer's second
  /// search (OptimizerSettings::cellSearchAllowance) sets it; alone, as a penalty from the
  /// start, it cost angle on every machine (Optimizer.h).
  double failingCellWeight = 0.0;
  /// Which failing cells failingCellWeight counts: true, those that are not wall-layer
  /// cells (BlockCells::failingAwayFromWalls: the O-grid's wall layers fail by the
  /// template's request); false, all.
  bool failingCellsAwayFromWalls = false;
  /// A configuration whose smallest element angle is below this (degrees) is infeasible
  /// (ControlProblem); 0: not held. The optimizer's second search (OptimizerSettings::
  /// cellSearchAllowance) holds the first's end angle less the allowance.
  double minimumAngle = 0.0;
};

/// One block grid: ni x nj x nk nodes, 3 doubles per node, i fastest.
using BlockGrid = StructuredBlock;

/**
 * The element angles of one block grid. The constructor normalises every grid edge once
 * and takes the smallest angle of every cell (degrees, cell (i, j, k) at
 * i + (ni-1) (j + (nj-1) k)), equal to round-off to GridQuality's MinAngle.
 */
class BlockAngles
{
public:
  explicit BlockAngles(const BlockGrid& grid);
  const std::vector<double>& cellMinimum() const { return CellMin; }
  /// The smallest of cellMinimum() (180 for a block without cells).
  double lowest() const { return Lowest; }
  /**
   * Sum of exp(-sharpness (angle - lowest)) over the 24 face corner angles of every cell
   * (the terms of the smooth minimum); corners more than 20 / sharpness degrees above
   * `lowest` are left out (below 2e-9 of the worst corner's term).
   * Cells with a collapsed edge contribute their smallest angle once.
   */
  double cornerSum(double lowest, double sharpness) const;

private:
  bool touchesCollapsedEdge(std::size_t node) const;
  double exactMinAngle(std::size_t node) const;
  void cornerCosines(std::size_t node, double* out) const;
  BlockGrid Grid;
  std::vector<double> Edges; ///< unit vectors then lengths of the i, j and k grid edges
  std::array<std::size_t, 3> Steps{};
  double Collapsed = 0.0;
  std::vector<double> CellMin;
  double Lowest = 180.0;
  std::vector<char> Exact;
};

/// Smallest element angle of every cell of a block into `out` (BlockAngles::cellMinimum).
void cellMinAngles(const BlockGrid& grid, double* out);

/**
 * Smooth minimum (Kreisselmeier-Steinhauser) of `values`:
 * m - ln(sum exp(-k (v - m))) / k with m the true minimum; never above m and at most
 * ln(count) / k below it. Values more than 20 / k above m are skipped (their terms are
 * below 2e-9 of the minimum's).
 */
double softMinimum(const std::vector<double>& values, double sharpness);

/// Largest ratio of neighbouring edge lengths along the grid lines of a block (1 for a
/// uniform grid), within the block.
double maxNeighbourSizeRatio(const BlockGrid& grid);

/// What one evaluation measured on a whole grid.
struct GridMeasures
{
  bool feasible = false;          ///< grid built and no inverted cell
  long long invertedCells = 0;
  double minAngle = 0.0;          ///< smallest element angle of all cells, degrees
  double softMinAngle = 0.0;      ///< smooth minimum of all face corner angles
  double maxSizeRatio = 1.0;      ///< largest neighbour size ratio (MinAngleAndSizeRatio)
  double maxNonOrthogonality = 0.0; ///< NonOrthogonality objective only, degrees
  std::array<long long, 5> classes{}; ///< MinAngle classes 0-20, 20-40, ... 80-90
  /// Angle objectives: per block, whether any of its corners lies within the smooth
  /// minimum's window (cornerSum counts it); a step that changes only blocks outside the
  /// window cannot raise the smooth minimum. Empty for other objectives.
  std::vector<char> activeBlocks;
  /// Faces failing checkMesh's interpolation weight or volume ratio (FaceChecks.h); a
  /// configuration with more than its start is infeasible. 0 when not measured.
  long long weakFaces = 0;
  /// Cells failing checkMesh's cell determinant (FaceChecks.h BlockCells); a configuration
  /// with more than its start is infeasible. 0 when not measured.
  long long failingCells = 0;
  /// The failing cells that drive the search (ObjectiveSettings::failingCellsAwayFromWalls:
  /// those that are not wall-layer cells, or all); 0 when not measured.
  long long drivenFailingCells = 0;
  /// Largest neighbour size ratio across the faces between blocks (FaceChecks.h); 0 when
  /// not measured.
  double interfaceRatio = 0.0;
  double objective = 0.0;         ///< the value minimised (lower is better)
  std::string failure;            ///< why it is not feasible
};

/// Penalty objective of an infeasible configuration (far above any feasible value, and
/// growing with the inverted cell count so the optimizer sees the way back).
double infeasibleObjective(long long invertedCells);

/**
 * Measures the grid of every block (and, for NonOrthogonality, the interfaces and the
 * periodic sides in `periodic`) and the objective of `settings`. Inverted cells make the
 * configuration infeasible.
 */
GridMeasures measureGrid(const std::vector<BlockGrid>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const ObjectiveSettings& settings);

/**
 * The angle objectives (MinAngle, MinAngleAndSizeRatio with the grid's largest neighbour
 * size ratio `maxSizeRatio`) of a feasible grid from the angles of its blocks, in block
 * order: what measureGrid gives, bit for bit, so an optimizer may keep the angles of the
 * blocks a step did not change.
 */
GridMeasures measureAngles(const std::vector<const BlockAngles*>& blocks, double maxSizeRatio,
  const ObjectiveSettings& settings);

/// Whether `candidate` is no worse than `reference` by the objective's own criterion
/// (smallest angle for the angle objectives, largest non-orthogonality otherwise).
bool notWorse(const GridMeasures& candidate, const GridMeasures& reference, ObjectiveKind kind);
} // namespace optimize
} // namespace blockforge
