#include "BlockForgeModelIO.h"

#include "BlockForgeParallel.h"
#include "BlockForgeRanges.h"

#include "../Model/ModelDocument.h"
#include "../Model/Partition.h"
#include "../Model/Template.h"

#include <vtkCellArray.h>
#include <vtkCompositeDataSet.h>
#include <vtkDataArray.h>
#include <vtkDataObject.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>

#include <cmath>
#include <stdexcept>

namespace blockforge
{
namespace vtkglue
{
namespace
{
std::string blockName(vtkMultiBlockDataSet* parent, unsigned int index)
{
  if (parent->HasMetaData(index))
  {
    vtkInformation* meta = parent->GetMetaData(index);
    if (meta->Has(vtkCompositeDataSet::NAME()))
    {
      return meta->Get(vtkCompositeDataSet::NAME());
    }
  }
  return "Block " + std::to_string(index);
}

/// The points of a polyline (of all its line cells in order; the points when it has none).
model::InputCurve readCurve(vtkPolyData* polyData, const std::string& name)
{
  model::InputCurve curve;
  curve.name = name;
  vtkPoints* points = polyData->GetPoints();
  if (!points)
  {
    return curve;
  }
  auto add = [&](vtkIdType id) {
    double p[3];
    points->GetPoint(id, p);
    curve.points.emplace_back(p[0], p[1], p[2]);
  };
  vtkCellArray* lines = polyData->GetLines();
  if (lines && lines->GetNumberOfCells() > 0)
  {
    vtkNew<vtkIdList> ids;
    for (lines->InitTraversal(); lines->GetNextCell(ids);)
    {
      for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
      {
        // consecutive cells of one polyline share their joint point: keep it once
        if (k == 0 && !curve.points.empty())
        {
          double p[3];
          points->GetPoint(ids->GetId(0), p);
          if (curve.points.back() == Vec3(p[0], p[1], p[2]))
          {
            continue;
          }
        }
        add(ids->GetId(k));
      }
    }
  }
  else
  {
    for (vtkIdType id = 0; id < points->GetNumberOfPoints(); ++id)
    {
      add(id);
    }
  }
  if (vtkDataArray* span = polyData->GetFieldData()->GetArray("SpanFraction"))
  {
    if (span->GetNumberOfTuples() > 0)
    {
      curve.span = span->GetComponent(0, 0);
    }
  }
  return curve;
}
} // namespace

void readTemplateInputs(vtkDataObject* input, model::TemplateInputs& inputs)
{
  auto* root = vtkMultiBlockDataSet::SafeDownCast(input);
  if (!root)
  {
    throw std::runtime_error(std::string("the input must be a multiblock of point sets (the "
                                         "output of a TurboPointSetsReader), not a ") +
      (input ? input->GetClassName() : "null object"));
  }
  inputs = model::TemplateInputs();
  for (unsigned int b = 0; b < root->GetNumberOfBlocks(); ++b)
  {
    model::InputPointSet set;
    set.name = blockName(root, b);
    vtkDataObject* block = root->GetBlock(b);
    if (auto* polyData = vtkPolyData::SafeDownCast(block))
    {
      set.curves.push_back(readCurve(polyData, set.name));
    }
    else if (auto* list = vtkMultiBlockDataSet::SafeDownCast(block))
    {
      set.isList = true;
      for (unsigned int k = 0; k < list->GetNumberOfBlocks(); ++k)
      {
        if (auto* curve = vtkPolyData::SafeDownCast(list->GetBlock(k)))
        {
          set.curves.push_back(readCurve(curve, blockName(list, k)));
        }
        else
        {
          set.curves.emplace_back(); // an empty curve: reported if the template uses it
          set.curves.back().name = blockName(list, k);
        }
      }
    }
    inputs.pointSets.push_back(set);
  }
  vtkFieldData* fields = root->GetFieldData();
  if (vtkDataArray* axis = fields ? fields->GetArray("Axis") : nullptr)
  {
    if (axis->GetNumberOfTuples() * axis->GetNumberOfComponents() >= 3)
    {
      Vec3 direction;
      for (int c = 0; c < 3; ++c)
      {
        direction[c] = axis->GetNumberOfComponents() >= 3 ? axis->GetComponent(0, c)
                                                          : axis->GetComponent(c, 0);
      }
      if (direction.allFinite() && direction.norm() > 0.0)
      {
        inputs.hasMachine = true;
        inputs.axis = direction.normalized();
      }
    }
  }
  if (vtkDataArray* count = fields ? fields->GetArray("BladeCount") : nullptr)
  {
    if (count->GetNumberOfTuples() > 0)
    {
      const double value = count->GetComponent(0, 0);
      if (std::isfinite(value) && value >= 1.0 && value == std::floor(value))
      {
        inputs.bladeCount = static_cast<int>(value);
      }
    }
  }
}

void attachModel(vtkFieldData* fieldData, const std::string& document)
{
  vtkNew<vtkStringArray> array;
  array->SetName(model::ModelDocumentArrayName);
  array->SetNumberOfValues(1);
  array->SetValue(0, document);
  fieldData->RemoveArray(model::ModelDocumentArrayName);
  fieldData->AddArray(array);
}

RequestedPiece requestedPiece(vtkInformation* outInfo)
{
  RequestedPiece request;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()))
  {
    request.piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
  }
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()))
  {
    request.count = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  }
  return request;
}

