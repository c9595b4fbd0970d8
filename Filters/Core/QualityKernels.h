/**
 * @file QualityKernels.h
 * @brief Private to the quality measures (Quality.cpp, QualityInterfaces.cpp,
 * QualityMeasures.cpp) and their tests (not installed): the per-cell and per-face
 * kernels of the quality measures, written once as templates on T = double (one cell) or
 * Lanes (several cells in SIMD lanes): lane arithmetic, cell shape (angles, scaled
 * Jacobian, aspect ratio), face area and centre, OpenFOAM's non-orthogonality and
 * skewness, OpenFOAM's cell centre.
 */
#pragma once

#include "Types.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace quality
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

// ---------------------------------------------------------------------------------------
// Lane arithmetic: the kernels are templates on T = double (one cell) or Lanes (several).

/**
 * Several cells processed together in one SIMD register: Eigen's packet of doubles for
 * the build's instruction set (2 lanes with SSE2, which every x86-64 CPU has; 1 lane
 * when Eigen does not vectorise). A thin wrapper over Eigen's packet primitives rather
 * than Eigen::Array2d, whose expression templates were not always inlined here.
 */
namespace packet = Eigen::internal;
using Packet = packet::packet_traits<double>::type;
constexpr int packetLanes = packet::packet_traits<double>::size;

struct Lanes
{
  Packet v;

  static Lanes load(const double* p) { return { packet::ploadu<Packet>(p) }; }
  static Lanes splat(double s) { return { packet::pset1<Packet>(s) }; }
  void store(double* p) const { packet::pstoreu(p, v); }
  void extract(double (&out)[packetLanes]) const { packet::pstoreu(out, v); }
  void set(int l, double value)
  {
    double out[packetLanes];
    extract(out);
    out[l] = value;
    v = packet::ploadu<Packet>(out);
  }
  friend Lanes operator+(const Lanes& a, const Lanes& b) { return { packet::padd(a.v, b.v) }; }
  friend Lanes operator-(const Lanes& a, const Lanes& b) { return { packet::psub(a.v, b.v) }; }
  friend Lanes operator*(const Lanes& a, const Lanes& b) { return { packet::pmul(a.v, b.v) }; }
  friend Lanes operator/(const Lanes& a, const Lanes& b) { return { packet::pdiv(a.v, b.v) }; }
  friend Lanes operator*(double s, const Lanes& a) { return splat(s) * a; }
  friend Lanes operator/(double s, const Lanes& a) { return splat(s) / a; }
  friend Lanes operator+(const Lanes& a, double s) { return a + splat(s); }
  friend Lanes vmin(const Lanes& a, const Lanes& b) { return { packet::pmin(a.v, b.v) }; }
  friend Lanes vmax(const Lanes& a, const Lanes& b) { return { packet::pmax(a.v, b.v) }; }
  friend Lanes vsqrt(const Lanes& a) { return { packet::psqrt(a.v) }; }
  friend Lanes vabs(const Lanes& a) { return { packet::pabs(a.v) }; }
};

inline double vmin(double a, double b)
{
  return std::min(a, b);
}
inline double vmax(double a, double b)
{
  return std::max(a, b);
}
inline double vabs(double a)
{
  return std::abs(a);
}
inline double vsqrt(double a)
{
  return std::sqrt(a);
}

template <typename T>
constexpr int laneCount = 1;
template <>
constexpr int laneCount<Lanes> = packetLanes;

template <typename T>
T splat(double value);
template <>
inline double splat<double>(double value)
{
  return value;
}
template <>
inline Lanes splat<Lanes>(double value)
{
  return Lanes::splat(value);
}

template <typename T>
T loadLanes(const double* p);
template <>
inline double loadLanes<double>(const double* p)
{
  return *p;
}
template <>
inline Lanes loadLanes<Lanes>(const double* p)
{
  return Lanes::load(p);
}
inline void storeLanes(double* p, double v)
{
  *p = v;
}
inline void storeLanes(double* p, const Lanes& v)
{
  v.store(p);
}
/// All lanes of a value as plain doubles.
inline void extractLanes(double v, double (&out)[1])
{
  out[0] = v;
}
inline void extractLanes(const Lanes& v, double (&out)[packetLanes])
{
  v.extract(out);
}
inline void setLane(double& v, int, double value)
{
  v = value;
}
inline void setLane(Lanes& v, int l, double value)
{
  v.set(l, value);
}

template <typename T>
struct V3
{
  T x, y, z;
};
using P3 = V3<double>;

