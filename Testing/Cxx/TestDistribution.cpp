// Node distribution laws along an edge (paper eq. 7 and friends).
#include "Distribution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using namespace blockforge;

namespace
{
DistributionLaw law(DistributionLaw::Kind kind, double ratio, double firstCell = 0.0)
{
  DistributionLaw l;
  l.kind = kind;
  l.expansionRatio = ratio;
  l.firstCellSize = firstCell;
  return l;
}

/// Exactly n values, exact ends, strictly increasing.
void expectValidNodes(const std::vector<double>& s, int n)
{
  ASSERT_EQ(static_cast<int>(s.size()), n);
  EXPECT_EQ(s.front(), 0.0);
  EXPECT_EQ(s.back(), 1.0);
  for (int i = 1; i < n; ++i)
  {
    EXPECT_GT(s[i], s[i - 1]) << "node " << i;
  }
}

double cell(const std::vector<double>& s, int i)
{
  return s[i + 1] - s[i];
}
} // namespace

TEST(Distribution, UniformIsEquallySpaced)
{
  for (int n : { 2, 3, 10, 101 })
  {
    const auto s = distributeNodes(DistributionLaw{}, n);
    expectValidNodes(s, n);
    for (int i = 0; i < n; ++i)
    {
      EXPECT_NEAR(s[i], static_cast<double>(i) / (n - 1), 1e-16);
    }
  }
}

TEST(Distribution, GeometricPaperEquation7)
{
  for (double k : { 0.5, 0.8, 0.95, 1.0 - 1e-9, 1.0 + 1e-12, 1.05, 1.2, 2.0 })
  {
    for (int n : { 2, 3, 5, 11, 21 })
    {
      const auto s = distributeNodes(law(DistributionLaw::Kind::Geometric, k), n);
      expectValidNodes(s, n);
      // Eq. 7 literally (small n keeps the literal sums accurate enough to compare).
      double denominator = 0.0;
      for (int j = 0; j <= n - 2; ++j)
      {
        denominator += std::pow(k, j);
      }
      const double a = 1.0 / denominator;
      double partial = 0.0;
      for (int i = 1; i < n - 1; ++i)
      {
        partial += std::pow(k, i - 1);
        EXPECT_NEAR(s[i], a * partial, 4e-16) << "k " << k << " n " << n << " i " << i;
      }
      for (int i = 1; i + 1 < n; ++i)
      {
        // Positions near 1 carry an absolute rounding of ~1e-16, which limits the relative
        // accuracy of tiny cells there (k < 1); elsewhere the ratio is exact to 1e-12.
        const double smaller = std::min(cell(s, i), cell(s, i - 1));
        const double tolerance = std::max(1e-12, 4.5e-16 / smaller);
        EXPECT_NEAR(cell(s, i) / cell(s, i - 1), k, tolerance * k)
          << "k " << k << " n " << n << " i " << i;
        if (smaller > 1e-3)
        {
          EXPECT_NEAR(cell(s, i) / cell(s, i - 1), k, 1e-12 * k);
        }
      }
    }
  }
}

TEST(Distribution, GeometricKEqualOneIsUniform)
{
  const auto s = distributeNodes(law(DistributionLaw::Kind::Geometric, 1.0), 17);
  const auto u = distributeNodes(DistributionLaw{}, 17);
  EXPECT_EQ(s, u);
  // Close to 1 there is no cancellation: compare with the closed form
  // s_i = (k^i - 1) / (k^m - 1) written with expm1/log1p.
  for (double epsilon : { 1e-14, -1e-12, 1e-9, -3e-7 })
  {
    const double k = 1.0 + epsilon;
    const double logK = std::log1p(k - 1.0);
    const int m = 16;
    const auto near = distributeNodes(law(DistributionLaw::Kind::Geometric, k), m + 1);
    expectValidNodes(near, m + 1);
    for (int i = 0; i <= m; ++i)
    {
      EXPECT_NEAR(near[i], std::expm1(i * logK) / std::expm1(m * logK), 4.5e-16) << epsilon;
      EXPECT_NEAR(near[i], u[i], 20 * std::abs(epsilon) + 1e-16) << epsilon;
    }
  }
}

