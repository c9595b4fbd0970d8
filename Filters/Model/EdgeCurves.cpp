#include "MeshInternals.h"

#include "../Core/BSpline.h"
#include "../Core/Carriers.h"
#include "../Core/Curve.h"
#include "../Core/Projection.h"

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

namespace
{
// -------------------------------------------------------------------- edge geometry

/// A curve moved parallel to itself: base(t) + (1 - t) startShift + t endShift, t the base
/// curve's own parameter (a `follow` edge: the source edge's shape between other ends).
class FollowCurve : public Curve
{
public:
  /// `reversed`: the follow edge runs from the base's end to its start. `samples`: first
  /// derivatives of the base already taken (its length table's), or null.
  FollowCurve(CurvePtr base, const Vec3& startShift, const Vec3& endShift, bool reversed,
    std::shared_ptr<const DerivativeSamples> samples = nullptr)
    : Base(std::move(base))
    , StartShift(startShift)
    , EndShift(endShift)
    , Reversed(reversed)
    , Samples(std::move(samples))
  {
  }
  Vec3 point(double t) const override
  {
    return Base->point(Reversed ? 1.0 - t : t) + (1.0 - t) * StartShift + t * EndShift;
  }
  Vec3 derivative(double t, int order = 1) const override
  {
    const double sign = Reversed && order % 2 == 1 ? -1.0 : 1.0;
    if (order == 1 && !Reversed && Samples)
    {
      // the base's derivative taken at this very parameter: the same bits
      std::uint64_t bits = 0;
      std::memcpy(&bits, &t, sizeof(bits));
      const auto found = Samples->find(bits);
      if (found != Samples->end())
      {
        return Vec3(sign * found->second + EndShift - StartShift);
      }
    }
    const Vec3 base = sign * Base->derivative(Reversed ? 1.0 - t : t, order);
    return order == 1 ? Vec3(base + EndShift - StartShift) : base;
  }
  std::vector<double> breakpoints() const override
  {
    std::vector<double> points = Base->breakpoints();
    if (Reversed)
    {
      std::reverse(points.begin(), points.end());
      for (double& b : points)
      {
        b = 1.0 - b;
      }
    }
    return points;
  }

private:
  CurvePtr Base;
  Vec3 StartShift, EndShift;
  bool Reversed;
  std::shared_ptr<const DerivativeSamples> Samples;
};

/// A curve as it is, recording the first derivatives taken while `recording` (a length
/// table being built); afterwards it only passes calls on.
class RecordingCurve : public Curve
{
public:
  explicit RecordingCurve(CurvePtr curve)
    : TheCurve(std::move(curve))
  {
  }
  Vec3 point(double t) const override { return TheCurve->point(t); }
  Vec3 derivative(double t, int order = 1) const override
  {
    const Vec3 value = TheCurve->derivative(t, order);
    if (order == 1 && Recorded)
    {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &t, sizeof(bits));
      Recorded->emplace(bits, value);
    }
    return value;
  }
  void jet(double t, Vec3 out[3]) const override { TheCurve->jet(t, out); }
  std::vector<double> breakpoints() const override { return TheCurve->breakpoints(); }
  /// The derivatives recorded; recording stops (the curve is then used on threads).
  std::shared_ptr<const DerivativeSamples> stop() const
  {
    std::shared_ptr<const DerivativeSamples> samples = std::move(Recorded);
    Recorded.reset();
    return samples;
  }

private:
  CurvePtr TheCurve;
  mutable std::shared_ptr<DerivativeSamples> Recorded = std::make_shared<DerivativeSamples>();
};

/// The length table of `named.curve`, keeping its derivatives when a follow edge follows
/// the edge (`followed`, see followedEdges).
void buildLengthTable(bool followed, NamedCurve& named)
{
  if (!followed)
  {
    named.lengthTable = std::make_shared<ArcLength>(named.curve);
    return;
  }
  const auto recording = std::make_shared<RecordingCurve>(named.curve);
  named.lengthTable = std::make_shared<ArcLength>(recording);
  named.samples = recording->stop();
}
} // namespace

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

std::vector<char> followedEdges(const BlockModel& model)
{
  std::vector<char> followed(model.edges.size(), 0);
  for (const Edge& edge : model.edges)
  {
    if (edge.kind == Edge::Kind::Follow && edge.source >= 0 &&
      edge.source < static_cast<int>(followed.size()))
    {
      followed[edge.source] = 1;
    }
  }
  return followed;
}

