#include "vtkBlockGridWriter.h"

#include "BlockForgeModelIO.h"

#include "../Export/ExportModel.h"
#include "../Model/ModelDocument.h"

#include <vtkDataArray.h>
#include <vtkDataObjectTreeIterator.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkMultiProcessController.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStructuredGrid.h>

#include <deque>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
namespace exporting = blockforge::exporting;

/// The blocks this process holds, by leaf index (model order), with coordinates as
/// doubles: pointing into the grid where its points are doubles, else into `storage`.
struct LocalBlocks
{
  std::vector<int> leaf;
  std::vector<exporting::GridBlock> blocks;
  std::deque<std::vector<double>> storage;
  std::size_t leafCount = 0;
};

LocalBlocks collectBlocks(vtkMultiBlockDataSet* input)
{
  LocalBlocks local;
  vtkSmartPointer<vtkDataObjectTreeIterator> iterator;
  iterator.TakeReference(input->NewTreeIterator());
  iterator->VisitOnlyLeavesOn();
  iterator->SkipEmptyNodesOff();
  for (iterator->InitTraversal(); !iterator->IsDoneWithTraversal(); iterator->GoToNextItem())
  {
    const int leaf = static_cast<int>(local.leafCount++);
    auto* grid = vtkStructuredGrid::SafeDownCast(iterator->GetCurrentDataObject());
    if (!grid || !grid->GetPoints() || grid->GetNumberOfPoints() == 0)
    {
      continue; // another rank's block, or missing (found when the blocks are put together)
    }
    exporting::GridBlock block;
    int dimensions[3];
    grid->GetDimensions(dimensions);
    block.nodes = { dimensions[0], dimensions[1], dimensions[2] };
    vtkDataArray* points = grid->GetPoints()->GetData();
    if (points->GetDataType() == VTK_DOUBLE && points->GetNumberOfComponents() == 3)
    {
      block.xyz = static_cast<const double*>(points->GetVoidPointer(0));
    }
    else
    {
      local.storage.emplace_back(static_cast<std::size_t>(grid->GetNumberOfPoints()) * 3);
      for (vtkIdType p = 0; p < grid->GetNumberOfPoints(); ++p)
      {
        grid->GetPoint(p, local.storage.back().data() + 3 * p);
      }
      block.xyz = local.storage.back().data();
    }
    local.leaf.push_back(leaf);
    local.blocks.push_back(block);
  }
  return local;
}

std::size_t coordinateCount(const exporting::GridBlock& block)
{
  return 3 * static_cast<std::size_t>(block.nodes[0]) * block.nodes[1] * block.nodes[2];
}

/**
 * Rank 0 receives the blocks of every rank (collective: every rank calls it, also one
 * that failed, with `ready` false and no blocks). Per rank an integer record
 * [ready, block count, (leaf, ni, nj, nk) per block] and the blocks' coordinates, both
 * in rank order; on rank 0 `local` gets the blocks it lacked (the lowest rank's copy of
 * a block held twice) and the ranks that were not ready are returned.
 */
std::vector<int> gatherBlocks(vtkMultiProcessController* controller, LocalBlocks& local, bool ready)
{
  vtkNew<vtkIdTypeArray> header;
  vtkNew<vtkDoubleArray> coordinates;
  header->InsertNextValue(ready ? 1 : 0);
  header->InsertNextValue(ready ? static_cast<vtkIdType>(local.blocks.size()) : 0);
  std::size_t total = 0;
  for (std::size_t b = 0; ready && b < local.blocks.size(); ++b)
  {
    header->InsertNextValue(local.leaf[b]);
    for (int d = 0; d < 3; ++d)
    {
      header->InsertNextValue(local.blocks[b].nodes[d]);
    }
    total += coordinateCount(local.blocks[b]);
  }
  coordinates->SetNumberOfValues(static_cast<vtkIdType>(total));
  std::size_t at = 0;
  for (std::size_t b = 0; ready && b < local.blocks.size(); ++b)
  {
    const std::size_t count = coordinateCount(local.blocks[b]);
    std::copy(local.blocks[b].xyz, local.blocks[b].xyz + count, coordinates->GetPointer(0) + at);
    at += count;
  }

  vtkNew<vtkIdTypeArray> headers;
  vtkNew<vtkDoubleArray> allCoordinates;
  controller->GatherV(header, headers, 0);
  controller->GatherV(coordinates, allCoordinates, 0);
  std::vector<int> notReady;
  if (controller->GetLocalProcessId() != 0)
  {
    return notReady;
  }
  std::vector<bool> held(local.leafCount, false);
  for (int leaf : local.leaf)
  {
    held[static_cast<std::size_t>(leaf)] = true;
  }
  vtkIdType h = 0;
  std::size_t c = 0;
  for (int rank = 0; rank < controller->GetNumberOfProcesses(); ++rank)
  {
    const bool rankReady = headers->GetValue(h++) != 0;
    const vtkIdType count = headers->GetValue(h++);
    if (!rankReady)
    {
      notReady.push_back(rank);
    }
    for (vtkIdType b = 0; b < count; ++b, h += 4)
    {
      const auto leaf = static_cast<std::size_t>(headers->GetValue(h));
      exporting::GridBlock block;
      block.nodes = { static_cast<int>(headers->GetValue(h + 1)),
        static_cast<int>(headers->GetValue(h + 2)), static_cast<int>(headers->GetValue(h + 3)) };
      const std::size_t size = coordinateCount(block);
      if (rank != 0 && leaf < held.size() && !held[leaf])
      {
        const double* from = allCoordinates->GetPointer(0) + c;
        local.storage.emplace_back(from, from + size);
        block.xyz = local.storage.back().data();
        local.leaf.push_back(static_cast<int>(leaf));
        local.blocks.push_back(block);
        held[leaf] = true;
      }
      c += size;
    }
  }
  return notReady;
}
} // namespace

