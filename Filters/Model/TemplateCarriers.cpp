// The template reader: carriers (curves and surfaces from point sets and other carriers) and the queries on them.
#include "TemplateReader.h"

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
void TemplateReader::readCarriersAndVertices()
{
  if (const MapEntry* carriers = section("carriers"))
  {
    for (const MapEntry& entry : syntax::mapEntries(
           carriers->value, carriers->line, "", "the carriers section", Report, "carrier"))
    {
      checkEntityName(entry, "carrier");
      Carrier carrier;
      carrier.name = entry.key;
      carrier.where = where(entry.line);
      Model.carriers.push_back(carrier);
      CarrierEntries.push_back(entry);
    }
  }
  CarrierState.assign(CarrierEntries.size(), 0);
  const MapEntry* vertices = section("vertices");
  if (!vertices || vertices->value.IsNull())
  {
    fail(vertices ? vertices->line : 1, "", "the template has no 'vertices' section");
  }
  for (const MapEntry& entry : syntax::mapEntries(
         vertices->value, vertices->line, "", "the vertices section", Report, "vertex"))
  {
    checkEntityName(entry, "vertex");
    Vertex vertex;
    vertex.name = entry.key;
    vertex.where = where(entry.line);
    vertex.position = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    Model.vertices.push_back(vertex);
    VertexEntries.push_back(entry);
  }
  VertexState.assign(VertexEntries.size(), 0);
  readDefinitionNames();
  Evaluator.OnReference = [this](const std::string& referenced, const std::string& attribute) {
    if (attribute.empty())
    {
      const auto definition = DefinitionIndex.find(referenced);
      if (definition != DefinitionIndex.end())
      {
        ensureDefinition(definition->second);
        if (!Referenced.empty())
        {
          const std::set<int>& vertices = DefinitionVertices[definition->second];
          Referenced.back().insert(vertices.begin(), vertices.end());
        }
      }
      return;
    }
    const int index = Model.findVertex(referenced);
    if (index >= 0)
    {
      ensureVertex(index);
      if (!Referenced.empty())
      {
        Referenced.back().insert(index);
      }
    }
    else if (Model.findCarrier(referenced) >= 0)
    {
      ensureCarrier(Model.findCarrier(referenced)); // contour.axial_min, ...
    }
  };
  for (std::size_t d = 0; d < DefinitionEntries.size(); ++d)
  {
    ensureDefinition(static_cast<int>(d));
  }
  for (std::size_t v = 0; v < VertexEntries.size(); ++v)
  {
    ensureVertex(static_cast<int>(v));
  }
  for (std::size_t c = 0; c < CarrierEntries.size(); ++c)
  {
    ensureCarrier(static_cast<int>(c));
  }
}

/// `revolve: ..., extend: f`: the contour continues straight along its end tangents by
/// f times its length at both ends (short exports: inlet and outlet further out).
void TemplateReader::extendContour(std::vector<Vec3>& points, double fraction, int line,
  const std::string& entityText)
{
  if (!(fraction >= 0.0) || fraction > 10.0)
  {
    fail(line, entityText, "extend: expected a fraction of the contour's length from 0 to "
                           "10, got " + shortNumber(fraction));
  }
  if (fraction == 0.0 || points.size() < 2)
  {
    return;
  }
  double length = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k)
  {
    length += (points[k] - points[k - 1]).norm();
  }
  const Vec3 back = (points[0] - points[1]).normalized();
  const Vec3 ahead = (points.back() - points[points.size() - 2]).normalized();
  const Vec3 first = points.front(), last = points.back();
  for (int step = 1; step <= 4; ++step)
  {
    points.insert(points.begin(), first + fraction * length * step / 4.0 * back);
    points.push_back(last + fraction * length * step / 4.0 * ahead);
  }
}

/// `<revolve carrier>.axial_min` and `.axial_max`: where its contour starts and ends
/// along the axis (an inlet or outlet plane must stay within them).
void TemplateReader::defineContourQueries(const Carrier& carrier, const std::vector<Vec3>& points)
{
  if (!syntax::isIdentifier(carrier.name) || points.empty())
  {
    return;
  }
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Vec3& p : points)
  {
    const double axial = (p - carrier.axisPoint).dot(carrier.axis);
    low = std::min(low, axial);
    high = std::max(high, axial);
  }
  Evaluator.defineQuery(carrier.name + ".axial_min", low);
  Evaluator.defineQuery(carrier.name + ".axial_max", high);
}

