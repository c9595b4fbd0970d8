#include "vtkBlockFoamWriter.h"

#include "../Export/PolyMesh.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkBlockFoamWriter);

void vtkBlockFoamWriter::WriteGrid(
  const blockforge::exporting::ExportGrid& grid, const std::function<void(double)>& progress)
{
  blockforge::exporting::FoamWriteOptions options;
  options.binary = this->Binary;
  options.progress = progress;
  blockforge::exporting::writeFoamCase(grid, this->FileName, options);
}

void vtkBlockFoamWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Binary: " << this->Binary << "\n";
}