TEST(Distribution, GeometricReversedLaw)
{
  const auto forward = distributeNodes(law(DistributionLaw::Kind::Geometric, 1.3), 12);
  const DistributionLaw reversed = reversedLaw(law(DistributionLaw::Kind::Geometric, 1.3));
  EXPECT_EQ(reversed.kind, DistributionLaw::Kind::Geometric);
  EXPECT_DOUBLE_EQ(reversed.expansionRatio, 1.0 / 1.3);
  const auto backward = distributeNodes(reversed, 12);
  for (int i = 0; i < 12; ++i)
  {
    EXPECT_NEAR(backward[i], 1.0 - forward[11 - i], 1e-15);
  }
  EXPECT_EQ(reversedLaw(law(DistributionLaw::Kind::TwoSided, 1.2)),
    law(DistributionLaw::Kind::TwoSided, 1.2));
  EXPECT_THROW(reversedLaw(law(DistributionLaw::Kind::FirstCell, 1.2, 0.01)), GeometryError);
}

TEST(Distribution, TwoSidedSymmetricWithRatioK)
{
  for (double k : { 0.7, 1.1, 1.5 })
  {
    for (int n : { 2, 3, 4, 9, 10, 24 })
    {
      const auto s = distributeNodes(law(DistributionLaw::Kind::TwoSided, k), n);
      expectValidNodes(s, n);
      const int m = n - 1;
      for (int i = 0; i < n; ++i)
      {
        EXPECT_NEAR(s[i] + s[n - 1 - i], 1.0, 2e-16) << "k " << k << " n " << n;
      }
      // Cell i is proportional to k^min(i, m-1-i).
      for (int i = 1; i < m; ++i)
      {
        const int e0 = std::min(i - 1, m - i), e1 = std::min(i, m - 1 - i);
        EXPECT_NEAR(cell(s, i) / cell(s, i - 1), std::pow(k, e1 - e0), 1e-12)
          << "k " << k << " n " << n << " i " << i;
      }
      if (m % 2 == 0)
      {
        EXPECT_EQ(s[m / 2], 0.5);
      }
    }
  }
}

TEST(Distribution, FirstCellCappedGrowth)
{
  const double length = 2.5;
  int feasible = 0, infeasible = 0;
  for (double h : { 1e-4, 0.01, 0.05 })
  {
    for (double r : { 1.05, 1.2, 1.5 })
    {
      for (int n : { 20, 41, 80 })
      {
        const int m = n - 1;
        double uncapped = 0.0;
        for (int i = 0; i < m; ++i)
        {
          uncapped += h * std::pow(r, i);
        }
        if (h * m > length || uncapped < length)
        {
          EXPECT_THROW(distributeNodes(law(DistributionLaw::Kind::FirstCell, r, h), n, length),
            GeometryError)
            << h << " " << r << " " << n;
          ++infeasible;
          continue;
        }
        ++feasible;
        const auto s = distributeNodes(law(DistributionLaw::Kind::FirstCell, r, h), n, length);
        expectValidNodes(s, n);
        EXPECT_NEAR(s[1] * length, h, 1e-12 * h) << h << " " << r << " " << n;
        bool capped = false;
        for (int i = 1; i < m; ++i)
        {
          const double ratio = cell(s, i) / cell(s, i - 1);
          EXPECT_LE(ratio, r * (1 + 1e-12)) << h << " " << r << " " << n << " i " << i;
          EXPECT_GE(ratio, 1.0 - 1e-9);
          if (!capped && std::abs(ratio - r) > 1e-9 * r)
          {
            capped = true; // from here on all cells are the cap
          }
          else if (capped)
          {
            EXPECT_NEAR(ratio, 1.0, 1e-9) << h << " " << r << " " << n << " i " << i;
          }
          else
          {
            EXPECT_NEAR(ratio, r, 1e-12 * r);
          }
        }
      }
    }
  }
  EXPECT_GE(feasible, 10);
  EXPECT_GE(infeasible, 5);
}

