// The template reader: machine, inputs and the theta direction, parameters, definitions and the lazy resolution of named entities.
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
// --- sections -----------------------------------------------------------------------
void TemplateReader::readHeader()
{
  YAML::Node root;
  try
  {
    const std::vector<YAML::Node> documents = YAML::LoadAll(Text);
    if (documents.size() > 1)
    {
      fail(documents[1].Mark().line >= 0 ? documents[1].Mark().line + 1 : 0, "",
        "a second YAML document (after '---' or '...'): a template is one document");
    }
    root = documents.empty() ? YAML::Node() : documents.front();
  }
  catch (const YAML::Exception& error)
  {
    fail(error.mark.line >= 0 ? error.mark.line + 1 : 0, "",
      "YAML syntax error: " + error.msg +
        (error.mark.column >= 0 ? " (column " + std::to_string(error.mark.column + 1) + ")"
                                : std::string()));
  }
  if (!root.IsDefined() || root.IsNull())
  {
    fail(1, "", "the template is empty; it must start with 'blockforge: " +
        std::to_string(TemplateFormatVersion) + "'");
  }
  Sections = syntax::mapEntries(root, 1, "", "the template", Report);
  syntax::checkKeys(Sections,
    { "blockforge", "name", "description", "inputs", "machine", "parameters", "definitions",
      "carriers", "vertices", "edges", "blocks", "faces", "patches", "notes" },
    "", Report);
  const MapEntry* version = syntax::findEntry(Sections, "blockforge");
  if (!version)
  {
    fail(1, "", "missing 'blockforge: 1' (or 'blockforge: 2' for templates with inputs "
                "and carriers): the template format version, at the top of the template");
  }
  double versionNumber = 0.0;
  if (!version->value.IsScalar() ||
    !syntax::parseNumber(version->value.Scalar(), versionNumber) ||
    versionNumber != std::floor(versionNumber) || versionNumber < 1)
  {
    fail(version->line, "", "'blockforge' must be the template format version, a whole "
                            "number such as " + std::to_string(TemplateFormatVersion));
  }
  if (versionNumber > TemplateFormatVersion)
  {
    fail(version->line, "",
      "this template needs BlockForge template format " + version->value.Scalar() +
        " but this BlockForge reads format " + std::to_string(TemplateFormatVersion) +
        " and older; please update BlockForge");
  }
  Version = static_cast<int>(versionNumber);
  if (Version < 2)
  {
    for (const char* key : { "inputs", "machine", "definitions", "carriers", "faces", "notes" })
    {
      if (const MapEntry* entry = syntax::findEntry(Sections, key))
      {
        fail(entry->line, "",
          std::string("the '") + key + "' section needs template format 2: write "
          "'blockforge: 2' at the top");
      }
    }
  }
  if (const MapEntry* nameEntry = syntax::findEntry(Sections, "name"))
  {
    Name = name(nameEntry->value, nameEntry->line, "", "'name'");
  }
  if (const MapEntry* description = syntax::findEntry(Sections, "description"))
  {
    if (!description->value.IsScalar() && !description->value.IsNull())
    {
      fail(description->line, "", "'description' must be text");
    }
  }
}

