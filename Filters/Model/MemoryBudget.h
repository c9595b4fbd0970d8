/**
 * @file MemoryBudget.h
 * @brief The size of grid a user may ask for: the density multiplier and scaled cell
 * counts are validated (errors, not clamps), and what a stage will allocate is estimated
 * and checked before it allocates: a grid too large for the machine is refused with a
 * clear error instead of VTK's "Unable to allocate" abort, std::bad_alloc, or a machine
 * swapping for minutes.
 */
#pragma once

#include "BlockModel.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
/// Largest density multiplier the mesher accepts (a stated bound, not a clamp).
constexpr double MaxDensityMultiplier = 1000.0;
/// Largest cell count per block direction after the density multiplier.
constexpr double MaxScaledCellsPerDirection = 1.0e6;

/// Throws TemplateError unless `multiplier` is finite, above 0 and at most
/// MaxDensityMultiplier and every block direction of `model` has at most
/// MaxScaledCellsPerDirection cells after it (the message names the block and direction).
void checkDensityMultiplier(const BlockModel& model, double multiplier);

/**
 * @class ResourceError
 * @brief A stage would need more memory than the machine has available or than the
 * user's MaximumMemory allows. The message says how much, for how many nodes or cells,
 * and what to lower.
 */
class ResourceError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Bytes of memory this process can still get: the smallest of the kernel's MemAvailable
/// (/proc/meminfo), the cgroup's memory.max minus memory.current, and RLIMIT_AS minus the
/// process's current size. 0 when none of them can be read (no check then).
std::uint64_t availableMemoryBytes();

/// "48.0 GB" / "512 MB" (binary units, as `free` shows them).
std::string formatBytes(double bytes);

/**
 * Throws ResourceError when `bytes` exceed `maximumGigabytes` (user limit; <= 0: none)
 * or what availableMemoryBytes() reports. `what` names the result ("the grid", "the
 * quality arrays"), `count` its size ("2.0e9 nodes"), `advice` what to lower. The message
 * reads "the grid would need 48 GB for 2.0e9 nodes; this machine has 23 GB available;
 * lower the density multiplier or the cell counts".
 */
void checkMemory(double bytes, double maximumGigabytes, const std::string& what,
  const std::string& count, const std::string& advice);

/// Node counts (ni, nj, nk) per block.
using BlockNodeCounts = std::vector<std::array<int, 3>>;

/// Bytes a mesher output needs for these blocks (coordinates, BlockId, shared face and
/// edge grids, per-block working copies of the faces).
double gridMemoryBytes(const BlockNodeCounts& blocks);

/// gridMemoryBytes checked with checkMemory; `advice` tells the user what to lower.
void checkGridMemory(
  const BlockNodeCounts& blocks, double maximumGigabytes, const std::string& advice);

/// Bytes of the quality stage's output arrays for `cells` cells (seven measures, BlockId).
double qualityMemoryBytes(double cells);
} // namespace model
} // namespace blockforge
