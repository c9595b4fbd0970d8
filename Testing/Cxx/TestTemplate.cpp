// Template engine (Filters/Model/Template.h), model document (ModelDocument.h) and model
// check (Mesher.h checkModel): parsing, expressions, overrides, located errors.
#include "Mesher.h"
#include "ModelDocument.h"
#include "Template.h"

#include "TestHelpers.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
using test::expectError;
using test::lineContaining;
using test::meshAll;
using test::parameter;
using test::Pi;
using test::readText;
using test::replaced;
using test::sameBits;
using test::templatePath;

const std::vector<std::string>& ExampleTemplates = test::exampleTemplates();

/// Two unit boxes side by side along x; the error tests each break one line of it.
const std::string TwoBoxes = R"(blockforge: 1
name: two_boxes
parameters:
  L: 1.0          # box size [m]
  n: 4            # cells per direction
vertices:
  a0: [0, 0, 0]
  a1: [L, 0, 0]
  a2: [L, L, 0]
  a3: [0, L, 0]
  a4: [0, 0, L]
  a5: [L, 0, L]
  a6: [L, L, L]
  a7: [0, L, L]
  b1: [2*L, 0, 0]
  b2: [2*L, L, 0]
  b5: [2*L, 0, L]
  b6: [2*L, L, L]
blocks:
  left:
    vertices: [a0, a1, a2, a3, a4, a5, a6, a7]
    cells: [n, n, n]
  right:
    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]
    cells: [n, n, n]
patches:
  inlet: {type: inlet, faces: [left.i0]}
  outlet: {type: outlet, faces: [right.i1]}
)";

const std::string TwoBoxesFile = "two_boxes.yaml";

/// Parses a broken variant of TwoBoxes, expects "two_boxes.yaml:<line of marker>: <entity>"
/// plus the given message pieces.
void expectTwoBoxesError(const std::string& text, const std::string& lineMarker,
  const std::string& entityText, std::vector<std::string> pieces,
  const ParameterOverrides& overrides = {})
{
  const int line = lineContaining(text, lineMarker);
  pieces.insert(pieces.begin(), TwoBoxesFile + ":" + std::to_string(line) + ": " + entityText);
  expectError([&] { parseTemplate(text, TwoBoxesFile, overrides); }, pieces);
}

const Vec3& position(const BlockModel& model, const std::string& name)
{
  const int v = model.findVertex(name);
  EXPECT_GE(v, 0) << name;
  return model.vertices[v].position;
}

/// Every number and name of two models, compared bit for bit.
void expectIdenticalModels(const BlockModel& a, const BlockModel& b)
{
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.sourceFile, b.sourceFile);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t i = 0; i < a.parameters.size(); ++i)
  {
    EXPECT_EQ(a.parameters[i].first, b.parameters[i].first);
    EXPECT_TRUE(sameBits(a.parameters[i].second, b.parameters[i].second));
  }
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i)
  {
    EXPECT_EQ(a.vertices[i].name, b.vertices[i].name);
    EXPECT_TRUE(sameBits(a.vertices[i].position, b.vertices[i].position)) << a.vertices[i].name;
    EXPECT_EQ(a.vertices[i].where.file, b.vertices[i].where.file);
    EXPECT_EQ(a.vertices[i].where.line, b.vertices[i].where.line);
  }
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i)
  {
    const Edge &x = a.edges[i], &y = b.edges[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.kind, y.kind);
    EXPECT_EQ(x.from, y.from);
    EXPECT_EQ(x.to, y.to);
    EXPECT_EQ(x.arcHasCentre, y.arcHasCentre);
    EXPECT_TRUE(sameBits(x.arcCentre, y.arcCentre));
    EXPECT_TRUE(sameBits(x.arcThrough, y.arcThrough));
    ASSERT_EQ(x.splinePoints.size(), y.splinePoints.size());
    for (std::size_t p = 0; p < x.splinePoints.size(); ++p)
    {
      EXPECT_TRUE(sameBits(x.splinePoints[p], y.splinePoints[p]));
    }
    EXPECT_EQ(x.where.line, y.where.line);
  }
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (std::size_t i = 0; i < a.blocks.size(); ++i)
  {
    const Block &x = a.blocks[i], &y = b.blocks[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.vertices, y.vertices);
    EXPECT_EQ(x.cells, y.cells);
    EXPECT_EQ(x.minCells, y.minCells);
    for (int e = 0; e < 12; ++e)
    {
      EXPECT_EQ(x.laws[e].kind, y.laws[e].kind);
      EXPECT_TRUE(sameBits(x.laws[e].expansionRatio, y.laws[e].expansionRatio));
      EXPECT_TRUE(sameBits(x.laws[e].firstCellSize, y.laws[e].firstCellSize));
    }
    EXPECT_EQ(x.where.file, y.where.file);
    EXPECT_EQ(x.where.line, y.where.line);
  }
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (std::size_t i = 0; i < a.patches.size(); ++i)
  {
    const Patch &x = a.patches[i], &y = b.patches[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.faces, y.faces);
    EXPECT_EQ(x.periodicPartner, y.periodicPartner);
    EXPECT_TRUE(sameBits(x.periodicAxis, y.periodicAxis));
    EXPECT_TRUE(sameBits(x.periodicAxisPoint, y.periodicAxisPoint));
    EXPECT_TRUE(sameBits(x.periodicAngle, y.periodicAngle));
    EXPECT_EQ(x.where.line, y.where.line);
  }
}

} // namespace

