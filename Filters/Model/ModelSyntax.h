/**
 * @file ModelSyntax.h
 * @brief Private helpers shared by the template reader and the model document: exact
 * number formatting, located errors, YAML mapping walks and the grading-law syntax.
 * Not installed; includes yaml-cpp, which stays a private dependency of the model.
 */
#pragma once

#include "BlockModel.h"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
namespace syntax
{
/// The file name errors of the model document carry (it has no file of its own).
constexpr const char* ModelDocumentFile = "<model document>";

/// 17 significant digits, independent of the C locale: parseNumber gives back the same double.
std::string formatNumber(double value);
/// Parses the whole of `text` as a double, independent of the C locale.
bool parseNumber(const std::string& text, double& value);

/// 1-based line of a node, 0 when yaml-cpp has no position for it.
int lineOf(const YAML::Node& node);

/// `[A-Za-z_][A-Za-z0-9_]*`: parameter names (they appear in expressions).
bool isIdentifier(const std::string& name);
/// `[A-Za-z_][A-Za-z0-9_-]*`: names of vertices, edges, blocks and patches.
bool isEntityName(const std::string& name);
/// "a, b, c" (at most `maxCount` names, then ", ...").
std::string joinNames(const std::vector<std::string>& names, std::size_t maxCount = 40);
/// The name of `candidates` closest to `name` (edit distance <= 2), "" if none.
std::string closestName(const std::string& name, const std::vector<std::string>& candidates);
/// "kind 'name'", the entity part of every message.
std::string entity(const std::string& kind, const std::string& name);
/// Paper edge label of local edge e: "E1" .. "E12".
std::string edgeLabel(int edge);

/// Throws TemplateError for one source (a template file or a model document).
struct Reporter
{
  std::string file;
  [[noreturn]] void fail(int line, const std::string& entity, const std::string& what) const;
};

/// One key/value pair of a YAML mapping, with the key's line.
struct MapEntry
{
  std::string key;
  YAML::Node value;
  int line = 0;
};

/**
 * The entries of mapping `node` in document order. Fails (at `line`, on `entity`) when
 * `node` is not a mapping, a key is not a plain name or a key is repeated; `what`
 * describes the mapping in messages ("the blocks section"). When the keys are names of
 * entities, `itemKind` ("block") names a repeated one as the entity of the message.
 */
std::vector<MapEntry> mapEntries(const YAML::Node& node, int line, const std::string& entity,
  const std::string& what, const Reporter& reporter, const std::string& itemKind = "");
/// Fails on the first key not in `allowed`, listing the allowed keys.
void checkKeys(const std::vector<MapEntry>& entries, const std::vector<std::string>& allowed,
  const std::string& entity, const Reporter& reporter);
/// The entry with `key`, or nullptr.
const MapEntry* findEntry(const std::vector<MapEntry>& entries, const std::string& key);
/// The one entry whose key is one of `kinds` (an entity's kind, e.g. `arc`), nullptr if
/// none; fails when two kinds are given.
const MapEntry* findKind(const std::vector<MapEntry>& entries,
  const std::vector<std::string>& kinds, const std::string& entity, const Reporter& reporter);
/// Short form of a number for messages (6 significant digits, C locale).
std::string shortNumber(double value);

/// Converts a scalar node to a number (a literal or an expression) or fails itself.
using NumberReader = std::function<double(const YAML::Node& node, int line, const std::string& what)>;

/// Converts a scalar node naming an edge to the index of the model's named edge or fails
/// itself (unknown names).
using EdgeReader = std::function<int(const YAML::Node& node, int line, const std::string& what)>;

/**
 * A grading law: `uniform`, `{geometric: k}`, `{two_sided: k}`,
 * `{first_cell: h, ratio: r}` (ratio optional), `{ends: [a, b]}`, `match` or `{match: r}`
 * (end cells from the neighbour edges, growing by r, default DefaultMatchRatio), or
 * `{project_from: edge}` (the nodes of that named edge projected onto this one; needs
 * `edges`), with `fade: k` the end shifts faded out (DistributionLaw::fade). `what` names the law in messages ("grading j", "grading E9").
 */
DistributionLaw parseLaw(const YAML::Node& node, int line, const std::string& entity,
  const std::string& what, const NumberReader& number, const Reporter& reporter,
  const EdgeReader& edges = EdgeReader());
/// A block's `interpolation` (Blending, Core/Transfinite.h) in i, j and k: `linear` or
/// `end_cells` for all three, or `{i: .., j: .., k: ..}` (a direction not given: linear).
std::array<Blending, 3> parseBlending(
  const YAML::Node& node, int line, const std::string& entity, const Reporter& reporter);
/// Writes a block's `interpolation` as parseBlending reads it (nothing when all linear).
void emitBlending(YAML::Emitter& out, const std::array<Blending, 3>& blending);
/// Writes a law in the syntax parseLaw reads, numbers with formatNumber, edges by their
/// names in `model`.
void emitLaw(YAML::Emitter& out, const DistributionLaw& law, const BlockModel& model);
} // namespace syntax
} // namespace model
} // namespace blockforge
