/**
 * @file GridCheck.h
 * @brief The check every finished block grid passes before it leaves the mesher: no
 * inverted cell (Core's findInvertedCells), reported with the block's name, its template
 * line and the cell index ranges.
 */
#pragma once

#include "BlockModel.h"

#include <array>
#include <cstdint>
#include <string>

namespace blockforge
{
namespace model
{
/// The inverted cells of one block grid, as reportInvertedCells found them.
struct InvertedCellReport
{
  std::int64_t cells = 0; ///< inverted cells (0: the block is fine)
  /// "file:line: block 'name': N inverted cells of M (a x b x c cells) in cell range
  /// i a-b, j c-d, k e-f; worst scaled Jacobian -0.53 at cell (1, 11, 2); ...", or "".
  std::string message;
};

/// Checks the nodes of block `block` (`nodes` = node counts, `xyz` i fastest, as
/// MultiBlockMesher::meshBlock writes them) for inverted cells.
InvertedCellReport reportInvertedCells(
  const BlockModel& model, int block, const std::array<int, 3>& nodes, const double* xyz);

/// Throws TemplateError with reportInvertedCells' message when the block has inverted cells.
void checkBlockCells(
  const BlockModel& model, int block, const std::array<int, 3>& nodes, const double* xyz);
} // namespace model
} // namespace blockforge
