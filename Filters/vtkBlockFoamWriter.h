/**
 * @class   vtkBlockFoamWriter
 * @brief   Writes a BlockForge grid as an OpenFOAM case: FileName DIR/NAME.foam gives
 *          DIR/constant/polyMesh (points, faces, owner, neighbour, boundary) and an empty
 *          NAME.foam that ParaView's OpenFOAM reader opens.
 *
 * Block interfaces become internal faces, template patches OpenFOAM patches (wall for
 * walls, cyclic with a rotational transform for periodic pairs, patch for inlets and
 * outlets), wedge blocks prism cells. Binary by default (fast, exact), ASCII on request.
 * Minimal system/ dictionaries are added when the case has none; an existing solver
 * set-up (0/, system/) is left alone. Cells are numbered block by block, i fastest, as
 * the blocks' cells, so GridQuality's cell arrays line up with OpenFOAM's cells.
 *
 * @sa vtkBlockGridWriter vtkBlockMesher
 */
#ifndef vtkBlockFoamWriter_h
#define vtkBlockFoamWriter_h

#include "BlockForgeFiltersModule.h"
#include "vtkBlockGridWriter.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockFoamWriter : public vtkBlockGridWriter
{
public:
  static vtkBlockFoamWriter* New();
  vtkTypeMacro(vtkBlockFoamWriter, vtkBlockGridWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Binary (default) or ASCII polyMesh files.
  vtkSetMacro(Binary, bool);
  vtkGetMacro(Binary, bool);
  vtkBooleanMacro(Binary, bool);
  ///@}

protected:
  vtkBlockFoamWriter() = default;
  ~vtkBlockFoamWriter() override = default;

#ifndef __VTK_WRAP__
  void WriteGrid(const blockforge::exporting::ExportGrid& grid,
    const std::function<void(double)>& progress) override;
#endif

  bool Binary = true;

private:
  vtkBlockFoamWriter(const vtkBlockFoamWriter&) = delete;
  void operator=(const vtkBlockFoamWriter&) = delete;
};

#endif
