/**
 * @file Quality.h
 * @brief Per-cell quality of hexahedral structured grids: element angles (the paper's
 * criterion), OpenFOAM-style non-orthogonality and skewness (also across block
 * interfaces), aspect ratio, the Verdict hex scaled Jacobian and checkMesh's cell
 * determinant.
 *
 * Hexahedron corners are in VTK order. Angles are in degrees.
 */
#pragma once

#include "FaceTransform.h"
#include "Types.h"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <utility>
#include <vector>

namespace blockforge
{
/// Smallest and largest corner angle of the 6 quadrilateral faces (24 angles), degrees.
/// Degenerate faces (a collapsed edge: shorter than 1e-14 of the cell's longest edge)
/// count as triangles without the corner at the collapsed edge (a prism's apex: geometry,
/// see collapsedCellAngles); collapsed faces are skipped; a cell with no face left gets 0, 180.
void hexFaceAngles(const std::array<Vec3, 8>& corners, double& minAngle, double& maxAngle);

/**
 * The smallest MinAngle (hexFaceAngles' minAngle) of the cells of one structured block of
 * ni x nj x nk nodes (xyz: 3 doubles per node, i fastest), the same bits as the smallest
 * of hexFaceAngles over its cells, at a fraction of the cost: only the angles, and one
 * arccosine for the block (the arccosine is monotonic). 180 for a block without cells.
 * What an optimizer or a move measures on the blocks it changed.
 */
double smallestMinAngle(const double* xyz, int ni, int nj, int nk);

/// Verdict's hex scaled Jacobian (as vtkMeshQuality::HexScaledJacobian): the minimum of
/// the normalised Jacobian determinant at the 8 corners and the centre; 1 for a cube,
/// negative for an inverted cell.
double hexScaledJacobian(const std::array<Vec3, 8>& corners);

/// Longest over shortest of the cell's three mean widths (mean of 4 parallel edges);
/// 1e30 when a width is zero.
double hexAspectRatio(const std::array<Vec3, 8>& corners);

/// Cell centre as OpenFOAM computes it (primitiveMesh::makeCellCentresAndVols): the
/// volume-weighted centre of the pyramids from each face to the mean of the face centres,
/// i.e. the volume centroid (not the mean of the corners, unless the cell is a
/// parallelepiped). Collapsed faces are left out, as blockMesh drops them.
Vec3 hexCentre(const std::array<Vec3, 8>& corners);

/// Face area vector (sum of the triangle fan about the face centre) and face centre,
/// as OpenFOAM's face::areaAndCentre: fan about the corners' average, centre weighted
/// by the triangle areas projected on the face normal.
void quadAreaAndCentre(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
  Vec3& area, Vec3& centre);

/// OpenFOAM's non-orthogonality of a face, degrees: angle between the face area vector
/// and the vector from owner to neighbour cell centre.
double faceNonOrthogonality(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea);

/// OpenFOAM's face skewness: distance from the face centre to the point where the
/// owner-neighbour line crosses the face plane, over the owner-neighbour distance.
/// (checkMesh normalises differently; see the overload taking the face corners.)
double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea, const Vec3& faceCentre);

/// OpenFOAM's boundary-face skewness (neighbour replaced by the owner centre mirrored
/// through the face plane).
double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea,
  const Vec3& faceCentre);

/// Face skewness exactly as OpenFOAM's checkMesh reports it (meshCheck::faceSkewness):
/// the same skewness vector sv, but divided by max(0.2 |d|, largest projection of the
/// face corners, taken from the face centre, onto sv's direction). computeGridQuality
/// uses this definition, so its Skewness compares with checkMesh's "Max skewness".
double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre,
  const Vec3& faceArea, const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners);

/// OpenFOAM's meshCheck::boundaryFaceSkewness: d is the owner-to-face vector projected
/// on the face normal and the distance term is 0.4 |d| (a mirrored cell).
double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea,
  const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners);