void TemplateReader::readParameters()
{
  const MapEntry* parameters = section("parameters");
  std::vector<MapEntry> entries;
  if (parameters)
  {
    entries = syntax::mapEntries(
      parameters->value, parameters->line, "", "the parameters section", Report, "parameter");
  }
  // Unknown overrides are reported first: a typo in a GUI field should not look like a
  // problem of the template.
  for (const auto& override : Overrides)
  {
    if (!syntax::findEntry(entries, override.first))
    {
      std::vector<std::string> declared;
      for (const MapEntry& entry : entries)
      {
        declared.push_back(entry.key);
      }
      std::string what = "no such parameter in this template";
      const std::string suggestion = syntax::closestName(override.first, declared);
      if (!suggestion.empty())
      {
        what += " (did you mean '" + suggestion + "'?)";
      }
      fail(parameters ? parameters->line : 1, entity("parameter override", override.first),
        what + "; declared parameters: " + syntax::joinNames(declared));
    }
  }
  std::vector<std::string> lines;
  {
    std::istringstream stream(Text);
    for (std::string line; std::getline(stream, line);)
    {
      lines.push_back(line);
    }
  }
  for (const MapEntry& entry : entries)
  {
    const std::string entityText = entity("parameter", entry.key);
    if (!syntax::isIdentifier(entry.key))
    {
      fail(entry.line, entityText,
        "parameter names may contain letters, digits and '_' and must start with a "
        "letter or '_' (they are used in expressions)");
    }
    if (ExpressionEvaluator::isReserved(entry.key))
    {
      fail(entry.line, entityText,
        "'" + entry.key + "' is a built-in constant or function of expressions; choose "
                          "another name");
    }
    if (Version >= 2 && isMachineName(entry.key))
    {
      fail(entry.line, entityText,
        "'" + entry.key + "' is a machine value (blade_count, pitch, axis_x, axis_y, "
                          "axis_z come from the input or the 'machine' section); choose "
                          "another name");
    }
    ParameterInfo info;
    info.name = entry.key;
    if (entry.value.IsScalar())
    {
      info.expression = entry.value.Scalar();
    }
    double value = 0.0;
    const auto override = Overrides.find(entry.key);
    if (override != Overrides.end())
    {
      try
      {
        value = Evaluator.evaluate(override->second);
      }
      catch (const ExpressionError& error)
      {
        fail(entry.line, entityText, "override: " + error.message);
      }
    }
    else if (InfoOnly && Version >= 2)
    {
      // Listing parameters without the filter input: values that need the machine
      // (blade_count, pitch) are unknown here.
      try
      {
        value = number(entry.value, entry.line, entityText, "");
      }
      catch (const TemplateError&)
      {
        value = std::numeric_limits<double>::quiet_NaN();
        Evaluator.Unavailable[entry.key] = "it depends on machine values of the input";
        info.value = value;
        info.comment = entry.line >= 1 && entry.line <= static_cast<int>(lines.size())
          ? trailingComment(lines[entry.line - 1])
          : std::string();
        Infos.push_back(std::move(info));
        continue;
      }
    }
    else
    {
      value = number(entry.value, entry.line, entityText, "");
    }
    info.value = value;
    if (entry.line >= 1 && entry.line <= static_cast<int>(lines.size()))
    {
      info.comment = trailingComment(lines[entry.line - 1]);
    }
    Evaluator.define(entry.key, value);
    Model.parameters.emplace_back(entry.key, value);
    Infos.push_back(std::move(info));
  }
}

/// Format 2 `notes`: `name: {when: <expression>, say: "text with {expression}s"}`; the
/// text of every note whose `when` is not 0 goes to Model.notes, each {expression}
/// replaced by its value (how a template says which of its choices it made).
void TemplateReader::readNotes()
{
  const MapEntry* notes = section("notes");
  if (!notes || notes->value.IsNull())
  {
    return;
  }
  for (const MapEntry& entry :
    syntax::mapEntries(notes->value, notes->line, "", "the notes section", Report, "note"))
  {
    const std::string entityText = entity("note", entry.key);
    const auto keys =
      syntax::mapEntries(entry.value, entry.line, entityText, "a note", Report);
    syntax::checkKeys(keys, { "when", "say" }, entityText, Report);
    const MapEntry* when = syntax::findEntry(keys, "when");
    const MapEntry* say = syntax::findEntry(keys, "say");
    if (!say || !say->value.IsScalar())
    {
      fail(entry.line, entityText, "a note needs 'say: <text>' (and 'when: <expression>')");
    }
    if (when && number(when->value, when->line, entityText, "when") == 0.0)
    {
      continue;
    }
    const std::string text = say->value.Scalar();
    std::string said;
    for (std::size_t at = 0; at < text.size();)
    {
      const std::size_t open = text.find('{', at);
      if (open == std::string::npos)
      {
        said += text.substr(at);
        break;
      }
      const std::size_t close = text.find('}', open);
      if (close == std::string::npos)
      {
        fail(say->line, entityText, "'{' without '}' in the text");
      }
      said += text.substr(at, open - at);
      YAML::Node expression(text.substr(open + 1, close - open - 1));
      said += shortNumber(number(expression, say->line, entityText, "say"));
      at = close + 1;
    }
    Model.notes.push_back(said);
  }
}

