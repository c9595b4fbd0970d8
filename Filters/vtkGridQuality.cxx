#include "vtkGridQuality.h"

#include "../Core/Quality.h"

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
#include <vtkStringArray.h>
#include <vtkStructuredGrid.h>
#include <vtkTable.h>

#include <algorithm>
#include <array>
#include <limits>
#include <vector>

vtkStandardNewMacro(vtkGridQuality);

namespace
{
const char* const MeasureNames[6] = { "MinAngle", "MaxAngle", "NonOrthogonality", "Skewness",
  "AspectRatio", "ScaledJacobian" };
const char* const ClassLabels[5] = { "0-20", "20-40", "40-60", "60-80", "80-90" };

std::vector<double>& measure(blockforge::CellQualityArrays& quality, int index)
{
  switch (index)
  {
    case 0:
      return quality.minAngle;
    case 1:
      return quality.maxAngle;
    case 2:
      return quality.nonOrthogonality;
    case 3:
      return quality.skewness;
    case 4:
      return quality.aspectRatio;
    default:
      return quality.scaledJacobian;
  }
}

vtkSmartPointer<vtkDoubleArray> toVtkArray(const char* name, const std::vector<double>& values)
{
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  std::copy(values.begin(), values.end(), array->GetPointer(0));
  return array;
}
} // namespace

vtkGridQuality::vtkGridQuality()
{
  this->SetNumberOfOutputPorts(3);
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

  // Gather the structured blocks; float coordinates are converted once to double.
  std::vector<vtkStructuredGrid*> grids;
  std::vector<std::vector<double>> convertedPoints;
  std::vector<blockforge::StructuredBlock> blocks;
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
  }

  std::vector<blockforge::CellQualityArrays> quality;
  try
  {
    quality = blockforge::computeGridQuality(
      blocks, [this](double fraction) { this->UpdateProgress(0.9 * fraction); });
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    return 0;
  }

  // Local statistics, reduced across MPI ranks below.
  std::array<double, 5> classCounts{};
  std::array<double, 6> minimum, maximum, sum{};
  minimum.fill(std::numeric_limits<double>::max());
  maximum.fill(std::numeric_limits<double>::lowest());
  double cellCount = 0.0;
  {
    const auto classes = blockforge::minAngleClasses(quality);
    std::copy(classes.begin(), classes.end(), classCounts.begin());
  }
  std::vector<vtkSmartPointer<vtkStructuredGrid>> measuredGrids;
  for (size_t b = 0; b < grids.size(); ++b)
  {
    auto measured = vtkSmartPointer<vtkStructuredGrid>::New();
    measured->ShallowCopy(grids[b]);
    for (int m = 0; m < 6; ++m)
    {
      const std::vector<double>& values = measure(quality[b], m);
      for (double value : values)
      {
        minimum[m] = std::min(minimum[m], value);
        maximum[m] = std::max(maximum[m], value);
        sum[m] += value;
      }
      measured->GetCellData()->AddArray(toVtkArray(MeasureNames[m], values));
    }
    cellCount += static_cast<double>(quality[b].minAngle.size());
    vtkNew<vtkIntArray> blockId;
    blockId->SetName("BlockId");
    blockId->SetNumberOfTuples(measured->GetNumberOfCells());
    blockId->FillValue(static_cast<int>(b));
    measured->GetCellData()->AddArray(blockId);
    measuredGrids.push_back(measured);
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

  if (auto* controller = vtkMultiProcessController::GetGlobalController())
  {
    if (controller->GetNumberOfProcesses() > 1)
    {
      std::array<double, 5> classTotal{};
      std::array<double, 6> minTotal{}, maxTotal{}, sumTotal{};
      double countTotal = 0.0;
      controller->AllReduce(classCounts.data(), classTotal.data(), 5, vtkCommunicator::SUM_OP);
      controller->AllReduce(minimum.data(), minTotal.data(), 6, vtkCommunicator::MIN_OP);
      controller->AllReduce(maximum.data(), maxTotal.data(), 6, vtkCommunicator::MAX_OP);
      controller->AllReduce(sum.data(), sumTotal.data(), 6, vtkCommunicator::SUM_OP);
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

  vtkNew<vtkStringArray> labelColumn;
  labelColumn->SetName("Class");
  vtkNew<vtkIdTypeArray> cellColumn;
  cellColumn->SetName("Cells");
  vtkNew<vtkDoubleArray> percentColumn;
  percentColumn->SetName("Percent");
  for (int c = 0; c < 5; ++c)
  {
    labelColumn->InsertNextValue(ClassLabels[c]);
    cellColumn->InsertNextValue(static_cast<vtkIdType>(classCounts[c]));
    percentColumn->InsertNextValue(cellCount > 0 ? 100.0 * classCounts[c] / cellCount : 0.0);
  }
  classTable->AddColumn(labelColumn);
  classTable->AddColumn(cellColumn);
  classTable->AddColumn(percentColumn);

  vtkNew<vtkStringArray> measureColumn;
  measureColumn->SetName("Measure");
  vtkNew<vtkDoubleArray> minColumn, meanColumn, maxColumn;
  minColumn->SetName("Min");
  meanColumn->SetName("Mean");
  maxColumn->SetName("Max");
  for (int m = 0; m < 6; ++m)
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
}
