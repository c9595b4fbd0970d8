// Internal to ControlProblem.cpp and ControlPoints.cpp: the problem's state, shared by the
// file that chooses the control points (ControlPoints.cpp) and the one that evaluates them.
#ifndef BLOCKFORGE_CONTROL_PROBLEM_IMPL_H
#define BLOCKFORGE_CONTROL_PROBLEM_IMPL_H

#include "ControlProblem.h"
#include "FaceChecks.h"

#include "../../Core/InvertedCells.h"

#include "Errors.h"
#include "MeshPlan.h"
#include "ModelSyntax.h"
#include "Placement.h"
#include "Topology.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>


namespace blockforge
{
namespace optimize
{
using model::BlockModel;
using model::CarrierGeometry;

namespace detail
{
/// A surface curve drawn through control points: point `index` of carrier `carrier` is
/// the (s, t) of `vertex` on the surface.
struct ThroughPoint
{
  int carrier = -1;
  int index = -1;
  int vertex = -1;
};

/// Sets variable `variable` to `value`: a control point's carrier parameter, or a
/// coordinate of a free interior vertex's position (components 2, 3, 4: x, y, z).
inline void setVariable(
  BlockModel& model, const CarrierGeometry& geometry, const ControlVariable& variable, double value)
{
  if (variable.component >= 2)
  {
    model.vertices[variable.vertex].position[variable.component - 2] = value;
    return;
  }
  setParameter(model, geometry, variable.vertex, variable.component, value);
}
} // namespace detail
using detail::setVariable;
using detail::ThroughPoint;

struct ControlProblem::Impl
{
  BlockModel Base;
  CarrierGeometry Geometry;
  double Density = 1.0;
  ObjectiveSettings Objective;
  /// Angles (and neighbour size ratios) of every block of the plan as of the last feasible
  /// evaluation; empty where a block changed since (an evaluation measures only those).
  std::vector<std::unique_ptr<BlockAngles>> Angles;
  std::vector<double> SizeRatios;
  /// The angles and size ratios forgetUpdated() took off the blocks the last update
  /// recomputed, as they were before it (what reject() puts back with the plan's undo).
  std::vector<std::pair<int, std::unique_ptr<BlockAngles>>> AnglesBefore;
  std::vector<double> SizeRatiosBefore;
  /// Cell centres, volumes and weak faces (FaceChecks.h) of every block as of the last
  /// feasible evaluation, kept and put back as the angles are; the faces between blocks;
  /// and the weak faces of the start's grid, the most a configuration may have.
  std::vector<std::unique_ptr<BlockCells>> Cells;
  std::vector<std::pair<int, std::unique_ptr<BlockCells>>> CellsBefore;
  std::unique_ptr<InterfaceFaces> Interfaces;
  long long StartWeakFaces = 0;
  bool RefuseWeakFaces = true;
  /// Cells failing checkMesh's cell determinant (BlockCells::failingCells) at the start:
  /// the most a configuration may have.
  long long StartFailingCells = 0;
  /// ... and of them the driven ones (Objective.failingCellsAwayFromWalls).
  long long StartDrivenCells = 0;
  /// Per block, the bits 1 << side of its sides on wall patches (BlockCells).
  std::vector<unsigned char> WallSides;
  /// The start grid's largest neighbour size ratio across block interfaces; a
  /// configuration may have max(this, Objective.maximumInterfaceRatio).
  double StartInterfaceRatio = 1.0;

  /// Forgets the measured angles of the blocks the last plan update recomputed.
  void forgetUpdated()
  {
    AnglesBefore.clear();
    CellsBefore.clear();
    if (!Plan)
    {
      Angles.clear();
      Cells.clear();
      return;
    }
    Angles.resize(Plan->blockCount());
    Cells.resize(Plan->blockCount());
    SizeRatios.resize(Plan->blockCount(), 1.0);
    SizeRatiosBefore = SizeRatios;
    for (int b : Plan->updatedBlocks())
    {
      AnglesBefore.emplace_back(b, std::move(Angles[b]));
      CellsBefore.emplace_back(b, std::move(Cells[b]));
    }
  }

  /// The grids of the plan's blocks.
  std::vector<BlockGrid> planGrids() const
  {
    std::vector<BlockGrid> grids;
    for (int b = 0; b < Plan->blockCount(); ++b)
    {
      const std::array<int, 3> n = Plan->nodeCounts(b);
      grids.push_back({ Plan->blockNodes(b).data(), n[0], n[1], n[2] });
    }
    return grids;
  }