// --- machine and inputs -------------------------------------------------------
bool TemplateReader::isMachineName(const std::string& text)
{
  return text == "blade_count" || text == "pitch" || text == "axis_x" || text == "axis_y" ||
    text == "axis_z";
}

/// Unit vector perpendicular to the machine axis from which theta is measured: the
/// x axis projected (the y axis when the machine axis is close to x).
/// The direction of theta = 0 about `axis`: x (y when the axis is x), made normal to it.
Vec3 TemplateReader::defaultReference(const Vec3& axis)
{
  const Vec3 guess = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (guess - guess.dot(axis) * axis).normalized();
}

/// theta = 0 about the machine axis: `machine: {theta_zero: ...}`, else the default.
Vec3 TemplateReader::referenceDirection() const
{
  return ThetaZero.allFinite() ? ThetaZero : defaultReference(Model.machine.axis);
}

void TemplateReader::cylindrical(const Vec3& p, double& axial, double& radius, double& theta) const
{
  cylindricalAbout(Model.machine, referenceDirection(), p, axial, radius, theta);
}

Vec3 TemplateReader::fromCylindrical(double axial, double radius, double theta) const
{
  return fromCylindricalAbout(Model.machine, referenceDirection(), axial, radius, theta);
}

void TemplateReader::recordExpressionScope()
{
  const bool follows =
    std::any_of(Model.vertices.begin(), Model.vertices.end(),
      [](const Vertex& v) { return v.rule.expressions.form != PlacementExpressions::Form::None; }) ||
    std::any_of(Model.edges.begin(), Model.edges.end(),
      [](const Edge& e) { return !e.atFollows.empty(); });
  if (!follows)
  {
    return;
  }
  ExpressionScope& scope = Model.expressionScope;
  scope.thetaZero = referenceDirection();
  std::set<std::string> skipped; // built in (pi, deg, ...), definitions
  for (const auto& builtIn : ExpressionEvaluator().constants())
  {
    skipped.insert(builtIn.first);
  }
  for (const auto& definition : DefinitionIndex)
  {
    skipped.insert(definition.first);
  }
  for (const auto& value : Evaluator.constants())
  {
    const std::size_t dot = value.first.find('.');
    if (skipped.count(value.first) ||
      (dot != std::string::npos && Model.findVertex(value.first.substr(0, dot)) >= 0))
    {
      continue; // definitions are evaluated again, vertex queries come from the positions
    }
    scope.values.emplace_back(value.first, value.second);
  }
  for (const MapEntry& entry : DefinitionEntries)
  {
    scope.definitions.emplace_back(entry.key, entry.value.Scalar());
  }
}