void TemplateReader::ensureCarrier(int index)
{
  resolveOnce(CarrierState, CarrierEntries, index, "carrier",
    [&](const MapEntry& entry, const std::string& entityText) {
      Carrier carrier = Model.carriers[index];
      Referenced.emplace_back(); // what the carrier's expressions refer to is its own
      readCarrier(entry, entityText, index, carrier);
      Referenced.pop_back();
      Model.carriers[index] = carrier;
      Geometry.build(Model, index);
    });
}

/// A carrier named in the template (declared or hidden), resolved; -1 if there is none.
int TemplateReader::findCarrierIndex(const std::string& carrierName)
{
  const int index = Model.findCarrier(carrierName);
  if (index >= 0)
  {
    ensureCarrier(index);
  }
  return index;
}

int TemplateReader::carrierRef(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what, Want want)
{
  const int here = lineOrFallback(node, line);
  const std::string carrierName = name(node, line, entityText, what);
  const int index = Model.findCarrier(carrierName);
  if (index < 0)
  {
    std::string message = what + ": unknown carrier '" + carrierName + "'";
    const std::string suggestion = syntax::closestName(carrierName, carrierNames());
    if (!suggestion.empty())
    {
      message += " (did you mean '" + suggestion + "'?)";
    }
    if (BoundInputs.count(carrierName))
    {
      message += "; '" + carrierName + "' is an input point set: make a carrier of it, "
                 "e.g. {interpolate: " + carrierName + "}";
    }
    fail(here, entityText, message + "; carriers: " + syntax::joinNames(carrierNames()));
  }
  ensureCarrier(index);
  const bool surface = Model.carriers[index].isSurface();
  if (want == Want::Curve && surface)
  {
    fail(here, entityText, what + ": '" + carrierName + "' is a surface, a curve is needed");
  }
  if (want == Want::Surface && !surface)
  {
    fail(here, entityText, what + ": '" + carrierName + "' is a curve, a surface is needed");
  }
  return index;
}

/// Adds a fully defined carrier (sections of a Gordon surface, meridional contours).
int TemplateReader::addHiddenCarrier(Carrier carrier)
{
  const int existing = Model.findCarrier(carrier.name);
  if (existing >= 0)
  {
    fail(carrier.where.line, entity("carrier", carrier.name),
      "the name is taken: carriers may not use names with a '.'");
  }
  Model.carriers.push_back(carrier);
  const int index = static_cast<int>(Model.carriers.size()) - 1;
  Geometry.build(Model, index);
  return index;
}

// --- carriers -------------------------------------------------------------------
/// A list of points [[x, y, z], ...] written in the template.
std::vector<Vec3> TemplateReader::pointList(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what)
{
  std::vector<Vec3> points;
  for (std::size_t p = 0; p < node.size(); ++p)
  {
    points.push_back(vector3(node[p], line, entityText, what + " point " + std::to_string(p + 1)));
  }
  return points;
}

/// Input points without consecutive duplicates (exports often repeat a point where
/// two pieces of a contour meet; interpolation needs distinct consecutive points).
std::vector<Vec3> TemplateReader::withoutDuplicates(const std::vector<Vec3>& points)
{
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const Vec3& p : points)
  {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const double tolerance = 1e-12 * (points.empty() ? 0.0 : (high - low).norm());
  std::vector<Vec3> kept;
  for (const Vec3& p : points)
  {
    if (kept.empty() || (p - kept.back()).norm() > tolerance)
    {
      kept.push_back(p);
    }
  }
  return kept;
}

const TemplateReader::BoundInput& TemplateReader::inputRef(const std::string& inputName, int line, const std::string& entityText,
  const std::string& what)
{
  const auto found = BoundInputs.find(inputName);
  if (found == BoundInputs.end())
  {
    std::string message = what + ": '" + inputName + "' is neither a carrier nor an input";
    std::vector<std::string> names = inputNames();
    for (const std::string& carrierName : carrierNames())
    {
      names.push_back(carrierName);
    }
    const std::string suggestion = syntax::closestName(inputName, names);
    if (!suggestion.empty())
    {
      message += " (did you mean '" + suggestion + "'?)";
    }
    fail(line, entityText,
      message + "; inputs: " + syntax::joinNames(inputNames()) +
        "; carriers: " + syntax::joinNames(carrierNames()));
  }
  return found->second;
}

