/**
 * @file SurfaceFaceGrid.h
 * @brief Grids of faces lying on a parametric surface (a blade, a hub, a shroud): every
 * node evaluated by the surface, the boundary distributions' node order kept.
 *
 * Two ways of placing a face's interior nodes are combined:
 * - projected TFI: each node is the surface point nearest the face's 3-D TFI node,
 *   searched from the node of a TFI in (s, t). It spaces nodes as the 3-D edges do,
 *   whatever the parametrisation, but near an edge whose cells are much smaller than
 *   the face's curvature the 3-D TFI node is off the surface by more than a cell
 *   (the chord of a twisted or bowed surface), and its nearest point can lie past its
 *   neighbours: cells fold.
 * - parameter TFI in an even metric: TFI of the boundary's parameters after each
 *   parameter is mapped to the arc length along the surface's iso-line through the middle
 *   of the face (sigma(s), tau(t)), mapped back after. A plane TFI of monotone boundary
 *   distributions on a near-rectangular region does not fold however strongly they are
 *   graded, the monotone maps keep that, and a regular surface keeps the order of its
 *   parameter grid.
 * The face takes the projected TFI; where one of its cell corners is nearly flat or
 * folded (scaled Jacobian below a small bound, measured with the surface's first
 * fundamental form), or one of its cell sides is more than 2 times longer or shorter than
 * the parameter grid's (the 3-D TFI node off the surface by more than a cell near a thin
 * edge, projected to a point that slid along the edge's round without folding anything:
 * Rotor 37's trailing-edge cells 6 times shorter at mid-span than at hub and shroud), the
 * nodes are moved towards the parameter grid, halving their step until every cell corner
 * is at least as good as the bound or the parameter grid's and, on a face that slid so,
 * every side within 1.5 of the parameter grid's. Faces where the projected TFI is fine keep
 * it bit for bit.
 */
#pragma once

#include "Transfinite.h"
#include "Types.h"

#include <Eigen/Core>

#include <vector>

namespace blockforge
{
/**
 * @class ParametricSurface
 * @brief A surface as a face grid sees it: points at (s, t) (wrapping closed directions,
 * limiting t to its range).
 */
class ParametricSurface
{
public:
  virtual ~ParametricSurface() = default;
  virtual Vec3 point(double s, double t) const = 0;
  /// point() at (s, t), (s + h, t), (s - h, t), (s, t + h), (s, t - h).
  virtual void crossPoints(double s, double t, double h, Vec3 out[5]) const;
  virtual double tMin() const { return 0.0; }
  virtual double tMax() const { return 1.0; }
};

/**
 * The surface point closest to `target` near (s, t): Gauss-Newton from there on the
 * surface's own parameters (derivatives by central differences), steps limited so the
 * node stays on the part of the surface it started on (a thin trailing edge has another
 * side close by). `start` gets the surface point at the (s, t) it starts from; `ps`, `pt`
 * (when given) the last tangents evaluated.
 */
void closestNear(const ParametricSurface& surface, const Vec3& target, double& s, double& t,
  Vec3& start, Vec3* ps = nullptr, Vec3* pt = nullptr);

enum class SurfaceFaceMethod
{
  ProjectedTfi, ///< the nearest surface point of each 3-D TFI node only (may fold)
  Guarded       ///< that, moved towards the even-metric parameter TFI where a cell folds
};

/// What surfaceFaceGrid did (for tests and diagnostics).
struct SurfaceFaceReport
{
  int guardedNodes = 0; ///< interior nodes moved towards the parameter grid
  int rounds = 0;       ///< halving rounds
};

/**
 * Grid of a face of na x nb nodes (a fastest) on `surface`. `loop` holds the (s, t) of
 * the boundary nodes in loop order (bottom a up, right b up, top a down, left b down;
 * 2 (na - 1) + 2 (nb - 1) nodes), unwrapped across seams so neighbours are close; the
 * edges give the 3-D boundary nodes and their distribution parameters. `out` (na * nb * 3)
 * gets the interior nodes (each evaluated by the surface); its boundary nodes are the
 * edges' own (copied). `blending` is that of both interpolations (Transfinite.h). Deterministic, the same bits with or without threads.
 */
void surfaceFaceGrid(const ParametricSurface& surface, const std::vector<Eigen::Vector2d>& loop,
  const EdgeNodes& bottom, const EdgeNodes& top, const EdgeNodes& left, const EdgeNodes& right,
  double* out, SurfaceFaceMethod method = SurfaceFaceMethod::Guarded,
  SurfaceFaceReport* report = nullptr,
  std::array<Blending, 2> blending = { Blending::Linear, Blending::Linear });
} // namespace blockforge
