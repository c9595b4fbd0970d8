/**
 * @class   vtkBlockPlot3DWriter
 * @brief   Writes a BlockForge grid as a Plot3D multi-grid file (.xyz), one grid per
 *          block, and its patches and block interfaces beside it as a Neutral Map File
 *          (same name, .nmf).
 *
 * Binary by default: Fortran unformatted records (32-bit lengths), 64-bit little-endian
 * coordinates, no iblank; vtkMultiBlockPLOT3DReader reads it with BinaryFile, MultiGrid,
 * HasByteCount and DoublePrecision on. ASCII on request (exact: shortest round-trip
 * numbers).
 *
 * @sa vtkBlockGridWriter vtkBlockFoamWriter
 */
#ifndef vtkBlockPlot3DWriter_h
#define vtkBlockPlot3DWriter_h

#include "BlockForgeFiltersModule.h"
#include "vtkBlockGridWriter.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockPlot3DWriter : public vtkBlockGridWriter
{
public:
  static vtkBlockPlot3DWriter* New();
  vtkTypeMacro(vtkBlockPlot3DWriter, vtkBlockGridWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Binary (default) or ASCII.
  vtkSetMacro(Binary, bool);
  vtkGetMacro(Binary, bool);
  vtkBooleanMacro(Binary, bool);
  ///@}

  ///@{
  /// Also write the Neutral Map File (patches and interfaces) beside the grid (default on).
  vtkSetMacro(WriteNeutralMap, bool);
  vtkGetMacro(WriteNeutralMap, bool);
  vtkBooleanMacro(WriteNeutralMap, bool);
  ///@}

protected:
  vtkBlockPlot3DWriter() = default;
  ~vtkBlockPlot3DWriter() override = default;

#ifndef __VTK_WRAP__
  void WriteGrid(const blockforge::exporting::ExportGrid& grid,
    const std::function<void(double)>& progress) override;
#endif

  bool Binary = true;
  bool WriteNeutralMap = true;

private:
  vtkBlockPlot3DWriter(const vtkBlockPlot3DWriter&) = delete;
  void operator=(const vtkBlockPlot3DWriter&) = delete;
};

#endif
