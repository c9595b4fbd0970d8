/**
 * @file WorkBudget.h
 * @brief A bound on the work of an iterative geometric search (projection, intersection,
 * offsets, root finding), so bad input fails quickly with a clear error instead of
 * searching for seconds or minutes.
 *
 * Each iteration of a search is bounded, but a search made of many nested ones (an
 * intersection curve refined node by node, each node a root of a projection distance, each
 * projection a few bracketed Newton solves) can still multiply into minutes on kinked or
 * spiky input. A WorkBudget counts units of work (curve evaluations of the inner
 * projection, evaluations of the outer function) across the whole search and throws a
 * GeometryError naming the search when it is spent. Scope makes a budget the current one
 * of this thread, so inner routines (CurveProjector::project) charge it without a
 * parameter on every call path; scopes nest, and a charge counts for every enclosing
 * budget (a caller can bound or measure a whole template).
 */
#pragma once

#include "Types.h"

#include <cstddef>
#include <string>

namespace blockforge
{
/**
 * @class WorkBudget
 * @brief Counts work units and throws GeometryError once more than `limit` are spent.
 */
class WorkBudget
{
public:
  /// `what` names the search in the error ("intersection with a surface of revolution").
  WorkBudget(std::size_t limit, std::string what);

  /// Charges `units`; throws GeometryError when the total exceeds the limit.
  void spend(std::size_t units = 1)
  {
    Spent += units;
    if (Spent > Limit)
    {
      exhausted();
    }
  }
  std::size_t spent() const { return Spent; }
  std::size_t limit() const { return Limit; }

  /// Charges the current budget of this thread (the innermost Scope) and every budget
  /// whose Scope encloses it, so an outer search also bounds (and counts) nested ones.
  static void charge(std::size_t units = 1)
  {
    for (WorkBudget* budget = Current; budget; budget = budget->Parent)
    {
      budget->spend(units);
    }
  }

  /**
   * @class Scope
   * @brief Makes a budget the current one of this thread for its lifetime (nests).
   */
  class Scope
  {
  public:
    explicit Scope(WorkBudget& budget)
      : Previous(Current)
      , Budget(budget)
      , PreviousParent(budget.Parent)
    {
      budget.Parent = Current;
      Current = &budget;
    }
    ~Scope()
    {
      Current = Previous;
      Budget.Parent = PreviousParent;
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

  private:
    WorkBudget* Previous;
    WorkBudget& Budget;
    WorkBudget* PreviousParent;
  };

private:
  [[noreturn]] void exhausted() const;

  std::size_t Limit;
  std::size_t Spent = 0;
  std::string What;
  WorkBudget* Parent = nullptr; ///< the enclosing scope's budget while in a Scope
  inline static thread_local WorkBudget* Current = nullptr;
};
} // namespace blockforge
