// The grading law `project_from`: an edge's interior nodes are the closest points on its
// curve of another edge's nodes. Checked on analytic shapes: a circular arc and its
// concentric offset (the projected nodes at the source's angles), parallel straight
// edges, with graded and matched sources, at density multipliers, through the model
// document and the mesh plan; and the errors for mismatched counts, cycles and names.
#include "MeshInternals.h"
#include "MeshPlan.h"
#include "Mesher.h"
#include "ModelDocument.h"
#include "Template.h"

#include "TestHelpers.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
/**
 * A quarter ring between radii 1 and 1.5 about the z axis, 1 high: i runs clockwise along
 * the arcs from (0, 1) to (1, 0), j outwards, k up. The inner arcs (in0 and in1 on E1 and
 * E5) are graded by `innerLaw`, the outer ones (out0, out1 on E3 and E7) by `outerLaw`, a
 * '#' in a law standing for the layer (0 at the bottom, 1 at the top). The outer arcs are
 * defined against the block's i direction and the inner ones with it, so both
 * orientations are used.
 */
std::string quarterRing(const std::string& innerLaw, const std::string& outerLaw, int cells = 8)
{
  const auto layer = [](std::string law, int k) {
    const std::size_t at = law.find('#');
    if (at != std::string::npos)
    {
      law.replace(at, 1, std::to_string(k));
    }
    return law;
  };
  return "blockforge: 1\n"
         "parameters:\n"
         "  n: " + std::to_string(cells) + "\n"
         "vertices:\n"
         "  p0: [0, 1, 0]\n"
         "  p1: [1, 0, 0]\n"
         "  p2: [1.5, 0, 0]\n"
         "  p3: [0, 1.5, 0]\n"
         "  p4: [0, 1, 1]\n"
         "  p5: [1, 0, 1]\n"
         "  p6: [1.5, 0, 1]\n"
         "  p7: [0, 1.5, 1]\n"
         "edges:\n"
         "  in0: {arc: [p0, p1], centre: [0, 0, 0]}\n"
         "  out0: {arc: [p2, p3], centre: [0, 0, 0]}\n"
         "  in1: {arc: [p4, p5], centre: [0, 0, 1]}\n"
         "  out1: {arc: [p6, p7], centre: [0, 0, 1]}\n"
         "blocks:\n"
         "  ring: {vertices: [p0, p1, p2, p3, p4, p5, p6, p7], cells: [n, 4, 2], grading: "
         "{edges: {E1: " + layer(innerLaw, 0) + ", E5: " + layer(innerLaw, 1) + ", E3: " +
    layer(outerLaw, 0) + ", E7: " + layer(outerLaw, 1) + "}}}\n";
}

double angleOf(const Vec3& p)
{
  return std::atan2(p.y(), p.x());
}

/// Node (i, j, k) of block b.
Vec3 node(const test::Grid& grid, int b, int i, int j, int k)
{
  return grid.at(b, i, j, k);
}

/// The blade wall cells of the corner tests (block 0 beside the corner, block 1 the side
/// along the blade): block 0's last wall cell and block 1's wall cells, as the distances
/// between the centres of their cells' blade faces' spanwise edges (j, k = 0..1).
struct WallCells
{
  double corner = 0.0;       ///< block 0's last wall cell, next to block 1
  std::vector<double> side;  ///< block 1's wall cells from the corner on
};

WallCells wallCells(const test::Grid& grid)
{
  const int nr = grid.nodes[0][0], na = grid.nodes[1][0];
  const auto centre = [&](int b, int i) -> Vec3 {
    return 0.25 * (node(grid, b, i, 0, 0) + node(grid, b, i, 1, 0) + node(grid, b, i, 0, 1) +
                    node(grid, b, i, 1, 1));
  };
  WallCells cells;
  cells.corner = (centre(0, nr - 1) - centre(0, nr - 2)).norm();
  for (int i = 0; i + 1 < na; ++i)
  {
    cells.side.push_back((centre(1, i + 1) - centre(1, i)).norm());
  }
  return cells;
}

/// Block 1's feet graded up from the corner (rampFeet): they advance along the blade
/// (in x, on the plane y = 0 where `onAxis`), land on the normal feet of their outer nodes
/// after 2 to half of the side's nodes and keep them from there on, and the ramp's cells
/// grow by less than 11 from one to the next.
void expectFeetRampToTheNormalFeet(const test::Grid& grid, const std::vector<double>& side,
  bool onAxis)
{
  const int na = grid.nodes[1][0], outer = grid.nodes[1][1] - 1;
  int landed = -1;
  for (int i = 1; i < na; ++i)
  {
    const double foot = node(grid, 1, i, 0, 0).x(), above = node(grid, 1, i, outer, 0).x();
    EXPECT_GT(foot, node(grid, 1, i - 1, 0, 0).x()) << i;
    if (onAxis)
    {
      EXPECT_NEAR(node(grid, 1, i, 0, 0).y(), 0.0, 1e-12) << i;
    }
    if (landed < 0 && std::abs(foot - above) < 1e-12)
    {
      landed = i;
    }
    if (landed >= 0)
    {
      EXPECT_NEAR(foot, above, 1e-12) << i; // the normal feet from there on
    }
  }
  EXPECT_GE(landed, 2);
  EXPECT_LE(landed, na / 2);
  for (int i = 1; i < landed + 1; ++i)
  {
    EXPECT_LT(side[i] / side[i - 1], 11.0) << i;
  }
}

/// The largest difference in angle between an inner arc node of block b and the outer
/// arc node of the same i (interior nodes only unless `withEnds`); the outer ones must lie
/// on the radius 1.5.
double largestAngleDifference(const test::Grid& grid, int b, bool withEnds = true)
{
  const auto& n = grid.nodes[b];
  double largest = 0.0;
  for (int k : { 0, n[2] - 1 })
  {
    for (int i = withEnds ? 0 : 1; i < (withEnds ? n[0] : n[0] - 1); ++i)
    {
      const Vec3 inner = node(grid, b, i, 0, k);
      const Vec3 outer = node(grid, b, i, n[1] - 1, k);
      EXPECT_NEAR(Vec3(outer.x(), outer.y(), 0).norm(), 1.5, 1e-12) << i;
      largest = std::max(largest, std::abs(angleOf(inner) - angleOf(outer)));
    }
  }
  return largest;
}

std::string errorOf(const std::string& text)
{
  try
  {
    test::meshAll(parseTemplate(text, "projected.yaml"));
  }
  catch (const std::exception& error)
  {
    return error.what();
  }
  ADD_FAILURE() << "no error";
  return std::string();
}

