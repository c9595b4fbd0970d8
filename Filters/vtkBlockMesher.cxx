#include "vtkBlockMesher.h"

#include "BlockForgeModelIO.h"

#include "../Model/ModelDocument.h"

#include <vtkDataObject.h>
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
    blockforge::vtkglue::meshModel(blockModel, document, this->DensityMultiplier, 0, piece,
      pieceCount, output, [this](double fraction) { this->UpdateProgress(fraction); }, nullptr,
      this->MaximumMemory);
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
}
