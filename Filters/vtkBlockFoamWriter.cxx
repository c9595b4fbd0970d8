#include "vtkBlockFoamWriter.h"

#include "../Export/PolyMesh.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkBlockFoamWriter);

void vtkBlockFoamWriter::WriteGrid(
  const blockforge::exporting::ExportGrid& grid, const std::function<void(double)>& progress)
{
  const blockforge::exporting::PolyMesh mesh = blockforge::exporting::buildPolyMesh(grid);
  progress(0.3);
  blockforge::exporting::FoamWriteOptions options;
  options.binary = this->Binary;
  options.progress = [&](double fraction) { progress(0.3 + 0.7 * fraction); };
  blockforge::exporting::writeFoamCase(mesh, this->FileName, options);
}

void vtkBlockFoamWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Binary: " << this->Binary << "\n";
}
