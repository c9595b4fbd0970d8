#include "Mesher.h"

#include "../Core/BSpline.h"
#include "../Core/Curve.h"
#include "../Core/Parallel.h"
#include "../Core/Projection.h"
#include "../Core/Transfinite.h"
#include "CarrierGeometry.h"
#include "MemoryBudget.h"
#include "ModelSyntax.h"
#include "Topology.h"

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

using syntax::shortNumber;

// -------------------------------------------------------------------- edge geometry
/// The curve of a named edge in its own direction (from -> to), with what it takes to
/// place nodes at arc-length fractions.
struct NamedCurve
{
  CurvePtr curve;
  std::shared_ptr<const ArcLength> arcLength; ///< splines only: arcs are arc-length already
  std::shared_ptr<const ArcLengthTable> lengthTable; ///< curves on carriers
  double length = 0.0;
  int projectOnto = -1; ///< Project: the nodes of the straight line are projected onto it
};

/// A curve moved parallel to itself: base(t) + (1 - t) startShift + t endShift, t the base
/// curve's own parameter (a `follow` edge: the source edge's shape between other ends).
class FollowCurve : public Curve
{
public:
  /// `reversed`: the follow edge runs from the base's end to its start.
  FollowCurve(CurvePtr base, const Vec3& startShift, const Vec3& endShift, bool reversed)
    : Base(std::move(base))
    , StartShift(startShift)
    , EndShift(endShift)
    , Reversed(reversed)
  {
  }
  Vec3 point(double t) const override
  {
    return Base->point(Reversed ? 1.0 - t : t) + (1.0 - t) * StartShift + t * EndShift;
  }
  Vec3 derivative(double t, int order = 1) const override
  {
    const double sign = Reversed && order % 2 == 1 ? -1.0 : 1.0;
    const Vec3 base = sign * Base->derivative(Reversed ? 1.0 - t : t, order);
    return order == 1 ? Vec3(base + EndShift - StartShift) : base;
  }

private:
  CurvePtr Base;
  Vec3 StartShift, EndShift;
  bool Reversed;
};

/// Tolerance of "lies on a carrier": 1e-9 of the larger of the model and the carrier.
double carrierTolerance(const CarrierGeometry& geometry, int carrier, double size)
{
  return 1e-9 * std::max(size, geometry.size(carrier));
}

/// Parameters of `vertex` on `carrier`; GeometryError (ending with `advice`) when the
/// vertex is not on it.
Eigen::Vector2d vertexOnCarrier(const BlockModel& model, const CarrierGeometry& geometry,
  int vertex, int carrier, double size, const std::string& advice)
{
  double s = 0.0, t = 0.0, distance = 0.0;
  geometry.vertexParameters(model, vertex, carrier, s, t, distance);
  if (distance > carrierTolerance(geometry, carrier, size))
  {
    throw GeometryError("vertex '" + model.vertices[vertex].name + "' is not on carrier '" +
      model.carriers[carrier].name + "' (" + shortNumber(distance) + " away); " + advice);
  }
  return Eigen::Vector2d(s, t);
}

/// Parameter(s) of an edge end on the edge's carrier: from `at`, else from the vertex.
Eigen::Vector2d edgeEndParameters(const BlockModel& model, const CarrierGeometry& geometry,
  const Edge& edge, int end, double size)
{
  const int vertex = end == 0 ? edge.from : edge.to;
  const bool surface = edge.kind != Edge::Kind::OnCurve;
  const std::size_t per = surface ? 2 : 1;
  if (edge.at.size() == 2 * per)
  {
    Eigen::Vector2d st(edge.at[end * per], surface ? edge.at[end * per + 1] : 0.0);
    const double distance =
      (geometry.point(edge.carrier, st[0], st[1]) - model.vertices[vertex].position).norm();
    if (distance > carrierTolerance(geometry, edge.carrier, size))
    {
      throw GeometryError("'at' puts its " + std::string(end == 0 ? "first" : "second") +
        " end " + shortNumber(distance) + " away from vertex '" + model.vertices[vertex].name +
        "'");
    }
    return st;
  }
  return vertexOnCarrier(model, geometry, vertex, edge.carrier, size, "attach it to the carrier");
}

