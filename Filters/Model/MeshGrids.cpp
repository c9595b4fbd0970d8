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
        law.matchFlatness != edge.matchFlatness || law.matchAtMost != edge.matchAtMost)
      {
        const std::array<int, 2> ends = edgeVertices(use.localEdge);
        fail(block.where, blockEntity(model, use.block),
          "edge " + edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) + " (" +
            syntax::edgeLabel(use.localEdge) + ") is matched to its neighbours in another "
            "block that uses it: give it the same law 'match' (with the same ratio, flat and at_most) here");
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
