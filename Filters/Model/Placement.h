/**
 * @file Placement.h
 * @brief Vertex placement: every vertex keeps its rule (VertexRule in BlockModel.h) and
 * its parameters; applying the rules in dependency order gives the positions. The
 * template engine places its vertices through applyRule, and the optimizer and manual
 * moves change free parameters and call applyPlacement, which also moves everything that
 * follows the moved vertices (projections, periodic images, rotated copies).
 *
 * Positions given by expressions (VertexRule::Kind::Fixed) are evaluated when the
 * template is read; they do not follow later moves.
 */
#pragma once

#include "BlockModel.h"
#include "CarrierGeometry.h"

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

/// For every vertex, the vertices whose rules follow it directly.
std::vector<std::vector<int>> vertexDependents(const BlockModel& model);

/// Every vertex once, each after the vertex its rule follows. Throws TemplateError naming
/// a vertex on a cycle.
std::vector<int> placementOrder(const BlockModel& model);

/**
 * Applies the rules of `moved` and of every vertex that follows them (directly or through
 * others), in dependency order. Returns the vertices whose rules were applied, in that
 * order (`moved` included).
 */
std::vector<int> applyPlacement(
  BlockModel& model, const CarrierGeometry& geometry, const std::vector<int>& moved);

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

/// Sets free parameter `parameter` to `value` (wrapped into [0, 1) on closed carriers,
/// clamped into the bounds otherwise) and applies the placement; returns what
/// applyPlacement returns.
std::vector<int> moveParameter(BlockModel& model, const CarrierGeometry& geometry,
  const FreeParameter& parameter, double value);
} // namespace model
} // namespace blockforge