NamedCurve buildNamedCurve(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& previous, const Edge& edge, double size)
{
  const Vec3& start = model.vertices[edge.from].position;
  const Vec3& end = model.vertices[edge.to].position;
  NamedCurve named;
  const int carrierCount = static_cast<int>(model.carriers.size());
  if ((edge.kind == Edge::Kind::OnCurve || edge.kind == Edge::Kind::OnSurface ||
        edge.kind == Edge::Kind::Project) &&
    (edge.carrier < 0 || edge.carrier >= carrierCount))
  {
    throw GeometryError("refers to a carrier that does not exist");
  }
  switch (edge.kind)
  {
    case Edge::Kind::OnCurve:
    {
      if (geometry.isSurface(edge.carrier))
      {
        throw GeometryError("carrier '" + model.carriers[edge.carrier].name +
          "' is a surface; on_curve needs a curve");
      }
      const double u0 = edgeEndParameters(model, geometry, edge, 0, size)[0];
      const double u1 = edgeEndParameters(model, geometry, edge, 1, size)[0];
      if (u0 == u1)
      {
        throw GeometryError("both ends are at the same curve parameter");
      }
      named.curve = std::make_shared<SubCurve>(
        geometry.curve(edge.carrier), u0, u1, geometry.closedS(edge.carrier));
      named.lengthTable = std::make_shared<ArcLengthTable>(named.curve);
      named.length = named.lengthTable->totalLength();
      break;
    }
    case Edge::Kind::OnSurface:
    {
      if (!geometry.isSurface(edge.carrier))
      {
        throw GeometryError("carrier '" + model.carriers[edge.carrier].name +
          "' is a curve; on_surface needs a surface");
      }
      const Eigen::Vector2d a = edgeEndParameters(model, geometry, edge, 0, size);
      Eigen::Vector2d b = edgeEndParameters(model, geometry, edge, 1, size);
      // Straight in (s, t) the short way across the seam of a closed direction: a blade
      // edge from s = 0.99 at the hub to s = 0.01 at the shroud (an export that starts
      // its sections at the trailing edge) must not run round the whole blade.
      if (geometry.closedS(edge.carrier))
      {
        b[0] -= std::round(b[0] - a[0]);
      }
      if (geometry.closedT(edge.carrier))
      {
        b[1] -= std::round(b[1] - a[1]);
      }
      named.curve = std::make_shared<ParameterLineCurve>(geometry.surface(edge.carrier), a, b,
        geometry.closedS(edge.carrier), geometry.closedT(edge.carrier),
        geometry.extendsT(edge.carrier));
      named.lengthTable = std::make_shared<ArcLengthTable>(named.curve);
      named.length = named.lengthTable->totalLength();
      break;
    }
    case Edge::Kind::Project:
    {
      named.curve = std::make_shared<LineCurve>(start, end);
      named.length = (end - start).norm();
      named.projectOnto = edge.carrier;
      for (const int vertex : { edge.from, edge.to })
      {
        vertexOnCarrier(model, geometry, vertex, edge.carrier, size,
          "the ends of a projected edge must lie on it");
      }
      break;
    }
    case Edge::Kind::Periodic:
    {
      const int self = static_cast<int>(&edge - model.edges.data());
      if (edge.source < 0 || edge.source >= self)
      {
        throw GeometryError("the source of a periodic edge must be an edge defined before it");
      }
      if (!model.machine.defined || model.machine.bladeCount <= 0)
      {
        throw GeometryError("a periodic edge needs the machine's blade count");
      }
      const Edge& source = model.edges[edge.source];
      const double angle = edge.pitches * model.machine.pitch();
      const double tolerance = 1e-9 * size;
      for (int k = 0; k < 2; ++k)
      {
        const Vertex& image = model.vertices[k == 0 ? edge.from : edge.to];
        const Vertex& original = model.vertices[k == 0 ? source.from : source.to];
        const Vec3 rotated = rotateAboutAxis(
          original.position, model.machine.axisPoint, model.machine.axis, angle);
        const double miss = (rotated - image.position).norm();
        if (miss > tolerance)
        {
          throw GeometryError("vertex '" + image.name + "' is not the image of '" +
            original.name + "' of source edge '" + source.name + "' rotated by " +
            std::to_string(edge.pitches) + " pitch(es) (off by " + shortNumber(miss) + ")");
        }
      }
      named.length = previous[edge.source].length;
      break;
    }
    case Edge::Kind::Follow:
    {
      const int self = static_cast<int>(&edge - model.edges.data());
      if (edge.source < 0 || edge.source >= self)
      {
        throw GeometryError("the source of a follow edge must be an edge defined before it");
      }
      const Edge& source = model.edges[edge.source];
      const NamedCurve& base = previous[edge.source];
      if (!base.curve || base.projectOnto >= 0 || source.kind == Edge::Kind::Periodic ||
        source.kind == Edge::Kind::Follow)
      {
        throw GeometryError("edge '" + source.name +
          "' cannot be followed: follow a line, arc, spline, on_curve or on_surface edge");
      }
      // The follow edge may run either way along its source: its ends go with the
      // source's nearer ends.
      const Vec3& sourceStart = model.vertices[source.from].position;
      const Vec3& sourceEnd = model.vertices[source.to].position;
      const bool reversed = (start - sourceEnd).norm() + (end - sourceStart).norm() <
        (start - sourceStart).norm() + (end - sourceEnd).norm();
      named.curve = reversed
        ? std::make_shared<FollowCurve>(base.curve, start - sourceEnd, end - sourceStart, true)
        : std::make_shared<FollowCurve>(base.curve, start - sourceStart, end - sourceEnd, false);
      named.lengthTable = std::make_shared<ArcLengthTable>(named.curve);
      named.length = named.lengthTable->totalLength();
      break;
    }
    default:
      break;
  }
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
    default:
      break;
  }
  if (!std::isfinite(named.length) || !(named.length > 0.0))
  {
    throw GeometryError("the edge has no length");
  }
  return named;
}

