/**
 * @file Cgns.h
 * @brief CGNS file of a meshed block model (Debian's CGNS library, HDF5 files): one
 * structured zone per block, GridConnectivity1to1 for every block interface (in both
 * zones), periodic pairs as 1-to-1 connectivity with its periodic rotation, boundary
 * conditions by family (one family per template patch, with its BC type). No VTK types.
 */
#pragma once

#include "ExportGrid.h"

#include <functional>
#include <string>

namespace blockforge
{
namespace exporting
{
/// The CGNS BC type name of a template patch type (BCWall, BCInflow, BCOutflow,
/// BCSymmetryPlane; UserDefined for others).
std::string cgnsBoundaryType(const std::string& templateType);

/**
 * Writes `path` (.cgns) under a temporary name, then renames it into place. Zones are
 * named after the blocks, families after the patches; coordinates are 64-bit. Throws
 * std::runtime_error naming the file and the CGNS library's reason.
 */
void writeCgns(const ExportGrid& grid, const std::string& path,
  const std::function<void(double)>& progress = {});
} // namespace exporting
} // namespace blockforge
