/**
 * @file ControlProblem.h
 * @brief The block optimizer's problem on a model (paper section 2.4): which control
 * point parameters may move, within which bounds, and what the final cells are at a
 * configuration.
 *
 * Variables are the free parameters of the placement rules (Placement.h): s of a control
 * point on a curve, (s, t) on a surface, and (x, y, z) of a free interior vertex (a block
 * vertex placed by position, on no boundary face). A parameter is left out when
 * - its vertex is fixed by name (FixedControlPoints, or moved by hand) or marked
 *   `fixed: true` in the template;
 * - moving it moves no block vertex (directly or through the vertices that follow it);
 * - moving it would change the domain's boundary: a moved vertex (itself or a follower)
 *   on a boundary face leaves that face's surface carrier or, for faces without one,
 *   the face's plane (a curved boundary face without carrier holds its vertices).
 *   Periodic faces are not boundary: their partners move with them.
 * Bounds keep each vertex between its neighbours on its carrier: the block vertices next
 * to it along a curve carrier, or its block-edge neighbours in each parameter direction
 * of a surface; a vertex may cover 45 % of the way to a neighbour that moves too, 90 %
 * to one that stays.
 *
 * With `maximumSkew` above 1, a block direction whose four edges are graded `{ends: [a, b]}`
 * in every block that uses them, or projected from another edge (`project_from`, which
 * then follows its source), with at least one `ends` edge and none on a periodic face,
 * gets a variable u, its skew: the `ends` edges' end cells become a e^-u and b e^u (at
 * most maximumSkew times either way), so its nodes slide towards one end on all four
 * edges at once, and with them the nodes of the neighbour blocks that share those edges. That is what a blade passage's O-grid side
 * needs for the H lines beside it to cross a staggered passage at a fair angle: the
 * nodes of side a shifted against those of side b (measured on the OH template: Rotor 37
 * 23.6 -> 30.8 degrees with the end cells skewed 3 times, Benchmark/OPTIMIZER_LIMITS.md).
 *
 * A configuration is infeasible when its grid folds, or when it fails more of checkMesh's
 * interpolation-weight and volume-ratio faces than the start's grid (FaceChecks.h; e.g. a
 * fan's corner moved off the tip's arc while its feet stay on the tip): the smallest angle
 * does not see a wall cell beside one 20 times its width; or when more of its cells fail
 * checkMesh's cell determinant than the start's (FaceChecks.h: the O-grid's thin cells
 * count too; counting only the cells off the walls' layers kept the turbine's angle
 * better at density 1 but let it end with more failing cells at 0.5). It is infeasible too when two
 * cells across a block interface differ more than ObjectiveSettings::maximumInterfaceRatio
 * times (or than the start's grid's, where that is more; FaceChecks.h InterfaceRatio):
 * the inlet points sliding along the inlet (lo_in, b_in) and the O-grid's corner ob_f left
 * Rotor 37's U_M cell at the inlet 3.6 times its U_R neighbour, none of it in the angles
 * the search improves (issue 8).
 *
 * Everything that follows a moved vertex follows it: vertices placed from it (rules),
 * the parameters of carrier edges ending at it, and surface curves drawn through it.
 * Evaluations run on a mesh plan (MeshPlan.h) kept between them, which recomputes only
 * what depends on the parameters that changed.
 */
#pragma once

#include "GridObjective.h"

