// The template reader: vertices, their placement rules and the queries on points and carriers (extrema, intersections, axial/theta on surfaces).
#include "TemplateReader.h"

#include "../Core/RootFinding.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <limits>
#include <locale>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace blockforge
{
namespace model
{
namespace detail
{
void TemplateReader::readVertices()
{
  const MapEntry* vertices = section("vertices");
  if (!vertices || vertices->value.IsNull())
  {
    fail(vertices ? vertices->line : 1, "", "the template has no 'vertices' section");
  }
  for (const MapEntry& entry :
    syntax::mapEntries(vertices->value, vertices->line, "", "the vertices section", Report, "vertex"))
  {
    checkEntityName(entry, "vertex");
    const std::string entityText = entity("vertex", entry.key);
    Vertex vertex;
    vertex.name = entry.key;
    vertex.where = where(entry.line);
    if (entry.value.IsSequence())
    {
      vertex.position = vector3(entry.value, entry.line, entityText, "position");
    }
    else if (entry.value.IsMap())
    {
      readVertexMapping(entry, entityText, vertex);
      vertex.fixed = fixedMark(entry, entityText);
    }
    else
    {
      fail(entry.line, entityText,
        "expected a position [x, y, z] or a rotated copy {rotate: vertex, angle: a}");
    }
    Model.vertices.push_back(vertex);
  }
}

/// `{position: [x, y, z]}` or `{rotate: v, angle: a, axis: [..], origin: [..]}`: the
/// mapping form leaves room for the constraints of later format versions.
void TemplateReader::readVertexMapping(const MapEntry& entry, const std::string& entityText, Vertex& vertex)
{
  const auto keys =
    syntax::mapEntries(entry.value, entry.line, entityText, "the vertex", Report);
  syntax::checkKeys(keys, { "position", "rotate", "angle", "axis", "origin", "fixed" },
    entityText, Report);
  const MapEntry* position = syntax::findEntry(keys, "position");
  const MapEntry* rotate = syntax::findEntry(keys, "rotate");
  if ((position != nullptr) == (rotate != nullptr))
  {
    fail(entry.line, entityText, "give either 'position' or 'rotate'");
  }
  if (position)
  {
    if (keys.size() != (syntax::findEntry(keys, "fixed") ? 2u : 1u))
    {
      fail(entry.line, entityText, "'angle', 'axis' and 'origin' belong to 'rotate'");
    }
    vertex.position = vector3(position->value, position->line, entityText, "position");
    return;
  }
  const MapEntry* angle = syntax::findEntry(keys, "angle");
  if (!angle)
  {
    fail(entry.line, entityText, "'rotate' needs an 'angle'");
  }
  const int source = vertexRef(rotate->value, rotate->line, entityText);
  Vec3 axis = Vec3::UnitZ();
  Vec3 origin = Vec3::Zero();
  if (const MapEntry* axisEntry = syntax::findEntry(keys, "axis"))
  {
    axis = unitAxis(*axisEntry, entityText, "rotation axis");
  }
  if (const MapEntry* originEntry = syntax::findEntry(keys, "origin"))
  {
    origin = vector3(originEntry->value, originEntry->line, entityText, "origin");
  }
  vertex.rule.kind = VertexRule::Kind::Rotated;
  vertex.rule.source = source;
  vertex.rule.axis = axis;
  vertex.rule.origin = origin;
  vertex.rule.angle = number(angle->value, angle->line, entityText, "angle");
  placeVertex(Model, Geometry, vertex);
}

bool TemplateReader::fixedMark(const MapEntry& entry, const std::string& entityText)
{
  if (!entry.value.IsMap())
  {
    return false;
  }
  return flag(syntax::mapEntries(entry.value, entry.line, entityText, "the vertex", Report),
    "fixed", false, entityText);
}

void TemplateReader::ensureVertex(int index)
{
  resolveOnce(VertexState, VertexEntries, index, "vertex",
    [&](const MapEntry& entry, const std::string& entityText) {
      Vertex vertex = Model.vertices[index];
      Referenced.emplace_back(); // what its expressions refer to (not its referrer's)
      readVertexV2(entry, entityText, vertex);
      Referenced.pop_back();
      if (!vertex.position.allFinite())
      {
        fail(entry.line, entityText, "the position is not finite");
      }
      Model.vertices[index] = vertex;
      Model.vertices[index].fixed = fixedMark(entry, entityText);
      defineVertexQueries(vertex);
    });
}

void TemplateReader::defineVertexQueries(const Vertex& vertex)
{
  if (!syntax::isIdentifier(vertex.name))
  {
    return; // names with '-' cannot appear in expressions
  }
  double cylindricalValues[3] = { 0.0, 0.0, 0.0 };
  cylindrical(vertex.position, cylindricalValues[0], cylindricalValues[1], cylindricalValues[2]);
  const std::string& n = vertex.name;
  const double st[2] = { vertex.constraint.s, vertex.constraint.t };
  Evaluator.defineVertexQueries(
    n, vertex.position.data(), cylindricalValues, vertex.constraint.carrier >= 0 ? st : nullptr);
  if (vertex.constraint.carrier < 0)
  {
    const std::string why = "vertex '" + n + "' is not attached to a carrier, so it has no "
                                             "parameters s, t";
    Evaluator.Unavailable[n + ".s"] = why;
    Evaluator.Unavailable[n + ".t"] = why;
  }
}

/// Tolerance for "lies on": 1e-9 of the larger of the vertices' and the carrier's size.
double TemplateReader::onTolerance(int carrier) const
{
  return 1e-9 * std::max(vertexSpan(), Geometry.size(carrier));
}

double TemplateReader::vertexSpan() const
{
  return placedVertexSpan(Model);
}

void TemplateReader::checkOnCarrier(int vertex, int carrier, double distance, int line, const std::string& entityText)
{
  if (distance > onTolerance(carrier))
  {
    fail(line, entityText,
      "vertex '" + Model.vertices[vertex].name + "' is not on carrier '" +
        Model.carriers[carrier].name + "' (" + shortNumber(distance) +
        " away); attach it with {on_curve: ...}, {on_surface: ...} or {project: ..., onto: ...}");
  }
}

// --- vertices (format 2) ----------------------------------------------------------
/// A point given as [x, y, z], {cylindrical: [axial, radius, theta]} or a vertex name.
Vec3 TemplateReader::pointValue(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what)
{
  const int here = lineOrFallback(node, line);
  if (node.IsSequence())
  {
    return vector3(node, here, entityText, what);
  }
  if (node.IsMap())
  {
    const auto keys = syntax::mapEntries(node, here, entityText, what, Report);
    syntax::checkKeys(keys, { "cylindrical" }, entityText, Report);
    const MapEntry* cyl = syntax::findEntry(keys, "cylindrical");
    if (!cyl)
    {
      fail(here, entityText, what + ": expected [x, y, z], {cylindrical: [axial, radius, theta]} or a vertex");
    }
    return cylindricalValue(*cyl, entityText);
  }
  const int vertex = vertexRef(node, here, entityText);
  return Model.vertices[vertex].position;
}

Vec3 TemplateReader::cylindricalValue(const MapEntry& entry, const std::string& entityText)
{
  if (!entry.value.IsSequence() || entry.value.size() != 3)
  {
    fail(entry.line, entityText,
      "cylindrical expects [axial, radius, theta] about the machine axis (theta in "
      "radians, 10deg, from the reference direction)");
  }
  const double axial = number(entry.value[0], entry.line, entityText, "axial");
  const double radius = number(entry.value[1], entry.line, entityText, "radius");
  const double theta = number(entry.value[2], entry.line, entityText, "theta");
  return fromCylindrical(axial, radius, theta);
}

/// The values x, y, z, axial, radius, theta of a point, in that order.
void TemplateReader::pointVariables(const Vec3& p, double* values) const
{
  values[0] = p.x();
  values[1] = p.y();
  values[2] = p.z();
  cylindrical(p, values[3], values[4], values[5]);
}

/// Parameter u of curve `carrier` in [from, to] (which may pass the seam of a closed
/// curve) where `value` is smallest (sign = 1) or largest (-1): a sample of 512 points,
/// then golden-section search in the bracketing interval.
double TemplateReader::extremum(int carrier, const std::function<double(const Vec3&)>& value, double sign,
  double from, double to)
{
  return extremum([&](double u) { return Geometry.point(carrier, u); },
    Geometry.closedS(carrier), value, sign, from, to);
}

/// The same on any curve point(u) (u wraps when `closed`).
double TemplateReader::extremum(const std::function<Vec3(double)>& point, bool closed,
  const std::function<double(const Vec3&)>& value, double sign, double from, double to)
{
  const int samples = 512;
  auto f = [&](double u) { return sign * value(point(closed ? wrapUnit(u) : u)); };
  auto at = [&](int k) { return from + (to - from) * static_cast<double>(k) / samples; };
  int best = 0;
  double bestValue = f(from);
  for (int k = 1; k <= samples; ++k)
  {
    const double v = f(at(k));
    if (v < bestValue)
    {
      bestValue = v;
      best = k;
    }
  }
  const bool whole = closed && to - from >= 1.0;
  double a = at(best - 1), b = at(best + 1);
  if (!whole)
  {
    a = std::max(a, from);
    b = std::min(b, to);
  }
  double u = goldenSectionMinimum(f, a, b, 1e-14);
  if (!whole && f(from) <= f(u))
  {
    u = from;
  }
  if (!whole && f(to) < f(u))
  {
    u = to;
  }
  return closed ? wrapUnit(u) : u;
}

/// Parameter u where curve `curve` meets surface `surface`.
double TemplateReader::curveSurfaceIntersection(int curve, int surface, const MapEntry* near,
  const std::string& entityText, int line)
{
  const int samples = 512;
  const SurfaceOfRevolution* revolution = Geometry.revolution(surface);
  std::vector<double> roots;
  if (revolution)
  {
    auto f = [&](double u) { return revolution->signedMeridionalDistance(Geometry.point(curve, u)); };
    double previous = f(0.0);
    if (previous == 0.0)
    {
      roots.push_back(0.0);
    }
    for (int k = 1; k <= samples; ++k)
    {
      const double u = static_cast<double>(k) / samples;
      const double value = f(u);
      if (value == 0.0)
      {
        roots.push_back(u);
      }
      else if (previous != 0.0 && (value < 0.0) != (previous < 0.0))
      {
        roots.push_back(brentRoot(f, static_cast<double>(k - 1) / samples, u, previous, value, 1e-15));
      }
      previous = value;
    }
  }
  else
  {
    auto f = [&](double u) {
      double s = 0.0, t = 0.0, distance = 0.0;
      Geometry.project(surface, Geometry.point(curve, u), s, t, distance);
      return distance;
    };
    int best = 0;
    double bestValue = f(0.0);
    for (int k = 1; k <= samples; ++k)
    {
      const double value = f(static_cast<double>(k) / samples);
      if (value < bestValue)
      {
        bestValue = value;
        best = k;
      }
    }
    const double u = goldenSectionMinimum(
      f, std::max(0.0, (best - 1.0) / samples), std::min(1.0, (best + 1.0) / samples), 1e-15);
    const double distance = f(u);
    if (distance > onTolerance(surface))
    {
      fail(line, entityText,
        "curve '" + Model.carriers[curve].name + "' does not meet surface '" +
          Model.carriers[surface].name + "' (closest approach " + shortNumber(distance) + ")");
    }
    return u;
  }
  if (roots.empty())
  {
    fail(line, entityText,
      "curve '" + Model.carriers[curve].name + "' does not cross surface '" +
        Model.carriers[surface].name + "'");
  }
  if (roots.size() == 1)
  {
    return roots.front();
  }
  if (!near)
  {
    fail(line, entityText,
      "curve '" + Model.carriers[curve].name + "' crosses surface '" +
        Model.carriers[surface].name + "' " + std::to_string(roots.size()) +
        " times; add 'near: [x, y, z]' (or a vertex) to choose one");
  }
  const Vec3 target = pointValue(near->value, near->line, entityText, "near");
  double best = roots.front();
  for (double u : roots)
  {
    if ((Geometry.point(curve, u) - target).norm() < (Geometry.point(curve, best) - target).norm())
    {
      best = u;
    }
  }
  return best;
}

/// Parameters (s, t) of the point of a surface of revolution about the machine axis at
/// the given axial position and angle theta: the contour's first crossing of the axial
/// plane (bisection to rounding), then the exact meridional projection.
void TemplateReader::onRevolutionAt(int surface, double axial, double theta, const std::string& entityText,
  int line, double& s, double& t)
{
  try
  {
    revolutionParametersAt(Model, Geometry, referenceDirection(), surface, axial, theta, s, t);
  }
  catch (const GeometryError& error)
  {
    fail(line, entityText, error.what());
  }
}

/// `at: {length: f}`, `at: {min: q}` or `at: {max: q}` (q: x, y, z, axial, radius, theta
/// or an expression of them), optionally `within: [u0, u1]`: a parameter of `curve`.
double TemplateReader::curveParameterQuery(const MapEntry& at, int curve, const std::string& entityText)
{
  const auto how = syntax::mapEntries(at.value, at.line, entityText, "'at'", Report);
  syntax::checkKeys(how, { "length", "min", "max", "within" }, entityText, Report);
  const MapEntry* within = syntax::findEntry(how, "within");
  const MapEntry* length = syntax::findEntry(how, "length");
  const MapEntry* minimum = syntax::findEntry(how, "min");
  const MapEntry* maximum = syntax::findEntry(how, "max");
  if ((length ? 1 : 0) + (minimum ? 1 : 0) + (maximum ? 1 : 0) != 1 || (length && within))
  {
    fail(at.line, entityText,
      "'at' takes one of length, min or max (min and max may add 'within: [u0, u1]')");
  }
  if (length)
  {
    const double fraction = number(length->value, length->line, entityText, "length");
    if (fraction < 0.0 || fraction > 1.0)
    {
      fail(length->line, entityText, "the length fraction must be in [0, 1]");
    }
    return Geometry.lengthTable(curve)->parameterAtFraction(fraction);
  }
  const MapEntry& extreme = minimum ? *minimum : *maximum;
  const bool closed = Geometry.closedS(curve);
  double from = 0.0, to = 1.0;
  if (within)
  {
    if (!within->value.IsSequence() || within->value.size() != 2)
    {
      fail(within->line, entityText, "'within' expects [u0, u1], parameters of the curve");
    }
    from = number(within->value[0], within->line, entityText, "within u0");
    to = number(within->value[1], within->line, entityText, "within u1");
    const bool ordered = to > from;
    if (!ordered || (closed && to - from > 1.0) || (!closed && (from < 0.0 || to > 1.0)))
    {
      fail(within->line, entityText,
        "'within: [" + shortNumber(from) + ", " + shortNumber(to) + "]' must have u0 < u1 " +
          (closed ? std::string("and span at most the whole closed curve (1)")
                  : std::string("inside the curve's parameter range [0, 1]")));
    }
  }
  double variables[6] = {};
  std::function<double()> objective;
  static const std::vector<std::string> quantities = { "x", "y", "z", "axial", "radius",
    "theta" };
  const std::string text = extreme.value.IsScalar() ? extreme.value.Scalar() : std::string();
  const auto named = std::find(quantities.begin(), quantities.end(), text);
  if (named != quantities.end())
  {
    const std::size_t index = static_cast<std::size_t>(named - quantities.begin());
    objective = [&variables, index]() { return variables[index]; };
  }
  else
  {
    if (!extreme.value.IsScalar())
    {
      fail(extreme.line, entityText,
        extreme.key + ": expected a quantity (x y z axial radius theta) or an expression "
                      "of them");
    }
    try
    {
      objective = Evaluator.pointFunction(text, variables);
    }
    catch (const ExpressionError& error)
    {
      fail(extreme.line, entityText, extreme.key + ": " + error.message);
    }
  }
  auto value = [&](const Vec3& p) {
    pointVariables(p, variables);
    const double result = objective();
    if (!std::isfinite(result))
    {
      fail(extreme.line, entityText,
        extreme.key + ": '" + text + "' is " + (std::isnan(result) ? "NaN" : "not finite") +
          " at the curve point (" + shortNumber(p.x()) + ", " + shortNumber(p.y()) + ", " +
          shortNumber(p.z()) + ")");
    }
    return result;
  };
  return extremum(curve, value, extreme.key == "min" ? 1.0 : -1.0, from, to);
}

void TemplateReader::recordPlacementExpressions(
  Vertex& vertex, PlacementExpressions::Form form, const std::vector<std::string>& texts)
{
  const std::set<int>& followed = Referenced.back();
  if (followed.empty())
  {
    return; // numbers and parameters only: nothing to follow
  }
  PlacementExpressions& expressions = vertex.rule.expressions;
  expressions.form = form;
  expressions.texts = texts;
  expressions.follows.assign(followed.begin(), followed.end());
}

void TemplateReader::readVertexV2(const MapEntry& entry, const std::string& entityText, Vertex& vertex)
{
  if (entry.value.IsSequence())
  {
    vertex.position = vector3(entry.value, entry.line, entityText, "position");
    return;
  }
  static const std::vector<std::string> kinds = { "position", "rotate", "cylindrical",
    "on_curve", "on_surface", "project", "periodic", "intersect" };
  if (!entry.value.IsMap())
  {
    fail(entry.line, entityText,
      "expected a position [x, y, z] or a mapping with one of: " + syntax::joinNames(kinds));
  }
  const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "the vertex", Report);
  const MapEntry* kind = syntax::findKind(keys, kinds, entityText, Report);
  if (!kind)
  {
    syntax::checkKeys(keys, kinds, entityText, Report);
    fail(entry.line, entityText, "needs one of: " + syntax::joinNames(kinds));
  }
  const int here = lineOrFallback(kind->value, kind->line);
  if (kind->key == "position" || kind->key == "rotate")
  {
    readVertexMapping(entry, entityText, vertex);
    return;
  }
  if (kind->key == "cylindrical")
  {
    syntax::checkKeys(keys, { "cylindrical", "fixed" }, entityText, Report);
    vertex.position = cylindricalValue(*kind, entityText);
    return;
  }
  VertexConstraint& constraint = vertex.constraint;
  if (kind->key == "on_curve")
  {
    syntax::checkKeys(keys, { "on_curve", "at", "fixed" }, entityText, Report);
    const int curve = carrierRef(kind->value, kind->line, entityText, "on_curve", Want::Curve);
    const MapEntry* at = syntax::findEntry(keys, "at");
    if (!at)
    {
      fail(entry.line, entityText,
        "on_curve needs 'at': a parameter u in [0, 1], {length: fraction}, "
        "{min: quantity} or {max: quantity} (quantities: x y z axial radius theta)");
    }
    double u = 0.0;
    if (at->value.IsMap())
    {
      u = curveParameterQuery(*at, curve, entityText);
    }
    else
    {
      Referenced.back().clear();
      u = number(at->value, at->line, entityText, "at");
      recordPlacementExpressions(
        vertex, PlacementExpressions::Form::CurveParameter, { at->value.Scalar() });
      if (Geometry.closedS(curve))
      {
        u = wrapUnit(u);
      }
      else if (u < 0.0 || u > 1.0)
      {
        fail(at->line, entityText,
          "at = " + shortNumber(u) + " is outside the curve's parameter range [0, 1]");
      }
    }
    constraint.carrier = curve;
    constraint.s = u;
    vertex.rule.kind = VertexRule::Kind::OnCarrier;
    vertex.rule.expressions.base = { { u, 0.0 } };
    placeVertex(Model, Geometry, vertex);
    return;
  }
  if (kind->key == "on_surface" && syntax::findEntry(keys, "axial"))
  {
    syntax::checkKeys(keys, { "on_surface", "axial", "theta", "fixed" }, entityText, Report);
    const int surface =
      carrierRef(kind->value, kind->line, entityText, "on_surface", Want::Surface);
    const MapEntry* axialEntry = syntax::findEntry(keys, "axial");
    const MapEntry* thetaEntry = syntax::findEntry(keys, "theta");
    if (!thetaEntry)
    {
      fail(entry.line, entityText, "on_surface with 'axial' needs 'theta' too");
    }
    Referenced.back().clear();
    const double axial = number(axialEntry->value, axialEntry->line, entityText, "axial");
    const double theta = number(thetaEntry->value, thetaEntry->line, entityText, "theta");
    recordPlacementExpressions(vertex, PlacementExpressions::Form::AxialTheta,
      { axialEntry->value.Scalar(), thetaEntry->value.Scalar() });
    double s = 0.0, t = 0.0;
    onRevolutionAt(surface, axial, theta, entityText, axialEntry->line, s, t);
    constraint.carrier = surface;
    constraint.s = s;
    constraint.t = t;
    vertex.rule.expressions.base = { { s, t } };
    vertex.rule.kind = VertexRule::Kind::OnCarrier;
    placeVertex(Model, Geometry, vertex);
    return;
  }
  if (kind->key == "on_surface")
  {
    syntax::checkKeys(keys, { "on_surface", "at", "fixed" }, entityText, Report);
    const int surface =
      carrierRef(kind->value, kind->line, entityText, "on_surface", Want::Surface);
    const MapEntry* at = syntax::findEntry(keys, "at");
    if (!at || !at->value.IsSequence() || at->value.size() != 2)
    {
      fail(at ? at->line : entry.line, entityText, "on_surface needs 'at: [s, t]'");
    }
    double st[2] = { number(at->value[0], at->line, entityText, "at s"),
      number(at->value[1], at->line, entityText, "at t") };
    const bool closed[2] = { Geometry.closedS(surface), Geometry.closedT(surface) };
    const double low[2] = { 0.0, Geometry.tMin(surface) };
    const double high[2] = { 1.0, Geometry.tMax(surface) };
    for (int k = 0; k < 2; ++k)
    {
      if (closed[k])
      {
        st[k] = wrapUnit(st[k]);
      }
      else if (st[k] < low[k] || st[k] > high[k])
      {
        fail(at->line, entityText,
          std::string(k ? "t" : "s") + " = " + shortNumber(st[k]) +
            " is outside the surface's parameter range [" + shortNumber(low[k]) + ", " +
            shortNumber(high[k]) + "]");
      }
    }
    constraint.carrier = surface;
    constraint.s = st[0];
    constraint.t = st[1];
    vertex.rule.kind = VertexRule::Kind::OnCarrier;
    placeVertex(Model, Geometry, vertex);
    return;
  }
  if (kind->key == "project")
  {
    syntax::checkKeys(keys, { "project", "onto", "fixed" }, entityText, Report);
    const MapEntry* onto = syntax::findEntry(keys, "onto");
    if (!onto)
    {
      fail(entry.line, entityText, "project needs 'onto: <carrier>'");
    }
    const Vec3 point = pointValue(kind->value, kind->line, entityText, "project");
    const int carrier = carrierRef(onto->value, onto->line, entityText, "onto", Want::Any);
    constraint.carrier = carrier;
    if (!kind->value.IsSequence() && !kind->value.IsMap())
    {
      // Projected from a vertex: follows it wherever it moves later.
      vertex.rule.kind = VertexRule::Kind::Projected;
      vertex.rule.source = vertexRef(kind->value, kind->line, entityText);
    }
    else
    {
      // Projected from a point: a control point where the point lands.
      double s = 0.0, t = 0.0, distance = 0.0;
      Geometry.project(carrier, point, s, t, distance);
      constraint.s = s;
      constraint.t = t;
      vertex.rule.kind = VertexRule::Kind::OnCarrier;
    }
    placeVertex(Model, Geometry, vertex);
    return;
  }
  if (kind->key == "intersect")
  {
    syntax::checkKeys(keys, { "intersect", "near", "fixed" }, entityText, Report);
    if (!kind->value.IsSequence() || kind->value.size() != 2)
    {
      fail(here, entityText, "intersect expects [curve, surface]");
    }
    const int curve = carrierRef(kind->value[0], here, entityText, "intersect", Want::Curve);
    const int surface = carrierRef(kind->value[1], here, entityText, "intersect", Want::Surface);
    const double u =
      curveSurfaceIntersection(curve, surface, syntax::findEntry(keys, "near"), entityText, here);
    constraint.carrier = curve;
    constraint.s = u;
    vertex.rule.kind = VertexRule::Kind::Intersection;
    placeVertex(Model, Geometry, vertex);
    return;
  }
  // periodic
  syntax::checkKeys(keys, { "periodic", "pitches", "fixed" }, entityText, Report);
  const int source = vertexRef(kind->value, kind->line, entityText);
  int pitches = 1;
  if (const MapEntry* count = syntax::findEntry(keys, "pitches"))
  {
    const double value = number(count->value, count->line, entityText, "pitches");
    if (value != std::floor(value) || value == 0.0 || std::abs(value) > 100000)
    {
      fail(count->line, entityText, "pitches must be a whole number other than 0");
    }
    pitches = static_cast<int>(value);
  }
  const Machine& machine = Model.machine;
  if (machine.bladeCount <= 0)
  {
    fail(here, entityText,
      "a periodic vertex needs the blade count: " + Evaluator.Unavailable["pitch"]);
  }
  constraint.periodicSource = source;
  constraint.pitches = pitches;
  vertex.rule.kind = VertexRule::Kind::Periodic;
  placeVertex(Model, Geometry, vertex);
}
} // namespace detail
} // namespace model
} // namespace blockforge