void TemplateReader::readMachineAndInputs()
{
  if (Version < 2)
  {
    return;
  }
  Machine& machine = Model.machine;
  machine.defined = true;
  double bladeCount = 0.0;
  std::vector<MapEntry> thetaZero; // a copy: the machine section's entries are local
  if (const MapEntry* section = this->section("machine"))
  {
    const std::string entityText = "machine";
    const auto keys =
      syntax::mapEntries(section->value, section->line, entityText, "the machine section", Report);
    syntax::checkKeys(keys, { "axis", "origin", "blade_count", "theta_zero" }, entityText, Report);
    if (const MapEntry* found = syntax::findEntry(keys, "theta_zero"))
    {
      thetaZero.push_back(*found);
    }
    if (const MapEntry* axis = syntax::findEntry(keys, "axis"))
    {
      machine.axis = unitAxis(*axis, entityText, "machine axis");
    }
    if (const MapEntry* origin = syntax::findEntry(keys, "origin"))
    {
      machine.axisPoint = vector3(origin->value, origin->line, entityText, "origin");
    }
    if (const MapEntry* count = syntax::findEntry(keys, "blade_count"))
    {
      bladeCount = number(count->value, count->line, entityText, "blade_count");
      if (bladeCount != std::floor(bladeCount) || bladeCount < 1 || bladeCount > MaxBladeCount)
      {
        fail(count->line, entityText, "blade_count must be a whole number from 1 to 100000");
      }
    }
  }
  if (Inputs && Inputs->hasMachine)
  {
    machine.axis = Inputs->axis.normalized();
    machine.axisPoint = Inputs->axisPoint;
  }
  if (Inputs && Inputs->bladeCount > 0)
  {
    bladeCount = Inputs->bladeCount;
    if (bladeCount > MaxBladeCount)
    {
      fail(0, "machine",
        Inputs->origin + " gives blade count " + std::to_string(Inputs->bladeCount) +
          "; the blade count must be a whole number from 1 to 100000");
    }
  }
  machine.bladeCount = static_cast<int>(bladeCount);
  Evaluator.define("axis_x", machine.axis.x());
  Evaluator.define("axis_y", machine.axis.y());
  Evaluator.define("axis_z", machine.axis.z());
  if (machine.bladeCount > 0)
  {
    Evaluator.define("blade_count", machine.bladeCount);
    Evaluator.define("pitch", machine.pitch());
  }
  else
  {
    const std::string why = "the blade count is unknown: " +
      (Inputs ? Inputs->origin + " gives none (set BladeCount on the reader)"
              : std::string("there is no filter input")) +
      " and the template has no 'machine: {blade_count: n}'";
    Evaluator.Unavailable["blade_count"] = why;
    Evaluator.Unavailable["pitch"] = why;
  }

  if (const MapEntry* inputs = section("inputs"))
  {
    bindInputs(*inputs);
  }
  if (!thetaZero.empty())
  {
    readThetaZero(thetaZero.front());
  }
}

void TemplateReader::bindInputs(const MapEntry& inputs)
{
  for (const MapEntry& entry :
    syntax::mapEntries(inputs.value, inputs.line, "", "the inputs section", Report, "input"))
  {
    const std::string entityText = entity("input", entry.key);
    if (!syntax::isEntityName(entry.key))
    {
      fail(entry.line, entityText,
        "names may contain letters, digits, '_' and '-' and must start with a letter or '_'");
    }
    const std::string setName = name(entry.value, entry.line, entityText, "point set");
    if (!Inputs)
    {
      if (InfoOnly)
      {
        continue;
      }
      fail(entry.line, entityText,
        "this template reads the point set '" + setName +
          "' from a filter input: apply it with the BlockTemplate filter to the output of "
          "a TurboPointSetsReader (BlockTemplateSource has no input); from Python, "
          "mesh_template(..., input_file=...) or python3 -m blockforge TEMPLATE -i FILE");
    }
    const InputPointSet* found = nullptr;
    std::vector<std::string> available;
    for (const InputPointSet& set : Inputs->pointSets)
    {
      available.push_back(set.name);
      if (set.name == setName)
      {
        found = &set;
      }
    }
    if (!found)
    {
      const std::string suggestion = syntax::closestName(setName, available);
      fail(lineOrFallback(entry.value, entry.line), entityText,
        Inputs->origin + " has no point set '" + setName + "'" +
          (suggestion.empty() ? std::string() : " (did you mean '" + suggestion + "'?)") +
          "; it has: " + syntax::joinNames(available));
    }
    bool empty = found->curves.empty();
    for (const InputCurve& curve : found->curves)
    {
      empty = empty || curve.points.empty();
    }
    if (empty)
    {
      fail(lineOrFallback(entry.value, entry.line), entityText,
        "the point set '" + setName + "' of " + Inputs->origin + " is empty");
    }
    BoundInputs[entry.key] = BoundInput{ found, entry.line };
  }
}

