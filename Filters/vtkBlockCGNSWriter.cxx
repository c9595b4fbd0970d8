#include "vtkBlockCGNSWriter.h"

#include "../Export/Cgns.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkBlockCGNSWriter);

void vtkBlockCGNSWriter::WriteGrid(
  const blockforge::exporting::ExportGrid& grid, const std::function<void(double)>& progress)
{
  blockforge::exporting::writeCgns(grid, this->FileName, progress);
}
