#include "FaceChecks.h"

#include "../../Core/QualityInterfaces.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace optimize
{
namespace
{
using quality::P3;

/// A face's area vector and centre as the checks take them: the area exactly OpenFOAM's
/// (the vector area of a quadrilateral is half the cross product of its diagonals,
/// whatever the fan), the centre the corners' mean. Both checks read the centre only
/// along the face normal (S.(f - o)), where for a plane face every point of it is
/// alike; the cell centres below are volume centroids. No square root: this runs on
/// every face of the blocks a trial changed.
inline void quadFace(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, Vec3& area, Vec3& centre)
{
  area = 0.5 * (c - a).cross(d - b);
  centre = 0.25 * ((a + b) + (c + d));
}

/// The sum of the squared diagonals of the face a, b, c, d (its size, for `collapsed`).
inline double squaredDiagonals(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
  return (c - a).squaredNorm() + (d - b).squaredNorm();
}

/// Whether a face of squared area `area2` and squared diagonals `diagonals2` is collapsed
/// (a prism's or a wedge's: no face of OpenFOAM's mesh), or within `fraction` of it.
inline bool collapsed(double area2, double diagonals2, double fraction = 1e-24)
{
  return area2 <= fraction * diagonals2 * diagonals2;
}
} // namespace

BlockCells::BlockCells(
  const BlockGrid& grid, const std::vector<unsigned char>* boundarySides, unsigned char wallSides)
{
  const int ni = grid.ni, nj = grid.nj, nk = grid.nk;
  const int ci = std::max(ni - 1, 0), cj = std::max(nj - 1, 0), ck = std::max(nk - 1, 0);
  const std::size_t count = static_cast<std::size_t>(ci) * cj * ck;
  Centres.resize(count);
  Volumes.resize(count);
  if (count == 0)
  {
    return;
  }
  auto node = [&](int i, int j, int k) {
    return Eigen::Map<const Vec3>(grid.xyz +
      3 * (static_cast<std::size_t>(i) +
            static_cast<std::size_t>(ni) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(nj) * k)));
  };
  // The faces of every node layer of each direction (area along increasing i, j, k),
  // indexed like the cells they start: d = 0 at (i, j, k) for i in [0, ni), j < cj, k < ck.
  struct Face
  {
    Vec3 area, centre;
    bool collapsed;
    bool nearlyCollapsed; ///< within 1e4 of `collapsed`'s limit (the cell determinant's screen)
    double length;        ///< |area|, when the cell determinant is counted
  };
  const bool determinant = boundarySides && boundarySides->size() == count;
  const int layers[3][3] = { { ni, cj, ck }, { ci, nj, ck }, { ci, cj, nk } };
  std::vector<Face> faces[3];
  for (int d = 0; d < 3; ++d)
  {
    const int (&n)[3] = layers[d];
    faces[d].resize(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    std::size_t f = 0;
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        for (int i = 0; i < n[0]; ++i, ++f)
        {
          Vec3 a, b, c, e;
          if (d == 0)
          {
            a = node(i, j, k), b = node(i, j + 1, k), c = node(i, j + 1, k + 1), e = node(i, j, k + 1);
          }
          else if (d == 1)
          {
            a = node(i, j, k), b = node(i, j, k + 1), c = node(i + 1, j, k + 1), e = node(i + 1, j, k);
          }
          else
          {
            a = node(i, j, k), b = node(i + 1, j, k), c = node(i + 1, j + 1, k), e = node(i, j + 1, k);
          }
          Face& face = faces[d][f];
          quadFace(a, b, c, e, face.area, face.centre);
          const double area2 = face.area.squaredNorm(), diagonals2 = squaredDiagonals(a, b, c, e);
          face.collapsed = collapsed(area2, diagonals2);
          face.nearlyCollapsed = determinant && collapsed(area2, diagonals2, 1e-20);
          face.length = determinant ? std::sqrt(area2) : 0.0;
        }
      }
    }
  }
  auto faceIndex = [&](int d, int i, int j, int k) {
    const int (&n)[3] = layers[d];
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(n[0]) * (j + static_cast<std::size_t>(n[1]) * k);
  };
  // Cells: OpenFOAM's volume centroid (primitiveMesh::makeCellCentresAndVols: pyramids
  // from the faces to the mean of the face centres; collapsed faces are none).
  std::size_t n = 0;
  for (int k = 0; k < ck; ++k)
  {
    for (int j = 0; j < cj; ++j)
    {
      for (int i = 0; i < ci; ++i, ++n)
      {
        const Face* cell[6] = { &faces[0][faceIndex(0, i, j, k)], &faces[0][faceIndex(0, i + 1, j, k)],
          &faces[1][faceIndex(1, i, j, k)], &faces[1][faceIndex(1, i, j + 1, k)],
          &faces[2][faceIndex(2, i, j, k)], &faces[2][faceIndex(2, i, j, k + 1)] };
        Vec3 estimate = Vec3::Zero();
        int kept = 0;
        for (const Face* face : cell)
        {
          if (!face->collapsed)
          {
            estimate += face->centre;
            ++kept;
          }
        }
        if (kept == 0)
        {
          Centres[n] = (cell[0]->centre + cell[1]->centre) * 0.5;
          Volumes[n] = 0.0;
          continue;
        }
        estimate /= kept;
        Vec3 weighted = Vec3::Zero();
        double volume = 0.0;
        for (int f = 0; f < 6; ++f)
        {
          if (!cell[f]->collapsed)
          {
            // outward: the lower face of each direction points inwards
            const double pyramid3 = (f % 2 == 0 ? -1.0 : 1.0) * cell[f]->area.dot(cell[f]->centre - estimate);
            weighted += pyramid3 * (0.75 * cell[f]->centre + 0.25 * estimate);
            volume += pyramid3;
          }
        }
        Centres[n] = std::abs(volume) > quality::vSmall ? Vec3(weighted / volume) : estimate;
        Volumes[n] = std::abs(volume) / 3.0;
      }
    }
  }
  // The faces between cells: node layers 1 .. n-2 of each direction.
  const std::size_t steps[3] = { 1, static_cast<std::size_t>(ci), static_cast<std::size_t>(ci) * cj };
  for (int d = 0; d < 3; ++d)
  {
    const int (&m)[3] = layers[d];
    for (int k = d == 2 ? 1 : 0; k < (d == 2 ? m[2] - 1 : m[2]); ++k)
    {
      for (int j = d == 1 ? 1 : 0; j < (d == 1 ? m[1] - 1 : m[1]); ++j)
      {
        for (int i = d == 0 ? 1 : 0; i < (d == 0 ? m[0] - 1 : m[0]); ++i)
        {
          const Face& face = faces[d][faceIndex(d, i, j, k)];
          if (face.collapsed)
          {
            continue;
          }
          const std::size_t after = static_cast<std::size_t>(i) + static_cast<std::size_t>(ci) * (j + static_cast<std::size_t>(cj) * k);
          const std::size_t before = after - steps[d];
          if (weakFace(face.area, face.centre, Centres[before], Centres[after], Volumes[before], Volumes[after]))
          {
            ++Weak;
          }
        }
      }
    }
  }
  if (!determinant)
  {
    return;
  }
  // checkMesh's cell determinant over the faces GridQuality counts (the true boundary's
  // left out, collapsed ones dropped): screened with the faces above (the kernel's
  // formula, det(sum S S^T) / (8 mean|S|^6)), decided by Core's hexCellDeterminant where
  // the screen lies within 1e-6 of the limit or a face is nearly collapsed (the two
  // compute the area vectors differently, to round-off). A third of the cost of calling
  // hexCellDeterminant on every cell: that took the distributor's optimizer from 2.0 to
  // 2.45 s at density 1.
  n = 0;
  for (int k = 0; k < ck; ++k)
  {
    for (int j = 0; j < cj; ++j)
    {
      for (int i = 0; i < ci; ++i, ++n)
      {
        const unsigned char sides = (*boundarySides)[n];
        const Face* cell[6] = { &faces[0][faceIndex(0, i, j, k)], &faces[0][faceIndex(0, i + 1, j, k)],
          &faces[1][faceIndex(1, i, j, k)], &faces[1][faceIndex(1, i, j + 1, k)],
          &faces[2][faceIndex(2, i, j, k)], &faces[2][faceIndex(2, i, j, k + 1)] };
        bool exact = false;
        P3 areas[6];
        double lengths[6], sum = 0.0;
        int counted = 0;
        for (int f = 0; f < 6 && !exact; ++f)
        {
          if (sides & (1 << f))
          {
            continue;
          }
          exact = cell[f]->nearlyCollapsed;
          const Vec3& a = cell[f]->area;
          areas[counted] = { a.x(), a.y(), a.z() };
          lengths[counted] = cell[f]->length;
          sum += lengths[counted];
          ++counted;
        }
        bool fails = true;
        exact = exact || counted == 0 || sum < quality::vSmall;
        if (!exact)
        {
          // Core's formula on these area vectors (the cell's kernel in GridQuality)
          const double value = quality::cellDeterminantKernel(areas, lengths, counted);
          exact = !(std::abs(value - MinimumCellDeterminant) > 1e-6 * MinimumCellDeterminant);
          fails = value < MinimumCellDeterminant;
        }
        if (exact)
        {
          const std::array<Vec3, 8> corners = { node(i, j, k), node(i + 1, j, k),
            node(i + 1, j + 1, k), node(i, j + 1, k), node(i, j, k + 1), node(i + 1, j, k + 1),
            node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1) };
          std::array<bool, 6> counts;
          for (int f = 0; f < 6; ++f)
          {
            counts[f] = !(sides & (1 << f));
          }
          fails = !(hexCellDeterminant(corners, counts) >= MinimumCellDeterminant);
        }
        if (!fails)
        {
          continue;
        }
        ++Failing;
        // a wall-layer cell: thin along a direction that runs to a wall side of the block
        // (its mean edge along it under WallLayerRatio of its longest mean edge)
        double lengths3[3];
        for (int d = 0; d < 3; ++d)
        {
          const int e[3] = { d == 0, d == 1, d == 2 };
          const int first = d == 0 ? 1 : 0, second = d == 2 ? 1 : 2; // the other two directions
          lengths3[d] = 0.0;
          for (int a = 0; a < 2; ++a)
          {
            for (int b = 0; b < 2; ++b)
            {
              // the edge along d at offsets a, b along the other two directions
              int o[3] = { 0, 0, 0 };
              o[first] = a;
              o[second] = b;
              lengths3[d] += (node(i + o[0] + e[0], j + o[1] + e[1], k + o[2] + e[2]) -
                node(i + o[0], j + o[1], k + o[2])).norm();
            }
          }
        }
        const double longest = std::max({ lengths3[0], lengths3[1], lengths3[2] });
        bool wallLayer = false;
        for (int d = 0; d < 3; ++d)
        {
          wallLayer = wallLayer ||
            ((wallSides & (3u << (2 * d))) && lengths3[d] < WallLayerRatio * longest);
        }
        if (!wallLayer)
        {
          ++FailingAway;
        }
      }
    }
  }
}

