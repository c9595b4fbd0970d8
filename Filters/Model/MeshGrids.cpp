#include "MeshInternals.h"

#include "../Core/Carriers.h"
#include "../Core/Parallel.h"
#include "../Core/Projection.h"
#include "../Core/SurfaceFaceGrid.h"
#include "../Core/Transfinite.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace blockforge
{
namespace model
{
using syntax::entity;
using syntax::formatNumber;
using syntax::shortNumber;

// -------------------------------------------------------------------- mesh topology

std::array<int, 3> scaledNodeCounts(const Block& block, double multiplier, int cap)
{
  std::array<int, 3> nodes{};
  for (int d = 0; d < 3; ++d)
  {
    // validated by checkDensityMultiplier: at most MaxScaledCellsPerDirection. A coarser
    // grid keeps at least the block's min_cells (at most its cells), so that the graded
    // laws still have the cells to grow from small matched end cells
    const double scaled = std::round(block.cells[d] * multiplier);
    const int floor = std::max(1, std::min(block.cells[d], block.minCells[d]));
    int cells = static_cast<int>(std::max(static_cast<double>(floor), scaled));
    if (cap > 0)
    {
      cells = std::min(cells, cap);
    }
    nodes[d] = cells + 1;
  }
  return nodes;
}

/**
 * The topology of the model for the given node counts (buildConnectivity's checks) with
 * the node parameters of every edge, checked on shared edges: the same laws must put the
 * nodes at the same places.
 */
MeshTopology buildMeshTopology(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& curves, const std::vector<std::array<int, 3>>& nodes,
  bool allowFallback)
{
  MeshTopology topology;
  topology.connectivity = buildConnectivity(model, nodes);
  for (const TopologyEdge& edge : topology.connectivity.edges)
  {
    UniqueEdge unique;
    static_cast<TopologyEdge&>(unique) = edge;
    unique.length = edge.named >= 0
      ? curves[edge.named].length
      : (model.vertices[edge.b].position - model.vertices[edge.a].position).norm();
    topology.edges.push_back(std::move(unique));
  }
  for (const TopologyFace& face : topology.connectivity.faces)
  {
    UniqueFace unique;
    static_cast<TopologyFace&>(unique) = face;
    topology.faces.push_back(std::move(unique));
  }
  for (const BlockLinks& links : topology.connectivity.blocks)
  {
    MeshLinks mesh;
    static_cast<BlockLinks&>(mesh) = links;
    topology.blocks.push_back(std::move(mesh));
  }
  // faces that follow the face opposite them in their block (made after it)
  for (const SurfaceFaces& set : model.surfaceFaces)
  {
    if (!set.followOpposite)
    {
      continue;
    }
    for (const BlockFace& named : set.faces)
    {
      const MeshLinks& links = topology.blocks[named.block];
      const int unique = links.face[named.face];
      const int opposite = links.face[named.face ^ 1];
      if (unique < 0 || opposite < 0)
      {
        fail(set.where, "face set '" + set.name + "'",
          "face " + blockFaceText(model, named.block, named.face) +
            " or the face opposite it is collapsed: a following face needs both");
      }
      topology.faces[unique].follows = named;
      topology.faces[unique].opposite = opposite;
    }
  }
  for (const UniqueFace& face : topology.faces)
  {
    if (face.opposite >= 0 && topology.faces[face.opposite].opposite >= 0)
    {
      fail(model.blocks[face.follows.block].where, blockEntity(model, face.follows.block),
        "face " + blockFaceText(model, face.follows.block, face.follows.face) +
          " follows a face that follows another: the face a following face follows must lie on a "
          "surface or come from its edges");
    }
  }
  // graded edges first: matched edges take their end cells from them, projected edges
  // their nodes
  buildMatchGroups(model, topology);
  buildProjections(model, topology);
  computeEdgeGrading(model, curves, geometry, topology, nullptr, allowFallback);
  for (int b = 0; b < static_cast<int>(model.blocks.size()); ++b)
  {
    computeCollapsedParameters(model, topology, b);
  }
  return topology;
}

/// Node parameters: the first block's law defines the edge; every other block must give
/// the same parameters, compared in the edge's canonical direction.
void computeEdgeParameters(const BlockModel& model, MeshTopology& topology, int e, bool allowFallback)
{
  UniqueEdge& edge = topology.edges[e];
  edge.params.clear();
  if (edge.matched)
  {
    for (const EdgeUse& use : edge.uses)
    {
      const Block& block = model.blocks[use.block];
      const DistributionLaw& law = block.laws[use.localEdge];
      if (law.kind != DistributionLaw::Kind::Match || law.expansionRatio != edge.matchRatio ||
        law.matchFlatness != edge.matchFlatness)
      {
        const std::array<int, 2> ends = edgeVertices(use.localEdge);
        fail(block.where, blockEntity(model, use.block),
          "edge " + edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) + " (" +
            syntax::edgeLabel(use.localEdge) + ") is matched to its neighbours in another "
            "block that uses it: give it the same law 'match' (with the same ratio and flat) here");
      }
    }
    try
    {
      edge.params = matchedNodes(
        edge.matchFirst, edge.matchLast, edge.length, edge.nodeCount, edge.matchRatio,
        edge.matchFlatness);
    }
    catch (const GeometryError& error)
    {
      const EdgeUse& use = edge.uses.front();
      const Block& block = model.blocks[use.block];
      const std::array<int, 2> ends = edgeVertices(use.localEdge);
      fail(block.where, blockEntity(model, use.block),
        "grading of edge " + edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) +
          " (" + syntax::edgeLabel(use.localEdge) + "): " + error.what());
    }
    return;
  }
  for (const EdgeUse& use : edge.uses)
  {
    const Block& block = model.blocks[use.block];
    std::vector<double> params;
    try
    {
      params = lawParameters(refinedLaw(block.laws[use.localEdge],
                               block.cells[edgeDirection(use.localEdge)], edge.nodeCount - 1),
        edge.nodeCount, edge.length, allowFallback);
    }
    catch (const GeometryError& error)
    {
      const std::array<int, 2> ends = edgeVertices(use.localEdge);
      fail(block.where, blockEntity(model, use.block),
        "grading of edge " + edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) +
          " (" + syntax::edgeLabel(use.localEdge) + "): " + error.what());
    }
    if (use.reversed)
    {
      params = reversedParameters(params);
    }
    if (edge.params.empty())
    {
      edge.params = std::move(params);
      continue;
    }
    double difference = 0.0;
    for (std::size_t i = 0; i < params.size(); ++i)
    {
      difference = std::max(difference, std::abs(params[i] - edge.params[i]));
    }
    if (difference > 1e-12)
    {
      const EdgeUse& first = edge.uses.front();
      const std::array<int, 2> ends = edgeVertices(use.localEdge);
      fail(block.where, blockEntity(model, use.block),
        "the grading of edge " +
          edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) + " (" +
          syntax::edgeLabel(use.localEdge) + ") puts its nodes differently from block '" +
          model.blocks[first.block].name + "' (" + syntax::edgeLabel(first.localEdge) +
          "), by up to " + shortNumber(difference) +
          " of the edge length; give both blocks the same law along this edge (a reversed "
          "direction needs the inverse ratio)");
    }
  }
}

