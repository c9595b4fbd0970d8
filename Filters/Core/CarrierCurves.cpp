// Curves made from carriers (Carriers.h): the blade's intersection with a surface of
// revolution and offsets within a surface. The surfaces are in SurfaceOfRevolution.cpp
// and GordonSurface.cpp, curves drawn in a surface's (s, t) in Carriers.cpp.
#include "Carriers.h"
#include "CoreSupport.h"
#include "RootFinding.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace blockforge
{
using core::format;

// =======================================================================================
namespace
{

/// Finds t with f(s, t) = 0 on [tMin, tMax] for one s of the intersection.
class RootFinder
{
public:
  RootFinder(const GordonSurface& surface, const SurfaceOfRevolution& revolution, double tMin,
    double tMax)
    : Surface(surface)
    , Revolution(revolution)
    , TMin(tMin)
    , TMax(tMax)
  {
  }

  double f(double s, double t) const
  {
    WorkBudget::charge();
    return Revolution.signedMeridionalDistance(Surface.point(s, t));
  }

  enum class Preference
  {
    NearUnitRange, ///< nearest [0, 1], then nearest `preferred` (if finite), then lowest t
    NearPreferred  ///< nearest `preferred`
  };

  /// A root within `reach` of `preferred`, when f changes sign across that small bracket
  /// (the refinement's guesses are that close): two evaluations and Brent instead of the
  /// whole scan. False when the bracket shows no sign change (then scan).
  bool findNear(double s, double preferred, double reach, double& root) const
  {
    const double a = std::max(TMin, preferred - reach), b = std::min(TMax, preferred + reach);
    const double fa = f(s, a), fb = f(s, b);
    if (!(b > a) || fa == 0.0 || fb == 0.0 || (fa < 0.0) == (fb < 0.0))
    {
      return false;
    }
    auto fAt = [&](double t) { return f(s, t); };
    const double t = brentRoot(fAt, a, b, fa, fb, 5e-14);
    // as in find(): a true root (|f| ~ 0 against the size of the scanned range), not the
    // jump of f across a contour end's normal
    const double size = (Surface.point(s, TMin) - Surface.point(s, TMax)).norm();
    if (std::abs(fAt(t)) > 1e-7 * (size > 0.0 ? size : 1.0))
    {
      return false;
    }
    root = t;
    return true;
  }

  /// False when no root exists in the range (as far as the scan can see).
  bool find(double s, double preferred, Preference preference, double& root) const
  {
    constexpr int Intervals = 16;
    std::array<double, Intervals + 1> ts, fs;
    Vec3 lower, upper;
    for (int k = 0; k <= Intervals; ++k)
    {
      ts[k] = k == Intervals ? TMax : TMin + (TMax - TMin) * k / Intervals;
      const Vec3 p = Surface.point(s, ts[k]);
      fs[k] = Revolution.signedMeridionalDistance(p);
      lower = k == 0 ? p : lower.cwiseMin(p);
      upper = k == 0 ? p : upper.cwiseMax(p);
    }
    // A sign change of f can also be a jump (the foot point passing a contour end, where
    // the sign flips at non-zero distance); true roots converge to |f| ~ 0, jumps do not.
    const double size = (upper - lower).norm();
    const double residualTolerance = 1e-7 * (size > 0.0 ? size : 1.0);
    bool found = false;
    auto consider = [&](double t) {
      if (!found || better(t, root, preferred, preference))
      {
        root = t;
        found = true;
      }
    };
    auto fAt = [&](double t) { return f(s, t); };
    for (int k = 0; k <= Intervals; ++k)
    {
      if (fs[k] == 0.0)
      {
        consider(ts[k]);
        continue;
      }
      if (k < Intervals && fs[k + 1] != 0.0 && ((fs[k] < 0.0) != (fs[k + 1] < 0.0)))
      {
        const double t = brentRoot(fAt, ts[k], ts[k + 1], fs[k], fs[k + 1], 5e-14);
        if (std::abs(fAt(t)) <= residualTolerance)
        {
          consider(t);
        }
      }
    }
    return found;
  }

private:
  static double distanceToUnit(double t) { return t < 0.0 ? -t : (t > 1.0 ? t - 1.0 : 0.0); }

  static bool better(double t, double incumbent, double preferred, Preference preference)
  {
    if (preference == Preference::NearUnitRange)
    {
      const double dt = distanceToUnit(t), di = distanceToUnit(incumbent);
      if (dt != di)
      {
        return dt < di;
      }
    }
    if (std::isfinite(preferred))
    {
      const double dt = std::abs(t - preferred), di = std::abs(incumbent - preferred);
      if (dt != di)
      {
        return dt < di;
      }
    }
    return t < incumbent;
  }

  const GordonSurface& Surface;
  const SurfaceOfRevolution& Revolution;
  double TMin, TMax;
};
} // namespace

std::shared_ptr<SurfaceCurve> intersectWithRevolution(std::shared_ptr<const GordonSurface> surface,
  const SurfaceOfRevolution& revolution, double tMin, double tMax, int samples,
  WorkBudget* budget)
{
  // more initial samples are more work: the budget grows with them past the default 64
  WorkBudget ownBudget(IntersectionWorkLimit * static_cast<std::size_t>(std::max(1, samples / 64)),
    "intersection with a surface of revolution");
  WorkBudget& work = budget ? *budget : ownBudget;
  const WorkBudget::Scope scope(work);
  if (!surface)
  {
    throw GeometryError("intersection with a surface of revolution: no surface given");
  }
  if (!std::isfinite(tMin) || !std::isfinite(tMax) || !(tMax > tMin))
  {
    throw GeometryError("intersection with a surface of revolution: invalid t range [" +
      format(tMin) + ", " + format(tMax) + "]");
  }
  if (samples < 2)
  {
    throw GeometryError("intersection with a surface of revolution needs at least 2 samples, "
                        "got " +
      std::to_string(samples));
  }
  constexpr std::size_t MaxNodes = 4096;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const RootFinder finder(*surface, revolution, tMin, tMax);
  auto noIntersection = [&](double s) {
    return GeometryError("intersection with a surface of revolution: the surface does not meet "
                         "it at s = " +
      format(s) + " for t in [" + format(tMin) + ", " + format(tMax) +
      "] (sections too short for the extension range, or no crossing)");
  };

  // Closed sections (blade profiles through the trailing edge): s = 0 and s = 1 are one
  // point, which must get one t so the intersection curve closes exactly.
  bool closed = true;
  {
    double size = 0.0;
    for (double t : { 0.0, 0.5, 1.0 })
    {
      size = std::max(size, (surface->point(0.5, t) - surface->point(0.0, t)).norm());
    }
    for (double t : { 0.0, 0.5, 1.0 })
    {
      if (!((surface->point(1.0, t) - surface->point(0.0, t)).norm() <= 1e-12 * size))
      {
        closed = false;
      }
    }
  }

  std::vector<double> sValues(samples), tValues(samples);
  for (int k = 0; k < samples; ++k)
  {
    const double s = k == samples - 1 ? 1.0 : static_cast<double>(k) / (samples - 1);
    sValues[k] = s;
    if (k == samples - 1 && closed)
    {
      tValues[k] = tValues[0];
      continue;
    }
    if (!finder.find(s, k > 0 ? tValues[k - 1] : nan, RootFinder::Preference::NearUnitRange,
          tValues[k]))
    {
      throw noIntersection(s);
    }
  }

  const SurfacePtr base = surface;
  auto build = [&]() {
    std::vector<Eigen::Vector2d> points(sValues.size());
    for (std::size_t k = 0; k < sValues.size(); ++k)
    {
      points[k] = Eigen::Vector2d(sValues[k], tValues[k]);
    }
    return std::make_shared<SurfaceCurve>(base, std::move(points));
  };
  std::shared_ptr<SurfaceCurve> curve = build();

  // Size of the curve for the acceptance tolerance: bounding box and radius of its nodes.
  double scale = 0.0;
  {
    Vec3 lower = surface->point(sValues[0], tValues[0]), upper = lower;
    for (std::size_t k = 0; k < sValues.size(); ++k)
    {
      const Vec3 p = surface->point(sValues[k], tValues[k]);
      lower = lower.cwiseMin(p);
      upper = upper.cwiseMax(p);
      double axial, radius;
      revolution.axialRadial(p, axial, radius);
      scale = std::max(scale, radius);
    }
    scale = std::max(scale, (upper - lower).norm());
    if (!(scale > 0.0))
    {
      scale = 1.0;
    }
  }
  const double tolerance = 1e-10 * scale;

  // Between nodes the curve is an interpolation in (s, t); insert exact roots where it
  // strays from the revolution surface (checked at the middle of each node interval).
  for (int round = 0; round < 16 && sValues.size() < MaxNodes; ++round)
  {
    const std::vector<double>& u = curve->nodeParameters();
    std::vector<double> newS, newT;
    newS.reserve(2 * sValues.size());
    newT.reserve(2 * sValues.size());
    bool inserted = false;
    for (std::size_t k = 0; k < sValues.size(); ++k)
    {
      newS.push_back(sValues[k]);
      newT.push_back(tValues[k]);
      if (k + 1 == sValues.size() || sValues.size() + (newS.size() - k - 1) >= MaxNodes)
      {
        continue;
      }
      const Eigen::Vector2d mid = curve->parameters(0.5 * (u[k] + u[k + 1]));
      if (std::abs(finder.f(mid.x(), mid.y())) <= tolerance)
      {
        continue;
      }
      double s = mid.x();
      if (!(s > sValues[k] && s < sValues[k + 1]))
      {
        s = 0.5 * (sValues[k] + sValues[k + 1]);
      }
      if (!(s > sValues[k] && s < sValues[k + 1]))
      {
        continue; // the interval cannot be split further in double precision
      }
      double t;
      const double reach = 1e-3 * (tMax - tMin);
      if (!finder.findNear(s, mid.y(), reach, t) &&
        !finder.find(s, mid.y(), RootFinder::Preference::NearPreferred, t))
      {
        throw noIntersection(s);
      }
      newS.push_back(s);
      newT.push_back(t);
      inserted = true;
    }
    if (!inserted)
    {
      break;
    }
    sValues = std::move(newS);
    tValues = std::move(newT);
    curve = build();
  }
  return curve;
}
} // namespace blockforge

