/**
 * @class   vtkBlockGridWriter
 * @brief   Base of the solver-format writers: hands a block-structured grid with its
 *          block model (the output of vtkBlockMesher or vtkGridQuality) to a format writer.
 *
 * The input is a vtkMultiBlockDataSet with one vtkStructuredGrid per model block, in
 * model order, and the model document in its field data: the writers need the model's
 * interfaces, periodic pairs and patches, which a bare grid does not have (a grid without
 * a model is an error that says so). Subclasses write one format from the gathered grid;
 * files are written under a temporary name and moved into place, so a failure (an
 * unwritable folder, a full disk) leaves no partial grid and keeps an older one. Write()
 * returns 0 and the error is reported through vtkErrorMacro on any failure.
 *
 * Under MPI with GatherPieces on (ParaView's writer proxies turn it on: pvbatch, pvserver),
 * every rank asks the pipeline for its own piece (the mesher shares the blocks out), rank
 * 0 gathers the blocks of every rank and alone writes the files, which are the same bytes
 * as a serial run's; Write() returns the same on every rank. With GatherPieces off (the
 * default, plain VTK, also inside an MPI process) the whole grid is requested and written
 * by this process, with no communication.
 *
 * @sa vtkBlockFoamWriter vtkBlockMesher vtkGridQuality
 */
#ifndef vtkBlockGridWriter_h
#define vtkBlockGridWriter_h

#include "BlockForgeFiltersModule.h"
#include "vtkWriter.h"

#include <functional> // for the progress callback

#ifndef __VTK_WRAP__
namespace blockforge
{
namespace exporting
{
struct ExportGrid;
}
}
#endif

class BLOCKFORGEFILTERS_EXPORT vtkBlockGridWriter : public vtkWriter
{
public:
  vtkTypeMacro(vtkBlockGridWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The file to write (its meaning is the format's: see the subclasses).
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// Under MPI (more than one rank in the global controller): request this rank's piece and
  /// gather every rank's blocks to rank 0, which writes. Off by default (the whole grid is
  /// requested and written here); ParaView's writer proxies turn it on.
  vtkSetMacro(GatherPieces, bool);
  vtkGetMacro(GatherPieces, bool);
  vtkBooleanMacro(GatherPieces, bool);
  ///@}

  /// Asks for this rank's piece when gathering (see GatherPieces).
  vtkTypeBool ProcessRequest(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

protected:
  vtkBlockGridWriter();
  ~vtkBlockGridWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  void WriteData() override;

#ifndef __VTK_WRAP__
  /// Writes the grid to FileName; throws std::exception with a message for the user.
  /// `progress` takes fractions in [0, 1].
  virtual void WriteGrid(const blockforge::exporting::ExportGrid& grid,
    const std::function<void(double)>& progress) = 0;
#endif

  char* FileName = nullptr;
  bool GatherPieces = false;

private:
  vtkBlockGridWriter(const vtkBlockGridWriter&) = delete;
  void operator=(const vtkBlockGridWriter&) = delete;
};

#endif
