#include "Optimizer.h"

#include "MemoryBudget.h"
#include "Topology.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace blockforge
{
namespace optimize
{
namespace
{
/// Node counts of every block at density multiplier `density` (as the mesher makes them).
model::BlockNodeCounts nodeCounts(const model::BlockModel& model, double density)
{
  model::BlockNodeCounts counts;
  for (const model::Block& block : model.blocks)
  {
    counts.push_back(model::scaledNodeCounts(block, density));
  }
  return counts;
}

/// Nodes of the grid of `model` at density multiplier `density`.
double nodeCount(const model::BlockModel& model, double density)
{
  double nodes = 0.0;
  for (const std::array<int, 3>& n : nodeCounts(model, density))
  {
    nodes += static_cast<double>(n[0]) * n[1] * n[2];
  }
  return nodes;
}

/// A history row for an evaluation made outside the search (manual moves only).
HistoryEntry historyEntry(
  int evaluation, const GridMeasures& measures, std::chrono::steady_clock::time_point begin)
{
  HistoryEntry entry;
  entry.evaluation = evaluation;
  entry.objective = measures.objective;
  entry.minAngle = measures.feasible ? measures.minAngle : 0.0;
  entry.feasible = measures.feasible;
  entry.seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return entry;
}
} // namespace

double measuredDensity(const model::BlockModel& model, double densityMultiplier)
{
  double density = densityMultiplier;
  while (density > 1e-6 && nodeCount(model, density) > MaximumMeasuredNodes)
  {
    density *= 0.8;
  }
  return density;
}

OptimizerResult optimizeModel(const model::BlockModel& model, model::CarrierGeometry& geometry,
  const OptimizerSettings& requested, const ProgressFunction& progress)
{
  // The mesher's rules for the density (errors, not clamps): a density it would refuse is
  // refused here too, before any work.
  model::checkDensityMultiplier(model, requested.densityMultiplier);
  model::checkGridMemory(nodeCounts(model, requested.densityMultiplier),
    requested.maximumMemory, "lower the density multiplier or the cell counts");
  const std::chrono::steady_clock::time_point begin = std::chrono::steady_clock::now();
  OptimizerSettings settings = requested;
  settings.densityMultiplier = measuredDensity(model, requested.densityMultiplier);
  OptimizerResult result;
  result.densityMultiplier = settings.densityMultiplier;
  // The input as it is gives the "before" of the class counts (an input that folds or
  // cannot be meshed is infeasible; the search may still find a way out).
  if (!settings.moves.empty())
  {
    ControlProblem input(model, geometry, settings.densityMultiplier, settings.objective, {});
    result.before = input.evaluate(input.start());
  }
  result.model = model;
  applyMoves(result.model, geometry, settings.moves);
  std::vector<std::string> fixed = settings.fixed;
  for (const ControlPointMove& move : settings.moves)
  {
    fixed.push_back(move.name);
  }
  const double skew =
    settings.automatic && settings.skewDistributions ? settings.maximumSkew : 0.0;
  ControlProblem problem(
    result.model, geometry, settings.densityMultiplier, settings.objective, fixed, skew);
  result.variables = problem.variables();
  result.boundaryLocked = problem.boundaryLocked();
  if (!settings.automatic)
  {
    // Manual moves only: the history holds the input (evaluation 1) and, when points
    // were moved, the moved model (evaluation 2), which is the result.
    result.after = problem.evaluate(problem.start());
    if (settings.moves.empty())
    {
      result.before = result.after;
    }
    SearchResult& record = result.search;
    record.start = result.before;
    record.bestMeasures = result.after;
    record.best = problem.start();
    record.history.push_back(historyEntry(1, result.before, begin));
    if (!settings.moves.empty())
    {
      record.history.push_back(historyEntry(2, result.after, begin));
    }
    record.evaluations = static_cast<int>(record.history.size());
    record.seconds = record.history.back().seconds;
    record.stopReason = "manual moves only";
    return result;
  }
  result.search = search(problem.start(), problem.low(), problem.high(),
    settings.objective.kind,
    [&](const std::vector<double>& x) { return problem.evaluate(x); }, settings.search,
    progress,
    [&](std::size_t variable, const GridMeasures& current) {
      return problem.mayGain(variable, current);
    },
    [&] { problem.reject(); });
  // (the trial budget covers both searches: the second takes what the first left, at most
  // cellSearchEvaluations)
  const int cellTrials = std::min(settings.cellSearchEvaluations,
    settings.search.maxEvaluations - result.search.evaluations - result.search.skipped);
  if (settings.cellSearchAllowance > 0.0 && settings.cellSearchWeight > 0.0 && cellTrials > 1 &&
    result.search.bestMeasures.feasible && settings.objective.kind != ObjectiveKind::NonOrthogonality)
  {
    // Issue 10: the second search, from the first's end point (its history follows the
    // first's; its start is that end point's evaluation again)
    ObjectiveSettings cells = settings.objective;
    cells.failingCellWeight = settings.cellSearchWeight;
    cells.failingCellsAwayFromWalls = true;
    cells.minimumAngle = result.search.bestMeasures.minAngle - settings.cellSearchAllowance;
    problem.setObjective(cells);
    SearchSettings second = settings.search;
    second.maxEvaluations = cellTrials;
    second.stallAfter = cellTrials;
    second.angleAllowance = settings.cellSearchAllowance;
    second.initialStep = settings.cellSearchStep;
    const SearchResult phase = search(result.search.best, problem.low(), problem.high(),
      settings.objective.kind,
      [&](const std::vector<double>& x) { return problem.evaluate(x); }, second, progress,
      [&](std::size_t variable, const GridMeasures& current) {
        return problem.mayGain(variable, current);
      },
      [&] { problem.reject(); });
    problem.setObjective(settings.objective);
    if (phase.best != result.search.best)
    {
      result.search.best = phase.best;
      result.search.bestMeasures = phase.bestMeasures;
    }
    const double offset = result.search.seconds;
    for (HistoryEntry entry : phase.history)
    {
      entry.evaluation += result.search.evaluations;
      entry.seconds += offset;
      result.search.history.push_back(entry);
    }
    result.search.evaluations += phase.evaluations;
    result.search.skipped += phase.skipped;
    result.search.seconds += phase.seconds;
    result.search.stopReason += "; cell search: " + phase.stopReason;
  }
  result.after = result.search.bestMeasures;
  if (settings.moves.empty())
  {
    result.before = result.search.start;
  }
  // (When the search kept the start, the grid at the requested density is the template's
  // own: nothing to check; that check meshed 1 M cells twice for nothing, 0.4 s.)
  if (settings.densityMultiplier != requested.densityMultiplier && result.after.feasible &&
    result.search.best != problem.start())
  {
    // The search measured a coarsened copy, whose first cells differ from the grid the
    // mesher will make: that grid must be valid and no worse than the start's at the
    // requested density. Otherwise step back towards the start (halving the step); the
    // start itself is what the template gave.
    ControlProblem fine(
      result.model, geometry, requested.densityMultiplier, settings.objective, fixed, skew);
    // (The search refused configurations with more weak faces than the start on the copy
    // it measured; the final grid's own are not held to its start's: the cells that shrink
    // with the density there fail faces the copy does not have, and holding them stepped
    // the compressor at density 4 back to 4.6 degrees, 129 weak faces, against 20.9 and
    // 219 for the search's end point, where 510 failed before the search refused them.)
    // (Nor its interface ratio: held there too, the final grid's jumps, which differ from
    // the copy's, stepped Rotor 37 at density 2 back to half the move, 35.99 degrees and
    // 1.37 against 42.39 and 1.62.)
    fine.refuseWeakFaces(false);
    const std::vector<double> start = problem.start();
    const std::vector<double> best = result.search.best;
    const GridMeasures fineStart = fine.evaluate(start);
    std::vector<double> x = best;
    double step = 1.0;
    for (;;)
    {
      const GridMeasures measured = fine.evaluate(x);
      if (measured.feasible &&
        (!fineStart.feasible || notWorse(measured, fineStart, settings.objective.kind)))
      {
        break;
      }
      step *= 0.5;
      if (step < 1.0 / 64.0)
      {
        x = start;
        break;
      }
      for (std::size_t i = 0; i < x.size(); ++i)
      {
        x[i] = start[i] + step * (best[i] - start[i]);
      }
    }
    if (x != best)
    {
      result.search.best = x;
      result.after = problem.evaluate(x);
      result.keptStep = x == start ? 0.0 : step;
    }
  }
  const model::BlockModel moved = result.model;
  result.model = problem.modelAt(result.search.best);
  // Surface curves drawn through points that moved are drawn again in `geometry`.
  for (std::size_t c = 0; c < moved.carriers.size(); ++c)
  {
    if (moved.carriers[c].parameterPoints != result.model.carriers[c].parameterPoints)
    {
      geometry.rebuild(result.model, static_cast<int>(c));
    }
  }
  return result;
}
} // namespace optimize
} // namespace blockforge
