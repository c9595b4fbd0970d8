/**
 * @file QualityInterfaces.h
 * @brief Private to the quality measures (not installed): how the grid pass sees a block
 * (BlockView: nodes, cells, the faces of its six sides) and which block-boundary faces
 * are one face of the grid (InterfaceTable: interfaces found by coincident corners,
 * periodic sides paired through their rotation, neighbour layers of other ranks).
 *
 * It exists so that the pairing of faces (QualityInterfaces.cpp) and the grid pass that
 * measures them (Quality.cpp) each stay one responsibility in one file.
 */
#pragma once

#include "Quality.h"
#include "QualityKernels.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace blockforge
{
namespace quality
{
// ---------------------------------------------------------------------------------------
// Memory

/**
 * Fresh memory is first-touched page by page, and page faults can cost as much as the
 * whole quality computation (about 10 us per 4 KiB page on some virtual machines).
 * prefault() prepares a range with two Linux hints: transparent huge pages for its
 * 2 MiB-aligned interior, then one prefault of the whole range, which costs far less
 * than faulting page by page. Neither changes memory contents; both are advisory (older
 * kernels, or other systems, simply skip them).
 */
void prefault(std::uintptr_t begin, std::uintptr_t end);

/// Reserves a vector's storage and prefaults it.
template <typename Value>
void reservePrefaulted(std::vector<Value>& values, std::size_t count)
{
  values.reserve(count);
  const auto begin = reinterpret_cast<std::uintptr_t>(values.data());
  prefault(begin, begin + sizeof(Value) * values.capacity());
}

// ---------------------------------------------------------------------------------------
// Block interfaces

/// One block's structured addressing.
struct BlockView
{
  const double* xyz;
  int ni, nj, nk; // nodes
  int ci, cj, ck; // cells
  long cellCount;
  /// A neighbour layer (another rank's cells) takes part with this side only; -1: all.
  int onlySide = -1;

  explicit BlockView(const StructuredBlock& b)
    : xyz(b.xyz)
    , ni(b.ni)
    , nj(b.nj)
    , nk(b.nk)
    , ci(std::max(b.ni - 1, 0))
    , cj(std::max(b.nj - 1, 0))
    , ck(std::max(b.nk - 1, 0))
    , cellCount(static_cast<long>(ci) * cj * ck)
  {
  }
  const double* node(int i, int j, int k) const
  {
    return xyz + 3 * (i + static_cast<long>(ni) * (j + static_cast<long>(nj) * k));
  }
  long cell(int i, int j, int k) const
  {
    return i + static_cast<long>(ci) * (j + static_cast<long>(cj) * k);
  }
  void cellCorners(int i, int j, int k, P3 (&c)[8]) const
  {
    c[0] = load(node(i, j, k));
    c[1] = load(node(i + 1, j, k));
    c[2] = load(node(i + 1, j + 1, k));
    c[3] = load(node(i, j + 1, k));
    c[4] = load(node(i, j, k + 1));
    c[5] = load(node(i + 1, j, k + 1));
    c[6] = load(node(i + 1, j + 1, k + 1));
    c[7] = load(node(i, j + 1, k + 1));
  }
  P3 cellCentre(int i, int j, int k) const
  {
    P3 c[8];
    cellCorners(i, j, k, c);
    return cellCentroid(c);
  }
  /// Face grid size of a block side: 0/1 are i = 0 / i = ni-1 (indexed j, k),
  /// 2/3 are j = 0 / nj-1 (i, k), 4/5 are k = 0 / nk-1 (i, j).
  int sideWidth(int side) const { return side < 2 ? cj : ci; }
  int sideHeight(int side) const { return side < 4 ? ck : cj; }

  /// Corners of face (a, b) of a side, ordered so the right-hand normal points along
  /// increasing i, j or k, and the cell that owns it.
  void sideFace(int side, int a, int b, P3 (&q)[4], int (&cellIjk)[3]) const
  {
    switch (side)
    {
      case 0:
      case 1:
      {
        const int i = side == 0 ? 0 : ni - 1;
        q[0] = load(node(i, a, b));
        q[1] = load(node(i, a + 1, b));
        q[2] = load(node(i, a + 1, b + 1));
        q[3] = load(node(i, a, b + 1));
        cellIjk[0] = side == 0 ? 0 : ci - 1;
        cellIjk[1] = a;
        cellIjk[2] = b;
        break;
      }
      case 2:
      case 3:
      {
        const int j = side == 2 ? 0 : nj - 1;
        q[0] = load(node(a, j, b));
        q[1] = load(node(a, j, b + 1));
        q[2] = load(node(a + 1, j, b + 1));
        q[3] = load(node(a + 1, j, b));
        cellIjk[0] = a;
        cellIjk[1] = side == 2 ? 0 : cj - 1;
        cellIjk[2] = b;
        break;
      }
      default:
      {
        const int k = side == 4 ? 0 : nk - 1;
        q[0] = load(node(a, b, k));
        q[1] = load(node(a + 1, b, k));
        q[2] = load(node(a + 1, b + 1, k));
        q[3] = load(node(a, b + 1, k));
        cellIjk[0] = a;
        cellIjk[1] = b;
        cellIjk[2] = side == 4 ? 0 : ck - 1;
        break;
      }
    }
  }
};

/// Same 4 corners as multisets, coordinates compared exactly.
bool sameCorners(const P3* a, const P3* b);

struct BoundaryFaceRef
{
  int block, side, a, b;
};

/**
 * All block-boundary faces of the grid, numbered block by block, side by side, and for
 * each the index of the coincident face (another block's, or the same block's across a
 * seam) or -1 for a true boundary.
 */
struct InterfaceTable
{
  static constexpr long unmatched = -1;

  std::vector<long> partner;
  std::vector<long> sideOffset; // first face of each (block, side), block-major
  /// Periodic faces: 2 l + 0 when the partner cell is rotated by link l's rotation into
  /// this face's frame, 2 l + 1 by its inverse; -1 for interfaces and boundaries. Empty
  /// when there are no periodic links.
  std::vector<int> periodic;
  std::vector<PeriodicSideLink> links;

  /// The neighbour centre as the face at `index` sees it.
  P3 neighbourCentre(long index, const P3& centre) const
  {
    const int code = periodic.empty() ? -1 : periodic[index];
    if (code < 0)
    {
      return centre;
    }
    const PeriodicSideLink& link = links[code / 2];
    const Vec3 relative = toVec3(centre) - link.origin;
    return toP3(link.origin +
      (code % 2 == 0 ? Vec3(link.rotation * relative) : Vec3(link.rotation.transpose() * relative)));
  }

  long index(int block, int side, int a, int b, const BlockView& view) const
  {
    return sideOffset[6 * block + side] + a + static_cast<long>(view.sideWidth(side)) * b;
  }
  BoundaryFaceRef face(long index, const std::vector<BlockView>& views) const
  {
    // The last (block, side) starting at or before index: sides without faces share
    // their offset with the next side, so they are never the last one.
    const auto found = std::upper_bound(sideOffset.begin(), sideOffset.end(), index) - 1;
    const long blockSide = found - sideOffset.begin();
    const int block = static_cast<int>(blockSide / 6), side = static_cast<int>(blockSide % 6);
    const long local = index - *found;
    const int width = views[block].sideWidth(side);
    return { block, side, static_cast<int>(local % width), static_cast<int>(local / width) };
  }
};

/**
 * Pairs boundary faces whose four corners coincide exactly. Order-independent hashes of
 * the corners are sorted (deterministic). Two faces alone with a hash are paired
 * provisionally: the boundary pass, which reads both faces' corners anyway, confirms
 * them bit for bit (a face's true partner has the same hash, so a pair that fails has no
 * partner at all). Larger groups are resolved here on the corners: a face pairs only
 * when exactly one other face has its corners; more would be an ambiguous, non-manifold
 * contact (or collapsed faces along a wedge's axis, which the boundary pass skips).
 */
InterfaceTable matchBlockInterfaces(const std::vector<BlockView>& views);

/**
 * Whether the image side of `link` is its source side rotated, cell face for cell face:
 * the side sizes agree under the transform and the four corner nodes land within 1e-9
 * of the side's size.
 */
bool linkMatches(const std::vector<BlockView>& views, const PeriodicSideLink& link);

/// Pairs the faces of periodic sides (replacing what hashing found there).
void addPeriodicLinks(InterfaceTable& table, const std::vector<BlockView>& views,
  const std::vector<PeriodicSideLink>& links);

/// Views of the blocks (throws GeometryError for a negative node count or missing nodes)
/// and their total cell count.
std::vector<BlockView> blockViews(const std::vector<StructuredBlock>& blocks, double& totalCells);

/// Appends the views of neighbour layers (one side each) after the measured blocks'.
void addNeighbourViews(std::vector<BlockView>& views, const std::vector<NeighbourLayer>& neighbours);
} // namespace quality
} // namespace blockforge
