// Multiblock mesher (Filters/Model/Mesher.h) on the example templates: geometry of the
// boundary nodes, bit-identical shared faces, density multiplier and preview cap,
// determinism, periodicity, degenerate wedges and total volume.
#include "Mesher.h"
#include "ModelDocument.h"
#include "Quality.h"
#include "Template.h"

#include <Eigen/Geometry>
#include "TestHelpers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <map>
#include <set>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
using test::parameter;
using test::Pi;
using test::templatePath;

const std::vector<std::string>& ExampleTemplates = test::exampleTemplates();

/// One block of a grid, with the accessors these tests use (same layout as test::Grid).
struct BlockGrid
{
  int ni = 0, nj = 0, nk = 0;
  std::vector<double> xyz;
  Vec3 node(int i, int j, int k) const
  {
    const std::size_t n = static_cast<std::size_t>(i) + ni * (j + static_cast<std::size_t>(nj) * k);
    return Vec3(xyz[3 * n], xyz[3 * n + 1], xyz[3 * n + 2]);
  }
  const double* raw(int i, int j, int k) const
  {
    return &xyz[3 * (static_cast<std::size_t>(i) + ni * (j + static_cast<std::size_t>(nj) * k))];
  }
  std::size_t cellCount() const
  {
    return static_cast<std::size_t>(ni - 1) * (nj - 1) * (nk - 1);
  }
  std::array<Vec3, 8> cell(int i, int j, int k) const
  {
    return { node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
      node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
      node(i, j + 1, k + 1) };
  }
};

/// test::meshAll(model, multiplier, cap), one BlockGrid per block.
std::vector<BlockGrid> meshBlocks(const BlockModel& model, double multiplier = 1.0, int cap = 0)
{
  test::Grid grid = test::meshAll(model, multiplier, cap);
  std::vector<BlockGrid> blocks(grid.nodes.size());
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    blocks[b].ni = grid.nodes[b][0];
    blocks[b].nj = grid.nodes[b][1];
    blocks[b].nk = grid.nodes[b][2];
    blocks[b].xyz = std::move(grid.xyz[b]);
  }
  return blocks;
}

/// Pointers to the nodes of one block face, in the face's (a, b) order.
std::vector<const double*> faceNodes(const BlockGrid& g, int face)
{
  std::vector<const double*> nodes;
  const int fixedI = face == 0 ? 0 : g.ni - 1, fixedJ = face == 2 ? 0 : g.nj - 1,
            fixedK = face == 4 ? 0 : g.nk - 1;
  for (int k = 0; k < g.nk; ++k)
    for (int j = 0; j < g.nj; ++j)
      for (int i = 0; i < g.ni; ++i)
      {
        const bool on = (face < 2 && i == fixedI) || (face >= 2 && face < 4 && j == fixedJ) ||
          (face >= 4 && k == fixedK);
        if (on)
        {
          nodes.push_back(g.raw(i, j, k));
        }
      }
  return nodes;
}

