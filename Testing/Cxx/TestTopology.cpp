// The public topology of a block model (Topology.h) and what the quality measures make of
// it: interfaces with their index transforms, periodic pairs with their rotation, patches,
// and non-orthogonality and skewness across periodic faces against closed forms.
#include "TestHelpers.h"
#include "Topology.h"

#include "../../Filters/Core/Quality.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
constexpr double Degrees = 180.0 / test::Pi;

std::string dataPath(const std::string& name)
{
  return test::sourcePath("Testing/Data/" + name);
}

std::vector<StructuredBlock> structuredBlocks(const test::Grid& grid)
{
  std::vector<StructuredBlock> blocks;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  return blocks;
}
} // namespace

TEST(Topology, TwoBlocksShareOneFace)
{
  const BlockModel model = loadTemplate(dataPath("two_blocks.yaml"));
  const Topology topology = buildTopology(model);
  ASSERT_EQ(topology.blocks.size(), 2u);
  // 12 + 12 edges, 4 shared; 6 + 6 faces, 1 shared.
  EXPECT_EQ(topology.edges.size(), 20u);
  EXPECT_EQ(topology.faces.size(), 11u);
  const std::vector<Interface> interfaces = topology.interfaces();
  ASSERT_EQ(interfaces.size(), 1u);
  EXPECT_EQ(interfaces[0].first, (BlockFace{ 0, 1 }));  // left.i1
  EXPECT_EQ(interfaces[0].second, (BlockFace{ 1, 0 })); // right.i0
  EXPECT_EQ(interfaces[0].transform.code, 0);
  EXPECT_TRUE(topology.periodic.empty());
  EXPECT_EQ(topology.patchOfFace[6 * 0 + 0], 0); // left.i0: inlet
  EXPECT_EQ(topology.patchOfFace[6 * 1 + 1], 1); // right.i1: outlet
  EXPECT_EQ(topology.patchOfFace[6 * 0 + 2], -1);
  // Every block of every edge use agrees with the block's own links.
  for (std::size_t e = 0; e < topology.edges.size(); ++e)
  {
    for (const EdgeUse& use : topology.edges[e].uses)
    {
      EXPECT_EQ(topology.blocks[use.block].edge[use.localEdge], static_cast<int>(e));
    }
  }
}

TEST(Topology, FlippedNeighbourGetsItsTransform)
{
  // The right block listed upside down (turned by 180 degrees about x): its i0 face meets
  // left.i1 with both face directions reversed.
  const std::string text = test::replaced(test::readText(dataPath("two_blocks.yaml")),
    "vertices: [a1, b1, b2, a2, a5, b5, b6, a6]", "vertices: [a6, b6, b5, a5, a2, b2, b1, a1]");
  const BlockModel model = parseTemplate(text, "two_blocks_flipped.yaml");
  const Topology topology = buildTopology(model);
  const std::vector<Interface> interfaces = topology.interfaces();
  ASSERT_EQ(interfaces.size(), 1u);
  const FaceTransform t = interfaces[0].transform;
  EXPECT_FALSE(t.swap());
  EXPECT_TRUE(t.flipA());
  EXPECT_TRUE(t.flipB());
  // The transform maps the right block's face nodes onto the left block's, node for node.
  const test::Grid grid = test::meshAll(model);
  const int n = grid.nodes[0][1];
  for (int b = 0; b < n; ++b)
  {
    for (int a = 0; a < n; ++a)
    {
      int la = 0, lb = 0;
      t.map(a, b, n, n, la, lb);
      EXPECT_TRUE(test::sameBits(grid.at(1, 0, a, b), grid.at(0, n - 1, la, lb)));
    }
  }
}

TEST(Topology, AnnularSectorPeriodicPairs)
{
  const BlockModel model = loadTemplate(test::templatePath("annular_sector.yaml"));
  const Topology topology = buildTopology(model);
  ASSERT_EQ(topology.periodic.size(), 2u);
  EXPECT_EQ(topology.interfaces().size(), 7u); // 2 x 3 blocks: 3 radial + 2 x 2 around
  const test::Grid grid = test::meshAll(model);
  for (const PeriodicPair& pair : topology.periodic)
  {
    EXPECT_EQ(model.patches[pair.patch].name, "periodic_low");
    EXPECT_EQ(model.patches[pair.partner].name, "periodic_high");
    EXPECT_NEAR(pair.angle, 30.0 / Degrees, 1e-15);
    EXPECT_NEAR((pair.axis - Vec3::UnitZ()).norm(), 0.0, 1e-15);
    // Every node of the image face is the rotated source node the transform names.
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(pair.angle, pair.axis).toRotationMatrix();
    const auto& imageNodes = grid.nodes[pair.imageFace.block];
    const auto& sourceNodes = grid.nodes[pair.sourceFace.block];
    const std::array<int, 2> imageDirs = faceDirections(pair.imageFace.face);
    const std::array<int, 2> sourceDirs = faceDirections(pair.sourceFace.face);
    auto node = [&](const BlockFace& face, const std::array<int, 3>& n,
                  const std::array<int, 2>& dirs, int a, int b) {
      std::array<int, 3> ijk{};
      ijk[face.face / 2] = face.face % 2 == 0 ? 0 : n[face.face / 2] - 1;
      ijk[dirs[0]] = a;
      ijk[dirs[1]] = b;
      return grid.at(face.block, ijk[0], ijk[1], ijk[2]);
    };
    for (int b = 0; b < imageNodes[imageDirs[1]]; ++b)
    {
      for (int a = 0; a < imageNodes[imageDirs[0]]; ++a)
      {
        int sa = 0, sb = 0;
        pair.transform.map(
          a, b, sourceNodes[sourceDirs[0]], sourceNodes[sourceDirs[1]], sa, sb);
        const Vec3 rotated = pair.axisPoint +
          rotation * (node(pair.sourceFace, sourceNodes, sourceDirs, sa, sb) - pair.axisPoint);
        EXPECT_NEAR(
          (rotated - node(pair.imageFace, imageNodes, imageDirs, a, b)).norm(), 0.0, 1e-12);
      }
    }
  }
  // The links the quality measures take: one per pair, and they fit the grid.
  const std::vector<PeriodicSideLink> links = topology.periodicSideLinks();
  ASSERT_EQ(links.size(), 2u);
  for (const PeriodicSideLink& link : links)
  {
    EXPECT_TRUE(periodicSidesMatch(structuredBlocks(grid), link));
  }
}