struct InterfaceFaces::Pairs
{
  struct Pair
  {
    quality::BoundaryFaceRef owner, neighbour;
    int periodic = -1; ///< InterfaceTable::periodic code of the owner's face
  };
  std::vector<Pair> pairs;
  std::vector<PeriodicSideLink> links;
  std::vector<std::vector<unsigned char>> boundarySides; ///< per block, per cell
};

InterfaceFaces::InterfaceFaces(
  const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic)
  : P(new Pairs)
{
  double totalCells = 0.0;
  const std::vector<quality::BlockView> views = quality::blockViews(blocks, totalCells);
  quality::InterfaceTable table = quality::matchBlockInterfaces(views);
  quality::addPeriodicLinks(table, views, periodic);
  P->links = table.links;
  // every block side on the boundary until paired below
  for (const quality::BlockView& view : views)
  {
    std::vector<unsigned char> sides(static_cast<std::size_t>(view.cellCount), 0);
    for (int side = 0; side < 6 && view.cellCount > 0; ++side)
    {
      for (int b = 0; b < view.sideHeight(side); ++b)
      {
        for (int a = 0; a < view.sideWidth(side); ++a)
        {
          P3 q[4];
          int ijk[3];
          view.sideFace(side, a, b, q, ijk);
          sides[view.cell(ijk[0], ijk[1], ijk[2])] |= static_cast<unsigned char>(1 << side);
        }
      }
    }
    P->boundarySides.push_back(std::move(sides));
  }
  for (long f = 0; f < static_cast<long>(table.partner.size()); ++f)
  {
    const long partner = table.partner[f];
    if (partner <= f)
    {
      continue; // a boundary, or the pair taken from its other face
    }
    Pairs::Pair pair;
    pair.owner = table.face(f, views);
    pair.neighbour = table.face(partner, views);
    pair.periodic = table.periodic.empty() ? -1 : table.periodic[f];
    if (pair.periodic < 0)
    {
      // hashing pairs provisionally: the corners must be the same, bit for bit
      P3 q[4], r[4];
      int ijk[3];
      views[pair.owner.block].sideFace(pair.owner.side, pair.owner.a, pair.owner.b, q, ijk);
      views[pair.neighbour.block].sideFace(pair.neighbour.side, pair.neighbour.a, pair.neighbour.b, r, ijk);
      if (!quality::sameCorners(q, r))
      {
        continue;
      }
    }
    P->pairs.push_back(pair);
    for (const quality::BoundaryFaceRef& face : { pair.owner, pair.neighbour })
    {
      P3 q[4];
      int ijk[3];
      views[face.block].sideFace(face.side, face.a, face.b, q, ijk);
      P->boundarySides[face.block][views[face.block].cell(ijk[0], ijk[1], ijk[2])] &=
        static_cast<unsigned char>(~(1 << face.side));
    }
  }
}