bool contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}
} // namespace

TEST(ProjectedEdges, OffsetArcTakesTheAnglesOfItsSourceAtEveryDensity)
{
  for (const std::string law :
    { "{geometric: 1.3}", "{two_sided: 1.25}", "{ends: [0.1, 4]}", "{first_cell: 0.02}" })
  {
    SCOPED_TRACE(law);
    const BlockModel layered =
      parseTemplate(quarterRing(law, "{project_from: in#}"), "ring.yaml");
    for (const double density : { 1.0, 2.0, 0.5 })
    {
      SCOPED_TRACE(density);
      const test::Grid grid = test::meshAll(layered, density);
      EXPECT_EQ(grid.nodes[0][0], static_cast<int>(std::round(8 * density)) + 1);
      EXPECT_LT(largestAngleDifference(grid, 0), 1e-12);
      // graded: the projection is not the arc-length distribution of the outer arc
      const double first = angleOf(node(grid, 0, 1, 0, 0)) - angleOf(node(grid, 0, 0, 0, 0));
      const double middle = angleOf(node(grid, 0, grid.nodes[0][0] / 2 + 1, 0, 0)) -
        angleOf(node(grid, 0, grid.nodes[0][0] / 2, 0, 0));
      EXPECT_GT(std::abs(first - middle), 1e-3);
    }
  }
}

TEST(ProjectedEdges, InnerArcTakesTheAnglesOfTheOuterOne)
{
  // The other way round: the graded outer arc gives its nodes to the inner arc.
  const test::Grid grid = test::meshAll(
    parseTemplate(quarterRing("{project_from: out#}", "{geometric: 0.8}"), "ring.yaml"));
  EXPECT_LT(largestAngleDifference(grid, 0), 1e-12);
}

TEST(ProjectedEdges, ParallelStraightEdgesKeepTheirNodesAcross)
{
  // A box turned by 30 degrees about z: its bottom front edge graded, the back edge (not
  // named, straight) takes its nodes; each back node lies straight across from its front
  // node (the same coordinate along the edge).
  const std::string text = R"yaml(blockforge: 1
parameters:
  c: 0.8660254037844386
  s: 0.5
vertices:
  a0: [0, 0, 0]
  a1: [2*c, 2*s, 0]
  a2: [2*c - s, 2*s + c, 0]
  a3: [-s, c, 0]
  a4: [0, 0, 1]
  a5: [2*c, 2*s, 1]
  a6: [2*c - s, 2*s + c, 1]
  a7: [-s, c, 1]
edges:
  front: {line: [a0, a1]}
blocks:
  box: {vertices: [a0, a1, a2, a3, a4, a5, a6, a7], cells: [7, 3, 1], grading: {edges: {E1: {geometric: 1.4}, E3: {project_from: front}}}}
)yaml";
  const test::Grid grid = test::meshAll(parseTemplate(text, "box.yaml"));
  const Vec3 along(0.8660254037844386, 0.5, 0.0);
  for (int i = 0; i < grid.nodes[0][0]; ++i)
  {
    const Vec3 front = node(grid, 0, i, 0, 0);
    const Vec3 back = node(grid, 0, i, grid.nodes[0][1] - 1, 0);
    EXPECT_NEAR(front.dot(along), back.dot(along), 1e-12) << i;
  }
  // the front edge is graded, so the back edge is too
  const double first = (node(grid, 0, 1, 3, 0) - node(grid, 0, 0, 3, 0)).norm();
  const double last = (node(grid, 0, 7, 3, 0) - node(grid, 0, 6, 3, 0)).norm();
  EXPECT_NEAR(last / first, std::pow(1.4, 6), 1e-9);
}

TEST(ProjectedEdges, ProjectedFromMatchedEdgesComeAfterThem)
{
  // Two quarter-ring halves of 4 and 12 cells whose inner arcs are matched (their cells
  // meet at 45 degrees with one length); the outer arcs take the inner arcs' nodes, so
  // they follow the matched distribution.
  const std::string text = R"yaml(blockforge: 1
vertices:
  a0: [0, 1, 0]
  m0: [sqrt(0.5), sqrt(0.5), 0]
  b0: [1, 0, 0]
  a3: [0, 1.5, 0]
  m3: [1.5*sqrt(0.5), 1.5*sqrt(0.5), 0]
  b3: [1.5, 0, 0]
  a4: [0, 1, 1]
  m4: [sqrt(0.5), sqrt(0.5), 1]
  b4: [1, 0, 1]
  a7: [0, 1.5, 1]
  m7: [1.5*sqrt(0.5), 1.5*sqrt(0.5), 1]
  b7: [1.5, 0, 1]
edges:
  ia0: {arc: [a0, m0], centre: [0, 0, 0]}
  ib0: {arc: [m0, b0], centre: [0, 0, 0]}
  oa0: {arc: [a3, m3], centre: [0, 0, 0]}
  ob0: {arc: [m3, b3], centre: [0, 0, 0]}
  ia1: {arc: [a4, m4], centre: [0, 0, 1]}
  ib1: {arc: [m4, b4], centre: [0, 0, 1]}
  oa1: {arc: [a7, m7], centre: [0, 0, 1]}
  ob1: {arc: [m7, b7], centre: [0, 0, 1]}
blocks:
  A: {vertices: [a0, m0, m3, a3, a4, m4, m7, a7], cells: [4, 3, 1], grading: {edges: {E1: match, E5: match, E3: {project_from: ia0}, E7: {project_from: ia1}}}}
  B: {vertices: [m0, b0, b3, m3, m4, b4, b7, m7], cells: [12, 3, 1], grading: {edges: {E1: match, E5: match, E3: {project_from: ib0}, E7: {project_from: ib1}}}}
)yaml";
  const BlockModel model = parseTemplate(text, "halves.yaml");
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const test::Grid grid = test::meshAll(model, density);
    for (int b = 0; b < 2; ++b)
    {
      EXPECT_LT(largestAngleDifference(grid, b), 1e-12) << b;
    }
    // matched: the inner cells at 45 degrees are one length, so the outer ones are too
    const int na = grid.nodes[0][0], outer = grid.nodes[0][1] - 1;
    const double innerA = (node(grid, 0, na - 1, 0, 0) - node(grid, 0, na - 2, 0, 0)).norm();
    const double innerB = (node(grid, 1, 1, 0, 0) - node(grid, 1, 0, 0, 0)).norm();
    const double outerA =
      (node(grid, 0, na - 1, outer, 0) - node(grid, 0, na - 2, outer, 0)).norm();
    const double outerB = (node(grid, 1, 1, outer, 0) - node(grid, 1, 0, outer, 0)).norm();
    EXPECT_NEAR(innerA, innerB, 1e-12);
    EXPECT_NEAR(outerA / innerA, 1.5, 1e-12);
    EXPECT_NEAR(outerB / innerB, 1.5, 1e-12);
  }
}

