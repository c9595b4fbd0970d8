// The inverted-cell check of block grids (Core: findInvertedCells) on analytic grids, and
// agreement of its verdict with the sign of Verdict's hex scaled Jacobian.
#include "InvertedCells.h"
#include "Quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

using namespace blockforge;

namespace
{
constexpr double Pi = 3.14159265358979323846;

/// A block of ni x nj x nk nodes mapped from the unit cube by `map(s, t, u)`.
struct Block
{
  int ni, nj, nk;
  std::vector<double> xyz;

  Block(int i, int j, int k, const std::function<Vec3(double, double, double)>& map)
    : ni(i)
    , nj(j)
    , nk(k)
    , xyz(3 * static_cast<std::size_t>(i) * j * k)
  {
    for (int c = 0; c < nk; ++c)
      for (int b = 0; b < nj; ++b)
        for (int a = 0; a < ni; ++a)
        {
          const Vec3 p = map(double(a) / (ni - 1), double(b) / (nj - 1), double(c) / (nk - 1));
          for (int d = 0; d < 3; ++d)
          {
            xyz[3 * index(a, b, c) + d] = p[d];
          }
        }
  }
  std::size_t index(int i, int j, int k) const
  {
    return i + static_cast<std::size_t>(ni) * (j + static_cast<std::size_t>(nj) * k);
  }
  double* node(int i, int j, int k) { return &xyz[3 * index(i, j, k)]; }
  std::array<Vec3, 8> cell(int i, int j, int k) const
  {
    const int offsets[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
      { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
    std::array<Vec3, 8> corners;
    for (int v = 0; v < 8; ++v)
    {
      const double* p =
        &xyz[3 * index(i + offsets[v][0], j + offsets[v][1], k + offsets[v][2])];
      corners[v] = Vec3(p[0], p[1], p[2]);
    }
    return corners;
  }
  InvertedCells check() const { return findInvertedCells(xyz.data(), ni, nj, nk); }
};

Vec3 cube(double s, double t, double u)
{
  return Vec3(s, 2 * t, 3 * u);
}

/// A quarter annulus, r in [1, 2], angle in [0, pi/2], height 1: curved, right-handed.
Vec3 annulus(double s, double t, double u)
{
  const double r = 1 + s, phi = 0.5 * Pi * t;
  return Vec3(r * std::cos(phi), r * std::sin(phi), u);
}
} // namespace

TEST(InvertedCells, RightHandedGridsPass)
{
  using Map = std::function<Vec3(double, double, double)>;
  for (const Map& map : { Map(cube), Map(annulus) })
  {
    const InvertedCells found = Block(9, 7, 5, map).check();
    EXPECT_EQ(found.count, 0);
    EXPECT_EQ(found.nonFinite, 0);
  }
}

TEST(InvertedCells, MirroredGridIsInvertedEverywhere)
{
  const Block mirrored(5, 4, 3, [](double s, double t, double u) {
    return Vec3(-s, t, u); // a left-handed box: every Jacobian is exactly -1 when scaled
  });
  const InvertedCells found = mirrored.check();
  EXPECT_EQ(found.count, 4 * 3 * 2);
  EXPECT_EQ(found.lowest, (std::array<int, 3>{ 0, 0, 0 }));
  EXPECT_EQ(found.highest, (std::array<int, 3>{ 3, 2, 1 }));
  EXPECT_NEAR(found.worstScaledJacobian, -1.0, 1e-12);
}

TEST(InvertedCells, OneNodePushedPastItsNeighbourInvertsTheCellsItLeads)
{
  // Unit spacing h = 0.25; node (2, 2, 2) moved by 1.5 h along +x passes node (3, 2, 2):
  // the four cells i = 2, j = 1..2, k = 1..2 (whose -x corner it is) fold at that corner.
  Block block(5, 5, 5, [](double s, double t, double u) { return Vec3(s, t, u); });
  block.node(2, 2, 2)[0] += 1.5 * 0.25;
  const InvertedCells found = block.check();
  EXPECT_EQ(found.count, 4);
  EXPECT_EQ(found.lowest, (std::array<int, 3>{ 2, 1, 1 }));
  EXPECT_EQ(found.highest, (std::array<int, 3>{ 2, 2, 2 }));
  // The folded corner: a = (-0.5h, 0, 0) against the unit frame: scaled Jacobian -1.
  EXPECT_NEAR(found.worstScaledJacobian, -1.0, 1e-12);
}

TEST(InvertedCells, VerdictAgreesOnEveryCellOfARandomlyDisturbedGrid)
{
  // Nodes moved at random by up to 0.45 of the spacing in each direction: some cells fold.
  Block block(9, 9, 9, annulus);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.45, 0.45);
  for (double& value : block.xyz)
  {
    value += jitter(random) * 0.12; // spacing: 0.125 radially, 0.196 around, 0.125 up
  }
  const InvertedCells found = block.check();
  std::int64_t expected = 0;
  double worst = 1.0;
  for (int k = 0; k + 1 < block.nk; ++k)
    for (int j = 0; j + 1 < block.nj; ++j)
      for (int i = 0; i + 1 < block.ni; ++i)
      {
        const double verdict = hexScaledJacobian(block.cell(i, j, k));
        expected += verdict < -1e-10;
        worst = std::min(worst, verdict);
      }
  ASSERT_GT(expected, 0) << "the disturbance must fold some cells for this test to mean much";
  EXPECT_LT(expected, 512);
  EXPECT_EQ(found.count, expected);
  EXPECT_NEAR(found.worstScaledJacobian, worst, 1e-12);
}

TEST(InvertedCells, WedgesOnAnAxisPassAndInvertedWedgesDoNot)
{
  // i = 0 on the z axis: every cell of the first layer has a collapsed edge.
  const auto wedge = [](double sign) {
    return [sign](double s, double t, double u) {
      const double phi = sign * 0.25 * Pi * t;
      return Vec3(s * std::cos(phi), s * std::sin(phi), u);
    };
  };
  EXPECT_EQ(Block(5, 4, 3, wedge(1.0)).check().count, 0);
  const InvertedCells folded = Block(5, 4, 3, wedge(-1.0)).check();
  EXPECT_EQ(folded.count, 4 * 3 * 2); // the wedges on the axis too
  EXPECT_EQ(folded.lowest[0], 0);
}

TEST(InvertedCells, FlatCellsAreNotInverted)
{
  // Zero thickness in k: no Jacobian is negative, so nothing is reported.
  EXPECT_EQ(Block(4, 4, 2, [](double s, double t, double) { return Vec3(s, t, 0); })
              .check()
              .count,
    0);
}

TEST(InvertedCells, NonFiniteNodesAreReported)
{
  Block block(4, 4, 4, cube);
  block.node(3, 3, 3)[1] = std::numeric_limits<double>::quiet_NaN();
  const InvertedCells found = block.check();
  EXPECT_EQ(found.count, 1);
  EXPECT_EQ(found.nonFinite, 1);
  EXPECT_EQ(found.lowest, (std::array<int, 3>{ 2, 2, 2 }));
}

TEST(InvertedCells, TooFewNodesIsNoCell)
{
  const std::vector<double> xyz(3 * 4, 0.0);
  EXPECT_EQ(findInvertedCells(xyz.data(), 4, 1, 1).count, 0);
  EXPECT_EQ(findInvertedCells(nullptr, 0, 0, 0).count, 0);
}
