/**
 * @file Topology.h
 * @brief The connectivity of a block model: which blocks share which edges and faces and
 * how they index them (interfaces with their index transforms), which boundary faces are
 * periodic images of which (with the rotation), and which faces form each patch.
 *
 * Public so that everything that needs block connectivity reads it from one place: the
 * mesher (shared edges and faces are meshed once), the quality measures (interfaces and
 * periodic faces are measured like interior faces) and solver writers (OpenFOAM internal
 * faces and cyclics, CGNS 1-to-1 connectivity). Built from vertex indices alone (plus the
 * vertex positions for periodic pairs): no carrier and no grid is needed.
 */
#pragma once

#include "BlockModel.h"
#include "Errors.h"

#include "../Core/FaceTransform.h"
#include "../Core/Quality.h"

#include <array>
#include <string>
#include <vector>

namespace blockforge
{
namespace model
{
/// One block's use of a shared edge.
struct EdgeUse
{
  int block = -1;
  int localEdge = -1;    ///< 0..11
  bool reversed = false; ///< the block runs this edge from the higher vertex index
};

/// An edge of the model, shared by every block that uses it, in canonical direction
/// a -> b (a < b, vertex indices).
struct TopologyEdge
{
  int a = -1, b = -1;
  int named = -1;    ///< index into model.edges, -1 for a straight edge
  int nodeCount = 0; ///< the same in every block that uses it (checked)
  std::vector<EdgeUse> uses;
};

/// One block's use of a shared face; `transform` maps this block's face index (a, b) to
/// the first use's (the owner's).
struct FaceUse
{
  int block = -1;
  int face = -1; ///< 0..5 = i0 i1 j0 j1 k0 k1
  FaceTransform transform;
};

/// A face with at least three distinct vertices, used by one block (a boundary face) or
/// two (an interface). Faces collapsed to a line or a point are not faces.
struct TopologyFace
{
  std::array<int, 4> ownerIds{}; ///< vertex indices at the owner's face corners 0..3
  int na = 0, nb = 0;            ///< node counts along the owner's face directions
  std::vector<FaceUse> uses;     ///< uses[0] is the owner
  bool isInterface() const { return uses.size() == 2; }
};

/// What one block is connected to.
struct BlockLinks
{
  std::array<int, 3> nodes{};       ///< node counts (ni, nj, nk)
  std::array<int, 12> edge{};       ///< TopologyEdge index, -1 when collapsed
  std::array<bool, 12> reversed{};  ///< the block runs the edge b -> a
  std::array<int, 6> face{};        ///< TopologyFace index, -1 when collapsed
  std::array<FaceTransform, 6> transform{}; ///< this block's (a, b) -> the owner's
};

/**
 * A face of a periodic patch and its partner face: `image` is `source` rotated by
 * `angle` (radians, right-hand rule) about the axis through `axisPoint` along `axis`
 * (unit). `transform` maps the image face's (a, b) to the source face's (a, b). For each
 * pair of periodic patches the faces of the earlier patch are the sources.
 */
struct PeriodicPair
{
  int source = -1, image = -1; ///< TopologyFace indices
  BlockFace sourceFace, imageFace;
  FaceTransform transform;
  Vec3 axisPoint = Vec3::Zero(), axis = Vec3::UnitZ();
  double angle = 0.0;
  int patch = -1;   ///< the patch of the source face
  int partner = -1; ///< the patch of the image face
};

/// Two blocks meeting at a face: `second`'s face index (a, b) maps to `first`'s by
/// `transform`.
struct Interface
{
  BlockFace first, second;
  FaceTransform transform;
};

struct Topology
{
  std::vector<TopologyEdge> edges;
  std::vector<TopologyFace> faces;
  std::vector<BlockLinks> blocks;
  std::vector<PeriodicPair> periodic;
  /// Patch index of face f of block b at 6 b + f, -1 when the face is in no patch.
  std::vector<int> patchOfFace;

  /// Every face shared by two blocks, in face order.
  std::vector<Interface> interfaces() const;
  /// The periodic pairs as the quality measures take them (Core types).
  std::vector<PeriodicSideLink> periodicSideLinks() const;
};

/// Node counts (cells + 1) of every block as the model gives them (density 1, no cap).
std::vector<std::array<int, 3>> baseNodeCounts(const BlockModel& model);

/// Node counts of a block at a density multiplier, as the mesher makes them:
/// max(min(cells, min_cells), round(cells * m)) cells per direction (min_cells 1 by
/// default: max(1, round(cells * m))), at most `cap` when cap > 0, plus one.
/// The multiplier must be valid (checkDensityMultiplier), so every count fits an int.
std::array<int, 3> scaledNodeCounts(const Block& block, double multiplier, int cap = 0);

/**
 * Shared edges and faces for the given node counts, with every consistency check that
 * depends on them alone: node counts on shared edges, faces shared by more than two
 * blocks, faces that share vertices but do not match edge for edge. Throws TemplateError
 * naming the block. Block vertex indices must be valid (checkModel's basics).
 */
Topology buildConnectivity(const BlockModel& model, const std::vector<std::array<int, 3>>& nodes);

/**
 * Checks the patches against the connectivity (faces exist, are on the domain boundary,
 * are in one patch only; periodic partners exist, name each other, have as many faces
 * and each face lands on a partner face under the rotation) and fills
 * `topology.patchOfFace`. Throws TemplateError naming the patch.
 */
void checkPatches(const BlockModel& model, Topology& topology);

/// Pairs the faces of periodic patches node for node (fills `topology.periodic`). Throws
/// TemplateError naming the patch when a rotated face matches no partner face.
void findPeriodicPairs(const BlockModel& model, Topology& topology);

/// The complete topology of a valid model at the given node counts (default: the
/// model's own): connectivity, patch check and periodic pairs.
Topology buildTopology(const BlockModel& model, const std::vector<std::array<int, 3>>& nodes);
Topology buildTopology(const BlockModel& model);

/// Tolerance scale: the diagonal of the vertices' bounding box (1 when empty or flat).
double modelSize(const BlockModel& model);

/// Vertex indices at the corners 0..3 of face `face` of `block` (faceCorners order).
std::array<int, 4> faceVertexIds(const Block& block, int face);

/// "block.j0": how messages name a block face.
std::string blockFaceText(const BlockModel& model, int block, int face);
/// "w_ne-b_ne" or "'wall_n' (w_ne-b_ne)": how messages name the edge between a and b.
std::string edgeText(const BlockModel& model, int a, int b);
} // namespace model
} // namespace blockforge