TEST(ProjectedEdges, AProjectedEdgeJoinsItsMatchedSourcesGroupWhereItContinues)
{
  // The matched inner arc of A continues through a0 into F's inner edge, and the outer arc
  // projected from it continues through a3 into F's outer edge: both of F's edges are
  // graded, with end cells 0.067 and 0.53 of their length at density 1. The projected arc's
  // end cell follows the inner arc's, so the inner arc takes the geometric mean of the two
  // (not the inner one alone), and neither layer jumps by the whole factor across F|A.
  const std::string text = R"yaml(blockforge: 1
vertices:
  a0: [0, 1, 0]
  m0: [sqrt(0.5), sqrt(0.5), 0]
  a3: [0, 1.5, 0]
  m3: [1.5*sqrt(0.5), 1.5*sqrt(0.5), 0]
  a4: [0, 1, 1]
  m4: [sqrt(0.5), sqrt(0.5), 1]
  a7: [0, 1.5, 1]
  m7: [1.5*sqrt(0.5), 1.5*sqrt(0.5), 1]
  f0: [-1, 1, 0]
  f3: [-1, 1.5, 0]
  f4: [-1, 1, 1]
  f7: [-1, 1.5, 1]
edges:
  ia0: {arc: [a0, m0], centre: [0, 0, 0]}
  oa0: {arc: [a3, m3], centre: [0, 0, 0]}
  ia1: {arc: [a4, m4], centre: [0, 0, 1]}
  oa1: {arc: [a7, m7], centre: [0, 0, 1]}
blocks:
  F: {vertices: [f0, a0, a3, f3, f4, a4, a7, f7], cells: [4, 3, 1], grading: {edges: {E1: {geometric: 0.5}, E5: {geometric: 0.5}, E3: {geometric: 2}, E7: {geometric: 2}}}}
  A: {vertices: [a0, m0, m3, a3, a4, m4, m7, a7], cells: [6, 3, 1], grading: {edges: {E1: match, E5: match, E3: {project_from: ia0}, E7: {project_from: ia1}}}}
)yaml";
  const BlockModel model = parseTemplate(text, "joined.yaml");
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const test::Grid grid = test::meshAll(model, density);
    const int nf = grid.nodes[0][0], outerF = grid.nodes[0][1] - 1, outerA = grid.nodes[1][1] - 1;
    const double innerF = (node(grid, 0, nf - 1, 0, 0) - node(grid, 0, nf - 2, 0, 0)).norm();
    const double outerFCell = (node(grid, 0, nf - 1, outerF, 0) - node(grid, 0, nf - 2, outerF, 0)).norm();
    // the inner arc's first cell (radius 1: the angle), and the outer arc's (radius 1.5)
    const double innerA = angleOf(node(grid, 1, 0, 0, 0)) - angleOf(node(grid, 1, 1, 0, 0));
    const double outerACell = 1.5 * (angleOf(node(grid, 1, 0, outerA, 0)) - angleOf(node(grid, 1, 1, outerA, 0)));
    EXPECT_GT(outerFCell / innerF, 7.0); // F's ends differ by a large factor
    EXPECT_NEAR(innerA, std::sqrt(innerF * outerFCell), 1e-9);
    EXPECT_NEAR(outerACell / innerA, 1.5, 1e-9);
  }
}

TEST(ProjectedEdges, TheLawTravelsInTheModelDocument)
{
  const BlockModel model =
    parseTemplate(quarterRing("{geometric: 1.2}", "{project_from: in#}"), "ring.yaml");
  const std::string document = writeModelDocument(model);
  EXPECT_TRUE(contains(document, "{project_from: in1}")) << document;
  const BlockModel reread = readModelDocument(document);
  EXPECT_EQ(reread.blocks[0].laws, model.blocks[0].laws);
  EXPECT_EQ(reread.blocks[0].laws[2].kind, DistributionLaw::Kind::ProjectFrom);
  EXPECT_EQ(reread.blocks[0].laws[2].sourceEdge, reread.findNamedEdge("in0"));
  const test::Grid original = test::meshAll(model);
  const test::Grid again = test::meshAll(reread);
  EXPECT_TRUE(test::sameBits(original.xyz[0], again.xyz[0]));
  // an unknown edge in a document is an error naming it
  std::string broken = document;
  const std::size_t at = broken.find("{project_from: in1}");
  broken.replace(at, 19, "{project_from: in9}");
  try
  {
    readModelDocument(broken);
    ADD_FAILURE() << "no error for an unknown edge";
  }
  catch (const TemplateError& error)
  {
    EXPECT_TRUE(contains(error.what(), "unknown edge 'in9'")) << error.what();
  }
}

TEST(ProjectedEdges, MovingTheSourceUpdatesTheProjectionAsAFreshMesherDoes)
{
  const BlockModel model =
    parseTemplate(quarterRing("{two_sided: 1.3}", "{project_from: in#}"), "ring.yaml");
  const CarrierGeometry carriers(model);
  MeshPlan plan(model, carriers);
  const int p1 = plan.model().findVertex("p1");
  // p1 (the inner arc's end, not on the outer arc) slides 5 degrees round the circle
  const double angle = 5.0 * test::Pi / 180.0;
  plan.model().vertices[p1].position = Vec3(std::cos(angle), std::sin(angle), 0.0);
  const Feasibility feasibility = plan.update({ p1 });
  ASSERT_TRUE(feasibility.feasible()) << feasibility.message;
  const test::Grid fresh = test::meshAll(plan.model());
  EXPECT_TRUE(test::sameBits(plan.blockNodes(0), fresh.xyz[0]));
  // the outer arc's nodes moved with the inner ones though none of its vertices did
  const test::Grid before = test::meshAll(model);
  EXPECT_FALSE(test::sameBits(node(fresh, 0, 3, 4, 0), node(before, 0, 3, 4, 0)));
  EXPECT_LT(largestAngleDifference(fresh, 0, false), 1e-12); // p1 is no longer above p2
}

