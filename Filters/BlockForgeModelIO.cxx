#include "BlockForgeModelIO.h"

#include "../Model/ModelDocument.h"

#include <vtkDataObject.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkStringArray.h>

namespace blockforge
{
namespace vtkglue
{
void attachModel(vtkFieldData* fieldData, const std::string& document)
{
  vtkNew<vtkStringArray> array;
  array->SetName(model::ModelDocumentArrayName);
  array->SetNumberOfValues(1);
  array->SetValue(0, document);
  fieldData->RemoveArray(model::ModelDocumentArrayName);
  fieldData->AddArray(array);
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

#include "../Model/Mesher.h"

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
void fillMultiBlock(const model::BlockModel& blockModel, const model::MultiBlockMesher& mesher,
  vtkMultiBlockDataSet* output, int piece, int pieceCount,
  const std::function<void(double)>& progress)
{
  const int blockCount = mesher.blockCount();
  output->SetNumberOfBlocks(static_cast<unsigned int>(blockCount));
  for (int b = 0; b < blockCount; ++b)
  {
    output->GetMetaData(static_cast<unsigned int>(b))
      ->Set(vtkCompositeDataSet::NAME(), blockModel.blocks[b].name.c_str());
    if (pieceCount > 1 && b % pieceCount != piece)
    {
      continue;
    }
    const auto nodes = mesher.nodeCounts(b);
    const vtkIdType nodeCount = static_cast<vtkIdType>(nodes[0]) * nodes[1] * nodes[2];
    vtkNew<vtkDoubleArray> coordinates;
    coordinates->SetNumberOfComponents(3);
    coordinates->SetNumberOfTuples(nodeCount);
    mesher.meshBlock(b, coordinates->GetPointer(0));

    vtkNew<vtkPoints> points;
    points->SetData(coordinates);
    vtkNew<vtkStructuredGrid> grid;
    grid->SetDimensions(nodes[0], nodes[1], nodes[2]);
    grid->SetPoints(points);

    vtkNew<vtkIntArray> blockId;
    blockId->SetName("BlockId");
    blockId->SetNumberOfTuples(grid->GetNumberOfCells());
    blockId->FillValue(b);
    grid->GetCellData()->AddArray(blockId);

    output->SetBlock(static_cast<unsigned int>(b), grid);
    if (progress)
    {
      progress(static_cast<double>(b + 1) / blockCount);
    }
  }
}

void meshModel(const model::BlockModel& blockModel, const std::string& document,
  double densityMultiplier, int cellCap, int piece, int pieceCount,
  vtkMultiBlockDataSet* output, const std::function<void(double)>& progress)
{
  model::MultiBlockMesher mesher(blockModel, densityMultiplier);
  mesher.setCellCap(cellCap);
  mesher.computeBoundaries();
  if (progress)
  {
    progress(0.05);
  }
  vtkNew<vtkMultiBlockDataSet> grid;
  fillMultiBlock(blockModel, mesher, grid, piece, pieceCount, [&progress](double fraction) {
    if (progress)
    {
      progress(0.05 + 0.95 * fraction);
    }
  });
  attachModel(grid->GetFieldData(), document);
  output->ShallowCopy(grid);
}
} // namespace vtkglue
} // namespace blockforge
