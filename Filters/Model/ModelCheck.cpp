#include "MeshInternals.h"
#include "Mesher.h"

#include "../Core/Carriers.h"

#include <Eigen/Dense>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace model
{
using syntax::entity;
using syntax::formatNumber;
using syntax::shortNumber;

// -------------------------------------------------------------------- model checks
/// Trilinear corner order (s, t, u) of the 8 local vertices (Fig. 7 = VTK order).
const int CornerS[8] = { 0, 1, 1, 0, 0, 1, 1, 0 };
const int CornerT[8] = { 0, 0, 1, 1, 0, 0, 1, 1 };
const int CornerU[8] = { 0, 0, 0, 0, 1, 1, 1, 1 };

int cornerAt(int s, int t, int u)
{
  for (int v = 0; v < 8; ++v)
  {
    if (CornerS[v] == s && CornerT[v] == t && CornerU[v] == u)
    {
      return v;
    }
  }
  return -1;
}

/// Jacobian matrix (columns d/ds, d/dt, d/du) of the trilinear map of 8 corners.
Eigen::Matrix3d trilinearJacobian(const std::array<Vec3, 8>& p, double s, double t, double u)
{
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  for (int v = 0; v < 8; ++v)
  {
    const double ws = CornerS[v] ? s : 1.0 - s, wt = CornerT[v] ? t : 1.0 - t,
                 wu = CornerU[v] ? u : 1.0 - u;
    const double ds = CornerS[v] ? 1.0 : -1.0, dt = CornerT[v] ? 1.0 : -1.0,
                 du = CornerU[v] ? 1.0 : -1.0;
    jacobian.col(0) += ds * wt * wu * p[v];
    jacobian.col(1) += ws * dt * wu * p[v];
    jacobian.col(2) += ws * wt * du * p[v];
  }
  return jacobian;
}

/**
 * The direction in which the edge from vertex a to vertex b leaves a: along the named
 * edge's curve when there is one (a curved block, e.g. an O-grid block around a blade's
 * nose, can be right-handed at its corners while the straight lines between its vertices
 * are not), else the straight line.
 */
Vec3 edgeDirectionAt(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const std::map<std::pair<int, int>, int>& named, int a, int b)
{
  const Vec3 straight = model.vertices[b].position - model.vertices[a].position;
  const auto found = named.find({ std::min(a, b), std::max(a, b) });
  if (found == named.end() || !curves[found->second].curve)
  {
    return straight;
  }
  const Curve& curve = *curves[found->second].curve;
  const bool forward = model.edges[found->second].from == a;
  const double h = 1e-6;
  const Vec3 step = forward ? Vec3(curve.point(h) - curve.point(0.0))
                            : Vec3(curve.point(1.0 - h) - curve.point(1.0));
  const double length = step.norm();
  return length > 0.0 && std::isfinite(length) ? Vec3(step * (straight.norm() / length))
                                               : straight;
}

void checkOrientation(const BlockModel& model, const std::vector<NamedCurve>& curves,
  double size, const std::vector<int>* blocks)
{
  std::map<std::pair<int, int>, int> named;
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    const Edge& edge = model.edges[e];
    named[{ std::min(edge.from, edge.to), std::max(edge.from, edge.to) }] = static_cast<int>(e);
  }
  const std::string advice = "; list its vertices in Fig. 7 order so that V0->V1 (i), V0->V3 "
                             "(j) and V0->V4 (k) form a right-handed system";
  const int count = blocks ? static_cast<int>(blocks->size()) : static_cast<int>(model.blocks.size());
  for (int n = 0; n < count; ++n)
  {
    const int b = blocks ? (*blocks)[n] : n;
    const Block& block = model.blocks[b];
    std::array<Vec3, 8> p;
    for (int v = 0; v < 8; ++v)
    {
      p[v] = model.vertices[block.vertices[v]].position;
    }
    // Exact volume: det J of a trilinear map is quadratic per direction, so 2x2x2 Gauss
    // points integrate it exactly.
    const double g = 0.5 / std::sqrt(3.0);
    double volume = 0.0;
    for (double s : { 0.5 - g, 0.5 + g })
      for (double t : { 0.5 - g, 0.5 + g })
        for (double u : { 0.5 - g, 0.5 + g })
        {
          volume += trilinearJacobian(p, s, t, u).determinant() / 8.0;
        }
    if (volume < 0.0)
    {
      fail(block.where, blockEntity(model, b),
        "the block is inside-out (negative volume " + shortNumber(volume) + ")" + advice);
    }
    if (volume <= 1e-12 * size * size * size)
    {
      fail(block.where, blockEntity(model, b),
        "the block has no volume (its vertices lie in a plane or on a line)");
    }
    // A corner is folded when the frame of the straight lines to its neighbours and the
    // frame of its edges as they leave it (curved edges: their tangents) are both
    // left-handed: a wrong vertex order flips both, while a curved block (an O-grid block
    // wrapping a blade's nose, whose straight frame flips) or a slightly turned tangent at
    // a corner that meshes well is not rejected here; the cells' quality tells the rest.
    auto along = [&](int from, int to) {
      return edgeDirectionAt(model, curves, named, block.vertices[from], block.vertices[to]);
    };
    for (int v = 0; v < 8; ++v)
    {
      const int s = CornerS[v], t = CornerT[v], u = CornerU[v];
      const Vec3 ds = p[cornerAt(1, t, u)] - p[cornerAt(0, t, u)];
      const Vec3 dt = p[cornerAt(s, 1, u)] - p[cornerAt(s, 0, u)];
      const Vec3 du = p[cornerAt(s, t, 1)] - p[cornerAt(s, t, 0)];
      const double scale = ds.norm() * dt.norm() * du.norm();
      if (ds.norm() <= 1e-12 * size || dt.norm() <= 1e-12 * size || du.norm() <= 1e-12 * size)
      {
        continue; // a collapsed edge meets here: degenerate corners are allowed
      }
      const int si = cornerAt(1 - s, t, u), ti = cornerAt(s, 1 - t, u), ui = cornerAt(s, t, 1 - u);
      const Vec3 es = s == 0 ? along(v, si) : Vec3(-along(v, si));
      const Vec3 et = t == 0 ? along(v, ti) : Vec3(-along(v, ti));
      const Vec3 eu = u == 0 ? along(v, ui) : Vec3(-along(v, ui));
      const double jacobian = ds.dot(dt.cross(du));
      const double curved = es.dot(et.cross(eu));
      if (jacobian < -1e-10 * scale && curved < -1e-10 * es.norm() * et.norm() * eu.norm())
      {
        fail(block.where, blockEntity(model, b),
          "the block is inside-out or folded: negative Jacobian at V" + std::to_string(v) +
            " (vertex '" + model.vertices[block.vertices[v]].name + "')" + advice);
      }
    }
  }
}

