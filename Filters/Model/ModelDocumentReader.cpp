/**
 * @file ModelDocumentReader.cpp
 * @brief readModelDocument: the versioned YAML text of writeModelDocument
 * (ModelDocumentWriter.cpp) back into a block model, every format since 1, with errors
 * naming the document's line and entity.
 */
#include "ModelDocument.h"

#include "ModelSyntax.h"
#include "Placement.h"
#include "Errors.h"

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace model
{
namespace
{
using syntax::entity;
using syntax::MapEntry;
using syntax::ModelDocumentFile;

// ---------------------------------------------------------------------------- reading
class DocumentReader
{
public:
  explicit DocumentReader(const std::string& text)
    : Text(text)
  {
    Report.file = ModelDocumentFile;
  }

  BlockModel read()
  {
    YAML::Node root;
    try
    {
      root = YAML::Load(Text);
    }
    catch (const YAML::Exception& error)
    {
      fail(error.mark.line >= 0 ? error.mark.line + 1 : 0, "",
        "not a BlockForge model document (YAML error: " + error.msg + ")");
    }
    if (!root.IsMap())
    {
      fail(1, "", "not a BlockForge model document (expected 'blockforge_model: 1')");
    }
    const auto sections = syntax::mapEntries(root, 1, "", "the model document", Report);
    const MapEntry* version = syntax::findEntry(sections, "blockforge_model");
    if (!version)
    {
      fail(1, "", "not a BlockForge model document (missing 'blockforge_model')");
    }
    const double format = number(version->value, version->line, "", "blockforge_model");
    if (format != std::floor(format) || format < 1)
    {
      fail(version->line, "", "'blockforge_model' must be a whole version number");
    }
    if (format > BlockModel::FormatVersion)
    {
      fail(version->line, "",
        "the model document has format " + version->value.Scalar() +
          ", newer than this BlockForge reads (" + std::to_string(BlockModel::FormatVersion) +
          "); please update BlockForge");
    }
    // Checked after the version: a newer document may well have keys this build lacks.
    syntax::checkKeys(sections,
      { "blockforge_model", "name", "source", "parameters", "machine", "carriers", "vertices",
        "edges", "blocks", "faces", "patches", "expression_scope" },
      "", Report);
    if (const MapEntry* name = syntax::findEntry(sections, "name"))
    {
      Model.name = text(name->value, name->line, "", "name");
    }
    if (const MapEntry* source = syntax::findEntry(sections, "source"))
    {
      Model.sourceFile = text(source->value, source->line, "", "source");
    }
    if (const MapEntry* parameters = syntax::findEntry(sections, "parameters"))
    {
      for (const MapEntry& entry : syntax::mapEntries(
             parameters->value, parameters->line, "", "parameters", Report))
      {
        Model.parameters.emplace_back(entry.key,
          number(entry.value, entry.line, entity("parameter", entry.key), "value"));
      }
    }
    if (const MapEntry* machine = syntax::findEntry(sections, "machine"))
    {
      readMachine(*machine);
    }
    const std::vector<YAML::Node> carriers = list(sections, "carriers");
    for (const YAML::Node& node : carriers)
    {
      // Names first: carriers may refer to carriers listed after them.
      Carrier carrier;
      entries(node, "carrier", CarrierKeys, carrier.name, carrier.where);
      if (Model.findCarrier(carrier.name) >= 0)
      {
        fail(syntax::lineOf(node), entity("carrier", carrier.name), "defined twice");
      }
      Model.carriers.push_back(carrier);
    }
    for (std::size_t c = 0; c < carriers.size(); ++c)
    {
      readCarrier(carriers[c], Model.carriers[c]);
    }
    for (const YAML::Node& node : list(sections, "vertices"))
    {
      readVertex(node);
    }
    for (Vertex& vertex : Model.vertices)
    {
      resolvePeriodicSource(vertex);
      resolveRuleSource(vertex);
    }
    resolveFollowedVertices();
    if (const MapEntry* scope = syntax::findEntry(sections, "expression_scope"))
    {
      readExpressionScope(*scope);
    }
    for (const YAML::Node& node : list(sections, "edges"))
    {
      readEdge(node);
    }
    for (const YAML::Node& node : list(sections, "blocks"))
    {
      readBlock(node);
    }
    for (const YAML::Node& node : list(sections, "faces"))
    {
      readFaces(node);
    }
    for (const YAML::Node& node : list(sections, "patches"))
    {
      readPatch(node);
    }
    return std::move(Model);
  }

private:
  [[noreturn]] void fail(int line, const std::string& entityText, const std::string& what) const
  {
    Report.fail(line, entityText, what);
  }

  int here(const YAML::Node& node, int fallback) const
  {
    const int line = syntax::lineOf(node);
    return line && !node.IsNull() ? line : fallback;
  }

  double number(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what) const
  {
    double value = 0.0;
    if (!node.IsScalar() || !syntax::parseNumber(node.Scalar(), value) || !std::isfinite(value))
    {
      fail(here(node, line), entityText, what + ": expected a finite number");
    }
    return value;
  }

  int integer(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what) const
  {
    const double value = number(node, line, entityText, what);
    if (value != std::floor(value) || std::abs(value) > 2.0e9)
    {
      fail(here(node, line), entityText, what + ": expected a whole number");
    }
    return static_cast<int>(value);
  }

  std::string text(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what) const
  {
    if (!node.IsScalar())
    {
      fail(here(node, line), entityText, what + ": expected text");
    }
    return node.Scalar();
  }

  Vec3 vector3(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what) const
  {
    if (!node.IsSequence() || node.size() != 3)
    {
      fail(here(node, line), entityText, what + ": expected [x, y, z]");
    }
    return Vec3(number(node[0], line, entityText, what), number(node[1], line, entityText, what),
      number(node[2], line, entityText, what));
  }

  std::vector<YAML::Node> list(const std::vector<MapEntry>& sections, const std::string& key)
  {
    std::vector<YAML::Node> nodes;
    const MapEntry* section = syntax::findEntry(sections, key);
    if (!section || section->value.IsNull())
    {
      return nodes;
    }
    if (!section->value.IsSequence())
    {
      fail(section->line, "", "'" + key + "' must be a list");
    }
    for (const YAML::Node& node : section->value)
    {
      nodes.push_back(node);
    }
    return nodes;
  }

  /// The entity's keys; its name and source location are read here for every kind.
  std::vector<MapEntry> entries(const YAML::Node& node, const std::string& kind,
    const std::vector<std::string>& allowed, std::string& name, SourceLocation& where)
  {
    const int line = syntax::lineOf(node);
    auto keys = syntax::mapEntries(node, line, kind, "a " + kind, Report);
    if (!node.IsMap())
    {
      fail(line, "", "each " + kind + " must be a mapping");
    }
    std::vector<std::string> all = allowed;
    all.insert(all.end(), { "name", "file", "line" });
    const MapEntry* nameEntry = syntax::findEntry(keys, "name");
    if (!nameEntry)
    {
      fail(line, "", "a " + kind + " without a name");
    }
    name = text(nameEntry->value, nameEntry->line, kind, "name");
    syntax::checkKeys(keys, all, entity(kind, name), Report);
    where.file = Model.sourceFile;
    if (const MapEntry* file = syntax::findEntry(keys, "file"))
    {
      where.file = text(file->value, file->line, entity(kind, name), "file");
    }
    if (const MapEntry* sourceLine = syntax::findEntry(keys, "line"))
    {
      where.line = integer(sourceLine->value, sourceLine->line, entity(kind, name), "line");
    }
    return keys;
  }

  const MapEntry& required(const std::vector<MapEntry>& keys, const std::string& key,
    const YAML::Node& node, const std::string& entityText) const
  {
    const MapEntry* found = syntax::findEntry(keys, key);
    if (!found)
    {
      fail(syntax::lineOf(node), entityText, "missing '" + key + "'");
    }
    return *found;
  }

  /// The index `find` gives the name in `node` (a `kind`: vertex, carrier), or an error.
  template <typename Find>
  int namedRef(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& kind, const Find& find) const
  {
    const std::string name = text(node, line, entityText, kind);
    const int index = find(name);
    if (index < 0)
    {
      fail(here(node, line), entityText, "unknown " + kind + " '" + name + "'");
    }
    return index;
  }

  int vertexRef(const YAML::Node& node, int line, const std::string& entityText) const
  {
    return namedRef(node, line, entityText, "vertex",
      [this](const std::string& name) { return Model.findVertex(name); });
  }

  void readVertex(const YAML::Node& node)
  {
    Vertex vertex;
    const auto keys = entries(
      node, "vertex", { "position", "on", "at", "periodic", "pitches", "rule", "source", "origin",
        "axis", "angle", "expressions", "fixed" }, vertex.name, vertex.where);
    const std::string entityText = entity("vertex", vertex.name);
    if (Model.findVertex(vertex.name) >= 0)
    {
      fail(syntax::lineOf(node), entityText, "defined twice");
    }
    const MapEntry& position = required(keys, "position", node, entityText);
    vertex.position = vector3(position.value, position.line, entityText, "position");
    if (const MapEntry* on = syntax::findEntry(keys, "on"))
    {
      vertex.constraint.carrier = carrierRef(on->value, on->line, entityText);
      const MapEntry& at = required(keys, "at", node, entityText);
      if (!at.value.IsSequence() || at.value.size() != 2)
      {
        fail(at.line, entityText, "'at' expects [s, t]");
      }
      vertex.constraint.s = number(at.value[0], at.line, entityText, "at");
      vertex.constraint.t = number(at.value[1], at.line, entityText, "at");
    }
    if (const MapEntry* periodic = syntax::findEntry(keys, "periodic"))
    {
      PeriodicSources.push_back(text(periodic->value, periodic->line, entityText, "periodic"));
      const MapEntry& pitches = required(keys, "pitches", node, entityText);
      vertex.constraint.pitches = integer(pitches.value, pitches.line, entityText, "pitches");
      vertex.constraint.periodicSource = -2; // resolved once every vertex is known
    }
    readRule(keys, node, entityText, vertex);
    if (const MapEntry* fixed = syntax::findEntry(keys, "fixed"))
    {
      const std::string mark = text(fixed->value, fixed->line, entityText, "fixed");
      if (mark != "true" && mark != "false")
      {
        fail(fixed->line, entityText, "fixed: expected true or false");
      }
      vertex.fixed = mark == "true";
    }
    if (const MapEntry* expressions = syntax::findEntry(keys, "expressions"))
    {
      readPlacementExpressions(*expressions, entityText, vertex);
    }
    Model.vertices.push_back(vertex);
  }

  /// Format 4: `expressions: {form: axial_theta | curve_parameter, texts: [...],
  /// follows: [vertex, ...], base: [s, t], shift: [s, t]}`.
  void readPlacementExpressions(const MapEntry& entry, const std::string& entityText, Vertex& vertex)
  {
    const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "expressions", Report);
    syntax::checkKeys(keys, { "form", "texts", "follows", "base", "shift" }, entityText, Report);
    PlacementExpressions& expressions = vertex.rule.expressions;
    const MapEntry& form = required(keys, "form", entry.value, entityText);
    const std::string formName = text(form.value, form.line, entityText, "form");
    if (formName != "axial_theta" && formName != "curve_parameter")
    {
      fail(form.line, entityText, "unknown expression form '" + formName + "' (axial_theta, curve_parameter)");
    }
    expressions.form = formName == "axial_theta" ? PlacementExpressions::Form::AxialTheta
                                                 : PlacementExpressions::Form::CurveParameter;
    const MapEntry& texts = required(keys, "texts", entry.value, entityText);
    const std::size_t count = expressions.form == PlacementExpressions::Form::AxialTheta ? 2 : 1;
    if (!texts.value.IsSequence() || texts.value.size() != count)
    {
      fail(texts.line, entityText, "'texts' expects " + std::to_string(count) + " expressions");
    }
    for (const YAML::Node& item : texts.value)
    {
      expressions.texts.push_back(text(item, texts.line, entityText, "texts"));
    }
    const MapEntry& follows = required(keys, "follows", entry.value, entityText);
    if (!follows.value.IsSequence())
    {
      fail(follows.line, entityText, "'follows' expects a list of vertices");
    }
    std::vector<std::string> names;
    for (const YAML::Node& item : follows.value)
    {
      names.push_back(text(item, follows.line, entityText, "follows"));
    }
    FollowedNames.push_back({ Model.vertices.size(), names, follows.line, entityText });
    for (const char* key : { "base", "shift" })
    {
      const MapEntry& pair = required(keys, key, entry.value, entityText);
      if (!pair.value.IsSequence() || pair.value.size() != 2)
      {
        fail(pair.line, entityText, std::string("'") + key + "' expects [s, t]");
      }
      std::array<double, 2>& values = std::string(key) == "base" ? expressions.base : expressions.shift;
      values = { { number(pair.value[0], pair.line, entityText, key),
        number(pair.value[1], pair.line, entityText, key) } };
    }
  }

  /// Vertices named in `follows` and carriers' `through`, once every vertex is known.
  void resolveFollowedVertices()
  {
    auto resolve = [&](const FollowedName& item, std::vector<int>& out) {
      out.clear();
      for (const std::string& name : item.names)
      {
        const int vertex = name == "-" ? -1 : Model.findVertex(name);
        if (name != "-" && vertex < 0)
        {
          fail(item.line, item.entity, "unknown vertex '" + name + "'");
        }
        out.push_back(vertex);
      }
    };
    for (const FollowedName& item : FollowedNames)
    {
      resolve(item, Model.vertices[item.index].rule.expressions.follows);
    }
    for (const FollowedName& item : ThroughNames)
    {
      std::vector<int>& through = Model.carriers[item.index].throughVertices;
      resolve(item, through);
      if (through.size() != Model.carriers[item.index].parameterPoints.size())
      {
        fail(item.line, item.entity, "'through' names one vertex (or -) per point");
      }
    }
  }

  /// Format 4: `expression_scope: {theta_zero: [x, y, z], values: {name: v},
  /// definitions: {name: expression}}`.
  void readExpressionScope(const MapEntry& entry)
  {
    const std::string entityText = "expression_scope";
    const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, entityText, Report);
    syntax::checkKeys(keys, { "theta_zero", "values", "definitions" }, entityText, Report);
    ExpressionScope& scope = Model.expressionScope;
    const MapEntry& zero = required(keys, "theta_zero", entry.value, entityText);
    scope.thetaZero = vector3(zero.value, zero.line, entityText, "theta_zero");
    if (const MapEntry* values = syntax::findEntry(keys, "values"))
    {
      for (const MapEntry& value : syntax::mapEntries(values->value, values->line, entityText, "values", Report))
      {
        scope.values.emplace_back(value.key, number(value.value, value.line, entityText, value.key));
      }
    }
    if (const MapEntry* definitions = syntax::findEntry(keys, "definitions"))
    {
      for (const MapEntry& definition :
        syntax::mapEntries(definitions->value, definitions->line, entityText, "definitions", Report))
      {
        scope.definitions.emplace_back(
          definition.key, text(definition.value, definition.line, entityText, definition.key));
      }
    }
  }

  /// Format 3: the placement rule when the constraint does not imply it (older documents
  /// have none: their rules are the implied ones).
  void readRule(const std::vector<MapEntry>& keys, const YAML::Node& node,
    const std::string& entityText, Vertex& vertex)
  {
    VertexConstraint constraint = vertex.constraint;
    if (constraint.periodicSource == -2)
    {
      constraint.periodicSource = 0; // periodic, its source not resolved yet
    }
    vertex.rule = impliedRule(constraint);
    const MapEntry* rule = syntax::findEntry(keys, "rule");
    if (!rule)
    {
      return;
    }
    const std::string name = text(rule->value, rule->line, entityText, "rule");
    const std::vector<std::string>& names = vertexRuleNames();
    const auto found = std::find(names.begin(), names.end(), name);
    if (found == names.end())
    {
      fail(rule->line, entityText,
        "unknown placement rule '" + name + "' (" + syntax::joinNames(names) + ")");
    }
    vertex.rule.kind = static_cast<VertexRule::Kind>(found - names.begin());
    const bool needsCarrier = vertex.rule.kind == VertexRule::Kind::OnCarrier ||
      vertex.rule.kind == VertexRule::Kind::Intersection ||
      vertex.rule.kind == VertexRule::Kind::Projected;
    if (needsCarrier && vertex.constraint.carrier < 0)
    {
      fail(rule->line, entityText, "rule '" + name + "' needs 'on' and 'at'");
    }
    if (vertex.rule.kind == VertexRule::Kind::Periodic && vertex.constraint.periodicSource == -1)
    {
      fail(rule->line, entityText, "rule 'periodic' needs 'periodic' and 'pitches'");
    }
    if (vertex.rule.kind == VertexRule::Kind::Projected ||
      vertex.rule.kind == VertexRule::Kind::Rotated)
    {
      const MapEntry& source = required(keys, "source", node, entityText);
      RuleSources.push_back(text(source.value, source.line, entityText, "source"));
      vertex.rule.source = -2; // resolved once every vertex is known
    }
    if (vertex.rule.kind == VertexRule::Kind::Rotated)
    {
      const MapEntry& origin = required(keys, "origin", node, entityText);
      const MapEntry& axis = required(keys, "axis", node, entityText);
      const MapEntry& angle = required(keys, "angle", node, entityText);
      vertex.rule.origin = vector3(origin.value, origin.line, entityText, "origin");
      vertex.rule.axis = vector3(axis.value, axis.line, entityText, "axis");
      vertex.rule.angle = number(angle.value, angle.line, entityText, "angle");
    }
  }

  void resolveRuleSource(Vertex& vertex)
  {
    if (vertex.rule.source != -2)
    {
      return;
    }
    const std::string& sourceName = RuleSources[NextRuleSource++];
    vertex.rule.source = Model.findVertex(sourceName);
    if (vertex.rule.source < 0 || vertex.rule.source == &vertex - Model.vertices.data())
    {
      fail(vertex.where.line, entity("vertex", vertex.name),
        "unknown source vertex '" + sourceName + "' of its placement rule");
    }
  }

  void readEdge(const YAML::Node& node)
  {
    Edge edge;
    const auto keys = entries(node, "edge",
      { "kind", "from", "to", "centre", "through", "points", "carrier", "at", "at_expressions",
        "at_follows", "source", "pitches" },
      edge.name, edge.where);
    const std::string entityText = entity("edge", edge.name);
    const MapEntry& kind = required(keys, "kind", node, entityText);
    const std::string kindName = text(kind.value, kind.line, entityText, "kind");
    const MapEntry& from = required(keys, "from", node, entityText);
    const MapEntry& to = required(keys, "to", node, entityText);
    edge.from = vertexRef(from.value, from.line, entityText);
    edge.to = vertexRef(to.value, to.line, entityText);
    const bool known = edgeKindFromName(kindName, edge.kind); // the one table of edge kinds
    if (known && edge.kind == Edge::Kind::Line)
    {
    }
    else if (known && edge.kind == Edge::Kind::Arc)
    {
      const MapEntry* centre = syntax::findEntry(keys, "centre");
      const MapEntry* through = syntax::findEntry(keys, "through");
      if ((centre != nullptr) == (through != nullptr))
      {
        fail(kind.line, entityText, "an arc needs exactly one of 'centre' or 'through'");
      }
      edge.arcHasCentre = centre != nullptr;
      if (centre)
      {
        edge.arcCentre = vector3(centre->value, centre->line, entityText, "centre");
      }
      else
      {
        edge.arcThrough = vector3(through->value, through->line, entityText, "through");
      }
    }
    else if (known && edge.kind == Edge::Kind::Spline)
    {
      const MapEntry& points = required(keys, "points", node, entityText);
      if (!points.value.IsSequence())
      {
        fail(points.line, entityText, "'points' must be a list of [x, y, z]");
      }
      for (const YAML::Node& point : points.value)
      {
        edge.splinePoints.push_back(vector3(point, points.line, entityText, "point"));
      }
    }
    else if (known &&
      (edge.kind == Edge::Kind::OnCurve || edge.kind == Edge::Kind::OnSurface ||
        edge.kind == Edge::Kind::Project))
    {
      const MapEntry& carrier = required(keys, "carrier", node, entityText);
      edge.carrier = carrierRef(carrier.value, carrier.line, entityText);
      if (const MapEntry* at = syntax::findEntry(keys, "at"))
      {
        if (!at->value.IsSequence())
        {
          fail(at->line, entityText, "'at' must be a list of numbers");
        }
        for (const YAML::Node& value : at->value)
        {
          edge.at.push_back(number(value, at->line, entityText, "at"));
        }
      }
      const MapEntry* texts = syntax::findEntry(keys, "at_expressions");
      const MapEntry* follows = syntax::findEntry(keys, "at_follows");
      if ((texts != nullptr) != (follows != nullptr))
      {
        fail((texts ? texts : follows)->line, entityText,
          "'at_expressions' and 'at_follows' come together");
      }
      if (texts)
      {
        if (!texts->value.IsSequence() || texts->value.size() != edge.at.size() ||
          !follows->value.IsSequence())
        {
          fail(texts->line, entityText, "'at_expressions' gives one expression per value of 'at'");
        }
        for (const YAML::Node& text : texts->value)
        {
          edge.atExpressions.push_back(this->text(text, texts->line, entityText, "at_expressions"));
        }
        for (const YAML::Node& vertex : follows->value)
        {
          edge.atFollows.push_back(vertexRef(vertex, follows->line, entityText));
        }
      }
    }
    else if (known && (edge.kind == Edge::Kind::Periodic || edge.kind == Edge::Kind::Follow))
    {
      const MapEntry& source = required(keys, "source", node, entityText);
      edge.source = edgeRef(source.value, source.line, entityText, "source");
      if (edge.kind == Edge::Kind::Periodic)
      {
        const MapEntry& pitches = required(keys, "pitches", node, entityText);
        edge.pitches = integer(pitches.value, pitches.line, entityText, "pitches");
      }
    }
    else
    {
      fail(kind.line, entityText,
        "unknown edge kind '" + kindName + "' (" + syntax::joinNames(edgeKindNames()) + ")");
    }
    Model.edges.push_back(edge);
  }

  void readBlock(const YAML::Node& node)
  {
    Block block;
    const auto keys =
      entries(node, "block", { "vertices", "cells", "min_cells", "laws", "interpolation" }, block.name, block.where);
    const std::string entityText = entity("block", block.name);
    const MapEntry& vertices = required(keys, "vertices", node, entityText);
    if (!vertices.value.IsSequence() || vertices.value.size() != 8)
    {
      fail(vertices.line, entityText, "needs 8 vertices");
    }
    for (int v = 0; v < 8; ++v)
    {
      block.vertices[v] = vertexRef(vertices.value[v], vertices.line, entityText);
    }
    // `cells` and `min_cells` alike: three counts of at least 1
    const auto readCounts = [&](const MapEntry& counts, const std::string& key, std::array<int, 3>& out) {
      if (!counts.value.IsSequence() || counts.value.size() != 3)
      {
        fail(counts.line, entityText, "'" + key + "' needs three counts");
      }
      for (int d = 0; d < 3; ++d)
      {
        out[d] = integer(counts.value[d], counts.line, entityText, key);
        if (out[d] < 1)
        {
          fail(counts.line, entityText, key + " must be at least 1");
        }
      }
    };
    readCounts(required(keys, "cells", node, entityText), "cells", block.cells);
    if (const MapEntry* least = syntax::findEntry(keys, "min_cells"))
    {
      readCounts(*least, "min_cells", block.minCells);
    }
    if (const MapEntry* interpolation = syntax::findEntry(keys, "interpolation"))
    {
      block.blending = syntax::parseBlending(interpolation->value, interpolation->line, entityText, Report);
    }
    const MapEntry& laws = required(keys, "laws", node, entityText);
    if (!laws.value.IsSequence() || laws.value.size() != 12)
    {
      fail(laws.line, entityText, "'laws' needs one law per edge, E1 to E12");
    }
    const syntax::NumberReader reader = [this, &entityText](const YAML::Node& value, int line,
                                          const std::string& what) {
      return number(value, line, entityText, what);
    };
    const syntax::EdgeReader edges = [this, &entityText](const YAML::Node& value, int line,
                                       const std::string& what) {
      return edgeRef(value, line, entityText, what);
    };
    for (int e = 0; e < 12; ++e)
    {
      block.laws[e] = syntax::parseLaw(laws.value[e], laws.line, entityText,
        "law " + syntax::edgeLabel(e), reader, Report, edges);
    }
    Model.blocks.push_back(block);
  }

  /// The named edge called by `node` (read above).
  int edgeRef(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what)
  {
    const std::string edgeName = text(node, line, entityText, what);
    const int index = Model.findNamedEdge(edgeName);
    if (index < 0)
    {
      fail(line, entityText, what + ": unknown edge '" + edgeName + "'");
    }
    return index;
  }

  void readPatch(const YAML::Node& node)
  {
    Patch patch;
    const auto keys = entries(node, "patch",
      { "type", "faces", "partner", "axis", "origin", "angle", "pitches" }, patch.name, patch.where);
    const std::string entityText = entity("patch", patch.name);
    const MapEntry& type = required(keys, "type", node, entityText);
    patch.type = text(type.value, type.line, entityText, "type");
    const MapEntry& faces = required(keys, "faces", node, entityText);
    if (!faces.value.IsSequence())
    {
      fail(faces.line, entityText, "'faces' must be a list of block.face");
    }
    for (const YAML::Node& face : faces.value)
    {
      patch.faces.push_back(blockFaceRef(face, faces.line, entityText));
    }
    if (const MapEntry* partner = syntax::findEntry(keys, "partner"))
    {
      patch.periodicPartner = text(partner->value, partner->line, entityText, "partner");
    }
    if (const MapEntry* axis = syntax::findEntry(keys, "axis"))
    {
      patch.periodicAxis = vector3(axis->value, axis->line, entityText, "axis");
    }
    if (const MapEntry* origin = syntax::findEntry(keys, "origin"))
    {
      patch.periodicAxisPoint = vector3(origin->value, origin->line, entityText, "origin");
    }
    if (const MapEntry* angle = syntax::findEntry(keys, "angle"))
    {
      patch.periodicAngle = number(angle->value, angle->line, entityText, "angle");
    }
    if (const MapEntry* pitches = syntax::findEntry(keys, "pitches"))
    {
      patch.pitches = integer(pitches->value, pitches->line, entityText, "pitches");
    }
    Model.patches.push_back(patch);
  }

  BlockFace blockFaceRef(const YAML::Node& face, int line, const std::string& entityText) const
  {
    const std::string name = text(face, line, entityText, "face");
    const std::size_t dot = name.rfind('.');
    BlockFace blockFace;
    if (dot != std::string::npos)
    {
      blockFace.block = Model.findBlock(name.substr(0, dot));
      blockFace.face = faceFromName(name.substr(dot + 1));
    }
    if (blockFace.block < 0 || blockFace.face < 0)
    {
      fail(here(face, line), entityText, "unknown face '" + name + "'");
    }
    return blockFace;
  }

  void readFaces(const YAML::Node& node)
  {
    SurfaceFaces set;
    const auto keys = entries(node, "face set", { "on_surface", "follow", "faces" }, set.name, set.where);
    const std::string entityText = entity("face set", set.name);
    const MapEntry* follow = syntax::findEntry(keys, "follow");
    if (follow)
    {
      if (!(follow->value.IsScalar() && follow->value.Scalar() == "opposite"))
      {
        fail(follow->line, entityText, "'follow' must be 'opposite'");
      }
      set.followOpposite = true;
    }
    else
    {
      const MapEntry& surface = required(keys, "on_surface", node, entityText);
      set.carrier = carrierRef(surface.value, surface.line, entityText);
    }
    const MapEntry& faces = required(keys, "faces", node, entityText);
    if (!faces.value.IsSequence())
    {
      fail(faces.line, entityText, "'faces' must be a list of block.face");
    }
    for (const YAML::Node& face : faces.value)
    {
      set.faces.push_back(blockFaceRef(face, faces.line, entityText));
    }
    Model.surfaceFaces.push_back(set);
  }

  void readMachine(const MapEntry& machine)
  {
    const std::string entityText = "machine";
    const auto keys =
      syntax::mapEntries(machine.value, machine.line, entityText, "the machine", Report);
    syntax::checkKeys(keys, { "axis", "origin", "blade_count" }, entityText, Report);
    Model.machine.defined = true;
    const MapEntry& axis = required(keys, "axis", machine.value, entityText);
    Model.machine.axis = vector3(axis.value, axis.line, entityText, "axis");
    const MapEntry& origin = required(keys, "origin", machine.value, entityText);
    Model.machine.axisPoint = vector3(origin.value, origin.line, entityText, "origin");
    const MapEntry& count = required(keys, "blade_count", machine.value, entityText);
    Model.machine.bladeCount = integer(count.value, count.line, entityText, "blade_count");
  }

  int carrierRef(const YAML::Node& node, int line, const std::string& entityText) const
  {
    return namedRef(node, line, entityText, "carrier",
      [this](const std::string& name) { return Model.findCarrier(name); });
  }

  /// The items of list `key` (empty when absent), each read by `item(node, line)`.
  template <typename Item, typename Read>
  std::vector<Item> listOf(const std::vector<MapEntry>& keys, const std::string& key,
    const std::string& entityText, const std::string& what, Read&& item) const
  {
    std::vector<Item> values;
    const MapEntry* found = syntax::findEntry(keys, key);
    if (!found)
    {
      return values;
    }
    if (!found->value.IsSequence())
    {
      fail(found->line, entityText, "'" + key + "' must be a list of " + what);
    }
    for (const YAML::Node& node : found->value)
    {
      values.push_back(item(node, found->line));
    }
    return values;
  }

  std::vector<int> carrierRefs(
    const std::vector<MapEntry>& keys, const std::string& key, const std::string& entityText) const
  {
    return listOf<int>(keys, key, entityText, "carriers",
      [&](const YAML::Node& node, int line) { return carrierRef(node, line, entityText); });
  }

  std::vector<double> numbers(const std::vector<MapEntry>& keys, const std::string& key,
    const std::string& entityText) const
  {
    return listOf<double>(keys, key, entityText, "numbers",
      [&](const YAML::Node& node, int line) { return number(node, line, entityText, key); });
  }

  void readCarrier(const YAML::Node& node, Carrier& carrier)
  {
    std::string name;
    SourceLocation where;
    const auto keys = entries(node, "carrier", CarrierKeys, name, where);
    const std::string entityText = entity("carrier", name);
    const MapEntry& kind = required(keys, "kind", node, entityText);
    const std::string kindName = text(kind.value, kind.line, entityText, "kind");
    const std::vector<std::string>& kinds = carrierKindNames();
    int found = -1;
    for (std::size_t k = 0; k < kinds.size(); ++k)
    {
      if (kindName == kinds[k])
      {
        found = static_cast<int>(k);
      }
    }
    if (found < 0)
    {
      fail(kind.line, entityText, "unknown carrier kind '" + kindName + "'");
    }
    carrier.kind = static_cast<Carrier::Kind>(found);
    if (const MapEntry* points = syntax::findEntry(keys, "points"))
    {
      if (!points->value.IsSequence())
      {
        fail(points->line, entityText, "'points' must be a list");
      }
      for (const YAML::Node& point : points->value)
      {
        if (carrier.kind == Carrier::Kind::SurfaceCurve)
        {
          if (!point.IsSequence() || point.size() != 2)
          {
            fail(points->line, entityText, "'points' of a surface curve are [s, t] pairs");
          }
          carrier.parameterPoints.emplace_back(number(point[0], points->line, entityText, "s"),
            number(point[1], points->line, entityText, "t"));
        }
        else
        {
          carrier.points.push_back(vector3(point, points->line, entityText, "point"));
        }
      }
    }
    if (const MapEntry* through = syntax::findEntry(keys, "through"))
    {
      if (!through->value.IsSequence())
      {
        fail(through->line, entityText, "'through' expects a list of vertices (- for none)");
      }
      std::vector<std::string> names;
      for (const YAML::Node& item : through->value)
      {
        names.push_back(text(item, through->line, entityText, "through"));
      }
      ThroughNames.push_back({ static_cast<std::size_t>(&carrier - Model.carriers.data()), names,
        through->line, entityText });
    }
    if (const MapEntry* degree = syntax::findEntry(keys, "degree"))
    {
      carrier.degree = integer(degree->value, degree->line, entityText, "degree");
    }
    if (const MapEntry* method = syntax::findEntry(keys, "parameters"))
    {
      const std::string value = text(method->value, method->line, entityText, "parameters");
      carrier.parameterMethod = value == "uniform" ? 0 : value == "centripetal" ? 2 : 1;
      if (value != "uniform" && value != "centripetal" && value != "chord")
      {
        fail(method->line, entityText, "unknown parameters '" + value + "'");
      }
    }
    carrier.refs = carrierRefs(keys, "refs", entityText);
    carrier.crossRefs = carrierRefs(keys, "cross_refs", entityText);
    carrier.nodes = numbers(keys, "at", entityText);
    carrier.crossNodes = numbers(keys, "cross_at", entityText);
    if (const MapEntry* blending = syntax::findEntry(keys, "blending"))
    {
      const std::string value = text(blending->value, blending->line, entityText, "blending");
      if (value != "spline" && value != "lagrange")
      {
        fail(blending->line, entityText, "unknown blending '" + value + "'");
      }
      carrier.blending =
        value == "lagrange" ? Carrier::Blending::Lagrange : Carrier::Blending::Spline;
    }
    if (const MapEntry* closed = syntax::findEntry(keys, "closed"))
    {
      carrier.closed = text(closed->value, closed->line, entityText, "closed") == "true";
    }
    if (const MapEntry* axis = syntax::findEntry(keys, "axis"))
    {
      carrier.axis = vector3(axis->value, axis->line, entityText, "axis");
    }
    if (const MapEntry* origin = syntax::findEntry(keys, "origin"))
    {
      carrier.axisPoint = vector3(origin->value, origin->line, entityText, "origin");
    }
    const std::vector<double> angle = numbers(keys, "angle", entityText);
    if (angle.size() == 2)
    {
      carrier.angleStart = angle[0];
      carrier.angleEnd = angle[1];
    }
    const std::vector<double> range = numbers(keys, "range", entityText);
    if (range.size() == 2)
    {
      carrier.rangeMin = range[0];
      carrier.rangeMax = range[1];
    }
    if (const MapEntry* samples = syntax::findEntry(keys, "samples"))
    {
      carrier.samples = integer(samples->value, samples->line, entityText, "samples");
    }
    if (const MapEntry* distance = syntax::findEntry(keys, "distance"))
    {
      carrier.distance = number(distance->value, distance->line, entityText, "distance");
    }
  }

  void resolvePeriodicSource(Vertex& vertex)
  {
    if (vertex.constraint.periodicSource != -2)
    {
      return;
    }
    const std::string& sourceName = PeriodicSources[NextPeriodic++];
    vertex.constraint.periodicSource = Model.findVertex(sourceName);
    if (vertex.constraint.periodicSource < 0)
    {
      fail(vertex.where.line, entity("vertex", vertex.name),
        "unknown periodic source vertex '" + sourceName + "'");
    }
  }

  const std::vector<std::string> CarrierKeys = { "kind", "points", "degree", "parameters",
    "refs", "cross_refs", "at", "cross_at", "blending", "closed", "axis", "origin", "angle",
    "range", "samples", "distance", "through" };
  /// Vertex names read before every vertex is known: whose (vertex or carrier index),
  /// the names, and where.
  struct FollowedName
  {
    std::size_t index;
    std::vector<std::string> names;
    int line;
    std::string entity;
  };
  std::vector<FollowedName> FollowedNames, ThroughNames;
  std::vector<std::string> PeriodicSources;
  std::size_t NextPeriodic = 0;
  std::vector<std::string> RuleSources;
  std::size_t NextRuleSource = 0;

  const std::string& Text;
  syntax::Reporter Report;
  BlockModel Model;
};
} // namespace

BlockModel readModelDocument(const std::string& document)
{
  return DocumentReader(document).read();
}
} // namespace model
} // namespace blockforge
