#include "Search.h"

#include <nlopt.hpp>

#include <algorithm>
#include <limits>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace blockforge
{
namespace optimize
{
namespace
{
nlopt::algorithm nloptAlgorithm(SearchAlgorithm algorithm)
{
  switch (algorithm)
  {
    case SearchAlgorithm::Cobyla:
      return nlopt::LN_COBYLA;
    case SearchAlgorithm::Subplex:
      return nlopt::LN_SBPLX;
    case SearchAlgorithm::Bobyqa:
      break;
  }
  return nlopt::LN_BOBYQA;
}

const char* resultText(nlopt::result result)
{
  switch (result)
  {
    case nlopt::SUCCESS:
      return "converged";
    case nlopt::STOPVAL_REACHED:
      return "objective limit reached";
    case nlopt::FTOL_REACHED:
      return "objective tolerance reached";
    case nlopt::XTOL_REACHED:
      return "step tolerance reached";
    case nlopt::MAXEVAL_REACHED:
      return "evaluation limit reached";
    case nlopt::MAXTIME_REACHED:
      return "time limit reached";
    default:
      return "stopped";
  }
}

/// What the NLopt callback needs: the map from the normalised variables NLopt sees
/// (offset from the start, in units of each range) to the model's.
struct SearchState
{
  const std::vector<double>* start = nullptr;
  std::vector<double> range;
  const EvaluateFunction* evaluate = nullptr;
  const ProgressFunction* progress = nullptr;
  ObjectiveKind kind = ObjectiveKind::MinAngle;
  int maxEvaluations = 1;
  int trials = 0; ///< evaluations and skipped trials, against maxEvaluations
  std::chrono::steady_clock::time_point begin;
  SearchResult* result = nullptr;
  double bestObjective = 0.0;
  double angleAllowance = 0.0;
  /// What a better configuration must not be worse than (notWorse): the start, its
  /// smallest angle lowered by angleAllowance; set with the start.
  GridMeasures reference;

  std::vector<double> toModel(const std::vector<double>& u) const
  {
    std::vector<double> x(u.size());
    for (std::size_t i = 0; i < u.size(); ++i)
    {
      x[i] = (*start)[i] + u[i] * range[i];
    }
    return x;
  }

  GridMeasures record(const std::vector<double>& x)
  {
    GridMeasures measures = (*evaluate)(x);
    SearchResult& out = *result;
    ++trials;
    HistoryEntry entry;
    entry.evaluation = ++out.evaluations;
    entry.objective = measures.objective;
    entry.minAngle = measures.feasible ? measures.minAngle : 0.0;
    entry.feasible = measures.feasible;
    entry.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    out.history.push_back(entry);
    if (out.evaluations == 1)
    {
      out.start = measures;
      out.bestMeasures = measures;
      out.best = x;
      bestObjective = measures.objective;
      reference.feasible = measures.feasible;
      reference.invertedCells = measures.invertedCells;
      reference.minAngle = measures.minAngle - angleAllowance;
      reference.maxNonOrthogonality = measures.maxNonOrthogonality;
    }
    else if (measures.feasible && measures.objective < bestObjective &&
      notWorse(measures, reference, kind))
    {
      out.bestMeasures = measures;
      out.best = x;
      bestObjective = measures.objective;
    }
    if (*progress)
    {
      (*progress)(std::min(1.0, static_cast<double>(trials) / maxEvaluations));
    }
    return measures;
  }
};

/**
 * Compass search (Torczon's coordinate pattern search): each variable in turn tries a step
 * up and down (the direction that last succeeded first); a step that lowers the objective
 * is taken and grows by half, one that does not halves. Stops when every step is below
 * 1e-7 of its range, when a pass that took steps gained less than `tolerance`, at
 * `stallAfter` trials when the last complete pass gained less than `stallGain`, and after
 * that at the end of a pass that gained less than `stallGain`.
 * A trial `mayGain` rules out is counted as a failed one without being evaluated; after
 * an evaluated trial that fails, `reject` (when given) lets the evaluator step back.
 */
void compassSearch(SearchState& state, const std::vector<double>& start,
  const std::vector<double>& low, const std::vector<double>& high,
  const SearchSettings& settings, const TrialFilter& mayGain, const RejectFunction& reject,
  SearchResult& result)
{
  const std::size_t n = start.size();
  std::vector<double> x = start, step(n), direction(n, 1.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    step[i] = settings.initialStep * (high[i] - low[i]);
  }
  double value = result.history.front().objective;
  GridMeasures current = result.start; // the measures of x
  auto largestStep = [&] {
    double largest = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (high[i] > low[i])
      {
        largest = std::max(largest, step[i] / (high[i] - low[i]));
      }
    }
    return largest;
  };
  // The gain of the last complete pass decides at stallAfter trials whether the search
  // goes on (a run that stops there is the run of a budget of stallAfter, bit for bit).
  double lastPassGain = std::numeric_limits<double>::infinity();
  bool extended = false;
  while (true)
  {
    const double passStart = value;
    bool moved = false;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (!(high[i] > low[i]) || step[i] < 1.0e-7 * (high[i] - low[i]))
      {
        continue;
      }
      bool improved = false;
      for (double sign : { direction[i], -direction[i] })
      {
        if (state.trials >= state.maxEvaluations)
        {
          result.stopReason = "evaluation limit reached";
          return;
        }
        if (!extended && state.trials >= settings.stallAfter)
        {
          if (lastPassGain < settings.stallGain)
          {
            result.stopReason = "the last pass before " + std::to_string(settings.stallAfter) +
              " trials gained little";
            return;
          }
          extended = true;
        }
        std::vector<double> y = x;
        y[i] = std::min(high[i], std::max(low[i], x[i] + sign * step[i]));
        if (y[i] == x[i])
        {
          continue;
        }
        if (mayGain && !mayGain(i, current))
        {
          ++state.trials;
          ++result.skipped;
          continue;
        }
        GridMeasures measures = state.record(y);
        const double trial = measures.objective;
        if (trial < value)
        {
          x = y;
          value = trial;
          current = std::move(measures);
          direction[i] = sign;
          step[i] *= 1.5;
          improved = true;
          moved = true;
          break;
        }
        if (reject)
        {
          reject();
        }
      }
      if (!improved)
      {
        step[i] *= 0.5;
      }
    }
    const double largest = largestStep();
    if (largest < 1.0e-7)
    {
      result.stopReason = "step tolerance reached";
      return;
    }
    if (moved && passStart - value < settings.tolerance)
    {
      result.stopReason = "objective tolerance reached";
      return;
    }
    lastPassGain = passStart - value;
    if (extended && lastPassGain < settings.stallGain)
    {
      result.stopReason = "a pass after " + std::to_string(settings.stallAfter) +
        " trials gained little";
      return;
    }
  }
}

double nloptObjective(unsigned n, const double* u, double* gradient, void* data)
{
  (void)gradient; // derivative-free algorithms only
  auto* state = static_cast<SearchState*>(data);
  return state->record(state->toModel(std::vector<double>(u, u + n))).objective;
}
} // namespace

