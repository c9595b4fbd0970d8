// The template reader: the document and its sections (header, edges, blocks, gradings, patches, periodic partners, faces).
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
BlockModel TemplateReader::readModel()
{
  readHeader();
  readMachineAndInputs();
  readParameters();
  Model.name = Name.empty() ? fileStem(Report.file) : Name;
  Model.sourceFile = Report.file;
  if (Version >= 2)
  {
    readCarriersAndVertices();
  }
  else
  {
    readVertices();
  }
  readEdges();
  readBlocks();
  readFaces();
  readPatches();
  readNotes();
  recordExpressionScope();
  return std::move(Model);
}

std::vector<ParameterInfo> TemplateReader::readParameterInfos()
{
  InfoOnly = true;
  readHeader();
  readMachineAndInputs();
  readParameters();
  return std::move(Infos);
}

// --- locations and messages ---------------------------------------------------------
[[noreturn]] void TemplateReader::fail(int line, const std::string& entityText, const std::string& what) const
{
  Report.fail(line, entityText, what);
}

int TemplateReader::lineOrFallback(const YAML::Node& node, int fallback) const
{
  // yaml-cpp places null values on the next token; the key's line reads better.
  if (!node.IsDefined() || node.IsNull())
  {
    return fallback;
  }
  const int line = lineOf(node);
  return line ? line : fallback;
}

// --- values -----------------------------------------------------------------------
double TemplateReader::number(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what)
{
  const int here = lineOrFallback(node, line);
  if (!node.IsDefined() || node.IsNull())
  {
    fail(here, entityText, (what.empty() ? "" : what + ": ") + "value missing");
  }
  if (!node.IsScalar())
  {
    fail(here, entityText,
      (what.empty() ? "" : what + ": ") + "expected a number or an expression");
  }
  try
  {
    return Evaluator.evaluate(node.Scalar());
  }
  catch (const ExpressionError& error)
  {
    fail(here, entityText, what.empty() ? error.message : what + ": " + error.message);
  }
}

int TemplateReader::edgeRef(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what, const std::string& advice)
{
  const std::string edgeName = name(node, line, entityText, what);
  const int index = Model.findNamedEdge(edgeName);
  if (index < 0)
  {
    std::vector<std::string> names;
    for (const Edge& other : Model.edges)
    {
      names.push_back(other.name);
    }
    const std::string suggestion = syntax::closestName(edgeName, names);
    fail(line, entityText,
      what + ": unknown edge '" + edgeName + "'" +
        (suggestion.empty() ? std::string() : " (did you mean '" + suggestion + "'?)") +
        "; " + advice);
  }
  return index;
}

syntax::NumberReader TemplateReader::numberReader(const std::string& entityText)
{
  return [this, entityText](const YAML::Node& node, int line, const std::string& what) {
    return number(node, line, entityText, what);
  };
}

Vec3 TemplateReader::vector3(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what)
{
  const int here = lineOrFallback(node, line);
  if (!node.IsSequence() || node.size() != 3)
  {
    fail(here, entityText,
      what + ": expected three coordinates [x, y, z]" +
        (node.IsSequence() ? ", got " + std::to_string(node.size()) +
              " (quote expressions that contain commas)"
                           : std::string()));
  }
  Vec3 value;
  static const char* const axisNames[3] = { "x", "y", "z" };
  for (int c = 0; c < 3; ++c)
  {
    value[c] = number(node[c], here, entityText, what + " " + axisNames[c]);
  }
  return value;
}

std::string TemplateReader::name(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what)
{
  const int here = lineOrFallback(node, line);
  if (!node.IsScalar() || node.Scalar().empty())
  {
    fail(here, entityText, what + ": expected a name");
  }
  return node.Scalar();
}

std::vector<std::string> TemplateReader::vertexNames() const
{
  std::vector<std::string> names;
  for (const Vertex& vertex : Model.vertices)
  {
    names.push_back(vertex.name);
  }
  return names;
}

