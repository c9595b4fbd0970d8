#include "WorkBudget.h"

#include <utility>

namespace blockforge
{

WorkBudget::WorkBudget(std::size_t limit, std::string what)
  : Limit(limit)
  , What(std::move(what))
{
}

void WorkBudget::exhausted() const
{
  throw GeometryError(What + ": no result within " + std::to_string(Limit) +
    " evaluations (a normal case needs a small fraction of that); the input curves have "
    "kinks, spikes or scaled points that keep the search from settling: check them");
}
} // namespace blockforge
