#include "MemoryBudget.h"

#include "Errors.h"
#include "ModelSyntax.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <sys/resource.h>

namespace blockforge
{
namespace model
{
namespace
{
constexpr double Unlimited = std::numeric_limits<double>::infinity();

/// The value of `key` (in kB) in /proc/meminfo, or infinity.
double meminfoBytes(const std::string& key)
{
  std::ifstream file("/proc/meminfo");
  std::string line;
  while (std::getline(file, line))
  {
    if (line.compare(0, key.size() + 1, key + ":") == 0)
    {
      std::istringstream value(line.substr(key.size() + 1));
      double kilobytes = 0.0;
      if (value >> kilobytes)
      {
        return kilobytes * 1024.0;
      }
    }
  }
  return Unlimited;
}

/// A number in a one-line file (cgroup v2 memory.max / memory.current), or infinity
/// ("max", missing file).
double numberInFile(const std::string& path)
{
  std::ifstream file(path);
  double value = 0.0;
  if (file >> value)
  {
    return value;
  }
  return Unlimited;
}

/// The process's virtual size in bytes (/proc/self/statm), or 0.
double processVirtualBytes()
{
  std::ifstream file("/proc/self/statm");
  double pages = 0.0;
  if (file >> pages)
  {
    return pages * 4096.0;
  }
  return 0.0;
}
} // namespace

void checkDensityMultiplier(const BlockModel& model, double multiplier)
{
  using syntax::formatNumber;
  if (!std::isfinite(multiplier) || !(multiplier > 0.0) || multiplier > MaxDensityMultiplier)
  {
    throw TemplateError(model.sourceFile, 0, syntax::entity("model", model.name),
      "the density multiplier must be a number above 0 and at most " +
        formatNumber(MaxDensityMultiplier) + ", got " + formatNumber(multiplier));
  }
  static const char* const directionNames[3] = { "i", "j", "k" };
  for (const Block& block : model.blocks)
  {
    for (int d = 0; d < 3; ++d)
    {
      const double scaled = std::round(block.cells[d] * multiplier);
      if (scaled > MaxScaledCellsPerDirection)
      {
        throw TemplateError(block.where.file, block.where.line,
          syntax::entity("block", block.name),
          std::string(directionNames[d]) + ": " + std::to_string(block.cells[d]) +
            " cells x density multiplier " + formatNumber(multiplier) + " = " +
            formatNumber(scaled) + " cells, more than " +
            formatNumber(MaxScaledCellsPerDirection) +
            " per direction; lower the density multiplier or the cell counts");
      }
    }
  }
}

std::uint64_t availableMemoryBytes()
{
  double available = meminfoBytes("MemAvailable");
  const double cgroupLimit = numberInFile("/sys/fs/cgroup/memory.max");
  if (std::isfinite(cgroupLimit))
  {
    const double used = numberInFile("/sys/fs/cgroup/memory.current");
    available = std::min(available, cgroupLimit - (std::isfinite(used) ? used : 0.0));
  }
  struct rlimit limit;
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
  {
    available =
      std::min(available, static_cast<double>(limit.rlim_cur) - processVirtualBytes());
  }
  if (!std::isfinite(available))
  {
    return 0;
  }
  return static_cast<std::uint64_t>(std::max(available, 1.0));
}

std::string formatBytes(double bytes)
{
  static const char* const units[] = { "bytes", "kB", "MB", "GB", "TB", "PB", "EB" };
  int unit = 0;
  while (bytes >= 1024.0 && unit < 6)
  {
    bytes /= 1024.0;
    ++unit;
  }
  char text[64];
  std::snprintf(text, sizeof(text), unit == 0 ? "%.0f %s" : "%.3g %s", bytes, units[unit]);
  return text;
}

void checkMemory(double bytes, double maximumGigabytes, const std::string& what,
  const std::string& count, const std::string& advice)
{
  const double limit = maximumGigabytes > 0.0 ? maximumGigabytes * 1073741824.0 : Unlimited;
  const std::uint64_t available = availableMemoryBytes();
  const std::string need = what + " would need " + formatBytes(bytes) + " for " + count;
  if (!(bytes <= limit)) // also NaN
  {
    throw ResourceError(need + ", more than MaximumMemory (" + formatBytes(limit) + "); " +
      advice + ", or raise MaximumMemory");
  }
  if (available > 0 && !(bytes <= static_cast<double>(available)))
  {
    throw ResourceError(
      need + "; this machine has " + formatBytes(static_cast<double>(available)) +
      " available; " + advice);
  }
}

double gridMemoryBytes(const BlockNodeCounts& blocks)
{
  double bytes = 0.0;
  for (const auto& n : blocks)
  {
    const double ni = n[0], nj = n[1], nk = n[2];
    const double nodes = ni * nj * nk;
    const double cells = std::max(ni - 1, 1.0) * std::max(nj - 1, 1.0) * std::max(nk - 1, 1.0);
    const double faceNodes = 2.0 * (ni * nj + nj * nk + ni * nk);
    // coordinates (3 doubles), BlockId (int), the six face grids computed once and their
    // copies in the block's orientation (3 doubles each)
    bytes += 24.0 * nodes + 4.0 * cells + 2.0 * 24.0 * faceNodes;
  }
  return bytes;
}

void checkGridMemory(
  const BlockNodeCounts& blocks, double maximumGigabytes, const std::string& advice)
{
  double nodes = 0.0;
  for (const auto& n : blocks)
  {
    nodes += static_cast<double>(n[0]) * n[1] * n[2];
  }
  char count[64];
  std::snprintf(count, sizeof(count), "%.2g nodes", nodes);
  checkMemory(gridMemoryBytes(blocks), maximumGigabytes, "the grid", count, advice);
}

double qualityMemoryBytes(double cells)
{
  return cells * (7.0 * 8.0 + 4.0); // seven measures (double) and BlockId (int)
}
} // namespace model
} // namespace blockforge
