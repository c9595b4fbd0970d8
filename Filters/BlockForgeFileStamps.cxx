#include "BlockForgeFileStamps.h"

#include <filesystem>
#include <system_error>

namespace blockforge
{
namespace vtkglue
{
namespace
{
std::string stampOf(const std::string& path)
{
  std::error_code error;
  const auto time = std::filesystem::last_write_time(path, error);
  if (error)
  {
    return "missing";
  }
  const auto size = std::filesystem::file_size(path, error);
  return std::to_string(time.time_since_epoch().count()) + " " +
    (error ? std::string("?") : std::to_string(size));
}
} // namespace

void FileStamps::remember(const std::vector<std::string>& paths)
{
  this->Stamps.clear();
  for (const std::string& path : paths)
  {
    if (!path.empty())
    {
      this->Stamps[path] = stampOf(path);
    }
  }
}

vtkMTimeType FileStamps::changeTime()
{
  for (auto& entry : this->Stamps)
  {
    std::string now = stampOf(entry.first);
    if (now != entry.second)
    {
      entry.second = std::move(now);
      this->Changed.Modified();
    }
  }
  return this->Changed.GetMTime();
}
} // namespace vtkglue
} // namespace blockforge
