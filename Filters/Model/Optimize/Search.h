/**
 * @file Search.h
 * @brief The optimizer's search over bounded variables (NLopt, derivative-free), kept
 * apart from the block model so it can be tested on closed-form functions: evaluation
 * history, the best configuration that is no worse than the start, deterministic runs.
 */
#pragma once

#include "GridObjective.h"

#include <functional>
#include <string>
#include <vector>

namespace blockforge
{
namespace optimize
{
/// The algorithms the search offers (all local, derivative-free, deterministic).
enum class SearchAlgorithm
{
  Bobyqa,  ///< NLopt: bound-constrained quadratic models (Powell), all variables at once
  Cobyla,  ///< NLopt: linear models (Powell)
  Subplex, ///< NLopt: Nelder-Mead on subspaces (Rowan): robust on kinks and penalties
  Compass  ///< coordinate (compass) search: one variable per step, so a mesh plan
           ///< recomputes only that control point's neighbourhood; robust on the kinks
           ///< of a max-min objective and on infeasible penalties
};

struct SearchSettings
{
  /// Compass by default: on the passage templates it reached 1-4 degrees more than
  /// BOBYQA, with evaluations about 5 times cheaper (README, "The optimizer").
  SearchAlgorithm algorithm = SearchAlgorithm::Compass;
  /// Evaluations at most (compass: trials, evaluated or left out by a TrialFilter).
  /// 700: on axial_passage_oh's sheared O corners (its default o_shear) the compass search
  /// still gains 1-3 degrees a pass after 400 trials (distributor 42.5 degrees at 400, 49.1
  /// at 700; Rotor 37 44.3 and 44.9); runs that stop gaining end at stallAfter (below).
  int maxEvaluations = 700;
  /// Compass: at this many trials the search goes on only when its last complete pass
  /// gained at least stallGain (degrees for the angle objectives), and then until a pass
  /// gains less: a case that has stopped gaining ends where a budget of stallAfter
  /// (the budget before the sheared O-grid) ended it, bit for bit, while the sheared
  /// axial_passage_oh, still gaining 1-3 degrees a pass, goes on.
  int stallAfter = 400;
  double stallGain = 1.0;
  /// Stop when a step changes the objective by less than this (degrees for the angle
  /// objectives) or moves every variable by less than 1e-9 of its range.
  double tolerance = 1.0e-3;
  /// First step of every variable, as a fraction of its range (the feasible region is
  /// often much smaller than the bounds: a few percent keeps the first steps inside;
  /// BOBYQA does better with 0.02).
  double initialStep = 0.05;
  /// The best configuration may be this many degrees below the start's smallest angle
  /// (notWorse against the start less this); 0: no worse than the start.
  double angleAllowance = 0.0;
};

/// One evaluation of the search, in order.
struct HistoryEntry
{
  int evaluation = 0;      ///< 1-based
  double objective = 0.0;  ///< value minimised
  double minAngle = 0.0;   ///< smallest element angle, degrees (0 when infeasible)
  double seconds = 0.0;    ///< since the search started
  bool feasible = false;
};

struct SearchResult
{
  std::vector<double> best;       ///< the returned variables (the start when nothing better)
  GridMeasures start, bestMeasures;
  std::vector<HistoryEntry> history;
  int evaluations = 0;
  /// Compass trials left out because they could not gain (TrialFilter); they count
  /// against maxEvaluations, so the search takes the steps it takes when evaluating them.
  int skipped = 0;
  double seconds = 0.0;
  std::string stopReason;         ///< NLopt's reason, for the log
};

/// Evaluates the configuration at `x` (never throws: failures are infeasible measures).
using EvaluateFunction = std::function<GridMeasures(const std::vector<double>& x)>;
/// Progress in [0, 1] after each evaluation.
using ProgressFunction = std::function<void(double)>;
/// Whether a compass trial of variable `variable` from the configuration measured as
/// `current` may lower the objective; false only when it certainly cannot (the trial
/// is then counted as failed without evaluating it).
using TrialFilter = std::function<bool(std::size_t variable, const GridMeasures& current)>;
/// Called after an evaluated compass trial that the search does not take: the evaluator
/// may put its state back to the configuration before that trial (the next trial then
/// starts from there), as long as its evaluations stay the same, bit for bit.
using RejectFunction = std::function<void()>;

/**
 * Minimises the objective of `evaluate` over low <= x <= high from `start` (inside the
 * bounds). Returns the best evaluated configuration that is notWorse() than the start by
 * the objective's own criterion (the start itself when none is). Deterministic: the same
 * inputs give the same evaluations, bit for bit.
 */
SearchResult search(const std::vector<double>& start, const std::vector<double>& low,
  const std::vector<double>& high, ObjectiveKind kind, const EvaluateFunction& evaluate,
  const SearchSettings& settings, const ProgressFunction& progress = {},
  const TrialFilter& mayGain = {}, const RejectFunction& reject = {});
} // namespace optimize
} // namespace blockforge
