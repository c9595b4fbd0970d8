// The optimizer's objective over final cells and its search (Filters/Model/Optimize),
// against closed forms: no block model involved.
#include "GridObjective.h"
#include "Search.h"

#include "TestBlockNodes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

using namespace blockforge;
using namespace blockforge::optimize;

namespace
{
const double degrees = 180.0 / M_PI;

using Grid = test::BlockNodes;
const auto makeGrid = test::makeBlockNodes;

/// A unit-spaced block whose layers k > 0 are sheared along x by tan(angle) per layer.
Grid shearedBlock(int n, double angle)
{
  return makeGrid(n, n, n, [&](int i, int j, int k) {
    return Vec3(i + k * std::tan(angle), j, k);
  });
}

GridMeasures measure(const Grid& grid, ObjectiveKind kind = ObjectiveKind::MinAngle)
{
  ObjectiveSettings settings;
  settings.kind = kind;
  return measureGrid({ grid.block() }, {}, settings);
}
} // namespace

TEST(GridObjective, CellAnglesOfAShearedBlock)
{
  const double shear = 35.0 / degrees; // corner angles 55 and 125 degrees in the xz faces
  const Grid grid = shearedBlock(4, shear);
  std::vector<double> angles(27);
  cellMinAngles(grid.block(), angles.data());
  for (double angle : angles)
  {
    EXPECT_NEAR(angle, 55.0, 1e-9);
  }
  const GridMeasures measures = measure(grid);
  EXPECT_TRUE(measures.feasible);
  EXPECT_NEAR(measures.minAngle, 55.0, 1e-9);
  EXPECT_EQ(measures.classes[2], 27); // [40, 60)
}

TEST(GridObjective, CellAnglesAgreeWithGridQuality)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  const Grid grid = makeGrid(6, 5, 4, [&](int i, int j, int k) {
    return Vec3(i + jitter(random), j + jitter(random), k + jitter(random));
  });
  std::vector<double> angles(5 * 4 * 3);
  cellMinAngles(grid.block(), angles.data());
  const std::vector<CellQualityArrays> quality = computeGridQuality({ grid.block() });
  ASSERT_EQ(quality[0].minAngle.size(), angles.size());
  for (std::size_t c = 0; c < angles.size(); ++c)
  {
    EXPECT_NEAR(angles[c], quality[0].minAngle[c], 1e-9) << "cell " << c;
  }
}

TEST(GridObjective, WedgeCellsTakeCoreRules)
{
  // A block whose i = 0 layer collapses onto the z axis (a wedge at every cell there).
  const Grid grid = makeGrid(3, 3, 2, [&](int i, int j, int k) {
    const double r = i, angle = j * 20.0 / degrees;
    return Vec3(r * std::cos(angle), r * std::sin(angle), k);
  });
  std::vector<double> angles(2 * 2 * 1);
  cellMinAngles(grid.block(), angles.data());
  const std::vector<CellQualityArrays> quality = computeGridQuality({ grid.block() });
  for (std::size_t c = 0; c < angles.size(); ++c)
  {
    EXPECT_NEAR(angles[c], quality[0].minAngle[c], 1e-9) << "cell " << c;
  }
  // the wedge's apex angle (20) is left out: its triangles' base angles, 80
  EXPECT_NEAR(angles[0], 80.0, 1e-9);
}

TEST(GridObjective, SmoothMinimumBounds)
{
  const std::vector<double> values = { 30.0, 31.0, 45.0, 80.0, 30.0 };
  const double k = 2.0;
  const double soft = softMinimum(values, k);
  const double expected =
    30.0 - std::log(2.0 + std::exp(-2.0) + std::exp(-30.0) + std::exp(-100.0)) / k;
  EXPECT_NEAR(soft, expected, 1e-12);
  EXPECT_LE(soft, 30.0);
  EXPECT_GE(soft, 30.0 - std::log(5.0) / k);
}

TEST(GridObjective, SmoothMinimumOverCornerAngles)
{
  // Every cell has 4 corners of 60 degrees and 4 of 120 (its two xz faces); the other 16
  // are right angles.
  const Grid grid = shearedBlock(4, 30.0 / degrees);
  ObjectiveSettings settings;
  settings.angleSharpness = 0.5;
  const GridMeasures measures = measureGrid({ grid.block() }, {}, settings);
  const double expected =
    60.0 - std::log(27.0 * (4.0 + 16.0 * std::exp(-15.0) + 4.0 * std::exp(-30.0))) / 0.5;
  EXPECT_NEAR(measures.softMinAngle, expected, 1e-9);
  EXPECT_NEAR(measures.objective, -expected, 1e-9);
}