// ------------------------------------------------------------------ the example templates
TEST(Template, CylinderInBoxParses)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"));
  EXPECT_EQ(model.name, "cylinder_in_box");
  EXPECT_EQ(model.sourceFile, templatePath("cylinder_in_box.yaml"));
  EXPECT_EQ(model.vertices.size(), 16u);
  EXPECT_EQ(model.edges.size(), 8u);
  EXPECT_EQ(model.blocks.size(), 4u);
  EXPECT_EQ(model.patches.size(), 7u);
  EXPECT_DOUBLE_EQ(parameter(model, "R"), 0.5);
  EXPECT_DOUBLE_EQ(parameter(model, "B"), 2.0);
  EXPECT_DOUBLE_EQ(parameter(model, "k_wall"), 1.1);
  const double c45 = std::cos(Pi / 4);
  EXPECT_NEAR(parameter(model, "c45"), c45, 1e-16);
  const Vec3& wall = position(model, "w_nw1");
  EXPECT_NEAR(wall.x(), -0.5 * c45, 1e-16);
  EXPECT_NEAR(wall.y(), 0.5 * c45, 1e-16);
  EXPECT_EQ(wall.z(), 1.0);
  EXPECT_EQ(position(model, "b_se0"), Vec3(2, -2, 0));

  const Block& north = model.blocks[model.findBlock("north")];
  EXPECT_EQ(north.cells, (std::array<int, 3>{ 16, 16, 8 }));
  EXPECT_EQ(model.vertices[north.vertices[0]].name, "w_nw0");
  EXPECT_EQ(model.vertices[north.vertices[6]].name, "b_ne1");
  for (int e = 0; e < 12; ++e)
  {
    // grading j applies to the four j edges E2, E4, E6, E8 only
    const bool j = edgeDirection(e) == 1;
    EXPECT_EQ(north.laws[e].kind,
      j ? DistributionLaw::Kind::Geometric : DistributionLaw::Kind::Uniform);
    if (j)
    {
      EXPECT_DOUBLE_EQ(north.laws[e].expansionRatio, 1.1);
    }
  }
  const Edge& arc = model.edges[model.findEdge(model.findVertex("w_ne0"), model.findVertex("w_nw0"))];
  EXPECT_EQ(arc.name, "wall_n0");
  EXPECT_EQ(arc.kind, Edge::Kind::Arc);
  EXPECT_TRUE(arc.arcHasCentre);
  EXPECT_EQ(arc.where.line, lineContaining(readText(templatePath("cylinder_in_box.yaml")), "wall_n0:"));

  const Patch& cylinder = model.patches[0];
  EXPECT_EQ(cylinder.name, "cylinder");
  EXPECT_EQ(cylinder.type, "wall");
  ASSERT_EQ(cylinder.faces.size(), 4u);
  EXPECT_EQ(cylinder.faces[0], (BlockFace{ model.findBlock("north"), 2 }));
}

