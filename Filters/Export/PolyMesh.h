/**
 * @file PolyMesh.h
 * @brief OpenFOAM's polyMesh (points, faces, owner, neighbour, boundary) from a meshed
 * block model, and the writer of an OpenFOAM case (`constant/polyMesh` plus an empty
 * `NAME.foam` for ParaView's OpenFOAM reader). No VTK types.
 *
 * Block interfaces become internal faces (their nodes are merged), every boundary patch
 * becomes an OpenFOAM patch (wall -> wall, symmetry -> symmetry, periodic -> cyclic with a
 * rotational transform, anything else -> patch), boundary faces in no patch go to
 * `defaultFaces`. Collapsed block edges and faces are merged, so the cells of wedge blocks
 * become prisms (their collapsed faces vanish, their quadrilaterals touching the collapsed
 * edge become triangles). Cells are numbered block by block, i fastest, as the blocks'
 * cells (so per-cell fields line up with GridQuality's arrays); internal faces are in
 * upper-triangular order, as OpenFOAM requires.
 */
#pragma once

#include "ExportGrid.h"
#include "LargeAllocator.h"

#include <functional>
#include <string>
#include <vector>

namespace blockforge
{
namespace exporting
{
/// One entry of `constant/polyMesh/boundary`.
struct FoamPatch
{
  std::string name;
  std::string type; ///< OpenFOAM patch type: patch, wall, symmetry, cyclic
  int startFace = 0;
  int faceCount = 0;
  std::string neighbourPatch; ///< cyclic only
  Vec3 rotationAxis = Vec3::UnitZ();
  Vec3 rotationCentre = Vec3::Zero();
  double rotationAngle = 0.0; ///< degrees, this patch onto its neighbour (cyclic only)
};

struct PolyMesh
{
  LargeVector<double> points;           ///< x y z interleaved
  LargeVector<int> faceOffsets{ 0 };    ///< faces + 1 entries into faceNodes
  LargeVector<int> faceNodes;
  LargeVector<int> owner;               ///< one per face
  LargeVector<int> neighbour;           ///< one per internal face
  int cellCount = 0;
  std::vector<FoamPatch> patches;
  int triangleFaces = 0; ///< faces that lost a corner to a collapsed edge (prism cells)

  int pointCount() const { return static_cast<int>(points.size() / 3); }
  int faceCount() const { return static_cast<int>(owner.size()); }
  int internalFaceCount() const { return static_cast<int>(neighbour.size()); }
};

/// The OpenFOAM patch type of a template patch type.
std::string foamPatchType(const std::string& templateType);

/// Builds the polyMesh. Throws std::runtime_error when the grid exceeds 32-bit labels.
PolyMesh buildPolyMesh(const ExportGrid& grid);

struct FoamWriteOptions
{
  bool binary = true;
  /// Called with the fraction done in [0, 1].
  std::function<void(double)> progress;
};

/**
 * Writes the case of `foamFile` (DIR/NAME.foam): `DIR/constant/polyMesh/{points, faces,
 * owner, neighbour, boundary}` and an empty `DIR/NAME.foam` (kept if it exists; other
 * case files, e.g. 0/ and system/, are not touched). The polyMesh directory is written
 * under a temporary name and put in place by one rename (an older polyMesh is exchanged
 * with it, then removed), so a failure leaves the older mesh as it was. Throws
 * std::runtime_error naming the file and the reason (unwritable folder, disk full).
 */
void writeFoamCase(const PolyMesh& mesh, const std::string& foamFile,
  const FoamWriteOptions& options = {});

/// What writeFoamCase wrote.
struct FoamSummary
{
  int points = 0;
  int cells = 0;
  int faces = 0;
  int internalFaces = 0;
  int triangleFaces = 0;
  std::vector<FoamPatch> patches;
};

/**
 * The same case straight from the grid: binary files are streamed as the faces are
 * walked (no polyMesh held in memory: a million cells need about a quarter of the memory
 * and time), ASCII goes through buildPolyMesh. Same files, same guarantees as above.
 */
FoamSummary writeFoamCase(const ExportGrid& grid, const std::string& foamFile,
  const FoamWriteOptions& options = {});
} // namespace exporting
} // namespace blockforge
