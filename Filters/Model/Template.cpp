#include "Template.h"

#include "CarrierGeometry.h"
#include "Mesher.h"
#include "ModelSyntax.h"
#include "Placement.h"

#include <muParser.h>

#include <Eigen/Geometry>

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

#include <sys/stat.h>

namespace blockforge
{
namespace model
{
namespace
{
using syntax::entity;
using syntax::lineOf;
using syntax::MapEntry;

/// The newest template format this build reads.
constexpr int TemplateFormatVersion = 2;
constexpr double Pi = 3.14159265358979323846;
/// Cells per block direction; keeps node arrays well inside int range.
constexpr double MaxCellsPerDirection = 1.0e6;
constexpr double MaxBladeCount = 1.0e5;

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
    // '.' joins a vertex name and an attribute: le_hub.radius (format 2 queries).
    Parser.DefineNameChars(
      "0123456789_abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.");
    Parser.DefineConst("pi", Pi);
    Parser.DefineConst("deg", Pi / 180.0);
  }

  /// Called with every `name.attribute` token (and every plain name, attribute "") of an
  /// expression before it is evaluated (resolves vertices and definitions further down).
  std::function<void(const std::string& name, const std::string& attribute)> OnReference;
  /// Names that are not available, with the reason (shown instead of "unknown name").
  std::map<std::string, std::string> Unavailable;

  /// Defines a query value such as `le_hub.radius` (not listed among the parameters).
  void defineQuery(const std::string& name, double value)
  {
    Parser.DefineConst(name, value);
    Queries.insert(name);
  }
  bool hasQuery(const std::string& name) const { return Queries.count(name) != 0; }

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
    const std::string expanded = prepare(expression);
    const std::string readAs = expanded != expression ? " (read as '" + expanded + "')" : "";
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
      const auto unavailable = Unavailable.find(token);
      if (error.GetCode() == mu::ecUNASSIGNABLE_TOKEN && unavailable != Unavailable.end())
      {
        throw ExpressionError{ "'" + token + "' in '" + expression + "' is not available: " +
          unavailable->second };
      }
      const std::size_t dot = token.find('.');
      if (error.GetCode() == mu::ecUNASSIGNABLE_TOKEN && dot != std::string::npos &&
        syntax::isIdentifier(token.substr(0, dot)))
      {
        throw ExpressionError{ "unknown name '" + token + "' in '" + expression +
          "'; vertex queries are written vertex.attribute with the attributes x, y, z, "
          "axial, radius, theta (about the machine axis) and s, t (parameters of a vertex "
          "on a carrier), for vertices defined in this template (format 2)" };
      }
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

  /**
   * A function of a point: `expression` may use everything a template expression may and
   * the variables x, y, z, axial, radius, theta of the point (set through `variables`,
   * six doubles in that order, before each call). Referenced vertices and definitions are
   * resolved first.
   */
  std::function<double()> pointFunction(const std::string& expression, double* variables)
  {
    const std::string expanded = prepare(expression);
    auto parser = std::make_shared<mu::Parser>(Parser);
    static const char* const names[6] = { "x", "y", "z", "axial", "radius", "theta" };
    try
    {
      for (int k = 0; k < 6; ++k)
      {
        if (std::find(Names.begin(), Names.end(), names[k]) != Names.end())
        {
          throw ExpressionError{ std::string("'") + names[k] +
            "' is a parameter or definition of this template, so it cannot be the point "
            "variable of '" + expression + "'; rename it" };
        }
        parser->DefineVar(names[k], variables + k);
      }
      parser->SetExpr(expanded);
      parser->Eval(); // reports unknown names and syntax errors here, once
      if (parser->GetNumResults() != 1)
      {
        throw ExpressionError{ "'" + expression + "' gives " +
          std::to_string(parser->GetNumResults()) +
          " comma-separated values where one number is expected" };
      }
    }
    catch (const mu::ParserError& error)
    {
      if (error.GetCode() == mu::ecUNASSIGNABLE_TOKEN)
      {
        std::vector<std::string> known(Names);
        known.insert(known.end(), std::begin(names), std::end(names));
        std::string message = "unknown name '" + error.GetToken() + "' in '" + expression + "'";
        const std::string suggestion = syntax::closestName(error.GetToken(), known);
        if (!suggestion.empty())
        {
          message += " (did you mean '" + suggestion + "'?)";
        }
        throw ExpressionError{ message +
          "; a function of the point may use x, y, z, axial, radius, theta and the "
          "parameters and definitions: " + syntax::joinNames(Names) };
      }
      throw ExpressionError{ "cannot evaluate '" + expression + "' (a function of the point "
                                                               "x, y, z, axial, radius, theta): " +
        error.GetMsg() };
    }
    return [parser]() { return parser->Eval(); };
  }

