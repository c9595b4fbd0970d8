/**
 * @file Quality.cpp
 * @brief Cell quality of structured hexahedral blocks.
 *
 * The grid pass is written for throughput: every cell evaluates its shape measures from
 * one set of edge vectors, each internal face is evaluated once (by the cell on its
 * upper side) and updates both neighbours, and non-orthogonality is accumulated as the
 * smallest cosine so that only one acos per cell is needed.
 */
#include "Quality.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace blockforge
{
namespace
{
// OpenFOAM's guards (rootVSmall, vSmall) and Verdict's clamp values.
constexpr double rootVSmall = 1.0e-150;
constexpr double vSmall = 1.0e-300;
constexpr double verdictMin = 1.0e-30;
constexpr double verdictMax = 1.0e30;
constexpr double radiansToDegrees = 57.295779513082320876798;
/// An edge shorter than this fraction of the cell's longest edge is collapsed.
constexpr double collapsedEdgeFraction = 1.0e-14;
/// A face whose area is below this fraction of its squared diagonals has no normal.
constexpr double collapsedFaceFraction = 1.0e-12;
/// Aspect ratio reported for a cell with a zero mean width (Verdict's "infinite").
constexpr double degenerateAspectRatio = verdictMax;

struct P3
{
  double x, y, z;
};
inline P3 load(const double* p)
{
  return { p[0], p[1], p[2] };
}
inline P3 operator-(const P3& a, const P3& b)
{
  return { a.x - b.x, a.y - b.y, a.z - b.z };
}
inline P3 operator+(const P3& a, const P3& b)
{
  return { a.x + b.x, a.y + b.y, a.z + b.z };
}
inline P3 operator*(double s, const P3& a)
{
  return { s * a.x, s * a.y, s * a.z };
}
inline double dot(const P3& a, const P3& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline P3 cross(const P3& a, const P3& b)
{
  return { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}
inline P3 toP3(const Vec3& v)
{
  return { v.x(), v.y(), v.z() };
}
inline Vec3 toVec3(const P3& p)
{
  return Vec3(p.x, p.y, p.z);
}
inline double clampCosine(double c)
{
  return std::min(1.0, std::max(-1.0, c));
}
inline double angleFromCosine(double c)
{
  return std::acos(clampCosine(c)) * radiansToDegrees;
}

// Hexahedron topology in VTK order. Edges are directed along increasing s, t or u.
constexpr int edgeEnds[12][2] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 }, { 4, 5 }, { 5, 6 },
  { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 2, 6 }, { 3, 7 } };
// At each corner, Verdict's (xi, eta, zeta) neighbours: the Jacobian there is
// (n0 - v) . ((n1 - v) x (n2 - v)); the same pairs give the 3 face angles at the corner.
constexpr int cornerNeighbours[8][3] = { { 1, 3, 4 }, { 2, 0, 5 }, { 3, 1, 6 }, { 0, 2, 7 },
  { 7, 5, 0 }, { 4, 6, 1 }, { 5, 7, 2 }, { 6, 4, 3 } };
constexpr int cornerEdges[8][3] = { { 0, 3, 8 }, { 1, 0, 9 }, { 2, 1, 10 }, { 3, 2, 11 },
  { 7, 4, 8 }, { 4, 5, 9 }, { 5, 6, 10 }, { 6, 7, 11 } };
// vtkHexahedron's faces.
constexpr int hexFaces[6][4] = { { 0, 4, 7, 3 }, { 1, 2, 6, 5 }, { 0, 1, 5, 4 },
  { 3, 7, 6, 2 }, { 0, 3, 2, 1 }, { 4, 5, 6, 7 } };

struct CellShape
{
  double minAngle, maxAngle, scaledJacobian, aspectRatio;
};

/// Face angles of a cell with collapsed edges: each face loses its collapsed edges and
/// the angles are taken between the remaining consecutive edges (a triangle for one
/// collapsed edge); faces left with fewer than 3 edges have no angles.
void collapsedCellAngles(const P3 (&c)[8], double collapsedLength2, double& minAngle,
  double& maxAngle)
{
  double minCos = 2.0, maxCos = -2.0;
  for (const auto& face : hexFaces)
  {
    P3 edge[4];
    double length2[4];
    int kept[4];
    int keptCount = 0;
    for (int m = 0; m < 4; ++m)
    {
      edge[m] = c[face[(m + 1) % 4]] - c[face[m]];
      length2[m] = dot(edge[m], edge[m]);
      if (length2[m] > collapsedLength2)
      {
        kept[keptCount++] = m;
      }
    }
    if (keptCount < 3)
    {
      continue;
    }
    for (int q = 0; q < keptCount; ++q)
    {
      const int in = kept[q];
      const int outgoing = kept[(q + 1) % keptCount];
      const double cosine =
        -dot(edge[in], edge[outgoing]) / std::sqrt(length2[in] * length2[outgoing]);
      minCos = std::min(minCos, cosine);
      maxCos = std::max(maxCos, cosine);
    }
  }
  if (maxCos < -1.5)
  {
    // Every face collapsed: report the worst possible angles rather than nothing.
    minAngle = 0.0;
    maxAngle = 180.0;
    return;
  }
  minAngle = angleFromCosine(maxCos);
  maxAngle = angleFromCosine(minCos);
}

/**
 * Angles, scaled Jacobian and aspect ratio of one hexahedron from a single set of edge
 * lengths. The scaled Jacobian follows Verdict's hex_scaled_jacobian (VTK 9.2): the
 * minimum over the 8 corner Jacobians and the centre Jacobian (from the efg vectors),
 * each divided by the lengths of its three vectors; any of those lengths squared at or
 * below 1e-30 makes the result 1e30, and the result is clamped to +-1e30.
 */
inline CellShape evaluateCellShape(const P3 (&c)[8])
{
  double length2[12];
  double longest2 = 0.0;
  for (int e = 0; e < 12; ++e)
  {
    const P3 v = c[edgeEnds[e][1]] - c[edgeEnds[e][0]];
    length2[e] = dot(v, v);
    longest2 = std::max(longest2, length2[e]);
  }
  const double collapsedLength2 = collapsedEdgeFraction * collapsedEdgeFraction * longest2;
  bool anyCollapsed = false;
  bool verdictDegenerate = false;
  double length[12], inverseLength[12];
  for (int e = 0; e < 12; ++e)
  {
    anyCollapsed |= length2[e] <= collapsedLength2;
    verdictDegenerate |= length2[e] <= verdictMin;
    length[e] = std::sqrt(length2[e]);
    inverseLength[e] = length[e] > 0.0 ? 1.0 / length[e] : 0.0;
  }

  CellShape shape;
  double minJacobian = verdictMax;
  double minCos = 1.0, maxCos = -1.0;
  if (!anyCollapsed)
  {
    for (int v = 0; v < 8; ++v)
    {
      const P3 a = c[cornerNeighbours[v][0]] - c[v];
      const P3 b = c[cornerNeighbours[v][1]] - c[v];
      const P3 w = c[cornerNeighbours[v][2]] - c[v];
      const double ia = inverseLength[cornerEdges[v][0]];
      const double ib = inverseLength[cornerEdges[v][1]];
      const double iw = inverseLength[cornerEdges[v][2]];
      const double cab = dot(a, b) * (ia * ib);
      const double caw = dot(a, w) * (ia * iw);
      const double cbw = dot(b, w) * (ib * iw);
      minCos = std::min(minCos, std::min(cab, std::min(caw, cbw)));
      maxCos = std::max(maxCos, std::max(cab, std::max(caw, cbw)));
      minJacobian = std::min(minJacobian, dot(a, cross(b, w)) * (ia * ib * iw));
    }
    shape.minAngle = angleFromCosine(maxCos);
    shape.maxAngle = angleFromCosine(minCos);
  }
  else
  {
    collapsedCellAngles(c, collapsedLength2, shape.minAngle, shape.maxAngle);
    if (!verdictDegenerate)
    {
      for (int v = 0; v < 8; ++v)
      {
        const P3 a = c[cornerNeighbours[v][0]] - c[v];
        const P3 b = c[cornerNeighbours[v][1]] - c[v];
        const P3 w = c[cornerNeighbours[v][2]] - c[v];
        const double scale = inverseLength[cornerEdges[v][0]] *
          inverseLength[cornerEdges[v][1]] * inverseLength[cornerEdges[v][2]];
        minJacobian = std::min(minJacobian, dot(a, cross(b, w)) * scale);
      }
    }
  }

  // Centre Jacobian from the efg (principal axis) vectors.
  const P3 xi = (c[1] + c[2] + c[5] + c[6]) - (c[0] + c[3] + c[4] + c[7]);
  const P3 eta = (c[2] + c[3] + c[6] + c[7]) - (c[0] + c[1] + c[4] + c[5]);
  const P3 zeta = (c[4] + c[5] + c[6] + c[7]) - (c[0] + c[1] + c[2] + c[3]);
  const double xi2 = dot(xi, xi), eta2 = dot(eta, eta), zeta2 = dot(zeta, zeta);
  verdictDegenerate |= xi2 <= verdictMin || eta2 <= verdictMin || zeta2 <= verdictMin;
  if (verdictDegenerate)
  {
    shape.scaledJacobian = verdictMax;
  }
  else
  {
    minJacobian =
      std::min(minJacobian, dot(xi, cross(eta, zeta)) / std::sqrt(xi2 * eta2 * zeta2));
    shape.scaledJacobian = minJacobian > 0 ? std::min(minJacobian, verdictMax)
                                           : std::max(minJacobian, -verdictMax);
  }

  const double widthS = 0.25 * (length[0] + length[2] + length[4] + length[6]);
  const double widthT = 0.25 * (length[3] + length[1] + length[7] + length[5]);
  const double widthU = 0.25 * (length[8] + length[9] + length[11] + length[10]);
  const double narrowest = std::min(widthS, std::min(widthT, widthU));
  const double widest = std::max(widthS, std::max(widthT, widthU));
  shape.aspectRatio = narrowest > 0.0 ? widest / narrowest : degenerateAspectRatio;
  return shape;
}

inline void loadCorners(const std::array<Vec3, 8>& corners, P3 (&c)[8])
{
  for (int v = 0; v < 8; ++v)
  {
    c[v] = toP3(corners[v]);
  }
}

/// Face area vector, centre and their derived lengths (OpenFOAM's face::areaAndCentre).
struct FaceGeometry
{
  P3 area;
  P3 centre;
  double areaMagnitude;
  bool collapsed; ///< no usable normal (zero area up to round-off)
};

/**
 * OpenFOAM (current -dev) face::areaAndCentre: triangle fan about the point average;
 * the centre weights each triangle centre by its area projected on the face normal.
 * Weights are kept unnormalised (n . sumN) which divides out.
 */
inline FaceGeometry quadFace(const P3& a, const P3& b, const P3& c, const P3& d)
{
  const P3 average = 0.25 * (a + b + c + d);
  const P3 n0 = cross(b - a, average - a);
  const P3 n1 = cross(c - b, average - b);
  const P3 n2 = cross(d - c, average - c);
  const P3 n3 = cross(a - d, average - d);
  const P3 sumN = (n0 + n1) + (n2 + n3);
  const double sumN2 = dot(sumN, sumN);
  const double magnitude = std::sqrt(sumN2);

  FaceGeometry face;
  face.area = 0.5 * sumN;
  face.areaMagnitude = 0.5 * magnitude;
  const double w0 = dot(n0, sumN), w1 = dot(n1, sumN), w2 = dot(n2, sumN), w3 = dot(n3, sumN);
  const double sumW = (w0 + w1) + (w2 + w3);
  // OpenFOAM's "sumAn > vSmall" with sumAn = sumW / |sumN|.
  if (magnitude > 0.0 && sumW > vSmall * magnitude)
  {
    const P3 weighted = w0 * (a + b) + w1 * (b + c) + w2 * (c + d) + w3 * (d + a);
    face.centre = (1.0 / (3.0 * sumW)) * weighted + (1.0 / 3.0) * average;
  }
  else
  {
    face.centre = average;
  }
  const P3 diagonal0 = c - a, diagonal1 = d - b;
  const double scale2 = dot(diagonal0, diagonal0) + dot(diagonal1, diagonal1);
  face.collapsed = face.areaMagnitude <= collapsedFaceFraction * scale2;
  return face;
}

/// Cosine of the non-orthogonality angle (OpenFOAM's faceOrthogonality).
inline double orthogonalityCosine(const P3& ownerToNeighbour, const P3& area, double areaMagnitude)
{
  const double distance = std::sqrt(dot(ownerToNeighbour, ownerToNeighbour));
  return dot(ownerToNeighbour, area) / (distance * areaMagnitude + rootVSmall);
}

/// OpenFOAM's skewness of a face with the given owner-to-neighbour vector `d`
/// (meshCheck::faceSkewness; boundaryFaceSkewness passes the projected d and 0.4).
inline double skewness(const P3& ownerCentre, const P3& d, double distanceFactor,
  const FaceGeometry& face, const P3 (&corners)[4])
{
  const P3 ownerToFace = face.centre - ownerCentre;
  const double along =
    dot(face.area, ownerToFace) / (dot(face.area, d) + rootVSmall);
  const P3 sv = ownerToFace - along * d;
  const double svLength = std::sqrt(dot(sv, sv));
  const P3 svHat = (1.0 / (svLength + rootVSmall)) * sv;
  double normalisation = distanceFactor * std::sqrt(dot(d, d)) + rootVSmall;
  for (const P3& corner : corners)
  {
    normalisation = std::max(normalisation, std::abs(dot(svHat, corner - face.centre)));
  }
  return svLength / normalisation;
}

inline double boundarySkewness(const P3& ownerCentre, const FaceGeometry& face,
  const P3 (&corners)[4])
{
  const P3 normal = (1.0 / (face.areaMagnitude + rootVSmall)) * face.area;
  const P3 d = dot(normal, face.centre - ownerCentre) * normal;
  return skewness(ownerCentre, d, 0.4, face, corners);
}

// ---------------------------------------------------------------------------------------
// Grid pass

/// One block's structured addressing.
struct BlockView
{
  const double* xyz;
  int ni, nj, nk;    // nodes
  int ci, cj, ck;    // cells
  long cellCount;

  explicit BlockView(const StructuredBlock& b)
    : xyz(b.xyz)
    , ni(b.ni)
    , nj(b.nj)
    , nk(b.nk)
    , ci(std::max(b.ni - 1, 0))
    , cj(std::max(b.nj - 1, 0))
    , ck(std::max(b.nk - 1, 0))
    , cellCount(static_cast<long>(ci) * cj * ck)
  {
  }
  const double* node(int i, int j, int k) const
  {
    return xyz + 3 * (i + static_cast<long>(ni) * (j + static_cast<long>(nj) * k));
  }
  long cell(int i, int j, int k) const
  {
    return i + static_cast<long>(ci) * (j + static_cast<long>(cj) * k);
  }
  void cellCorners(int i, int j, int k, P3 (&c)[8]) const
  {
    c[0] = load(node(i, j, k));
    c[1] = load(node(i + 1, j, k));
    c[2] = load(node(i + 1, j + 1, k));
    c[3] = load(node(i, j + 1, k));
    c[4] = load(node(i, j, k + 1));
    c[5] = load(node(i + 1, j, k + 1));
    c[6] = load(node(i + 1, j + 1, k + 1));
    c[7] = load(node(i, j + 1, k + 1));
  }
  P3 cellCentre(int i, int j, int k) const
  {
    P3 c[8];
    cellCorners(i, j, k, c);
    return 0.125 * (((c[0] + c[1]) + (c[2] + c[3])) + ((c[4] + c[5]) + (c[6] + c[7])));
  }
  /// Face grid size of a block side: 0/1 are i = 0 / i = ni-1 (indexed j, k),
  /// 2/3 are j = 0 / nj-1 (i, k), 4/5 are k = 0 / nk-1 (i, j).
  int sideWidth(int side) const { return side < 2 ? cj : ci; }
  int sideHeight(int side) const { return side < 4 ? ck : cj; }

  /// Corners of face (a, b) of a side, ordered so the right-hand normal points along
  /// increasing i, j or k, and the cell that owns it.
  void sideFace(int side, int a, int b, P3 (&q)[4], int (&cellIjk)[3]) const
  {
    switch (side)
    {
      case 0:
      case 1:
      {
        const int i = side == 0 ? 0 : ni - 1;
        q[0] = load(node(i, a, b));
        q[1] = load(node(i, a + 1, b));
        q[2] = load(node(i, a + 1, b + 1));
        q[3] = load(node(i, a, b + 1));
        cellIjk[0] = side == 0 ? 0 : ci - 1;
        cellIjk[1] = a;
        cellIjk[2] = b;
        break;
      }
      case 2:
      case 3:
      {
        const int j = side == 2 ? 0 : nj - 1;
        q[0] = load(node(a, j, b));
        q[1] = load(node(a, j, b + 1));
        q[2] = load(node(a + 1, j, b + 1));
        q[3] = load(node(a + 1, j, b));
        cellIjk[0] = a;
        cellIjk[1] = side == 2 ? 0 : cj - 1;
        cellIjk[2] = b;
        break;
      }
      default:
      {
        const int k = side == 4 ? 0 : nk - 1;
        q[0] = load(node(a, b, k));
        q[1] = load(node(a + 1, b, k));
        q[2] = load(node(a + 1, b + 1, k));
        q[3] = load(node(a, b + 1, k));
        cellIjk[0] = a;
        cellIjk[1] = b;
        cellIjk[2] = side == 4 ? 0 : ck - 1;
        break;
      }
    }
  }
};

/// Boundary face identity: its four corners sorted, with -0.0 folded onto +0.0 so that
/// comparing bits equals comparing values.
struct FaceKey
{
  double v[12];
  bool operator==(const FaceKey& o) const { return std::memcmp(v, o.v, sizeof(v)) == 0; }
};

inline bool lexicographicLess(const P3& a, const P3& b)
{
  if (a.x != b.x)
  {
    return a.x < b.x;
  }
  if (a.y != b.y)
  {
    return a.y < b.y;
  }
  return a.z < b.z;
}

FaceKey makeFaceKey(const P3 (&q)[4])
{
  P3 sorted[4] = { q[0], q[1], q[2], q[3] };
  for (P3& p : sorted)
  {
    p.x += 0.0;
    p.y += 0.0;
    p.z += 0.0;
  }
  std::sort(sorted, sorted + 4, lexicographicLess);
  FaceKey key;
  for (int m = 0; m < 4; ++m)
  {
    key.v[3 * m] = sorted[m].x;
    key.v[3 * m + 1] = sorted[m].y;
    key.v[3 * m + 2] = sorted[m].z;
  }
  return key;
}

std::uint64_t hashFaceKey(const FaceKey& key)
{
  std::uint64_t h = 0x9E3779B97F4A7C15ull;
  for (double value : key.v)
  {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    h ^= bits + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 31;
  }
  return h;
}

struct BoundaryFaceRef
{
  int block, side, a, b;
};

/**
 * All block-boundary faces of the grid and, for each, the index of the coincident face
 * (another block's, or the same block's across a seam) or a marker: unmatched faces are
 * true boundaries, collapsed faces (no normal) are ignored altogether.
 */
struct InterfaceTable
{
  static constexpr long unmatched = -1;
  static constexpr long collapsed = -2;

  std::vector<BoundaryFaceRef> faces;
  std::vector<long> partner;
  std::vector<std::array<long, 6>> sideOffset; // per block, first face of each side

  long index(int block, int side, int a, int b, const BlockView& view) const
  {
    return sideOffset[block][side] + a + static_cast<long>(view.sideWidth(side)) * b;
  }
};

InterfaceTable matchBlockInterfaces(const std::vector<BlockView>& views)
{
  InterfaceTable table;
  table.sideOffset.resize(views.size());
  for (std::size_t blockIndex = 0; blockIndex < views.size(); ++blockIndex)
  {
    const BlockView& view = views[blockIndex];
    for (int side = 0; side < 6; ++side)
    {
      table.sideOffset[blockIndex][side] = static_cast<long>(table.faces.size());
      if (view.cellCount == 0)
      {
        continue;
      }
      for (int b = 0; b < view.sideHeight(side); ++b)
      {
        for (int a = 0; a < view.sideWidth(side); ++a)
        {
          table.faces.push_back({ static_cast<int>(blockIndex), side, a, b });
        }
      }
    }
  }

  const long count = static_cast<long>(table.faces.size());
  table.partner.assign(count, InterfaceTable::unmatched);
  std::vector<std::pair<std::uint64_t, long>> hashed;
  hashed.reserve(count);
  for (long n = 0; n < count; ++n)
  {
    const BoundaryFaceRef& ref = table.faces[n];
    P3 q[4];
    int cellIjk[3];
    views[ref.block].sideFace(ref.side, ref.a, ref.b, q, cellIjk);
    if (quadFace(q[0], q[1], q[2], q[3]).collapsed)
    {
      table.partner[n] = InterfaceTable::collapsed;
      continue;
    }
    hashed.emplace_back(hashFaceKey(makeFaceKey(q)), n);
  }
  std::sort(hashed.begin(), hashed.end());

  std::vector<FaceKey> groupKeys;
  for (std::size_t first = 0; first < hashed.size();)
  {
    std::size_t last = first + 1;
    while (last < hashed.size() && hashed[last].first == hashed[first].first)
    {
      ++last;
    }
    if (last - first >= 2)
    {
      // Same hash: pair faces whose sorted corners are identical, and only when exactly
      // two faces share those corners (more would be an ambiguous, non-manifold contact).
      groupKeys.clear();
      for (std::size_t m = first; m < last; ++m)
      {
        const BoundaryFaceRef& ref = table.faces[hashed[m].second];
        P3 q[4];
        int cellIjk[3];
        views[ref.block].sideFace(ref.side, ref.a, ref.b, q, cellIjk);
        groupKeys.push_back(makeFaceKey(q));
      }
      for (std::size_t m = 0; m < groupKeys.size(); ++m)
      {
        std::size_t equalCount = 0, other = m;
        for (std::size_t n = 0; n < groupKeys.size(); ++n)
        {
          if (n != m && groupKeys[n] == groupKeys[m])
          {
            ++equalCount;
            other = n;
          }
        }
        if (equalCount == 1)
        {
          table.partner[hashed[first + m].second] = hashed[first + other].second;
        }
      }
    }
    first = last;
  }
  return table;
}

/// Reports progress at most `maxReports` times, whatever the number of blocks or cells.
class ProgressReporter
{
public:
  ProgressReporter(const std::function<void(double)>& callback, double total)
    : callback_(callback)
    , total_(total > 0 ? total : 1.0)
  {
  }
  void advance(double amount)
  {
    done_ += amount;
    const double fraction = std::min(1.0, done_ / total_);
    if (callback_ && fraction - reported_ >= 1.0 / 32)
    {
      reported_ = fraction;
      callback_(fraction);
    }
  }
  void start()
  {
    if (callback_)
    {
      callback_(0.0);
    }
  }
  void finish()
  {
    if (callback_ && reported_ < 1.0)
    {
      callback_(1.0);
    }
  }

private:
  const std::function<void(double)>& callback_;
  double total_;
  double done_ = 0.0;
  double reported_ = 0.0;
};

/// Internal face between cells `owner` and `neighbour`, corners ordered so the area
/// vector points from owner to neighbour.
inline void internalFace(const P3 (&q)[4], const double* centres, long owner, long neighbour,
  double* minCosine, double* maxSkewness)
{
  const FaceGeometry face = quadFace(q[0], q[1], q[2], q[3]);
  if (face.collapsed)
  {
    return;
  }
  const P3 ownerCentre = load(centres + 3 * owner);
  const P3 d = load(centres + 3 * neighbour) - ownerCentre;
  const double cosine = orthogonalityCosine(d, face.area, face.areaMagnitude);
  minCosine[owner] = std::min(minCosine[owner], cosine);
  minCosine[neighbour] = std::min(minCosine[neighbour], cosine);
  const double skew = skewness(ownerCentre, d, 0.2, face, q);
  maxSkewness[owner] = std::max(maxSkewness[owner], skew);
  maxSkewness[neighbour] = std::max(maxSkewness[neighbour], skew);
}

void evaluateBlock(const std::vector<BlockView>& views, int blockIndex,
  const InterfaceTable& interfaces, CellQualityArrays& quality, std::vector<double>& centres,
  ProgressReporter& progress)
{
  const BlockView& view = views[blockIndex];
  const long cellCount = view.cellCount;
  quality.minAngle.assign(cellCount, 0.0);
  quality.maxAngle.assign(cellCount, 0.0);
  quality.nonOrthogonality.assign(cellCount, 1.0); // smallest cosine until the end
  quality.skewness.assign(cellCount, 0.0);
  quality.aspectRatio.assign(cellCount, 0.0);
  quality.scaledJacobian.assign(cellCount, 0.0);
  if (cellCount == 0)
  {
    return;
  }
  centres.resize(3 * cellCount);
  double* minCosine = quality.nonOrthogonality.data();
  double* maxSkewness = quality.skewness.data();

  for (int k = 0; k < view.ck; ++k)
  {
    for (int j = 0; j < view.cj; ++j)
    {
      for (int i = 0; i < view.ci; ++i)
      {
        const long cell = view.cell(i, j, k);
        P3 c[8];
        view.cellCorners(i, j, k, c);
        const CellShape shape = evaluateCellShape(c);
        quality.minAngle[cell] = shape.minAngle;
        quality.maxAngle[cell] = shape.maxAngle;
        quality.scaledJacobian[cell] = shape.scaledJacobian;
        quality.aspectRatio[cell] = shape.aspectRatio;
        const P3 centre =
          0.125 * (((c[0] + c[1]) + (c[2] + c[3])) + ((c[4] + c[5]) + (c[6] + c[7])));
        centres[3 * cell] = centre.x;
        centres[3 * cell + 1] = centre.y;
        centres[3 * cell + 2] = centre.z;

        // Each cell evaluates its lower faces: the neighbours there are already done.
        if (i > 0)
        {
          const P3 q[4] = { c[0], c[3], c[7], c[4] };
          internalFace(q, centres.data(), cell - 1, cell, minCosine, maxSkewness);
        }
        if (j > 0)
        {
          const P3 q[4] = { c[0], c[4], c[5], c[1] };
          internalFace(q, centres.data(), cell - view.ci, cell, minCosine, maxSkewness);
        }
        if (k > 0)
        {
          const P3 q[4] = { c[0], c[1], c[2], c[3] };
          internalFace(q, centres.data(), cell - static_cast<long>(view.ci) * view.cj, cell,
            minCosine, maxSkewness);
        }
      }
    }
    progress.advance(static_cast<double>(view.ci) * view.cj);
  }

  for (int side = 0; side < 6; ++side)
  {
    const bool lowerSide = side % 2 == 0;
    for (int b = 0; b < view.sideHeight(side); ++b)
    {
      for (int a = 0; a < view.sideWidth(side); ++a)
      {
        const long faceIndex = interfaces.index(blockIndex, side, a, b, view);
        const long partner = interfaces.partner[faceIndex];
        if (partner == InterfaceTable::collapsed)
        {
          continue;
        }
        P3 q[4];
        int ijk[3];
        view.sideFace(side, a, b, q, ijk);
        FaceGeometry face = quadFace(q[0], q[1], q[2], q[3]);
        if (lowerSide)
        {
          face.area = -1.0 * face.area; // outward from the owner
        }
        const long owner = view.cell(ijk[0], ijk[1], ijk[2]);
        const P3 ownerCentre = load(centres.data() + 3 * owner);
        if (partner >= 0)
        {
          const BoundaryFaceRef& other = interfaces.faces[partner];
          const BlockView& otherView = views[other.block];
          P3 otherCorners[4];
          int otherIjk[3];
          otherView.sideFace(other.side, other.a, other.b, otherCorners, otherIjk);
          const P3 d = otherView.cellCentre(otherIjk[0], otherIjk[1], otherIjk[2]) - ownerCentre;
          minCosine[owner] =
            std::min(minCosine[owner], orthogonalityCosine(d, face.area, face.areaMagnitude));
          maxSkewness[owner] = std::max(maxSkewness[owner], skewness(ownerCentre, d, 0.2, face, q));
        }
        else
        {
          maxSkewness[owner] = std::max(maxSkewness[owner], boundarySkewness(ownerCentre, face, q));
        }
      }
    }
  }

  for (long cell = 0; cell < cellCount; ++cell)
  {
    quality.nonOrthogonality[cell] = angleFromCosine(minCosine[cell]);
  }
}
} // namespace

void hexFaceAngles(const std::array<Vec3, 8>& corners, double& minAngle, double& maxAngle)
{
  P3 c[8];
  loadCorners(corners, c);
  const CellShape shape = evaluateCellShape(c);
  minAngle = shape.minAngle;
  maxAngle = shape.maxAngle;
}

double hexScaledJacobian(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).scaledJacobian;
}

