// Placement rules and the mesh plan: moving a control point moves what follows it, the
// plan recomputes only the blocks that depend on it, the result is the grid a fresh mesher
// makes of the moved model bit for bit, and infeasible moves come back as values.
#include "MeshPlan.h"
#include "ControlProblem.h"

#include <cstdio>
#include "ModelDocument.h"
#include "Placement.h"
#include "TemplateExpressions.h"
#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <memory>

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

/// Every block of `plan` equals the same block of `other`, bit for bit.
void expectSameGrids(const MeshPlan& plan, const MeshPlan& other)
{
  ASSERT_EQ(plan.blockCount(), other.blockCount());
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), other.blockNodes(b))) << "block " << b;
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
  // a_f_h is the projection of ta_f_h, the O curve's point at oa_f_h's parameter (or, with
  // o_fan_prisms at a sharp edge, off the tip), which follows oa_f_h by its expression
  const int ta = vertexIndex(model, "ta_f_h");
  EXPECT_EQ(model.vertices[oa].rule.kind, VertexRule::Kind::OnCarrier);
  EXPECT_EQ(model.vertices[a].rule.kind, VertexRule::Kind::Projected);
  EXPECT_EQ(model.vertices[a].rule.source, ta);
  const std::vector<int>& follows = model.vertices[ta].rule.expressions.follows;
  EXPECT_NE(std::find(follows.begin(), follows.end(), oa), follows.end());
  // and not le_h, which the optimizer moves (o_fan_prisms decides on fixed helpers)
  const int le = vertexIndex(model, "le_h");
  EXPECT_EQ(std::find(follows.begin(), follows.end(), le), follows.end());
  EXPECT_TRUE(test::sameBits(model.vertices[ta].position, model.vertices[oa].position));
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
  EXPECT_NE(std::find(dependents[oa].begin(), dependents[oa].end(), ta), dependents[oa].end());
  EXPECT_NE(std::find(dependents[ta].begin(), dependents[ta].end(), a), dependents[ta].end());

  // Applying every rule again changes nothing: the template placed its vertices with them.
  BlockModel again = model;
  std::vector<int> all(model.vertices.size());
  for (std::size_t v = 0; v < all.size(); ++v)
  {
    all[v] = static_cast<int>(v);
  }
  CarrierGeometry carriers = rotor37Passage().carriers;
  applyPlacement(again, carriers, all);
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
  CarrierGeometry carriers = rotor37Passage().carriers;
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
  EXPECT_NE(document.find("blockforge_model: 4"), std::string::npos);
  EXPECT_NE(document.find("rule: projected, source: ta_f_h"), std::string::npos);
  EXPECT_NE(document.find("through: [lo_f_h, lo_m_h, lo_r_h]"), std::string::npos);
  EXPECT_NE(document.find("expression_scope:"), std::string::npos);
  const BlockModel reread = readModelDocument(document);
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    const VertexRule& rule = model.vertices[v].rule;
    EXPECT_EQ(reread.vertices[v].rule.kind, rule.kind) << model.vertices[v].name;
    EXPECT_EQ(reread.vertices[v].rule.source, rule.source);
    EXPECT_EQ(reread.vertices[v].rule.expressions.texts, rule.expressions.texts);
    EXPECT_EQ(reread.vertices[v].rule.expressions.follows, rule.expressions.follows);
  }
  const int arc = reread.findEdge(vertexIndex(model, "oa_f_h"), vertexIndex(model, "oa_r_h"));
  ASSERT_GE(arc, 0);
  EXPECT_EQ(reread.edges[arc].atExpressions, model.edges[arc].atExpressions);
  EXPECT_EQ(reread.edges[arc].atFollows, model.edges[arc].atFollows);
  EXPECT_FALSE(reread.edges[arc].atFollows.empty()); // ol_a_h: at: [oa_f_h.s, ...]
  EXPECT_EQ(writeModelDocument(reread), document);
  // The reread model places its vertices as the template did, bit for bit.
  BlockModel replaced = reread;
  CarrierGeometry rereadCarriers(reread);
  std::vector<int> all(model.vertices.size());
  for (std::size_t v = 0; v < all.size(); ++v)
  {
    all[v] = static_cast<int>(v);
  }
  applyPlacement(replaced, rereadCarriers, all);
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    EXPECT_TRUE(test::sameBits(replaced.vertices[v].position, model.vertices[v].position))
      << model.vertices[v].name;
  }

  // A document of format 3 (rules, no expressions) still reads.
  BlockModel withoutExpressions = model;
  for (Vertex& vertex : withoutExpressions.vertices)
  {
    vertex.rule.expressions = PlacementExpressions();
  }
  for (Carrier& carrier : withoutExpressions.carriers)
  {
    carrier.throughVertices.clear();
  }
  for (Edge& edge : withoutExpressions.edges)
  {
    edge.atExpressions.clear();
    edge.atFollows.clear();
  }
  withoutExpressions.expressionScope = ExpressionScope();
  const std::string format3 = writeModelDocument(withoutExpressions);
  EXPECT_NE(format3.find("blockforge_model: 3"), std::string::npos);
  EXPECT_EQ(readModelDocument(format3).vertices.size(), model.vertices.size());

  // A document of format 2 (before rules) still reads: the rules are those its
  // constraints imply, and it meshes the same grid.
  std::string older = test::replaced(format3, "blockforge_model: 3", "blockforge_model: 2");
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
  test::expectError([&] { readModelDocument(test::replaced(document, "rule: projected, source: ta_f_h", "rule: glued, source: ta_f_h")); },
    { "vertex 'a_f_h'", "unknown placement rule 'glued'" });
}

