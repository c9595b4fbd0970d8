#include "vtkBlockTemplateSource.h"

#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkBlockTemplateSource);

vtkBlockTemplateSource::vtkBlockTemplateSource()
{
  this->SetNumberOfInputPorts(0);
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
  return this->ApplyTemplate(nullptr, outputVector);
}

void vtkBlockTemplateSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
