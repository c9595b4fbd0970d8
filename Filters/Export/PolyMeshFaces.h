/**
 * @file PolyMeshFaces.h
 * @brief Private to the polyMesh writer: the walk over a block grid that yields OpenFOAM's
 * points and faces in OpenFOAM's order (internal faces upper-triangular, then the patches),
 * handing every face to a sink. The same walk fills a PolyMesh in memory (buildPolyMesh)
 * or streams a binary case straight into its files (writeFoamCase of an ExportGrid), so
 * the two cannot disagree.
 */
#pragma once

#include "PolyMesh.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace blockforge
{
namespace exporting
{
namespace polymesh
{
constexpr double Pi = 3.14159265358979323846;

/// Union-find over every block node; the root of a set is always its smallest index, so
/// the first node of a set in block order is its representative (deterministic numbering).
class NodeSets
{
public:
  explicit NodeSets(std::size_t count)
    : Parent(count)
  {
    std::iota(Parent.begin(), Parent.end(), 0);
  }
  int find(int x)
  {
    while (Parent[x] != x)
    {
      Parent[x] = Parent[Parent[x]];
      x = Parent[x];
    }
    return x;
  }
  void unite(int x, int y)
  {
    x = find(x);
    y = find(y);
    if (x != y)
    {
      Parent[std::max(x, y)] = std::min(x, y);
    }
  }

private:
  LargeVector<int> Parent;
};

inline /// Corners (a, b) of the face of cell (ca, cb) on block face `face`, in the order whose
/// right-hand normal points out of the block (and so out of the cell).
std::array<std::array<int, 2>, 4> outwardCorners(int face, int ca, int cb)
{
  std::array<std::array<int, 2>, 4> corners{ { { ca, cb }, { ca + 1, cb }, { ca + 1, cb + 1 },
    { ca, cb + 1 } } };
  // (a, b) order runs out of the block on i1, j0 and k1 (right-handed blocks).
  if (!(face == 1 || face == 2 || face == 5))
  {
    std::swap(corners[1], corners[3]);
  }
  return corners;
}

inline /// Cell index (in its block) of the cell at (ca, cb) next to a block face.
long long faceCell(const GridBlock& block, int face, int ca, int cb)
{
  const std::array<int, 2> directions = model::faceDirections(face);
  const std::array<int, 3> cells{ block.nodes[0] - 1, block.nodes[1] - 1, block.nodes[2] - 1 };
  std::array<long long, 3> index{ 0, 0, 0 };
  const int normal = face / 2;
  index[normal] = face % 2 == 0 ? 0 : cells[normal] - 1;
  index[directions[0]] = ca;
  index[directions[1]] = cb;
  return index[0] + cells[0] * (index[1] + static_cast<long long>(cells[1]) * index[2]);
}

/**
 * Numbers the points (interfaces, collapsed edges and coincident neighbour nodes merged,
 * first occurrence first) and
 * walks the faces. A sink has internalFace(owner, neighbour, corners, count),
 * boundaryFace(owner, corners, count) and patch(FoamPatch) (after the patch's faces).
 */
class FaceWalker
{
public:
  explicit FaceWalker(const ExportGrid& g);

  int points() const { return pointCount; }
  long long cells() const { return cellBase.back(); }
  /// Faces, face corners, internal faces and triangles seen by the last walk.
  int faceCount = 0;
  long long cornerCount = 0;
  int internalFaceCount = 0;
  int triangleCount = 0;

  /// Calls f(xyz) for every point in point order.
  template <typename F>
  void forEachPoint(F f) const
  {
    int expected = 0; // new points got the ids 0, 1, 2, ... in node order
    for (std::size_t b = 0; b < grid.blocks.size(); ++b)
    {
      const double* xyz = grid.blocks[b].xyz;
      const int* ids = pointOf.data() + nodeBase[b];
      const long long count = grid.blocks[b].nodeCount();
      for (long long n = 0; n < count; ++n)
      {
        if (ids[n] == expected)
        {
          f(xyz + 3 * n);
          ++expected;
        }
      }
    }
  }

  template <typename Sink>
  void walk(Sink& sink)
  {
    faceCount = 0;
    cornerCount = 0;
    internalFaceCount = 0;
    triangleCount = 0;
    internalFaces(sink);
    boundaryFaces(sink);
  }

private:
  const ExportGrid& grid;
  std::vector<long long> nodeBase, cellBase;
  LargeVector<int> pointOf; ///< block node -> point id
  int pointCount = 0;
  /// Per block face: the global cell across an interface for each face cell, empty when
  /// the face is not an interface.
  std::vector<std::array<std::vector<int>, 6>> across;

  int point(int block, long long node) const
  {
    return pointOf[static_cast<std::size_t>(nodeBase[block] + node)];
  }
  void numberPoints();
  void uniteCollapsed(NodeSets& sets, int b);
  bool uniteCoincident(NodeSets& sets, int b);
  /// Per block: some nodes merged (collapsed edges or coincident nodes), so cell faces
  /// may lose corners.
  std::vector<char> degenerate;
  void linkInterfaces();
  void linkSide(model::BlockFace from, model::BlockFace to, FaceTransform transform);

  /// Drops repeated corners (collapsed edges) in place; returns the corners left.
  static int compact(int* corners)
  {
    int size = 0;
    for (int c = 0; c < 4; ++c)
    {
      if (size == 0 || corners[size - 1] != corners[c])
      {
        corners[size++] = corners[c];
      }
    }
    while (size > 1 && corners[size - 1] == corners[0])
    {
      --size;
    }
    return size;
  }
  void tally(int size)
  {
    ++faceCount;
    cornerCount += size;
    triangleCount += size == 3 ? 1 : 0;
  }

  template <typename Sink>
  void internalFaces(Sink& sink)
  {
    // Corners of the outward face of a cell towards -i, +i, -j, +j, -k, +k (VTK hexahedron
    // numbering of the cell's 8 nodes).
    static const int Loops[6][4] = { { 0, 4, 7, 3 }, { 1, 2, 6, 5 }, { 0, 1, 5, 4 },
      { 3, 7, 6, 2 }, { 0, 3, 2, 1 }, { 4, 5, 6, 7 } };
    for (std::size_t b = 0; b < grid.blocks.size(); ++b)
    {
      const GridBlock& block = grid.blocks[b];
      const int ni = block.nodes[0], nj = block.nodes[1];
      const int ci = ni - 1, cj = block.nodes[1] - 1, ck = block.nodes[2] - 1;
      const int* points = pointOf.data() + nodeBase[b];
      int cell = static_cast<int>(cellBase[b]);
      // Without merged nodes no cell face can lose a corner: no check needed.
      const bool regular = !degenerate[b];
      for (int k = 0; k < ck; ++k)
      {
        for (int j = 0; j < cj; ++j)
        {
          for (int i = 0; i < ci; ++i, ++cell)
          {
            const long long n0 = i + static_cast<long long>(ni) * (j + static_cast<long long>(nj) * k);
            const long long layer = static_cast<long long>(ni) * nj;
            const int p[8] = { points[n0], points[n0 + 1], points[n0 + ni + 1], points[n0 + ni],
              points[n0 + layer], points[n0 + layer + 1], points[n0 + layer + ni + 1],
              points[n0 + layer + ni] };
            // Up to 6 neighbours with a higher number, emitted in increasing order.
            std::pair<int, int> next[6];
            int count = 0;
            auto consider = [&](int neighbour, int side) {
              if (neighbour > cell)
              {
                next[count++] = { neighbour, side };
              }
            };
            if (i + 1 < ci)
              consider(cell + 1, 1);
            if (j + 1 < cj)
              consider(cell + ci, 3);
            if (k + 1 < ck)
              consider(cell + ci * cj, 5);
            if (i == 0 || i + 1 == ci || j == 0 || j + 1 == cj || k == 0 || k + 1 == ck)
            {
              const int position[3] = { i, j, k };
              const int last[3] = { ci - 1, cj - 1, ck - 1 };
              for (int f = 0; f < 6; ++f)
              {
                const int direction = f / 2;
                const std::vector<int>& cross = across[b][f];
                if (cross.empty() || position[direction] != (f % 2 == 0 ? 0 : last[direction]))
                {
                  continue;
                }
                const std::array<int, 2> d = model::faceDirections(f);
                const int na = block.nodes[d[0]] - 1;
                consider(cross[position[d[0]] + static_cast<std::size_t>(na) * position[d[1]]], f);
              }
              std::sort(next, next + count);
            }
            for (int c = 0; c < count; ++c)
            {
              const int* loop = Loops[next[c].second];
              int corners[4] = { p[loop[0]], p[loop[1]], p[loop[2]], p[loop[3]] };
              const int size = regular ? 4 : compact(corners);
              if (size >= 3)
              {
                tally(size);
                ++internalFaceCount;
                sink.internalFace(cell, next[c].first, corners, size);
              }
            }
          }
        }
      }
    }
  }

  /// One boundary face: cell (ca, cb) of a block face, with corners through `corners`.
  template <typename Sink>
  void boundaryFace(Sink& sink, const model::BlockFace& face, int ca, int cb, int* corners)
  {
    const int size = compact(corners);
    if (size >= 3)
    {
      tally(size);
      sink.boundaryFace(static_cast<int>(cellBase[face.block] +
                          faceCell(grid.blocks[face.block], face.face, ca, cb)),
        corners, size);
    }
  }

  template <typename Sink>
  void patchFaces(Sink& sink, const model::BlockFace& face)
  {
    const GridBlock& block = grid.blocks[face.block];
    const std::array<int, 2> n = faceNodeCounts(block, face.face);
    for (int cb = 0; cb + 1 < n[1]; ++cb)
    {
      for (int ca = 0; ca + 1 < n[0]; ++ca)
      {
        int corners[4];
        const auto loop = outwardCorners(face.face, ca, cb);
        for (int c = 0; c < 4; ++c)
        {
          corners[c] = point(face.block, faceNode(block, face.face, loop[c][0], loop[c][1]));
        }
        boundaryFace(sink, face, ca, cb, corners);
      }
    }
  }

  /// The image faces of a periodic patch, in the order of its partner's faces: the first
  /// corner is the image of the partner face's first corner, the loop runs the other way
  /// (the image's outward normal is opposite), as OpenFOAM's cyclic patches expect.
  template <typename Sink>
  void imageFaces(Sink& sink, const FaceMatch& match)
  {
    const GridBlock& source = grid.blocks[match.from.block];
    const GridBlock& image = grid.blocks[match.to.block];
    const std::array<int, 2> n = faceNodeCounts(source, match.from.face);
    const std::array<int, 2> m = faceNodeCounts(image, match.to.face);
    for (int cb = 0; cb + 1 < n[1]; ++cb)
    {
      for (int ca = 0; ca + 1 < n[0]; ++ca)
      {
        const auto loop = outwardCorners(match.from.face, ca, cb);
        int corners[4];
        std::array<int, 2> low{ std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
        for (int c = 0; c < 4; ++c)
        {
          const std::array<int, 2> at = mapFaceNode(match.transform, loop[(4 - c) % 4][0],
            loop[(4 - c) % 4][1], m[0], m[1]);
          corners[c] = point(match.to.block, faceNode(image, match.to.face, at[0], at[1]));
          low = { std::min(low[0], at[0]), std::min(low[1], at[1]) };
        }
        boundaryFace(sink, match.to, low[0], low[1], corners);
      }
    }
  }

  template <typename Sink>
  void boundaryFaces(Sink& sink)
  {
    const int patchCount = static_cast<int>(grid.patches.size());
    std::vector<std::array<bool, 6>> inPatch(grid.blocks.size(), std::array<bool, 6>{});
    for (const GridPatch& patch : grid.patches)
    {
      for (const model::BlockFace& face : patch.faces)
      {
        inPatch[face.block][face.face] = true;
      }
    }
    for (const FaceMatch& match : grid.interfaces)
    {
      inPatch[match.from.block][match.from.face] = true;
      inPatch[match.to.block][match.to.face] = true;
    }
    auto add = [&](FoamPatch patch, int start) {
      patch.startFace = start;
      patch.faceCount = faceCount - start;
      sink.patch(patch);
    };
    for (int p = 0; p < patchCount; ++p)
    {
      const GridPatch& patch = grid.patches[p];
      FoamPatch entry;
      entry.name = patch.name;
      entry.type = foamPatchType(patch.type);
      const int start = faceCount;
      const bool cyclic = patch.partner >= 0 && patch.partner < patchCount;
      if (!cyclic)
      {
        entry.type = entry.type == "cyclic" ? "patch" : entry.type;
        for (const model::BlockFace& face : patch.faces)
        {
          if (!grid.collapsedFaces[face.block][face.face])
          {
            patchFaces(sink, face);
          }
        }
        add(entry, start);
        continue;
      }
      const GridPatch& partner = grid.patches[patch.partner];
      entry.type = "cyclic";
      entry.neighbourPatch = partner.name;
      entry.rotationAxis = patch.axis.normalized();
      entry.rotationCentre = patch.axisPoint;
      entry.rotationAngle = patch.angle * 180.0 / Pi;
      if (p < patch.partner)
      {
        // In the order of the pairs, which the later patch follows.
        for (const FaceMatch& match : patch.images)
        {
          patchFaces(sink, match.from);
        }
      }
      else
      {
        // The faces of the earlier patch of the pair, mapped onto this one in its order.
        for (const FaceMatch& match : partner.images)
        {
          imageFaces(sink, match);
        }
      }
      add(entry, start);
    }
    // Boundary faces in no patch.
    FoamPatch rest;
    rest.name = "defaultFaces";
    rest.type = "patch";
    const int start = faceCount;
    for (std::size_t b = 0; b < grid.blocks.size(); ++b)
    {
      for (int f = 0; f < 6; ++f)
      {
        if (!inPatch[b][f] && !grid.collapsedFaces[b][f])
        {
          patchFaces(sink, model::BlockFace{ static_cast<int>(b), f });
        }
      }
    }
    if (faceCount > start)
    {
      add(rest, start);
    }
  }
};
} // namespace polymesh
} // namespace exporting
} // namespace blockforge