TEST(GridObjective, InvertedCellsAreInfeasible)
{
  Grid grid = shearedBlock(3, 0.0);
  // Push one interior node through its neighbour.
  const int n = 1 + 3 * (1 + 3 * 1);
  grid.xyz[3 * n] += 1.5;
  const GridMeasures measures = measure(grid);
  EXPECT_FALSE(measures.feasible);
  EXPECT_GT(measures.invertedCells, 0);
  EXPECT_GE(measures.objective, infeasibleObjective(1));
}

TEST(GridObjective, NeighbourSizeRatio)
{
  // Geometric spacing 1.5 along i, uniform along j and k.
  const Grid grid = makeGrid(5, 3, 3, [&](int i, int j, int k) {
    return Vec3((std::pow(1.5, i) - 1.0) / 0.5, j, k);
  });
  EXPECT_NEAR(maxNeighbourSizeRatio(grid.block()), 1.5, 1e-12);
  ObjectiveSettings settings;
  settings.kind = ObjectiveKind::MinAngleAndSizeRatio;
  settings.sizeRatioWeight = 10.0;
  // Up to the limit (1.5 by default) a ratio costs nothing; above it, weight per unit.
  const GridMeasures withinLimit = measureGrid({ grid.block() }, {}, settings);
  EXPECT_NEAR(withinLimit.maxSizeRatio, 1.5, 1e-12);
  EXPECT_NEAR(withinLimit.objective, -withinLimit.softMinAngle, 1e-12);
  settings.sizeRatioLimit = 1.0;
  const GridMeasures fromOne = measureGrid({ grid.block() }, {}, settings);
  EXPECT_NEAR(fromOne.objective, -fromOne.softMinAngle + 5.0, 1e-12);
  // Geometric spacing 2: 10 * (2 - 1.5) = 5 degrees above the limit.
  const Grid doubling = makeGrid(5, 3, 3, [&](int i, int j, int k) {
    return Vec3(std::pow(2.0, i) - 1.0, j, k);
  });
  settings.sizeRatioLimit = 1.5;
  const GridMeasures aboveLimit = measureGrid({ doubling.block() }, {}, settings);
  EXPECT_NEAR(aboveLimit.maxSizeRatio, 2.0, 1e-12);
  EXPECT_NEAR(aboveLimit.objective, -aboveLimit.softMinAngle + 5.0, 1e-12);
}

TEST(GridObjective, NonOrthogonalityOfAShearedBlock)
{
  const Grid grid = shearedBlock(4, 25.0 / degrees);
  const GridMeasures measures = measure(grid, ObjectiveKind::NonOrthogonality);
  EXPECT_NEAR(measures.maxNonOrthogonality, 25.0, 1e-9);
  EXPECT_GE(measures.objective, 25.0 - 1e-9);
}

TEST(GridObjective, ObjectiveNames)
{
  EXPECT_EQ(objectiveFromName("NonOrthogonality"), ObjectiveKind::NonOrthogonality);
  EXPECT_STREQ(objectiveName(ObjectiveKind::MinAngleAndSizeRatio), "MinAngleAndSizeRatio");
  EXPECT_THROW(objectiveFromName("Orthogonality"), std::invalid_argument);
}

namespace
{
/// A closed-form stand-in for a grid: the "smallest angle" is 90 - |x - optimum| * 50
/// summed over the variables, feasible inside |x - optimum| < 0.8.
GridMeasures peak(const std::vector<double>& x, const std::vector<double>& optimum)
{
  GridMeasures m;
  double distance = 0.0, squared = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    distance += std::abs(x[i] - optimum[i]);
    squared += (x[i] - optimum[i]) * (x[i] - optimum[i]);
  }
  if (distance >= 0.8)
  {
    m.invertedCells = 3;
    m.objective = infeasibleObjective(3);
    return m;
  }
  m.feasible = true;
  m.minAngle = 90.0 - 50.0 * distance;
  m.objective = -90.0 + 100.0 * squared; // smooth surrogate with the same optimum
  return m;
}
} // namespace

