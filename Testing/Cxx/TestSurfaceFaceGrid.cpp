// Face grids on surfaces (Filters/Core/SurfaceFaceGrid.h) on analytic surfaces: a
// cylinder, a sphere and a thin twisted blade of elliptic section, with edge
// distributions graded to cells 1e-4 of the face: no folded cell, every node on the
// surface, and the projected TFI alone shown to fold on the blade; on a thin blade whose
// sections turn along the span, its cells by the nose shown to shrink 3 times without a
// fold, and the guard to keep them within 1.5 of the parameter grid's.
#include "SurfaceFaceGrid.h"

#include "TestHelpers.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

using namespace blockforge;

namespace
{
constexpr double Pi = 3.14159265358979323846;

/// An analytic surface with its unit normal and the distance of a point from it.
class Analytic : public ParametricSurface
{
public:
  virtual Vec3 normal(double s, double t) const = 0;
  virtual double distance(const Vec3& p) const = 0;
  /// (s, t) of a point on the surface.
  virtual Eigen::Vector2d parameters(const Vec3& p) const = 0;
};

/// Cylinder of radius 1 about z: s is the angle / 2 pi, t the height.
class Cylinder final : public Analytic
{
public:
  Vec3 point(double s, double t) const override
  {
    return Vec3(std::cos(2 * Pi * s), std::sin(2 * Pi * s), t);
  }
  Vec3 normal(double s, double) const override
  {
    return Vec3(std::cos(2 * Pi * s), std::sin(2 * Pi * s), 0.0);
  }
  double distance(const Vec3& p) const override { return std::abs(std::hypot(p[0], p[1]) - 1.0); }
  Eigen::Vector2d parameters(const Vec3& p) const override
  {
    return Eigen::Vector2d(std::atan2(p[1], p[0]) / (2 * Pi), p[2]);
  }
};

/// Unit sphere: s the longitude / 2 pi, t the latitude / pi + 1/2.
class Sphere final : public Analytic
{
public:
  Vec3 point(double s, double t) const override
  {
    const double lat = Pi * (t - 0.5), lon = 2 * Pi * s;
    return Vec3(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
  }
  Vec3 normal(double s, double t) const override { return point(s, t); }
  double distance(const Vec3& p) const override { return std::abs(p.norm() - 1.0); }
  Eigen::Vector2d parameters(const Vec3& p) const override
  {
    return Eigen::Vector2d(
      std::atan2(p[1], p[0]) / (2 * Pi), std::asin(std::clamp(p[2], -1.0, 1.0)) / Pi + 0.5);
  }
};

/**
 * A thin blade: ellipse sections of chord 1 (semi-axes 0.5 and b, leading-edge radius
 * b^2 / 0.5 = 1e-3 of the chord), twisted by `twist` radians from t = 0 to t = 1 about
 * the mid-chord, span 1 along z; s = 0.5 is the leading edge (x = -0.5).
 */
class TwistedBlade final : public Analytic
{
public:
  explicit TwistedBlade(double twist)
    : Twist(twist)
  {
  }
  static constexpr double A = 0.5;
  const double B = std::sqrt(1e-3 * A);
  Vec3 point(double s, double t) const override
  {
    const double x = A * std::cos(2 * Pi * s), y = B * std::sin(2 * Pi * s);
    const double c = std::cos(Twist * t), n = std::sin(Twist * t);
    return Vec3(c * x - n * y, n * x + c * y, t);
  }
  Vec3 normal(double s, double t) const override
  {
    const Vec3 ps = (point(s + 1e-7, t) - point(s - 1e-7, t));
    const Vec3 pt = (point(s, t + 1e-7) - point(s, t - 1e-7));
    return ps.cross(pt).normalized();
  }
  /// First-order distance from the implicit section equation (x/A)^2 + (y/B)^2 = 1.
  double distance(const Vec3& p) const override
  {
    const double t = p[2], c = std::cos(Twist * t), n = std::sin(Twist * t);
    const double x = c * p[0] + n * p[1], y = -n * p[0] + c * p[1];
    const double f = x * x / (A * A) + y * y / (B * B) - 1.0;
    const double g = std::hypot(2 * x / (A * A), 2 * y / (B * B));
    return std::abs(f) / g;
  }
  Eigen::Vector2d parameters(const Vec3& p) const override
  {
    const double t = p[2], c = std::cos(Twist * t), n = std::sin(Twist * t);
    const double x = c * p[0] + n * p[1], y = -n * p[0] + c * p[1];
    double s = std::atan2(y / B, x / A) / (2 * Pi);
    return Eigen::Vector2d(s < 0.0 ? s + 1.0 : s, t);
  }

private:
  double Twist;
};

/**
 * A thin blade whose sections turn about the leading edge's tip along the span: the
 * TwistedBlade's elliptic sections (leading-edge radius 1e-3 of the chord) turned by
 * `turn` 4 t (1 - t) radians about (-A, 0), so hub and shroud sections are alike and a
 * face's nodes should lie at the same s on every row.
 */
class BentBlade final : public Analytic
{
public:
  explicit BentBlade(double turn)
    : Turn(turn)
  {
  }
  static constexpr double A = 0.5;
  const double B = std::sqrt(1e-3 * A);
  Vec3 point(double s, double t) const override
  {
    const double x = A * std::cos(2 * Pi * s) + A, y = B * std::sin(2 * Pi * s);
    const double a = angle(t), c = std::cos(a), n = std::sin(a);
    return Vec3(c * x - n * y - A, n * x + c * y, t);
  }
  Vec3 normal(double s, double t) const override
  {
    const Vec3 ps = (point(s + 1e-7, t) - point(s - 1e-7, t));
    const Vec3 pt = (point(s, t + 1e-7) - point(s, t - 1e-7));
    return ps.cross(pt).normalized();
  }
  /// First-order distance from the implicit section equation (x/A)^2 + (y/B)^2 = 1.
  double distance(const Vec3& p) const override
  {
    double x = 0.0, y = 0.0;
    section(p, x, y);
    const double f = x * x / (A * A) + y * y / (B * B) - 1.0;
    return std::abs(f) / std::hypot(2 * x / (A * A), 2 * y / (B * B));
  }
  Eigen::Vector2d parameters(const Vec3& p) const override
  {
    double x = 0.0, y = 0.0;
    section(p, x, y);
    double s = std::atan2(y / B, x / A) / (2 * Pi);
    return Eigen::Vector2d(s < 0.0 ? s + 1.0 : s, p[2]);
  }

private:
  double angle(double t) const { return Turn * 4 * t * (1 - t); }
  /// The point in its section's own frame (ellipse centred at the origin).
  void section(const Vec3& p, double& x, double& y) const
  {
    const double a = angle(p[2]), c = std::cos(a), n = std::sin(a);
    const double u = p[0] + A, v = p[1];
    x = c * u + n * v - A;
    y = -n * u + c * v;
  }
  double Turn;
};

/// Node fractions of `cells` cells: geometric from a first cell `first` (relative) at
/// u = 0 (atStart) or at u = 1, uniform for first = 0.
std::vector<double> graded(int cells, double first, bool atStart)
{
  std::vector<double> u(cells + 1);
  double ratio = 1.0;
  if (first > 0.0)
  {
    double low = 1.0, high = 10.0; // sum of first * ratio^k = 1
    for (int i = 0; i < 200; ++i)
    {
      ratio = 0.5 * (low + high);
      (first * (std::pow(ratio, cells) - 1) / (ratio - 1) > 1.0 ? high : low) = ratio;
    }
  }
  double x = 0.0, h = first > 0.0 ? first : 1.0 / cells;
  for (int k = 0; k <= cells; ++k)
  {
    u[k] = k == cells ? 1.0 : x;
    x += h;
    h *= ratio;
  }
  if (!atStart)
  {
    std::reverse(u.begin(), u.end());
    for (double& v : u)
      v = 1.0 - v;
  }
  return u;
}

/// An edge: a straight line in (s, t) from `from` to `to`, nodes at arc-length fractions.
struct Edge
{
  std::vector<Eigen::Vector2d> st;
  std::vector<double> xyz, params;
  EdgeNodes nodes() const { return EdgeNodes{ xyz.data(), params.data(), static_cast<int>(params.size()) }; }
};

Edge makeEdge(const ParametricSurface& surface, Eigen::Vector2d from, Eigen::Vector2d to,
  const std::vector<double>& fractions)
{
  const int samples = 20000;
  std::vector<double> arc(samples + 1, 0.0);
  auto at = [&](double u) { return Eigen::Vector2d(from + u * (to - from)); };
  for (int k = 1; k <= samples; ++k)
  {
    const Eigen::Vector2d a = at((k - 1.0) / samples), b = at(double(k) / samples);
    arc[k] = arc[k - 1] + (surface.point(b[0], b[1]) - surface.point(a[0], a[1])).norm();
  }
  Edge edge;
  for (const double f : fractions)
  {
    // the curve parameter at arc-length fraction f: table, then bisection between samples
    const double wanted = f * arc.back();
    const auto it = std::lower_bound(arc.begin(), arc.end(), wanted);
    const int k = std::clamp(static_cast<int>(it - arc.begin()), 1, samples);
    double low = (k - 1.0) / samples, high = double(k) / samples;
    const Eigen::Vector2d a = at(low);
    const Vec3 pa = surface.point(a[0], a[1]);
    for (int i = 0; i < 60; ++i)
    {
      const double mid = 0.5 * (low + high);
      const Eigen::Vector2d m = at(mid);
      ((arc[k - 1] + (surface.point(m[0], m[1]) - pa).norm() < wanted) ? low : high) = mid;
    }
    const double u = f <= 0.0 ? 0.0 : f >= 1.0 ? 1.0 : 0.5 * (low + high);
    const Eigen::Vector2d p = at(u);
    edge.st.push_back(p);
    const Vec3 x = surface.point(p[0], p[1]);
    edge.xyz.insert(edge.xyz.end(), { x[0], x[1], x[2] });
    edge.params.push_back(f);
  }
  return edge;
}

/// A face given by its four corners in (s, t) and the node fractions along a and b.
struct FaceCase
{
  Eigen::Vector2d corner[4]; // (a, b) = (0, 0), (1, 0), (1, 1), (0, 1)
  std::vector<double> alongA, alongB;
};

struct FaceResult
{
  std::vector<double> xyz;
  int na = 0, nb = 0;
  SurfaceFaceReport report;
};

FaceResult meshFace(const ParametricSurface& surface, const FaceCase& face, SurfaceFaceMethod method)
{
  const Edge bottom = makeEdge(surface, face.corner[0], face.corner[1], face.alongA);
  const Edge top = makeEdge(surface, face.corner[3], face.corner[2], face.alongA);
  const Edge left = makeEdge(surface, face.corner[0], face.corner[3], face.alongB);
  const Edge right = makeEdge(surface, face.corner[1], face.corner[2], face.alongB);
  FaceResult result;
  result.na = static_cast<int>(face.alongA.size());
  result.nb = static_cast<int>(face.alongB.size());
  const int na = result.na, nb = result.nb;
  std::vector<Eigen::Vector2d> loop;
  for (int a = 0; a < na; ++a)
    loop.push_back(bottom.st[a]);
  for (int b = 1; b < nb; ++b)
    loop.push_back(right.st[b]);
  for (int a = na - 2; a >= 0; --a)
    loop.push_back(top.st[a]);
  for (int b = nb - 2; b >= 1; --b)
    loop.push_back(left.st[b]);
  result.xyz.assign(3 * static_cast<std::size_t>(na) * nb, 0.0);
  surfaceFaceGrid(surface, loop, bottom.nodes(), top.nodes(), left.nodes(), right.nodes(),
    result.xyz.data(), method, &result.report);
  return result;
}

/// Smallest scaled Jacobian of the cells' corners on the surface (the normal at the
/// surface point nearest the cell's first corner, found from its (s, t) guess).
struct Check
{
  double smallestJacobian = 1.0;
  int folded = 0;
  int foldedInParameters = 0; ///< cells whose corners' (s, t) are out of order
  double offSurface = 0.0;
};

Check check(const Analytic& surface, const FaceResult& grid, const FaceCase& face)
{
  Check result;
  const int na = grid.na, nb = grid.nb;
  auto node = [&](int a, int b) {
    const double* p = &grid.xyz[3 * (static_cast<std::size_t>(b) * na + a)];
    return Vec3(p[0], p[1], p[2]);
  };
  // the face's orientation: its corners' (s, t) loop
  const Eigen::Vector2d e1 = face.corner[1] - face.corner[0], e2 = face.corner[3] - face.corner[0];
  const double orientation = e1[0] * e2[1] - e1[1] * e2[0] > 0.0 ? 1.0 : -1.0;
  for (int b = 0; b < nb; ++b)
  {
    for (int a = 0; a < na; ++a)
    {
      result.offSurface = std::max(result.offSurface, surface.distance(node(a, b)));
    }
  }
  for (int b = 0; b + 1 < nb; ++b)
  {
    for (int a = 0; a + 1 < na; ++a)
    {
      const Vec3 c[4] = { node(a, b), node(a + 1, b), node(a + 1, b + 1), node(a, b + 1) };
      bool folded = false;
      for (int k = 0; k < 4; ++k)
      {
        // against the surface normal at the corner
        const Eigen::Vector2d st = surface.parameters(c[k]);
        const Vec3 n = orientation * surface.normal(st[0], st[1]);
        const Vec3 x = c[(k + 1) % 4] - c[k], y = c[(k + 3) % 4] - c[k];
        const double j = x.cross(y).dot(n) / (x.norm() * y.norm());
        result.smallestJacobian = std::min(result.smallestJacobian, j);
        folded = folded || !(j > 0.0);
      }
      result.folded += folded;
      bool out = false;
      for (int k = 0; k < 4; ++k)
      {
        const Eigen::Vector2d p = surface.parameters(c[k]);
        Eigen::Vector2d x = surface.parameters(c[(k + 1) % 4]) - p, y = surface.parameters(c[(k + 3) % 4]) - p;
        for (Eigen::Vector2d* e : { &x, &y })
          (*e)[0] -= std::round((*e)[0]);
        out = out || !(orientation * (x[0] * y[1] - x[1] * y[0]) > 0.0);
      }
      result.foldedInParameters += out;
    }
  }
  return result;
}
/// The guarded grid of `face`, checked: no cell folded (on the surface, in (s, t)),
/// corners' scaled Jacobians above `least`, every node on the surface to 1e-12.
FaceResult meshValidFace(const Analytic& surface, const FaceCase& face, double least)
{
  FaceResult grid = meshFace(surface, face, SurfaceFaceMethod::Guarded);
  const Check result = check(surface, grid, face);
  EXPECT_EQ(result.folded, 0);
  EXPECT_EQ(result.foldedInParameters, 0);
  EXPECT_GT(result.smallestJacobian, least);
  EXPECT_LT(result.offSurface, 1e-12);
  return grid;
}
} // namespace

TEST(SurfaceFaceGrid, CylinderGradedToOneTenThousandth)
{
  const Cylinder cylinder;
  for (const bool atStart : { true, false })
  {
    FaceCase face{ { Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.25, 0.1),
                     Eigen::Vector2d(0.3, 1.0), Eigen::Vector2d(-0.05, 0.9) },
      graded(40, 1e-4, atStart), graded(30, 1e-4, !atStart) };
    const FaceResult grid = meshValidFace(cylinder, face, 0.5);
    // where the projected TFI does not fold, the guard leaves it alone, bit for bit
    const FaceResult plain = meshFace(cylinder, face, SurfaceFaceMethod::ProjectedTfi);
    EXPECT_EQ(grid.report.guardedNodes, 0);
    EXPECT_EQ(plain.xyz, grid.xyz);
  }
}

