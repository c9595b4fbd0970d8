// The block optimizer on the blade-passage templates and every machine given: MinAngle
// classes before and after, run time (median of repetitions), evaluations per second,
// against two baselines on the same control points and bounds:
// - Laplacian smoothing: every control point moves towards the mean of its block-edge
//   neighbours, projected onto its carrier (20 sweeps, relaxation 0.5);
// - a classy_blocks-style score: every block seen as one straight-edged hexahedron, the
//   same search (NLopt BOBYQA) maximising the smooth minimum of those blocks' corner
//   angles, then the real grid measured.
// Not a test (nothing asserts a time). Prints a Markdown table.
// Usage: bench_optimizer [--repetitions N] [--evaluations N] [--sharpness K] [--step F] [--tolerance T] [--stall-gain G]
//          [--algorithm bobyqa|cobyla|subplex] [--blocks] [--timing] [--csv FILE]
//          [--history FILE] [--no-baselines] [--objective NAME] [--size-weight W]
//          [--scan name:weight,... T] [--probe] [--max-skew S] template.yaml input.inf [...]
// --blocks: where the smallest angles are (block, cell, grid plane) and which variables end
// on their bounds; --csv: the table's numbers for Benchmark/optimizer_figure.py; --history:
// every evaluation of every case (objective, smallest angle, the best so far); --no-baselines:
// the optimizer alone; --objective, --size-weight: ObjectiveSettings; --scan: the smallest
// angle along a direction from the optimizer's result (weights in units of each
// variable's range, steps up to T times the direction each way), with the lowest blocks;
// --probe: the smallest angle after moving each variable alone a little from the result;
// --max-skew: skew distributions (OptimizerSettings::skewDistributions) by at most this
// (default 3; 1: none).
#include "Optimizer.h"

#include "../Testing/Cxx/TestTurboInputs.h"

#include "CarrierGeometry.h"
#include "MeshPlan.h"
#include "Template.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <set>
#include <string>
#include <vector>

using namespace blockforge;
using namespace blockforge::optimize;

