/**
 * @file RootFinding.h
 * @brief The 1-D solvers of BlockForge: roots on a sign-changing bracket by Brent's method
 * (blade/hub intersections, curves meeting surfaces) or by bisection (vertices on axial
 * planes, the ratios of distribution laws: the bits of the grids made before these were
 * unified), and minima on a bracket by golden-section search (extreme points of curves).
 */
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace blockforge
{
/// Brent's method (Brent 1973; zbrent in Numerical Recipes) on a sign-changing bracket:
/// inverse quadratic / secant steps with bisection fallback, always converges. Stops when
/// the bracket is narrower than `tolerance` (absolute in t) or f hits 0.
template <typename F>
inline double brentRoot(const F& f, double a, double b, double fa, double fb, double tolerance)
{
  constexpr double Eps = std::numeric_limits<double>::epsilon();
  double c = b, fc = fb, d = b - a, e = d;
  for (int iteration = 0; iteration < 200; ++iteration)
  {
    if ((fb > 0.0 && fc > 0.0) || (fb < 0.0 && fc < 0.0))
    {
      c = a;
      fc = fa;
      e = d = b - a;
    }
    if (std::abs(fc) < std::abs(fb))
    {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol1 = 2.0 * Eps * std::abs(b) + 0.5 * tolerance;
    const double xm = 0.5 * (c - b);
    if (std::abs(xm) <= tol1 || fb == 0.0)
    {
      return b;
    }
    if (std::abs(e) >= tol1 && std::abs(fa) > std::abs(fb))
    {
      const double s = fb / fa;
      double p, q;
      if (a == c)
      {
        p = 2.0 * xm * s;
        q = 1.0 - s;
      }
      else
      {
        const double qq = fa / fc, r = fb / fc;
        p = s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0));
        q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0.0)
      {
        q = -q;
      }
      p = std::abs(p);
      const double min1 = 3.0 * xm * q - std::abs(tol1 * q), min2 = std::abs(e * q);
      if (2.0 * p < std::min(min1, min2))
      {
        e = d;
        d = p / q;
      }
      else
      {
        d = xm;
        e = d;
      }
    }
    else
    {
      d = xm;
      e = d;
    }
    a = b;
    fa = fb;
    b += std::abs(d) > tol1 ? d : std::copysign(tol1, xm);
    fb = f(b);
  }
  return b;
}

/**
 * Bisection on a predicate that holds below a threshold and fails above it: [low, high]
 * (below(low), !below(high)) shrinks around the threshold until it is no wider than
 * `width` (0: until low and high are adjacent doubles) or after `iterations` halvings.
 * Deterministic and, with width 0, as accurate as doubles allow.
 */
template <typename P>
inline void bisect(const P& below, double& low, double& high, double width, int iterations)
{
  for (int iteration = 0; iteration < iterations && high - low > width; ++iteration)
  {
    const double middle = 0.5 * (low + high);
    if (!(middle > low && middle < high))
    {
      break;
    }
    (below(middle) ? low : high) = middle;
  }
}

/// The root of f in the sign-changing bracket [a, b] (f(a) = fa) by bisection until the
/// bracket is no wider than `width` (at most 200 halvings): the midpoint of the last one.
template <typename F>
inline double bisectedRoot(const F& f, double a, double b, double fa, double width)
{
  const bool negative = fa < 0.0;
  bisect([&](double x) { return (f(x) < 0.0) == negative; }, a, b, width, 200);
  return 0.5 * (a + b);
}

/// Golden-section search for the minimum of f on [a, b], until the bracket is no wider
/// than `width` (at most 200 steps; far from 0 the bracket stops shrinking at the spacing
/// of doubles); the midpoint of the last bracket.
template <typename F>
inline double goldenSectionMinimum(const F& f, double a, double b, double width)
{
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  double fc = f(c), fd = f(d);
  for (int iteration = 0; b - a > width && iteration < 200; ++iteration)
  {
    if (fc < fd)
    {
      b = d;
      d = c;
      fd = fc;
      c = b - ratio * (b - a);
      fc = f(c);
    }
    else
    {
      a = c;
      c = d;
      fc = fd;
      d = a + ratio * (b - a);
      fd = f(d);
    }
  }
  return 0.5 * (a + b);
}
} // namespace blockforge
