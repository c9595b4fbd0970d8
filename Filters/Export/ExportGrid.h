/**
 * @file ExportGrid.h
 * @brief What every solver-format writer needs to know about a meshed block model: the
 * node grid of every block, the block interfaces and periodic pairs with the map of their
 * face nodes, and the named patches with their types. No VTK types.
 *
 * The writers (PolyMesh.h, Plot3D.h, Cgns.h) only read this; exportGrid() fills it from the
 * model's topology and the mesher's (or a VTK grid's) node arrays.
 */
#pragma once

#include "BlockModel.h"
#include "FaceTransform.h"

#include <array>
#include <string>
#include <vector>

namespace blockforge
{
namespace exporting
{
/// The nodes of one block (ni * nj * nk points, x y z interleaved, i fastest).
struct GridBlock
{
  std::string name;
  std::array<int, 3> nodes{ 0, 0, 0 };
  const double* xyz = nullptr;

  long long nodeCount() const { return static_cast<long long>(nodes[0]) * nodes[1] * nodes[2]; }
  long long cellCount() const
  {
    return static_cast<long long>(nodes[0] - 1) * (nodes[1] - 1) * (nodes[2] - 1);
  }
};

/**
 * Two block faces whose node grids coincide node for node (or are rotated copies): node
 * (a, b) of `from` (a, b along model::faceDirections(from.face)) is node
 * transform.map(a, b) of `to`.
 */
struct FaceMatch
{
  model::BlockFace from;
  model::BlockFace to;
  FaceTransform transform;
};

/// Node counts (along a, b) of a block face.
std::array<int, 2> faceNodeCounts(const GridBlock& block, int face);
/// Index (into the block's nodes) of node (a, b) of a block face.
long long faceNode(const GridBlock& block, int face, int a, int b);
/// (a, b) on the other face of node (a, b); (toA, toB) are the other face's node counts.
std::array<int, 2> mapFaceNode(FaceTransform transform, int a, int b, int toA, int toB);
/// The inverse map (from the other side back).
FaceTransform inverse(FaceTransform transform);

/// A named boundary patch as the template declares it.
struct GridPatch
{
  std::string name;
  std::string type; ///< the template's type: wall, inlet, outlet, patch, symmetry, periodic
  std::vector<model::BlockFace> faces;
  /// Periodic pairs: the index of the partner patch (-1 otherwise), and for every face of
  /// this patch (same order as `faces`) its match on the partner: from = this patch's
  /// face rotated by `angle` about `axis` through `axisPoint` lands on `to`.
  int partner = -1;
  std::vector<FaceMatch> images;
  Vec3 axisPoint = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double angle = 0.0; ///< radians, right-hand rule about axis
};

/// A meshed model, ready to be written.
struct ExportGrid
{
  std::string name; ///< the model's name
  std::vector<GridBlock> blocks;
  /// Every pair of block faces that are one face inside the domain (each pair once).
  std::vector<FaceMatch> interfaces;
  std::vector<GridPatch> patches;
  /// Per block and local edge (model numbering): the edge collapses to a point (its two
  /// corners are one vertex): degenerate wedge or prism blocks.
  std::vector<std::array<bool, 12>> collapsedEdges;
  /// Per block face: collapsed to a line or point (fewer than three distinct corners).
  std::vector<std::array<bool, 6>> collapsedFaces;

  long long cellCount() const;
  long long nodeCount() const; ///< per block, shared nodes counted in each
};
} // namespace exporting
} // namespace blockforge
