/**
 * @file MeshPlan.h
 * @brief A mesh plan, built once per topology: the model checked in full, its edge
 * curves, shared edges, faces and blocks with what each depends on, and the grid of every
 * block. After vertices move (Placement.h), update() recomputes only what depends on them
 * and says whether the result is feasible, naming the block that is not, as a value an
 * optimizer can use as a constraint.
 */
#pragma once

#include "BlockModel.h"
#include "CarrierGeometry.h"
#include "Topology.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
/// Whether a grid can be used, and if not where and why.
struct Feasibility
{
  enum class Problem
  {
    None,
    ModelError,   ///< the model check fails (message says why; block when one is at fault)
    FoldedCorner, ///< a block's edges leave a corner in a left-handed frame
    InvertedCell  ///< a cell of the block has a negative Jacobian at a corner
  };
  Problem problem = Problem::None;
  int block = -1; ///< the block at fault, -1 when none (or not one block)
  std::string message;
  bool feasible() const { return problem == Problem::None; }
};

/**
 * @class MeshPlan
 * @brief The grid of a model kept alive: move vertices, update, read the blocks again.
 *
 * Typical use (an optimizer step): change a free parameter of model() with
 * moveParameter() (or set parameters and call applyPlacement()), pass the vertices it
 * returns to update(), read feasibility, then the nodes of updatedBlocks(). Every grid
 * the plan holds is bit for bit the grid MultiBlockMesher makes of the current model.
 */
class MeshPlan
{
public:
  /// Checks the model in full and meshes it; throws TemplateError like MultiBlockMesher.
  MeshPlan(const BlockModel& model, const CarrierGeometry& carriers, double densityMultiplier = 1.0);
  ~MeshPlan();
  MeshPlan(const MeshPlan&) = delete;
  MeshPlan& operator=(const MeshPlan&) = delete;

  /// The model the plan meshes; move its vertices through Placement.h, then update().
  BlockModel& model();
  const BlockModel& model() const;
  const CarrierGeometry& carriers() const;
  /// The carriers to place vertices with (applyPlacement draws curves through moved
  /// vertices again here; update() rebuilds what lies on carriers that changed).
  CarrierGeometry& carriers();
  const Topology& topology() const;

  /**
   * Recomputes what depends on the vertices `moved` (their positions already changed):
   * named edge curves, shared edges and their node distributions, periodic copies, faces,
   * and the blocks touching any of these, with the model check of what moved, the corner
   * check and a check for inverted cells of those blocks. Never throws for a bad model;
   * after an infeasible update the next update recomputes these vertices' dependents too.
   */
  Feasibility update(const std::vector<int>& moved);

  /**
   * Puts back what the last update() changed, as it was before it: the vertices passed to
   * it (and those of earlier failed updates), the edges' ends, the carriers drawn again,
   * the edge, face and block grids, bit for bit; updatedBlocks() then lists the blocks put
   * back. One step only: an optimizer rejecting a trial move undoes it instead of moving
   * back and updating again. False (nothing changed) when there is nothing to undo: after
   * construction or after undo().
   */
  bool undo();

  /// Builds carrier `index` again from its changed definition in model() (a surface curve
  /// drawn through control points that moved); then update() the vertices of the edges on
  /// it, so they follow.
  void rebuildCarrier(int index);

  /// Blocks recomputed by the last update (all blocks after construction).
  const std::vector<int>& updatedBlocks() const;
  int blockCount() const;
  std::array<int, 3> nodeCounts(int block) const;
  /// Nodes of block b (ni*nj*nk*3 doubles, i fastest) as of the last update.
  const std::vector<double>& blockNodes(int block) const;

private:
  struct Impl;
  std::unique_ptr<Impl> P;
};

/// Feasibility of the nodes of one block: InvertedCell (naming `block`) when Core's
/// findInvertedCells finds an inverted cell (InvertedCells.h).
Feasibility checkCells(const double* xyz, const std::array<int, 3>& nodes, int block);
} // namespace model
} // namespace blockforge