namespace
{
double seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string classes(const GridMeasures& m)
{
  char text[128];
  std::snprintf(text, sizeof text, "%lld / %lld / %lld / %lld / %lld", m.classes[0],
    m.classes[1], m.classes[2], m.classes[3], m.classes[4]);
  return text;
}

/// The smallest angle, or why there is none.
std::string angleText(const GridMeasures& m)
{
  char text[64];
  if (!m.feasible && m.invertedCells == 0 && !m.failure.empty())
  {
    // the baseline moved a point so that the template cannot place a vertex that
    // depends on it (e.g. a mid-passage point beyond the hub or shroud contour)
    std::snprintf(text, sizeof text, "no placement");
  }
  else if (!m.feasible)
  {
    std::snprintf(text, sizeof text, "inverted cells");
  }
  else
  {
    std::snprintf(text, sizeof text, "%.1f", m.minAngle);
  }
  return text;
}

std::string baseName(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

/// Laplacian smoothing of the control points; returns the configuration.
std::vector<double> laplacian(ControlProblem& problem, const model::BlockModel& model,
  const model::CarrierGeometry& geometry)
{
  std::vector<std::set<int>> neighbours(model.vertices.size());
  for (const model::Block& block : model.blocks)
  {
    for (int e = 0; e < 12; ++e)
    {
      const auto ends = model::edgeVertices(e);
      const int a = block.vertices[ends[0]], b = block.vertices[ends[1]];
      if (a != b)
      {
        neighbours[a].insert(b);
        neighbours[b].insert(a);
      }
    }
  }
  const std::vector<ControlVariable>& variables = problem.variables();
  std::vector<double> x = problem.start();
  for (int sweep = 0; sweep < 20; ++sweep)
  {
    const std::vector<Vec3> positions = problem.verticesAt(x);
    for (std::size_t i = 0; i < variables.size(); ++i)
    {
      const int v = variables[i].vertex;
      if (neighbours[v].empty())
      {
        continue;
      }
      Vec3 mean = Vec3::Zero();
      for (int w : neighbours[v])
      {
        mean += positions[w];
      }
      mean /= static_cast<double>(neighbours[v].size());
      const Vec3 target = positions[v] + 0.5 * (mean - positions[v]);
      if (variables[i].component >= 2) // a free interior vertex: its coordinate
      {
        x[i] = std::min(variables[i].high,
          std::max(variables[i].low, target[variables[i].component - 2]));
        continue;
      }
      double s = 0.0, t = 0.0, distance = 0.0;
      geometry.project(model.vertices[v].constraint.carrier, target, s, t, distance);
      const double value = variables[i].component == 0 ? s : t;
      // The projection may wrap on closed carriers: take the representative nearest x.
      double best = value;
      for (double shift : { -1.0, 1.0 })
      {
        if (std::abs(value + shift - x[i]) < std::abs(best - x[i]))
        {
          best = value + shift;
        }
      }
      x[i] = std::min(variables[i].high, std::max(variables[i].low, best));
    }
  }
  return x;
}

/// classy_blocks-style: the blocks as single straight-edged cells.
GridMeasures blockScore(ControlProblem& problem, const model::BlockModel& model,
  const std::vector<double>& x, double sharpness)
{
  GridMeasures measures;
  std::vector<Vec3> positions;
  try
  {
    positions = problem.verticesAt(x);
  }
  catch (const std::exception& error)
  {
    // a point the template cannot place there: infeasible, as the optimizer counts it
    measures.invertedCells = 1;
    measures.objective = infeasibleObjective(1);
    measures.failure = error.what();
    return measures;
  }
  std::vector<double> corners;
  double lowest = 180.0;
  for (const model::Block& block : model.blocks)
  {
    std::array<Vec3, 8> hex;
    for (int c = 0; c < 8; ++c)
    {
      hex[c] = positions[block.vertices[c]];
    }
    if (hexScaledJacobian(hex) <= 0.0)
    {
      measures.invertedCells += 1;
    }
    double minAngle = 0.0, maxAngle = 0.0;
    hexFaceAngles(hex, minAngle, maxAngle);
    corners.push_back(minAngle);
    lowest = std::min(lowest, minAngle);
  }
  if (measures.invertedCells > 0)
  {
    measures.objective = infeasibleObjective(measures.invertedCells);
    return measures;
  }
  measures.feasible = true;
  measures.minAngle = lowest;
  measures.objective = -softMinimum(corners, sharpness);
  return measures;
}

/// Where the smallest angles of a block are: for its `count` worst cells, the cell
/// (i, j, k) and the grid plane of the face corner with the smallest angle (ij: the face
/// of constant k, ...), printed to stderr.
void printWorstCells(const std::string& block, const std::vector<double>& xyz,
  const std::array<int, 3>& n, std::size_t count)
{
  auto node = [&](int i, int j, int k) {
    const double* p = xyz.data() + 3 * (i + n[0] * (j + n[1] * static_cast<std::size_t>(k)));
    return Vec3(p[0], p[1], p[2]);
  };
  struct Worst
  {
    double angle;
    int i, j, k;
    const char* plane;
    int nodeK; ///< node layer of the corner with the smallest angle
  };
  std::vector<Worst> cells;
  for (int k = 0; k + 1 < n[2]; ++k)
    for (int j = 0; j + 1 < n[1]; ++j)
      for (int i = 0; i + 1 < n[0]; ++i)
      {
        Worst worst{ 180.0, i, j, k, "", k };
        // Corner angles between the cell's edges at each of its 8 corners, per plane.
        for (int c = 0; c < 8; ++c)
        {
          const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
          const Vec3 p = node(i + di, j + dj, k + dk);
          const Vec3 ei = node(i + 1 - di, j + dj, k + dk) - p;
          const Vec3 ej = node(i + di, j + 1 - dj, k + dk) - p;
          const Vec3 ek = node(i + di, j + dj, k + 1 - dk) - p;
          const std::pair<double, const char*> angles[3] = {
            { std::acos(std::max(-1.0, std::min(1.0, ei.normalized().dot(ej.normalized())))), "ij" },
            { std::acos(std::max(-1.0, std::min(1.0, ei.normalized().dot(ek.normalized())))), "ik" },
            { std::acos(std::max(-1.0, std::min(1.0, ej.normalized().dot(ek.normalized())))), "jk" }
          };
          for (const auto& [angle, plane] : angles)
          {
            const double degrees = angle * 180.0 / M_PI;
            if (degrees < worst.angle)
            {
              worst.angle = degrees;
              worst.plane = plane;
              worst.nodeK = k + dk;
            }
          }
        }
        cells.push_back(worst);
      }
  std::sort(cells.begin(), cells.end(),
    [](const Worst& a, const Worst& b) { return a.angle < b.angle; });
  const long below40 = std::count_if(
    cells.begin(), cells.end(), [](const Worst& w) { return w.angle < 40.0; });
  std::fprintf(stderr, "  block %-6s %ld cells below 40:", block.c_str(), below40);
  for (std::size_t c = 0; c < std::min(count, cells.size()); ++c)
  {
    std::fprintf(stderr, " %.1f at (%d,%d,%d) %s node k %d;", cells[c].angle, cells[c].i,
      cells[c].j, cells[c].k, cells[c].plane, cells[c].nodeK);
  }
  std::fprintf(stderr, "\n");
}

/// Block b of `grids` (nodes as ControlProblem::gridAt gives them, counts from `plan`).
BlockGrid blockGrid(const model::MeshPlan& plan, const std::vector<std::vector<double>>& grids,
  std::size_t b)
{
  const std::array<int, 3> n = plan.nodeCounts(static_cast<int>(b));
  return BlockGrid{ grids[b].data(), n[0], n[1], n[2] };
}

/// Per-block smallest angle of a grid, as "name angle" of the `count` lowest blocks.
std::string blockMinima(const model::BlockModel& model, const std::vector<std::vector<double>>& grids,
  model::MeshPlan& plan, std::size_t count)
{
  std::vector<std::pair<double, std::string>> minima;
  for (std::size_t b = 0; b < grids.size(); ++b)
  {
    minima.emplace_back(BlockAngles(blockGrid(plan, grids, b)).lowest(), model.blocks[b].name);
  }
  std::sort(minima.begin(), minima.end());
  std::string text;
  for (std::size_t b = 0; b < std::min(count, minima.size()); ++b)
  {
    char item[64];
    std::snprintf(item, sizeof item, " %s %.1f", minima[b].second.c_str(), minima[b].first);
    text += item;
  }
  return text;
}

/**
 * The objective along a direction from the optimizer's result: `spec` is
 * "name:weight,name:weight,..." (weights in units of each variable's range); prints the
 * smallest angle and the lowest blocks at steps t = -1.0 ... 1.0 of `scale` times the
 * direction (clipped to the bounds).
 */
void scanDirection(const model::BlockModel& model, const model::CarrierGeometry& geometry,
  const OptimizerSettings& settings, const std::vector<double>& best, const std::string& spec,
  double scale)
{
  ControlProblem problem(model, geometry, 1.0, settings.objective, {},
    settings.skewDistributions ? settings.maximumSkew : 0.0);
  const std::vector<ControlVariable>& variables = problem.variables();
  std::vector<double> direction(variables.size(), 0.0);
  std::size_t from = 0;
  while (from < spec.size())
  {
    std::size_t comma = spec.find(',', from);
    if (comma == std::string::npos)
    {
      comma = spec.size();
    }
    const std::string item = spec.substr(from, comma - from);
    const std::size_t colon = item.find(':');
    const std::string name = item.substr(0, colon);
    const double weight = colon == std::string::npos ? 1.0 : std::atof(item.c_str() + colon + 1);
    bool found = false;
    for (std::size_t i = 0; i < variables.size(); ++i)
    {
      if (variables[i].name == name)
      {
        direction[i] = weight * (variables[i].high - variables[i].low);
        found = true;
      }
    }
    if (!found)
    {
      std::fprintf(stderr, "scan: no variable %s\n", name.c_str());
    }
    from = comma + 1;
  }
  model::MeshPlan plan(model, geometry);
  for (int step = -10; step <= 10; ++step)
  {
    const double t = scale * step / 10.0;
    std::vector<double> y = best;
    for (std::size_t i = 0; i < y.size(); ++i)
    {
      y[i] = std::min(variables[i].high, std::max(variables[i].low, best[i] + t * direction[i]));
    }
    const GridMeasures m = problem.evaluate(y);
    std::string lowest;
    if (m.feasible)
    {
      lowest = blockMinima(model, problem.gridAt(y), plan, 5);
    }
    if (!m.feasible)
    {
      lowest = " " + m.failure.substr(0, 160);
    }
    std::fprintf(stderr, "  t %+6.3f: %s min %.2f soft %.2f |%s\n", t,
      m.feasible ? "ok " : "INV", m.feasible ? m.minAngle : 0.0, m.feasible ? m.softMinAngle : 0.0,
      lowest.c_str());
  }
}

/// For every variable, the smallest angle (or "INV" for a folded grid) after moving it
/// alone by -5 %, -1 %, +1 % and +5 % of its range from `best`.
void probeVariables(const model::BlockModel& model, const model::CarrierGeometry& geometry,
  const OptimizerSettings& settings, const std::vector<double>& best)
{
  ControlProblem problem(model, geometry, 1.0, settings.objective, {},
    settings.skewDistributions ? settings.maximumSkew : 0.0);
  const std::vector<ControlVariable>& variables = problem.variables();
  const GridMeasures here = problem.evaluate(best);
  std::fprintf(stderr, "  probe from %.2f deg (moves of -5, -1, +1, +5 %% of the range):\n",
    here.minAngle);
  for (std::size_t i = 0; i < variables.size(); ++i)
  {
    std::string text;
    for (double f : { -0.05, -0.01, 0.01, 0.05 })
    {
      std::vector<double> y = best;
      y[i] = std::min(variables[i].high,
        std::max(variables[i].low, best[i] + f * (variables[i].high - variables[i].low)));
      const GridMeasures m = problem.evaluate(y);
      char item[32];
      std::snprintf(item, sizeof item, m.feasible ? " %6.2f" : "    INV", m.minAngle);
      text += item;
    }
    std::fprintf(stderr, "  %-10s%s\n", variables[i].name.c_str(), text.c_str());
  }
}

struct Row
{
  std::string name, templateName, input;
  GridMeasures before, after, laplace, classy;
  std::size_t variables = 0;
  double seconds = 0.0, cpuSeconds = 0.0, searchSeconds = 0.0, laplaceSeconds = 0.0,
         classySeconds = 0.0;
  int evaluations = 0;
  std::string stop;
};
} // namespace

int main(int argc, char** argv)
{
  int repetitions = 5;
  bool blocks = false;
  bool timing = false;
  bool baselines = true;
  bool probe = false;
  std::string csvFile, historyFile, scan;
  double scanScale = 0.1;
  FILE* history = nullptr;
  OptimizerSettings settings;
  std::vector<std::pair<std::string, std::string>> cases;
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    if (arg == "--repetitions" && a + 1 < argc)
    {
      repetitions = std::atoi(argv[++a]);
    }
    else if (arg == "--evaluations" && a + 1 < argc)
    {
      settings.search.maxEvaluations = std::atoi(argv[++a]);
    }
    else if (arg == "--sharpness" && a + 1 < argc)
    {
      settings.objective.angleSharpness = std::atof(argv[++a]);
    }
    else if (arg == "--step" && a + 1 < argc)
    {
      settings.search.initialStep = std::atof(argv[++a]);
    }
    else if (arg == "--tolerance" && a + 1 < argc)
    {
      settings.search.tolerance = std::atof(argv[++a]);
    }
    else if (arg == "--stall-gain" && a + 1 < argc)
    {
      settings.search.stallGain = std::atof(argv[++a]);
    }
    else if (arg == "--algorithm" && a + 1 < argc)
    {
      const std::string name = argv[++a];
      settings.search.algorithm = name == "cobyla" ? SearchAlgorithm::Cobyla
        : name == "subplex"                        ? SearchAlgorithm::Subplex
        : name == "compass"                        ? SearchAlgorithm::Compass
                                                   : SearchAlgorithm::Bobyqa;
    }
    else if (arg == "--objective" && a + 1 < argc)
    {
      settings.objective.kind = objectiveFromName(argv[++a]);
    }
    else if (arg == "--size-limit" && a + 1 < argc)
    {
      settings.objective.sizeRatioLimit = std::atof(argv[++a]);
    }
    else if (arg == "--size-weight" && a + 1 < argc)
    {
      settings.objective.sizeRatioWeight = std::atof(argv[++a]);
    }
    else if (arg == "--blocks")
    {
      blocks = true;
    }
    else if (arg == "--timing")
    {
      timing = true;
    }
    else if (arg == "--history" && a + 1 < argc)
    {
      historyFile = argv[++a];
    }
    else if (arg == "--scan" && a + 2 < argc)
    {
      scan = argv[++a];
      scanScale = std::atof(argv[++a]);
    }
    else if (arg == "--max-skew" && a + 1 < argc)
    {
      settings.maximumSkew = std::atof(argv[++a]);
      settings.skewDistributions = settings.maximumSkew > 1.0;
    }
    else if (arg == "--probe")
    {
      probe = true;
    }
    else if (arg == "--no-baselines")
    {
      baselines = false;
    }
    else if (arg == "--csv" && a + 1 < argc)
    {
      csvFile = argv[++a];
    }
    else if (a + 1 < argc)
    {
      cases.emplace_back(argv[a], argv[a + 1]);
      ++a;
    }
  }
  if (!historyFile.empty())
  {
    history = std::fopen(historyFile.c_str(), "w");
    if (!history)
    {
      std::fprintf(stderr, "cannot write %s\n", historyFile.c_str());
      return 1;
    }
    std::fprintf(history, "template,input,evaluation,objective,min_angle,feasible,seconds,"
                          "best_objective,best_min_angle\n");
  }
  std::vector<Row> rows;
  for (const auto& [templateFile, inputFile] : cases)
  {
    const model::TemplateInputs inputs = test::readTemplateInputs(inputFile);
    model::CarrierGeometry geometry;
    const model::BlockModel model = model::loadTemplate(templateFile, {}, &inputs, &geometry);
    Row row;
    row.name = baseName(templateFile) + ", " + inputFile;
    row.templateName = baseName(templateFile);
    row.input = inputFile;
    if (timing)
    {
      // Cost of one evaluation: one parameter moved (the plan updates its neighbourhood)
      // against all of them moved (median of 20 each).
      ControlProblem problem(model, geometry, 1.0, settings.objective, {});
      std::vector<double> x = problem.start();
      problem.evaluate(x);
      std::vector<double> one, all;
      for (int r = 0; r < 20; ++r)
      {
        const std::size_t i = r % x.size();
        const double sign = r % 2 ? 1.0 : -1.0;
        std::vector<double> y = x;
        y[i] += sign * 0.01 * (problem.high()[i] - problem.low()[i]);
        auto begin = std::chrono::steady_clock::now();
        problem.evaluate(y);
        one.push_back(seconds(begin));
        problem.evaluate(x);
        for (std::size_t j = 0; j < x.size(); ++j)
        {
          y[j] = x[j] + sign * 0.001 * (problem.high()[j] - problem.low()[j]);
        }
        begin = std::chrono::steady_clock::now();
        problem.evaluate(y);
        all.push_back(seconds(begin));
        problem.evaluate(x);
      }
      std::fprintf(stderr, "%s: evaluation with one parameter moved %.2f ms, all %.2f ms\n",
        row.name.c_str(), 1e3 * median(one), 1e3 * median(all));
    }
    std::vector<double> times, cpuTimes;
    OptimizerResult result;
    for (int r = 0; r < repetitions; ++r)
    {
      model::CarrierGeometry copy = geometry;
      const auto begin = std::chrono::steady_clock::now();
      const std::clock_t cpuBegin = std::clock();
      result = optimizeModel(model, copy, settings);
      times.push_back(seconds(begin));
      cpuTimes.push_back(static_cast<double>(std::clock() - cpuBegin) / CLOCKS_PER_SEC);
    }
    row.cpuSeconds = median(cpuTimes);
    row.before = result.before;
    row.after = result.after;
    row.variables = result.variables.size();
    row.seconds = median(times);
    row.searchSeconds = result.search.seconds;
    row.evaluations = result.search.evaluations;
    row.stop = result.search.stopReason;
    if (history)
    {
      // The best so far is what a run limited to that many evaluations returns (the
      // search is deterministic): the smallest objective no worse than the start.
      double bestObjective = 0.0, bestAngle = 0.0;
      for (const HistoryEntry& entry : result.search.history)
      {
        const HistoryEntry& start = result.search.history.front();
        if (entry.evaluation == 1 ||
          (entry.feasible && entry.objective < bestObjective &&
            (!start.feasible || entry.minAngle >= start.minAngle)))
        {
          bestObjective = entry.objective;
          bestAngle = entry.minAngle;
        }
        std::fprintf(history, "%s,%s,%d,%.9g,%.9g,%d,%.4f,%.9g,%.9g\n", row.templateName.c_str(),
          row.input.c_str(), entry.evaluation, entry.objective, entry.minAngle,
          entry.feasible ? 1 : 0, entry.seconds, bestObjective, bestAngle);
      }
    }
    if (baselines)
    {
      const auto begin = std::chrono::steady_clock::now();
      ControlProblem problem(model, geometry, 1.0, settings.objective, {});
      try
      {
        const std::vector<double> x = laplacian(problem, model, geometry);
        row.laplace = problem.evaluate(x);
      }
      catch (const std::exception& error)
      {
        row.laplace = GridMeasures();
        row.laplace.failure = error.what();
      }
      row.laplaceSeconds = seconds(begin);
    }
    if (baselines)
    {
      const auto begin = std::chrono::steady_clock::now();
      ControlProblem problem(model, geometry, 1.0, settings.objective, {});
      const SearchResult scored = search(problem.start(), problem.low(), problem.high(),
        ObjectiveKind::MinAngle,
        [&](const std::vector<double>& x) {
          return blockScore(problem, model, x, settings.objective.angleSharpness);
        },
        settings.search);
      row.classy = problem.evaluate(scored.best);
      row.classySeconds = seconds(begin);
    }
    std::fprintf(stderr,
      "%s: %zu variables, %.2f -> %.2f deg, %d evaluations (%d trials left out), %.3f s "
      "(CPU %.3f s, search %.3f s) (%s)\n",
      row.name.c_str(), row.variables, row.before.minAngle, row.after.minAngle,
      row.evaluations, result.search.skipped, row.seconds, row.cpuSeconds, row.searchSeconds,
      row.stop.c_str());
    {
      // Largest neighbour size ratio within the blocks, before and after (what the
      // MinAngleAndSizeRatio objective weighs).
      auto largestRatio = [&](const model::BlockModel& m) {
        const model::CarrierGeometry built(m);
        ControlProblem problem(m, built, 1.0, settings.objective, {});
        const std::vector<std::vector<double>> grids = problem.gridAt(problem.start());
        model::MeshPlan plan(m, built);
        std::pair<double, std::string> largest(1.0, "");
        for (std::size_t b = 0; b < grids.size(); ++b)
        {
          largest = std::max(largest,
            std::make_pair(maxNeighbourSizeRatio(blockGrid(plan, grids, b)), m.blocks[b].name));
        }
        return largest;
      };
      try
      {
        const auto before = largestRatio(model), after = largestRatio(result.model);
        std::fprintf(stderr, "  size ratio within blocks: %.2f (%s) -> %.2f (%s)\n", before.first,
          before.second.c_str(), after.first, after.second.c_str());
      }
      catch (const std::exception& error)
      {
        std::fprintf(stderr, "  size ratio: %s\n", error.what());
      }
    }
    if (blocks)
    {
      for (std::size_t i = 0; i < result.variables.size(); ++i)
      {
        const ControlVariable& v = result.variables[i];
        const double value = result.search.best.empty() ? v.start : result.search.best[i];
        std::fprintf(stderr, "  %-10s %.4f in [%.4f, %.4f] from %.4f%s\n", v.name.c_str(), value,
          v.low, v.high, v.start,
          std::abs(value - v.low) < 1e-3 * (v.high - v.low) ||
              std::abs(value - v.high) < 1e-3 * (v.high - v.low)
            ? "  (at its bound)"
            : "");
      }
      const model::CarrierGeometry built(result.model);
      ControlProblem problem(result.model, built, 1.0, settings.objective, {});
      const std::vector<std::vector<double>> grids = problem.gridAt(problem.start());
      model::MeshPlan plan(result.model, built);
      for (std::size_t b = 0; b < grids.size(); ++b)
      {
        printWorstCells(result.model.blocks[b].name, grids[b], plan.nodeCounts(static_cast<int>(b)), 4);
      }
    }
    if (probe)
    {
      probeVariables(model, geometry, settings,
        result.search.best.empty() ? ControlProblem(model, geometry, 1.0, settings.objective, {},
            settings.skewDistributions ? settings.maximumSkew : 0.0).start()
                                   : result.search.best);
    }
    if (!scan.empty())
    {
      scanDirection(model, geometry, settings,
        result.search.best.empty() ? ControlProblem(model, geometry, 1.0, settings.objective, {},
            settings.skewDistributions ? settings.maximumSkew : 0.0).start()
                                   : result.search.best,
        scan, scanScale);
    }
    rows.push_back(row);
  }
  std::printf("| case | variables | before: min angle, classes 0-20 / 20-40 / 40-60 / 60-80 / "
              "80-90 | optimizer: min angle, classes | time, CPU time (medians of %d) | "
              "evaluations, per s | Laplacian: min angle, time | block score: min angle, "
              "time |\n",
    repetitions);
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Row& row : rows)
  {
    std::printf("| %s | %zu | %.1f, %s | %.1f, %s | %.2f s, %.2f s | %d, %.0f/s | %s, %.2f s | "
                "%s, %.2f s |\n",
      row.name.c_str(), row.variables, row.before.minAngle, classes(row.before).c_str(),
      row.after.minAngle, classes(row.after).c_str(), row.seconds, row.cpuSeconds,
      row.evaluations,
      row.evaluations / row.searchSeconds, angleText(row.laplace).c_str(), row.laplaceSeconds,
      angleText(row.classy).c_str(), row.classySeconds);
  }
  if (history)
  {
    std::fclose(history);
  }
  if (!csvFile.empty())
  {
    FILE* csv = std::fopen(csvFile.c_str(), "w");
    if (!csv)
    {
      std::fprintf(stderr, "cannot write %s\n", csvFile.c_str());
      return 1;
    }
    std::fprintf(csv, "template,input,variables,before_min,before_classes,after_min,"
                      "after_classes,seconds,cpu_seconds,evaluations,evaluations_per_second,"
                      "laplacian_min,laplacian_seconds,block_score_min,block_score_seconds\n");
    auto minText = [](const GridMeasures& m) {
      return m.feasible ? std::to_string(m.minAngle) : std::string("inverted");
    };
    auto classText = [](const GridMeasures& m) {
      std::string text;
      for (long long c : m.classes)
      {
        text += (text.empty() ? "" : " ") + std::to_string(c);
      }
      return text;
    };
    for (const Row& row : rows)
    {
      std::fprintf(csv, "%s,%s,%zu,%.6f,%s,%.6f,%s,%.4f,%.4f,%d,%.2f,%s,%.4f,%s,%.4f\n",
        row.templateName.c_str(), row.input.c_str(), row.variables, row.before.minAngle,
        classText(row.before).c_str(), row.after.minAngle, classText(row.after).c_str(),
        row.seconds, row.cpuSeconds, row.evaluations, row.evaluations / row.searchSeconds,
        minText(row.laplace).c_str(), row.laplaceSeconds, minText(row.classy).c_str(),
        row.classySeconds);
    }
    std::fclose(csv);
  }
  return 0;
}
