/**
 * @file Plot3D.h
 * @brief Plot3D grid files of a meshed block model: multiblock ("multi-grid"), 3D, whole,
 * no iblank, one grid per block in model order. No VTK types.
 *
 * Binary (default): Fortran unformatted sequential records as most Plot3D tools read
 * them (NASA's OVERFLOW, Pointwise, VTK's vtkMultiBlockPLOT3DReader with byte counts):
 * little-endian 32-bit record lengths around each record; records: the block count; the
 * (ni, nj, nk) of every block; per block all x, then all y, then all z as 64-bit floats,
 * i fastest. ASCII: the same numbers as text (coordinates in the shortest form that
 * reads back to the same double).
 *
 * Plot3D has no boundary conditions or block connectivity; writePlot3DNeutralMap writes
 * them in the layout of a Neutral Map File (.nmf, the block-connectivity convention of
 * NASA Glenn's codes and Pointwise): block dimensions, then one line per boundary patch
 * face and per block interface with 1-based node ranges. The in-face indices run in the
 * order (j, k) on i faces, (i, k) on j faces, (i, j) on k faces, as the file's header
 * says; a reader with another convention must swap them.
 */
#pragma once

#include "ExportGrid.h"

#include <functional>
#include <string>

namespace blockforge
{
namespace exporting
{
struct Plot3DOptions
{
  bool binary = true;
  std::function<void(double)> progress;
};

/// Writes `path` (.xyz) under a temporary name, then renames it into place. Throws
/// std::runtime_error naming the file and the reason.
void writePlot3D(const ExportGrid& grid, const std::string& path, const Plot3DOptions& options = {});

/// Writes the Neutral Map File `path` (.nmf) of the grid: patches by their template type
/// and name, block interfaces as ONE_TO_ONE with their index orientation, periodic pairs
/// as ONE_TO_ONE with the comment naming the rotation.
void writePlot3DNeutralMap(const ExportGrid& grid, const std::string& path);
} // namespace exporting
} // namespace blockforge
