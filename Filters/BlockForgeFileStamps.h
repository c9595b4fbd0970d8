/**
 * @file BlockForgeFileStamps.h
 * @brief Private helper of the file-reading algorithms: notices that files read before
 * were edited on disk (modification time and size), so that an Update after editing a
 * template or an input file reads it again although no property changed (ParaView's
 * Apply, Reload Files and re-entering the same path all end in such an Update).
 */
#pragma once

#include <vtkTimeStamp.h>

#include <map>
#include <string>
#include <vector>

namespace blockforge
{
namespace vtkglue
{
class FileStamps
{
public:
  /// Notes the current state of the files just read (empty paths are skipped); they
  /// replace the files noted before.
  void remember(const std::vector<std::string>& paths);
  /**
   * The time of the last change seen in the remembered files: when one's modification
   * time or size (or existence) differs from when it was remembered or last checked,
   * the returned time is new. Cheap (one stat per file); meant for GetMTime().
   */
  vtkMTimeType changeTime();

private:
  std::map<std::string, std::string> Stamps;
  vtkTimeStamp Changed;
};
} // namespace vtkglue
} // namespace blockforge