TEST(Template, AnnularSectorParses)
{
  const BlockModel model = loadTemplate(templatePath("annular_sector.yaml"));
  EXPECT_EQ(model.blocks.size(), 6u);
  EXPECT_EQ(model.edges.size(), 18u);
  const double theta = 30.0 * Pi / 180.0;
  EXPECT_NEAR(parameter(model, "theta"), theta, 1e-16);
  EXPECT_DOUBLE_EQ(parameter(model, "r_mid"), 0.75);
  // {rotate: in0_b, angle: theta}
  const Vec3& rotated = position(model, "in3_b");
  EXPECT_NEAR(rotated.x(), 0.5 * std::cos(theta), 1e-15);
  EXPECT_NEAR(rotated.y(), 0.5 * std::sin(theta), 1e-15);
  EXPECT_NEAR(rotated.z(), 0.0, 1e-15);

  const Block& inner = model.blocks[model.findBlock("in_2")];
  EXPECT_EQ(inner.laws[0].kind, DistributionLaw::Kind::FirstCell);
  EXPECT_DOUBLE_EQ(inner.laws[0].firstCellSize, 0.01);
  EXPECT_DOUBLE_EQ(inner.laws[0].expansionRatio, 1.2);
  EXPECT_EQ(inner.laws[8].kind, DistributionLaw::Kind::TwoSided);
  EXPECT_DOUBLE_EQ(inner.laws[8].expansionRatio, 1.15);

  const auto find = [&](const std::string& name) -> const Patch& {
    for (const Patch& p : model.patches)
      if (p.name == name)
        return p;
    throw std::runtime_error("no patch " + name);
  };
  const Patch& low = find("periodic_low");
  const Patch& high = find("periodic_high");
  EXPECT_EQ(low.type, "periodic");
  EXPECT_EQ(low.periodicPartner, "periodic_high");
  EXPECT_EQ(high.periodicPartner, "periodic_low"); // implied by the partner
  EXPECT_NEAR(low.periodicAngle, theta, 1e-16);
  EXPECT_EQ(high.periodicAngle, -low.periodicAngle); // inverse rotation implied
  EXPECT_EQ(low.periodicAxis, Vec3::UnitZ());
  EXPECT_EQ(low.faces.size(), 2u);
}

TEST(Template, WedgeSectorParses)
{
  const BlockModel model = loadTemplate(templatePath("wedge_sector.yaml"));
  ASSERT_EQ(model.blocks.size(), 2u);
  const Block& core = model.blocks[model.findBlock("core")];
  // the collapsed edges on the axis: V0 = V3 and V4 = V7
  EXPECT_EQ(core.vertices[0], core.vertices[3]);
  EXPECT_EQ(core.vertices[4], core.vertices[7]);
  EXPECT_NE(core.vertices[0], core.vertices[4]);
  EXPECT_NEAR(parameter(model, "phi"), Pi / 3, 1e-15);
}

TEST(Template, EveryExampleHasCommentedParameters)
{
  for (const std::string& name : ExampleTemplates)
  {
    const std::vector<ParameterInfo> parameters = templateParameters(templatePath(name));
    ASSERT_FALSE(parameters.empty()) << name;
    for (const ParameterInfo& p : parameters)
    {
      EXPECT_FALSE(p.comment.empty()) << name << ": parameter " << p.name << " has no comment";
      EXPECT_TRUE(std::isfinite(p.value));
    }
  }
}

TEST(Template, ParameterInfo)
{
  const std::vector<ParameterInfo> parameters =
    templateParameters(templatePath("cylinder_in_box.yaml"), { { "D", "B/8" } });
  ASSERT_GE(parameters.size(), 8u);
  EXPECT_EQ(parameters[0].name, "R");
  EXPECT_EQ(parameters[0].expression, "0.5");
  EXPECT_EQ(parameters[0].value, 0.5);
  EXPECT_EQ(parameters[0].comment, "cylinder radius [m]");
  EXPECT_EQ(parameters[2].name, "D");
  EXPECT_EQ(parameters[2].expression, "1.0"); // as written in the template ...
  EXPECT_EQ(parameters[2].value, 0.25);       // ... evaluated with the override
  EXPECT_EQ(parameters[7].name, "c45");
  EXPECT_EQ(parameters[7].expression, "cos(45deg)");
  EXPECT_NEAR(parameters[7].value, std::sqrt(0.5), 1e-16);
}

