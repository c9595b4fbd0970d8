#include "vtkGridQuality.h"

#include "../Core/Parallel.h"
#include "../Core/Quality.h"
#include "../Model/MemoryBudget.h"
#include "../Model/ModelDocument.h"
#include "../Model/Topology.h"
#include "BlockForgeModelIO.h"
#include "BlockForgeParallel.h"
#include "BlockForgeRanges.h"

#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkDataObjectTreeIterator.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkMultiProcessController.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtkStructuredGrid.h>
#include <vtkTable.h>

#include <algorithm>
#include <cstdio>
#include <array>
#include <limits>
#include <map>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkGridQuality);

namespace
{
constexpr int MeasureCount = 7;
const char* const MeasureNames[MeasureCount] = { "MinAngle", "MaxAngle", "NonOrthogonality",
  "Skewness", "AspectRatio", "ScaledJacobian", "CellDeterminant" };
const char* const ClassLabels[5] = { "0-20", "20-40", "40-60", "60-80", "80-90" };
const double ClassCentres[5] = { 10.0, 30.0, 50.0, 70.0, 85.0 };

} // namespace

vtkGridQuality::vtkGridQuality()
{
  this->SetNumberOfOutputPorts(3);
  blockforge::vtkglue::useSMPTools();
}

int vtkGridQuality::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  return 1;
}

int vtkGridQuality::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
  {
    return this->Superclass::FillOutputPortInformation(port, info);
  }
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkTable");
  return 1;
}

