// Guards the grids against unintended change: the exact bytes of the node coordinates of
// every block of every template in Templates/ (and the two-block test model) on every
// data set, at density multipliers 1 and 2, hashed and compared with the hashes stored in
// Testing/Data/grid_checksums.txt. A refactoring of the model must keep them bit for bit.
//
// When a grid changes on purpose, regenerate the file (and say why in the commit):
//   BLOCKFORGE_WRITE_GRID_CHECKSUMS=Testing/Data/grid_checksums.txt build/bin/TestGridChecksums
// The hashes hold for the Release build of the supported toolchain (Debian bookworm g++,
// x86-64); another compiler may round differently.
#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <map>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
/// 64-bit FNV-1a of a byte range, continuing from `hash`.
std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash = 1469598103934665603ULL)
{
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i)
  {
    hash ^= p[i];
    hash *= 1099511628211ULL;
  }
  return hash;
}

struct Case
{
  std::string templateFile; ///< relative to the source tree
  std::string dataSet;      ///< "-" for parameter-only templates
  std::string inf;          ///< description file of the data set (empty: none)
};

std::vector<Case> cases()
{
  const std::vector<std::pair<std::string, std::string>> data = {
    { "rotor37_turbogrid", "Data/rotor37/turbogrid/BladeGen.inf" },
    { "rotor37_dat", "Data/rotor37/dat/Info.txt" },
    { "distributor", "Data/distributor/BladeGen.inf" } };
  std::vector<Case> result;
  for (const std::string& name : test::exampleTemplates())
  {
    result.push_back({ "Templates/" + name, "-", "" });
  }
  result.push_back({ "Testing/Data/two_blocks.yaml", "-", "" });
  for (const std::string& name :
    { "Templates/axial_passage_h.yaml", "Templates/axial_passage_oh.yaml" })
  {
    for (const auto& set : data)
    {
      result.push_back({ name, set.first, set.second });
    }
  }
  return result;
}

/// "template data multiplier block" -> "ni nj nk hash" of every block of every case.
std::map<std::string, std::string> computeChecksums()
{
  std::map<std::string, std::string> result;
  for (const Case& c : cases())
  {
    SCOPED_TRACE(c.templateFile + " on " + c.dataSet);
    model::TemplateInputs inputs;
    if (!c.inf.empty())
    {
      inputs = test::readTemplateInputs(test::sourcePath(c.inf));
    }
    const BlockModel model = loadTemplate(
      test::sourcePath(c.templateFile), {}, c.inf.empty() ? nullptr : &inputs);
    for (const int multiplier : { 1, 2 })
    {
      const test::Grid grid = test::meshAll(model, multiplier);
      for (std::size_t b = 0; b < grid.xyz.size(); ++b)
      {
        const auto& n = grid.nodes[b];
        const std::uint64_t hash =
          fnv1a(grid.xyz[b].data(), grid.xyz[b].size() * sizeof(double));
        char value[96];
        std::snprintf(value, sizeof(value), "%d %d %d %016" PRIx64, n[0], n[1], n[2], hash);
        result[c.templateFile + " " + c.dataSet + " " + std::to_string(multiplier) + " " +
          model.blocks[b].name] = value;
      }
    }
  }
  return result;
}

std::map<std::string, std::string> readChecksums(const std::string& path)
{
  std::map<std::string, std::string> result;
  std::istringstream lines(test::readText(path));
  for (std::string line; std::getline(lines, line);)
  {
    if (line.empty() || line[0] == '#')
    {
      continue;
    }
    // key = first four fields, value = the rest
    std::size_t at = 0;
    for (int field = 0; field < 4 && at != std::string::npos; ++field)
    {
      at = line.find(' ', at + (field ? 1 : 0));
    }
    if (at == std::string::npos)
    {
      ADD_FAILURE() << "bad line in " << path << ": " << line;
      continue;
    }
    result[line.substr(0, at)] = line.substr(at + 1);
  }
  return result;
}
} // namespace

TEST(GridChecksums, EveryTemplateOnEveryDataSetIsBitIdentical)
{
  const std::map<std::string, std::string> actual = computeChecksums();
  if (const char* out = std::getenv("BLOCKFORGE_WRITE_GRID_CHECKSUMS"))
  {
    std::ofstream file(out);
    file << "# template data-set density block: ni nj nk FNV-1a-64 of the node coordinates\n"
         << "# written by TestGridChecksums (see Testing/Cxx/TestGridChecksums.cpp)\n";
    for (const auto& entry : actual)
    {
      file << entry.first << " " << entry.second << "\n";
    }
    GTEST_SKIP() << "wrote " << actual.size() << " checksums to " << out;
  }
  const std::map<std::string, std::string> expected =
    readChecksums(test::sourcePath("Testing/Data/grid_checksums.txt"));
  ASSERT_GT(expected.size(), 100u);
  EXPECT_EQ(actual.size(), expected.size());
  for (const auto& entry : expected)
  {
    const auto found = actual.find(entry.first);
    if (found == actual.end())
    {
      ADD_FAILURE() << "no grid for " << entry.first;
      continue;
    }
    EXPECT_EQ(found->second, entry.second) << entry.first;
  }
  for (const auto& entry : actual)
  {
    EXPECT_TRUE(expected.count(entry.first)) << "no stored checksum for " << entry.first;
  }
}