vtkBlockGridWriter::vtkBlockGridWriter() = default;

vtkBlockGridWriter::~vtkBlockGridWriter()
{
  this->SetFileName(nullptr);
}

int vtkBlockGridWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  return 1;
}

namespace
{
/// The controller to gather with: the global one when gathering is on and it has ranks
/// besides this one; null otherwise (the whole grid is written here).
vtkMultiProcessController* gatheringController(bool gatherPieces)
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return gatherPieces && controller && controller->GetNumberOfProcesses() > 1 ? controller
                                                                               : nullptr;
}
}

vtkTypeBool vtkBlockGridWriter::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT()))
  {
    if (vtkMultiProcessController* controller = gatheringController(this->GatherPieces))
    {
      vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(),
        controller->GetLocalProcessId());
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(),
        controller->GetNumberOfProcesses());
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
    }
  }
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

void vtkBlockGridWriter::WriteData()
{
  const std::string fileName = this->FileName ? this->FileName : "";
  vtkMultiProcessController* controller = gatheringController(this->GatherPieces);
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  auto* input = vtkMultiBlockDataSet::SafeDownCast(this->GetInput());

  // Every rank takes its blocks (a failure here still joins the gathering below, so that
  // no rank waits for another forever).
  LocalBlocks local;
  std::string failure;
  try
  {
    if (fileName.empty())
    {
      throw std::runtime_error("no file name given");
    }
    if (input)
    {
      local = collectBlocks(input);
    }
  }
  catch (const std::exception& error)
  {
    failure = error.what();
  }
  std::vector<int> notReady;
  if (controller)
  {
    notReady = gatherBlocks(controller, local, failure.empty());
  }

  int written = 0;
  if (rank == 0)
  {
    try
    {
      if (!failure.empty())
      {
        throw std::runtime_error(failure);
      }
      if (!notReady.empty())
      {
        throw std::runtime_error("rank " + std::to_string(notReady.front()) +
          " could not hand over its blocks (its message says why), so " + fileName +
          " is not written");
      }
      const std::string document = blockforge::vtkglue::findModelDocument(input);
      if (!input || document.empty())
      {
        throw std::runtime_error("the grid carries no BlockForge model (the output of "
                                 "BlockMesher or GridQuality has one): its patches and block "
                                 "interfaces are unknown, so " + fileName + " is not written");
      }
      const blockforge::model::BlockModel model =
        blockforge::model::readModelDocument(document);

      // One structured grid per model block, in model order.
      std::vector<exporting::GridBlock> blocks(local.leafCount);
      std::vector<bool> held(local.leafCount, false);
      for (std::size_t b = 0; b < local.blocks.size(); ++b)
      {
        blocks[static_cast<std::size_t>(local.leaf[b])] = local.blocks[b];
        held[static_cast<std::size_t>(local.leaf[b])] = true;
      }
      for (std::size_t b = 0; b < blocks.size(); ++b)
      {
        blocks[b].name = b < model.blocks.size() ? model.blocks[b].name : std::to_string(b);
        if (!held[b])
        {
          throw std::runtime_error("block '" + blocks[b].name + "' has no grid " +
            (controller ? std::string("on any rank") : std::string("here")) +
            " (a writer needs every block of the model)");
        }
      }
      const exporting::ExportGrid grid = exporting::exportGrid(model, std::move(blocks));
      this->UpdateProgress(0.1);
      this->WriteGrid(
        grid, [this](double fraction) { this->UpdateProgress(0.1 + 0.9 * fraction); });
      this->UpdateProgress(1.0);
      written = 1;
    }
    catch (const std::exception& error)
    {
      vtkErrorMacro(<< error.what());
    }
  }
  else if (!failure.empty())
  {
    vtkErrorMacro(<< "rank " << rank << ": " << failure);
  }
  if (controller)
  {
    // Every rank returns what rank 0 did.
    controller->Broadcast(&written, 1, 0);
  }
  if (!written)
  {
    this->SetErrorCode(vtkErrorCode::UserError);
  }
}

void vtkBlockGridWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "GatherPieces: " << this->GatherPieces << "\n";
}
