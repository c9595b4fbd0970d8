/**
 * @file TestPassageGeometry.h
 * @brief What the blade-passage tests measure on a meshed grid, independently of the
 * mesher: distances to surface carriers, block face nodes, cell volumes, and the size ratio of neighbour cells across
 * block interfaces (periodic ones included). Header-only; for tests that link
 * BlockForgeModel.
 */
#pragma once

#include "CarrierGeometry.h"
#include "TestHelpers.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

namespace blockforge
{
namespace test
{
/// Distance from p to the surface carrier: the carrier's projection, and when that lands
/// far off (on the other side of a thin edge, from a coarse sample), local Gauss-Newton
/// searches started around it and across the section loop.
inline double surfaceDistance(const model::CarrierGeometry& geometry, int carrier, const Vec3& p)
{
  double s = 0.0, t = 0.0, d = 0.0;
  geometry.project(carrier, p, s, t, d);
  if (d < 1e-12 * geometry.size(carrier))
    return d;
  for (double start : { s - 0.05, s - 0.02, s - 0.01, s + 0.01, s + 0.02, s + 0.05, 1.5 - s, 0.5 - s })
  {
    double u = start, v = t;
    for (int iteration = 0; iteration < 40; ++iteration)
    {
      const double h = 1e-7;
      const Vec3 q = geometry.point(carrier, u, v);
      const Vec3 qs = (geometry.point(carrier, u + h, v) - geometry.point(carrier, u - h, v)) / (2 * h);
      const Vec3 qt = (geometry.point(carrier, u, v + h) - geometry.point(carrier, u, v - h)) / (2 * h);
      const Vec3 r = p - q;
      const double a = qs.dot(qs), b = qs.dot(qt), e = qt.dot(qt), det = a * e - b * b;
      if (!(det > 0.0))
        break;
      double du = (e * qs.dot(r) - b * qt.dot(r)) / det, dv = (a * qt.dot(r) - b * qs.dot(r)) / det;
      const double step = std::max(std::abs(du), std::abs(dv));
      if (step > 0.01)
      {
        du *= 0.01 / step;
        dv *= 0.01 / step;
      }
      u += du;
      v = std::clamp(v + dv, geometry.tMin(carrier), geometry.tMax(carrier));
      if (step < 1e-14)
        break;
    }
    d = std::min(d, (geometry.point(carrier, u, v) - p).norm());
  }
  return d;
}

/// The nodes of one block face (0..5 = i0 i1 j0 j1 k0 k1).
inline std::vector<Vec3> faceNodes(const Grid& grid, const model::BlockFace& face)
{
  const auto& n = grid.nodes[face.block];
  std::vector<Vec3> result;
  const int axis = face.face / 2;
  const int fixed = face.face % 2 == 0 ? 0 : n[axis] - 1;
  const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
  for (int v = 0; v < n[b]; ++v)
  {
    for (int u = 0; u < n[a]; ++u)
    {
      std::array<int, 3> ijk{};
      ijk[axis] = fixed;
      ijk[a] = u;
      ijk[b] = v;
      result.push_back(grid.at(face.block, ijk[0], ijk[1], ijk[2]));
    }
  }
  return result;
}

inline double tetVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// Volume of a hexahedron (VTK order) with possibly warped faces: every face is split
/// into four triangles about its centre, each joined to the cell centre.
inline double hexVolume(const std::array<Vec3, 8>& p)
{
  static const int faces[6][4] = { { 0, 3, 2, 1 }, { 4, 5, 6, 7 }, { 0, 1, 5, 4 },
    { 1, 2, 6, 5 }, { 2, 3, 7, 6 }, { 3, 0, 4, 7 } };
  Vec3 centre = Vec3::Zero();
  for (const Vec3& q : p)
  {
    centre += q / 8.0;
  }
  double volume = 0.0;
  for (const auto& f : faces)
  {
    const Vec3 fc = (p[f[0]] + p[f[1]] + p[f[2]] + p[f[3]]) / 4.0;
    for (int e = 0; e < 4; ++e)
    {
      // faces listed with outward normals by the right-hand rule
      volume += tetVolume(centre, fc, p[f[e]], p[f[(e + 1) % 4]]);
    }
  }
  return volume;
}

inline double gridVolume(const Grid& grid)
{
  double total = 0.0;
  for (std::size_t b = 0; b < grid.nodes.size(); ++b)
  {
    const auto& n = grid.nodes[b];
    const int B = static_cast<int>(b);
    for (int k = 0; k + 1 < n[2]; ++k)
      for (int j = 0; j + 1 < n[1]; ++j)
        for (int i = 0; i + 1 < n[0]; ++i)
        {
          total += hexVolume({ grid.at(B, i, j, k), grid.at(B, i + 1, j, k),
            grid.at(B, i + 1, j + 1, k), grid.at(B, i, j + 1, k), grid.at(B, i, j, k + 1),
            grid.at(B, i + 1, j, k + 1), grid.at(B, i + 1, j + 1, k + 1),
            grid.at(B, i, j + 1, k + 1) });
        }
  }
  return total;
}

/// The largest size ratio of neighbour cells across block interfaces, and where.
struct NeighbourRatio
{
  double ratio = 1.0;       ///< max over interface faces of larger / smaller cell width
  std::string where;        ///< "block a face / block b face"
  std::size_t pairs = 0;    ///< interface face pairs measured
};

/**
 * The measure of the cell size jump across block interfaces: for every cell face on a
 * block boundary that another block's cell face covers (the same four nodes, or their
 * images one pitch further about `axis` through the origin for periodic sides), the width
 * of each of the two cells across that face (the distance between the centre of the shared
 * face and the centre of the cell's opposite face), and the ratio of the larger to the
 * smaller. This is what makes checkMesh's interpolation weights small (weight = smaller /
 * (sum) = 1 / (1 + ratio)) and its volume ratios far from 1 at block interfaces.
 */
inline NeighbourRatio neighbourSizeRatio(const Grid& grid, const model::BlockModel& model,
  const Vec3& axis, double pitch, double size)
{
  struct FaceCell
  {
    Vec3 centre;
    double width;
    int block, face;
  };
  std::vector<FaceCell> cells;
  for (int b = 0; b < static_cast<int>(grid.nodes.size()); ++b)
  {
    const auto& n = grid.nodes[b];
    for (int f = 0; f < 6; ++f)
    {
      const int d = f / 2, a = d == 0 ? 1 : 0, c = d == 2 ? 1 : 2;
      const int fixed = f % 2 == 0 ? 0 : n[d] - 1, inner = f % 2 == 0 ? 1 : n[d] - 2;
      if (n[d] < 2)
        continue;
      for (int v = 0; v + 1 < n[c]; ++v)
        for (int u = 0; u + 1 < n[a]; ++u)
        {
          auto quad = [&](int level) {
            Vec3 sum = Vec3::Zero();
            for (int du = 0; du < 2; ++du)
              for (int dv = 0; dv < 2; ++dv)
              {
                std::array<int, 3> ijk{};
                ijk[d] = level;
                ijk[a] = u + du;
                ijk[c] = v + dv;
                sum += grid.at(b, ijk[0], ijk[1], ijk[2]);
              }
            return Vec3(sum / 4.0);
          };
          const Vec3 centre = quad(fixed);
          cells.push_back({ centre, (quad(inner) - centre).norm(), b, f });
        }
    }
  }
  const double cell = 1e-6 * size;
  auto key = [cell](const Vec3& p) {
    return std::make_tuple(static_cast<long long>(std::floor(p.x() / cell)),
      static_cast<long long>(std::floor(p.y() / cell)),
      static_cast<long long>(std::floor(p.z() / cell)));
  };
  std::map<std::tuple<long long, long long, long long>, std::vector<int>> buckets;
  for (int k = 0; k < static_cast<int>(cells.size()); ++k)
  {
    buckets[key(cells[k].centre)].push_back(k);
  }
  auto findAt = [&](const Vec3& p, int self) {
    const auto base = key(p);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz)
        {
          const auto found = buckets.find(std::make_tuple(
            std::get<0>(base) + dx, std::get<1>(base) + dy, std::get<2>(base) + dz));
          if (found == buckets.end())
            continue;
          for (int other : found->second)
          {
            if (other != self &&
              (cells[other].block != cells[self].block || cells[other].face != cells[self].face) &&
              (cells[other].centre - p).norm() < 1e-6 * size)
            {
              return other;
            }
          }
        }
    return -1;
  };
  const Eigen::AngleAxisd rotation(pitch, axis.normalized());
  NeighbourRatio result;
  for (int k = 0; k < static_cast<int>(cells.size()); ++k)
  {
    for (const Vec3& p : { cells[k].centre, Vec3(rotation * cells[k].centre) })
    {
      const int other = findAt(p, k);
      if (other < 0 || (p == cells[k].centre && other < k))
        continue;
      ++result.pairs;
      const double a = cells[k].width, b = cells[other].width;
      const double ratio = std::max(a, b) / std::max(std::min(a, b), 1e-300);
      if (ratio > result.ratio)
      {
        result.ratio = ratio;
        result.where = model.blocks[cells[k].block].name + "." + model::faceName(cells[k].face) +
          " / " + model.blocks[cells[other].block].name + "." +
          model::faceName(cells[other].face);
      }
    }
  }
  return result;
}
/**
 * The largest ratio of neighbour cell lengths along a grid line inside any block (the
 * expansion ratio of the distributions as meshed): for every pair of consecutive cell
 * edges along i, j or k, the longer over the shorter.
 */
inline double maxExpansionInBlocks(const Grid& grid)
{
  double worst = 1.0;
  for (int b = 0; b < static_cast<int>(grid.nodes.size()); ++b)
  {
    const auto& n = grid.nodes[b];
    for (int d = 0; d < 3; ++d)
    {
      std::array<int, 3> ijk{};
      for (ijk[2] = 0; ijk[2] < n[2]; ++ijk[2])
        for (ijk[1] = 0; ijk[1] < n[1]; ++ijk[1])
          for (ijk[0] = 0; ijk[0] < n[0]; ++ijk[0])
          {
            if (ijk[d] + 2 >= n[d])
              continue;
            std::array<int, 3> q1 = ijk, q2 = ijk;
            q1[d] += 1;
            q2[d] += 2;
            const Vec3 p0 = grid.at(b, ijk[0], ijk[1], ijk[2]);
            const Vec3 p1 = grid.at(b, q1[0], q1[1], q1[2]);
            const Vec3 p2 = grid.at(b, q2[0], q2[1], q2[2]);
            const double a = (p1 - p0).norm(), c = (p2 - p1).norm();
            const double r = std::max(a, c) / std::max(std::min(a, c), 1e-300);
            worst = std::max(worst, r);
          }
    }
  }
  return worst;
}
} // namespace test
} // namespace blockforge
