/**
 * @file RootFinding.h
 * @brief Every 1-D solver of BlockForge, in one place. Which one a caller uses depends on
 * what it knows about its function, not on where it was written:
 *
 * - a root of a function known only by its values, on a sign-changing bracket:
 *   brentRoot (blade/hub intersections, curves meeting surfaces, extreme points);
 * - a root of a function whose derivative comes at little extra cost, on a
 *   sign-changing bracket: newtonInBracket, Newton safeguarded by bisection (closest
 *   points on curves, the arc-length inverse), which converges quadratically where Brent
 *   would only be superlinear;
 * - the threshold of a monotone predicate, to rounding: bisect. This is not root finding:
 *   its predicates need not come from a continuous function (sums of powers against a
 *   target, "cells grown by this ratio reach the length") and it answers to the last
 *   bit, which is what the distribution laws and the vertices on axial planes need;
 * - the minimum of a function on a bracket: goldenSectionMinimum.
 *
 * Why not one method for all: the grids are kept bit for bit across changes of the code
 * (Testing/Data/grid_checksums.txt). Moving the axial-plane vertices from bisection to
 * Brent moved 96 of those checksums by rounding, and Brent in place of the safeguarded
 * Newton would both move bits and cost more evaluations where the derivative is at hand.
 * So the methods stay, each written once here; no other file carries its own loop.
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

/// When newtonInBracket stops (see there).
struct NewtonStop
{
  int iterations = 200;         ///< evaluations at most
  double valueTolerance = 0.0;  ///< |f(t)| at or below this: t is the root
  double stepTolerance = 0.0;   ///< a step or the bracket at or below this: done
  bool halveEveryTwoSteps = false; ///< rtsafe's rule: bisect when Newton slows down
};

/**
 * Newton's method safeguarded by bisection (rtsafe, Numerical Recipes) for the root of f
 * in the sign-changing bracket [lo, hi] (f(lo) < 0 < f(hi), or the other way with the
 * bracket kept by sign), from `t` inside it. `value(t)` gives f(t), then `slope(t)` its
 * derivative at the same t (so a caller may compute both at once and hand the slope on).
 * A step that leaves the bracket, a non-positive slope, or with halveEveryTwoSteps a step
 * not half the one two iterations before, becomes a bisection, so the bracket shrinks and
 * the solve always ends. Returns the last t.
 */
template <typename V, typename S>
inline double newtonInBracket(const V& value, const S& slope, double lo, double hi, double t,
  const NewtonStop& stop)
{
  double previousStep = hi - lo, lastStep = previousStep;
  for (int iteration = 0; iteration < stop.iterations; ++iteration)
  {
    const double f = value(t);
    if (std::abs(f) <= stop.valueTolerance)
    {
      return t;
    }
    (f < 0.0 ? lo : hi) = t;
    const double df = slope(t);
    double next = df > 0.0 ? t - f / df : 0.5 * (lo + hi);
    if (!(next > lo && next < hi) ||
      (stop.halveEveryTwoSteps && std::abs(next - t) > 0.5 * previousStep))
    {
      next = 0.5 * (lo + hi);
    }
    previousStep = lastStep;
    lastStep = std::abs(next - t);
    t = next;
    if (lastStep <= stop.stepTolerance || hi - lo <= stop.stepTolerance)
    {
      break;
    }
  }
  return t;
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
