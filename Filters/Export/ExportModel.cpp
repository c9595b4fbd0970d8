#include "ExportModel.h"

#include "Topology.h"

#include <stdexcept>

namespace blockforge
{
namespace exporting
{
ExportGrid exportGrid(const model::BlockModel& model, std::vector<GridBlock> blocks)
{
  if (blocks.size() != model.blocks.size())
  {
    throw std::runtime_error("the grid has " + std::to_string(blocks.size()) +
      " blocks but its model '" + model.name + "' has " + std::to_string(model.blocks.size()));
  }
  std::vector<std::array<int, 3>> nodes;
  for (const GridBlock& block : blocks)
  {
    nodes.push_back(block.nodes);
  }
  // The model's connectivity at the grid's node counts (checks that they fit).
  const model::Topology topology = model::buildTopology(model, nodes);

  ExportGrid grid;
  grid.name = model.name;
  grid.blocks = std::move(blocks);
  const std::size_t blockCount = model.blocks.size();
  grid.collapsedEdges.assign(blockCount, {});
  grid.collapsedFaces.assign(blockCount, {});
  for (std::size_t b = 0; b < blockCount; ++b)
  {
    const model::BlockLinks& links = topology.blocks[b];
    for (int e = 0; e < 12; ++e)
    {
      grid.collapsedEdges[b][e] = links.edge[e] < 0;
    }
    for (int f = 0; f < 6; ++f)
    {
      grid.collapsedFaces[b][f] = links.face[f] < 0;
    }
  }
  for (const model::Interface& link : topology.interfaces())
  {
    grid.interfaces.push_back(FaceMatch{ link.second, link.first, link.transform });
  }
  for (const model::Patch& patch : model.patches)
  {
    GridPatch entry;
    entry.name = patch.name;
    entry.type = patch.type;
    entry.faces = patch.faces;
    grid.patches.push_back(entry);
  }
  // Periodic pairs: `transform` maps the image face's (a, b) to the source face's.
  for (const model::PeriodicPair& pair : topology.periodic)
  {
    GridPatch& source = grid.patches[pair.patch];
    GridPatch& image = grid.patches[pair.partner];
    source.partner = pair.partner;
    image.partner = pair.patch;
    source.images.push_back(FaceMatch{ pair.sourceFace, pair.imageFace, inverse(pair.transform) });
    image.images.push_back(FaceMatch{ pair.imageFace, pair.sourceFace, pair.transform });
    source.axis = image.axis = pair.axis;
    source.axisPoint = image.axisPoint = pair.axisPoint;
    source.angle = pair.angle;
    image.angle = -pair.angle;
  }
  return grid;
}
} // namespace exporting
} // namespace blockforge
