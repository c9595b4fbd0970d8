// Placement rules and the mesh plan: moving a control point moves what follows it, the
// plan recomputes only the blocks that depend on it, the result is the grid a fresh mesher
// makes of the moved model bit for bit, and infeasible moves come back as values.
#include "MeshPlan.h"
#include "ModelDocument.h"
#include "Placement.h"
#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
struct Passage
{
  BlockModel model;
  CarrierGeometry carriers;
};

/// axial_passage_oh on Rotor 37, read once for all tests.
const Passage& rotor37Passage()
{
  static const Passage passage = [] {
    Passage p;
    const TemplateInputs inputs =
      test::readTemplateInputs(test::sourcePath("Data/rotor37/turbogrid/BladeGen.inf"));
    p.model = loadTemplate(test::templatePath("axial_passage_oh.yaml"), {}, &inputs, &p.carriers);
    return p;
  }();
  return passage;
}

int vertexIndex(const BlockModel& model, const std::string& name)
{
  const int index = model.findVertex(name);
  EXPECT_GE(index, 0) << name;
  return index;
}

/// Every block of `plan` equals what MultiBlockMesher makes of the plan's model, bit for bit.
void expectSameAsFreshMesher(const MeshPlan& plan)
{
  const test::Grid fresh = test::meshAll(plan.model());
  ASSERT_EQ(static_cast<int>(fresh.xyz.size()), plan.blockCount());
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), fresh.xyz[b])) << "block " << b;
  }
}

const FreeParameter& sParameter(const std::vector<FreeParameter>& parameters, int vertex)
{
  for (const FreeParameter& parameter : parameters)
  {
    if (parameter.vertex == vertex && parameter.component == 0)
    {
      return parameter;
    }
  }
  ADD_FAILURE() << "no free parameter s of vertex " << vertex;
  return parameters.front();
}
} // namespace

TEST(Placement, PassageRulesAndOrder)
{
  const BlockModel& model = rotor37Passage().model;
  const int oa = vertexIndex(model, "oa_f_h"), a = vertexIndex(model, "a_f_h");
  const int lo = vertexIndex(model, "lo_f_h"), hi = vertexIndex(model, "hi_f_h");
  EXPECT_EQ(model.vertices[oa].rule.kind, VertexRule::Kind::OnCarrier);
  EXPECT_EQ(model.vertices[a].rule.kind, VertexRule::Kind::Projected);
  EXPECT_EQ(model.vertices[a].rule.source, oa);
  EXPECT_EQ(model.vertices[hi].rule.kind, VertexRule::Kind::Periodic);
  EXPECT_EQ(ruleSource(model.vertices[hi]), lo);
  EXPECT_EQ(model.vertices[vertexIndex(model, "le_h")].rule.kind, VertexRule::Kind::OnCarrier);
  const std::vector<int> order = placementOrder(model);
  ASSERT_EQ(order.size(), model.vertices.size());
  std::vector<int> position(order.size());
  for (std::size_t n = 0; n < order.size(); ++n)
  {
    position[order[n]] = static_cast<int>(n);
  }
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    const int source = ruleSource(model.vertices[v]);
    if (source >= 0)
    {
      EXPECT_LT(position[source], position[v]) << model.vertices[v].name;
    }
  }
  const std::vector<std::vector<int>> dependents = vertexDependents(model);
  EXPECT_NE(std::find(dependents[oa].begin(), dependents[oa].end(), a), dependents[oa].end());

  // Applying every rule again changes nothing: the template placed its vertices with them.
  BlockModel again = model;
  std::vector<int> all(model.vertices.size());
  for (std::size_t v = 0; v < all.size(); ++v)
  {
    all[v] = static_cast<int>(v);
  }
  applyPlacement(again, rotor37Passage().carriers, all);
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    EXPECT_TRUE(test::sameBits(again.vertices[v].position, model.vertices[v].position))
      << model.vertices[v].name;
  }

  // Free parameters: s of every curve control point, s and t on surfaces, with bounds.
  const std::vector<FreeParameter> parameters = freeParameters(model, rotor37Passage().carriers);
  EXPECT_EQ(sParameter(parameters, oa).vertex, oa);
  for (const FreeParameter& parameter : parameters)
  {
    EXPECT_EQ(model.vertices[parameter.vertex].rule.kind, VertexRule::Kind::OnCarrier);
    EXPECT_LT(parameter.low, parameter.high);
    EXPECT_NE(parameter.vertex, a);
  }
}

