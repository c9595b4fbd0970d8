/**
 * @class   vtkBlockMesher
 * @brief   Generates the block-structured grid (paper step 4): node distributions along
 *          the edges, Coons face grids and trilinear transfinite interpolation (paper
 *          eq. 6) inside every block.
 *
 * Input: any data object carrying a BlockForge model in its field data (the output of
 * vtkBlockTemplateSource, of the optimizer, or a .vtm file saved from them). Output: a
 * vtkMultiBlockDataSet with one named vtkStructuredGrid per block and a BlockId cell
 * array; the model document is passed on in the field data. Every edge and face shared
 * by two blocks is computed once, so the nodes of a shared face coincide bit for bit.
 * Under MPI, blocks are shared out between the ranks by cell count (largest first, to
 * the rank with the fewest cells); large blocks are meshed on threads (vtkSMPTools).
 *
 * @sa vtkBlockTemplateSource vtkGridQuality
 */
#ifndef vtkBlockMesher_h
#define vtkBlockMesher_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockMesher : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkBlockMesher* New();
  vtkTypeMacro(vtkBlockMesher, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The paper's grid density multiplier: every cell count of the template is multiplied
  /// by it and rounded (at least one cell). Dimensionless, in (0, 1000]; default 1. Not
  /// clamped: a value outside the range (NaN, infinity, 0, negative) or one that makes a
  /// block direction exceed 1,000,000 cells is an error when the filter runs.
  vtkSetMacro(DensityMultiplier, double);
  vtkGetMacro(DensityMultiplier, double);
  ///@}

  ///@{
  /// Largest memory the grid may take, in GB (2^30 bytes); 0 (default) = only what the
  /// machine has available. A grid estimated to need more is refused before anything is
  /// allocated, with an error saying how much it would need.
  vtkSetMacro(MaximumMemory, double);
  vtkGetMacro(MaximumMemory, double);
  ///@}

  ///@{
  /// Off (default): a grid with an inverted cell (negative Jacobian at one of a cell's
  /// corners or its centre, the sign of GridQuality's ScaledJacobian) is an error naming
  /// the block, its cell range and the worst cell, and the output stays empty. On: the
  /// grid is output anyway so the folds can be inspected, with a warning per folded block
  /// and the field data array InvertedCellCount (cells found on this piece).
  vtkSetMacro(AllowInvertedCells, bool);
  vtkGetMacro(AllowInvertedCells, bool);
  vtkBooleanMacro(AllowInvertedCells, bool);
  ///@}

protected:
  vtkBlockMesher();
  ~vtkBlockMesher() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double DensityMultiplier = 1.0;
  double MaximumMemory = 0.0;
  bool AllowInvertedCells = false;

private:
  vtkBlockMesher(const vtkBlockMesher&) = delete;
  void operator=(const vtkBlockMesher&) = delete;
};

#endif
