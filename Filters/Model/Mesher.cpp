#include "Mesher.h"

#include "../Core/BSpline.h"
#include "../Core/Curve.h"
#include "../Core/Projection.h"
#include "../Core/Transfinite.h"
#include "ModelSyntax.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

namespace blockforge
{
namespace model
{
namespace
{
using syntax::entity;
using syntax::formatNumber;

constexpr double Pi = 3.14159265358979323846;

[[noreturn]] void fail(
  const SourceLocation& where, const std::string& entityText, const std::string& what)
{
  throw TemplateError(where.file, where.line, entityText, what);
}

std::string blockEntity(const BlockModel& model, int block)
{
  return entity("block", model.blocks[block].name);
}

std::string faceText(const BlockModel& model, int block, int face)
{
  return model.blocks[block].name + "." + faceName(face);
}

/// Short form of a number for messages.
std::string shortNumber(double value)
{
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text.precision(6);
  text << value;
  return text.str();
}

/// "w_ne-b_ne" or "'wall_n' (w_ne-b_ne)": how messages name the edge between a and b.
std::string edgeText(const BlockModel& model, int a, int b)
{
  const std::string ends = model.vertices[a].name + "-" + model.vertices[b].name;
  const int named = model.findEdge(a, b);
  return named >= 0 ? "'" + model.edges[named].name + "' (" + ends + ")" : ends;
}

/// Model size for tolerances: the diagonal of the vertices' bounding box.
double modelSize(const BlockModel& model)
{
  if (model.vertices.empty())
  {
    return 1.0;
  }
  Vec3 low = model.vertices[0].position, high = low;
  for (const Vertex& vertex : model.vertices)
  {
    low = low.cwiseMin(vertex.position);
    high = high.cwiseMax(vertex.position);
  }
  const double size = (high - low).norm();
  return size > 0.0 ? size : 1.0;
}

// -------------------------------------------------------------------- edge geometry
/// The curve of a named edge in its own direction (from -> to), with what it takes to
/// place nodes at arc-length fractions.
struct NamedCurve
{
  CurvePtr curve;
  std::shared_ptr<const ArcLength> arcLength; ///< splines only: arcs are arc-length already
  double length = 0.0;
};

NamedCurve buildNamedCurve(const BlockModel& model, const Edge& edge)
{
  const Vec3& start = model.vertices[edge.from].position;
  const Vec3& end = model.vertices[edge.to].position;
  NamedCurve named;
  switch (edge.kind)
  {
    case Edge::Kind::Line:
      named.curve = std::make_shared<LineCurve>(start, end);
      named.length = (end - start).norm();
      break;
    case Edge::Kind::Arc:
    {
      auto arc = std::make_shared<ArcCurve>(edge.arcHasCentre
          ? ArcCurve::fromCentre(start, end, edge.arcCentre)
          : ArcCurve::throughPoint(start, edge.arcThrough, end));
      named.length = arc->radius() * arc->sweepAngle();
      named.curve = arc;
      break;
    }
    case Edge::Kind::Spline:
    {
      std::vector<Vec3> points;
      points.push_back(start);
      points.insert(points.end(), edge.splinePoints.begin(), edge.splinePoints.end());
      points.push_back(end);
      named.curve = std::make_shared<BSplineCurve>(
        BSplineCurve::interpolate(points, 3, ParameterMethod::ChordLength));
      named.arcLength = std::make_shared<ArcLength>(named.curve);
      named.length = named.arcLength->totalLength();
      break;
    }
  }
  if (!std::isfinite(named.length) || !(named.length > 0.0))
  {
    throw GeometryError("the edge has no length");
  }
  return named;
}

/// Curves of all named edges; GeometryError becomes a TemplateError naming the edge.
std::vector<NamedCurve> buildNamedCurves(const BlockModel& model)
{
  std::vector<NamedCurve> curves;
  for (const Edge& edge : model.edges)
  {
    try
    {
      curves.push_back(buildNamedCurve(model, edge));
    }
    catch (const GeometryError& error)
    {
      fail(edge.where, entity("edge", edge.name), error.what());
    }
  }
  return curves;
}

/// Node parameters of `law` for `nodeCount` nodes on an edge of `length`. When the cell
/// counts were changed for a preview or a density multiplier, a first-cell law that no
/// longer fits falls back to the solved ratio, then to uniform: previews must not fail
/// on a template that meshes at its own density.
std::vector<double> lawParameters(
  const DistributionLaw& law, int nodeCount, double length, bool allowFallback)
{
  if (!allowFallback)
  {
    return distributeNodes(law, nodeCount, length);
  }
  try
  {
    return distributeNodes(law, nodeCount, length);
  }
  catch (const GeometryError&)
  {
  }
  if (law.kind == DistributionLaw::Kind::FirstCell && law.expansionRatio != 0.0)
  {
    DistributionLaw solved = law;
    solved.expansionRatio = 0.0;
    try
    {
      return distributeNodes(solved, nodeCount, length);
    }
    catch (const GeometryError&)
    {
    }
  }
  return distributeNodes(DistributionLaw(), nodeCount, length);
}

std::vector<double> reversedParameters(const std::vector<double>& params)
{
  const std::size_t n = params.size();
  std::vector<double> reversed(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    reversed[i] = 1.0 - params[n - 1 - i];
  }
  reversed.front() = 0.0;
  reversed.back() = 1.0;
  return reversed;
}

// -------------------------------------------------------------------- face orientation
/// Unit (a, b) coordinates of face corners 0..3 (see faceCorners()).
const int CornerA[4] = { 0, 1, 1, 0 };
const int CornerB[4] = { 0, 0, 1, 1 };

/**
 * One of the 8 symmetries of a square, mapping a face grid index (a, b) as one block sees
 * it to the owner block's (a, b): bit 2 swaps a and b, then bits 0 and 1 flip a and b.
 */
struct FaceTransform
{
  int code = 0;
  bool swap() const { return (code & 4) != 0; }
  bool flipA() const { return (code & 1) != 0; }
  bool flipB() const { return (code & 2) != 0; }
  /// Owner index of (a, b); (ownerA, ownerB) are the owner's node counts.
  void map(int a, int b, int ownerA, int ownerB, int& outA, int& outB) const
  {
    const int x = swap() ? b : a;
    const int y = swap() ? a : b;
    outA = flipA() ? ownerA - 1 - x : x;
    outB = flipB() ? ownerB - 1 - y : y;
  }
  int mapCorner(int corner) const
  {
    int a = 0, b = 0;
    map(CornerA[corner], CornerB[corner], 2, 2, a, b);
    for (int c = 0; c < 4; ++c)
    {
      if (CornerA[c] == a && CornerB[c] == b)
      {
        return c;
      }
    }
    return -1;
  }
};

// -------------------------------------------------------------------- topology
struct EdgeUse
{
  int block = -1;
  int localEdge = -1;
  bool reversed = false; ///< the block runs this edge from the higher vertex index
};

/// An edge shared by every block that uses it, in canonical direction a -> b (a < b).
struct UniqueEdge
{
  int a = -1, b = -1;
  int named = -1; ///< index into model.edges, -1 for a straight edge
  int nodeCount = 0;
  double length = 0.0;
  std::vector<double> params; ///< canonical direction, from the first block that uses it
  std::vector<double> xyz;
  std::vector<EdgeUse> uses;
};

struct FaceUse
{
  int block = -1;
  int face = -1;
  FaceTransform transform;
};

/// A face with at least three distinct vertices; its grid is stored in the orientation of
/// its first block (the owner).
struct UniqueFace
{
  std::array<int, 4> ownerIds{};
  int na = 0, nb = 0;
  std::vector<FaceUse> uses;
  std::vector<double> xyz;
};

struct BlockLinks
{
  std::array<int, 3> nodes{};
  std::array<int, 12> edge{};      ///< unique edge, -1 when collapsed
  std::array<bool, 12> reversed{};
  std::array<std::vector<double>, 12> collapsedParams; ///< for collapsed edges only
  std::array<int, 6> face{};       ///< unique face, -1 when collapsed to a line or point
  std::array<FaceTransform, 6> transform{};
};

struct Topology
{
  std::vector<UniqueEdge> edges;
  std::vector<UniqueFace> faces;
  std::vector<BlockLinks> blocks;
};

int faceNodeCount(const BlockLinks& links, int face, int which)
{
  return links.nodes[faceDirections(face)[which]];
}

std::array<int, 4> faceVertexIds(const Block& block, int face)
{
  std::array<int, 4> ids{};
  const std::array<int, 4> corners = faceCorners(face);
  for (int c = 0; c < 4; ++c)
  {
    ids[c] = block.vertices[corners[c]];
  }
  return ids;
}

int distinctCount(std::array<int, 4> ids)
{
  std::sort(ids.begin(), ids.end());
  return static_cast<int>(std::unique(ids.begin(), ids.end()) - ids.begin());
}

/**
 * Unique edges and faces of the model for the given node counts, with every consistency
 * check that depends on them: node counts and laws on shared edges, faces shared by more
 * than two blocks, faces that share vertices but do not match.
 */
Topology buildTopology(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const std::vector<std::array<int, 3>>& nodes, bool allowFallback)
{
  Topology topology;
  const int blockCount = static_cast<int>(model.blocks.size());
  topology.blocks.resize(blockCount);
  std::map<std::pair<int, int>, int> edgeIndex;

  for (int b = 0; b < blockCount; ++b)
  {
    const Block& block = model.blocks[b];
    BlockLinks& links = topology.blocks[b];
    links.nodes = nodes[b];
    for (int e = 0; e < 12; ++e)
    {
      const std::array<int, 2> ends = edgeVertices(e);
      const int from = block.vertices[ends[0]], to = block.vertices[ends[1]];
      const int count = links.nodes[edgeDirection(e)];
      if (from == to)
      {
        links.edge[e] = -1;
        continue;
      }
      const std::pair<int, int> key(std::min(from, to), std::max(from, to));
      auto found = edgeIndex.find(key);
      if (found == edgeIndex.end())
      {
        UniqueEdge edge;
        edge.a = key.first;
        edge.b = key.second;
        edge.named = model.findEdge(edge.a, edge.b);
        edge.nodeCount = count;
        edge.length = edge.named >= 0
          ? curves[edge.named].length
          : (model.vertices[edge.b].position - model.vertices[edge.a].position).norm();
        found = edgeIndex.emplace(key, static_cast<int>(topology.edges.size())).first;
        topology.edges.push_back(std::move(edge));
      }
      UniqueEdge& edge = topology.edges[found->second];
      if (edge.nodeCount != count)
      {
        const EdgeUse& first = edge.uses.front();
        fail(block.where, blockEntity(model, b),
          "edge " + edgeText(model, from, to) + " (" + syntax::edgeLabel(e) + ") has " +
            std::to_string(count - 1) + " cells here but " + std::to_string(edge.nodeCount - 1) +
            " in block '" + model.blocks[first.block].name + "' (" +
            syntax::edgeLabel(first.localEdge) +
            "); blocks sharing an edge need the same cell count along it");
      }
      edge.uses.push_back(EdgeUse{ b, e, from > to });
      links.edge[e] = found->second;
      links.reversed[e] = from > to;
    }
  }

  // Node parameters: the first block's law defines the edge; every other block must give
  // the same parameters, compared in the edge's canonical direction.
  for (UniqueEdge& edge : topology.edges)
  {
    for (const EdgeUse& use : edge.uses)
    {
      const Block& block = model.blocks[use.block];
      std::vector<double> params;
      try
      {
        params = lawParameters(block.laws[use.localEdge], edge.nodeCount, edge.length, allowFallback);
      }
      catch (const GeometryError& error)
      {
        const std::array<int, 2> ends = edgeVertices(use.localEdge);
        fail(block.where, blockEntity(model, use.block),
          "grading of edge " +
            edgeText(model, block.vertices[ends[0]], block.vertices[ends[1]]) + " (" +
            syntax::edgeLabel(use.localEdge) + "): " + error.what());
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

  // Collapsed edges carry no geometry, but their parameters still steer the blending
  // inside the block: take the block's law over the length of the longest parallel edge.
  for (int b = 0; b < blockCount; ++b)
  {
    BlockLinks& links = topology.blocks[b];
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
      links.collapsedParams[e] = lawParameters(model.blocks[b].laws[e],
        links.nodes[edgeDirection(e)], length > 0.0 ? length : 1.0, true);
    }
  }

  std::map<std::array<int, 4>, int> faceIndex;
  for (int b = 0; b < blockCount; ++b)
  {
    const Block& block = model.blocks[b];
    BlockLinks& links = topology.blocks[b];
    for (int f = 0; f < 6; ++f)
    {
      const std::array<int, 4> ids = faceVertexIds(block, f);
      links.face[f] = -1;
      if (distinctCount(ids) < 3)
      {
        continue;
      }
      std::array<int, 4> key = ids;
      std::sort(key.begin(), key.end());
      auto found = faceIndex.find(key);
      const int na = faceNodeCount(links, f, 0), nb = faceNodeCount(links, f, 1);
      if (found == faceIndex.end())
      {
        UniqueFace face;
        face.ownerIds = ids;
        face.na = na;
        face.nb = nb;
        face.uses.push_back(FaceUse{ b, f, FaceTransform{ 0 } });
        faceIndex.emplace(key, static_cast<int>(topology.faces.size()));
        links.face[f] = static_cast<int>(topology.faces.size());
        topology.faces.push_back(std::move(face));
        continue;
      }
      UniqueFace& face = topology.faces[found->second];
      const FaceUse& owner = face.uses.front();
      if (face.uses.size() >= 2)
      {
        std::string blocks;
        for (const FaceUse& use : face.uses)
        {
          blocks += faceText(model, use.block, use.face) + ", ";
        }
        fail(block.where, blockEntity(model, b),
          "face " + faceText(model, b, f) + " is also a face of " + blocks +
            "but a face can join at most two blocks");
      }
      bool matched = false;
      for (int code = 0; code < 8 && !matched; ++code)
      {
        const FaceTransform transform{ code };
        bool same = true;
        for (int c = 0; c < 4 && same; ++c)
        {
          same = face.ownerIds[transform.mapCorner(c)] == ids[c];
        }
        const int mappedA = transform.swap() ? nb : na;
        const int mappedB = transform.swap() ? na : nb;
        if (same && mappedA == face.na && mappedB == face.nb)
        {
          face.uses.push_back(FaceUse{ b, f, transform });
          links.face[f] = found->second;
          links.transform[f] = transform;
          matched = true;
        }
      }
      if (!matched)
      {
        fail(block.where, blockEntity(model, b),
          "face " + faceText(model, b, f) + " has the same vertices as face " +
            faceText(model, owner.block, owner.face) +
            " but the two do not match edge for edge (or differ in node counts); check the "
            "vertex order of both blocks");
      }
    }
  }
  return topology;
}

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

void checkOrientation(const BlockModel& model, double size)
{
  const std::string advice = "; list its vertices in Fig. 7 order so that V0->V1 (i), V0->V3 "
                             "(j) and V0->V4 (k) form a right-handed system";
  for (int b = 0; b < static_cast<int>(model.blocks.size()); ++b)
  {
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
      const double jacobian = ds.dot(dt.cross(du));
      if (jacobian < -1e-10 * scale)
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
  }
}

/// Named edges must lie on some block edge, or they are almost certainly a typo.
void checkNamedEdgesUsed(const BlockModel& model, const Topology& topology)
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

Eigen::Matrix3d periodicRotation(const Patch& patch)
{
  return Eigen::AngleAxisd(patch.periodicAngle, patch.periodicAxis.normalized())
    .toRotationMatrix();
}

void checkPatches(const BlockModel& model, const Topology& topology, double size)
{
  const int blockCount = static_cast<int>(model.blocks.size());
  std::map<std::pair<int, int>, int> patchOfFace;
  for (int p = 0; p < static_cast<int>(model.patches.size()); ++p)
  {
    const Patch& patch = model.patches[p];
    const std::string entityText = entity("patch", patch.name);
    for (const BlockFace& face : patch.faces)
    {
      if (face.block < 0 || face.block >= blockCount || face.face < 0 || face.face > 5)
      {
        fail(patch.where, entityText, "refers to a face that does not exist");
      }
      const std::string name = faceText(model, face.block, face.face);
      const int unique = topology.blocks[face.block].face[face.face];
      if (unique < 0)
      {
        fail(patch.where, entityText,
          "face " + name + " is collapsed to a line or a point and cannot be a patch face");
      }
      const std::vector<FaceUse>& uses = topology.faces[unique].uses;
      if (uses.size() > 1)
      {
        const FaceUse& other =
          uses[0].block == face.block && uses[0].face == face.face ? uses[1] : uses[0];
        fail(patch.where, entityText,
          "face " + name + " is internal (it is also face " +
            faceText(model, other.block, other.face) +
            "); patch faces must lie on the domain boundary");
      }
      const auto inserted = patchOfFace.emplace(std::make_pair(face.block, face.face), p);
      if (!inserted.second)
      {
        const int other = inserted.first->second;
        fail(patch.where, entityText,
          other == p ? "face " + name + " is listed twice"
                     : "face " + name + " is already in patch '" + model.patches[other].name +
              "'; a face belongs to at most one patch");
      }
    }
  }

  const double tolerance = 1e-9 * size;
  for (const Patch& patch : model.patches)
  {
    if (patch.type != "periodic")
    {
      continue;
    }
    const std::string entityText = entity("patch", patch.name);
    const auto partnerIt = std::find_if(model.patches.begin(), model.patches.end(),
      [&](const Patch& other) { return other.name == patch.periodicPartner; });
    if (patch.periodicPartner.empty() || partnerIt == model.patches.end())
    {
      fail(patch.where, entityText,
        patch.periodicPartner.empty()
          ? std::string("a periodic patch needs a partner")
          : "periodic partner '" + patch.periodicPartner + "' does not exist");
    }
    const Patch& partner = *partnerIt;
    if (partner.type != "periodic" || partner.periodicPartner != patch.name)
    {
      fail(patch.where, entityText,
        "periodic partner '" + partner.name + "' must be periodic and name '" + patch.name +
          "' as its partner");
    }
    if (!patch.periodicAxis.allFinite() || !(patch.periodicAxis.norm() > 0.0) ||
      !patch.periodicAxisPoint.allFinite() || !std::isfinite(patch.periodicAngle))
    {
      fail(patch.where, entityText, "the periodic rotation (axis, origin, angle) is invalid");
    }
    if (partner.faces.size() != patch.faces.size())
    {
      fail(patch.where, entityText,
        "has " + std::to_string(patch.faces.size()) + " faces but its periodic partner '" +
          partner.name + "' has " + std::to_string(partner.faces.size()));
    }
    const Eigen::Matrix3d rotation = periodicRotation(patch);
    std::vector<bool> taken(partner.faces.size(), false);
    for (const BlockFace& face : patch.faces)
    {
      const std::array<int, 4> ids = faceVertexIds(model.blocks[face.block], face.face);
      std::array<Vec3, 4> image;
      for (int c = 0; c < 4; ++c)
      {
        image[c] = patch.periodicAxisPoint +
          rotation * (model.vertices[ids[c]].position - patch.periodicAxisPoint);
      }
      const UniqueFace& grid = topology.faces[topology.blocks[face.block].face[face.face]];
      int match = -1;
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t q = 0; q < partner.faces.size() && match < 0; ++q)
      {
        const BlockFace& candidate = partner.faces[q];
        const std::array<int, 4> other =
          faceVertexIds(model.blocks[candidate.block], candidate.face);
        double worst = 0.0;
        for (int c = 0; c < 4; ++c)
        {
          double best = std::numeric_limits<double>::infinity();
          for (int d = 0; d < 4; ++d)
          {
            best = std::min(best, (image[c] - model.vertices[other[d]].position).norm());
          }
          worst = std::max(worst, best);
        }
        nearest = std::min(nearest, worst);
        if (worst <= tolerance && !taken[q])
        {
          match = static_cast<int>(q);
        }
      }
      const std::string name = faceText(model, face.block, face.face);
      if (match < 0)
      {
        fail(patch.where, entityText,
          "face " + name + " rotated by " + shortNumber(patch.periodicAngle * 180.0 / Pi) +
            " deg does not land on a face of periodic partner '" + partner.name +
            "' (nearest miss " + shortNumber(nearest) + "); check axis, origin and angle");
      }
      taken[match] = true;
      const BlockFace& image_face = partner.faces[match];
      const UniqueFace& other =
        topology.faces[topology.blocks[image_face.block].face[image_face.face]];
      if (std::min(grid.na, grid.nb) != std::min(other.na, other.nb) ||
        std::max(grid.na, grid.nb) != std::max(other.na, other.nb))
      {
        fail(patch.where, entityText,
          "face " + name + " has " + std::to_string(grid.na - 1) + " x " +
            std::to_string(grid.nb - 1) + " cells but its periodic image " +
            faceText(model, image_face.block, image_face.face) + " has " +
            std::to_string(other.na - 1) + " x " + std::to_string(other.nb - 1));
      }
    }
  }
}

std::vector<std::array<int, 3>> baseNodeCounts(const BlockModel& model)
{
  std::vector<std::array<int, 3>> nodes;
  for (const Block& block : model.blocks)
  {
    nodes.push_back({ block.cells[0] + 1, block.cells[1] + 1, block.cells[2] + 1 });
  }
  return nodes;
}

// -------------------------------------------------------------------- grids
/// Nodes of one edge as a block sees it (its local direction), possibly borrowed.
struct LocalEdge
{
  std::vector<double> xyzStorage, paramStorage;
  const double* borrowedXyz = nullptr;
  const double* borrowedParams = nullptr;
  int count = 0;
  const double* xyz() const { return xyzStorage.empty() ? borrowedXyz : xyzStorage.data(); }
  const double* params() const
  {
    return paramStorage.empty() ? borrowedParams : paramStorage.data();
  }
  EdgeNodes nodes() const { return EdgeNodes{ xyz(), params(), count }; }
};

LocalEdge localEdge(
  const BlockModel& model, const Topology& topology, int block, int localEdgeIndex)
{
  const BlockLinks& links = topology.blocks[block];
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

/// Face grid of `face` of `block` in the block's own orientation, from its four edges.
void faceFromEdges(const BlockModel& model, const Topology& topology, int block, int face,
  std::vector<double>& out)
{
  const std::array<int, 4> edges = faceEdges(face);
  const LocalEdge bottom = localEdge(model, topology, block, edges[0]);
  const LocalEdge top = localEdge(model, topology, block, edges[1]);
  const LocalEdge left = localEdge(model, topology, block, edges[2]);
  const LocalEdge right = localEdge(model, topology, block, edges[3]);
  out.resize(3 * static_cast<std::size_t>(bottom.count) * left.count);
  transfiniteFace(bottom.nodes(), top.nodes(), left.nodes(), right.nodes(), out.data());
}

void computeEdgeNodes(const BlockModel& model, const std::vector<NamedCurve>& curves,
  UniqueEdge& edge)
{
  const Vec3& start = model.vertices[edge.a].position;
  const Vec3& end = model.vertices[edge.b].position;
  const int n = edge.nodeCount;
  edge.xyz.resize(3 * n);
  const NamedCurve* named = edge.named >= 0 ? &curves[edge.named] : nullptr;
  // The named edge may run b -> a; its curve is evaluated at the mirrored fraction.
  const bool curveReversed = named && model.edges[edge.named].from != edge.a;
  for (int i = 0; i < n; ++i)
  {
    Vec3 point;
    if (i == 0)
    {
      point = start; // end nodes are the vertices themselves, bit for bit
    }
    else if (i == n - 1)
    {
      point = end;
    }
    else if (!named || model.edges[edge.named].kind == Edge::Kind::Line)
    {
      point = (1.0 - edge.params[i]) * start + edge.params[i] * end;
    }
    else
    {
      const double fraction = curveReversed ? 1.0 - edge.params[i] : edge.params[i];
      const double t =
        named->arcLength ? named->arcLength->parameterAtFraction(fraction) : fraction;
      point = named->curve->point(t);
    }
    for (int c = 0; c < 3; ++c)
    {
      edge.xyz[3 * i + c] = point[c];
    }
  }
}
} // namespace

void checkModel(const BlockModel& model)
{
  checkBasics(model);
  const std::vector<NamedCurve> curves = buildNamedCurves(model);
  const Topology topology = buildTopology(model, curves, baseNodeCounts(model), false);
  checkNamedEdgesUsed(model, topology);
  const double size = modelSize(model);
  checkOrientation(model, size);
  checkPatches(model, topology, size);
}

struct MultiBlockMesher::Impl
{
  BlockModel Model; // a copy: the mesher may outlive the caller's model
  double Multiplier = 1.0;
  int Cap = 0;
  std::vector<NamedCurve> Curves;
  Topology Topo;
  bool Ready = false;

  std::array<int, 3> nodeCounts(int block) const
  {
    std::array<int, 3> nodes{};
    for (int d = 0; d < 3; ++d)
    {
      const double scaled = std::round(Model.blocks[block].cells[d] * Multiplier);
      int cells = static_cast<int>(std::max(1.0, std::min(scaled, 1.0e6)));
      if (Cap > 0)
      {
        cells = std::min(cells, Cap);
      }
      nodes[d] = cells + 1;
    }
    return nodes;
  }
};

MultiBlockMesher::MultiBlockMesher(const BlockModel& model, double densityMultiplier)
  : P(new Impl)
{
  if (!std::isfinite(densityMultiplier) || !(densityMultiplier > 0.0))
  {
    throw TemplateError(model.sourceFile, 0, entity("model", model.name),
      "the density multiplier must be a positive number, got " +
        formatNumber(densityMultiplier));
  }
  checkModel(model);
  P->Model = model;
  P->Multiplier = densityMultiplier;
  P->Curves = buildNamedCurves(P->Model);
}

MultiBlockMesher::~MultiBlockMesher() = default;

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
  P->Topo = buildTopology(model, P->Curves, nodes, countsChanged);
  for (UniqueEdge& edge : P->Topo.edges)
  {
    computeEdgeNodes(model, P->Curves, edge);
  }
  for (UniqueFace& face : P->Topo.faces)
  {
    const FaceUse& owner = face.uses.front();
    try
    {
      faceFromEdges(model, P->Topo, owner.block, owner.face, face.xyz);
    }
    catch (const GeometryError& error)
    {
      fail(model.blocks[owner.block].where, blockEntity(model, owner.block),
        "face " + faceText(model, owner.block, owner.face) + ": " + error.what());
    }
  }
  P->Ready = true;
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
  const BlockModel& model = P->Model;
  const Topology& topology = P->Topo;
  const BlockLinks& links = topology.blocks[block];

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
    const int na = links.nodes[faceDirections(f)[0]], nb = links.nodes[faceDirections(f)[1]];
    std::vector<double>& grid = faceStorage[f];
    grid.resize(3 * static_cast<std::size_t>(na) * nb);
    for (int b = 0; b < nb; ++b)
    {
      for (int a = 0; a < na; ++a)
      {
        int ownerA = 0, ownerB = 0;
        links.transform[f].map(a, b, face.na, face.nb, ownerA, ownerB);
        std::copy_n(&face.xyz[3 * (static_cast<std::size_t>(ownerB) * face.na + ownerA)], 3,
          &grid[3 * (static_cast<std::size_t>(b) * na + a)]);
      }
    }
    boundary.faces[f] = grid.data();
  }
  std::array<LocalEdge, 12> edges;
  for (int e = 0; e < 12; ++e)
  {
    edges[e] = localEdge(model, topology, block, e);
    boundary.edgeParams[e] = edges[e].params();
  }
  transfiniteBlock(boundary, links.nodes[0], links.nodes[1], links.nodes[2], out);
}
} // namespace model
} // namespace blockforge