/// The OH template on Rotor 37 with `text` in place of `from`.
BlockModel rotor37With(const std::string& from, const std::string& text, CarrierGeometry& carriers)
{
  const TemplateInputs inputs =
    test::readTemplateInputs(test::sourcePath("Data/rotor37/turbogrid/BladeGen.inf"));
  const std::string path = test::templatePath("axial_passage_oh.yaml");
  return parseTemplate(test::replaced(test::readText(path), from, text), path, {}, &inputs, &carriers);
}

std::string exactNumber(double value)
{
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

TEST(Placement, ExpressionAndCurveChainsFollowMovesAsTheTemplateWould)
{
  const Passage& passage = rotor37Passage();
  const BlockModel& model = passage.model;
  const int oa = vertexIndex(model, "oa_f_h"), ob = vertexIndex(model, "ob_f_h");
  const int lo = vertexIndex(model, "lo_f_h"), aIn = vertexIndex(model, "a_in_h");
  const int loIn = vertexIndex(model, "lo_in_h"), hi = vertexIndex(model, "hi_f_h");
  // What follows what: expressions (lo_f_h is mid-way between the O corners, moved across
  // the line between them at a sharp edge, le_turn_h: it follows the corners and what the
  // turn reads, the H lines' slope among them), and the periodic line lo_h drawn through
  // lo_f_h, lo_m_h, lo_r_h.
  const PlacementExpressions& mid = model.vertices[lo].rule.expressions;
  EXPECT_EQ(mid.form, PlacementExpressions::Form::AxialTheta);
  EXPECT_TRUE(std::is_sorted(mid.follows.begin(), mid.follows.end()));
  for (const int corner : { oa, ob })
  {
    EXPECT_TRUE(std::binary_search(mid.follows.begin(), mid.follows.end(), corner));
  }
  EXPECT_FALSE(std::binary_search(mid.follows.begin(), mid.follows.end(), lo));
  EXPECT_EQ(model.vertices[oa].rule.expressions.form, PlacementExpressions::Form::None);
  const int line = model.findCarrier("lo_h");
  ASSERT_GE(line, 0);
  EXPECT_EQ(model.carriers[line].throughVertices,
    (std::vector<int>{ lo, vertexIndex(model, "lo_m_h"), vertexIndex(model, "lo_r_h") }));
  const std::vector<std::vector<int>> dependents = vertexDependents(model);
  for (const int follower : { lo, aIn })
  {
    EXPECT_TRUE(std::binary_search(dependents[oa].begin(), dependents[oa].end(), follower))
      << model.vertices[follower].name;
  }
  EXPECT_TRUE(std::binary_search(dependents[lo].begin(), dependents[lo].end(), loIn));
  EXPECT_TRUE(std::binary_search(dependents[lo].begin(), dependents[lo].end(), hi));

  // oa_f_h moved through the mesh plan, against the template with oa_f_h given there (the
  // plan moved on from one place to the next; 0.0013 once differed in an O-grid arc whose
  // end is given by an expression, before `at` expressions were evaluated again).
  MeshPlan plan(model, passage.carriers);
  const FreeParameter s = sParameter(freeParameters(plan.model(), plan.carriers()), oa);
  const std::string corner = test::readText(test::templatePath("axial_passage_oh.yaml"));
  const std::size_t at = corner.find("  oa_f_h: {on_curve: o_h, at: ");
  ASSERT_NE(at, std::string::npos);
  const std::string line0 = corner.substr(at, corner.find('\n', at) - at);
  for (const double delta : { 0.004, 0.0013, -0.003 })
  {
    SCOPED_TRACE(delta);
    const double moved = model.vertices[oa].constraint.s + delta;
    const Feasibility feasibility =
      plan.update(moveParameter(plan.model(), plan.carriers(), s, moved));
    ASSERT_TRUE(feasibility.feasible()) << feasibility.message;
    CarrierGeometry carriers;
    const BlockModel expected = rotor37With(
      line0, "  oa_f_h: {on_curve: o_h, at: " + exactNumber(moved) + "}", carriers);
    ASSERT_EQ(expected.vertices[oa].constraint.s, moved);
    const BlockModel& followed = plan.model();
    for (std::size_t v = 0; v < model.vertices.size(); ++v)
    {
      EXPECT_TRUE(test::sameBits(followed.vertices[v].position, expected.vertices[v].position))
        << model.vertices[v].name;
      EXPECT_EQ(followed.vertices[v].constraint.s, expected.vertices[v].constraint.s);
      EXPECT_EQ(followed.vertices[v].constraint.t, expected.vertices[v].constraint.t);
    }
    for (std::size_t e = 0; e < model.edges.size(); ++e)
    {
      EXPECT_EQ(followed.edges[e].at, expected.edges[e].at) << model.edges[e].name;
    }
    EXPECT_GT((followed.vertices[lo].position - model.vertices[lo].position).norm(), 1e-6);
    EXPECT_GT((followed.vertices[loIn].position - model.vertices[loIn].position).norm(), 1e-6);
    EXPECT_EQ(followed.carriers[line].parameterPoints, expected.carriers[line].parameterPoints);
    // The curve drawn again is the template's, and the plan's grid is the grid of the
    // moved model (expectSameAsFreshMesher) and, bit for bit, the template's.
    for (const double u : { 0.0, 0.3, 0.5, 1.0 })
    {
      EXPECT_TRUE(test::sameBits(plan.carriers().point(line, u), carriers.point(line, u)));
    }
    expectSameAsFreshMesher(plan);
    const test::Grid grid = test::meshAll(expected);
    for (int b = 0; b < plan.blockCount(); ++b)
    {
      EXPECT_TRUE(test::sameBits(plan.blockNodes(b), grid.xyz[b])) << model.blocks[b].name;
    }
  }

  // The middle point of the periodic line moved alone (no edge ends there): the line is
  // drawn again, and the plan rebuilds the edge on it and the blocks along it.
  const int middle = vertexIndex(model, "lo_m_h");
  FreeParameter t;
  for (const FreeParameter& p : freeParameters(plan.model(), plan.carriers()))
  {
    if (p.vertex == middle && p.component == 1)
    {
      t = p;
    }
  }
  ASSERT_EQ(t.vertex, middle);
  const Eigen::Vector2d before = plan.model().carriers[line].parameterPoints[1];
  const Feasibility shifted = plan.update(
    moveParameter(plan.model(), plan.carriers(), t, plan.model().vertices[middle].constraint.t + 0.002));
  ASSERT_TRUE(shifted.feasible()) << shifted.message;
  EXPECT_NE(plan.model().carriers[line].parameterPoints[1], before);
  EXPECT_NEAR(plan.model().vertices[middle].constraint.t, before[1] + 0.002, 1e-15);
  const std::vector<int>& updated = plan.updatedBlocks();
  EXPECT_NE(std::find(updated.begin(), updated.end(), plan.model().findBlock("M_L")), updated.end());
  expectSameAsFreshMesher(plan);
}

TEST(Placement, GradingsReferToNoVertexAMoveShifts)
{
  // A law's values are numbers once read: one that referred to a corner the optimizer moves
  // would leave the live model's grid other than the template's with the corner given
  // there (the periodic lines' end cells, period_end_*, once followed the O corners). The
  // reader refuses it, naming the block, the law and the vertex; the template's own laws
  // refer to fixed twins placed where the corners were.
  const std::string law = "E4: {ends: [period_end_h, period_end_h]";
  CarrierGeometry carriers;
  test::expectError([&] { rotor37With(law, "E4: {ends: [oa_f_h.s + 0.1, period_end_h]", carriers); },
    { "block 'M_L'", "'grading E4' refers to vertex 'oa_f_h'", "fixed: true" });
  // through a definition and a vertex following a moved one (a_m_h follows le_h)
  test::expectError([&] { rotor37With(law, "E4: {ends: [0.1 + 0*a_m_h.x, period_end_h]", carriers); },
    { "block 'M_L'", "refers to vertex 'a_m_h'" });
  test::expectError([&] { rotor37With(law, "E4: {ends: [0.1 + 0*chord_h, period_end_h]", carriers); },
    { "block 'M_L'", "refers to vertex 'le_h'" });
  // a fixed helper placed by a search is what a grading may refer to
  const BlockModel model = rotor37With(law, "E4: {ends: [0.1 + 0*oa_f0_h.x, period_end_h]", carriers);
  EXPECT_EQ(model.blocks[model.findBlock("M_L")].laws[3].firstCellSize, 0.1);
}

TEST(Placement, ManualMovesThroughTheDocumentFollowAsTheTemplateWould)
{
  // ControlPointMoves as BlockOptimizer applies them, on the model read back from its
  // document (what travels between the pipeline's filters).
  const Passage& passage = rotor37Passage();
  BlockModel model = readModelDocument(writeModelDocument(passage.model));
  CarrierGeometry geometry(model);
  const int ob = vertexIndex(model, "ob_r_s");
  const double moved = model.vertices[ob].constraint.s - 0.003;
  optimize::applyMoves(model, geometry, { { "ob_r_s", { moved } } });
  CarrierGeometry carriers;
  const std::string text = test::readText(test::templatePath("axial_passage_oh.yaml"));
  const std::size_t at = text.find("  ob_r_s: {on_curve: o_s, at: ");
  ASSERT_NE(at, std::string::npos);
  const BlockModel expected = rotor37With(text.substr(at, text.find('\n', at) - at),
    "  ob_r_s: {on_curve: o_s, at: " + exactNumber(moved) + "}", carriers);
  int followed = 0;
  for (std::size_t v = 0; v < model.vertices.size(); ++v)
  {
    EXPECT_TRUE(test::sameBits(model.vertices[v].position, expected.vertices[v].position))
      << model.vertices[v].name;
    followed += model.vertices[v].position != passage.model.vertices[v].position ? 1 : 0;
  }
  EXPECT_GE(followed, 5); // ob_r_s, b_r_s, lo_r_s, hi_r_s, b_out_s, lo_out_s, ...
  const int line = model.findCarrier("lo_s");
  EXPECT_EQ(model.carriers[line].parameterPoints, expected.carriers[line].parameterPoints);
  const test::Grid grid = test::meshAll(model), reference = test::meshAll(expected);
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    EXPECT_TRUE(test::sameBits(grid.xyz[b], reference.xyz[b])) << model.blocks[b].name;
  }
}

