// Grid quality measured in parts (as MPI ranks do, with neighbour layers of the other
// blocks) and on threads equals the whole grid measured at once, bit for bit; meshing on
// threads equals meshing on one.
#include "InvertedCells.h"
#include "Parallel.h"
#include "Quality.h"
#include "Partition.h"
#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace blockforge
{
namespace
{
using model::BlockModel;

struct MeshedCase
{
  BlockModel model;
  test::Grid grid;
  model::Topology topology;
};

MeshedCase meshCase(const std::string& templateFile, const std::string& inf, double density)
{
  MeshedCase result;
  model::TemplateInputs inputs;
  if (!inf.empty())
  {
    inputs = test::readTemplateInputs(test::sourcePath(inf));
  }
  result.model = model::loadTemplate(
    test::sourcePath(templateFile), {}, inf.empty() ? nullptr : &inputs);
  model::MultiBlockMesher mesher(result.model, density);
  mesher.computeBoundaries();
  result.topology = mesher.topology();
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    result.grid.nodes.push_back(mesher.nodeCounts(b));
    const auto& n = result.grid.nodes.back();
    result.grid.xyz.emplace_back(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    mesher.meshBlock(b, result.grid.xyz.back().data());
  }
  return result;
}

StructuredBlock structured(const test::Grid& grid, int block)
{
  StructuredBlock b;
  b.xyz = grid.xyz[block].data();
  b.ni = grid.nodes[block][0];
  b.nj = grid.nodes[block][1];
  b.nk = grid.nodes[block][2];
  return b;
}

std::vector<CellQualityArrays> measureSubset(const MeshedCase& c, const std::vector<int>& subset)
{
  const model::QualityNeighbours neighbours = model::qualityNeighbours(c.topology, subset);
  std::vector<StructuredBlock> blocks;
  for (int b : subset)
  {
    blocks.push_back(structured(c.grid, b));
  }
  std::vector<std::vector<double>> storage(neighbours.layers.size());
  std::vector<NeighbourLayer> layers;
  for (std::size_t n = 0; n < neighbours.layers.size(); ++n)
  {
    const model::BlockFace& side = neighbours.layers[n];
    layers.push_back(
      { sideLayer(structured(c.grid, side.block), side.face, storage[n]), side.face });
  }
  std::vector<CellQualityArrays> quality(subset.size());
  std::vector<CellQualityPointers> outputs;
  for (std::size_t n = 0; n < subset.size(); ++n)
  {
    const long cells = static_cast<long>(blocks[n].ni - 1) * (blocks[n].nj - 1) * (blocks[n].nk - 1);
    CellQualityArrays& q = quality[n];
    for (auto* values : { &q.minAngle, &q.maxAngle, &q.nonOrthogonality, &q.skewness,
           &q.aspectRatio, &q.scaledJacobian, &q.cellDeterminant })
    {
      values->assign(cells, -1.0);
    }
    outputs.push_back({ q.minAngle.data(), q.maxAngle.data(), q.nonOrthogonality.data(),
      q.skewness.data(), q.aspectRatio.data(), q.scaledJacobian.data(),
      q.cellDeterminant.data() });
  }
  computeGridQuality(blocks, neighbours.links, layers, outputs);
  return quality;
}

std::vector<CellQualityArrays> measureAll(const MeshedCase& c)
{
  std::vector<int> all;
  for (std::size_t b = 0; b < c.grid.xyz.size(); ++b)
  {
    all.push_back(static_cast<int>(b));
  }
  std::vector<StructuredBlock> blocks;
  for (int b : all)
  {
    blocks.push_back(structured(c.grid, b));
  }
  return computeGridQuality(blocks, c.topology.periodicSideLinks());
}

/// Number of cells of `part` (blocks `subset` of the whole) that differ from `whole` in any
/// measure, bit for bit.
long differingCells(const std::vector<CellQualityArrays>& whole,
  const std::vector<CellQualityArrays>& part, const std::vector<int>& subset)
{
  long differing = 0;
  for (std::size_t n = 0; n < subset.size(); ++n)
  {
    const CellQualityArrays& a = whole[subset[n]];
    const CellQualityArrays& b = part[n];
    for (std::size_t cell = 0; cell < a.minAngle.size(); ++cell)
    {
      differing += !(test::sameBits(a.minAngle[cell], b.minAngle[cell]) &&
        test::sameBits(a.maxAngle[cell], b.maxAngle[cell]) &&
        test::sameBits(a.nonOrthogonality[cell], b.nonOrthogonality[cell]) &&
        test::sameBits(a.skewness[cell], b.skewness[cell]) &&
        test::sameBits(a.aspectRatio[cell], b.aspectRatio[cell]) &&
        test::sameBits(a.scaledJacobian[cell], b.scaledJacobian[cell]) &&
        test::sameBits(a.cellDeterminant[cell], b.cellDeterminant[cell]));
    }
  }
  return differing;
}

/// The subsets of a partition of `blocks` blocks: round robin over `parts`, and halves.
std::vector<std::vector<int>> partitions(int blocks)
{
  std::vector<std::vector<int>> subsets;
  for (int parts : { 2, 3 })
  {
    for (int p = 0; p < parts; ++p)
    {
      std::vector<int> subset;
      for (int b = p; b < blocks; b += parts)
      {
        subset.push_back(b);
      }
      subsets.push_back(subset);
    }
  }
  std::vector<int> low, high;
  for (int b = 0; b < blocks; ++b)
  {
    (b < blocks / 2 ? low : high).push_back(b);
  }
  subsets.push_back(low);
  subsets.push_back(high);
  for (int b = 0; b < blocks; ++b)
  {
    subsets.push_back({ b });
  }
  return subsets;
}

void expectPartsEqualWhole(const MeshedCase& c)
{
  const std::vector<CellQualityArrays> whole = measureAll(c);
  const int blocks = static_cast<int>(c.grid.xyz.size());
  for (const std::vector<int>& subset : partitions(blocks))
  {
    std::string name;
    for (int b : subset)
    {
      name += " " + c.model.blocks[b].name;
    }
    SCOPED_TRACE("blocks" + name);
    EXPECT_EQ(differingCells(whole, measureSubset(c, subset), subset), 0);
  }
}

using test::ThreadRunner;

TEST(Partition, DistributorPartsEqualWhole)
{
  // Interfaces between O and H blocks and periodic sides, 887 cells differed by up to 54
  // degrees when a rank measured its interfaces to the other rank's blocks as boundaries.
  expectPartsEqualWhole(
    meshCase("Templates/axial_passage_oh.yaml", "Data/distributor/BladeGen.inf", 1.0));
}

TEST(Partition, PeriodicAndDegenerateTemplatesPartsEqualWhole)
{
  for (const std::string& name : test::exampleTemplates())
  {
    SCOPED_TRACE(name);
    expectPartsEqualWhole(meshCase("Templates/" + name, "", 1.0));
  }
}

TEST(Partition, WithoutNeighboursInterfacesAreBoundaries)
{
  // The test must be able to fail: a part measured without its neighbours differs.
  const MeshedCase c =
    meshCase("Templates/axial_passage_oh.yaml", "Data/distributor/BladeGen.inf", 1.0);
  const std::vector<CellQualityArrays> whole = measureAll(c);
  std::vector<int> even;
  std::vector<StructuredBlock> blocks;
  for (int b = 0; b < static_cast<int>(c.grid.xyz.size()); b += 2)
  {
    even.push_back(b);
    blocks.push_back(structured(c.grid, b));
  }
  const std::vector<CellQualityArrays> alone = computeGridQuality(blocks);
  EXPECT_GT(differingCells(whole, alone, even), 100);
  // The cell determinant alone: an interface measured as a boundary loses its face.
  long determinants = 0;
  for (std::size_t n = 0; n < even.size(); ++n)
  {
    for (std::size_t cell = 0; cell < alone[n].cellDeterminant.size(); ++cell)
    {
      determinants += alone[n].cellDeterminant[cell] != whole[even[n]].cellDeterminant[cell];
    }
  }
  EXPECT_GT(determinants, 100);
}

TEST(Partition, NeighboursOfSubsets)
{
  const MeshedCase c = meshCase("Templates/annular_sector.yaml", "", 1.0);
  const int blocks = static_cast<int>(c.grid.xyz.size());
  std::vector<int> all;
  for (int b = 0; b < blocks; ++b)
  {
    all.push_back(b);
  }
  const model::QualityNeighbours none = model::qualityNeighbours(c.topology, all);
  EXPECT_TRUE(none.layers.empty());
  EXPECT_EQ(none.links.size(), c.topology.periodic.size());
  const model::QualityNeighbours first = model::qualityNeighbours(c.topology, { 0 });
  for (const model::BlockFace& side : first.layers)
  {
    EXPECT_NE(side.block, 0);
  }
  for (const PeriodicSideLink& link : first.links)
  {
    EXPECT_TRUE(link.sourceBlock == 0 || link.imageBlock == 0);
    EXPECT_GE(link.sourceBlock, 0);
    EXPECT_GE(link.imageBlock, 0);
  }
}

TEST(Partition, SideLayerKeepsTheSideCells)
{
  const MeshedCase c = meshCase("Templates/cylinder_in_box.yaml", "", 1.0);
  const StructuredBlock block = structured(c.grid, 0);
  for (int side = 0; side < 6; ++side)
  {
    std::vector<double> nodes;
    const StructuredBlock layer = sideLayer(block, side, nodes);
    const int counts[3] = { layer.ni, layer.nj, layer.nk };
    EXPECT_EQ(counts[side / 2], 2);
    // Node (0, 0, 0) of the layer is the block's node at the side's lowest corner.
    const int i = side == 1 ? block.ni - 2 : 0;
    const int j = side == 3 ? block.nj - 2 : 0;
    const int k = side == 5 ? block.nk - 2 : 0;
    EXPECT_TRUE(test::sameBits(Vec3(layer.xyz[0], layer.xyz[1], layer.xyz[2]), c.grid.at(0, i, j, k)));
  }
  std::vector<double> nodes;
  EXPECT_THROW(sideLayer(block, 6, nodes), GeometryError);
}

TEST(Threads, QualityAndMeshingOnThreadsEqualOneThread)
{
  for (const auto& c : { std::make_pair(std::string("Templates/cylinder_in_box.yaml"), std::string()),
         std::make_pair(std::string("Templates/axial_passage_oh.yaml"),
           std::string("Data/distributor/BladeGen.inf")) })
  {
    SCOPED_TRACE(c.first);
    const MeshedCase serial = meshCase(c.first, c.second, 2.0);
    const std::vector<CellQualityArrays> serialQuality = measureAll(serial);
    for (int threads : { 2, 3 })
    {
      SCOPED_TRACE(std::to_string(threads) + " threads");
      ThreadRunner runner(threads);
      const MeshedCase threaded = meshCase(c.first, c.second, 2.0);
      for (std::size_t b = 0; b < serial.grid.xyz.size(); ++b)
      {
        EXPECT_TRUE(test::sameBits(serial.grid.xyz[b], threaded.grid.xyz[b])) << "block " << b;
      }
      std::vector<int> all;
      for (std::size_t b = 0; b < serial.grid.xyz.size(); ++b)
      {
        all.push_back(static_cast<int>(b));
      }
      EXPECT_EQ(differingCells(serialQuality, measureAll(threaded), all), 0);
      // Parts on threads too.
      EXPECT_EQ(differingCells(serialQuality, measureSubset(threaded, { 0, 2 }), { 0, 2 }), 0);
    }
  }
}

TEST(Threads, ChunksAreUsedAndErrorsPropagate)
{
  ThreadRunner runner(2);
  EXPECT_EQ(chunkThreads(), 2);
  EXPECT_EQ(chunkCount(1000, 1, 1000), 8);
  EXPECT_EQ(chunkCount(1000, 1, 3), 3);
  std::vector<int> done(8, 0);
  forEachChunk(8, [&](long chunk) { done[chunk] = 1; });
  EXPECT_EQ(std::count(done.begin(), done.end(), 1), 8);
  EXPECT_THROW(forEachChunk(4,
                 [](long chunk)
                 {
                   if (chunk == 2)
                   {
                     throw GeometryError("chunk 2");
                   }
                 }),
    GeometryError);
}

/// Each share of a partition, meshed by a mesher that computes only the share's boundary
/// (what an MPI rank does), gives the share's blocks the same bits as meshing them all.
void expectSharesMeshLikeWhole(const std::string& templateFile, const std::string& inf)
{
  const MeshedCase whole = meshCase(templateFile, inf, 1.5);
  model::TemplateInputs inputs;
  if (!inf.empty())
  {
    inputs = test::readTemplateInputs(test::sourcePath(inf));
  }
  const BlockModel blockModel = model::loadTemplate(
    test::sourcePath(templateFile), {}, inf.empty() ? nullptr : &inputs);
  const int blocks = static_cast<int>(whole.grid.xyz.size());
  for (const std::vector<int>& share : partitions(blocks))
  {
    model::MultiBlockMesher mesher(blockModel, 1.5);
    mesher.computeBoundaries(share);
    for (int b : share)
    {
      const auto n = mesher.nodeCounts(b);
      std::vector<double> xyz(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
      mesher.meshBlock(b, xyz.data());
      EXPECT_TRUE(test::sameBits(xyz, whole.grid.xyz[b])) << "block " << b;
    }
    for (int b = 0; b < blocks; ++b)
    {
      if (std::find(share.begin(), share.end(), b) == share.end())
      {
        std::vector<double> xyz(3 * whole.grid.xyz[b].size());
        EXPECT_THROW(mesher.meshBlock(b, xyz.data()), std::logic_error) << "block " << b;
      }
    }
  }
}

TEST(Partition, SharesMeshTheirBlocksLikeTheWhole)
{
  // Periodic faces (images rotated from sources on other ranks), O/H interfaces, surface
  // faces on the blade, hub and shroud; periodic edges; a degenerate (wedge) block.
  expectSharesMeshLikeWhole("Templates/axial_passage_oh.yaml", "Data/distributor/BladeGen.inf");
  for (const std::string& name : test::exampleTemplates())
  {
    SCOPED_TRACE(name);
    expectSharesMeshLikeWhole("Templates/" + name, "");
  }
}

TEST(Threads, InvertedCellCheckOnThreadsEqualsOneThread)
{
  // A block folded in two places (k-layers far apart, so different chunks): the count,
  // the index range and the worst cell must not depend on the chunks.
  const int ni = 9, nj = 7, nk = 40;
  std::vector<double> xyz(3 * static_cast<std::size_t>(ni) * nj * nk);
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i)
      {
        double* p = &xyz[3 * ((static_cast<std::size_t>(k) * nj + j) * ni + i)];
        p[0] = i;
        p[1] = j;
        p[2] = k;
      }
  auto push = [&](int i, int j, int k, double dz) {
    xyz[3 * ((static_cast<std::size_t>(k) * nj + j) * ni + i) + 2] += dz;
  };
  push(3, 2, 5, 1.6);   // node pushed through the next layer: folds cells of layers 4, 5
  push(6, 4, 33, -1.9); // and deeper at layers 32, 33
  const InvertedCells one = findInvertedCells(xyz.data(), ni, nj, nk);
  ASSERT_GT(one.count, 0);
  EXPECT_LT(one.lowest[2], 10);
  EXPECT_GT(one.highest[2], 30);
  for (int threads : { 2, 3 })
  {
    ThreadRunner runner(threads);
    const InvertedCells many = findInvertedCells(xyz.data(), ni, nj, nk);
    EXPECT_EQ(many.count, one.count);
    EXPECT_EQ(many.nonFinite, one.nonFinite);
    EXPECT_EQ(many.lowest, one.lowest);
    EXPECT_EQ(many.highest, one.highest);
    EXPECT_EQ(many.worstCell, one.worstCell);
    EXPECT_TRUE(test::sameBits(many.worstScaledJacobian, one.worstScaledJacobian));
  }
}

TEST(Threads, SequentialByDefault)
{
  EXPECT_EQ(chunkThreads(), 1);
  EXPECT_EQ(chunkCount(1L << 40, 1, 1000), 1);
}
} // namespace
} // namespace blockforge