const std::vector<unsigned char>& InterfaceFaces::boundarySides(int block) const
{
  return P->boundarySides.at(block);
}

InterfaceFaces::~InterfaceFaces() = default;

long long InterfaceFaces::weakFaces(
  const std::vector<BlockGrid>& blocks, const std::vector<const BlockCells*>& cells) const
{
  double totalCells = 0.0;
  const std::vector<quality::BlockView> views = quality::blockViews(blocks, totalCells);
  long long weak = 0;
  for (const Pairs::Pair& pair : P->pairs)
  {
    P3 q[4];
    int owner[3], neighbour[3];
    const quality::BlockView& ownerView = views[pair.owner.block];
    const quality::BlockView& neighbourView = views[pair.neighbour.block];
    ownerView.sideFace(pair.owner.side, pair.owner.a, pair.owner.b, q, owner);
    P3 r[4];
    neighbourView.sideFace(pair.neighbour.side, pair.neighbour.a, pair.neighbour.b, r, neighbour);
    Vec3 area, centre;
    const Vec3 a = quality::toVec3(q[0]), b = quality::toVec3(q[1]), c = quality::toVec3(q[2]),
               d = quality::toVec3(q[3]);
    quadFace(a, b, c, d, area, centre);
    if (collapsed(area.squaredNorm(), squaredDiagonals(a, b, c, d)))
    {
      continue;
    }
    const long o = ownerView.cell(owner[0], owner[1], owner[2]);
    const long n = neighbourView.cell(neighbour[0], neighbour[1], neighbour[2]);
    const BlockCells& ownerCells = *cells[pair.owner.block];
    const BlockCells& neighbourCells = *cells[pair.neighbour.block];
    Vec3 neighbourCentre = neighbourCells.centres()[n];
    if (pair.periodic >= 0)
    {
      // the neighbour cell rotated into the owner's frame
      const PeriodicSideLink& link = P->links[pair.periodic / 2];
      const Vec3 relative = neighbourCentre - link.origin;
      neighbourCentre = link.origin +
        (pair.periodic % 2 == 0 ? Vec3(link.rotation * relative)
                                : Vec3(link.rotation.transpose() * relative));
    }
    if (weakFace(area, centre, ownerCells.centres()[o], neighbourCentre, ownerCells.volumes()[o],
          neighbourCells.volumes()[n]))
    {
      ++weak;
    }
  }
  return weak;
}

