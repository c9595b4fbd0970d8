/**
 * @file MeshInternals.h
 * @brief Private to the mesher, the mesh plan and the model check (not installed): the
 * geometry of named edges, the model's topology with the node data the mesher adds, and
 * the steps that turn them into edge, face and block grids.
 */
#pragma once

#include "BlockModel.h"
#include "CarrierGeometry.h"
#include "Errors.h"
#include "ModelSyntax.h"
#include "Topology.h"

#include "../Core/Curve.h"
#include "../Core/Transfinite.h"

#include <array>
#include <cstdint>
#include <unordered_map>
#include <map>
#include <mutex>
#include <memory>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
constexpr double Pi = 3.14159265358979323846;

[[noreturn]] inline void fail(
  const SourceLocation& where, const std::string& entityText, const std::string& what)
{
  throw TemplateError(where.file, where.line, entityText, what);
}

inline std::string blockEntity(const BlockModel& model, int block)
{
  return syntax::entity("block", model.blocks[block].name);
}

// -------------------------------------------------------------------- edge geometry
/// A curve's first derivatives at parameters (by their bits), as derivative(t, 1) gave them.
using DerivativeSamples = std::unordered_map<std::uint64_t, Vec3>;

/// The curve of a named edge in its own direction (from -> to), with what it takes to
/// place nodes at arc-length fractions.
struct NamedCurve
{
  CurvePtr curve;
  /// The first derivatives its length table took, kept when a follow edge follows it: the
  /// follow edge's table takes its speeds at the same parameters, mostly (FollowCurve).
  std::shared_ptr<const DerivativeSamples> samples;
  /// Curves on carriers, splines and follow edges (arcs and lines are arc-length already).
  std::shared_ptr<const ArcLength> lengthTable;
  double length = 0.0;
  int projectOnto = -1; ///< Project: the nodes of the straight line are projected onto it
  /// The projector onto `curve`, made when an edge first takes nodes projected onto it
  /// (project_from) and kept while the curve is: the same projector, the same bits, and
  /// a move that leaves the curve does not sample it again. Serial use (edge grading).
  mutable std::shared_ptr<const CurveProjector> projector;
};

/// Tolerance of "lies on a carrier": 1e-9 of the larger of the model and the carrier.
double carrierTolerance(const CarrierGeometry& geometry, int carrier, double size);

/// Per named edge: whether a follow edge follows it (its length table's derivatives are
/// then kept, NamedCurve::samples).
std::vector<char> followedEdges(const BlockModel& model);
/// The curve of named edge `index` (`previous`: the curves of the edges before it, which a
/// periodic or follow edge takes its shape from; `followed`: followedEdges()[index]).
/// Throws GeometryError.
NamedCurve buildNamedCurve(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& previous, int index, bool followed, double size);
/// Curves of all named edges; GeometryError becomes a TemplateError naming the edge.
std::vector<NamedCurve> buildNamedCurves(const BlockModel& model, const CarrierGeometry& geometry);

/**
 * Keeps the explicit end parameters (`at`) of an on_curve or on_surface edge on its end
 * vertices after they moved: each moved end takes its vertex's parameters on the edge's
 * carrier; on closed carriers the change is taken the short way round, so an edge that
 * ran across the seam (ends outside [0, 1]) still does. Ends given by expressions of
 * vertices are left to the placement (applyPlacement evaluates them again).
 */
void followEdgeEnds(
  BlockModel& model, const CarrierGeometry& geometry, int edge, const std::vector<char>& movedVertex);

/// Node parameters of `law` for `nodeCount` nodes on an edge of `length` (with the
/// fallbacks of previews and density multipliers when `allowFallback`).
std::vector<double> lawParameters(
  const DistributionLaw& law, int nodeCount, double length, bool allowFallback);
std::vector<double> reversedParameters(const std::vector<double>& params);
/**
 * `law` as it applies to `cells` cells when the template gives `templateCells`: a density
 * multiplier or a preview cap refines or coarsens the grid without changing its shape, so
 * graded laws keep their overall expansion (geometric: last over first cell; two-sided:
 * middle over end cell; first cell: its share of the edge). Without this a geometric
 * ratio of 1.15 over 4 times the cells would make the first cell 1.15^18 times thinner
 * (besides 4 times), and thin cells at a curved wall fold.
 */
DistributionLaw refinedLaw(const DistributionLaw& law, int templateCells, int cells);