TEST(ProjectedEdges, ErrorsNameTheEdges)
{
  // Two unit cubes side by side along x (Testing/Data/two_blocks.yaml), their bottom front
  // edges named: 'front' (a0-a1, left block E1) and 'other' (a1-b1, right block E1).
  BlockModel base = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  for (const auto& ends : { std::make_pair("a0", "a1"), std::make_pair("a1", "b1") })
  {
    Edge edge;
    edge.name = base.edges.empty() ? "front" : "other";
    edge.from = base.findVertex(ends.first);
    edge.to = base.findVertex(ends.second);
    base.edges.push_back(edge);
  }
  DistributionLaw fromFront;
  fromFront.kind = DistributionLaw::Kind::ProjectFrom;
  fromFront.sourceEdge = 0;
  DistributionLaw fromOther = fromFront;
  fromOther.sourceEdge = 1;
  const auto errorFor = [](const BlockModel& model) {
    try
    {
      test::meshAll(model);
    }
    catch (const TemplateError& error)
    {
      return std::string(error.what());
    }
    ADD_FAILURE() << "no error";
    return std::string();
  };

  // different cell counts
  BlockModel counts = base;
  counts.blocks[1].cells[0] = 6;
  counts.blocks[1].laws[0] = fromFront;
  const std::string mismatch = errorFor(counts);
  EXPECT_TRUE(contains(mismatch, "edge 'other' (a1-b1) takes its nodes from edge 'front' (a0-a1)"))
    << mismatch;
  EXPECT_TRUE(contains(mismatch, "has 6 cells against its 4")) << mismatch;
  EXPECT_TRUE(contains(mismatch, "block 'right'")) << mismatch;

  // two edges taking their nodes from one another, and an edge from itself
  BlockModel cycle = base;
  cycle.blocks[0].laws[0] = fromOther;
  cycle.blocks[1].laws[0] = fromFront;
  const std::string both = errorFor(cycle);
  EXPECT_TRUE(contains(both, "take their nodes from one another")) << both;
  EXPECT_TRUE(contains(both, "'front'") && contains(both, "'other'")) << both;
  BlockModel self = base;
  self.blocks[1].laws[0] = fromOther;
  EXPECT_TRUE(contains(errorFor(self), "take their nodes from one another"));

  // an unknown name in a template, with the nearest one suggested
  const std::string unknown = errorOf(quarterRing("{geometric: 1.2}", "{project_from: im#}"));
  EXPECT_TRUE(
    contains(unknown, "grading E3 project_from: unknown edge 'im0' (did you mean 'in0'?)"))
    << unknown;
}

TEST(ProjectedEdges, FadeMovesTheNodesNearAnEndOffTheNormalTowardsIt)
{
  // The outer arc reaches 10 degrees past the normal offset of the inner arc's end at p0
  // (90 degrees): without a fade its first cell takes the whole 10 degrees on top of the
  // projected 11.25; with {fade: [6, 0]} (its own direction, from p3) the nodes near p3
  // move towards it, the shift fading out over 6 x 0.1 of the arc, and nodes beyond are the
  // projections still.
  const auto mesh = [](const std::string& outerLaw) {
    std::string text = quarterRing("uniform", outerLaw);
    const std::size_t at = text.find("p3: [0, 1.5, 0]");
    text.replace(at, 15, "p3: [1.5*cos(100*pi/180), 1.5*sin(100*pi/180), 0]");
    const std::size_t top = text.find("p7: [0, 1.5, 1]");
    text.replace(top, 15, "p7: [1.5*cos(100*pi/180), 1.5*sin(100*pi/180), 1]");
    return test::meshAll(parseTemplate(text, "ring.yaml"));
  };
  const double degree = std::acos(-1.0) / 180.0;
  const auto outerAngle = [&](const test::Grid& grid, int i) {
    return angleOf(node(grid, 0, i, grid.nodes[0][1] - 1, 0)) / degree;
  };
  const test::Grid plain = mesh("{project_from: in#}");
  EXPECT_NEAR(outerAngle(plain, 0) - outerAngle(plain, 1), 21.25, 1e-9);
  const test::Grid faded = mesh("{project_from: in#, fade: [6, 0]}");
  EXPECT_NEAR(outerAngle(faded, 0), 100.0, 1e-9);
  for (const int i : { 6, 7, 8 })
  {
    EXPECT_NEAR(outerAngle(faded, i), 90.0 - 11.25 * i, 1e-9) << i;
  }
  double previous = outerAngle(faded, 0) - outerAngle(faded, 1);
  EXPECT_GT(previous, 11.25);
  EXPECT_LT(previous, 13.0); // the projected 11.25, not 21.25
  for (int i = 1; i < 8; ++i)
  {
    const double cell = outerAngle(faded, i) - outerAngle(faded, i + 1);
    EXPECT_GT(cell, 0.0) << i;
    EXPECT_LT(std::max(cell / previous, previous / cell), 1.0 + 1.5 / 6.0 + 1e-9) << i;
    previous = cell;
  }
  // the law travels in the model document
  const BlockModel model =
    parseTemplate(quarterRing("uniform", "{project_from: in#, fade: [6, 0]}"), "ring.yaml");
  const std::string document = writeModelDocument(model);
  EXPECT_TRUE(contains(document, "{project_from: in0, fade: [6, 0]}")) << document;
  EXPECT_EQ(readModelDocument(document).blocks[0].laws, model.blocks[0].laws);
  EXPECT_TRUE(contains(errorOf(quarterRing("uniform", "{project_from: in#, fade: 1}")),
    "must be 0 (none) or at least 2"));
  EXPECT_TRUE(contains(errorOf(quarterRing("{geometric: 1.2, fade: 3}", "uniform")),
    "'fade' belongs to the law project_from"));
}

/**
 * The `ends` law's `flat` option (Distribution.h, endsFlatness) on this file's quarter
 * ring: it travels in the model document, and a flatness below 1 or `flat` on another law
 * is an error naming it.
 */
TEST(ProjectedEdges, FlatEndsTravelInTheModelDocument)
{
  const BlockModel model =
    parseTemplate(quarterRing("{ends: [0.25, 0.5], flat: 3}", "{project_from: in#}"), "ring.yaml");
  const std::string document = writeModelDocument(model);
  EXPECT_TRUE(contains(document, "{ends: [0.25, 0.5], flat: 3}")) << document;
  EXPECT_EQ(readModelDocument(document).blocks[0].laws, model.blocks[0].laws);
  EXPECT_TRUE(contains(errorOf(quarterRing("{ends: [0.1, 0.3], flat: 0.5}", "uniform")),
    "must be at least 1"));
  EXPECT_TRUE(contains(errorOf(quarterRing("{geometric: 1.2, flat: 2}", "uniform")),
    "'flat' belongs to the laws ends and match"));
  // `match` with `flat` (matchFlatness) travels too; below 1 it is an error.
  const BlockModel matched =
    parseTemplate(quarterRing("{match: 2, flat: 3}", "uniform"), "ring.yaml");
  const std::string matchedDocument = writeModelDocument(matched);
  EXPECT_TRUE(contains(matchedDocument, "{match: 2, flat: 3}")) << matchedDocument;
  EXPECT_EQ(readModelDocument(matchedDocument).blocks[0].laws, matched.blocks[0].laws);
  EXPECT_EQ(matched.blocks[0].laws[0].matchFlatness, 3.0);
  EXPECT_TRUE(contains(errorOf(quarterRing("{match: 2, flat: 0.5}", "uniform")),
    "must be at least 1"));
}

