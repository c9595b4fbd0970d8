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

void applyRule(BlockModel& model, const CarrierGeometry& geometry, int index)
{
  placeVertex(model, geometry, model.vertices[index]);
}

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

std::vector<std::vector<int>> vertexDependents(const BlockModel& model)
{
  std::vector<std::vector<int>> dependents(model.vertices.size());
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    const int source = ruleSource(model.vertices[v]);
    if (source >= 0 && source < static_cast<int>(model.vertices.size()))
    {
      dependents[source].push_back(static_cast<int>(v));
    }
  }
  return dependents;
}

std::vector<int> placementOrder(const BlockModel& model)
{
  const int count = static_cast<int>(model.vertices.size());
  const std::vector<std::vector<int>> dependents = vertexDependents(model);
  std::vector<int> order;
  order.reserve(count);
  std::vector<int> pending(count, 0);
  for (int v = 0; v < count; ++v)
  {
    const int source = ruleSource(model.vertices[v]);
    pending[v] = source >= 0 && source < count ? 1 : 0;
    if (!pending[v])
    {
      order.push_back(v);
    }
  }
  for (std::size_t next = 0; next < order.size(); ++next)
  {
    for (const int follower : dependents[order[next]])
    {
      if (--pending[follower] == 0)
      {
        order.push_back(follower);
      }
    }
  }
  if (static_cast<int>(order.size()) != count)
  {
    for (int v = 0; v < count; ++v)
    {
      if (pending[v])
      {
        const Vertex& vertex = model.vertices[v];
        throw TemplateError(vertex.where.file, vertex.where.line,
          syntax::entity("vertex", vertex.name),
          "its placement follows itself through other vertices (a cycle)");
      }
    }
  }
  return order;
}

std::vector<int> applyPlacement(
  BlockModel& model, const CarrierGeometry& geometry, const std::vector<int>& moved)
{
  const int count = static_cast<int>(model.vertices.size());
  const std::vector<std::vector<int>> dependents = vertexDependents(model);
  std::vector<char> affected(count, 0);
  std::vector<int> stack(moved.begin(), moved.end());
  while (!stack.empty())
  {
    const int v = stack.back();
    stack.pop_back();
    if (v < 0 || v >= count || affected[v])
    {
      continue;
    }
    affected[v] = 1;
    stack.insert(stack.end(), dependents[v].begin(), dependents[v].end());
  }
  std::vector<int> applied;
  for (const int v : placementOrder(model))
  {
    if (affected[v])
    {
      applyRule(model, geometry, v);
      applied.push_back(v);
    }
  }
  return applied;
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

std::vector<int> moveParameter(BlockModel& model, const CarrierGeometry& geometry,
  const FreeParameter& parameter, double value)
{
  const double bounded = parameter.wraps ? wrapUnit(value)
                                         : std::max(parameter.low, std::min(parameter.high, value));
  VertexConstraint& constraint = model.vertices[parameter.vertex].constraint;
  (parameter.component == 0 ? constraint.s : constraint.t) = bounded;
  return applyPlacement(model, geometry, { parameter.vertex });
}
} // namespace model
} // namespace blockforge
