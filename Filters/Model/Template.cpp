#include "Template.h"

#include "Mesher.h"
#include "ModelSyntax.h"

#include <muParser.h>

#include <Eigen/Geometry>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace blockforge
{
namespace model
{
namespace
{
std::string composeMessage(
  const std::string& file, int line, const std::string& entity, const std::string& message)
{
  std::string text = file.empty() ? std::string("<template>") : file;
  if (line > 0)
  {
    text += ":" + std::to_string(line);
  }
  text += ": ";
  if (!entity.empty())
  {
    text += entity + ": ";
  }
  return text + message;
}
} // namespace

TemplateError::TemplateError(const std::string& file, int line, const std::string& entity,
  const std::string& message)
  : std::runtime_error(composeMessage(file, line, entity, message))
  , File(file)
  , Entity(entity)
  , Line(line)
{
}

namespace
{
using syntax::entity;
using syntax::lineOf;
using syntax::MapEntry;

/// The newest template format this build reads.
constexpr int TemplateFormatVersion = 1;
constexpr double Pi = 3.14159265358979323846;
/// Cells per block direction; keeps node arrays well inside int range.
constexpr double MaxCellsPerDirection = 1.0e6;

/// Failure of one expression, in user terms; the caller adds file, line and entity.
struct ExpressionError
{
  std::string message;
};

/**
 * muParser with the template conventions: constants pi and deg (= pi/180), and a number
 * written immediately before `deg` means degrees (45deg -> (45*deg)).
 */
class ExpressionEvaluator
{
public:
  ExpressionEvaluator()
  {
    Parser.DefineConst("pi", Pi);
    Parser.DefineConst("deg", Pi / 180.0);
  }

  /// Names that parameters must not take: the constants and muParser's functions.
  static bool isReserved(const std::string& name)
  {
    static const std::set<std::string> reserved = { "pi", "deg", "sin", "cos", "tan", "asin",
      "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "log2",
      "log10", "log", "ln", "exp", "sqrt", "sign", "rint", "abs", "min", "max", "sum", "avg",
      "_pi", "_e" };
    return reserved.count(name) != 0;
  }

  void define(const std::string& name, double value)
  {
    Parser.DefineConst(name, value);
    Names.push_back(name);
  }

  const std::vector<std::string>& names() const { return Names; }

  double evaluate(const std::string& expression)
  {
    const std::string expanded = expandDegrees(expression);
    const std::string readAs = expanded != expression ? " (read as '" + expanded + "')" : "";
    if (!parenthesesBalance(expression))
    {
      throw ExpressionError{ "unbalanced parentheses in '" + expression +
        "'; inside [x, y, z] lists put an expression containing commas in quotes, "
        "e.g. \"min(a, b)\"" };
    }
    double value = 0.0;
    try
    {
      Parser.SetExpr(expanded);
      value = Parser.Eval();
      if (Parser.GetNumResults() != 1)
      {
        throw ExpressionError{ "'" + expression + "' gives " +
          std::to_string(Parser.GetNumResults()) +
          " comma-separated values where one number is expected" };
      }
    }
    catch (const mu::ParserError& error)
    {
      const std::string token = error.GetToken();
      if (error.GetCode() == mu::ecUNASSIGNABLE_TOKEN && syntax::isIdentifier(token))
      {
        std::string message = "unknown name '" + token + "' in '" + expression + "'";
        const std::string suggestion = syntax::closestName(token, Names);
        if (!suggestion.empty())
        {
          message += " (did you mean '" + suggestion + "'?)";
        }
        throw ExpressionError{ message + "; parameters available here: " +
          syntax::joinNames(Names) };
      }
      if (error.GetCode() == mu::ecUNEXPECTED_EOF && expression.find_first_not_of(" \t") ==
          std::string::npos)
      {
        throw ExpressionError{ "empty expression" };
      }
      const std::string hint = token == "deg"
        ? " (write degrees without a space: 45deg, or multiply: 45*deg)"
        : std::string();
      throw ExpressionError{ "cannot evaluate '" + expression + "'" + readAs + ": " +
        error.GetMsg() + hint };
    }
    if (!std::isfinite(value))
    {
      throw ExpressionError{ "'" + expression + "'" + readAs + " evaluates to " +
        (std::isnan(value) ? std::string("NaN") : std::string(value > 0 ? "inf" : "-inf")) };
    }
    return value;
  }

  /// `45deg` -> `(45*deg)`; identifiers that merely contain digits (x2deg) are untouched.
  static std::string expandDegrees(const std::string& text)
  {
    auto isDigit = [](char c) { return c >= '0' && c <= '9'; };
    auto isNameChar = [&](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || isDigit(c);
    };
    std::string out;
    std::size_t i = 0;
    const std::size_t n = text.size();
    while (i < n)
    {
      const char c = text[i];
      if (isNameChar(c) && !isDigit(c))
      {
        const std::size_t start = i;
        while (i < n && isNameChar(text[i]))
        {
          ++i;
        }
        out.append(text, start, i - start);
        continue;
      }
      if (isDigit(c) || (c == '.' && i + 1 < n && isDigit(text[i + 1])))
      {
        const std::size_t start = i;
        while (i < n && isDigit(text[i]))
        {
          ++i;
        }
        if (i < n && text[i] == '.')
        {
          ++i;
          while (i < n && isDigit(text[i]))
          {
            ++i;
          }
        }
        if (i < n && (text[i] == 'e' || text[i] == 'E'))
        {
          std::size_t j = i + 1;
          if (j < n && (text[j] == '+' || text[j] == '-'))
          {
            ++j;
          }
          if (j < n && isDigit(text[j]))
          {
            i = j;
            while (i < n && isDigit(text[i]))
            {
              ++i;
            }
          }
        }
        const std::string number = text.substr(start, i - start);
        if (text.compare(i, 3, "deg") == 0 && (i + 3 == n || !isNameChar(text[i + 3])))
        {
          out += "(" + number + "*deg)";
          i += 3;
        }
        else
        {
          out += number;
        }
        continue;
      }
      out += c;
      ++i;
    }
    return out;
  }

private:
  static bool parenthesesBalance(const std::string& text)
  {
    int depth = 0;
    for (char c : text)
    {
      depth += c == '(' ? 1 : c == ')' ? -1 : 0;
      if (depth < 0)
      {
        return false;
      }
    }
    return depth == 0;
  }

  mu::Parser Parser;
  std::vector<std::string> Names;
};

/// The trailing `# comment` of a line, ignoring '#' inside quotes or glued to a word.
std::string trailingComment(const std::string& line)
{
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i)
  {
    const char c = line[i];
    if (quote)
    {
      quote = c == quote ? 0 : quote;
    }
    else if (c == '"' || c == '\'')
    {
      quote = c;
    }
    else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t'))
    {
      const std::size_t first = line.find_first_not_of(" \t#", i);
      if (first == std::string::npos)
      {
        return "";
      }
      const std::size_t last = line.find_last_not_of(" \t\r");
      return line.substr(first, last - first + 1);
    }
  }
  return "";
}

std::string fileStem(const std::string& path)
{
  std::string base = path.substr(path.find_last_of("/\\") + 1);
  const std::size_t dot = base.rfind('.');
  return dot == std::string::npos || dot == 0 ? base : base.substr(0, dot);
}

/// Reads one template text into a BlockModel; every failure is a located TemplateError.
class TemplateReader
{
public:
  TemplateReader(const std::string& text, const std::string& file,
    const ParameterOverrides& overrides)
    : Text(text)
    , Overrides(overrides)
  {
    Report.file = file;
  }

  BlockModel readModel()
  {
    readHeader();
    readParameters();
    Model.name = Name.empty() ? fileStem(Report.file) : Name;
    Model.sourceFile = Report.file;
    readVertices();
    readEdges();
    readBlocks();
    readPatches();
    return std::move(Model);
  }

  std::vector<ParameterInfo> readParameterInfos()
  {
    readHeader();
    readParameters();
    return std::move(Infos);
  }

private:
  // --- locations and messages ---------------------------------------------------------
  [[noreturn]] void fail(int line, const std::string& entityText, const std::string& what) const
  {
    Report.fail(line, entityText, what);
  }

  SourceLocation where(int line) const { return SourceLocation{ Report.file, line }; }

  int lineOrFallback(const YAML::Node& node, int fallback) const
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
  double number(const YAML::Node& node, int line, const std::string& entityText,
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

  syntax::NumberReader numberReader(const std::string& entityText)
  {
    return [this, entityText](const YAML::Node& node, int line, const std::string& what) {
      return number(node, line, entityText, what);
    };
  }

  Vec3 vector3(const YAML::Node& node, int line, const std::string& entityText,
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

  std::string name(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what)
  {
    const int here = lineOrFallback(node, line);
    if (!node.IsScalar() || node.Scalar().empty())
    {
      fail(here, entityText, what + ": expected a name");
    }
    return node.Scalar();
  }

  std::vector<std::string> vertexNames() const
  {
    std::vector<std::string> names;
    for (const Vertex& vertex : Model.vertices)
    {
      names.push_back(vertex.name);
    }
    return names;
  }

  int vertexRef(const YAML::Node& node, int line, const std::string& entityText)
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
    return index;
  }

  void checkEntityName(const MapEntry& entry, const std::string& kind)
  {
    if (!syntax::isEntityName(entry.key))
    {
      fail(entry.line, entity(kind, entry.key),
        "names may contain letters, digits, '_' and '-' and must start with a letter or '_'");
    }
  }

  // --- sections -----------------------------------------------------------------------
  void readHeader()
  {
    YAML::Node root;
    try
    {
      root = YAML::Load(Text);
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
      { "blockforge", "name", "description", "parameters", "vertices", "edges", "blocks",
        "patches" },
      "", Report);
    const MapEntry* version = syntax::findEntry(Sections, "blockforge");
    if (!version)
    {
      fail(1, "", "missing 'blockforge: " + std::to_string(TemplateFormatVersion) +
          "' (the template format version) at the top of the template");
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

  const MapEntry* section(const std::string& key) const
  {
    return syntax::findEntry(Sections, key);
  }

  void readParameters()
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

  void readVertices()
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
        vertex.position = readVertexMapping(entry, entityText);
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
  Vec3 readVertexMapping(const MapEntry& entry, const std::string& entityText)
  {
    const auto keys =
      syntax::mapEntries(entry.value, entry.line, entityText, "the vertex", Report);
    syntax::checkKeys(keys, { "position", "rotate", "angle", "axis", "origin" }, entityText,
      Report);
    const MapEntry* position = syntax::findEntry(keys, "position");
    const MapEntry* rotate = syntax::findEntry(keys, "rotate");
    if ((position != nullptr) == (rotate != nullptr))
    {
      fail(entry.line, entityText, "give either 'position' or 'rotate'");
    }
    if (position)
    {
      if (keys.size() != 1)
      {
        fail(entry.line, entityText, "'angle', 'axis' and 'origin' belong to 'rotate'");
      }
      return vector3(position->value, position->line, entityText, "position");
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
      axis = vector3(axisEntry->value, axisEntry->line, entityText, "axis");
    }
    if (const MapEntry* originEntry = syntax::findEntry(keys, "origin"))
    {
      origin = vector3(originEntry->value, originEntry->line, entityText, "origin");
    }
    if (!(axis.norm() > 0.0))
    {
      fail(entry.line, entityText, "the rotation axis must not be zero");
    }
    const double radians = number(angle->value, angle->line, entityText, "angle");
    const Eigen::AngleAxisd rotation(radians, axis.normalized());
    return origin + rotation * (Model.vertices[source].position - origin);
  }

  void readEdges()
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
      const int other = Model.findEdge(edge.from, edge.to);
      if (other >= 0)
      {
        fail(entry.line, entityText,
          "joins the same vertices as edge '" + Model.edges[other].name + "' (line " +
            std::to_string(Model.edges[other].where.line) + ")");
      }
      Model.edges.push_back(edge);
    }
  }

  void readBlocks()
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
      syntax::checkKeys(keys, { "vertices", "cells", "grading" }, entityText, Report);
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
      if (!cells->value.IsSequence() || cells->value.size() != 3)
      {
        fail(lineOrFallback(cells->value, cells->line), entityText,
          "'cells' expects three counts [ni, nj, nk]");
      }
      static const char* const directionNames[3] = { "i", "j", "k" };
      for (int d = 0; d < 3; ++d)
      {
        const YAML::Node node = cells->value[d];
        const double value =
          number(node, cells->line, entityText, std::string("cells ") + directionNames[d]);
        const double whole = std::round(value);
        if (std::abs(value - whole) > 1e-9 * std::max(1.0, std::abs(value)) || whole < 1 ||
          whole > MaxCellsPerDirection)
        {
          fail(lineOrFallback(node, cells->line), entityText,
            std::string("cells must be whole numbers from 1 to 1000000, but ") +
              directionNames[d] + " = '" + node.Scalar() + "' = " +
              syntax::formatNumber(value));
        }
        block.cells[d] = static_cast<int>(whole);
      }

      if (const MapEntry* grading = syntax::findEntry(keys, "grading"))
      {
        readGrading(*grading, entityText, block);
      }
      Model.blocks.push_back(block);
    }
  }

  void readGrading(const MapEntry& grading, const std::string& entityText, Block& block)
  {
    const auto keys =
      syntax::mapEntries(grading.value, grading.line, entityText, "'grading'", Report);
    syntax::checkKeys(keys, { "i", "j", "k", "edges" }, entityText, Report);
    for (int d = 0; d < 3; ++d)
    {
      const std::string direction(1, static_cast<char>('i' + d));
      if (const MapEntry* law = syntax::findEntry(keys, direction))
      {
        const DistributionLaw value = syntax::parseLaw(law->value, law->line, entityText,
          "grading " + direction, numberReader(entityText), Report);
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
        block.laws[e] = syntax::parseLaw(law.value, law.line, entityText,
          "grading " + law.key, numberReader(entityText), Report);
      }
    }
  }

  void readPatches()
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
      syntax::checkKeys(
        keys, { "type", "faces", "partner", "axis", "origin", "angle" }, entityText, Report);
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
      for (const char* key : { "partner", "axis", "origin", "angle" })
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
        patch.periodicAxis = vector3(axis->value, axis->line, entityText, "axis");
        if (!(patch.periodicAxis.norm() > 0.0))
        {
          fail(axis->line, entityText, "the periodic axis must not be zero");
        }
        patch.periodicAxis.normalize();
      }
      if (const MapEntry* origin = syntax::findEntry(keys, "origin"))
      {
        patch.periodicAxisPoint = vector3(origin->value, origin->line, entityText, "origin");
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

  BlockFace faceRef(const YAML::Node& node, int line, const std::string& entityText)
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
  void resolvePeriodicPartners(const std::vector<int>& lines, const std::vector<bool>& hasRotation)
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
    }
  }

  const std::string& Text;
  const ParameterOverrides& Overrides;
  syntax::Reporter Report;
  ExpressionEvaluator Evaluator;
  std::vector<MapEntry> Sections;
  std::string Name;
  BlockModel Model;
  std::vector<ParameterInfo> Infos;
};

std::string readFile(const std::string& path)
{
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    const int error = errno;
    throw TemplateError(path, 0, "",
      "cannot open template file '" + path + "'" +
        (error ? std::string(": ") + std::strerror(error) : std::string()));
  }
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}
} // namespace

BlockModel parseTemplate(
  const std::string& text, const std::string& fileName, const ParameterOverrides& overrides)
{
  TemplateReader reader(text, fileName, overrides);
  BlockModel model = reader.readModel();
  // Topology and geometry problems are template errors too: report them now, with the
  // template's lines, rather than when the mesher runs.
  checkModel(model);
  return model;
}

BlockModel loadTemplate(const std::string& path, const ParameterOverrides& overrides)
{
  return parseTemplate(readFile(path), path, overrides);
}

std::vector<ParameterInfo> templateParameters(
  const std::string& path, const ParameterOverrides& overrides)
{
  const std::string text = readFile(path);
  TemplateReader reader(text, path, overrides);
  return reader.readParameterInfos();
}
} // namespace model
} // namespace blockforge
