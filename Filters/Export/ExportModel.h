/**
 * @file ExportModel.h
 * @brief The ExportGrid of a meshed block model: its blocks' node grids with the model's
 * interfaces, periodic pairs, patches and collapsed (wedge) edges. No VTK types.
 */
#pragma once

#include "ExportGrid.h"

namespace blockforge
{
namespace exporting
{
/**
 * `blocks` are the model's blocks in model order with their node grids (as the mesher
 * made them, at any density). Throws std::runtime_error when their number or node counts
 * do not fit the model (a grid that does not come from this model).
 */
ExportGrid exportGrid(const model::BlockModel& model, std::vector<GridBlock> blocks);
} // namespace exporting
} // namespace blockforge
