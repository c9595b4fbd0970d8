/**
 * @file StagedOutput.h
 * @brief Writing a grid file so that a failure never leaves half a grid behind: every
 * write is checked (a short write, a full disk or a failing close is an error naming the
 * file), files are written under a temporary name beside the target and published by one
 * rename. No VTK types.
 */
#pragma once

#include <cstddef>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace blockforge
{
namespace exporting
{
/**
 * @class CheckedFile
 * @brief A binary file opened for writing whose every write, flush and close is checked:
 * throws std::runtime_error "could not write FILE: REASON" (e.g. "No space left on
 * device") at the first failure.
 */
class CheckedFile
{
public:
  explicit CheckedFile(const std::string& path);
  ~CheckedFile(); ///< closes without checking (only after an exception)
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  void write(const void* data, std::size_t bytes);
  void write(const std::string& text) { write(text.data(), text.size()); }
  /// Flushes and closes; throws when the data did not reach the file system.
  void close();
  const std::string& path() const { return Path; }

private:
  [[noreturn]] void fail(int error) const;
  std::string Path;
  std::FILE* File = nullptr;
};

/**
 * @class PositionalFile
 * @brief A file written at known offsets, region by region (pwrite), with every write
 * and the close checked like CheckedFile: for binary files whose sections can be filled
 * in one pass once their sizes are known.
 */
class PositionalFile
{
public:
  explicit PositionalFile(const std::string& path);
  ~PositionalFile();
  PositionalFile(const PositionalFile&) = delete;
  PositionalFile& operator=(const PositionalFile&) = delete;

  void writeAt(unsigned long long offset, const void* data, std::size_t bytes);
  void close();

  /// Sequential writes into the file from `offset` on, gathered in a buffer.
  class Region
  {
  public:
    Region(PositionalFile& file, unsigned long long offset);
    template <typename T>
    void put(const T& value)
    {
      if (Used + sizeof(T) > Capacity)
      {
        flush();
      }
      std::memcpy(Buffer.data() + Used, &value, sizeof(T));
      Used += sizeof(T);
    }
    void put(const void* data, std::size_t bytes);
    void flush();
    unsigned long long offset() const { return Offset + Used; }

  private:
    static constexpr std::size_t Capacity = std::size_t(1) << 20;
    PositionalFile& File;
    unsigned long long Offset;
    std::string Buffer;
    std::size_t Used = 0;
  };

private:
  [[noreturn]] void fail(int error) const;
  std::string Path;
  int Descriptor = -1;
};

/**
 * @class StagedOutput
 * @brief A temporary file or directory beside `target`, named as blockforge.output (the
 * Python command line's verified writing) names its staging folders,
 * "DIR/.NAME.<pid>-<token>.staging"; publish() renames it onto `target` (a directory is
 * exchanged atomically with an older one, which is then removed). Destroyed without
 * publish() (an exception), it removes what it staged; what a killed process left is
 * removed by the next run for the same target (removeStaleStaging).
 */
class StagedOutput
{
public:
  enum class Kind
  {
    File,
    Directory
  };
  /// Creates the folder of `target` if needed and the staging entry in it.
  StagedOutput(const std::string& target, Kind kind);
  ~StagedOutput();
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;

  /// The temporary path to write (the file, or the directory to fill).
  const std::string& path() const { return Staging; }
  /// "<pid>-<hex>" of the staging name: companions of the output (the .vtm's pieces
  /// folder) take it too, so stale ones are recognised the same way.
  const std::string& token() const { return Token; }
  void publish();

private:
  std::string Target, Staging, Token;
  Kind What;
  bool Published = false;
};

/// Removes the staging entries of `target` left by processes that no longer run.
void removeStaleStaging(const std::string& target);

/// The folder of `path` ("." for a bare name) and its last component.
std::string folderOf(const std::string& path);
std::string nameOf(const std::string& path);

/// The entries of `folder` named PREFIX<pid>-<hex token>SUFFIX whose process no longer
/// runs (this process's own count as stale), as full paths.
std::vector<std::string> staleEntries(
  const std::string& folder, const std::string& prefix, const std::string& suffix);

/// mkdir -p; throws std::runtime_error naming the folder that could not be made.
void makeDirectories(const std::string& path);
/// Removes a file or a directory tree; errors are ignored.
void removeTree(const std::string& path);

/**
 * Why writing `path` most likely failed when a library reported only that it failed
 * (HDF5 under CGNS): "No space left on device" when its file system has no block left for
 * the user, "File too large" when the file reached the process's file-size limit; else
 * the text of `error` (errno as the library left it) when that is a write error, else "".
 */
std::string writeFailureReason(const std::string& path, int error);
} // namespace exporting
} // namespace blockforge
