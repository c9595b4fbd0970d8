// Matched edges (grading law `match`): the end cells of an edge take the length of the
// cells that continue it across block interfaces and periodic pairs, so that neighbour
// cells in two blocks differ by little however different the blocks' own mean cells are
// (an O-grid's nose block against its blade sides, an H block against the O-grid's outer
// layer). Resolved once the node counts and edge lengths are known: graded edges first,
// then every matched edge from the groups at its two ends, so nothing depends on itself.
#include "MeshInternals.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace blockforge
{
namespace model
{
namespace
{
int findRoot(std::vector<int>& parent, int key)
{
  while (parent[key] != key)
  {
    parent[key] = parent[parent[key]];
    key = parent[key];
  }
  return key;
}

void join(std::vector<int>& parent, int a, int b)
{
  a = findRoot(parent, a);
  b = findRoot(parent, b);
  if (a != b)
  {
    parent[std::max(a, b)] = std::min(a, b); // the smaller key leads: deterministic groups
  }
}

/// The end key (2 edge + end) at local vertex `local` of local edge `e` of `block`, -1
/// when the edge is collapsed.
int endKey(const MeshTopology& topology, int block, int e, int local)
{
  const MeshLinks& links = topology.blocks[block];
  const int unique = links.edge[e];
  if (unique < 0)
  {
    return -1;
  }
  const bool atLocalStart = edgeVertices(e)[0] == local;
  const bool atB = atLocalStart == links.reversed[e]; // the local start is b when reversed
  return 2 * unique + (atB ? 1 : 0);
}

/// The end key at local vertex `local` of the edge of `block` that leaves it normal to
/// face `face`, -1 when that edge is collapsed.
int normalEdgeEnd(const MeshTopology& topology, int block, int face, int local)
{
  for (int e = 0; e < 12; ++e)
  {
    const std::array<int, 2> ends = edgeVertices(e);
    if (edgeDirection(e) == face / 2 && (ends[0] == local || ends[1] == local))
    {
      return endKey(topology, block, e, local);
    }
  }
  return -1;
}

/// The end key at local vertex `from` of the edge of `block` from `from` to `to`, -1
/// when there is none or it is collapsed.
int edgeEndBetween(const MeshTopology& topology, int block, int from, int to)
{
  for (int e = 0; e < 12; ++e)
  {
    const std::array<int, 2> ends = edgeVertices(e);
    if ((ends[0] == from && ends[1] == to) || (ends[0] == to && ends[1] == from))
    {
      return endKey(topology, block, e, from);
    }
  }
  return -1;
}

/// Joins the edge ends normal to two faces that are one (an interface, or a periodic
/// pair), corner by corner: `transform` maps the second face's corners to the first's.
void joinAcross(const MeshTopology& topology, const BlockFace& first, const BlockFace& second,
  const FaceTransform& transform, std::vector<int>& parent)
{
  const std::array<int, 4> firstCorners = faceCorners(first.face);
  const std::array<int, 4> secondCorners = faceCorners(second.face);
  for (int c = 0; c < 4; ++c)
  {
    const int mapped = transform.mapCorner(c);
    if (mapped < 0)
    {
      continue;
    }
    const int a = normalEdgeEnd(topology, first.block, first.face, firstCorners[mapped]);
    const int b = normalEdgeEnd(topology, second.block, second.face, secondCorners[c]);
    if (a >= 0 && b >= 0 && a != b)
    {
      join(parent, a, b);
    }
  }
}

/// The groups of the ends joined in `parent` that hold a matched edge's end.
void groupMatchedEnds(MeshTopology& topology, std::vector<int>& parent)
{
  std::vector<std::vector<int>> byRoot(parent.size());
  for (int key = 0; key < static_cast<int>(parent.size()); ++key)
  {
    byRoot[findRoot(parent, key)].push_back(key);
  }
  for (std::vector<int>& group : byRoot)
  {
    bool hasMatched = false;
    for (const int key : group)
    {
      hasMatched = hasMatched || topology.edges[key / 2].matched;
    }
    if (group.size() > 1 && hasMatched)
    {
      topology.matchGroups.push_back(std::move(group));
    }
  }
}
} // namespace

void buildMatchGroups(const BlockModel& model, MeshTopology& topology)
{
  topology.matchGroups.clear();
  topology.matchClasses.clear();
  bool any = false;
  for (UniqueEdge& edge : topology.edges)
  {
    edge.matched = false;
    edge.matchLean = 0.0;
    for (const EdgeUse& use : edge.uses)
    {
      const DistributionLaw& law = model.blocks[use.block].laws[use.localEdge];
      if (law.kind == DistributionLaw::Kind::Match)
      {
        edge.matched = true;
        edge.matchRatio = law.expansionRatio;
        edge.matchFlatness = law.matchFlatness;
        edge.matchAtMost = law.matchAtMost;
        edge.matchLean = std::max(edge.matchLean, law.leanLimit);
      }
    }
    any = any || edge.matched;
  }
  if (!any)
  {
    return;
  }
  if (topology.connectivity.periodic.empty())
  {
    try
    {
      findPeriodicPairs(model, topology.connectivity);
    }
    catch (const std::exception&)
    {
      topology.connectivity.periodic.clear(); // reported by the patch check
    }
  }
  std::vector<int> parent(2 * topology.edges.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const TopologyFace& face : topology.faces)
  {
    if (face.isInterface())
    {
      const FaceUse& owner = face.uses[0];
      const FaceUse& other = face.uses[1];
      joinAcross(topology, { owner.block, owner.face }, { other.block, other.face },
        other.transform, parent);
    }
  }
  topology.matchCopies.clear();
  for (const PeriodicPair& pair : topology.connectivity.periodic)
  {
    joinAcross(topology, pair.sourceFace, pair.imageFace, pair.transform, parent);
    // the image face's edges are rotated copies of the source face's: their ends too
    const std::array<int, 4> imageCorners = faceCorners(pair.imageFace.face);
    const std::array<int, 4> sourceCorners = faceCorners(pair.sourceFace.face);
    for (int c = 0; c < 4; ++c)
    {
      for (const int next : { (c + 1) % 4, (c + 3) % 4 })
      {
        const int image = edgeEndBetween(
          topology, pair.imageFace.block, imageCorners[c], imageCorners[next]);
        const int mapped = pair.transform.mapCorner(c);
        const int mappedNext = pair.transform.mapCorner(next);
        if (image < 0 || mapped < 0 || mappedNext < 0)
        {
          continue;
        }
        const int source = edgeEndBetween(topology, pair.sourceFace.block,
          sourceCorners[mapped], sourceCorners[mappedNext]);
        if (source >= 0 && source != image)
        {
          topology.matchCopies.emplace_back(image, source);
        }
      }
    }
  }
  topology.matchClasses.resize(parent.size());
  for (int key = 0; key < static_cast<int>(parent.size()); ++key)
  {
    topology.matchClasses[key] = findRoot(parent, key);
  }
  groupMatchedEnds(topology, parent);
}

void joinProjectedMatchEnds(const BlockModel& model, MeshTopology& topology)
{
  if (topology.matchClasses.empty())
  {
    return;
  }
  std::vector<int> parent = topology.matchClasses; // every key points at its class's root
  std::vector<int> classSize(parent.size(), 0);
  for (const int root : parent)
  {
    ++classSize[root];
  }
  bool joined = false;
  for (std::size_t u = 0; u < topology.edges.size(); ++u)
  {
    const UniqueEdge& edge = topology.edges[u];
    if (!edge.projectedAfterMatch)
    {
      continue;
    }
    int root = edge.projectedFrom;
    while (topology.edges[root].projectedFrom >= 0)
    {
      root = topology.edges[root].projectedFrom;
    }
    const UniqueEdge& source = topology.edges[root];
    const bool crossed = runsAgainst(model, edge, source);
    for (int end = 0; end < 2; ++end)
    {
      const int key = 2 * static_cast<int>(u) + end;
      if (classSize[topology.matchClasses[key]] > 1) // it continues into other edges
      {
        join(parent, key, 2 * root + (crossed ? 1 - end : end));
        joined = true;
      }
    }
  }
  if (joined)
  {
    topology.matchGroups.clear();
    groupMatchedEnds(topology, parent);
  }
}

std::vector<int> matchEdgeEnds(const BlockModel& model, MeshTopology& topology)
{
  (void)model;
  std::vector<double> first(topology.edges.size(), 0.0), last(topology.edges.size(), 0.0);
  for (const std::vector<int>& group : topology.matchGroups)
  {
    double gradedLogs = 0.0, meanLogs = 0.0;
    int graded = 0, matched = 0;
    for (const int key : group)
    {
      const UniqueEdge& edge = topology.edges[key / 2];
      if (edge.projectedAfterMatch)
      {
        continue; // its nodes come from a matched edge, after these
      }
      if (!edge.matched)
      {
        gradedLogs += std::log(std::max(endCell(edge, key % 2), 1e-300));
        ++graded;
      }
      else
      {
        meanLogs += std::log(std::max(edge.length / (edge.nodeCount - 1), 1e-300));
        ++matched;
      }
    }
    double target = graded > 0 ? std::exp(gradedLogs / graded) : std::exp(meanLogs / matched);
    for (const int key : group)
    {
      // a member whose end cells may be at most k times its mean cell lowers the group's
      const UniqueEdge& edge = topology.edges[key / 2];
      if (edge.matched && edge.matchAtMost > 0.0 && !edge.projectedAfterMatch)
      {
        target = std::min(target, edge.matchAtMost * edge.length / (edge.nodeCount - 1));
      }
    }
    for (const int key : group)
    {
      // a member leaving its end across its course asks for a longer cell: all follow
      const UniqueEdge& edge = topology.edges[key / 2];
      if (edge.matched && edge.matchFloor[key % 2] > target)
      {
        target = edge.matchFloor[key % 2];
      }
    }
    for (const int key : group)
    {
      if (topology.edges[key / 2].matched)
      {
        (key % 2 == 0 ? first : last)[key / 2] = target;
      }
    }
  }
  for (const auto& copy : topology.matchCopies)
  {
    const int image = copy.first, source = copy.second;
    (image % 2 == 0 ? first : last)[image / 2] = (source % 2 == 0 ? first : last)[source / 2];
  }
  std::vector<int> changed;
  for (std::size_t e = 0; e < topology.edges.size(); ++e)
  {
    UniqueEdge& edge = topology.edges[e];
    if (edge.matched && (edge.matchFirst != first[e] || edge.matchLast != last[e]))
    {
      edge.matchFirst = first[e];
      edge.matchLast = last[e];
      changed.push_back(static_cast<int>(e));
    }
  }
  return changed;
}
void computeMatchFloors(const BlockModel& model, const std::vector<NamedCurve>& curves,
  MeshTopology& topology, const std::vector<char>* changed)
{
  for (std::size_t e = 0; e < topology.edges.size(); ++e)
  {
    UniqueEdge& edge = topology.edges[e];
    if (changed && !(*changed)[e])
    {
      continue;
    }
    edge.matchFloor = { { 0.0, 0.0 } };
    if (!edge.matched || !(edge.matchLean > 0.0) || edge.named < 0)
    {
      continue;
    }
    const Edge& named = model.edges[edge.named];
    if (named.kind == Edge::Kind::Line || named.kind == Edge::Kind::Project ||
      named.kind == Edge::Kind::Periodic)
    {
      continue; // straight (no lean), or a rotated copy whose ends follow its source's
    }
    const NamedCurve& curve = curves[edge.named];
    const bool reversed = named.from != edge.a;
    // the point at arc-length fraction f from end a, as computeEdgeNodes places nodes
    auto at = [&](double f) {
      const double fraction = reversed ? 1.0 - f : f;
      return curve.curve->point(
        curve.lengthTable ? curve.lengthTable->parameterAtFraction(fraction) : fraction);
    };
    const Vec3 a = at(0.0), b = at(1.0);
    const double cosLimit = std::cos(edge.matchLean);
    for (int end = 0; end < 2; ++end)
    {
      const Vec3 origin = end == 0 ? a : b;
      const Vec3 course = ((end == 0 ? b : a) - origin).normalized();
      // does the cell of fraction f from this end lean no more than the limit?
      auto complies = [&](double f) {
        const Vec3 chord = at(end == 0 ? f : 1.0 - f) - origin;
        const double n = chord.norm();
        return n > 0.0 && chord.dot(course) >= cosLimit * n;
      };
      // a cell of 1/4096 of the edge that complies needs no floor (the cells the limit is
      // for are a fraction of an edge's radius of curvature long, far more)
      double low = 1.0 / 4096.0;
      if (complies(low))
      {
        continue;
      }
      double high = low;
      while (high < 0.5 && !complies(high))
      {
        low = high;
        high *= 2.0;
      }
      if (high >= 0.5 && !complies(high))
      {
        continue; // leans across its whole first half: not an edge this limit is for
      }
      for (int iteration = 0; iteration < 24; ++iteration) // to 6e-8 of the bracket
      {
        const double mid = 0.5 * (low + high);
        (complies(mid) ? high : low) = mid;
      }
      edge.matchFloor[end] = high * edge.length;
    }
  }
}
} // namespace model
} // namespace blockforge