double hexAspectRatio(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).aspectRatio;
}

Vec3 hexCentre(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return toVec3(0.125 * (((c[0] + c[1]) + (c[2] + c[3])) + ((c[4] + c[5]) + (c[6] + c[7]))));
}

void quadAreaAndCentre(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
  Vec3& area, Vec3& centre)
{
  const FaceGeometry face = quadFace(toP3(a), toP3(b), toP3(c), toP3(d));
  area = toVec3(face.area);
  centre = toVec3(face.centre);
}

double faceNonOrthogonality(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea)
{
  const P3 area = toP3(faceArea);
  return angleFromCosine(orthogonalityCosine(
    toP3(neighbourCentre) - toP3(ownerCentre), area, std::sqrt(dot(area, area))));
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea, const Vec3& faceCentre)
{
  const P3 owner = toP3(ownerCentre);
  const P3 d = toP3(neighbourCentre) - owner;
  const P3 area = toP3(faceArea);
  const P3 ownerToFace = toP3(faceCentre) - owner;
  const P3 sv = ownerToFace - (dot(area, ownerToFace) / (dot(area, d) + rootVSmall)) * d;
  return std::sqrt(dot(sv, sv)) / (std::sqrt(dot(d, d)) + rootVSmall);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea,
  const Vec3& faceCentre)
{
  const Vec3 normal = faceArea / (faceArea.norm() + rootVSmall);
  const Vec3 mirrored = ownerCentre + 2.0 * normal * normal.dot(faceCentre - ownerCentre);
  return faceSkewness(ownerCentre, mirrored, faceArea, faceCentre);
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea, const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners)
{
  FaceGeometry face;
  face.area = toP3(faceArea);
  face.centre = toP3(faceCentre);
  face.areaMagnitude = faceArea.norm();
  face.collapsed = false;
  const P3 corners[4] = { toP3(faceCorners[0]), toP3(faceCorners[1]), toP3(faceCorners[2]),
    toP3(faceCorners[3]) };
  const P3 owner = toP3(ownerCentre);
  return skewness(owner, toP3(neighbourCentre) - owner, 0.2, face, corners);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea,
  const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners)
{
  FaceGeometry face;
  face.area = toP3(faceArea);
  face.centre = toP3(faceCentre);
  face.areaMagnitude = faceArea.norm();
  face.collapsed = false;
  const P3 corners[4] = { toP3(faceCorners[0]), toP3(faceCorners[1]), toP3(faceCorners[2]),
    toP3(faceCorners[3]) };
  return boundarySkewness(toP3(ownerCentre), face, corners);
}