// -------------------------------------------------------------------- mesh topology
/// A shared edge with its nodes: parameters in the canonical direction (from the first
/// block that uses it) and coordinates.
struct UniqueEdge : TopologyEdge
{
  double length = 0.0;
  /// Law `match` in its blocks: the end cells come from the edges continuing it across
  /// block interfaces (matchEdgeEnds), lengths in the canonical direction (0: free).
  bool matched = false;
  double matchRatio = DefaultMatchRatio;
  double matchFlatness = 0.0; ///< DistributionLaw::matchFlatness of its blocks' law
  double matchAtMost = 0.0;   ///< DistributionLaw::matchAtMost of its blocks' law (0: none)
  double matchFirst = 0.0, matchLast = 0.0;
  /// Law `project_from` in its blocks: the unique edge whose nodes are projected onto this
  /// one (-1: none), and whether that edge's nodes come after the matched edges' (a chain
  /// of projections from a matched edge).
  int projectedFrom = -1;
  bool projectedAfterMatch = false;
  /// Match with a lean limit (DistributionLaw::leanLimit, 0: none): the shortest end
  /// cells at a and b that lean no more than that from the edge's chord (0: any).
  double matchLean = 0.0;
  std::array<double, 2> matchFloor{ { 0.0, 0.0 } };
  std::vector<double> params;
  /// A projected edge's params as projected, before its feet joined (ProjectedEdges.cpp).
  std::vector<double> projectedParams;
  std::vector<double> xyz;
};

/// A shared face with its grid, stored in the orientation of its owner.
struct UniqueFace : TopologyFace
{
  std::vector<double> xyz;
  /// A face of a `follow: opposite` set: the block face that names it and the unique face
  /// opposite it in that block (made first); opposite -1 for every other face.
  BlockFace follows;
  int opposite = -1;
};

struct MeshLinks : BlockLinks
{
  std::array<std::vector<double>, 12> collapsedParams; ///< for collapsed edges only
};

/// The model's public topology with what the mesher adds to its edges, faces and blocks.
struct MeshTopology
{
  Topology connectivity;
  std::vector<UniqueEdge> edges;
  std::vector<UniqueFace> faces;
  std::vector<MeshLinks> blocks;
  /// Edge ends (2 edge + 0 at vertex a, + 1 at b) that continue one another across a
  /// block interface or a periodic pair, grouped; only when the model has matched edges.
  std::vector<std::vector<int>> matchGroups;
  /// The class (smallest key) of every edge end in those groups before projected edges
  /// join them (joinProjectedMatchEnds); empty when the model has no matched edges.
  std::vector<int> matchClasses;
  /// (image, source) edge ends of periodic faces: the image end takes the source's cell.
  std::vector<std::pair<int, int>> matchCopies;
  /// Projected unique edges, each after the edge it projects from.
  std::vector<int> projectionOrder;
};

MeshTopology buildMeshTopology(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& curves, const std::vector<std::array<int, 3>>& nodes,
  bool allowFallback);
/// Node parameters of unique edge `e` from the laws of the blocks that use it (checked to
/// agree), with its current length.
void computeEdgeParameters(const BlockModel& model, MeshTopology& topology, int e, bool allowFallback);
/**
 * Groups the ends of edges that continue one another through a vertex across a block
 * interface (the edges normal to the shared face at its corners, in the two blocks) or a
 * periodic pair (the same at corresponding corners of the two faces), and marks the
 * edges whose law is `match` (all their blocks must say so). Needs the periodic pairs of
 * topology.connectivity (found here when the model has matched edges; a model whose
 * periodic patches do not pair is left to the patch check).
 */
void buildMatchGroups(const BlockModel& model, MeshTopology& topology);
/**
 * The end cell lengths of every matched edge from its group at that end: the geometric
 * mean of the end cells of the graded (not matched) edges there, else the smallest mean
 * cell (length / cells) of the matched edges there; free (0) when the end continues into
 * no other edge. The parameters of the graded edges must be current. Returns the matched
 * edges whose end lengths changed.
 */
std::vector<int> matchEdgeEnds(const BlockModel& model, MeshTopology& topology);
/**
 * Marks the edges whose law is `project_from` (all their blocks must say so, naming the
 * same edge) with the unique edge they project from, and orders them sources first: a
 * cycle, a source used by no block or a periodic source is a TemplateError naming the
 * edges. After buildMatchGroups (a chain from a matched edge comes after the matched
 * edges).
 */