TEST(ProjectedEdges, CollapsedEdgeIsOnePointAndItsFaceALine)
{
  // A fan: a quarter disc of radius 1.5, its inner edges E1 and E5 collapsed onto an axis
  // by the geometry only (p0 = p1, p4 = p5: two vertices on one point, as the feet of a
  // fan on a sharp tip), the axis leaning (0.3, 0.2) over the height 1 so that the face
  // j0 between the two axis edges is interpolated between equal edges (a round-off apart
  // unless the mesher makes it the line). The collapsed edges project from the outer
  // arcs: every node on the point, the face j0 every row the axis node, exactly.
  const std::string text = "blockforge: 1\n"
                           "vertices:\n"
                           "  p0: [0, 0, 0]\n"
                           "  p1: [0, 0, 0]\n"
                           "  p2: [1.5, 0, 0]\n"
                           "  p3: [0, 1.5, 0]\n"
                           "  p4: [0.3, 0.2, 1]\n"
                           "  p5: [0.3, 0.2, 1]\n"
                           "  p6: [1.8, 0.2, 1]\n"
                           "  p7: [0.3, 1.7, 1]\n"
                           "edges:\n"
                           "  out0: {arc: [p2, p3], centre: [0, 0, 0]}\n"
                           "  out1: {arc: [p6, p7], centre: [0.3, 0.2, 1]}\n"
                           "blocks:\n"
                           "  fan: {vertices: [p0, p1, p2, p3, p4, p5, p6, p7], cells: [6, 4, 7], "
                           "grading: {k: {geometric: 1.3}, edges: {E1: {project_from: out0}, "
                           "E5: {project_from: out1}}}}\n";
  const test::Grid grid = test::meshAll(parseTemplate(text, "fan.yaml"));
  const auto& n = grid.nodes[0];
  double volume = 0.0;
  for (int k = 0; k < n[2]; ++k)
  {
    const Vec3 axis = node(grid, 0, 0, 0, k);
    EXPECT_NEAR((axis - Vec3(0.3, 0.2, 1.0) * axis.z()).norm(), 0.0, 1e-12) << k;
    for (int i = 1; i < n[0]; ++i)
    {
      EXPECT_EQ(node(grid, 0, i, 0, k), axis) << i << ", " << k; // bit for bit
    }
  }
  // The sheared fan's volume: the polygon of the outer nodes (equal angles) times the height.
  for (int k = 0; k + 1 < n[2]; ++k)
  {
    for (int i = 0; i + 1 < n[0]; ++i)
    {
      // layer k to k + 1 of the triangle fan, as two wedges (a prism of the axis and two
      // outer-arc nodes at each level, cut into three tetrahedra)
      const Vec3 a0 = node(grid, 0, i, 0, k), b0 = node(grid, 0, i, n[1] - 1, k),
                 c0 = node(grid, 0, i + 1, n[1] - 1, k);
      const Vec3 a1 = node(grid, 0, i, 0, k + 1), b1 = node(grid, 0, i, n[1] - 1, k + 1),
                 c1 = node(grid, 0, i + 1, n[1] - 1, k + 1);
      const auto tet = [](const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
        return (q - p).dot((r - p).cross(s - p)) / 6.0;
      };
      volume += tet(a0, b0, c0, a1) + tet(b0, c0, a1, b1) + tet(c0, a1, b1, c1);
    }
  }
  const double Pi = 3.14159265358979323846;
  // (i runs clockwise seen from +z, from p3's side to p2's: the tetrahedra come out negative)
  EXPECT_NEAR(-volume, 6 * 0.5 * 1.5 * 1.5 * std::sin(Pi / 12), 1e-12);
}

namespace
{
/**
 * Two blocks meeting at a blade corner: R round a tip about the origin (its inner edge an
 * arc of radius `tip` from (-tip, 0) to (0, tip), its outer edge the concentric arc of
 * radius tip + 0.5), A along the flank y = tip from x = 0 to 2 (its outer line y = tip + 0.5
 * matched to R's arc's cell at (0, tip + 0.5)); both inner edges projected from the outer
 * ones, 1 high, j graded geometric 1.3 away from the wall.
 */
std::string bladeCorner(double tip)
{
  const std::string t = std::to_string(tip), o = std::to_string(tip + 0.5);
  std::string text = "blockforge: 1\nvertices:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  p0" + k + ": [-" + t + ", 0, " + k + "]\n  p1" + k + ": [0, " + t + ", " + k +
      "]\n  s" + k + ": [0, " + o + ", " + k + "]\n  t" + k + ": [-" + o + ", 0, " + k +
      "]\n  w0" + k + ": [2, " + t + ", " + k + "]\n  w3" + k + ": [2, " + o + ", " + k + "]\n";
  }
  text += "edges:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  tip" + k + ": {arc: [p0" + k + ", p1" + k + "], centre: [0, 0, " + k + "]}\n" +
      "  fan" + k + ": {arc: [t" + k + ", s" + k + "], centre: [0, 0, " + k + "]}\n" +
      "  side" + k + ": {line: [s" + k + ", w3" + k + "]}\n" +
      "  flank" + k + ": {line: [p1" + k + ", w0" + k + "]}\n";
  }
  text += "blocks:\n"
          "  R: {vertices: [p00, p10, s0, t0, p01, p11, s1, t1], cells: [6, 5, 1], grading: "
          "{j: {geometric: 1.3}, edges: {E1: {project_from: fan0}, E5: {project_from: fan1}, "
          "E3: match, E7: match}}}\n"
          "  A: {vertices: [p10, w00, w30, s0, p11, w01, w31, s1], cells: [12, 5, 1], grading: "
          "{j: {geometric: 1.3}, edges: {E1: {project_from: side0}, E5: {project_from: side1}, "
          "E3: match, E7: match}}}\n";
  return text;
}
} // namespace

