/**
 * @file CarrierGeometry.h
 * @brief The curves and surfaces of a model's carriers (format 2), built from their
 * definitions in the model. The template engine, the model check and the mesher all build
 * them here, from the same numbers, so they get the same geometry bit for bit.
 *
 * Also the small curve types edges need: a piece of a curve between two parameters and a
 * straight line in the (s, t) space of a surface. Parameters outside [0, 1] wrap around
 * carriers that are closed in that direction (a blade surface around its sections, a full
 * surface of revolution around the axis).
 */
#pragma once

#include "../Core/ArcLength.h"
#include "BlockModel.h"

#include "../Core/Carriers.h"
#include "../Core/Projection.h"

#include <memory>
#include <mutex>

namespace blockforge
{
namespace model
{
/// x for x in [0, 1], else x - floor(x): the parameter on a closed carrier.
double wrapUnit(double x);

/// Carrier::parameterMethod (0 uniform, 1 chord length, 2 centripetal) as the core's enum.
ParameterMethod parameterMethodOf(int method);

/// The piece u0 -> u1 of a curve, reparametrised on [0, 1] (u0 > u1 runs backwards).
/// With `closed`, parameters outside [0, 1] wrap.
class SubCurve : public Curve
{
public:
  SubCurve(CurvePtr curve, double u0, double u1, bool closed);
  Vec3 point(double t) const override;
  Vec3 derivative(double t, int order = 1) const override;
  /// The base's breakpoints and its ends (the seam of a closed curve, the clamps of an
  /// open one) inside the piece, on the piece's parameter.
  std::vector<double> breakpoints() const override;

private:
  CurvePtr Base;
  double U0, U1;
  bool Closed;
  double map(double t) const;
};

/// The straight line from (s0, t0) to (s1, t1) in the parameter space of a surface,
/// mapped onto it; every point lies on the surface.
class ParameterLineCurve : public Curve
{
public:
  ParameterLineCurve(SurfacePtr surface, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
    bool closedS, bool closedT, bool extendT = false);
  Vec3 point(double u) const override;
  Vec3 derivative(double u, int order = 1) const override;
  Eigen::Vector2d parameters(double u) const;
  /// Where the line crosses the surface's breakpoints (and, wrapping, its seams).
  std::vector<double> breakpoints() const override;

private:
  SurfacePtr TheSurface;
  Eigen::Vector2d From, To;
  bool ClosedS, ClosedT, ExtendT;
};

/**
 * @class CarrierGeometry
 * @brief Built carriers of one model, by carrier index.
 */
class CarrierGeometry
{
public:
  CarrierGeometry() = default;
  /// Builds every carrier; throws TemplateError naming the carrier on a geometry error.
  explicit CarrierGeometry(const BlockModel& model);
  /// Builds carrier `index` and, first, the carriers it refers to (template engine).
  void build(const BlockModel& model, int index);
  /// Builds carrier `index` again from its (changed) definition in `model`, e.g. a surface
  /// curve drawn through control points that moved. Carriers built on it are not rebuilt.
  void rebuild(const BlockModel& model, int index);

  bool isSurface(int index) const { return Entries.at(index).surface != nullptr; }
  const CurvePtr& curve(int index) const { return Entries.at(index).curve; }
  const SurfacePtr& surface(int index) const { return Entries.at(index).surface; }
  /// The surface of revolution, or nullptr for other carriers.
  const SurfaceOfRevolution* revolution(int index) const
  {
    return Entries.at(index).revolution.get();
  }
  /// Closed in s (curves: closed loop; Gordon: closed sections) / in t (full revolution).
  bool closedS(int index) const { return Entries.at(index).closedS; }
  bool closedT(int index) const { return Entries.at(index).closedT; }
  /// Gordon surfaces continue past their first and last sections: t may lie in
  /// [-1, 2] (a blade extended to the hub and shroud it stops short of).
  bool extendsT(int index) const { return Entries.at(index).extendT; }
  /// The range of t: [0, 1], or [-1, 2] for extending surfaces.
  double tMin(int index) const { return extendsT(index) ? -1.0 : 0.0; }
  double tMax(int index) const { return extendsT(index) ? 2.0 : 1.0; }

  /// Curve point at u or surface point at (s, t); wraps on closed carriers.
  Vec3 point(int index, double s, double t = 0.0) const;
  /// point() at (s, t), (s + h, t), (s - h, t), (s, t + h) and (s, t - h), the same bits,
  /// with the curves of Gordon surfaces evaluated once per parameter (central differences).
  void crossPoints(int index, double s, double t, double h, Vec3 out[5]) const;
  /// Parameters of the closest point of carrier `index` to p (t = 0 for curves).
  void project(int index, const Vec3& p, double& s, double& t, double& distance) const;
  /**
   * Parameters of vertex `vertex` on carrier `carrier`: its own (s, t) when it is attached
   * to that carrier; the surface parameters of its curve point when it is attached to a
   * curve lying on that surface (a surface curve, an intersection); else the parameters of
   * its closest point. `distance` is how far the vertex is from carrier(s, t).
   */
  void vertexParameters(const BlockModel& model, int vertex, int carrier, double& s, double& t,
    double& distance) const;
  /// Diagonal of the bounding box of a sample of the carrier.
  double size(int index) const { return Entries.at(index).size; }
  /**
   * The arc-length table of curve carrier `index` (ArcLength.h), made on first use, kept
   * with the carrier (and shared by copies of this geometry) until the carrier is built
   * again: an edge on the carrier measures its length and places its nodes from it.
   */
  std::shared_ptr<const ArcLength> lengthTable(int index) const;
  /**
   * Makes the length tables of the curve carriers `indices` that are not made yet, as
   * independent chunks of work (on threads when a runner is installed, Parallel.h): each
   * table depends on its carrier only, so the tables are the same for any thread count.
   * A table that fails is left unmade, so its error comes from lengthTable() where it is
   * used, naming that entity.
   */
  void prepareLengthTables(const std::vector<int>& indices) const;

private:
  struct Entry
  {
    bool built = false;
    CurvePtr curve;
    SurfacePtr surface;
    std::shared_ptr<const SurfaceOfRevolution> revolution;
    std::shared_ptr<const GordonSurface> gordon;
    bool closedS = false, closedT = false, extendT = false;
    double size = 1.0;
    mutable std::shared_ptr<CurveProjector> curveProjector;
    mutable std::shared_ptr<SurfaceProjector> surfaceProjector;
    struct LengthSlot
    {
      std::mutex lock;
      std::shared_ptr<const ArcLength> table;
    };
    std::shared_ptr<LengthSlot> length = std::make_shared<LengthSlot>();
  };
  void buildEntry(const BlockModel& model, int index, int depth);
  void refineExtended(const Entry& entry, const Vec3& p, double& s, double& t, double& distance) const;
  std::vector<Entry> Entries;
  /// Guards the projectors made on first use (copies share it, and the projectors).
  std::shared_ptr<std::mutex> ProjectorMutex = std::make_shared<std::mutex>();
};
} // namespace model
} // namespace blockforge