/**
 * checkMesh's cell determinant (`checkMesh -allGeometry`, OpenFOAM's
 * primitiveMeshTools::cellDeterminant) of a cell whose internal or coupled faces (faces
 * shared with another cell, across a block interface or a periodic pair included; not
 * walls, inlets, outlets) have the area vectors `faceAreas`: with a the mean of |S_f|,
 * |det(sum (S_f/a)(S_f/a)^T)| / 8. 1 for a cube with six such faces, V^4/a^6 for a
 * parallelepiped of volume V; 0 without faces or when the summed area is below 1e-300.
 * checkMesh fails a cell under 1e-3: a thin cell, or a cell that lost a face to the
 * boundary (a unit cube with one boundary face gives 1/2, with two opposite ones 0).
 */
double cellDeterminant(const std::vector<Vec3>& faceAreas);

/// The cell determinant of a hexahedron (corners in VTK order) whose faces i0 i1 j0 j1
/// k0 k1 (hexFaces order, 0..5 as block sides) count where `counted` is true, with the
/// face area vectors of quadAreaAndCentre; faces without area are left out, as the
/// polyMesh writer drops them.
double hexCellDeterminant(const std::array<Vec3, 8>& corners, const std::array<bool, 6>& counted);

/// Quality measures of every cell of a multiblock structured grid.
struct StructuredBlock
{
  const double* xyz = nullptr; ///< nodes, interleaved, i fastest
  int ni = 0, nj = 0, nk = 0;  ///< node counts
};

struct CellQualityArrays
{
  std::vector<double> minAngle, maxAngle, nonOrthogonality, skewness, aspectRatio,
    scaledJacobian, cellDeterminant;
};

/**
 * Two block sides that are periodic images of each other: side `imageSide` of block
 * `imageBlock` is side `sourceSide` of block `sourceBlock` rotated, x_image = origin +
 * rotation (x_source - origin). Sides are 0..5 = i0 i1 j0 j1 k0 k1; `transform` maps a
 * cell face (a, b) of the image side to the source side's (see FaceTransform.h).
 * model::Topology::periodicSideLinks() gives them for a block model.
 */
struct PeriodicSideLink
{
  int sourceBlock = -1, sourceSide = -1;
  int imageBlock = -1, imageSide = -1;
  FaceTransform transform;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 origin = Vec3::Zero();
};

/// Whether `link` fits the grid: both blocks exist and have cells, the sides have the same
/// cell counts under the transform and the rotated source side lands on the image side.
bool periodicSidesMatch(const std::vector<StructuredBlock>& blocks, const PeriodicSideLink& link);

/**
 * Computes all measures for every cell of every block. NonOrthogonality and Skewness of a
 * cell are the maxima over its faces, with OpenFOAM's cell centres (hexCentre); faces on
 * a block boundary that coincide with a face of another block (same four node coordinates, bit for bit) are treated as
 * internal faces, so interfaces are measured like the interior. `progress` (may be
 * empty) is called with a fraction in [0, 1].
 *
 * Conventions: face area vectors follow the block's index directions (a right-handed
 * block has outward normals), so the faces of an inverted cell give NonOrthogonality
 * above 90. Skewness is checkMesh's (the overload of faceSkewness with face corners);
 * true boundary faces contribute boundaryFaceSkewness and no non-orthogonality. Faces
 * with no area (collapsed edges of wedge/prism blocks) contribute nothing, and a block
 * boundary face is paired only when exactly one other face has the same corners.
 * Degenerate cells never give NaN: angles of collapsed faces are skipped (a cell with no
 * valid face gets MinAngle 0, MaxAngle 180), AspectRatio follows Verdict's convention of
 * 1e30. The ScaledJacobian of a cell with a collapsed edge (where Verdict and
 * vtkMeshQuality give 1e30) is the Verdict corner formula over the corners whose three
 * edges have length, plus the centre: a wedge gets the sine of its smallest corner angle,
 * an inverted one a negative value. hexScaledJacobian() stays Verdict-exact.
 *
 * CellDeterminant is checkMesh's (cellDeterminant()) over the faces OpenFOAM's mesh of the
 * grid has as internal or coupled: every face inside a block, and the block-boundary faces
 * paired here as interfaces or periodic faces; true boundary faces and faces with no area
 * are left out. A periodic face counts with its own area vector, as in OpenFOAM (a cyclic
 * face is a face of this cell; its partner's rotation does not enter).
 */
