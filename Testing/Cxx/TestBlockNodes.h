/**
 * @file TestBlockNodes.h
 * @brief Nodes of one structured block built from a function of the node indices, for
 * tests of the cell measures (Core Quality, the optimizer's objective) that need no block
 * model. Core types only.
 */
#pragma once

#include "Quality.h"

#include <functional>
#include <vector>

namespace blockforge
{
namespace test
{
/// Nodes of a structured block, i fastest, then j, then k (the mesher's order).
struct BlockNodes
{
  int ni, nj, nk;
  std::vector<double> xyz;
  StructuredBlock block() const { return { xyz.data(), ni, nj, nk }; }
  Vec3 node(int i, int j, int k) const
  {
    const long n = i + static_cast<long>(ni) * (j + static_cast<long>(nj) * k);
    return Vec3(xyz[3 * n], xyz[3 * n + 1], xyz[3 * n + 2]);
  }
};

/// The block of ni x nj x nk nodes whose node (i, j, k) is at(i, j, k).
inline BlockNodes makeBlockNodes(
  int ni, int nj, int nk, const std::function<Vec3(int, int, int)>& at)
{
  BlockNodes g{ ni, nj, nk, {} };
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i)
      {
        const Vec3 p = at(i, j, k);
        g.xyz.insert(g.xyz.end(), { p.x(), p.y(), p.z() });
      }
  return g;
}
} // namespace test
} // namespace blockforge
