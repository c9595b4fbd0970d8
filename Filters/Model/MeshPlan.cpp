#include "MeshPlan.h"

#include "MemoryBudget.h"
#include "MeshInternals.h"
#include "Mesher.h"

#include "../Core/InvertedCells.h"
#include "../Core/Parallel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace model
{
struct MeshPlan::Impl
{
  BlockModel Model;
  CarrierGeometry Geometry;
  double Multiplier = 1.0;
  bool AllowFallback = false;
  std::vector<NamedCurve> Curves;
  MeshTopology Topo;
  std::vector<EdgeCopy> Copies;
  std::map<int, int> OnSurface;
  std::vector<bool> IsImage;
  std::vector<std::vector<double>> Nodes;
  std::vector<int> Updated;
  std::vector<int> Pending; ///< vertices of failed updates, recomputed with the next one
  ProjectionCache Projections;
  /// The curve and surface of every carrier as last meshed: a carrier whose shape is no
  /// longer these was drawn again by the placement (a curve through moved vertices).
  std::vector<std::pair<const void*, const void*>> CarrierShapes;
  /// The `at` of every edge as last meshed: the placement evaluates `at` expressions again.
  std::vector<std::vector<double>> EdgeEnds;

  std::pair<const void*, const void*> shape(int c) const
  {
    return { Geometry.curve(c).get(), Geometry.surface(c).get() };
  }

  // What depends on what, built once.
  std::vector<std::vector<int>> VertexNamedEdges;  ///< vertex -> named edges ending at it
  std::vector<std::vector<int>> NamedFollowers;    ///< named edge -> periodic/follow edges
  std::vector<char> FollowedEdges;                 ///< named edge -> followed (followedEdges)
  std::vector<std::vector<int>> VertexUniqueEdges; ///< vertex -> unique edges ending at it
  std::vector<int> NamedUnique;                    ///< named edge -> unique edge, -1
  std::vector<std::vector<int>> EdgeFaces;         ///< unique edge -> unique faces
  std::vector<std::vector<int>> EdgeBlocks;        ///< unique edge -> blocks
  std::vector<std::vector<int>> FaceBlocks;        ///< unique face -> blocks
  std::vector<std::vector<int>> VertexBlocks;      ///< vertex -> blocks

  /**
   * The model's vertices, carriers and carrier shapes as of the last update (what undo()
   * puts back in the model), and what the last update changed, as it was before it.
   * Grids are saved just before they are overwritten, into buffers kept from update to
   * update (no allocation once they have their sizes).
   */
  std::vector<Vertex> CommittedVertices;
  std::vector<Carrier> CommittedCarriers;
  CarrierGeometry CommittedGeometry;
  struct Saved
  {
    bool valid = false;
    std::vector<std::pair<int, Vertex>> vertices;
    std::vector<std::pair<int, Carrier>> carriers;
    CarrierGeometry geometry;
    std::vector<std::vector<double>> edgeEnds;
    std::vector<std::pair<const void*, const void*>> carrierShapes;
    std::vector<int> curveIndices;
    std::vector<NamedCurve> curves;
    std::vector<UniqueEdge> edges;
    std::vector<MeshLinks> blocks;
    std::vector<PeriodicPair> periodic;
    std::vector<int> faceIndices;
    std::vector<std::vector<double>> faces;  ///< by unique face (only faceIndices valid)
    std::vector<int> nodeIndices;
    std::vector<std::vector<double>> nodes; ///< by block (only nodeIndices valid)
    std::vector<int> updated, pending;
  } Before;

  void buildDependencies();
  void run(const std::vector<int>& moved);
  /// Saves what an update of `vertices` may change (before it changes it).
  void save(const std::vector<int>& vertices);
  void saveFace(int f)
  {
    if (std::find(Before.faceIndices.begin(), Before.faceIndices.end(), f) != Before.faceIndices.end())
    {
      return; // saved before this update changed it
    }
    Before.faceIndices.push_back(f);
    Before.faces[f] = Topo.faces[f].xyz;
  }
};

namespace
{
template <typename T>
void addUnique(std::vector<T>& list, const T& value)
{
  if (std::find(list.begin(), list.end(), value) == list.end())
  {
    list.push_back(value);
  }
}

Feasibility infeasible(Feasibility::Problem problem, int block, const std::string& message)
{
  Feasibility result;
  result.problem = problem;
  result.block = block;
  result.message = message;
  return result;
}
} // namespace

void MeshPlan::Impl::buildDependencies()
{
  const std::size_t vertexCount = Model.vertices.size();
  VertexNamedEdges.assign(vertexCount, {});
  VertexUniqueEdges.assign(vertexCount, {});
  VertexBlocks.assign(vertexCount, {});
  NamedFollowers.assign(Model.edges.size(), {});
  NamedUnique.assign(Model.edges.size(), -1);
  FollowedEdges = followedEdges(Model);
  for (std::size_t e = 0; e < Model.edges.size(); ++e)
  {
    const Edge& edge = Model.edges[e];
    VertexNamedEdges[edge.from].push_back(static_cast<int>(e));
    VertexNamedEdges[edge.to].push_back(static_cast<int>(e));
    if ((edge.kind == Edge::Kind::Periodic || edge.kind == Edge::Kind::Follow) && edge.source >= 0)
    {
      NamedFollowers[edge.source].push_back(static_cast<int>(e));
    }
  }
  EdgeFaces.assign(Topo.edges.size(), {});
  EdgeBlocks.assign(Topo.edges.size(), {});
  FaceBlocks.assign(Topo.faces.size(), {});
  for (std::size_t u = 0; u < Topo.edges.size(); ++u)
  {
    const UniqueEdge& edge = Topo.edges[u];
    VertexUniqueEdges[edge.a].push_back(static_cast<int>(u));
    VertexUniqueEdges[edge.b].push_back(static_cast<int>(u));
    if (edge.named >= 0)
    {
      NamedUnique[edge.named] = static_cast<int>(u);
    }
    for (const EdgeUse& use : edge.uses)
    {
      addUnique(EdgeBlocks[u], use.block);
    }
  }
  for (std::size_t b = 0; b < Topo.blocks.size(); ++b)
  {
    const MeshLinks& links = Topo.blocks[b];
    for (int v : Model.blocks[b].vertices)
    {
      addUnique(VertexBlocks[v], static_cast<int>(b));
    }
    for (int f = 0; f < 6; ++f)
    {
      const int face = links.face[f];
      if (face < 0)
      {
        continue;
      }
      addUnique(FaceBlocks[face], static_cast<int>(b));
      for (const int local : faceEdges(f))
      {
        if (links.edge[local] >= 0)
        {
          addUnique(EdgeFaces[links.edge[local]], face);
        }
      }
    }
  }
}

MeshPlan::MeshPlan(const BlockModel& model, const CarrierGeometry& carriers, double densityMultiplier)
  : P(new Impl)
{
  checkDensityMultiplier(model, densityMultiplier);
  checkBasics(model);
  P->Model = model;
  P->Geometry = carriers;
  P->Multiplier = densityMultiplier;
  checkModelWith(P->Model, P->Geometry);
  P->Curves = buildNamedCurves(P->Model, P->Geometry);
  std::vector<std::array<int, 3>> nodes;
  for (const Block& block : P->Model.blocks)
  {
    nodes.push_back(scaledNodeCounts(block, densityMultiplier, 0));
  }
  P->AllowFallback = nodes != baseNodeCounts(P->Model);
  P->Topo = buildMeshTopology(P->Model, P->Geometry, P->Curves, nodes, P->AllowFallback);
  computeAllBoundaries(P->Model, P->Geometry, P->Curves, P->Topo);
  P->Copies = periodicEdgeCopies(P->Model, P->Topo);
  P->OnSurface = surfaceFaceCarriers(P->Model, P->Topo);
  P->IsImage.assign(P->Topo.faces.size(), false);
  for (const PeriodicPair& pair : P->Topo.connectivity.periodic)
  {
    P->IsImage[pair.image] = true;
  }
  P->buildDependencies();
  for (int c = 0; c < static_cast<int>(P->Model.carriers.size()); ++c)
  {
    P->CarrierShapes.push_back(P->shape(c));
  }
  for (const Edge& edge : P->Model.edges)
  {
    P->EdgeEnds.push_back(edge.at);
  }
  P->CommittedVertices = P->Model.vertices;
  P->CommittedCarriers = P->Model.carriers;
  P->CommittedGeometry = P->Geometry;
  P->Before.faces.resize(P->Topo.faces.size());
  P->Before.nodes.resize(P->Model.blocks.size());
  P->Nodes.resize(P->Model.blocks.size());
  for (int b = 0; b < blockCount(); ++b)
  {
    const std::array<int, 3>& n = P->Topo.blocks[b].nodes;
    P->Nodes[b].resize(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    meshBlockNodes(P->Model, P->Topo, b, P->Nodes[b].data());
    P->Updated.push_back(b);
  }
}

MeshPlan::~MeshPlan() = default;

BlockModel& MeshPlan::model()
{
  return P->Model;
}

const BlockModel& MeshPlan::model() const
{
  return P->Model;
}

const CarrierGeometry& MeshPlan::carriers() const
{
  return P->Geometry;
}

CarrierGeometry& MeshPlan::carriers()
{
  return P->Geometry;
}

const Topology& MeshPlan::topology() const
{
  return P->Topo.connectivity;
}

const std::vector<int>& MeshPlan::updatedBlocks() const
{
  return P->Updated;
}

int MeshPlan::blockCount() const
{
  return static_cast<int>(P->Model.blocks.size());
}

std::array<int, 3> MeshPlan::nodeCounts(int block) const
{
  return P->Topo.blocks.at(block).nodes;
}

const std::vector<double>& MeshPlan::blockNodes(int block) const
{
  return P->Nodes.at(block);
}

/// The update itself; throws TemplateError or GeometryError like the mesher would.
void MeshPlan::Impl::run(const std::vector<int>& moved)
{
  BlockModel& model = Model;
  const double size = modelSize(model);
  std::vector<char> movedVertex(model.vertices.size(), 0);
  for (const int v : moved)
  {
    movedVertex.at(v) = 1;
  }
  checkCarriers(model, Geometry, size, &moved);
  std::vector<char> changedCarrier(model.carriers.size(), 0);
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    changedCarrier[c] = shape(static_cast<int>(c)) != CarrierShapes[c] ? 1 : 0;
  }
  if (std::find(changedCarrier.begin(), changedCarrier.end(), 1) != changedCarrier.end())
  {
    Projections.clear(changedCarrier); // it remembers projections onto the old shapes
  }

  // Named edge curves: those ending at a moved vertex, those on a carrier drawn again,
  // and those following a rebuilt one (a follow or periodic edge comes after its source).
  std::vector<char> rebuilt(model.edges.size(), 0);
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    const int carrier = model.edges[e].carrier;
    const bool onChanged = carrier >= 0 && carrier < static_cast<int>(changedCarrier.size()) &&
      changedCarrier[carrier];
    rebuilt[e] = onChanged || model.edges[e].at != EdgeEnds[e] ? 1 : 0;
  }
  for (const int v : moved)
  {
    for (const int e : VertexNamedEdges[v])
    {
      rebuilt[e] = 1;
    }
  }
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    if (!rebuilt[e])
    {
      continue;
    }
    for (const int follower : NamedFollowers[e])
    {
      rebuilt[follower] = 1;
    }
    Before.curveIndices.push_back(static_cast<int>(e));
    Before.curves.push_back(Curves[e]);
    try
    {
      followEdgeEnds(model, Geometry, static_cast<int>(e), movedVertex);
      Curves[e] = buildNamedCurve(
        model, Geometry, Curves, static_cast<int>(e), FollowedEdges[e] != 0, size);
    }
    catch (const GeometryError& error)
    {
      fail(model.edges[e].where, syntax::entity("edge", model.edges[e].name), error.what());
    }
  }

  // Shared edges: node parameters (the length may change them) and nodes.
  std::vector<char> changedEdge(Topo.edges.size(), 0);
  for (const int v : moved)
  {
    for (const int u : VertexUniqueEdges[v])
    {
      changedEdge[u] = 1;
    }
  }
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    if (rebuilt[e] && NamedUnique[e] >= 0)
    {
      changedEdge[NamedUnique[e]] = 1;
    }
  }
  std::vector<int> blocks;
  for (std::size_t u = 0; u < Topo.edges.size(); ++u)
  {
    if (!changedEdge[u])
    {
      continue;
    }
    UniqueEdge& edge = Topo.edges[u];
    edge.length = edge.named >= 0
      ? Curves[edge.named].length
      : (model.vertices[edge.b].position - model.vertices[edge.a].position).norm();
  }
  // matched edges follow the graded edges and the lengths at their ends, projected edges
  // the edges they project from
  computeEdgeGrading(model, Curves, Geometry, Topo, &changedEdge, AllowFallback);
  std::vector<int> nodeEdges;
  for (std::size_t u = 0; u < Topo.edges.size(); ++u)
  {
    if (!changedEdge[u])
    {
      continue;
    }
    nodeEdges.push_back(static_cast<int>(u));
    for (const int b : EdgeBlocks[u])
    {
      addUnique(blocks, b);
    }
  }
  // The nodes of each edge depend on its own curve and parameters alone: on threads when
  // a runner is installed (Core/Parallel.h), the same bits, the first failing edge's error.
  forEachChunk(static_cast<long>(nodeEdges.size()), [&](long n) {
    computeEdgeNodes(model, Curves, Geometry, Topo.edges[nodeEdges[n]]);
  });
  for (const int b : blocks)
  {
    computeCollapsedParameters(model, Topo, b);
  }

  // Periodic copies of changed edges (their pairing checked again: vertices moved).
  findPeriodicPairs(model, Topo.connectivity);
  for (const EdgeCopy& copy : Copies)
  {
    if (changedEdge[copy.source] || changedEdge[copy.image])
    {
      copyPeriodicEdge(model, Topo, copy);
      changedEdge[copy.image] = 1;
      for (const int b : EdgeBlocks[copy.image])
      {
        addUnique(blocks, b);
      }
    }
  }

  // Faces with a changed edge, then the periodic images of changed faces.
  std::vector<char> changedFace(Topo.faces.size(), 0);
  for (std::size_t u = 0; u < Topo.edges.size(); ++u)
  {
    if (changedEdge[u])
    {
      for (const int f : EdgeFaces[u])
      {
        changedFace[f] = 1;
      }
    }
  }
  for (const auto& onSurface : OnSurface)
  {
    if (changedCarrier[onSurface.second])
    {
      changedFace[onSurface.first] = 1;
    }
  }
  // The nodes of a face on a surface are placed on threads inside (surfaceFace), which
  // balances better than whole faces of unequal cost.
  for (std::size_t f = 0; f < Topo.faces.size(); ++f)
  {
    if (changedFace[f] && !IsImage[f] && Topo.faces[f].opposite < 0)
    {
      saveFace(static_cast<int>(f));
      computeFaceGrid(model, Geometry, OnSurface, Topo, static_cast<int>(f), &Projections);
    }
  }
  // The periodic images of those, then the faces that follow the face opposite them (after
  // it, also when only it changed; it may be an image), then the images of these.
  const auto copyImages = [&](bool ofFollowingFaces) {
    for (const PeriodicPair& pair : Topo.connectivity.periodic)
    {
      if ((changedFace[pair.source] || changedFace[pair.image]) &&
        (Topo.faces[pair.source].opposite >= 0) == ofFollowingFaces)
      {
        changedFace[pair.image] = 1;
        saveFace(pair.image);
        periodicFace(model, Topo, pair, Topo.faces[pair.image].xyz);
      }
    }
  };
  copyImages(false);
  for (std::size_t f = 0; f < Topo.faces.size(); ++f)
  {
    const int opposite = Topo.faces[f].opposite;
    if (opposite >= 0 && (changedFace[f] || changedFace[opposite]) && !IsImage[f])
    {
      changedFace[f] = 1;
      saveFace(static_cast<int>(f));
      computeFaceGrid(model, Geometry, OnSurface, Topo, static_cast<int>(f), &Projections);
    }
  }
  copyImages(true);
  for (std::size_t f = 0; f < Topo.faces.size(); ++f)
  {
    if (changedFace[f])
    {
      for (const int b : FaceBlocks[f])
      {
        addUnique(blocks, b);
      }
    }
  }
  for (const int v : moved)
  {
    for (const int b : VertexBlocks[v])
    {
      addUnique(blocks, b);
    }
  }
  std::sort(blocks.begin(), blocks.end());
  Updated = blocks;
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    CarrierShapes[c] = shape(static_cast<int>(c));
  }
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    EdgeEnds[e] = model.edges[e].at;
  }
}

