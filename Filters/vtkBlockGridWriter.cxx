#include "vtkBlockGridWriter.h"

#include "BlockForgeModelIO.h"

#include "../Export/ExportModel.h"
#include "../Model/ModelDocument.h"

#include <vtkDataArray.h>
#include <vtkDataObjectTreeIterator.h>
#include <vtkErrorCode.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkStructuredGrid.h>

#include <stdexcept>
#include <string>
#include <vector>

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

void vtkBlockGridWriter::WriteData()
{
  namespace exporting = blockforge::exporting;
  const std::string fileName = this->FileName ? this->FileName : "";
  try
  {
    if (fileName.empty())
    {
      throw std::runtime_error("no file name given");
    }
    auto* input = vtkMultiBlockDataSet::SafeDownCast(this->GetInput());
    const std::string document = blockforge::vtkglue::findModelDocument(input);
    if (!input || document.empty())
    {
      throw std::runtime_error("the grid carries no BlockForge model (the output of "
                               "BlockMesher or GridQuality has one): its patches and block "
                               "interfaces are unknown, so " + fileName + " is not written");
    }
    const blockforge::model::BlockModel model = blockforge::model::readModelDocument(document);

    // One structured grid per model block, in model order; coordinates as doubles.
    std::vector<exporting::GridBlock> blocks;
    std::vector<std::vector<double>> converted;
    converted.reserve(model.blocks.size());
    vtkSmartPointer<vtkDataObjectTreeIterator> iterator;
    iterator.TakeReference(input->NewTreeIterator());
    iterator->VisitOnlyLeavesOn();
    iterator->SkipEmptyNodesOff();
    for (iterator->InitTraversal(); !iterator->IsDoneWithTraversal(); iterator->GoToNextItem())
    {
      const std::size_t b = blocks.size();
      const std::string name =
        b < model.blocks.size() ? model.blocks[b].name : std::to_string(b);
      auto* grid = vtkStructuredGrid::SafeDownCast(iterator->GetCurrentDataObject());
      if (!grid || !grid->GetPoints() || grid->GetNumberOfPoints() == 0)
      {
        throw std::runtime_error("block '" + name + "' has no grid here (a writer needs "
                                 "every block in one process)");
      }
      exporting::GridBlock block;
      block.name = name;
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
        converted.emplace_back(static_cast<std::size_t>(grid->GetNumberOfPoints()) * 3);
        for (vtkIdType p = 0; p < grid->GetNumberOfPoints(); ++p)
        {
          grid->GetPoint(p, converted.back().data() + 3 * p);
        }
        block.xyz = converted.back().data();
      }
      blocks.push_back(block);
    }
    const exporting::ExportGrid grid = exporting::exportGrid(model, std::move(blocks));
    this->UpdateProgress(0.1);
    this->WriteGrid(grid, [this](double fraction) { this->UpdateProgress(0.1 + 0.9 * fraction); });
    this->UpdateProgress(1.0);
  }
  catch (const std::exception& error)
  {
    this->SetErrorCode(vtkErrorCode::UserError);
    vtkErrorMacro(<< error.what());
  }
}

void vtkBlockGridWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
