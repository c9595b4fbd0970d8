/**
 * @file Partition.h
 * @brief Blocks shared out between MPI ranks: which rank meshes which block (balanced by
 * cells), and what a rank's share needs from the other blocks to be measured exactly as
 * in a run with every block: the cells beside every interface and periodic face that
 * leads to a block outside the share.
 *
 * The grid quality measures of a cell next to a block face depend on the cell across it
 * (non-orthogonality and skewness use its centre). Topology names those faces; the cells
 * travel as neighbour layers (two node layers of the far block at its side, see
 * blockforge::NeighbourLayer) and periodic links are renumbered to point at them.
 */
#pragma once

#include "Topology.h"

#include <vector>

namespace blockforge
{
namespace model
{
struct QualityNeighbours
{
  /// Sides of blocks outside the subset whose layers the subset needs, in a fixed order
  /// (by block, then side), each once.
  std::vector<BlockFace> layers;
  /// The topology's periodic links that touch the subset, renumbered: subset[i] -> i,
  /// layers[j] -> subset.size() + j (the numbering of computeGridQuality with neighbours).
  std::vector<PeriodicSideLink> links;
};

/**
 * The neighbours of the blocks `subset` (model block indices, in the order the blocks
 * are measured). Interfaces and periodic pairs with both blocks in the subset need
 * nothing; those with neither are left out.
 */
QualityNeighbours qualityNeighbours(const Topology& topology, const std::vector<int>& subset);

/**
 * The piece (0 .. pieceCount-1) of every block, given the node counts of each: largest
 * blocks first, each to the piece with the fewest cells so far (the lowest piece on a
 * tie). Deterministic, so every rank computes the same assignment.
 */
std::vector<int> balancedPieces(const std::vector<std::array<int, 3>>& nodeCounts, int pieceCount);
} // namespace model
} // namespace blockforge
