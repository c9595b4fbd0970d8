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
#include "../Core/Types.h"

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

struct Vertex
{
  std::string name;
  Vec3 position = Vec3::Zero();
  SourceLocation where;
};

/// Geometry of the edge between two vertices; edges not named in a template are straight.
struct Edge
{
  enum class Kind
  {
    Line,
    Arc,   ///< circular arc, from `centre` or through `through`
    Spline ///< cubic B-spline interpolating from, points..., to
  };
  std::string name;
  Kind kind = Kind::Line;
  int from = -1, to = -1; ///< vertex indices
  bool arcHasCentre = false;
  Vec3 arcCentre = Vec3::Zero();
  Vec3 arcThrough = Vec3::Zero();
  std::vector<Vec3> splinePoints; ///< interior points, from `from` towards `to`
  SourceLocation where;
};

/// A hexahedral subvolume, possibly degenerate (repeated vertices: wedges, prisms).
struct Block
{
  std::string name;
  /// Vertex indices in the paper's Fig. 7 order = VTK hexahedron order (Transfinite.h).
  std::array<int, 8> vertices{};
  /// Cells along i (s), j (t), k (u) before the density multiplier.
  std::array<int, 3> cells{ 1, 1, 1 };
  /// Distribution law of each local edge (Transfinite.h numbering), in the local edge
  /// direction (increasing i, j or k).
  std::array<DistributionLaw, 12> laws{};
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
  SourceLocation where;
};

struct BlockModel
{
  static constexpr int FormatVersion = 1;
  std::string name;
  std::string sourceFile;
  /// Parameter values after overrides, in definition order.
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<Vertex> vertices;
  std::vector<Edge> edges;
  std::vector<Block> blocks;
  std::vector<Patch> patches;

  int findVertex(const std::string& name) const; ///< -1 if absent
  int findBlock(const std::string& name) const;  ///< -1 if absent
  /// Index into `edges` of the edge joining a and b in either direction, -1 if straight.
  int findEdge(int a, int b) const;
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