  /// The expression with degrees expanded, after checking its parentheses and resolving
  /// the vertices and definitions it refers to (OnReference).
  std::string prepare(const std::string& expression)
  {
    if (!parenthesesBalance(expression))
    {
      throw ExpressionError{ "unbalanced parentheses in '" + expression +
        "'; inside [x, y, z] lists put an expression containing commas in quotes, "
        "e.g. \"min(a, b)\"" };
    }
    const std::string expanded = expandDegrees(expression);
    if (OnReference)
    {
      for (const auto& reference : referencedNames(expanded))
      {
        OnReference(reference.first, reference.second);
      }
    }
    return expanded;
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

  /// The `name.attribute` tokens of an expression (names start with a letter or '_').
  /// The names an expression refers to: (vertex, attribute) for `vertex.attribute`, (name, "")
  /// for plain names (parameters, definitions, constants); functions are left out.
  static std::vector<std::pair<std::string, std::string>> referencedNames(const std::string& text)
  {
    std::vector<std::pair<std::string, std::string>> names;
    auto isStart = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
    auto isChar = [&](char c) { return isStart(c) || (c >= '0' && c <= '9'); };
    std::size_t i = 0;
    const std::size_t n = text.size();
    while (i < n)
    {
      if (isStart(text[i]) && (i == 0 || !(isChar(text[i - 1]) || text[i - 1] == '.')))
      {
        std::size_t j = i;
        while (j < n && isChar(text[j]))
        {
          ++j;
        }
        if (j < n && text[j] == '.')
        {
          std::size_t k = j + 1;
          while (k < n && isChar(text[k]))
          {
            ++k;
          }
          names.emplace_back(text.substr(i, j - i), text.substr(j + 1, k - j - 1));
          i = k;
          continue;
        }
        std::size_t next = j;
        while (next < n && (text[next] == ' ' || text[next] == '\t'))
        {
          ++next;
        }
        if (next >= n || text[next] != '(') // a function call is not a name
        {
          names.emplace_back(text.substr(i, j - i), std::string());
        }
        i = j;
        continue;
      }
      ++i;
    }
    return names;
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
  std::set<std::string> Queries;
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

using syntax::shortNumber;

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
    const ParameterOverrides& overrides, const TemplateInputs* inputs)
    : Text(text)
    , Overrides(overrides)
    , Inputs(inputs)
  {
    Report.file = file;
  }

  BlockModel readModel()
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
    return std::move(Model);
  }

  /// The carriers built while reading (valid after readModel()).
  const CarrierGeometry& geometry() const { return Geometry; }

  std::vector<ParameterInfo> readParameterInfos()
  {
    InfoOnly = true;
    readHeader();
    readMachineAndInputs();
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
    if (Version >= 2)
    {
      ensureVertex(index);
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
        readVertexMapping(entry, entityText, vertex);
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
  void readVertexMapping(const MapEntry& entry, const std::string& entityText, Vertex& vertex)
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
  Vec3 unitAxis(const MapEntry& axis, const std::string& entityText, const std::string& what)
  {
    const Vec3 direction = vector3(axis.value, axis.line, entityText, "axis");
    if (!(direction.norm() > 0.0))
    {
      fail(axis.line, entityText, "the " + what + " must not be zero");
    }
    return direction.normalized();
  }

  /// Adds an edge unless another one already joins the same two vertices.
  void addEdge(const Edge& edge, int line, const std::string& entityText)
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

  /// Format 2 `notes`: `name: {when: <expression>, say: "text with {expression}s"}`; the
  /// text of every note whose `when` is not 0 goes to Model.notes, each {expression}
  /// replaced by its value (how a template says which of its choices it made).
  void readNotes()
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
      patch.pitches = -other.pitches;
    }
  }