/// `degree` and `parameters` of an interpolation.
void TemplateReader::readInterpolationOptions(const std::vector<MapEntry>& keys, const std::string& entityText,
  Carrier& carrier)
{
  if (const MapEntry* degree = syntax::findEntry(keys, "degree"))
  {
    const double value = number(degree->value, degree->line, entityText, "degree");
    if (value != std::floor(value) || value < 1 || value > 15)
    {
      fail(degree->line, entityText, "degree must be a whole number from 1 to 15");
    }
    carrier.degree = static_cast<int>(value);
  }
  if (const MapEntry* method = syntax::findEntry(keys, "parameters"))
  {
    const std::string text = name(method->value, method->line, entityText, "parameters");
    if (text == "uniform")
    {
      carrier.parameterMethod = 0;
    }
    else if (text == "chord")
    {
      carrier.parameterMethod = 1;
    }
    else if (text == "centripetal")
    {
      carrier.parameterMethod = 2;
    }
    else
    {
      fail(method->line, entityText,
        "parameters: expected uniform, chord or centripetal, got '" + text + "'");
    }
  }
}

bool TemplateReader::flag(const std::vector<MapEntry>& keys, const std::string& key, bool fallback,
  const std::string& entityText)
{
  const MapEntry* entry = syntax::findEntry(keys, key);
  if (!entry)
  {
    return fallback;
  }
  if (entry->value.IsScalar())
  {
    const std::string& text = entry->value.Scalar();
    if (text == "true" || text == "yes" || text == "on")
    {
      return true;
    }
    if (text == "false" || text == "no" || text == "off")
    {
      return false;
    }
  }
  fail(entry->line, entityText, key + ": expected true or false");
}

/// Meridional image of a point: its (axial, radius) placed in the half-plane theta = 0.
Vec3 TemplateReader::meridional(const Vec3& p, const Vec3& axisPoint, const Vec3& axis) const
{
  const Vec3 q = p - axisPoint;
  const double axial = q.dot(axis);
  const double radius = (q - axial * axis).norm();
  // the machine's theta = 0 when revolving about the machine axis, so that t measures
  // the same theta as vertex queries (and the seam t = 0, 1 lies at theta = +-pi)
  const Vec3 e1 = (axis - Model.machine.axis).norm() <= 1e-12 ? referenceDirection()
                                                               : defaultReference(axis);
  return axisPoint + axial * axis + radius * e1;
}

/// Parameters of a Gordon surface's sections: `at`, else the input's span fractions,
/// else uniform.
std::vector<double> TemplateReader::sectionParameters(const MapEntry* at, std::size_t count,
  const std::vector<double>& spans, const std::string& entityText)
{
  std::vector<double> nodes;
  if (at)
  {
    if (!at->value.IsSequence() || at->value.size() != count)
    {
      fail(at->line, entityText,
        "'at' needs one parameter per section (" + std::to_string(count) + ")");
    }
    for (std::size_t k = 0; k < count; ++k)
    {
      nodes.push_back(number(at->value[k], at->line, entityText, "at " + std::to_string(k + 1)));
      if (k > 0 && !(nodes[k] > nodes[k - 1]))
      {
        fail(at->line, entityText, "the section parameters 'at' must increase strictly");
      }
    }
    return nodes;
  }
  bool useSpans = spans.size() == count;
  for (std::size_t k = 0; useSpans && k < count; ++k)
  {
    useSpans = std::isfinite(spans[k]) && (k == 0 || spans[k] > spans[k - 1]);
  }
  if (useSpans)
  {
    return spans;
  }
  for (std::size_t k = 0; k < count; ++k)
  {
    nodes.push_back(count > 1 ? static_cast<double>(k) / (count - 1) : 0.0);
  }
  return nodes;
}