std::string findModelDocument(vtkDataObject* object)
{
  if (!object || !object->GetFieldData())
  {
    return {};
  }
  auto* array = vtkStringArray::SafeDownCast(
    object->GetFieldData()->GetAbstractArray(model::ModelDocumentArrayName));
  if (!array || array->GetNumberOfValues() < 1)
  {
    return {};
  }
  return array->GetValue(0);
}
} // namespace vtkglue
} // namespace blockforge

#include "../Core/Quality.h"
#include "../Model/MemoryBudget.h"
#include "../Model/GridCheck.h"
#include "../Model/Mesher.h"
#include "../Model/PrintableText.h"

#include <deque>
#include <mutex>

#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkPoints.h>
#include <vtkStructuredGrid.h>

namespace blockforge
{
namespace vtkglue
{
namespace
{
/// The blocks of `piece` (model::balancedPieces: shared out by cells), all for one piece.
std::vector<int> pieceBlocks(const model::MultiBlockMesher& mesher, int piece, int pieceCount)
{
  std::vector<std::array<int, 3>> nodeCounts;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    nodeCounts.push_back(mesher.nodeCounts(b));
  }
  const std::vector<int> pieceOf = model::balancedPieces(nodeCounts, pieceCount);
  std::vector<int> blocks;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    if (pieceCount <= 1 || pieceOf[b] == piece)
    {
      blocks.push_back(b);
    }
  }
  return blocks;
}
} // namespace

void fillMultiBlock(const model::BlockModel& blockModel, const model::MultiBlockMesher& mesher,
  vtkMultiBlockDataSet* output, int piece, int pieceCount,
  const std::function<void(double)>& progress, InvertedCellPolicy policy,
  std::vector<model::InvertedCellReport>* reports)
{
  const int blockCount = mesher.blockCount();
  output->SetNumberOfBlocks(static_cast<unsigned int>(blockCount));
  std::vector<char> mine(static_cast<std::size_t>(blockCount), 0);
  for (const int b : pieceBlocks(mesher, piece, pieceCount))
  {
    mine[b] = 1;
  }
  for (int b = 0; b < blockCount; ++b)
  {
    output->GetMetaData(static_cast<unsigned int>(b))
      ->Set(vtkCompositeDataSet::NAME(), blockModel.blocks[b].name.c_str());
    if (!mine[b])
    {
      continue;
    }
    const auto nodes = mesher.nodeCounts(b);
    const vtkIdType nodeCount = static_cast<vtkIdType>(nodes[0]) * nodes[1] * nodes[2];
    vtkNew<vtkDoubleArray> coordinates;
    coordinates->SetNumberOfComponents(3);
    if (!coordinates->Resize(nodeCount) || coordinates->GetPointer(0) == nullptr)
    {
      throw model::ResourceError("block '" + blockModel.blocks[b].name + "': cannot allocate " +
        model::formatBytes(24.0 * static_cast<double>(nodeCount)) + " for " +
        std::to_string(nodeCount) + " nodes");
    }
    coordinates->SetNumberOfTuples(nodeCount);
    // Fresh memory faulted in one go is much cheaper than page by page on some VMs.
    prepareOutputMemory(coordinates->GetPointer(0), sizeof(double) * 3 * nodeCount);
    mesher.meshBlock(b, coordinates->GetPointer(0));
    if (policy == InvertedCellPolicy::Refuse)
    {
      model::checkBlockCells(blockModel, b, nodes, coordinates->GetPointer(0));
    }
    else if (policy == InvertedCellPolicy::Report)
    {
      model::InvertedCellReport report =
        model::reportInvertedCells(blockModel, b, nodes, coordinates->GetPointer(0));
      if (report.cells > 0 && reports)
      {
        reports->push_back(std::move(report));
      }
    }

    // With its bounds (and the coordinates' ranges) computed now, on threads: ParaView
    // asks for them after every update.
    vtkSmartPointer<vtkPoints> points = pointsWithKnownBounds(coordinates);
    vtkNew<vtkStructuredGrid> grid;
    grid->SetDimensions(nodes[0], nodes[1], nodes[2]);
    grid->SetPoints(points);

    vtkNew<vtkIntArray> blockId;
    blockId->SetName("BlockId");
    blockId->SetNumberOfTuples(grid->GetNumberOfCells());
    blockId->FillValue(b);
    grid->GetCellData()->AddArray(blockId);
    cacheConstantRange(blockId, b);
    // The active scalars are what ParaView colours by at first: the decomposition.
    grid->GetCellData()->SetActiveScalars("BlockId");

    output->SetBlock(static_cast<unsigned int>(b), grid);
    if (progress)
    {
      progress(static_cast<double>(b + 1) / blockCount);
    }
  }
}