/// Node coordinates of a face, sorted lexicographically: compares faces whatever their
/// orientation in the two blocks.
std::vector<std::array<double, 3>> sortedFaceNodes(const BlockGrid& g, int face)
{
  std::vector<std::array<double, 3>> nodes;
  for (const double* p : faceNodes(g, face))
  {
    nodes.push_back({ p[0], p[1], p[2] });
  }
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

std::vector<Vec3> patchNodes(
  const BlockModel& model, const std::vector<BlockGrid>& grids, const std::string& name)
{
  std::vector<Vec3> nodes;
  for (const Patch& patch : model.patches)
  {
    if (patch.name != name)
    {
      continue;
    }
    for (const BlockFace& face : patch.faces)
    {
      for (const double* p : faceNodes(grids[face.block], face.face))
      {
        nodes.emplace_back(p[0], p[1], p[2]);
      }
    }
    return nodes;
  }
  ADD_FAILURE() << "no patch " << name;
  return nodes;
}

/// Hexahedron volume by 6 tetrahedra about the diagonal V0-V6.
double hexVolume(const std::array<Vec3, 8>& p)
{
  static const int tets[6][4] = { { 0, 1, 2, 6 }, { 0, 2, 3, 6 }, { 0, 3, 7, 6 },
    { 0, 7, 4, 6 }, { 0, 4, 5, 6 }, { 0, 5, 1, 6 } };
  double volume = 0.0;
  for (const auto& t : tets)
  {
    volume += (p[t[1]] - p[t[0]]).dot((p[t[2]] - p[t[0]]).cross(p[t[3]] - p[t[0]])) / 6.0;
  }
  return volume;
}

double gridVolume(const std::vector<BlockGrid>& grids)
{
  double volume = 0.0;
  for (const BlockGrid& g : grids)
    for (int k = 0; k + 1 < g.nk; ++k)
      for (int j = 0; j + 1 < g.nj; ++j)
        for (int i = 0; i + 1 < g.ni; ++i)
        {
          volume += hexVolume(g.cell(i, j, k));
        }
  return volume;
}

/// Pairs of (block, face) whose four corners are the same vertices (>= 3 distinct).
std::vector<std::pair<BlockFace, BlockFace>> sharedFaces(const BlockModel& model)
{
  std::map<std::vector<int>, std::vector<BlockFace>> byVertices;
  for (int b = 0; b < static_cast<int>(model.blocks.size()); ++b)
  {
    for (int f = 0; f < 6; ++f)
    {
      std::vector<int> ids;
      for (int corner : faceCorners(f))
      {
        ids.push_back(model.blocks[b].vertices[corner]);
      }
      std::sort(ids.begin(), ids.end());
      if (std::set<int>(ids.begin(), ids.end()).size() >= 3)
      {
        byVertices[ids].push_back(BlockFace{ b, f });
      }
    }
  }
  std::vector<std::pair<BlockFace, BlockFace>> pairs;
  for (const auto& entry : byVertices)
  {
    if (entry.second.size() == 2)
    {
      pairs.emplace_back(entry.second[0], entry.second[1]);
    }
  }
  return pairs;
}

bool identical(const std::vector<BlockGrid>& a, const std::vector<BlockGrid>& b)
{
  if (a.size() != b.size())
  {
    return false;
  }
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    if (!test::sameBits(a[i].xyz, b[i].xyz))
    {
      return false;
    }
  }
  return true;
}

/// Law `match` with ratio 1.2 (the matched-edge tests).
DistributionLaw matchLaw()
{
  DistributionLaw match;
  match.kind = DistributionLaw::Kind::Match;
  match.expansionRatio = 1.2;
  return match;
}

/// Testing/Data/two_blocks.yaml (two unit cubes along x) with 4 cells across the left cube
/// and 16 across the right one, every edge along x graded matchLaw(), the right block's
/// with at_most `rightAtMost` (0: no limit).
BlockModel twoCubesMatchedAlongX(double rightAtMost)
{
  BlockModel model = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  model.blocks[1].cells[0] = 16;
  for (std::size_t b = 0; b < model.blocks.size(); ++b)
  {
    for (int e = 0; e < 12; ++e)
    {
      if (edgeDirection(e) == 0)
      {
        model.blocks[b].laws[e] = matchLaw();
        model.blocks[b].laws[e].matchAtMost = b == 1 ? rightAtMost : 0.0;
      }
    }
  }
  return model;
}
} // namespace

TEST(Mesher, CylinderWallNodesAtRadius)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  const auto grids = meshBlocks(model);
  const double R = parameter(model, "R");
  const std::vector<Vec3> wall = patchNodes(model, grids, "cylinder");
  ASSERT_EQ(wall.size(), 4u * 17 * 9);
  for (const Vec3& p : wall)
  {
    EXPECT_LT(std::abs(std::hypot(p.x(), p.y()) - R) / R, 1e-9) << p.transpose();
  }
}