TEST(Template, Overrides)
{
  const BlockModel model = loadTemplate(templatePath("cylinder_in_box.yaml"),
    { { "R", "0.25" }, { "n_around", "2*4" }, { "k_wall", "1 + 0.05" } });
  EXPECT_EQ(parameter(model, "R"), 0.25);
  const double c45 = std::cos(Pi / 4);
  EXPECT_NEAR(position(model, "w_ne0").x(), 0.25 * c45, 1e-16);
  for (const Block& block : model.blocks)
  {
    EXPECT_EQ(block.cells[0], 8);
    EXPECT_EQ(block.cells[1], 16);
    EXPECT_DOUBLE_EQ(block.laws[1].expansionRatio, 1.05);
  }
  // An override may use the parameters defined before it.
  const BlockModel scaled = loadTemplate(templatePath("cylinder_in_box.yaml"), { { "D", "4*R" } });
  EXPECT_EQ(position(scaled, "b_ne1").z(), 2.0);
}

TEST(Template, Expressions)
{
  const std::string text = R"yaml(blockforge: 1
parameters:
  a: 45deg            # degrees suffix
  b: 1.5e1deg         # with an exponent
  c: 2*pi - 360*deg   # constants
  x2deg: 3            # a name that merely ends in deg
  d: x2deg*2
  e: min(a, b) / deg
  f: "c > -1 ? 7 : 8" # quoted: contains ': '
vertices:
  v0: [0, 0, 0]
  v1: [1, 0, 0]
  v2: [1, 1, 0]
  v3: [0, 1, 0]
  v4: [0, 0, 1]
  v5: [1, 0, 1]
  v6: [1, 1, 1]
  v7: [0, 1, "max(1, f/7)"]
blocks:
  box: {vertices: [v0, v1, v2, v3, v4, v5, v6, v7], cells: [1, 1, 1]}
)yaml";
  const BlockModel model = parseTemplate(text, "expressions.yaml");
  EXPECT_NEAR(parameter(model, "a"), Pi / 4, 1e-16);
  EXPECT_NEAR(parameter(model, "b"), 15 * Pi / 180, 1e-16);
  EXPECT_NEAR(parameter(model, "c"), 0.0, 1e-15);
  EXPECT_EQ(parameter(model, "d"), 6.0);
  EXPECT_NEAR(parameter(model, "e"), 15.0, 1e-12);
  EXPECT_EQ(parameter(model, "f"), 7.0);
  EXPECT_EQ(position(model, "v7").z(), 1.0);
  EXPECT_EQ(model.name, "expressions"); // from the file name when `name` is absent
}

// ------------------------------------------------------------------ located errors
TEST(TemplateErrors, ValidBaseParses)
{
  const BlockModel model = parseTemplate(TwoBoxes, TwoBoxesFile);
  EXPECT_EQ(model.blocks.size(), 2u);
}

TEST(TemplateErrors, MissingFile)
{
  const std::string path = templatePath("no_such_template.yaml");
  expectError([&] { loadTemplate(path); }, { path, "cannot open" });
  expectError([&] { templateParameters(path); }, { path });
}

TEST(TemplateErrors, YamlSyntaxError)
{
  const std::string text =
    replaced(TwoBoxes, "  inlet: {type: inlet, faces: [left.i0]}", "  inlet: {type: inlet, faces: [left.i0}");
  expectTwoBoxesError(text, "inlet: {type", "", { "YAML syntax error" });
}

TEST(TemplateErrors, UnknownVertex)
{
  const std::string text = replaced(TwoBoxes, "[a1, b1, b2, a2,", "[a1, b1, b9, a2,");
  expectTwoBoxesError(
    text, "[a1, b1, b9", "block 'right'", { "unknown vertex 'b9'", "did you mean 'b1'" });
}