NamedCurve buildNamedCurve(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& previous, int index, bool followed, double size)
{
  const Edge& edge = model.edges[index];
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
      // one point (both ends on it): a collapsed edge, all its nodes there
      if (u0 == u1 && start != end)
      {
        throw GeometryError("both ends are at the same curve parameter");
      }
      named.curve = std::make_shared<SubCurve>(
        geometry.curve(edge.carrier), u0, u1, geometry.closedS(edge.carrier));
      // from the carrier's table: the carrier stays while the edge's ends move
      named.lengthTable = std::make_shared<ArcLength>(
        geometry.lengthTable(edge.carrier), u0, u1, geometry.closedS(edge.carrier));
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
      buildLengthTable(followed, named);
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
      if (edge.source < 0 || edge.source >= index)
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
      if (edge.source < 0 || edge.source >= index)
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
        : std::make_shared<FollowCurve>(
            base.curve, start - sourceStart, end - sourceEnd, false, base.samples);
      named.lengthTable = std::make_shared<ArcLength>(named.curve);
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
      buildLengthTable(followed, named);
      named.length = named.lengthTable->totalLength();
      break;
    }
    default:
      break;
  }
  const bool collapsed = named.length == 0.0 && start == end; // on one point (above)
  if (!std::isfinite(named.length) || !(named.length > 0.0 || collapsed))
  {
    throw GeometryError("the edge has no length");
  }
  return named;
}

void followEdgeEnds(
  BlockModel& model, const CarrierGeometry& geometry, int index, const std::vector<char>& movedVertex)
{
  Edge& edge = model.edges[index];
  if (edge.at.empty() || !edge.atExpressions.empty() ||
    (edge.kind != Edge::Kind::OnCurve && edge.kind != Edge::Kind::OnSurface))
  {
    return; // ends given by expressions: the placement evaluates them again
  }
  const bool surface = edge.kind == Edge::Kind::OnSurface;
  const std::size_t per = surface ? 2 : 1;
  if (edge.at.size() != 2 * per)
  {
    return;
  }
  const bool closed[2] = { geometry.closedS(edge.carrier), geometry.closedT(edge.carrier) };
  for (int end = 0; end < 2; ++end)
  {
    const int vertex = end == 0 ? edge.from : edge.to;
    if (!movedVertex[vertex])
    {
      continue;
    }
    double st[2] = { 0.0, 0.0 }, distance = 0.0;
    geometry.vertexParameters(model, vertex, edge.carrier, st[0], st[1], distance);
    for (std::size_t k = 0; k < per; ++k)
    {
      double& at = edge.at[end * per + k];
      if (!closed[k])
      {
        at = st[k];
        continue;
      }
      double change = st[k] - wrapUnit(at);
      change -= std::floor(change + 0.5); // the short way round
      at += change;
    }
  }
}

/// Curves of all named edges; GeometryError becomes a TemplateError naming the edge.
std::vector<NamedCurve> buildNamedCurves(const BlockModel& model, const CarrierGeometry& geometry)
{
  std::vector<NamedCurve> curves;
  const double size = modelSize(model);
  // the carriers' length tables are independent of each other: make them at once
  std::vector<int> tabulated;
  for (const Edge& edge : model.edges)
  {
    if (edge.kind == Edge::Kind::OnCurve && edge.carrier >= 0 &&
      edge.carrier < static_cast<int>(model.carriers.size()) && geometry.curve(edge.carrier) &&
      !geometry.isSurface(edge.carrier))
    {
      tabulated.push_back(edge.carrier);
    }
  }
  std::sort(tabulated.begin(), tabulated.end());
  tabulated.erase(std::unique(tabulated.begin(), tabulated.end()), tabulated.end());
  geometry.prepareLengthTables(tabulated);
  const std::vector<char> followed = followedEdges(model);
  for (std::size_t e = 0; e < model.edges.size(); ++e)
  {
    try
    {
      curves.push_back(
        buildNamedCurve(model, geometry, curves, static_cast<int>(e), followed[e] != 0, size));
    }
    catch (const GeometryError& error)
    {
      fail(model.edges[e].where, entity("edge", model.edges[e].name), error.what());
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

} // namespace model
} // namespace blockforge
