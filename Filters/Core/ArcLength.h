/**
 * @file ArcLength.h
 * @brief Arc length of a curve and its inverse (Eigen only): the one arc length of
 * BlockForge, for every edge and query that places points by length.
 */
#pragma once

#include "Curve.h"

#include <memory>
#include <vector>

namespace blockforge
{
/**
 * @class ArcLength
 * @brief The arc length of BlockForge's curves (edges on carriers, splines, follow edges,
 * `at: {length: f}`) and its inverse, in one of two forms:
 *
 * - the table of a curve on [0, 1]: cumulative lengths at piece ends. Pieces end at the
 *   curve's breakpoints (Curve::breakpoints(): the knots of a B-spline, where the slope
 *   of the speed jumps, and where a curve on a surface crosses the surface's) and are
 *   halved while the 5-point Gauss-Legendre value of a piece differs from its 11-point
 *   Kronrod extension by more than `relativeTolerance` of the curve's length, or the
 *   quartic through the Gauss values misses the speed at the Kronrod nodes (a length
 *   inside a piece is Gauss on part of it), at most MaxLevels halvings. Accurate to about
 *   1e-13 of the length also on curves with hundreds of knots (the blade-hub intersection
 *   of Rotor 37: 2,100 pieces, mostly one per knot span, 11 evaluations each), at a cost
 *   that follows the curve's smoothness, not a fixed count. The old rule (5-point Gauss
 *   on 512 equal pieces) erred by 5e-7 to 2e-3 of the length on the carriers of the
 *   passage templates: knots inside a piece spoil a Gauss rule.
 * - a piece u0 -> u1 of a curve whose table is given (an edge on a fixed carrier): the
 *   carrier's table is built once, and a length is two lookups and two partial pieces, so
 *   an edge whose ends move costs a few curve evaluations, not a table.
 *
 * A length from t = 0 to t is the table's sum up to t's piece plus Gauss on the part of
 * that piece; the inverse is Newton inside the piece found by bisection of the table.
 * Deterministic: the same bits on any number of threads (the table is built on one).
 */
class ArcLength
{
public:
  /// Relative accuracy a table's pieces are refined to.
  static constexpr double DefaultTolerance = 1e-14;
  /// Halvings of a piece at most (kinks no breakpoint announces converge at this depth).
  static constexpr int MaxLevels = 24;
  /// Pieces of a table beyond which no piece is halved any more (bounded cost).
  static constexpr std::size_t MaxPieces = 1 << 18;

  /// The table of `curve` over [0, 1].
  explicit ArcLength(CurvePtr curve, double relativeTolerance = DefaultTolerance);
  /**
   * The arc length of the piece u0 -> u1 of the curve whose table is `base` (u1 < u0 runs
   * backwards), on its own parameter t in [0, 1], u = u0 + t (u1 - u0). With `closed`, u
   * outside [0, 1] goes round the curve again (length adds whole turns); otherwise it is
   * clamped into [0, 1], as model::SubCurve evaluates it.
   */
  ArcLength(std::shared_ptr<const ArcLength> base, double u0, double u1, bool closed);

  double totalLength() const { return Total; }
  /// Length of the curve from 0 to t (t clamped into [0, 1]).
  double lengthAt(double t) const;
  /// Parameter t at which the length from 0 is `fraction` of the total; 0 and 1 exactly
  /// at the ends.
  double parameterAtFraction(double fraction) const;
  /// Pieces of the table (of the base's table for a piece of a curve).
  int pieceCount() const;

private:
  /// Gauss-Legendre (5 points) of the speed on [a, b].
  double gauss(double a, double b) const;
  /// gauss(a, b), the same bits, with the difference from the 11-point Kronrod rule.
  double gaussKronrod(double a, double b, double& error) const;
  /// Table form: the length from 0 to u, and u at which it is `length` (both in [0, 1]).
  double tableLength(double u) const;
  double tableParameter(double length) const;
  /// Piece form: the base's length from 0 to u, u on the real line (closed: turns added).
  double baseLength(double u) const;
  CurvePtr TheCurve;
  std::vector<double> Ends;       ///< piece ends, from 0 to 1 (table form)
  std::vector<double> Cumulative; ///< length at every piece end (table form)
  std::shared_ptr<const ArcLength> Base; ///< piece form
  double U0 = 0.0, U1 = 1.0;
  bool Closed = false;
  double Start = 0.0; ///< piece form: baseLength(U0)
  double Total = 0.0;
};
} // namespace blockforge