TEST(Search, FindsTheOptimumWithinBounds)
{
  const std::vector<double> optimum = { 0.55, 0.35 };
  SearchSettings settings;
  settings.tolerance = 1e-14;
  settings.maxEvaluations = 200;
  const SearchResult result = search({ 0.4, 0.5 }, { 0.0, 0.0 }, { 1.0, 1.0 },
    ObjectiveKind::MinAngle, [&](const std::vector<double>& x) { return peak(x, optimum); },
    settings);
  ASSERT_EQ(result.best.size(), 2u);
  EXPECT_NEAR(result.best[0], 0.55, 1e-6);
  EXPECT_NEAR(result.best[1], 0.35, 1e-6);
  EXPECT_LE(result.evaluations, 200);
  EXPECT_EQ(static_cast<int>(result.history.size()), result.evaluations);
  EXPECT_EQ(result.history.front().evaluation, 1);
  EXPECT_GT(result.bestMeasures.minAngle, result.start.minAngle);
}

TEST(Search, OptimumOnABoundIsKept)
{
  const std::vector<double> optimum = { 1.3 };
  SearchSettings settings;
  settings.tolerance = 1e-14;
  const SearchResult result = search({ 0.8 }, { 0.0 }, { 1.0 }, ObjectiveKind::MinAngle,
    [&](const std::vector<double>& x) { return peak(x, optimum); }, settings);
  EXPECT_NEAR(result.best[0], 1.0, 1e-9);
}

TEST(Search, NeverWorseThanTheStart)
{
  // The surrogate prefers x = 0.5, the true smallest angle is best at the start x = 0.
  auto evaluate = [](const std::vector<double>& x) {
    GridMeasures m;
    m.feasible = true;
    m.minAngle = 40.0 - std::abs(x[0]);
    m.objective = (x[0] - 0.5) * (x[0] - 0.5);
    return m;
  };
  const SearchResult result = search({ 0.0 }, { -1.0 }, { 1.0 }, ObjectiveKind::MinAngle,
    evaluate, SearchSettings{});
  EXPECT_EQ(result.best[0], 0.0);
  EXPECT_EQ(result.bestMeasures.minAngle, 40.0);
  EXPECT_GT(result.evaluations, 1);
}

TEST(Search, DeterministicBitForBit)
{
  const std::vector<double> optimum = { 0.21, 0.77, 0.5 };
  auto run = [&](SearchAlgorithm algorithm) {
    SearchSettings settings;
    settings.algorithm = algorithm;
    settings.maxEvaluations = 60;
    return search({ 0.3, 0.6, 0.45 }, { 0.0, 0.0, 0.0 }, { 1.0, 1.0, 1.0 },
      ObjectiveKind::MinAngle, [&](const std::vector<double>& x) { return peak(x, optimum); },
      settings);
  };
  for (SearchAlgorithm algorithm :
    { SearchAlgorithm::Bobyqa, SearchAlgorithm::Cobyla, SearchAlgorithm::Subplex,
      SearchAlgorithm::Compass })
  {
    const SearchResult a = run(algorithm), b = run(algorithm);
    ASSERT_EQ(a.history.size(), b.history.size());
    for (std::size_t i = 0; i < a.history.size(); ++i)
    {
      EXPECT_EQ(a.history[i].objective, b.history[i].objective);
    }
    EXPECT_EQ(a.best, b.best);
  }
}

TEST(Search, EvaluationLimitAndProgress)
{
  int calls = 0;
  double lastProgress = 0.0;
  SearchSettings settings;
  settings.maxEvaluations = 17;
  settings.tolerance = 0.0;
  const SearchResult result = search({ 0.5, 0.5 }, { 0.0, 0.0 }, { 1.0, 1.0 },
    ObjectiveKind::MinAngle,
    [&](const std::vector<double>& x) {
      ++calls;
      return peak(x, { 0.123, 0.987 });
    },
    settings, [&](double fraction) { lastProgress = fraction; });
  EXPECT_EQ(calls, 17);
  EXPECT_EQ(result.evaluations, 17);
  EXPECT_DOUBLE_EQ(lastProgress, 1.0);
}

TEST(Search, RejectsAStartOutsideItsBounds)
{
  EXPECT_THROW(search({ 2.0 }, { 0.0 }, { 1.0 }, ObjectiveKind::MinAngle,
                 [](const std::vector<double>& x) { return peak(x, { 0.5 }); }, SearchSettings{}),
    std::invalid_argument);
}