namespace
{
/// Width of cell (i, j, k) of a block along its direction d: the distance between the
/// centres (corner means) of its two faces across d.
double cellWidth(const quality::BlockView& view, const int (&cell)[3], int d)
{
  Vec3 low = Vec3::Zero(), high = Vec3::Zero();
  for (int corner = 0; corner < 8; ++corner)
  {
    int ijk[3] = { cell[0] + (corner & 1), cell[1] + ((corner >> 1) & 1), cell[2] + ((corner >> 2) & 1) };
    const Vec3 p = Eigen::Map<const Vec3>(view.node(ijk[0], ijk[1], ijk[2]));
    (ijk[d] == cell[d] ? low : high) += p;
  }
  return 0.25 * (high - low).norm();
}
} // namespace

InterfaceRatio InterfaceFaces::largestRatio(const std::vector<BlockGrid>& blocks) const
{
  double totalCells = 0.0;
  const std::vector<quality::BlockView> views = quality::blockViews(blocks, totalCells);
  InterfaceRatio worst;
  for (const Pairs::Pair& pair : P->pairs)
  {
    int owner[3], neighbour[3];
    P3 q[4];
    views[pair.owner.block].sideFace(pair.owner.side, pair.owner.a, pair.owner.b, q, owner);
    views[pair.neighbour.block].sideFace(
      pair.neighbour.side, pair.neighbour.a, pair.neighbour.b, q, neighbour);
    const double a = cellWidth(views[pair.owner.block], owner, pair.owner.side / 2);
    const double b = cellWidth(views[pair.neighbour.block], neighbour, pair.neighbour.side / 2);
    const double smaller = std::min(a, b);
    if (!(smaller > 0.0))
    {
      continue; // a collapsed cell (a fan's apex): no width to compare
    }
    const double ratio = std::max(a, b) / smaller;
    if (ratio > worst.ratio)
    {
      worst.ratio = ratio;
      worst.ownerBlock = pair.owner.block;
      worst.neighbourBlock = pair.neighbour.block;
      worst.ownerCell = { { owner[0], owner[1], owner[2] } };
      worst.neighbourCell = { { neighbour[0], neighbour[1], neighbour[2] } };
    }
  }
  return worst;
}

long long weakFaceCount(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic)
{
  std::vector<BlockCells> cells;
  cells.reserve(blocks.size());
  std::vector<const BlockCells*> pointers;
  long long weak = 0;
  for (const BlockGrid& grid : blocks)
  {
    cells.emplace_back(grid);
    pointers.push_back(&cells.back());
    weak += cells.back().weakFaces();
  }
  return weak + InterfaceFaces(blocks, periodic).weakFaces(blocks, pointers);
}

long long failingCellCount(const std::vector<BlockGrid>& blocks, const std::vector<PeriodicSideLink>& periodic)
{
  const InterfaceFaces interfaces(blocks, periodic);
  long long failing = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    failing += BlockCells(blocks[b], &interfaces.boundarySides(static_cast<int>(b))).failingCells();
  }
  return failing;
}
} // namespace optimize
} // namespace blockforge