  // ===================================================================== format 2
  struct BoundInput
  {
    const InputPointSet* set = nullptr;
    int line = 0;
  };
  // --- machine and inputs -------------------------------------------------------
  static bool isMachineName(const std::string& text)
  {
    return text == "blade_count" || text == "pitch" || text == "axis_x" || text == "axis_y" ||
      text == "axis_z";
  }

  /// Unit vector perpendicular to the machine axis from which theta is measured: the
  /// x axis projected (the y axis when the machine axis is close to x).
  /// The direction of theta = 0 about `axis`: x (y when the axis is x), made normal to it.
  static Vec3 defaultReference(const Vec3& axis)
  {
    const Vec3 guess = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return (guess - guess.dot(axis) * axis).normalized();
  }

  /// theta = 0 about the machine axis: `machine: {theta_zero: ...}`, else the default.
  Vec3 referenceDirection() const
  {
    return ThetaZero.allFinite() ? ThetaZero : defaultReference(Model.machine.axis);
  }

  void cylindrical(const Vec3& p, double& axial, double& radius, double& theta) const
  {
    const Vec3& axis = Model.machine.axis;
    const Vec3 q = p - Model.machine.axisPoint;
    axial = q.dot(axis);
    const Vec3 radial = q - axial * axis;
    radius = radial.norm();
    const Vec3 e1 = referenceDirection();
    const Vec3 e2 = axis.cross(e1);
    theta = std::atan2(radial.dot(e2), radial.dot(e1));
  }

  Vec3 fromCylindrical(double axial, double radius, double theta) const
  {
    const Vec3& axis = Model.machine.axis;
    const Vec3 e1 = referenceDirection();
    const Vec3 e2 = axis.cross(e1);
    return Model.machine.axisPoint + axial * axis +
      radius * (std::cos(theta) * e1 + std::sin(theta) * e2);
  }

  void readMachineAndInputs()
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

  void bindInputs(const MapEntry& inputs)
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
  void readThetaZero(const MapEntry& entry)
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

  std::vector<std::string> inputNames() const
  {
    std::vector<std::string> names;
    for (const auto& bound : BoundInputs)
    {
      names.push_back(bound.first);
    }
    return names;
  }

  std::vector<std::string> carrierNames() const
  {
    std::vector<std::string> names;
    for (std::size_t c = 0; c < CarrierEntries.size(); ++c)
    {
      names.push_back(Model.carriers[c].name);
    }
    return names;
  }

  // --- resolution order ---------------------------------------------------------
  std::string resolvingChain(const std::string& last) const
  {
    std::string chain;
    for (const std::string& item : Resolving)
    {
      chain += item + " -> ";
    }
    return chain + last;
  }