void checkBasics(const BlockModel& model)
{
  const int vertexCount = static_cast<int>(model.vertices.size());
  for (const Vertex& vertex : model.vertices)
  {
    if (!vertex.position.allFinite())
    {
      fail(vertex.where, entity("vertex", vertex.name), "the position is not finite");
    }
  }
  for (const Edge& edge : model.edges)
  {
    if (edge.from < 0 || edge.from >= vertexCount || edge.to < 0 || edge.to >= vertexCount ||
      edge.from == edge.to)
    {
      fail(edge.where, entity("edge", edge.name), "needs two different, existing vertices");
    }
    if (model.findEdge(edge.from, edge.to) != &edge - model.edges.data())
    {
      fail(edge.where, entity("edge", edge.name),
        "joins the same vertices as edge '" +
          model.edges[model.findEdge(edge.from, edge.to)].name + "'");
    }
  }
  if (model.blocks.empty())
  {
    throw TemplateError(model.sourceFile, 0, entity("model", model.name), "has no blocks");
  }
  for (const Block& block : model.blocks)
  {
    for (int vertex : block.vertices)
    {
      if (vertex < 0 || vertex >= vertexCount)
      {
        fail(block.where, entity("block", block.name),
          "refers to vertex #" + std::to_string(vertex) + ", which does not exist");
      }
    }
    for (int cells : block.cells)
    {
      if (cells < 1)
      {
        fail(block.where, entity("block", block.name), "cells must be at least 1");
      }
    }
    for (int cells : block.minCells)
    {
      if (cells < 1)
      {
        fail(block.where, entity("block", block.name), "min_cells must be at least 1");
      }
    }
    for (int e = 0; e < 12; ++e)
    {
      const DistributionLaw& law = block.laws[e];
      if (law.kind == DistributionLaw::Kind::ProjectFrom &&
        (law.sourceEdge < 0 || law.sourceEdge >= static_cast<int>(model.edges.size())))
      {
        fail(block.where, entity("block", block.name),
          "the law project_from of " + syntax::edgeLabel(e) + " refers to edge #" +
            std::to_string(law.sourceEdge) + ", which does not exist");
      }
    }
  }
}