/// Collapsed edges carry no geometry, but their parameters still steer the blending
/// inside the block: take the block's law over the length of the longest parallel edge.
void computeCollapsedParameters(const BlockModel& model, MeshTopology& topology, int b)
{
  MeshLinks& links = topology.blocks[b];
  for (int e = 0; e < 12; ++e)
  {
    if (links.edge[e] >= 0)
    {
      continue;
    }
    double length = 0.0;
    for (int other = 0; other < 12; ++other)
    {
      if (edgeDirection(other) == edgeDirection(e) && links.edge[other] >= 0)
      {
        length = std::max(length, topology.edges[links.edge[other]].length);
      }
    }
    links.collapsedParams[e] = lawParameters(
      refinedLaw(model.blocks[b].laws[e], model.blocks[b].cells[edgeDirection(e)],
        links.nodes[edgeDirection(e)] - 1),
      links.nodes[edgeDirection(e)], length > 0.0 ? length : 1.0, true);
  }
}

// -------------------------------------------------------------------- grids

LocalEdge localEdge(
  const BlockModel& model, const MeshTopology& topology, int block, int localEdgeIndex)
{
  const MeshLinks& links = topology.blocks[block];
  LocalEdge local;
  local.count = links.nodes[edgeDirection(localEdgeIndex)];
  const int unique = links.edge[localEdgeIndex];
  if (unique < 0)
  {
    const Vec3& point =
      model.vertices[model.blocks[block].vertices[edgeVertices(localEdgeIndex)[0]]].position;
    local.xyzStorage.resize(3 * local.count);
    for (int i = 0; i < local.count; ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        local.xyzStorage[3 * i + c] = point[c];
      }
    }
    local.borrowedParams = links.collapsedParams[localEdgeIndex].data();
    return local;
  }
  const UniqueEdge& edge = topology.edges[unique];
  if (!links.reversed[localEdgeIndex])
  {
    local.borrowedXyz = edge.xyz.data();
    local.borrowedParams = edge.params.data();
    return local;
  }
  local.xyzStorage.resize(3 * local.count);
  for (int i = 0; i < local.count; ++i)
  {
    std::copy_n(&edge.xyz[3 * (local.count - 1 - i)], 3, &local.xyzStorage[3 * i]);
  }
  local.paramStorage = reversedParameters(edge.params);
  return local;
}

/**
 * The first cells at every block corner must not be inverted: the first nodes of the three
 * edges leaving a corner (in +i, +j, +k: towards the corner from the far side) form a
 * right-handed frame. This is the real shape of the corner cells, whatever the curvature
 * of the edges; corners where an edge is collapsed (wedges) are skipped.
 */
void checkCornerCells(const BlockModel& model, const MeshTopology& topology, double size)
{
  for (int b = 0; b < static_cast<int>(model.blocks.size()); ++b)
  {
    checkCornerCells(model, topology, b, size);
  }
}

void checkCornerCells(const BlockModel& model, const MeshTopology& topology, int b, double size)
{
  {
    std::array<std::array<Vec3, 3>, 8> frame{};
    for (int e = 0; e < 12; ++e)
    {
      const LocalEdge edge = localEdge(model, topology, b, e);
      const double* xyz = edge.xyz();
      const int n = edge.count;
      const std::array<int, 2> ends = edgeVertices(e);
      auto node = [&](int i) { return Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]); };
      frame[ends[0]][edgeDirection(e)] = node(1) - node(0);
      frame[ends[1]][edgeDirection(e)] = node(n - 1) - node(n - 2);
    }
    for (int v = 0; v < 8; ++v)
    {
      const Vec3 &ds = frame[v][0], &dt = frame[v][1], &du = frame[v][2];
      const double scale = ds.norm() * dt.norm() * du.norm();
      if (ds.norm() <= 1e-12 * size || dt.norm() <= 1e-12 * size || du.norm() <= 1e-12 * size)
      {
        continue;
      }
      if (ds.dot(dt.cross(du)) < -1e-10 * scale)
      {
        const Block& block = model.blocks[b];
        throw FoldError(block.where.file, block.where.line, blockEntity(model, b),
          "the block folds at V" + std::to_string(v) + " (vertex '" +
            model.vertices[block.vertices[v]].name +
            "'): the edges leaving it form a left-handed frame, so its corner cells are "
            "inverted; move the vertices or change the edges' shapes");
      }
    }
  }
}