TEST(Mesher, CylinderBoxNodesOnTheBox)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  const auto grids = meshBlocks(model);
  const double B = parameter(model, "B"), D = parameter(model, "D");
  for (const auto& side : std::vector<std::pair<std::string, int>>{
         { "inlet", 0 }, { "outlet", 0 }, { "top", 1 }, { "bottom", 1 } })
  {
    const std::vector<Vec3> nodes = patchNodes(model, grids, side.first);
    ASSERT_EQ(nodes.size(), 17u * 9) << side.first;
    for (const Vec3& p : nodes)
    {
      EXPECT_LT(std::abs(std::abs(p[side.second]) - B), 1e-12) << side.first << p.transpose();
      EXPECT_LE(std::max(std::abs(p.x()), std::abs(p.y())), B + 1e-12);
    }
  }
  for (const Vec3& p : patchNodes(model, grids, "front"))
  {
    EXPECT_LT(std::abs(p.z()), 1e-12);
  }
  for (const Vec3& p : patchNodes(model, grids, "back"))
  {
    EXPECT_LT(std::abs(p.z() - D), 1e-12);
  }
}

TEST(Mesher, EdgeNodesFollowTheLaws)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  const auto grids = meshBlocks(model);
  const BlockGrid& north = grids[model.findBlock("north")];
  const double kWall = parameter(model, "k_wall");
  // The radial edge w_ne0 -> b_ne0 (north's E2): geometric, each cell k_wall times the last.
  for (int j = 1; j + 1 < north.nj; ++j)
  {
    const double before = (north.node(north.ni - 1, j, 0) - north.node(north.ni - 1, j - 1, 0)).norm();
    const double after = (north.node(north.ni - 1, j + 1, 0) - north.node(north.ni - 1, j, 0)).norm();
    EXPECT_NEAR(after / before, kWall, 1e-9);
  }
  // The wall arc: uniform in arc length, so in angle.
  const double step = (Pi / 2) / (north.ni - 1);
  for (int i = 0; i + 1 < north.ni; ++i)
  {
    const Vec3 a = north.node(i, 0, 0), b = north.node(i + 1, 0, 0);
    const double angle = std::atan2(a.y(), a.x()) - std::atan2(b.y(), b.x());
    EXPECT_NEAR(angle, step, 1e-12);
  }
}

TEST(Mesher, CornerNodesAreTheVertices)
{
  for (const std::string& name : ExampleTemplates)
  {
    const BlockModel model = loadTemplate(templatePath(name));
    const auto grids = meshBlocks(model);
    for (std::size_t b = 0; b < grids.size(); ++b)
    {
      const BlockGrid& g = grids[b];
      const int is[8] = { 0, g.ni - 1, g.ni - 1, 0, 0, g.ni - 1, g.ni - 1, 0 };
      const int js[8] = { 0, 0, g.nj - 1, g.nj - 1, 0, 0, g.nj - 1, g.nj - 1 };
      const int ks[8] = { 0, 0, 0, 0, g.nk - 1, g.nk - 1, g.nk - 1, g.nk - 1 };
      for (int v = 0; v < 8; ++v)
      {
        const Vec3& vertex = model.vertices[model.blocks[b].vertices[v]].position;
        EXPECT_EQ(0, std::memcmp(g.raw(is[v], js[v], ks[v]), vertex.data(), 3 * sizeof(double)))
          << name << " block " << model.blocks[b].name << " V" << v;
      }
    }
  }
}

TEST(Mesher, SharedFacesAreBitIdentical)
{
  for (const std::string& name : ExampleTemplates)
  {
    const BlockModel model = loadTemplate(templatePath(name));
    for (double multiplier : { 1.0, 2.0 })
    {
      const auto grids = meshBlocks(model, multiplier);
      const auto pairs = sharedFaces(model);
      EXPECT_FALSE(pairs.empty()) << name;
      for (const auto& pair : pairs)
      {
        const auto a = sortedFaceNodes(grids[pair.first.block], pair.first.face);
        const auto b = sortedFaceNodes(grids[pair.second.block], pair.second.face);
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])))
          << name << ": " << model.blocks[pair.first.block].name << "."
          << faceName(pair.first.face) << " vs " << model.blocks[pair.second.block].name << "."
          << faceName(pair.second.face);
      }
    }
  }
}