/// Named edges must lie on some block edge, or they are almost certainly a typo.
void checkNamedEdgesUsed(const BlockModel& model, const MeshTopology& topology)
{
  std::vector<bool> used(model.edges.size(), false);
  for (const UniqueEdge& edge : topology.edges)
  {
    if (edge.named >= 0)
    {
      used[edge.named] = true;
    }
  }
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    if (!used[e])
    {
      const Edge& edge = model.edges[e];
      fail(edge.where, entity("edge", edge.name),
        "no block has an edge from '" + model.vertices[edge.from].name + "' to '" +
          model.vertices[edge.to].name + "'");
    }
  }
}

// -------------------------------------------------------------------- carrier checks
/**
 * Format 2 checks: carriers build; closed Gordon surfaces are closed; every control point
 * lies on its carrier; periodic vertices are rotations of their sources; surface faces
 * name surfaces and their corners lie on them.
 */
void checkCarriers(const BlockModel& model, const CarrierGeometry& geometry, double size,
  const std::vector<int>* vertices)
{
  const int carrierCount = static_cast<int>(model.carriers.size());
  for (std::size_t c = 0; !vertices && c < model.carriers.size(); ++c)
  {
    const Carrier& carrier = model.carriers[c];
    if ((carrier.kind == Carrier::Kind::Gordon || carrier.kind == Carrier::Kind::Network) &&
      carrier.closed)
    {
      for (std::size_t k = 0; k < carrier.refs.size(); ++k)
      {
        const int ref = carrier.refs[k];
        const CurvePtr& curve = geometry.curve(ref);
        const double gap = (curve->point(0.0) - curve->point(1.0)).norm();
        if (gap > 1e-9 * std::max(size, geometry.size(ref)))
        {
          fail(carrier.where, entity("carrier", carrier.name),
            "the surface is not closed: section " + std::to_string(k + 1) + " ('" +
              model.carriers[ref].name + "') has its ends " + shortNumber(gap) + " apart");
        }
      }
    }
  }
  const int vertexCount = vertices ? static_cast<int>(vertices->size()) : static_cast<int>(model.vertices.size());
  for (int n = 0; n < vertexCount; ++n)
  {
    const Vertex& vertex = model.vertices[vertices ? (*vertices)[n] : n];
    const std::string entityText = entity("vertex", vertex.name);
    const VertexConstraint& constraint = vertex.constraint;
    if (constraint.carrier >= 0)
    {
      if (constraint.carrier >= carrierCount)
      {
        fail(vertex.where, entityText, "is attached to a carrier that does not exist");
      }
      const bool surface = geometry.isSurface(constraint.carrier);
      const int c = constraint.carrier;
      const bool inRange = constraint.s >= 0.0 && constraint.s <= 1.0 &&
        (!surface || (constraint.t >= geometry.tMin(c) && constraint.t <= geometry.tMax(c)));
      if (!std::isfinite(constraint.s) || !std::isfinite(constraint.t) || !inRange)
      {
        fail(vertex.where, entityText,
          "its carrier parameters (" + shortNumber(constraint.s) + ", " +
            shortNumber(constraint.t) + ") are outside the carrier's range");
      }
      const Vec3 onCarrier = geometry.point(constraint.carrier, constraint.s, constraint.t);
      const double distance = (onCarrier - vertex.position).norm();
      if (!(distance <= carrierTolerance(geometry, constraint.carrier, size)))
      {
        fail(vertex.where, entityText,
          "the control point is " + shortNumber(distance) + " away from its carrier '" +
            model.carriers[constraint.carrier].name + "' at " +
            (surface ? "(s, t) = (" + shortNumber(constraint.s) + ", " +
                  shortNumber(constraint.t) + ")"
                     : "u = " + shortNumber(constraint.s)) +
            "; a control point must lie on its carrier");
      }
    }
    if (constraint.periodicSource >= 0)
    {
      const int source = constraint.periodicSource;
      if (source >= static_cast<int>(model.vertices.size()) ||
        source == static_cast<int>(&vertex - model.vertices.data()))
      {
        fail(vertex.where, entityText, "is periodic with a vertex that does not exist");
      }
      if (!model.machine.defined || model.machine.bladeCount <= 0)
      {
        fail(vertex.where, entityText, "a periodic vertex needs the machine's blade count");
      }
      const Vec3 image = rotateAboutAxis(model.vertices[source].position, model.machine.axisPoint,
        model.machine.axis, constraint.pitches * model.machine.pitch());
      const double miss = (image - vertex.position).norm();
      if (!(miss <= 1e-9 * size))
      {
        fail(vertex.where, entityText,
          "is not the periodic image of vertex '" + model.vertices[source].name + "' (" +
            std::to_string(constraint.pitches) + " pitch(es) about the machine axis): off by " +
            shortNumber(miss));
      }
    }
  }
}