TEST(SurfaceFaceGrid, SphereGradedToOneTenThousandth)
{
  const Sphere sphere;
  FaceCase face{ { Eigen::Vector2d(0.0, 0.3), Eigen::Vector2d(0.2, 0.25),
                   Eigen::Vector2d(0.22, 0.8), Eigen::Vector2d(0.02, 0.85) },
    graded(40, 1e-4, false), graded(40, 1e-4, true) };
  meshValidFace(sphere, face, 0.3);
}

TEST(SurfaceFaceGrid, TwistedThinBladeProjectedTfiFoldsGuardedDoesNot)
{
  // Leading-edge radius 1e-3 of the chord, twisted by 2 radians over the span. The face
  // runs along one side from mid-chord round the leading edge (s = 0.5) a little onto the
  // other side, its cells graded to 1e-4 of the face at the leading-edge end and at the
  // tip. The nearest surface points of its 3-D TFI nodes fall behind their neighbours
  // round the nose; the guard keeps every cell's corners in order in (s, t), so on the
  // surface (the surface maps a positive parameter cell to a positive surface cell).
  const TwistedBlade blade(2.0);
  for (const double from : { 0.25, 0.4 })
  {
    FaceCase face{ { Eigen::Vector2d(from, 0.0), Eigen::Vector2d(0.52, 0.0),
                     Eigen::Vector2d(0.52, 1.0), Eigen::Vector2d(from, 1.0) },
      graded(48, 1e-4, false), graded(24, 1e-4, false) };
    const FaceResult old = meshFace(blade, face, SurfaceFaceMethod::ProjectedTfi);
    const Check before = check(blade, old, face);
    std::printf("s from %.2f: projected TFI: %d cells out of order\n", from, before.foldedInParameters);
    EXPECT_GT(before.foldedInParameters, 0);
    const FaceResult grid = meshFace(blade, face, SurfaceFaceMethod::Guarded);
    const Check after = check(blade, grid, face);
    std::printf("guarded: %d cells out of order, %d nodes guarded in %d rounds\n",
      after.foldedInParameters, grid.report.guardedNodes, grid.report.rounds);
    EXPECT_EQ(after.foldedInParameters, 0);
    EXPECT_GT(grid.report.guardedNodes, 0);
    EXPECT_LT(after.offSurface, 1e-12);
    // the same bits on threads
    test::ThreadRunner threads(2);
    EXPECT_EQ(meshFace(blade, face, SurfaceFaceMethod::Guarded).xyz, grid.xyz);
  }
}

