// The control points of a BlockModel and their bounds (ControlProblem's constructor, the
// distribution skews), and the manual moves of control points. Evaluating a set of values is
// in ControlProblem.cpp.
#include "ControlProblemImpl.h"

namespace blockforge
{
namespace optimize
{
using model::BlockModel;
using model::CarrierGeometry;


namespace
{
/// Share of the way to a neighbour a vertex may go: half-way less a margin when the
/// neighbour moves too (they cannot cross), most of the way when it stays.
constexpr double movingNeighbourShare = 0.45;
constexpr double fixedNeighbourShare = 0.9;
/// Parameter step of the boundary test, and its tolerances.
constexpr double probeStep = 1.0e-5;
constexpr double onSurfaceTolerance = 1.0e-7;
constexpr double inPlaneTolerance = 1.0e-6;

[[noreturn]] void failVertex(const model::Vertex& vertex, const std::string& what)
{
  throw model::TemplateError(
    vertex.where.file, vertex.where.line, model::syntax::entity("vertex", vertex.name), what);
}

/// Difference a - b of two parameters, wrapped into (-0.5, 0.5] on closed carriers.
double parameterDifference(double a, double b, bool closed)
{
  double d = a - b;
  if (closed)
  {
    d -= std::floor(d + 0.5);
  }
  return d;
}

std::vector<ThroughPoint> throughPoints(const BlockModel& model)
{
  std::vector<ThroughPoint> found;
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    const model::Carrier& carrier = model.carriers[c];
    if (carrier.kind != model::Carrier::Kind::SurfaceCurve || carrier.refs.empty())
    {
      continue;
    }
    for (std::size_t k = 0; k < carrier.parameterPoints.size(); ++k)
    {
      for (std::size_t v = 0; v < model.vertices.size(); ++v)
      {
        const model::VertexConstraint& constraint = model.vertices[v].constraint;
        if (constraint.carrier == carrier.refs[0] &&
          constraint.s == carrier.parameterPoints[k][0] &&
          constraint.t == carrier.parameterPoints[k][1])
        {
          found.push_back({ static_cast<int>(c), static_cast<int>(k), static_cast<int>(v) });
          break;
        }
      }
    }
  }
  return found;
}

/// Whether carrier `c` is referred to by another carrier (then it cannot be rebuilt alone).
bool referredTo(const BlockModel& model, int c)
{
  for (const model::Carrier& other : model.carriers)
  {
    if (std::find(other.refs.begin(), other.refs.end(), c) != other.refs.end() ||
      std::find(other.crossRefs.begin(), other.crossRefs.end(), c) != other.crossRefs.end())
    {
      return true;
    }
  }
  return false;
}

using model::setParameter;

/// Block vertices adjacent to each vertex along block edges.
std::vector<std::set<int>> edgeNeighbours(const BlockModel& model)
{
  std::vector<std::set<int>> neighbours(model.vertices.size());
  for (const model::Block& block : model.blocks)
  {
    for (int e = 0; e < 12; ++e)
    {
      const std::array<int, 2> ends = model::edgeVertices(e);
      const int a = block.vertices[ends[0]], b = block.vertices[ends[1]];
      if (a != b)
      {
        neighbours[a].insert(b);
        neighbours[b].insert(a);
      }
    }
  }
  return neighbours;
}

/// Every vertex that follows `vertex` (itself included).
std::vector<int> followers(const std::vector<std::vector<int>>& dependents, int vertex)
{
  std::vector<int> result, stack{ vertex };
  std::set<int> seen;
  while (!stack.empty())
  {
    const int v = stack.back();
    stack.pop_back();
    if (!seen.insert(v).second)
    {
      continue;
    }
    result.push_back(v);
    stack.insert(stack.end(), dependents[v].begin(), dependents[v].end());
  }
  return result;
}
} // namespace

ControlProblem::ControlProblem(const BlockModel& model, const CarrierGeometry& geometry,
  double densityMultiplier, const ObjectiveSettings& objective,
  const std::vector<std::string>& fixed, double maximumSkew)
  : P(new Impl)
{
  P->Base = model;
  P->Geometry = geometry;
  // Vertices placed by expressions shift from where those put them at the start.
  model::rebasePlacementExpressions(P->Base, P->Geometry);
  P->Density = densityMultiplier;
  P->Objective = objective;
  const BlockModel& base = P->Base;
  std::set<int> fixedVertices;
  for (std::size_t v = 0; v < base.vertices.size(); ++v)
  {
    if (base.vertices[v].fixed) // marked `fixed: true` in the template
    {
      fixedVertices.insert(static_cast<int>(v));
    }
  }
  for (const std::string& name : fixed)
  {
    const int v = base.findVertex(name);
    if (v < 0)
    {
      throw model::TemplateError(base.sourceFile, 0, model::syntax::entity("vertex", name),
        "FixedControlPoints names a vertex the model does not have");
    }
    fixedVertices.insert(v);
  }
  const int vertexCount = static_cast<int>(base.vertices.size());
  std::vector<char> inBlock(vertexCount, 0);
  for (const model::Block& block : base.blocks)
  {
    for (int v : block.vertices)
    {
      inBlock[v] = 1;
    }
  }
  const std::vector<std::vector<int>> dependents = model::vertexDependents(base);
  // Surface curves drawn through control points follow them, unless other carriers are
  // built on them (then those points stay).
  std::vector<char> drawsCurve(vertexCount, 0);
  for (const ThroughPoint& point : throughPoints(base))
  {
    if (referredTo(base, point.carrier))
    {
      fixedVertices.insert(point.vertex);
      continue;
    }
    P->Through.push_back(point);
    drawsCurve[point.vertex] = 1;
  }
  // Candidates: free parameters of vertices that are not fixed and move a block vertex
  // or a curve drawn through them.
  std::vector<model::FreeParameter> candidates;
  for (const model::FreeParameter& parameter : model::freeParameters(base, P->Geometry))
  {
    if (fixedVertices.count(parameter.vertex))
    {
      continue;
    }
    const std::vector<int> moved = followers(dependents, parameter.vertex);
    if (std::none_of(moved.begin(), moved.end(),
          [&](int v) { return inBlock[v] != 0 || drawsCurve[v] != 0; }))
    {
      continue;
    }
    candidates.push_back(parameter);
  }
  std::vector<std::set<int>> neighbours = edgeNeighbours(base);
  // The points a curve is drawn through are neighbours along it.
  for (const ThroughPoint& a : P->Through)
  {
    for (const ThroughPoint& b : P->Through)
    {
      if (a.carrier == b.carrier && std::abs(a.index - b.index) == 1)
      {
        neighbours[a.vertex].insert(b.vertex);
      }
    }
  }
  const double size = model::modelSize(base);
  // Boundary faces (one block, not periodic) with their surface carrier (-1: none).
  const model::Topology topology = model::buildTopology(base);
  std::set<int> periodicFaces;
  for (const model::PeriodicPair& pair : topology.periodic)
  {
    periodicFaces.insert(pair.source);
    periodicFaces.insert(pair.image);
  }
  std::map<std::pair<int, int>, int> faceCarrier;
  for (const model::SurfaceFaces& set : base.surfaceFaces)
  {
    if (set.followOpposite)
    {
      continue; // not on a carrier
    }
    for (const model::BlockFace& face : set.faces)
    {
      faceCarrier[{ face.block, face.face }] = set.carrier;
    }
  }
  struct BoundaryFace
  {
    std::array<int, 4> ids;
    int carrier;
  };
  std::vector<std::vector<BoundaryFace>> boundaryOf(vertexCount);
  for (std::size_t f = 0; f < topology.faces.size(); ++f)
  {
    const model::TopologyFace& face = topology.faces[f];
    if (face.uses.size() != 1 || periodicFaces.count(static_cast<int>(f)))
    {
      continue;
    }
    const auto found = faceCarrier.find({ face.uses[0].block, face.uses[0].face });
    const BoundaryFace entry{ face.ownerIds, found == faceCarrier.end() ? -1 : found->second };
    std::set<int> corners(face.ownerIds.begin(), face.ownerIds.end());
    for (int v : corners)
    {
      boundaryOf[v].push_back(entry);
    }
  }
  auto staysOnBoundary = [&](const BlockModel& moved, int v) {
    const Vec3 before = base.vertices[v].position, after = moved.vertices[v].position;
    const Vec3 step = after - before;
    if (step.norm() == 0.0)
    {
      return true;
    }
    for (const BoundaryFace& face : boundaryOf[v])
    {
      if (face.carrier >= 0)
      {
        double s = 0.0, t = 0.0, distance = 0.0;
        P->Geometry.project(face.carrier, after, s, t, distance);
        if (distance > onSurfaceTolerance * size)
        {
          return false;
        }
        continue;
      }
      // A face without carrier: its corners must be coplanar and the step in their plane.
      Vec3 normal = Vec3::Zero();
      for (int c = 0; c < 4; ++c)
      {
        const Vec3& p = base.vertices[face.ids[c]].position;
        const Vec3& q = base.vertices[face.ids[(c + 1) % 4]].position;
        normal += (p - q).cross(p + q) * 0.5; // Newell's method
      }
      if (normal.norm() == 0.0)
      {
        return false;
      }
      normal.normalize();
      for (int c = 1; c < 4; ++c)
      {
        const Vec3 d = base.vertices[face.ids[c]].position - base.vertices[face.ids[0]].position;
        if (std::abs(d.dot(normal)) > onSurfaceTolerance * size)
        {
          return false;
        }
      }
      if (std::abs(step.dot(normal)) > inPlaneTolerance * step.norm())
      {
        return false;
      }
    }
    return true;
  };
  // The boundary test: a small step must keep every moved vertex on its boundary faces.
  std::set<std::string> locked;
  std::set<std::pair<int, int>> inert; // (vertex, component) whose step changes nothing
  std::vector<char> carrierEdgeEnd(vertexCount, 0);
  for (const model::Edge& edge : base.edges)
  {
    if (edge.carrier >= 0)
    {
      carrierEdgeEnd[edge.from] = carrierEdgeEnd[edge.to] = 1;
    }
  }
  std::vector<model::FreeParameter> kept;
  std::vector<char> moves(vertexCount, 0); // vertex moves with some kept parameter
  for (const model::FreeParameter& parameter : candidates)
  {
    const int v = parameter.vertex;
    if (fixedVertices.count(v))
    {
      continue;
    }
    const model::VertexConstraint& constraint = base.vertices[v].constraint;
    const double value = parameter.component == 0 ? constraint.s : constraint.t;
    BlockModel probe = base;
    CarrierGeometry probeGeometry = P->Geometry; // curves through the probe are drawn again
    const double step = value + probeStep <= parameter.high || parameter.wraps ? probeStep : -probeStep;
    setParameter(probe, P->Geometry, v, parameter.component, value + step);
    bool keeps = true;
    const std::vector<int> placed = model::applyPlacement(probe, probeGeometry, { v });
    for (int w : placed)
    {
      keeps = keeps && staysOnBoundary(probe, w);
    }
    if (!keeps)
    {
      locked.insert(base.vertices[v].name + (parameter.component == 0 ? ".s" : ".t"));
      continue;
    }
    // A parameter whose step moves no block vertex, no carrier edge end and no curve (a
    // helper vertex outside the blocks, or a vertex its rule places whatever the
    // parameter) changes no grid.
    bool changesNothing = std::all_of(placed.begin(), placed.end(), [&](int w) {
      const model::Vertex &before = base.vertices[w], &after = probe.vertices[w];
      const bool same = after.position == before.position &&
        after.constraint.s == before.constraint.s && after.constraint.t == before.constraint.t;
      return same || (!inBlock[w] && !carrierEdgeEnd[w]);
    });
    for (std::size_t c = 0; changesNothing && c < base.carriers.size(); ++c)
    {
      changesNothing = probe.carriers[c].parameterPoints == base.carriers[c].parameterPoints;
    }
    for (std::size_t e = 0; changesNothing && e < base.edges.size(); ++e)
    {
      changesNothing = probe.edges[e].at == base.edges[e].at;
    }
    if (changesNothing)
    {
      inert.insert({ v, parameter.component });
    }
    kept.push_back(parameter);
    for (int w : followers(dependents, v))
    {
      moves[w] = 1;
    }
  }
  // Bounds: between the neighbours on the carrier.
  for (const model::FreeParameter& parameter : kept)
  {
    const int v = parameter.vertex;
    const model::Vertex& vertex = base.vertices[v];
    const int carrier = vertex.constraint.carrier;
    const int component = parameter.component;
    const bool closed = parameter.wraps;
    const double value = component == 0 ? vertex.constraint.s : vertex.constraint.t;
    // Neighbours on the carrier: parameter offsets towards each side.
    double gapLow = 0.0, gapHigh = 0.0, shareLow = 0.0, shareHigh = 0.0;
    auto consider = [&](int w, double delta) {
      const double share = moves[w] ? movingNeighbourShare : fixedNeighbourShare;
      if (delta < 0.0 && (gapLow == 0.0 || -delta < gapLow))
      {
        gapLow = -delta;
        shareLow = share;
      }
      else if (delta > 0.0 && (gapHigh == 0.0 || delta < gapHigh))
      {
        gapHigh = delta;
        shareHigh = share;
      }
    };
    if (!P->Geometry.isSurface(carrier))
    {
      for (int w = 0; w < vertexCount; ++w)
      {
        if (w != v && inBlock[w] && base.vertices[w].constraint.carrier == carrier)
        {
          consider(w, parameterDifference(base.vertices[w].constraint.s, value, closed));
        }
      }
    }
    else
    {
      // Physical lengths of unit parameter steps, to tell which direction a neighbour is in.
      const double h = 1.0e-6;
      const double s0 = vertex.constraint.s, t0 = vertex.constraint.t;
      const double lengthS =
        (P->Geometry.point(carrier, s0 + h, t0) - P->Geometry.point(carrier, s0 - h, t0)).norm() / (2 * h);
      const double lengthT =
        (P->Geometry.point(carrier, s0, t0 + h) - P->Geometry.point(carrier, s0, t0 - h)).norm() / (2 * h);
      for (int w : neighbours[v])
      {
        double s = 0.0, t = 0.0, distance = 0.0;
        P->Geometry.vertexParameters(base, w, carrier, s, t, distance);
        if (distance > onSurfaceTolerance * size)
        {
          continue;
        }
        const double ds = parameterDifference(s, s0, P->Geometry.closedS(carrier));
        const double dt = parameterDifference(t, t0, P->Geometry.closedT(carrier));
        const double along = component == 0 ? std::abs(ds) * lengthS : std::abs(dt) * lengthT;
        const double across = component == 0 ? std::abs(dt) * lengthT : std::abs(ds) * lengthS;
        if (along >= 0.5 * across)
        {
          consider(w, component == 0 ? ds : dt);
        }
      }
    }
    if (gapLow == 0.0 && gapHigh == 0.0)
    {
      continue; // no neighbour in this direction: nothing to keep it between
    }
    if (gapLow == 0.0)
    {
      gapLow = gapHigh;
      shareLow = shareHigh;
    }
    if (gapHigh == 0.0)
    {
      gapHigh = gapLow;
      shareHigh = shareLow;
    }
    ControlVariable variable;
    variable.vertex = v;
    variable.component = component;
    variable.start = value;
    variable.low = value - shareLow * gapLow;
    variable.high = value + shareHigh * gapHigh;
    if (!closed)
    {
      variable.low = std::max(variable.low, parameter.low);
      variable.high = std::min(variable.high, parameter.high);
    }
    variable.name = vertex.name + (component == 0 ? ".s" : ".t");
    variable.inert = inert.count({ v, component }) > 0;
    if (variable.low < variable.high)
    {
      Variables.push_back(variable);
    }
  }
  // Free interior vertices: block vertices placed by position alone (no carrier, no rule
  // that follows another vertex), on no boundary face and no end of an edge that needs
  // them where they are (carrier edges, arcs), move in x, y and z. On a periodic face only
  // a source moves (its image follows); bounds keep it within 45 % of the way to its
  // nearest block-edge neighbour.
  std::vector<char> onPeriodic(vertexCount, 0);
  for (int f : periodicFaces)
  {
    for (int v : topology.faces[f].ownerIds)
    {
      onPeriodic[v] = 1;
    }
  }
  std::vector<char> edgeEnd(vertexCount, 0);
  for (const model::Edge& edge : base.edges)
  {
    if (edge.kind != model::Edge::Kind::Line && edge.kind != model::Edge::Kind::Spline &&
      edge.kind != model::Edge::Kind::Follow)
    {
      edgeEnd[edge.from] = edgeEnd[edge.to] = 1;
    }
  }
  for (int v = 0; v < vertexCount; ++v)
  {
    const model::Vertex& vertex = base.vertices[v];
    if (!inBlock[v] || fixedVertices.count(v) || vertex.rule.kind != model::VertexRule::Kind::Fixed ||
      vertex.constraint.carrier >= 0 || vertex.constraint.periodicSource >= 0 ||
      !boundaryOf[v].empty() || edgeEnd[v] || neighbours[v].empty())
    {
      continue;
    }
    if (onPeriodic[v] &&
      std::none_of(dependents[v].begin(), dependents[v].end(), [&](int w) {
        return base.vertices[w].rule.kind == model::VertexRule::Kind::Periodic;
      }))
    {
      continue; // a periodic image placed by position: moving it alone breaks periodicity
    }
    double nearest = std::numeric_limits<double>::infinity();
    for (int w : neighbours[v])
    {
      nearest = std::min(nearest, (base.vertices[w].position - vertex.position).norm());
    }
    if (!(nearest > 0.0) || !std::isfinite(nearest))
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      ControlVariable variable;
      variable.vertex = v;
      variable.component = 2 + c;
      variable.start = vertex.position[c];
      variable.low = variable.start - movingNeighbourShare * nearest;
      variable.high = variable.start + movingNeighbourShare * nearest;
      variable.name = vertex.name + "." + "xyz"[c];
      Variables.push_back(variable);
    }
  }
  // Vertices fixed above (surface curve points under other carriers) drop out.
  Variables.erase(std::remove_if(Variables.begin(), Variables.end(),
                    [&](const ControlVariable& v) { return fixedVertices.count(v.vertex) > 0; }),
    Variables.end());
  P->SkewOf.resize(Variables.size());
  if (maximumSkew > 1.0)
  {
    addSkewVariables(topology, periodicFaces, maximumSkew);
  }
  Locked.assign(locked.begin(), locked.end());
  P->Variables = Variables;
  P->VariableBlocks.resize(Variables.size());
}

