#include "ExportGrid.h"

namespace blockforge
{
namespace exporting
{
std::array<int, 2> faceNodeCounts(const GridBlock& block, int face)
{
  const std::array<int, 2> directions = model::faceDirections(face);
  return { block.nodes[directions[0]], block.nodes[directions[1]] };
}

long long faceNode(const GridBlock& block, int face, int a, int b)
{
  const std::array<int, 2> directions = model::faceDirections(face);
  std::array<long long, 3> index{ 0, 0, 0 };
  const int normal = face / 2;
  index[normal] = face % 2 == 0 ? 0 : block.nodes[normal] - 1;
  index[directions[0]] = a;
  index[directions[1]] = b;
  return index[0] + block.nodes[0] * (index[1] + static_cast<long long>(block.nodes[1]) * index[2]);
}

std::array<int, 2> mapFaceNode(FaceTransform transform, int a, int b, int toA, int toB)
{
  std::array<int, 2> out{};
  transform.map(a, b, toA, toB, out[0], out[1]);
  return out;
}

FaceTransform inverse(FaceTransform transform)
{
  // Without a swap, reversing a and b undoes itself; with a swap, the reversal of the
  // target's a is the reversal of the source's b and the other way round.
  const int code = transform.code;
  if ((code & 4) == 0)
  {
    return transform;
  }
  return FaceTransform{ 4 | ((code & 1) << 1) | ((code & 2) >> 1) };
}

long long ExportGrid::cellCount() const
{
  long long count = 0;
  for (const GridBlock& block : blocks)
  {
    count += block.cellCount();
  }
  return count;
}

long long ExportGrid::nodeCount() const
{
  long long count = 0;
  for (const GridBlock& block : blocks)
  {
    count += block.nodeCount();
  }
  return count;
}
} // namespace exporting
} // namespace blockforge
