/**
 * @file Quality.cpp
 * @brief Cell quality of structured hexahedral blocks.
 *
 * The grid pass is written for throughput. Per block it keeps rolling buffers: two node
 * planes in structure-of-arrays form, the squared and inverse lengths of the edges
 * leaving each node (each edge is shared by 4 cells) and the centres of two cell layers.
 * Cells are evaluated several at a time in SIMD lanes (Eigen packets: 2 lanes with SSE2
 * on x86-64). Each internal face is evaluated once, by the cell above it, and updates
 * both cells; non-orthogonality is accumulated as a signed squared cosine, so one root
 * and one acos per cell remain. Rare special cases (collapsed edges or faces, Verdict's
 * degenerate cells) take the literal formulas, for that lane only.
 */
#include "Quality.h"
#include "QualityKernels.h"

#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace blockforge
{
using namespace quality;

namespace
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
void prefault(std::uintptr_t begin, std::uintptr_t end)
{
#if defined(__linux__)
  constexpr std::uintptr_t smallPage = 4096;
  constexpr std::uintptr_t hugePage = std::uintptr_t(1) << 21;
  constexpr int populateWrite = 23; // MADV_POPULATE_WRITE (Linux 5.14), absent from older headers
  if (end - begin < 16 * smallPage)
  {
    return; // not worth two system calls
  }
#if defined(MADV_HUGEPAGE)
  const std::uintptr_t hugeBegin = (begin + hugePage - 1) & ~(hugePage - 1);
  const std::uintptr_t hugeEnd = end & ~(hugePage - 1);
  if (hugeEnd > hugeBegin)
  {
    madvise(reinterpret_cast<void*>(hugeBegin), hugeEnd - hugeBegin, MADV_HUGEPAGE);
  }
#endif
  const std::uintptr_t pageBegin = begin & ~(smallPage - 1);
  const std::uintptr_t pageEnd = (end + smallPage - 1) & ~(smallPage - 1);
  madvise(reinterpret_cast<void*>(pageBegin), pageEnd - pageBegin, populateWrite);
#else
  (void)begin;
  (void)end;
#endif
}

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

/// Order-independent hash of a face's corners (a sum of per-corner hashes), with -0.0
/// folded onto +0.0 so that equal coordinates hash equally.
std::uint64_t hashFaceCorners(const P3 (&q)[4])
{
  auto mix = [](double value)
  {
    value += 0.0;
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    bits ^= bits >> 31;
    bits *= 0xBF58476D1CE4E5B9ull;
    bits ^= bits >> 29;
    return bits;
  };
  std::uint64_t sum = 0;
  for (const P3& p : q)
  {
    std::uint64_t h = mix(p.x);
    h = (h ^ mix(p.y)) * 0x94D049BB133111EBull;
    h = (h ^ mix(p.z)) * 0x9E3779B97F4A7C15ull;
    sum += h ^ (h >> 32);
  }
  return sum;
}

/// Same 4 corners as multisets, coordinates compared exactly.
bool sameCorners(const P3* a, const P3* b)
{
  auto equal = [](const P3& p, const P3& q)
  {
    return p.x == q.x && p.y == q.y && p.z == q.z;
  };
  for (int n = 0; n < 4; ++n)
  {
    const P3& p = a[n];
    int inA = 0, inB = 0;
    for (int m = 0; m < 4; ++m)
    {
      inA += equal(p, a[m]);
      inB += equal(p, b[m]);
    }
    if (inA != inB)
    {
      return false;
    }
  }
  return true;
}

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
InterfaceTable matchBlockInterfaces(const std::vector<BlockView>& views)
{
  InterfaceTable table;
  table.sideOffset.resize(6 * views.size());
  long count = 0;
  for (std::size_t blockIndex = 0; blockIndex < views.size(); ++blockIndex)
  {
    const BlockView& view = views[blockIndex];
    for (int side = 0; side < 6; ++side)
    {
      table.sideOffset[6 * blockIndex + side] = count;
      if (view.cellCount > 0 && (view.onlySide < 0 || view.onlySide == side))
      {
        count += static_cast<long>(view.sideWidth(side)) * view.sideHeight(side);
      }
    }
  }
  reservePrefaulted(table.partner, count);
  table.partner.assign(count, InterfaceTable::unmatched);

  std::vector<std::pair<std::uint64_t, long>> hashed;
  reservePrefaulted(hashed, count);
  for (std::size_t blockIndex = 0; blockIndex < views.size(); ++blockIndex)
  {
    const BlockView& view = views[blockIndex];
    if (view.cellCount == 0)
    {
      continue;
    }
    for (int side = 0; side < 6; ++side)
    {
      if (view.onlySide >= 0 && view.onlySide != side)
      {
        continue;
      }
      for (int b = 0; b < view.sideHeight(side); ++b)
      {
        for (int a = 0; a < view.sideWidth(side); ++a)
        {
          P3 q[4];
          int cellIjk[3];
          view.sideFace(side, a, b, q, cellIjk);
          hashed.emplace_back(
            hashFaceCorners(q), table.index(static_cast<int>(blockIndex), side, a, b, view));
        }
      }
    }
  }
  std::sort(hashed.begin(), hashed.end());

  auto corners = [&](long index, P3(&q)[4])
  {
    const BoundaryFaceRef ref = table.face(index, views);
    int cellIjk[3];
    views[ref.block].sideFace(ref.side, ref.a, ref.b, q, cellIjk);
  };
  std::vector<std::array<P3, 4>> group;
  for (std::size_t first = 0; first < hashed.size();)
  {
    std::size_t last = first + 1;
    while (last < hashed.size() && hashed[last].first == hashed[first].first)
    {
      ++last;
    }
    if (last - first == 2)
    {
      table.partner[hashed[first].second] = hashed[first + 1].second;
      table.partner[hashed[first + 1].second] = hashed[first].second;
    }
    else if (last - first > 2)
    {
      group.resize(last - first);
      for (std::size_t m = 0; m < group.size(); ++m)
      {
        P3 q[4];
        corners(hashed[first + m].second, q);
        std::copy(q, q + 4, group[m].begin());
      }
      for (std::size_t m = 0; m < group.size(); ++m)
      {
        std::size_t equalCount = 0, other = m;
        for (std::size_t n = 0; n < group.size(); ++n)
        {
          if (n != m && sameCorners(group[m].data(), group[n].data()))
          {
            ++equalCount;
            other = n;
          }
        }
        if (equalCount == 1)
        {
          table.partner[hashed[first + m].second] = hashed[first + other].second;
        }
      }
    }
    first = last;
  }
  return table;
}

/// Cells along the a and b directions of a block side.
void sideCells(const BlockView& view, int side, int& width, int& height)
{
  width = view.sideWidth(side);
  height = view.sideHeight(side);
}

/**
 * Whether the image side of `link` is its source side rotated, cell face for cell face:
 * the side sizes agree under the transform and the four corner nodes land within 1e-9
 * of the side's size.
 */
bool linkMatches(const std::vector<BlockView>& views, const PeriodicSideLink& link)
{
  const int blocks = static_cast<int>(views.size());
  if (link.sourceBlock < 0 || link.sourceBlock >= blocks || link.imageBlock < 0 ||
    link.imageBlock >= blocks || link.sourceSide < 0 || link.sourceSide > 5 ||
    link.imageSide < 0 || link.imageSide > 5)
  {
    return false;
  }
  const BlockView& source = views[link.sourceBlock];
  const BlockView& image = views[link.imageBlock];
  if (source.cellCount == 0 || image.cellCount == 0 ||
    (source.onlySide >= 0 && source.onlySide != link.sourceSide) ||
    (image.onlySide >= 0 && image.onlySide != link.imageSide))
  {
    return false;
  }
  int sw = 0, sh = 0, iw = 0, ih = 0;
  sideCells(source, link.sourceSide, sw, sh);
  sideCells(image, link.imageSide, iw, ih);
  if ((link.transform.swap() ? ih : iw) != sw || (link.transform.swap() ? iw : ih) != sh)
  {
    return false;
  }
  // Corner nodes of the image side's cell faces at the four corners of the side.
  const int cornerA[4] = { 0, iw - 1, iw - 1, 0 }, cornerB[4] = { 0, 0, ih - 1, ih - 1 };
  double size = 0.0, miss = 0.0;
  for (int n = 0; n < 4; ++n)
  {
    int a = 0, b = 0;
    link.transform.map(cornerA[n], cornerB[n], sw, sh, a, b);
    P3 q[4], r[4];
    int ijk[3];
    image.sideFace(link.imageSide, cornerA[n], cornerB[n], q, ijk);
    source.sideFace(link.sourceSide, a, b, r, ijk);
    // The face centroids (corner means) must coincide after the rotation.
    const P3 imageMean = 0.25 * ((q[0] + q[1]) + (q[2] + q[3]));
    const P3 sourceMean = 0.25 * ((r[0] + r[1]) + (r[2] + r[3]));
    const Vec3 rotated = link.origin + link.rotation * (toVec3(sourceMean) - link.origin);
    miss = std::max(miss, (rotated - toVec3(imageMean)).norm());
    for (const P3& p : q)
    {
      size = std::max(size, (toVec3(p) - toVec3(imageMean)).norm());
    }
  }
  return miss <= 1e-6 * size;
}

/// Pairs the faces of periodic sides (replacing what hashing found there).
void addPeriodicLinks(InterfaceTable& table, const std::vector<BlockView>& views,
  const std::vector<PeriodicSideLink>& links)
{
  if (links.empty())
  {
    return;
  }
  table.links = links;
  table.periodic.assign(table.partner.size(), -1);
  for (std::size_t l = 0; l < links.size(); ++l)
  {
    const PeriodicSideLink& link = links[l];
    if (!linkMatches(views, link))
    {
      throw GeometryError("grid quality: side " + std::to_string(link.imageSide) + " of block " +
        std::to_string(link.imageBlock) + " is not the periodic image of side " +
        std::to_string(link.sourceSide) + " of block " + std::to_string(link.sourceBlock));
    }
    const BlockView& source = views[link.sourceBlock];
    const BlockView& image = views[link.imageBlock];
    int sw = 0, sh = 0, iw = 0, ih = 0;
    sideCells(source, link.sourceSide, sw, sh);
    sideCells(image, link.imageSide, iw, ih);
    for (int b = 0; b < ih; ++b)
    {
      for (int a = 0; a < iw; ++a)
      {
        int sa = 0, sb = 0;
        link.transform.map(a, b, sw, sh, sa, sb);
        const long imageIndex = table.index(link.imageBlock, link.imageSide, a, b, image);
        const long sourceIndex = table.index(link.sourceBlock, link.sourceSide, sa, sb, source);
        table.partner[imageIndex] = sourceIndex;
        table.partner[sourceIndex] = imageIndex;
        table.periodic[imageIndex] = static_cast<int>(2 * l);
        table.periodic[sourceIndex] = static_cast<int>(2 * l + 1);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Grid pass

/// Reports progress at most about 32 times, whatever the number of blocks or cells.
class ProgressReporter
{
public:
  ProgressReporter(const std::function<void(double)>& callback, double total)
    : callback_(callback)
    , total_(total > 0 ? total : 1.0)
  {
  }
  void advance(double amount)
  {
    done_ += amount;
    const double fraction = std::min(1.0, done_ / total_);
    if (callback_ && fraction - reported_ >= 1.0 / 32)
    {
      reported_ = fraction;
      callback_(fraction);
    }
  }
  void start()
  {
    if (callback_)
    {
      callback_(0.0);
    }
  }
  void finish()
  {
    if (callback_ && reported_ < 1.0)
    {
      callback_(1.0);
    }
  }

private:
  const std::function<void(double)>& callback_;
  double total_;
  double done_ = 0.0;
  double reported_ = 0.0;
};

/// Reserves all result arrays up front, so that arrays the allocator placed next to
/// each other (small blocks) are prefaulted as one span.
void reserveResultArrays(
  std::vector<CellQualityArrays>& quality, const std::vector<BlockView>& views)
{
  struct Range
  {
    std::uintptr_t begin, end;
  };
  std::vector<Range> ranges;
  for (std::size_t n = 0; n < views.size(); ++n)
  {
    CellQualityArrays& q = quality[n];
    for (std::vector<double>* values : { &q.minAngle, &q.maxAngle, &q.nonOrthogonality, &q.skewness,
           &q.aspectRatio, &q.scaledJacobian })
    {
      values->reserve(views[n].cellCount);
      const auto begin = reinterpret_cast<std::uintptr_t>(values->data());
      ranges.push_back({ begin, begin + sizeof(double) * values->capacity() });
    }
  }
  std::sort(
    ranges.begin(), ranges.end(), [](const Range& a, const Range& b) { return a.begin < b.begin; });
  constexpr std::uintptr_t allocatorGap = 4096; // headers between neighbouring blocks
  for (std::size_t first = 0; first < ranges.size();)
  {
    std::uintptr_t spanEnd = ranges[first].end;
    std::size_t last = first + 1;
    while (last < ranges.size() && ranges[last].begin <= spanEnd + allocatorGap)
    {
      spanEnd = std::max(spanEnd, ranges[last].end);
      ++last;
    }
    prefault(ranges[first].begin, spanEnd);
    first = last;
  }
  // Sized only now, so that the zero fill touches prefaulted pages.
  for (std::size_t n = 0; n < views.size(); ++n)
  {
    CellQualityArrays& q = quality[n];
    for (std::vector<double>* values : { &q.minAngle, &q.maxAngle, &q.nonOrthogonality, &q.skewness,
           &q.aspectRatio, &q.scaledJacobian })
    {
      values->resize(views[n].cellCount);
    }
  }
}

/// Points in structure-of-arrays form (a node plane, a layer of cell centres), so that
/// neighbouring cells load as SIMD lanes.
struct CoordinateArrays
{
  double *x, *y, *z;
};

/// Squared and inverse lengths (0 for zero length) of the grid edges leaving each node
/// of a plane along i or j, or between two planes along k; indexed like the nodes.
struct EdgeLengths
{
  double* length2;
  double* inverseLength;
};

void invertLengths(EdgeLengths edges, long count)
{
  const Eigen::Map<const Eigen::ArrayXd> squared(edges.length2, count);
  Eigen::Map<Eigen::ArrayXd> inverse(edges.inverseLength, count);
  inverse = squared.sqrt().inverse();
  inverse = (squared > 0.0).select(inverse, 0.0);
}

void loadPlane(const BlockView& view, int k, CoordinateArrays plane)
{
  const long count = static_cast<long>(view.ni) * view.nj;
  const double* p = view.node(0, 0, k);
  for (long n = 0; n < count; ++n)
  {
    plane.x[n] = p[3 * n];
    plane.y[n] = p[3 * n + 1];
    plane.z[n] = p[3 * n + 2];
  }
}

/// Edge lengths of vectors b[n + offset] - a[n] for n < count - offset; the rest 0.
void edgeLengths(
  const CoordinateArrays& a, const CoordinateArrays& b, long offset, long count, EdgeLengths edges)
{
  for (long n = 0; n + offset < count; ++n)
  {
    const double dx = b.x[n + offset] - a.x[n];
    const double dy = b.y[n + offset] - a.y[n];
    const double dz = b.z[n + offset] - a.z[n];
    edges.length2[n] = dx * dx + dy * dy + dz * dz;
  }
  for (long n = std::max(count - offset, 0L); n < count; ++n)
  {
    edges.length2[n] = 0.0;
  }
  invertLengths(edges, count);
}

/// Face geometry in structure-of-arrays form: the upper faces of a row (i), of the
/// previous row (j) or of the previous layer (k), each read by the next cell as its lower
/// face, so that every face is computed once.
struct FaceArrays
{
  double *ax, *ay, *az, *cx, *cy, *cz, *area2, *diagonals2, *weightSum;

  template <typename T>
  void store(long n, const FaceGeometry<T>& f) const
  {
    storeLanes(ax + n, f.area.x);
    storeLanes(ay + n, f.area.y);
    storeLanes(az + n, f.area.z);
    storeLanes(cx + n, f.centre.x);
    storeLanes(cy + n, f.centre.y);
    storeLanes(cz + n, f.centre.z);
    storeLanes(area2 + n, f.area2);
    storeLanes(diagonals2 + n, f.diagonals2);
    storeLanes(weightSum + n, f.weightSum);
  }
  template <typename T>
  FaceGeometry<T> load(long n) const
  {
    FaceGeometry<T> f;
    f.area = loadV3<T>(ax + n, ay + n, az + n);
    f.centre = loadV3<T>(cx + n, cy + n, cz + n);
    f.area2 = loadLanes<T>(area2 + n);
    f.diagonals2 = loadLanes<T>(diagonals2 + n);
    f.weightSum = loadLanes<T>(weightSum + n);
    f.average = f.centre; // not used by the kernels
    return f;
  }
};

/// Rolling per-block buffers of the grid pass.
class BlockPass
{
public:
  BlockPass(const BlockView& view, const CellQualityPointers& quality, std::vector<double>& scratch)
    : view_(view)
    , quality_(quality)
    , plane_(static_cast<long>(view.ni) * view.nj)
    , layerCells_(static_cast<long>(view.ci) * view.cj)
  {
    // 2 node planes (x, y, z), i- and j-edges of both (length2, inverse), k-edges
    // between them, 2 layers of cell centres (x, y, z).
    // Upper faces: of a row (i), of the previous row (j), of the previous layer (k).
    const long size = 2 * 3 * plane_ + 2 * 2 * 2 * plane_ + 2 * plane_ + 2 * 3 * layerCells_ +
      9 * (2 * static_cast<long>(view.ci) + layerCells_);
    if (scratch.capacity() < static_cast<std::size_t>(size))
    {
      scratch = std::vector<double>();
      reservePrefaulted(scratch, size);
    }
    scratch.assign(size, 0.0);
    double* buffer = scratch.data();
    auto take = [&buffer](long count)
    {
      double* start = buffer;
      buffer += count;
      return start;
    };
    for (int n = 0; n < 2; ++n)
    {
      planes_[n] = { take(plane_), take(plane_), take(plane_) };
    }
    for (int n = 0; n < 2; ++n)
    {
      iEdges_[n] = { take(plane_), take(plane_) };
      jEdges_[n] = { take(plane_), take(plane_) };
    }
    kEdges_ = { take(plane_), take(plane_) };
    for (int n = 0; n < 2; ++n)
    {
      centres_[n] = { take(layerCells_), take(layerCells_), take(layerCells_) };
    }
    auto faceArrays = [&take](long count) {
      return FaceArrays{ take(count), take(count), take(count), take(count), take(count),
        take(count), take(count), take(count), take(count) };
    };
    iFaces_ = faceArrays(view.ci);
    jFaces_ = faceArrays(view.ci);
    kFaces_ = faceArrays(layerCells_);
    minCosine2_ = quality.nonOrthogonality;
    maxSkewness_ = quality.skewness;
  }

  /// Shape measures of every cell of layer k and the faces below and beside them. The
  /// first layer passed starts the pass: its faces below are left to the layer under it.
  void layer(int k)
  {
    if (first_ < 0)
    {
      first_ = k;
      loadPlane(view_, k, planes_[k % 2]);
      planeEdges(k % 2);
    }
    lower_ = k % 2;
    upper_ = 1 - lower_;
    loadPlane(view_, k + 1, planes_[upper_]);
    planeEdges(upper_);
    edgeLengths(planes_[lower_], planes_[upper_], 0, plane_, kEdges_);
    k_ = k;
    for (int j = 0; j < view_.cj; ++j)
    {
      j_ = j;
      // Cell 0 has no lower i-face, so SIMD groups start at cell 1.
      cells<double>(0);
      int i = 1;
      for (; i + packetLanes <= view_.ci; i += packetLanes)
      {
        cells<Lanes>(i);
      }
      for (; i < view_.ci; ++i)
      {
        cells<double>(i);
      }
    }
  }

private:
  void planeEdges(int p)
  {
    edgeLengths(planes_[p], planes_[p], 1, plane_, iEdges_[p]);
    edgeLengths(planes_[p], planes_[p], view_.ni, plane_, jEdges_[p]);
  }

  /// Cells (i, j_, k_) to (i + lanes - 1, j_, k_).
  template <typename T>
  void cells(int i)
  {
    constexpr int lanes = laneCount<T>;
    const long n00 = i + static_cast<long>(view_.ni) * j_; // node (i, j) in a plane
    const long n10 = n00 + 1, n01 = n00 + view_.ni, n11 = n01 + 1;
    const CoordinateArrays& lowerPlane = planes_[lower_];
    const CoordinateArrays& upperPlane = planes_[upper_];
    auto corner = [](const CoordinateArrays& plane, long n)
    {
      return loadV3<T>(plane.x + n, plane.y + n, plane.z + n);
    };
    const V3<T> c[8] = { corner(lowerPlane, n00), corner(lowerPlane, n10), corner(lowerPlane, n11),
      corner(lowerPlane, n01), corner(upperPlane, n00), corner(upperPlane, n10),
      corner(upperPlane, n11), corner(upperPlane, n01) };
    V3<T> e[12];
    edgeVectors(c, e);
    const EdgeLengths edge[12] = { iEdges_[lower_], jEdges_[lower_], iEdges_[lower_],
      jEdges_[lower_], iEdges_[upper_], jEdges_[upper_], iEdges_[upper_], jEdges_[upper_], kEdges_,
      kEdges_, kEdges_, kEdges_ };
    const long edgeStart[12] = { n00, n10, n01, n00, n00, n10, n01, n00, n00, n10, n11, n01 };
    T length2[12], inverseLength[12];
    for (int n = 0; n < 12; ++n)
    {
      length2[n] = loadLanes<T>(edge[n].length2 + edgeStart[n]);
      inverseLength[n] = loadLanes<T>(edge[n].inverseLength + edgeStart[n]);
    }
    ShapeSums<double> sums[lanes];
    splitLanes(shapeKernel(e, length2, inverseLength), sums);
    const long cell = view_.cell(i, j_, k_);
    for (int l = 0; l < lanes; ++l)
    {
      const CellShape shape = finishShape(sums[l], c, l);
      quality_.minAngle[cell + l] = shape.minAngle;
      quality_.maxAngle[cell + l] = shape.maxAngle;
      quality_.scaledJacobian[cell + l] = shape.scaledJacobian;
      if (shape.scaledJacobian == verdictMax)
      {
        P3 corners[8];
        for (int v = 0; v < 8; ++v)
        {
          corners[v] = laneOf(c[v], l);
        }
        quality_.scaledJacobian[cell + l] = collapsedCellScaledJacobian(corners);
      }
      quality_.aspectRatio[cell + l] = shape.aspectRatio;
    }

    // Each face once, in its canonical corner order (hexFaceGeometry): the upper faces
    // here, the lower ones from the cells below (the upper face of lane l is the lower
    // face of lane l + 1: stored before loaded), or computed where there is none below in
    // this pass (the same bits as the cell below would give: chunks and neighbour layers
    // agree with one whole pass).
    const long inLayer = i + static_cast<long>(view_.ci) * j_;
    FaceGeometry<T> faces[6];
    for (const int f : { 1, 3, 5 })
    {
      faces[f] = hexFace(c, f);
    }
    iFaces_.store(i, faces[1]);
    FaceGeometry<T> below[3]; // lower i, j, k faces with area vectors into these cells
    const bool hasBelow[3] = { i > 0, j_ > 0, k_ > first_ };
    below[0] = hasBelow[0] ? iFaces_.load<T>(i - 1) : lowerHexFace(c, 0);
    below[1] = hasBelow[1] ? jFaces_.load<T>(i) : lowerHexFace(c, 1);
    below[2] = hasBelow[2] ? kFaces_.load<T>(inLayer) : lowerHexFace(c, 2);
    jFaces_.store(i, faces[3]);
    kFaces_.store(inLayer, faces[5]);
    for (int d = 0; d < 3; ++d)
    {
      faces[2 * d] = reversed(below[d]);
    }
    const V3<T> centre = cellCentroidFromFaces(c, faces);
    const CoordinateArrays& centres = centres_[k_ % 2];
    storeLanes(centres.x + inLayer, centre.x);
    storeLanes(centres.y + inLayer, centre.y);
    storeLanes(centres.z + inLayer, centre.z);

    // Lower faces, corners ordered so that the area vector points into these cells.
    if (i > 0)
    {
      const V3<T> q[4] = { c[0], c[3], c[7], c[4] };
      lowerFace<T>(q, below[0], centres, inLayer - 1, cell - 1, centre, cell);
    }
    if (j_ > 0)
    {
      const V3<T> q[4] = { c[0], c[4], c[5], c[1] };
      lowerFace<T>(q, below[1], centres, inLayer - view_.ci, cell - view_.ci, centre, cell);
    }
    if (k_ > first_)
    {
      const V3<T> q[4] = { c[0], c[1], c[2], c[3] };
      lowerFace<T>(q, below[2], centres_[1 - k_ % 2], inLayer, cell - layerCells_, centre, cell);
    }
  }

  template <typename T>
  void lowerFace(const V3<T> (&q)[4], const FaceGeometry<T>& face,
    const CoordinateArrays& neighbourCentres, long neighbourInLayer, long neighbour,
    const V3<T>& centre, long cell)
  {
    const V3<T> neighbourCentre = loadV3<T>(neighbourCentres.x + neighbourInLayer,
      neighbourCentres.y + neighbourInLayer, neighbourCentres.z + neighbourInLayer);
    FaceMeasures<T> m = internalFaceKernel(q, face, neighbourCentre, centre);
    const int usable = usableLanes(face, m);
    for (int l = 0; usable != (1 << laneCount<T>)-1 && l < laneCount<T>; ++l)
    {
      if (!(usable & (1 << l)))
      {
        P3 corners[4];
        for (int n = 0; n < 4; ++n)
        {
          corners[n] = laneOf(q[n], l);
        }
        double cosine2 = 1.0, skew = 0.0;
        internalFaceSpecialCase(
          corners, laneOf(neighbourCentre, l), laneOf(centre, l), cosine2, skew);
        setLane(m.cosine2, l, cosine2);
        setLane(m.skew, l, skew);
      }
    }
    // Neighbours first: along i, lane l's neighbour is lane l - 1.
    for (long target : { neighbour, cell })
    {
      storeLanes(minCosine2_ + target, vmin(loadLanes<T>(minCosine2_ + target), m.cosine2));
      storeLanes(maxSkewness_ + target, vmax(loadLanes<T>(maxSkewness_ + target), m.skew));
    }
  }

  const BlockView& view_;
  const CellQualityPointers& quality_;
  const long plane_, layerCells_;
  CoordinateArrays planes_[2];
  EdgeLengths iEdges_[2], jEdges_[2], kEdges_;
  CoordinateArrays centres_[2];
  FaceArrays iFaces_, jFaces_, kFaces_;
  double* minCosine2_;
  double* maxSkewness_;
  int lower_ = 0, upper_ = 1, j_ = 0, k_ = 0;
  int first_ = -1;
};

/// Block-boundary faces: interfaces are measured with the other cell's centre, true
/// boundaries with OpenFOAM's boundary skewness only.
void boundaryFaces(const std::vector<BlockView>& views, int blockIndex,
  const InterfaceTable& interfaces, const CellQualityPointers& quality)
{
  const BlockView& view = views[blockIndex];
  for (int side = 0; side < 6; ++side)
  {
    const bool lowerSide = side % 2 == 0;
    for (int b = 0; b < view.sideHeight(side); ++b)
    {
      for (int a = 0; a < view.sideWidth(side); ++a)
      {
        const long faceIndex = interfaces.index(blockIndex, side, a, b, view);
        const long partner = interfaces.partner[faceIndex];
        const bool periodic = !interfaces.periodic.empty() && interfaces.periodic[faceIndex] >= 0;
        P3 q[4];
        int ijk[3];
        view.sideFace(side, a, b, q, ijk);
        const FaceGeometry<double> face = scalarFace(q);
        if (faceCollapsed(face.area2, face.diagonals2))
        {
          continue; // no normal, e.g. along a wedge's axis
        }
        const P3 outward = lowerSide ? -1.0 * face.area : face.area;
        const long owner = view.cell(ijk[0], ijk[1], ijk[2]);
        const P3 ownerCentre = view.cellCentre(ijk[0], ijk[1], ijk[2]);
        double& minCosine2 = quality.nonOrthogonality[owner];
        double& maxSkewness = quality.skewness[owner];
        const BlockView* otherView = nullptr;
        P3 otherCorners[4];
        int otherIjk[3];
        if (partner >= 0)
        {
          const BoundaryFaceRef other = interfaces.face(partner, views);
          otherView = &views[other.block];
          otherView->sideFace(other.side, other.a, other.b, otherCorners, otherIjk);
          if (!periodic && !sameCorners(q, otherCorners))
          {
            otherView = nullptr; // hashes collided: a true boundary face
          }
        }
        if (otherView)
        {
          const P3 d = interfaces.neighbourCentre(faceIndex,
                         otherView->cellCentre(otherIjk[0], otherIjk[1], otherIjk[2])) -
            ownerCentre;
          minCosine2 = std::min(minCosine2, signedSquare(orthogonalityCosine(d, outward)));
          maxSkewness =
            std::max(maxSkewness, skewness(ownerCentre, d, 0.2, outward, face.centre, q));
        }
        else
        {
          maxSkewness =
            std::max(maxSkewness, boundarySkewness(ownerCentre, outward, face.centre, q));
        }
      }
    }
  }
}

/// body(first, count) over [0, cells) in ranges on threads (elementwise work: the same
/// bits in any chunking).
void forEachCellRange(long cells, const std::function<void(long, long)>& body)
{
  const long chunks = chunkCount(cells, 1L << 17, 64);
  forEachChunk(chunks, [&](long chunk) {
    const long first = cells * chunk / chunks;
    body(first, cells * (chunk + 1) / chunks - first);
  });
}

void evaluateBlock(const std::vector<BlockView>& views, int blockIndex,
  const InterfaceTable& interfaces, const CellQualityPointers& quality,
  std::vector<double>& scratch, ProgressReporter& progress)
{
  const BlockView& view = views[blockIndex];
  const long cellCount = view.cellCount;
  if (cellCount == 0)
  {
    return;
  }
  forEachCellRange(cellCount, [&](long first, long count) {
    std::fill_n(quality.minAngle + first, count, 0.0);
    std::fill_n(quality.maxAngle + first, count, 0.0);
    // signed squared cosine until finishBlock
    std::fill_n(quality.nonOrthogonality + first, count, 1.0);
    std::fill_n(quality.skewness + first, count, 0.0);
    std::fill_n(quality.aspectRatio + first, count, 0.0);
    std::fill_n(quality.scaledJacobian + first, count, 0.0);
  });
  // Layers in chunks of at least two, on threads when a runner is installed. A chunk
  // [k0, k1) first re-evaluates layer k0 - 1 (the same values again: idempotent writes and
  // min/max updates), whose centres its lowest faces need, and updates cells of layers
  // k0 - 1 .. k1 - 1 only. Even chunks run first, then odd ones, so no two chunks that
  // touch the same layer run at once; min and max do not depend on the order, so every
  // chunking gives the same bits.
  const long layerCells = static_cast<long>(view.ci) * view.cj;
  const int chunks =
    static_cast<int>(chunkCount(cellCount, 1L << 16, std::max(1, view.ck / 2)));
  if (chunks == 1)
  {
    BlockPass pass(view, quality, scratch);
    for (int k = 0; k < view.ck; ++k)
    {
      pass.layer(k);
      progress.advance(static_cast<double>(layerCells));
    }
  }
  else
  {
    auto runChunk = [&](long chunk)
    {
      const int k0 = static_cast<int>(view.ck * chunk / chunks);
      const int k1 = static_cast<int>(view.ck * (chunk + 1) / chunks);
      std::vector<double> chunkScratch;
      BlockPass pass(view, quality, chunkScratch);
      for (int k = std::max(k0 - 1, 0); k < k1; ++k)
      {
        pass.layer(k);
      }
    };
    for (int parity = 0; parity < 2; ++parity)
    {
      const long count = (chunks - parity + 1) / 2;
      forEachChunk(count, [&](long n) { runChunk(2 * n + parity); });
      progress.advance(static_cast<double>(layerCells) * view.ck * 0.5);
    }
  }
}

/// After every block's interior: the faces on the block's sides (boundaryFaces), then
/// non-orthogonality from the signed squared cosine to degrees. Writes this block's
/// cells only.
void finishBlock(const std::vector<BlockView>& views, int blockIndex,
  const InterfaceTable& interfaces, const CellQualityPointers& quality)
{
  if (views[blockIndex].cellCount == 0)
  {
    return;
  }
  boundaryFaces(views, blockIndex, interfaces, quality);
  for (long cell = 0; cell < views[blockIndex].cellCount; ++cell)
  {
    double& value = quality.nonOrthogonality[cell];
    value = angleFromCosine(std::copysign(std::sqrt(std::abs(value)), value));
  }
}

inline void loadCorners(const std::array<Vec3, 8>& corners, P3 (&c)[8])
{
  for (int v = 0; v < 8; ++v)
  {
    c[v] = toP3(corners[v]);
  }
}

inline void loadFace(const std::array<Vec3, 4>& corners, P3 (&q)[4])
{
  for (int v = 0; v < 4; ++v)
  {
    q[v] = toP3(corners[v]);
  }
}
} // namespace

void hexFaceAngles(const std::array<Vec3, 8>& corners, double& minAngle, double& maxAngle)
{
  P3 c[8];
  loadCorners(corners, c);
  const CellShape shape = evaluateCellShape(c);
  minAngle = shape.minAngle;
  maxAngle = shape.maxAngle;
}

double hexScaledJacobian(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).scaledJacobian;
}

double hexAspectRatio(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return evaluateCellShape(c).aspectRatio;
}

Vec3 hexCentre(const std::array<Vec3, 8>& corners)
{
  P3 c[8];
  loadCorners(corners, c);
  return toVec3(cellCentroid(c));
}

void quadAreaAndCentre(
  const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, Vec3& area, Vec3& centre)
{
  const P3 q[4] = { toP3(a), toP3(b), toP3(c), toP3(d) };
  const FaceGeometry<double> face = scalarFace(q);
  area = toVec3(face.area);
  centre = toVec3(face.centre);
}

double faceNonOrthogonality(
  const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea)
{
  return angleFromCosine(
    orthogonalityCosine(toP3(neighbourCentre) - toP3(ownerCentre), toP3(faceArea)));
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea,
  const Vec3& faceCentre)
{
  const P3 owner = toP3(ownerCentre);
  const P3 d = toP3(neighbourCentre) - owner;
  const P3 area = toP3(faceArea);
  const P3 ownerToFace = toP3(faceCentre) - owner;
  const P3 sv = ownerToFace - (dot(area, ownerToFace) / (dot(area, d) + rootVSmall)) * d;
  return std::sqrt(dot(sv, sv)) / (std::sqrt(dot(d, d)) + rootVSmall);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea, const Vec3& faceCentre)
{
  const Vec3 normal = faceArea / (faceArea.norm() + rootVSmall);
  const Vec3 mirrored = ownerCentre + 2.0 * normal * normal.dot(faceCentre - ownerCentre);
  return faceSkewness(ownerCentre, mirrored, faceArea, faceCentre);
}

double faceSkewness(const Vec3& ownerCentre, const Vec3& neighbourCentre, const Vec3& faceArea,
  const Vec3& faceCentre, const std::array<Vec3, 4>& faceCorners)
{
  P3 q[4];
  loadFace(faceCorners, q);
  const P3 owner = toP3(ownerCentre);
  return skewness(owner, toP3(neighbourCentre) - owner, 0.2, toP3(faceArea), toP3(faceCentre), q);
}

double boundaryFaceSkewness(const Vec3& ownerCentre, const Vec3& faceArea, const Vec3& faceCentre,
  const std::array<Vec3, 4>& faceCorners)
{
  P3 q[4];
  loadFace(faceCorners, q);
  return boundarySkewness(toP3(ownerCentre), toP3(faceArea), toP3(faceCentre), q);
}

namespace
{
std::vector<BlockView> blockViews(const std::vector<StructuredBlock>& blocks, double& totalCells)
{
  std::vector<BlockView> views;
  views.reserve(blocks.size());
  totalCells = 0.0;
  for (std::size_t n = 0; n < blocks.size(); ++n)
  {
    const StructuredBlock& block = blocks[n];
    if (block.ni < 0 || block.nj < 0 || block.nk < 0)
    {
      throw GeometryError(
        "grid quality: block " + std::to_string(n) + " has a negative node count");
    }
    views.emplace_back(block);
    if (views.back().cellCount > 0 && !block.xyz)
    {
      throw GeometryError("grid quality: block " + std::to_string(n) + " has no nodes");
    }
    totalCells += static_cast<double>(views.back().cellCount);
  }
  return views;
}

/// Appends the views of neighbour layers (one side each) after the measured blocks'.
void addNeighbourViews(std::vector<BlockView>& views, const std::vector<NeighbourLayer>& neighbours)
{
  for (std::size_t n = 0; n < neighbours.size(); ++n)
  {
    const NeighbourLayer& neighbour = neighbours[n];
    const StructuredBlock& cells = neighbour.cells;
    const int across[3] = { cells.ni, cells.nj, cells.nk };
    if (neighbour.side < 0 || neighbour.side > 5 || across[neighbour.side / 2] != 2 ||
      cells.ni < 2 || cells.nj < 2 || cells.nk < 2 || !cells.xyz)
    {
      throw GeometryError("grid quality: neighbour layer " + std::to_string(n) +
        " is not two node layers at a block side");
    }
    views.emplace_back(cells);
    views.back().onlySide = neighbour.side;
  }
}

/// Measures the first `measured` views; the views after them are neighbour layers.
void evaluateBlocks(const std::vector<BlockView>& views, std::size_t measured, double totalCells,
  const std::vector<PeriodicSideLink>& periodic, const std::vector<CellQualityPointers>& outputs,
  const std::function<void(double)>& progress)
{
  ProgressReporter reporter(progress, totalCells);
  reporter.start();
  InterfaceTable interfaces = matchBlockInterfaces(views);
  addPeriodicLinks(interfaces, views, periodic);
  std::vector<double> scratch;
  for (std::size_t n = 0; n < measured; ++n)
  {
    evaluateBlock(views, static_cast<int>(n), interfaces, outputs[n], scratch, reporter);
  }
  // The blocks' sides read other blocks' nodes only and write their own block's cells:
  // blocks on threads (min and max updates, the same bits in any order).
  forEachChunk(static_cast<long>(measured), [&](long n) {
    finishBlock(views, static_cast<int>(n), interfaces, outputs[n]);
  });
  reporter.finish();
}
} // namespace

std::vector<CellQualityArrays> computeGridQuality(
  const std::vector<StructuredBlock>& blocks, const std::function<void(double)>& progress)
{
  return computeGridQuality(blocks, std::vector<PeriodicSideLink>(), progress);
}

std::vector<CellQualityArrays> computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::function<void(double)>& progress)
{
  double totalCells = 0.0;
  const std::vector<BlockView> views = blockViews(blocks, totalCells);
  std::vector<CellQualityArrays> quality(blocks.size());
  reserveResultArrays(quality, views);
  std::vector<CellQualityPointers> outputs(blocks.size());
  for (std::size_t n = 0; n < blocks.size(); ++n)
  {
    CellQualityArrays& q = quality[n];
    outputs[n] = { q.minAngle.data(), q.maxAngle.data(), q.nonOrthogonality.data(),
      q.skewness.data(), q.aspectRatio.data(), q.scaledJacobian.data() };
  }
  evaluateBlocks(views, views.size(), totalCells, periodic, outputs, progress);
  return quality;
}

void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<CellQualityPointers>& outputs, const std::function<void(double)>& progress)
{
  computeGridQuality(blocks, std::vector<PeriodicSideLink>(), outputs, progress);
}

bool periodicSidesMatch(const std::vector<StructuredBlock>& blocks, const PeriodicSideLink& link)
{
  double totalCells = 0.0;
  return linkMatches(blockViews(blocks, totalCells), link);
}

void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::vector<CellQualityPointers>& outputs,
  const std::function<void(double)>& progress)
{
  computeGridQuality(blocks, periodic, std::vector<NeighbourLayer>(), outputs, progress);
}

