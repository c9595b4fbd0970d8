// The mesher's check of finished block grids: a folded grid is refused with the block's
// name, its template line and the cell range.
#include "GridCheck.h"
#include "TestHelpers.h"

using namespace blockforge;
using namespace blockforge::test;

namespace
{
const std::string folded = sourcePath("Testing/Data/folded_spline.yaml");
}

TEST(GridCheck, FoldedSplineEdgeIsRefusedWithBlockAndCellRange)
{
  const model::BlockModel model = model::loadTemplate(folded);
  const Grid grid = meshAll(model); // the corner check passes: the fold is inside
  const int line = lineContaining(readText(folded), "  bent:");
  expectError([&] { model::checkBlockCells(model, 0, grid.nodes[0], grid.xyz[0].data()); },
    { "folded_spline.yaml:" + std::to_string(line) + ":", "block 'bent'", "inverted cells of 512",
      "cell range i ", ", j 0", "worst scaled Jacobian -", "AllowInvertedCells" });
  const model::InvertedCellReport report =
    model::reportInvertedCells(model, 0, grid.nodes[0], grid.xyz[0].data());
  EXPECT_GT(report.cells, 0);
  EXPECT_LT(report.cells, 512);
  EXPECT_NE(report.message.find("block 'bent'"), std::string::npos);
}

TEST(GridCheck, SameBlockWithASmallBulgePasses)
{
  const model::BlockModel model = model::loadTemplate(folded, { { "bulge", "0.3" } });
  const Grid grid = meshAll(model);
  EXPECT_NO_THROW(model::checkBlockCells(model, 0, grid.nodes[0], grid.xyz[0].data()));
  EXPECT_EQ(model::reportInvertedCells(model, 0, grid.nodes[0], grid.xyz[0].data()).cells, 0);
}

TEST(GridCheck, ExampleTemplatesPassAtSeveralDensities)
{
  for (const std::string& name : exampleTemplates())
  {
    const model::BlockModel model = model::loadTemplate(templatePath(name));
    for (double density : { 0.5, 1.0, 3.0 })
    {
      const Grid grid = meshAll(model, density);
      for (std::size_t b = 0; b < grid.nodes.size(); ++b)
      {
        EXPECT_EQ(model::reportInvertedCells(model, static_cast<int>(b), grid.nodes[b],
                    grid.xyz[b].data())
                    .cells,
          0)
          << name << " block " << b << " density " << density;
      }
    }
  }
}

// A density multiplier refines a graded block without changing its shape: the geometric
// law's overall expansion (last over first cell) stays, so the first cell is the template's
// divided by the multiplier (not by k^(n' - n) more).
TEST(GridCheck, DensityKeepsTheOverallExpansionOfGradedLaws)
{
  const model::BlockModel model =
    model::loadTemplate(templatePath("cylinder_in_box.yaml"), { { "n_radial", "8" } });
  const Grid coarse = meshAll(model, 1.0), fine = meshAll(model, 4.0);
  // block 0, the j line at i = 0, k = 0: from the cylinder wall outwards
  auto sizes = [](const Grid& grid) {
    const int n = grid.nodes[0][1];
    return std::make_pair((grid.at(0, 0, 1, 0) - grid.at(0, 0, 0, 0)).norm(),
      (grid.at(0, 0, n - 1, 0) - grid.at(0, 0, n - 2, 0)).norm());
  };
  const auto [firstCoarse, lastCoarse] = sizes(coarse);
  const auto [firstFine, lastFine] = sizes(fine);
  EXPECT_NEAR(lastCoarse / firstCoarse, lastFine / firstFine, 0.02 * lastCoarse / firstCoarse);
  EXPECT_NEAR(firstFine / firstCoarse, 0.25, 0.05);
}
