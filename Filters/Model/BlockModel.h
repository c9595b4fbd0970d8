/**
 * @file BlockModel.h
 * @brief The geometric database of the paper (section 2.1) as BlockForge keeps it:
 * named vertices, edges, blocks (subvolumes) and patches, all resolved to numbers.
 *
 * No VTK types: the model is built by the template engine (Template.h), travels between
 * pipeline stages as a versioned text document (ModelDocument.h) and is meshed by
 * MultiBlockMesher (Mesher.h).
 */
#pragma once

#include "../Core/Distribution.h"
#include "../Core/Transfinite.h"
#include "../Core/Types.h"

#include <Eigen/Core>

#include <array>
#include <map>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
/// Where an entity was defined, for error messages ("file:line").
struct SourceLocation
{
  std::string file;
  int line = 0; ///< 1-based, 0 when unknown
};

/**
 * The machine (format 2): axis of rotation and blade count, from the filter input (the
 * reader's Axis and BladeCount) or the template's `machine:` section. Periodic vertices,
 * edges and patches rotate about this axis by whole pitches.
 */
struct Machine
{
  bool defined = false;
  Vec3 axisPoint = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ(); ///< unit vector
  int bladeCount = 0;        ///< 0: unknown (pitch undefined)
  /// 2 pi / bladeCount, 0 when unknown.
  double pitch() const;
};

/**
 * A carrier (paper Fig. 3, Ec/Sc): a curve or surface built from point data or from other
 * carriers. Carriers are stored with their complete definition (input points with 17
 * digits in the model document), so every stage rebuilds the same geometry bit for bit.
 */
struct Carrier;

/// The names of the carrier kinds in templates and model documents, in Carrier::Kind order.
const std::vector<std::string>& carrierKindNames();

struct Carrier
{
  enum class Kind
  {
    Interpolate,  ///< curve: B-spline through `points` (degree, parameter method, or
                  ///< explicit parameters `nodes` when not empty)
    Revolve,      ///< surface: refs[0] (a curve) swept about axis, t -> angleStart..angleEnd
    Gordon,       ///< surface: lofted through section curves refs at t = nodes (eqs. 4-5)
    Network,      ///< surface: Gordon through s-curves refs at t = nodes and t-curves
                  ///< crossRefs at s = crossNodes
    Coons,        ///< surface: Coons patch (eq. 3) from refs = bottom, right, top, left
    SurfaceCurve, ///< curve: through parameterPoints in the (s, t) space of surface refs[0]
    Intersect,    ///< curve: surface refs[0] (Gordon) cut by revolution surface refs[1]
    Offset        ///< curve: curve refs[0] offset within surface refs[1] by `distance`
  };
  enum class Blending
  {
    Spline,
    Lagrange
  };
  std::string name;
  Kind kind = Kind::Interpolate;
  std::vector<Vec3> points;
  int degree = 3;
  /// 0 uniform, 1 chord length, 2 centripetal (ParameterMethod order).
  int parameterMethod = 1;
  std::vector<int> refs;
  std::vector<int> crossRefs;
  std::vector<double> nodes;
  std::vector<double> crossNodes;
  Blending blending = Blending::Spline;
  /// Gordon/Network: every section is a closed loop (s = 0 and s = 1 coincide); checked.
  bool closed = false;
  Vec3 axisPoint = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double angleStart = 0.0, angleEnd = 0.0;
  std::vector<Eigen::Vector2d> parameterPoints;
  /// SurfaceCurve: the vertex each parameter point is taken from (-1: a given [s, t]); the
  /// curve is drawn again through them when they move (Placement.h).
  std::vector<int> throughVertices;
  double rangeMin = -0.5, rangeMax = 1.5; ///< Intersect: t range searched on refs[0]
  int samples = 64;                       ///< Intersect: s samples
  /// Offset: distance within the surface, in model units (> 0: outwards for closed curves).
  double distance = 0.0;
  SourceLocation where;

