// The block optimizer on models (Filters/Model/Optimize): a known optimum, the domain's
// boundary and periodic partners kept, never worse than the start, deterministic, manual
// moves held, and the blade-passage templates on both machines.
#include "Optimizer.h"

#include "CarrierGeometry.h"
#include "Mesher.h"
#include "ModelDocument.h"
#include "Template.h"
#include "Topology.h"
#include "FaceChecks.h"

#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

using namespace blockforge;
using namespace blockforge::optimize;

namespace
{
std::string dataPath(const std::string& name)
{
  return std::string(BLOCKFORGE_SOURCE_DIR) + "/Testing/Data/" + name;
}

struct Loaded
{
  model::BlockModel model;
  model::CarrierGeometry geometry;
};

Loaded loadSymmetric(const std::string& s0 = "0.3")
{
  Loaded loaded;
  loaded.model = model::loadTemplate(
    dataPath("optimizer_symmetric.yaml"), { { "s0", s0 } }, nullptr, &loaded.geometry);
  return loaded;
}

Loaded loadPassage(const std::string& templateName, const std::string& machine)
{
  Loaded loaded;
  const model::TemplateInputs inputs = test::readTemplateInputs(
    std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/" + machine + "/BladeGen.inf");
  loaded.model = model::loadTemplate(
    test::templatePath(templateName + ".yaml"), {}, &inputs, &loaded.geometry);
  return loaded;
}

/// Smallest element angle of the grid the full mesher makes of `model`.
double meshedMinAngle(const model::BlockModel& model)
{
  const test::Grid grid = test::meshAll(model);
  std::vector<BlockGrid> blocks;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  return measureGrid(blocks, {}, ObjectiveSettings{}).minAngle;
}

double meshedInterfaceRatio(const model::BlockModel& model);
long long meshedFailingCells(const model::BlockModel& model);

const ControlVariable* findVariable(const std::vector<ControlVariable>& variables,
  const std::string& name)
{
  for (const ControlVariable& variable : variables)
  {
    if (variable.name == name)
    {
      return &variable;
    }
  }
  return nullptr;
}
} // namespace

TEST(Optimizer, FindsTheSymmetricOptimum)
{
  Loaded loaded = loadSymmetric();
  OptimizerSettings settings;
  settings.search.tolerance = 1e-12;
  settings.search.maxEvaluations = 300;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  // Only the shared vertex moves: the carrier's ends are corners of the domain.
  ASSERT_EQ(result.variables.size(), 1u);
  EXPECT_EQ(result.variables[0].name, "m0.s");
  EXPECT_EQ(result.boundaryLocked, (std::vector<std::string>{ "a0.s", "b1.s" }));
  const int m0 = result.model.findVertex("m0");
  EXPECT_NEAR(result.model.vertices[m0].constraint.s, 0.5, 1e-6);
  EXPECT_NEAR(result.model.vertices[m0].position.x(), 1.0, 2e-6);
  EXPECT_NEAR(result.before.minAngle, std::atan2(1.0, 0.4) * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(result.after.minAngle, 90.0, 1e-3);
  EXPECT_EQ(result.after.classes[4], 128); // all 2 x 4^3 cells in 80-90
  // The output model meshes to what the optimizer measured.
  EXPECT_EQ(meshedMinAngle(result.model), result.after.minAngle);
}

TEST(Optimizer, SkewFindsTheMatchingDistribution)
{
  Loaded loaded;
  loaded.model =
    model::loadTemplate(dataPath("optimizer_skew.yaml"), {}, nullptr, &loaded.geometry);
  const double r = 1.2;
  const double a0 = 4.0 * (r - 1.0) / (std::pow(r, 4) - 1.0) * std::pow(r, 1.5);
  OptimizerSettings settings;
  settings.search.tolerance = 1e-12;
  settings.search.maxEvaluations = 300;
  settings.skewDistributions = true;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  // The lower block's i-direction is the only one graded `ends` on all four edges.
  ASSERT_EQ(result.variables.size(), 1u);
  const ControlVariable& skew = result.variables[0];
  EXPECT_EQ(skew.name, "lower.skew_i");
  EXPECT_EQ(skew.component, ControlVariable::SkewComponent);
  EXPECT_NEAR(skew.low, -std::log(3.0), 1e-15);
  EXPECT_NEAR(skew.high, std::log(3.0), 1e-15);
  const double u = result.search.best[0];
  EXPECT_NEAR(u, 1.5 * std::log(r), 1e-6);
  EXPECT_LT(result.before.minAngle, 85.0);
  EXPECT_NEAR(result.after.minAngle, 90.0, 1e-4);
  // The output model carries the skewed laws, on every block that uses the edges, and
  // meshes to what the optimizer measured.
  const model::Block& lower = result.model.blocks[result.model.findBlock("lower")];
  const model::Block& upper = result.model.blocks[result.model.findBlock("upper")];
  EXPECT_NEAR(lower.laws[0].firstCellSize, a0 * std::exp(-u), 1e-15);
  EXPECT_NEAR(lower.laws[0].lastCellSize, a0 * std::exp(u), 1e-15);
  EXPECT_EQ(upper.laws[0].firstCellSize, lower.laws[2].firstCellSize);
  EXPECT_EQ(upper.laws[2].kind, DistributionLaw::Kind::Geometric);
  EXPECT_EQ(meshedMinAngle(result.model), result.after.minAngle);
  // Without skews there is nothing to move.
  settings.skewDistributions = false;
  const OptimizerResult held = optimizeModel(loaded.model, loaded.geometry, settings);
  EXPECT_TRUE(held.variables.empty());
  EXPECT_EQ(held.after.minAngle, result.before.minAngle);
}

TEST(Optimizer, BoundsKeepTheVertexBetweenItsNeighbours)
{
  Loaded loaded = loadSymmetric("0.3");
  ControlProblem problem(loaded.model, loaded.geometry, 1.0, ObjectiveSettings{}, {});
  ASSERT_EQ(problem.variables().size(), 1u);
  // Neighbours on the carrier: a0 at 0 and b1 at 1, both held: 90 % of the way to each.
  EXPECT_NEAR(problem.low()[0], 0.3 - 0.9 * 0.3, 1e-15);
  EXPECT_NEAR(problem.high()[0], 0.3 + 0.9 * 0.7, 1e-15);
}

TEST(Optimizer, BoundaryStaysPut)
{
  Loaded loaded = loadSymmetric("0.35");
  OptimizerSettings settings;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  const test::Grid grid = test::meshAll(result.model);
  // Every node of the bottom (z = 0), front (y = 0), inlet (x = 0) and outlet (x = 2)
  // faces stays on its plane.
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    const auto& n = grid.nodes[b];
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        for (int i = 0; i < n[0]; ++i)
        {
          const Vec3 p = grid.at(static_cast<int>(b), i, j, k);
          if (k == 0)
          {
            EXPECT_NEAR(p.z(), 0.0, 1e-12);
          }
          if (j == 0)
          {
            EXPECT_NEAR(p.y(), 0.0, 1e-12);
          }
          if (b == 0 && i == 0)
          {
            EXPECT_NEAR(p.x(), 0.0, 1e-12);
          }
          if (b == 1 && i == n[0] - 1)
          {
            EXPECT_NEAR(p.x(), 2.0, 1e-12);
          }
        }
      }
    }
  }
  for (const char* corner : { "a0", "b1", "a3", "b2", "a4", "b5" })
  {
    const int v = result.model.findVertex(corner);
    EXPECT_TRUE(test::sameBits(result.model.vertices[v].position, loaded.model.vertices[v].position))
      << corner;
  }
}