void buildProjections(const BlockModel& model, MeshTopology& topology);
/**
 * After buildProjections: an edge projected (through a chain) from a matched edge has its
 * end cells from that edge's, so where its end continues into other edges (an O-grid's
 * outer side meeting the H blocks at an O corner) the group there and the group at the
 * matched edge's end (the blade side at the corner's foot) are one: both take one cell,
 * from the graded edges of either. Ends of the projected edge that continue into nothing
 * join nothing.
 */
void joinProjectedMatchEnds(const BlockModel& model, MeshTopology& topology);
/// Length of the cell at one end of an edge (end 0: at its vertex a) from its node
/// parameters.
inline double endCell(const UniqueEdge& edge, int end)
{
  const std::vector<double>& p = edge.params;
  const std::size_t n = p.size();
  return edge.length * (end == 0 ? p[1] - p[0] : p[n - 1] - p[n - 2]);
}
/// Whether `edge` runs against `source` (its a end nearer the source's b end): their nearer
/// ends decide, so a projected edge takes its source's nodes in the right order.
bool runsAgainst(const BlockModel& model, const UniqueEdge& edge, const UniqueEdge& source);
/// Beside a fan (ProjectedEdges.cpp, gradeBesideFan) the side's wall cells, and round a
/// corner the spread feet (FootBunches.cpp), grow by at most this from cell to cell:
/// checkMesh's interpolation weight (0.05) fails between cells whose centres lie more than
/// 19 times as far from their face.
constexpr double FanSideGrowth = 10.0;
/**
 * Feet bunched on a convex corner inside a projected edge (`params`, its node parameters, 0
 * to 1; `feet` and `outer`, the projected feet and the source's nodes, the edge's ends
 * included). Round a cap's corner (any blunt or capped edge) the outer nodes on the O
 * curve's arc round it all have their normal feet on the corner: a fan of lines whose
 * wall cells are slivers (the turbine's O_te and O_a: 0.002-0.003 mm between 0.06 mm of
 * flank and 0.3 mm of cap), and checkMesh's interpolation weight fails between them and
 * the next cells (turbine, template candidate of stop 18: 1 / 46 faces at densities 2 / 4
 * placed; defaults 7 at 4, 14 / 6 optimized at 2 / 4). A run of cells each narrower than
 * a fifth of both cells beside it is spread round the corner: the run's node whose line
 * (foot to outer node) lies most nearly along the corner's bisector stays on the corner,
 * the nodes before it go before it and those after it after it (spread all to one side,
 * the fan's lines lie along the wall there: min angle 24.5 -> 17.9 deg, face tets), the
 * cells growing from the corner by 1.5 (d + 0.5 |x - corner|, and no more than the
 * landing cell plus 0.5 times the distance to it) until they meet the projected cells,
 * d such that they fill the nodes in between. Where that still leaves cells more than
 * FanSideGrowth (10) apart (too few cells: the turbine's cap at density 1), the feet stay
 * as projected. Nodes outside a spread run keep their bits.
 */
void spreadFootBunches(std::vector<double>& params, const std::vector<Vec3>& feet,
  const std::vector<Vec3>& outer);
/**
 * spreadFootBunches' fallback where too few cells lie round the corner to grade them
 * (the turbine's cap at density 1, main's defaults k_o 1.35, n_o 5: feet 0.058 / 0.003 /
 * 0.8 mm, O_te's wall cells there at checkMesh's interpolation weight, 0.0509 against
 * 0.05): the run s..e (cells) is spread between the nodes next to it, one of its nodes
 * (`middle`, the bisector's, unless another leaves the cells more alike) staying on the
 * corner: the run's other nodes, each moved between its neighbours to where the worst
 * ratio of the cells beside it is least (sweeps of golden sections), then back towards their projected
 * places as far as keeps the worst ratio among these cells and the one beyond either end
 * at localMost (5; the spread feet lean the lines: O_te's smallest angle at the turbine's
 * cap 63.6 -> 41.8 deg, 37.9 at the optimum's 3.3). Where no spread brings it to 5 or
 * halves the projected one, params stay as they were. Turbine, density 1: feet 0.058 /
 * 0.003 / 0.799 -> 0.058 / 0.131 / 0.670 mm (hub), checkMesh's interpolation weight
 * 0.0509 -> 0.171 placed, 0.0508 -> 0.148 optimized.
 */
