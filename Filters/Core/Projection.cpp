#include "Projection.h"

#include "CoreSupport.h"
#include "RootFinding.h"

#include "WorkBudget.h"

#include "BSpline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace blockforge
{
namespace
{
constexpr double Epsilon = std::numeric_limits<double>::epsilon();
/// Local minima of the sampled distance refined per projection: more than one guards
/// against points near the medial axis, where the nearest sample may sit in the basin
/// of the slightly farther foot point.
constexpr std::size_t MaxCandidates = 6;

/// Point, first and second derivative of a curve; B-spline curves compute all three from
/// one basis evaluation.
struct CurveJet
{
  Vec3 P, D1, D2;
};

class CurveEvaluator
{
public:
  explicit CurveEvaluator(const Curve& curve)
    : TheCurve(curve)
    , Spline(dynamic_cast<const BSplineCurve*>(&curve))
  {
  }

  void evaluate(double t, CurveJet& jet) const
  {
    WorkBudget::charge();
    if (Spline)
    {
      Vec3 values[3];
      Spline->derivatives(t, 2, values);
      jet.P = values[0];
      jet.D1 = values[1];
      jet.D2 = values[2];
    }
    else
    {
      Vec3 values[3];
      TheCurve.jet(t, values);
      jet.P = values[0];
      jet.D1 = values[1];
      jet.D2 = values[2];
    }
  }

  Vec3 point(double t) const { return TheCurve.point(t); }

private:
  const Curve& TheCurve;
  const BSplineCurve* Spline;
};

using core::clampUnit;

void requireFinite(const Vec3& p)
{
  if (!core::isFinite(p))
  {
    throw GeometryError("projection: the point to project has a non-finite coordinate");
  }
}

struct Candidate
{
  double distance;
  int index;
  bool operator<(const Candidate& o) const
  {
    return distance < o.distance || (distance == o.distance && index < o.index);
  }
};

/// Keeps the `MaxCandidates` best candidates in a fixed array (no heap allocation).
class CandidateList
{
public:
  void offer(const Candidate& c)
  {
    std::size_t position = Count < MaxCandidates ? Count++ : MaxCandidates;
    if (position == MaxCandidates)
    {
      if (!(c < Items[MaxCandidates - 1]))
      {
        return;
      }
      position = MaxCandidates - 1;
    }
    // Insertion into the sorted list.
    while (position > 0 && c < Items[position - 1])
    {
      Items[position] = Items[position - 1];
      --position;
    }
    Items[position] = c;
  }
  std::size_t size() const { return Count; }
  const Candidate& operator[](std::size_t i) const { return Items[i]; }

private:
  std::array<Candidate, MaxCandidates> Items{};
  std::size_t Count = 0;
};

// ---------------------------------------------------------------------------------------
// Curves: the closest point is a root of g(t) = (C(t) - p) . C'(t) with g' > 0 there, or a
// clamped end of [0, 1]. Within a sign-changing bracket Newton is safeguarded by bisection
// (rtsafe), which always converges.

double gradient(const CurveJet& jet, const Vec3& p)
{
  return (jet.P - p).dot(jet.D1);
}

double solveBracketed(const CurveEvaluator& curve, const Vec3& p, double lo, double hi,
  double gLo, double gHi, double tolerance)
{
  // Regula falsi start: better than the midpoint when g is nearly linear.
  double t = lo + gLo / (gLo - gHi) * (hi - lo);
  if (!(t > lo && t < hi))
  {
    t = 0.5 * (lo + hi);
  }
  CurveJet jet;
  const auto g = [&](double at) {
    curve.evaluate(at, jet);
    return gradient(jet, p);
  };
  const auto slope = [&](double) { return jet.D1.squaredNorm() + (jet.P - p).dot(jet.D2); };
  NewtonStop stop;
  stop.stepTolerance = tolerance;
  stop.halveEveryTwoSteps = true; // the bracket shrinks geometrically
  return newtonInBracket(g, slope, lo, hi, t, stop);
}

// ---------------------------------------------------------------------------------------
// Surfaces: minimise f = |S(s,t) - p|^2 / 2 on the unit square by projected Newton steps
// (bound constraints handled by an active set), falling back to Gauss-Newton or steepest
// descent where the Hessian is not positive definite, with a backtracking line search.

struct SurfaceState
{
  double s, t;
  SurfaceDerivatives d;
  Vec3 residual;
  double f;
  double gs, gt; // gradient of f
};

void evaluateState(const Surface& surface, const Vec3& p, SurfaceState& state)
{
  WorkBudget::charge();
  surface.derivatives(state.s, state.t, state.d);
  state.residual = state.d.P - p;
  state.f = 0.5 * state.residual.squaredNorm();
  state.gs = state.residual.dot(state.d.Ps);
  state.gt = state.residual.dot(state.d.Pt);
}

/// Gradient with the components that push against an active bound removed.
void projectedGradient(const SurfaceState& x, double& ps, double& pt)
{
  ps = ((x.s <= 0.0 && x.gs > 0.0) || (x.s >= 1.0 && x.gs < 0.0)) ? 0.0 : x.gs;
  pt = ((x.t <= 0.0 && x.gt > 0.0) || (x.t >= 1.0 && x.gt < 0.0)) ? 0.0 : x.gt;
}

void descentDirection(const SurfaceState& x, bool freeS, bool freeT, double& ds, double& dt)
{
  const SurfaceDerivatives& d = x.d;
  const double jss = d.Ps.squaredNorm(), jst = d.Ps.dot(d.Pt), jtt = d.Pt.squaredNorm();
  const double hss = jss + x.residual.dot(d.Pss);
  const double hst = jst + x.residual.dot(d.Pst);
  const double htt = jtt + x.residual.dot(d.Ptt);
  const double gs = freeS ? x.gs : 0.0, gt = freeT ? x.gt : 0.0;
  ds = dt = 0.0;

  auto solve2 = [&](double a, double b, double c) {
    // [a b; b c] positive definite with a margin against near-singular steps.
    const double det = a * c - b * b;
    if (a > 0.0 && c > 0.0 && det > 1e-12 * a * c)
    {
      ds = -(c * gs - b * gt) / det;
      dt = -(a * gt - b * gs) / det;
      return true;
    }
    return false;
  };
  auto solve1 = [](double h, double g, double& step) {
    if (h > 0.0)
    {
      step = -g / h;
      return true;
    }
    return false;
  };

  bool solved = false;
  if (freeS && freeT)
  {
    solved = solve2(hss, hst, htt) || solve2(jss, jst, jtt);
  }
  else if (freeS)
  {
    solved = solve1(hss, gs, ds) || solve1(jss, gs, ds);
  }
  else if (freeT)
  {
    solved = solve1(htt, gt, dt) || solve1(jtt, gt, dt);
  }
  if (!solved || !(ds * gs + dt * gt < 0.0))
  {
    // Steepest descent scaled by the metric, so its size is that of a Gauss-Newton step.
    const double scale = std::max(jss + jtt, std::numeric_limits<double>::min());
    ds = -gs / scale;
    dt = -gt / scale;
  }
}

SurfaceState refineOnSurface(const Surface& surface, const Vec3& p, double s0, double t0,
  double maxStep, double tolerance)
{
  SurfaceState x;
  x.s = s0;
  x.t = t0;
  evaluateState(surface, p, x);
  SurfaceState trial;
  for (int iteration = 0; iteration < 100; ++iteration)
  {
    double pgs, pgt;
    projectedGradient(x, pgs, pgt);
    if (pgs == 0.0 && pgt == 0.0)
    {
      break;
    }
    double ds, dt;
    descentDirection(x, pgs != 0.0 || (x.s > 0.0 && x.s < 1.0),
      pgt != 0.0 || (x.t > 0.0 && x.t < 1.0), ds, dt);
    // Damping: far from the solution Newton may jump across the surface; a step is
    // limited to a few sample cells.
    const double largest = std::max(std::abs(ds), std::abs(dt));
    if (largest > maxStep)
    {
      ds *= maxStep / largest;
      dt *= maxStep / largest;
    }
    const double gradientNorm = std::hypot(pgs, pgt);
    bool accepted = false;
    double stepS = 0.0, stepT = 0.0;
    for (double alpha = 1.0; alpha > 1e-12; alpha *= 0.5)
    {
      trial.s = clampUnit(x.s + alpha * ds);
      trial.t = clampUnit(x.t + alpha * dt);
      stepS = trial.s - x.s;
      stepT = trial.t - x.t;
      if (stepS == 0.0 && stepT == 0.0)
      {
        break;
      }
      evaluateState(surface, p, trial);
      const double predicted = x.gs * stepS + x.gt * stepT; // < 0 for a descent step
      if (trial.f <= x.f + 1e-4 * predicted)
      {
        accepted = true;
        break;
      }
      // Near the minimum f changes below its rounding, which comes from the coordinates
      // (|r| * |P| * eps), not from f itself; progress then shows in the gradient.
      double tgs, tgt;
      projectedGradient(trial, tgs, tgt);
      const double noise = 8.0 * Epsilon *
        (x.f + std::sqrt(2.0 * x.f) * (x.d.P.cwiseAbs().maxCoeff() + p.cwiseAbs().maxCoeff()));
      if (trial.f <= x.f + noise && std::hypot(tgs, tgt) < gradientNorm)
      {
        accepted = true;
        break;
      }
    }
    if (!accepted)
    {
      break;
    }
    x = trial;
    if (std::max(std::abs(stepS), std::abs(stepT)) <= tolerance)
    {
      break;
    }
  }
  return x;
}
} // namespace

// =======================================================================================
CurveProjector::CurveProjector(CurvePtr curve, int samples)
  : TheCurve(std::move(curve))
{
  if (!TheCurve)
  {
    throw GeometryError("curve projection: no curve given");
  }
  if (samples < 2)
  {
    throw GeometryError("curve projection needs at least 2 samples, got " +
      std::to_string(samples));
  }
  SampleT.resize(samples);
  SamplePoints.resize(samples);
  for (int i = 0; i < samples; ++i)
  {
    SampleT[i] = static_cast<double>(i) / (samples - 1);
  }
  SampleT.back() = 1.0;
  for (int i = 0; i < samples; ++i)
  {
    SamplePoints[i] = TheCurve->point(SampleT[i]);
  }
  SampleX.resize(samples);
  SampleY.resize(samples);
  SampleZ.resize(samples);
  Spacing.assign(samples, 0.0);
  for (int i = 0; i < samples; ++i)
  {
    SampleX[i] = SamplePoints[i].x();
    SampleY[i] = SamplePoints[i].y();
    SampleZ[i] = SamplePoints[i].z();
    if (i > 0)
    {
      Spacing[i] = std::max(Spacing[i], (SamplePoints[i] - SamplePoints[i - 1]).norm());
    }
    if (i + 1 < samples)
    {
      Spacing[i] = std::max(Spacing[i], (SamplePoints[i + 1] - SamplePoints[i]).norm());
    }
  }
}

CurveProjection CurveProjector::project(const Vec3& p, double tolerance) const
{
  requireFinite(p);
  const int n = static_cast<int>(SamplePoints.size());
  const CurveEvaluator curve(*TheCurve);

  // Local minima of the sampled distance; one whose distance minus its sample spacing
  // exceeds the best sampled distance cannot contain the closest point.
  thread_local std::vector<double> distances;
  distances.resize(n);
  // (sample - p).norm() written out: the same operations in the same order, the same
  // bits, as a loop the compiler vectorises (most of a projection's time otherwise).
  {
    using Column = Eigen::Map<const Eigen::ArrayXd>;
    const Column x(SampleX.data(), n), y(SampleY.data(), n), z(SampleZ.data(), n);
    Eigen::Map<Eigen::ArrayXd> out(distances.data(), n);
    out = ((x - p.x()).square() + (y - p.y()).square() + (z - p.z()).square()).sqrt();
  }
  // The smallest (finite, non-negative distances: any order gives the same value).
  const double best = Eigen::Map<const Eigen::ArrayXd>(distances.data(), n).minCoeff();
  CandidateList candidates;
  for (int i = 0; i < n; ++i)
  {
    const double d = distances[i];
    if ((i > 0 && distances[i - 1] < d) || (i + 1 < n && distances[i + 1] < d))
    {
      continue;
    }
    if (d - Spacing[i] <= best)
    {
      candidates.offer({ d, i });
    }
  }

  CurveProjection result;
  result.distance = std::numeric_limits<double>::infinity();
  auto consider = [&](double t) {
    const Vec3 q = curve.point(t);
    const double d = (q - p).norm();
    if (d < result.distance)
    {
      result.t = t;
      result.point = q;
      result.distance = d;
    }
  };

  CurveJet jet;
  for (std::size_t c = 0; c < candidates.size(); ++c)
  {
    const int i = candidates[c].index;
    const double lo = SampleT[std::max(i - 1, 0)];
    const double mid = SampleT[i];
    const double hi = SampleT[std::min(i + 1, n - 1)];
    curve.evaluate(lo, jet);
    const double gLo = gradient(jet, p);
    curve.evaluate(mid, jet);
    const double gMid = gradient(jet, p);
    curve.evaluate(hi, jet);
    const double gHi = gradient(jet, p);
    auto halfDistanceSquared = [&](int k) {
      return 0.5 * (SamplePoints[std::min(std::max(k, 0), n - 1)] - p).squaredNorm();
    };
    const double fLo = halfDistanceSquared(i - 1), fMid = halfDistanceSquared(i),
                 fHi = halfDistanceSquared(i + 1);

    // Stationary points and clamped ends only: near the minimum the distance is flat to
    // second order, so comparing it with the sample's distance cannot tell them apart.
    bool found = false;
    if (gMid == 0.0)
    {
      consider(mid);
      found = true;
    }
    auto searchInterval = [&](double a, double b, double fa, double fb, double ga, double gb) {
      if (!(b > a))
      {
        return;
      }
      if (ga < 0.0 && gb > 0.0)
      {
        consider(solveBracketed(curve, p, a, b, ga, gb, tolerance));
        found = true;
        return;
      }
      // Same sign at both ends: a minimum and a maximum may hide inside. The cubic
      // Hermite model of f from the known values and slopes locates them at no cost;
      // g at the model's critical points then brackets the minimum.
      if (!((ga < 0.0 && gb < 0.0) || (ga > 0.0 && gb > 0.0)))
      {
        return;
      }
      const double h = b - a;
      const double m0 = ga * h, m1 = gb * h, delta = fb - fa;
      const double c0 = m0, c1 = 2.0 * (3.0 * delta - 2.0 * m0 - m1),
                   c2 = 3.0 * (m0 + m1 - 2.0 * delta);
      const double discriminant = c1 * c1 - 4.0 * c2 * c0;
      if (c2 == 0.0 || !(discriminant > 0.0))
      {
        return;
      }
      // Numerically stable roots of c2 x^2 + c1 x + c0.
      const double q = -0.5 * (c1 + std::copysign(std::sqrt(discriminant), c1));
      double r1 = q / c2, r2 = q != 0.0 ? c0 / q : r1;
      if (r1 > r2)
      {
        std::swap(r1, r2);
      }
      double points[4] = { a, a + h * r1, a + h * r2, b };
      double slopes[4] = { ga, 0.0, 0.0, gb };
      if (!(r1 > 0.0 && r2 < 1.0))
      {
        return;
      }
      for (int k = 1; k <= 2; ++k)
      {
        curve.evaluate(points[k], jet);
        slopes[k] = gradient(jet, p);
      }
      for (int k = 0; k < 3; ++k)
      {
        if (slopes[k] < 0.0 && slopes[k + 1] > 0.0 && points[k + 1] > points[k])
        {
          consider(solveBracketed(
            curve, p, points[k], points[k + 1], slopes[k], slopes[k + 1], tolerance));
          found = true;
        }
      }
    };
    searchInterval(lo, mid, fLo, fMid, gLo, gMid);
    searchInterval(mid, hi, fMid, fHi, gMid, gHi);
    // Clamping: the distance still decreases towards an end of the curve.
    if (lo == 0.0 && gLo >= 0.0)
    {
      consider(0.0);
      found = true;
    }
    if (hi == 1.0 && gHi <= 0.0)
    {
      consider(1.0);
      found = true;
    }
    if (!found)
    {
      // The distance wiggles within two sample intervals (very curved or noisy curve):
      // look for a sign change of g on a finer grid.
      constexpr int Sub = 32;
      double tPrev = lo, gPrev = gLo;
      for (int k = 1; k <= Sub; ++k)
      {
        const double tk = k == Sub ? hi : lo + (hi - lo) * k / Sub;
        curve.evaluate(tk, jet);
        const double gk = gradient(jet, p);
        if (gPrev < 0.0 && gk > 0.0)
        {
          consider(solveBracketed(curve, p, tPrev, tk, gPrev, gk, tolerance));
        }
        tPrev = tk;
        gPrev = gk;
      }
      consider(mid);
    }
  }
  return result;
}

// =======================================================================================
SurfaceProjector::SurfaceProjector(SurfacePtr surface, int samplesS, int samplesT)
  : TheSurface(std::move(surface))
  , SamplesS(samplesS)
  , SamplesT(samplesT)
{
  if (!TheSurface)
  {
    throw GeometryError("surface projection: no surface given");
  }
  if (samplesS < 2 || samplesT < 2)
  {
    throw GeometryError("surface projection needs at least 2 x 2 samples");
  }
  SamplePoints.resize(static_cast<std::size_t>(samplesS) * samplesT);
  for (int j = 0; j < samplesT; ++j)
  {
    const double t = j == samplesT - 1 ? 1.0 : static_cast<double>(j) / (samplesT - 1);
    for (int i = 0; i < samplesS; ++i)
    {
      const double s = i == samplesS - 1 ? 1.0 : static_cast<double>(i) / (samplesS - 1);
      SamplePoints[i + static_cast<std::size_t>(j) * samplesS] = TheSurface->point(s, t);
    }
  }
  auto at = [&](int i, int j) -> const Vec3& {
    return SamplePoints[i + static_cast<std::size_t>(j) * samplesS];
  };
  Spacing.assign(SamplePoints.size(), 0.0);
  for (int j = 0; j < samplesT; ++j)
  {
    for (int i = 0; i < samplesS; ++i)
    {
      double& spacing = Spacing[i + static_cast<std::size_t>(j) * samplesS];
      for (int dj = -1; dj <= 1; ++dj)
      {
        for (int di = -1; di <= 1; ++di)
        {
          const int ii = i + di, jj = j + dj;
          if (ii >= 0 && jj >= 0 && ii < samplesS && jj < samplesT)
          {
            spacing = std::max(spacing, (at(ii, jj) - at(i, j)).norm());
          }
        }
      }
    }
  }
  const int size = 8;
  for (int j0 = 0; j0 < samplesT; j0 += size)
  {
    for (int i0 = 0; i0 < samplesS; i0 += size)
    {
      Tile tile;
      tile.i0 = i0;
      tile.j0 = j0;
      tile.i1 = std::min(samplesS, i0 + size);
      tile.j1 = std::min(samplesT, j0 + size);
      tile.low = Vec3::Constant(std::numeric_limits<double>::infinity());
      tile.high = -tile.low;
      for (int j = tile.j0; j < tile.j1; ++j)
      {
        for (int i = tile.i0; i < tile.i1; ++i)
        {
          tile.low = tile.low.cwiseMin(at(i, j));
          tile.high = tile.high.cwiseMax(at(i, j));
          tile.spacing = std::max(tile.spacing, Spacing[i + static_cast<std::size_t>(j) * samplesS]);
        }
      }
      Tiles.push_back(tile);
    }
  }
}

SurfaceProjection SurfaceProjector::project(const Vec3& p, double tolerance) const
{
  requireFinite(p);
  const int ns = SamplesS, nt = SamplesT;
  const std::size_t count = SamplePoints.size();

  // Per-thread scratch: projection runs in inner loops and must not allocate each call.
  // Distances are computed when first needed, each with the same formula, so the search
  // sees the same numbers as one computing them all.
  thread_local std::vector<double> distances;
  thread_local std::vector<char> known;
  distances.resize(count);
  known.assign(count, 0);
  auto distance = [&](std::size_t k) {
    if (!known[k])
    {
      distances[k] = (SamplePoints[k] - p).norm();
      known[k] = 1;
    }
    return distances[k];
  };
  // The nearest sample: tiles nearest first, until a tile's box is farther than the best
  // sample so far (its samples cannot be nearer). Bounds are lowered by a margin far above
  // rounding, so no tile that might hold the nearest sample is left out.
  const std::size_t tileCount = Tiles.size();
  thread_local std::vector<std::pair<double, std::size_t>> byBound;
  byBound.clear();
  for (std::size_t k = 0; k < tileCount; ++k)
  {
    const Tile& tile = Tiles[k];
    const Vec3 gap = (tile.low - p).cwiseMax(p - tile.high).cwiseMax(Vec3::Zero());
    byBound.emplace_back(gap.norm() * (1.0 - 1e-12), k);
  }
  std::sort(byBound.begin(), byBound.end());
  double best = std::numeric_limits<double>::infinity();
  for (const auto& entry : byBound)
  {
    if (entry.first > best)
    {
      break;
    }
    const Tile& tile = Tiles[entry.second];
    for (int j = tile.j0; j < tile.j1; ++j)
    {
      for (int i = tile.i0; i < tile.i1; ++i)
      {
        best = std::min(best, distance(i + static_cast<std::size_t>(j) * ns));
      }
    }
  }
  // Candidates: local minima no farther than the best sample by more than their cell size
  // (Spacing); only tiles near enough to hold one are searched, and candidates are offered
  // in sample order.
  thread_local std::vector<std::size_t> found;
  found.clear();
  for (const auto& entry : byBound)
  {
    const Tile& tile = Tiles[entry.second];
    if (entry.first > (best + tile.spacing) * (1.0 + 1e-12))
    {
      continue;
    }
    for (int j = tile.j0; j < tile.j1; ++j)
    {
      for (int i = tile.i0; i < tile.i1; ++i)
      {
        const std::size_t index = i + static_cast<std::size_t>(j) * ns;
        const double d = distance(index);
        if (!(d - Spacing[index] <= best))
        {
          continue;
        }
        // A local minimum farther than the best sample by more than its cell size cannot
        // hold the closest point.
        bool localMinimum = true;
        for (int dj = -1; dj <= 1 && localMinimum; ++dj)
        {
          for (int di = -1; di <= 1; ++di)
          {
            const int ii = i + di, jj = j + dj;
            if (ii >= 0 && jj >= 0 && ii < ns && jj < nt &&
              distance(ii + static_cast<std::size_t>(jj) * ns) < d)
            {
              localMinimum = false;
              break;
            }
          }
        }
        if (localMinimum)
        {
          found.push_back(index);
        }
      }
    }
  }
  std::sort(found.begin(), found.end());
  CandidateList candidates;
  for (const std::size_t index : found)
  {
    candidates.offer({ distances[index], static_cast<int>(index) });
  }

  // A step may cross at most two sample cells; beyond that the sample is a better guide.
  const double maxStep = 2.0 / std::min(ns - 1, nt - 1);
  SurfaceProjection result;
  result.distance = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < candidates.size(); ++c)
  {
    const int i = candidates[c].index % ns, j = candidates[c].index / ns;
    const double s0 = i == ns - 1 ? 1.0 : static_cast<double>(i) / (ns - 1);
    const double t0 = j == nt - 1 ? 1.0 : static_cast<double>(j) / (nt - 1);
    const SurfaceState x = refineOnSurface(*TheSurface, p, s0, t0, maxStep, tolerance);
    const double d = x.residual.norm();
    if (d < result.distance)
    {
      result.s = x.s;
      result.t = x.t;
      result.point = x.d.P;
      result.distance = d;
    }
  }
  return result;
}

} // namespace blockforge
