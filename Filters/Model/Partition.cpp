#include "Partition.h"

#include <algorithm>
#include <map>

namespace blockforge
{
namespace model
{
QualityNeighbours qualityNeighbours(const Topology& topology, const std::vector<int>& subset)
{
  std::map<int, int> position; // model block -> index in the subset
  for (std::size_t n = 0; n < subset.size(); ++n)
  {
    position.emplace(subset[n], static_cast<int>(n));
  }
  auto inSubset = [&](int block) { return position.count(block) > 0; };

  // Far sides of interfaces and periodic pairs that cross the subset's border.
  std::vector<std::pair<int, int>> needed;
  auto need = [&](const BlockFace& here, const BlockFace& there)
  {
    if (inSubset(here.block) && !inSubset(there.block))
    {
      needed.emplace_back(there.block, there.face);
    }
  };
  for (const Interface& interface : topology.interfaces())
  {
    need(interface.first, interface.second);
    need(interface.second, interface.first);
  }
  for (const PeriodicPair& pair : topology.periodic)
  {
    need(pair.sourceFace, pair.imageFace);
    need(pair.imageFace, pair.sourceFace);
  }
  std::sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end()), needed.end());

  QualityNeighbours result;
  std::map<std::pair<int, int>, int> layerIndex;
  for (const auto& side : needed)
  {
    layerIndex[side] = static_cast<int>(subset.size() + result.layers.size());
    result.layers.push_back(BlockFace{ side.first, side.second });
  }
  auto renumber = [&](int block, int side) -> int
  {
    const auto local = position.find(block);
    if (local != position.end())
    {
      return local->second;
    }
    const auto layer = layerIndex.find({ block, side });
    return layer != layerIndex.end() ? layer->second : -1;
  };
  for (PeriodicSideLink link : topology.periodicSideLinks())
  {
    if (!inSubset(link.sourceBlock) && !inSubset(link.imageBlock))
    {
      continue;
    }
    link.sourceBlock = renumber(link.sourceBlock, link.sourceSide);
    link.imageBlock = renumber(link.imageBlock, link.imageSide);
    result.links.push_back(link);
  }
  return result;
}

std::vector<int> balancedPieces(const std::vector<std::array<int, 3>>& nodeCounts, int pieceCount)
{
  const int blocks = static_cast<int>(nodeCounts.size());
  std::vector<int> piece(blocks, 0);
  if (pieceCount <= 1)
  {
    return piece;
  }
  std::vector<long long> cells(blocks);
  for (int b = 0; b < blocks; ++b)
  {
    cells[b] = 1;
    for (int n : nodeCounts[b])
    {
      cells[b] *= std::max(n - 1, 1);
    }
  }
  std::vector<int> order(blocks);
  for (int b = 0; b < blocks; ++b)
  {
    order[b] = b;
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return cells[a] > cells[b]; });
  std::vector<long long> load(pieceCount, 0);
  for (int b : order)
  {
    const int lightest = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    piece[b] = lightest;
    load[lightest] += cells[b];
  }
  return piece;
}
} // namespace model
} // namespace blockforge
