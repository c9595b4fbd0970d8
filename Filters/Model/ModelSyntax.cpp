#include "ModelSyntax.h"

#include "Errors.h"

#include <algorithm>
#include <charconv>
#include <sstream>
#include <locale>
#include <cmath>

namespace blockforge
{
namespace model
{
namespace syntax
{
std::string formatNumber(double value)
{
  // std::to_chars ignores the C locale (ParaView's GUI may set a decimal comma) and 17
  // significant digits always round-trip an IEEE double.
  char buffer[64];
  const auto result =
    std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 17);
  return std::string(buffer, result.ptr);
}

bool parseNumber(const std::string& text, double& value)
{
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+')
  {
    ++first;
  }
  if (first == last)
  {
    return false;
  }
  const auto result = std::from_chars(first, last, value);
  return result.ec == std::errc() && result.ptr == last;
}

int lineOf(const YAML::Node& node)
{
  if (!node.IsDefined())
  {
    return 0;
  }
  const YAML::Mark mark = node.Mark();
  return mark.line >= 0 ? mark.line + 1 : 0;
}

namespace
{
bool isNameStart(char c)
{
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool isNameChar(char c)
{
  return isNameStart(c) || (c >= '0' && c <= '9');
}
}

bool isIdentifier(const std::string& name)
{
  return !name.empty() && isNameStart(name[0]) &&
    std::all_of(name.begin(), name.end(), isNameChar);
}

bool isEntityName(const std::string& name)
{
  return !name.empty() && isNameStart(name[0]) &&
    std::all_of(name.begin(), name.end(), [](char c) { return isNameChar(c) || c == '-'; });
}

std::string joinNames(const std::vector<std::string>& names, std::size_t maxCount)
{
  std::string text;
  for (std::size_t i = 0; i < names.size() && i < maxCount; ++i)
  {
    text += (i ? ", " : "") + names[i];
  }
  if (names.size() > maxCount)
  {
    text += ", ...";
  }
  return text.empty() ? "(none)" : text;
}

namespace
{
std::size_t editDistance(const std::string& a, const std::string& b)
{
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
  {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i)
  {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
    {
      const std::size_t above = row[j];
      row[j] = std::min({ row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1]) });
      diagonal = above;
    }
  }
  return row[b.size()];
}
}

std::string closestName(const std::string& name, const std::vector<std::string>& candidates)
{
  auto lower = [](std::string text) {
    std::transform(text.begin(), text.end(), text.begin(),
      [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
    return text;
  };
  // A difference of case only is the likeliest slip.
  for (const std::string& candidate : candidates)
  {
    if (lower(candidate) == lower(name))
    {
      return candidate;
    }
  }
  std::string best;
  std::size_t bestDistance = 3;
  for (const std::string& candidate : candidates)
  {
    const std::size_t distance = editDistance(name, candidate);
    if (distance < bestDistance)
    {
      bestDistance = distance;
      best = candidate;
    }
  }
  return best;
}

std::string entity(const std::string& kind, const std::string& name)
{
  return kind + " '" + name + "'";
}

std::string edgeLabel(int edge)
{
  return "E" + std::to_string(edge + 1);
}

void Reporter::fail(int line, const std::string& entityText, const std::string& what) const
{
  throw TemplateError(file, line, entityText, what);
}

std::vector<MapEntry> mapEntries(const YAML::Node& node, int line,
  const std::string& entityText, const std::string& what, const Reporter& reporter,
  const std::string& itemKind)
{
  std::vector<MapEntry> entries;
  if (!node.IsDefined() || node.IsNull())
  {
    return entries;
  }
  if (!node.IsMap())
  {
    reporter.fail(lineOf(node) ? lineOf(node) : line, entityText,
      what + " must be a mapping (name: value lines or {key: value, ...})");
  }
  for (auto it = node.begin(); it != node.end(); ++it)
  {
    MapEntry entry;
    entry.line = lineOf(it->first);
    if (!it->first.IsScalar())
    {
      reporter.fail(entry.line ? entry.line : line, entityText,
        what + " has a key that is not a plain name");
    }
    entry.key = it->first.Scalar();
    entry.value = it->second;
    for (const MapEntry& earlier : entries)
    {
      if (earlier.key == entry.key && !itemKind.empty())
      {
        reporter.fail(entry.line, entity(itemKind, entry.key),
          "defined twice (first on line " + std::to_string(earlier.line) + ")");
      }
      if (earlier.key == entry.key)
      {
        reporter.fail(entry.line, entityText,
          "'" + entry.key + "' appears twice in " + what + " (first on line " +
            std::to_string(earlier.line) + ")");
      }
    }
    entries.push_back(std::move(entry));
  }
  return entries;
}

void checkKeys(const std::vector<MapEntry>& entries, const std::vector<std::string>& allowed,
  const std::string& entityText, const Reporter& reporter)
{
  for (const MapEntry& entry : entries)
  {
    if (std::find(allowed.begin(), allowed.end(), entry.key) == allowed.end())
    {
      // A misplaced comment or text block can make a long key: keep the message short.
      std::string shown = entry.key.substr(0, 60) + (entry.key.size() > 60 ? "..." : "");
      std::replace(shown.begin(), shown.end(), '\n', ' ');
      std::string what = "unknown key '" + shown + "'";
      const std::string suggestion = closestName(entry.key, allowed);
      if (!suggestion.empty())
      {
        what += " (did you mean '" + suggestion + "'?)";
      }
      reporter.fail(entry.line, entityText, what + "; expected one of: " + joinNames(allowed));
    }
  }
}

const MapEntry* findEntry(const std::vector<MapEntry>& entries, const std::string& key)
{
  for (const MapEntry& entry : entries)
  {
    if (entry.key == key)
    {
      return &entry;
    }
  }
  return nullptr;
}

const MapEntry* findKind(const std::vector<MapEntry>& entries,
  const std::vector<std::string>& kinds, const std::string& entity, const Reporter& reporter)
{
  const MapEntry* kind = nullptr;
  for (const MapEntry& entry : entries)
  {
    if (std::find(kinds.begin(), kinds.end(), entry.key) != kinds.end())
    {
      if (kind)
      {
        reporter.fail(entry.line, entity,
          "give one kind only, not both '" + kind->key + "' and '" + entry.key + "'");
      }
      kind = &entry;
    }
  }
  return kind;
}

std::string shortNumber(double value)
{
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text.precision(6);
  text << value;
  return text.str();
}

namespace
{
const char* const LawSyntax =
  "uniform, {geometric: k}, {two_sided: k}, {first_cell: h, ratio: r}, "
  "{ends: [a, b]}, {ends: [a, b], flat: k}, match, {match: r}, {match: r, lean: angle}, {match: r, flat: k}, {match: r, at_most: k}, "
  "{project_from: edge} or "
  "{project_from: edge, fade: k} (or fade: [k_first, k_last])";
}

std::array<Blending, 3> parseBlending(
  const YAML::Node& node, int line, const std::string& entityText, const Reporter& reporter)
{
  const int here = lineOf(node) ? lineOf(node) : line;
  const auto one = [&](const YAML::Node& value, int at) {
    if (value.IsScalar() && value.Scalar() == "linear")
    {
      return Blending::Linear;
    }
    if (value.IsScalar() && value.Scalar() == "end_cells")
    {
      return Blending::EndCells;
    }
    if (value.IsScalar() && value.Scalar() == "adaptive")
    {
      return Blending::Adaptive;
    }
    if (value.IsScalar() && value.Scalar() == "end_widths")
    {
      return Blending::EndWidths;
    }
    reporter.fail(at, entityText,
      "'interpolation' must be 'linear' (the default: interior lines take the edges' "
      "fractions), 'end_cells' (interior lines keep the edges' end cells as lengths), "
      "'adaptive' (linear while the interior lines' lengths stay within 20 % of their "
      "edges', else towards end_cells so that their end cells do), 'end_widths' (linear, and "
      "on a face a cell next to a side that comes out under 0.7 of the width of that side's "
      "end cells is widened to 0.8 of it) or "
      "{i: .., j: .., k: ..} of those");
  };
  if (!node.IsMap())
  {
    const Blending all = one(node, here);
    return { all, all, all };
  }
  const auto keys = mapEntries(node, here, entityText, "'interpolation'", reporter);
  checkKeys(keys, { "i", "j", "k" }, entityText, reporter);
  std::array<Blending, 3> blending{ Blending::Linear, Blending::Linear, Blending::Linear };
  for (int d = 0; d < 3; ++d)
  {
    if (const MapEntry* entry = findEntry(keys, std::string(1, static_cast<char>('i' + d))))
    {
      blending[d] = one(entry->value, entry->line);
    }
  }
  return blending;
}

void emitBlending(YAML::Emitter& out, const std::array<Blending, 3>& blending)
{
  const auto name = [](Blending b) {
    return b == Blending::EndCells ? "end_cells"
      : b == Blending::Adaptive    ? "adaptive"
      : b == Blending::EndWidths   ? "end_widths"
                                   : "linear";
  };
  if (blending[0] == blending[1] && blending[1] == blending[2])
  {
    if (blending[0] != Blending::Linear)
    {
      out << YAML::Key << "interpolation" << YAML::Value << name(blending[0]);
    }
    return;
  }
  out << YAML::Key << "interpolation" << YAML::Value << YAML::Flow << YAML::BeginMap;
  for (int d = 0; d < 3; ++d)
  {
    out << YAML::Key << std::string(1, static_cast<char>('i' + d)) << YAML::Value << name(blending[d]);
  }
  out << YAML::EndMap;
}

DistributionLaw parseLaw(const YAML::Node& node, int line, const std::string& entityText,
  const std::string& what, const NumberReader& number, const Reporter& reporter,
  const EdgeReader& edges)
{
  const int here = lineOf(node) ? lineOf(node) : line;
  DistributionLaw law;
  if (node.IsScalar())
  {
    if (node.Scalar() == "uniform")
    {
      return law;
    }
    if (node.Scalar() == "match")
    {
      law.kind = DistributionLaw::Kind::Match;
      law.expansionRatio = DefaultMatchRatio;
      return law;
    }
    reporter.fail(here, entityText,
      what + ": unknown law '" + node.Scalar() + "'; expected " + LawSyntax);
  }
  if (!node.IsMap())
  {
    reporter.fail(here, entityText, what + ": expected " + LawSyntax);
  }
  const std::vector<MapEntry> entries = mapEntries(node, here, entityText, what, reporter);
  checkKeys(entries,
    { "geometric", "two_sided", "first_cell", "ratio", "ends", "match", "lean", "project_from",
      "fade", "flat", "at_most" },
    entityText, reporter);
  const MapEntry* fade = findEntry(entries, "fade");
  if (const MapEntry* project = findEntry(entries, "project_from"))
  {
    if (entries.size() != (fade ? 2u : 1u))
    {
      reporter.fail(project->line, entityText,
        what + ": expected {project_from: edge} or {project_from: edge, fade: k} alone");
    }
    if (fade)
    {
      const auto fadeOf = [&](const YAML::Node& value, const std::string& which) {
        const double k = number(value, fade->line, what + " fade" + which);
        if (!(k == 0.0 || k >= 2.0) || !std::isfinite(k))
        {
          reporter.fail(fade->line, entityText,
            what + ": the fade of a projected edge's end shift must be 0 (none) or at least "
                   "2 (times the shift), got " + formatNumber(k));
        }
        return k;
      };
      if (fade->value.IsSequence() && fade->value.size() == 2)
      {
        law.fadeStart = fadeOf(fade->value[0], " (first end)");
        law.fadeEnd = fadeOf(fade->value[1], " (last end)");
      }
      else if (fade->value.IsScalar())
      {
        law.fadeStart = law.fadeEnd = fadeOf(fade->value, "");
      }
      else
      {
        reporter.fail(fade->line, entityText,
          what + ": expected fade: k or fade: [k_first, k_last]");
      }
    }
    law.kind = DistributionLaw::Kind::ProjectFrom;
    law.sourceEdge = edges(project->value, project->line, what + " project_from");
    return law;
  }
  if (fade)
  {
    reporter.fail(fade->line, entityText, what + ": 'fade' belongs to the law project_from");
  }
  const MapEntry* lean = findEntry(entries, "lean");
  // `flat: k`, the bump flatness of the laws ends and match (at least 1); `rule` states the
  // bound for the law in the message.
  const MapEntry* flat = findEntry(entries, "flat");
  const auto flatness = [&](const std::string& rule) {
    const double k = number(flat->value, flat->line, what + " flat");
    if (!(k >= 1.0) || !std::isfinite(k))
    {
      reporter.fail(flat->line, entityText,
        what + ": the flatness of " + rule + ", got " + formatNumber(k));
    }
    return k;
  };
  const MapEntry* atMost = findEntry(entries, "at_most");
  if (const MapEntry* match = findEntry(entries, "match"))
  {
    if (entries.size() != 1u + (lean ? 1u : 0u) + (flat ? 1u : 0u) + (atMost ? 1u : 0u))
    {
      reporter.fail(match->line, entityText,
        what + ": expected {match: r} with any of lean: angle, flat: k, at_most: k, alone");
    }
    if (atMost)
    {
      law.matchAtMost = number(atMost->value, atMost->line, what + " at_most");
      if (!(law.matchAtMost >= 0.0) || !std::isfinite(law.matchAtMost))
      {
        reporter.fail(atMost->line, entityText,
          what + ": a matched edge's end cells at most k times its mean cell needs k > 0 (0: "
                 "no limit), got " + formatNumber(law.matchAtMost));
      }
    }
    if (flat)
    {
      law.matchFlatness = flatness("a matched edge's bump must be at least 1");
    }
    if (lean)
    {
      law.leanLimit = number(lean->value, lean->line, what + " lean");
      if (!(law.leanLimit > 0.0) || !(law.leanLimit < 3.14159265358979))
      {
        reporter.fail(lean->line, entityText,
          what + ": the lean of a matched edge's end cells must be an angle between 0 and "
                 "180deg, got " + formatNumber(law.leanLimit) + " rad");
      }
    }
    law.kind = DistributionLaw::Kind::Match;
    law.expansionRatio = number(match->value, match->line, what + " match");
    if (!(law.expansionRatio > 1.0) || !std::isfinite(law.expansionRatio))
    {
      reporter.fail(match->line, entityText,
        what + ": the growth ratio of a matched edge must be above 1, got " +
          formatNumber(law.expansionRatio));
    }
    return law;
  }
  if (lean)
  {
    reporter.fail(lean->line, entityText, what + ": 'lean' belongs to the law match");
  }
  if (atMost)
  {
    reporter.fail(atMost->line, entityText, what + ": 'at_most' belongs to the law match");
  }
  if (const MapEntry* ends = findEntry(entries, "ends"))
  {
    if (entries.size() != (flat ? 2u : 1u) || !ends->value.IsSequence() ||
      ends->value.size() != 2)
    {
      reporter.fail(ends->line, entityText,
        what + ": expected {ends: [a, b]} or {ends: [a, b], flat: k}: the first and last "
               "cells a and b times the mean cell of the edge");
    }
    if (flat)
    {
      law.endsFlatness = flatness("an ends law's bump must be at least 1 (1: the default bump)");
    }
    law.kind = DistributionLaw::Kind::Ends;
    law.firstCellSize = number(ends->value[0], ends->line, what + " ends a");
    law.lastCellSize = number(ends->value[1], ends->line, what + " ends b");
    if (!(law.firstCellSize > 0.0) || !(law.lastCellSize > 0.0) ||
      !std::isfinite(law.firstCellSize) || !std::isfinite(law.lastCellSize))
    {
      reporter.fail(ends->line, entityText,
        what + ": the end cell sizes must be positive, got " +
          formatNumber(law.firstCellSize) + " and " + formatNumber(law.lastCellSize));
    }
    return law;
  }
  if (flat)
  {
    reporter.fail(flat->line, entityText, what + ": 'flat' belongs to the laws ends and match");
  }
  const MapEntry* geometric = findEntry(entries, "geometric");
  const MapEntry* twoSided = findEntry(entries, "two_sided");
  const MapEntry* firstCell = findEntry(entries, "first_cell");
  const MapEntry* ratio = findEntry(entries, "ratio");
  if ((geometric != nullptr) + (twoSided != nullptr) + (firstCell != nullptr) != 1 ||
    (ratio && !firstCell))
  {
    reporter.fail(here, entityText, what + ": expected exactly one of " + LawSyntax);
  }
  if (geometric || twoSided)
  {
    const MapEntry& entry = geometric ? *geometric : *twoSided;
    law.kind = geometric ? DistributionLaw::Kind::Geometric : DistributionLaw::Kind::TwoSided;
    law.expansionRatio = number(entry.value, entry.line, what + " " + entry.key);
    if (!(law.expansionRatio > 0.0))
    {
      reporter.fail(entry.line, entityText,
        what + ": the expansion ratio must be positive, got " +
          formatNumber(law.expansionRatio));
    }
    return law;
  }
  law.kind = DistributionLaw::Kind::FirstCell;
  law.firstCellSize = number(firstCell->value, firstCell->line, what + " first_cell");
  if (!(law.firstCellSize > 0.0))
  {
    reporter.fail(firstCell->line, entityText,
      what + ": the first cell size must be positive, got " + formatNumber(law.firstCellSize));
  }
  law.expansionRatio = 0.0; // solved by distributeNodes
  if (ratio)
  {
    law.expansionRatio = number(ratio->value, ratio->line, what + " ratio");
    if (!(law.expansionRatio > 1.0))
    {
      reporter.fail(ratio->line, entityText,
        what + ": the largest growth ratio must be above 1, got " +
          formatNumber(law.expansionRatio));
    }
  }
  return law;
}

void emitLaw(YAML::Emitter& out, const DistributionLaw& law, const BlockModel& model)
{
  switch (law.kind)
  {
    case DistributionLaw::Kind::Uniform:
      out << "uniform";
      return;
    case DistributionLaw::Kind::Geometric:
    case DistributionLaw::Kind::TwoSided:
      out << YAML::Flow << YAML::BeginMap << YAML::Key
          << (law.kind == DistributionLaw::Kind::Geometric ? "geometric" : "two_sided")
          << YAML::Value << formatNumber(law.expansionRatio) << YAML::EndMap;
      return;
    case DistributionLaw::Kind::FirstCell:
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "first_cell" << YAML::Value
          << formatNumber(law.firstCellSize);
      if (law.expansionRatio != 0.0)
      {
        out << YAML::Key << "ratio" << YAML::Value << formatNumber(law.expansionRatio);
      }
      out << YAML::EndMap;
      return;
    case DistributionLaw::Kind::Ends:
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "ends" << YAML::Value
          << YAML::Flow << YAML::BeginSeq << formatNumber(law.firstCellSize)
          << formatNumber(law.lastCellSize) << YAML::EndSeq;
      if (law.endsFlatness != 1.0)
      {
        out << YAML::Key << "flat" << YAML::Value << formatNumber(law.endsFlatness);
      }
      out << YAML::EndMap;
      return;
    case DistributionLaw::Kind::Match:
      // the end cells are the mesher's, from the neighbour edges: only the ratio is the law's
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "match" << YAML::Value
          << formatNumber(law.expansionRatio);
      if (law.leanLimit > 0.0)
      {
        out << YAML::Key << "lean" << YAML::Value << formatNumber(law.leanLimit);
      }
      if (law.matchFlatness != 0.0)
      {
        out << YAML::Key << "flat" << YAML::Value << formatNumber(law.matchFlatness);
      }
      if (law.matchAtMost != 0.0)
      {
        out << YAML::Key << "at_most" << YAML::Value << formatNumber(law.matchAtMost);
      }
      out << YAML::EndMap;
      return;
    case DistributionLaw::Kind::ProjectFrom:
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "project_from" << YAML::Value
          << model.edges.at(law.sourceEdge).name;
      if (law.fadeStart > 0.0 || law.fadeEnd > 0.0)
      {
        out << YAML::Key << "fade" << YAML::Value << YAML::Flow << YAML::BeginSeq
            << formatNumber(law.fadeStart) << formatNumber(law.fadeEnd) << YAML::EndSeq;
      }
      out << YAML::EndMap;
      return;
  }
}
} // namespace syntax
} // namespace model
} // namespace blockforge
