/**
 * @file TemplateExpressions.h
 * @brief Private to the template reader (not installed): the expression language of
 * templates (muParser with degrees, constants and point queries such as `le_h.axial`).
 */
#pragma once

#include "Errors.h"
#include "ModelSyntax.h"

#include <muParser.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

namespace blockforge
{
namespace model
{
namespace detail
{
constexpr double Pi = 3.14159265358979323846;

/// Failure of one expression, in user terms; the caller adds file, line and entity.
struct ExpressionError
{
  std::string message;
};

/**
 * Values of expressions already evaluated, by their text and the values of the named
 * constants in it. muParser reads an expression into byte code with the constants' values
 * folded in, the same byte code for the same text and values, so a remembered value is
 * the same bits as evaluating again; reading is most of the cost (tens of thousands of
 * instructions for a line of a template). A placement after a move evaluates the
 * template's expressions again, most with nothing in them moved. Shared by threads
 * (serialised); the last few values of every text are kept, and all are forgotten past
 * a bound (a long optimisation must not grow it without end).
 */
class ExpressionMemo
{
public:
  bool find(const std::string& text, const std::vector<double>& constants, double& value)
  {
    std::lock_guard<std::mutex> guard(Lock);
    const auto found = Known.find(text);
    if (found == Known.end())
    {
      return false;
    }
    for (const Entry& entry : found->second.entries)
    {
      if (entry.used && sameBits(entry.constants, constants))
      {
        value = entry.value;
        return true;
      }
    }
    return false;
  }

  void remember(const std::string& text, const std::vector<double>& constants, double value)
  {
    std::lock_guard<std::mutex> guard(Lock);
    if (Known.size() > 100000)
    {
      Known.clear();
    }
    Slots& slots = Known[text];
    Entry& entry = slots.entries[slots.next];
    slots.next = (slots.next + 1) % slots.entries.size();
    entry.used = true;
    entry.constants = constants;
    entry.value = value;
  }

private:
  static bool sameBits(const std::vector<double>& a, const std::vector<double>& b)
  {
    return a.size() == b.size() &&
      (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
  }
  struct Entry
  {
    bool used = false;
    std::vector<double> constants;
    double value = 0.0;
  };
  struct Slots
  {
    std::array<Entry, 4> entries;
    std::size_t next = 0;
  };
  std::mutex Lock;
  std::unordered_map<std::string, Slots> Known;
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
    Parser.DefineNameChars(NameChars);
    Parser.DefineConst("pi", Pi);
    Parser.DefineConst("deg", Pi / 180.0);
  }

  /// Called with every `name.attribute` token (and every plain name, attribute "") of an
  /// expression before it is evaluated (resolves vertices and definitions further down).
  std::function<void(const std::string& name, const std::string& attribute)> OnReference;
  /// Names that are not available, with the reason (shown instead of "unknown name").
  std::map<std::string, std::string> Unavailable;
  /// Values already evaluated (none: every expression is read); see ExpressionMemo.
  ExpressionMemo* Memo = nullptr;

  /// Defines a query value such as `le_hub.radius` (not listed among the parameters).
  void defineQuery(const std::string& name, double value)
  {
    Parser.DefineConst(name, value);
    Queries.insert(name);
  }
  bool hasQuery(const std::string& name) const { return Queries.count(name) != 0; }

