// Vertex placement by template expressions that refer to other vertices: evaluated again,
// in the template's scope, with the current positions of those vertices.
#include "Placement.h"

#include "../Core/Carriers.h"
#include "../Core/RootFinding.h"
#include "ModelSyntax.h"
#include "TemplateExpressions.h"

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <set>

namespace blockforge
{
namespace model
{
void cylindricalAbout(const Machine& machine, const Vec3& thetaZero, const Vec3& p, double& axial,
  double& radius, double& theta)
{
  const Vec3& axis = machine.axis;
  const Vec3 q = p - machine.axisPoint;
  axial = q.dot(axis);
  const Vec3 radial = q - axial * axis;
  radius = radial.norm();
  const Vec3 e2 = axis.cross(thetaZero);
  theta = std::atan2(radial.dot(e2), radial.dot(thetaZero));
}

Vec3 fromCylindricalAbout(
  const Machine& machine, const Vec3& thetaZero, double axial, double radius, double theta)
{
  const Vec3& axis = machine.axis;
  const Vec3 e2 = axis.cross(thetaZero);
  return machine.axisPoint + axial * axis +
    radius * (std::cos(theta) * thetaZero + std::sin(theta) * e2);
}

void revolutionParametersAt(const BlockModel& model, const CarrierGeometry& geometry,
  const Vec3& thetaZero, int surface, double axial, double theta, double& s, double& t)
{
  const SurfaceOfRevolution* revolution = geometry.revolution(surface);
  const Machine& machine = model.machine;
  const std::string& name = model.carriers[surface].name;
  const double size = std::max(geometry.size(surface), 1e-300);
  if (!revolution || revolution->axisDirection().cross(machine.axis).norm() > 1e-12 ||
    (revolution->axisPoint() - machine.axisPoint).cross(machine.axis).norm() > 1e-12 * size)
  {
    throw GeometryError("'axial' and 'theta' place a vertex on a surface of revolution about "
                        "the machine axis; '" + name + "' is not one");
  }
  auto f = [&](double u) {
    double a = 0.0, r = 0.0, th = 0.0;
    cylindricalAbout(machine, thetaZero, geometry.point(surface, u, 0.5), a, r, th);
    return a - axial;
  };
  // The contour's first crossing of the axial plane: the sign change in 256 samples,
  // then bisection to rounding.
  const int samples = 256;
  double a = 0.0, fa = f(0.0);
  bool found = fa == 0.0;
  double root = 0.0;
  for (int k = 1; k <= samples && !found; ++k)
  {
    const double b = static_cast<double>(k) / samples, fb = f(b);
    if (fb == 0.0)
    {
      root = b;
      found = true;
    }
    else if ((fa < 0.0) != (fb < 0.0))
    {
      // the sign of f switches at the crossing: bisect that predicate to rounding
      const bool negative = fa < 0.0;
      double low = a, high = b;
      bisect([&](double u) { return (f(u) < 0.0) == negative; }, low, high, 1e-16, 200);
      root = 0.5 * (low + high);
      found = true;
    }
    a = b;
    fa = fb;
  }
  if (!found)
  {
    double a0 = 0.0, a1 = 0.0, r = 0.0, th = 0.0;
    cylindricalAbout(machine, thetaZero, geometry.point(surface, 0.0, 0.5), a0, r, th);
    cylindricalAbout(machine, thetaZero, geometry.point(surface, 1.0, 0.5), a1, r, th);
    throw GeometryError("surface '" + name + "' does not reach axial = " +
      syntax::shortNumber(axial) + " (its contour spans axial " +
      syntax::shortNumber(std::min(a0, a1)) + " to " + syntax::shortNumber(std::max(a0, a1)) + ")");
  }
  double ignored = 0.0, radius = 0.0;
  cylindricalAbout(machine, thetaZero, geometry.point(surface, root, 0.5), ignored, radius, ignored);
  double distance = 0.0;
  const Vec3 target = fromCylindricalAbout(machine, thetaZero, axial, radius, theta);
  geometry.project(surface, target, s, t, distance);
  if ((geometry.point(surface, s, t) - target).norm() > 1e-9 * size)
  {
    throw GeometryError("theta = " + syntax::shortNumber(theta) +
      " is outside the angle range of surface '" + name + "'");
  }
}

namespace
{
/// Expressions placements evaluated, for every scope: the value of an expression is a
/// function of its text and its constants' values alone (ExpressionMemo), whichever
/// model they come from.
detail::ExpressionMemo& placementMemo()
{
  static detail::ExpressionMemo memo;
  return memo;
}
} // namespace

/// The template's expression scope, evaluating definitions when first used and vertex
/// queries from the current positions: the same values and the same operations as when
/// the template was read, so the same bits for the same positions.
struct PlacementScope::Impl
{
  explicit Impl(const BlockModel& model)
    : Model(model)
  {
    Evaluator.Memo = &placementMemo();
    for (const auto& value : model.expressionScope.values)
    {
      Evaluator.defineQuery(value.first, value.second);
    }
    for (const auto& definition : model.expressionScope.definitions)
    {
      Definitions[definition.first] = &definition.second;
    }
    Evaluator.OnReference = [this](const std::string& name, const std::string& attribute) {
      resolve(name, attribute);
    };
  }

