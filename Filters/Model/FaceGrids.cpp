// Face grids of the multiblock mesher: a face from its edges (Coons patch), on a surface
// (projected TFI guarded by the parameter grid), a periodic image (its partner rotated), a
// face following the face opposite it, and a fan's line face snapped to one line. The
// mesh topology, edge grids and the order in which faces are made live in MeshGrids.cpp.
#include "MeshInternals.h"

#include "../Core/Carriers.h"
#include "../Core/Parallel.h"
#include "../Core/Projection.h"
#include "../Core/RootFinding.h"
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
  // node k's closest point searched from (s, t), kept where nearer than the one it has
  auto keepNearer = [&](int k, double s, double t) {
    Vec3 start;
    closestNear(surface, loop[k], s, t, start);
    const double near = (geometry.point(carrier, s, t) - loop[k]).norm();
    if (near + onSurface < away[k])
    {
      st[k] = Eigen::Vector2d(s, t);
      away[k] = near;
    }
  };
  auto follow = [&](int k, int from) {
    if (away[k] > onSurface)
    {
      keepNearer(k, st[from][0], st[from][1]);
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
  // segment between the neighbours (golden section on the distance, 60 steps to a bracket
  // of 2.9e-13 of the segment), then polished.
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
    const Eigen::Vector2d p = from + goldenSectionMinimum(distance, 0.0, 1.0, 3.5e-13) * (to - from);
    keepNearer(k, p[0], p[1]);
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
} // namespace model
} // namespace blockforge