TEST(TemplateErrors, BadExpression)
{
  expectTwoBoxesError(replaced(TwoBoxes, "L: 1.0", "L: 1.0 +"), "L: 1.0 +", "parameter 'L'",
    { "cannot evaluate '1.0 +'" });
  expectTwoBoxesError(replaced(TwoBoxes, "n: 4", "n: m*2"), "n: m*2", "parameter 'n'",
    { "unknown name 'm'", "parameters available here: L" });
  expectTwoBoxesError(replaced(TwoBoxes, "b1: [2*L, 0, 0]", "b1: [2*L, 0, sqrt(-L)]"),
    "b1: [2*L", "vertex 'b1'", { "NaN" });
  expectTwoBoxesError(replaced(TwoBoxes, "b1: [2*L, 0, 0]", "b1: [2*L, 0, min(0, L)]"),
    "b1: [2*L", "vertex 'b1'", { "quote" });
}

TEST(TemplateErrors, UnknownOverride)
{
  expectTwoBoxesError(TwoBoxes, "parameters:", "parameter override 'N'",
    { "no such parameter", "did you mean 'n'", "declared parameters: L, n" }, { { "N", "3" } });
  expectTwoBoxesError(TwoBoxes, "L: 1.0", "parameter 'L'", { "override", "unknown name 'q'" },
    { { "L", "q" } });
}

TEST(TemplateErrors, SevenVertices)
{
  const std::string text =
    replaced(TwoBoxes, "[a1, b1, b2, a2, a5, b5, b6, a6]", "[a1, b1, b2, a2, a5, b5, b6]");
  expectTwoBoxesError(text, "[a1, b1, b2, a2, a5, b5, b6]", "block 'right'",
    { "needs 8 vertices", "got 7" });
}

TEST(TemplateErrors, NonWholeCells)
{
  const std::string text =
    replaced(TwoBoxes, "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]",
      "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n/3, n, n]");
  expectTwoBoxesError(text, "cells: [n/3", "block 'right'", { "whole numbers", "i = 'n/3'" });
  expectTwoBoxesError(replaced(TwoBoxes, "cells: [n, n, n]", "cells: [n, 0, n]"),
    "cells: [n, 0, n]", "block 'left'", { "whole numbers from 1" });
}

TEST(TemplateErrors, BadMinCells)
{
  const std::string left = "    cells: [n, n, n]\n  right:";
  expectTwoBoxesError(replaced(TwoBoxes, left, "    cells: [n, n, n]\n    min_cells: [3, 0, 1]\n  right:"),
    "min_cells: [3, 0, 1]", "block 'left'", { "min_cells must be whole numbers from 1", "j = '0'" });
  expectTwoBoxesError(replaced(TwoBoxes, left, "    cells: [n, n, n]\n    min_cells: [3, 2]\n  right:"),
    "min_cells: [3, 2]", "block 'left'", { "'min_cells' expects three counts" });
  // j and k run along the face the boxes share: the same floor on both sides, or an error
  // naming the edge and both blocks (a floor above cells counts as cells: 4 here)
  expectTwoBoxesError(replaced(TwoBoxes, left, "    cells: [n, n, n]\n    min_cells: [1, 3, 1]\n  right:"),
    "  right:", "block 'right'", { "edge a1-a2", "min_cells 1 along j here but 3 in block 'left'" });
  EXPECT_NO_THROW(parseTemplate(replaced(replaced(TwoBoxes, left,
    "    cells: [n, n, n]\n    min_cells: [1, 9, 1]\n  right:"), "    cells: [n, n, n]\npatches",
    "    cells: [n, n, n]\n    min_cells: [1, 4, 1]\npatches"), TwoBoxesFile));
}

TEST(TemplateErrors, MismatchedNodeCountsOnSharedEdge)
{
  const std::string text =
    replaced(TwoBoxes, "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]",
      "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, 2*n, n]");
  // The message names both blocks and the edge by its vertex names.
  expectTwoBoxesError(text, "  right:", "block 'right'",
    { "edge a1-a2", "8 cells here but 4 in block 'left'" });
}

