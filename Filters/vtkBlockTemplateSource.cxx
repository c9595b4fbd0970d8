#include "vtkBlockTemplateSource.h"

#include "BlockForgeModelIO.h"

#include "../Model/ModelDocument.h"
#include "../Model/Template.h"

#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include <iterator>

vtkStandardNewMacro(vtkBlockTemplateSource);

vtkBlockTemplateSource::vtkBlockTemplateSource()
{
  this->SetNumberOfInputPorts(0);
}

vtkBlockTemplateSource::~vtkBlockTemplateSource()
{
  this->SetTemplateFile(nullptr);
}

void vtkBlockTemplateSource::SetParameter(const char* name, const char* expression)
{
  if (!name || !*name)
  {
    return;
  }
  const std::string value = expression ? expression : "";
  auto found = this->Parameters.find(name);
  if (found != this->Parameters.end() && found->second == value)
  {
    return;
  }
  this->Parameters[name] = value;
  this->Modified();
}

void vtkBlockTemplateSource::ClearParameters()
{
  if (!this->Parameters.empty())
  {
    this->Parameters.clear();
    this->Modified();
  }
}

int vtkBlockTemplateSource::GetNumberOfParameters() const
{
  return static_cast<int>(this->Parameters.size());
}

const char* vtkBlockTemplateSource::GetParameterName(int index) const
{
  if (index < 0 || index >= this->GetNumberOfParameters())
  {
    return nullptr;
  }
  return std::next(this->Parameters.begin(), index)->first.c_str();
}

const char* vtkBlockTemplateSource::GetParameterExpression(int index) const
{
  if (index < 0 || index >= this->GetNumberOfParameters())
  {
    return nullptr;
  }
  return std::next(this->Parameters.begin(), index)->second.c_str();
}

int vtkBlockTemplateSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // Each MPI rank previews its own share of the blocks.
  outputVector->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int vtkBlockTemplateSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  auto* output = vtkMultiBlockDataSet::GetData(outInfo);
  this->ModelDocument.clear();
  if (!this->TemplateFile || !*this->TemplateFile)
  {
    vtkErrorMacro("No TemplateFile set: choose a BlockForge template (.yaml).");
    return 0;
  }
  const int piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
  const int pieceCount =
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  try
  {
    this->UpdateProgress(0.0);
    const blockforge::model::BlockModel blockModel =
      blockforge::model::loadTemplate(this->TemplateFile, this->Parameters);
    this->UpdateProgress(0.3);
    const std::string document = blockforge::model::writeModelDocument(blockModel);
    blockforge::vtkglue::meshModel(blockModel, document, 1.0, this->PreviewCells, piece,
      pieceCount, output, [this](double fraction) { this->UpdateProgress(0.3 + 0.7 * fraction); });
    this->ModelDocument = document;
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    output->Initialize();
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkBlockTemplateSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TemplateFile: " << (this->TemplateFile ? this->TemplateFile : "(none)")
     << "\n";
  os << indent << "PreviewCells: " << this->PreviewCells << "\n";
  for (const auto& parameter : this->Parameters)
  {
    os << indent << "Parameter " << parameter.first << " = " << parameter.second << "\n";
  }
}