TEST(Distribution, FirstCellKnownCap)
{
  // h = 0.1, r = 2, 6 cells on L = 3.1: 0.1, 0.2, 0.4, 0.8, then two caps of 0.8.
  const auto s = distributeNodes(law(DistributionLaw::Kind::FirstCell, 2.0, 0.1), 7, 3.1);
  const double expected[] = { 0.0, 0.1, 0.3, 0.7, 1.5, 2.3, 3.1 };
  for (int i = 0; i < 7; ++i)
  {
    EXPECT_NEAR(s[i] * 3.1, expected[i], 1e-14);
  }
  // Cap between two growth steps: h = 1, r = 2, 4 cells on L = 10: 1, 2, c, c, c = 3.5.
  const auto t = distributeNodes(law(DistributionLaw::Kind::FirstCell, 2.0, 1.0), 5, 10.0);
  const double cells[] = { 1.0, 2.0, 3.5, 3.5 };
  for (int i = 0; i < 4; ++i)
  {
    EXPECT_NEAR(cell(t, i) * 10.0, cells[i], 1e-14);
  }
}

TEST(Distribution, FirstCellSolvedRatio)
{
  const double length = 1.7;
  for (double h : { 1e-5, 1e-3, 0.05, 0.3 })
  {
    for (int n : { 3, 10, 50 })
    {
      const int m = n - 1;
      if (h >= length)
      {
        continue;
      }
      const auto s = distributeNodes(law(DistributionLaw::Kind::FirstCell, 0.0, h), n, length);
      expectValidNodes(s, n);
      EXPECT_NEAR(s[1] * length, h, 1e-12 * h) << h << " " << n;
      // All cells grow (or shrink) by one constant ratio.
      const double k = cell(s, 1) / cell(s, 0);
      EXPECT_EQ(k > 1.0, h * m < length);
      for (int i = 2; i < m; ++i)
      {
        EXPECT_NEAR(cell(s, i) / cell(s, i - 1), k, 1e-9 * k) << h << " " << n << " " << i;
      }
    }
  }
  // h * cells == L: uniform.
  const auto u = distributeNodes(law(DistributionLaw::Kind::FirstCell, 0.0, 0.25), 5, 1.0);
  for (int i = 0; i < 5; ++i)
  {
    EXPECT_NEAR(u[i], 0.25 * i, 1e-15);
  }
}

TEST(Distribution, ImpossibleLawsThrow)
{
  using Kind = DistributionLaw::Kind;
  EXPECT_THROW(distributeNodes(DistributionLaw{}, 1), GeometryError);
  EXPECT_THROW(distributeNodes(DistributionLaw{}, 0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::Geometric, 0.0), 5), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::Geometric, -1.2), 5), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::Geometric, std::numeric_limits<double>::quiet_NaN()), 5),
    GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::TwoSided, -1.0), 5), GeometryError);
  // Cells too small to represent.
  EXPECT_THROW(distributeNodes(law(Kind::Geometric, 1e-30), 50), GeometryError);
  // First cell: larger than the edge allows, too small to reach the end, bad arguments.
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.2, 0.2), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.1, 1e-4), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.0, 0.05), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 0.9, 0.05), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.2, 0.0), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.2, 0.05), 11, 0.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 0.0, 1.5), 11, 1.0), GeometryError);
  EXPECT_THROW(distributeNodes(law(Kind::FirstCell, 1.2, 0.3), 2, 1.0), GeometryError);
  EXPECT_NO_THROW(distributeNodes(law(Kind::FirstCell, 1.2, 1.0), 2, 1.0));
  EXPECT_NO_THROW(distributeNodes(law(Kind::FirstCell, 1.0, 0.1), 11, 1.0)); // exactly uniform

  try
  {
    distributeNodes(law(Kind::FirstCell, 1.2, 0.2), 11, 1.0);
  }
  catch (const GeometryError& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("first cell size"), std::string::npos) << message;
    EXPECT_NE(message.find("edge length"), std::string::npos) << message;
  }
}

/**
 * `{ends: [a, b], flat: k}`: the bump that fills the edge is 1 - |2 xi - 1|^(2k). The cells
 * are the analytic shape (log-linear ends times exp(beta bump), beta solved here by its own
 * bisection) within 1e-12; k = 1 is the default law bit for bit; a flatter bump keeps the
 * middle cells nearer the mean cell with small ends (ends 0.1 on 16 cells: the largest cell
 * 2.09 times the mean with k = 1, 1.51 with k = 2, 1.35 with k = 3).
 */