TEST(Mesher, DensityMultiplierAndCap)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  {
    MultiBlockMesher mesher(model, 2.0);
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      const std::array<int, 3> n = mesher.nodeCounts(b);
      for (int d = 0; d < 3; ++d)
      {
        EXPECT_EQ(n[d], 2 * model.blocks[b].cells[d] + 1);
      }
    }
  }
  {
    MultiBlockMesher mesher(model, 0.3); // 16 -> 5 (4.8), 8 -> 2 (2.4)
    EXPECT_EQ(mesher.nodeCounts(0), (std::array<int, 3>{ 6, 6, 3 }));
  }
  {
    MultiBlockMesher mesher(model, 0.001); // never fewer than one cell
    EXPECT_EQ(mesher.nodeCounts(0), (std::array<int, 3>{ 2, 2, 2 }));
  }
  {
    MultiBlockMesher mesher(model, 1.0);
    mesher.setCellCap(4);
    EXPECT_EQ(mesher.nodeCounts(0), (std::array<int, 3>{ 5, 5, 5 }));
    mesher.computeBoundaries();
    std::vector<double> xyz(3 * 5 * 5 * 5);
    mesher.meshBlock(0, xyz.data());
    for (double v : xyz)
    {
      EXPECT_TRUE(std::isfinite(v));
    }
  }
  // A preview cap where the first-cell law cannot fit any more falls back, not fails.
  const BlockModel annulus = loadTemplate(templatePath("annular_sector.yaml"));
  EXPECT_NO_THROW(meshBlocks(annulus, 1.0, 3));
  EXPECT_NO_THROW(meshBlocks(annulus, 0.2));
}

TEST(Mesher, DensityMultiplierKeepsMinCells)
{
  // min_cells: the fewest cells a multiplier below 1 leaves, never more than cells. The
  // left box keeps 5 of its 6 cells along i (not shared with the right box); along j, which
  // the boxes share, both keep their 4 (the left box's 9 counts as its 4 cells); k and the
  // right box's i have no floor.
  const std::string text = R"yaml(blockforge: 1
name: floors
vertices:
  a0: [0, 0, 0]
  a1: [1, 0, 0]
  a2: [1, 1, 0]
  a3: [0, 1, 0]
  a4: [0, 0, 1]
  a5: [1, 0, 1]
  a6: [1, 1, 1]
  a7: [0, 1, 1]
  b1: [2, 0, 0]
  b2: [2, 1, 0]
  b5: [2, 0, 1]
  b6: [2, 1, 1]
blocks:
  left: {vertices: [a0, a1, a2, a3, a4, a5, a6, a7], cells: [6, 4, 6], min_cells: [5, 9, 1]}
  right: {vertices: [a1, b1, b2, a2, a5, b5, b6, a6], cells: [6, 4, 6], min_cells: [1, 4, 1]}
)yaml";
  const BlockModel model = parseTemplate(text, "floors.yaml");
  const std::vector<std::pair<double, std::array<std::array<int, 3>, 2>>> expected = {
    { 1.0, { { { 7, 5, 7 }, { 7, 5, 7 } } } },    // the template's counts
    { 2.0, { { { 13, 9, 13 }, { 13, 9, 13 } } } }, // refined: floors play no part
    { 0.5, { { { 6, 5, 4 }, { 4, 5, 4 } } } },     // i: 3 -> 5 on the left; j: 2 -> 4
    { 0.1, { { { 6, 5, 2 }, { 2, 5, 2 } } } },     // never fewer than one cell
  };
  for (const auto& [density, nodes] : expected)
  {
    SCOPED_TRACE(density);
    MultiBlockMesher mesher(model, density);
    EXPECT_EQ(mesher.nodeCounts(0), nodes[0]);
    EXPECT_EQ(mesher.nodeCounts(1), nodes[1]);
    const auto grids = meshBlocks(model, density);
    ASSERT_EQ(grids.size(), 2u);
    EXPECT_EQ(grids[0].ni, nodes[0][0]);
  }
}

