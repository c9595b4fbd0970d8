#include "ArcLength.h"

#include "Parallel.h"
#include "RootFinding.h"

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace
{
const double GaussX[5] = { -0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
  0.9061798459386640 };
const double GaussW[5] = { 0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
  0.4786286704993665, 0.2369268850561891 };
}

ArcLength::ArcLength(CurvePtr curve, int pieces, bool keepDerivatives)
  : TheCurve(std::move(curve))
{
  Cumulative.assign(pieces + 1, 0.0);
  if (keepDerivatives)
  {
    Derivatives.resize(5 * static_cast<std::size_t>(pieces));
  }
  // The pieces' lengths are independent: they go to threads when a runner is installed
  // (Parallel.h), each into its own slot, and are added up afterwards in piece order, so
  // the table is the same bits on any number of threads.
  std::vector<double> lengths(pieces, 0.0);
  const long chunks = chunkCount(pieces, 32, 64);
  forEachChunk(chunks, [&](long chunk) {
    const int first = static_cast<int>(chunk * pieces / chunks);
    const int last = static_cast<int>((chunk + 1) * pieces / chunks);
    for (int k = first; k < last; ++k)
    {
      const double a = static_cast<double>(k) / pieces, b = static_cast<double>(k + 1) / pieces;
      if (!keepDerivatives)
      {
        lengths[k] = piece(a, b);
        continue;
      }
      // piece(a, b), remembering the derivatives
      const double half = 0.5 * (b - a), centre = 0.5 * (a + b);
      double sum = 0.0;
      for (int g = 0; g < 5; ++g)
      {
        Vec3& derivative = Derivatives[5 * static_cast<std::size_t>(k) + g];
        derivative = TheCurve->derivative(centre + half * GaussX[g], 1);
        sum += GaussW[g] * derivative.norm();
      }
      lengths[k] = sum * half;
    }
  });
  for (int k = 0; k < pieces; ++k)
  {
    Cumulative[k + 1] = Cumulative[k] + lengths[k];
  }
}

ArcLength::ArcLength(
  CurvePtr curve, const ArcLength& base, const Vec3& startShift, const Vec3& endShift)
  : TheCurve(std::move(curve))
{
  const int pieces = static_cast<int>(base.Cumulative.size()) - 1;
  Cumulative.assign(pieces + 1, 0.0);
  for (int k = 0; k < pieces; ++k)
  {
    const double a = static_cast<double>(k) / pieces, b = static_cast<double>(k + 1) / pieces;
    const double half = 0.5 * (b - a);
    double sum = 0.0;
    for (int g = 0; g < 5; ++g)
    {
      // As FollowCurve::derivative: (base + endShift) - startShift.
      const Vec3& derivative = base.Derivatives[5 * static_cast<std::size_t>(k) + g];
      sum += GaussW[g] * Vec3(derivative + endShift - startShift).norm();
    }
    Cumulative[k + 1] = Cumulative[k] + sum * half;
  }
}

double ArcLength::piece(double a, double b) const
{
  const double half = 0.5 * (b - a), centre = 0.5 * (a + b);
  double sum = 0.0;
  for (int k = 0; k < 5; ++k)
  {
    sum += GaussW[k] * TheCurve->derivative(centre + half * GaussX[k], 1).norm();
  }
  return sum * half;
}

double ArcLength::parameterAtFraction(double fraction) const
{
  const double total = totalLength();
  if (!(fraction > 0.0) || !(total > 0.0))
  {
    return fraction >= 1.0 ? 1.0 : 0.0;
  }
  if (fraction >= 1.0)
  {
    return 1.0;
  }
  const int pieces = static_cast<int>(Cumulative.size()) - 1;
  const double target = fraction * total;
  int k = static_cast<int>(
    std::upper_bound(Cumulative.begin(), Cumulative.end(), target) - Cumulative.begin()) - 1;
  k = std::max(0, std::min(k, pieces - 1));
  const double a = static_cast<double>(k) / pieces, b = static_cast<double>(k + 1) / pieces;
  const double span = Cumulative[k + 1] - Cumulative[k];
  const double t = span > 0.0 ? a + (target - Cumulative[k]) / span * (b - a) : a;
  NewtonStop stop;
  stop.iterations = 60;
  stop.valueTolerance = 1e-15 * total;
  return newtonInBracket([&](double at) { return Cumulative[k] + piece(a, at) - target; },
    [&](double at) { return TheCurve->derivative(at, 1).norm(); }, a, b, t, stop);
}

double ArcLength::lengthAt(double t) const
{
  const int pieces = static_cast<int>(Cumulative.size()) - 1;
  if (!(t > 0.0))
  {
    return 0.0;
  }
  if (t >= 1.0)
  {
    return totalLength();
  }
  const int k = std::min(static_cast<int>(t * pieces), pieces - 1);
  return Cumulative[k] + piece(static_cast<double>(k) / pieces, t);
}
} // namespace blockforge