TEST(Optimizer, AnOptimalStartStays)
{
  Loaded loaded = loadSymmetric("0.5");
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, OptimizerSettings{});
  const int m0 = result.model.findVertex("m0");
  EXPECT_EQ(result.model.vertices[m0].constraint.s, 0.5);
  EXPECT_NEAR(result.after.minAngle, 90.0, 1e-9);
}

TEST(Optimizer, ManualMoveIsHeld)
{
  Loaded loaded = loadSymmetric("0.3");
  OptimizerSettings settings;
  settings.moves = { { "m0", { 0.42 } } };
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  const int m0 = result.model.findVertex("m0");
  EXPECT_EQ(result.model.vertices[m0].constraint.s, 0.42);
  EXPECT_NEAR(result.model.vertices[m0].position.x(), 0.84, 1e-12);
  EXPECT_TRUE(result.variables.empty());
  EXPECT_NEAR(result.before.minAngle, std::atan2(1.0, 0.4) * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(result.after.minAngle, std::atan2(1.0, 0.16) * 180.0 / M_PI, 1e-9);
  // The moved model travels through the model document.
  const model::BlockModel reread = model::readModelDocument(model::writeModelDocument(result.model));
  EXPECT_EQ(reread.vertices[m0].constraint.s, 0.42);
}

TEST(Optimizer, ManualMovesOnlyFillTheHistory)
{
  // Automatic off: the history holds the input and the moved model (the result).
  Loaded loaded = loadSymmetric("0.3");
  OptimizerSettings settings;
  settings.automatic = false;
  settings.moves = { { "m0", { 0.42 } } };
  const OptimizerResult moved = optimizeModel(loaded.model, loaded.geometry, settings);
  ASSERT_EQ(moved.search.history.size(), 2u);
  EXPECT_EQ(moved.search.evaluations, 2);
  EXPECT_EQ(moved.search.history[0].evaluation, 1);
  EXPECT_EQ(moved.search.history[1].evaluation, 2);
  EXPECT_NEAR(moved.search.history[0].minAngle, std::atan2(1.0, 0.4) * 180.0 / M_PI, 1e-9);
  EXPECT_EQ(moved.search.history[1].minAngle, moved.after.minAngle);
  EXPECT_NEAR(moved.after.minAngle, std::atan2(1.0, 0.16) * 180.0 / M_PI, 1e-9);
  EXPECT_EQ(moved.search.history[1].objective, moved.after.objective);
  EXPECT_LT(moved.search.history[1].objective, moved.search.history[0].objective);
  EXPECT_LE(moved.search.history[0].seconds, moved.search.history[1].seconds);
  // Nothing moved: one row, the input as it is.
  settings.moves.clear();
  const OptimizerResult unchanged = optimizeModel(loaded.model, loaded.geometry, settings);
  ASSERT_EQ(unchanged.search.history.size(), 1u);
  EXPECT_EQ(unchanged.search.history[0].minAngle, unchanged.before.minAngle);
  EXPECT_EQ(unchanged.before.minAngle, unchanged.after.minAngle);
}

TEST(Optimizer, FixedControlPointStays)
{
  Loaded loaded = loadSymmetric("0.3");
  OptimizerSettings settings;
  settings.fixed = { "m0" };
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  EXPECT_TRUE(result.variables.empty());
  EXPECT_EQ(result.model.vertices[result.model.findVertex("m0")].constraint.s, 0.3);
}

TEST(Optimizer, FreeInteriorVertexFindsTheCentre)
{
  Loaded loaded;
  loaded.model = model::loadTemplate(
    dataPath("optimizer_interior.yaml"), {}, nullptr, &loaded.geometry);
  OptimizerSettings settings;
  settings.search.tolerance = 1e-12;
  settings.search.maxEvaluations = 600;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  // Only the centre touches no boundary face: its x, y and z are the variables, within
  // 45 % of the way to its nearest block-edge neighbour ((2, 1, 1), sqrt(0.66) away).
  ASSERT_EQ(result.variables.size(), 3u);
  EXPECT_EQ(result.variables[0].name, "c.x");
  EXPECT_EQ(result.variables[2].name, "c.z");
  EXPECT_NEAR(result.variables[0].low, 1.2 - 0.45 * std::sqrt(0.66), 1e-12);
  const model::Vertex& centre = result.model.vertices[result.model.findVertex("c")];
  EXPECT_NEAR(centre.position.x(), 1.0, 1e-6);
  EXPECT_NEAR(centre.position.y(), 1.0, 1e-6);
  EXPECT_NEAR(centre.position.z(), 1.0, 1e-6);
  EXPECT_NEAR(result.after.minAngle, 90.0, 1e-3);
  EXPECT_LT(result.before.minAngle, 80.0);
  // Every other vertex stays where it was, bit for bit.
  for (std::size_t v = 0; v < loaded.model.vertices.size(); ++v)
  {
    if (loaded.model.vertices[v].name != "c")
    {
      EXPECT_EQ(result.model.vertices[v].position, loaded.model.vertices[v].position);
    }
  }
  EXPECT_EQ(meshedMinAngle(result.model), result.after.minAngle);
}

TEST(Optimizer, TemplateFixedMarkHoldsAVertex)
{
  // The same cube with the centre marked `fixed: true`: no variable, nothing moves, and
  // the mark survives the model document (the pipeline's way between filters).
  std::ifstream in(dataPath("optimizer_interior.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string centre = "  c: {position: [cx, cy, cz]}";
  ASSERT_NE(yaml.find(centre), std::string::npos);
  yaml.replace(yaml.find(centre), centre.size(), "  c: {position: [cx, cy, cz], fixed: true}");
  const std::string path = ::testing::TempDir() + "blockforge_optimizer_interior_fixed.yaml";
  std::ofstream(path) << yaml;
  Loaded loaded;
  loaded.model = model::loadTemplate(path, {}, nullptr, &loaded.geometry);
  const int c = loaded.model.findVertex("c");
  EXPECT_TRUE(loaded.model.vertices[c].fixed);
  const model::BlockModel reloaded =
    model::readModelDocument(model::writeModelDocument(loaded.model));
  EXPECT_TRUE(reloaded.vertices[c].fixed);
  EXPECT_FALSE(reloaded.vertices[0].fixed);
  const OptimizerResult result = optimizeModel(reloaded, loaded.geometry, OptimizerSettings{});
  EXPECT_TRUE(result.variables.empty());
  EXPECT_EQ(result.model.vertices[c].position, loaded.model.vertices[c].position);
  // A mark that is not true or false is an error naming the vertex and its line.
  yaml.replace(yaml.find("fixed: true"), 11, "fixed: maybe");
  std::ofstream(path) << yaml;
  try
  {
    model::loadTemplate(path, {}, nullptr, &loaded.geometry);
    FAIL() << "expected an error";
  }
  catch (const model::TemplateError& error)
  {
    EXPECT_NE(std::string(error.what()).find("vertex 'c': fixed: expected true or false"),
      std::string::npos)
      << error.what();
  }
}

TEST(Optimizer, BadNamesAndMovesAreErrors)
{
  Loaded loaded = loadSymmetric();
  OptimizerSettings settings;
  settings.fixed = { "nowhere" };
  test::expectError([&] { optimizeModel(loaded.model, loaded.geometry, settings); },
    { "nowhere", "FixedControlPoints" });
  settings.fixed.clear();
  settings.moves = { { "a2", { 0.5 } } };
  test::expectError([&] { optimizeModel(loaded.model, loaded.geometry, settings); },
    { "optimizer_symmetric.yaml", "a2", "not a control point" });
  settings.moves = { { "m0", { 0.5, 0.2 } } };
  test::expectError(
    [&] { optimizeModel(loaded.model, loaded.geometry, settings); }, { "m0", "1 value" });
  settings.moves = { { "m0", { 1.5 } } };
  test::expectError(
    [&] { optimizeModel(loaded.model, loaded.geometry, settings); }, { "m0", "outside" });
}

TEST(Optimizer, HandleProjectsOntoTheCarrier)
{
  Loaded loaded = loadSymmetric();
  const ControlPointMove move = moveTowards(loaded.model, loaded.geometry, "m0", Vec3(1.3, 0.4, -0.2));
  ASSERT_EQ(move.parameters.size(), 1u);
  EXPECT_NEAR(move.parameters[0], 0.65, 1e-12);
}

namespace
{
/// The passage templates, a short run: what every passage test checks.
struct PassageRun
{
  Loaded loaded;
  OptimizerResult result;
};

PassageRun runPassage(const std::string& templateName, const std::string& machine, int evaluations)
{
  PassageRun run;
  run.loaded = loadPassage(templateName, machine);
  OptimizerSettings settings;
  settings.search.maxEvaluations = evaluations;
  model::CarrierGeometry geometry = run.loaded.geometry;
  run.result = optimizeModel(run.loaded.model, geometry, settings);
  return run;
}
} // namespace

TEST(OptimizerPassage, ImprovesAndKeepsBoundaryAndPeriodicity)
{
  for (const char* machine : { "distributor", "rotor37/turbogrid" })
  {
    const PassageRun run = runPassage("axial_passage_oh", machine, 100);
    const OptimizerResult& result = run.result;
    SCOPED_TRACE(machine);
    EXPECT_GT(result.variables.size(), 10u);
    EXPECT_TRUE(result.after.feasible);
    EXPECT_GE(result.after.minAngle, result.before.minAngle); // never worse
    EXPECT_GT(result.after.minAngle, result.before.minAngle);
    // Inlet and outlet vertices move only around the axis (their s is held).
    for (const char* name : { "lo_in_h.s", "a_in_h.s", "b_out_s.s" })
    {
      EXPECT_EQ(findVariable(result.variables, name), nullptr) << name;
    }
    EXPECT_NE(findVariable(result.variables, "a_in_h.t"), nullptr);
    // The output meshes (full mesher) to what the optimizer measured.
    EXPECT_EQ(meshedMinAngle(result.model), result.after.minAngle);
    // Periodic partners still match, inlet and outlet vertices keep their axial planes.
    const model::BlockModel& before = run.loaded.model;
    const model::BlockModel& after = result.model;
    const model::Machine& machineAxis = after.machine;
    const double size = model::modelSize(before);
    for (std::size_t v = 0; v < after.vertices.size(); ++v)
    {
      const model::Vertex& vertex = after.vertices[v];
      if (vertex.constraint.periodicSource >= 0)
      {
        const Vec3 source = after.vertices[vertex.constraint.periodicSource].position;
        const Eigen::AngleAxisd rotation(vertex.constraint.pitches * machineAxis.pitch(), machineAxis.axis);
        const Vec3 image = machineAxis.axisPoint + rotation * (source - machineAxis.axisPoint);
        EXPECT_LT((image - vertex.position).norm(), 1e-9 * size) << vertex.name;
      }
      if (vertex.name.find("_in_") != std::string::npos ||
        vertex.name.find("_out_") != std::string::npos)
      {
        const double axialBefore = machineAxis.axis.dot(before.vertices[v].position);
        const double axialAfter = machineAxis.axis.dot(vertex.position);
        EXPECT_NEAR(axialAfter, axialBefore, 1e-12 * size) << vertex.name;
      }
    }
  }
}

TEST(OptimizerPassage, SameResultTwiceBitForBit)
{
  const PassageRun first = runPassage("axial_passage_oh", "distributor", 30);
  const PassageRun second = runPassage("axial_passage_oh", "distributor", 30);
  ASSERT_EQ(first.result.search.history.size(), second.result.search.history.size());
  for (std::size_t i = 0; i < first.result.search.history.size(); ++i)
  {
    EXPECT_TRUE(test::sameBits(
      first.result.search.history[i].objective, second.result.search.history[i].objective));
  }
  EXPECT_EQ(model::writeModelDocument(first.result.model),
    model::writeModelDocument(second.result.model));
}

TEST(OptimizerPassage, HTemplateNeverWorse)
{
  const PassageRun run = runPassage("axial_passage_h", "rotor37/turbogrid", 40);
  EXPECT_TRUE(run.result.after.feasible);
  EXPECT_GE(run.result.after.minAngle, run.result.before.minAngle);
  EXPECT_EQ(meshedMinAngle(run.result.model), run.result.after.minAngle);
}

TEST(OptimizerPassage, RefusesAGridTheMesherWouldRefuse)
{
  // The objective is measured on the final grid: one that would not fit in memory is
  // refused before any work, with the mesher's message.
  Loaded loaded = loadPassage("axial_passage_oh", "distributor");
  OptimizerSettings settings;
  settings.densityMultiplier = 1000.0;
  try
  {
    optimizeModel(loaded.model, loaded.geometry, settings);
    FAIL() << "expected a memory error";
  }
  catch (const std::exception& error)
  {
    EXPECT_NE(std::string(error.what()).find("the grid would need"), std::string::npos)
      << error.what();
    EXPECT_NE(std::string(error.what()).find("lower the density multiplier"), std::string::npos)
      << error.what();
  }
  // A density within MaximumMeasuredNodes is measured as it is (1.5: about 48,000 nodes;
  // 2, about 113,000, is above it since the blade sides have 18 cells and the edges 10).
  EXPECT_EQ(measuredDensity(loaded.model, 1.5), 1.5);
  EXPECT_LT(measuredDensity(loaded.model, 2.0), 2.0);
  EXPECT_LT(measuredDensity(loaded.model, 3.0), 3.0);
}

TEST(OptimizerPassage, TrialsLeftOutChangeNoStep)
{
  // The control problem's TrialFilter leaves out trials that cannot gain (inert helper
  // points, moves of blocks outside the smooth minimum's window): the same steps and
  // result bit for bit as evaluating every trial, with fewer evaluations.
  Loaded loaded = loadPassage("axial_passage_oh", "rotor37/turbogrid");
  SearchSettings settings;
  settings.maxEvaluations = 120;
  auto run = [&](bool filtered) {
    ControlProblem problem(loaded.model, loaded.geometry, 1.0, ObjectiveSettings{}, {});
    return search(problem.start(), problem.low(), problem.high(), ObjectiveKind::MinAngle,
      [&](const std::vector<double>& x) { return problem.evaluate(x); }, settings, {},
      filtered ? TrialFilter([&](std::size_t variable, const GridMeasures& current) {
        return problem.mayGain(variable, current);
      })
               : TrialFilter());
  };
  const SearchResult all = run(false), filtered = run(true);
  EXPECT_GT(filtered.skipped, 5);
  EXPECT_EQ(filtered.evaluations + filtered.skipped, all.evaluations);
  EXPECT_EQ(filtered.best, all.best);
  EXPECT_TRUE(test::sameBits(filtered.bestMeasures.objective, all.bestMeasures.objective));
  EXPECT_EQ(filtered.bestMeasures.minAngle, all.bestMeasures.minAngle);
}

TEST(OptimizerPassage, RejectedTrialsPutBackGiveTheSameSearch)
{
  // A trial the compass search does not take is put back (ControlProblem::reject: the mesh
  // plan's undo, the angles measured before it, the laws of skewed edges) instead of being
  // moved back by the next evaluation: every evaluation, the steps and the result the same,
  // bit for bit, on the O-grid with distribution skews (laws the plan does not keep;
  // without putting those back the distributor's search differs within these 300
  // evaluations). axial_passage_oh's spanwise laws are `ends` in every block (since stop
  // 19: end-wall layers), so the O blocks and the edge H blocks have spanwise skews.
  Loaded loaded;
  {
    const model::TemplateInputs inputs = test::readTemplateInputs(
      std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/distributor/BladeGen.inf");
    const std::string text = test::readText(test::templatePath("axial_passage_oh.yaml"));
    const std::string ends = "k: {ends: [span_wall, span_wall]";
    int spanwiseEnds = 0;
    for (std::size_t at = text.find(ends); at != std::string::npos;
         at = text.find(ends, at + ends.size()))
    {
      ++spanwiseEnds;
    }
    ASSERT_EQ(spanwiseEnds, 12); // every block's spanwise direction
    loaded.model =
      model::parseTemplate(text, "axial_passage_oh.yaml", {}, &inputs, &loaded.geometry);
  }
  SearchSettings settings;
  settings.maxEvaluations = 300;
  const OptimizerSettings defaults;
  auto run = [&](bool putBack, std::vector<std::vector<double>>* grid) {
    ControlProblem problem(
      loaded.model, loaded.geometry, 1.0, ObjectiveSettings{}, {}, defaults.maximumSkew);
    const SearchResult result = search(problem.start(), problem.low(), problem.high(),
      ObjectiveKind::MinAngle, [&](const std::vector<double>& x) { return problem.evaluate(x); },
      settings, {}, {}, putBack ? RejectFunction([&] { problem.reject(); }) : RejectFunction());
    *grid = problem.gridAt(result.best);
    return result;
  };
  std::vector<std::vector<double>> movedBack, putBack;
  const SearchResult plain = run(false, &movedBack), undone = run(true, &putBack);
  ASSERT_EQ(plain.history.size(), undone.history.size());
  int rejected = 0;
  double value = plain.history.front().objective;
  for (std::size_t n = 0; n < plain.history.size(); ++n)
  {
    EXPECT_TRUE(test::sameBits(plain.history[n].objective, undone.history[n].objective)) << n;
    rejected += n > 0 && !(plain.history[n].objective < value) ? 1 : 0;
    value = std::min(value, plain.history[n].objective);
  }
  EXPECT_GT(rejected, 50); // trials put back
  EXPECT_EQ(plain.best, undone.best);
  EXPECT_EQ(movedBack, putBack);
  ControlProblem skews(
    loaded.model, loaded.geometry, 1.0, ObjectiveSettings{}, {}, defaults.maximumSkew);
  int skewVariables = 0;
  for (const ControlVariable& variable : skews.variables())
  {
    skewVariables += variable.component == ControlVariable::SkewComponent ? 1 : 0;
  }
  EXPECT_GT(skewVariables, 0);
}

/**
 * Issue 9's target: axial_passage_oh at its defaults (sheared O corners, o_shear 45deg) on
 * the distributor and on Rotor 37, the automatic run at its defaults (700 trials with the
 * stall rule): no element angle below 40 degrees, aiming at 45 (49.05 and 44.89 when
 * written), no cell in MinAngle class 0-20 or 20-40, within 700 trials (a bound on the
 * time that does not depend on the machine). Without the shear (o_shear 0) the same run
 * stays at 34.7 and 31.8 degrees: the shear is what lifts it. The bounds guard today's
 * values: 47.86 and 46.98 since the sides' O arcs `match` the O corners' cells (issue 8:
 * neighbour ratio on Rotor 37 at density 4 22.9 -> 4.1), 53.26 and 48.50 before (the
 * distributor's bound 48.5 -> 47.5, Rotor 37's 44.5 -> 46.5). Stop 14 (the O-grid's outer
 * faces follow the blade faces, end-cell interpolation in the H blocks beside the wake and
 * inlet blocks, the blade faces' cell-size guard): 47.22 and 47.29, bounds 47.0 and 47.0;
 * the end point of the search moves by 1-2 degrees with any change of the grid (period_flat
 * 2.4 / 2.6 / 2.8 / 3.0 / 3.2: distributor 47.08 / 46.05 / 47.46 / 47.22 / 47.43, Rotor 37
 * 47.45 / 46.61 / 44.17 / 47.29 / 47.32), so the bounds sit a little under today's values.
 * Stop 16 (issue 8): the optimized grid's cells across block interfaces differ at most
 * 1.6 times (ObjectiveSettings::maximumInterfaceRatio; unguarded 2.50 and 3.58), 47.12 and
 * 47.40 degrees. Stop 17 (issue 10): no more cells failing checkMesh's cell determinant
 * than placed (ControlProblem; unguarded Rotor 37 309 -> 311): 47.40 degrees, 638 -> 483
 * cells (unguarded 47.52, 474), and 47.38, 309 -> 309. Stop 19 (thicker O-grid outer cell,
 * end-wall layers): 46.54 and 47.57 with period_follow 1.25 (the distributor's search
 * settles on M_L's corner cell at oa_r on the hub), 48.35 and 48.01 with 1.28.
 */
TEST(OptimizerPassage, ShearedOGridReachesFortyDegrees)
{
  for (const auto& [machine, bound] :
    { std::pair<const char*, double>{ "distributor", 47.0 }, { "rotor37/turbogrid", 47.0 } })
  {
    SCOPED_TRACE(machine);
    Loaded loaded;
    const model::TemplateInputs inputs = test::readTemplateInputs(
      std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/" + machine + "/BladeGen.inf");
    loaded.model = model::loadTemplate(
      test::templatePath("axial_passage_oh.yaml"), {}, &inputs, &loaded.geometry);
    const OptimizerSettings settings;
    EXPECT_EQ(settings.search.maxEvaluations, 700);
    const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
    EXPECT_TRUE(result.after.feasible);
    EXPECT_GT(result.after.minAngle, bound);
    EXPECT_EQ(result.after.classes[0], 0);
    EXPECT_EQ(result.after.classes[1], 0);
    EXPECT_LE(result.search.evaluations + result.search.skipped, 700);
    EXPECT_EQ(meshedMinAngle(result.model), result.after.minAngle);
    // issue 8 on the optimized grid (the interface ratio guard, ControlProblem)
    const double ratio = meshedInterfaceRatio(result.model);
    EXPECT_LE(ratio, 1.6);
    EXPECT_EQ(ratio, result.after.interfaceRatio);
    // issue 10: no more cells failing checkMesh's cell determinant than placed (stop 17)
    const long long placed = meshedFailingCells(loaded.model);
    EXPECT_EQ(result.before.failingCells, placed);
    EXPECT_LE(meshedFailingCells(result.model), placed);
    EXPECT_EQ(meshedFailingCells(result.model), result.after.failingCells);
    std::cout << machine << ": " << result.after.minAngle << " degrees, cell determinant "
              << placed << " -> " << result.after.failingCells << " cells\n";
  }
}

/**
 * The compressor's sharp edges (Data/compressor, fans on the tips): at density 4 the
 * automatic run reached only 9.6 degrees while density 0.5-2 reached 21.9-22.9, because
 * the blade sides' `ends` law with flat 3 next to the fans' tiny end cells (side_fan)
 * stalled the search at a corner cell of M_R; the template gives sides ending at a fan
 * side_flat_fan (2): 22.1 degrees. The optimizer measures a coarsened copy of the grid at
 * density 4 (MaximumMeasuredNodes), so the run costs about what density 2 costs. Since the
 * fans' wall cells are prisms (o_fan_prisms, stop 14) and MinAngle leaves out a prism's
 * apex on the tip (the fan's 20 cells per layer at density 4 share the tip's turn: 3 degrees
 * each), 23.4 degrees; counted, the apex held the run at 2.8. Since the search refuses
 * configurations that fail more of checkMesh's interpolation-weight and volume-ratio faces
 * than the start (FaceChecks.h, on the copy it measures), 21.7 degrees (bound 22 -> 21):
 * the final grid's weak faces 510 weights and 128 volume ratios -> 219 weights.
 */
TEST(OptimizerPassage, CompressorAtDensityFourKeepsItsAngle)
{
  Loaded loaded;
  const model::TemplateInputs inputs = test::readTemplateInputs(
    std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/compressor/rotor.inf");
  loaded.model = model::loadTemplate(
    test::templatePath("axial_passage_oh.yaml"), {}, &inputs, &loaded.geometry);
  OptimizerSettings settings;
  settings.densityMultiplier = 4.0;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  EXPECT_TRUE(result.after.feasible);
  EXPECT_GT(result.after.minAngle, 21.0);
}

namespace
{
/// A box grid: node coordinates along x from `xs`, 2 cells of 1 along y and z.
std::vector<double> boxGrid(const std::vector<double>& xs, double x0 = 0.0)
{
  std::vector<double> nodes;
  for (int k = 0; k < 3; ++k)
  {
    for (int j = 0; j < 3; ++j)
    {
      for (double x : xs)
      {
        nodes.insert(nodes.end(), { x0 + x, static_cast<double>(j), static_cast<double>(k) });
      }
    }
  }
  return nodes;
}

/// Views of a meshed grid's blocks (pointing into `grid`, which must outlive them).
std::vector<BlockGrid> blockGridsOf(const test::Grid& grid)
{
  std::vector<BlockGrid> blocks;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  return blocks;
}

/// The largest neighbour size ratio across the block interfaces (periodic sides included)
/// of the grid the full mesher makes of `model` (FaceChecks.h InterfaceRatio).
double meshedInterfaceRatio(const model::BlockModel& model)
{
  const test::Grid grid = test::meshAll(model);
  const std::vector<BlockGrid> blocks = blockGridsOf(grid);
  return InterfaceFaces(blocks, model::buildTopology(model).periodicSideLinks())
    .largestRatio(blocks)
    .ratio;
}

/// Faces of a meshed model that fail checkMesh's interpolation weight or volume ratio.
long long meshedWeakFaces(const model::BlockModel& model)
{
  const test::Grid grid = test::meshAll(model);
  return weakFaceCount(blockGridsOf(grid), model::buildTopology(model).periodicSideLinks());
}
} // namespace

/**
 * FaceChecks: OpenFOAM's interpolation weight min(dO, dN) / (dO + dN) of a face between
 * box cells of widths a and b is min(a, b) / (a + b) (the volume centroids at half-widths),
 * failed below 0.05, i.e. for neighbours more than 19 times apart; the volume ratio
 * min/max fails below 0.01. Within a block and across an interface alike.
 */
TEST(FaceChecks, CountsTheFacesCheckMeshFails)
{
  // cells 1, 1, 1/25, 1/25 (a jump of 25: weight 1/26), 4 faces of 2 x 2 per layer
  const std::vector<double> xs = { 0.0, 1.0, 2.0, 2.04, 2.08 };
  std::vector<double> nodes = boxGrid(xs);
  const BlockGrid jump{ nodes.data(), 5, 3, 3 };
  const BlockCells cells(jump);
  EXPECT_EQ(cells.weakFaces(), 4);
  EXPECT_NEAR(cells.centres()[1].x(), 1.5, 1e-12);
  EXPECT_NEAR(cells.centres()[2].x(), 2.02, 1e-12);
  EXPECT_NEAR(cells.volumes()[2], 0.04, 1e-12);
  // a jump of 15 (weight 1/16) passes
  std::vector<double> mild = boxGrid({ 0.0, 1.0, 2.0, 2.0 + 1.0 / 15.0, 2.0 + 2.0 / 15.0 });
  EXPECT_EQ(BlockCells(BlockGrid{ mild.data(), 5, 3, 3 }).weakFaces(), 0);
  // the same jump across an interface between two blocks: 4 faces, found by their corners
  std::vector<double> left = boxGrid({ 0.0, 1.0, 2.0 });
  std::vector<double> right = boxGrid({ 0.0, 0.04, 0.08 }, 2.0);
  const std::vector<BlockGrid> blocks = { { left.data(), 3, 3, 3 }, { right.data(), 3, 3, 3 } };
  EXPECT_EQ(weakFaceCount(blocks, {}), 4);
  std::vector<double> even = boxGrid({ 0.0, 1.0, 2.0 }, 2.0);
  EXPECT_EQ(weakFaceCount({ blocks[0], { even.data(), 3, 3, 3 } }, {}), 0);
}

/**
 * InterfaceRatio: the neighbour size ratio across the faces between blocks is the larger
 * over the smaller width of the two cells across the face (cells of 1 against cells of
 * 0.25: 4); cells that match give 1.
 */
TEST(FaceChecks, MeasuresTheNeighbourRatioAcrossInterfaces)
{
  std::vector<double> left = boxGrid({ 0.0, 1.0, 2.0 });
  std::vector<double> right = boxGrid({ 0.0, 0.25, 0.5 }, 2.0);
  const std::vector<BlockGrid> blocks = { { left.data(), 3, 3, 3 }, { right.data(), 3, 3, 3 } };
  const InterfaceRatio jump = InterfaceFaces(blocks, {}).largestRatio(blocks);
  EXPECT_NEAR(jump.ratio, 4.0, 1e-12);
  EXPECT_EQ(jump.ownerBlock + jump.neighbourBlock, 1);
  EXPECT_EQ(jump.ownerBlock == 0 ? jump.ownerCell[0] : jump.neighbourCell[0], 1);
  EXPECT_EQ(jump.ownerBlock == 1 ? jump.ownerCell[0] : jump.neighbourCell[0], 0);
  std::vector<double> even = boxGrid({ 0.0, 1.0, 2.0 }, 2.0);
  const std::vector<BlockGrid> matched = { blocks[0], { even.data(), 3, 3, 3 } };
  EXPECT_NEAR(InterfaceFaces(matched, {}).largestRatio(matched).ratio, 1.0, 1e-12);
}

/**
 * Issue 10: the optimized OH grids of the compressor and the turbine at density 1 fail no
 * interpolation weight or volume ratio (checkMesh -allGeometry; Testing/Python
 * test_openfoam runs checkMesh itself). Before the optimizer refused such configurations it
 * moved the compressor's fan corners off the tip's arc while their feet stayed on the tip
 * (36 faces, 27.55 degrees) and the turbine's corner oa_r onto the cap corner's fan (12
 * faces, 26.06 degrees at the command line); now 22.35 and 23.08 degrees here (19.81 and
 * 25.32 at the command line, whose search runs on the model the reader's inputs give).
 * Stop 16 (issue 8): the optimized grid's interface ratio stays at most max(the placed
 * grid's, maximumInterfaceRatio): compressor 1.69 -> 1.59 (unguarded 1.70), turbine 1.36
 * -> 1.52 (unguarded 6.70, periodic M_L|M_R). Stop 17: nor more cells failing checkMesh's
 * cell determinant than placed (compressor 942 -> 925, unguarded 1036; turbine 362 -> 355,
 * unguarded 388): 23.25 and 34.63 degrees (unguarded 23.40 and 38.10). Stop 19 (k_o 1.35,
 * n_o 5): the turbine's cap corner had 9 weak faces here placed and optimized (0.0509 at the
 * command line) until spreadBunchLocally spread its feet (0 and 0; 40.61 -> 40.78 degrees).
 */
TEST(OptimizerPassage, OptimizedGridsFailNoFaceWeight)
{
  for (const auto& [input, bound] :
    { std::pair<const char*, double>{ "compressor/rotor.inf", 19.0 }, { "turbine/Info.txt", 22.5 } })
  {
    SCOPED_TRACE(input);
    Loaded loaded;
    const model::TemplateInputs inputs =
      test::readTemplateInputs(std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/" + input);
    loaded.model = model::loadTemplate(
      test::templatePath("axial_passage_oh.yaml"), {}, &inputs, &loaded.geometry);
    EXPECT_EQ(meshedWeakFaces(loaded.model), 0); // as placed
    const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, OptimizerSettings{});
    EXPECT_TRUE(result.after.feasible);
    EXPECT_EQ(result.after.weakFaces, 0);
    EXPECT_EQ(meshedWeakFaces(result.model), 0);
    EXPECT_GT(result.after.minAngle, bound);
    // issue 8: the optimized grid's cells across block interfaces differ no more than
    // maximumInterfaceRatio, or than the start's where that is more (the compressor's)
    const double placed = meshedInterfaceRatio(loaded.model);
    const double ratio = meshedInterfaceRatio(result.model);
    EXPECT_LE(ratio, std::max(placed, OptimizerSettings{}.objective.maximumInterfaceRatio));
    // issue 10: no more cells failing checkMesh's cell determinant than placed (stop 17)
    EXPECT_LE(meshedFailingCells(result.model), meshedFailingCells(loaded.model));
    std::cout << input << ": " << result.before.minAngle << " -> " << result.after.minAngle
              << " degrees, interface ratio " << placed << " -> " << ratio << "\n";
  }
}

/**
 * FaceChecks' cell determinant count (BlockCells::failingCells, failingCellCount) is
 * GridQuality's: Core's CellDeterminant below 1e-3 over the faces OpenFOAM's mesh has as
 * internal or coupled, with the same interface and periodic pairing, cell for cell on
 * Rotor 37's OH grid (placed). A box of plates 0.02 x 1 x 1 fails cell by cell (a plate
 * thinner than about 1/29 of its sides; these lose two or three faces to the boundary), one of
 * 0.5 x 1 x 1 passes.
 */
TEST(FaceChecks, CountsTheCellsCheckMeshFailsByDeterminant)
{
  std::vector<double> thin = boxGrid({ 0.0, 0.02, 0.04, 0.06 });
  EXPECT_EQ(failingCellCount({ { thin.data(), 4, 3, 3 } }, {}), 12);
  std::vector<double> fair = boxGrid({ 0.0, 0.5, 1.0, 1.5 });
  EXPECT_EQ(failingCellCount({ { fair.data(), 4, 3, 3 } }, {}), 0);
  Loaded loaded = loadPassage("axial_passage_oh", "rotor37/turbogrid");
  const test::Grid grid = test::meshAll(loaded.model);
  const std::vector<BlockGrid> blocks = blockGridsOf(grid);
  const std::vector<PeriodicSideLink> periodic =
    model::buildTopology(loaded.model).periodicSideLinks();
  const std::vector<CellQualityArrays> quality = computeGridQuality(blocks, periodic);
  long long expected = 0;
  for (const CellQualityArrays& block : quality)
  {
    for (double determinant : block.cellDeterminant)
    {
      expected += determinant < MinimumCellDeterminant ? 1 : 0;
    }
  }
  // (a count to compare, not a figure to hold: 309 at stop 17, 29 since stop 19's thicker
  // O-grid outer cell and end-wall layers, all in the O-grid's wall cells)
  EXPECT_GT(expected, 20);
  EXPECT_EQ(failingCellCount(blocks, periodic), expected);
}

namespace
{
/// optimizer_symmetric.yaml made thin along z (0.1 instead of 1): its cells 0.25 x 0.25 x
/// 0.025 at the symmetric optimum, plates near checkMesh's cell determinant limit; the
/// control point at s0, `height` instead of 0.1, and with `walls` its bottom and top (z)
/// sides wall patches.
Loaded loadThinSymmetric(const std::string& s0 = "0.3", bool walls = false,
  const std::string& height = "0.1")
{
  std::string yaml = test::readText(dataPath("optimizer_symmetric.yaml"));
  std::size_t at = 0;
  int replaced = 0;
  while ((at = yaml.find(", 1]\n", at)) != std::string::npos)
  {
    yaml.replace(at, 5, ", " + height + "]\n");
    ++replaced;
  }
  EXPECT_EQ(replaced, 6);
  if (walls)
  {
    yaml += "  floor: {type: wall, faces: [left.k0, right.k0]}\n"
            "  ceiling: {type: wall, faces: [left.k1, right.k1]}\n";
  }
  const std::string path = ::testing::TempDir() + "blockforge_optimizer_thin.yaml";
  std::ofstream(path) << yaml;
  Loaded loaded;
  loaded.model = model::loadTemplate(path, { { "s0", s0 } }, nullptr, &loaded.geometry);
  return loaded;
}

long long meshedFailingCells(const model::BlockModel& model)
{
  const test::Grid grid = test::meshAll(model);
  return failingCellCount(blockGridsOf(grid), model::buildTopology(model).periodicSideLinks());
}
} // namespace

/**
 * Issue 10: the optimizer refuses a configuration with more cells failing checkMesh's cell
 * determinant than its start (ControlProblem, FaceChecks.h). The thin symmetric model: its
 * control point m0 at s = 0.3 gives 6 failing cells (corner plates of the right block), the
 * angle optimum s = 0.5 (every angle 90 degrees) 8; s = 0.4 still 6. Refused, the search
 * stops short of the optimum with at most the start's 6.
 */
TEST(Optimizer, RefusesCellsFailingTheDeterminant)
{
  Loaded loaded = loadThinSymmetric();
  ControlProblem problem(loaded.model, loaded.geometry, 1.0, ObjectiveSettings{}, {});
  ASSERT_EQ(problem.variables().size(), 1u);
  const GridMeasures start = problem.evaluate(problem.start());
  ASSERT_TRUE(start.feasible);
  EXPECT_EQ(start.failingCells, 6);
  EXPECT_EQ(meshedFailingCells(loaded.model), 6);
  const GridMeasures optimum = problem.evaluate({ 0.5 });
  EXPECT_FALSE(optimum.feasible);
  EXPECT_NE(optimum.failure.find("cell determinant"), std::string::npos) << optimum.failure;
  problem.refuseWeakFaces(false);
  const GridMeasures measured = problem.evaluate({ 0.5 });
  ASSERT_TRUE(measured.feasible);
  EXPECT_EQ(measured.failingCells, 8);
  EXPECT_NEAR(measured.minAngle, 90.0, 1e-9);

  OptimizerSettings settings;
  settings.search.tolerance = 1e-12;
  settings.search.maxEvaluations = 300;
  const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
  ASSERT_TRUE(result.after.feasible);
  EXPECT_GT(result.after.minAngle, result.before.minAngle + 5.0);
  EXPECT_LT(result.after.minAngle, 89.0);
  EXPECT_LE(result.after.failingCells, 6);
  EXPECT_LE(meshedFailingCells(result.model), 6);
}

/**
 * Issue 10: the optimizer drives the count of cells failing checkMesh's cell determinant
 * down, not only holds it at the start's: a second search from the angle search's end
 * point, fewest failing cells first, then the angle, the angle held at the first's end
 * less OptimizerSettings::cellSearchAllowance. The thin symmetric model started at its
 * angle optimum s = 0.5 (every angle 90 degrees, 8 failing cells): without the second
 * search (allowance 0, the stop 17 rule) it stays there; with an allowance of 70 degrees
 * it leaves for a configuration with fewer failing cells (the angle falls fast: 45 degrees
 * at s = 0.45 with 7 cells, 26.6 at 0.4 with 6). 0.08 high with bottom and top wall
 * patches, its plates are wall-layer cells (their short edge, z, runs to a wall and is
 * under WallLayerRatio of their long ones: BlockCells::failingAwayFromWalls), which the
 * second search does not count: the angle optimum stands.
 */
TEST(Optimizer, DrivesDownCellsFailingTheDeterminant)
{
  EXPECT_GT(OptimizerSettings{}.cellSearchAllowance, 0.0);
  OptimizerSettings settings;
  settings.search.tolerance = 1e-12;
  settings.search.maxEvaluations = 300;
  {
    Loaded loaded = loadThinSymmetric("0.5");
    EXPECT_EQ(meshedFailingCells(loaded.model), 8);
    OptimizerSettings held = settings;
    held.cellSearchAllowance = 0.0;
    const OptimizerResult kept = optimizeModel(loaded.model, loaded.geometry, held);
    ASSERT_TRUE(kept.after.feasible);
    EXPECT_EQ(kept.after.failingCells, 8);
    EXPECT_NEAR(kept.after.minAngle, 90.0, 1e-9);
  }
  settings.cellSearchAllowance = 70.0;
  {
    Loaded loaded = loadThinSymmetric("0.5");
    const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
    ASSERT_TRUE(result.after.feasible);
    EXPECT_LT(result.after.failingCells, 8);
    EXPECT_EQ(meshedFailingCells(result.model), result.after.failingCells);
    EXPECT_LT(result.after.minAngle, 90.0);
    EXPECT_GE(result.after.minAngle, 20.0);
    std::cout << "thin symmetric from s = 0.5: 8 -> " << result.after.failingCells
              << " failing cells, 90 -> " << result.after.minAngle << " degrees\n";
  }
  {
    Loaded loaded = loadThinSymmetric("0.5", true, "0.08");
    ObjectiveSettings away;
    away.failingCellsAwayFromWalls = true;
    ControlProblem problem(loaded.model, loaded.geometry, 1.0, away, {});
    const GridMeasures start = problem.evaluate(problem.start());
    ASSERT_TRUE(start.feasible);
    EXPECT_GE(start.failingCells, 8);
    EXPECT_EQ(start.drivenFailingCells, 0);
    Loaded open = loadThinSymmetric("0.5", false, "0.08");
    ControlProblem without(open.model, open.geometry, 1.0, away, {});
    EXPECT_EQ(without.evaluate(without.start()).drivenFailingCells, start.failingCells);
    const OptimizerResult result = optimizeModel(loaded.model, loaded.geometry, settings);
    ASSERT_TRUE(result.after.feasible);
    EXPECT_EQ(result.after.failingCells, start.failingCells);
    EXPECT_NEAR(result.after.minAngle, 90.0, 1e-9);
  }
}