TEST(Mesher, Deterministic)
{
  for (const std::string& name : ExampleTemplates)
  {
    const BlockModel model = loadTemplate(templatePath(name));
    const auto first = meshBlocks(model);
    const auto second = meshBlocks(model);
    EXPECT_TRUE(identical(first, second)) << name;

    // Blocks meshed concurrently, in reverse order, from one mesher: the same doubles.
    MultiBlockMesher mesher(model);
    mesher.computeBoundaries();
    std::vector<BlockGrid> parallel(mesher.blockCount());
    std::vector<std::future<void>> jobs;
    for (int b = mesher.blockCount() - 1; b >= 0; --b)
    {
      const std::array<int, 3> n = mesher.nodeCounts(b);
      parallel[b].ni = n[0];
      parallel[b].nj = n[1];
      parallel[b].nk = n[2];
      parallel[b].xyz.resize(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
      jobs.push_back(std::async(std::launch::async,
        [&mesher, &parallel, b] { mesher.meshBlock(b, parallel[b].xyz.data()); }));
    }
    for (auto& job : jobs)
    {
      job.get();
    }
    EXPECT_TRUE(identical(first, parallel)) << name;
  }
}

TEST(Mesher, AnnularSectorIsPeriodic)
{
  const BlockModel model = loadTemplate(templatePath("annular_sector.yaml"));
  const auto grids = meshBlocks(model);
  const double theta = parameter(model, "theta");
  const double size = parameter(model, "r_out");
  const std::vector<Vec3> low = patchNodes(model, grids, "periodic_low");
  const std::vector<Vec3> high = patchNodes(model, grids, "periodic_high");
  ASSERT_EQ(low.size(), high.size());
  ASSERT_FALSE(low.empty());
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(theta, Vec3::UnitZ()).toRotationMatrix();
  for (const Vec3& p : low)
  {
    const Vec3 image = rotation * p;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& q : high)
    {
      nearest = std::min(nearest, (image - q).norm());
    }
    EXPECT_LT(nearest / size, 1e-9) << p.transpose();
  }
  // Inner and outer walls are on their radii.
  for (const Vec3& p : patchNodes(model, grids, "inner"))
  {
    EXPECT_NEAR(std::hypot(p.x(), p.y()), parameter(model, "r_in"), 1e-12);
  }
  for (const Vec3& p : patchNodes(model, grids, "outer"))
  {
    EXPECT_NEAR(std::hypot(p.x(), p.y()), parameter(model, "r_out"), 1e-12);
  }
  // The first cell at the inner wall has the requested height.
  const BlockGrid& in1 = grids[model.findBlock("in_1")];
  EXPECT_NEAR((in1.node(1, 0, 0) - in1.node(0, 0, 0)).norm(), parameter(model, "h_wall"), 1e-12);
  const double expected = theta / 2 *
    (std::pow(parameter(model, "r_out"), 2) - std::pow(parameter(model, "r_in"), 2)) *
    parameter(model, "H");
  EXPECT_NEAR(gridVolume(grids) / expected, 1.0, 0.01);
}

TEST(Mesher, WedgeMeshesWithoutInvertedCells)
{
  const BlockModel model = loadTemplate(templatePath("wedge_sector.yaml"));
  for (double multiplier : { 1.0, 2.0 })
  {
    const auto grids = meshBlocks(model, multiplier);
    std::size_t cells = 0;
    for (const BlockGrid& g : grids)
    {
      for (double v : g.xyz)
      {
        ASSERT_TRUE(std::isfinite(v));
      }
      for (int k = 0; k + 1 < g.nk; ++k)
        for (int j = 0; j + 1 < g.nj; ++j)
          for (int i = 0; i + 1 < g.ni; ++i)
          {
            const double jacobian = hexScaledJacobian(g.cell(i, j, k));
            EXPECT_FALSE(std::isnan(jacobian));
            EXPECT_GE(jacobian, 0.0) << "cell " << i << " " << j << " " << k;
            EXPECT_GT(hexVolume(g.cell(i, j, k)), 0.0);
            ++cells;
          }
    }
    EXPECT_GT(cells, 0u);
    // The collapsed edge of the core wedge lies on the axis.
    const BlockGrid& core = grids[model.findBlock("core")];
    for (int k = 0; k < core.nk; ++k)
      for (int j = 0; j < core.nj; ++j)
      {
        EXPECT_EQ(core.node(0, j, k).head<2>().norm(), 0.0);
      }
    const double phi = parameter(model, "phi"), R = parameter(model, "R");
    EXPECT_NEAR(gridVolume(grids) / (phi / 2 * R * R * parameter(model, "H")), 1.0, 0.01);
  }
}