SearchResult search(const std::vector<double>& start, const std::vector<double>& low,
  const std::vector<double>& high, ObjectiveKind kind, const EvaluateFunction& evaluate,
  const SearchSettings& settings, const ProgressFunction& progress, const TrialFilter& mayGain,
  const RejectFunction& reject)
{
  const std::size_t n = start.size();
  if (low.size() != n || high.size() != n)
  {
    throw std::invalid_argument("search: bounds and start differ in size");
  }
  SearchResult result;
  SearchState state;
  state.start = &start;
  state.evaluate = &evaluate;
  state.progress = &progress;
  state.kind = kind;
  state.maxEvaluations = std::max(1, settings.maxEvaluations);
  state.begin = std::chrono::steady_clock::now();
  state.result = &result;
  state.angleAllowance = settings.angleAllowance;
  state.range.resize(n);
  std::vector<double> lowU(n), highU(n), stepU(n), u(n, 0.0);
  bool movable = false;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (!(low[i] <= start[i] && start[i] <= high[i]))
    {
      throw std::invalid_argument("search: the start lies outside its bounds");
    }
    state.range[i] = high[i] - low[i];
    if (state.range[i] > 0.0)
    {
      lowU[i] = (low[i] - start[i]) / state.range[i];
      highU[i] = (high[i] - start[i]) / state.range[i];
      movable = true;
    }
    else
    {
      state.range[i] = 1.0;
    }
    // A first step that fits inside the bounds on at least one side.
    stepU[i] = std::max(std::min(settings.initialStep, std::max(highU[i], -lowU[i])), 1e-6);
  }
  // The start is always the first evaluation, so the result is never worse than it.
  state.record(start);
  if (n == 0 || !movable || settings.maxEvaluations <= 1)
  {
    result.stopReason = "nothing to move";
    result.seconds = result.history.back().seconds;
    return result;
  }
  if (settings.algorithm == SearchAlgorithm::Compass)
  {
    compassSearch(state, start, low, high, settings, mayGain, reject, result);
    result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - state.begin).count();
    return result;
  }
  nlopt::srand(20031139); // only stochastic algorithms use it; fixed for determinism
  nlopt::opt optimizer(nloptAlgorithm(settings.algorithm), static_cast<unsigned>(n));
  optimizer.set_lower_bounds(lowU);
  optimizer.set_upper_bounds(highU);
  optimizer.set_min_objective(nloptObjective, &state);
  optimizer.set_maxeval(settings.maxEvaluations - 1);
  optimizer.set_ftol_abs(settings.tolerance);
  optimizer.set_xtol_abs(1.0e-9);
  optimizer.set_initial_step(stepU);
  double value = 0.0;
  try
  {
    result.stopReason = resultText(optimizer.optimize(u, value));
  }
  catch (const nlopt::roundoff_limited&)
  {
    result.stopReason = "round-off limited";
  }
  catch (const nlopt::forced_stop&)
  {
    result.stopReason = "stopped";
  }
  catch (const std::runtime_error& error)
  {
    // NLopt's generic failure (e.g. BOBYQA's model breaking down near a penalty): the best
    // evaluated configuration stands.
    result.stopReason = std::string("NLopt failure: ") + error.what();
  }
  result.seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - state.begin).count();
  return result;
}
} // namespace optimize
} // namespace blockforge