void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const std::vector<NeighbourLayer>& neighbours,
  const std::vector<CellQualityPointers>& outputs, const std::function<void(double)>& progress)
{
  if (outputs.size() != blocks.size())
  {
    throw GeometryError("grid quality: " + std::to_string(outputs.size()) +
      " output buffers for " + std::to_string(blocks.size()) + " blocks");
  }
  double totalCells = 0.0;
  std::vector<BlockView> views = blockViews(blocks, totalCells);
  addNeighbourViews(views, neighbours);
  evaluateBlocks(views, blocks.size(), totalCells, periodic, outputs, progress);
}

StructuredBlock sideLayer(const StructuredBlock& block, int side, std::vector<double>& nodes)
{
  if (side < 0 || side > 5 || block.ni < 2 || block.nj < 2 || block.nk < 2 || !block.xyz)
  {
    throw GeometryError("grid quality: no side " + std::to_string(side) + " to take a layer of");
  }
  int begin[3] = { 0, 0, 0 };
  int count[3] = { block.ni, block.nj, block.nk };
  const int axis = side / 2;
  begin[axis] = side % 2 == 0 ? 0 : count[axis] - 2;
  count[axis] = 2;
  nodes.resize(3 * static_cast<std::size_t>(count[0]) * count[1] * count[2]);
  double* out = nodes.data();
  for (int k = 0; k < count[2]; ++k)
  {
    for (int j = 0; j < count[1]; ++j)
    {
      const double* row = block.xyz +
        3 * (begin[0] + static_cast<long>(block.ni) * (begin[1] + j + static_cast<long>(block.nj) * (begin[2] + k)));
      std::copy_n(row, 3 * static_cast<std::size_t>(count[0]), out);
      out += 3 * count[0];
    }
  }
  StructuredBlock layer;
  layer.xyz = nodes.data();
  layer.ni = count[0];
  layer.nj = count[1];
  layer.nk = count[2];
  return layer;
}

