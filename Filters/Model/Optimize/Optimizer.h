/**
 * @file Optimizer.h
 * @brief The block optimizer (paper step 3, section 2.4): manual moves first, then the
 * control points slide along their carriers until the final cells are as good as the
 * geometry allows. The output is the same block model with moved vertices.
 */
#pragma once

#include "ControlProblem.h"
#include "Search.h"

namespace blockforge
{
namespace optimize
{
/// The largest grid the objective is measured on (nodes): the final grid (the density the
/// mesher is asked for) up to this size; a larger one is measured on a coarsened copy (a
/// smaller density multiplier), which keeps a run within tens of seconds but does not
/// rank configurations exactly as the final grid does (two points of a run on the
/// distributor's OH grid: 26.9 and 28.9 degrees at density 1, 26.6 and 26.0 at density 2).
constexpr double MaximumMeasuredNodes = 1.0e5;

/// The density multiplier the objective is measured at: `densityMultiplier`, lowered by
/// factors of 0.8 until the grid has at most MaximumMeasuredNodes nodes.
double measuredDensity(const model::BlockModel& model, double densityMultiplier);

struct OptimizerSettings
{
  ObjectiveSettings objective;
  SearchSettings search;
  /// The grid the objective measures: the model's cell counts times this (as BlockMesher),
  /// coarsened to at most MaximumMeasuredNodes nodes.
  double densityMultiplier = 1.0;
  /// The final grid at densityMultiplier must fit in this memory (GB; 0: what the machine
  /// has available), as the mesher checks it: a grid the mesher would refuse is refused
  /// before the optimizer works on it.
  double maximumMemory = 0.0;
  /// Control points that stay where they are (names of vertices).
  std::vector<std::string> fixed;
  /// Manual moves, applied before the automatic run, which then holds these points.
  std::vector<ControlPointMove> moves;
  /// false: only the manual moves are applied (no automatic run).
  bool automatic = true;
  /// The automatic run also skews the node distributions of block directions graded
  /// `ends` (ControlProblem): axial_passage_oh's blade sides, which the O-grid's sides
  /// follow (`project_from`) and its edge blocks match (`match`). OH smallest angle on the
  /// four machines 28.5 / 22.8 / 22.7 / 29.0 -> 34.1 / 28.7 / 24.1 / 29.2 degrees
  /// (Benchmark/OPTIMIZER_LIMITS.md).
  bool skewDistributions = true;
  /// A skewed distribution's end cells change at most this many times either way (2
  /// left one more checkMesh failure on Rotor 37's OH grid, an interpolation weight).
  double maximumSkew = 3.0;
  /// Issue 10: after the angle search, a second search from its end point drives down the
  /// cells failing checkMesh's cell determinant away from walls (ObjectiveSettings::
  /// failingCellsAwayFromWalls: on axial_passage_oh exactly the H blocks' count) with
  /// cellSearchWeight degrees per cell (above the angles' range: fewest cells first, then
  /// the angle), holding the smallest angle at the first search's end less this allowance
  /// (degrees; 0: no second search). axial_passage_oh at density 1, H blocks' failing
  /// cells and end angle (distributor / Rotor 37 / compressor / turbine): one search
  /// 49 / 31 / 129 / 8 at 47.40 / 47.38 / 23.25 / 34.63 degrees; with the second search
  /// (0.35, step 0.1, the rest of the 700 trials) 28 / 2 / 65 / 7 at 47.40 / 47.45 / 23.41
  /// / 35.69 (the second search also raises the angle where the count ties), 1.3-1.7 times
  /// the trials (given 300 beyond the first's on the distributor: 25 at 47.34). Tried and
  /// left (stop 18, figures in README): the count as a penalty from the start
  /// (failingCellWeight 0.03-1, all cells or away from walls: 18-28 H cells on the
  /// distributor but at 44.2-45.3 degrees, Rotor 37 0-2 at 41.9-46.6), lexicographic from
  /// the start (32.6 degrees on Rotor 37 counting all cells), a ratchet (no trial with more
  /// cells than the current configuration: 28 / 2 / 101 / 6 at 44.3 / 44.8 / 22.7 / 35.0);
  /// allowance 1: 25 / 9 / 70 / 4 (47.02 / 47.05 degrees); a second step of 0.05: 29 / 6 /
  /// 73 / 4, 0.01-0.02: Rotor 37 keeps its 31.
  double cellSearchAllowance = 0.35;
  double cellSearchWeight = 100.0;
  /// The second search's trial budget, at most what the first left of SearchSettings::
  /// maxEvaluations (600 beyond the first's: 26 / 6 / 66 / 4 at 48.00 / 47.99 degrees,
  /// 2.2 times the trials), and its first step (SearchSettings::initialStep).
  int cellSearchEvaluations = 300;
  double cellSearchStep = 0.1;
};

struct OptimizerResult
{
  model::BlockModel model;           ///< the model with moved vertices
  GridMeasures before;               ///< the input model's grid
  GridMeasures after;                ///< the output model's grid
  /// History of the automatic run; without one (manual moves only), the input's evaluation
  /// and, when points were moved, the moved model's.
  SearchResult search;
  std::vector<ControlVariable> variables;
  std::vector<std::string> boundaryLocked;
  double densityMultiplier = 1.0;    ///< the density the objective was measured at
  /// Fraction of the search's move kept so that the grid at the requested density (not
  /// only the coarsened copy measured) is valid: 1 = all of it, 0 = the start.
  double keptStep = 1.0;
};

/**
 * Optimizes `model` (its carriers built in `geometry`, which is updated for surface
 * curves drawn through moved points). Throws model::TemplateError for bad names or
 * moves and when the input model cannot be meshed. `progress` gets fractions in [0, 1].
 */
OptimizerResult optimizeModel(const model::BlockModel& model, model::CarrierGeometry& geometry,
  const OptimizerSettings& settings, const ProgressFunction& progress = {});
} // namespace optimize
} // namespace blockforge