TEST(ProjectedEdges, FeetAtABladeCornerKeepTheWallCellsAlike)
{
  // R's feet lie on a circle of radius 1, 1.5 times nearer one another than the outer
  // nodes (radius 1.5), A's on the flank as far apart as theirs: the wall cells across R|A
  // differ by about 1.45 (their outer cells match). The feet join (joinFeet): A's first
  // foot is cut so that the wall cells differ by 1.2 (estimated from the radial edge's first
  // layer), the next four cells taking the length it gives up; A's other feet stay the
  // normal feet of its outer nodes. At a thin tip (radius 0.001: R a fan, its feet 500
  // times nearer one another than its outer nodes) A's first foot would be cut to a few
  // hundredths of its next one; cut only to half of it (InBlockRatio) the wall cells
  // differed by 10.8 / 20.6 at densities 1 / 2, so A's feet are graded up from the corner
  // instead (rampFeet, as beside a fan): 1.35 times R's wall cell, the next growing by at
  // most 10 until they land on the normal feet.
  for (const double tip : { 1.0, 0.001 })
  {
    const BlockModel model = parseTemplate(bladeCorner(tip), "corner.yaml");
    for (const double density : { 1.0, 2.0 })
    {
      SCOPED_TRACE(std::to_string(tip) + " " + std::to_string(density));
      const test::Grid grid = test::meshAll(model, density);
      const int nr = grid.nodes[0][0], na = grid.nodes[1][0], outer = grid.nodes[1][1] - 1;
      // the wall cells' widths as the neighbour ratio measures them: between the centres
      // of their faces across i (k = 0 to 1, j = 0 to 1)
      const auto centre = [&](int b, int i) -> Vec3 {
        return 0.25 * (node(grid, b, i, 0, 0) + node(grid, b, i, 1, 0) + node(grid, b, i, 0, 1) +
                        node(grid, b, i, 1, 1));
      };
      const double ring = (centre(0, nr - 1) - centre(0, nr - 2)).norm();
      const double side = (centre(1, 1) - centre(1, 0)).norm();
      const double next = (centre(1, 2) - centre(1, 1)).norm();
      std::printf("tip %g, density %g: wall cells R %.4g, A %.4g (ratio %.3f), A's next %.4g (%.3f)\n",
        tip, density, ring, side, side / ring, next, next / side);
      if (tip == 1.0)
      {
        EXPECT_NEAR(side / ring, 1.2, 0.01);
      }
      else
      {
        EXPECT_NEAR(side / ring, 1.35, 0.03);
        EXPECT_LT(next / side, 10.0);
        EXPECT_GT(next / side, 2.0);
      }
      int landed = -1;
      for (int i = 1; i < na; ++i)
      {
        const double foot = node(grid, 1, i, 0, 0).x(), above = node(grid, 1, i, outer, 0).x();
        EXPECT_GT(foot, node(grid, 1, i - 1, 0, 0).x()) << i;
        if (landed < 0 && std::abs(foot - above) < 1e-12)
        {
          landed = i;
        }
        if (landed >= 0)
        {
          EXPECT_NEAR(foot, above, 1e-12) << i; // the normal feet
        }
        else
        {
          EXPECT_LT(foot, above) << i; // the cut foot's length taken up by the next ones
        }
      }
      // the one cut: the next four cells share it; the ramp lands within half the side
      if (tip == 1.0)
      {
        EXPECT_EQ(landed, 5);
      }
      else
      {
        EXPECT_GE(landed, 2);
        EXPECT_LE(landed, na / 2);
      }
    }
  }
}

TEST(ProjectedEdges, FeetHeldByTheirNextCellAreGradedUpFromTheCorner)
{
  // A blunt corner (bladeCorner(0.1): R's feet 6 times nearer one another than its outer
  // nodes, as the turbine's edge block by its cap's corner): cut to 1.2 times R's wall
  // cell, A's first foot would be under a quarter of its next one, so the one cut stops at
  // half of it (InBlockRatio) and left the wall cells across R|A 2.69 / 3.00 apart at
  // densities 1 / 2. Held there
  // above 1.35, A's feet are graded up from the corner instead (rampFeet, as beside a fan):
  // its first wall cell 1.35 times R's, the next ones growing by at most 10 from cell to
  // cell (the estimate's outer part a little more) until they land on the normal feet,
  // which A keeps from there on.
  const BlockModel model = parseTemplate(bladeCorner(0.1), "corner.yaml");
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const test::Grid grid = test::meshAll(model, density);
    const WallCells cells = wallCells(grid);
    const double ring = cells.corner;
    const std::vector<double>& side = cells.side;
    std::printf("density %g: wall cells R %.4g, A %.4g (ratio %.3f), A's next %.4g %.4g %.4g\n",
      density, ring, side[0], side[0] / ring, side[1], side[2], side[3]);
    EXPECT_NEAR(side[0] / ring, 1.35, 0.03);
    expectFeetRampToTheNormalFeet(grid, side, false);
  }
}

TEST(ProjectedEdges, JoinedFeetFollowMovesAsAFreshMesherDoes)
{
  // The ring's corner beside the flank (bladeCorner(1): A's first foot is cut; 0.1: A's
  // feet are graded up from the corner, rampFeet). The flank's far end moves (its outer
  // and inner corners, w00 and w30, along x): the outer line's matched nodes change, the
  // flank's projection with them, the join is made again from the new projection, and the
  // grid is a fresh mesher's, bit for bit; moved back, too.
  for (const double tip : { 1.0, 0.1 })
  {
    SCOPED_TRACE(tip);
    const BlockModel model = parseTemplate(bladeCorner(tip), "corner.yaml");
    const CarrierGeometry carriers(model);
    MeshPlan plan(model, carriers);
    const int inner = plan.model().findVertex("w00"), outer = plan.model().findVertex("w30");
    for (const double x : { 2.4, 1.7, 2.0 })
    {
      SCOPED_TRACE(x);
      plan.model().vertices[inner].position.x() = x;
      plan.model().vertices[outer].position.x() = x;
      const Feasibility feasibility = plan.update({ inner, outer });
      ASSERT_TRUE(feasibility.feasible()) << feasibility.message;
      const test::Grid fresh = test::meshAll(plan.model());
      for (int b = 0; b < 2; ++b)
      {
        EXPECT_TRUE(test::sameBits(plan.blockNodes(b), fresh.xyz[b])) << b;
      }
      // the join applies: A's first foot short of its outer node
      EXPECT_LT(node(fresh, 1, 1, 0, 0).x(), 0.9 * node(fresh, 1, 1, fresh.nodes[1][1] - 1, 0).x());
    }
    const test::Grid back = test::meshAll(model);
    EXPECT_TRUE(test::sameBits(plan.blockNodes(1), back.xyz[1]));
  }
}