Feasibility MeshPlan::update(const std::vector<int>& moved)
{
  std::vector<int> vertices = P->Pending;
  for (const int v : moved)
  {
    if (v < 0 || v >= static_cast<int>(P->Model.vertices.size()))
    {
      return infeasible(Feasibility::Problem::ModelError, -1,
        "MeshPlan::update: no vertex " + std::to_string(v));
    }
    addUnique(vertices, v);
  }
  P->save(vertices);
  P->Pending = vertices;
  P->Updated.clear();
  try
  {
    P->run(vertices);
  }
  catch (const std::exception& error)
  {
    return infeasible(Feasibility::Problem::ModelError, -1, error.what());
  }
  const double size = modelSize(P->Model);
  for (const int b : P->Updated)
  {
    try
    {
      const std::vector<int> one = { b };
      checkOrientation(P->Model, P->Curves, size, &one);
      checkCornerCells(P->Model, P->Topo, b, size);
    }
    catch (const TemplateError& error)
    {
      return infeasible(Feasibility::Problem::FoldedCorner, b, error.what());
    }
  }
  P->Pending.clear();
  // Blocks are meshed and checked each on its own (on threads when a runner is
  // installed); the first infeasible block in block order is the one reported.
  std::vector<Feasibility> cells(P->Updated.size());
  P->Before.nodeIndices = P->Updated;
  forEachChunk(static_cast<long>(P->Updated.size()), [&](long n) {
    const int b = P->Updated[n];
    P->Before.nodes[b] = P->Nodes[b];
    meshBlockNodes(P->Model, P->Topo, b, P->Nodes[b].data());
    cells[n] = checkCells(P->Nodes[b].data(), P->Topo.blocks[b].nodes, b);
  });
  for (const Feasibility& block : cells)
  {
    if (!block.feasible())
    {
      return block;
    }
  }
  return Feasibility();
}

