/**
 * @file Mesher.h
 * @brief Model check and multiblock grid generation (paper step 4): edge node
 * distributions, face grids and block interiors by transfinite interpolation.
 *
 * Every shared edge and face is computed once and copied into each block that uses it,
 * so nodes on a shared face coincide bit for bit.
 */
#pragma once

#include "BlockModel.h"
#include "CarrierGeometry.h"
#include "Errors.h"
#include "Topology.h"

#include <functional>
#include <memory>

namespace blockforge
{
namespace model
{
/**
 * Checks the model before meshing and throws TemplateError naming the entity:
 * - every block vertex index valid; every block has positive cells;
 * - node counts agree on every shared edge (message names both blocks and the edge by
 *   its vertex names), and so do the distribution laws (node parameters within 1e-12);
 * - no block is inside-out: negative volume of the straight-edged block, or a
 *   non-degenerate corner left-handed both along the straight lines to its neighbours and
 *   along its edges' tangents (curved blocks wrapping a blade's nose pass); degenerate
 *   blocks (collapsed edges/faces) are allowed. The mesher checks the real corner cells
 *   too (computeBoundaries: the first nodes of the edges leaving every corner);
 * - a face is shared by at most two blocks, with matching node counts;
 * - patch faces are on the domain boundary, no face is in two patches;
 * - periodic partners exist, have as many faces, and each face maps onto a partner face
 *   under the rotation (vertex positions within 1e-9 of the model size).
 * Edge geometry is validated too (arc radii, spline points).
 */
void checkModel(const BlockModel& model);

/// The same check with the model's carriers already built (the template engine's, which
/// are the same bit for bit as CarrierGeometry(model) would build): saves building them
/// again (the blade intersections are most of the time to apply a template).
void checkModel(const BlockModel& model, const CarrierGeometry& geometry);

/**
 * @class MultiBlockMesher
 * @brief Generates the grid of every block of a checked model.
 */
class MultiBlockMesher
{
public:
  /// `densityMultiplier` scales every cell count: cells = max(min(cells, min_cells),
  /// round(cells * m)) (min_cells 1 unless the block gives one).
  /// Calls checkModel(); throws TemplateError on any problem, also when the multiplier is
  /// not in (0, MaxDensityMultiplier] or a scaled count exceeds MaxScaledCellsPerDirection
  /// (checkDensityMultiplier; errors, not clamps: the user asked for something else than
  /// what would be meshed).
  MultiBlockMesher(const BlockModel& model, double densityMultiplier = 1.0);
  /// Same with the model's carriers already built (loadTemplate's `carriers`).
  MultiBlockMesher(const BlockModel& model, const CarrierGeometry& carriers,
    double densityMultiplier = 1.0);
  ~MultiBlockMesher();

  /// Cell count cap for previews: each direction uses min(cells, cap) cells (0 = off).
  /// Must be called before computeBoundaries().
  void setCellCap(int cap);

  /// Computes all edge and face node grids (cheap: surface only). Throws TemplateError
  /// naming the block and corner when the first nodes of the edges leaving a corner form
  /// a left-handed frame (inverted corner cells).
  void computeBoundaries();
  /// The same for a share of the blocks (an MPI rank's): only the edge and face grids
  /// `blocks` need are computed and only their corner cells checked, so a rank does its
  /// own part of the boundary work. The grids of these blocks are the same bits as after
  /// computeBoundaries(); meshBlock() then takes these blocks only.
  void computeBoundaries(const std::vector<int>& blocks);

  int blockCount() const;
  /// The model's carriers as built for meshing.
  const CarrierGeometry& carriers() const;
  /// Node counts (ni, nj, nk) of block b.
  std::array<int, 3> nodeCounts(int block) const;
  /// The model's topology at the mesher's node counts (shared edges and faces, interfaces,
  /// periodic pairs, patches). computeBoundaries() must have been called.
  const Topology& topology() const;
  /// Writes the nodes of block b (ni*nj*nk*3 doubles, i fastest) into `out`.
  /// computeBoundaries() must have been called (for this block). Thread-safe for
  /// different blocks.
  void meshBlock(int block, double* out) const;

private:
  MultiBlockMesher(const BlockModel& model, const CarrierGeometry* carriers,
    double densityMultiplier);
  struct Impl;
  std::unique_ptr<Impl> P;
};
} // namespace model
} // namespace blockforge