  bool isSurface() const
  {
    return kind == Kind::Revolve || kind == Kind::Gordon || kind == Kind::Network ||
      kind == Kind::Coons;
  }
};

/**
 * How a vertex is attached (paper Fig. 5). A vertex with a carrier is a control point:
 * the optimizer may move it along the carrier by changing (s, t); its position is always
 * carrier(s, t). A periodic vertex is the rotation of another vertex by `pitches` machine
 * pitches; if it also has a carrier, these are the image's parameters (the source's with
 * the periodic offset).
 */
struct VertexConstraint
{
  int carrier = -1; ///< -1: not attached
  double s = 0.0, t = 0.0;
  int periodicSource = -1; ///< -1: not periodic
  int pitches = 0;
};

/**
 * How a vertex's position follows from its parameters and from other vertices: its
 * placement rule (Placement.h applies the rules in dependency order, for the template,
 * the optimizer and manual moves alike).
 */
/**
 * Template expressions that placed an OnCarrier vertex and refer to other vertices
 * (`on_surface` with `axial`/`theta`, `on_curve` with `at` an expression), so the vertex
 * follows them (format 4). The vertex's own parameters stay free: a move shifts them from
 * what the expressions give, and the shift is kept when the followed vertices move.
 */
struct PlacementExpressions
{
  enum class Form
  {
    None,
    AxialTheta,    ///< texts: axial, theta on the surface of revolution (machine axis)
    CurveParameter ///< texts: the parameter u on the curve
  };
  Form form = Form::None;
  std::vector<std::string> texts;
  std::vector<int> follows; ///< vertices referred to, directly or through definitions
  /// (s, t) the expressions gave when the template placed the vertex, and the shift of
  /// the vertex's parameters from what they give (0 0 until the vertex itself is moved).
  std::array<double, 2> base{ { 0.0, 0.0 } }, shift{ { 0.0, 0.0 } };
};

/**
 * What placement expressions are evaluated in (format 4): the template's named values
 * other than vertex queries (parameters, machine values, carrier queries such as
 * `hub.axial_min`), its definitions (expressions, evaluated when used) and the direction
 * of theta = 0 about the machine axis.
 */
struct ExpressionScope
{
  std::vector<std::pair<std::string, double>> values;
  std::vector<std::pair<std::string, std::string>> definitions;
  Vec3 thetaZero = Vec3::UnitX();
};

struct VertexRule
{
  enum class Kind
  {
    Fixed,        ///< the position itself (a point, cylindrical coordinates or expressions)
    OnCarrier,    ///< carrier(s, t) of the constraint: a control point, (s, t) free
    Intersection, ///< curve(s) where a curve meets a surface: on its carrier, s not free
    Projected,    ///< the position of vertex `source` projected onto the constraint's carrier
    Periodic,     ///< the constraint's periodic source rotated by whole machine pitches
    Rotated       ///< vertex `source` rotated by `angle` about `axis` through `origin`
  };
  Kind kind = Kind::Fixed;
  int source = -1; ///< Projected, Rotated: the vertex followed
  Vec3 origin = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ(); ///< unit vector
  double angle = 0.0;        ///< radians, right-hand rule
  PlacementExpressions expressions; ///< OnCarrier: what places it, when it follows vertices
};

/// The rule a vertex's constraint implies on its own (documents older than format 3
/// carry no rules): OnCarrier with a carrier, Periodic with a periodic source, else Fixed.
VertexRule impliedRule(const VertexConstraint& constraint);

/// The names of the rule kinds in model documents, in VertexRule::Kind order.
const std::vector<std::string>& vertexRuleNames();

struct Vertex
{
  std::string name;
  Vec3 position = Vec3::Zero();
  VertexConstraint constraint;
  VertexRule rule;
  /// The template marks this vertex fixed (`fixed: true`): the block optimizer leaves its
  /// free parameters (or, for a free interior vertex, its position) alone.
  bool fixed = false;
  SourceLocation where;
};

