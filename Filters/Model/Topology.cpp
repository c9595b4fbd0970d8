#include "Topology.h"

#include "../Core/Carriers.h"
#include "ModelSyntax.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace blockforge
{
namespace model
{
namespace
{
using syntax::entity;
using syntax::shortNumber;

constexpr double Pi = 3.14159265358979323846;

[[noreturn]] void fail(
  const SourceLocation& where, const std::string& entityText, const std::string& what)
{
  throw TemplateError(where.file, where.line, entityText, what);
}

std::string blockEntity(const BlockModel& model, int block)
{
  return entity("block", model.blocks[block].name);
}

int distinctCount(std::array<int, 4> ids)
{
  std::sort(ids.begin(), ids.end());
  return static_cast<int>(std::unique(ids.begin(), ids.end()) - ids.begin());
}

int faceNodeCount(const BlockLinks& links, int face, int which)
{
  return links.nodes[faceDirections(face)[which]];
}

int findPatch(const BlockModel& model, const std::string& name)
{
  for (int p = 0; p < static_cast<int>(model.patches.size()); ++p)
  {
    if (model.patches[p].name == name)
    {
      return p;
    }
  }
  return -1;
}
} // namespace

double modelSize(const BlockModel& model)
{
  if (model.vertices.empty())
  {
    return 1.0;
  }
  Vec3 low = model.vertices[0].position, high = low;
  for (const Vertex& vertex : model.vertices)
  {
    low = low.cwiseMin(vertex.position);
    high = high.cwiseMax(vertex.position);
  }
  const double size = (high - low).norm();
  return size > 0.0 ? size : 1.0;
}

std::array<int, 4> faceVertexIds(const Block& block, int face)
{
  std::array<int, 4> ids{};
  const std::array<int, 4> corners = faceCorners(face);
  for (int c = 0; c < 4; ++c)
  {
    ids[c] = block.vertices[corners[c]];
  }
  return ids;
}

std::string blockFaceText(const BlockModel& model, int block, int face)
{
  return model.blocks[block].name + "." + faceName(face);
}

std::string edgeText(const BlockModel& model, int a, int b)
{
  const std::string ends = model.vertices[a].name + "-" + model.vertices[b].name;
  const int named = model.findEdge(a, b);
  return named >= 0 ? "'" + model.edges[named].name + "' (" + ends + ")" : ends;
}

std::vector<std::array<int, 3>> baseNodeCounts(const BlockModel& model)
{
  std::vector<std::array<int, 3>> nodes;
  for (const Block& block : model.blocks)
  {
    nodes.push_back({ block.cells[0] + 1, block.cells[1] + 1, block.cells[2] + 1 });
  }
  return nodes;
}

Topology buildConnectivity(const BlockModel& model, const std::vector<std::array<int, 3>>& nodes)
{
  Topology topology;
  const int blockCount = static_cast<int>(model.blocks.size());
  topology.blocks.resize(blockCount);
  topology.patchOfFace.assign(6 * static_cast<std::size_t>(blockCount), -1);
  std::map<std::pair<int, int>, int> edgeIndex;

  for (int b = 0; b < blockCount; ++b)
  {
    const Block& block = model.blocks[b];
    BlockLinks& links = topology.blocks[b];
    links.nodes = nodes[b];
    for (int e = 0; e < 12; ++e)
    {
      const std::array<int, 2> ends = edgeVertices(e);
      const int from = block.vertices[ends[0]], to = block.vertices[ends[1]];
      const int count = links.nodes[edgeDirection(e)];
      if (from == to)
      {
        links.edge[e] = -1;
        continue;
      }
      const std::pair<int, int> key(std::min(from, to), std::max(from, to));
      auto found = edgeIndex.find(key);
      if (found == edgeIndex.end())
      {
        TopologyEdge edge;
        edge.a = key.first;
        edge.b = key.second;
        edge.named = model.findEdge(edge.a, edge.b);
        edge.nodeCount = count;
        found = edgeIndex.emplace(key, static_cast<int>(topology.edges.size())).first;
        topology.edges.push_back(std::move(edge));
      }
      TopologyEdge& edge = topology.edges[found->second];
      if (edge.nodeCount != count)
      {
        const EdgeUse& first = edge.uses.front();
        fail(block.where, blockEntity(model, b),
          "edge " + edgeText(model, from, to) + " (" + syntax::edgeLabel(e) + ") has " +
            std::to_string(count - 1) + " cells here but " + std::to_string(edge.nodeCount - 1) +
            " in block '" + model.blocks[first.block].name + "' (" +
            syntax::edgeLabel(first.localEdge) +
            "); blocks sharing an edge need the same cell count along it");
      }
      edge.uses.push_back(EdgeUse{ b, e, from > to });
      links.edge[e] = found->second;
      links.reversed[e] = from > to;
    }
  }

  std::map<std::array<int, 4>, int> faceIndex;
  for (int b = 0; b < blockCount; ++b)
  {
    const Block& block = model.blocks[b];
    BlockLinks& links = topology.blocks[b];
    for (int f = 0; f < 6; ++f)
    {
      const std::array<int, 4> ids = faceVertexIds(block, f);
      links.face[f] = -1;
      if (distinctCount(ids) < 3)
      {
        continue;
      }
      std::array<int, 4> key = ids;
      std::sort(key.begin(), key.end());
      auto found = faceIndex.find(key);
      const int na = faceNodeCount(links, f, 0), nb = faceNodeCount(links, f, 1);
      if (found == faceIndex.end())
      {
        TopologyFace face;
        face.ownerIds = ids;
        face.na = na;
        face.nb = nb;
        face.uses.push_back(FaceUse{ b, f, FaceTransform{ 0 } });
        faceIndex.emplace(key, static_cast<int>(topology.faces.size()));
        links.face[f] = static_cast<int>(topology.faces.size());
        topology.faces.push_back(std::move(face));
        continue;
      }
      TopologyFace& face = topology.faces[found->second];
      const FaceUse& owner = face.uses.front();
      if (face.uses.size() >= 2)
      {
        std::string blocks;
        for (const FaceUse& use : face.uses)
        {
          blocks += blockFaceText(model, use.block, use.face) + ", ";
        }
        fail(block.where, blockEntity(model, b),
          "face " + blockFaceText(model, b, f) + " is also a face of " + blocks +
            "but a face can join at most two blocks");
      }
      bool matched = false;
      for (int code = 0; code < 8 && !matched; ++code)
      {
        const FaceTransform transform{ code };
        bool same = true;
        for (int c = 0; c < 4 && same; ++c)
        {
          same = face.ownerIds[transform.mapCorner(c)] == ids[c];
        }
        const int mappedA = transform.swap() ? nb : na;
        const int mappedB = transform.swap() ? na : nb;
        if (same && mappedA == face.na && mappedB == face.nb)
        {
          face.uses.push_back(FaceUse{ b, f, transform });
          links.face[f] = found->second;
          links.transform[f] = transform;
          matched = true;
        }
      }
      if (!matched)
      {
        fail(block.where, blockEntity(model, b),
          "face " + blockFaceText(model, b, f) + " has the same vertices as face " +
            blockFaceText(model, owner.block, owner.face) +
            " but the two do not match edge for edge (or differ in node counts); check the "
            "vertex order of both blocks");
      }
    }
  }
  return topology;
}

void checkPatches(const BlockModel& model, Topology& topology)
{
  const int blockCount = static_cast<int>(model.blocks.size());
  topology.patchOfFace.assign(6 * static_cast<std::size_t>(blockCount), -1);
  for (int p = 0; p < static_cast<int>(model.patches.size()); ++p)
  {
    const Patch& patch = model.patches[p];
    const std::string entityText = entity("patch", patch.name);
    for (const BlockFace& face : patch.faces)
    {
      if (face.block < 0 || face.block >= blockCount || face.face < 0 || face.face > 5)
      {
        fail(patch.where, entityText, "refers to a face that does not exist");
      }
      const std::string name = blockFaceText(model, face.block, face.face);
      const int unique = topology.blocks[face.block].face[face.face];
      if (unique < 0)
      {
        fail(patch.where, entityText,
          "face " + name + " is collapsed to a line or a point and cannot be a patch face");
      }
      const std::vector<FaceUse>& uses = topology.faces[unique].uses;
      if (uses.size() > 1)
      {
        const FaceUse& other =
          uses[0].block == face.block && uses[0].face == face.face ? uses[1] : uses[0];
        fail(patch.where, entityText,
          "face " + name + " is internal (it is also face " +
            blockFaceText(model, other.block, other.face) +
            "); patch faces must lie on the domain boundary");
      }
      int& patchOf = topology.patchOfFace[6 * face.block + face.face];
      if (patchOf >= 0)
      {
        fail(patch.where, entityText,
          patchOf == p ? "face " + name + " is listed twice"
                       : "face " + name + " is already in patch '" +
              model.patches[patchOf].name + "'; a face belongs to at most one patch");
      }
      patchOf = p;
    }
  }

  const double tolerance = 1e-9 * modelSize(model);
  for (const Patch& patch : model.patches)
  {
    if (patch.type != "periodic")
    {
      continue;
    }
    const std::string entityText = entity("patch", patch.name);
    const int partnerIndex = patch.periodicPartner.empty() ? -1 : findPatch(model, patch.periodicPartner);
    if (partnerIndex < 0)
    {
      fail(patch.where, entityText,
        patch.periodicPartner.empty()
          ? std::string("a periodic patch needs a partner")
          : "periodic partner '" + patch.periodicPartner + "' does not exist");
    }
    const Patch& partner = model.patches[partnerIndex];
    if (partner.type != "periodic" || partner.periodicPartner != patch.name)
    {
      fail(patch.where, entityText,
        "periodic partner '" + partner.name + "' must be periodic and name '" + patch.name +
          "' as its partner");
    }
    if (!patch.periodicAxis.allFinite() || !(patch.periodicAxis.norm() > 0.0) ||
      !patch.periodicAxisPoint.allFinite() || !std::isfinite(patch.periodicAngle))
    {
      fail(patch.where, entityText, "the periodic rotation (axis, origin, angle) is invalid");
    }
    if (partner.faces.size() != patch.faces.size())
    {
      fail(patch.where, entityText,
        "has " + std::to_string(patch.faces.size()) + " faces but its periodic partner '" +
          partner.name + "' has " + std::to_string(partner.faces.size()));
    }
    const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(patch.periodicAngle, patch.periodicAxis.normalized()).toRotationMatrix();
    std::vector<bool> taken(partner.faces.size(), false);
    for (const BlockFace& face : patch.faces)
    {
      const std::array<int, 4> ids = faceVertexIds(model.blocks[face.block], face.face);
      std::array<Vec3, 4> image;
      for (int c = 0; c < 4; ++c)
      {
        image[c] = patch.periodicAxisPoint +
          rotation * (model.vertices[ids[c]].position - patch.periodicAxisPoint);
      }
      const TopologyFace& grid = topology.faces[topology.blocks[face.block].face[face.face]];
      int match = -1;
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t q = 0; q < partner.faces.size() && match < 0; ++q)
      {
        const BlockFace& candidate = partner.faces[q];
        const std::array<int, 4> other =
          faceVertexIds(model.blocks[candidate.block], candidate.face);
        double worst = 0.0;
        for (int c = 0; c < 4; ++c)
        {
          double best = std::numeric_limits<double>::infinity();
          for (int d = 0; d < 4; ++d)
          {
            best = std::min(best, (image[c] - model.vertices[other[d]].position).norm());
          }
          worst = std::max(worst, best);
        }
        nearest = std::min(nearest, worst);
        if (worst <= tolerance && !taken[q])
        {
          match = static_cast<int>(q);
        }
      }
      const std::string name = blockFaceText(model, face.block, face.face);
      if (match < 0)
      {
        fail(patch.where, entityText,
          "face " + name + " rotated by " + shortNumber(patch.periodicAngle * 180.0 / Pi) +
            " deg does not land on a face of periodic partner '" + partner.name +
            "' (nearest miss " + shortNumber(nearest) + "); check axis, origin and angle");
      }
      taken[match] = true;
      const BlockFace& imageFace = partner.faces[match];
      const TopologyFace& other =
        topology.faces[topology.blocks[imageFace.block].face[imageFace.face]];
      if (std::min(grid.na, grid.nb) != std::min(other.na, other.nb) ||
        std::max(grid.na, grid.nb) != std::max(other.na, other.nb))
      {
        fail(patch.where, entityText,
          "face " + name + " has " + std::to_string(grid.na - 1) + " x " +
            std::to_string(grid.nb - 1) + " cells but its periodic image " +
            blockFaceText(model, imageFace.block, imageFace.face) + " has " +
            std::to_string(other.na - 1) + " x " + std::to_string(other.nb - 1));
      }
    }
  }
}

void findPeriodicPairs(const BlockModel& model, Topology& topology)
{
  topology.periodic.clear();
  const double tolerance = 1e-9 * modelSize(model);
  const int count = static_cast<int>(model.patches.size());
  for (int p = 0; p < count; ++p)
  {
    const Patch& patch = model.patches[p];
    if (patch.type != "periodic")
    {
      continue;
    }
    const int partner = findPatch(model, patch.periodicPartner);
    if (partner <= p)
    {
      continue; // the pair is handled from its first patch
    }
    const std::string entityText = entity("patch", model.patches[partner].name);
    for (const BlockFace& face : patch.faces)
    {
      const int source = topology.blocks[face.block].face[face.face];
      const TopologyFace& from = topology.faces[source];
      std::array<Vec3, 4> rotated;
      for (int c = 0; c < 4; ++c)
      {
        rotated[c] = rotateAboutAxis(model.vertices[from.ownerIds[c]].position,
          patch.periodicAxisPoint, patch.periodicAxis.normalized(), patch.periodicAngle);
      }
      bool found = false;
      for (const BlockFace& other : model.patches[partner].faces)
      {
        const int image = topology.blocks[other.block].face[other.face];
        const TopologyFace& to = topology.faces[image];
        for (int code = 0; code < 8 && !found; ++code)
        {
          const FaceTransform transform{ code };
          bool same = true;
          for (int c = 0; c < 4 && same; ++c)
          {
            same = (rotated[transform.mapCorner(c)] - model.vertices[to.ownerIds[c]].position)
                     .norm() <= tolerance;
          }
          const int mappedA = transform.swap() ? to.nb : to.na;
          const int mappedB = transform.swap() ? to.na : to.nb;
          if (same && mappedA == from.na && mappedB == from.nb)
          {
            PeriodicPair entry;
            entry.source = source;
            entry.image = image;
            entry.sourceFace = face;
            entry.imageFace = other;
            entry.transform = transform;
            entry.axisPoint = patch.periodicAxisPoint;
            entry.axis = patch.periodicAxis.normalized();
            entry.angle = patch.periodicAngle;
            entry.patch = p;
            entry.partner = partner;
            topology.periodic.push_back(entry);
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
        fail(model.patches[partner].where, entityText,
          "no face matches the rotation of face " + blockFaceText(model, face.block, face.face) +
            " of periodic partner '" + patch.name + "' node for node");
      }
    }
  }
}

Topology buildTopology(const BlockModel& model, const std::vector<std::array<int, 3>>& nodes)
{
  Topology topology = buildConnectivity(model, nodes);
  checkPatches(model, topology);
  findPeriodicPairs(model, topology);
  return topology;
}

Topology buildTopology(const BlockModel& model)
{
  return buildTopology(model, baseNodeCounts(model));
}

std::vector<Interface> Topology::interfaces() const
{
  std::vector<Interface> result;
  for (const TopologyFace& face : faces)
  {
    if (face.isInterface())
    {
      const FaceUse& first = face.uses[0];
      const FaceUse& second = face.uses[1];
      result.push_back(Interface{ BlockFace{ first.block, first.face },
        BlockFace{ second.block, second.face }, second.transform });
    }
  }
  return result;
}

std::vector<PeriodicSideLink> Topology::periodicSideLinks() const
{
  std::vector<PeriodicSideLink> links;
  for (const PeriodicPair& pair : periodic)
  {
    PeriodicSideLink link;
    link.sourceBlock = pair.sourceFace.block;
    link.sourceSide = pair.sourceFace.face;
    link.imageBlock = pair.imageFace.block;
    link.imageSide = pair.imageFace.face;
    link.transform = pair.transform;
    link.origin = pair.axisPoint;
    link.rotation = Eigen::AngleAxisd(pair.angle, pair.axis).toRotationMatrix();
    links.push_back(link);
  }
  return links;
}
} // namespace model
} // namespace blockforge