TEST(Search, TrialsRuledOutAreCountedNotEvaluated)
{
  // Variable 1 does not enter the objective: ruling its trials out gives the same steps
  // (the same evaluations of variable 0, the same best) with fewer evaluations, the
  // trials left out counted against the limit.
  const std::vector<double> optimum = { 0.62 };
  auto evaluate = [&](const std::vector<double>& x) { return peak({ x[0] }, optimum); };
  SearchSettings settings;
  settings.maxEvaluations = 40;
  settings.tolerance = 0.0;
  const SearchResult all = search({ 0.3, 0.5 }, { 0.0, 0.0 }, { 1.0, 1.0 },
    ObjectiveKind::MinAngle, evaluate, settings);
  int asked = 0;
  const SearchResult filtered = search({ 0.3, 0.5 }, { 0.0, 0.0 }, { 1.0, 1.0 },
    ObjectiveKind::MinAngle, evaluate, settings, {},
    [&](std::size_t variable, const GridMeasures& current) {
      ++asked;
      EXPECT_TRUE(current.feasible);
      return variable != 1;
    });
  EXPECT_EQ(all.evaluations, 40);
  EXPECT_EQ(all.skipped, 0);
  EXPECT_GT(filtered.skipped, 5);
  EXPECT_EQ(filtered.evaluations + filtered.skipped, 40);
  EXPECT_EQ(asked, filtered.evaluations - 1 + filtered.skipped);
  EXPECT_EQ(filtered.best[0], all.best[0]);
  EXPECT_EQ(filtered.bestMeasures.objective, all.bestMeasures.objective);
  // The evaluations made are those of the unfiltered run, in order, less the left out.
  std::vector<double> kept;
  for (const HistoryEntry& entry : all.history)
  {
    kept.push_back(entry.objective);
  }
  std::size_t next = 0;
  for (const HistoryEntry& entry : filtered.history)
  {
    while (next < kept.size() && kept[next] != entry.objective)
    {
      ++next;
    }
    ASSERT_LT(next, kept.size());
    ++next;
  }
}

TEST(GridObjective, ActiveBlocksAreThoseInTheSmoothMinimumsWindow)
{
  // Block 0 sheared by 50 degrees (smallest angle 40), block 1 by 25 (65, more than 20
  // above the minimum: outside the window), block 2 by 35 (55).
  const Grid a = shearedBlock(3, 50.0 / degrees), b = shearedBlock(3, 25.0 / degrees),
             c = shearedBlock(3, 35.0 / degrees);
  const GridMeasures m = measureGrid({ a.block(), b.block(), c.block() }, {}, ObjectiveSettings{});
  EXPECT_NEAR(m.minAngle, 40.0, 1e-9);
  EXPECT_EQ(m.activeBlocks, (std::vector<char>{ 1, 0, 1 }));
  // without block 1 the smooth minimum is the same bit for bit
  const GridMeasures without = measureGrid({ a.block(), c.block() }, {}, ObjectiveSettings{});
  EXPECT_EQ(without.objective, m.objective);
}

TEST(Search, StallRuleAtStallAfter)
{
  // A climb that gains `rate` per unit of the sum of ten variables (no optimum within
  // reach): slow, the search stops at stallAfter trials exactly as a budget of stallAfter
  // does (the same history, bit for bit); fast, it goes on to the evaluation limit.
  auto run = [](double rate, int maxEvaluations, int stallAfter) {
    SearchSettings settings;
    settings.tolerance = 0.0;
    settings.initialStep = 1.0e-6;
    settings.maxEvaluations = maxEvaluations;
    settings.stallAfter = stallAfter;
    settings.stallGain = 1.0;
    const std::vector<double> start(10, 0.0), low(10, 0.0), high(10, 1.0);
    return search(start, low, high, ObjectiveKind::MinAngle,
      [rate](const std::vector<double>& x) {
        GridMeasures m;
        m.feasible = true;
        m.objective = 0.0;
        for (double value : x)
        {
          m.objective -= rate * value;
        }
        m.minAngle = -m.objective;
        return m;
      },
      settings);
  };
  const SearchResult slow = run(1.0, 100, 20), budget = run(1.0, 20, 1000);
  ASSERT_EQ(slow.history.size(), budget.history.size());
  EXPECT_EQ(slow.evaluations, 20);
  for (std::size_t i = 0; i < slow.history.size(); ++i)
  {
    EXPECT_EQ(slow.history[i].objective, budget.history[i].objective);
  }
  EXPECT_EQ(slow.best, budget.best);
  const SearchResult fast = run(1.0e7, 100, 20);
  EXPECT_EQ(fast.evaluations, 100);
}
