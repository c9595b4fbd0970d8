/**
 * @file Projection.h
 * @brief Closest-point projection onto curves and surfaces: the nearest point of a
 * precomputed sample, then Newton iterations with a safeguarded fallback (bisection of the
 * bracketing interval for curves, a damped step inside the current cell for surfaces),
 * to a tight tolerance. Parameters are clamped to [0, 1].
 */
#pragma once

#include "Surface.h"

namespace blockforge
{
struct CurveProjection
{
  double t = 0.0;    ///< curve parameter of the closest point
  Vec3 point;        ///< the closest point
  double distance = 0.0;
};

struct SurfaceProjection
{
  double s = 0.0, t = 0.0;
  Vec3 point;
  double distance = 0.0;
};

/**
 * @class CurveProjector
 * @brief Projects many points onto one curve; the sample is computed once.
 */
class CurveProjector
{
public:
  explicit CurveProjector(CurvePtr curve, int samples = 128);
  /// Closest point to p; `tolerance` bounds the parameter step at convergence.
  CurveProjection project(const Vec3& p, double tolerance = 1e-14) const;

private:
  CurvePtr TheCurve;
  std::vector<double> SampleT;
  std::vector<Vec3> SamplePoints;
  /// The samples' coordinates one array each (the distance scan runs as a vector loop,
  /// the same operations as (sample - p).norm()), and each sample's largest distance to a
  /// neighbour.
  std::vector<double> SampleX, SampleY, SampleZ, Spacing;
};

/**
 * @class SurfaceProjector
 * @brief Projects many points onto one surface; the sample grid is computed once.
 */
class SurfaceProjector
{
public:
  explicit SurfaceProjector(SurfacePtr surface, int samplesS = 48, int samplesT = 48);
  SurfaceProjection project(const Vec3& p, double tolerance = 1e-14) const;

private:
  SurfacePtr TheSurface;
  int SamplesS, SamplesT;
  std::vector<Vec3> SamplePoints; // s fastest
  /// Per sample, the largest distance to a neighbour (the sample cell's size).
  std::vector<double> Spacing;
  /// Blocks of 8 x 8 samples with their bounding boxes: the search skips the far ones.
  struct Tile
  {
    int i0 = 0, i1 = 0, j0 = 0, j1 = 0;
    Vec3 low, high;
    double spacing = 0.0;
  };
  std::vector<Tile> Tiles;
};

} // namespace blockforge