TEST(SurfaceFaceGrid, BentThinBladeCellsDoNotSlideAlongTheNose)
{
  // A face along one side of a thin blade (leading-edge radius 1e-3 of the chord) from a
  // tenth of the loop behind the leading edge to its tip, cells graded to 1e-3 of the face
  // there, on a blade whose sections turn about the tip by up to 0.6 radians at mid-span,
  // none at hub and shroud. The face's far side bows with the turn, its tip side does
  // not; TFI blends the far side's bow into the nodes by the tip with its small weight,
  // and the turned nose runs across the hub's and shroud's offsets: projected, the nodes
  // next to the tip slide towards it, the cells there 3 times shorter at mid-span than
  // at hub and shroud though none folds (Rotor 37's trailing edge in axial_passage_oh: 6
  // times). The guard holds every cell side within 1.5 of the parameter grid's, whose
  // nodes here lie at the same s on every row.
  const BentBlade blade(-0.6);
  FaceCase face{ { Eigen::Vector2d(0.4, 0.0), Eigen::Vector2d(0.5, 0.0),
                   Eigen::Vector2d(0.5, 1.0), Eigen::Vector2d(0.4, 1.0) },
    graded(24, 1e-3, false), graded(12, 0.0, true) };
  // the end cells by the tip on every row, over the hub row's (the same boundary
  // distribution on every row: 1 when nothing slides)
  auto endCells = [&](const FaceResult& grid, double& smallest, double& largest) {
    const int na = grid.na;
    auto node = [&](int a, int b) {
      const double* p = &grid.xyz[3 * (static_cast<std::size_t>(b) * na + a)];
      return Vec3(p[0], p[1], p[2]);
    };
    smallest = largest = 1.0;
    for (int a = na - 4; a + 1 < na; ++a)
    {
      const double hub = (node(a + 1, 0) - node(a, 0)).norm();
      for (int b = 1; b + 1 < grid.nb; ++b)
      {
        const double ratio = (node(a + 1, b) - node(a, b)).norm() / hub;
        smallest = std::min(smallest, ratio);
        largest = std::max(largest, ratio);
      }
    }
  };
  double smallest = 0.0, largest = 0.0;
  const FaceResult plain = meshFace(blade, face, SurfaceFaceMethod::ProjectedTfi);
  endCells(plain, smallest, largest);
  std::printf("projected TFI: end cells %.3f to %.3f of the hub's\n", smallest, largest);
  EXPECT_EQ(check(blade, plain, face).folded, 0);
  EXPECT_LT(smallest, 0.5);
  const FaceResult grid = meshValidFace(blade, face, 0.3);
  endCells(grid, smallest, largest);
  std::printf("guarded: end cells %.3f to %.3f of the hub's, %d nodes guarded in %d rounds\n",
    smallest, largest, grid.report.guardedNodes, grid.report.rounds);
  EXPECT_GT(grid.report.guardedNodes, 0);
  EXPECT_GT(smallest, 1.0 / 1.5);
  EXPECT_LT(largest, 1.5);
  test::ThreadRunner threads(2);
  EXPECT_EQ(meshFace(blade, face, SurfaceFaceMethod::Guarded).xyz, grid.xyz);
}