TEST(Distribution, FlatEndsKeepTheMiddleCellsNearTheMean)
{
  DistributionLaw ends;
  ends.kind = DistributionLaw::Kind::Ends;
  ends.firstCellSize = 0.1;
  ends.lastCellSize = 0.1;
  const int cells = 16;
  const auto largest = [&](const std::vector<double>& s) {
    double big = 0.0;
    for (int i = 0; i < cells; ++i)
    {
      big = std::max(big, (s[i + 1] - s[i]) * cells);
    }
    return big;
  };
  const std::vector<double> round = distributeNodes(ends, cells + 1);
  DistributionLaw one = ends;
  one.endsFlatness = 1.0;
  EXPECT_EQ(distributeNodes(one, cells + 1), round); // k = 1: the default, same bits
  EXPECT_NEAR(largest(round), 2.092, 1e-3);
  for (const double k : { 2.0, 3.0 })
  {
    DistributionLaw flat = ends;
    flat.endsFlatness = k;
    flat.lastCellSize = 0.3;
    const std::vector<double> s = distributeNodes(flat, cells + 1);
    // the analytic shape: sizes exp((1 - xi) ln a + xi ln b + beta (1 - |2 xi - 1|^(2k)))
    const auto sizes = [&](double beta) {
      std::vector<double> h(cells);
      double sum = 0.0;
      for (int i = 0; i < cells; ++i)
      {
        const double xi = static_cast<double>(i) / (cells - 1);
        h[i] = std::exp((1.0 - xi) * std::log(0.1) + xi * std::log(0.3) +
          beta * (1.0 - std::pow(std::abs(2.0 * xi - 1.0), 2.0 * k)));
        sum += h[i];
      }
      for (double& v : h)
      {
        v /= sum;
      }
      return std::make_pair(h, sum / cells);
    };
    double low = -60.0, high = 60.0;
    for (int step = 0; step < 200; ++step)
    {
      const double mid = 0.5 * (low + high);
      (sizes(mid).second < 1.0 ? low : high) = mid;
    }
    const std::vector<double> h = sizes(0.5 * (low + high)).first;
    for (int i = 0; i < cells; ++i)
    {
      EXPECT_NEAR(s[i + 1] - s[i], h[i], 1e-12) << "k " << k << " cell " << i;
    }
    EXPECT_NEAR((s[1] - s[0]) * cells, 0.1, 1e-9);
    EXPECT_NEAR((s[cells] - s[cells - 1]) * cells, 0.3, 1e-9);
    // mirrored by reversedLaw
    const std::vector<double> r = distributeNodes(reversedLaw(flat), cells + 1);
    for (int i = 0; i <= cells; ++i)
    {
      EXPECT_NEAR(r[i], 1.0 - s[cells - i], 1e-14);
    }
    flat.lastCellSize = 0.1;
    EXPECT_NEAR(largest(distributeNodes(flat, cells + 1)), k == 2.0 ? 1.514 : 1.349, 1e-3);
  }
  ends.endsFlatness = 0.5;
  EXPECT_THROW(distributeNodes(ends, cells + 1), GeometryError);
}

