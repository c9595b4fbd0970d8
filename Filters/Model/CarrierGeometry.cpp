#include "CarrierGeometry.h"

#include "ModelSyntax.h"
#include "Errors.h"

#include "../Core/BSpline.h"
#include "../Core/Parallel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

namespace blockforge
{
namespace model
{
namespace
{
constexpr double Pi = 3.14159265358979323846;
constexpr int MaxDepth = 64;

double clampUnit(double x)
{
  return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}
} // namespace

ParameterMethod parameterMethodOf(int method)
{
  return method == 0 ? ParameterMethod::Uniform
    : method == 2    ? ParameterMethod::Centripetal
                     : ParameterMethod::ChordLength;
}

double wrapUnit(double x)
{
  if (x >= 0.0 && x <= 1.0)
  {
    return x;
  }
  return x - std::floor(x);
}

// ------------------------------------------------------------------------ SubCurve
SubCurve::SubCurve(CurvePtr curve, double u0, double u1, bool closed)
  : Base(std::move(curve))
  , U0(u0)
  , U1(u1)
  , Closed(closed)
{
}

double SubCurve::map(double t) const
{
  const double u = t <= 0.0 ? U0 : (t >= 1.0 ? U1 : U0 + t * (U1 - U0));
  return Closed ? wrapUnit(u) : clampUnit(u);
}

Vec3 SubCurve::point(double t) const
{
  return Base->point(map(t));
}

Vec3 SubCurve::derivative(double t, int order) const
{
  const double scale = U1 - U0;
  return Base->derivative(map(t), order) * (order == 1 ? scale : scale * scale);
}

namespace
{
/**
 * Appends to `out` the parameters u in (0, 1) at which x = from + u (to - from) passes a
 * value of `marks` or 0 or 1 (where a curve or surface may kink), or, when `closed`, one
 * of those plus a whole number of turns (the seam, and the marks again past it).
 */
void addCrossings(std::vector<double> marks, double from, double to, bool closed,
  std::vector<double>& out)
{
  if (from == to)
  {
    return;
  }
  marks.insert(marks.begin(), 0.0);
  marks.push_back(1.0);
  const double low = std::min(from, to), high = std::max(from, to);
  const double firstTurn = closed ? std::floor(low) : 0.0, lastTurn = closed ? std::floor(high) : 0.0;
  for (double turn = firstTurn; turn <= lastTurn; turn += 1.0)
  {
    for (const double mark : marks)
    {
      const double u = (turn + mark - from) / (to - from);
      if (u > 0.0 && u < 1.0)
      {
        out.push_back(u);
      }
    }
  }
}
} // namespace

std::vector<double> SubCurve::breakpoints() const
{
  std::vector<double> inner;
  addCrossings(Base->breakpoints(), U0, U1, Closed, inner);
  std::sort(inner.begin(), inner.end());
  return inner;
}

// ------------------------------------------------------------- ParameterLineCurve
ParameterLineCurve::ParameterLineCurve(SurfacePtr surface, const Eigen::Vector2d& from,
  const Eigen::Vector2d& to, bool closedS, bool closedT, bool extendT)
  : TheSurface(std::move(surface))
  , From(from)
  , To(to)
  , ClosedS(closedS)
  , ClosedT(closedT)
  , ExtendT(extendT)
{
}

Eigen::Vector2d ParameterLineCurve::parameters(double u) const
{
  Eigen::Vector2d st = u <= 0.0 ? From : (u >= 1.0 ? To : Eigen::Vector2d(From + u * (To - From)));
  st[0] = ClosedS ? wrapUnit(st[0]) : clampUnit(st[0]);
  st[1] = ClosedT ? wrapUnit(st[1]) : ExtendT ? std::max(-1.0, std::min(2.0, st[1])) : clampUnit(st[1]);
  return st;
}

std::vector<double> ParameterLineCurve::breakpoints() const
{
  std::vector<double> result;
  addCrossings(TheSurface->breakpoints(false), From[0], To[0], ClosedS, result);
  addCrossings(TheSurface->breakpoints(true), From[1], To[1], ClosedT, result);
  std::sort(result.begin(), result.end());
  return result;
}

Vec3 ParameterLineCurve::point(double u) const
{
  const Eigen::Vector2d st = parameters(u);
  return TheSurface->point(st[0], st[1]);
}

Vec3 ParameterLineCurve::derivative(double u, int order) const
{
  const Eigen::Vector2d st = parameters(u);
  const Eigen::Vector2d delta = To - From;
  if (order == 1)
  {
    Vec3 P, Ps, Pt;
    TheSurface->firstDerivatives(st[0], st[1], P, Ps, Pt);
    return Ps * delta[0] + Pt * delta[1];
  }
  SurfaceDerivatives d;
  TheSurface->derivatives(st[0], st[1], d);
  return d.Pss * delta[0] * delta[0] + 2.0 * d.Pst * delta[0] * delta[1] +
    d.Ptt * delta[1] * delta[1];
}

// ---------------------------------------------------------------- CarrierGeometry
CarrierGeometry::CarrierGeometry(const BlockModel& model)
{
  for (int i = 0; i < static_cast<int>(model.carriers.size()); ++i)
  {
    build(model, i);
  }
}

std::shared_ptr<const ArcLength> CarrierGeometry::lengthTable(int index) const
{
  const Entry& entry = Entries.at(index);
  std::lock_guard<std::mutex> lock(entry.length->lock);
  if (!entry.length->table)
  {
    entry.length->table = std::make_shared<ArcLength>(entry.curve);
  }
  return entry.length->table;
}

void CarrierGeometry::prepareLengthTables(const std::vector<int>& indices) const
{
  forEachChunk(static_cast<long>(indices.size()), [&](long k) {
    try
    {
      lengthTable(indices[k]);
    }
    catch (const std::exception&)
    {
      // left unmade: lengthTable() throws again where an entity uses it
    }
  });
}

void CarrierGeometry::build(const BlockModel& model, int index)
{
  if (Entries.size() < model.carriers.size())
  {
    Entries.resize(model.carriers.size());
  }
  buildEntry(model, index, 0);
}

void CarrierGeometry::rebuild(const BlockModel& model, int index)
{
  Entries.at(index) = Entry();
  buildEntry(model, index, 0);
}

void CarrierGeometry::buildEntry(const BlockModel& model, int index, int depth)
{
  const Carrier& carrier = model.carriers.at(index);
  const std::string entityText = syntax::entity("carrier", carrier.name);
  auto fail = [&](const std::string& what) {
    throw TemplateError(carrier.where.file, carrier.where.line, entityText, what);
  };
  Entry& entry = Entries[index];
  if (entry.built)
  {
    return;
  }
  if (depth > MaxDepth)
  {
    fail("the carriers refer to each other in a cycle");
  }
  const int count = static_cast<int>(model.carriers.size());
  auto checkRef = [&](int ref, bool surface, const char* role) {
    if (ref < 0 || ref >= count || ref == index)
    {
      fail(std::string("refers to a ") + role + " carrier that does not exist");
    }
    buildEntry(model, ref, depth + 1);
    if (Entries[ref].surface != nullptr) // a surface
    {
      if (!surface)
      {
        fail(std::string("'") + model.carriers[ref].name + "' is a surface, but a " + role +
          " curve is needed here");
      }
    }
    else if (surface)
    {
      fail(std::string("'") + model.carriers[ref].name + "' is a curve, but a " + role +
        " surface is needed here");
    }
  };
  auto refCount = [&](std::size_t low, std::size_t high) {
    if (carrier.refs.size() < low || carrier.refs.size() > high)
    {
      fail("refers to " + std::to_string(carrier.refs.size()) + " carriers, expected " +
        (low == high ? std::to_string(low) : std::to_string(low) + " or more"));
    }
  };
  for (const Vec3& point : carrier.points)
  {
    if (!point.allFinite())
    {
      fail("a point is not finite");
    }
  }

  Entry built;
  try
  {
    switch (carrier.kind)
    {
      case Carrier::Kind::Interpolate:
      {
        if (carrier.degree < 1 || carrier.degree > bspline::MaxDegree)
        {
          fail("the degree must be from 1 to " + std::to_string(bspline::MaxDegree));
        }
        const ParameterMethod method = parameterMethodOf(carrier.parameterMethod);
        // Explicit parameters (nodes) give sections a common parametrisation (align).
        built.curve = std::make_shared<BSplineCurve>(carrier.nodes.empty()
            ? BSplineCurve::interpolate(carrier.points, carrier.degree, method)
            : BSplineCurve::interpolateAt(carrier.points, carrier.nodes, carrier.degree));
        built.closedS = carrier.points.size() > 2 && carrier.points.front() == carrier.points.back();
        break;
      }
      case Carrier::Kind::Revolve:
      {
        refCount(1, 1);
        checkRef(carrier.refs[0], false, "contour");
        if (!carrier.axis.allFinite() || !(carrier.axis.norm() > 0.0) ||
          !carrier.axisPoint.allFinite() || !std::isfinite(carrier.angleStart) ||
          !std::isfinite(carrier.angleEnd) || !(carrier.angleEnd > carrier.angleStart))
        {
          fail("needs a non-zero axis and an angle range [a0, a1] with a0 < a1");
        }
        auto revolution = std::make_shared<SurfaceOfRevolution>(Entries[carrier.refs[0]].curve,
          carrier.axisPoint, carrier.axis.normalized(), carrier.angleStart, carrier.angleEnd);
        built.revolution = revolution;
        built.surface = revolution;
        built.closedT = carrier.angleEnd - carrier.angleStart >= 2.0 * Pi * (1.0 - 1e-12);
        break;
      }
      case Carrier::Kind::Gordon:
      case Carrier::Kind::Network:
      {
        refCount(2, 100000);
        std::vector<CurvePtr> sections, cross;
        for (int ref : carrier.refs)
        {
          checkRef(ref, false, "section");
          sections.push_back(Entries[ref].curve);
        }
        for (int ref : carrier.crossRefs)
        {
          checkRef(ref, false, "cross-section");
          cross.push_back(Entries[ref].curve);
        }
        if (carrier.nodes.size() != sections.size())
        {
          fail("needs one parameter per section");
        }
        const GordonSurface::Blending blending = carrier.blending == Carrier::Blending::Lagrange
          ? GordonSurface::Blending::Lagrange
          : GordonSurface::Blending::Spline;
        std::shared_ptr<const GordonSurface> gordon;
        if (carrier.kind == Carrier::Kind::Gordon)
        {
          gordon = std::make_shared<GordonSurface>(
            GordonSurface::fromSections(sections, carrier.nodes, blending));
        }
        else
        {
          if (cross.size() < 2 || carrier.crossNodes.size() != cross.size())
          {
            fail("a network needs at least 2 curves in each direction, each with its "
                 "parameter");
          }
          gordon = std::make_shared<GordonSurface>(GordonSurface::fromNetwork(
            sections, carrier.nodes, cross, carrier.crossNodes, blending));
        }
        built.gordon = gordon;
        built.surface = gordon;
        built.closedS = carrier.closed;
        built.extendT = true;
        break;
      }
      case Carrier::Kind::Coons:
      {
        refCount(4, 4);
        std::array<CurvePtr, 4> sides;
        for (int k = 0; k < 4; ++k)
        {
          checkRef(carrier.refs[k], false, "boundary");
          sides[k] = Entries[carrier.refs[k]].curve;
        }
        built.surface = std::make_shared<CoonsPatch>(sides[0], sides[1], sides[2], sides[3]);
        break;
      }
      case Carrier::Kind::SurfaceCurve:
      {
        refCount(1, 1);
        checkRef(carrier.refs[0], true, "base");
        if (carrier.parameterPoints.size() < 2)
        {
          fail("a curve on a surface needs at least 2 points");
        }
        const Entry& base = Entries[carrier.refs[0]];
        std::vector<Eigen::Vector2d> points = carrier.parameterPoints;
        if (!base.closedS && !base.closedT)
        {
          built.curve = std::make_shared<SurfaceCurve>(base.surface, points);
        }
        else if (points.size() == 2)
        {
          built.curve = std::make_shared<ParameterLineCurve>(
            base.surface, points[0], points[1], base.closedS, base.closedT, base.extendT);
        }
        else
        {
          for (const Eigen::Vector2d& st : points)
          {
            if (st[0] < 0.0 || st[0] > 1.0 || st[1] < 0.0 || st[1] > 1.0)
            {
              fail("a curve through more than 2 points of a closed surface must stay "
                   "inside [0, 1] x [0, 1]");
            }
          }
          built.curve = std::make_shared<SurfaceCurve>(base.surface, points);
        }
        break;
      }
      case Carrier::Kind::Intersect:
      {
        refCount(2, 2);
        checkRef(carrier.refs[0], true, "cut");
        checkRef(carrier.refs[1], true, "cutting");
        const Entry& cut = Entries[carrier.refs[0]];
        const Entry& by = Entries[carrier.refs[1]];
        if (!cut.gordon)
        {
          fail("the first surface of an intersection must be a Gordon surface (a blade)");
        }
        if (!by.revolution)
        {
          fail("the second surface of an intersection must be a surface of revolution "
               "(hub or shroud)");
        }
        built.curve = intersectWithRevolution(
          cut.gordon, *by.revolution, carrier.rangeMin, carrier.rangeMax, carrier.samples);
        break;
      }
      case Carrier::Kind::Offset:
      {
        refCount(2, 2);
        checkRef(carrier.refs[0], false, "offset");
        checkRef(carrier.refs[1], true, "base");
        const int base = carrier.refs[1];
        const Entry& curve = Entries[carrier.refs[0]];
        const double tolerance = 1e-6 * std::max(curve.size, Entries[base].size);
        auto toParameters = [&](const Vec3& p) {
          double s = 0.0, t = 0.0, distance = 0.0;
          project(base, p, s, t, distance);
          return Eigen::Vector2d(s, t);
        };
        // The curve must lie on the surface it is offset in (checked at a few points).
        for (int k = 0; k <= 8; ++k)
        {
          double s = 0.0, t = 0.0, distance = 0.0;
          project(base, curve.curve->point(k / 8.0), s, t, distance);
          if (distance > tolerance)
          {
            fail("curve '" + model.carriers[carrier.refs[0]].name + "' does not lie on '" +
              model.carriers[base].name + "' (a point is " + syntax::shortNumber(distance) +
              " away from it); offset a curve on its own surface");
          }
        }
        std::vector<Eigen::Vector2d> points = offsetOnSurface(
          *curve.curve, curve.closedS, *Entries[base].surface, toParameters, carrier.distance);
        // Across the seam of a full surface of revolution t jumps by 1: unwrap it, so the
        // curve is interpolated the short way round (the surface rotates on past t = 1).
        if (Entries[base].revolution && Entries[base].closedT)
        {
          for (std::size_t k = 1; k < points.size(); ++k)
          {
            points[k][1] -= std::round(points[k][1] - points[k - 1][1]);
          }
        }
        built.curve = std::make_shared<SurfaceCurve>(Entries[base].surface, points);
        built.closedS = curve.closedS;
        break;
      }
    }
  }
  catch (const GeometryError& error)
  {
    fail(error.what());
  }

  // Size of a sample, for tolerances; curves also learn here whether they are closed.
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 high = -low;
  if (built.surface)
  {
    for (int j = 0; j <= 16; ++j)
    {
      for (int i = 0; i <= 16; ++i)
      {
        const Vec3 p = built.surface->point(i / 16.0, j / 16.0);
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
      }
    }
  }
  else
  {
    for (int i = 0; i <= 64; ++i)
    {
      const Vec3 p = built.curve->point(i / 64.0);
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  const double size = (high - low).norm();
  if (!std::isfinite(size))
  {
    fail("the carrier has points that are not finite");
  }
  built.size = size > 0.0 ? size : 1.0;
  if (built.curve && !built.closedS)
  {
    built.closedS = (built.curve->point(0.0) - built.curve->point(1.0)).norm() <= 1e-12 * built.size;
  }
  built.built = true;
  entry = std::move(built);
}

Vec3 CarrierGeometry::point(int index, double s, double t) const
{
  const Entry& entry = Entries.at(index);
  const double ws = entry.closedS ? wrapUnit(s) : clampUnit(s);
  if (entry.surface)
  {
    const double wt = entry.closedT ? wrapUnit(t)
      : entry.extendT             ? std::max(-1.0, std::min(2.0, t))
                                  : clampUnit(t);
    return entry.surface->point(ws, wt);
  }
  return entry.curve->point(ws);
}

void CarrierGeometry::crossPoints(int index, double s, double t, double h, Vec3 out[5]) const
{
  const Entry& entry = Entries.at(index);
  if (!entry.surface)
  {
    out[0] = point(index, s, t);
    out[1] = point(index, s + h, t);
    out[2] = point(index, s - h, t);
    out[3] = point(index, s, t + h);
    out[4] = point(index, s, t - h);
    return;
  }
  // as point() wraps or limits each parameter
  auto inS = [&](double u) { return entry.closedS ? wrapUnit(u) : clampUnit(u); };
  auto inT = [&](double u) {
    return entry.closedT ? wrapUnit(u)
      : entry.extendT    ? std::max(-1.0, std::min(2.0, u))
                         : clampUnit(u);
  };
  entry.surface->crossPoints(inS(s), inS(s + h), inS(s - h), inT(t), inT(t + h), inT(t - h), out);
}

void CarrierGeometry::project(
  int index, const Vec3& p, double& s, double& t, double& distance) const
{
  const Entry& entry = Entries.at(index);
  if (entry.revolution)
  {
    // Exact: the closest point lies in p's meridional plane.
    const SurfaceOfRevolution& surface = *entry.revolution;
    s = surface.contourParameter(p);
    const Vec3 axis = surface.axisDirection();
    const Vec3 c = surface.contour()->point(s) - surface.axisPoint();
    const Vec3 q = p - surface.axisPoint();
    const Vec3 cp = c - c.dot(axis) * axis, qp = q - q.dot(axis) * axis;
    double angle = std::atan2(cp.cross(qp).dot(axis), cp.dot(qp));
    const double a0 = surface.angleStart(), a1 = surface.angleEnd();
    // whole turns into [a0, a1] in one step (a loop of 2 pi steps never ends for a
    // range far from 0)
    if (angle < a0 && std::isfinite(a0))
    {
      const double turns = std::floor((a1 + 1e-12 - angle) / (2.0 * Pi));
      angle += 2.0 * Pi * std::max(0.0, std::min(turns, std::ceil((a0 - angle) / (2.0 * Pi))));
    }
    if (angle > a1 && std::isfinite(a1))
    {
      const double turns = std::floor((angle - a0 + 1e-12) / (2.0 * Pi));
      angle -= 2.0 * Pi * std::max(0.0, std::min(turns, std::ceil((angle - a1) / (2.0 * Pi))));
    }
    t = clampUnit((angle - a0) / (a1 - a0));
    distance = (surface.point(s, t) - p).norm();
    return;
  }
  if (entry.surface)
  {
    std::shared_ptr<const SurfaceProjector> projector;
    {
      // made on first use (a sample of the surface), once, whichever thread asks first
      std::lock_guard<std::mutex> lock(*ProjectorMutex);
      if (!entry.surfaceProjector)
      {
        entry.surfaceProjector = std::make_shared<SurfaceProjector>(entry.surface, 64, 64);
      }
      projector = entry.surfaceProjector;
    }
    const SurfaceProjection found = projector->project(p);
    s = found.s;
    t = found.t;
    distance = found.distance;
    if (entry.extendT && (t <= 1e-9 || t >= 1.0 - 1e-9))
    {
      refineExtended(entry, p, s, t, distance);
    }
    return;
  }
  std::shared_ptr<const CurveProjector> projector;
  {
    std::lock_guard<std::mutex> lock(*ProjectorMutex);
    if (!entry.curveProjector)
    {
      entry.curveProjector = std::make_shared<CurveProjector>(entry.curve, 256);
    }
    projector = entry.curveProjector;
  }
  const CurveProjection found = projector->project(p);
  s = found.t;
  t = 0.0;
  distance = found.distance;
}

void CarrierGeometry::refineExtended(
  const Entry& entry, const Vec3& p, double& s, double& t, double& distance) const
{
  // Newton on |S(s, t) - p|^2 with t free in [-1, 2]: the projector stops at t = 0 or 1,
  // the continued surface goes on.
  auto evaluate = [&](double ss, double tt) {
    return entry.surface->point(entry.closedS ? wrapUnit(ss) : clampUnit(ss), tt);
  };
  double best = (evaluate(s, t) - p).squaredNorm();
  for (int iteration = 0; iteration < 100; ++iteration)
  {
    SurfaceDerivatives d;
    entry.surface->derivatives(entry.closedS ? wrapUnit(s) : clampUnit(s), t, d);
    const Vec3 r = d.P - p;
    const Eigen::Vector2d g(d.Ps.dot(r), d.Pt.dot(r));
    Eigen::Matrix2d h;
    h << d.Ps.dot(d.Ps) + d.Pss.dot(r), d.Ps.dot(d.Pt) + d.Pst.dot(r),
      d.Ps.dot(d.Pt) + d.Pst.dot(r), d.Pt.dot(d.Pt) + d.Ptt.dot(r);
    Eigen::Vector2d step;
    if (std::abs(h.determinant()) > 1e-300 && h(0, 0) > 0.0 && h.determinant() > 0.0)
    {
      step = -h.inverse() * g;
    }
    else
    {
      const Eigen::Vector2d diagonal(d.Ps.squaredNorm(), d.Pt.squaredNorm());
      step = Eigen::Vector2d(-g[0] / std::max(diagonal[0], 1e-300), -g[1] / std::max(diagonal[1], 1e-300));
    }
    bool improved = false;
    for (double damping = 1.0; damping > 1e-6; damping *= 0.5)
    {
      double ns = s + damping * step[0];
      double nt = std::max(-1.0, std::min(2.0, t + damping * step[1]));
      if (!entry.closedS)
      {
        ns = clampUnit(ns);
      }
      const double value = (evaluate(ns, nt) - p).squaredNorm();
      if (value < best)
      {
        const bool converged = std::abs(ns - s) < 1e-15 && std::abs(nt - t) < 1e-15;
        s = ns;
        t = nt;
        best = value;
        improved = !converged;
        break;
      }
    }
    if (!improved)
    {
      break;
    }
  }
  if (entry.closedS)
  {
    s = wrapUnit(s);
  }
  distance = std::sqrt(best);
}

void CarrierGeometry::vertexParameters(const BlockModel& model, int vertex, int carrier,
  double& s, double& t, double& distance) const
{
  const Vertex& v = model.vertices.at(vertex);
  const int own = v.constraint.carrier;
  if (own == carrier)
  {
    s = v.constraint.s;
    t = v.constraint.t;
    distance = (point(carrier, s, t) - v.position).norm();
    return;
  }
  if (own >= 0 && own < static_cast<int>(Entries.size()) && isSurface(carrier) &&
    !isSurface(own))
  {
    const Carrier& curve = model.carriers[own];
    if ((curve.kind == Carrier::Kind::SurfaceCurve || curve.kind == Carrier::Kind::Intersect) &&
      !curve.refs.empty() && curve.refs[0] == carrier)
    {
      const double u = closedS(own) ? wrapUnit(v.constraint.s) : clampUnit(v.constraint.s);
      Eigen::Vector2d st(0.0, 0.0);
      bool found = false;
      if (const auto* onSurface = dynamic_cast<const SurfaceCurve*>(Entries[own].curve.get()))
      {
        st = onSurface->parameters(u);
        found = true;
      }
      else if (const auto* line = dynamic_cast<const ParameterLineCurve*>(Entries[own].curve.get()))
      {
        st = line->parameters(u);
        found = true;
      }
      if (found)
      {
        s = st[0];
        t = st[1];
        distance = (point(carrier, s, t) - v.position).norm();
        return;
      }
    }
  }
  project(carrier, v.position, s, t, distance);
}
} // namespace model
} // namespace blockforge