TEST(Placement, RememberedExpressionsTakeTheCurrentConstants)
{
  // Placements remember values by the expression and its constants' values: a constant
  // that changed gives the new value, the same values give the bits of a fresh reading,
  // and what fails (an unknown name) fails every time.
  detail::ExpressionMemo memo;
  auto evaluate = [&](double a, double b, const std::string& text, bool remember) {
    detail::ExpressionEvaluator evaluator;
    evaluator.Memo = remember ? &memo : nullptr;
    evaluator.defineQuery("oa.s", a);
    evaluator.define("b", b);
    return evaluator.evaluate(text);
  };
  const std::string text = "oa.s/3 + sin(b)*2deg - min(b, 0.25)";
  const double fresh = evaluate(0.1, 0.7, text, false);
  EXPECT_EQ(evaluate(0.1, 0.7, text, true), fresh);
  EXPECT_EQ(evaluate(0.1, 0.7, text, true), fresh); // remembered
  EXPECT_EQ(evaluate(0.1, 0.2, text, true), evaluate(0.1, 0.2, text, false));
  EXPECT_NE(evaluate(0.1, 0.2, text, true), fresh);
  EXPECT_EQ(evaluate(0.3, 0.7, text, true), evaluate(0.3, 0.7, text, false));
  EXPECT_EQ(evaluate(0.1, 0.7, text, true), fresh);
  for (int round = 0; round < 2; ++round)
  {
    EXPECT_THROW(evaluate(0.1, 0.7, "oa.s + c", true), detail::ExpressionError);
  }
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

TEST(MeshPlan, ThreadsGiveTheSameBits)
{
  // The update runs its arc-length tables, edges, faces and blocks in chunks on threads
  // when a runner is installed: the same moves on two threads (chunks as small as they
  // go) and on one give the same grids, and those are the fresh mesher's.
  const Passage& passage = rotor37Passage();
  MeshPlan serial(passage.model, passage.carriers);
  MeshPlan threaded(passage.model, passage.carriers);
  const int oa = vertexIndex(serial.model(), "oa_f_h");
  const FreeParameter s = sParameter(freeParameters(serial.model(), serial.carriers()), oa);
  const double original = serial.model().vertices[oa].constraint.s;
  const auto move = [&](MeshPlan& plan, double value, int threads) {
    std::unique_ptr<test::ThreadRunner> runner;
    if (threads > 1)
    {
      runner.reset(new test::ThreadRunner(threads));
    }
    return plan.update(moveParameter(plan.model(), plan.carriers(), s, value));
  };
  for (const double delta : { 0.0035, -0.0021 })
  {
    SCOPED_TRACE(delta);
    ASSERT_TRUE(move(serial, original + delta, 1).feasible());
    ASSERT_TRUE(move(threaded, original + delta, 2).feasible());
    EXPECT_EQ(threaded.updatedBlocks(), serial.updatedBlocks());
    expectSameGrids(threaded, serial);
  }
  expectSameAsFreshMesher(threaded);
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

TEST(MeshPlan, UndoPutsTheGridBackBitForBit)
{
  // An optimizer rejecting a trial move undoes it: the model, the carriers drawn through
  // moved vertices and every grid are as before the move, bit for bit, and the next move
  // from there gives what it gives without the rejected one in between.
  const Passage& passage = rotor37Passage();
  MeshPlan plan(passage.model, passage.carriers);
  MeshPlan direct(passage.model, passage.carriers);
  EXPECT_FALSE(plan.undo()); // nothing to undo after construction
  const int oa = vertexIndex(plan.model(), "oa_f_h");
  const FreeParameter s = sParameter(freeParameters(plan.model(), plan.carriers()), oa);
  const double original = plan.model().vertices[oa].constraint.s;
  const auto move = [&](MeshPlan& p, double value) {
    return p.update(moveParameter(p.model(), p.carriers(), s, value));
  };
  ASSERT_TRUE(move(plan, original + 0.003).feasible());
  ASSERT_TRUE(move(direct, original + 0.003).feasible());
  std::vector<std::vector<double>> kept;
  std::vector<Vec3> positions;
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    kept.push_back(plan.blockNodes(b));
  }
  for (const Vertex& vertex : plan.model().vertices)
  {
    positions.push_back(vertex.position);
  }
  const std::string document = writeModelDocument(plan.model());

  ASSERT_TRUE(move(plan, original - 0.002).feasible()); // the trial move, rejected
  const std::vector<int> trialBlocks = plan.updatedBlocks();
  EXPECT_TRUE(plan.undo());
  EXPECT_FALSE(plan.undo()); // one step only
  EXPECT_EQ(plan.updatedBlocks(), trialBlocks);
  EXPECT_EQ(writeModelDocument(plan.model()), document);
  for (std::size_t v = 0; v < positions.size(); ++v)
  {
    EXPECT_TRUE(test::sameBits(positions[v], plan.model().vertices[v].position))
      << plan.model().vertices[v].name;
  }
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), kept[b])) << "block " << b;
  }
  // The next moves from the restored state, of another corner (its blocks share faces
  // with the trial's, not all of which it recomputes) and of the same: as if the trial
  // had never been made.
  const int ob = vertexIndex(plan.model(), "ob_f_h");
  const FreeParameter other = sParameter(freeParameters(plan.model(), plan.carriers()), ob);
  const double otherValue = plan.model().vertices[ob].constraint.s - 0.002;
  for (MeshPlan* p : { &plan, &direct })
  {
    ASSERT_TRUE(p->update(moveParameter(p->model(), p->carriers(), other, otherValue)).feasible());
  }
  expectSameGrids(plan, direct);
  ASSERT_TRUE(move(plan, original + 0.001).feasible());
  ASSERT_TRUE(move(direct, original + 0.001).feasible());
  expectSameGrids(plan, direct);
  expectSameAsFreshMesher(plan);
}