  /// What the plan's grid fails of checkMesh's checks (FaceChecks.h): faces failing the
  /// interpolation weight or volume ratio, cells failing the cell determinant.
  struct CheckCounts
  {
    long long weakFaces = 0, failingCells = 0, drivenCells = 0;
  };

  long long drivenCells(const BlockCells& cells) const
  {
    return Objective.failingCellsAwayFromWalls ? cells.failingAwayFromWalls() : cells.failingCells();
  }

  /// The plan's grid's CheckCounts, measuring the cells of the blocks that changed only.
  CheckCounts checkCounts()
  {
    const std::vector<BlockGrid> grids = planGrids();
    Cells.resize(grids.size());
    std::vector<const BlockCells*> cells;
    CheckCounts counts;
    for (std::size_t b = 0; b < grids.size(); ++b)
    {
      if (!Cells[b])
      {
        Cells[b].reset(new BlockCells(grids[b], &Interfaces->boundarySides(static_cast<int>(b)),
          b < WallSides.size() ? WallSides[b] : 0));
      }
      cells.push_back(Cells[b].get());
      counts.weakFaces += Cells[b]->weakFaces();
      counts.failingCells += Cells[b]->failingCells();
      counts.drivenCells += drivenCells(*Cells[b]);
    }
    counts.weakFaces += Interfaces->weakFaces(grids, cells);
    return counts;
  }

  /// A feasible measure with more weak faces than the start becomes infeasible: the
  /// optimizer refuses configurations that fail more of checkMesh's face checks.
  /// A feasible measure whose neighbour size ratio across block interfaces exceeds
  /// max(the start's, Objective.maximumInterfaceRatio) becomes infeasible too: the
  /// trials' inlet and outlet points left U_M's last cell 3.6 times U_R's first (Rotor 37).
  GridMeasures refuseWeakFaces(GridMeasures measures)
  {
    if (!measures.feasible)
    {
      return measures;
    }
    const CheckCounts counts = checkCounts();
    measures.weakFaces = counts.weakFaces;
    if (RefuseWeakFaces && measures.weakFaces > StartWeakFaces)
    {
      measures.feasible = false;
      measures.objective = infeasibleObjective(measures.weakFaces - StartWeakFaces);
      measures.failure = std::to_string(measures.weakFaces) +
        " faces fail checkMesh's interpolation weight or volume ratio (" +
        std::to_string(StartWeakFaces) + " at the start)";
      return measures;
    }
    measures.failingCells = counts.failingCells;
    if (RefuseWeakFaces && measures.failingCells > StartFailingCells)
    {
      measures.feasible = false;
      measures.objective = infeasibleObjective(measures.failingCells - StartFailingCells);
      measures.failure = std::to_string(measures.failingCells) + " cells fail checkMesh's cell determinant (" +
        std::to_string(StartFailingCells) + " at the start)";
      return measures;
    }
    measures.drivenFailingCells = counts.drivenCells;
    if (RefuseWeakFaces && Objective.minimumAngle > 0.0 && measures.minAngle < Objective.minimumAngle)
    {
      measures.feasible = false;
      // (grows with the shortfall, in hundredths of a degree)
      measures.objective = infeasibleObjective(
        1 + static_cast<long long>(100.0 * (Objective.minimumAngle - measures.minAngle)));
      measures.failure = "smallest angle " + std::to_string(measures.minAngle) + " (at least " +
        std::to_string(Objective.minimumAngle) + ")";
      return measures;
    }
    if (RefuseWeakFaces && Objective.failingCellWeight > 0.0)
    {
      // (below the start's count: the objective falls with each cell that passes)
      measures.objective += Objective.failingCellWeight *
        static_cast<double>(counts.drivenCells - StartDrivenCells);
      // blocks with driven failing cells may gain: the search's trial filter (mayGain)
      // must not leave out the moves that change them
      for (std::size_t b = 0; b < Cells.size() && b < measures.activeBlocks.size(); ++b)
      {
        if (drivenCells(*Cells[b]) > 0)
        {
          measures.activeBlocks[b] = 1;
        }
      }
    }
    if (RefuseWeakFaces && Objective.maximumInterfaceRatio > 0.0)
    {
      measures.interfaceRatio = Interfaces->largestRatio(planGrids()).ratio;
      const double bound = std::max(StartInterfaceRatio, Objective.maximumInterfaceRatio);
      if (measures.interfaceRatio > bound)
      {
        measures.feasible = false;
        // (grows with the excess, in hundredths, so the search sees the way back)
        measures.objective =
          infeasibleObjective(1 + static_cast<long long>(100.0 * (measures.interfaceRatio - bound)));
        measures.failure = "neighbour size ratio " + std::to_string(measures.interfaceRatio) +
          " across a block interface (at most " + std::to_string(bound) + ")";
      }
    }
    return measures;
  }