/// Curves of all named edges; GeometryError becomes a TemplateError naming the edge.
std::vector<NamedCurve> buildNamedCurves(const BlockModel& model, const CarrierGeometry& geometry)
{
  std::vector<NamedCurve> curves;
  const double size = modelSize(model);
  for (const Edge& edge : model.edges)
  {
    try
    {
      curves.push_back(buildNamedCurve(model, geometry, curves, edge, size));
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

/**
 * `law` as it applies to `cells` cells when the template gives `templateCells`: a density
 * multiplier or a preview cap refines or coarsens the grid without changing its shape, so
 * graded laws keep their overall expansion (geometric: last over first cell; two-sided:
 * middle over end cell; first cell: its share of the edge). Without this a geometric
 * ratio of 1.15 over 4 times the cells would make the first cell 1.15^18 times thinner
 * (besides 4 times), and thin cells at a curved wall fold.
 */
DistributionLaw refinedLaw(const DistributionLaw& law, int templateCells, int cells)
{
  DistributionLaw refined = law;
  if (cells == templateCells || templateCells < 1 || cells < 1)
  {
    return refined;
  }
  switch (law.kind)
  {
    case DistributionLaw::Kind::Geometric:
      if (templateCells > 1 && cells > 1 && law.expansionRatio > 0.0)
      {
        refined.expansionRatio = std::pow(law.expansionRatio,
          static_cast<double>(templateCells - 1) / static_cast<double>(cells - 1));
      }
      break;
    case DistributionLaw::Kind::TwoSided:
    {
      const int from = (templateCells - 1) / 2, to = (cells - 1) / 2;
      if (from > 0 && to > 0 && law.expansionRatio > 0.0)
      {
        refined.expansionRatio =
          std::pow(law.expansionRatio, static_cast<double>(from) / static_cast<double>(to));
      }
      break;
    }
    case DistributionLaw::Kind::FirstCell:
      refined.firstCellSize = law.firstCellSize * templateCells / cells;
      if (law.expansionRatio > 1.0 && cells > 1 && templateCells > 1)
      {
        refined.expansionRatio = std::pow(law.expansionRatio,
          static_cast<double>(templateCells - 1) / static_cast<double>(cells - 1));
      }
      break;
    default:
      break;
  }
  return refined;
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

// -------------------------------------------------------------------- mesh topology
/// A shared edge with its nodes: parameters in the canonical direction (from the first
/// block that uses it) and coordinates.
struct UniqueEdge : TopologyEdge
{
  double length = 0.0;
  std::vector<double> params;
  std::vector<double> xyz;
};

/// A shared face with its grid, stored in the orientation of its owner.
struct UniqueFace : TopologyFace
{
  std::vector<double> xyz;
};

struct MeshLinks : BlockLinks
{
  std::array<std::vector<double>, 12> collapsedParams; ///< for collapsed edges only
};

/// The model's public topology with what the mesher adds to its edges, faces and blocks.
struct MeshTopology
{
  Topology connectivity;
  std::vector<UniqueEdge> edges;
  std::vector<UniqueFace> faces;
  std::vector<MeshLinks> blocks;
};

/**
 * The topology of the model for the given node counts (buildConnectivity's checks) with
 * the node parameters of every edge, checked on shared edges: the same laws must put the
 * nodes at the same places.
 */
MeshTopology buildMeshTopology(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const std::vector<std::array<int, 3>>& nodes, bool allowFallback)
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
  const int blockCount = static_cast<int>(model.blocks.size());
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
        params = lawParameters(refinedLaw(block.laws[use.localEdge],
                                 block.cells[edgeDirection(use.localEdge)], edge.nodeCount - 1),
          edge.nodeCount, edge.length, allowFallback);
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

void checkOrientation(const BlockModel& model, const std::vector<NamedCurve>& curves, double size)
{
  std::map<std::pair<int, int>, int> named;
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    const Edge& edge = model.edges[e];
    named[{ std::min(edge.from, edge.to), std::max(edge.from, edge.to) }] = static_cast<int>(e);
  }
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
        fail(block.where, blockEntity(model, b),
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
  transfiniteFace(bottom.nodes(), top.nodes(), left.nodes(), right.nodes(), out.data());
}

void computeEdgeNodes(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, UniqueEdge& edge)
{
  const Vec3& start = model.vertices[edge.a].position;
  const Vec3& end = model.vertices[edge.b].position;
  const int n = edge.nodeCount;
  edge.xyz.resize(3 * n);
  const NamedCurve* named = edge.named >= 0 ? &curves[edge.named] : nullptr;
  if (named && model.edges[edge.named].kind == Edge::Kind::Periodic)
  {
    return; // rotated from its source edge afterwards
  }
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
    else if (!named || model.edges[edge.named].kind == Edge::Kind::Line ||
      model.edges[edge.named].kind == Edge::Kind::Project)
    {
      point = (1.0 - edge.params[i]) * start + edge.params[i] * end;
      if (named && named->projectOnto >= 0)
      {
        double s = 0.0, t = 0.0, distance = 0.0;
        geometry.project(named->projectOnto, point, s, t, distance);
        point = geometry.point(named->projectOnto, s, t);
      }
    }
    else
    {
      const double fraction = curveReversed ? 1.0 - edge.params[i] : edge.params[i];
      const double t = named->lengthTable ? named->lengthTable->parameterAtFraction(fraction)
        : named->arcLength                ? named->arcLength->parameterAtFraction(fraction)
                                          : fraction;
      point = named->curve->point(t);
    }
    for (int c = 0; c < 3; ++c)
    {
      edge.xyz[3 * i + c] = point[c];
    }
  }
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
  double difference = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const int along = imageForward ? i : n - 1 - i; // index along imageFrom -> imageTo
    const int sourceIndex = sourceForward ? along : n - 1 - along;
    const double sourceParam =
      sourceForward ? from.params[sourceIndex] : 1.0 - from.params[sourceIndex];
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

/// Named periodic edges: rotated copies of their source edges.
void computePeriodicEdges(const BlockModel& model, MeshTopology& topology)
{
  const auto lookup = edgeLookup(topology);
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
    rotateEdgeNodes(model, topology, sourceEdge, source.from, static_cast<int>(e), named.from,
      model.machine.axisPoint, model.machine.axis, named.pitches * model.machine.pitch(),
      named.where, entity("edge", named.name));
  }
}

/// The edges of every periodic image face: rotations of the source face's edges.
void computePeriodicPatchEdges(const BlockModel& model, MeshTopology& topology)
{
  const auto lookup = edgeLookup(topology);
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
      rotateEdgeNodes(model, topology, source, f0, image, g0, entry.axisPoint, entry.axis,
        entry.angle, patch.where, entity("patch", patch.name));
    }
  }
}

/// Copies the boundary nodes of a face grid from its block's edges (bit for bit).
void copyFaceBoundary(const BlockModel& model, const MeshTopology& topology, int block, int face,
  int na, int nb, std::vector<double>& grid);

/**
 * The surface point closest to `target` near (s, t): Gauss-Newton from there on the
 * surface's own parameters (derivatives by central differences through geometry.point,
 * which wraps closed and extends Gordon carriers), steps limited so the node stays on
 * the part of the surface it started on (a thin trailing edge has another side close by).
 */
void closestNear(const CarrierGeometry& geometry, int carrier, const Vec3& target, double& s,
  double& t)
{
  const double h = 1e-6, largest = 0.02;
  for (int iteration = 0; iteration < 8; ++iteration)
  {
    const Vec3 p = geometry.point(carrier, s, t);
    const Vec3 ps = (geometry.point(carrier, s + h, t) - geometry.point(carrier, s - h, t)) / (2 * h);
    const Vec3 pt = (geometry.point(carrier, s, t + h) - geometry.point(carrier, s, t - h)) / (2 * h);
    const Vec3 r = target - p;
    const double a = ps.dot(ps), b = ps.dot(pt), c = pt.dot(pt);
    const double det = a * c - b * b;
    if (!(det > 0.0) || !std::isfinite(det))
    {
      return;
    }
    double ds = (c * ps.dot(r) - b * pt.dot(r)) / det;
    double dt = (a * pt.dot(r) - b * ps.dot(r)) / det;
    const double step = std::max(std::abs(ds), std::abs(dt));
    if (!std::isfinite(step))
    {
      return;
    }
    if (step > largest)
    {
      ds *= largest / step;
      dt *= largest / step;
    }
    s += ds;
    t = std::clamp(t + dt, geometry.tMin(carrier), geometry.tMax(carrier));
    if (step < 1e-13)
    {
      return;
    }
  }
}

/// Grid of a face that lies on a surface: boundary nodes kept from the edges; each
/// interior node is the surface point closest to the face's 3-D TFI node, searched from
/// the TFI node in the surface's (s, t) space. TFI in (s, t) alone follows the
/// parametrisation, which is far from even on a blade (aligned sections crowd the round
/// edges into small s ranges): at high densities it put nodes behind their neighbours.
void surfaceFace(const BlockModel& model, const MeshTopology& topology, const CarrierGeometry& geometry,
  int carrier, int block, int face, std::vector<double>& out)
{
  const std::array<int, 4> edges = faceEdges(face);
  const LocalEdge bottom = localEdge(model, topology, block, edges[0]);
  const LocalEdge top = localEdge(model, topology, block, edges[1]);
  const LocalEdge left = localEdge(model, topology, block, edges[2]);
  const LocalEdge right = localEdge(model, topology, block, edges[3]);
  const int na = bottom.count, nb = left.count;
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
  for (int k = 0; k < loopSize; ++k)
  {
    double s = 0.0, t = 0.0, distance = 0.0;
    geometry.project(carrier, loop[k], s, t, distance);
    st[k] = Eigen::Vector2d(s, t);
  }
  // Unwrap across the seam of closed directions.
  const bool closed[2] = { geometry.closedS(carrier), geometry.closedT(carrier) };
  for (int k = 1; k < loopSize; ++k)
  {
    for (int d = 0; d < 2; ++d)
    {
      if (!closed[d])
        continue;
      while (st[k][d] - st[k - 1][d] > 0.5)
        st[k][d] -= 1.0;
      while (st[k][d] - st[k - 1][d] < -0.5)
        st[k][d] += 1.0;
    }
  }
  auto fill = [&](int count, auto index) {
    std::vector<double> xyz(3 * count);
    for (int i = 0; i < count; ++i)
    {
      const Eigen::Vector2d& p = st[index(i) % loopSize];
      xyz[3 * i] = p[0];
      xyz[3 * i + 1] = p[1];
      xyz[3 * i + 2] = 0.0;
    }
    return xyz;
  };
  const std::vector<double> pb = fill(na, [&](int a) { return a; });
  const std::vector<double> pr = fill(nb, [&](int b) { return (na - 1) + b; });
  const std::vector<double> pt = fill(na, [&](int a) { return (na - 1) + (nb - 1) + (na - 1 - a); });
  const std::vector<double> pl =
    fill(nb, [&](int b) { return 2 * (na - 1) + (nb - 1) + (nb - 1 - b); });
  std::vector<double> parameters(3 * static_cast<std::size_t>(na) * nb);
  transfiniteFace(EdgeNodes{ pb.data(), bottom.params(), na }, EdgeNodes{ pt.data(), top.params(), na },
    EdgeNodes{ pl.data(), left.params(), nb }, EdgeNodes{ pr.data(), right.params(), nb },
    parameters.data());
  std::vector<double> targets(parameters.size());
  transfiniteFace(bottom.nodes(), top.nodes(), left.nodes(), right.nodes(), targets.data());
  out.resize(parameters.size());
  for (int b = 1; b + 1 < nb; ++b)
  {
    for (int a = 1; a + 1 < na; ++a)
    {
      const std::size_t i = static_cast<std::size_t>(b) * na + a;
      const double s0 = parameters[3 * i], t0 = parameters[3 * i + 1];
      const Vec3 target(targets[3 * i], targets[3 * i + 1], targets[3 * i + 2]);
      double s = s0, t = t0;
      closestNear(geometry, carrier, target, s, t);
      Vec3 p = geometry.point(carrier, s, t);
      const Vec3 p0 = geometry.point(carrier, s0, t0);
      if (!((p - target).norm() <= (p0 - target).norm()))
      {
        p = p0; // no better than the (s, t) node: keep that
      }
      std::copy_n(p.data(), 3, &out[3 * i]);
    }
  }
  copyFaceBoundary(model, topology, block, face, na, nb, out);
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

// -------------------------------------------------------------------- carrier checks
/**
 * Format 2 checks: carriers build; closed Gordon surfaces are closed; every control point
 * lies on its carrier; periodic vertices are rotations of their sources; surface faces
 * name surfaces and their corners lie on them.
 */
void checkCarriers(const BlockModel& model, const CarrierGeometry& geometry, double size)
{
  const int carrierCount = static_cast<int>(model.carriers.size());
  for (const Carrier& carrier : model.carriers)
  {
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
  for (const Vertex& vertex : model.vertices)
  {
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
    if (set.carrier < 0 || set.carrier >= carrierCount || !geometry.isSurface(set.carrier))
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
} // namespace

namespace
{
void checkModelWith(const BlockModel& model, const CarrierGeometry& geometry)
{
  const double size = modelSize(model);
  checkCarriers(model, geometry, size);
  const std::vector<NamedCurve> curves = buildNamedCurves(model, geometry);
  MeshTopology topology = buildMeshTopology(model, curves, baseNodeCounts(model), false);
  checkNamedEdgesUsed(model, topology);
  checkSurfaceFaces(model, geometry, topology, size);
  checkOrientation(model, curves, size);
  checkPatches(model, topology.connectivity);
  findPeriodicPairs(model, topology.connectivity); // the rotated copies must match node for node
}
} // namespace

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
    std::array<int, 3> nodes{};
    for (int d = 0; d < 3; ++d)
    {
      // validated in the constructor: at most MaxScaledCellsPerDirection
      const double scaled = std::round(Model.blocks[block].cells[d] * Multiplier);
      int cells = static_cast<int>(std::max(1.0, scaled));
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
  MeshTopology& topology = P->Topo;
  for (UniqueEdge& edge : topology.edges)
  {
    computeEdgeNodes(model, P->Curves, P->Geometry, edge);
  }
  // Periodic copies: named periodic edges, then the edges and faces of every periodic
  // patch's partner, rotated node for node from the first patch of the pair.
  computePeriodicEdges(model, topology);
  findPeriodicPairs(model, topology.connectivity);
  const std::vector<PeriodicPair>& images = topology.connectivity.periodic;
  computePeriodicPatchEdges(model, topology);
  checkCornerCells(model, topology, modelSize(model));
  std::map<int, const PeriodicPair*> imageOf;
  for (const PeriodicPair& entry : images)
  {
    imageOf[entry.image] = &entry;
  }
  const std::map<int, int> onSurface = surfaceFaceCarriers(model, topology);
  // Faces are computed from their edges alone, each into its own grid: on threads when a
  // runner is installed (Core/Parallel.h), with the same bits, and the error of the first
  // failing face in face order.
  forEachChunk(static_cast<long>(topology.faces.size()), [&](long f) {
    UniqueFace& face = topology.faces[f];
    const FaceUse& owner = face.uses.front();
    if (imageOf.count(static_cast<int>(f)))
    {
      return;
    }
    try
    {
      const auto surface = onSurface.find(static_cast<int>(f));
      if (surface != onSurface.end())
      {
        surfaceFace(model, topology, P->Geometry, surface->second, owner.block, owner.face, face.xyz);
      }
      else
      {
        faceFromEdges(model, topology, owner.block, owner.face, face.xyz);
      }
    }
    catch (const GeometryError& error)
    {
      fail(model.blocks[owner.block].where, blockEntity(model, owner.block),
        "face " + blockFaceText(model, owner.block, owner.face) + ": " + error.what());
    }
  });
  for (const PeriodicPair& entry : images)
  {
    periodicFace(model, topology, entry, topology.faces[entry.image].xyz);
  }
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
  const BlockModel& model = P->Model;
  const MeshTopology& topology = P->Topo;
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