template <typename T>
inline V3<T> operator-(const V3<T>& a, const V3<T>& b)
{
  return { a.x - b.x, a.y - b.y, a.z - b.z };
}
template <typename T>
inline V3<T> operator+(const V3<T>& a, const V3<T>& b)
{
  return { a.x + b.x, a.y + b.y, a.z + b.z };
}
template <typename T>
inline V3<T> operator*(const T& s, const V3<T>& a)
{
  return { s * a.x, s * a.y, s * a.z };
}
template <typename T>
inline V3<T> operator*(double s, const V3<T>& a)
{
  return { s * a.x, s * a.y, s * a.z };
}
inline P3 operator*(double s, const P3& a)
{
  return { s * a.x, s * a.y, s * a.z };
}
template <typename T>
inline T dot(const V3<T>& a, const V3<T>& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
inline V3<T> cross(const V3<T>& a, const V3<T>& b)
{
  return { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}
template <typename T>
inline V3<T> loadV3(const double* x, const double* y, const double* z)
{
  return { loadLanes<T>(x), loadLanes<T>(y), loadLanes<T>(z) };
}
template <typename T>
inline P3 laneOf(const V3<T>& v, int l)
{
  double x[laneCount<T>], y[laneCount<T>], z[laneCount<T>];
  extractLanes(v.x, x);
  extractLanes(v.y, y);
  extractLanes(v.z, z);
  return { x[l], y[l], z[l] };
}
inline P3 load(const double* p)
{
  return { p[0], p[1], p[2] };
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

// ---------------------------------------------------------------------------------------
// Cell shape: angles, scaled Jacobian, aspect ratio

// Hexahedron topology in VTK order. Edges are directed along increasing s, t or u, as in
// the block notation of Transfinite.h, so a grid edge has the same vector in all cells.
constexpr int edgeEnds[12][2] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 }, { 4, 5 }, { 5, 6 },
  { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 2, 6 }, { 3, 7 } };
// vtkHexahedron's faces.
constexpr int hexFaces[6][4] = { { 0, 4, 7, 3 }, { 1, 2, 6, 5 }, { 0, 1, 5, 4 }, { 3, 7, 6, 2 },
  { 0, 3, 2, 1 }, { 4, 5, 6, 7 } };

struct CellShape
{
  double minAngle, maxAngle, scaledJacobian, aspectRatio;
};

/// What the branch-free kernel leaves for the per-lane finish.
template <typename T>
struct ShapeSums
{
  T minCos, maxCos;      ///< over the 24 face corners (valid without collapsed edges)
  T minCornerJacobian;   ///< scaled, over the 8 corners
  T centreJacobian;      ///< scaled (NaN for a degenerate centre, not used then)
  T shortest2, longest2; ///< squared edge lengths
  T shortestAxis2;       ///< smallest squared efg vector
  T narrowest, widest;   ///< mean widths
};

template <typename T>
inline void edgeVectors(const V3<T> (&c)[8], V3<T> (&e)[12])
{
  for (int n = 0; n < 12; ++n)
  {
    e[n] = c[edgeEnds[n][1]] - c[edgeEnds[n][0]];
  }
}

/// Accumulates one hexahedron corner: the vectors to its three neighbours are
/// sa*E[ea], sb*E[eb], sw*E[ew] (Verdict's xi, eta, zeta there). Its three face angles
/// are the angles between pairs of them; its Jacobian is their triple product.
template <typename T>
struct CornerAccumulator
{
  const V3<T>* e;
  const T* inverseLength;
  T minCos, maxCos, minJacobian;

  template <int ea, int eb, int ew, int sa, int sb, int sw>
  inline void corner()
  {
    const T ia = inverseLength[ea], ib = inverseLength[eb], iw = inverseLength[ew];
    const T cab = double(sa * sb) * dot(e[ea], e[eb]) * (ia * ib);
    const T caw = double(sa * sw) * dot(e[ea], e[ew]) * (ia * iw);
    const T cbw = double(sb * sw) * dot(e[eb], e[ew]) * (ib * iw);
    minCos = vmin(minCos, vmin(cab, vmin(caw, cbw)));
    maxCos = vmax(maxCos, vmax(cab, vmax(caw, cbw)));
    const T jacobian = double(sa * sb * sw) * dot(e[ea], cross(e[eb], e[ew])) * (ia * ib * iw);
    minJacobian = vmin(minJacobian, jacobian);
  }

  /// All eight corners.
  inline void all()
  {
    corner<0, 3, 8, 1, 1, 1>();     // V0: V1, V3, V4
    corner<1, 0, 9, 1, -1, 1>();    // V1: V2, V0, V5
    corner<2, 1, 10, -1, -1, 1>();  // V2: V3, V1, V6
    corner<3, 2, 11, -1, 1, 1>();   // V3: V0, V2, V7
    corner<7, 4, 8, 1, 1, -1>();    // V4: V7, V5, V0
    corner<4, 5, 9, -1, 1, -1>();   // V5: V4, V6, V1
    corner<5, 6, 10, -1, -1, -1>(); // V6: V5, V7, V2
    corner<6, 7, 11, 1, -1, -1>();  // V7: V6, V4, V3
  }
};

/**
 * Branch-free part of the shape measures, from the edge vectors, squared lengths and
 * inverse lengths (0 for zero length). Angles and the Verdict clamp are finished per
 * lane by finishShape.
 */
template <typename T>
inline ShapeSums<T> shapeKernel(
  const V3<T> (&e)[12], const T (&length2)[12], const T (&inverseLength)[12])
{
  ShapeSums<T> sums;
  CornerAccumulator<T> corners{ e, inverseLength, splat<T>(1.0), splat<T>(-1.0),
    splat<T>(verdictMax) };
  corners.all();
  sums.minCos = corners.minCos;
  sums.maxCos = corners.maxCos;
  sums.minCornerJacobian = corners.minJacobian;

  // Centre Jacobian from the efg (principal axis) vectors: sums of the 4 parallel edges.
  const V3<T> xi = (e[0] + e[2]) + (e[4] + e[6]);
  const V3<T> eta = (e[3] + e[1]) + (e[7] + e[5]);
  const V3<T> zeta = (e[8] + e[9]) + (e[10] + e[11]);
  const T xi2 = dot(xi, xi), eta2 = dot(eta, eta), zeta2 = dot(zeta, zeta);
  sums.centreJacobian = dot(xi, cross(eta, zeta)) / vsqrt(xi2 * eta2 * zeta2);
  sums.shortestAxis2 = vmin(xi2, vmin(eta2, zeta2));

  T shortest2 = length2[0], longest2 = length2[0];
  T length[12];
  for (int n = 0; n < 12; ++n)
  {
    shortest2 = vmin(shortest2, length2[n]);
    longest2 = vmax(longest2, length2[n]);
    length[n] = length2[n] * inverseLength[n];
  }
  sums.shortest2 = shortest2;
  sums.longest2 = longest2;
  const T widthS = 0.25 * ((length[0] + length[2]) + (length[4] + length[6]));
  const T widthT = 0.25 * ((length[3] + length[1]) + (length[7] + length[5]));
  const T widthU = 0.25 * ((length[8] + length[9]) + (length[10] + length[11]));
  sums.narrowest = vmin(widthS, vmin(widthT, widthU));
  sums.widest = vmax(widthS, vmax(widthT, widthU));
  return sums;
}

/**
 * Scaled Jacobian of a cell with collapsed edges (a wedge or prism written as a hex).
 * Verdict gives such cells 1e30, which says nothing and ruins colour maps and means, so
 * the grid pass uses the Verdict corner formula on the corners whose three edges all
 * have length, plus the centre Jacobian when its vectors have length: a right wedge gets
 * 1, an inverted one a negative value. 0 when no corner is measurable.
 */
inline double collapsedCellScaledJacobian(const P3 (&c)[8])
{
  // Verdict's corner order: the three neighbours of each corner, right-handed.
  static const int neighbours[8][3] = { { 1, 3, 4 }, { 2, 0, 5 }, { 3, 1, 6 }, { 0, 2, 7 },
    { 7, 5, 0 }, { 4, 6, 1 }, { 5, 7, 2 }, { 6, 4, 3 } };
  double smallest = verdictMax;
  bool measured = false;
  for (int v = 0; v < 8; ++v)
  {
    const P3 a = c[neighbours[v][0]] - c[v];
    const P3 b = c[neighbours[v][1]] - c[v];
    const P3 d = c[neighbours[v][2]] - c[v];
    const double a2 = dot(a, a), b2 = dot(b, b), d2 = dot(d, d);
    if (a2 <= verdictMin || b2 <= verdictMin || d2 <= verdictMin)
    {
      continue;
    }
    smallest = std::min(smallest, dot(a, cross(b, d)) / std::sqrt(a2 * b2 * d2));
    measured = true;
  }
  const P3 xi = (c[1] - c[0]) + (c[2] - c[3]) + (c[5] - c[4]) + (c[6] - c[7]);
  const P3 eta = (c[3] - c[0]) + (c[2] - c[1]) + (c[7] - c[4]) + (c[6] - c[5]);
  const P3 zeta = (c[4] - c[0]) + (c[5] - c[1]) + (c[6] - c[2]) + (c[7] - c[3]);
  const double xi2 = dot(xi, xi), eta2 = dot(eta, eta), zeta2 = dot(zeta, zeta);
  if (xi2 > verdictMin && eta2 > verdictMin && zeta2 > verdictMin)
  {
    smallest = std::min(smallest, dot(xi, cross(eta, zeta)) / std::sqrt(xi2 * eta2 * zeta2));
    measured = true;
  }
  return measured ? smallest : 0.0;
}

/// Face angles of a cell with collapsed edges: each face loses its collapsed edges and
/// the angles are taken between the remaining consecutive edges (a triangle for one
/// collapsed edge); faces left with fewer than 3 edges have no angles. The corner at a
/// collapsed edge (a prism's apex: a wedge on an axis, a fan's wall cell on a sharp blade
/// tip) is left out: the cells round the collapsed edge share the wedge's angle or the
/// tip's turn, set by the geometry, so the smallest share is at most that over the cell
/// count whatever the node placement, and a prism's faces stay planar and
/// orthogonal to its neighbours' whatever that angle (non-orthogonality and skewness,
/// measured on every cell, see it). Counted, it would be the grid's smallest angle
/// wherever a fan has many cells (the compressor's tips: 3 degrees at density 4) and
/// the optimizer, which maximises the smallest angle, would work on a constant.
inline void collapsedCellAngles(
  const P3 (&c)[8], double collapsedLength2, double& minAngle, double& maxAngle)
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
      if (outgoing != (in + 1) % 4)
      {
        continue; // a collapsed edge lies between them: the apex
      }
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

/// The kernel's sums as one ShapeSums<double> per lane.
template <typename T>
inline void splitLanes(const ShapeSums<T>& sums, ShapeSums<double> (&out)[laneCount<T>])
{
  double values[laneCount<T>];
  auto split = [&](const T& value, double ShapeSums<double>::*member)
  {
    extractLanes(value, values);
    for (int l = 0; l < laneCount<T>; ++l)
    {
      out[l].*member = values[l];
    }
  };
  split(sums.minCos, &ShapeSums<double>::minCos);
  split(sums.maxCos, &ShapeSums<double>::maxCos);
  split(sums.minCornerJacobian, &ShapeSums<double>::minCornerJacobian);
  split(sums.centreJacobian, &ShapeSums<double>::centreJacobian);
  split(sums.shortest2, &ShapeSums<double>::shortest2);
  split(sums.longest2, &ShapeSums<double>::longest2);
  split(sums.shortestAxis2, &ShapeSums<double>::shortestAxis2);
  split(sums.narrowest, &ShapeSums<double>::narrowest);
  split(sums.widest, &ShapeSums<double>::widest);
}

/**
 * Finishes lane l. The scaled Jacobian is Verdict's hex_scaled_jacobian (VTK 9.2): the
 * minimum of the 8 corner Jacobians and the centre Jacobian, each divided by the lengths
 * of its three vectors; a squared length at or below 1e-30 (any edge or efg vector)
 * makes it 1e30, and it is clamped to +-1e30.
 */
template <typename T>
inline CellShape finishShape(const ShapeSums<double>& sums, const V3<T> (&c)[8], int l)
{
  CellShape shape;
  const double collapsedLength2 = collapsedEdgeFraction * collapsedEdgeFraction * sums.longest2;
  if (sums.shortest2 > collapsedLength2)
  {
    shape.minAngle = angleFromCosine(sums.maxCos);
    shape.maxAngle = angleFromCosine(sums.minCos);
  }
  else
  {
    P3 corners[8];
    for (int v = 0; v < 8; ++v)
    {
      corners[v] = laneOf(c[v], l);
    }
    collapsedCellAngles(corners, collapsedLength2, shape.minAngle, shape.maxAngle);
  }
  if (sums.shortest2 <= verdictMin || sums.shortestAxis2 <= verdictMin)
  {
    shape.scaledJacobian = verdictMax;
  }
  else
  {
    const double jacobian = std::min(sums.minCornerJacobian, sums.centreJacobian);
    shape.scaledJacobian =
      jacobian > 0 ? std::min(jacobian, verdictMax) : std::max(jacobian, -verdictMax);
  }
  shape.aspectRatio = sums.narrowest > 0.0 ? sums.widest / sums.narrowest : degenerateAspectRatio;
  return shape;
}

/// Edge vectors of one cell with their squared and inverse lengths (0 for zero length).
inline void cellEdges(const P3 (&c)[8], P3 (&e)[12], double (&length2)[12], double (&inverseLength)[12])
{
  edgeVectors(c, e);
  for (int n = 0; n < 12; ++n)
  {
    length2[n] = dot(e[n], e[n]);
    inverseLength[n] = length2[n] > 0.0 ? 1.0 / std::sqrt(length2[n]) : 0.0;
  }
}

inline CellShape evaluateCellShape(const P3 (&c)[8])
{
  P3 e[12];
  double length2[12], inverseLength[12];
  cellEdges(c, e, length2, inverseLength);
  return finishShape(shapeKernel(e, length2, inverseLength), c, 0);
}

// ---------------------------------------------------------------------------------------
// Faces

/// Face area vector and centre (OpenFOAM's face::areaAndCentre) with what the special
/// cases need.
template <typename T>
struct FaceGeometry
{
  V3<T> area;
  V3<T> centre;
  T area2;       ///< |area|^2
  T diagonals2;  ///< sum of the squared diagonals (the face's size)
  T weightSum;   ///< sum of the triangle weights |n_k| (OpenFOAM's sumA)
  V3<T> average; ///< point average (OpenFOAM's fallback centre)
  T length;      ///< |area|: set by the grid pass for the cell determinant only
};

/**
 * OpenFOAM's face centre and area vector (primitiveMesh::makeFaceCentresAndAreas of
 * OpenFOAM v1912, the version Debian ships and checkMesh validates against): a triangle
 * fan about the point average; the centre weights each triangle's centre by the
 * triangle's area |n_k|. (Later OpenFOAM.org versions weight by the area projected on the
 * face normal, n_k . sum n; on a warped face the two differ by up to about 1e-3 degrees
 * of non-orthogonality.) Corners are taken relative to the average, q_k = p_k - average,
 * where each fan triangle's area vector is simply q_k x q_k+1. Branch-free: see
 * scalarFace and usableLanes for the degenerate cases.
 */
/// The corners relative to their average (set in `face`, with the squared diagonals
/// faceCollapsed needs): what quadFace and quadFaceArea start from, the same bits.
template <typename T>
inline void centredCorners(const V3<T> (&p)[4], FaceGeometry<T>& face, V3<T> (&q)[4])
{
  face.average = 0.25 * ((p[0] + p[1]) + (p[2] + p[3]));
  for (int corner = 0; corner < 4; ++corner)
  {
    q[corner] = p[corner] - face.average;
  }
  const V3<T> diagonal0 = q[2] - q[0], diagonal1 = q[3] - q[1];
  face.diagonals2 = dot(diagonal0, diagonal0) + dot(diagonal1, diagonal1);
}

template <typename T>
inline FaceGeometry<T> quadFace(const V3<T> (&p)[4])
{
  FaceGeometry<T> face;
  V3<T> q[4];
  centredCorners(p, face, q);
  const V3<T> &q0 = q[0], &q1 = q[1], &q2 = q[2], &q3 = q[3];
  const V3<T> n0 = cross(q0, q1), n1 = cross(q1, q2), n2 = cross(q2, q3), n3 = cross(q3, q0);
  const V3<T> sumN = (n0 + n1) + (n2 + n3);
  face.area = 0.5 * sumN;
  face.area2 = dot(face.area, face.area);
  const T w0 = vsqrt(dot(n0, n0)), w1 = vsqrt(dot(n1, n1)), w2 = vsqrt(dot(n2, n2)),
          w3 = vsqrt(dot(n3, n3));
  face.weightSum = (w0 + w1) + (w2 + w3);
  const V3<T> weighted = (w0 * (q0 + q1) + w1 * (q1 + q2)) + (w2 * (q2 + q3) + w3 * (q3 + q0));
  const T scale = 1.0 / (3.0 * face.weightSum);
  face.centre = face.average + scale * weighted;
  return face;
}

/// The area vector of quadFace alone, by the same operations (the same bits), with the
/// squared diagonals faceCollapsed needs; the centre and weights are not computed (0).
template <typename T>
inline FaceGeometry<T> quadFaceArea(const V3<T> (&p)[4])
{
  FaceGeometry<T> face;
  V3<T> q[4];
  centredCorners(p, face, q);
  const V3<T> sumN = (cross(q[0], q[1]) + cross(q[1], q[2])) + (cross(q[2], q[3]) + cross(q[3], q[0]));
  face.area = 0.5 * sumN;
  face.area2 = dot(face.area, face.area);
  face.centre = face.average;
  face.weightSum = splat<T>(0.0);
  return face;
}

/// No usable normal: zero area up to round-off (collapsed edges of wedges and prisms).
inline bool faceCollapsed(double area2, double diagonals2)
{
  return area2 <= collapsedFaceFraction * collapsedFaceFraction * diagonals2 * diagonals2;
}

/// OpenFOAM v1912's guard for the face centre: the point average when sumA < rootVSmall.
inline bool regularCentre(double weightSum)
{
  return weightSum >= rootVSmall;
}

/// Scalar face with OpenFOAM's guard for the centre (regularCentre).
inline FaceGeometry<double> scalarFace(const P3 (&p)[4])
{
  FaceGeometry<double> face = quadFace(p);
  if (!regularCentre(face.weightSum))
  {
    face.centre = face.average;
  }
  return face;
}

/// Cosine of the non-orthogonality angle (OpenFOAM's faceOrthogonality).
inline double orthogonalityCosine(const P3& ownerToNeighbour, const P3& area)
{
  return dot(ownerToNeighbour, area) /
    (std::sqrt(dot(ownerToNeighbour, ownerToNeighbour) * dot(area, area)) + rootVSmall);
}

/// OpenFOAM's skewness of a face with the given owner-to-neighbour vector `d`
/// (meshCheck::faceSkewness; boundaryFaceSkewness passes the projected d and 0.4).
inline double skewness(const P3& ownerCentre, const P3& d, double distanceFactor, const P3& area,
  const P3& centre, const P3 (&corners)[4])
{
  const P3 ownerToFace = centre - ownerCentre;
  const double along = dot(area, ownerToFace) / (dot(area, d) + rootVSmall);
  const P3 sv = ownerToFace - along * d;
  const double svLength = std::sqrt(dot(sv, sv));
  const P3 svHat = (1.0 / (svLength + rootVSmall)) * sv;
  double normalisation = distanceFactor * std::sqrt(dot(d, d)) + rootVSmall;
  for (const P3& corner : corners)
  {
    normalisation = std::max(normalisation, std::abs(dot(svHat, corner - centre)));
  }
  return svLength / normalisation;
}

inline double boundarySkewness(
  const P3& ownerCentre, const P3& area, const P3& centre, const P3 (&corners)[4])
{
  const P3 normal = (1.0 / (std::sqrt(dot(area, area)) + rootVSmall)) * area;
  const P3 d = dot(normal, centre - ownerCentre) * normal;
  return skewness(ownerCentre, d, 0.4, area, centre, corners);
}

/// cos * |cos|: ordered like the cosine, and needs no square root per face.
inline double signedSquare(double cosine)
{
  return cosine * std::abs(cosine);
}

/// Face measures before the per-lane checks.
template <typename T>
struct FaceMeasures
{
  T cosine2; ///< signed squared cosine of the non-orthogonality
  T skew;
  T areaDotD; ///< S . d, the denominator OpenFOAM guards
  T sv2;
};

/**
 * Non-orthogonality (as signed squared cosine) and skewness of an internal face whose
 * area vector points from owner to neighbour, with one root and three divisions.
 * Skewness is OpenFOAM's |sv| / fd rewritten with sv' = (S.d) sv, which avoids forming
 * sv and its unit vector:
 *   |sv| / max(0.2 |d|, max_k |sv^.r_k|) = |sv'|^2 / (|S.d| max(0.2 |d||sv'|, max_k |sv'.r_k|)).
 * Branch-free; usableLanes says which lanes need the literal formulas.
 */
template <typename T>
inline FaceMeasures<T> internalFaceKernel(const V3<T> (&q)[4], const FaceGeometry<T>& face,
  const V3<T>& ownerCentre, const V3<T>& neighbourCentre)
{
  FaceMeasures<T> m;
  const V3<T> d = neighbourCentre - ownerCentre;
  const T dd = dot(d, d);
  const T g = dot(face.area, d);
  m.areaDotD = g;
  m.cosine2 = g * vabs(g) / (dd * face.area2 + rootVSmall * rootVSmall);
  const V3<T> ownerToFace = face.centre - ownerCentre;
  const V3<T> svScaled = g * ownerToFace - dot(face.area, ownerToFace) * d;
  m.sv2 = dot(svScaled, svScaled);
  T largestProjection = vabs(dot(svScaled, q[0] - face.centre));
  for (int k = 1; k < 4; ++k)
  {
    largestProjection = vmax(largestProjection, vabs(dot(svScaled, q[k] - face.centre)));
  }
  m.skew = m.sv2 / (vabs(g) * vmax(0.2 * vsqrt(dd * m.sv2), largestProjection));
  return m;
}

/// The literal formulas for the lanes the kernel cannot handle; true if the face counts.
inline bool internalFaceSpecialCase(
  const P3 (&q)[4], const P3& ownerCentre, const P3& neighbourCentre, double& cosine2, double& skew)
{
  const FaceGeometry<double> face = scalarFace(q);
  if (faceCollapsed(face.area2, face.diagonals2))
  {
    return false;
  }
  const P3 d = neighbourCentre - ownerCentre;
  cosine2 = signedSquare(orthogonalityCosine(d, face.area));
  skew = skewness(ownerCentre, d, 0.2, face.area, face.centre, q);
  return true;
}

/// Lanes (bits) where the kernel's result holds: a usable face with S.d and sv' away
/// from 0 and a regular centre; the others take internalFaceSpecialCase.
template <typename T>
inline int usableLanes(const FaceGeometry<T>& face, const FaceMeasures<T>& m)
{
  constexpr int lanes = laneCount<T>;
  double area2[lanes], diagonals2[lanes], weightSum[lanes], areaDotD[lanes], sv2[lanes];
  extractLanes(face.area2, area2);
  extractLanes(face.diagonals2, diagonals2);
  extractLanes(face.weightSum, weightSum);
  extractLanes(m.areaDotD, areaDotD);
  extractLanes(m.sv2, sv2);
  int usable = 0;
  for (int l = 0; l < lanes; ++l)
  {
    if (!faceCollapsed(area2[l], diagonals2[l]) && std::abs(areaDotD[l]) >= 1e-100 &&
      sv2[l] > 0.0 && regularCentre(weightSum[l]))
    {
      usable |= 1 << l;
    }
  }
  return usable;
}

// ---------------------------------------------------------------------------------------
// Cell centres

/// Upper face f (1, 3, 5: i1, j1, k1) of a hexahedron, outward, in the corner order of
/// hexFaces.
template <typename T>
inline FaceGeometry<T> hexFace(const V3<T> (&c)[8], int f)
{
  const V3<T> p[4] = { c[hexFaces[f][0]], c[hexFaces[f][1]], c[hexFaces[f][2]], c[hexFaces[f][3]] };
  return quadFace(p);
}

/// Lower face along direction d (0, 1, 2: i0, j0, k0) with its area vector into the cell,
/// in the corner order in which the neighbour below computes it as its upper face
/// (hexFace), so both cells get the same bits.
template <typename T>
inline FaceGeometry<T> lowerHexFace(const V3<T> (&c)[8], int d)
{
  static constexpr int lower[3][4] = { { 0, 3, 7, 4 }, { 0, 4, 5, 1 }, { 0, 1, 2, 3 } };
  const V3<T> p[4] = { c[lower[d][0]], c[lower[d][1]], c[lower[d][2]], c[lower[d][3]] };
  return quadFace(p);
}

/// The same face seen from its other side: the area vector reversed.
template <typename T>
inline FaceGeometry<T> reversed(FaceGeometry<T> face)
{
  face.area = { splat<T>(0.0) - face.area.x, splat<T>(0.0) - face.area.y,
    splat<T>(0.0) - face.area.z };
  return face;
}

/// The six faces of a hexahedron, outward area vectors (hexFaces order), each computed in
/// its canonical corner order (a face shared by two cells gets the same bits in both).
template <typename T>
inline void hexFaceGeometry(const V3<T> (&c)[8], FaceGeometry<T> (&faces)[6])
{
  for (int d = 0; d < 3; ++d)
  {
    faces[2 * d] = reversed(lowerHexFace(c, d));
    faces[2 * d + 1] = hexFace(c, 2 * d + 1);
  }
}

/// Positive where a face is not collapsed (faceCollapsed); NaN inputs give NaN, which
/// callers treat as not positive.
template <typename T>
inline T collapseMargin(const FaceGeometry<T>& face)
{
  return face.area2 -
    (collapsedFaceFraction * collapsedFaceFraction) * (face.diagonals2 * face.diagonals2);
}

/**
 * OpenFOAM's cell centre (primitiveMesh::makeCellCentresAndVols): the volume-weighted
 * centre of the pyramids from each face to the mean of the face centres, which is the
 * cell's volume centroid (the mean of the corners is not, unless the cell is a
 * parallelepiped). Branch-free; `usable` gets the lanes (bits) where the result holds:
 * every face has a regular centre and no face is collapsed, and the volume is not zero.
 * The others take cellCentroidSpecialCase.
 */
template <typename T>
inline V3<T> cellCentroidKernel(int& usable, const FaceGeometry<T> (&faces)[6])
{
  const V3<T> estimate = (1.0 / 6.0) *
    (((faces[0].centre + faces[1].centre) + (faces[2].centre + faces[3].centre)) +
      (faces[4].centre + faces[5].centre));
  V3<T> weighted = { splat<T>(0.0), splat<T>(0.0), splat<T>(0.0) };
  T volume = splat<T>(0.0);
  for (const FaceGeometry<T>& face : faces)
  {
    const T pyramid3 = dot(face.area, face.centre - estimate);
    weighted = weighted + pyramid3 * (0.75 * face.centre + 0.25 * estimate);
    volume = volume + pyramid3;
  }
  // Lane-wise minima over the faces, extracted once: the areas against their collapse
  // threshold, the centre weights against OpenFOAM's guard; and the volume against vSmall.
  T collapse = collapseMargin(faces[0]), weight = faces[0].weightSum;
  for (int f = 1; f < 6; ++f)
  {
    collapse = vmin(collapse, collapseMargin(faces[f]));
    weight = vmin(weight, faces[f].weightSum);
  }
  constexpr int lanes = laneCount<T>;
  double volumes[lanes], collapses[lanes], weights[lanes];
  extractLanes(volume, volumes);
  extractLanes(collapse, collapses);
  extractLanes(weight, weights);
  usable = 0;
  for (int l = 0; l < lanes; ++l)
  {
    usable |= (std::abs(volumes[l]) > vSmall && collapses[l] > 0.0 && regularCentre(weights[l])) << l;
  }
  return (1.0 / volume) * weighted;
}

/// The centre of a cell with collapsed faces or edges, or no volume: as OpenFOAM's mesh
/// of it would have it (blockMesh drops collapsed faces), the estimate alone when the
/// volume is zero, the mean of the corners when no face is left.
inline P3 cellCentroidSpecialCase(const P3 (&c)[8])
{
  FaceGeometry<double> faces[6];
  bool kept[6];
  P3 estimate = { 0.0, 0.0, 0.0 };
  int count = 0;
  for (int f = 0; f < 6; ++f)
  {
    const P3 p[4] = { c[hexFaces[f][0]], c[hexFaces[f][1]], c[hexFaces[f][2]], c[hexFaces[f][3]] };
    faces[f] = scalarFace(p);
    kept[f] = !faceCollapsed(faces[f].area2, faces[f].diagonals2);
    if (kept[f])
    {
      estimate = estimate + faces[f].centre;
      ++count;
    }
  }
  if (count == 0)
  {
    return 0.125 * (((c[0] + c[1]) + (c[2] + c[3])) + ((c[4] + c[5]) + (c[6] + c[7])));
  }
  estimate = (1.0 / count) * estimate;
  P3 weighted = { 0.0, 0.0, 0.0 };
  double volume = 0.0;
  for (int f = 0; f < 6; ++f)
  {
    if (kept[f])
    {
      const double pyramid3 = dot(faces[f].area, faces[f].centre - estimate);
      weighted = weighted + pyramid3 * (0.75 * faces[f].centre + 0.25 * estimate);
      volume += pyramid3;
    }
  }
  return std::abs(volume) > vSmall ? (1.0 / volume) * weighted : estimate;
}

/// OpenFOAM's cell centre of every lane from the geometry of its six faces (outward area
/// vectors, hexFaces order; the grid pass computes each face once for both its cells).
/// `regular` (may be null) gets the lanes (bits) whose cell has no collapsed face and a
/// volume: the lanes where cellDeterminantKernel's result holds.
template <typename T>
inline V3<T> cellCentroidFromFaces(
  const V3<T> (&c)[8], const FaceGeometry<T> (&faces)[6], int* regular = nullptr)
{
  int usable = 0;
  V3<T> centre = cellCentroidKernel(usable, faces);
  if (regular)
  {
    *regular = usable;
  }
  for (int l = 0; usable != (1 << laneCount<T>)-1 && l < laneCount<T>; ++l)
  {
    if (!(usable & (1 << l)))
    {
      P3 corners[8];
      for (int v = 0; v < 8; ++v)
      {
        corners[v] = laneOf(c[v], l);
      }
      const P3 special = cellCentroidSpecialCase(corners);
      setLane(centre.x, l, special.x);
      setLane(centre.y, l, special.y);
      setLane(centre.z, l, special.z);
    }
  }
  return centre;
}

// ---------------------------------------------------------------------------------------
// Cell determinant

/**
 * checkMesh's cell determinant (OpenFOAM primitiveMeshTools::cellDeterminant, under
 * -allGeometry) of one cell from the area vectors S_f of its `count` internal or coupled
 * faces and their lengths |S_f|: with a = mean |S_f|, T = sum (S_f/a)(S_f/a)^T, the value
 * is |det T| / 8, 1 for a cube whose six faces all count. checkMesh fails a cell under
 * 1e-3. The caller has left out the true boundary faces and the collapsed ones, and
 * handles count 0 and a vanishing mean (cellDeterminantOfFaces). det T is taken as
 * det(sum S_f S_f^T) / a^6 (18 multiplications fewer than scaling every S_f first; the
 * same value to round-off, and no under- or overflow for face areas between about 1e-50
 * and 1e50). The determinant is expanded as for OpenFOAM's symmTensor. Branch-free.
 */
template <typename T>
inline T cellDeterminantKernel(const V3<T>* areas, const T* lengths, int count)
{
  T sum = lengths[0];
  const T zero = splat<T>(0.0);
  T xx = zero, xy = zero, xz = zero, yy = zero, yz = zero, zz = zero;
  for (int f = 0; f < count; ++f)
  {
    if (f > 0)
    {
      sum = sum + lengths[f];
    }
    const V3<T>& s = areas[f];
    xx = xx + s.x * s.x;
    xy = xy + s.x * s.y;
    xz = xz + s.x * s.z;
    yy = yy + s.y * s.y;
    yz = yz + s.y * s.z;
    zz = zz + s.z * s.z;
  }
  const T det = ((xx * yy * zz + xy * yz * xz) + xz * xy * yz) - xx * yz * yz - xy * xy * zz -
    xz * yy * xz;
  const T scale = double(count) / sum; // 1 / mean area
  const T scale2 = scale * scale;
  return (0.125 * vabs(det)) * (scale2 * scale2 * scale2);
}

/**
 * The cell determinant from the cell's six faces (hexFaces order) of which the bits of
 * `counted` (1 << f) are internal or coupled: collapsed faces (no area: a wedge's or a
 * fan's collapsed edge, which the polyMesh writer drops) are left out as well; 0 when no
 * face is left or the faces' summed area is under OpenFOAM's vSmall, as checkMesh has it.
 * The sign of an area vector does not matter (T is quadratic in S_f).
 */
inline double cellDeterminantOfFaces(const FaceGeometry<double> (&faces)[6], int counted)
{
  P3 areas[6];
  double lengths[6];
  int count = 0;
  double sum = 0.0;
  for (int f = 0; f < 6; ++f)
  {
    if ((counted & (1 << f)) && !faceCollapsed(faces[f].area2, faces[f].diagonals2))
    {
      areas[count] = faces[f].area;
      lengths[count] = std::sqrt(faces[f].area2);
      sum += lengths[count];
      ++count;
    }
  }
  if (count == 0 || sum < vSmall)
  {
    return 0.0;
  }
  return cellDeterminantKernel(areas, lengths, count);
}

template <typename T>
inline V3<T> cellCentroid(const V3<T> (&c)[8])
{
  FaceGeometry<T> faces[6];
  hexFaceGeometry(c, faces);
  return cellCentroidFromFaces(c, faces);
}


} // namespace quality
} // namespace blockforge
