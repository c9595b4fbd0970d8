#include "ExportModel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <map>
#include <stdexcept>

namespace blockforge
{
namespace exporting
{
namespace
{
std::array<int, 4> cornerIds(const model::BlockModel& model, model::BlockFace face)
{
  std::array<int, 4> ids{};
  const std::array<int, 4> corners = model::faceCorners(face.face);
  for (int c = 0; c < 4; ++c)
  {
    ids[c] = model.blocks[face.block].vertices[corners[c]];
  }
  return ids;
}

/// Corner (0..3, faceCorners order) that corner c lands on under `code`.
int mapCorner(int code, int c)
{
  static const int A[4] = { 0, 1, 1, 0 }, B[4] = { 0, 0, 1, 1 };
  const std::array<int, 2> at = mapFaceNode(code, A[c], B[c], 2, 2);
  for (int d = 0; d < 4; ++d)
  {
    if (A[d] == at[0] && B[d] == at[1])
    {
      return d;
    }
  }
  return -1;
}

bool countsFit(const std::array<int, 2>& from, const std::array<int, 2>& to, int code)
{
  const bool swap = (code & 4) != 0;
  return (swap ? from[1] : from[0]) == to[0] && (swap ? from[0] : from[1]) == to[1];
}

double modelSize(const model::BlockModel& model)
{
  Eigen::AlignedBox3d box;
  for (const model::Vertex& vertex : model.vertices)
  {
    box.extend(vertex.position);
  }
  return box.isEmpty() ? 1.0 : std::max(box.diagonal().norm(), 1e-300);
}
} // namespace

ExportGrid exportGrid(const model::BlockModel& model, std::vector<GridBlock> blocks)
{
  if (blocks.size() != model.blocks.size())
  {
    throw std::runtime_error("the grid has " + std::to_string(blocks.size()) +
      " blocks but its model '" + model.name + "' has " + std::to_string(model.blocks.size()));
  }
  ExportGrid grid;
  grid.name = model.name;
  grid.blocks = std::move(blocks);
  const int blockCount = static_cast<int>(model.blocks.size());
  grid.collapsedEdges.assign(blockCount, {});
  grid.collapsedFaces.assign(blockCount, {});
  for (int b = 0; b < blockCount; ++b)
  {
    const std::array<int, 8>& v = model.blocks[b].vertices;
    for (int e = 0; e < 12; ++e)
    {
      const std::array<int, 2> ends = model::edgeVertices(e);
      grid.collapsedEdges[b][e] = v[ends[0]] == v[ends[1]];
    }
    for (int f = 0; f < 6; ++f)
    {
      std::array<int, 4> ids = cornerIds(model, { b, f });
      std::sort(ids.begin(), ids.end());
      grid.collapsedFaces[b][f] = std::unique(ids.begin(), ids.end()) - ids.begin() < 3;
    }
  }
  // Interfaces: faces with the same corner vertices.
  std::map<std::array<int, 4>, model::BlockFace> owners;
  for (int b = 0; b < blockCount; ++b)
  {
    for (int f = 0; f < 6; ++f)
    {
      if (grid.collapsedFaces[b][f])
      {
        continue;
      }
      const std::array<int, 4> ids = cornerIds(model, { b, f });
      std::array<int, 4> key = ids;
      std::sort(key.begin(), key.end());
      const auto found = owners.find(key);
      if (found == owners.end())
      {
        owners.emplace(key, model::BlockFace{ b, f });
        continue;
      }
      const model::BlockFace owner = found->second;
      const std::array<int, 4> ownerIds = cornerIds(model, owner);
      const std::array<int, 2> n = faceNodeCounts(grid.blocks[b], f);
      const std::array<int, 2> m = faceNodeCounts(grid.blocks[owner.block], owner.face);
      bool matched = false;
      for (int code = 0; code < 8 && !matched; ++code)
      {
        bool same = countsFit(n, m, code);
        for (int c = 0; c < 4 && same; ++c)
        {
          same = ownerIds[mapCorner(code, c)] == ids[c];
        }
        if (same)
        {
          grid.interfaces.push_back(FaceMatch{ { b, f }, owner, code });
          matched = true;
        }
      }
      if (!matched)
      {
        throw std::runtime_error("block faces " + model.blocks[b].name + "." +
          model::faceName(f) + " and " + model.blocks[owner.block].name + "." +
          model::faceName(owner.face) + " share their corners but not their nodes");
      }
    }
  }
  // Patches; periodic faces matched to their partner's by rotating the corners.
  const double tolerance = 1e-9 * modelSize(model);
  for (const model::Patch& patch : model.patches)
  {
    GridPatch entry;
    entry.name = patch.name;
    entry.type = patch.type;
    entry.faces = patch.faces;
    grid.patches.push_back(entry);
  }
  for (std::size_t p = 0; p < model.patches.size(); ++p)
  {
    const model::Patch& patch = model.patches[p];
    if (patch.type != "periodic")
    {
      continue;
    }
    GridPatch& entry = grid.patches[p];
    for (std::size_t q = 0; q < model.patches.size(); ++q)
    {
      if (model.patches[q].name == patch.periodicPartner)
      {
        entry.partner = static_cast<int>(q);
      }
    }
    if (entry.partner < 0)
    {
      throw std::runtime_error("periodic patch '" + patch.name + "' has no partner");
    }
    entry.axis = patch.periodicAxis.normalized();
    entry.axisPoint = patch.periodicAxisPoint;
    entry.angle = patch.periodicAngle;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(patch.periodicAngle, entry.axis).toRotationMatrix();
    for (const model::BlockFace& face : patch.faces)
    {
      const std::array<int, 4> ids = cornerIds(model, face);
      const std::array<int, 2> n = faceNodeCounts(grid.blocks[face.block], face.face);
      bool found = false;
      for (const model::BlockFace& other : model.patches[entry.partner].faces)
      {
        const std::array<int, 4> otherIds = cornerIds(model, other);
        const std::array<int, 2> m = faceNodeCounts(grid.blocks[other.block], other.face);
        for (int code = 0; code < 8 && !found; ++code)
        {
          bool same = countsFit(n, m, code);
          for (int c = 0; c < 4 && same; ++c)
          {
            const Vec3 image = entry.axisPoint +
              rotation * (model.vertices[ids[c]].position - entry.axisPoint);
            same = (image - model.vertices[otherIds[mapCorner(code, c)]].position).norm() <= tolerance;
          }
          if (same)
          {
            entry.images.push_back(FaceMatch{ face, other, code });
            found = true;
          }
        }
        if (found)
        {
          break;
        }
      }
      if (!found)
      {
        throw std::runtime_error("face " + model.blocks[face.block].name + "." +
          model::faceName(face.face) + " of periodic patch '" + patch.name +
          "' does not land on a face of '" + patch.periodicPartner + "'");
      }
    }
  }
  return grid;
}
} // namespace exporting
} // namespace blockforge
