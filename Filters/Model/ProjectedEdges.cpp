// Projected edges (grading law `project_from`): an edge whose interior nodes are the
// closest points on its own curve of the interior nodes of another edge. On a curve that
// is a normal offset of the other edge's curve (an O-grid's outer boundary offset from the
// blade) these are exactly the normal offsets of its nodes, so the lines joining
// corresponding nodes are normal to both curves however the nodes are graded: arc-length
// nodes on the two curves drift apart where the curvature changes, and with cells
// clustered there that drift shears a thin layer inside out.
//
// Also the order in which the mesher computes the node parameters of all edges: graded
// edges, edges projected from them, matched edges (their end cells from the graded and
// projected ones), then edges projected from matched edges.
#include "MeshInternals.h"

#include "../Core/Projection.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace blockforge
{
namespace model
{
using syntax::entity;
using syntax::shortNumber;

namespace
{
/// A projected edge's end run of cells narrower together than this fraction of the next
/// cell is widened to it (feet on a tip; projectEdgeParameters). A 25th: the narrowest
/// that leaves no interpolation-weight face on the compressor's sides at densities 0.5 and
/// 1 (a 30th: 6 faces at 0.5; a 50th: 48 at 1); wider, the sides' cells beside the fans'
/// prisms grow against them (issue 8's neighbour ratio O_le|O_b at density 1: 2.55, 2.93
/// with a 20th).
constexpr double tipFloor = 0.04;

const DistributionLaw& useLaw(const BlockModel& model, const EdgeUse& use)
{
  return model.blocks[use.block].laws[use.localEdge];
}

[[noreturn]] void failOnUse(const BlockModel& model, const EdgeUse& use, const std::string& what)
{
  fail(model.blocks[use.block].where, blockEntity(model, use.block), what);
}

std::string uniqueEdgeText(const BlockModel& model, const UniqueEdge& edge)
{
  return "edge " + edgeText(model, edge.a, edge.b);
}

/// The law of `use` seen along `edge`'s own direction (a -> b).
DistributionLaw lawAlongEdge(const BlockModel& model, const UniqueEdge& edge, const EdgeUse& use)
{
  const int start = model.blocks[use.block].vertices[edgeVertices(use.localEdge)[0]];
  const DistributionLaw& law = useLaw(model, use);
  return start == edge.a ? law : reversedLaw(law);
}

/// The named edge every use of `edge` projects from, -1 when none does; fails when some
/// uses do and others do not, or name different edges.
int projectedSource(const BlockModel& model, const UniqueEdge& edge)
{
  const EdgeUse* projecting = nullptr;
  for (const EdgeUse& use : edge.uses)
  {
    if (useLaw(model, use).kind == DistributionLaw::Kind::ProjectFrom)
    {
      projecting = &use;
      break;
    }
  }
  if (!projecting)
  {
    return -1;
  }
  const int source = useLaw(model, *projecting).sourceEdge;
  for (const EdgeUse& use : edge.uses)
  {
    const DistributionLaw& law = useLaw(model, use);
    if (law.kind != DistributionLaw::Kind::ProjectFrom ||
      lawAlongEdge(model, edge, use) != lawAlongEdge(model, edge, *projecting))
    {
      failOnUse(model, use,
        uniqueEdgeText(model, edge) + " (" + syntax::edgeLabel(use.localEdge) +
          ") takes its nodes from edge '" + model.edges[source].name + "' in block '" +
          model.blocks[projecting->block].name + "': give it the same law {project_from: " +
          model.edges[source].name + "} here (with the same fade)");
    }
  }
  return source;
}

/// Two projected edges that continue one another through a vertex V (a blade corner)
/// whose sources continue one another through the corresponding vertex S (an O corner),
/// with the edge V-S between them (the radial edge at the corner).
struct FootJoin
{
  int edge[2];   ///< unique edges
  int end[2];    ///< 0: at the edge's vertex a, 1: at b
  int radial;    ///< unique edge V-S
  int vertex;    ///< V
};

/// The feet's widths at a blade corner are held within this ratio (below).
constexpr double FootWidthRatio = 1.2;
/// ... and the cut foot's wall cell stays within this of the next one (or their ratio).
constexpr double InBlockRatio = 2.0;

int sourceEndVertex(const BlockModel& model, const MeshTopology& topology, int u, int end)
{
  const UniqueEdge& edge = topology.edges[u];
  const UniqueEdge& source = topology.edges[edge.projectedFrom];
  const bool crossed = runsAgainst(model, edge, source);
  return (end == 0) != crossed ? source.a : source.b;
}

std::vector<FootJoin> footJoins(const BlockModel& model, const MeshTopology& topology)
{
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> ends; // (V, S) -> (edge, end)
  std::map<std::pair<int, int>, int> byVertices;
  for (int u = 0; u < static_cast<int>(topology.edges.size()); ++u)
  {
    const UniqueEdge& edge = topology.edges[u];
    byVertices[{ std::min(edge.a, edge.b), std::max(edge.a, edge.b) }] = u;
  }
  const auto joined = [&](int v, int s) {
    return byVertices.count({ std::min(v, s), std::max(v, s) }) > 0;
  };
  for (int u = 0; u < static_cast<int>(topology.edges.size()); ++u)
  {
    const UniqueEdge& edge = topology.edges[u];
    if (edge.projectedFrom < 0 || edge.a == edge.b)
    {
      continue;
    }
    // a collapsed edge (its ends one point: a fan's feet on a sharp tip) cannot tell by
    // position which source end is whose: the one joined to its vertex by an edge
    const UniqueEdge& source = topology.edges[edge.projectedFrom];
    const bool collapsed = model.vertices[edge.a].position == model.vertices[edge.b].position;
    for (int end = 0; end < 2; ++end)
    {
      const int v = end == 0 ? edge.a : edge.b;
      int s = sourceEndVertex(model, topology, u, end);
      const int other = s == source.a ? source.b : source.a;
      if (collapsed && !joined(v, s) && joined(v, other))
      {
        s = other;
      }
      ends[{ v, s }].push_back({ u, end });
    }
  }
  std::vector<FootJoin> joins;
  for (const auto& [key, members] : ends)
  {
    const auto radial = byVertices.find({ std::min(key.first, key.second), std::max(key.first, key.second) });
    if (members.size() != 2 || members[0].first == members[1].first || key.first == key.second ||
      radial == byVertices.end())
    {
      continue;
    }
    joins.push_back(FootJoin{ { members[0].first, members[1].first },
      { members[0].second, members[1].second }, radial->second, key.first });
  }
  return joins;
}

/// Beside a fan (gradeBesideFan): the side's first wall cell at most this many times the
/// fan's, across the interface (the neighbour size ratio, issue 8's 1.5 with a margin for
/// the estimate); its next wall cells grow by at most FanSideGrowth (MeshInternals.h).
constexpr double FanSideRatio = 1.35;


/// The end cell length of `edge` at vertex `v` (one of its ends).
double cellAtVertex(const UniqueEdge& edge, int v)
{
  return endCell(edge, edge.a == v ? 0 : 1);
}

/**
 * The feet of a projected edge graded up from its end at a blade corner: its first wall
 * cell (measured as joinFeet measures it, foot (1 - layer) + outer cell layer) is
 * `firstWidth`, the next ones grow by a common factor of at most `growth` (never
 * shrinking) until they land on a projected foot M, which is kept from there on with the
 * feet after it: the smallest M within half the edge for which such a factor exists and
 * the projected cell after M is within `growth` of cell M. `fromA`: the corner is the
 * edge's vertex a; `sourceFromA`: it is the source's vertex a (the O corner's side).
 * Returns false, leaving the edge as it was, where no such M exists.
 */
bool rampFeet(UniqueEdge& edge, const UniqueEdge& source, bool fromA, bool sourceFromA,
  double layer, double firstWidth, double growth)
{
  const int cells = static_cast<int>(edge.params.size()) - 1;
  if (cells < 3 || source.params.size() != edge.params.size() || !(layer > 0.0 && layer < 0.5))
  {
    return false;
  }
  // lengths from the corner: the edge's feet as projected (P) and its outer cells
  std::vector<double> P(cells + 1), outer(cells + 1, 0.0);
  for (int m = 0; m <= cells; ++m)
  {
    P[m] = edge.length * (fromA ? edge.params[m] : 1.0 - edge.params[cells - m]);
    if (m > 0)
    {
      const std::vector<double>& q = source.params;
      outer[m] = source.length *
        (sourceFromA ? q[m] - q[m - 1] : q[cells - m + 1] - q[cells - m]);
    }
  }
  const double first = (firstWidth - outer[1] * layer) / (1.0 - layer);
  if (!(first > 0.0))
  {
    return false; // the outer cells differ more than that
  }
  const auto widthOf = [&](double foot, int k) { return foot * (1.0 - layer) + outer[k] * layer; };
  const double startWidth = widthOf(first, 1);
  std::vector<double> Q(cells + 1, 0.0);
  const auto fill = [&](double g, int last) { // Q[1..last] for factor g; returns Q[last]
    double foot = first, width = startWidth;
    Q[1] = first;
    for (int k = 2; k <= last; ++k)
    {
      width *= g;
      foot = std::max((width - outer[k] * layer) / (1.0 - layer), foot);
      Q[k] = Q[k - 1] + foot;
    }
    return Q[last];
  };
  // smooth[k]: the projected wall cells from k to the middle of the edge grow by at most
  // `growth` from cell to cell (feet still on a tip are not)
  const int half = cells / 2;
  std::vector<char> smooth(cells + 2, 1);
  for (int k = half; k >= 1; --k)
  {
    smooth[k] = smooth[k + 1] &&
      widthOf(P[k + 1] - P[k], k + 1) <= growth * widthOf(P[k] - P[k - 1], k);
  }
  int m = 2;
  for (; m <= half; ++m)
  {
    if (!smooth[m] || !(fill(1.0, m) <= P[m]) || !(fill(growth, m) >= P[m]))
    {
      continue;
    }
    double low = 1.0, high = growth;
    for (int round = 0; round < 60; ++round)
    {
      const double g = 0.5 * (low + high);
      (fill(g, m) < P[m] ? low : high) = g;
    }
    fill(high, m);
    if (P[m] > Q[m - 1] &&
      widthOf(P[m + 1] - P[m], m + 1) <= growth * widthOf(P[m] - Q[m - 1], m))
    {
      break;
    }
  }
  if (m > half)
  {
    return false; // not reached within half the edge: left as projected
  }
  std::vector<double>& p = edge.params;
  for (int k = 1; k < m; ++k)
  {
    if (fromA)
    {
      p[k] = Q[k] / edge.length;
    }
    else
    {
      p[cells - k] = 1.0 - Q[k] / edge.length;
    }
  }
  return true;
}

/**
 * The feet of a side beside a fan whose feet are one point (FootJoin with one edge
 * collapsed: axial_passage_oh's prisms on a sharp tip). The wall cells are measured as
 * joinFeet measures them: the fan's is e + (o - e) h / W with e = 0, a sliver of its outer
 * cell o. The side's first outer node past the fan still lies on the O curve's arc round
 * the tip, so its foot is the tip too (widened there to a 25th of the next cell), and its
 * second on the flank, its foot as long as its outer cell: the side's first wall cell was
 * 2.5-3.5 times the fan's (the compressor's O_le|O_b at densities 0.5-4), and the next
 * 16-25 times that. Here the side's first foot is cut to FanSideRatio times the fan's wall
 * cell, the next ones grow from it by at most FanSideGrowth per cell (their outer cells
 * counted as above) until they reach the projected feet, which are kept from there on
 * (rampFeet). The radial lines of the cells in between lean towards the tip (round a sharp
 * tip the normal of a point on the O curve's arc has its foot on the tip, so those have no
 * orthogonal foot).
 */
void gradeBesideFan(MeshTopology& topology, const FootJoin& join, int fan)
{
  const int side = 1 - fan;
  UniqueEdge& edge = topology.edges[join.edge[side]];
  const UniqueEdge& radial = topology.edges[join.radial];
  const int outerVertex = radial.a == join.vertex ? radial.b : radial.a;
  const UniqueEdge& fanSource = topology.edges[topology.edges[join.edge[fan]].projectedFrom];
  const UniqueEdge& source = topology.edges[edge.projectedFrom];
  if ((fanSource.a != outerVertex && fanSource.b != outerVertex) ||
    (source.a != outerVertex && source.b != outerVertex))
  {
    return;
  }
  // (rampFeet leaves the edge as it is for too few cells or a layer outside (0, 0.5))
  const double layer = cellAtVertex(radial, join.vertex) / radial.length / 2;
  const double fanWidth = cellAtVertex(fanSource, outerVertex) * layer;
  rampFeet(edge, source, join.end[side] == 0, source.a == outerVertex, layer,
    FanSideRatio * fanWidth, FanSideGrowth);
}

/**
 * The feet at a blade corner (FootJoin): the wall cells on both sides of the radial edge
 * there are measured as the neighbour size ratio measures them, the mean of the foot (the
 * projected edge's end cell e) and the first layer's line, estimated as e + (o - e) h / W
 * (o the source's end cell, h and W the radial edge's first cell and length). Where the
 * larger of the two is more than FootWidthRatio times the other, its foot is cut down to
 * that ratio (not below the other foot), the cells after it taking the length it gives up
 * in equal parts (up to four cells, never the other end's). Why: a foot is where the normal
 * of its outer node meets the blade, and at a corner whose radial edge starts on a fan (a
 * sharp tip, a thin edge) the fan's feet sit on the tip while the side's first outer node,
 * past the fan, has its foot on the flank: the compressor's side cells at the wall were
 * 3.4 times the fan's at density 0.5; round a cap's corner the smoothed O curve's normals
 * spread the feet on one side (turbine 1.6). Only the larger foot moves: the fan's feet
 * cannot spread (they share the tip), and the moved foot's radial line leans by its shift
 * over the O-grid's width. Where the cut is held (by InBlockRatio against its next cell)
 * above FanSideRatio times the other side's cell, the feet are graded up from the corner
 * instead, as beside a fan (rampFeet).
 */
void joinFeet(const BlockModel& model, MeshTopology& topology, const FootJoin& join)
{
  UniqueEdge* edges[2] = { &topology.edges[join.edge[0]], &topology.edges[join.edge[1]] };
  const UniqueEdge& radial = topology.edges[join.radial];
  if (radial.params.size() < 2 || !(radial.length > 0.0))
  {
    return;
  }
  // A fan whose feet are one point (its blade arc collapsed, axial_passage_oh's prisms on a
  // sharp tip) has no wall width to join: cut to it, the side's first foot would vanish
  // and fold the block at the corner. The side's feet are graded up from the fan's instead.
  if (!(edges[0]->length > 0.0) != !(edges[1]->length > 0.0))
  {
    gradeBesideFan(topology, join, edges[0]->length > 0.0 ? 1 : 0);
    return;
  }
  if (!(edges[0]->length > 0.0) || !(edges[1]->length > 0.0))
  {
    return;
  }
  const double layer = endCell(radial, radial.a == join.vertex ? 0 : 1) / radial.length / 2;
  double foot[2], outer[2], width[2];
  for (int k = 0; k < 2; ++k)
  {
    foot[k] = endCell(*edges[k], join.end[k]);
    const UniqueEdge& source = topology.edges[edges[k]->projectedFrom];
    const bool crossed = runsAgainst(model, *edges[k], source);
    outer[k] = endCell(source, crossed ? 1 - join.end[k] : join.end[k]);
    width[k] = foot[k] + (outer[k] - foot[k]) * layer;
  }
  const int large = width[0] > width[1] ? 0 : 1, small = 1 - large;
  if (!(width[large] > FootWidthRatio * width[small]))
  {
    return;
  }
  UniqueEdge& edge = *edges[large];
  const int cells = static_cast<int>(edge.params.size()) - 1;
  if (cells < 3 || !(edge.length > 0.0))
  {
    return;
  }
  const int spread = std::min(3, (cells - 2) / 2); // the cells after the foot that share
  // The cut foot's wall cell against the next one inside its edge (which grows by its
  // share): at most the ratio they had, or InBlockRatio if that is more. Why: next to a
  // fan on a sharp tip the side's second foot is on the flank, tens of times the first
  // (the compressor's wall cells there 24 times at density 1); cut further, the faces
  // between them fall under checkMesh's interpolation weight (26 -> 48 faces optimized).
  const UniqueEdge& source = topology.edges[edge.projectedFrom];
  const bool crossed = runsAgainst(model, edge, source);
  const int second = join.end[large] == 0 ? 1 : cells - 2; // the next cell's first node
  const std::vector<double>& q = source.params;
  const double nextFoot = edge.length * (edge.params[second + 1] - edge.params[second]);
  const int sourceSecond = (join.end[large] == 0) != crossed ? 1 : cells - 2;
  const double nextOuter = source.length * (q[sourceSecond + 1] - q[sourceSecond]);
  const double nextWidth = nextFoot + (nextOuter - nextFoot) * layer;
  const double allowed = std::max(InBlockRatio, nextWidth / width[large]);
  const double share = (1.0 - layer) / (spread + 1);
  const double floor = (nextWidth + foot[large] * share - allowed * outer[large] * layer) /
    ((1.0 - layer) * allowed + share);
  const double wanted = std::max(std::max(foot[small], floor),
    (FootWidthRatio * width[small] - outer[large] * layer) / (1.0 - layer));
  // Held by that floor above FanSideRatio times the other side's cell (the next cell
  // inside as long as the foot), the one cut leaves the jump at the interface: the
  // turbine's side a at its cap's corner, where the O corner's foot lies 0.06-0.09 mm
  // before the corner, whatever the density, and the edge block's first wall cell is that
  // piece of flank (O_a|O_te 2.17 / 1.68 / 1.57 at densities 0.5 / 1 / 2, the side's
  // foot cut to half its next cell; 6.3 in the optimized grid, whose corner slides nearer
  // the cap's corner). There the feet are graded up as beside a fan (rampFeet:
  // FanSideRatio times the other side's cell, growing by at most FanSideGrowth, within
  // checkMesh's interpolation weight, until they land on the projected feet; O_a|O_te
  // 1.36 / 1.35 / 1.35). Not to FootWidthRatio: thinner, the cut wall cell fails
  // checkMesh's determinant (one more cell at density 1); nor slower than FanSideGrowth:
  // the longer ramp leans more radial lines (growth 4: the min scaled Jacobian at density
  // 0.5 0.209 -> 0.148).
  const double reached = wanted * (1.0 - layer) + outer[large] * layer;
  const int outerVertex = radial.a == join.vertex ? radial.b : radial.a;
  if (reached > FanSideRatio * width[small] && (source.a == outerVertex || source.b == outerVertex) &&
    rampFeet(edge, source, join.end[large] == 0, source.a == outerVertex, layer,
      FanSideRatio * width[small], FanSideGrowth))
  {
    return;
  }
  if (!(wanted < foot[large]))
  {
    return;
  }
  const double given = (foot[large] - wanted) / edge.length;
  std::vector<double>& p = edge.params;
  for (int k = 1; k <= spread + 1; ++k)
  {
    const double shift = given * (spread + 2 - k) / (spread + 1);
    if (join.end[large] == 0)
    {
      p[k] -= shift;
    }
    else
    {
      p[cells - k] += shift;
    }
  }
}
} // namespace

bool runsAgainst(const BlockModel& model, const UniqueEdge& edge, const UniqueEdge& source)
{
  const Vec3& start = model.vertices[edge.a].position;
  const Vec3& end = model.vertices[edge.b].position;
  const Vec3& sourceStart = model.vertices[source.a].position;
  const Vec3& sourceEnd = model.vertices[source.b].position;
  return (start - sourceEnd).norm() + (end - sourceStart).norm() <
    (start - sourceStart).norm() + (end - sourceEnd).norm();
}

void buildProjections(const BlockModel& model, MeshTopology& topology)
{
  topology.projectionOrder.clear();
  std::vector<int> namedUnique(model.edges.size(), -1);
  for (std::size_t u = 0; u < topology.edges.size(); ++u)
  {
    if (topology.edges[u].named >= 0)
    {
      namedUnique[topology.edges[u].named] = static_cast<int>(u);
    }
  }
  bool any = false;
  for (UniqueEdge& edge : topology.edges)
  {
    edge.projectedFrom = -1;
    edge.projectedAfterMatch = false;
    const int source = projectedSource(model, edge);
    if (source < 0)
    {
      continue;
    }
    any = true;
    const EdgeUse& use = edge.uses.front();
    const Edge& sourceEdge = model.edges[source];
    if (namedUnique[source] < 0)
    {
      failOnUse(model, use,
        uniqueEdgeText(model, edge) + ": project_from: edge '" + sourceEdge.name +
          "' is not an edge of any block");
    }
    if (sourceEdge.kind == Edge::Kind::Periodic)
    {
      failOnUse(model, use,
        uniqueEdgeText(model, edge) + ": project_from: edge '" + sourceEdge.name +
          "' is a periodic copy; project from the edge it copies");
    }
    if (edge.named >= 0 &&
      (model.edges[edge.named].kind == Edge::Kind::Periodic ||
        model.edges[edge.named].kind == Edge::Kind::Project))
    {
      failOnUse(model, use,
        uniqueEdgeText(model, edge) + ": project_from needs an edge with a curve of its own "
          "(line, arc, spline, on_curve, on_surface or follow), not a " +
          edgeKindNames()[static_cast<int>(model.edges[edge.named].kind)] + " edge");
    }
    edge.projectedFrom = namedUnique[source];
  }
  if (!any)
  {
    return;
  }
  // Sources first (depth-first); a chain that comes back to itself is a cycle.
  std::vector<char> state(topology.edges.size(), 0); // 1: on the chain, 2: ordered
  for (std::size_t start = 0; start < topology.edges.size(); ++start)
  {
    if (topology.edges[start].projectedFrom < 0 || state[start] == 2)
    {
      continue;
    }
    std::vector<int> chain;
    int u = static_cast<int>(start);
    while (u >= 0 && topology.edges[u].projectedFrom >= 0 && state[u] == 0)
    {
      state[u] = 1;
      chain.push_back(u);
      u = topology.edges[u].projectedFrom;
    }
    if (u >= 0 && state[u] == 1)
    {
      std::string names;
      const auto first = std::find(chain.begin(), chain.end(), u);
      for (auto it = first; it != chain.end(); ++it)
      {
        names += edgeText(model, topology.edges[*it].a, topology.edges[*it].b) + " -> ";
      }
      names += edgeText(model, topology.edges[u].a, topology.edges[u].b);
      failOnUse(model, topology.edges[u].uses.front(),
        "edges " + names + " take their nodes from one another (project_from): give one of "
          "them another law");
    }
    // the root: a graded or matched edge, or a projected edge ordered before
    const bool afterMatch = topology.edges[u].matched || topology.edges[u].projectedAfterMatch;
    for (auto it = chain.rbegin(); it != chain.rend(); ++it)
    {
      topology.edges[*it].projectedAfterMatch = afterMatch;
      topology.projectionOrder.push_back(*it);
      state[*it] = 2;
    }
  }
  joinProjectedMatchEnds(model, topology);
}

void projectEdgeParameters(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, MeshTopology& topology, int e)
{
  UniqueEdge& edge = topology.edges[e];
  const UniqueEdge& source = topology.edges[edge.projectedFrom];
  const EdgeUse& use = edge.uses.front();
  const int n = edge.nodeCount;
  const std::string names = uniqueEdgeText(model, edge) + " takes its nodes from " +
    uniqueEdgeText(model, source) + " (project_from)";
  if (source.nodeCount != n)
  {
    failOnUse(model, use,
      names + ", but has " + std::to_string(n - 1) + " cells against its " +
        std::to_string(source.nodeCount - 1) + "; give both the same cell count");
  }
  // The target's curve in its canonical direction (a -> b) as computeEdgeNodes places
  // nodes on it: arc-length fractions, a named curve possibly running b -> a.
  const NamedCurve* named = edge.named >= 0 ? &curves[edge.named] : nullptr;
  const Vec3& start = model.vertices[edge.a].position;
  const Vec3& end = model.vertices[edge.b].position;
  const bool curveReversed = named && model.edges[edge.named].from != edge.a;
  std::shared_ptr<const CurveProjector> kept = named ? named->projector : nullptr;
  if (!kept)
  {
    kept = std::make_shared<const CurveProjector>(
      named ? named->curve : std::make_shared<LineCurve>(start, end));
    if (named)
    {
      named->projector = kept;
    }
  }
  const CurveProjector& projector = *kept;
  const bool crossed = runsAgainst(model, edge, source);
  std::vector<double> params(n, 0.0);
  params[n - 1] = 1.0;
  if (start == end && (!named || named->length == 0.0))
  {
    // A collapsed edge (its ends one point, e.g. a fan's blade arc on a sharp tip): every
    // node is that point, whatever the parameters; they stay evenly spread.
    for (int i = 1; i < n - 1; ++i)
    {
      params[i] = static_cast<double>(i) / (n - 1);
    }
    edge.params = std::move(params);
    return;
  }
  std::vector<Vec3> feet(n), outer(n);
  feet[0] = start;
  feet[n - 1] = end;
  outer[0] = edgeNodePoint(model, curves, geometry, source, crossed ? n - 1 : 0);
  outer[n - 1] = edgeNodePoint(model, curves, geometry, source, crossed ? 0 : n - 1);
  for (int i = 1; i < n - 1; ++i)
  {
    const Vec3 node = edgeNodePoint(model, curves, geometry, source, crossed ? n - 1 - i : i);
    const CurveProjection foot = projector.project(node);
    const double t = foot.t;
    outer[i] = node;
    feet[i] = foot.point;
    double fraction = named && named->lengthTable
      ? named->lengthTable->lengthAt(t) / named->lengthTable->totalLength()
      : t;
    params[i] = curveReversed ? 1.0 - fraction : fraction;
    if (!(params[i] > params[i - 1]) || !(params[i] < 1.0))
    {
      failOnUse(model, use,
        names + ", but the projection of node " + std::to_string(i) +
          " is not between those of its neighbours (at " + shortNumber(params[i]) +
          " of the edge): the edges are too far apart or too differently curved for their "
          "nodes to project in order");
    }
  }
  // Feet on a tip: where an O corner's radial line starts on a sharp tip (a fan), the
  // source's nodes next to it may still lie on the O curve's arc round the tip, so their
  // feet are the tip too, 1e-7-1e-5 of the edge from its end, beside a next cell of a
  // hundredth of it: a sliver (the compressor's sides: checkMesh's interpolation weight
  // failed between it and the next cell, and it folded at density 2). Such an end run,
  // narrower together than tipFloor of the cell after it, is widened to tipFloor of it
  // (each of its cells tipFloor of the one after): wide enough for the mesher and checkMesh,
  // narrow enough that the edge block's fan beside it (its wall cells shrink to the tip)
  // stays within a few times its size.
  const auto widenTip = [&](auto at, auto set) {
    int m = 1;
    while (m + 1 < n - 1 && at(m) < tipFloor * (at(m + 1) - at(m)))
    {
      ++m;
    }
    double node = at(m);
    for (int i = m - 1; i >= 1; --i)
    {
      node *= tipFloor;
      set(i, node);
    }
  };
  widenTip([&](int i) { return params[i]; }, [&](int i, double v) { params[i] = v; });
  widenTip([&](int i) { return 1.0 - params[n - 1 - i]; },
    [&](int i, double v) { params[n - 1 - i] = 1.0 - v; });
  // Feet bunched on a convex corner inside the edge (a cap's corner): spread round it.
  spreadFootBunches(params, feet, outer);
  const DistributionLaw law = lawAlongEdge(model, edge, use);
  if (law.fadeStart > 0.0 || law.fadeEnd > 0.0)
  {
    // Where an end vertex is not the projection of the source's end vertex, the nodes near
    // it move towards it: by the whole shift at the end, less farther in (smoothstep over
    // fade times the shift), so the end cell keeps its projected length.
    const auto fractionOf = [&](const Vec3& point) {
      const double t = projector.project(point).t;
      const double fraction = named && named->lengthTable
        ? named->lengthTable->lengthAt(t) / named->lengthTable->totalLength()
        : t;
      return curveReversed ? 1.0 - fraction : fraction;
    };
    const double startShift = law.fadeStart > 0.0
      ? -fractionOf(edgeNodePoint(model, curves, geometry, source, crossed ? n - 1 : 0))
      : 0.0;
    const double endShift = law.fadeEnd > 0.0
      ? 1.0 - fractionOf(edgeNodePoint(model, curves, geometry, source, crossed ? 0 : n - 1))
      : 0.0;
    const auto smoothstep = [](double x) {
      return x <= 0.0 ? 1.0 : x >= 1.0 ? 0.0 : 1.0 - x * x * (3.0 - 2.0 * x);
    };
    for (int i = 1; i < n - 1; ++i)
    {
      const double f = params[i];
      double moved = f;
      if (startShift != 0.0)
      {
        moved +=
          startShift * smoothstep((f + startShift) / (law.fadeStart * std::abs(startShift)));
      }
      if (endShift != 0.0)
      {
        moved +=
          endShift * smoothstep((1.0 - endShift - f) / (law.fadeEnd * std::abs(endShift)));
      }
      params[i] = moved;
    }
    for (int i = 1; i < n; ++i)
    {
      if (!(params[i] > params[i - 1]))
      {
        failOnUse(model, use,
          names + ", but its nodes " + std::to_string(i - 1) + " and " + std::to_string(i) +
            " come out of order once the end shifts are faded in (fade " +
            shortNumber(law.fadeStart) + ", " + shortNumber(law.fadeEnd) + "): give a larger fade");
      }
    }
  }
  edge.params = std::move(params);
}

void computeEdgeGrading(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, MeshTopology& topology, std::vector<char>* changed,
  bool allowFallback)
{
  const auto isChanged = [&](int u) { return !changed || (*changed)[u]; };
  // Feet joined at blade corners (joinFeet), from the projections as they came (kept in
  // projectedParams): where anything a join reads changed, every edge of its chain of joins
  // restarts from its projection and the chain's joins are made again, so that the nodes
  // are a full run's; an edge whose nodes come out different is marked changed.
  const std::vector<FootJoin> joins =
    topology.projectionOrder.empty() ? std::vector<FootJoin>() : footJoins(model, topology);
  std::vector<int> chain(topology.edges.size());
  std::iota(chain.begin(), chain.end(), 0);
  const auto chainOf = [&](int u) {
    while (chain[u] != u)
    {
      u = chain[u] = chain[chain[u]];
    }
    return u;
  };
  for (const FootJoin& join : joins)
  {
    chain[chainOf(join.edge[0])] = chainOf(join.edge[1]);
  }
  const auto project = [&](bool afterMatch) {
    for (const int u : topology.projectionOrder)
    {
      UniqueEdge& edge = topology.edges[u];
      if (edge.projectedAfterMatch != afterMatch ||
        !(isChanged(u) || isChanged(edge.projectedFrom)))
      {
        continue;
      }
      if (changed)
      {
        (*changed)[u] = 1;
      }
      projectEdgeParameters(model, curves, geometry, topology, u);
      edge.projectedParams = edge.params;
    }
    // the joins of this pass: both edges projected in it, and before the matched edges only
    // where the radial edge's nodes are there already
    std::vector<char> redo(topology.edges.size(), 0);
    std::vector<const FootJoin*> pass;
    for (const FootJoin& join : joins)
    {
      const UniqueEdge& first = topology.edges[join.edge[0]];
      const UniqueEdge& second = topology.edges[join.edge[1]];
      const UniqueEdge& radial = topology.edges[join.radial];
      if (first.projectedAfterMatch != afterMatch || second.projectedAfterMatch != afterMatch ||
        !(afterMatch || (!radial.matched && radial.projectedFrom < 0)))
      {
        continue;
      }
      pass.push_back(&join);
      if (isChanged(join.edge[0]) || isChanged(join.edge[1]) || isChanged(first.projectedFrom) ||
        isChanged(second.projectedFrom) || isChanged(join.radial))
      {
        redo[chainOf(join.edge[0])] = 1;
      }
    }
    std::vector<std::vector<double>> before(topology.edges.size());
    for (const FootJoin* join : pass)
    {
      for (const int u : join->edge)
      {
        if (redo[chainOf(u)] && before[u].empty())
        {
          UniqueEdge& edge = topology.edges[u];
          before[u] = edge.params;
          if (edge.projectedParams.size() != static_cast<std::size_t>(edge.nodeCount))
          {
            projectEdgeParameters(model, curves, geometry, topology, u); // none kept yet
            edge.projectedParams = edge.params;
          }
          edge.params = edge.projectedParams;
        }
      }
    }
    for (const FootJoin* join : pass)
    {
      if (redo[chainOf(join->edge[0])])
      {
        joinFeet(model, topology, *join);
      }
    }
    for (int u = 0; changed && u < static_cast<int>(topology.edges.size()); ++u)
    {
      if (!before[u].empty() && before[u] != topology.edges[u].params)
      {
        (*changed)[u] = 1;
      }
    }
  };
  const int count = static_cast<int>(topology.edges.size());
  for (int u = 0; u < count; ++u)
  {
    const UniqueEdge& edge = topology.edges[u];
    if (!edge.matched && edge.projectedFrom < 0 && isChanged(u))
    {
      computeEdgeParameters(model, topology, u, allowFallback);
    }
  }
  project(false);
  if (!topology.matchGroups.empty())
  {
    computeMatchFloors(model, curves, topology, changed); // the floors of moved curves
    for (const int u : matchEdgeEnds(model, topology))
    {
      if (changed)
      {
        (*changed)[u] = 1;
      }
    }
  }
  for (int u = 0; u < count; ++u)
  {
    if (topology.edges[u].matched && isChanged(u))
    {
      computeEdgeParameters(model, topology, u, allowFallback);
    }
  }
  project(true);
}
} // namespace model
} // namespace blockforge