/// The blending of the face's two directions (the block's, Transfinite.h).
static std::array<Blending, 2> faceBlending(const BlockModel& model, int block, int face)
{
  const std::array<int, 2> directions = faceDirections(face);
  const auto& blending = model.blocks[block].blending;
  return { blending[directions[0]], blending[directions[1]] };
}

/// Face grid of `face` of `block` in the block's own orientation, from its four edges.
void faceFromEdges(const BlockModel& model, const MeshTopology& topology, int block, int face,
  std::vector<double>& out)
{
  const std::array<int, 4> edges = faceEdges(face);
  const LocalEdge bottom = localEdge(model, topology, block, edges[0]);
  const LocalEdge top = localEdge(model, topology, block, edges[1]);
  const LocalEdge left = localEdge(model, topology, block, edges[2]);
  const LocalEdge right = localEdge(model, topology, block, edges[3]);
  out.resize(3 * static_cast<std::size_t>(bottom.count) * left.count);
  transfiniteFace(bottom.nodes(), top.nodes(), left.nodes(), right.nodes(), out.data(),
    faceBlending(model, block, face));
}

void computeEdgeNodes(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, UniqueEdge& edge)
{
  const int n = edge.nodeCount;
  edge.xyz.resize(3 * n);
  if (edge.named >= 0 && model.edges[edge.named].kind == Edge::Kind::Periodic)
  {
    return; // rotated from its source edge afterwards
  }
  for (int i = 0; i < n; ++i)
  {
    const Vec3 point = edgeNodePoint(model, curves, geometry, edge, i);
    for (int c = 0; c < 3; ++c)
    {
      edge.xyz[3 * i + c] = point[c];
    }
  }
}

Vec3 edgeNodePoint(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, const UniqueEdge& edge, int i)
{
  const Vec3& start = model.vertices[edge.a].position;
  const Vec3& end = model.vertices[edge.b].position;
  if (i == 0)
  {
    return start; // end nodes are the vertices themselves, bit for bit
  }
  if (i == edge.nodeCount - 1)
  {
    return end;
  }
  const NamedCurve* named = edge.named >= 0 ? &curves[edge.named] : nullptr;
  if (!named || model.edges[edge.named].kind == Edge::Kind::Line ||
    model.edges[edge.named].kind == Edge::Kind::Project)
  {
    Vec3 point = (1.0 - edge.params[i]) * start + edge.params[i] * end;
    if (named && named->projectOnto >= 0)
    {
      double s = 0.0, t = 0.0, distance = 0.0;
      geometry.project(named->projectOnto, point, s, t, distance);
      point = geometry.point(named->projectOnto, s, t);
    }
    return point;
  }
  // The named edge may run b -> a; its curve is evaluated at the mirrored fraction.
  const bool curveReversed = model.edges[edge.named].from != edge.a;
  const double fraction = curveReversed ? 1.0 - edge.params[i] : edge.params[i];
  const double t =
    named->lengthTable ? named->lengthTable->parameterAtFraction(fraction) : fraction;
  return named->curve->point(t);
}

std::map<std::pair<int, int>, int> edgeLookup(const MeshTopology& topology)
{
  std::map<std::pair<int, int>, int> lookup;
  for (std::size_t e = 0; e < topology.edges.size(); ++e)
  {
    lookup.emplace(std::make_pair(topology.edges[e].a, topology.edges[e].b), static_cast<int>(e));
  }
  return lookup;
}

int findUniqueEdge(const std::map<std::pair<int, int>, int>& lookup, int a, int b)
{
  const auto found = lookup.find(std::make_pair(std::min(a, b), std::max(a, b)));
  return found == lookup.end() ? -1 : found->second;
}

/**
 * Makes unique edge `image` (running imageFrom -> imageTo) the rotation of unique edge
 * `source` (running sourceFrom -> sourceTo): interior nodes rotated, end nodes the vertices
 * themselves. The node parameters of both must agree (the same grading).
 */
void rotateEdgeNodes(const BlockModel& model, MeshTopology& topology, int source, int sourceFrom,
  int image, int imageFrom, const Vec3& axisPoint, const Vec3& axis, double angle,
  const SourceLocation& where, const std::string& entityText)
{
  const UniqueEdge& from = topology.edges[source];
  UniqueEdge& to = topology.edges[image];
  const int n = to.nodeCount;
  if (from.nodeCount != n)
  {
    fail(where, entityText,
      "edge " + edgeText(model, to.a, to.b) + " has " + std::to_string(n - 1) +
        " cells but its periodic source " + edgeText(model, from.a, from.b) + " has " +
        std::to_string(from.nodeCount - 1));
  }
  const bool sourceForward = sourceFrom == from.a;
  const bool imageForward = imageFrom == to.a;
  // A matched edge's nodes follow its length and neighbours: its image, whose length may
  // differ (a straight chord of a source on a surface), takes the source's.
  const bool copyParams = to.matched && from.matched;
  double difference = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const int along = imageForward ? i : n - 1 - i; // index along imageFrom -> imageTo
    const int sourceIndex = sourceForward ? along : n - 1 - along;
    const double sourceParam =
      sourceForward ? from.params[sourceIndex] : 1.0 - from.params[sourceIndex];
    if (copyParams)
    {
      to.params[i] = imageForward ? sourceParam : 1.0 - sourceParam;
    }
    const double imageParam = imageForward ? to.params[i] : 1.0 - to.params[i];
    difference = std::max(difference, std::abs(sourceParam - imageParam));
    if (i == 0 || i == n - 1)
    {
      const Vec3& vertex = model.vertices[i == 0 ? to.a : to.b].position;
      std::copy_n(vertex.data(), 3, &to.xyz[3 * i]);
      continue;
    }
    const Vec3 p(from.xyz[3 * sourceIndex], from.xyz[3 * sourceIndex + 1], from.xyz[3 * sourceIndex + 2]);
    const Vec3 q = rotateAboutAxis(p, axisPoint, axis, angle);
    std::copy_n(q.data(), 3, &to.xyz[3 * i]);
  }
  if (difference > 1e-12)
  {
    fail(where, entityText,
      "edge " + edgeText(model, to.a, to.b) + " places its nodes differently from its periodic "
      "source " + edgeText(model, from.a, from.b) + " (by up to " + shortNumber(difference) +
        " of the edge length); give both the same grading");
  }
}