int TemplateReader::vertexRef(const YAML::Node& node, int line, const std::string& entityText)
{
  const std::string vertexName = name(node, line, entityText, "vertex reference");
  const int index = Model.findVertex(vertexName);
  if (index < 0)
  {
    std::string what = "unknown vertex '" + vertexName + "'";
    const std::string suggestion = syntax::closestName(vertexName, vertexNames());
    if (!suggestion.empty())
    {
      what += " (did you mean '" + suggestion + "'?)";
    }
    fail(lineOrFallback(node, line), entityText, what);
  }
  if (Version >= 2)
  {
    ensureVertex(index);
  }
  return index;
}

void TemplateReader::checkEntityName(const MapEntry& entry, const std::string& kind)
{
  if (!syntax::isEntityName(entry.key))
  {
    fail(entry.line, entity(kind, entry.key),
      "names may contain letters, digits, '_' and '-' and must start with a letter or '_'");
  }
}

const MapEntry* TemplateReader::section(const std::string& key) const
{
  return syntax::findEntry(Sections, key);
}

void TemplateReader::readEdges()
{
  const MapEntry* edges = section("edges");
  if (!edges)
  {
    return;
  }
  for (const MapEntry& entry :
    syntax::mapEntries(edges->value, edges->line, "", "the edges section", Report, "edge"))
  {
    checkEntityName(entry, "edge");
    const std::string entityText = entity("edge", entry.key);
    if (isEdgeV2(entry))
    {
      readEdgeV2(entry, entityText);
      continue;
    }
    if (!entry.value.IsMap())
    {
      fail(entry.line, entityText,
        "expected {line: [a, b]}, {arc: [a, b], centre: [x, y, z]}, "
        "{arc: [a, b], through: [x, y, z]} or {spline: [a, b], points: [[x, y, z], ...]}");
    }
    const auto keys =
      syntax::mapEntries(entry.value, entry.line, entityText, "the edge", Report);
    syntax::checkKeys(
      keys, { "line", "arc", "spline", "centre", "through", "points" }, entityText, Report);
    const MapEntry* line = syntax::findEntry(keys, "line");
    const MapEntry* arc = syntax::findEntry(keys, "arc");
    const MapEntry* spline = syntax::findEntry(keys, "spline");
    if ((line != nullptr) + (arc != nullptr) + (spline != nullptr) != 1)
    {
      fail(entry.line, entityText, "give exactly one of 'line', 'arc' or 'spline'");
    }
    const MapEntry& ends = line ? *line : arc ? *arc : *spline;
    Edge edge;
    edge.name = entry.key;
    edge.where = where(entry.line);
    if (!ends.value.IsSequence() || ends.value.size() != 2)
    {
      fail(ends.line, entityText, "'" + ends.key + "' expects its two end vertices [a, b]");
    }
    edge.from = vertexRef(ends.value[0], ends.line, entityText);
    edge.to = vertexRef(ends.value[1], ends.line, entityText);
    if (edge.from == edge.to)
    {
      fail(ends.line, entityText, "an edge needs two different end vertices");
    }
    const MapEntry* centre = syntax::findEntry(keys, "centre");
    const MapEntry* through = syntax::findEntry(keys, "through");
    const MapEntry* points = syntax::findEntry(keys, "points");
    if (line)
    {
      edge.kind = Edge::Kind::Line;
      if (centre || through || points)
      {
        fail(entry.line, entityText, "a straight line takes no centre, through or points");
      }
    }
    else if (arc)
    {
      edge.kind = Edge::Kind::Arc;
      if ((centre != nullptr) == (through != nullptr) || points)
      {
        fail(entry.line, entityText,
          "an arc needs exactly one of 'centre: [x, y, z]' or 'through: [x, y, z]'");
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
    else
    {
      edge.kind = Edge::Kind::Spline;
      if (centre || through)
      {
        fail(entry.line, entityText, "a spline takes 'points', not centre or through");
      }
      if (!points || !points->value.IsSequence())
      {
        fail(points ? points->line : entry.line, entityText,
          "a spline needs 'points: [[x, y, z], ...]', its interior points from the first "
          "vertex to the second");
      }
      for (std::size_t p = 0; p < points->value.size(); ++p)
      {
        edge.splinePoints.push_back(vector3(points->value[p], points->line, entityText,
          "point " + std::to_string(p + 1)));
      }
    }
    addEdge(edge, entry.line, entityText);
  }
}

/// A rotation axis given as [x, y, z]: must not be zero; returned as a unit vector.
/// `what` names it in the message ("the machine axis must not be zero").
Vec3 TemplateReader::unitAxis(const MapEntry& axis, const std::string& entityText, const std::string& what)
{
  const Vec3 direction = vector3(axis.value, axis.line, entityText, "axis");
  if (!(direction.norm() > 0.0))
  {
    fail(axis.line, entityText, "the " + what + " must not be zero");
  }
  return direction.normalized();
}

/// Adds an edge unless another one already joins the same two vertices.
void TemplateReader::addEdge(const Edge& edge, int line, const std::string& entityText)
{
  const int other = Model.findEdge(edge.from, edge.to);
  if (other >= 0)
  {
    fail(line, entityText,
      "joins the same vertices as edge '" + Model.edges[other].name + "' (line " +
        std::to_string(Model.edges[other].where.line) + ")");
  }
  Model.edges.push_back(edge);
}

void TemplateReader::readBlocks()
{
  const MapEntry* blocks = section("blocks");
  if (!blocks || blocks->value.IsNull())
  {
    fail(blocks ? blocks->line : 1, "", "the template has no 'blocks' section");
  }
  for (const MapEntry& entry :
    syntax::mapEntries(blocks->value, blocks->line, "", "the blocks section", Report, "block"))
  {
    checkEntityName(entry, "block");
    const std::string entityText = entity("block", entry.key);
    if (!entry.value.IsMap())
    {
      fail(entry.line, entityText,
        "expected {vertices: [8 names], cells: [ni, nj, nk], grading: {...}}");
    }
    const auto keys =
      syntax::mapEntries(entry.value, entry.line, entityText, "the block", Report);
    syntax::checkKeys(keys, { "vertices", "cells", "min_cells", "grading", "interpolation" }, entityText, Report);
    Block block;
    block.name = entry.key;
    block.where = where(entry.line);

    const MapEntry* vertices = syntax::findEntry(keys, "vertices");
    if (!vertices)
    {
      fail(entry.line, entityText, "missing 'vertices' (8 names in Fig. 7 order)");
    }
    if (!vertices->value.IsSequence() || vertices->value.size() != 8)
    {
      fail(lineOrFallback(vertices->value, vertices->line), entityText,
        "needs 8 vertices in Fig. 7 order (VTK hexahedron order), got " +
          (vertices->value.IsSequence() ? std::to_string(vertices->value.size())
                                        : std::string("no list")));
    }
    for (int v = 0; v < 8; ++v)
    {
      block.vertices[v] = vertexRef(vertices->value[v], vertices->line, entityText);
    }

    const MapEntry* cells = syntax::findEntry(keys, "cells");
    if (!cells)
    {
      fail(entry.line, entityText, "missing 'cells: [ni, nj, nk]'");
    }
    // `cells` and `min_cells` alike: three whole counts from 1 to MaxCellsPerDirection
    static const char* const directionNames[3] = { "i", "j", "k" };
    const auto readCounts = [&](const MapEntry& counts, const std::string& key, std::array<int, 3>& out) {
      if (!counts.value.IsSequence() || counts.value.size() != 3)
      {
        fail(lineOrFallback(counts.value, counts.line), entityText,
          "'" + key + "' expects three counts [ni, nj, nk]");
      }
      for (int d = 0; d < 3; ++d)
      {
        const YAML::Node node = counts.value[d];
        const double value =
          number(node, counts.line, entityText, key + " " + directionNames[d]);
        const double whole = std::round(value);
        if (std::abs(value - whole) > 1e-9 * std::max(1.0, std::abs(value)) || whole < 1 ||
          whole > MaxCellsPerDirection)
        {
          fail(lineOrFallback(node, counts.line), entityText,
            key + " must be whole numbers from 1 to 1000000, but " + directionNames[d] + " = '" +
              node.Scalar() + "' = " + syntax::formatNumber(value));
        }
        out[d] = static_cast<int>(whole);
      }
    };
    readCounts(*cells, "cells", block.cells);
    // the fewest cells a density multiplier below 1 leaves (optional; a count above
    // `cells` means `cells`, so a parameter lowering `cells` needs no matching edit)
    if (const MapEntry* least = syntax::findEntry(keys, "min_cells"))
    {
      readCounts(*least, "min_cells", block.minCells);
    }

    if (const MapEntry* grading = syntax::findEntry(keys, "grading"))
    {
      readGrading(*grading, entityText, block);
    }
    if (const MapEntry* interpolation = syntax::findEntry(keys, "interpolation"))
    {
      block.blending = syntax::parseBlending(interpolation->value, interpolation->line, entityText, Report);
    }
    Model.blocks.push_back(block);
  }
}

syntax::EdgeReader TemplateReader::edgeReader(const std::string& entityText)
{
  return [this, entityText](const YAML::Node& node, int line, const std::string& what) {
    return edgeRef(node, line, entityText, what, "name an edge of the edges section");
  };
}

void TemplateReader::readGrading(const MapEntry& grading, const std::string& entityText, Block& block)
{
  const auto keys =
    syntax::mapEntries(grading.value, grading.line, entityText, "'grading'", Report);
  syntax::checkKeys(keys, { "i", "j", "k", "edges" }, entityText, Report);
  // a law, refused when its values refer to a vertex a move can shift
  const auto readLaw = [&](const MapEntry& law, const std::string& what) {
    Referenced.emplace_back();
    const DistributionLaw value = syntax::parseLaw(law.value, law.line, entityText, what,
      numberReader(entityText), Report, edgeReader(entityText));
    refuseMovableReferences(law.line, entityText, what);
    return value;
  };
  for (int d = 0; d < 3; ++d)
  {
    const std::string direction(1, static_cast<char>('i' + d));
    if (const MapEntry* law = syntax::findEntry(keys, direction))
    {
      const DistributionLaw value = readLaw(*law, "grading " + direction);
      for (int e = 0; e < 12; ++e)
      {
        if (edgeDirection(e) == d)
        {
          block.laws[e] = value;
        }
      }
    }
  }
  if (const MapEntry* edges = syntax::findEntry(keys, "edges"))
  {
    std::vector<std::string> labels;
    for (int e = 0; e < 12; ++e)
    {
      labels.push_back(syntax::edgeLabel(e));
    }
    const auto overrides =
      syntax::mapEntries(edges->value, edges->line, entityText, "'grading: edges'", Report);
    syntax::checkKeys(overrides, labels, entityText, Report);
    for (const MapEntry& law : overrides)
    {
      const int e = std::stoi(law.key.substr(1)) - 1;
      block.laws[e] = readLaw(law, "grading " + law.key);
    }
  }
}

void TemplateReader::refuseMovableReferences(
  int line, const std::string& entityText, const std::string& what)
{
  const std::set<int> referenced = std::move(Referenced.back());
  Referenced.pop_back();
  if (referenced.empty())
  {
    return;
  }
  if (Movable.size() != Model.vertices.size())
  {
    Movable = movableVertices(Model);
  }
  for (const int v : referenced)
  {
    if (Movable[v])
    {
      // A law's values are numbers once read: moved, the vertex would leave the live
      // model's grid other than the template's with the vertex given there.
      fail(line, entityText,
        "'" + what + "' refers to vertex '" + Model.vertices[v].name +
          "', which the optimizer or a manual move can move, and a grading does not follow "
          "moves: refer to vertices marked 'fixed: true' (and placed from such alone)");
    }
  }
}

void TemplateReader::readPatches()
{
  const MapEntry* patches = section("patches");
  if (!patches)
  {
    return;
  }
  std::vector<int> patchLines;
  std::vector<bool> hasRotation;
  for (const MapEntry& entry :
    syntax::mapEntries(patches->value, patches->line, "", "the patches section", Report, "patch"))
  {
    checkEntityName(entry, "patch");
    const std::string entityText = entity("patch", entry.key);
    if (!entry.value.IsMap())
    {
      fail(entry.line, entityText, "expected {type: wall, faces: [block.face, ...]}");
    }
    const auto keys =
      syntax::mapEntries(entry.value, entry.line, entityText, "the patch", Report);
    syntax::checkKeys(keys, { "type", "faces", "partner", "axis", "origin", "angle", "pitches" },
      entityText, Report);
    Patch patch;
    patch.name = entry.key;
    patch.where = where(entry.line);
    if (const MapEntry* type = syntax::findEntry(keys, "type"))
    {
      static const std::vector<std::string> types = { "patch", "wall", "symmetry", "inlet",
        "outlet", "empty", "periodic" };
      patch.type = name(type->value, type->line, entityText, "'type'");
      if (std::find(types.begin(), types.end(), patch.type) == types.end())
      {
        fail(type->line, entityText,
          "unknown patch type '" + patch.type + "'; expected one of: " +
            syntax::joinNames(types));
      }
    }
    const MapEntry* faces = syntax::findEntry(keys, "faces");
    if (!faces || !faces->value.IsSequence() || faces->value.size() == 0)
    {
      fail(faces ? faces->line : entry.line, entityText,
        "needs 'faces: [block.face, ...]' with at least one face (faces i0 i1 j0 j1 k0 k1)");
    }
    for (std::size_t f = 0; f < faces->value.size(); ++f)
    {
      patch.faces.push_back(faceRef(faces->value[f], faces->line, entityText));
    }
    const bool periodic = patch.type == "periodic";
    bool rotation = false;
    for (const char* key : { "partner", "axis", "origin", "angle", "pitches" })
    {
      const MapEntry* found = syntax::findEntry(keys, key);
      if (found && !periodic)
      {
        fail(found->line, entityText,
          std::string("'") + key + "' is only used by patches of type periodic");
      }
    }
    if (const MapEntry* partner = syntax::findEntry(keys, "partner"))
    {
      patch.periodicPartner = name(partner->value, partner->line, entityText, "'partner'");
    }
    if (const MapEntry* axis = syntax::findEntry(keys, "axis"))
    {
      patch.periodicAxis = unitAxis(*axis, entityText, "periodic axis");
    }
    if (const MapEntry* origin = syntax::findEntry(keys, "origin"))
    {
      patch.periodicAxisPoint = vector3(origin->value, origin->line, entityText, "origin");
    }
    if (const MapEntry* pitches = syntax::findEntry(keys, "pitches"))
    {
      if (Version < 2)
      {
        fail(pitches->line, entityText, "'pitches' needs template format 2");
      }
      if (syntax::findEntry(keys, "angle") || syntax::findEntry(keys, "axis") ||
        syntax::findEntry(keys, "origin"))
      {
        fail(pitches->line, entityText,
          "give either 'pitches' (about the machine axis) or 'angle' with 'axis' and 'origin'");
      }
      const double value = number(pitches->value, pitches->line, entityText, "pitches");
      if (value != std::floor(value) || value == 0.0 || std::abs(value) > 100000)
      {
        fail(pitches->line, entityText, "pitches must be a whole number other than 0");
      }
      if (Model.machine.bladeCount <= 0)
      {
        fail(pitches->line, entityText,
          "periodic pitches need the blade count: " + Evaluator.Unavailable["pitch"]);
      }
      patch.pitches = static_cast<int>(value);
      patch.periodicAngle = patch.pitches * Model.machine.pitch();
      patch.periodicAxis = Model.machine.axis;
      patch.periodicAxisPoint = Model.machine.axisPoint;
      rotation = true;
    }
    if (const MapEntry* angle = syntax::findEntry(keys, "angle"))
    {
      patch.periodicAngle = number(angle->value, angle->line, entityText, "angle");
      rotation = true;
    }
    else if (syntax::findEntry(keys, "axis") || syntax::findEntry(keys, "origin"))
    {
      fail(entry.line, entityText, "'axis' and 'origin' need an 'angle'");
    }
    Model.patches.push_back(patch);
    patchLines.push_back(entry.line);
    hasRotation.push_back(rotation);
  }
  resolvePeriodicPartners(patchLines, hasRotation);
}

BlockFace TemplateReader::faceRef(const YAML::Node& node, int line, const std::string& entityText)
{
  const int here = lineOrFallback(node, line);
  const std::string text = name(node, line, entityText, "face");
  const std::size_t dot = text.rfind('.');
  if (dot == std::string::npos)
  {
    fail(here, entityText,
      "face '" + text + "' must be written block.face, e.g. north.j0 (faces i0 i1 j0 j1 k0 k1)");
  }
  const std::string blockName = text.substr(0, dot);
  BlockFace face;
  face.block = Model.findBlock(blockName);
  face.face = faceFromName(text.substr(dot + 1));
  if (face.block < 0)
  {
    std::vector<std::string> names;
    for (const Block& block : Model.blocks)
    {
      names.push_back(block.name);
    }
    const std::string suggestion = syntax::closestName(blockName, names);
    fail(here, entityText,
      "unknown block '" + blockName + "' in face '" + text + "'" +
        (suggestion.empty() ? std::string() : " (did you mean '" + suggestion + "'?)"));
  }
  if (face.face < 0)
  {
    fail(here, entityText,
      "unknown face '" + text.substr(dot + 1) + "' in '" + text +
        "'; faces are i0 i1 j0 j1 k0 k1");
  }
  return face;
}

/// Completes each periodic pair: the partner named on one side is set on the other, and
/// the rotation given on one side is inverted for the other.
void TemplateReader::resolvePeriodicPartners(const std::vector<int>& lines, const std::vector<bool>& hasRotation)
{
  std::vector<std::string> patchNames;
  for (const Patch& patch : Model.patches)
  {
    patchNames.push_back(patch.name);
  }
  const int count = static_cast<int>(Model.patches.size());
  auto findPatch = [&](const std::string& patchName) {
    for (int p = 0; p < count; ++p)
    {
      if (Model.patches[p].name == patchName)
      {
        return p;
      }
    }
    return -1;
  };
  for (int p = 0; p < count; ++p)
  {
    const Patch& patch = Model.patches[p];
    if (patch.type != "periodic" || patch.periodicPartner.empty())
    {
      continue;
    }
    const std::string entityText = entity("patch", patch.name);
    const int partner = findPatch(patch.periodicPartner);
    if (partner < 0)
    {
      const std::string suggestion = syntax::closestName(patch.periodicPartner, patchNames);
      fail(lines[p], entityText,
        "periodic partner '" + patch.periodicPartner + "' is not a patch of this template" +
          (suggestion.empty() ? std::string() : " (did you mean '" + suggestion + "'?)") +
          "; patches: " + syntax::joinNames(patchNames));
    }
    if (partner == p)
    {
      fail(lines[p], entityText, "a periodic patch cannot be its own partner");
    }
    Patch& other = Model.patches[partner];
    if (other.type != "periodic")
    {
      fail(lines[p], entityText,
        "periodic partner '" + other.name + "' must have type periodic, not " + other.type);
    }
    if (!other.periodicPartner.empty() && other.periodicPartner != patch.name)
    {
      fail(lines[partner], entity("patch", other.name),
        "names partner '" + other.periodicPartner + "' but patch '" + patch.name +
          "' names it as its partner");
    }
    other.periodicPartner = patch.name;
  }
  for (int p = 0; p < count; ++p)
  {
    Patch& patch = Model.patches[p];
    if (patch.type != "periodic")
    {
      continue;
    }
    const std::string entityText = entity("patch", patch.name);
    if (patch.periodicPartner.empty())
    {
      fail(lines[p], entityText,
        "a periodic patch needs 'partner: <patch>' (here or on its partner)");
    }
    const int partner = findPatch(patch.periodicPartner);
    if (hasRotation[p])
    {
      continue;
    }
    if (!hasRotation[partner])
    {
      fail(lines[p], entityText,
        "periodic pair '" + patch.name + "' / '" + patch.periodicPartner +
          "' needs 'angle' (and 'axis', 'origin' unless z through the origin) on one of "
          "the two patches");
    }
    const Patch& other = Model.patches[partner];
    patch.periodicAxis = other.periodicAxis;
    patch.periodicAxisPoint = other.periodicAxisPoint;
    patch.periodicAngle = -other.periodicAngle;
    patch.pitches = -other.pitches;
  }
}

// --- edges and faces (format 2) --------------------------------------------------
bool TemplateReader::isEdgeV2(const MapEntry& entry) const
{
  if (Version < 2 || !entry.value.IsMap())
  {
    return false;
  }
  for (const std::string& key : carrierEdgeKindNames())
  {
    if (entry.value[key])
    {
      return true;
    }
  }
  return false;
}

void TemplateReader::readEdgeV2(const MapEntry& entry, const std::string& entityText)
{
  const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "the edge", Report);
  std::vector<std::string> allowed = carrierEdgeKindNames();
  allowed.insert(allowed.end(), { "between", "at", "pitches" });
  syntax::checkKeys(keys, allowed, entityText, Report);
  const MapEntry* kind = syntax::findKind(keys, carrierEdgeKindNames(), entityText, Report);
  Edge edge;
  edge.name = entry.key;
  edge.where = where(entry.line);
  const MapEntry* between = syntax::findEntry(keys, "between");
  if (!between || !between->value.IsSequence() || between->value.size() != 2)
  {
    fail(between ? between->line : entry.line, entityText,
      "'" + kind->key + "' edges need 'between: [a, b]', their two end vertices");
  }
  edge.from = vertexRef(between->value[0], between->line, entityText);
  edge.to = vertexRef(between->value[1], between->line, entityText);
  if (edge.from == edge.to)
  {
    fail(between->line, entityText, "an edge needs two different end vertices");
  }
  const MapEntry* at = syntax::findEntry(keys, "at");
  const MapEntry* pitches = syntax::findEntry(keys, "pitches");
  Edge::Kind edgeKind = Edge::Kind::Line;
  edgeKindFromName(kind->key, edgeKind); // one of carrierEdgeKindNames(), found above
  if (pitches && edgeKind != Edge::Kind::Periodic)
  {
    fail(pitches->line, entityText, "'pitches' belongs to periodic edges");
  }
  if (edgeKind == Edge::Kind::Periodic || edgeKind == Edge::Kind::Follow)
  {
    if (at)
    {
      fail(at->line, entityText,
        "a " + kind->key + " edge takes its shape from its source edge, not from 'at'");
    }
    edge.kind = edgeKind;
    edge.source = edgeRef(
      kind->value, kind->line, entityText, kind->key, "the source edge must be defined above this one");
  }
  if (edgeKind == Edge::Kind::Periodic)
  {
    edge.pitches = 1;
    if (pitches)
    {
      const double value = number(pitches->value, pitches->line, entityText, "pitches");
      if (value != std::floor(value) || value == 0.0 || std::abs(value) > 100000)
      {
        fail(pitches->line, entityText, "pitches must be a whole number other than 0");
      }
      edge.pitches = static_cast<int>(value);
    }
    if (Model.machine.bladeCount <= 0)
    {
      fail(kind->line, entityText,
        "a periodic edge needs the blade count: " + Evaluator.Unavailable["pitch"]);
    }
  }
  else if (edgeKind != Edge::Kind::Follow) // a follow edge is its source's shape at its own ends
  {
    const Want want = edgeKind == Edge::Kind::OnCurve ? Want::Curve : Want::Surface;
    edge.carrier = carrierRef(kind->value, kind->line, entityText, kind->key, want);
    edge.kind = edgeKind;
    if (at)
    {
      if (edge.kind == Edge::Kind::Project)
      {
        fail(at->line, entityText, "a projected edge takes no 'at'");
      }
      if (!at->value.IsSequence() || at->value.size() != 2)
      {
        fail(at->line, entityText,
          edge.kind == Edge::Kind::OnCurve ? "'at' expects [u_a, u_b]"
                                           : "'at' expects [[s_a, t_a], [s_b, t_b]]");
      }
      Referenced.emplace_back(); // the vertices the ends follow
      std::vector<std::string> texts;
      for (int end = 0; end < 2; ++end)
      {
        const YAML::Node item = at->value[end];
        if (edge.kind == Edge::Kind::OnCurve)
        {
          edge.at.push_back(number(item, at->line, entityText, "at"));
          texts.push_back(item.Scalar());
        }
        else
        {
          if (!item.IsSequence() || item.size() != 2)
          {
            fail(at->line, entityText, "'at' expects [[s_a, t_a], [s_b, t_b]]");
          }
          edge.at.push_back(number(item[0], at->line, entityText, "at s"));
          edge.at.push_back(number(item[1], at->line, entityText, "at t"));
          texts.push_back(item[0].Scalar());
          texts.push_back(item[1].Scalar());
        }
      }
      if (!Referenced.back().empty())
      {
        edge.atExpressions = texts;
        edge.atFollows.assign(Referenced.back().begin(), Referenced.back().end());
      }
      Referenced.pop_back();
    }
  }
  addEdge(edge, entry.line, entityText);
}

/// Faces whose grids lie on surfaces: {on_surface: S, faces: [block.face | [4 vertices]]};
/// or that follow the face opposite them in their block: {follow: opposite, faces: [...]}.
void TemplateReader::readFaces()
{
  const MapEntry* faces = section("faces");
  if (!faces)
  {
    return;
  }
  for (const MapEntry& entry :
    syntax::mapEntries(faces->value, faces->line, "", "the faces section", Report, "face set"))
  {
    checkEntityName(entry, "face set");
    const std::string entityText = entity("face set", entry.key);
    if (!entry.value.IsMap())
    {
      fail(entry.line, entityText, "expected {on_surface: S, faces: [block.face, ...]}");
    }
    const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "the face set", Report);
    syntax::checkKeys(keys, { "on_surface", "follow", "faces" }, entityText, Report);
    const MapEntry* surface = syntax::findEntry(keys, "on_surface");
    const MapEntry* follow = syntax::findEntry(keys, "follow");
    const MapEntry* list = syntax::findEntry(keys, "faces");
    if (!surface && !follow)
    {
      fail(entry.line, entityText,
        "needs 'on_surface: <surface carrier>' or 'follow: opposite' (periodic faces come "
        "from periodic patches)");
    }
    if (surface && follow)
    {
      fail(follow->line, entityText, "has both 'on_surface' and 'follow': give one");
    }
    if (follow && !(follow->value.IsScalar() && follow->value.Scalar() == "opposite"))
    {
      fail(follow->line, entityText,
        "'follow' must be 'opposite' (each face follows the face opposite it in its block)");
    }
    if (!list || !list->value.IsSequence() || list->value.size() == 0)
    {
      fail(list ? list->line : entry.line, entityText,
        "needs 'faces: [...]': block.face names or lists of 4 corner vertices");
    }
    SurfaceFaces set;
    set.name = entry.key;
    set.where = where(entry.line);
    if (surface)
    {
      set.carrier = carrierRef(surface->value, surface->line, entityText, "on_surface", Want::Surface);
    }
    set.followOpposite = follow != nullptr;
    for (std::size_t f = 0; f < list->value.size(); ++f)
    {
      const YAML::Node item = list->value[f];
      if (item.IsSequence() && follow)
      {
        fail(list->line, entityText, "a following face must be given as block.face (its block says which face is opposite)");
      }
      if (item.IsSequence())
      {
        set.faces.push_back(faceByVertices(item, list->line, entityText));
      }
      else
      {
        set.faces.push_back(faceRef(item, list->line, entityText));
      }
    }
    Model.surfaceFaces.push_back(set);
  }
}