  void readCarriersAndVertices()
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
        }
        return;
      }
      const int index = Model.findVertex(referenced);
      if (index >= 0)
      {
        ensureVertex(index);
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

  /// Format 2 `definitions`: named expressions that may use parameters, machine values,
  /// vertex queries and other definitions, resolved when first used (in any order).
  void readDefinitionNames()
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
  }

  /**
   * Resolves entity `entries[index]` of kind `kind` once (format 2 names resolve in any
   * order): `resolve(entry, entityText)` runs with the entity marked in progress, so a
   * reference back to it is reported as a cycle with the chain of entities being resolved.
   */
  template <typename Resolve>
  void resolveOnce(std::vector<int>& state, const std::vector<MapEntry>& entries, int index,
    const char* kind, Resolve&& resolve)
  {
    if (index < 0 || index >= static_cast<int>(state.size()) || state[index] == 2)
    {
      return; // done, or (carriers) hidden ones, complete when created
    }
    const MapEntry& entry = entries[index];
    const std::string entityText = entity(kind, entry.key);
    const std::string item = std::string(kind) + " '" + entry.key + "'";
    if (state[index] == 1)
    {
      fail(entry.line, entityText, "is defined in terms of itself: " + resolvingChain(item));
    }
    state[index] = 1;
    Resolving.push_back(item);
    resolve(entry, entityText);
    Resolving.pop_back();
    state[index] = 2;
  }

  void ensureDefinition(int index)
  {
    resolveOnce(DefinitionState, DefinitionEntries, index, "definition",
      [&](const MapEntry& entry, const std::string& entityText) {
        Evaluator.define(entry.key, number(entry.value, entry.line, entityText, ""));
      });
  }

  void ensureVertex(int index)
  {
    resolveOnce(VertexState, VertexEntries, index, "vertex",
      [&](const MapEntry& entry, const std::string& entityText) {
        Vertex vertex = Model.vertices[index];
        readVertexV2(entry, entityText, vertex);
        if (!vertex.position.allFinite())
        {
          fail(entry.line, entityText, "the position is not finite");
        }
        Model.vertices[index] = vertex;
        defineVertexQueries(vertex);
      });
  }

  void defineVertexQueries(const Vertex& vertex)
  {
    if (!syntax::isIdentifier(vertex.name))
    {
      return; // names with '-' cannot appear in expressions
    }
    double axial = 0.0, radius = 0.0, theta = 0.0;
    cylindrical(vertex.position, axial, radius, theta);
    const std::string& n = vertex.name;
    Evaluator.defineQuery(n + ".x", vertex.position.x());
    Evaluator.defineQuery(n + ".y", vertex.position.y());
    Evaluator.defineQuery(n + ".z", vertex.position.z());
    Evaluator.defineQuery(n + ".axial", axial);
    Evaluator.defineQuery(n + ".radius", radius);
    Evaluator.defineQuery(n + ".theta", theta);
    if (vertex.constraint.carrier >= 0)
    {
      Evaluator.defineQuery(n + ".s", vertex.constraint.s);
      Evaluator.defineQuery(n + ".t", vertex.constraint.t);
    }
    else
    {
      const std::string why = "vertex '" + n + "' is not attached to a carrier, so it has no "
                                               "parameters s, t";
      Evaluator.Unavailable[n + ".s"] = why;
      Evaluator.Unavailable[n + ".t"] = why;
    }
  }

  /// `revolve: ..., extend: f`: the contour continues straight along its end tangents by
  /// f times its length at both ends (short exports: inlet and outlet further out).
  void extendContour(std::vector<Vec3>& points, double fraction, int line,
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
  void defineContourQueries(const Carrier& carrier, const std::vector<Vec3>& points)
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

  void ensureCarrier(int index)
  {
    resolveOnce(CarrierState, CarrierEntries, index, "carrier",
      [&](const MapEntry& entry, const std::string& entityText) {
        Carrier carrier = Model.carriers[index];
        readCarrier(entry, entityText, index, carrier);
        Model.carriers[index] = carrier;
        Geometry.build(Model, index);
      });
  }

  /// A carrier named in the template (declared or hidden), resolved; -1 if there is none.
  int findCarrierIndex(const std::string& carrierName)
  {
    const int index = Model.findCarrier(carrierName);
    if (index >= 0)
    {
      ensureCarrier(index);
    }
    return index;
  }

  enum class Want
  {
    Curve,
    Surface,
    Any
  };

  int carrierRef(const YAML::Node& node, int line, const std::string& entityText,
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
  int addHiddenCarrier(Carrier carrier)
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
  std::vector<Vec3> pointList(const YAML::Node& node, int line, const std::string& entityText,
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
  static std::vector<Vec3> withoutDuplicates(const std::vector<Vec3>& points)
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

  const BoundInput& inputRef(const std::string& inputName, int line, const std::string& entityText,
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
  void readInterpolationOptions(const std::vector<MapEntry>& keys, const std::string& entityText,
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

  bool flag(const std::vector<MapEntry>& keys, const std::string& key, bool fallback,
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
  Vec3 meridional(const Vec3& p, const Vec3& axisPoint, const Vec3& axis) const
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
  std::vector<double> sectionParameters(const MapEntry* at, std::size_t count,
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

  void readCarrier(const MapEntry& entry, const std::string& entityText, int index, Carrier& carrier)
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
  void alignSection(Carrier& section)
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

  void checkClosedSection(const std::vector<Vec3>& points, const std::string& entityText,
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

  /// Tolerance for "lies on": 1e-9 of the larger of the vertices' and the carrier's size.
  double onTolerance(int carrier) const
  {
    return 1e-9 * std::max(vertexSpan(), Geometry.size(carrier));
  }

  double vertexSpan() const
  {
    return placedVertexSpan(Model);
  }

  void checkOnCarrier(int vertex, int carrier, double distance, int line, const std::string& entityText)
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
  Vec3 pointValue(const YAML::Node& node, int line, const std::string& entityText,
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

  Vec3 cylindricalValue(const MapEntry& entry, const std::string& entityText)
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
  void pointVariables(const Vec3& p, double* values) const
  {
    values[0] = p.x();
    values[1] = p.y();
    values[2] = p.z();
    cylindrical(p, values[3], values[4], values[5]);
  }

  /// Parameter u of curve `carrier` in [from, to] (which may pass the seam of a closed
  /// curve) where `value` is smallest (sign = 1) or largest (-1): a sample of 512 points,
  /// then golden-section search in the bracketing interval.
  double extremum(int carrier, const std::function<double(const Vec3&)>& value, double sign,
    double from, double to)
  {
    return extremum([&](double u) { return Geometry.point(carrier, u); },
      Geometry.closedS(carrier), value, sign, from, to);
  }

  /// The same on any curve point(u) (u wraps when `closed`).
  static double extremum(const std::function<Vec3(double)>& point, bool closed,
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
    const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
    double c = b - ratio * (b - a), d = a + ratio * (b - a);
    double fc = f(c), fd = f(d);
    // bounded: far from 0 the bracket stops shrinking at the spacing of doubles
    for (int iteration = 0; b - a > 1e-14 && iteration < 200; ++iteration)
    {
      if (fc < fd)
      {
        b = d;
        d = c;
        fd = fc;
        c = b - ratio * (b - a);
        fc = f(c);
      }
      else
      {
        a = c;
        c = d;
        fc = fd;
        d = a + ratio * (b - a);
        fd = f(d);
      }
    }
    double u = 0.5 * (a + b);
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
  double curveSurfaceIntersection(int curve, int surface, const MapEntry* near,
    const std::string& entityText, int line)
  {
    const int samples = 512;
    const SurfaceOfRevolution* revolution = Geometry.revolution(surface);
    std::vector<double> roots;
    auto refine = [&](auto&& f, double a, double b) {
      double fa = f(a), fb = f(b);
      for (int iteration = 0; iteration < 200 && b - a > 1e-15; ++iteration)
      {
        // Illinois-style regula falsi with bisection safeguard.
        double m = fb != fa ? b - fb * (b - a) / (fb - fa) : 0.5 * (a + b);
        if (!(m > a && m < b) || iteration % 3 == 2)
        {
          m = 0.5 * (a + b);
        }
        const double fm = f(m);
        if (fm == 0.0)
        {
          return m;
        }
        if ((fm < 0.0) == (fa < 0.0))
        {
          a = m;
          fa = fm;
        }
        else
        {
          b = m;
          fb = fm;
        }
      }
      return std::abs(fa) < std::abs(fb) ? a : b;
    };
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
          roots.push_back(refine(f, static_cast<double>(k - 1) / samples, u));
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
      double a = std::max(0.0, (best - 1.0) / samples), b = std::min(1.0, (best + 1.0) / samples);
      const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
      for (int iteration = 0; b - a > 1e-15 && iteration < 200; ++iteration)
      {
        const double c = b - ratio * (b - a), d = a + ratio * (b - a);
        if (f(c) < f(d))
        {
          b = d;
        }
        else
        {
          a = c;
        }
      }
      const double u = 0.5 * (a + b);
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
  void onRevolutionAt(int surface, double axial, double theta, const std::string& entityText,
    int line, double& s, double& t)
  {
    const SurfaceOfRevolution* revolution = Geometry.revolution(surface);
    const Machine& machine = Model.machine;
    const double size = std::max(Geometry.size(surface), 1e-300);
    if (!revolution || revolution->axisDirection().cross(machine.axis).norm() > 1e-12 ||
      (revolution->axisPoint() - machine.axisPoint).cross(machine.axis).norm() > 1e-12 * size)
    {
      fail(line, entityText,
        "'axial' and 'theta' place a vertex on a surface of revolution about the machine "
        "axis; '" + Model.carriers[surface].name + "' is not one");
    }
    auto f = [&](double u) {
      double a = 0.0, r = 0.0, th = 0.0;
      cylindrical(Geometry.point(surface, u, 0.5), a, r, th);
      return a - axial;
    };
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
        double low = a, high = b, flow = fa;
        for (int iteration = 0; iteration < 200 && high - low > 1e-16; ++iteration)
        {
          const double middle = 0.5 * (low + high), fm = f(middle);
          if ((fm < 0.0) == (flow < 0.0))
          {
            low = middle;
            flow = fm;
          }
          else
          {
            high = middle;
          }
        }
        root = 0.5 * (low + high);
        found = true;
      }
      a = b;
      fa = fb;
    }
    if (!found)
    {
      double a0 = 0.0, a1 = 0.0, r = 0.0, th = 0.0;
      cylindrical(Geometry.point(surface, 0.0, 0.5), a0, r, th);
      cylindrical(Geometry.point(surface, 1.0, 0.5), a1, r, th);
      fail(line, entityText,
        "surface '" + Model.carriers[surface].name + "' does not reach axial = " +
          shortNumber(axial) + " (its contour spans axial " + shortNumber(std::min(a0, a1)) +
          " to " + shortNumber(std::max(a0, a1)) + ")");
    }
    double ignored = 0.0, radius = 0.0;
    cylindrical(Geometry.point(surface, root, 0.5), ignored, radius, ignored);
    double distance = 0.0;
    const Vec3 target = fromCylindrical(axial, radius, theta);
    Geometry.project(surface, target, s, t, distance);
    if ((Geometry.point(surface, s, t) - target).norm() > 1e-9 * size)
    {
      fail(line, entityText,
        "theta = " + shortNumber(theta) + " is outside the angle range of surface '" +
          Model.carriers[surface].name + "'");
    }
  }

  /// `at: {length: f}`, `at: {min: q}` or `at: {max: q}` (q: x, y, z, axial, radius, theta
  /// or an expression of them), optionally `within: [u0, u1]`: a parameter of `curve`.
  double curveParameterQuery(const MapEntry& at, int curve, const std::string& entityText)
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
      return ArcLengthTable(Geometry.curve(curve)).parameterAtFraction(fraction);
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

  void readVertexV2(const MapEntry& entry, const std::string& entityText, Vertex& vertex)
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
      syntax::checkKeys(keys, { "cylindrical" }, entityText, Report);
      vertex.position = cylindricalValue(*kind, entityText);
      return;
    }
    VertexConstraint& constraint = vertex.constraint;
    if (kind->key == "on_curve")
    {
      syntax::checkKeys(keys, { "on_curve", "at" }, entityText, Report);
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
        u = number(at->value, at->line, entityText, "at");
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
      placeVertex(Model, Geometry, vertex);
      return;
    }
    if (kind->key == "on_surface" && syntax::findEntry(keys, "axial"))
    {
      syntax::checkKeys(keys, { "on_surface", "axial", "theta" }, entityText, Report);
      const int surface =
        carrierRef(kind->value, kind->line, entityText, "on_surface", Want::Surface);
      const MapEntry* axialEntry = syntax::findEntry(keys, "axial");
      const MapEntry* thetaEntry = syntax::findEntry(keys, "theta");
      if (!thetaEntry)
      {
        fail(entry.line, entityText, "on_surface with 'axial' needs 'theta' too");
      }
      const double axial = number(axialEntry->value, axialEntry->line, entityText, "axial");
      const double theta = number(thetaEntry->value, thetaEntry->line, entityText, "theta");
      double s = 0.0, t = 0.0;
      onRevolutionAt(surface, axial, theta, entityText, axialEntry->line, s, t);
      constraint.carrier = surface;
      constraint.s = s;
      constraint.t = t;
      vertex.rule.kind = VertexRule::Kind::OnCarrier;
      placeVertex(Model, Geometry, vertex);
      return;
    }
    if (kind->key == "on_surface")
    {
      syntax::checkKeys(keys, { "on_surface", "at" }, entityText, Report);
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
      syntax::checkKeys(keys, { "project", "onto" }, entityText, Report);
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
      syntax::checkKeys(keys, { "intersect", "near" }, entityText, Report);
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
    syntax::checkKeys(keys, { "periodic", "pitches" }, entityText, Report);
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
  // --- edges and faces (format 2) --------------------------------------------------
  bool isEdgeV2(const MapEntry& entry) const
  {
    if (Version < 2 || !entry.value.IsMap())
    {
      return false;
    }
    for (const char* key : { "on_curve", "on_surface", "project", "periodic", "follow" })
    {
      if (entry.value[key])
      {
        return true;
      }
    }
    return false;
  }

  void readEdgeV2(const MapEntry& entry, const std::string& entityText)
  {
    const auto keys = syntax::mapEntries(entry.value, entry.line, entityText, "the edge", Report);
    syntax::checkKeys(keys,
      { "on_curve", "on_surface", "project", "periodic", "follow", "between", "at", "pitches" },
      entityText, Report);
    const MapEntry* kind = syntax::findKind(
      keys, { "on_curve", "on_surface", "project", "periodic", "follow" }, entityText, Report);
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
    if (pitches && kind->key != "periodic")
    {
      fail(pitches->line, entityText, "'pitches' belongs to periodic edges");
    }
    if (kind->key == "periodic" || kind->key == "follow")
    {
      if (at)
      {
        fail(at->line, entityText,
          "a " + kind->key + " edge takes its shape from its source edge, not from 'at'");
      }
      edge.kind = kind->key == "periodic" ? Edge::Kind::Periodic : Edge::Kind::Follow;
      const std::string sourceName = name(kind->value, kind->line, entityText, kind->key);
      for (std::size_t e = 0; e < Model.edges.size(); ++e)
      {
        if (Model.edges[e].name == sourceName)
        {
          edge.source = static_cast<int>(e);
        }
      }
      if (edge.source < 0)
      {
        std::vector<std::string> names;
        for (const Edge& other : Model.edges)
        {
          names.push_back(other.name);
        }
        const std::string suggestion = syntax::closestName(sourceName, names);
        fail(kind->line, entityText,
          kind->key + ": unknown edge '" + sourceName + "'" +
            (suggestion.empty() ? std::string() : " (did you mean '" + suggestion + "'?)") +
            "; the source edge must be defined above this one");
      }
    }
    if (kind->key == "periodic")
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
    else if (kind->key != "follow") // a follow edge is its source's shape at its own ends
    {
      const Want want = kind->key == "on_curve" ? Want::Curve : Want::Surface;
      edge.carrier = carrierRef(kind->value, kind->line, entityText, kind->key, want);
      edge.kind = kind->key == "on_curve" ? Edge::Kind::OnCurve
        : kind->key == "on_surface"       ? Edge::Kind::OnSurface
                                          : Edge::Kind::Project;
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
        for (int end = 0; end < 2; ++end)
        {
          const YAML::Node item = at->value[end];
          if (edge.kind == Edge::Kind::OnCurve)
          {
            edge.at.push_back(number(item, at->line, entityText, "at"));
          }
          else
          {
            if (!item.IsSequence() || item.size() != 2)
            {
              fail(at->line, entityText, "'at' expects [[s_a, t_a], [s_b, t_b]]");
            }
            edge.at.push_back(number(item[0], at->line, entityText, "at s"));
            edge.at.push_back(number(item[1], at->line, entityText, "at t"));
          }
        }
      }
    }
    addEdge(edge, entry.line, entityText);
  }

  /// Faces whose grids lie on surfaces: {on_surface: S, faces: [block.face | [4 vertices]]}.
  void readFaces()
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
      syntax::checkKeys(keys, { "on_surface", "faces" }, entityText, Report);
      const MapEntry* surface = syntax::findEntry(keys, "on_surface");
      const MapEntry* list = syntax::findEntry(keys, "faces");
      if (!surface)
      {
        fail(entry.line, entityText,
          "needs 'on_surface: <surface carrier>' (periodic faces come from periodic patches)");
      }
      if (!list || !list->value.IsSequence() || list->value.size() == 0)
      {
        fail(list ? list->line : entry.line, entityText,
          "needs 'faces: [...]': block.face names or lists of 4 corner vertices");
      }
      SurfaceFaces set;
      set.name = entry.key;
      set.where = where(entry.line);
      set.carrier = carrierRef(surface->value, surface->line, entityText, "on_surface", Want::Surface);
      for (std::size_t f = 0; f < list->value.size(); ++f)
      {
        const YAML::Node item = list->value[f];
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

  BlockFace faceByVertices(const YAML::Node& node, int line, const std::string& entityText)
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

  const std::string& Text;
  const ParameterOverrides& Overrides;
  const TemplateInputs* Inputs = nullptr;
  bool InfoOnly = false;
  int Version = 1;
  std::map<std::string, BoundInput> BoundInputs;
  CarrierGeometry Geometry;
  std::vector<MapEntry> CarrierEntries, VertexEntries;
  /// theta = 0 direction (machine: theta_zero); NaN: the default.
  Vec3 ThetaZero = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<MapEntry> DefinitionEntries;
  std::map<std::string, int> DefinitionIndex;
  std::vector<int> CarrierState, VertexState, DefinitionState; // 0 pending, 1 in progress, 2 done
  std::vector<std::string> Resolving;         // entities being resolved, for cycles
  syntax::Reporter Report;
  ExpressionEvaluator Evaluator;
  std::vector<MapEntry> Sections;
  std::string Name;
  BlockModel Model;
  std::vector<ParameterInfo> Infos;
};

/// Templates are a few kilobytes; this bound keeps /dev/zero or a grid picked by mistake
/// from being read until memory runs out.
constexpr std::size_t MaxTemplateBytes = 16u << 20;

/// The template's text with line ends made "\n" (Windows "\r\n" and old Mac lone "\r",
/// which YAML would otherwise read as one long line).
std::string readFile(const std::string& path)
{
  struct stat status;
  if (::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode))
  {
    throw TemplateError(path, 0, "", "'" + path + "' is a folder, not a template file");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    const int error = errno;
    throw TemplateError(path, 0, "",
      "cannot open template file '" + path + "'" +
        (error ? std::string(": ") + std::strerror(error) : std::string()));
  }
  std::string text(MaxTemplateBytes + 1, '\0');
  stream.read(&text[0], static_cast<std::streamsize>(text.size()));
  if (stream.bad() || (stream.fail() && !stream.eof()))
  {
    const int error = errno;
    throw TemplateError(path, 0, "",
      "cannot read template file '" + path + "'" +
        (error ? std::string(": ") + std::strerror(error) : std::string()));
  }
  text.resize(static_cast<std::size_t>(stream.gcount()));
  if (text.size() > MaxTemplateBytes)
  {
    throw TemplateError(path, 0, "",
      "'" + path + "' is larger than " + std::to_string(MaxTemplateBytes >> 20) +
        " MB: not a template file");
  }
  std::string normalized;
  normalized.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    if (text[i] == '\r')
    {
      normalized += '\n';
      if (i + 1 < text.size() && text[i + 1] == '\n')
      {
        ++i;
      }
      continue;
    }
    normalized += text[i];
  }
  return normalized;
}
} // namespace

BlockModel parseTemplate(const std::string& text, const std::string& fileName,
  const ParameterOverrides& overrides, const TemplateInputs* inputs, CarrierGeometry* carriers)
{
  TemplateReader reader(text, fileName, overrides, inputs);
  BlockModel model = reader.readModel();
  // Topology and geometry problems are template errors too: report them now, with the
  // template's lines, rather than when the mesher runs.
  checkModel(model, reader.geometry());
  if (carriers)
  {
    *carriers = reader.geometry();
  }
  return model;
}

BlockModel loadTemplate(const std::string& path, const ParameterOverrides& overrides,
  const TemplateInputs* inputs, CarrierGeometry* carriers)
{
  return parseTemplate(readFile(path), path, overrides, inputs, carriers);
}

std::vector<ParameterInfo> templateParameters(const std::string& path,
  const ParameterOverrides& overrides, const TemplateInputs* inputs)
{
  const std::string text = readFile(path);
  TemplateReader reader(text, path, overrides, inputs);
  return reader.readParameterInfos();
}
} // namespace model
} // namespace blockforge
