#include "vtkBlockPlot3DWriter.h"

#include "../Export/Plot3D.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkBlockPlot3DWriter);

void vtkBlockPlot3DWriter::WriteGrid(
  const blockforge::exporting::ExportGrid& grid, const std::function<void(double)>& progress)
{
  blockforge::exporting::Plot3DOptions options;
  options.binary = this->Binary;
  options.progress = progress;
  const std::string path = this->FileName;
  blockforge::exporting::writePlot3D(grid, path, options);
  if (this->WriteNeutralMap)
  {
    const std::size_t dot = path.find_last_of('.');
    const std::size_t slash = path.find_last_of('/');
    const std::string stem =
      dot != std::string::npos && (slash == std::string::npos || dot > slash) ? path.substr(0, dot)
                                                                               : path;
    blockforge::exporting::writePlot3DNeutralMap(grid, stem + ".nmf");
  }
}

void vtkBlockPlot3DWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Binary: " << this->Binary << "\n";
  os << indent << "WriteNeutralMap: " << this->WriteNeutralMap << "\n";
}