BlockFace TemplateReader::faceByVertices(const YAML::Node& node, int line, const std::string& entityText)
{
  const int here = lineOrFallback(node, line);
  if (node.size() != 4)
  {
    fail(here, entityText, "a face by its corners needs 4 vertices");
  }
  std::array<int, 4> wanted{};
  for (int c = 0; c < 4; ++c)
  {
    wanted[c] = vertexRef(node[c], here, entityText);
  }
  std::sort(wanted.begin(), wanted.end());
  for (std::size_t b = 0; b < Model.blocks.size(); ++b)
  {
    for (int f = 0; f < 6; ++f)
    {
      std::array<int, 4> ids{};
      const std::array<int, 4> corners = faceCorners(f);
      for (int c = 0; c < 4; ++c)
      {
        ids[c] = Model.blocks[b].vertices[corners[c]];
      }
      std::sort(ids.begin(), ids.end());
      if (ids == wanted)
      {
        return BlockFace{ static_cast<int>(b), f };
      }
    }
  }
  std::string names;
  for (int c = 0; c < 4; ++c)
  {
    names += (c ? ", " : "") + node[c].Scalar();
  }
  fail(here, entityText, "no block has a face with the corners [" + names + "]");
}
} // namespace detail
} // namespace model
} // namespace blockforge