std::vector<EdgeCopy> periodicEdgeCopies(const BlockModel& model, const MeshTopology& topology)
{
  std::vector<EdgeCopy> copies;
  const auto lookup = edgeLookup(topology);
  // Named periodic edges: rotated copies of their source edges.
  for (std::size_t e = 0; e < topology.edges.size(); ++e)
  {
    const UniqueEdge& edge = topology.edges[e];
    if (edge.named < 0 || model.edges[edge.named].kind != Edge::Kind::Periodic)
    {
      continue;
    }
    const Edge& named = model.edges[edge.named];
    const Edge& source = model.edges[named.source];
    const int sourceEdge = findUniqueEdge(lookup, source.from, source.to);
    if (sourceEdge < 0)
    {
      fail(named.where, entity("edge", named.name),
        "its source edge '" + source.name + "' is not an edge of any block");
    }
    copies.push_back(EdgeCopy{ sourceEdge, source.from, static_cast<int>(e), named.from,
      model.machine.axisPoint, model.machine.axis, named.pitches * model.machine.pitch(),
      named.where, entity("edge", named.name) });
  }
  // The edges of every periodic image face: rotations of the source face's edges.
  for (const PeriodicPair& entry : topology.connectivity.periodic)
  {
    const UniqueFace& from = topology.faces[entry.source];
    const UniqueFace& to = topology.faces[entry.image];
    for (int k = 0; k < 4; ++k)
    {
      const int g0 = to.ownerIds[k], g1 = to.ownerIds[(k + 1) % 4];
      const int f0 = from.ownerIds[entry.transform.mapCorner(k)];
      const int f1 = from.ownerIds[entry.transform.mapCorner((k + 1) % 4)];
      if (g0 == g1 || f0 == f1)
      {
        continue; // collapsed
      }
      const int image = findUniqueEdge(lookup, g0, g1);
      const int source = findUniqueEdge(lookup, f0, f1);
      if (image < 0 || source < 0 || image == source)
      {
        continue;
      }
      const Patch& patch = model.patches[entry.patch];
      copies.push_back(EdgeCopy{ source, f0, image, g0, entry.axisPoint, entry.axis, entry.angle,
        patch.where, entity("patch", patch.name) });
    }
  }
  return copies;
}

void copyPeriodicEdge(const BlockModel& model, MeshTopology& topology, const EdgeCopy& copy)
{
  rotateEdgeNodes(model, topology, copy.source, copy.sourceFrom, copy.image, copy.imageFrom,
    copy.axisPoint, copy.axis, copy.angle, copy.where, copy.entity);
}

/// Copies the boundary nodes of a face grid from its block's edges (bit for bit).
void copyFaceBoundary(const BlockModel& model, const MeshTopology& topology, int block, int face,
  int na, int nb, std::vector<double>& grid);

/// The carrier's projection of p, remembered by p's bits.
void ProjectionCache::project(
  const CarrierGeometry& geometry, int carrier, const Vec3& p, double& s, double& t, double* distance)
{
  Key key{ carrier, {} };
  std::memcpy(key.bits.data(), p.data(), sizeof(key.bits));
  const std::size_t slot = carrier < 0 ? 0 : static_cast<std::size_t>(carrier) + 1;
  {
    std::lock_guard<std::mutex> guard(Lock);
    if (slot >= Known.size())
    {
      Known.resize(slot + 1);
    }
    const auto found = Known[slot].find(key);
    if (found != Known[slot].end())
    {
      s = found->second[0];
      t = found->second[1];
      if (distance)
      {
        *distance = found->second[2];
      }
      return;
    }
  }
  double away = 0.0;
  geometry.project(carrier, p, s, t, away);
  if (distance)
  {
    *distance = away;
  }
  std::lock_guard<std::mutex> guard(Lock);
  if (Count > 1000000)
  {
    // bounded: a long optimisation must not grow it without end
    Known.clear();
    Known.resize(slot + 1);
    Count = 0;
  }
  Count += Known[slot].emplace(key, std::array<double, 3>{ s, t, away }).second ? 1 : 0;
}

void ProjectionCache::clear()
{
  std::lock_guard<std::mutex> guard(Lock);
  Known.clear();
  Count = 0;
}

void ProjectionCache::clear(const std::vector<char>& changed)
{
  std::lock_guard<std::mutex> guard(Lock);
  for (std::size_t slot = 0; slot < Known.size(); ++slot)
  {
    const bool stale = slot == 0 || slot > changed.size() || changed[slot - 1];
    if (stale && !Known[slot].empty())
    {
      Count -= Known[slot].size();
      Known[slot] = Projections();
    }
  }
}

std::size_t ProjectionCache::KeyHash::operator()(const Key& key) const
{
  std::uint64_t h = static_cast<std::uint64_t>(key.carrier) * 0x9E3779B97F4A7C15ull;
  for (const std::uint64_t b : key.bits)
  {
    h ^= b + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  }
  return static_cast<std::size_t>(h);
}