TEST(Distribution, EndsGiveTheEndCellsRelativeToTheMeanAtEveryCount)
{
  DistributionLaw ends;
  ends.kind = DistributionLaw::Kind::Ends;
  ends.firstCellSize = 0.1;
  ends.lastCellSize = 0.4;
  for (int cells : { 4, 8, 16, 64 })
  {
    const std::vector<double> s = distributeNodes(ends, cells + 1);
    ASSERT_EQ(s.size(), static_cast<std::size_t>(cells + 1));
    EXPECT_EQ(s.front(), 0.0);
    EXPECT_EQ(s.back(), 1.0);
    // first and last cells 0.1 and 0.4 times the mean cell 1 / cells, whatever the count
    EXPECT_NEAR((s[1] - s[0]) * cells, 0.1, 1e-9) << cells;
    EXPECT_NEAR((s[cells] - s[cells - 1]) * cells, 0.4, 1e-9) << cells;
    double worst = 1.0;
    for (int i = 1; i < cells; ++i)
    {
      ASSERT_GT(s[i + 1], s[i]);
      const double ratio = (s[i + 1] - s[i]) / (s[i] - s[i - 1]);
      worst = std::max({ worst, ratio, 1.0 / ratio });
    }
    // smooth once there are enough cells to grow from 0.1 to the middle and back
    if (cells >= 64)
    {
      EXPECT_LT(worst, 1.2) << cells;
    }
  }
  // Reversed: the ends swap, the nodes mirror.
  const DistributionLaw back = reversedLaw(ends);
  EXPECT_EQ(back.firstCellSize, 0.4);
  EXPECT_EQ(back.lastCellSize, 0.1);
  const std::vector<double> s = distributeNodes(ends, 11), r = distributeNodes(back, 11);
  for (int i = 0; i <= 10; ++i)
  {
    EXPECT_NEAR(r[i], 1.0 - s[10 - i], 1e-14);
  }
  // [1, 1] is uniform; too few cells keep the ratio of the ends.
  ends.firstCellSize = ends.lastCellSize = 1.0;
  const std::vector<double> u = distributeNodes(ends, 9);
  for (int i = 0; i <= 8; ++i)
  {
    EXPECT_NEAR(u[i], i / 8.0, 1e-13);
  }
  ends.firstCellSize = 1.0;
  ends.lastCellSize = 3.0;
  const std::vector<double> two = distributeNodes(ends, 3);
  EXPECT_NEAR(two[1], 0.25, 1e-15);
  ends.firstCellSize = 0.0;
  EXPECT_THROW(distributeNodes(ends, 5), GeometryError);
}

TEST(Distribution, MatchGivesTheEndCellsAndGrowsByTheRatio)
{
  // An edge of length 2 with first cell 0.01 and last cell 0.02, 40 cells, ratio 1.2: the
  // cells grow by exactly 1.2 from both ends up to a uniform middle that fills the edge.
  const std::vector<double> s = matchedNodes(0.01, 0.02, 2.0, 41, 1.2);
  expectValidNodes(s, 41);
  EXPECT_NEAR(cell(s, 0) * 2.0, 0.01, 1e-14);
  EXPECT_NEAR(cell(s, 39) * 2.0, 0.02, 1e-14);
  EXPECT_NEAR(cell(s, 1) / cell(s, 0), 1.2, 1e-12);
  EXPECT_NEAR(cell(s, 38) / cell(s, 39), 1.2, 1e-12);
  double largest = 0.0, worst = 1.0;
  for (int i = 0; i < 40; ++i)
  {
    largest = std::max(largest, cell(s, i));
    if (i > 0)
    {
      worst = std::max({ worst, cell(s, i) / cell(s, i - 1), cell(s, i - 1) / cell(s, i) });
    }
  }
  EXPECT_LE(worst, 1.2 + 1e-12);
  // the middle is uniform: the largest cell is reached by more than one cell
  int atLargest = 0;
  for (int i = 0; i < 40; ++i)
  {
    atLargest += std::abs(cell(s, i) - largest) < 1e-14 ? 1 : 0;
  }
  EXPECT_GT(atLargest, 1);

  // Too few cells to reach the length by 1.2: the ratio rises, the ends stay.
  const std::vector<double> few = matchedNodes(0.01, 0.01, 2.0, 9, 1.2);
  expectValidNodes(few, 9);
  EXPECT_NEAR(cell(few, 0) * 2.0, 0.01, 1e-12);
  EXPECT_NEAR(cell(few, 7) * 2.0, 0.01, 1e-12);
  const double r = cell(few, 1) / cell(few, 0);
  EXPECT_GT(r, 1.2);
  EXPECT_NEAR(cell(few, 2) / cell(few, 1), r, 1e-9);
  // (1 + r + r^2 + r^3) * 2 * 0.01 = 2 for the 8 symmetric cells
  EXPECT_NEAR((1 + r + r * r + r * r * r) * 0.02, 2.0, 1e-9);

  // An end cell larger than the mean cell: exact ends, cells shrinking towards the middle.
  const std::vector<double> big = matchedNodes(0.3, 0.2, 2.0, 11, 1.2);
  expectValidNodes(big, 11);
  EXPECT_NEAR(cell(big, 0) * 2.0, 0.3, 1e-9);
  EXPECT_NEAR(cell(big, 9) * 2.0, 0.2, 1e-9);
  EXPECT_LT(cell(big, 5), cell(big, 0));
  // One free end: cells grow from the given one and stay uniform after.
  const std::vector<double> one = matchedNodes(0.0, 0.02, 1.0, 21, 1.3);
  EXPECT_NEAR(cell(one, 19), 0.02, 1e-14);
  EXPECT_NEAR(cell(one, 0), cell(one, 1), 1e-14);
  // Both free: uniform; the law reversed swaps the ends; bad ratios throw.
  const std::vector<double> free = matchedNodes(0.0, 0.0, 3.0, 7, 1.2);
  for (int i = 0; i <= 6; ++i)
  {
    EXPECT_NEAR(free[i], i / 6.0, 1e-15);
  }
  DistributionLaw match;
  match.kind = DistributionLaw::Kind::Match;
  match.expansionRatio = 1.2;
  match.firstCellSize = 0.01;
  match.lastCellSize = 0.02;
  const DistributionLaw back = reversedLaw(match);
  EXPECT_EQ(back.firstCellSize, 0.02);
  EXPECT_EQ(back.lastCellSize, 0.01);
  const std::vector<double> viaLaw = distributeNodes(match, 41, 2.0);
  const std::vector<double> mirrored = distributeNodes(back, 41, 2.0);
  for (int i = 0; i <= 40; ++i)
  {
    EXPECT_EQ(viaLaw[i], s[i]);
    EXPECT_NEAR(mirrored[i], 1.0 - s[40 - i], 1e-14);
  }
  EXPECT_THROW(matchedNodes(0.01, 0.01, 1.0, 5, 1.0), GeometryError);
  EXPECT_THROW(matchedNodes(0.01, 0.01, 1.0, 5, std::nan("")), GeometryError);
}