void spreadBunchLocally(std::vector<double>& params, int s, int e, int middle);
/**
 * Node parameters of projected edge `e`: the closest points on its curve of the interior
 * nodes of the edge it projects from (whose parameters must be current), as arc-length
 * fractions; fails naming both edges when their cell counts differ or the projections are
 * not in order along the edge.
 */
void projectEdgeParameters(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, MeshTopology& topology, int e);
/**
 * Node parameters of the unique edges marked in `changed` (all when null) and of those
 * that depend on them, in dependency order: graded edges, edges projected from them,
 * matched edges (matchEdgeEnds), edges projected from matched edges. The edges whose
 * parameters were recomputed because others changed are marked in `changed`.
 */
void computeEdgeGrading(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, MeshTopology& topology, std::vector<char>* changed,
  bool allowFallback);
/**
 * The end-cell floors of the matched edges with a lean limit (UniqueEdge::matchFloor): at
 * each end, the arc length along the edge's curve at which the chord from the end first
 * leans no more than the limit from the edge's chord (bisection on the curve, the same
 * bits every time). Straight edges and ends that already comply get 0. Run again when the
 * edges' vertices moved, before matchEdgeEnds, which makes every group's cell at least
 * its members' floors. With `changed`, only the edges flagged there (their curves moved).
 */
void computeMatchFloors(const BlockModel& model, const std::vector<NamedCurve>& curves,
  MeshTopology& topology, const std::vector<char>* changed = nullptr);
/// Parameters of the collapsed edges of block `b`.
void computeCollapsedParameters(const BlockModel& model, MeshTopology& topology, int b);

// -------------------------------------------------------------------- grids
/// Nodes of one edge as a block sees it (its local direction), possibly borrowed.
struct LocalEdge
{
  std::vector<double> xyzStorage, paramStorage;
  const double* borrowedXyz = nullptr;
  const double* borrowedParams = nullptr;
  int count = 0;
  const double* xyz() const { return xyzStorage.empty() ? borrowedXyz : xyzStorage.data(); }
  const double* params() const
  {
    return paramStorage.empty() ? borrowedParams : paramStorage.data();
  }
  EdgeNodes nodes() const { return EdgeNodes{ xyz(), params(), count }; }
};

LocalEdge localEdge(
  const BlockModel& model, const MeshTopology& topology, int block, int localEdgeIndex);
/// Throws TemplateError when the first cells at a corner of block `b` are inverted.
void checkCornerCells(const BlockModel& model, const MeshTopology& topology, int block, double size);
void checkCornerCells(const BlockModel& model, const MeshTopology& topology, double size);
/// The blending of the face's two directions (the block's, Transfinite.h).
inline std::array<Blending, 2> faceBlending(const BlockModel& model, int block, int face)
{
  const std::array<int, 2> directions = faceDirections(face);
  const auto& blending = model.blocks[block].blending;
  return { blending[directions[0]], blending[directions[1]] };
}
void faceFromEdges(const BlockModel& model, const MeshTopology& topology, int block, int face,
  std::vector<double>& out);
void computeEdgeNodes(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, UniqueEdge& edge);
/// Node i of `edge` from its parameters as computeEdgeNodes places it (not for named
/// periodic edges, whose nodes are rotated copies).
Vec3 edgeNodePoint(const BlockModel& model, const std::vector<NamedCurve>& curves,
  const CarrierGeometry& geometry, const UniqueEdge& edge, int i);
std::map<std::pair<int, int>, int> edgeLookup(const MeshTopology& topology);
int findUniqueEdge(const std::map<std::pair<int, int>, int>& lookup, int a, int b);
/// A unique edge whose nodes are the rotated nodes of another.
struct EdgeCopy
{
  int source = -1, sourceFrom = -1; ///< unique edge, and the vertex it is read from
  int image = -1, imageFrom = -1;
  Vec3 axisPoint, axis;
  double angle = 0.0;
  SourceLocation where;
  std::string entity;
};
/// The periodic copies, in the order they must be made: named periodic edges, then the
/// edges of every periodic image face (topology.connectivity.periodic must be current).
std::vector<EdgeCopy> periodicEdgeCopies(const BlockModel& model, const MeshTopology& topology);
void copyPeriodicEdge(const BlockModel& model, MeshTopology& topology, const EdgeCopy& copy);
/**
 * Projections of points onto carriers already made, by carrier and exact coordinates:
 * CarrierGeometry::project is a function of these alone, so a remembered result is the
 * same bits as a new projection. The mesh plan keeps one, so that a surface face whose
 * boundary changed in one edge projects only that edge's nodes again. Faces may be
 * computed on threads: the lookups and insertions are serialised, the projections not.
 */
