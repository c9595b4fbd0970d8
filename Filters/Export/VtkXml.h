/**
 * @file VtkXml.h
 * @brief A meshed block model as a VTK XML multiblock file (.vtm) naming one XML
 * structured grid file (.vts) per block, written without VTK: what ParaView and
 * vtkXMLMultiBlockDataReader read, for the native command line. No VTK types.
 *
 * The layout is that of `python3 -m blockforge -o NAME.vtm` (blockforge.output.write_vtm):
 * NAME.vtm beside a fresh folder NAME.pieces-<pid>-<token>/ holding
 * NAME.pieces-<pid>-<token>_<n>.vts, block n in model order under its block name. Points
 * are Float64 in raw appended binary (uncompressed, UInt64 headers, little-endian); no
 * point or cell arrays. Staged like every writer: the pieces and the .vtm are written in
 * a staging folder beside the target, the pieces folder is moved beside it, then the .vtm
 * is renamed over the target (this one rename publishes the grid) and only then are the
 * pieces folders the older .vtm referenced removed. A failure leaves the older grid whole.
 */
#pragma once

#include "ExportGrid.h"

#include <string>

namespace blockforge
{
namespace exporting
{
/// Writes `path` (.vtm) and its pieces; throws std::runtime_error naming the file and the
/// reason (e.g. "No space left on device").
void writeVtkMultiBlock(const ExportGrid& grid, const std::string& path);
} // namespace exporting
} // namespace blockforge