#include "BlockModel.h"
#include "CarrierGeometry.h"

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
struct Topology;
}
namespace optimize
{
/// One free parameter: component 0 (s) or 1 (t) of control point `vertex`, or component
/// 2, 3, 4 (x, y, z) of the position of a free interior vertex, or (component
/// SkewComponent, vertex -1) the skew of the node distribution of direction `direction` of
/// block `block` (see ControlProblem).
struct ControlVariable
{
  static constexpr int SkewComponent = 5;
  int vertex = -1;
  int component = 0;
  int block = -1, direction = -1; ///< a skew's block direction
  double start = 0.0, low = 0.0, high = 1.0;
  std::string name; ///< "vertex.s", "vertex.t", or "vertex.x", "vertex.y", "vertex.z"
  /// A small step of it moved no vertex, carrier edge end or curve (its vertex follows a
  /// rule that places it whatever the parameter): its trials cannot change the grid.
  bool inert = false;
};

/// A manual move: the control point's new parameters (s on a curve, s and t on a surface).
struct ControlPointMove
{
  std::string name;
  std::vector<double> parameters;
};

/**
 * Applies manual moves (and everything that follows them) to `model`; surface curves
 * drawn through a moved point are drawn again in `geometry`. Throws
 * model::TemplateError naming the vertex when it is unknown, not a control point with
 * free parameters, given the wrong number of values or values outside its carrier.
 */
void applyMoves(model::BlockModel& model, model::CarrierGeometry& geometry,
  const std::vector<ControlPointMove>& moves);

/**
 * A manual move given as a point (the GUI's handle): the parameters of the point of
 * control point `name`'s carrier nearest to `point`.
 */
ControlPointMove moveTowards(const model::BlockModel& model, const model::CarrierGeometry& geometry,
  const std::string& name, const Vec3& point);

class ControlProblem
{
public:
  /// Throws model::TemplateError for unknown fixed names and for models the mesher refuses.
  ControlProblem(const model::BlockModel& model, const model::CarrierGeometry& geometry,
    double densityMultiplier, const ObjectiveSettings& objective,
    const std::vector<std::string>& fixed, double maximumSkew = 0.0);
  ~ControlProblem();

  const std::vector<ControlVariable>& variables() const { return Variables; }
  std::vector<double> start() const;
  std::vector<double> low() const;
  std::vector<double> high() const;
  /// Control points held because they would move the domain's boundary, for the log.
  const std::vector<std::string>& boundaryLocked() const { return Locked; }

  /**
   * Whether a configuration whose grid fails more of checkMesh's interpolation-weight and
   * volume-ratio faces or cell determinants (FaceChecks.h) than the start's, or jumps more across a block
   * interface than ObjectiveSettings::maximumInterfaceRatio allows, is infeasible (the
   * default), or only measured (GridMeasures::weakFaces).
   */
  void refuseWeakFaces(bool refuse);
  /// What evaluate() measures from now on (the kind must stay the same).
  void setObjective(const ObjectiveSettings& objective);

  /// Places the configuration, meshes it and measures its final cells. Never throws: a
  /// configuration the mesher refuses is infeasible, with the reason in `failure`.
  GridMeasures evaluate(const std::vector<double>& x);
  /**
   * Whether moving variable `variable` alone from the configuration measured as `current`
   * may raise the smooth minimum angle (a TrialFilter for the search). False only when
   * every block such a move recomputed in the evaluations so far lies outside the smooth
   * minimum's window (GridMeasures::activeBlocks): the other blocks keep their angles, so
   * the move can only add terms to the smooth minimum's sum (or lower the minimum itself,
   * the objective gaining then at most through corners near the window's far edge, whose
   * terms are below e^-14 of the worst corner's). False for an inert variable. Otherwise
   * true for other objectives and for a variable not yet moved in a feasible evaluation.
   */
  bool mayGain(std::size_t variable, const GridMeasures& current) const;
  /**
   * Puts the grid back to the configuration before the last evaluate() (a trial the search
   * did not take) with the mesh plan's undo and the angles measured there, instead of
   * moving back at the next evaluation: that one then recomputes only what its own move
   * changes. Evaluations and grids stay the same, bit for bit. Does nothing when the last
   * evaluation did not update the plan (its placement failed) or was already put back.
   */
  void reject();
  /// The model at configuration x (vertices, carrier edges and surface curves moved).
  model::BlockModel modelAt(const std::vector<double>& x);
  /// The vertices placed at configuration x (placement rules only: no edge, curve or
  /// grid follows), e.g. for scores of the blocks as single cells.
  std::vector<Vec3> verticesAt(const std::vector<double>& x) const;
  /// The grid (nodes of every block, i fastest) at configuration x; throws
  /// std::runtime_error when it is infeasible.
  std::vector<std::vector<double>> gridAt(const std::vector<double>& x);

private:
  /// The skew variables of the block directions graded `ends` (see the class comment).
  void addSkewVariables(
    const model::Topology& topology, const std::set<int>& periodicFaces, double maximumSkew);
  struct Impl;
  std::unique_ptr<Impl> P;
  std::vector<ControlVariable> Variables;
  std::vector<std::string> Locked;
};
} // namespace optimize
} // namespace blockforge
