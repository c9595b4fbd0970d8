/**
 * @class   vtkBlockCGNSWriter
 * @brief   Writes a BlockForge grid as CGNS (.cgns, HDF5): one structured zone per block,
 *          GridConnectivity1to1 for every block interface, periodic pairs as 1-to-1
 *          connectivity with their rotation, boundary conditions by family (one family
 *          per template patch: walls BCWall, inlets BCInflow, outlets BCOutflow).
 *
 * Unlike a generic CGNS writer, it knows the block model the grid carries, so the file
 * holds the block connectivity and the patches a solver needs.
 *
 * @sa vtkBlockGridWriter vtkBlockFoamWriter vtkBlockPlot3DWriter
 */
#ifndef vtkBlockCGNSWriter_h
#define vtkBlockCGNSWriter_h

#include "BlockForgeFiltersModule.h"
#include "vtkBlockGridWriter.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockCGNSWriter : public vtkBlockGridWriter
{
public:
  static vtkBlockCGNSWriter* New();
  vtkTypeMacro(vtkBlockCGNSWriter, vtkBlockGridWriter);

protected:
  vtkBlockCGNSWriter() = default;
  ~vtkBlockCGNSWriter() override = default;

#ifndef __VTK_WRAP__
  void WriteGrid(const blockforge::exporting::ExportGrid& grid,
    const std::function<void(double)>& progress) override;
#endif

private:
  vtkBlockCGNSWriter(const vtkBlockCGNSWriter&) = delete;
  void operator=(const vtkBlockCGNSWriter&) = delete;
};

#endif
