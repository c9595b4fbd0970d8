/**
 * @file QualityInterfaces.cpp
 * @brief Which block-boundary faces of a grid are one face: interfaces found by their
 * coincident corners (hashed, then confirmed bit for bit), periodic sides paired through
 * their rotation, and the neighbour layers that stand for blocks measured on other ranks.
 *
 * Split from Quality.cpp, which keeps the grid pass that measures the faces paired here.
 */
#include "QualityInterfaces.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

namespace blockforge
{
namespace quality
{
namespace
{
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

/// Cells along the a and b directions of a block side.
void sideCells(const BlockView& view, int side, int& width, int& height)
{
  width = view.sideWidth(side);
  height = view.sideHeight(side);
}
} // namespace

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
} // namespace quality

using namespace quality;

bool periodicSidesMatch(const std::vector<StructuredBlock>& blocks, const PeriodicSideLink& link)
{
  double totalCells = 0.0;
  return linkMatches(blockViews(blocks, totalCells), link);
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
} // namespace blockforge