void ControlProblem::addSkewVariables(
  const model::Topology& topology, const std::set<int>& periodicFaces, double maximumSkew)
{
  const BlockModel& base = P->Base;
  // Edges on periodic faces keep their laws: their images must match them.
  std::set<int> periodicEdges;
  for (int f : periodicFaces)
  {
    const model::FaceUse& use = topology.faces[f].uses.front();
    for (int e : model::faceEdges(use.face))
    {
      periodicEdges.insert(topology.blocks[use.block].edge[e]);
    }
  }
  std::map<int, int> skewedIndex; // topology edge -> SkewedEdges index
  for (std::size_t b = 0; b < base.blocks.size(); ++b)
  {
    for (int d = 0; d < 3; ++d)
    {
      // The direction's edges graded `ends` (in every block using them) are skewed; edges
      // projected from others (project_from) follow their sources; any other law, a
      // collapsed or a periodic edge leaves the direction as it is.
      std::vector<int> edges;
      bool eligible = true;
      for (int e = 0; e < 12 && eligible; ++e)
      {
        if (model::edgeDirection(e) != d)
        {
          continue;
        }
        const int u = topology.blocks[b].edge[e];
        eligible = u >= 0 && !periodicEdges.count(u);
        bool ends = true, projected = true;
        for (std::size_t k = 0; eligible && k < topology.edges[u].uses.size(); ++k)
        {
          const model::EdgeUse& use = topology.edges[u].uses[k];
          const DistributionLaw::Kind kind = base.blocks[use.block].laws[use.localEdge].kind;
          ends = ends && kind == DistributionLaw::Kind::Ends;
          projected = projected && kind == DistributionLaw::Kind::ProjectFrom;
        }
        eligible = eligible && (ends || projected);
        if (eligible && ends)
        {
          edges.push_back(e);
        }
      }
      if (!eligible || edges.empty())
      {
        continue;
      }
      ControlVariable variable;
      variable.component = ControlVariable::SkewComponent;
      variable.block = static_cast<int>(b);
      variable.direction = d;
      variable.start = 0.0;
      variable.low = -std::log(maximumSkew);
      variable.high = std::log(maximumSkew);
      variable.name = base.blocks[b].name + ".skew_" + "ijk"[d];
      std::vector<std::pair<int, int>> changes;
      for (int e : edges)
      {
        const int u = topology.blocks[b].edge[e];
        auto found = skewedIndex.find(u);
        if (found == skewedIndex.end())
        {
          Impl::SkewedEdge skewed;
          skewed.a = topology.edges[u].a;
          skewed.b = topology.edges[u].b;
          skewed.uses = topology.edges[u].uses;
          found = skewedIndex.emplace(u, static_cast<int>(P->SkewedEdges.size())).first;
          P->SkewedEdges.push_back(skewed);
        }
        changes.emplace_back(found->second, topology.blocks[b].reversed[e] ? -1 : 1);
      }
      Variables.push_back(variable);
      P->SkewOf.push_back(changes);
    }
  }
}