  /// The angle objectives of the plan's grid, measuring only the blocks that changed
  /// (bit for bit what measureGrid gives for the whole grid).
  GridMeasures measureChanged()
  {
    std::vector<const BlockAngles*> blocks;
    double maxSizeRatio = 1.0;
    for (int b = 0; b < Plan->blockCount(); ++b)
    {
      if (!Angles[b])
      {
        const std::array<int, 3> n = Plan->nodeCounts(b);
        const BlockGrid grid{ Plan->blockNodes(b).data(), n[0], n[1], n[2] };
        const long long inverted = findInvertedCells(grid.xyz, n[0], n[1], n[2]).count;
        if (inverted > 0) // only the plan's first grid is not checked by its update
        {
          GridMeasures failed;
          failed.invertedCells = inverted;
          failed.objective = infeasibleObjective(inverted);
          failed.failure = std::to_string(inverted) + " inverted cells";
          return failed;
        }
        Angles[b].reset(new BlockAngles(grid));
        SizeRatios[b] =
          Objective.kind == ObjectiveKind::MinAngleAndSizeRatio ? maxNeighbourSizeRatio(grid) : 1.0;
      }
      blocks.push_back(Angles[b].get());
      maxSizeRatio = std::max(maxSizeRatio, SizeRatios[b]);
    }
    return measureAngles(blocks, maxSizeRatio, Objective);
  }
  std::vector<ThroughPoint> Through;
  std::vector<ControlVariable> Variables;
  /// Per variable, the blocks a feasible update recomputed when it moved (a superset of
  /// what it changes: the update may have moved other variables too); empty: not known.
  std::vector<std::vector<char>> VariableBlocks;
  std::vector<std::size_t> LastMoved; ///< variables the last place() changed

  /// Notes the blocks the last (feasible) update recomputed against the variable it moved,
  /// when it moved one (a step that also moved back the last trial's variable recomputes
  /// that one's blocks too).
  void learnBlocks()
  {
    if (LastMoved.size() != 1)
    {
      return;
    }
    for (std::size_t i : LastMoved)
    {
      std::vector<char>& blocks = VariableBlocks[i];
      blocks.resize(Plan->blockCount(), 0);
      for (int b : Plan->updatedBlocks())
      {
        blocks[b] = 1;
      }
    }
  }
  /// A topology edge whose node distribution skew variables change: its ends and every
  /// block's use of it (laws are per block).
  struct SkewedEdge
  {
    int a = -1, b = -1;
    std::vector<model::EdgeUse> uses;
  };
  std::vector<SkewedEdge> SkewedEdges;
  /// Per variable (empty for the others): the skewed edges it changes, with +1 where its
  /// block runs the edge from a to b, -1 otherwise.
  std::vector<std::vector<std::pair<int, int>>> SkewOf;

  /// Sets the laws of the skewed edges in `work` for configuration x (each use's base law
  /// with its end cells skewed by the sum of the variables on the edge) and adds the ends
  /// of the edges that changed to `moved`, so the plan recomputes them.
  void applySkews(BlockModel& work, const std::vector<double>& x,
    const std::vector<std::size_t>& changed, std::vector<int>& moved) const
  {
    std::vector<char> touched(SkewedEdges.size(), 0);
    for (std::size_t i : changed)
    {
      for (const auto& [edge, orientation] : SkewOf[i])
      {
        (void)orientation;
        touched[edge] = 1;
      }
    }
    std::vector<double> skew(SkewedEdges.size(), 0.0); // along a -> b
    for (std::size_t i = 0; i < SkewOf.size(); ++i)
    {
      for (const auto& [edge, orientation] : SkewOf[i])
      {
        skew[edge] += orientation * x[i];
      }
    }
    for (std::size_t e = 0; e < SkewedEdges.size(); ++e)
    {
      if (!touched[e])
      {
        continue;
      }
      for (const model::EdgeUse& use : SkewedEdges[e].uses)
      {
        const double along = use.reversed ? -skew[e] : skew[e];
        const DistributionLaw& base = Base.blocks[use.block].laws[use.localEdge];
        DistributionLaw& law = work.blocks[use.block].laws[use.localEdge];
        law.firstCellSize = base.firstCellSize * std::exp(-along);
        law.lastCellSize = base.lastCellSize * std::exp(along);
      }
      moved.push_back(SkewedEdges[e].a);
      moved.push_back(SkewedEdges[e].b);
    }
  }