TEST(TemplateErrors, MismatchedGradingOnSharedEdge)
{
  const std::string text = replaced(TwoBoxes,
    "    vertices: [a0, a1, a2, a3, a4, a5, a6, a7]\n    cells: [n, n, n]",
    "    vertices: [a0, a1, a2, a3, a4, a5, a6, a7]\n    cells: [n, n, n]\n"
    "    grading: {j: {geometric: 1.2}}");
  expectTwoBoxesError(text, "  right:", "block 'right'",
    { "edge a1-a2", "differently from block 'left'" });
  // The same law on both sides is fine.
  const std::string both = replaced(text,
    "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]",
    "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]\n"
    "    grading: {j: {geometric: 1.2}}");
  EXPECT_NO_THROW(parseTemplate(both, TwoBoxesFile));
  // So is the inverse law on a block that runs the edge the other way round.
  const std::string flipped = replaced(replaced(TwoBoxes,
    "    vertices: [a0, a1, a2, a3, a4, a5, a6, a7]\n    cells: [n, n, n]",
    "    vertices: [a0, a1, a2, a3, a4, a5, a6, a7]\n    cells: [n, n, n]\n"
    "    grading: {j: {geometric: 1.25}}"),
    "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]",
    "    vertices: [b2, a2, a1, b1, b6, a6, a5, b5]\n    cells: [n, n, n]\n"
    "    grading: {j: {geometric: 0.8}}");
  EXPECT_NO_THROW(parseTemplate(replaced(flipped, "[right.i1]", "[right.i0]"), TwoBoxesFile));
}

TEST(TemplateErrors, NamedEdgeInMessage)
{
  const std::string text = replaced(replaced(TwoBoxes, "blocks:", "edges:\n  seam: {line: [a2, a1]}\nblocks:"),
    "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]",
    "    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, 3, n]");
  expectTwoBoxesError(text, "  right:", "block 'right'", { "edge 'seam' (a1-a2)", "'left'" });
}

TEST(TemplateErrors, FaceSharedByThreeBlocks)
{
  const std::string text = replaced(TwoBoxes, "patches:",
    "  again:\n    vertices: [a1, b1, b2, a2, a5, b5, b6, a6]\n    cells: [n, n, n]\npatches:");
  expectTwoBoxesError(text, "  again:", "block 'again'",
    { "face again.i0 is also a face of left.i1, right.i0", "at most two blocks" });
}

TEST(TemplateErrors, InsideOutBlock)
{
  const std::string text = replaced(
    TwoBoxes, "[a0, a1, a2, a3, a4, a5, a6, a7]", "[a1, a0, a3, a2, a5, a4, a7, a6]");
  expectTwoBoxesError(text, "  left:", "block 'left'", { "inside-out", "Fig. 7", "right-handed" });
}

TEST(TemplateErrors, InternalFaceInPatch)
{
  const std::string text = replaced(TwoBoxes, "faces: [left.i0]", "faces: [left.i0, left.i1]");
  expectTwoBoxesError(text, "inlet: {type", "patch 'inlet'",
    { "face left.i1 is internal", "right.i0" });
}

TEST(TemplateErrors, FaceInTwoPatches)
{
  const std::string text = replaced(TwoBoxes, "faces: [right.i1]", "faces: [right.i1, left.i0]");
  expectTwoBoxesError(text, "outlet: {type", "patch 'outlet'",
    { "left.i0", "already in patch 'inlet'" });
}

TEST(TemplateErrors, PeriodicPartnerMissing)
{
  const std::string text = TwoBoxes +
    "  low: {type: periodic, faces: [left.j0], partner: hihg, axis: [1, 0, 0], angle: 90deg}\n"
    "  high: {type: periodic, faces: [left.k1]}\n";
  expectTwoBoxesError(text, "  low: {type: periodic", "patch 'low'",
    { "periodic partner 'hihg' is not a patch", "did you mean 'high'" });
}

TEST(TemplateErrors, PeriodicFacesMustMatch)
{
  // j0 of `left` rotated by 90 deg about the x axis through (0, 0, 0) is not on k1.
  const std::string text = TwoBoxes +
    "  low: {type: periodic, faces: [left.j0], partner: high, axis: [1, 0, 0], angle: 90deg}\n"
    "  high: {type: periodic, faces: [left.k1]}\n";
  expectTwoBoxesError(text, "  low: {type: periodic", "patch 'low'",
    { "does not land on a face of periodic partner 'high'" });
  // About the box's own x axis through (0, 0.5, 0.5), it is.
  const std::string good = replaced(text, "axis: [1, 0, 0]", "axis: [1, 0, 0], origin: [0, 0.5, 0.5]");
  EXPECT_NO_THROW(parseTemplate(replaced(good, "angle: 90deg", "angle: -90deg"), TwoBoxesFile));
}