TEST(Mesher, CylinderInBoxVolume)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  const auto grids = meshBlocks(model);
  const double R = parameter(model, "R"), B = parameter(model, "B"), D = parameter(model, "D");
  const double exact = (4 * B * B - Pi * R * R) * D;
  const double volume = gridVolume(grids);
  EXPECT_NEAR(volume / exact, 1.0, 0.01);
  for (const BlockGrid& g : grids)
    for (int k = 0; k + 1 < g.nk; ++k)
      for (int j = 0; j + 1 < g.nj; ++j)
        for (int i = 0; i + 1 < g.ni; ++i)
        {
          ASSERT_GT(hexScaledJacobian(g.cell(i, j, k)), 0.0);
        }
}

TEST(Mesher, Misuse)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  EXPECT_THROW(MultiBlockMesher(model, 0.0), TemplateError);
  EXPECT_THROW(MultiBlockMesher(model, NAN), TemplateError);
  MultiBlockMesher mesher(model);
  std::vector<double> xyz(3 * 17 * 17 * 9);
  EXPECT_THROW(mesher.meshBlock(0, xyz.data()), std::logic_error);
  mesher.computeBoundaries();
  EXPECT_THROW(mesher.meshBlock(4, xyz.data()), std::out_of_range);
  EXPECT_NO_THROW(mesher.meshBlock(3, xyz.data()));
}

TEST(Mesher, SplineAndThroughArcEdges)
{
  // One unit box whose bottom front edge bows out as a spline and whose bottom back edge is
  // an arc through a third point; both are symmetric, so their arc-length midpoints are
  // known.
  const std::string text = R"yaml(blockforge: 1
vertices:
  a0: [0, 0, 0]
  a1: [1, 0, 0]
  a2: [1, 1, 0]
  a3: [0, 1, 0]
  a4: [0, 0, 1]
  a5: [1, 0, 1]
  a6: [1, 1, 1]
  a7: [0, 1, 1]
edges:
  bow: {spline: [a1, a0], points: [[0.75, -0.08, 0], [0.5, -0.1, 0], [0.25, -0.08, 0]]}
  hump: {arc: [a3, a2], through: [0.5, 1.2, 0]}
blocks:
  box: {vertices: [a0, a1, a2, a3, a4, a5, a6, a7], cells: [4, 3, 2]}
)yaml";
  const BlockModel model = parseTemplate(text, "edges.yaml");
  const auto grids = meshBlocks(model);
  const BlockGrid& g = grids[0];
  // Spline, defined from a1 to a0 (against the block's i direction).
  EXPECT_LT((g.node(2, 0, 0) - Vec3(0.5, -0.1, 0)).norm(), 1e-9);
  EXPECT_LT((g.node(1, 0, 0) - Vec3(1 - g.node(3, 0, 0).x(), g.node(3, 0, 0).y(), 0)).norm(), 1e-9);
  // Arc through (0.5, 1.2, 0): centre (0.5, y0) with 0.25 + (1 - y0)^2 = (1.2 - y0)^2.
  const double y0 = (1.44 - 1.0 - 0.25) / (2 * 0.2);
  const double radius = 1.2 - y0;
  EXPECT_LT((g.node(2, g.nj - 1, 0) - Vec3(0.5, 1.2, 0)).norm(), 1e-12);
  for (int i = 0; i < g.ni; ++i)
  {
    EXPECT_NEAR((g.node(i, g.nj - 1, 0) - Vec3(0.5, y0, 0)).norm(), radius, 1e-12);
  }
  for (double v : g.xyz)
  {
    ASSERT_TRUE(std::isfinite(v));
  }
}