/// Geometry of the edge between two vertices; edges not named in a template are straight.
struct Edge
{
  enum class Kind
  {
    Line,
    Arc,   ///< circular arc, from `centre` or through `through`
    Spline,    ///< cubic B-spline interpolating from, points..., to
    OnCurve,   ///< the piece of curve carrier `carrier` between the ends' parameters
    OnSurface, ///< straight in the (s, t) space of surface carrier `carrier`
    Project,   ///< straight line from -> to with its nodes projected onto `carrier`
    Periodic,  ///< the nodes of edge `source` rotated by `pitches` machine pitches
    Follow     ///< edge `source` moved by the blend (1 - f) (from - source.from) +
               ///< f (to - source.to) at each fraction f: parallel to it, e.g. the
               ///< O-grid's outer spanwise edges following the blade's
  };
  std::string name;
  Kind kind = Kind::Line;
  int from = -1, to = -1; ///< vertex indices
  bool arcHasCentre = false;
  Vec3 arcCentre = Vec3::Zero();
  Vec3 arcThrough = Vec3::Zero();
  std::vector<Vec3> splinePoints; ///< interior points, from `from` towards `to`
  int carrier = -1; ///< OnCurve, OnSurface, Project
  /// OnCurve: [u_from, u_to]; OnSurface: [s_from, t_from, s_to, t_to]; empty: taken from
  /// the end vertices (their constraint on this carrier, else their projection). Values
  /// outside [0, 1] wrap around a closed carrier.
  std::vector<double> at;
  /// `at` given by expressions that refer to vertices (format 4): one text per value of
  /// `at`, and the vertices they refer to (directly or through definitions); the values
  /// are evaluated again when those vertices move (Placement.h).
  std::vector<std::string> atExpressions;
  std::vector<int> atFollows;
  int source = -1; ///< Periodic: the edge this one is the image of; Follow: the one it follows
  int pitches = 0; ///< Periodic
  SourceLocation where;
};

/// The names of the edge kinds in templates and model documents, in Edge::Kind order.
const std::vector<std::string>& edgeKindNames();
/// The edge kind named `name` (edgeKindNames()); false when there is none.
bool edgeKindFromName(const std::string& name, Edge::Kind& kind);
/// The kinds a format-2 template gives as an edge's key (on_curve .. follow).
const std::vector<std::string>& carrierEdgeKindNames();

/// A hexahedral subvolume, possibly degenerate (repeated vertices: wedges, prisms).
struct Block
{
  std::string name;
  /// Vertex indices in the paper's Fig. 7 order = VTK hexahedron order (Transfinite.h).
  std::array<int, 8> vertices{};
  /// Cells along i (s), j (t), k (u) before the density multiplier.
  std::array<int, 3> cells{ 1, 1, 1 };
  /// The fewest cells a density multiplier below 1 leaves along i, j, k (template key
  /// `min_cells`; never more than `cells`): graded laws need a few cells to grow from
  /// small matched end cells to the cells beside them (1: the plain rule).
  std::array<int, 3> minCells{ 1, 1, 1 };
  /// Distribution law of each local edge (Transfinite.h numbering), in the local edge
  /// direction (increasing i, j or k).
  std::array<DistributionLaw, 12> laws{};
  /// How the interior blends the boundary in i, j and k (`interpolation: end_cells` or
  /// `{j: end_cells}`, Transfinite.h): also the faces this block owns (the first block
  /// using a face makes its grid).
  std::array<Blending, 3> blending{ Blending::Linear, Blending::Linear, Blending::Linear };
  SourceLocation where;
};

/// A block face: face index 0..5 = i0, i1, j0, j1, k0, k1 (Transfinite.h numbering).
struct BlockFace
{
  int block = -1;
  int face = -1;
  bool operator==(const BlockFace& o) const { return block == o.block && face == o.face; }
};