  /// The grid kept alive between evaluations, and the configuration it holds.
  std::unique_ptr<model::MeshPlan> Plan;
  std::vector<double> Current;
  bool Unplaced = false; ///< a placement failed: the next one places every vertex
  /// The configuration before the last place(), and whether that place() updated the
  /// plan from it (so the plan's undo() puts it back).
  std::vector<double> Previous;
  bool Undoable = false;
  /// The skew variables the last place() changed (their laws live in the model, which the
  /// plan's undo does not put back).
  std::vector<std::size_t> LastSkewed;

  /// Moves the plan to configuration x (only the parameters that changed) and updates it.
  model::Feasibility place(const std::vector<double>& x)
  {
    if (!Plan)
    {
      Plan.reset(new model::MeshPlan(Base, Geometry, Density));
      // the start's weak faces: the most a configuration may have
      const std::vector<BlockGrid> grids = planGrids();
      Interfaces.reset(new InterfaceFaces(grids, Plan->topology().periodicSideLinks()));
      Cells.clear();
      WallSides.assign(grids.size(), 0);
      for (const model::Patch& patch : Plan->model().patches)
      {
        if (patch.type != "wall")
        {
          continue;
        }
        for (const model::BlockFace& face : patch.faces)
        {
          if (face.block >= 0 && static_cast<std::size_t>(face.block) < WallSides.size())
          {
            WallSides[face.block] |= static_cast<unsigned char>(1 << face.face);
          }
        }
      }
      const CheckCounts start = checkCounts();
      StartWeakFaces = start.weakFaces;
      StartFailingCells = start.failingCells;
      StartDrivenCells = start.drivenCells;
      StartInterfaceRatio = Interfaces->largestRatio(grids).ratio;
      Current.clear();
      for (const ControlVariable& variable : Variables)
      {
        Current.push_back(variable.start);
      }
    }
    BlockModel& work = Plan->model();
    std::vector<int> moved;
    std::vector<std::size_t> skewed;
    LastMoved.clear();
    Undoable = false;
    Previous = Current;
    for (std::size_t i = 0; i < Variables.size(); ++i)
    {
      if (x[i] != Current[i])
      {
        LastMoved.push_back(i);
        if (Variables[i].component == ControlVariable::SkewComponent)
        {
          skewed.push_back(i);
          continue;
        }
        setVariable(work, Plan->carriers(), Variables[i], x[i]);
        moved.push_back(Variables[i].vertex);
      }
    }
    Current = x;
    LastSkewed = skewed;
    // Skewed distributions: new laws on their edges, whose ends the update then recomputes
    // (they do not move).
    std::vector<int> recomputed;
    if (!skewed.empty())
    {
      applySkews(work, x, skewed, recomputed);
    }
    if (Unplaced)
    {
      // the last placement failed half-way: place every vertex again
      moved.clear();
      for (std::size_t v = 0; v < work.vertices.size(); ++v)
      {
        moved.push_back(static_cast<int>(v));
      }
    }
    std::vector<int> applied;
    try
    {
      // also draws curves through moved points again (the plan follows them)
      applied = model::applyPlacement(work, Plan->carriers(), moved);
      Unplaced = false;
    }
    catch (const std::exception& error)
    {
      Unplaced = true;
      model::Feasibility failed;
      failed.problem = model::Feasibility::Problem::ModelError;
      failed.message = error.what();
      return failed;
    }
    for (int v : recomputed)
    {
      if (std::find(applied.begin(), applied.end(), v) == applied.end())
      {
        applied.push_back(v);
      }
    }
    Undoable = true;
    return Plan->update(applied);
  }
};

} // namespace optimize
} // namespace blockforge

#endif