TEST(Mesher, MatchedEdgesTakeTheirEndCellsFromTheirNeighbours)
{
  // Two unit cubes along x, 4 cells across the left one and 16 across the right one, law
  // `match` along x in both: at the shared face both cells are the geometric mean of the
  // two blocks' mean cells (0.25 and 0.0625), 0.125, at every density.
  const BlockModel model = twoCubesMatchedAlongX(0.0);
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const auto grids = meshBlocks(model, density);
    const BlockGrid& left = grids[0];
    const BlockGrid& right = grids[1];
    const double expected = std::sqrt(0.25 * 0.0625) / density;
    for (int k = 0; k < left.nk; ++k)
    {
      for (int j = 0; j < left.nj; ++j)
      {
        const double last = (left.node(left.ni - 1, j, k) - left.node(left.ni - 2, j, k)).norm();
        const double first = (right.node(1, j, k) - right.node(0, j, k)).norm();
        EXPECT_NEAR(last, expected, 1e-12);
        EXPECT_NEAR(first, expected, 1e-12);
      }
    }
  }
  // The law travels in the model document (the pipeline's stages pass the model so).
  const BlockModel reread = readModelDocument(writeModelDocument(model));
  for (std::size_t b = 0; b < model.blocks.size(); ++b)
  {
    EXPECT_EQ(reread.blocks[b].laws, model.blocks[b].laws) << b;
  }
  // A block that shares a matched edge must match it too.
  BlockModel mixed = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  mixed.blocks[0].laws[1] = matchLaw(); // left E2 (a1-a2, along j) is on the shared face
  try
  {
    meshBlocks(mixed);
    ADD_FAILURE() << "no error for an edge matched in one block only";
  }
  catch (const TemplateError& error)
  {
    EXPECT_NE(std::string(error.what()).find("give it the same law 'match'"), std::string::npos)
      << error.what();
  }
}

TEST(Mesher, MatchedEdgesStartAtMostTheirLimitTimesTheirMeanCell)
{
  // The two cubes of MatchedEdgesTakeTheirEndCellsFromTheirNeighbours (4 cells across the
  // left one, 16 across the right one, `match` along x): the geometric mean 0.125 of the
  // mean cells is twice the right block's mean cell. With `at_most: 1` on the right block's
  // x edges its cells are its mean cell, uniform, and the left block's cells at the shared
  // face take that cell too; at_most 3 (above 2) changes nothing; 0 is no limit.
  for (const double atMost : { 0.0, 1.0, 3.0 })
  {
    SCOPED_TRACE(atMost);
    const BlockModel model = twoCubesMatchedAlongX(atMost);
    for (const double density : { 1.0, 2.0 })
    {
      SCOPED_TRACE(density);
      const auto grids = meshBlocks(model, density);
      const BlockGrid& left = grids[0];
      const BlockGrid& right = grids[1];
      const double expected = (atMost == 1.0 ? 0.0625 : std::sqrt(0.25 * 0.0625)) / density;
      for (int k = 0; k < left.nk; ++k)
      {
        for (int j = 0; j < left.nj; ++j)
        {
          const double last = (left.node(left.ni - 1, j, k) - left.node(left.ni - 2, j, k)).norm();
          EXPECT_NEAR(last, expected, 1e-12);
          for (int i = 0; i + 1 < right.ni; ++i)
          {
            const double cell = (right.node(i + 1, j, k) - right.node(i, j, k)).norm();
            if (atMost == 1.0)
            {
              EXPECT_NEAR(cell, 0.0625 / density, 1e-12) << i; // its mean cell throughout
            }
            else if (i == 0)
            {
              EXPECT_NEAR(cell, expected, 1e-12);
            }
          }
        }
      }
    }
    // the limit travels in the model document
    const BlockModel reread = readModelDocument(writeModelDocument(model));
    EXPECT_EQ(reread.blocks[1].laws, model.blocks[1].laws);
    EXPECT_EQ(meshBlocks(reread)[1].xyz, meshBlocks(model)[1].xyz);
  }
  // a limit belongs to the law match only, and is not negative
  const std::string path = test::sourcePath("Testing/Data/match_lean.yaml");
  const std::string law = "grading: {i: {match: 1.2, lean: lean}}";
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
         { "grading: {i: {geometric: 1.2, at_most: 1}}", "'at_most' belongs to the law match" },
         { "grading: {i: {match: 1.2, at_most: -1}}", "needs k > 0" } })
  {
    std::string document = test::readText(path);
    document.replace(document.find(law), law.size(), text);
    try
    {
      parseTemplate(document, "match_lean.yaml");
      ADD_FAILURE() << "no error for " << text;
    }
    catch (const TemplateError& error)
    {
      EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << error.what();
    }
  }
}