namespace
{
/// A surface carrier seen through its parameters (wrapping, extending as the carrier does).
class CarrierSurface final : public ParametricSurface
{
public:
  CarrierSurface(const CarrierGeometry& geometry, int carrier)
    : Geometry(geometry)
    , Carrier(carrier)
  {
  }
  Vec3 point(double s, double t) const override { return Geometry.point(Carrier, s, t); }
  void crossPoints(double s, double t, double h, Vec3 out[5]) const override
  {
    Geometry.crossPoints(Carrier, s, t, h, out);
  }
  double tMin() const override { return Geometry.tMin(Carrier); }
  double tMax() const override { return Geometry.tMax(Carrier); }

private:
  const CarrierGeometry& Geometry;
  int Carrier;
};
} // namespace

/// Grid of a face that lies on a surface (surfaceFaceGrid): the boundary nodes' (s, t),
/// then the interior nodes by projected TFI guarded by the even-metric parameter TFI.
void surfaceFace(const BlockModel& model, const MeshTopology& topology, const CarrierGeometry& geometry,
  int carrier, int block, int face, std::vector<double>& out, ProjectionCache* cache)
{
  const std::array<int, 4> edges = faceEdges(face);
  const LocalEdge bottom = localEdge(model, topology, block, edges[0]);
  const LocalEdge top = localEdge(model, topology, block, edges[1]);
  const LocalEdge left = localEdge(model, topology, block, edges[2]);
  const LocalEdge right = localEdge(model, topology, block, edges[3]);
  const int na = bottom.count, nb = left.count;
  const CarrierSurface surface(geometry, carrier);
  // The boundary loop: bottom (a up), right (b up), top (a down), left (b down).
  std::vector<Vec3> loop;
  auto node = [](const LocalEdge& edge, int i) {
    const double* p = edge.xyz() + 3 * i;
    return Vec3(p[0], p[1], p[2]);
  };
  for (int a = 0; a < na; ++a)
    loop.push_back(node(bottom, a));
  for (int b = 1; b < nb; ++b)
    loop.push_back(node(right, b));
  for (int a = na - 2; a >= 0; --a)
    loop.push_back(node(top, a));
  for (int b = nb - 2; b >= 1; --b)
    loop.push_back(node(left, b));
  const int loopSize = static_cast<int>(loop.size());
  std::vector<Eigen::Vector2d> st(loopSize);
  std::vector<double> away(loopSize, 0.0);
  // Each node is projected, and below each interior node placed, on its own: in chunks
  // on threads when a runner is installed (a face computed inside another chunked loop
  // runs in that loop's thread), the same bits.
  const long loopChunks = std::min<long>(loopSize, 16);
  forEachChunk(loopChunks, [&](long chunk) {
    const int first = static_cast<int>(chunk * loopSize / loopChunks);
    const int last = static_cast<int>((chunk + 1) * loopSize / loopChunks);
    for (int k = first; k < last; ++k)
    {
      double s = 0.0, t = 0.0;
      if (cache)
      {
        cache->project(geometry, carrier, loop[k], s, t, &away[k]);
      }
      else
      {
        geometry.project(carrier, loop[k], s, t, away[k]);
      }
      st[k] = Eigen::Vector2d(s, t);
    }
  });
  // Unwrap across the seam of closed directions.
  const bool closed[2] = { geometry.closedS(carrier), geometry.closedT(carrier) };
  auto unwrap = [&](int k, int from) {
    for (int d = 0; d < 2; ++d)
    {
      if (!closed[d])
        continue;
      while (st[k][d] - st[from][d] > 0.5)
        st[k][d] -= 1.0;
      while (st[k][d] - st[from][d] < -0.5)
        st[k][d] += 1.0;
    }
  };
  // The closest point of the whole surface can lie on the far side of a thin edge (a
  // blade's leading or trailing edge, both sides closer than the projector's sample
  // spacing): where a node is not on the surface at the point found, follow the loop to
  // it from its neighbours, and keep the nearer point. Both ways round: from a sharp
  // edge's tip the way on is ambiguous, from the other neighbour it is not.
  const double onSurface = 1e-9 * geometry.size(carrier);
  auto follow = [&](int k, int from) {
    if (!(away[k] > onSurface))
    {
      return;
    }
    double s = st[from][0], t = st[from][1];
    Vec3 start;
    closestNear(surface, loop[k], s, t, start);
    const double near = (geometry.point(carrier, s, t) - loop[k]).norm();
    if (near + onSurface < away[k])
    {
      st[k] = Eigen::Vector2d(s, t);
      away[k] = near;
    }
  };
  for (int k = 1; k < loopSize; ++k)
  {
    unwrap(k, k - 1);
    follow(k, k - 1);
  }
  for (int k = loopSize - 2; k >= 0; --k)
  {
    follow(k, k + 1);
  }
  // A node still off the surface between two neighbours on it: next to a sharp tip (a fan's
  // feet) Gauss-Newton from either neighbour runs past the tip onto the other flank, a few
  // micrometres from the node (the compressor's hub foot beside its leading-edge fan, 9 um
  // from the tip, folded its side's wall cell at mid-span). Searched along the parameter
  // segment between the neighbours (golden section on the distance), then polished.
  for (int k = 0; k < loopSize; ++k)
  {
    const int before = (k + loopSize - 1) % loopSize, after = (k + 1) % loopSize;
    if (!(away[k] > onSurface) || away[before] > onSurface || away[after] > onSurface)
    {
      continue;
    }
    Eigen::Vector2d from = st[before], to = st[after];
    for (int d = 0; d < 2; ++d)
    {
      if (closed[d])
      {
        from[d] += std::round(st[k][d] - from[d]);
        to[d] += std::round(st[k][d] - to[d]);
      }
    }
    const auto distance = [&](double x) {
      const Eigen::Vector2d p = from + x * (to - from);
      return (geometry.point(carrier, p[0], p[1]) - loop[k]).norm();
    };
    const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = 0.0, hi = 1.0;
    double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
    double f1 = distance(x1), f2 = distance(x2);
    for (int round = 0; round < 60; ++round)
    {
      if (f1 < f2)
      {
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - golden * (hi - lo);
        f1 = distance(x1);
      }
      else
      {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + golden * (hi - lo);
        f2 = distance(x2);
      }
    }
    const Eigen::Vector2d p = from + 0.5 * (lo + hi) * (to - from);
    double s = p[0], t = p[1];
    Vec3 start;
    closestNear(surface, loop[k], s, t, start);
    const double near = (geometry.point(carrier, s, t) - loop[k]).norm();
    if (near + onSurface < away[k])
    {
      st[k] = Eigen::Vector2d(s, t);
      away[k] = near;
    }
  }
  out.resize(3 * static_cast<std::size_t>(na) * nb);
  surfaceFaceGrid(surface, st, bottom.nodes(), top.nodes(), left.nodes(), right.nodes(), out.data(),
    SurfaceFaceMethod::Guarded, nullptr, faceBlending(model, block, face));
}

