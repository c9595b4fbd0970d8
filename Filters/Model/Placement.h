/**
 * @file Placement.h
 * @brief Vertex placement: every vertex keeps its rule (VertexRule in BlockModel.h) and
 * its parameters; applying the rules in dependency order gives the positions. The
 * template engine places its vertices through applyRule, and the optimizer and manual
 * moves change free parameters and call applyPlacement, which also moves everything that
 * follows the moved vertices: projections, periodic images, rotated copies, vertices
 * placed by expressions that refer to moved vertices (PlacementExpressions, evaluated
 * again in the template's scope), curves drawn through moved vertices (drawn again) and
 * the vertices on those curves.
 *
 * Fixed positions given by expressions (VertexRule::Kind::Fixed) are evaluated when the
 * template is read; they do not follow later moves.
 */
#pragma once

#include "BlockModel.h"
#include "CarrierGeometry.h"

#include <memory>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
/// The diagonal of the bounding box of the vertices with finite positions (those placed
/// so far while a template is read), 0 when there are none.
double placedVertexSpan(const BlockModel& model);

/// The vertex whose position `vertex`'s rule follows, -1 when it follows none.
int ruleSource(const Vertex& vertex);

/// Every vertex whose position `vertex`'s rule follows: its rule source and the vertices
/// its placement expressions refer to.
std::vector<int> ruleSources(const Vertex& vertex);

/// Cylindrical coordinates of p about the machine axis, theta from `thetaZero` (a unit
/// vector normal to the axis), and back.
void cylindricalAbout(const Machine& machine, const Vec3& thetaZero, const Vec3& p, double& axial,
  double& radius, double& theta);
Vec3 fromCylindricalAbout(
  const Machine& machine, const Vec3& thetaZero, double axial, double radius, double theta);

/**
 * Parameters (s, t) of the point of surface of revolution `surface` (about the machine
 * axis) at `axial` and angle `theta`: the contour's first crossing of the axial plane,
 * then the exact meridional projection. Throws GeometryError saying why there is none.
 */
void revolutionParametersAt(const BlockModel& model, const CarrierGeometry& geometry,
  const Vec3& thetaZero, int surface, double axial, double theta, double& s, double& t);

/**
 * @class PlacementScope
 * @brief The template's expressions evaluated again (parameters, machine values and
 * carrier queries kept in the model, definitions evaluated when first used, vertex
 * queries from the current positions), kept through one application of the placement:
 * a definition is evaluated again only after a vertex it refers to moved (moved()).
 */
class PlacementScope
{
public:
  explicit PlacementScope(const BlockModel& model);
  ~PlacementScope();
  PlacementScope(const PlacementScope&) = delete;
  PlacementScope& operator=(const PlacementScope&) = delete;
  /// The value of `text`; GeometryError saying why there is none.
  double evaluate(const std::string& text);
  /// Vertex `vertex` moved: its queries and the definitions referring to it are stale.
  void moved(int vertex);

private:
  struct Impl;
  std::unique_ptr<Impl> P;
};

/// Evaluates the `at` expressions of edge `index` again with the current positions of
/// the vertices they refer to (Edge::atExpressions). Throws GeometryError.
void evaluateEdgeEnds(BlockModel& model, int index);
void evaluateEdgeEnds(BlockModel& model, int index, PlacementScope& scope);

/// The parameters (s, t) vertex `index`'s placement expressions give with the current
/// positions of the vertices they refer to. Throws GeometryError.
Eigen::Vector2d evaluatePlacementExpressions(
  const BlockModel& model, const CarrierGeometry& geometry, int index);
Eigen::Vector2d evaluatePlacementExpressions(
  const BlockModel& model, const CarrierGeometry& geometry, int index, PlacementScope& scope);

/**
 * Places `vertex` by its rule, from its parameters and the positions of the vertices of
 * `model` it follows: sets its position and, for projections and periodic images, its
 * carrier parameters. `vertex` need not be in `model` yet (the template places each
 * vertex as it reads it).
 */
