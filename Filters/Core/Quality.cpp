/**
 * @file Quality.cpp
 * @brief Cell quality of structured hexahedral blocks: the grid pass over every cell of a
 * multiblock grid (computeGridQuality) and the memory it writes into.
 *
 * The grid pass is written for throughput. Per block it keeps rolling buffers: two node
 * planes in structure-of-arrays form, the squared and inverse lengths of the edges
 * leaving each node (each edge is shared by 4 cells) and the centres of two cell layers.
 * Cells are evaluated several at a time in SIMD lanes (Eigen packets: 2 lanes with SSE2
 * on x86-64). Each internal face is evaluated once, by the cell above it, and updates
 * both cells; non-orthogonality is accumulated as a signed squared cosine, so one root
 * and one acos per cell remain. Rare special cases (collapsed edges or faces, Verdict's
 * degenerate cells) take the literal formulas, for that lane only. The cell determinant
 * takes the six face area vectors the pass has anyway, every face counted; the cells with
 * a true boundary face are measured again without it after the pass (boundaryFaces).
 *
 * The faces on block sides are paired in QualityInterfaces.cpp; the measures of a single
 * cell or face and the MinAngle classes are in QualityMeasures.cpp.
 */
#include "Quality.h"
#include "QualityInterfaces.h"
#include "QualityKernels.h"