void copyFaceBoundary(const BlockModel& model, const MeshTopology& topology, int block, int face,
  int na, int nb, std::vector<double>& grid)
{
  const std::array<int, 4> edges = faceEdges(face);
  const LocalEdge bottom = localEdge(model, topology, block, edges[0]);
  const LocalEdge top = localEdge(model, topology, block, edges[1]);
  const LocalEdge left = localEdge(model, topology, block, edges[2]);
  const LocalEdge right = localEdge(model, topology, block, edges[3]);
  for (int a = 0; a < na; ++a)
  {
    std::copy_n(bottom.xyz() + 3 * a, 3, &grid[3 * static_cast<std::size_t>(a)]);
    std::copy_n(top.xyz() + 3 * a, 3, &grid[3 * (static_cast<std::size_t>(nb - 1) * na + a)]);
  }
  for (int b = 0; b < nb; ++b)
  {
    std::copy_n(left.xyz() + 3 * b, 3, &grid[3 * (static_cast<std::size_t>(b) * na)]);
    std::copy_n(right.xyz() + 3 * b, 3, &grid[3 * (static_cast<std::size_t>(b) * na + na - 1)]);
  }
}

/// Grid of a periodic image face: the source face's nodes rotated; boundary from its edges.
void periodicFace(const BlockModel& model, const MeshTopology& topology, const PeriodicPair& entry,
  std::vector<double>& out)
{
  const UniqueFace& from = topology.faces[entry.source];
  const UniqueFace& to = topology.faces[entry.image];
  out.resize(3 * static_cast<std::size_t>(to.na) * to.nb);
  for (int b = 0; b < to.nb; ++b)
  {
    for (int a = 0; a < to.na; ++a)
    {
      int sa = 0, sb = 0;
      entry.transform.map(a, b, from.na, from.nb, sa, sb);
      const double* p = &from.xyz[3 * (static_cast<std::size_t>(sb) * from.na + sa)];
      const Vec3 q = rotateAboutAxis(Vec3(p[0], p[1], p[2]), entry.axisPoint, entry.axis, entry.angle);
      std::copy_n(q.data(), 3, &out[3 * (static_cast<std::size_t>(b) * to.na + a)]);
    }
  }
  const FaceUse& owner = to.uses.front();
  copyFaceBoundary(model, topology, owner.block, owner.face, to.na, to.nb, out);
}

/// Unique face -> surface carrier of the model's surface face sets.
std::map<int, int> surfaceFaceCarriers(const BlockModel& model, const MeshTopology& topology)
{
  std::map<int, int> carriers;
  for (const SurfaceFaces& set : model.surfaceFaces)
  {
    if (set.followOpposite)
    {
      continue;
    }
    for (const BlockFace& face : set.faces)
    {
      const int unique = topology.blocks[face.block].face[face.face];
      if (unique >= 0)
      {
        carriers[unique] = set.carrier;
      }
    }
  }
  return carriers;
}