TEST(Distribution, MatchWithFlatIsTheEndsShapeWithTheMatchedCells)
{
  // {match: r, flat: k}: the matched end cells (0.01 and 0.02 on an edge of length 2, 16
  // cells: 0.08 and 0.16 of the mean cell 0.125) with the Ends law's shape in between,
  // bit for bit the Ends law's nodes with those relative cells; a free end takes the mean
  // cell; the ratio plays no part; a flatness below 1 is an error.
  DistributionLaw ends;
  ends.kind = DistributionLaw::Kind::Ends;
  ends.firstCellSize = 0.01 / 0.125;
  ends.lastCellSize = 0.02 / 0.125;
  ends.endsFlatness = 3.0;
  const std::vector<double> expected = distributeNodes(ends, 17);
  EXPECT_EQ(matchedNodes(0.01, 0.02, 2.0, 17, 1.2, 3.0), expected);
  EXPECT_EQ(matchedNodes(0.01, 0.02, 2.0, 17, 5.0, 3.0), expected);
  const std::vector<double> s = matchedNodes(0.01, 0.02, 2.0, 17, 1.2, 3.0);
  expectValidNodes(s, 17);
  EXPECT_NEAR(cell(s, 0) * 2.0, 0.01, 1e-14);
  EXPECT_NEAR(cell(s, 15) * 2.0, 0.02, 1e-14);
  // grown by 1.2 to a uniform middle the same ends give other nodes
  EXPECT_NE(matchedNodes(0.01, 0.02, 2.0, 17, 1.2), expected);
  DistributionLaw law;
  law.kind = DistributionLaw::Kind::Match;
  law.expansionRatio = 2.0;
  law.firstCellSize = 0.01;
  law.matchFlatness = 3.0;
  ends.lastCellSize = 1.0;
  EXPECT_EQ(distributeNodes(law, 17, 2.0), distributeNodes(ends, 17));
  EXPECT_THROW(matchedNodes(0.01, 0.02, 2.0, 17, 1.2, 0.5), GeometryError);
}

