/**
 * @file InvertedCells.h
 * @brief The inverted-cell check of a structured block grid: one implementation, used by
 * the mesher on every block it hands out (and by anything else that must refuse a folded
 * grid).
 *
 * A hexahedron is inverted when the Jacobian determinant of its trilinear map is negative
 * at one of its 8 corners or at its centre (Verdict's nine sample points, so a cell
 * passes exactly when GridQuality's ScaledJacobian is not negative). A corner where one
 * of the three edges has collapsed (wedges and prisms written as hexahedra) has no
 * Jacobian and is skipped; so is the centre of a cell whose principal axes collapse.
 * The test is a sign test on triple products; norms are only taken for cells that fail it.
 */
#pragma once

#include <array>
#include <cstdint>

namespace blockforge
{
/// What findInvertedCells found in one block.
struct InvertedCells
{
  std::int64_t count = 0;           ///< inverted cells, including those below
  std::int64_t nonFinite = 0;       ///< cells with a NaN or infinite node
  std::array<int, 3> lowest{};      ///< smallest (i, j, k) cell index among them
  std::array<int, 3> highest{};     ///< largest (i, j, k) cell index among them
  std::array<int, 3> worstCell{};   ///< the cell with the most negative Jacobian
  double worstScaledJacobian = 0.0; ///< its scaled (normalised) Jacobian, in [-1, 0); 0
                                    ///< when only non-finite cells were found
};

/**
 * Finds the inverted cells of a block of ni x nj x nk nodes (`xyz`: 3 doubles per node,
 * i fastest). A normalised Jacobian below -`tolerance` counts as inverted (the default
 * ignores round-off on flat corners). Cells are checked in a fixed order, so the result
 * is deterministic.
 */
InvertedCells findInvertedCells(
  const double* xyz, int ni, int nj, int nk, double tolerance = 1.0e-10);
} // namespace blockforge