void MeshPlan::Impl::save(const std::vector<int>& vertices)
{
  Saved& saved = Before;
  saved.valid = true;
  saved.vertices.clear();
  for (const int v : vertices)
  {
    saved.vertices.emplace_back(v, CommittedVertices[v]);
    CommittedVertices[v] = Model.vertices[v];
  }
  saved.carriers.clear();
  bool carriersChanged = false;
  for (std::size_t c = 0; c < Model.carriers.size(); ++c)
  {
    if (shape(static_cast<int>(c)) != CarrierShapes[c])
    {
      carriersChanged = true;
      saved.carriers.emplace_back(static_cast<int>(c), CommittedCarriers[c]);
      CommittedCarriers[c] = Model.carriers[c];
    }
  }
  saved.geometry = CommittedGeometry;
  if (carriersChanged)
  {
    CommittedGeometry = Geometry;
  }
  saved.edgeEnds = EdgeEnds;
  saved.carrierShapes = CarrierShapes;
  saved.curveIndices.clear();
  saved.curves.clear();
  saved.edges = Topo.edges;
  saved.blocks = Topo.blocks;
  saved.periodic = Topo.connectivity.periodic;
  saved.faceIndices.clear();
  saved.nodeIndices.clear();
  saved.updated = Updated;
  saved.pending = Pending;
}

