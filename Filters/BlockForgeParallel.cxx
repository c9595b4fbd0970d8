#include "BlockForgeParallel.h"

#include "BlockForgeModelIO.h"

#include "../Core/Parallel.h"
#include "../Model/ModelDocument.h"
#include "../Model/Partition.h"
#include "../Model/Topology.h"

#include <vtkMultiProcessController.h>
#include <vtkSMPTools.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <set>

namespace blockforge
{
namespace vtkglue
{
void useSMPTools()
{
  static std::once_flag installed;
  std::call_once(installed,
    []
    {
      // Debian's ParaView 5.11 has the STDThread backend built in but starts on the
      // Sequential one: turn threads on, unless the user chose a backend.
      const char* chosen = std::getenv("VTK_SMP_BACKEND_IN_USE");
      if ((!chosen || !*chosen) && std::string(vtkSMPTools::GetBackend()) == "Sequential")
      {
        vtkSMPTools::SetBackend("STDThread");
      }
      vtkSMPTools::Initialize();
      const int threads = vtkSMPTools::GetEstimatedNumberOfThreads();
      if (threads <= 1)
      {
        return; // sequential backend or one thread: the core's default
      }
      setChunkRunner(
        [](long count, const std::function<void(long, long)>& body)
        {
          vtkSMPTools::For(0, static_cast<vtkIdType>(count), 1,
            [&body](vtkIdType begin, vtkIdType end) { body(begin, end); });
        },
        threads);
    });
}

namespace
{
/// Header of one layer in the exchange buffer: model block, side, node counts.
constexpr int headerSize = 5;

/// The model blocks of the measured grids, by name, in `subset`; false when a grid has
/// no model block or two grids have the same.
bool findModelBlocks(const model::BlockModel& blockModel, const std::vector<std::string>& names,
  std::vector<int>& subset)
{
  std::map<std::string, int> byName;
  for (std::size_t b = 0; b < blockModel.blocks.size(); ++b)
  {
    if (!byName.emplace(blockModel.blocks[b].name, static_cast<int>(b)).second)
    {
      return false;
    }
  }
  subset.clear();
  std::set<int> seen;
  for (const std::string& name : names)
  {
    const auto found = byName.find(name);
    if (found == byName.end() || !seen.insert(found->second).second)
    {
      return false;
    }
    subset.push_back(found->second);
  }
  return true;
}

/**
 * Sends every layer that another rank needs from this one and receives those this rank
 * needs (one all-gather: every rank sees every layer sent, which for the few ranks of a
 * workstation is as cheap as point to point and cannot deadlock). Returns the received
 * layers by (model block, side).
 */
std::map<std::pair<int, int>, std::pair<std::array<int, 3>, std::vector<double>>> exchangeLayers(
  vtkMultiProcessController* controller, const model::Topology& topology,
  const std::vector<int>& owner, const std::vector<int>& subset,
  const std::vector<StructuredBlock>& blocks, const std::set<std::pair<int, int>>& wanted)
{
  const int ranks = controller->GetNumberOfProcesses();
  const int rank = controller->GetLocalProcessId();
  std::map<int, int> localIndex;
  for (std::size_t n = 0; n < subset.size(); ++n)
  {
    localIndex[subset[n]] = static_cast<int>(n);
  }
  // What the other ranks need from this one.
  std::set<std::pair<int, int>> toSend;
  for (int other = 0; other < ranks; ++other)
  {
    if (other == rank)
    {
      continue;
    }
    std::vector<int> theirs;
    for (std::size_t b = 0; b < owner.size(); ++b)
    {
      if (owner[b] == other)
      {
        theirs.push_back(static_cast<int>(b));
      }
    }
    for (const model::BlockFace& side : model::qualityNeighbours(topology, theirs).layers)
    {
      if (localIndex.count(side.block))
      {
        toSend.emplace(side.block, side.face);
      }
    }
  }
  std::vector<double> buffer;
  std::vector<double> nodes;
  for (const auto& side : toSend)
  {
    const StructuredBlock& block = blocks[localIndex[side.first]];
    const StructuredBlock layer = sideLayer(block, side.second, nodes);
    buffer.insert(buffer.end(), { static_cast<double>(side.first),
                                  static_cast<double>(side.second), static_cast<double>(layer.ni),
                                  static_cast<double>(layer.nj), static_cast<double>(layer.nk) });
    buffer.insert(buffer.end(), nodes.begin(), nodes.end());
  }
  const vtkIdType length = static_cast<vtkIdType>(buffer.size());
  std::vector<vtkIdType> lengths(ranks), offsets(ranks);
  controller->AllGather(&length, lengths.data(), 1);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r] = total;
    total += lengths[r];
  }
  std::vector<double> received(static_cast<std::size_t>(std::max<vtkIdType>(total, 1)));
  controller->AllGatherV(buffer.data(), received.data(), length, lengths.data(), offsets.data());