TEST(Mesher, MatchedEdgesLeanNoMoreThanTheirLimit)
{
  // The right block's bottom edge is a half circle of radius 0.5 leaving the shared face
  // along it (Testing/Data/match_lean.yaml). The chord of its first cell, of angle a at the
  // centre, leans 90deg - a/2 from the edge's chord (+x): with a lean limit L the first
  // cell is the arc of a = 180deg - 2L, 0.5 (pi - 2L) long, and the left block's straight
  // edge ending there takes that cell too, at every density. Without the limit both take
  // the geometric mean of the mean cells, sqrt(0.25 * (pi/2) / 16).
  const std::string path = test::sourcePath("Testing/Data/match_lean.yaml");
  for (const double leanDegrees : { 75.0, 80.0, 179.0 })
  {
    SCOPED_TRACE(leanDegrees);
    const BlockModel model =
      loadTemplate(path, { { "lean", std::to_string(leanDegrees) + "deg" } });
    const double lean = leanDegrees * test::Pi / 180.0;
    EXPECT_NEAR(model.blocks[1].laws[0].leanLimit, lean, 1e-15);
    for (const double density : { 1.0, 2.0 })
    {
      const auto grids = meshBlocks(model, density);
      const BlockGrid& left = grids[0];
      const BlockGrid& right = grids[1];
      const double chord = (right.node(1, 0, 0) - right.node(0, 0, 0)).norm();
      const double arc = 2.0 * 0.5 * std::asin(chord / (2.0 * 0.5));
      const double expected = leanDegrees < 90.0
        ? 0.5 * (test::Pi - 2.0 * lean)
        : std::sqrt(0.25 / density * (test::Pi / 2.0) / (16.0 * density));
      EXPECT_NEAR(arc, expected, 1e-8);
      EXPECT_NEAR((left.node(left.ni - 1, 0, 0) - left.node(left.ni - 2, 0, 0)).norm(), expected,
        1e-8);
      // the straight edges at y = 1 keep the geometric mean (their ends lean nowhere)
      EXPECT_NEAR((right.node(1, right.nj - 1, 0) - right.node(0, right.nj - 1, 0)).norm(),
        std::sqrt(0.25 * (1.0 / 16.0)) / density, 1e-12);
    }
    // the limit travels in the model document: the same grid after a round trip
    const BlockModel reread = readModelDocument(writeModelDocument(model));
    EXPECT_EQ(reread.blocks[1].laws, model.blocks[1].laws);
    EXPECT_EQ(meshBlocks(reread)[1].xyz, meshBlocks(model)[1].xyz);
  }
  // a lean limit belongs to the law match only
  std::string text = test::readText(path);
  text.replace(text.find("grading: {i: {match: 1.2, lean: lean}}"),
    std::string("grading: {i: {match: 1.2, lean: lean}}").size(),
    "grading: {i: {geometric: 1.2, lean: lean}}");
  try
  {
    parseTemplate(text, "match_lean.yaml");
    ADD_FAILURE() << "no error for a lean limit on a geometric law";
  }
  catch (const TemplateError& error)
  {
    EXPECT_NE(std::string(error.what()).find("'lean' belongs to the law match"), std::string::npos)
      << error.what();
  }
}
