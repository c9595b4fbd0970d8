#include "StagedOutput.h"

#include <cerrno>
#include <csignal>
#include <random>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

namespace blockforge
{
namespace exporting
{
namespace
{
std::string reason(int error)
{
  return std::strerror(error);
}
} // namespace

std::string folderOf(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash == 0 ? 1 : slash);
}

std::string nameOf(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

CheckedFile::CheckedFile(const std::string& path)
  : Path(path)
{
  File = std::fopen(path.c_str(), "wb");
  if (!File)
  {
    fail(errno);
  }
  // Large writes go straight through; the buffer only gathers the small ones.
  std::setvbuf(File, nullptr, _IOFBF, 1 << 20);
}

CheckedFile::~CheckedFile()
{
  if (File)
  {
    std::fclose(File);
  }
}

void CheckedFile::fail(int error) const
{
  throw std::runtime_error("could not write " + Path + ": " + reason(error ? error : EIO));
}

void CheckedFile::write(const void* data, std::size_t bytes)
{
  errno = 0;
  if (bytes && std::fwrite(data, 1, bytes, File) != bytes)
  {
    fail(errno);
  }
}

void CheckedFile::close()
{
  errno = 0;
  const bool flushed = std::fflush(File) == 0;
  const int flushError = errno;
  const int closed = std::fclose(File);
  const int closeError = errno;
  File = nullptr;
  if (!flushed)
  {
    fail(flushError);
  }
  if (closed != 0)
  {
    fail(closeError);
  }
}

PositionalFile::PositionalFile(const std::string& path)
  : Path(path)
{
  Descriptor = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (Descriptor < 0)
  {
    fail(errno);
  }
}

PositionalFile::~PositionalFile()
{
  if (Descriptor >= 0)
  {
    ::close(Descriptor);
  }
}

void PositionalFile::fail(int error) const
{
  throw std::runtime_error("could not write " + Path + ": " + reason(error ? error : EIO));
}

void PositionalFile::writeAt(unsigned long long offset, const void* data, std::size_t bytes)
{
  const char* next = static_cast<const char*>(data);
  while (bytes > 0)
  {
    const ssize_t written = ::pwrite(Descriptor, next, bytes, static_cast<off_t>(offset));
    if (written < 0 && errno == EINTR)
    {
      continue;
    }
    if (written <= 0)
    {
      fail(written < 0 ? errno : ENOSPC);
    }
    next += written;
    offset += static_cast<unsigned long long>(written);
    bytes -= static_cast<std::size_t>(written);
  }
}

void PositionalFile::close()
{
  const int descriptor = Descriptor;
  Descriptor = -1;
  if (::close(descriptor) != 0)
  {
    fail(errno);
  }
}

PositionalFile::Region::Region(PositionalFile& file, unsigned long long offset)
  : File(file)
  , Offset(offset)
  , Buffer(Capacity, '\0')
{
}

void PositionalFile::Region::put(const void* data, std::size_t bytes)
{
  if (Used + bytes > Capacity)
  {
    flush();
  }
  if (bytes > Capacity)
  {
    File.writeAt(Offset, data, bytes);
    Offset += bytes;
    return;
  }
  std::memcpy(&Buffer[Used], data, bytes);
  Used += bytes;
}

void PositionalFile::Region::flush()
{
  File.writeAt(Offset, Buffer.data(), Used);
  Offset += Used;
  Used = 0;
}

namespace
{
const char* const StagingSuffix = ".staging";

bool processAlive(long pid)
{
  if (pid == static_cast<long>(::getpid()))
  {
    return false; // one process writes one target at a time: our own leftovers are stale
  }
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}
} // namespace

std::vector<std::string> staleEntries(
  const std::string& folder, const std::string& prefix, const std::string& suffix)
{
  std::vector<std::string> stale;
  DIR* directory = ::opendir(folder.c_str());
  if (!directory)
  {
    return stale;
  }
  while (dirent* entry = ::readdir(directory))
  {
    const std::string name = entry->d_name;
    if (name.size() <= prefix.size() + suffix.size() ||
      name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    {
      continue;
    }
    const std::string middle =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    const std::size_t dash = middle.find('-');
    if (dash == std::string::npos || dash == 0 || dash + 1 == middle.size() ||
      middle.find_first_not_of("0123456789") != dash ||
      middle.find_first_not_of("0123456789abcdef", dash + 1) != std::string::npos)
    {
      continue;
    }
    if (!processAlive(std::stol(middle.substr(0, dash))))
    {
      stale.push_back(folder + "/" + name);
    }
  }
  ::closedir(directory);
  return stale;
}

void removeStaleStaging(const std::string& target)
{
  // .NAME.<pid>-<hex token>.staging, as blockforge.output names them too.
  for (const std::string& path :
    staleEntries(folderOf(target), "." + nameOf(target) + ".", StagingSuffix))
  {
    removeTree(path);
  }
}

StagedOutput::StagedOutput(const std::string& target, Kind kind)
  : Target(target)
  , What(kind)
{
  makeDirectories(folderOf(target));
  removeStaleStaging(target);
  // The naming of blockforge.output (issue 12): .NAME.<pid>-<token>.staging beside the
  // target, so either side removes what a killed run of the other left.
  static std::mt19937_64 generator(std::random_device{}());
  char token[32];
  std::snprintf(token, sizeof(token), "%ld-%08llx", static_cast<long>(::getpid()),
    static_cast<unsigned long long>(generator() & 0xffffffffULL));
  Token = token;
  Staging = folderOf(target) + "/." + nameOf(target) + "." + Token + StagingSuffix;
  const int made = kind == Kind::Directory
    ? ::mkdir(Staging.c_str(), 0777)
    : ::open(Staging.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (made < 0)
  {
    throw std::runtime_error("could not write " + target + ": " + reason(errno));
  }
  if (kind == Kind::File)
  {
    ::close(made);
  }
}

StagedOutput::~StagedOutput()
{
  if (!Published)
  {
    removeTree(Staging);
  }
}

void StagedOutput::publish()
{
  struct stat existing;
  if (What == Kind::Directory && ::lstat(Target.c_str(), &existing) == 0 &&
    S_ISDIR(existing.st_mode))
  {
    // One exchange publishes the new directory; the older one ends up at the staging
    // path and is removed with it.
    if (::renameat2(AT_FDCWD, Staging.c_str(), AT_FDCWD, Target.c_str(), RENAME_EXCHANGE) == 0)
    {
      removeTree(Staging);
      Published = true;
      return;
    }
    if (errno != EINVAL && errno != ENOSYS)
    {
      throw std::runtime_error("could not write " + Target + ": " + reason(errno));
    }
    // A file system without exchange: move the older directory aside first, back on failure.
    const std::string old = Staging + ".old";
    if (::rename(Target.c_str(), old.c_str()) != 0)
    {
      throw std::runtime_error("could not write " + Target + ": " + reason(errno));
    }
    if (::rename(Staging.c_str(), Target.c_str()) != 0)
    {
      const int error = errno;
      ::rename(old.c_str(), Target.c_str());
      throw std::runtime_error("could not write " + Target + ": " + reason(error));
    }
    removeTree(old);
    Published = true;
    return;
  }
  if (::rename(Staging.c_str(), Target.c_str()) != 0)
  {
    throw std::runtime_error("could not write " + Target + ": " + reason(errno));
  }
  Published = true;
}

void makeDirectories(const std::string& path)
{
  if (path.empty())
  {
    return;
  }
  std::size_t position = 0;
  while (position != std::string::npos)
  {
    position = path.find('/', position + 1);
    const std::string prefix = path.substr(0, position);
    if (prefix.empty() || ::mkdir(prefix.c_str(), 0777) == 0 || errno == EEXIST)
    {
      continue;
    }
    throw std::runtime_error("could not make the folder " + prefix + ": " + reason(errno));
  }
  struct stat status;
  if (::stat(path.c_str(), &status) != 0 || !S_ISDIR(status.st_mode))
  {
    throw std::runtime_error("could not make the folder " + path + ": it is not a folder");
  }
}

void removeTree(const std::string& path)
{
  struct stat status;
  if (path.empty() || ::lstat(path.c_str(), &status) != 0)
  {
    return;
  }
  if (S_ISDIR(status.st_mode))
  {
    if (DIR* directory = ::opendir(path.c_str()))
    {
      std::vector<std::string> entries;
      while (dirent* entry = ::readdir(directory))
      {
        const std::string name = entry->d_name;
        if (name != "." && name != "..")
        {
          entries.push_back(path + "/" + name);
        }
      }
      ::closedir(directory);
      for (const std::string& entry : entries)
      {
        removeTree(entry);
      }
    }
    ::rmdir(path.c_str());
    return;
  }
  ::unlink(path.c_str());
}

std::string writeFailureReason(const std::string& path, int error)
{
  struct statvfs space;
  if (::statvfs(folderOf(path).c_str(), &space) == 0 && space.f_bavail == 0)
  {
    return reason(ENOSPC);
  }
  struct rlimit limit;
  struct stat status;
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
    ::stat(path.c_str(), &status) == 0 &&
    static_cast<unsigned long long>(status.st_size) >= limit.rlim_cur)
  {
    return reason(EFBIG);
  }
  if (error == ENOSPC || error == EFBIG || error == EDQUOT || error == EIO || error == EROFS)
  {
    return reason(error);
  }
  return std::string();
}
} // namespace exporting
} // namespace blockforge
