#include "ArcLength.h"

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
  for (int k = 0; k < pieces; ++k)
  {
    const double a = static_cast<double>(k) / pieces, b = static_cast<double>(k + 1) / pieces;
    if (!keepDerivatives)
    {
      Cumulative[k + 1] = Cumulative[k] + piece(a, b);
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
    Cumulative[k + 1] = Cumulative[k] + sum * half;
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
  double low = a, high = b;
  double t = span > 0.0 ? a + (target - Cumulative[k]) / span * (b - a) : a;
  for (int iteration = 0; iteration < 60; ++iteration)
  {
    const double error = Cumulative[k] + piece(a, t) - target;
    if (error > 0.0)
    {
      high = t;
    }
    else
    {
      low = t;
    }
    if (std::abs(error) <= 1e-15 * total)
    {
      break;
    }
    const double speed = TheCurve->derivative(t, 1).norm();
    double next = speed > 0.0 ? t - error / speed : 0.5 * (low + high);
    if (!(next > low && next < high))
    {
      next = 0.5 * (low + high);
    }
    if (next == t)
    {
      break;
    }
    t = next;
  }
  return t;
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