void checkSurfaceFaces(const BlockModel& model, const CarrierGeometry& geometry,
  const MeshTopology& topology, double size)
{
  const int carrierCount = static_cast<int>(model.carriers.size());
  for (const SurfaceFaces& set : model.surfaceFaces)
  {
    const std::string entityText = entity("face set", set.name);
    if (!set.followOpposite &&
      (set.carrier < 0 || set.carrier >= carrierCount || !geometry.isSurface(set.carrier)))
    {
      fail(set.where, entityText, "needs a surface carrier");
    }
    for (const BlockFace& face : set.faces)
    {
      if (face.block < 0 || face.block >= static_cast<int>(model.blocks.size()) || face.face < 0 ||
        face.face > 5)
      {
        fail(set.where, entityText, "refers to a face that does not exist");
      }
      if (topology.blocks[face.block].face[face.face] < 0)
      {
        fail(set.where, entityText,
          "face " + blockFaceText(model, face.block, face.face) + " is collapsed to a line or a point");
      }
      if (set.followOpposite)
      {
        // its grid comes from the face opposite it: that face must be one (that it does not
        // follow a face itself is checked with the mesher's topology, buildMeshTopology)
        const int opposite = topology.blocks[face.block].face[face.face ^ 1];
        if (opposite < 0)
        {
          fail(set.where, entityText,
            "face " + blockFaceText(model, face.block, face.face ^ 1) +
              ", opposite the following face " + blockFaceText(model, face.block, face.face) +
              ", is collapsed to a line or a point");
        }
        for (const SurfaceFaces& other : model.surfaceFaces)
        {
          for (const BlockFace& named : other.faces)
          {
            const int unique = topology.blocks[named.block].face[named.face];
            if (unique == topology.blocks[face.block].face[face.face] && &other != &set)
            {
              fail(set.where, entityText,
                "face " + blockFaceText(model, face.block, face.face) + " is also in face set '" +
                  other.name + "': a face follows the face opposite it or lies on a surface, not both");
            }
          }
        }
        continue;
      }
      for (int corner : faceVertexIds(model.blocks[face.block], face.face))
      {
        double s = 0.0, t = 0.0, distance = 0.0;
        geometry.vertexParameters(model, corner, set.carrier, s, t, distance);
        if (distance > carrierTolerance(geometry, set.carrier, size))
        {
          fail(set.where, entityText,
            "corner '" + model.vertices[corner].name + "' of face " +
              blockFaceText(model, face.block, face.face) + " is " + shortNumber(distance) +
              " away from surface '" + model.carriers[set.carrier].name + "'");
        }
      }
    }
  }
}
/// Blocks sharing an edge keep the same cells along it at every density multiplier, so
/// they must keep the same fewest cells there (min_cells, at most cells) when coarsened.
void checkMinCells(const BlockModel& model, const Topology& topology)
{
  static const char* const directionNames[3] = { "i", "j", "k" };
  auto floorOf = [&model](const EdgeUse& use) {
    const Block& block = model.blocks[use.block];
    const int d = edgeDirection(use.localEdge);
    return std::min(block.cells[d], block.minCells[d]);
  };
  for (const TopologyEdge& edge : topology.edges)
  {
    for (const EdgeUse& use : edge.uses)
    {
      const EdgeUse& first = edge.uses.front();
      if (floorOf(use) != floorOf(first))
      {
        const Block& block = model.blocks[use.block];
        fail(block.where, entity("block", block.name),
          "edge " + edgeText(model, edge.a, edge.b) + " (" + syntax::edgeLabel(use.localEdge) +
            ") has min_cells " + std::to_string(floorOf(use)) + " along " +
            directionNames[edgeDirection(use.localEdge)] + " here but " +
            std::to_string(floorOf(first)) + " in block '" + model.blocks[first.block].name +
            "' (" + syntax::edgeLabel(first.localEdge) +
            "); blocks sharing an edge need the same min_cells along it (a min_cells above "
            "cells counts as cells)");
      }
    }
  }
}