namespace
{
/// A face whose two opposite edges are each one point and whose other two edges are the
/// same nodes is a line (a fan's blade face on a sharp tip): every row across it is made
/// that line's node, so the face's nodes coincide exactly (the interpolation between two
/// equal edges leaves them a round-off apart) and the writers see prisms.
void snapLineFace(std::vector<double>& xyz, int na, int nb)
{
  const auto at = [&](int a, int b) { return &xyz[3 * (static_cast<std::size_t>(b) * na + a)]; };
  const auto same = [](const double* p, const double* q) {
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
  };
  for (int direction = 0; direction < 2; ++direction)
  {
    // direction 0: rows b = 0 and b = nb - 1 are points, columns a = 0 and na - 1 equal
    const int n = direction == 0 ? na : nb, m = direction == 0 ? nb : na;
    const auto node = [&](int along, int across) {
      return direction == 0 ? at(along, across) : at(across, along);
    };
    bool line = n > 1;
    for (int i = 1; line && i < n; ++i)
    {
      line = same(node(i, 0), node(0, 0)) && same(node(i, m - 1), node(0, m - 1));
    }
    for (int j = 0; line && j < m; ++j)
    {
      line = same(node(0, j), node(n - 1, j));
    }
    if (!line)
    {
      continue;
    }
    for (int j = 1; j + 1 < m; ++j)
    {
      for (int i = 1; i + 1 < n; ++i)
      {
        std::copy_n(node(0, j), 3, node(i, j));
      }
    }
    return;
  }
}

/// The grid of unique face `unique` in the orientation of `block`'s local face `local`.
void localFaceGrid(const MeshTopology& topology, int block, int local, int unique,
  std::vector<double>& out)
{
  const MeshLinks& links = topology.blocks[block];
  const UniqueFace& face = topology.faces[unique];
  const int na = links.nodes[faceDirections(local)[0]], nb = links.nodes[faceDirections(local)[1]];
  out.resize(3 * static_cast<std::size_t>(na) * nb);
  for (int b = 0; b < nb; ++b)
  {
    for (int a = 0; a < na; ++a)
    {
      int ownerA = 0, ownerB = 0;
      links.transform[local].map(a, b, face.na, face.nb, ownerA, ownerB);
      std::copy_n(&face.xyz[3 * (static_cast<std::size_t>(ownerB) * face.na + ownerA)], 3,
        &out[3 * (static_cast<std::size_t>(b) * na + a)]);
    }
  }
}

/**
 * A face that follows the face opposite it in its block: the Coons patch of its own edges
 * plus, at every interior node, the opposite face's departure from the Coons patch of the
 * opposite face's edges. Why: an O-grid's outer face made from its edges alone is the
 * ruled surface between the hub and shroud offsets, while the blade face between them
 * bulges (Rotor 37's suction side by 1 mm of the O-grid's 1.65 mm at mid-span): the O-grid
 * was 0.4 times as thick there and its outer cells 2.4 times smaller than the H block's
 * beside them. Boundary nodes are the edges' own (bit for bit); two blocks' faces that
 * both come from their edges are unchanged.
 */
void followOppositeFace(const BlockModel& model, MeshTopology& topology, int f)
{
  UniqueFace& face = topology.faces[f];
  const int block = face.follows.block, local = face.follows.face;
  std::vector<double> own, opposite, oppositeCoons;
  faceFromEdges(model, topology, block, local, own);
  faceFromEdges(model, topology, block, local ^ 1, oppositeCoons);
  localFaceGrid(topology, block, local ^ 1, face.opposite, opposite);
  const MeshLinks& links = topology.blocks[block];
  const int na = links.nodes[faceDirections(local)[0]], nb = links.nodes[faceDirections(local)[1]];
  for (int b = 1; b + 1 < nb; ++b)
  {
    for (int a = 1; a + 1 < na; ++a)
    {
      const std::size_t n = 3 * (static_cast<std::size_t>(b) * na + a);
      for (int c = 0; c < 3; ++c)
      {
        own[n + c] += opposite[n + c] - oppositeCoons[n + c];
      }
    }
  }
  face.xyz.resize(3 * static_cast<std::size_t>(face.na) * face.nb);
  for (int b = 0; b < nb; ++b)
  {
    for (int a = 0; a < na; ++a)
    {
      int ownerA = 0, ownerB = 0;
      links.transform[local].map(a, b, face.na, face.nb, ownerA, ownerB);
      std::copy_n(&own[3 * (static_cast<std::size_t>(b) * na + a)], 3,
        &face.xyz[3 * (static_cast<std::size_t>(ownerB) * face.na + ownerA)]);
    }
  }
}
} // namespace

void computeFaceGrid(const BlockModel& model, const CarrierGeometry& geometry,
  const std::map<int, int>& onSurface, MeshTopology& topology, int f, ProjectionCache* cache)
{
  UniqueFace& face = topology.faces[f];
  const FaceUse& owner = face.uses.front();
  try
  {
    const auto surface = onSurface.find(f);
    if (face.opposite >= 0)
    {
      followOppositeFace(model, topology, f);
    }
    else if (surface != onSurface.end())
    {
      surfaceFace(model, topology, geometry, surface->second, owner.block, owner.face, face.xyz, cache);
    }
    else
    {
      faceFromEdges(model, topology, owner.block, owner.face, face.xyz);
    }
    snapLineFace(face.xyz, face.na, face.nb);
  }
  catch (const GeometryError& error)
  {
    fail(model.blocks[owner.block].where, blockEntity(model, owner.block),
      "face " + blockFaceText(model, owner.block, owner.face) + ": " + error.what());
  }
}

BoundaryNeeds boundaryNeeds(const MeshTopology& topology, const std::vector<EdgeCopy>& copies,
  const std::vector<char>& meshed)
{
  BoundaryNeeds needs;
  needs.edges.assign(topology.edges.size(), 0);
  needs.faces.assign(topology.faces.size(), 0);
  for (std::size_t b = 0; b < topology.blocks.size() && b < meshed.size(); ++b)
  {
    if (!meshed[b])
    {
      continue;
    }
    const MeshLinks& links = topology.blocks[b];
    for (const int face : links.face)
    {
      if (face >= 0)
      {
        needs.faces[face] = 1;
      }
    }
    for (const int edge : links.edge)
    {
      if (edge >= 0)
      {
        needs.edges[edge] = 1;
      }
    }
  }
  // A periodic image face is its source face rotated: the source is needed too. A
  // following face is made from the face opposite it and from that face's four edges in
  // the same block (besides its own edges, below); the face it follows may be an image,
  // and an image's source may follow: grown until nothing is added.
  for (bool grown = true; grown;)
  {
    grown = false;
    for (const PeriodicPair& entry : topology.connectivity.periodic)
    {
      if (needs.faces[entry.image] && !needs.faces[entry.source])
      {
        needs.faces[entry.source] = 1;
        grown = true;
      }
    }
    for (std::size_t f = 0; f < topology.faces.size(); ++f)
    {
      const int opposite = topology.faces[f].opposite;
      if (needs.faces[f] && opposite >= 0)
      {
        grown = grown || !needs.faces[opposite];
        needs.faces[opposite] = 1;
        const BlockFace& named = topology.faces[f].follows;
        for (const int local : faceEdges(named.face ^ 1))
        {
          const int edge = topology.blocks[named.block].edge[local];
          if (edge >= 0)
          {
            needs.edges[edge] = 1;
          }
        }
      }
    }
  }
  // A face grid is made from its owner's four edges.
  for (std::size_t f = 0; f < topology.faces.size(); ++f)
  {
    if (!needs.faces[f])
    {
      continue;
    }
    const FaceUse& owner = topology.faces[f].uses.front();
    for (const int local : faceEdges(owner.face))
    {
      const int edge = topology.blocks[owner.block].edge[local];
      if (edge >= 0)
      {
        needs.edges[edge] = 1;
      }
    }
  }
  // A periodic copy needs its source edge, which may itself be a copy made before it.
  for (bool grown = true; grown;)
  {
    grown = false;
    for (const EdgeCopy& copy : copies)
    {
      if (needs.edges[copy.image] && !needs.edges[copy.source])
      {
        needs.edges[copy.source] = 1;
        grown = true;
      }
    }
  }
  return needs;
}