void prepareOutputMemory(void* begin, std::size_t bytes)
{
  prepareOutputMemory({ { begin, bytes } });
}

void prepareOutputMemory(const std::vector<std::pair<void*, std::size_t>>& buffers)
{
  // The kernel zeroes the pages it faults in: in 2 MiB-aligned pieces of about 4 MiB on
  // threads, so a large output is not prepared by one core alone.
  constexpr std::uintptr_t hugePage = std::uintptr_t(1) << 21;
  constexpr std::uintptr_t pieceSize = 2 * hugePage;
  std::vector<std::pair<std::uintptr_t, std::uintptr_t>> pieces;
  for (const auto& buffer : buffers)
  {
    const auto start = reinterpret_cast<std::uintptr_t>(buffer.first);
    const std::uintptr_t end = start + buffer.second;
    std::uintptr_t from = start;
    while (from < end)
    {
      std::uintptr_t to = ((from + pieceSize) & ~(hugePage - 1));
      to = to >= end || end - to < hugePage ? end : to;
      pieces.emplace_back(from, to);
      from = to;
    }
  }
  forEachChunk(static_cast<long>(pieces.size()), [&](long piece) {
    prefault(pieces[piece].first, pieces[piece].second);
  });
}

std::array<long long, 5> minAngleClasses(const double* minAngles, std::size_t count)
{
  std::array<long long, 5> counts{};
  for (std::size_t c = 0; c < count; ++c)
  {
    // Comparisons rather than a cast so that a NaN cannot index out of range.
    const double angle = minAngles[c];
    ++counts[(angle >= 20.0) + (angle >= 40.0) + (angle >= 60.0) + (angle >= 80.0)];
  }
  return counts;
}

std::array<long long, 5> minAngleClasses(const std::vector<CellQualityArrays>& quality)
{
  std::array<long long, 5> counts{};
  for (const CellQualityArrays& block : quality)
  {
    const auto blockCounts = minAngleClasses(block.minAngle.data(), block.minAngle.size());
    for (int c = 0; c < 5; ++c)
    {
      counts[c] += blockCounts[c];
    }
  }
  return counts;
}
} // namespace blockforge