TEST(TemplateErrors, VersionAndTopLevel)
{
  expectError([] { parseTemplate("name: x\nvertices: {}\n", "noversion.yaml"); },
    { "noversion.yaml:1: ", "missing 'blockforge: 1'" });
  expectTwoBoxesError(replaced(TwoBoxes, "blockforge: 1", "blockforge: 3"), "blockforge: 3", "",
    { "format 3", "update BlockForge" });
  expectTwoBoxesError(replaced(TwoBoxes, "patches:", "patchs:"), "patchs:", "",
    { "unknown key 'patchs'", "did you mean 'patches'" });
  expectError([] { parseTemplate("", "empty.yaml"); }, { "empty.yaml:1: ", "empty" });
}

TEST(TemplateErrors, UnknownKeysAndNames)
{
  expectTwoBoxesError(replaced(TwoBoxes, "cells: [n, n, n]", "cels: [n, n, n]"), "cels:",
    "block 'left'", { "unknown key 'cels'", "did you mean 'cells'" });
  expectTwoBoxesError(replaced(TwoBoxes, "faces: [right.i1]", "faces: [right.x1]"),
    "outlet: {type", "patch 'outlet'", { "unknown face 'x1'" });
  expectTwoBoxesError(replaced(TwoBoxes, "faces: [right.i1]", "faces: [rigth.i1]"),
    "outlet: {type", "patch 'outlet'", { "unknown block 'rigth'", "did you mean 'right'" });
  expectTwoBoxesError(replaced(TwoBoxes, "type: outlet", "type: outflow"), "outlet: {type",
    "patch 'outlet'", { "unknown patch type 'outflow'" });
  expectTwoBoxesError(replaced(TwoBoxes, "cells: [n, n, n]", "cells: [n, n, n]\n    grading: {i: {geometrc: 2}}"),
    "grading:", "block 'left'", { "unknown key 'geometrc'" });
  expectTwoBoxesError(replaced(TwoBoxes, "cells: [n, n, n]", "cells: [n, n, n]\n    grading: {edges: {E13: uniform}}"),
    "grading:", "block 'left'", { "unknown key 'E13'" });
}

TEST(TemplateErrors, DuplicateNames)
{
  expectTwoBoxesError(replaced(TwoBoxes, "  a7: [0, L, L]", "  a7: [0, L, L]\n  a0: [1, 1, 1]"),
    "  a0: [1, 1, 1]", "vertex 'a0'", { "defined twice", "first on line 7" });
  expectTwoBoxesError(
    replaced(TwoBoxes, "blocks:", "edges:\n  e1: {line: [a0, a1]}\n  e2: {line: [a1, a0]}\nblocks:"),
    "  e2: {line", "edge 'e2'", { "same vertices as edge 'e1'" });
}

TEST(TemplateErrors, EdgeGeometry)
{
  // a0 and a1 are not at the same distance from this centre: GeometryError -> edge named
  const std::string text = replaced(TwoBoxes, "blocks:",
    "edges:\n  bent: {arc: [a0, a1], centre: [0, 0.3, 0]}\nblocks:");
  expectTwoBoxesError(text, "  bent:", "edge 'bent'", {});
  const std::string unused = replaced(TwoBoxes, "blocks:",
    "edges:\n  diagonal: {line: [a0, a6]}\nblocks:");
  expectTwoBoxesError(unused, "  diagonal:", "edge 'diagonal'", { "no block has an edge" });
}

TEST(TemplateErrors, ErrorParts)
{
  try
  {
    parseTemplate(replaced(TwoBoxes, "[a1, b1, b2, a2,", "[a1, b1, b9, a2,"), TwoBoxesFile);
    FAIL();
  }
  catch (const TemplateError& error)
  {
    EXPECT_EQ(error.file(), TwoBoxesFile);
    EXPECT_EQ(error.line(), lineContaining(TwoBoxes, "[a1, b1, b2, a2,"));
    EXPECT_EQ(error.entity(), "block 'right'");
  }
}