void computeAllBoundaries(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& curves, MeshTopology& topology, const std::vector<char>* meshed)
{
  // Periodic copies: named periodic edges, then the edges and faces of every periodic
  // patch's partner, rotated node for node from the first patch of the pair.
  findPeriodicPairs(model, topology.connectivity);
  const std::vector<PeriodicPair>& images = topology.connectivity.periodic;
  const std::vector<EdgeCopy> copies = periodicEdgeCopies(model, topology);
  // Only what the meshed blocks need, when not all are (an MPI rank's share): every
  // edge and face grid depends on its own edges, sources and carriers alone, so the
  // grids computed are the same bits as in a run that computes all of them.
  BoundaryNeeds needs;
  if (meshed)
  {
    needs = boundaryNeeds(topology, copies, *meshed);
  }
  const auto edgeNeeded = [&](std::size_t e) { return !meshed || needs.edges[e]; };
  const auto faceNeeded = [&](std::size_t f) { return !meshed || needs.faces[f]; };
  // Edges are independent of each other (periodic ones are copied below): on threads
  // when a runner is installed (Core/Parallel.h), the first failing edge's error first.
  forEachChunk(static_cast<long>(topology.edges.size()), [&](long e) {
    if (edgeNeeded(static_cast<std::size_t>(e)))
    {
      computeEdgeNodes(model, curves, geometry, topology.edges[e]);
    }
  });
  for (const EdgeCopy& copy : copies)
  {
    if (edgeNeeded(static_cast<std::size_t>(copy.image)))
    {
      copyPeriodicEdge(model, topology, copy);
    }
  }
  const double size = modelSize(model);
  for (int b = 0; b < static_cast<int>(model.blocks.size()); ++b)
  {
    if (!meshed || (*meshed)[b])
    {
      checkCornerCells(model, topology, b, size);
    }
  }
  std::vector<bool> isImage(topology.faces.size(), false);
  for (const PeriodicPair& entry : images)
  {
    isImage[entry.image] = true;
  }
  const std::map<int, int> onSurface = surfaceFaceCarriers(model, topology);
  // Faces are computed from their edges alone, each into its own grid: on threads when a
  // runner is installed, with the same bits, and the error of the first failing face in
  // face order.
  forEachChunk(static_cast<long>(topology.faces.size()), [&](long f) {
    if (!isImage[f] && faceNeeded(static_cast<std::size_t>(f)) && topology.faces[f].opposite < 0)
    {
      computeFaceGrid(model, geometry, onSurface, topology, static_cast<int>(f));
    }
  });
  // then the periodic images of those (a following face may be opposite one), the faces
  // that follow those opposite them, and the images of these
  const auto copyImages = [&](bool ofFollowingFaces) {
    for (const PeriodicPair& entry : images)
    {
      if (faceNeeded(static_cast<std::size_t>(entry.image)) &&
        (topology.faces[entry.source].opposite >= 0) == ofFollowingFaces)
      {
        periodicFace(model, topology, entry, topology.faces[entry.image].xyz);
      }
    }
  };
  copyImages(false);
  forEachChunk(static_cast<long>(topology.faces.size()), [&](long f) {
    if (!isImage[f] && faceNeeded(static_cast<std::size_t>(f)) && topology.faces[f].opposite >= 0)
    {
      computeFaceGrid(model, geometry, onSurface, topology, static_cast<int>(f));
    }
  });
  copyImages(true);
}

void meshBlockNodes(const BlockModel& model, const MeshTopology& topology, int block, double* out)
{
  const MeshLinks& links = topology.blocks[block];
  BlockBoundary boundary;
  std::array<std::vector<double>, 6> faceStorage;
  for (int f = 0; f < 6; ++f)
  {
    const int unique = links.face[f];
    if (unique < 0)
    {
      // Collapsed to a line or a point: not shared, rebuilt from its (collapsed) edges.
      faceFromEdges(model, topology, block, f, faceStorage[f]);
      boundary.faces[f] = faceStorage[f].data();
      continue;
    }
    const UniqueFace& face = topology.faces[unique];
    const FaceUse& owner = face.uses.front();
    if (owner.block == block && owner.face == f)
    {
      boundary.faces[f] = face.xyz.data();
      continue;
    }
    // Another block owns the face: copy its nodes into this block's orientation, so the
    // shared nodes are the very same doubles.
    localFaceGrid(topology, block, f, unique, faceStorage[f]);
    boundary.faces[f] = faceStorage[f].data();
  }
  std::array<LocalEdge, 12> edges;
  for (int e = 0; e < 12; ++e)
  {
    edges[e] = localEdge(model, topology, block, e);
    boundary.edgeParams[e] = edges[e].params();
  }
  boundary.blending = model.blocks[block].blending;
  transfiniteBlock(boundary, links.nodes[0], links.nodes[1], links.nodes[2], out);
}
} // namespace model
} // namespace blockforge