namespace
{
/**
 * The carriers of the last few model documents meshed in this process. A BlockTemplate
 * and the BlockMesher below it see the same document: building its carriers (the blade
 * intersections) once is enough. Documents are compared whole, and carriers are built
 * from the document's numbers alone, so a hit gives the same grid bit for bit.
 */
class CarrierCache
{
public:
  static CarrierCache& instance()
  {
    static CarrierCache cache;
    return cache;
  }
  bool find(const std::string& document, model::CarrierGeometry& carriers)
  {
    std::lock_guard<std::mutex> lock(Mutex);
    for (const auto& entry : Entries)
    {
      if (entry.first == document)
      {
        carriers = entry.second;
        return true;
      }
    }
    return false;
  }
  void store(const std::string& document, const model::CarrierGeometry& carriers)
  {
    std::lock_guard<std::mutex> lock(Mutex);
    for (const auto& entry : Entries)
    {
      if (entry.first == document)
      {
        return;
      }
    }
    Entries.emplace_back(document, carriers);
    if (Entries.size() > 4)
    {
      Entries.pop_front();
    }
  }

private:
  std::mutex Mutex;
  std::deque<std::pair<std::string, model::CarrierGeometry>> Entries;
};
} // namespace

std::string meshModel(const model::BlockModel& blockModel, const std::string& document,
  double densityMultiplier, int cellCap, int piece, int pieceCount,
  vtkMultiBlockDataSet* output, const std::function<void(double)>& progress,
  const model::CarrierGeometry* carriers, InvertedCellPolicy policy,
  std::vector<model::InvertedCellReport>* reports, double maximumMemoryGigabytes)
{
  useSMPTools();
  model::CarrierGeometry known;
  bool haveCarriers = false;
  if (carriers)
  {
    known = *carriers;
    haveCarriers = true;
  }
  else if (!blockModel.carriers.empty())
  {
    haveCarriers = CarrierCache::instance().find(document, known);
  }
  model::MultiBlockMesher mesher = haveCarriers
    ? model::MultiBlockMesher(blockModel, known, densityMultiplier)
    : model::MultiBlockMesher(blockModel, densityMultiplier);
  if (!blockModel.carriers.empty())
  {
    CarrierCache::instance().store(document, mesher.carriers());
  }
  mesher.setCellCap(cellCap);
  // This piece's blocks (an MPI rank's share): their memory is checked and only the
  // boundary grids they need are computed.
  const std::vector<int> share = pieceBlocks(mesher, piece, pieceCount);
  model::BlockNodeCounts nodes;
  for (const int b : share)
  {
    nodes.push_back(mesher.nodeCounts(b));
  }
  const bool preview = cellCap > 0 || policy == InvertedCellPolicy::Skip;
  model::checkGridMemory(nodes, maximumMemoryGigabytes,
    preview ? "lower PreviewCells or the cell counts"
            : "lower the density multiplier or the cell counts");
  try
  {
    mesher.computeBoundaries(share);
  }
  catch (const model::FoldError& fold)
  {
    if (!preview)
    {
      throw;
    }
    // The preview's capped cell counts have other first cells than the grid: pass the
    // model on without a drawing (the blocks named and empty, the structure every rank has).
    vtkNew<vtkMultiBlockDataSet> modelOnly;
    modelOnly->SetNumberOfBlocks(static_cast<unsigned int>(mesher.blockCount()));
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      modelOnly->GetMetaData(static_cast<unsigned int>(b))
        ->Set(vtkCompositeDataSet::NAME(), blockModel.blocks[b].name.c_str());
    }
    attachModel(modelOnly->GetFieldData(), document);
    output->ShallowCopy(modelOnly);
    return "the preview (at most " + std::to_string(cellCap) +
      " cells per edge) folds and is not drawn; the model is passed on (BlockMesher checks "
      "the grid at the density it meshes): " +
      printable(fold.what());
  }
  if (progress)
  {
    progress(0.05);
  }
  vtkNew<vtkMultiBlockDataSet> grid;
  fillMultiBlock(
    blockModel, mesher, grid, piece, pieceCount,
    [&progress](double fraction) {
      if (progress)
      {
        progress(0.05 + 0.95 * fraction);
      }
    },
    policy, reports);
  attachModel(grid->GetFieldData(), document);
  output->ShallowCopy(grid);
  return {};
}

std::string printable(const char* text)
{
  return printableText(text ? text : "");
}
} // namespace vtkglue
} // namespace blockforge