void placeVertex(const BlockModel& model, const CarrierGeometry& geometry, Vertex& vertex);

/**
 * Applies the rule of `vertex` from its parameters and the current position of the vertex
 * it follows: sets its position and, for projections and periodic images, its carrier
 * parameters. The result is the same bit for bit whoever calls it (template, optimizer).
 */
void applyRule(BlockModel& model, const CarrierGeometry& geometry, int vertex);
/// (applyRule: vertices placed by expressions get what the expressions give plus their
/// shift; TemplateError naming the vertex when the expressions no longer place it.)

/// For every vertex, the vertices that follow it directly: through their rules, and (a
/// curve drawn through it) the vertices on that curve and on carriers built on it.
std::vector<std::vector<int>> vertexDependents(const BlockModel& model);

/// For every vertex, whether a move can shift it: a control point the optimizer or a
/// manual move may change (on a carrier, not marked `fixed`), or a vertex that follows
/// one (through rules, expressions or curves drawn through it).
std::vector<char> movableVertices(const BlockModel& model);

/// Every vertex once, each after the vertices it follows. Throws TemplateError naming
/// a vertex on a cycle.
std::vector<int> placementOrder(const BlockModel& model);

/**
 * Applies the rules of `moved` and of every vertex that follows them (directly or through
 * others), in dependency order. Returns the vertices whose rules were applied, in that
 * order (`moved` included).
 */
std::vector<int> applyPlacement(
  BlockModel& model, CarrierGeometry& geometry, const std::vector<int>& moved);
/// The same with carriers that stay as they are: curves through moved vertices are drawn
/// again in a copy (the vertices on them are placed on the new curves; callers that keep
/// carriers for later, such as a mesh plan, pass theirs to be changed).
std::vector<int> applyPlacement(
  BlockModel& model, const CarrierGeometry& geometry, const std::vector<int>& moved);
/// (applyPlacement: curves drawn through moved vertices are drawn again in `geometry`,
/// with the carriers built on them, before the vertices on them are placed; edge ends
/// given by expressions of moved vertices are evaluated again.)

/// A parameter the optimizer (or a manual move) may change: component 0 (s) or 1 (t) of
/// a control point's carrier parameters, within [low, high]; `wraps` on closed carriers.
struct FreeParameter
{
  int vertex = -1;
  int component = 0;
  double low = 0.0, high = 1.0;
  bool wraps = false;
};

/// The free parameters of the model: s (and t on surfaces) of every OnCarrier vertex.
std::vector<FreeParameter> freeParameters(const BlockModel& model, const CarrierGeometry& geometry);

/**
 * Sets component `component` of vertex `vertex`'s parameters to `value` (wrapped on
 * closed carriers, as given otherwise) without placing it. A vertex placed by
 * expressions keeps `value` less its expressions' base as its shift: it lands at `value`
 * (to rounding) while the vertices it follows are where they were for the base, and
 * follows them with that shift when they move. Its parameters thus stay free for the
 * optimizer and manual moves, and positions are a function of the parameters.
 */
void setParameter(BlockModel& model, const CarrierGeometry& geometry, int vertex, int component,
  double value);

/// Takes what the placement expressions give now as their base, for every vertex placed
/// by expressions (before a manual move or an optimization: moves then shift vertices
/// from where the expressions put them in that configuration).
void rebasePlacementExpressions(BlockModel& model, const CarrierGeometry& geometry);

/// Sets free parameter `parameter` to `value` (wrapped into [0, 1) on closed carriers,
/// clamped into the bounds otherwise) and applies the placement; returns what
/// applyPlacement returns.
std::vector<int> moveParameter(BlockModel& model, CarrierGeometry& geometry,
  const FreeParameter& parameter, double value);
std::vector<int> moveParameter(BlockModel& model, const CarrierGeometry& geometry,
  const FreeParameter& parameter, double value);
} // namespace model
} // namespace blockforge