void applyMoves(BlockModel& model, CarrierGeometry& geometry,
  const std::vector<ControlPointMove>& moves)
{
  if (moves.empty())
  {
    return;
  }
  model::MeshPlan plan(model, geometry);
  BlockModel& work = plan.model();
  // Vertices placed by expressions land where moved while what they follow stays.
  model::rebasePlacementExpressions(work, plan.carriers());
  std::vector<int> moved;
  for (const ControlPointMove& move : moves)
  {
    const int v = work.findVertex(move.name);
    if (v < 0)
    {
      throw model::TemplateError(model.sourceFile, 0, model::syntax::entity("vertex", move.name),
        "ControlPointMoves names a vertex the model does not have");
    }
    const model::Vertex& vertex = work.vertices[v];
    if (vertex.rule.kind != model::VertexRule::Kind::OnCarrier)
    {
      failVertex(vertex, "is not a control point with free parameters (it follows its placement "
                         "rule), so it cannot be moved by hand");
    }
    const int carrier = vertex.constraint.carrier;
    const std::size_t expected = geometry.isSurface(carrier) ? 2 : 1;
    if (move.parameters.size() != expected)
    {
      failVertex(vertex, "a move on its carrier takes " + std::to_string(expected) +
          (expected == 1 ? " value (s)" : " values (s t)") + ", got " +
          std::to_string(move.parameters.size()));
    }
    for (std::size_t c = 0; c < expected; ++c)
    {
      const double value = move.parameters[c];
      const bool closed = c == 0 ? geometry.closedS(carrier) : geometry.closedT(carrier);
      const double low = c == 0 ? 0.0 : geometry.tMin(carrier);
      const double high = c == 0 ? 1.0 : geometry.tMax(carrier);
      if (!std::isfinite(value) || (!closed && (value < low || value > high)))
      {
        failVertex(vertex, std::string("the moved parameter ") + (c == 0 ? "s" : "t") +
            " is outside its carrier's range");
      }
      setParameter(work, geometry, v, static_cast<int>(c), value);
    }
    moved.push_back(v);
  }
  // Also draws curves through moved points again; the plan follows carrier edges to
  // their moved ends and onto redrawn curves. A move that folds the grid is still the
  // user's move (the mesher reports the fold).
  const std::vector<int> applied = model::applyPlacement(work, plan.carriers(), moved);
  plan.update(applied);
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    if (work.carriers[c].parameterPoints != model.carriers[c].parameterPoints)
    {
      geometry.rebuild(work, static_cast<int>(c));
    }
  }
  model = work;
}

ControlPointMove moveTowards(const BlockModel& model, const CarrierGeometry& geometry,
  const std::string& name, const Vec3& point)
{
  const int v = model.findVertex(name);
  if (v < 0)
  {
    throw model::TemplateError(model.sourceFile, 0, model::syntax::entity("vertex", name),
      "the handle's control point is not a vertex of the model");
  }
  const int carrier = model.vertices[v].constraint.carrier;
  if (carrier < 0 || model.vertices[v].rule.kind != model::VertexRule::Kind::OnCarrier)
  {
    failVertex(model.vertices[v], "is not a control point with free parameters");
  }
  double s = 0.0, t = 0.0, distance = 0.0;
  geometry.project(carrier, point, s, t, distance);
  ControlPointMove move;
  move.name = name;
  move.parameters = { s };
  if (geometry.isSurface(carrier))
  {
    move.parameters.push_back(t);
  }
  return move;
}
} // namespace optimize
} // namespace blockforge