// ------------------------------------------------------------------ model document
TEST(ModelDocument, RoundTripIsBitIdentical)
{
  for (const std::string& name : ExampleTemplates)
  {
    SCOPED_TRACE(name);
    // Overrides with numbers that have no short decimal form.
    const ParameterOverrides overrides = name == "cylinder_in_box.yaml"
      ? ParameterOverrides{ { "R", "1/3" }, { "k_wall", "1.1 + 1e-9" } }
      : ParameterOverrides{};
    const BlockModel model = loadTemplate(templatePath(name), overrides);
    const std::string document = writeModelDocument(model);
    // Format 1 unless a vertex has a rule its constraint does not imply (annular_sector's
    // rotated copies: format 3).
    EXPECT_NE(document.find(name == "annular_sector.yaml" ? "blockforge_model: 3"
                                                          : "blockforge_model: 1"),
      std::string::npos);
    const BlockModel reread = readModelDocument(document);
    expectIdenticalModels(model, reread);
    EXPECT_EQ(writeModelDocument(reread), document);

    // ... and so is the grid meshed from it.
    const auto original = meshAll(model);
    const auto fromDocument = meshAll(reread);
    ASSERT_EQ(original.xyz.size(), fromDocument.xyz.size());
    for (std::size_t b = 0; b < original.xyz.size(); ++b)
    {
      ASSERT_EQ(original.xyz[b].size(), fromDocument.xyz[b].size());
      EXPECT_TRUE(sameBits(original.xyz[b], fromDocument.xyz[b])) << "block " << b;
    }
  }
}

TEST(ModelDocument, KeepsMinCells)
{
  // min_cells is written only where a block has one (older documents read as before)
  const std::string plain = writeModelDocument(parseTemplate(TwoBoxes, TwoBoxesFile));
  EXPECT_EQ(plain.find("min_cells"), std::string::npos);
  const BlockModel model = parseTemplate(replaced(TwoBoxes, "    cells: [n, n, n]\n  right:",
    "    cells: [n, n, n]\n    min_cells: [3, 1, 1]\n  right:"), TwoBoxesFile);
  EXPECT_EQ(model.blocks[0].minCells, (std::array<int, 3>{ 3, 1, 1 }));
  const std::string document = writeModelDocument(model);
  EXPECT_NE(document.find("min_cells: [3, 1, 1]"), std::string::npos);
  const BlockModel reread = readModelDocument(document);
  expectIdenticalModels(model, reread);
  EXPECT_EQ(writeModelDocument(reread), document);
  expectError([&] { readModelDocument(replaced(document, "min_cells: [3, 1, 1]",
                      "min_cells: [3, 0, 1]")); },
    { "block 'left'", "min_cells must be at least 1" });
}

TEST(ModelDocument, ErrorsAfterReloadNameTheTemplateLine)
{
  BlockModel model = parseTemplate(TwoBoxes, TwoBoxesFile);
  model.blocks[1].cells[1] = 7; // as if an optimizer broke it after the reload
  const BlockModel reread = readModelDocument(writeModelDocument(model));
  expectError([&] { checkModel(reread); },
    { TwoBoxesFile + ":" + std::to_string(lineContaining(TwoBoxes, "  right:")) +
        ": block 'right'",
      "'left'" });
}

TEST(ModelDocument, RejectsNewerAndMalformedDocuments)
{
  const std::string document = writeModelDocument(parseTemplate(TwoBoxes, TwoBoxesFile));
  expectError([&] { readModelDocument(replaced(document, "blockforge_model: 1", "blockforge_model: 5")); },
    { "<model document>", "newer", "update BlockForge" });
  expectError([&] { readModelDocument("just: text\n"); }, { "<model document>", "not a BlockForge model" });
  expectError([&] { readModelDocument("blockforge_model: 1\nvertices: [{name: a, position: [0, 0]}]\n"); },
    { "<model document>:2: vertex 'a'" });
  expectError([&] { readModelDocument("{ broken"); }, { "<model document>" });
  expectError([&] { readModelDocument(replaced(document, "cells: [4, 4, 4]", "cells: [4, 4.5, 4]")); },
    { "block 'left'", "whole number" });
}