/// A named boundary patch; periodic patches name their partner and the rotation that
/// maps this patch onto it.
struct Patch
{
  std::string name;
  std::string type = "patch"; ///< wall, patch, symmetry, periodic, ...
  std::vector<BlockFace> faces;
  std::string periodicPartner; ///< empty unless type == "periodic"
  Vec3 periodicAxisPoint = Vec3::Zero();
  Vec3 periodicAxis = Vec3::UnitZ();
  double periodicAngle = 0.0; ///< radians, right-hand rule about periodicAxis
  int pitches = 0; ///< format 2: the angle is `pitches` machine pitches (0: given as angle)
  SourceLocation where;
};

/// Block faces whose grids lie on a surface carrier (format 2 `faces:` section), or
/// (followOpposite, carrier -1) whose grids follow the opposite face of their block: the
/// Coons patch of the face's own edges plus the opposite face's departure from the Coons
/// patch of its edges, so that an O-grid's outer face keeps the blade face's bulge between
/// hub and shroud (`{follow: opposite, faces: [...]}`).
struct SurfaceFaces
{
  std::string name;
  int carrier = -1;
  bool followOpposite = false;
  std::vector<BlockFace> faces;
  SourceLocation where;
};

struct BlockModel
{
  /// Newest model document format (3: vertices carry their placement rules; 4: and the
  /// expressions that make them follow other vertices, with their scope, and the vertices
  /// curves are drawn through); documents of models without format-2 entities are still
  /// written as format 1, and documents of formats 1 to 3 still read (their rules follow
  /// from the constraints, nothing follows through expressions).
  static constexpr int FormatVersion = 4;
  std::string name;
  std::string sourceFile;
  /// Parameter values after overrides, in definition order.
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<Vertex> vertices;
  std::vector<Edge> edges;
  std::vector<Block> blocks;
  std::vector<Patch> patches;
  Machine machine;
  std::vector<Carrier> carriers;
  std::vector<SurfaceFaces> surfaceFaces;
  /// What the placement expressions of vertices are evaluated in (empty without any).
  ExpressionScope expressionScope;
  /// What applying the template chose for the user to know (its `notes:` whose `when`
  /// held, e.g. "the inlet is at the start of the hub contour"). Not part of the document.
  std::vector<std::string> notes;

  int findVertex(const std::string& name) const; ///< -1 if absent
  int findBlock(const std::string& name) const;  ///< -1 if absent
  int findCarrier(const std::string& name) const; ///< -1 if absent
  /// 4 when vertices follow others through expressions or curves are drawn through
  /// vertices, 3 with other rules than the constraints imply, 2 when the model uses
  /// carriers, constraints, surface faces or a machine, else 1.
  int requiredFormat() const;
  /// Index into `edges` of the edge joining a and b in either direction, -1 if straight.
  int findEdge(int a, int b) const;
  /// Index into `edges` of the edge called `name`, -1 if absent.
  int findNamedEdge(const std::string& name) const;
};

/// Face index names used in templates and messages: "i0", "i1", "j0", "j1", "k0", "k1".
const char* faceName(int face);
/// Local vertex indices (0..7) of face f, in the order that walks its (a, b) grid:
/// corner (0,0), (1,0), (1,1), (0,1) where a, b are the face's index directions.
std::array<int, 4> faceCorners(int face);
/// Local vertex indices (from, to) of edge e (0..11).
std::array<int, 2> edgeVertices(int edge);
/// Direction (0 = i, 1 = j, 2 = k) of edge e.
int edgeDirection(int edge);
/// Face index (0..5) of "i0" .. "k1", -1 for anything else.
int faceFromName(const std::string& name);
/// Local edges (0..11) bounding face f, as the face grid sees them: bottom (b = 0),
/// top (b = max), left (a = 0), right (a = max); each runs in increasing a or b.
std::array<int, 4> faceEdges(int face);
/// The two index directions (0 = i, 1 = j, 2 = k) of face f: a (fastest) and b.
std::array<int, 2> faceDirections(int face);
} // namespace model
} // namespace blockforge
