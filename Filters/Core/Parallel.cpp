#include "Parallel.h"

#include <algorithm>
#include <exception>
#include <mutex>
#include <vector>

namespace blockforge
{
namespace
{
struct Runner
{
  ChunkRunner run;
  int threads = 1;
  double grainScale = 1.0;
};

Runner& installed()
{
  static Runner runner;
  return runner;
}

std::mutex& installMutex()
{
  static std::mutex mutex;
  return mutex;
}
} // namespace

void setChunkRunner(ChunkRunner runner, int threads, double grainScale)
{
  std::lock_guard<std::mutex> lock(installMutex());
  installed().run = std::move(runner);
  installed().threads = installed().run && threads > 1 ? threads : 1;
  installed().grainScale = grainScale > 0.0 ? grainScale : 1.0;
}

long chunkCount(long items, long minimumItems, long maximumChunks)
{
  int threads = 1;
  double scale = 1.0;
  {
    std::lock_guard<std::mutex> lock(installMutex());
    threads = installed().threads;
    scale = installed().grainScale;
  }
  if (threads <= 1 || items <= 0)
  {
    return 1;
  }
  const double smallest = std::max(1.0, scale * static_cast<double>(minimumItems));
  const long byWork = static_cast<long>(static_cast<double>(items) / smallest);
  return std::max(1L, std::min({ 4L * threads, byWork, maximumChunks }));
}

int chunkThreads()
{
  std::lock_guard<std::mutex> lock(installMutex());
  return installed().threads;
}

void forEachChunk(long count, const std::function<void(long chunk)>& body)
{
  if (count <= 0)
  {
    return;
  }
  ChunkRunner run;
  {
    std::lock_guard<std::mutex> lock(installMutex());
    run = installed().run;
  }
  if (!run || count == 1)
  {
    for (long chunk = 0; chunk < count; ++chunk)
    {
      body(chunk);
    }
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(count));
  run(count,
    [&](long begin, long end)
    {
      for (long chunk = begin; chunk < end; ++chunk)
      {
        try
        {
          body(chunk);
        }
        catch (...)
        {
          errors[static_cast<std::size_t>(chunk)] = std::current_exception();
        }
      }
    });
  for (const std::exception_ptr& error : errors)
  {
    if (error)
    {
      std::rethrow_exception(error);
    }
  }
}
} // namespace blockforge
