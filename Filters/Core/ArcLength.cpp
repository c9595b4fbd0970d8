#include "ArcLength.h"

#include "RootFinding.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace blockforge
{
namespace
{
const double GaussX[5] = { -0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
  0.9061798459386640 };
const double GaussW[5] = { 0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
  0.4786286704993665, 0.2369268850561891 };
/// The Kronrod extension of the 5-point rule: 6 more nodes (by symmetry, the 3 positive
/// ones here), and the weights of all 11 at 0, the Kronrod node, the Gauss node, ...
/// (exact to degree 16; computed as the roots of the Stieltjes polynomial of P5).
const double KronrodX[3] = { 0.27963041316178319341, 0.75416672657084922044,
  0.98408536009484246450 };
const double KronrodW0 = 0.28298741785749121320;
const double KronrodWK[3] = { 0.27284980191255892234, 0.18680079655649265747,
  0.042582036751081832865 };
const double KronrodWG[2] = { 0.24104033922864758670, 0.11523331662247339402 }; // at GaussX[3], [4]

/// The spans of [0, 1] between the curve's breakpoints (ends of the table's first pieces).
std::vector<double> spanEnds(const Curve& curve)
{
  std::vector<double> inner = curve.breakpoints();
  std::sort(inner.begin(), inner.end());
  std::vector<double> ends{ 0.0 };
  for (const double b : inner)
  {
    if (b > ends.back() && b < 1.0)
    {
      ends.push_back(b);
    }
  }
  ends.push_back(1.0);
  return ends;
}
} // namespace

ArcLength::ArcLength(CurvePtr curve, double relativeTolerance)
  : TheCurve(std::move(curve))
{
  const std::vector<double> spans = spanEnds(*TheCurve);
  const std::size_t spanCount = spans.size() - 1;
  // A first estimate of the length sets the tolerance of every piece.
  std::vector<double> whole(spanCount), error(spanCount);
  double estimate = 0.0;
  for (std::size_t k = 0; k < spanCount; ++k)
  {
    whole[k] = gaussKronrod(spans[k], spans[k + 1], error[k]);
    estimate += whole[k];
  }
  const double tolerance = relativeTolerance * estimate;
  Ends.reserve(spanCount + 1);
  Cumulative.reserve(spanCount + 1);
  Ends.push_back(0.0);
  Cumulative.push_back(0.0);
  // A piece is kept when the Kronrod rule says its 5-point Gauss value is good, else its
  // halves are tried. Left to right, so the table is in order; one thread, so its bits do
  // not depend on the runner. A piece keeps the Gauss value, the same bits as gauss() on
  // it, so lengths are continuous at piece ends.
  struct Refine
  {
    ArcLength& table;
    double tolerance;
    void operator()(double a, double b, double value, double error, int level) const
    {
      const double m = 0.5 * (a + b);
      // Also kept: a piece whose estimate is down to rounding (a fast stretch of a curve
      // with crowded knots), and every piece once the table is very large (a curve with
      // kinks everywhere; the same pieces every time, so still deterministic).
      if (level >= MaxLevels || !(m > a && m < b) || !(error > tolerance) ||
        !(error > 1e-14 * std::abs(value)) || table.Ends.size() > MaxPieces)
      {
        table.Ends.push_back(b);
        table.Cumulative.push_back(table.Cumulative.back() + value);
        return;
      }
      double leftError = 0.0, rightError = 0.0;
      const double left = table.gaussKronrod(a, m, leftError);
      const double right = table.gaussKronrod(m, b, rightError);
      (*this)(a, m, left, leftError, level + 1);
      (*this)(m, b, right, rightError, level + 1);
    }
  };
  const Refine refine{ *this, tolerance };
  for (std::size_t k = 0; k < spanCount; ++k)
  {
    refine(spans[k], spans[k + 1], whole[k], error[k], 0);
  }
  Ends.back() = 1.0;
  Total = Cumulative.back();
}

ArcLength::ArcLength(std::shared_ptr<const ArcLength> base, double u0, double u1, bool closed)
  : Base(std::move(base))
  , U0(u0)
  , U1(u1)
  , Closed(closed)
{
  Start = baseLength(U0);
  Total = std::abs(baseLength(U1) - Start);
}

double ArcLength::gauss(double a, double b) const
{
  const double half = 0.5 * (b - a), centre = 0.5 * (a + b);
  double sum = 0.0;
  for (int k = 0; k < 5; ++k)
  {
    sum += GaussW[k] * TheCurve->derivative(centre + half * GaussX[k], 1).norm();
  }
  return sum * half;
}

double ArcLength::gaussKronrod(double a, double b, double& error) const
{
  // Lagrange weights of the five Gauss nodes at the six Kronrod nodes (-x2, -x1, -x0, x0,
  // x1, x2), computed once.
  static const std::array<std::array<double, 5>, 6> interpolate = [] {
    std::array<std::array<double, 5>, 6> weights{};
    const double at[6] = { -KronrodX[2], -KronrodX[1], -KronrodX[0], KronrodX[0], KronrodX[1],
      KronrodX[2] };
    for (int k = 0; k < 6; ++k)
    {
      for (int j = 0; j < 5; ++j)
      {
        double w = 1.0;
        for (int i = 0; i < 5; ++i)
        {
          if (i != j)
          {
            w *= (at[k] - GaussX[i]) / (GaussX[j] - GaussX[i]);
          }
        }
        weights[k][j] = w;
      }
    }
    return weights;
  }();
  const double half = 0.5 * (b - a), centre = 0.5 * (a + b);
  double speed[5];
  double sum = 0.0;
  for (int k = 0; k < 5; ++k)
  {
    speed[k] = TheCurve->derivative(centre + half * GaussX[k], 1).norm();
    sum += GaussW[k] * speed[k];
  }
  const double kronrodX[6] = { -KronrodX[2], -KronrodX[1], -KronrodX[0], KronrodX[0],
    KronrodX[1], KronrodX[2] };
  const double kronrodW[6] = { KronrodWK[2], KronrodWK[1], KronrodWK[0], KronrodWK[0],
    KronrodWK[1], KronrodWK[2] };
  double kronrod = KronrodW0 * speed[2] + KronrodWG[0] * (speed[1] + speed[3]) +
    KronrodWG[1] * (speed[0] + speed[4]);
  double residual = 0.0; // of the quartic through the Gauss values, at the Kronrod nodes
  for (int k = 0; k < 6; ++k)
  {
    const double value = TheCurve->derivative(centre + half * kronrodX[k], 1).norm();
    kronrod += kronrodW[k] * value;
    double quartic = 0.0;
    for (int j = 0; j < 5; ++j)
    {
      quartic += interpolate[k][j] * speed[j];
    }
    residual = std::max(residual, std::abs(value - quartic));
  }
  // The Kronrod difference is the error of the piece's Gauss value; a length inside the
  // piece (Gauss on a part of it) errs by about the square of the quartic's relative
  // residual (a 9th-degree rule against a 4th-degree fit), which symmetry cannot hide (a
  // speed odd about the centre fools both rules on the whole piece, not on a part).
  const double mean = 0.5 * std::abs(sum);
  const double relative = mean > 0.0 ? residual / mean : 0.0;
  error = std::max(std::abs(kronrod - sum), relative * relative * std::abs(sum)) * std::abs(half);
  return sum * half;
}

int ArcLength::pieceCount() const
{
  return Base ? Base->pieceCount() : static_cast<int>(Ends.size()) - 1;
}

double ArcLength::tableLength(double u) const
{
  if (!(u > 0.0))
  {
    return 0.0;
  }
  if (u >= 1.0)
  {
    return Total;
  }
  const int pieces = static_cast<int>(Ends.size()) - 1;
  int k = static_cast<int>(std::upper_bound(Ends.begin(), Ends.end(), u) - Ends.begin()) - 1;
  k = std::max(0, std::min(k, pieces - 1));
  return Cumulative[k] + gauss(Ends[k], u);
}

double ArcLength::tableParameter(double length) const
{
  if (!(length > 0.0) || !(Total > 0.0))
  {
    return length >= Total && Total > 0.0 ? 1.0 : 0.0;
  }
  if (length >= Total)
  {
    return 1.0;
  }
  const int pieces = static_cast<int>(Ends.size()) - 1;
  int k = static_cast<int>(
    std::upper_bound(Cumulative.begin(), Cumulative.end(), length) - Cumulative.begin()) - 1;
  k = std::max(0, std::min(k, pieces - 1));
  const double a = Ends[k], b = Ends[k + 1];
  const double span = Cumulative[k + 1] - Cumulative[k];
  const double t = span > 0.0 ? a + (length - Cumulative[k]) / span * (b - a) : a;
  NewtonStop stop;
  stop.iterations = 60;
  stop.valueTolerance = 1e-15 * Total;
  return newtonInBracket([&](double at) { return Cumulative[k] + gauss(a, at) - length; },
    [&](double at) { return TheCurve->derivative(at, 1).norm(); }, a, b, t, stop);
}

double ArcLength::baseLength(double u) const
{
  if (!Closed)
  {
    return Base->tableLength(std::max(0.0, std::min(1.0, u)));
  }
  const double turns = std::floor(u);
  return Base->tableLength(u - turns) + turns * Base->Total;
}

double ArcLength::lengthAt(double t) const
{
  if (!(t > 0.0))
  {
    return 0.0;
  }
  if (t >= 1.0)
  {
    return Total;
  }
  if (!Base)
  {
    return tableLength(t);
  }
  const double u = U0 + t * (U1 - U0);
  return (U1 >= U0 ? 1.0 : -1.0) * (baseLength(u) - Start);
}

double ArcLength::parameterAtFraction(double fraction) const
{
  if (!(fraction > 0.0) || !(Total > 0.0))
  {
    return fraction >= 1.0 ? 1.0 : 0.0;
  }
  if (fraction >= 1.0)
  {
    return 1.0;
  }
  if (!Base)
  {
    return tableParameter(fraction * Total);
  }
  const double target = Start + (U1 >= U0 ? 1.0 : -1.0) * fraction * Total;
  double u = 0.0;
  if (Closed && Base->Total > 0.0)
  {
    const double turns = std::floor(target / Base->Total);
    u = turns + Base->tableParameter(target - turns * Base->Total);
  }
  else
  {
    u = Base->tableParameter(target);
  }
  return std::max(0.0, std::min(1.0, (u - U0) / (U1 - U0)));
}
} // namespace blockforge
