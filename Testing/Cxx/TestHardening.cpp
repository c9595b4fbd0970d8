// Hostile input (issue 12): messages that survive any bytes, memory estimates and validated
// densities instead of clamps or aborts, bounded work in the iterative geometry, and the
// template reader's small cases (lone CR, folders, endless files, second YAML documents,
// blade counts).
#include "Distribution.h"
#include "MemoryBudget.h"
#include "PrintableText.h"
#include "TestHelpers.h"
#include "TestTurboInputs.h"
#include "WorkBudget.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <fstream>
#include <string>

#include <unistd.h>

using namespace blockforge;
using namespace blockforge::test;

namespace
{
std::string writeTemporary(const std::string& name, const std::string& text)
{
  const std::string path = "/tmp/blockforge_hardening_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string message(const std::function<void()>& action)
{
  try
  {
    action();
  }
  catch (const std::exception& error)
  {
    return error.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}
} // namespace

// --- messages -------------------------------------------------------------------------------

TEST(PrintableText, KeepsUtf8AndEscapesEverythingElse)
{
  EXPECT_EQ(printableText("blade \xc3\xa9t\xc3\xa9 \xe2\x82\xac \xf0\x9d\x84\x9e"),
    "blade \xc3\xa9t\xc3\xa9 \xe2\x82\xac \xf0\x9d\x84\x9e");
  EXPECT_EQ(printableText("name\xff"), "name\\xff");
  EXPECT_EQ(printableText("\xc3"), "\\xc3");                 // truncated sequence
  EXPECT_EQ(printableText("\xc0\xaf"), "\\xc0\\xaf");        // overlong '/'
  EXPECT_EQ(printableText("\xed\xa0\x80"), "\\xed\\xa0\\x80"); // UTF-16 surrogate
  EXPECT_EQ(printableText("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80"); // above U+10FFFF
  EXPECT_EQ(printableText("a\rb\x1b"), "a\\x0db\\x1b");
  EXPECT_EQ(printableText("two\nlines\tand a tab"), "two\nlines\tand a tab");
  EXPECT_EQ(printableText(std::string("nul\0byte", 8)), "nul\\x00byte");
}

TEST(PrintableText, TemplateErrorsNamingStrayBytesArePrintable)
{
  // a stray byte in a vertex name, and in the file name
  const std::string text = readText(templatePath("cylinder_in_box.yaml"));
  const std::string bad = replaced(text, "blocks:", "blocks:\n  b\xff: {}");
  const std::string path = writeTemporary("name\xfe.yaml", bad);
  const std::string raw = message([&] { model::loadTemplate(path); });
  std::remove(path.c_str());
  const std::string shown = printableText(raw);
  EXPECT_NE(shown.find("name\\xfe.yaml"), std::string::npos) << shown;
  EXPECT_EQ(printableText(shown), shown); // already escaped: stable
  EXPECT_EQ(shown.find('\xfe'), std::string::npos);
}

// --- memory and densities --------------------------------------------------------------------

TEST(MemoryBudget, GridEstimateAndRefusal)
{
  // one block of 10000^3 cells: 1.0e12 nodes, 24 bytes each at least
  const model::BlockNodeCounts huge = { { 10001, 10001, 10001 } };
  EXPECT_GT(model::gridMemoryBytes(huge), 24.0 * 1.0e12);
  EXPECT_LT(model::gridMemoryBytes(huge), 30.0 * 1.0003e12);
  const std::string refused =
    message([&] { model::checkGridMemory(huge, 0.0, "lower the density multiplier"); });
  EXPECT_NE(refused.find("the grid would need 25.5 TB for 1e+12 nodes"), std::string::npos)
    << refused;
  if (model::availableMemoryBytes() > 0)
  {
    EXPECT_NE(refused.find("available; lower the density multiplier"), std::string::npos)
      << refused;
  }
  // a user limit: 1000^3 nodes (22 GB) above MaximumMemory = 8 GB
  const model::BlockNodeCounts large = { { 1000, 1000, 1000 } };
  const std::string limited = message([&] { model::checkGridMemory(large, 8.0, "lower it"); });
  EXPECT_NE(limited.find("more than MaximumMemory (8 GB)"), std::string::npos) << limited;
  // small grids pass
  EXPECT_NO_THROW(model::checkGridMemory({ { 33, 33, 33 } }, 1.0, "lower it"));
  EXPECT_EQ(model::formatBytes(1536.0), "1.5 kB");
  EXPECT_EQ(model::formatBytes(48.0 * 1073741824.0), "48 GB");
  EXPECT_NEAR(model::qualityMemoryBytes(1e6), 60e6, 1.0); // 7 doubles and an int per cell
}

TEST(MemoryBudget, DensityMultiplierIsValidatedNotClamped)
{
  const model::BlockModel model = model::loadTemplate(templatePath("cylinder_in_box.yaml"));
  for (double bad : { std::numeric_limits<double>::infinity(), 1e308, 1000.5, 0.0, -1.0,
         std::numeric_limits<double>::quiet_NaN() })
  {
    expectError([&] { model::MultiBlockMesher mesher(model, bad); },
      { "density multiplier must be a number above 0 and at most 1000" });
  }
  // a density that makes a direction exceed 1,000,000 cells names the block
  const model::BlockModel fine =
    model::loadTemplate(templatePath("cylinder_in_box.yaml"), { { "n_around", "2000" } });
  expectError([&] { model::MultiBlockMesher mesher(fine, 999.0); },
    { "block 'north'", "2000 cells x density multiplier 999 = 1998000 cells",
      "more than 1000000 per direction" });
  // small densities: at least one cell per direction (documented, not an error)
  model::MultiBlockMesher coarse(model, 1e-9);
  EXPECT_EQ(coarse.nodeCounts(0), (std::array<int, 3>{ 2, 2, 2 }));
}

TEST(MemoryBudget, HugeTemplateBlockIsRefusedBeforeAllocating)
{
  // two blocks of 10000^3 cells through a parameter override, as `-p n=10000` does
  const model::BlockModel model =
    model::loadTemplate(sourcePath("Testing/Data/two_blocks.yaml"), { { "n", "10000" } });
  model::MultiBlockMesher mesher(model);
  model::BlockNodeCounts nodes;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    nodes.push_back(mesher.nodeCounts(b));
  }
  const std::string refused =
    message([&] { model::checkGridMemory(nodes, 0.0, "lower the cell counts"); });
  EXPECT_NE(refused.find("the grid would need 51 TB for 2e+12 nodes"), std::string::npos)
    << refused;
}

TEST(MemoryBudget, ExtremeGradingIsAnErrorNotCollapsedCells)
{
  // the fuzzer's case: a growth ratio of 2147483647 over 12 cells made cells of no volume
  DistributionLaw law;
  law.kind = DistributionLaw::Kind::Geometric;
  law.expansionRatio = 2147483647.0;
  const std::string text = message([&] { distributeNodes(law, 13); });
  EXPECT_NE(text.find("below 1e-12 of the edge"), std::string::npos) << text;
  // a strong but representable grading: smallest cell 1e-9 of the largest
  law.expansionRatio = 0.1;
  const std::vector<double> s = distributeNodes(law, 10);
  EXPECT_NEAR((s[9] - s[8]) / (s[1] - s[0]), 1e-8, 1e-15); // rounding of the small cell
}

// --- bounded iterative geometry ---------------------------------------------------------------

TEST(WorkBudget, ThrowsOnceSpentAndChargesEveryEnclosingScope)
{
  WorkBudget outer(100, "outer search");
  {
    const WorkBudget::Scope scope(outer);
    WorkBudget::charge(60);
    WorkBudget inner(10, "inner search");
    {
      const WorkBudget::Scope innerScope(inner);
      WorkBudget::charge(10);
      EXPECT_THROW(WorkBudget::charge(), GeometryError); // the inner one is spent
    }
    EXPECT_EQ(outer.spent(), 70u); // nested work counts for the outer search too
    WorkBudget::charge(30);
    const std::string text = message([] { WorkBudget::charge(); });
    EXPECT_NE(text.find("outer search: no result within 100 evaluations"), std::string::npos);
  }
  WorkBudget::charge(1000000); // no scope: free
  EXPECT_EQ(outer.spent(), 101u);
}

// The case of the issue: a hub contour with four scaled coordinates kept the blade-hub
// intersection busy for 17.5 s. Now the work is bounded and the error names the carrier.
TEST(WorkBudget, ScaledHubContourFailsWithBoundedWork)
{
  model::TemplateInputs inputs =
    readTemplateInputs(sourcePath("Data/distributor/BladeGen.inf"));
  auto& hub = inputs.pointSets[0].curves[0].points;
  ASSERT_GT(hub.size(), 210u);
  // (row, coordinate) pairs of the fuzzer's case; scaled by 1000
  const int rows[4][2] = { { 34, 2 }, { 205, 0 }, { 65, 0 }, { 126, 1 } };
  for (const auto& row : rows)
  {
    hub[row[0]][row[1]] *= 1000.0;
  }
  WorkBudget whole(100000000, "whole template");
  const WorkBudget::Scope scope(whole);
  const std::string text = message(
    [&] { model::loadTemplate(templatePath("axial_passage_oh.yaml"), {}, &inputs); });
  EXPECT_NE(text.find("carrier 'blade_h'"), std::string::npos) << text;
  EXPECT_NE(text.find("no result within 1000000 evaluations"), std::string::npos) << text;
  // the work bound: the failing intersection stopped at its limit, and what ran before it
  // (the other carriers) is small
  EXPECT_GE(whole.spent(), IntersectionWorkLimit);
  EXPECT_LT(whole.spent(), IntersectionWorkLimit + 200000u);
}

TEST(WorkBudget, NormalTemplatesUseAFractionOfTheBudget)
{
  // All the iterative geometry of the OH template on both data sets (four intersections,
  // two offsets and every projection), counted by an enclosing budget: the per-search
  // limits leave a wide margin.
  for (const char* data :
    { "Data/distributor/BladeGen.inf", "Data/rotor37/turbogrid/BladeGen.inf" })
  {
    const model::TemplateInputs inputs = readTemplateInputs(sourcePath(data));
    WorkBudget whole(100000000, "whole template");
    const WorkBudget::Scope scope(whole);
    model::loadTemplate(templatePath("axial_passage_oh.yaml"), {}, &inputs);
    EXPECT_GT(whole.spent(), 100000u) << data;
    EXPECT_LT(whole.spent(), IntersectionWorkLimit) << data;
  }
}

// --- template reader: small cases -------------------------------------------------------------

TEST(TemplateReader, LoneCarriageReturnsAreLineEnds)
{
  const std::string text = readText(templatePath("cylinder_in_box.yaml"));
  std::string mac = text, windows;
  for (char& c : mac)
  {
    if (c == '\n')
    {
      c = '\r';
    }
  }
  for (char c : text)
  {
    windows += c == '\n' ? std::string("\r\n") : std::string(1, c);
  }
  const Grid reference = meshAll(model::loadTemplate(templatePath("cylinder_in_box.yaml")));
  for (const std::string& variant : { mac, windows })
  {
    const std::string path = writeTemporary("cr.yaml", variant);
    const Grid grid = meshAll(model::loadTemplate(path));
    std::remove(path.c_str());
    ASSERT_EQ(grid.xyz.size(), reference.xyz.size());
    for (std::size_t b = 0; b < grid.xyz.size(); ++b)
    {
      EXPECT_TRUE(sameBits(grid.xyz[b], reference.xyz[b]));
    }
  }
  // line numbers count lone CRs as line ends: the same error, at the same line
  const std::string lfPath = writeTemporary("lf_bad.yaml", replaced(text, "blocks:", "blocks: [oops"));
  const std::string crPath = writeTemporary("cr_bad.yaml", replaced(mac, "blocks:", "blocks: [oops"));
  const std::string expected = message([&] { model::loadTemplate(lfPath); });
  const std::string got = message([&] { model::loadTemplate(crPath); });
  EXPECT_EQ(got.substr(crPath.size()), expected.substr(lfPath.size()));
  EXPECT_NE(got.find("YAML syntax error"), std::string::npos) << got;
  std::remove(lfPath.c_str());
  std::remove(crPath.c_str());
}

TEST(TemplateReader, FolderAndEndlessFilesAreRefused)
{
  expectError([] { model::loadTemplate("/tmp"); }, { "'/tmp' is a folder, not a template file" });
  expectError(
    [] { model::loadTemplate("/dev/zero"); }, { "'/dev/zero' is larger than 16 MB" });
}

TEST(TemplateReader, SecondYamlDocumentIsAnError)
{
  const std::string text = readText(templatePath("cylinder_in_box.yaml"));
  const int lines = lineContaining(text + "\n@end", "@end");
  expectError([&] { model::parseTemplate(text + "\n---\nblockforge: 1\n", "two.yaml"); },
    { "two.yaml:" + std::to_string(lines + 1), "a second YAML document" });
  // a leading document marker is one document
  EXPECT_NO_THROW(model::parseTemplate("---\n" + text, "one.yaml"));
}

TEST(TemplateReader, BladeCountOfTheInputIsRangeChecked)
{
  model::TemplateInputs inputs =
    readTemplateInputs(sourcePath("Data/distributor/BladeGen.inf"));
  inputs.bladeCount = 2147483647;
  inputs.origin = "BladeGen.inf";
  expectError([&] { model::loadTemplate(templatePath("axial_passage_oh.yaml"), {}, &inputs); },
    { "BladeGen.inf gives blade count 2147483647",
      "the blade count must be a whole number from 1 to 100000" });
}