TEST(MeshPlan, UndoAfterAnInfeasibleUpdate)
{
  const BlockModel model = loadTemplate(test::sourcePath("Testing/Data/two_blocks.yaml"));
  MeshPlan plan(model, CarrierGeometry(model));
  const int a1 = vertexIndex(plan.model(), "a1");
  const Vec3 original = plan.model().vertices[a1].position;
  plan.model().vertices[a1].position = Vec3(-0.5, 0.0, 0.0);
  EXPECT_FALSE(plan.update({ a1 }).feasible());
  EXPECT_TRUE(plan.undo());
  EXPECT_EQ(plan.model().vertices[a1].position, original);
  const test::Grid initial = test::meshAll(model);
  for (int b = 0; b < plan.blockCount(); ++b)
  {
    EXPECT_TRUE(test::sameBits(plan.blockNodes(b), initial.xyz[b])) << "block " << b;
  }
  // Nothing left pending: a move elsewhere updates what it updates on a fresh plan.
  MeshPlan fresh(model, CarrierGeometry(model));
  for (MeshPlan* p : { &plan, &fresh })
  {
    p->model().vertices[a1].position = original + Vec3(0.01, 0.02, 0.0);
    EXPECT_TRUE(p->update({ a1 }).feasible());
  }
  EXPECT_EQ(plan.updatedBlocks(), fresh.updatedBlocks());
  expectSameGrids(plan, fresh);
}