TEST(Placement, ProjectedVertexFollowsItsSource)
{
  BlockModel model = rotor37Passage().model;
  const CarrierGeometry& carriers = rotor37Passage().carriers;
  const int oa = vertexIndex(model, "oa_f_h"), a = vertexIndex(model, "a_f_h");
  const Vec3 before = model.vertices[a].position;
  const FreeParameter s = sParameter(freeParameters(model, carriers), oa);
  const std::vector<int> moved = moveParameter(model, carriers, s, model.vertices[oa].constraint.s + 0.01);
  EXPECT_EQ(moved.front(), oa);
  EXPECT_NE(std::find(moved.begin(), moved.end(), a), moved.end());
  EXPECT_GT((model.vertices[a].position - before).norm(), 1e-6);
  // a_f_h is where oa_f_h projects onto the blade curve now.
  double u = 0.0, t = 0.0, distance = 0.0;
  const int blade = model.vertices[a].constraint.carrier;
  carriers.project(blade, model.vertices[oa].position, u, t, distance);
  EXPECT_TRUE(test::sameBits(model.vertices[a].position, carriers.point(blade, u, t)));
}

TEST(Placement, RulesTravelInTheModelDocument)
{
  const BlockModel& model = rotor37Passage().model;
  const std::string document = writeModelDocument(model);
  EXPECT_NE(document.find("blockforge_model: 3"), std::string::npos);
  EXPECT_NE(document.find("rule: projected, source: oa_f_h"), std::string::npos);
  const BlockModel reread = readModelDocument(document);
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    EXPECT_EQ(reread.vertices[v].rule.kind, model.vertices[v].rule.kind) << model.vertices[v].name;
    EXPECT_EQ(reread.vertices[v].rule.source, model.vertices[v].rule.source);
  }
  EXPECT_EQ(writeModelDocument(reread), document);

  // A document of format 2 (before rules) still reads: the rules are those its
  // constraints imply, and it meshes the same grid.
  std::string older = test::replaced(document, "blockforge_model: 3", "blockforge_model: 2");
  for (std::size_t at; (at = older.find(", rule: ")) != std::string::npos;)
  {
    older.erase(at, older.find(", line:", at) - at);
  }
  const BlockModel old = readModelDocument(older);
  const int a = vertexIndex(old, "a_f_h");
  EXPECT_EQ(old.vertices[a].rule.kind, VertexRule::Kind::OnCarrier);
  EXPECT_EQ(old.vertices[vertexIndex(old, "hi_f_h")].rule.kind, VertexRule::Kind::Periodic);
  const test::Grid expected = test::meshAll(model);
  const test::Grid fromOld = test::meshAll(old);
  for (std::size_t b = 0; b < expected.xyz.size(); ++b)
  {
    EXPECT_TRUE(test::sameBits(expected.xyz[b], fromOld.xyz[b])) << "block " << b;
  }

  // Bad rules are named.
  test::expectError([&] { readModelDocument(test::replaced(document, "rule: projected, source: oa_f_h", "rule: glued, source: oa_f_h")); },
    { "vertex 'a_f_h'", "unknown placement rule 'glued'" });
}

TEST(Placement, CyclesAreReported)
{
  BlockModel model = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  model.vertices[0].rule.kind = VertexRule::Kind::Rotated;
  model.vertices[0].rule.source = 1;
  model.vertices[1].rule.kind = VertexRule::Kind::Rotated;
  model.vertices[1].rule.source = 0;
  test::expectError([&] { placementOrder(model); }, { "a cycle" });
}

