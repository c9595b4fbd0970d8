#include "Mesher.h"

#include "MemoryBudget.h"
#include "MeshInternals.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace blockforge
{
namespace model
{
using syntax::entity;
using syntax::formatNumber;

struct MultiBlockMesher::Impl
{
  BlockModel Model; // a copy: the mesher may outlive the caller's model
  double Multiplier = 1.0;
  int Cap = 0;
  CarrierGeometry Geometry;
  std::vector<NamedCurve> Curves;
  MeshTopology Topo;
  std::vector<char> Meshable; ///< blocks whose boundary grids were computed
  bool Ready = false;

  std::array<int, 3> nodeCounts(int block) const
  {
    return scaledNodeCounts(Model.blocks[block], Multiplier, Cap);
  }
};

MultiBlockMesher::MultiBlockMesher(const BlockModel& model, double densityMultiplier)
  : MultiBlockMesher(model, nullptr, densityMultiplier)
{
}

MultiBlockMesher::MultiBlockMesher(
  const BlockModel& model, const CarrierGeometry& carriers, double densityMultiplier)
  : MultiBlockMesher(model, &carriers, densityMultiplier)
{
}

MultiBlockMesher::MultiBlockMesher(
  const BlockModel& model, const CarrierGeometry* carriers, double densityMultiplier)
  : P(new Impl)
{
  checkDensityMultiplier(model, densityMultiplier);
  checkBasics(model);
  P->Model = model;
  P->Multiplier = densityMultiplier;
  P->Geometry = carriers ? *carriers : CarrierGeometry(P->Model);
  checkModelWith(P->Model, P->Geometry);
  P->Curves = buildNamedCurves(P->Model, P->Geometry);
}

MultiBlockMesher::~MultiBlockMesher() = default;

const CarrierGeometry& MultiBlockMesher::carriers() const
{
  return P->Geometry;
}

void MultiBlockMesher::setCellCap(int cap)
{
  P->Cap = std::max(0, cap);
  P->Ready = false;
}

void MultiBlockMesher::computeBoundaries()
{
  std::vector<int> all(static_cast<std::size_t>(blockCount()));
  for (int b = 0; b < blockCount(); ++b)
  {
    all[b] = b;
  }
  computeBoundaries(all);
}

void MultiBlockMesher::computeBoundaries(const std::vector<int>& blocks)
{
  const BlockModel& model = P->Model;
  std::vector<std::array<int, 3>> nodes;
  for (int b = 0; b < blockCount(); ++b)
  {
    nodes.push_back(P->nodeCounts(b));
  }
  P->Meshable.assign(static_cast<std::size_t>(blockCount()), 0);
  for (const int b : blocks)
  {
    if (b < 0 || b >= blockCount())
    {
      throw std::out_of_range("MultiBlockMesher::computeBoundaries: no block " + std::to_string(b));
    }
    P->Meshable[b] = 1;
  }
  const bool everyBlock =
    std::find(P->Meshable.begin(), P->Meshable.end(), 0) == P->Meshable.end();
  const bool countsChanged = nodes != baseNodeCounts(model);
  P->Topo = buildMeshTopology(model, P->Geometry, P->Curves, nodes, countsChanged);
  computeAllBoundaries(model, P->Geometry, P->Curves, P->Topo, everyBlock ? nullptr : &P->Meshable);
  P->Ready = true;
}

const Topology& MultiBlockMesher::topology() const
{
  if (!P->Ready)
  {
    throw std::logic_error("MultiBlockMesher::topology: call computeBoundaries() first");
  }
  return P->Topo.connectivity;
}

int MultiBlockMesher::blockCount() const
{
  return static_cast<int>(P->Model.blocks.size());
}

std::array<int, 3> MultiBlockMesher::nodeCounts(int block) const
{
  return P->nodeCounts(block);
}

void MultiBlockMesher::meshBlock(int block, double* out) const
{
  if (!P->Ready)
  {
    throw std::logic_error("MultiBlockMesher::meshBlock: call computeBoundaries() first");
  }
  if (block < 0 || block >= blockCount())
  {
    throw std::out_of_range("MultiBlockMesher::meshBlock: no block " + std::to_string(block));
  }
  if (!P->Meshable[block])
  {
    throw std::logic_error("MultiBlockMesher::meshBlock: block " + std::to_string(block) +
      " is not in the share passed to computeBoundaries()");
  }
  meshBlockNodes(P->Model, P->Topo, block, out);
}
} // namespace model
} // namespace blockforge