void TemplateReader::readCarrier(const MapEntry& entry, const std::string& entityText, int index, Carrier& carrier)
{
  const std::vector<std::string>& kinds = carrierKindNames();
  if (!entry.value.IsMap())
  {
    fail(entry.line, entityText,
      "expected a mapping with one of: " + syntax::joinNames(kinds) +
        " (e.g. {interpolate: hub} or {revolve: hub_line, axis: machine})");
  }
  const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "the carrier", Report);
  const MapEntry* kind = syntax::findKind(keys, kinds, entityText, Report);
  if (!kind)
  {
    fail(entry.line, entityText, "needs one of: " + syntax::joinNames(kinds));
  }
  const int here = lineOrFallback(kind->value, kind->line);
  // The name this carrier's own name resolves to in arguments: never itself.
  auto otherCarrier = [&](const std::string& text) {
    const int found = Model.findCarrier(text);
    return found == index ? -1 : found;
  };

  if (kind->key == "interpolate")
  {
    syntax::checkKeys(keys, { "interpolate", "degree", "parameters" }, entityText, Report);
    carrier.kind = Carrier::Kind::Interpolate;
    readInterpolationOptions(keys, entityText, carrier);
    if (kind->value.IsSequence())
    {
      carrier.points = pointList(kind->value, here, entityText, "interpolate");
    }
    else
    {
      const std::string setName = name(kind->value, kind->line, entityText, "interpolate");
      const BoundInput& input = inputRef(setName, here, entityText, "interpolate");
      if (input.set->isList)
      {
        fail(here, entityText,
          "interpolate: input '" + setName + "' is a list of " +
            std::to_string(input.set->curves.size()) +
            " curves; interpolate takes one curve (use gordon for sections)");
      }
      carrier.points = withoutDuplicates(input.set->curves.front().points);
    }
    if (carrier.points.size() < 2)
    {
      fail(here, entityText, "interpolate needs at least 2 points");
    }
    return;
  }

  if (kind->key == "revolve")
  {
    syntax::checkKeys(keys,
      { "revolve", "axis", "origin", "angle", "meridional", "degree", "parameters",
        "extend" },
      entityText, Report);
    carrier.kind = Carrier::Kind::Revolve;
    carrier.axis = Model.machine.axis;
    carrier.axisPoint = Model.machine.axisPoint;
    const MapEntry* axis = syntax::findEntry(keys, "axis");
    const MapEntry* origin = syntax::findEntry(keys, "origin");
    if (axis && !(axis->value.IsScalar() && axis->value.Scalar() == "machine"))
    {
      carrier.axis = unitAxis(*axis, entityText, "axis");
      carrier.axisPoint = Vec3::Zero();
    }
    if (origin)
    {
      if (!axis || axis->value.IsScalar())
      {
        fail(origin->line, entityText, "'origin' goes with an explicit 'axis: [x, y, z]'");
      }
      carrier.axisPoint = vector3(origin->value, origin->line, entityText, "origin");
    }
    carrier.angleStart = -Pi;
    carrier.angleEnd = Pi;
    if (const MapEntry* angle = syntax::findEntry(keys, "angle"))
    {
      if (!angle->value.IsSequence() || angle->value.size() != 2)
      {
        fail(angle->line, entityText, "'angle' expects the range [a0, a1] (radians; 30deg)");
      }
      carrier.angleStart = number(angle->value[0], angle->line, entityText, "angle a0");
      carrier.angleEnd = number(angle->value[1], angle->line, entityText, "angle a1");
      if (!(carrier.angleEnd > carrier.angleStart) ||
        carrier.angleEnd - carrier.angleStart > 2.0 * Pi * (1.0 + 1e-12))
      {
        fail(angle->line, entityText,
          "the angle range [a0, a1] needs a0 < a1 and at most one turn (2 pi)");
      }
    }
    const bool toMeridian = flag(keys, "meridional", true, entityText);
    const std::string source = name(kind->value, kind->line, entityText, "revolve");
    Carrier contour;
    contour.name = carrier.name + ".contour";
    contour.where = carrier.where;
    contour.kind = Carrier::Kind::Interpolate;
    const int curve = otherCarrier(source);
    if (curve >= 0)
    {
      const int ref = carrierRef(kind->value, kind->line, entityText, "revolve", Want::Curve);
      const Carrier& base = Model.carriers[ref];
      if (!toMeridian || base.kind != Carrier::Kind::Interpolate)
      {
        if (syntax::findEntry(keys, "degree") || syntax::findEntry(keys, "parameters"))
        {
          fail(entry.line, entityText,
            "'degree' and 'parameters' apply when revolve interpolates points");
        }
        carrier.refs = { ref };
        return;
      }
      contour.degree = base.degree;
      contour.parameterMethod = base.parameterMethod;
      contour.points = base.points;
    }
    else
    {
      const BoundInput& input = inputRef(source, here, entityText, "revolve");
      if (input.set->isList)
      {
        fail(here, entityText, "revolve: input '" + source + "' is a list of curves; a "
                               "contour is one curve");
      }
      contour.points = withoutDuplicates(input.set->curves.front().points);
    }
    readInterpolationOptions(keys, entityText, contour);
    if (toMeridian)
    {
      for (Vec3& point : contour.points)
      {
        point = meridional(point, carrier.axisPoint, carrier.axis);
      }
    }
    if (const MapEntry* extend = syntax::findEntry(keys, "extend"))
    {
      extendContour(contour.points,
        number(extend->value, extend->line, entityText, "extend"), extend->line, entityText);
    }
    defineContourQueries(carrier, contour.points);
    carrier.refs = { addHiddenCarrier(contour) };
    return;
  }

  if (kind->key == "gordon" || kind->key == "network")
  {
    syntax::checkKeys(keys,
      { kind->key, "blending", "at", "closed", "align", "degree", "parameters" }, entityText,
      Report);
    carrier.kind = kind->key == "gordon" ? Carrier::Kind::Gordon : Carrier::Kind::Network;
    carrier.blending = Carrier::Blending::Spline;
    if (const MapEntry* blending = syntax::findEntry(keys, "blending"))
    {
      const std::string text = name(blending->value, blending->line, entityText, "blending");
      if (text == "lagrange")
      {
        carrier.blending = Carrier::Blending::Lagrange;
      }
      else if (text != "spline")
      {
        fail(blending->line, entityText,
          "blending: expected spline or lagrange, got '" + text + "'");
      }
    }
    carrier.closed = flag(keys, "closed", false, entityText);
    const MapEntry* align = syntax::findEntry(keys, "align");
    if (align)
    {
      const std::string how = name(align->value, align->line, entityText, "align");
      if (how != "axial")
      {
        fail(align->line, entityText, "align: expected 'axial', got '" + how + "'");
      }
      if (!carrier.closed || kind->key != "gordon" || kind->value.IsSequence())
      {
        fail(align->line, entityText,
          "align needs closed: true and sections from an input (a blade)");
      }
    }
    Carrier sectionTemplate;
    sectionTemplate.kind = Carrier::Kind::Interpolate;
    sectionTemplate.where = carrier.where;
    readInterpolationOptions(keys, entityText, sectionTemplate);
    const MapEntry* at = syntax::findEntry(keys, "at");
    if (carrier.kind == Carrier::Kind::Gordon)
    {
      std::vector<double> spans;
      if (kind->value.IsSequence())
      {
        for (std::size_t k = 0; k < kind->value.size(); ++k)
        {
          carrier.refs.push_back(carrierRef(
            kind->value[k], here, entityText, "section " + std::to_string(k + 1), Want::Curve));
        }
      }
      else
      {
        const std::string source = name(kind->value, kind->line, entityText, "gordon");
        const BoundInput& input = inputRef(source, here, entityText, "gordon");
        if (!input.set->isList)
        {
          fail(here, entityText,
            "gordon: input '" + source + "' is one curve; a Gordon surface needs a list of "
            "sections (or a list of curve carriers [c1, c2, ...])");
        }
        const auto& curves = input.set->curves;
        for (std::size_t k = 0; k < curves.size(); ++k)
        {
          Carrier section = sectionTemplate;
          section.name = carrier.name + ".section" + std::to_string(k + 1);
          section.points = withoutDuplicates(curves[k].points);
          spans.push_back(curves[k].span);
          if (carrier.closed)
          {
            checkClosedSection(section.points, entityText, here,
              "section " + std::to_string(k + 1) +
                (curves[k].name.empty() ? std::string() : " ('" + curves[k].name + "')"));
          }
          try
          {
            if (align)
            {
              alignSection(section);
            }
            carrier.refs.push_back(addHiddenCarrier(section));
          }
          catch (const GeometryError& error)
          {
            fail(here, entityText,
              "section " + std::to_string(k + 1) + " of input '" + source + "': " +
                error.what());
          }
          catch (const TemplateError& error)
          {
            fail(here, entityText,
              "section " + std::to_string(k + 1) + " of input '" + source + "': " +
                error.what());
          }
        }
      }
      if (carrier.refs.size() < 2)
      {
        fail(here, entityText, "a Gordon surface needs at least 2 sections");
      }
      carrier.nodes = sectionParameters(at, carrier.refs.size(), spans, entityText);
      if (carrier.closed && kind->value.IsSequence())
      {
        for (std::size_t k = 0; k < carrier.refs.size(); ++k)
        {
          const CurvePtr& curve = Geometry.curve(carrier.refs[k]);
          const double gap = (curve->point(0.0) - curve->point(1.0)).norm();
          if (gap > 1e-9 * Geometry.size(carrier.refs[k]))
          {
            fail(here, entityText,
              "closed: section " + std::to_string(k + 1) + " ('" +
                Model.carriers[carrier.refs[k]].name + "') is open: its ends are " +
                shortNumber(gap) + " apart");
          }
        }
      }
      return;
    }
    // network: {along_s: [curves at t = at_t], at_t: [...], along_t: [...], at_s: [...]}
    if (at)
    {
      fail(at->line, entityText, "a network gives its parameters as at_s and at_t");
    }
    const auto parts = syntax::mapEntries(kind->value, kind->line, entityText, "network", Report);
    syntax::checkKeys(parts, { "along_s", "at_t", "along_t", "at_s" }, entityText, Report);
    const MapEntry* alongS = syntax::findEntry(parts, "along_s");
    const MapEntry* alongT = syntax::findEntry(parts, "along_t");
    if (!alongS || !alongT || !alongS->value.IsSequence() || !alongT->value.IsSequence())
    {
      fail(here, entityText,
        "network needs along_s: [curves running in s] and along_t: [curves running in t]");
    }
    for (std::size_t k = 0; k < alongS->value.size(); ++k)
    {
      carrier.refs.push_back(carrierRef(
        alongS->value[k], alongS->line, entityText, "along_s " + std::to_string(k + 1), Want::Curve));
    }
    for (std::size_t k = 0; k < alongT->value.size(); ++k)
    {
      carrier.crossRefs.push_back(carrierRef(
        alongT->value[k], alongT->line, entityText, "along_t " + std::to_string(k + 1), Want::Curve));
    }
    if (carrier.refs.size() < 2 || carrier.crossRefs.size() < 2)
    {
      fail(here, entityText, "a network needs at least 2 curves in each direction");
    }
    carrier.nodes = sectionParameters(syntax::findEntry(parts, "at_t"), carrier.refs.size(), {}, entityText);
    carrier.crossNodes =
      sectionParameters(syntax::findEntry(parts, "at_s"), carrier.crossRefs.size(), {}, entityText);
    return;
  }

  if (kind->key == "coons")
  {
    syntax::checkKeys(keys, { "coons" }, entityText, Report);
    carrier.kind = Carrier::Kind::Coons;
    if (!kind->value.IsSequence() || kind->value.size() != 4)
    {
      fail(here, entityText,
        "coons expects four curves [bottom, right, top, left]: P(s, 0), P(1, t), P(s, 1), "
        "P(0, t), each running in increasing s or t");
    }
    static const char* const roles[4] = { "bottom", "right", "top", "left" };
    for (int k = 0; k < 4; ++k)
    {
      carrier.refs.push_back(carrierRef(kind->value[k], here, entityText, roles[k], Want::Curve));
    }
    return;
  }

  if (kind->key == "surface_curve")
  {
    syntax::checkKeys(keys, { "surface_curve", "through" }, entityText, Report);
    carrier.kind = Carrier::Kind::SurfaceCurve;
    const int surface =
      carrierRef(kind->value, kind->line, entityText, "surface_curve", Want::Surface);
    carrier.refs = { surface };
    const MapEntry* through = syntax::findEntry(keys, "through");
    if (!through || !through->value.IsSequence() || through->value.size() < 2)
    {
      fail(through ? through->line : entry.line, entityText,
        "surface_curve needs 'through: [...]' with at least 2 items: vertices on the "
        "surface or parameter pairs [s, t]");
    }
    for (std::size_t k = 0; k < through->value.size(); ++k)
    {
      const YAML::Node item = through->value[k];
      const std::string what = "through " + std::to_string(k + 1);
      if (item.IsSequence())
      {
        if (item.size() != 2)
        {
          fail(lineOrFallback(item, through->line), entityText, what + ": expected [s, t]");
        }
        carrier.parameterPoints.emplace_back(
          number(item[0], through->line, entityText, what + " s"),
          number(item[1], through->line, entityText, what + " t"));
      }
      else
      {
        const int vertex = vertexRef(item, through->line, entityText);
        double s = 0.0, t = 0.0, distance = 0.0;
        Geometry.vertexParameters(Model, vertex, surface, s, t, distance);
        checkOnCarrier(vertex, surface, distance, lineOrFallback(item, through->line), entityText);
        carrier.parameterPoints.emplace_back(s, t);
        carrier.throughVertices.resize(carrier.parameterPoints.size(), -1);
        carrier.throughVertices.back() = vertex; // drawn again when it moves
      }
    }
    return;
  }

  if (kind->key == "offset")
  {
    syntax::checkKeys(keys, { "offset", "on", "distance" }, entityText, Report);
    carrier.kind = Carrier::Kind::Offset;
    const MapEntry* on = syntax::findEntry(keys, "on");
    const MapEntry* distance = syntax::findEntry(keys, "distance");
    if (!on || !distance)
    {
      fail(entry.line, entityText,
        "offset needs 'on: <surface the curve lies on>' and 'distance: <length>', e.g. "
        "{offset: blade_hub, on: hub, distance: 0.01}");
    }
    carrier.refs = { carrierRef(kind->value, kind->line, entityText, "offset", Want::Curve),
      carrierRef(on->value, on->line, entityText, "on", Want::Surface) };
    carrier.distance = number(distance->value, distance->line, entityText, "distance");
    if (carrier.distance == 0.0)
    {
      fail(distance->line, entityText, "the offset distance must not be zero");
    }
    return;
  }

  // intersect
  syntax::checkKeys(keys, { "intersect", "range", "samples" }, entityText, Report);
  carrier.kind = Carrier::Kind::Intersect;
  if (!kind->value.IsSequence() || kind->value.size() != 2)
  {
    fail(here, entityText,
      "intersect expects [surface, surface of revolution], e.g. [blade, hub]");
  }
  carrier.refs = { carrierRef(kind->value[0], here, entityText, "intersect", Want::Surface),
    carrierRef(kind->value[1], here, entityText, "intersect", Want::Surface) };
  if (const MapEntry* range = syntax::findEntry(keys, "range"))
  {
    if (!range->value.IsSequence() || range->value.size() != 2)
    {
      fail(range->line, entityText, "'range' expects [t_min, t_max] on the first surface");
    }
    carrier.rangeMin = number(range->value[0], range->line, entityText, "range t_min");
    carrier.rangeMax = number(range->value[1], range->line, entityText, "range t_max");
    if (!(carrier.rangeMax > carrier.rangeMin))
    {
      fail(range->line, entityText, "'range' needs t_min < t_max");
    }
  }
  if (const MapEntry* samples = syntax::findEntry(keys, "samples"))
  {
    const double value = number(samples->value, samples->line, entityText, "samples");
    if (value != std::floor(value) || value < 4 || value > 100000)
    {
      fail(samples->line, entityText, "samples must be a whole number from 4 to 100000");
    }
    carrier.samples = static_cast<int>(value);
  }
}

