#include "Placement.h"

#include "../Core/Carriers.h"
#include "Errors.h"
#include "ModelSyntax.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace blockforge
{
namespace model
{
int ruleSource(const Vertex& vertex)
{
  switch (vertex.rule.kind)
  {
    case VertexRule::Kind::Projected:
    case VertexRule::Kind::Rotated:
      return vertex.rule.source;
    case VertexRule::Kind::Periodic:
      return vertex.constraint.periodicSource;
    default:
      return -1;
  }
}

std::vector<int> ruleSources(const Vertex& vertex)
{
  std::vector<int> sources = vertex.rule.expressions.follows;
  const int source = ruleSource(vertex);
  if (source >= 0)
  {
    sources.push_back(source);
  }
  return sources;
}

double placedVertexSpan(const BlockModel& model)
{
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  bool any = false;
  for (const Vertex& vertex : model.vertices)
  {
    if (vertex.position.allFinite())
    {
      low = low.cwiseMin(vertex.position);
      high = high.cwiseMax(vertex.position);
      any = true;
    }
  }
  return any ? (high - low).norm() : 0.0;
}

namespace
{
/// The paper's parameter offsets: the image of a point on a surface of revolution about
/// the machine axis is on the same surface at t + angle / (a1 - a0), if that is on it.
void periodicParameters(const BlockModel& model, const CarrierGeometry& geometry,
  const Vertex& original, double angle, VertexConstraint& constraint)
{
  constraint.carrier = -1;
  if (original.constraint.carrier < 0)
  {
    return;
  }
  const Machine& machine = model.machine;
  const int carrier = original.constraint.carrier;
  const Carrier& definition = model.carriers[carrier];
  if (definition.kind == Carrier::Kind::Revolve &&
    (definition.axis - machine.axis).norm() <= 1e-12 &&
    (definition.axisPoint - machine.axisPoint).norm() <= 1e-12 * std::max(1.0, placedVertexSpan(model)))
  {
    double t = original.constraint.t + angle / (definition.angleEnd - definition.angleStart);
    if (geometry.closedT(carrier))
    {
      t = wrapUnit(t);
    }
    if (t >= 0.0 && t <= 1.0)
    {
      constraint.carrier = carrier;
      constraint.s = original.constraint.s;
      constraint.t = t;
    }
  }
}
} // namespace

namespace
{
void applyRuleIn(BlockModel& model, const CarrierGeometry& geometry, int index,
  std::unique_ptr<PlacementScope>& scope);
}

void applyRule(BlockModel& model, const CarrierGeometry& geometry, int index)
{
  std::unique_ptr<PlacementScope> scope;
  applyRuleIn(model, geometry, index, scope);
}

namespace
{
/// applyRule with the expression scope of the placement it is part of (made when first
/// needed).
void applyRuleIn(BlockModel& model, const CarrierGeometry& geometry, int index,
  std::unique_ptr<PlacementScope>& scope)
{
  Vertex& vertex = model.vertices[index];
  const PlacementExpressions& expressions = vertex.rule.expressions;
  if (vertex.rule.kind == VertexRule::Kind::OnCarrier &&
    expressions.form != PlacementExpressions::Form::None)
  {
    Eigen::Vector2d st;
    try
    {
      if (!scope)
      {
        scope.reset(new PlacementScope(model));
      }
      st = evaluatePlacementExpressions(model, geometry, index, *scope);
    }
    catch (const GeometryError& error)
    {
      throw TemplateError(vertex.where.file, vertex.where.line,
        syntax::entity("vertex", vertex.name),
        std::string("its placement expressions no longer place it: ") + error.what());
    }
    const int carrier = vertex.constraint.carrier;
    const bool surface = geometry.isSurface(carrier);
    for (int c = 0; c < (surface ? 2 : 1); ++c)
    {
      double value = st[c];
      if (expressions.shift[c] != 0.0)
      {
        value += expressions.shift[c];
        const bool closed = c == 0 ? geometry.closedS(carrier) : geometry.closedT(carrier);
        const double low = c == 0 ? 0.0 : geometry.tMin(carrier);
        const double high = c == 0 ? 1.0 : geometry.tMax(carrier);
        value = closed ? wrapUnit(value) : std::max(low, std::min(high, value));
      }
      (c == 0 ? vertex.constraint.s : vertex.constraint.t) = value;
    }
  }
  placeVertex(model, geometry, vertex);
  if (scope)
  {
    scope->moved(index);
  }
}
} // namespace

void placeVertex(const BlockModel& model, const CarrierGeometry& geometry, Vertex& vertex)
{
  VertexConstraint& constraint = vertex.constraint;
  switch (vertex.rule.kind)
  {
    case VertexRule::Kind::Fixed:
      return;
    case VertexRule::Kind::OnCarrier:
    case VertexRule::Kind::Intersection:
      vertex.position = geometry.point(constraint.carrier, constraint.s, constraint.t);
      return;
    case VertexRule::Kind::Projected:
    {
      double s = 0.0, t = 0.0, distance = 0.0;
      geometry.project(constraint.carrier, model.vertices[vertex.rule.source].position, s, t, distance);
      constraint.s = s;
      constraint.t = t;
      vertex.position = geometry.point(constraint.carrier, s, t);
      return;
    }
    case VertexRule::Kind::Periodic:
    {
      const Machine& machine = model.machine;
      const double angle = constraint.pitches * machine.pitch();
      const Vertex& original = model.vertices[constraint.periodicSource];
      vertex.position = rotateAboutAxis(original.position, machine.axisPoint, machine.axis, angle);
      periodicParameters(model, geometry, original, angle, constraint);
      return;
    }
    case VertexRule::Kind::Rotated:
    {
      const Eigen::AngleAxisd rotation(vertex.rule.angle, vertex.rule.axis);
      vertex.position = vertex.rule.origin +
        rotation * (model.vertices[vertex.rule.source].position - vertex.rule.origin);
      return;
    }
  }
}

namespace
{
/**
 * What follows what, vertices and carriers together: node v < vertexCount is vertex v,
 * node vertexCount + c is carrier c. A vertex follows the vertices of its rule; a curve
 * drawn through vertices follows them; a carrier follows the carriers it is built on; a
 * vertex on a carrier (or projected onto it) follows the carrier.
 */
struct PlacementGraph
{
  int vertexCount = 0;
  std::vector<std::vector<int>> followers;
  std::vector<int> order; ///< every node after the nodes it follows

  /// The nodes reached from `starts` (included) along followers; with `stopAtVertices`
  /// the walk goes on only through carriers.
  std::vector<char> reach(const std::vector<int>& starts, bool stopAtVertices) const
  {
    std::vector<char> reached(followers.size(), 0);
    std::vector<int> stack(starts.begin(), starts.end());
    while (!stack.empty())
    {
      const int node = stack.back();
      stack.pop_back();
      if (reached[node])
      {
        continue;
      }
      reached[node] = 1;
      if (!stopAtVertices || node >= vertexCount)
      {
        stack.insert(stack.end(), followers[node].begin(), followers[node].end());
      }
    }
    return reached;
  }
};

PlacementGraph placementGraph(const BlockModel& model)
{
  PlacementGraph graph;
  const int vertexCount = static_cast<int>(model.vertices.size());
  const int carrierCount = static_cast<int>(model.carriers.size());
  const int nodes = vertexCount + carrierCount;
  graph.vertexCount = vertexCount;
  graph.followers.assign(nodes, {});
  std::vector<int> pending(nodes, 0);
  auto follow = [&](int followed, int follower) {
    if (followed < 0 || followed >= nodes || follower == followed)
    {
      return;
    }
    std::vector<int>& list = graph.followers[followed];
    if (std::find(list.begin(), list.end(), follower) == list.end())
    {
      list.push_back(follower);
      ++pending[follower];
    }
  };
  for (int v = 0; v < vertexCount; ++v)
  {
    for (const int source : ruleSources(model.vertices[v]))
    {
      if (source < vertexCount)
      {
        follow(source, v);
      }
    }
  }
  for (int c = 0; c < carrierCount; ++c)
  {
    const Carrier& carrier = model.carriers[c];
    for (const int vertex : carrier.throughVertices)
    {
      if (vertex >= 0 && vertex < vertexCount)
      {
        follow(vertex, vertexCount + c);
      }
    }
    for (const std::vector<int>* refs : { &carrier.refs, &carrier.crossRefs })
    {
      for (const int ref : *refs)
      {
        if (ref >= 0 && ref < carrierCount)
        {
          follow(vertexCount + ref, vertexCount + c);
        }
      }
    }
  }
  for (int v = 0; v < vertexCount; ++v)
  {
    const Vertex& vertex = model.vertices[v];
    const VertexRule::Kind kind = vertex.rule.kind;
    if (vertex.constraint.carrier >= 0 && vertex.constraint.carrier < carrierCount &&
      (kind == VertexRule::Kind::OnCarrier || kind == VertexRule::Kind::Intersection ||
        kind == VertexRule::Kind::Projected))
    {
      follow(vertexCount + vertex.constraint.carrier, v);
    }
  }
  for (int node = 0; node < nodes; ++node)
  {
    if (pending[node] == 0)
    {
      graph.order.push_back(node);
    }
  }
  for (std::size_t next = 0; next < graph.order.size(); ++next)
  {
    for (const int follower : graph.followers[graph.order[next]])
    {
      if (--pending[follower] == 0)
      {
        graph.order.push_back(follower);
      }
    }
  }
  if (static_cast<int>(graph.order.size()) != nodes)
  {
    for (int v = 0; v < nodes; ++v)
    {
      if (pending[v])
      {
        const SourceLocation& where =
          v < vertexCount ? model.vertices[v].where : model.carriers[v - vertexCount].where;
        throw TemplateError(where.file, where.line,
          v < vertexCount ? syntax::entity("vertex", model.vertices[v].name)
                          : syntax::entity("carrier", model.carriers[v - vertexCount].name),
          "its placement follows itself through other vertices (a cycle)");
      }
    }
  }
  return graph;
}

/// Draws curve `c` again through its vertices' current parameters on its surface (and
/// builds carriers built on a changed carrier again); true when it changed.
bool redrawCarrier(BlockModel& model, CarrierGeometry& geometry, int c, const std::vector<char>& changed)
{
  Carrier& carrier = model.carriers[c];
  bool changes = false;
  for (std::size_t k = 0; k < carrier.throughVertices.size() && k < carrier.parameterPoints.size(); ++k)
  {
    const int vertex = carrier.throughVertices[k];
    if (vertex < 0 || carrier.refs.empty())
    {
      continue;
    }
    double s = 0.0, t = 0.0, distance = 0.0;
    geometry.vertexParameters(model, vertex, carrier.refs[0], s, t, distance);
    const Eigen::Vector2d st(s, t);
    if (st != carrier.parameterPoints[k])
    {
      carrier.parameterPoints[k] = st;
      changes = true;
    }
  }
  for (const std::vector<int>* refs : { &carrier.refs, &carrier.crossRefs })
  {
    for (const int ref : *refs)
    {
      changes = changes || (ref >= 0 && changed[ref]);
    }
  }
  if (changes)
  {
    geometry.rebuild(model, c);
  }
  return changes;
}
} // namespace

std::vector<std::vector<int>> vertexDependents(const BlockModel& model)
{
  const PlacementGraph graph = placementGraph(model);
  const int vertexCount = graph.vertexCount;
  std::vector<std::vector<int>> dependents(vertexCount);
  for (int v = 0; v < vertexCount; ++v)
  {
    // followers, through carriers to the vertices on them (not further)
    const std::vector<char> reached = graph.reach(graph.followers[v], true);
    for (int w = 0; w < vertexCount; ++w)
    {
      if (reached[w])
      {
        dependents[v].push_back(w);
      }
    }
  }
  return dependents;
}

std::vector<char> movableVertices(const BlockModel& model)
{
  const PlacementGraph graph = placementGraph(model);
  std::vector<int> controlPoints;
  for (int v = 0; v < graph.vertexCount; ++v)
  {
    const Vertex& vertex = model.vertices[v];
    if (vertex.rule.kind == VertexRule::Kind::OnCarrier && !vertex.fixed)
    {
      controlPoints.push_back(v);
    }
  }
  std::vector<char> reached = graph.reach(controlPoints, false);
  reached.resize(graph.vertexCount);
  return reached;
}

std::vector<int> placementOrder(const BlockModel& model)
{
  const PlacementGraph graph = placementGraph(model);
  std::vector<int> order;
  for (const int node : graph.order)
  {
    if (node < graph.vertexCount)
    {
      order.push_back(node);
    }
  }
  return order;
}

std::vector<int> applyPlacement(
  BlockModel& model, CarrierGeometry& geometry, const std::vector<int>& moved)
{
  const PlacementGraph graph = placementGraph(model);
  const int vertexCount = graph.vertexCount;
  std::vector<int> starts;
  for (const int v : moved)
  {
    if (v >= 0 && v < vertexCount)
    {
      starts.push_back(v);
    }
  }
  const std::vector<char> affected = graph.reach(starts, false);
  std::vector<int> applied;
  std::vector<char> changedCarrier(model.carriers.size(), 0);
  std::unique_ptr<PlacementScope> scope; // one for every expression, made when needed
  for (const int node : graph.order)
  {
    if (!affected[node])
    {
      continue;
    }
    if (node >= vertexCount)
    {
      const int c = node - vertexCount;
      changedCarrier[c] = redrawCarrier(model, geometry, c, changedCarrier) ? 1 : 0;
      continue;
    }
    applyRuleIn(model, geometry, node, scope);
    applied.push_back(node);
  }
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    const Edge& edge = model.edges[e];
    if (std::any_of(edge.atFollows.begin(), edge.atFollows.end(),
          [&](int v) { return v >= 0 && v < vertexCount && affected[v]; }))
    {
      try
      {
        if (!scope)
        {
          scope.reset(new PlacementScope(model));
        }
        evaluateEdgeEnds(model, static_cast<int>(e), *scope);
      }
      catch (const GeometryError& error)
      {
        throw TemplateError(edge.where.file, edge.where.line, syntax::entity("edge", edge.name),
          std::string("its 'at' expressions no longer place its ends: ") + error.what());
      }
    }
  }
  return applied;
}

std::vector<int> applyPlacement(
  BlockModel& model, const CarrierGeometry& geometry, const std::vector<int>& moved)
{
  CarrierGeometry redrawn = geometry;
  return applyPlacement(model, redrawn, moved);
}

std::vector<FreeParameter> freeParameters(const BlockModel& model, const CarrierGeometry& geometry)
{
  std::vector<FreeParameter> parameters;
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    const Vertex& vertex = model.vertices[v];
    if (vertex.rule.kind != VertexRule::Kind::OnCarrier)
    {
      continue;
    }
    const int carrier = vertex.constraint.carrier;
    FreeParameter s;
    s.vertex = static_cast<int>(v);
    s.wraps = geometry.closedS(carrier);
    parameters.push_back(s);
    if (geometry.isSurface(carrier))
    {
      FreeParameter t;
      t.vertex = static_cast<int>(v);
      t.component = 1;
      t.low = geometry.tMin(carrier);
      t.high = geometry.tMax(carrier);
      t.wraps = geometry.closedT(carrier);
      parameters.push_back(t);
    }
  }
  return parameters;
}