TEST(MeshPlan, MovingOneControlPointUpdatesOnlyItsBlocks)
{
  const Passage& passage = rotor37Passage();
  MeshPlan plan(passage.model, passage.carriers);
  EXPECT_EQ(static_cast<int>(plan.updatedBlocks().size()), plan.blockCount());
  expectSameAsFreshMesher(plan);

  const int oa = vertexIndex(plan.model(), "oa_f_h");
  const FreeParameter s = sParameter(freeParameters(plan.model(), plan.carriers()), oa);
  const double original = plan.model().vertices[oa].constraint.s;
  for (const double delta : { 0.004, -0.003 })
  {
    SCOPED_TRACE(delta);
    const std::vector<int> moved = moveParameter(plan.model(), plan.carriers(), s, original + delta);
    const Feasibility feasibility = plan.update(moved);
    EXPECT_TRUE(feasibility.feasible()) << feasibility.message;
    EXPECT_GT(plan.updatedBlocks().size(), 0u);
    EXPECT_LT(static_cast<int>(plan.updatedBlocks().size()), plan.blockCount());
    expectSameAsFreshMesher(plan);
  }
  // Back where it was: the original grid, bit for bit.
  plan.update(moveParameter(plan.model(), plan.carriers(), s, original));
  const test::Grid initial = test::meshAll(passage.model);
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), initial.xyz[b])) << "block " << b;
  }
}

TEST(MeshPlan, InfeasibleMovesAreValuesNamingTheBlock)
{
  const BlockModel model = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  MeshPlan plan(model, CarrierGeometry(model));
  // Vertex a1 (shared by both cubes) pushed through the left cube: it turns inside out.
  const int a1 = vertexIndex(plan.model(), "a1");
  const Vec3 original = plan.model().vertices[a1].position;
  plan.model().vertices[a1].position = Vec3(-0.5, 0.0, 0.0);
  const Feasibility folded = plan.update({ a1 });
  EXPECT_FALSE(folded.feasible());
  EXPECT_EQ(folded.problem, Feasibility::Problem::FoldedCorner);
  EXPECT_EQ(folded.block, plan.model().findBlock("left"));
  EXPECT_NE(folded.message.find("block 'left'"), std::string::npos) << folded.message;
  // Moved back, the plan is feasible again and has the original grid.
  plan.model().vertices[a1].position = original;
  const Feasibility restored = plan.update({ a1 });
  EXPECT_TRUE(restored.feasible()) << restored.message;
  const test::Grid initial = test::meshAll(model);
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), initial.xyz[b])) << "block " << b;
  }
  // A cell inverted inside a block: one node of a unit cube's grid pushed past another.
  std::vector<double> grid = plan.blockNodes(0);
  const std::array<int, 3> n = plan.nodeCounts(0);
  grid[3 * (1 + n[0] * (1 + n[1] * 1))] = -3.0; // node (1, 1, 1) moved to x = -3
  const Feasibility inverted = checkCells(grid.data(), n, 0);
  EXPECT_EQ(inverted.problem, Feasibility::Problem::InvertedCell);
  EXPECT_EQ(inverted.block, 0);
  EXPECT_TRUE(checkCells(plan.blockNodes(0).data(), n, 0).feasible());
}

TEST(MeshPlan, MatchedEdgesFollowMovesAsAFreshMesherDoes)
{
  // axial_passage_h grades its edges with `match`: a move changes the lengths at the
  // moved vertex, so the end cells of the edges continuing them change too.
  const TemplateInputs inputs =
    test::readTemplateInputs(test::sourcePath("Data/rotor37/turbogrid/BladeGen.inf"));
  CarrierGeometry carriers;
  const BlockModel model =
    loadTemplate(test::templatePath("axial_passage_h.yaml"), {}, &inputs, &carriers);
  MeshPlan plan(model, carriers);
  expectSameAsFreshMesher(plan);
  const int mid = vertexIndex(plan.model(), "lo_mid_h");
  const std::vector<FreeParameter> parameters = freeParameters(plan.model(), plan.carriers());
  const FreeParameter* s = nullptr;
  for (const FreeParameter& parameter : parameters)
  {
    if (parameter.vertex == mid)
    {
      s = &parameter;
      break;
    }
  }
  ASSERT_NE(s, nullptr);
  const double original = plan.model().vertices[mid].constraint.s;
  const double originalT = plan.model().vertices[mid].constraint.t;
  const double start = s->component == 0 ? original : originalT;
  for (const double delta : { 0.01, -0.01 })
  {
    SCOPED_TRACE(delta);
    const Feasibility feasibility =
      plan.update(moveParameter(plan.model(), plan.carriers(), *s, start + delta));
    EXPECT_TRUE(feasibility.feasible()) << feasibility.message;
    expectSameAsFreshMesher(plan);
  }
}