  /// The queries of vertex `name`: .x .y .z of `xyz`, .axial .radius .theta of
  /// `cylindrical` and, for a vertex on a carrier (`st` not null), .s and .t.
  void defineVertexQueries(
    const std::string& name, const double xyz[3], const double cylindrical[3], const double* st)
  {
    static const char* const attributes[6] = { ".x", ".y", ".z", ".axial", ".radius", ".theta" };
    for (int k = 0; k < 6; ++k)
    {
      defineQuery(name + attributes[k], k < 3 ? xyz[k] : cylindrical[k - 3]);
    }
    if (st)
    {
      defineQuery(name + ".s", st[0]);
      defineQuery(name + ".t", st[1]);
    }
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

  /// Every named constant: parameters, definitions, machine values, queries, pi, deg.
  std::map<std::string, double> constants() const
  {
    std::map<std::string, double> values;
    for (const auto& constant : Parser.GetConst())
    {
      values[constant.first] = constant.second;
    }
    return values;
  }

  double evaluate(const std::string& expression)
  {
    const std::string expanded = prepare(expression);
    std::vector<double> constants;
    std::string key;
    const bool memo = Memo && constantsIn(expanded, constants, key);
    double value = 0.0;
    if (memo && Memo->find(key, constants, value))
    {
      return value;
    }
    const std::string readAs = expanded != expression ? " (read as '" + expanded + "')" : "";
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
    if (memo)
    {
      Memo->remember(key, constants, value);
    }
    return value;
  }

  /**
   * The values of the constants muParser reads in `expanded`, in order: every name run
   * (muParser looks a token up among the constants first) that is one; `key` is the text
   * with which runs those are. False (not to be remembered) when a name is neither a
   * constant nor a function called, nor a number: a variable, or an unknown name (an
   * error, never remembered).
   */
  bool constantsIn(const std::string& expanded, std::vector<double>& constants, std::string& key) const
  {
    key = expanded;
    key += '\0';
    const auto& defined = Parser.GetConst();
    return forEachNameRun(expanded, [&](std::size_t start, std::size_t end, bool called) {
      const auto found = defined.find(expanded.substr(start, end - start));
      key += found != defined.end() ? 'c' : 'n';
      if (found != defined.end())
      {
        constants.push_back(found->second);
        return true;
      }
      const char first = expanded[start];
      const bool number = (first >= '0' && first <= '9') || first == '.';
      return number || called;
    });
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

  /// The names an expression refers to: (vertex, attribute) for `vertex.attribute`, (name, "")
  /// for plain names (parameters, definitions, constants); functions and numbers are left
  /// out. Names start with a letter or '_'; of a run `a.b.c`, only (a, b) is a reference.
  static std::vector<std::pair<std::string, std::string>> referencedNames(const std::string& text)
  {
    std::vector<std::pair<std::string, std::string>> names;
    forEachNameRun(text, [&](std::size_t start, std::size_t end, bool called) {
      const char first = text[start];
      if (!((first >= 'a' && first <= 'z') || (first >= 'A' && first <= 'Z') || first == '_'))
      {
        return true; // a number
      }
      const std::size_t dot = text.find('.', start);
      if (dot < end)
      {
        const std::size_t attributeEnd = std::min(text.find('.', dot + 1), end);
        names.emplace_back(
          text.substr(start, dot - start), text.substr(dot + 1, attributeEnd - dot - 1));
      }
      else if (!called)
      {
        names.emplace_back(text.substr(start, end - start), std::string());
      }
      return true;
    });
    return names;
  }

  /**
   * The one tokenizer of names: calls visit(start, end, called) for every maximal run of
   * muParser's name characters (NameChars) in `text`, in order, as muParser reads them as
   * one token (a number, a name or a vertex query); `called` when the run is followed,
   * past blanks, by '(' (a function call). Stops, returning false, when visit does.
   */
  template <typename Visit>
  static bool forEachNameRun(const std::string& text, Visit&& visit)
  {
    const std::size_t n = text.size();
    std::size_t i = 0;
    while (i < n)
    {
      if (!isNameChar(text[i]))
      {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < n && isNameChar(text[j]))
      {
        ++j;
      }
      std::size_t next = j;
      while (next < n && (text[next] == ' ' || text[next] == '\t'))
      {
        ++next;
      }
      if (!visit(i, j, next < n && text[next] == '('))
      {
        return false;
      }
      i = j;
    }
    return true;
  }

private:
  /// The characters of muParser names: '.' joins a vertex name and an attribute,
  /// le_hub.radius (format 2 queries).
  static constexpr const char* NameChars =
    "0123456789_abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.";
  /// One of NameChars (isNameChar and NameChars must agree).
  static bool isNameChar(char c)
  {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
      c == '_' || c == '.';
  }

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
} // namespace detail
} // namespace model
} // namespace blockforge
