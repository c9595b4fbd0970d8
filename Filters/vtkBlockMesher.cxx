#include "vtkBlockMesher.h"

#include "BlockForgeModelIO.h"

#include "../Model/ModelDocument.h"

#include <vtkDataObject.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStreamingDemandDrivenPipeline.h>

vtkStandardNewMacro(vtkBlockMesher);

vtkBlockMesher::vtkBlockMesher() = default;

int vtkBlockMesher::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  return 1;
}

int vtkBlockMesher::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  outputVector->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int vtkBlockMesher::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* input = vtkDataObject::GetData(inputVector[0], 0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  auto* output = vtkMultiBlockDataSet::GetData(outInfo);
  const std::string document = blockforge::vtkglue::findModelDocument(input);
  if (document.empty())
  {
    vtkErrorMacro("The input carries no BlockForge model (field data array '"
      << blockforge::model::ModelDocumentArrayName
      << "'): connect a BlockTemplateSource or BlockTemplate, or a .vtm saved from one.");
    return 0;
  }
  const int piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
  const int pieceCount =
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  try
  {
    this->UpdateProgress(0.0);
    const blockforge::model::BlockModel blockModel =
      blockforge::model::readModelDocument(document);
    std::vector<blockforge::model::InvertedCellReport> folds;
    blockforge::vtkglue::meshModel(blockModel, document, this->DensityMultiplier, 0, piece,
      pieceCount, output, [this](double fraction) { this->UpdateProgress(fraction); },
      nullptr,
      this->AllowInvertedCells ? blockforge::vtkglue::InvertedCellPolicy::Report
                               : blockforge::vtkglue::InvertedCellPolicy::Refuse,
      &folds, this->MaximumMemory);
    if (this->AllowInvertedCells)
    {
      vtkIdType inverted = 0;
      for (const auto& fold : folds)
      {
        vtkWarningMacro(<< "AllowInvertedCells is on, the grid is output anyway: "
                        << blockforge::vtkglue::printable(fold.message.c_str()));
        inverted += fold.cells;
      }
      vtkNew<vtkIdTypeArray> count;
      count->SetName("InvertedCellCount");
      count->InsertNextValue(inverted);
      output->GetFieldData()->AddArray(count);
    }
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    output->Initialize();
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkBlockMesher::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DensityMultiplier: " << this->DensityMultiplier << "\n";
  os << indent << "MaximumMemory: " << this->MaximumMemory << " GB\n";
  os << indent << "AllowInvertedCells: " << this->AllowInvertedCells << "\n";
}
