/**
 * @class   vtkGridQuality
 * @brief   Cell quality of a block-structured hexahedral grid, with the paper's element
 *          angle classes.
 *
 * Adds these cell arrays to every vtkStructuredGrid block of the input:
 * - MinAngle, MaxAngle: smallest/largest corner angle of the cell's 6 faces [degrees]
 *   (the paper's criterion; below 20 degrees harms accuracy and convergence); a prism
 *   written as a hexahedron (a collapsed edge: wedge blocks on an axis, fans on a sharp
 *   blade tip) leaves out its apex at the collapsed edge, whose angle is the share of the
 *   wedge or the tip's turn the cells round it divide, geometry no node placement fixes;
 * - NonOrthogonality: OpenFOAM's angle between a face normal and the line joining the
 *   two cell centres (OpenFOAM's cell centres: volume centroids), maximum over the cell's
 *   faces, block interfaces and periodic faces included [degrees];
 * - Skewness: OpenFOAM's face skewness (checkMesh's), maximum over the cell's faces [-];
 * - AspectRatio: longest over shortest mean cell width [-];
 * - ScaledJacobian: Verdict's hex scaled Jacobian (1 = cube, negative = inverted) [-];
 * - CellDeterminant: OpenFOAM checkMesh's cell determinant (-allGeometry;
 *   primitiveMeshTools::cellDeterminant): |det(sum (S_f/a)(S_f/a)^T)| / 8 over the
 *   cell's internal faces, block interfaces and periodic faces included, true boundary
 *   faces (walls, inlet, outlet) and faces without area left out, a their mean |S_f|;
 *   1 for a cube, V^4/a^6 for a parallelepiped inside the grid. checkMesh fails cells
 *   under 0.001: thin cells (a box thinner than about 1/29 of both other sides), and
 *   much sooner cells that lost a face to the boundary (a unit cube with one boundary
 *   face has 0.5, with two opposite ones 0) [-];
 * - BlockId: index of the block.
 *
 * Output port 0 is the input with these arrays; its field data holds
 * MinAngleClassCounts (cells with MinAngle in [0,20), [20,40), [40,60), [60,80),
 * [80,90] degrees) and, for every measure, "<Measure>Summary" (min, mean, max).
 * Output port 1 is a table of the MinAngle classes for a bar chart (columns Class,
 * Cells, bin_extents: the class centre angle, which ParaView's charts take as the x axis),
 * and the field data MinAngleClassPercent; output port 2 a table of the statistics
 * (Measure, Min, Mean, Max). The grid's active cell scalars are MinAngle.
 * Under MPI the class counts and statistics are global.
 *
 * Periodic faces are paired when the input carries its block model (the mesher's output
 * does): the model's topology names the periodic pairs and their rotation, and across a
 * periodic face the partner cell's centre is rotated into place, as OpenFOAM's cyclic
 * patches do. Under MPI (the pipeline in pieces on several ranks) the ranks exchange the
 * two node layers beside every interface and periodic face between their blocks, so
 * every measure equals the serial run's bit for bit. Large blocks are measured on
 * threads (vtkSMPTools), with the same bits.
 *
 * @sa vtkBlockMesher
 */
#ifndef vtkGridQuality_h
#define vtkGridQuality_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

class BLOCKFORGEFILTERS_EXPORT vtkGridQuality : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkGridQuality* New();
  vtkTypeMacro(vtkGridQuality, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Largest memory the quality arrays may take, in GB (2^30 bytes); 0 (default) = only
  /// what the machine has available. Checked before anything is allocated.
  vtkSetMacro(MaximumMemory, double);
  vtkGetMacro(MaximumMemory, double);
  ///@}

protected:
  vtkGridQuality();
  ~vtkGridQuality() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double MaximumMemory = 0.0;

private:
  vtkGridQuality(const vtkGridQuality&) = delete;
  void operator=(const vtkGridQuality&) = delete;
};

#endif
