#include "ControlProblemImpl.h"

namespace blockforge
{
namespace optimize
{
using model::BlockModel;
using model::CarrierGeometry;


ControlProblem::~ControlProblem() = default;

std::vector<double> ControlProblem::start() const
{
  std::vector<double> x;
  for (const ControlVariable& v : Variables)
  {
    x.push_back(v.start);
  }
  return x;
}

std::vector<double> ControlProblem::low() const
{
  std::vector<double> x;
  for (const ControlVariable& v : Variables)
  {
    x.push_back(v.low);
  }
  return x;
}

std::vector<double> ControlProblem::high() const
{
  std::vector<double> x;
  for (const ControlVariable& v : Variables)
  {
    x.push_back(v.high);
  }
  return x;
}

GridMeasures ControlProblem::evaluate(const std::vector<double>& x)
{
  try
  {
    const model::Feasibility feasibility = P->place(x);
    P->forgetUpdated();
    if (feasibility.feasible())
    {
      P->learnBlocks();
    }
    if (P->Objective.kind != ObjectiveKind::NonOrthogonality && feasibility.feasible())
    {
      return P->refuseWeakFaces(P->measureChanged());
    }
    if (!feasibility.feasible())
    {
      GridMeasures failed;
      failed.invertedCells = 1;
      failed.objective = infeasibleObjective(1);
      failed.failure = feasibility.message;
      return failed;
    }
    std::vector<BlockGrid> blocks;
    for (int b = 0; b < P->Plan->blockCount(); ++b)
    {
      const std::array<int, 3> n = P->Plan->nodeCounts(b);
      blocks.push_back({ P->Plan->blockNodes(b).data(), n[0], n[1], n[2] });
    }
    const std::vector<PeriodicSideLink> periodic =
      P->Objective.kind == ObjectiveKind::NonOrthogonality
      ? P->Plan->topology().periodicSideLinks()
      : std::vector<PeriodicSideLink>();
    P->Cells.clear(); // (this objective does not keep the blocks' angles either)
    return P->refuseWeakFaces(measureGrid(blocks, periodic, P->Objective));
  }
  catch (const std::exception& error)
  {
    // The input model itself fails the mesher's check: nothing to evaluate.
    P->Plan.reset();
    P->forgetUpdated();
    GridMeasures failed;
    failed.invertedCells = 1;
    failed.objective = infeasibleObjective(1);
    failed.failure = error.what();
    return failed;
  }
}

void ControlProblem::refuseWeakFaces(bool refuse)
{
  P->RefuseWeakFaces = refuse;
}

void ControlProblem::setObjective(const ObjectiveSettings& objective)
{
  P->Objective = objective;
}

bool ControlProblem::mayGain(std::size_t variable, const GridMeasures& current) const
{
  if (Variables.at(variable).inert)
  {
    return false;
  }
  const std::vector<char>& blocks = P->VariableBlocks.at(variable);
  if (P->Objective.kind != ObjectiveKind::MinAngle || !current.feasible || blocks.empty() ||
    current.activeBlocks.size() != blocks.size())
  {
    return true;
  }
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    if (blocks[b] && current.activeBlocks[b])
    {
      return true;
    }
  }
  return false;
}

void ControlProblem::reject()
{
  if (!P->Undoable || !P->Plan || !P->Plan->undo())
  {
    return;
  }
  P->Undoable = false;
  P->Current = P->Previous;
  P->LastMoved.clear();
  if (!P->LastSkewed.empty())
  {
    // the laws of the skewed edges as they were (the grids are back already)
    std::vector<int> ends;
    P->applySkews(P->Plan->model(), P->Current, P->LastSkewed, ends);
  }
  // the blocks put back have the angles measured before the trial (or none: measured
  // when next needed)
  for (auto& [block, angles] : P->AnglesBefore)
  {
    P->Angles[block] = std::move(angles);
  }
  P->AnglesBefore.clear();
  for (auto& [block, cells] : P->CellsBefore)
  {
    P->Cells[block] = std::move(cells);
  }
  P->CellsBefore.clear();
  P->SizeRatios = P->SizeRatiosBefore;
}

BlockModel ControlProblem::modelAt(const std::vector<double>& x)
{
  P->place(x);
  P->forgetUpdated();
  return P->Plan->model();
}

std::vector<Vec3> ControlProblem::verticesAt(const std::vector<double>& x) const
{
  BlockModel work = P->Base;
  CarrierGeometry geometry = P->Geometry;
  std::vector<int> moved;
  for (std::size_t i = 0; i < Variables.size(); ++i)
  {
    if (Variables[i].component == ControlVariable::SkewComponent)
    {
      continue; // no vertex moves
    }
    setVariable(work, geometry, Variables[i], x[i]);
    moved.push_back(Variables[i].vertex);
  }
  model::applyPlacement(work, geometry, moved);
  std::vector<Vec3> positions;
  for (const model::Vertex& vertex : work.vertices)
  {
    positions.push_back(vertex.position);
  }
  return positions;
}

std::vector<std::vector<double>> ControlProblem::gridAt(const std::vector<double>& x)
{
  const model::Feasibility feasibility = P->place(x);
  P->forgetUpdated();
  if (!feasibility.feasible())
  {
    throw std::runtime_error(feasibility.message);
  }
  std::vector<std::vector<double>> grids;
  for (int b = 0; b < P->Plan->blockCount(); ++b)
  {
    grids.push_back(P->Plan->blockNodes(b));
  }
  return grids;
}
} // namespace optimize
} // namespace blockforge