  std::map<std::pair<int, int>, std::pair<std::array<int, 3>, std::vector<double>>> layers;
  for (int r = 0; r < ranks; ++r)
  {
    vtkIdType at = offsets[r];
    const vtkIdType end = offsets[r] + lengths[r];
    while (at + headerSize <= end)
    {
      const double* header = &received[at];
      const std::pair<int, int> key(static_cast<int>(header[0]), static_cast<int>(header[1]));
      const std::array<int, 3> counts = { static_cast<int>(header[2]), static_cast<int>(header[3]),
        static_cast<int>(header[4]) };
      const vtkIdType size = 3 * static_cast<vtkIdType>(counts[0]) * counts[1] * counts[2];
      at += headerSize;
      if (r != rank && wanted.count(key) && at + size <= end)
      {
        layers[key] = { counts, std::vector<double>(&received[at], &received[at] + size) };
      }
      at += size;
    }
  }
  return layers;
}
} // namespace

QualityNeighbourhood findQualityNeighbours(vtkDataObject* input,
  const std::vector<std::string>& names, const std::vector<StructuredBlock>& blocks,
  vtkMultiProcessController* controller, bool ready)
{
  QualityNeighbourhood result;
  const std::string document = ready ? findModelDocument(input) : std::string();
  model::BlockModel blockModel;
  model::Topology topology;
  std::vector<int> subset;
  bool haveModel = false;
  if (!document.empty())
  {
    try
    {
      blockModel = model::readModelDocument(document);
      topology = model::buildTopology(blockModel);
      haveModel = findModelBlocks(blockModel, names, subset);
    }
    catch (const std::exception&)
    {
      haveModel = false; // a document that does not read gives no neighbours, as none
    }
  }
  if (controller)
  {
    // Every rank takes part in the same collective calls, whatever it found.
    int flags[2] = { ready ? 1 : 0, ready && haveModel ? 1 : 0 }, allFlags[2] = { 0, 0 };
    controller->AllReduce(flags, allFlags, 2, vtkCommunicator::MIN_OP);
    result.peerFailed = ready && !allFlags[0];
    if (!allFlags[1])
    {
      result.missingModel = ready && allFlags[0];
      return result;
    }
  }
  else if (!haveModel)
  {
    return result;
  }

  model::QualityNeighbours neighbours = model::qualityNeighbours(topology, subset);
  std::map<std::pair<int, int>, std::pair<std::array<int, 3>, std::vector<double>>> received;
  if (controller)
  {
    const int blockCount = static_cast<int>(blockModel.blocks.size());
    std::vector<int> mine(blockCount, -1), owner(blockCount, -1);
    for (int b : subset)
    {
      mine[b] = controller->GetLocalProcessId();
    }
    controller->AllReduce(mine.data(), owner.data(), blockCount, vtkCommunicator::MAX_OP);
    std::set<std::pair<int, int>> wanted;
    for (const model::BlockFace& side : neighbours.layers)
    {
      wanted.emplace(side.block, side.face);
    }
    received = exchangeLayers(controller, topology, owner, subset, blocks, wanted);
  }

  // Layers that arrived (none in a serial run: pairs with a block that is not here are
  // left out, as before), and the links renumbered to them.
  const int measured = static_cast<int>(blocks.size());
  std::vector<int> renumbered(neighbours.layers.size(), -1);
  for (std::size_t n = 0; n < neighbours.layers.size(); ++n)
  {
    const model::BlockFace& side = neighbours.layers[n];
    const auto found = received.find({ side.block, side.face });
    if (found == received.end())
    {
      continue;
    }
    renumbered[n] = measured + static_cast<int>(result.layers.size());
    result.layerNodes.push_back(std::move(found->second.second));
    StructuredBlock cells;
    cells.xyz = result.layerNodes.back().data();
    cells.ni = found->second.first[0];
    cells.nj = found->second.first[1];
    cells.nk = found->second.first[2];
    result.layers.push_back({ cells, side.face });
  }
  std::vector<StructuredBlock> all = blocks;
  for (const NeighbourLayer& layer : result.layers)
  {
    all.push_back(layer.cells);
  }
  for (PeriodicSideLink link : neighbours.links)
  {
    for (int* block : { &link.sourceBlock, &link.imageBlock })
    {
      if (*block >= measured)
      {
        *block = renumbered[*block - measured];
      }
    }
    if (link.sourceBlock < 0 || link.imageBlock < 0)
    {
      continue;
    }
    if (periodicSidesMatch(all, link))
    {
      result.links.push_back(link);
    }
    else
    {
      ++result.unfit;
    }
  }
  return result;
}
} // namespace vtkglue
} // namespace blockforge