namespace blockforge
{
namespace
{
struct OffsetSample
{
  double u;
  Vec3 point;
  Vec3 normal;        // unit normal of the curve within the surface
  Vec3 surfaceNormal; // unit normal of the surface there
};

Vec3 inSurfaceNormal(const Curve& curve, const Surface& surface,
  const SurfaceParameterFunction& toParameters, double u, const Vec3& point,
  Vec3& unitSurfaceNormal)
{
  Vec3 tangent = curve.derivative(u);
  if (!(tangent.norm() > 0.0) || !tangent.allFinite())
  {
    // a stationary point of the parametrisation: the chord through its neighbours
    const double h = 1e-7;
    tangent = curve.point(std::min(1.0, u + h)) - curve.point(std::max(0.0, u - h));
  }
  const Eigen::Vector2d st = toParameters(point);
  SurfaceDerivatives d;
  surface.derivatives(st[0], st[1], d);
  const Vec3 surfaceNormal = d.Ps.cross(d.Pt);
  const Vec3 normal = surfaceNormal.cross(tangent);
  if (!(surfaceNormal.norm() > 0.0) || !(normal.norm() > 0.0) || !normal.allFinite())
  {
    std::ostringstream message;
    message << "offset on a surface: the curve tangent or the surface normal vanishes at u = "
            << u;
    throw GeometryError(message.str());
  }
  unitSurfaceNormal = surfaceNormal.normalized();
  return normal.normalized();
}
/// Where segment a0-a1 crosses segment b0-b1 in the plane (e1, e2): true and the point.
bool crossing(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1, const Vec3& e1,
  const Vec3& e2, Vec3& at)
{
  auto flat = [&](const Vec3& p) { return Eigen::Vector2d(p.dot(e1), p.dot(e2)); };
  const Eigen::Vector2d p = flat(a0), r = flat(a1) - p, q = flat(b0), w = flat(b1) - q;
  const double denominator = r.x() * w.y() - r.y() * w.x();
  if (denominator == 0.0)
  {
    return false;
  }
  const Eigen::Vector2d d = q - p;
  const double ta = (d.x() * w.y() - d.y() * w.x()) / denominator;
  const double tb = (d.x() * r.y() - d.y() * r.x()) / denominator;
  if (ta < 0.0 || ta > 1.0 || tb < 0.0 || tb > 1.0)
  {
    return false;
  }
  at = a0 + ta * (a1 - a0);
  return true;
}

/**
 * Removes the swallowtails of an offset: where the curve bends with a radius of curvature
 * below the distance on the side it is offset to (a sharp or spline-wiggled leading edge,
 * the corners of a capped trailing edge), consecutive offset points run backwards and the
 * offset crosses itself. The loop between the two crossing segments is cut out and
 * replaced by the crossing point, as the boundary of the region within `distance` of the
 * curve has it. Elsewhere the offset points stay at their normals, so the O-grid's
 * first layer stays orthogonal to the curve. Throws GeometryError when a fold has no
 * crossing nearby (the offset folds globally: the distance exceeds the curve's size).
 */
void trimOffsetFolds(std::vector<OffsetSample>& samples, std::vector<Vec3>& offset,
  double distance, double side, bool closed)
{
  // Backwards offset steps only where the curve turns towards the offset side: across a
  // sharp convex corner (its normals turn away from that side) the curve's own step is no
  // guide to the offset's direction, and the offset is a fan, not a fold.
  auto folds = [&](std::size_t k) {
    const Vec3 along = samples[k].point - samples[k - 1].point;
    const double turn = side * distance *
      samples[k - 1].normal.cross(samples[k].normal).dot(samples[k].surfaceNormal);
    return along.norm() > 0.0 && (offset[k] - offset[k - 1]).dot(along) <= 0.0 &&
      turn >= 0.0;
  };
  auto fail = [&](std::size_t k) {
    std::ostringstream message;
    message << "offset on a surface: the offset by " << distance << " folds back near u = "
            << samples[k].u
            << " and does not cross itself nearby (the distance is larger than the curve "
               "is wide there); use a smaller distance";
    throw GeometryError(message.str());
  };
  std::size_t k = 1;
  int cuts = 0;
  while (k < offset.size())
  {
    if (!folds(k))
    {
      ++k;
      continue;
    }
    if (++cuts > 10000)
    {
      fail(k);
    }
    // The backward run [k, end): the loop's crossing lies before k and at or after end.
    std::size_t end = k + 1;
    while (end < offset.size() && folds(end))
    {
      ++end;
    }
    // The plane of the fold: the curve's tangent there and the in-surface normal.
    const Vec3 e2 = samples[k].normal;
    const Vec3 e1 = e2.cross(samples[k].surfaceNormal).normalized();
    bool found = false;
    std::size_t first = 0, last = 0;
    Vec3 point;
    const std::size_t widest = std::min<std::size_t>(offset.size(), 4096);
    for (std::size_t width = 8; !found && width <= widest; width *= 2)
    {
      const std::size_t low = k > width ? k - width : 1;
      const std::size_t high = std::min(offset.size() - 1, end + width);
      // The tightest loop around the run: the latest start, then the earliest end.
      for (std::size_t i = k - 1; i >= low && !found; --i)
      {
        for (std::size_t j = end; j <= high && !found; ++j)
        {
          // (A closed loop's first and last segments meet at the seam: not a crossing.)
          found = j > i + 1 && !(closed && i == 1 && j == offset.size() - 1) &&
            crossing(offset[i - 1], offset[i], offset[j - 1], offset[j], e1, e2, point);
          first = i;
          last = j;
        }
      }
    }
    if (!found)
    {
      // A fold too small to cross itself between samples (a zig-zag of a few samples at a
      // wiggle of the curve): drop the points that run backwards.
      if (end - k > 16)
      {
        fail(k);
      }
      offset.erase(offset.begin() + k, offset.begin() + end);
      samples.erase(samples.begin() + k, samples.begin() + end);
      continue;
    }
    // Keep offset[0 .. first - 1], the crossing, offset[last ..].
    offset[first] = point;
    offset.erase(offset.begin() + first + 1, offset.begin() + last);
    samples.erase(samples.begin() + first + 1, samples.begin() + last);
    k = std::max<std::size_t>(first, 1);
  }
}
} // namespace


std::vector<Eigen::Vector2d> offsetOnSurface(const Curve& curve, bool closed,
  const Surface& surface, const SurfaceParameterFunction& toParameters, double distance)
{
  if (!std::isfinite(distance) || distance == 0.0)
  {
    throw GeometryError("offset on a surface: the distance must be finite and not zero");
  }
  if (closed && (curve.point(0.0) - curve.point(1.0)).norm() >
      1e-9 * std::max({ (curve.point(0.5) - curve.point(0.0)).norm(), 1e-300 }))
  {
    throw GeometryError("offset on a surface: the curve is said to be closed but its ends "
                        "do not meet");
  }
  WorkBudget work(OffsetWorkLimit, "offset on a surface");
  const WorkBudget::Scope scope(work);
  constexpr int InitialSteps = 512;
  constexpr std::size_t MaxSamples = 65536;
  const double turnLimit = std::cos(3.0 * std::acos(-1.0) / 180.0);
  auto sampleAt = [&](double u) {
    OffsetSample sample{ u, curve.point(u), Vec3::Zero(), Vec3::Zero() };
    sample.normal =
      inSurfaceNormal(curve, surface, toParameters, u, sample.point, sample.surfaceNormal);
    return sample;
  };

  std::vector<OffsetSample> coarse;
  coarse.reserve(InitialSteps + 1);
  for (int k = 0; k <= InitialSteps; ++k)
  {
    coarse.push_back(sampleAt(static_cast<double>(k) / InitialSteps));
  }
  if (closed)
  {
    // The seam of a closed curve may be only C0: one normal for both ends closes the loop.
    const Vec3 seam = (coarse.front().normal + coarse.back().normal).normalized();
    coarse.front().normal = seam;
    coarse.back().normal = seam;
    coarse.back().point = coarse.front().point;
  }

  // Halve the steps across which the normal turns too fast (depth-first, in order, so the
  // result does not depend on anything but the curve).
  std::vector<OffsetSample> samples;
  samples.reserve(4 * InitialSteps);
  samples.push_back(coarse.front());
  std::function<void(const OffsetSample&, const OffsetSample&, int)> refine =
    [&](const OffsetSample& a, const OffsetSample& b, int depth) {
      if (depth < 16 && a.normal.dot(b.normal) < turnLimit && samples.size() < MaxSamples)
      {
        const OffsetSample middle = sampleAt(0.5 * (a.u + b.u));
        refine(a, middle, depth + 1);
        refine(middle, b, depth + 1);
        return;
      }
      samples.push_back(b);
    };
  for (std::size_t k = 1; k < coarse.size(); ++k)
  {
    refine(coarse[k - 1], coarse[k], 0);
  }

  double side = 1.0;
  if (closed)
  {
    Vec3 centroid = Vec3::Zero();
    for (std::size_t k = 0; k + 1 < samples.size(); ++k)
    {
      centroid += samples[k].point;
    }
    centroid /= static_cast<double>(samples.size() - 1);
    // Outward normals give a positive flux of (p - centroid) through the loop (twice its
    // area, by the divergence theorem); one point's normal (the farthest, say) is not
    // enough at a sharp edge, where it may point either way.
    double flux = 0.0;
    for (std::size_t k = 1; k < samples.size(); ++k)
    {
      const double length = (samples[k].point - samples[k - 1].point).norm();
      const Vec3 middle = 0.5 * (samples[k].point + samples[k - 1].point) - centroid;
      flux += length * middle.dot(samples[k].normal + samples[k - 1].normal);
    }
    if (flux < 0.0)
    {
      side = -1.0;
    }
  }

  std::vector<Vec3> offset(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k)
  {
    offset[k] = samples[k].point + side * distance * samples[k].normal;
  }
  const std::vector<OffsetSample> curveSamples = samples;
  trimOffsetFolds(samples, offset, distance, side, closed);
  // What is left must keep its distance from the whole curve: cutting loops cannot mend
  // an offset that turns inside out (inwards past the middle of a closed curve).
  const std::size_t stride =
    std::max<std::size_t>(1, offset.size() * curveSamples.size() / 4000000);
  for (std::size_t k = 0; k < offset.size(); k += stride)
  {
    double nearest = std::numeric_limits<double>::infinity();
    for (const OffsetSample& c : curveSamples)
    {
      nearest = std::min(nearest, (offset[k] - c.point).norm());
    }
    if (nearest < 0.9 * std::abs(distance))
    {
      std::ostringstream message;
      message << "offset on a surface: the offset by " << distance << " folds back near u = "
              << samples[k].u
              << " and comes within " << nearest
              << " of the curve (the distance is larger than the curve is wide there); use a "
                 "smaller distance";
      throw GeometryError(message.str());
    }
  }

  std::vector<Eigen::Vector2d> parameters;
  parameters.reserve(samples.size());
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  std::vector<Eigen::Vector2d> all(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k)
  {
    all[k] = toParameters(offset[k]);
    low = low.cwiseMin(all[k]);
    high = high.cwiseMax(all[k]);
  }
  if (closed)
  {
    all.back() = all.front();
  }
  // Drop samples that coincide in (s, t) (interpolation needs distinct points).
  const double tiny = 1e-12 * std::max((high - low).norm(), 1e-300);
  for (std::size_t k = 0; k < all.size(); ++k)
  {
    if (!parameters.empty() && (all[k] - parameters.back()).norm() <= tiny)
    {
      if (k + 1 == all.size())
      {
        parameters.back() = all[k]; // keep the exact last point
      }
      continue;
    }
    parameters.push_back(all[k]);
  }
  if (parameters.size() < 2)
  {
    throw GeometryError("offset on a surface: the curve has no length");
  }
  return parameters;
}
} // namespace blockforge