/**
 * `align: axial`: re-parametrises a closed section so that s = 0.25 is its leading edge
 * (the smallest axial coordinate) and s = 0.75 its trailing edge (the largest), by chord
 * length between them and the seam s = 0 (half-way along the second side). Every section of the blade then has its edges at the same s, so lines of
 * constant s on the Gordon surface follow the edges from hub to shroud, and so do block
 * edges straight in the blade's (s, t) space.
 */
void TemplateReader::alignSection(Carrier& section)
{
  const BSplineCurve curve = BSplineCurve::interpolate(
    section.points, section.degree, parameterMethodOf(section.parameterMethod));
  auto point = [&](double u) { return curve.point(u); };
  auto axialOf = [&](const Vec3& p) {
    double axial = 0.0, radius = 0.0, theta = 0.0;
    cylindrical(p, axial, radius, theta);
    return axial;
  };
  const double leading = extremum(point, true, axialOf, 1.0, 0.0, 1.0);
  const double trailing = extremum(point, true, axialOf, -1.0, 0.0, 1.0);
  const std::vector<double>& u = curve.dataParameters(); // u[0] = 0 ... u[n-1] = 1
  const std::size_t n = u.size() - 1;                    // distinct points (closed loop)
  auto offsetFrom = [](double from, double x) { return x - from - std::floor(x - from); };
  // An edge within a quarter of the neighbouring data spacing of a data point is moved
  // onto that point (rather than dropping the point: the blade passes through every
  // input point); otherwise it is inserted between the data points.
  auto snap = [&](double edge, std::size_t& index) {
    for (std::size_t k = 0; k < n; ++k)
    {
      const double before = k > 0 ? u[k] - u[k - 1] : u[n] - u[n - 1];
      const double after = u[k + 1] - u[k];
      const double ahead = offsetFrom(edge, u[k]); // from the edge forward to the point
      if (ahead <= 0.25 * before || 1.0 - ahead <= 0.25 * after)
      {
        index = k;
        return true;
      }
    }
    return false;
  };
  // Start (the seam) at the data point half-way along the side from the trailing to the
  // leading edge, so that neither edge lies on the seam, where the curves through the
  // blade are only C0.
  const double back = trailing + 0.5 * offsetFrom(trailing, leading);
  std::size_t seamIndex = 0;
  double nearest = 2.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    const double d = std::min(offsetFrom(back, u[k]), offsetFrom(u[k], back));
    if (d < nearest)
    {
      nearest = d;
      seamIndex = k;
    }
  }
  struct Mark
  {
    double at;         // parameter on the original curve
    bool isData;       // a data point (else an inserted edge point)
    std::size_t index; // data index
    int role;          // 0 data, 1 leading edge, 2 trailing edge
  };
  std::vector<Mark> marks;
  std::size_t snapped = n;
  const bool leadingOnData = snap(leading, snapped);
  const std::size_t leadingData = snapped;
  const bool trailingOnData = snap(trailing, snapped);
  const std::size_t trailingData = snapped;
  if (leadingOnData && trailingOnData && leadingData == trailingData)
  {
    throw GeometryError("align: the section's leading and trailing edges coincide");
  }
  for (std::size_t k = 0; k < n; ++k)
  {
    const int role = leadingOnData && k == leadingData ? 1
      : trailingOnData && k == trailingData          ? 2
                                                      : 0;
    marks.push_back({ u[k], true, k, role });
  }
  if (!leadingOnData)
  {
    marks.push_back({ leading, false, 0, 1 });
  }
  if (!trailingOnData)
  {
    marks.push_back({ trailing, false, 0, 2 });
  }
  const double seamAt = u[seamIndex];
  std::sort(marks.begin(), marks.end(), [&](const Mark& x, const Mark& y) {
    return offsetFrom(seamAt, x.at) < offsetFrom(seamAt, y.at);
  });
  std::vector<Vec3> points;
  std::size_t leadingIndex = 0, trailingIndex = 0;
  for (const Mark& mark : marks)
  {
    if (mark.role == 1)
    {
      leadingIndex = points.size();
    }
    if (mark.role == 2)
    {
      trailingIndex = points.size();
    }
    points.push_back(mark.isData ? section.points[mark.index] : curve.point(mark.at));
  }
  points.push_back(points.front());
  if (!(leadingIndex > 0 && trailingIndex > leadingIndex))
  {
    throw GeometryError("align: the section's edges are not in order around it");
  }
  std::vector<double> length(points.size(), 0.0);
  for (std::size_t k = 1; k < points.size(); ++k)
  {
    length[k] = length[k - 1] + (points[k] - points[k - 1]).norm();
  }
  // chord length within each piece: [0, 0.25] seam -> LE, [0.25, 0.75] LE -> TE (one
  // side), [0.75, 1] TE -> seam
  const std::size_t ends[4] = { 0, leadingIndex, trailingIndex, points.size() - 1 };
  const double at[4] = { 0.0, 0.25, 0.75, 1.0 };
  std::vector<double> parameters(points.size());
  for (int piece = 0; piece < 3; ++piece)
  {
    const double from = length[ends[piece]], to = length[ends[piece + 1]];
    for (std::size_t k = ends[piece]; k <= ends[piece + 1]; ++k)
    {
      parameters[k] = at[piece] + (at[piece + 1] - at[piece]) * (length[k] - from) / (to - from);
    }
    parameters[ends[piece + 1]] = at[piece + 1];
  }
  parameters.front() = 0.0;
  section.points = std::move(points);
  section.nodes = std::move(parameters);
}

void TemplateReader::checkClosedSection(const std::vector<Vec3>& points, const std::string& entityText,
  int line, const std::string& what)
{
  Vec3 low = points.front(), high = low;
  for (const Vec3& p : points)
  {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const double size = std::max((high - low).norm(), 1e-300);
  const double gap = (points.front() - points.back()).norm();
  if (points.size() < 3 || gap > 1e-9 * size)
  {
    fail(line, entityText,
      "closed: " + what + " is open: its first and last points are " + shortNumber(gap) +
        " apart (" + shortNumber(100.0 * gap / size) +
        " % of its size); the blade surface must close around every section (the "
        "TurboPointSetsReader joins gaps up to 0.2 % of the chord and caps blunt "
        "trailing edges up to 5 %)");
  }
}
} // namespace detail
} // namespace model
} // namespace blockforge
