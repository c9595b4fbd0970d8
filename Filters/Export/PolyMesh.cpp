#include "PolyMeshFaces.h"

namespace blockforge
{
namespace exporting
{
namespace polymesh
{
FaceWalker::FaceWalker(const ExportGrid& g)
  : grid(g)
{
  numberPoints();
  linkInterfaces();
}

void FaceWalker::numberPoints()
{
  const int blockCount = static_cast<int>(grid.blocks.size());
  nodeBase.assign(blockCount + 1, 0);
  cellBase.assign(blockCount + 1, 0);
  for (int b = 0; b < blockCount; ++b)
  {
    nodeBase[b + 1] = nodeBase[b] + grid.blocks[b].nodeCount();
    cellBase[b + 1] = cellBase[b] + grid.blocks[b].cellCount();
  }
  if (nodeBase.back() >= std::numeric_limits<int>::max() ||
    cellBase.back() * 3 + 1 >= std::numeric_limits<int>::max())
  {
    throw std::runtime_error("the grid is too large for OpenFOAM's 32-bit labels");
  }
  NodeSets sets(static_cast<std::size_t>(nodeBase.back()));
  for (const FaceMatch& match : grid.interfaces)
  {
    const GridBlock& from = grid.blocks[match.from.block];
    const GridBlock& to = grid.blocks[match.to.block];
    const std::array<int, 2> n = faceNodeCounts(from, match.from.face);
    const std::array<int, 2> m = faceNodeCounts(to, match.to.face);
    for (int b = 0; b < n[1]; ++b)
    {
      for (int a = 0; a < n[0]; ++a)
      {
        const std::array<int, 2> image = mapFaceNode(match.transform, a, b, m[0], m[1]);
        sets.unite(static_cast<int>(nodeBase[match.from.block] + faceNode(from, match.from.face, a, b)),
          static_cast<int>(nodeBase[match.to.block] + faceNode(to, match.to.face, image[0], image[1])));
      }
    }
  }
  degenerate.assign(blockCount, 0);
  for (int b = 0; b < blockCount; ++b)
  {
    const std::array<bool, 12>& collapsed = grid.collapsedEdges[b];
    degenerate[b] = std::any_of(collapsed.begin(), collapsed.end(), [](bool c) { return c; });
    uniteCollapsed(sets, b);
    if (uniteCoincident(sets, b))
    {
      degenerate[b] = 1;
    }
  }
  // Points in order of their first node.
  pointOf.resize(static_cast<std::size_t>(nodeBase.back()));
  int next = 0;
  for (int node = 0; node < static_cast<int>(pointOf.size()); ++node)
  {
    const int root = sets.find(node);
    pointOf[node] = root == node ? next++ : pointOf[root];
  }
  pointCount = next;
}

/// Collapsed edges merge their nodes; a face with two opposite collapsed edges merges
/// every line of nodes parallel to them (the face is a line: a wedge's axis).
void FaceWalker::uniteCollapsed(NodeSets& sets, int b)
{
  const GridBlock& block = grid.blocks[b];
  const std::array<bool, 12>& collapsed = grid.collapsedEdges[b];
  const int base = static_cast<int>(nodeBase[b]);
  for (int f = 0; f < 6; ++f)
  {
    const std::array<int, 4> edges = model::faceEdges(f); // bottom, top, left, right
    const std::array<int, 2> n = faceNodeCounts(block, f);
    const bool alongA = collapsed[edges[0]] && collapsed[edges[1]];
    const bool alongB = collapsed[edges[2]] && collapsed[edges[3]];
    for (int b2 = 0; b2 < n[1]; ++b2)
    {
      for (int a = 0; a < n[0]; ++a)
      {
        const int node = base + static_cast<int>(faceNode(block, f, a, b2));
        const bool onBottom = b2 == 0 && collapsed[edges[0]];
        const bool onTop = b2 == n[1] - 1 && collapsed[edges[1]];
        const bool onLeft = a == 0 && collapsed[edges[2]];
        const bool onRight = a == n[0] - 1 && collapsed[edges[3]];
        if (alongA || onBottom || onTop)
        {
          sets.unite(node, base + static_cast<int>(faceNode(block, f, 0, b2)));
        }
        if (alongB || onLeft || onRight)
        {
          sets.unite(node, base + static_cast<int>(faceNode(block, f, a, 0)));
        }
      }
    }
  }
}

/// Neighbour nodes along a grid line of the block that are the same point (equal
/// coordinates, bit for bit) are one point: a block edge or face that the geometry
/// collapses without the model saying so (two vertices placed on one point, a fan's feet
/// on a sharp tip) gives prisms as a wedge block does. Exact equality only: nodes a
/// round-off apart stay apart, so the cells written are the cells GridQuality measures
/// (it treats an edge shorter than 1e-14 of the cell's longest edge as collapsed). True
/// when any nodes were merged.
bool FaceWalker::uniteCoincident(NodeSets& sets, int b)
{
  const GridBlock& block = grid.blocks[b];
  const int ni = block.nodes[0], nj = block.nodes[1];
  const long long steps[3] = { 1, ni, static_cast<long long>(ni) * nj };
  const long long count = block.nodeCount();
  const double* xyz = block.xyz;
  const int base = static_cast<int>(nodeBase[b]);
  bool any = false;
  for (int d = 0; d < 3; ++d)
  {
    const long long step = steps[d];
    // x first, in a tight loop (equal x is rare); the whole point and whether n has a
    // neighbour along d (not the last node of its line) only then.
    for (long long n = 0; n + step < count; ++n)
    {
      if (xyz[3 * n] != xyz[3 * (n + step)])
      {
        continue;
      }
      const double* p = xyz + 3 * n;
      const double* q = xyz + 3 * (n + step);
      const bool inside = d == 0 ? n % ni + 1 < ni : d == 1 ? (n / ni) % nj + 1 < nj : true;
      if (inside && p[1] == q[1] && p[2] == q[2])
      {
        sets.unite(base + static_cast<int>(n), base + static_cast<int>(n + step));
        any = true;
      }
    }
  }
  return any;
}

/// Fills `across` for both sides of every interface.
void FaceWalker::linkInterfaces()
{
  across.assign(grid.blocks.size(), {});
  for (const FaceMatch& match : grid.interfaces)
  {
    linkSide(match.from, match.to, match.transform);
    linkSide(match.to, match.from, inverse(match.transform));
  }
}

void FaceWalker::linkSide(model::BlockFace from, model::BlockFace to, FaceTransform transform)
{
  const GridBlock& fromBlock = grid.blocks[from.block];
  const GridBlock& toBlock = grid.blocks[to.block];
  const std::array<int, 2> n = faceNodeCounts(fromBlock, from.face);
  const std::array<int, 2> m = faceNodeCounts(toBlock, to.face);
  std::vector<int>& cells = across[from.block][from.face];
  cells.assign(static_cast<std::size_t>(n[0] - 1) * (n[1] - 1), -1);
  for (int cb = 0; cb + 1 < n[1]; ++cb)
  {
    for (int ca = 0; ca + 1 < n[0]; ++ca)
    {
      // The transform maps cell indices as it maps node indices (with cell counts).
      const std::array<int, 2> image = mapFaceNode(transform, ca, cb, m[0] - 1, m[1] - 1);
      cells[ca + static_cast<std::size_t>(n[0] - 1) * cb] = static_cast<int>(
        cellBase[to.block] + faceCell(toBlock, to.face, image[0], image[1]));
    }
  }
}

} // namespace polymesh

namespace
{
/// Fills a PolyMesh.
struct MemorySink
{
  PolyMesh& mesh;
  void add(const int* corners, int count)
  {
    mesh.faceNodes.insert(mesh.faceNodes.end(), corners, corners + count);
    mesh.faceOffsets.push_back(static_cast<int>(mesh.faceNodes.size()));
  }
  void internalFace(int owner, int neighbour, const int* corners, int count)
  {
    add(corners, count);
    mesh.owner.push_back(owner);
    mesh.neighbour.push_back(neighbour);
  }
  void boundaryFace(int owner, const int* corners, int count)
  {
    add(corners, count);
    mesh.owner.push_back(owner);
  }
  void patch(const FoamPatch& entry) { mesh.patches.push_back(entry); }
};
} // namespace

std::string foamPatchType(const std::string& templateType)
{
  if (templateType == "wall" || templateType == "symmetry" || templateType == "symmetryPlane" ||
    templateType == "empty" || templateType == "wedge")
  {
    return templateType;
  }
  if (templateType == "periodic" || templateType == "cyclic")
  {
    return "cyclic";
  }
  return "patch";
}

PolyMesh buildPolyMesh(const ExportGrid& grid)
{
  polymesh::FaceWalker walker(grid);
  PolyMesh mesh;
  const std::size_t cells = static_cast<std::size_t>(walker.cells());
  mesh.cellCount = static_cast<int>(cells);
  mesh.faceNodes.reserve(cells * 12 + 64);
  mesh.faceOffsets.reserve(cells * 3 + 16);
  mesh.owner.reserve(cells * 3 + 16);
  mesh.neighbour.reserve(cells * 3 + 16);
  MemorySink sink{ mesh };
  walker.walk(sink);
  mesh.triangleFaces = walker.triangleCount;
  mesh.points.reserve(static_cast<std::size_t>(walker.points()) * 3);
  walker.forEachPoint([&](const double* xyz) { mesh.points.insert(mesh.points.end(), xyz, xyz + 3); });
  return mesh;
}
} // namespace exporting
} // namespace blockforge