/// A periodic image is its partner's face rotated, made after the faces it may be opposite
/// to: an image cannot follow, and a face cannot follow the image of a following face.
void checkFollowingImages(const BlockModel& model, const MeshTopology& topology)
{
  std::vector<int> imageSource(topology.faces.size(), -1);
  for (const PeriodicPair& pair : topology.connectivity.periodic)
  {
    imageSource[pair.image] = pair.source;
  }
  for (const SurfaceFaces& set : model.surfaceFaces)
  {
    if (!set.followOpposite)
    {
      continue;
    }
    const std::string entityText = entity("face set", set.name);
    for (const BlockFace& face : set.faces)
    {
      const MeshLinks& links = topology.blocks[face.block];
      if (imageSource[links.face[face.face]] >= 0)
      {
        fail(set.where, entityText,
          "face " + blockFaceText(model, face.block, face.face) +
            " is a periodic image (its partner's face rotated): it cannot follow the face "
            "opposite it; let the partner's block follow instead");
      }
      const int source = imageSource[links.face[face.face ^ 1]];
      if (source >= 0 && topology.faces[source].opposite >= 0)
      {
        fail(set.where, entityText,
          "face " + blockFaceText(model, face.block, face.face) +
            " follows the periodic image of a face that follows another: the face a following "
            "face follows must lie on a surface or come from its edges");
      }
    }
  }
}

void checkModelWith(const BlockModel& model, const CarrierGeometry& geometry)
{
  const double size = modelSize(model);
  checkCarriers(model, geometry, size);
  const std::vector<NamedCurve> curves = buildNamedCurves(model, geometry);
  MeshTopology topology = buildMeshTopology(model, geometry, curves, baseNodeCounts(model), false);
  checkMinCells(model, topology.connectivity);
  checkNamedEdgesUsed(model, topology);
  checkSurfaceFaces(model, geometry, topology, size);
  checkOrientation(model, curves, size);
  checkPatches(model, topology.connectivity);
  findPeriodicPairs(model, topology.connectivity); // the rotated copies must match node for node
  checkFollowingImages(model, topology);
}

void checkModel(const BlockModel& model)
{
  checkBasics(model);
  const CarrierGeometry geometry(model);
  checkModelWith(model, geometry);
}

void checkModel(const BlockModel& model, const CarrierGeometry& geometry)
{
  checkBasics(model);
  checkModelWith(model, geometry);
}
} // namespace model
} // namespace blockforge