/// `theta_zero: [x, y, z]` (a direction) or `theta_zero: <input>` (the centroid of that
/// input's points): where theta = 0 lies about the machine axis. Templates that compute
/// in theta put their passage there, away from the seam theta = +-pi.
void TemplateReader::readThetaZero(const MapEntry& entry)
{
  const std::string entityText = "machine";
  const Machine& machine = Model.machine;
  Vec3 direction = Vec3::Zero();
  if (entry.value.IsSequence())
  {
    direction = vector3(entry.value, entry.line, entityText, "theta_zero");
  }
  else
  {
    const std::string setName = name(entry.value, entry.line, entityText, "theta_zero");
    const auto bound = BoundInputs.find(setName);
    if (bound == BoundInputs.end())
    {
      if (InfoOnly && !Inputs)
      {
        return;
      }
      fail(entry.line, entityText,
        "theta_zero: '" + setName + "' is neither a direction [x, y, z] nor an input of "
        "this template");
    }
    std::size_t count = 0;
    for (const InputCurve& curve : bound->second.set->curves)
    {
      for (const Vec3& point : curve.points)
      {
        direction += point - machine.axisPoint;
        ++count;
      }
    }
    direction /= static_cast<double>(std::max<std::size_t>(count, 1));
  }
  direction -= direction.dot(machine.axis) * machine.axis;
  if (!direction.allFinite() || direction.norm() <= 1e-12 * std::max(1.0, vertexSpan()))
  {
    fail(entry.line, entityText,
      "theta_zero: the direction is along the machine axis (or zero), so it gives no angle");
  }
  ThetaZero = direction.normalized();
}

std::vector<std::string> TemplateReader::inputNames() const
{
  std::vector<std::string> names;
  for (const auto& bound : BoundInputs)
  {
    names.push_back(bound.first);
  }
  return names;
}

std::vector<std::string> TemplateReader::carrierNames() const
{
  std::vector<std::string> names;
  for (std::size_t c = 0; c < CarrierEntries.size(); ++c)
  {
    names.push_back(Model.carriers[c].name);
  }
  return names;
}

// --- resolution order ---------------------------------------------------------
std::string TemplateReader::resolvingChain(const std::string& last) const
{
  std::string chain;
  for (const std::string& item : Resolving)
  {
    chain += item + " -> ";
  }
  return chain + last;
}

/// Format 2 `definitions`: named expressions that may use parameters, machine values,
/// vertex queries and other definitions, resolved when first used (in any order).
void TemplateReader::readDefinitionNames()
{
  const MapEntry* definitions = section("definitions");
  if (!definitions || definitions->value.IsNull())
  {
    return;
  }
  for (const MapEntry& entry : syntax::mapEntries(definitions->value, definitions->line, "",
         "the definitions section", Report, "definition"))
  {
    const std::string entityText = entity("definition", entry.key);
    if (!syntax::isIdentifier(entry.key))
    {
      fail(entry.line, entityText,
        "definition names may contain letters, digits and '_' and must start with a "
        "letter or '_' (they are used in expressions)");
    }
    if (ExpressionEvaluator::isReserved(entry.key) || isMachineName(entry.key))
    {
      fail(entry.line, entityText,
        "'" + entry.key + "' is a built-in constant, function or machine value; choose "
                          "another name");
    }
    const auto& parameters = Evaluator.names();
    if (std::find(parameters.begin(), parameters.end(), entry.key) != parameters.end())
    {
      fail(entry.line, entityText, "a parameter has this name already");
    }
    if (!entry.value.IsScalar())
    {
      fail(entry.line, entityText, "expected an expression (a number or a quoted formula)");
    }
    DefinitionIndex[entry.key] = static_cast<int>(DefinitionEntries.size());
    DefinitionEntries.push_back(entry);
  }
  DefinitionState.assign(DefinitionEntries.size(), 0);
  DefinitionVertices.assign(DefinitionEntries.size(), {});
}

void TemplateReader::ensureDefinition(int index)
{
  resolveOnce(DefinitionState, DefinitionEntries, index, "definition",
    [&](const MapEntry& entry, const std::string& entityText) {
      Referenced.emplace_back();
      const double value = number(entry.value, entry.line, entityText, "");
      DefinitionVertices[index] = std::move(Referenced.back());
      Referenced.pop_back();
      Evaluator.define(entry.key, value);
    });
}
} // namespace detail
} // namespace model
} // namespace blockforge