  void resolve(const std::string& name, const std::string& attribute)
  {
    if (attribute.empty())
    {
      const auto definition = Definitions.find(name);
      if (definition == Definitions.end())
      {
        return; // a parameter or machine value: among the values
      }
      auto known = DefinitionVertices.find(name);
      if (known == DefinitionVertices.end())
      {
        Collecting.emplace_back();
        const double value = Evaluator.evaluate(*definition->second);
        known = DefinitionVertices.emplace(name, std::move(Collecting.back())).first;
        Collecting.pop_back();
        Evaluator.define(name, value);
      }
      if (!Collecting.empty())
      {
        Collecting.back().insert(known->second.begin(), known->second.end());
      }
      return;
    }
    const int index = Model.findVertex(name);
    if (index < 0)
    {
      return; // a carrier query: among the values
    }
    if (Queried.insert(index).second)
    {
      const Vertex& vertex = Model.vertices[index];
      double cylindrical[3] = { 0.0, 0.0, 0.0 };
      cylindricalAbout(Model.machine, Model.expressionScope.thetaZero, vertex.position,
        cylindrical[0], cylindrical[1], cylindrical[2]);
      const double st[2] = { vertex.constraint.s, vertex.constraint.t };
      Evaluator.defineVertexQueries(
        name, vertex.position.data(), cylindrical, vertex.constraint.carrier >= 0 ? st : nullptr);
    }
    if (!Collecting.empty())
    {
      Collecting.back().insert(index);
    }
  }

  const BlockModel& Model;
  detail::ExpressionEvaluator Evaluator;
  std::map<std::string, const std::string*> Definitions;
  /// Definitions evaluated, with the vertices they refer to (directly or through others).
  std::map<std::string, std::set<int>> DefinitionVertices;
  std::vector<std::set<int>> Collecting;
  std::set<int> Queried; ///< vertices whose queries are defined
};

PlacementScope::PlacementScope(const BlockModel& model)
  : P(new Impl(model))
{
}

PlacementScope::~PlacementScope() = default;

double PlacementScope::evaluate(const std::string& text)
{
  try
  {
    return P->Evaluator.evaluate(text);
  }
  catch (const detail::ExpressionError& error)
  {
    throw GeometryError(error.message);
  }
}

void PlacementScope::moved(int vertex)
{
  P->Queried.erase(vertex);
  for (auto it = P->DefinitionVertices.begin(); it != P->DefinitionVertices.end();)
  {
    it = it->second.count(vertex) ? P->DefinitionVertices.erase(it) : std::next(it);
  }
}

void evaluateEdgeEnds(BlockModel& model, int index, PlacementScope& scope)
{
  Edge& edge = model.edges[index];
  if (edge.atExpressions.size() != edge.at.size())
  {
    return;
  }
  std::vector<double> at;
  for (const std::string& text : edge.atExpressions)
  {
    at.push_back(scope.evaluate(text));
  }
  edge.at = at;
}

void evaluateEdgeEnds(BlockModel& model, int index)
{
  PlacementScope scope(model);
  evaluateEdgeEnds(model, index, scope);
}

Eigen::Vector2d evaluatePlacementExpressions(
  const BlockModel& model, const CarrierGeometry& geometry, int index)
{
  PlacementScope scope(model);
  return evaluatePlacementExpressions(model, geometry, index, scope);
}

Eigen::Vector2d evaluatePlacementExpressions(
  const BlockModel& model, const CarrierGeometry& geometry, int index, PlacementScope& scope)
{
  const Vertex& vertex = model.vertices[index];
  const PlacementExpressions& expressions = vertex.rule.expressions;
  const int carrier = vertex.constraint.carrier;
  std::vector<double> values;
  for (const std::string& text : expressions.texts)
  {
    values.push_back(scope.evaluate(text));
  }
  if (expressions.form == PlacementExpressions::Form::AxialTheta && values.size() == 2)
  {
    double s = 0.0, t = 0.0;
    revolutionParametersAt(
      model, geometry, model.expressionScope.thetaZero, carrier, values[0], values[1], s, t);
    return Eigen::Vector2d(s, t);
  }
  if (expressions.form == PlacementExpressions::Form::CurveParameter && values.size() == 1)
  {
    double u = values[0];
    if (geometry.closedS(carrier))
    {
      u = wrapUnit(u);
    }
    else if (u < 0.0 || u > 1.0)
    {
      throw GeometryError("at = " + syntax::shortNumber(u) +
        " is outside the curve's parameter range [0, 1]");
    }
    return Eigen::Vector2d(u, 0.0);
  }
  throw GeometryError("its placement expressions are incomplete");
}
} // namespace model
} // namespace blockforge