namespace
{
/**
 * A fan on a sharp tip beside a flank: the tip at the origin, the blade along +x (its flank
 * y = 0). R is the fan: its blade edge collapsed onto the tip (p0 = p1, two vertices on one
 * point, as axial_passage_oh's prisms), its outer edge the arc of radius 0.5 about the tip
 * from angle 220 to 90 deg; A runs along the flank from the tip to x = 2, its outer line
 * y = 0.5 matched to R's arc's cell at (0, 0.5). Both blade edges are projected from the
 * outer ones; j is graded geometric 1.3 away from the wall, 1 high.
 */
std::string fanBesideFlank()
{
  std::string text = "blockforge: 1\nvertices:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  p0" + k + ": [0, 0, " + k + "]\n  p1" + k + ": [0, 0, " + k + "]\n  s" + k +
      ": [0, 0.5, " + k + "]\n  t" + k + ": [-0.38302222155948906, -0.32139380484326968, " + k +
      "]\n  w0" + k + ": [2, 0, " + k + "]\n  w3" + k + ": [2, 0.5, " + k + "]\n";
  }
  text += "edges:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  fan" + k + ": {arc: [t" + k + ", s" + k + "], centre: [0, 0, " + k + "]}\n" +
      "  side" + k + ": {line: [s" + k + ", w3" + k + "]}\n" +
      "  flank" + k + ": {line: [p1" + k + ", w0" + k + "]}\n";
  }
  text += "blocks:\n"
          "  R: {vertices: [p00, p10, s0, t0, p01, p11, s1, t1], cells: [8, 5, 1], grading: "
          "{j: {geometric: 1.3}, edges: {E1: {project_from: fan0}, E5: {project_from: fan1}, "
          "E3: match, E7: match}}}\n"
          "  A: {vertices: [p10, w00, w30, s0, p11, w01, w31, s1], cells: [12, 5, 1], grading: "
          "{j: {geometric: 1.3}, edges: {E1: {project_from: side0}, E5: {project_from: side1}, "
          "E3: match, E7: match}}}\n";
  return text;
}
} // namespace

TEST(ProjectedEdges, FeetBesideAFanGrowFromItsWallCell)
{
  // The fan's wall cells are slivers of its outer cells (its feet are one point), while
  // A's first foot, the normal foot of its first outer node, is as long as that node's
  // cell: projected alone, A's first wall cell is about 11 times R's (as the compressor's
  // sides beside their fans: 2.2-3.5 with their feet widened on the tip). Graded up from
  // the fan (gradeBesideFan), A's first wall cell is 1.35 times R's across the interface
  // and A's next wall cells grow by at most 10 from cell to cell (the estimate's outer part
  // a little more) until they land on the normal feet, which A keeps from there on.
  const BlockModel model = parseTemplate(fanBesideFlank(), "fan_flank.yaml");
  for (const double density : { 1.0, 2.0, 4.0 })
  {
    SCOPED_TRACE(density);
    const test::Grid grid = test::meshAll(model, density);
    const int nr = grid.nodes[0][0];
    // R's feet are the tip
    EXPECT_EQ(node(grid, 0, nr - 1, 0, 0), node(grid, 0, 0, 0, 0));
    const WallCells cells = wallCells(grid);
    const double fan = cells.corner;
    const std::vector<double>& side = cells.side;
    std::printf("density %g: wall cells R %.4g, A %.4g (ratio %.3f), A's next %.4g %.4g %.4g\n",
      density, fan, side[0], side[0] / fan, side[1], side[2], side[3]);
    EXPECT_LT(side[0] / fan, 1.5);
    EXPECT_GT(side[0] / fan, 1.2);
    expectFeetRampToTheNormalFeet(grid, side, true);
  }
}

namespace
{
/**
 * A blunt corner: the blade's flank y = 0 from x = -1 meets its cap x = 0 (down to y = -1)
 * round a corner of radius 0.01 about (-0.01, -0.01), the blade edge a spline through
 * points of it from a = (-1, 0) to b = (0, -1); the outer edge is the same path offset by
 * 0.3 (radius 0.31 round the corner), graded evenly, and the blade edge is projected from
 * it. Symmetric about the line x = y. The outer nodes on the 0.31 arc have their normal
 * feet on the 0.01 one: projected alone, those cells are 0.05 (density 1) to 0.04
 * (density 4) of the cells beside them, a fan of lines from the corner.
 */
std::string bluntCorner()
{
  const auto path = [](double offset) {
    const double r = 0.01 + offset;
    std::vector<std::pair<double, double>> points;
    for (const double x : { -0.75, -0.5, -0.25, -0.1 })
    {
      points.push_back({ x, offset });
    }
    for (int degrees = 90; degrees >= 0; degrees -= 15)
    {
      const double t = degrees * std::acos(-1.0) / 180.0;
      points.push_back({ -0.01 + r * std::cos(t), -0.01 + r * std::sin(t) });
    }
    for (const double y : { -0.1, -0.25, -0.5, -0.75 })
    {
      points.push_back({ offset, y });
    }
    return points;
  };
  const auto list = [](const std::vector<std::pair<double, double>>& points, const char* z) {
    std::string text;
    char buffer[96];
    for (const auto& [x, y] : points)
    {
      std::snprintf(buffer, sizeof buffer, "%s[%.17g, %.17g, %s]", text.empty() ? "" : ", ", x, y, z);
      text += buffer;
    }
    return text;
  };
  std::string text = "blockforge: 1\nvertices:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  a" + k + ": [-1, 0, " + k + "]\n  b" + k + ": [0, -1, " + k + "]\n  c" + k +
      ": [0.3, -1, " + k + "]\n  d" + k + ": [-1, 0.3, " + k + "]\n";
  }
  text += "edges:\n";
  for (const char* z : { "0", "1" })
  {
    const std::string k = z;
    text += "  blade" + k + ": {spline: [a" + k + ", b" + k + "], points: [" + list(path(0.0), z) + "]}\n" +
      "  outer" + k + ": {spline: [d" + k + ", c" + k + "], points: [" + list(path(0.3), z) + "]}\n";
  }
  text += "blocks:\n"
          "  W: {vertices: [a0, b0, c0, d0, a1, b1, c1, d1], cells: [12, 4, 1], grading: "
          "{j: {geometric: 1.3}, edges: {E1: {project_from: outer0}, E5: {project_from: outer1}}}}\n";
  return text;
}
} // namespace