std::vector<CellQualityArrays> computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::function<void(double)>& progress = {});

/**
 * Same, with periodic sides measured like interfaces: across a periodic face, the
 * neighbour is the partner cell with its centre rotated into this face's frame (as
 * OpenFOAM's cyclic patches do), for non-orthogonality and skewness alike. Throws
 * GeometryError when a link does not fit the grid (periodicSidesMatch).
 */
std::vector<CellQualityArrays> computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::function<void(double)>& progress = {});

/// Caller-owned output buffers of one block, each with (ni-1)(nj-1)(nk-1) doubles.
struct CellQualityPointers
{
  double* minAngle = nullptr;
  double* maxAngle = nullptr;
  double* nonOrthogonality = nullptr;
  double* skewness = nullptr;
  double* aspectRatio = nullptr;
  double* scaledJacobian = nullptr;
  /// May stay null: the cell determinant is then not computed (callers that need the six
  /// other measures only, e.g. an optimizer's objective).
  double* cellDeterminant = nullptr;
};

/// Same as above, writing into caller-owned buffers (e.g. the arrays of the VTK output,
/// so the results are never copied). `outputs` has one entry per block.
void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<CellQualityPointers>& outputs,
  const std::function<void(double)>& progress = {});
/// With periodic sides, into caller-owned buffers.
void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::vector<CellQualityPointers>& outputs,
  const std::function<void(double)>& progress = {});

/**
 * Cells of a block that is measured elsewhere (on another MPI rank), next to its side
 * `side` (0..5 = i0 i1 j0 j1 k0 k1): the block's two node layers at that side, in the
 * block's own index order (sideLayer() copies them out). The measured blocks see that
 * side as they would see the whole block's: a face coinciding with one of theirs is an
 * interface, and a periodic link may name the layer. Cell centres next to the side are
 * the whole block's bit for bit, so the measures equal those of a run with every block.
 */
struct NeighbourLayer
{
  StructuredBlock cells;
  int side = -1;
};

/// The two node layers of `block` at `side` (see NeighbourLayer), copied into `nodes`.
StructuredBlock sideLayer(const StructuredBlock& block, int side, std::vector<double>& nodes);

/**
 * With neighbour layers of blocks measured elsewhere: only `blocks` are measured (one
 * output per block); periodic link block indices from blocks.size() on name
 * neighbours[index - blocks.size()].
 */
void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::vector<NeighbourLayer>& neighbours,
  const std::vector<CellQualityPointers>& outputs, const std::function<void(double)>& progress = {});

/// Advisory: asks the system to back a large fresh output buffer with huge pages and to
/// fault it in at once. On virtual machines where a first-touch page fault costs ~10 us,
/// this makes filling a fresh array several times cheaper. Contents are unchanged.
void prepareOutputMemory(void* begin, std::size_t bytes);
/// The same for several buffers at once (the arrays of a multiblock output), on threads
/// in pieces of a few MiB, whatever the sizes of the single buffers.
void prepareOutputMemory(const std::vector<std::pair<void*, std::size_t>>& buffers);

/// Counts of cells per MinAngle class: [0,20), [20,40), [40,60), [60,80), [80,90].
std::array<long long, 5> minAngleClasses(const std::vector<CellQualityArrays>& quality);
/// The same for one array of MinAngle values.
std::array<long long, 5> minAngleClasses(const double* minAngles, std::size_t count);
} // namespace blockforge