int vtkGridQuality::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  auto* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  auto* output = vtkMultiBlockDataSet::GetData(outputVector, 0);
  auto* classTable = vtkTable::GetData(outputVector, 1);
  auto* statisticsTable = vtkTable::GetData(outputVector, 2);
  output->CopyStructure(input);
  this->UpdateProgress(0.0);

  // Under MPI, when the pipeline runs in pieces, the ranks exchange the cells beside
  // interfaces and periodic faces between them, and reduce the statistics. A plain serial
  // pipeline inside an MPI program (e.g. on one rank of pvbatch) must not wait for ranks
  // that never join.
  const int pieceCount = outputVector->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!controller || pieceCount <= 1 || controller->GetNumberOfProcesses() <= 1)
  {
    controller = nullptr;
  }

  // Gather the structured blocks; float coordinates are converted once to double.
  std::vector<vtkStructuredGrid*> grids;
  std::vector<std::vector<double>> convertedPoints;
  std::vector<blockforge::StructuredBlock> blocks;
  std::vector<std::string> names;
  vtkSmartPointer<vtkDataObjectTreeIterator> iterator;
  iterator.TakeReference(input->NewTreeIterator());
  iterator->SkipEmptyNodesOn();
  for (iterator->InitTraversal(); !iterator->IsDoneWithTraversal(); iterator->GoToNextItem())
  {
    auto* grid = vtkStructuredGrid::SafeDownCast(iterator->GetCurrentDataObject());
    if (!grid)
    {
      vtkWarningMacro("Block " << iterator->GetCurrentFlatIndex()
                               << " is not a vtkStructuredGrid; it is passed on unmeasured.");
      output->SetDataSet(iterator, iterator->GetCurrentDataObject());
      continue;
    }
    int dims[3];
    grid->GetDimensions(dims);
    if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2 || !grid->GetPoints())
    {
      vtkErrorMacro("Block " << iterator->GetCurrentFlatIndex()
                             << " is not a 3-D hexahedral grid (dimensions " << dims[0] << " x "
                             << dims[1] << " x " << dims[2] << ").");
      // The other ranks wait for this one in the exchange: tell them it failed.
      blockforge::vtkglue::findQualityNeighbours(input, {}, {}, controller, false);
      return 0;
    }
    blockforge::StructuredBlock block;
    block.ni = dims[0];
    block.nj = dims[1];
    block.nk = dims[2];
    auto* doubles = vtkDoubleArray::SafeDownCast(grid->GetPoints()->GetData());
    if (doubles && doubles->GetNumberOfComponents() == 3)
    {
      block.xyz = doubles->GetPointer(0);
    }
    else
    {
      const vtkIdType count = grid->GetNumberOfPoints();
      std::vector<double> copy(static_cast<size_t>(count) * 3);
      for (vtkIdType p = 0; p < count; ++p)
      {
        grid->GetPoint(p, &copy[3 * p]);
      }
      convertedPoints.push_back(std::move(copy));
      block.xyz = convertedPoints.back().data();
    }
    blocks.push_back(block);
    grids.push_back(grid);
    vtkInformation* metaData =
      iterator->HasCurrentMetaData() ? iterator->GetCurrentMetaData() : nullptr;
    names.push_back(metaData && metaData->Has(vtkCompositeDataSet::NAME())
        ? metaData->Get(vtkCompositeDataSet::NAME())
        : "");
  }

  try
  {
    double cellTotal = 0.0;
    for (vtkStructuredGrid* grid : grids)
    {
      cellTotal += static_cast<double>(grid->GetNumberOfCells());
    }
    char count[64];
    std::snprintf(count, sizeof(count), "%.2g cells", cellTotal);
    blockforge::model::checkMemory(blockforge::model::qualityMemoryBytes(cellTotal),
      this->MaximumMemory, "the quality measures", count,
      "lower the density multiplier or the cell counts");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    return 0;
  }

  // The measures are written straight into the output arrays: no copy, and the fresh
  // memory is prepared in one go rather than faulted page by page.
  std::vector<vtkSmartPointer<vtkStructuredGrid>> measuredGrids;
  std::vector<std::array<vtkSmartPointer<vtkDoubleArray>, MeasureCount>> measureArrays(grids.size());
  std::vector<blockforge::CellQualityPointers> outputs(grids.size());
  std::vector<std::pair<void*, std::size_t>> freshMemory;
  for (size_t b = 0; b < grids.size(); ++b)
  {
    auto measured = vtkSmartPointer<vtkStructuredGrid>::New();
    measured->ShallowCopy(grids[b]);
    const vtkIdType cells = measured->GetNumberOfCells();
    for (int m = 0; m < MeasureCount; ++m)
    {
      auto array = vtkSmartPointer<vtkDoubleArray>::New();
      array->SetName(MeasureNames[m]);
      array->SetNumberOfTuples(cells);
      freshMemory.emplace_back(array->GetPointer(0), sizeof(double) * cells);
      measured->GetCellData()->AddArray(array);
      measureArrays[b][m] = array;
    }
    outputs[b] = { measureArrays[b][0]->GetPointer(0), measureArrays[b][1]->GetPointer(0),
      measureArrays[b][2]->GetPointer(0), measureArrays[b][3]->GetPointer(0),
      measureArrays[b][4]->GetPointer(0), measureArrays[b][5]->GetPointer(0),
      measureArrays[b][6]->GetPointer(0) };
    // The mesher already labels its blocks; other inputs get the leaf ordinal.
    if (!measured->GetCellData()->GetArray("BlockId"))
    {
      vtkNew<vtkIntArray> blockId;
      blockId->SetName("BlockId");
      blockId->SetNumberOfTuples(cells);
      blockId->FillValue(static_cast<int>(b));
      measured->GetCellData()->AddArray(blockId);
      blockforge::vtkglue::cacheConstantRange(blockId, static_cast<double>(b));
    }
    // ParaView colours by the active scalars at first: the paper's criterion.
    measured->GetCellData()->SetActiveScalars("MinAngle");
    measuredGrids.push_back(measured);
  }
  blockforge::prepareOutputMemory(freshMemory);
  try
  {
    const blockforge::vtkglue::QualityNeighbourhood neighbours =
      blockforge::vtkglue::findQualityNeighbours(input, names, blocks, controller);
    if (neighbours.peerFailed)
    {
      vtkErrorMacro("Another MPI rank failed to measure its blocks (see its messages).");
      return 0;
    }
    if (neighbours.unfit > 0)
    {
      vtkWarningMacro(<< neighbours.unfit
                      << " periodic face pair(s) of the input's block model do not fit its "
                         "grid (changed after meshing?); they are measured as boundaries.");
    }
    if (neighbours.missingModel)
    {
      vtkWarningMacro("The input carries no BlockForge model naming its blocks: faces between "
                      "blocks on different MPI ranks are measured as boundaries.");
    }
    blockforge::computeGridQuality(blocks, neighbours.links, neighbours.layers, outputs,
      [this](double fraction) { this->UpdateProgress(0.9 * fraction); });
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    return 0;
  }

  // Local statistics, reduced across MPI ranks below.
  std::array<double, 5> classCounts{};
  std::array<double, MeasureCount> minimum, maximum, sum{};
  minimum.fill(std::numeric_limits<double>::max());
  maximum.fill(std::numeric_limits<double>::lowest());
  double cellCount = 0.0;
  // Minimum, maximum and sum of every array of every block, arrays on threads; the sums
  // are then added in block order (the same bits on any number of threads).
  struct ArraySummary
  {
    double minimum = std::numeric_limits<double>::max();
    double maximum = std::numeric_limits<double>::lowest();
    double sum = 0.0;
  };
  std::vector<ArraySummary> summaries(MeasureCount * grids.size());
  blockforge::forEachChunk(static_cast<long>(summaries.size()), [&](long n) {
    const double* values = measureArrays[n / MeasureCount][n % MeasureCount]->GetPointer(0);
    const vtkIdType cells = measureArrays[n / MeasureCount][n % MeasureCount]->GetNumberOfTuples();
    ArraySummary& summary = summaries[n];
    for (vtkIdType c = 0; c < cells; ++c)
    {
      summary.minimum = std::min(summary.minimum, values[c]);
      summary.maximum = std::max(summary.maximum, values[c]);
      summary.sum += values[c];
    }
  });
  for (size_t b = 0; b < grids.size(); ++b)
  {
    const vtkIdType cells = measureArrays[b][0]->GetNumberOfTuples();
    for (int m = 0; m < MeasureCount; ++m)
    {
      const ArraySummary& summary = summaries[MeasureCount * b + m];
      minimum[m] = std::min(minimum[m], summary.minimum);
      maximum[m] = std::max(maximum[m], summary.maximum);
      sum[m] += summary.sum;
      blockforge::vtkglue::cacheRanges(measureArrays[b][m]);
    }
    const auto blockClasses = blockforge::minAngleClasses(
      measureArrays[b][0]->GetPointer(0), static_cast<std::size_t>(cells));
    for (int c = 0; c < 5; ++c)
    {
      classCounts[c] += static_cast<double>(blockClasses[c]);
    }
    cellCount += static_cast<double>(cells);
  }

  // Second traversal, same order as the first: put each measured grid in its leaf.
  {
    size_t next = 0;
    for (iterator->InitTraversal(); !iterator->IsDoneWithTraversal(); iterator->GoToNextItem())
    {
      if (next < grids.size() && iterator->GetCurrentDataObject() == grids[next])
      {
        output->SetDataSet(iterator, measuredGrids[next++]);
      }
    }
  }

  if (controller)
  {
    {
      std::array<double, 5> classTotal{};
      std::array<double, MeasureCount> minTotal{}, maxTotal{}, sumTotal{};
      double countTotal = 0.0;
      controller->AllReduce(classCounts.data(), classTotal.data(), 5, vtkCommunicator::SUM_OP);
      controller->AllReduce(minimum.data(), minTotal.data(), MeasureCount, vtkCommunicator::MIN_OP);
      controller->AllReduce(maximum.data(), maxTotal.data(), MeasureCount, vtkCommunicator::MAX_OP);
      controller->AllReduce(sum.data(), sumTotal.data(), MeasureCount, vtkCommunicator::SUM_OP);
      controller->AllReduce(&cellCount, &countTotal, 1, vtkCommunicator::SUM_OP);
      classCounts = classTotal;
      minimum = minTotal;
      maximum = maxTotal;
      sum = sumTotal;
      cellCount = countTotal;
    }
  }

  vtkFieldData* fieldData = output->GetFieldData();
  fieldData->ShallowCopy(input->GetFieldData());
  vtkNew<vtkIdTypeArray> counts;
  counts->SetName("MinAngleClassCounts");
  counts->SetNumberOfTuples(5);
  for (int c = 0; c < 5; ++c)
  {
    counts->SetValue(c, static_cast<vtkIdType>(classCounts[c]));
  }
  fieldData->AddArray(counts);

  // The class table is made for ParaView's bar chart: "bin_extents" (the class centre
  // angle) is the column charts take as their x axis and do not plot; the labels are
  // strings, which charts do not plot either; so the cells are the only bars. Percentages
  // would be invisible beside the counts: they go to the field data.
  vtkNew<vtkStringArray> labelColumn;
  labelColumn->SetName("Class");
  vtkNew<vtkDoubleArray> centreColumn;
  centreColumn->SetName("bin_extents");
  vtkNew<vtkIdTypeArray> cellColumn;
  cellColumn->SetName("Cells");
  vtkNew<vtkDoubleArray> percent;
  percent->SetName("MinAngleClassPercent");
  for (int c = 0; c < 5; ++c)
  {
    labelColumn->InsertNextValue(ClassLabels[c]);
    centreColumn->InsertNextValue(ClassCentres[c]);
    cellColumn->InsertNextValue(static_cast<vtkIdType>(classCounts[c]));
    percent->InsertNextValue(cellCount > 0 ? 100.0 * classCounts[c] / cellCount : 0.0);
  }
  classTable->AddColumn(labelColumn);
  classTable->AddColumn(cellColumn);
  classTable->AddColumn(centreColumn);
  fieldData->AddArray(percent);

  vtkNew<vtkStringArray> measureColumn;
  measureColumn->SetName("Measure");
  vtkNew<vtkDoubleArray> minColumn, meanColumn, maxColumn;
  minColumn->SetName("Min");
  meanColumn->SetName("Mean");
  maxColumn->SetName("Max");
  for (int m = 0; m < MeasureCount; ++m)
  {
    const bool empty = cellCount == 0.0;
    const double mean = empty ? 0.0 : sum[m] / cellCount;
    const double lo = empty ? 0.0 : minimum[m];
    const double hi = empty ? 0.0 : maximum[m];
    vtkNew<vtkDoubleArray> summary;
    summary->SetName((std::string(MeasureNames[m]) + "Summary").c_str());
    summary->SetNumberOfComponents(3);
    summary->SetComponentName(0, "Min");
    summary->SetComponentName(1, "Mean");
    summary->SetComponentName(2, "Max");
    summary->InsertNextTuple3(lo, mean, hi);
    fieldData->AddArray(summary);
    measureColumn->InsertNextValue(MeasureNames[m]);
    minColumn->InsertNextValue(lo);
    meanColumn->InsertNextValue(mean);
    maxColumn->InsertNextValue(hi);
  }
  statisticsTable->AddColumn(measureColumn);
  statisticsTable->AddColumn(minColumn);
  statisticsTable->AddColumn(meanColumn);
  statisticsTable->AddColumn(maxColumn);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkGridQuality::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MaximumMemory: " << this->MaximumMemory << " GB\n";
}