TEST(ProjectedEdges, FeetBunchedRoundABluntCornerAreSpreadRoundIt)
{
  // The feet bunched on the corner (spreadFootBunches) are spread round it: the run's node
  // whose outer node lies along the corner's bisector stays on the corner, the others go
  // to either side, the cells growing from the corner by about 1.5 until they meet the
  // projected ones. No wall cell is then under a fifth of both its neighbours (projected
  // alone: 0.05 / 0.04 / 0.04 of them at densities 1 / 2 / 4, as the turbine's cap
  // corners: 0.003 mm between 0.06 and 0.3 mm, where checkMesh's interpolation weight
  // failed); the feet stay symmetric, one stays on the corner, and the grid does not fold.
  const BlockModel model = parseTemplate(bluntCorner(), "blunt.yaml");
  for (const double density : { 1.0, 2.0, 4.0 })
  {
    SCOPED_TRACE(density);
    const test::Grid grid = test::meshAll(model, density);
    const int n = grid.nodes[0][0];
    std::vector<double> cells;
    for (int i = 0; i + 1 < n; ++i)
    {
      cells.push_back((node(grid, 0, i + 1, 0, 0) - node(grid, 0, i, 0, 0)).norm());
    }
    // the foot on the corner (the middle one, by symmetry), and the cells on either side
    const int c = n / 2;
    const Vec3 corner(-0.01 + 0.01 * std::sqrt(0.5), -0.01 + 0.01 * std::sqrt(0.5), 0.0);
    EXPECT_LT((node(grid, 0, c, 0, 0) - corner).norm(), 0.002);
    std::printf("density %g: cells from the corner %.4g %.4g %.4g (%.4g at the edge's middle)\n",
      density, cells[c], cells[c + 1], cells[c + 2], cells[n / 4]);
    // spread: the corner's cells at least a fifth of the next ones (projected alone: 0.04)
    // and of the flank's cells, the run beside it within 2 from cell to cell
    EXPECT_GT(cells[c] / cells[c + 1], 0.2);
    EXPECT_LT(cells[c] / cells[c + 1], 5.0);
    EXPECT_GT(cells[c + 1] / cells[c + 2], 0.5);
    EXPECT_LT(cells[c + 1] / cells[c + 2], 2.0);
    EXPECT_GT(cells[c] / cells[n / 4], 0.1);
    for (int i = 1; i + 1 < n; ++i)
    {
      const Vec3 foot = node(grid, 0, i, 0, 0);
      const Vec3 mirror = node(grid, 0, n - 1 - i, 0, 0);
      EXPECT_NEAR(foot.x(), mirror.y(), 1e-9) << i;
      EXPECT_NEAR(foot.y(), mirror.x(), 1e-9) << i;
    }
  }
}

TEST(ProjectedEdges, FeetBunchedWithTooFewCellsToGradeAreSpreadBetweenTheirNeighbours)
{
  // The turbine's cap corner at density 1 (main's k_o 1.35, n_o 5): 0.058 mm of flank, a
  // 0.003 mm cell on the corner, 0.8 mm across the cap, then 1.94 mm cells. Graded from the
  // corner by 1.5 the cells would still jump more than 10 times (too few of them: the edge's
  // other end, at side b, is graded down to 0.29 mm), so
  // spreadFootBunches used to keep them as projected: O_te's wall cells there at checkMesh's
  // interpolation weight (0.0509 against 0.05). The run's nodes are spread between their
  // neighbours instead (spreadBunchLocally): one end of the corner cell stays (here the
  // flank's, which leaves the cells most alike), the other goes onto the cap; the nodes
  // outside keep their bits.
  const std::vector<double> projected = { 0.0, 0.058, 0.061, 0.86, 2.799, 4.742, 6.687, 8.635,
    9.809, 10.396, 10.69 };
  // feet and outer nodes (mm) of O_te's hub edge (the outer ones on the O curve)
  const std::vector<Vec3> feet = { Vec3(14.655, 249.238, -3.831),
    Vec3(14.709, 249.235, -3.812),
    Vec3(14.711, 249.235, -3.809),
    Vec3(14.584, 249.253, -3.021),
    Vec3(14.118, 249.292, -1.138),
    Vec3(13.436, 249.327, 0.680),
    Vec3(12.553, 249.361, 2.414),
    Vec3(11.484, 249.393, 4.041),
    Vec3(10.757, 249.413, 4.963),
    Vec3(10.371, 249.423, 5.406),
    Vec3(10.173, 249.428, 5.623) };
  const std::vector<Vec3> outer = { Vec3(14.972, 249.207, -4.700),
    Vec3(15.247, 249.196, -4.564),
    Vec3(15.597, 249.187, -4.070),
    Vec3(15.492, 249.209, -2.851),
    Vec3(15.000, 249.249, -0.864),
    Vec3(14.281, 249.284, 1.054),
    Vec3(13.351, 249.316, 2.879),
    Vec3(12.227, 249.346, 4.590),
    Vec3(11.463, 249.365, 5.559),
    Vec3(11.057, 249.374, 6.024),
    Vec3(10.849, 249.379, 6.252) };
  std::vector<double> params = projected;
  spreadFootBunches(params, feet, outer);
  ASSERT_EQ(params.size(), projected.size());
  EXPECT_EQ(params[0], projected[0]);
  EXPECT_EQ(params[1], projected[1]); // the corner
  for (std::size_t i = 3; i < params.size(); ++i)
  {
    EXPECT_EQ(params[i], projected[i]) << i;
  }
  double worst = 1.0;
  for (std::size_t i = 0; i + 2 < params.size(); ++i)
  {
    const double a = params[i + 1] - params[i], b = params[i + 2] - params[i + 1];
    ASSERT_GT(a, 0.0);
    worst = std::max(worst, std::max(a / b, b / a));
  }
  std::printf("cells %.3f %.3f %.3f %.3f, worst neighbour ratio %.2f (projected 266)\n",
    params[1] - params[0], params[2] - params[1], params[3] - params[2], params[4] - params[3],
    worst);
  EXPECT_LT(worst, 5.0 + 1e-6); // spread no farther than ratios of 5 (the spread feet lean
  EXPECT_GT(worst, 4.9);        // the lines: the smallest angle)
  // a bunch the spread cannot bring within 5 (a lone sliver between cells 1000 times
  // wider) stays as projected
  const std::vector<double> lone = { 0.0, 1.0, 1.001, 1001.0, 2001.0 };
  params = lone;
  spreadFootBunches(params, {}, {});
  EXPECT_EQ(params, lone);
}