class ProjectionCache
{
public:
  /// `distance` (when given): how far p is from the point found.
  void project(const CarrierGeometry& geometry, int carrier, const Vec3& p, double& s, double& t,
    double* distance = nullptr);
  /// Forgets every projection (the carriers' shapes changed).
  void clear();
  /// Forgets the projections onto the carriers c with changed[c] set (their shapes
  /// changed); those onto other carriers stay good.
  void clear(const std::vector<char>& changed);

private:
  struct Key
  {
    int carrier;
    std::array<std::uint64_t, 3> bits;
    bool operator==(const Key& o) const { return carrier == o.carrier && bits == o.bits; }
  };
  struct KeyHash
  {
    std::size_t operator()(const Key& key) const;
  };
  using Projections = std::unordered_map<Key, std::array<double, 3>, KeyHash>; // s, t, distance
  /// By carrier (slot 0: negative indices, slot c + 1: carrier c), so forgetting the
  /// projections onto a redrawn carrier does not walk those onto the others (an
  /// optimizer's run redraws a surface curve at most trials).
  std::vector<Projections> Known;
  std::size_t Count = 0; ///< projections remembered in all slots
  std::mutex Lock;
};

void surfaceFace(const BlockModel& model, const MeshTopology& topology, const CarrierGeometry& geometry,
  int carrier, int block, int face, std::vector<double>& out, ProjectionCache* cache = nullptr);
void periodicFace(const BlockModel& model, const MeshTopology& topology, const PeriodicPair& entry,
  std::vector<double>& out);
/// Unique face -> surface carrier of the model's surface face sets.
std::map<int, int> surfaceFaceCarriers(const BlockModel& model, const MeshTopology& topology);
/// The grid of unique face `unique` in the orientation of `block`'s local face `local`.
void localFaceGrid(const MeshTopology& topology, int block, int local, int unique,
  std::vector<double>& out);
/// The grid of unique face f (not a periodic image), on its surface carrier if it has one;
/// a following face (UniqueFace::opposite) after the face it follows.
void computeFaceGrid(const BlockModel& model, const CarrierGeometry& geometry,
  const std::map<int, int>& onSurface, MeshTopology& topology, int f,
  ProjectionCache* cache = nullptr);
/// The unique edges and faces whose grids the blocks marked in `meshed` need: their own
/// edges and faces, the edges the faces are made from, and the sources of periodic
/// images among them (faces and edges), followed to their end.
struct BoundaryNeeds
{
  std::vector<char> edges, faces;
};
BoundaryNeeds boundaryNeeds(const MeshTopology& topology, const std::vector<EdgeCopy>& copies,
  const std::vector<char>& meshed);
/// Every edge and face grid of the model (computeBoundaries), after buildMeshTopology;
/// with `meshed`, only those the marked blocks need (BoundaryNeeds), the corner cells of
/// those blocks checked. Grids computed either way are the same bits.
void computeAllBoundaries(const BlockModel& model, const CarrierGeometry& geometry,
  const std::vector<NamedCurve>& curves, MeshTopology& topology,
  const std::vector<char>* meshed = nullptr);
/// The nodes of block b by transfinite interpolation from its face and edge grids.
void meshBlockNodes(const BlockModel& model, const MeshTopology& topology, int block, double* out);

// -------------------------------------------------------------------- model check
void checkBasics(const BlockModel& model);
/// Inside-out and folded blocks; only `blocks` when given.
void checkOrientation(const BlockModel& model, const std::vector<NamedCurve>& curves,
  double size, const std::vector<int>* blocks = nullptr);
/// Control points on their carriers, periodic vertices rotations of their sources; only
/// `vertices` when given (the carriers' own checks then are skipped).
void checkCarriers(const BlockModel& model, const CarrierGeometry& geometry, double size,
  const std::vector<int>* vertices = nullptr);
void checkSurfaceFaces(const BlockModel& model, const CarrierGeometry& geometry,
  const MeshTopology& topology, double size);
void checkNamedEdgesUsed(const BlockModel& model, const MeshTopology& topology);
/// Everything checkModel checks after the basics.
void checkModelWith(const BlockModel& model, const CarrierGeometry& geometry);
} // namespace model
} // namespace blockforge