#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace blockforge
{
namespace quality
{
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
} // namespace quality

using namespace quality;

namespace
{
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
           &q.aspectRatio, &q.scaledJacobian, &q.cellDeterminant })
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
           &q.aspectRatio, &q.scaledJacobian, &q.cellDeterminant })
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
  double *ax, *ay, *az, *cx, *cy, *cz, *area2, *diagonals2, *weightSum, *length;

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
    storeLanes(length + n, f.length);
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
    f.length = loadLanes<T>(length + n);
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
      10 * (2 * static_cast<long>(view.ci) + layerCells_);
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
        take(count), take(count), take(count), take(count), take(count) };
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
    // Face lengths |S_f| (the cell determinant's) are computed with the face, once.
    const bool determinant = quality_.cellDeterminant != nullptr;
    auto withLength = [determinant](FaceGeometry<T> face)
    {
      face.length = determinant ? vsqrt(face.area2) : splat<T>(0.0);
      return face;
    };
    FaceGeometry<T> faces[6];
    for (const int f : { 1, 3, 5 })
    {
      faces[f] = withLength(hexFace(c, f));
    }
    iFaces_.store(i, faces[1]);
    FaceGeometry<T> below[3]; // lower i, j, k faces with area vectors into these cells
    const bool hasBelow[3] = { i > 0, j_ > 0, k_ > first_ };
    below[0] = hasBelow[0] ? iFaces_.load<T>(i - 1) : withLength(lowerHexFace(c, 0));
    below[1] = hasBelow[1] ? jFaces_.load<T>(i) : withLength(lowerHexFace(c, 1));
    below[2] = hasBelow[2] ? kFaces_.load<T>(inLayer) : withLength(lowerHexFace(c, 2));
    jFaces_.store(i, faces[3]);
    kFaces_.store(inLayer, faces[5]);
    for (int d = 0; d < 3; ++d)
    {
      faces[2 * d] = reversed(below[d]);
    }
    int regular = 0;
    const V3<T> centre = cellCentroidFromFaces(c, faces, &regular);
    if (determinant)
    {
      cellDeterminants(faces, regular, cell);
    }
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

  /// The cell determinant of lanes whose six faces all count (faces inside the block, or
  /// on its sides: boundaryFaces measures the cells with a true boundary face again).
  /// Lanes with a collapsed face or no volume (not `regular`) leave the collapsed faces out.
  ///
  /// Interface and periodic faces count with the cell's own area vector, as in OpenFOAM
  /// (cellDeterminant sums over the faces of the cell, each with its own faceAreas entry;
  /// a cyclic face is one of them). Across a periodic pair the partner's face is this
  /// face rotated: rotated back it is -S_f (the same face seen from the other side), and
  /// T is quadratic in S_f, so the sign does not matter either. Rotating every face of the
  /// cell by R would give R T R^T, whose determinant is det T; rotating only the periodic
  /// ones (mixing frames) would not. Hence the cell's own faces, all in one frame.
  template <typename T>
  void cellDeterminants(const FaceGeometry<T> (&faces)[6], int regular, long cell)
  {
    V3<T> areas[6];
    T lengths[6];
    for (int f = 0; f < 6; ++f)
    {
      areas[f] = faces[f].area;
      lengths[f] = faces[f].length;
    }
    storeLanes(quality_.cellDeterminant + cell, cellDeterminantKernel(areas, lengths, 6));
    for (int l = 0; regular != (1 << laneCount<T>)-1 && l < laneCount<T>; ++l)
    {
      if (!(regular & (1 << l)))
      {
        FaceGeometry<double> laneFaces[6];
        for (int f = 0; f < 6; ++f)
        {
          laneFaces[f].area = laneOf(faces[f].area, l);
          laneFaces[f].area2 = dot(laneFaces[f].area, laneFaces[f].area);
          double diagonals2[laneCount<T>];
          extractLanes(faces[f].diagonals2, diagonals2);
          laneFaces[f].diagonals2 = diagonals2[l];
        }
        quality_.cellDeterminant[cell + l] = cellDeterminantOfFaces(laneFaces, 0x3f);
      }
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

/// A cell with faces on the true boundary: which (bits 1 << side, hexFaces order).
struct BoundaryCell
{
  long cell;
  int i, j, k;
  int sides;
};

/**
 * The cell determinant of the cells with true boundary faces, which the grid pass counted
 * as internal: measured again from the cell's corners with those faces left out (the
 * cell's own nodes only, so the same bits whatever the other blocks, ranks or layers).
 */
void boundaryCellDeterminants(
  const BlockView& view, std::vector<BoundaryCell>& cells, double* cellDeterminant)
{
  std::sort(cells.begin(), cells.end(),
    [](const BoundaryCell& a, const BoundaryCell& b) { return a.cell < b.cell; });
  for (std::size_t first = 0; first < cells.size();)
  {
    int sides = 0;
    std::size_t last = first;
    for (; last < cells.size() && cells[last].cell == cells[first].cell; ++last)
    {
      sides |= cells[last].sides;
    }
    const BoundaryCell& cell = cells[first];
    P3 c[8];
    view.cellCorners(cell.i, cell.j, cell.k, c);
    FaceGeometry<double> faces[6];
    for (int f = 0; f < 6; ++f)
    {
      const P3 q[4] = { c[hexFaces[f][0]], c[hexFaces[f][1]], c[hexFaces[f][2]], c[hexFaces[f][3]] };
      faces[f] = quadFaceArea(q);
    }
    cellDeterminant[cell.cell] = cellDeterminantOfFaces(faces, 0x3f & ~sides);
    first = last;
  }
}

/// Block-boundary faces: interfaces are measured with the other cell's centre, true
/// boundaries with OpenFOAM's boundary skewness only (and leave the cell determinant).
void boundaryFaces(const std::vector<BlockView>& views, int blockIndex,
  const InterfaceTable& interfaces, const CellQualityPointers& quality)
{
  const BlockView& view = views[blockIndex];
  std::vector<BoundaryCell> boundaryCells;
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
          if (quality.cellDeterminant)
          {
            boundaryCells.push_back({ owner, ijk[0], ijk[1], ijk[2], 1 << side });
          }
        }
      }
    }
  }
  if (quality.cellDeterminant)
  {
    boundaryCellDeterminants(view, boundaryCells, quality.cellDeterminant);
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
    if (quality.cellDeterminant)
    {
      std::fill_n(quality.cellDeterminant + first, count, 0.0);
    }
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
      q.skewness.data(), q.aspectRatio.data(), q.scaledJacobian.data(),
      q.cellDeterminant.data() };
  }
  evaluateBlocks(views, views.size(), totalCells, periodic, outputs, progress);
  return quality;
}

void computeGridQuality(const std::vector<StructuredBlock>& blocks,
  const std::vector<CellQualityPointers>& outputs, const std::function<void(double)>& progress)
{
  computeGridQuality(blocks, std::vector<PeriodicSideLink>(), outputs, progress);
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
} // namespace blockforge