TEST(Distribution, MatchNodesDoNotJumpWhenAnEndCellPassesTheMeanCell)
{
  // Two edges across a periodic pair share one end cell, the geometric mean of their
  // nearly equal mean cells: one of them always has an end a hair above its mean. With
  // the other end small, cells grown from both ends to a uniform middle keep both ends,
  // so the nodes are those of an end a hair below the mean (they used to switch to the
  // log-linear shape and move by a tenth of a cell).
  const double length = 2.0, mean = length / 6.0;
  const std::vector<double> below = matchedNodes(mean * (1.0 - 1e-9), 0.1, length, 7, 1.2);
  const std::vector<double> above = matchedNodes(mean * (1.0 + 1e-9), 0.1, length, 7, 1.2);
  expectValidNodes(above, 7);
  for (int i = 0; i <= 6; ++i)
  {
    EXPECT_NEAR(above[i], below[i], 1e-8) << i;
  }
  EXPECT_NEAR(cell(above, 0) * length, mean * (1.0 + 1e-9), 1e-12);
  EXPECT_NEAR(cell(above, 5) * length, 0.1, 1e-12);
  // Ends too large to be kept that way still shrink towards the middle, by at most
  // 1.2^2 from cell to cell (the ends lowered towards the mean: see the next test).
  const std::vector<double> big = matchedNodes(0.5, 0.45, length, 7, 1.2);
  EXPECT_LT(cell(big, 3), cell(big, 0));
  EXPECT_GT(cell(big, 0) * length, mean);
  EXPECT_LT(cell(big, 0) * length, 0.5);
}

TEST(Distribution, MatchBetweenTwoLargeEndCellsShrinksByAtMostTheRatioSquared)
{
  // Five cells between end cells 2.2 times the mean (a wake block's outlet edge at density
  // 0.5): the ends law's shape gives 2.2, 0.22, 0.1, 0.22, 2.2 times the mean, the middle
  // cells 10 times thinner than their neighbours. The end cells are lowered (both by the
  // same power towards the mean) until no cell is more than ratio^2 = 4 times its neighbour.
  const double length = 1.0, mean = 0.2;
  const std::vector<double> s = matchedNodes(2.2 * mean, 2.2 * mean, length, 6, 2.0);
  expectValidNodes(s, 6);
  double largest = 1.0;
  for (int i = 1; i < 5; ++i)
  {
    largest = std::max(largest, std::max(cell(s, i) / cell(s, i - 1), cell(s, i - 1) / cell(s, i)));
  }
  EXPECT_LE(largest, 4.0 * (1.0 + 1e-12));
  EXPECT_GT(largest, 4.0 * (1.0 - 1e-9)); // the largest ends that keep the limit
  EXPECT_NEAR(cell(s, 0), cell(s, 4), 1e-12);
  EXPECT_GT(cell(s, 0) * length, 1.5 * mean);
  EXPECT_LT(cell(s, 0) * length, 2.2 * mean);
  // Within the limit the nodes are the ends law's with the matched end cells, bit for bit.
  const std::vector<double> kept = matchedNodes(1.5 * mean, 1.4 * mean, length, 6, 2.0);
  DistributionLaw ends;
  ends.kind = DistributionLaw::Kind::Ends;
  ends.firstCellSize = 1.5 * mean / (length / 5); // as matchedNodes divides
  ends.lastCellSize = 1.4 * mean / (length / 5);
  EXPECT_EQ(kept, distributeNodes(ends, 6));
  // One end above the mean and one below: as before (no limit).
  const std::vector<double> mixed = matchedNodes(2.2 * mean, 0.5 * mean, length, 6, 2.0);
  EXPECT_NEAR(cell(mixed, 0) * length, 2.2 * mean, 1e-9);
}

TEST(Distribution, MatchWithAnEndCellNearTheWholeEdgeDoesNotFail)
{
  // A neighbour's cell as long as the edge itself: the end cell is capped so the other
  // cells shrink by at most ratio^4 each, and the nodes stay valid.
  const std::vector<double> s = matchedNodes(0.0, 0.99, 1.0, 33, 1.2);
  expectValidNodes(s, 33);
  for (int i = 1; i < 32; ++i)
  {
    EXPECT_LE(cell(s, i) / cell(s, i - 1), std::pow(1.2, 4.0) * (1.0 + 1e-4)); // tiny cells: differences of nodes near 1
  }
  const std::vector<double> both = matchedNodes(2.0, 0.99, 1.0, 9, 1.2);
  expectValidNodes(both, 9);
}