std::vector<CellQualityArrays> computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::function<void(double)>& progress)
{
  std::vector<BlockView> views;
  views.reserve(blocks.size());
  double totalCells = 0.0;
  for (std::size_t n = 0; n < blocks.size(); ++n)
  {
    const StructuredBlock& block = blocks[n];
    if (block.ni < 0 || block.nj < 0 || block.nk < 0)
    {
      throw GeometryError("grid quality: block " + std::to_string(n) +
        " has a negative node count");
    }
    views.emplace_back(block);
    if (views.back().cellCount > 0 && !block.xyz)
    {
      throw GeometryError("grid quality: block " + std::to_string(n) + " has no nodes");
    }
    totalCells += static_cast<double>(views.back().cellCount);
  }

  ProgressReporter reporter(progress, totalCells);
  reporter.start();
  const InterfaceTable interfaces = matchBlockInterfaces(views);
  std::vector<CellQualityArrays> quality(blocks.size());
  std::vector<double> centres;
  for (std::size_t n = 0; n < blocks.size(); ++n)
  {
    evaluateBlock(views, static_cast<int>(n), interfaces, quality[n], centres, reporter);
  }
  reporter.finish();
  return quality;
}

std::array<long long, 5> minAngleClasses(const std::vector<CellQualityArrays>& quality)
{
  std::array<long long, 5> counts{};
  for (const CellQualityArrays& block : quality)
  {
    for (double angle : block.minAngle)
    {
      // Comparisons rather than a cast so that a NaN cannot index out of range.
      const int bin = (angle >= 20.0) + (angle >= 40.0) + (angle >= 60.0) + (angle >= 80.0);
      ++counts[bin];
    }
  }
  return counts;
}
} // namespace blockforge
