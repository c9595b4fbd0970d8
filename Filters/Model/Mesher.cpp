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
  const BlockModel& model = P->Model;
  std::vector<std::array<int, 3>> nodes;
  for (int b = 0; b < blockCount(); ++b)
  {
    nodes.push_back(P->nodeCounts(b));
  }
  const bool countsChanged = nodes != baseNodeCounts(model);
  P->Topo = buildMeshTopology(model, P->Curves, nodes, countsChanged);
  computeAllBoundaries(model, P->Geometry, P->Curves, P->Topo);
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
  meshBlockNodes(P->Model, P->Topo, block, out);
}
} // namespace model
} // namespace blockforge