bool MeshPlan::undo()
{
  Impl::Saved& saved = P->Before;
  if (!saved.valid)
  {
    return false;
  }
  saved.valid = false;
  // The projections cache remembers projections onto the shapes the update drew
  std::vector<char> redrawn(P->Model.carriers.size(), 0);
  for (const auto& carrier : saved.carriers)
  {
    redrawn[carrier.first] = 1;
  }
  for (auto& vertex : saved.vertices)
  {
    P->CommittedVertices[vertex.first] = vertex.second;
    P->Model.vertices[vertex.first] = std::move(vertex.second);
  }
  for (auto& carrier : saved.carriers)
  {
    P->CommittedCarriers[carrier.first] = carrier.second;
    P->Model.carriers[carrier.first] = std::move(carrier.second);
  }
  P->CommittedGeometry = saved.geometry;
  P->Geometry = std::move(saved.geometry);
  for (std::size_t c = 0; c < P->Model.carriers.size(); ++c)
  {
    redrawn[c] = redrawn[c] || P->shape(static_cast<int>(c)) != P->CarrierShapes[c] ? 1 : 0;
  }
  if (std::find(redrawn.begin(), redrawn.end(), 1) != redrawn.end())
  {
    P->Projections.clear(redrawn);
  }
  for (std::size_t e = 0; e < P->Model.edges.size(); ++e)
  {
    P->Model.edges[e].at = saved.edgeEnds[e];
  }
  std::swap(P->EdgeEnds, saved.edgeEnds);
  std::swap(P->CarrierShapes, saved.carrierShapes);
  for (std::size_t n = 0; n < saved.curveIndices.size(); ++n)
  {
    P->Curves[saved.curveIndices[n]] = std::move(saved.curves[n]);
  }
  std::swap(P->Topo.edges, saved.edges);
  std::swap(P->Topo.blocks, saved.blocks);
  std::swap(P->Topo.connectivity.periodic, saved.periodic);
  for (const int f : saved.faceIndices)
  {
    std::swap(P->Topo.faces[f].xyz, saved.faces[f]);
  }
  for (const int b : saved.nodeIndices)
  {
    std::swap(P->Nodes[b], saved.nodes[b]);
  }
  P->Updated = saved.nodeIndices;
  std::sort(P->Updated.begin(), P->Updated.end());
  P->Pending = saved.pending;
  return true;
}

void MeshPlan::rebuildCarrier(int index)
{
  P->Geometry.rebuild(P->Model, index);
}

Feasibility checkCells(const double* xyz, const std::array<int, 3>& nodes, int block)
{
  const InvertedCells inverted = findInvertedCells(xyz, nodes[0], nodes[1], nodes[2]);
  if (inverted.count == 0)
  {
    return Feasibility();
  }
  const std::array<int, 3>& c = inverted.worstCell;
  return infeasible(Feasibility::Problem::InvertedCell, block,
    std::to_string(inverted.count) + " inverted cell(s) in block " + std::to_string(block) +
      ", the worst (" + std::to_string(c[0]) + ", " + std::to_string(c[1]) + ", " +
      std::to_string(c[2]) + ") with scaled Jacobian " +
      syntax::shortNumber(inverted.worstScaledJacobian));
}
} // namespace model
} // namespace blockforge