TEST(Topology, MesherHandsOutItsTopologyAtItsDensity)
{
  const BlockModel model = loadTemplate(test::templatePath("annular_sector.yaml"));
  MultiBlockMesher mesher(model, 2.0);
  mesher.computeBoundaries();
  const Topology& topology = mesher.topology();
  EXPECT_EQ(topology.periodic.size(), 2u);
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    EXPECT_EQ(topology.blocks[b].nodes, mesher.nodeCounts(b));
  }
}

TEST(Topology, PeriodicFacesAreMeasuredLikeInteriorFaces)
{
  const BlockModel model = loadTemplate(dataPath("sheared_periodic.yaml"));
  const double c = test::parameter(model, "c");
  const int ni = 2, nj = 4, nk = 4;
  const double dy = test::parameter(model, "h") / nj, dz = 1.0 / nk;
  const test::Grid grid = test::meshAll(model);
  const std::vector<StructuredBlock> blocks = structuredBlocks(grid);
  const Topology topology = buildTopology(model);
  ASSERT_EQ(topology.periodic.size(), 1u);
  const auto linked = computeGridQuality(blocks, topology.periodicSideLinks());
  const auto unlinked = computeGridQuality(blocks);

  // Closed forms for the low box's cells on the periodic face (see the template): the
  // owner-neighbour line d = (0, -dy, c dy / 2) leans atan(c / 2) from the face normal and
  // crosses the face c dy / 4 from its centre; checkMesh divides by
  // max(0.2 |d|, largest corner projection = dz / 2).
  const double nonOrthogonality = std::atan(c / 2.0) * Degrees;
  const double d = dy * std::sqrt(1.0 + c * c / 4.0);
  const double skewness = (c * dy / 4.0) / std::max(0.2 * d, dz / 2.0);
  const int low = model.findBlock("low"), high = model.findBlock("high");
  for (int k = 0; k < nk; ++k)
  {
    for (int j = 0; j < nj; ++j)
    {
      for (int i = 0; i < ni; ++i)
      {
        const int cell = i + ni * (j + nj * k);
        SCOPED_TRACE("low cell " + std::to_string(i) + " " + std::to_string(j) + " " +
          std::to_string(k));
        // The low box is an orthogonal box: nothing but the periodic face is skewed.
        EXPECT_NEAR(linked[low].nonOrthogonality[cell], j == 0 ? nonOrthogonality : 0.0, 1e-9);
        EXPECT_NEAR(linked[low].skewness[cell], j == 0 ? skewness : 0.0, 1e-12);
        EXPECT_NEAR(unlinked[low].nonOrthogonality[cell], 0.0, 1e-9);
        EXPECT_NEAR(unlinked[low].skewness[cell], 0.0, 1e-12);
        // The sheared box: its k faces lean atan(c) everywhere, more than the periodic
        // faces; across the periodic face its cells see the same skewness.
        EXPECT_NEAR(linked[high].nonOrthogonality[cell], std::atan(c) * Degrees, 1e-9);
        if (j == nj - 1)
        {
          EXPECT_GE(linked[high].skewness[cell], skewness - 1e-12);
        }
        else
        {
          EXPECT_EQ(linked[high].skewness[cell], unlinked[high].skewness[cell]);
        }
      }
    }
  }
  EXPECT_GT(nonOrthogonality, 26.0); // not a vacuous test
}

TEST(Topology, QualityRejectsALinkThatDoesNotFitTheGrid)
{
  const BlockModel model = loadTemplate(dataPath("sheared_periodic.yaml"));
  const test::Grid grid = test::meshAll(model);
  std::vector<PeriodicSideLink> links = buildTopology(model).periodicSideLinks();
  links[0].rotation = Eigen::AngleAxisd(0.5, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_FALSE(periodicSidesMatch(structuredBlocks(grid), links[0]));
  EXPECT_THROW(computeGridQuality(structuredBlocks(grid), links), GeometryError);
}