void setParameter(BlockModel& model, const CarrierGeometry& geometry, int vertex, int component,
  double value)
{
  Vertex& moved = model.vertices[vertex];
  VertexConstraint& constraint = moved.constraint;
  const bool closed =
    component == 0 ? geometry.closedS(constraint.carrier) : geometry.closedT(constraint.carrier);
  const double set = closed ? wrapUnit(value) : value;
  (component == 0 ? constraint.s : constraint.t) = set;
  PlacementExpressions& expressions = moved.rule.expressions;
  if (expressions.form != PlacementExpressions::Form::None)
  {
    // from the expressions' value as the template placed it: the same value gives the
    // same shift whatever moved before (a function of the parameters, for optimizers)
    double shift = set - expressions.base[component];
    if (closed)
    {
      shift -= std::floor(shift + 0.5); // the short way round
    }
    expressions.shift[component] = shift;
  }
}

void rebasePlacementExpressions(BlockModel& model, const CarrierGeometry& geometry)
{
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    PlacementExpressions& expressions = model.vertices[v].rule.expressions;
    if (expressions.form == PlacementExpressions::Form::None)
    {
      continue;
    }
    try
    {
      const Eigen::Vector2d st = evaluatePlacementExpressions(model, geometry, static_cast<int>(v));
      expressions.base = { { st[0], st[1] } };
    }
    catch (const GeometryError&)
    {
      // keeps its base: applying the placement reports the vertex
    }
  }
}

std::vector<int> moveParameter(BlockModel& model, CarrierGeometry& geometry,
  const FreeParameter& parameter, double value)
{
  const double bounded = parameter.wraps ? wrapUnit(value)
                                         : std::max(parameter.low, std::min(parameter.high, value));
  setParameter(model, geometry, parameter.vertex, parameter.component, bounded);
  return applyPlacement(model, geometry, { parameter.vertex });
}

std::vector<int> moveParameter(BlockModel& model, const CarrierGeometry& geometry,
  const FreeParameter& parameter, double value)
{
  CarrierGeometry redrawn = geometry;
  return moveParameter(model, redrawn, parameter, value);
}
} // namespace model
} // namespace blockforge
