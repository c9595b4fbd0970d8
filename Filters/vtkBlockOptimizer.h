/**
 * @class   vtkBlockOptimizer
 * @brief   The paper's step 3 (section 2.4): control points slide along their carrier
 *          curves and surfaces until the final cells are as good as the geometry allows,
 *          automatically (NLopt) and by hand.
 *
 * Input: a block model in the field data (the output of vtkBlockTemplate or
 * vtkBlockTemplateSource, or a .vtm saved from them). Output port 0: the same block model
 * with moved vertices (document in the field data, so vtkBlockMesher meshes it), with a
 * coarse preview of every block like the template's, and the field data
 * MinAngleClassCountsBefore / MinAngleClassCountsAfter (cells per MinAngle class 0-20,
 * 20-40, 40-60, 60-80, 80-90 degrees of the grid at DensityMultiplier), MinAngleBefore /
 * MinAngleAfter, OptimizerEvaluations and ControlPointNames (the parameters that moved).
 * Output port 1: the history table (Evaluation, Objective, MinAngle, Time, Feasible).
 *
 * Manual moves (ControlPointMoves, or the handle: HandleControlPoint and HandlePosition,
 * projected onto the point's carrier) are applied first and hold their points during the
 * automatic run. The domain's boundary never moves; the result is never worse than the
 * input by the objective's own criterion, and the same input gives the same result bit
 * for bit.
 *
 * @sa vtkBlockTemplate vtkBlockMesher vtkGridQuality
 */
#ifndef vtkBlockOptimizer_h
#define vtkBlockOptimizer_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

#include <string>
#include <utility>
#include <vector>

class vtkStringArray;

class BLOCKFORGEFILTERS_EXPORT vtkBlockOptimizer : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkBlockOptimizer* New();
  vtkTypeMacro(vtkBlockOptimizer, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum ObjectiveKind
  {
    MIN_ANGLE = 0,            ///< maximise the smallest element angle (the paper's criterion)
    NON_ORTHOGONALITY = 1,    ///< minimise the largest OpenFOAM non-orthogonality
    MIN_ANGLE_AND_SIZE_RATIO = 2 ///< smallest angle less a weighted neighbour size ratio
  };

  ///@{
  /// What the automatic run improves (default MIN_ANGLE).
  vtkSetClampMacro(Objective, int, MIN_ANGLE, MIN_ANGLE_AND_SIZE_RATIO);
  vtkGetMacro(Objective, int);
  ///@}

  enum SearchAlgorithm
  {
    COMPASS = 0, ///< one control point parameter per step (cheap mesh-plan updates)
    BOBYQA = 1,  ///< NLopt BOBYQA: quadratic models of all parameters
    COBYLA = 2,  ///< NLopt COBYLA
    SUBPLEX = 3  ///< NLopt Sbplx
  };

  ///@{
  /// The search of the automatic run (default COMPASS).
  vtkSetClampMacro(Algorithm, int, COMPASS, SUBPLEX);
  vtkGetMacro(Algorithm, int);
  ///@}

  ///@{
  /// Largest number of grid evaluations of the automatic run (default 700; a run that stops gaining ends at 400, see SearchSettings::stallAfter); the compass
  /// search counts the trials it leaves out because they cannot gain as evaluations.
  vtkSetClampMacro(MaximumEvaluations, int, 1, 1000000);
  vtkGetMacro(MaximumEvaluations, int);
  ///@}

  ///@{
  /// The run stops when a step improves the objective by less than this (degrees for the
  /// angle objectives; default 1e-3).
  vtkSetClampMacro(Tolerance, double, 0.0, 1.0e3);
  vtkGetMacro(Tolerance, double);
  ///@}

  ///@{
  /// Largest neighbour cell-size ratio across block interfaces (periodic sides included)
  /// a trial may reach: a trial whose two cells across an interface differ more than the
  /// larger of this and the start grid's largest ratio is infeasible (default 1.6; 0: not
  /// held). Unheld, the optimized passages jumped 2.5-11.8 between blocks at density 1
  /// (issue 8); held, the smallest angle may end lower (the H template's turbine 20.4 ->
  /// 16.3 deg).
  vtkSetClampMacro(MaximumInterfaceRatio, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaximumInterfaceRatio, double);
  ///@}

  ///@{
  /// The grid the objective measures: the template's cell counts times this (as
  /// vtkBlockMesher's DensityMultiplier; default 1). Give the mesher's value, so the
  /// optimizer measures the final cells (a coarsened copy above 1e5 nodes).
  vtkSetMacro(DensityMultiplier, double); // validated when run, as the mesher's
  vtkGetMacro(DensityMultiplier, double);
  ///@}

  ///@{
  /// The grid at DensityMultiplier must fit in this memory (GB; default 0: what the
  /// machine has available), as vtkBlockMesher's MaximumMemory: a grid the mesher would
  /// refuse is refused before the optimizer works on it.
  vtkSetClampMacro(MaximumMemory, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaximumMemory, double);
  ///@}

  ///@{
  /// Off: only the manual moves are applied (default on).
  vtkSetMacro(Automatic, bool);
  vtkGetMacro(Automatic, bool);
  vtkBooleanMacro(Automatic, bool);
  ///@}

  ///@{
  /// On (default): the automatic run also skews the node distributions of block
  /// directions graded `ends` (a blade passage's O-grid sides), so that the H lines beside
  /// a staggered blade cross the passage at a fairer angle; off keeps every distribution
  /// as the template gives it.
  vtkSetMacro(SkewDistributions, bool);
  vtkGetMacro(SkewDistributions, bool);
  vtkBooleanMacro(SkewDistributions, bool);
  ///@}

  ///@{
  /// Control points (vertex names) that stay where the template put them.
  void AddFixedControlPoint(const char* name);
  void ClearFixedControlPoints();
  ///@}

  ///@{
  /// Manual moves: a control point's name and its new carrier parameters as text ("s" on
  /// a curve, "s t" on a surface). A moved point is held by the automatic run.
  void SetControlPointMove(const char* name, const char* parameters);
  void ClearControlPointMoves();
  ///@}

  ///@{
  /// The GUI's manual move: the control point the 3-D handle moves ("" for none) and the
  /// handle's position. An update with a newly chosen point only locates it
  /// (GetHandleControlPointPosition, where the handle is reset to); once the handle is
  /// dragged away from there, Apply projects its position onto the point's carrier and
  /// applies that as a manual move (held by the automatic run). One handle move at a
  /// time: ControlPointMoves keeps several.
  vtkSetStringMacro(HandleControlPoint);
  vtkGetStringMacro(HandleControlPoint);
  vtkSetVector3Macro(HandlePosition, double);
  vtkGetVector3Macro(HandlePosition, double);
  ///@}

  ///@{
  /// After an update: the control points a manual move can take (vertices with free
  /// carrier parameters), for the GUI's list, and the position of HandleControlPoint in
  /// the output model (where the handle starts; (0, 0, 0) when none).
  vtkStringArray* GetControlPointNames() { return this->ControlPointNames; }
  vtkGetVector3Macro(HandleControlPointPosition, double);
  ///@}

  ///@{
  /// Largest number of preview cells per block direction (0 = full resolution).
  vtkSetClampMacro(PreviewCells, int, 0, 1000);
  vtkGetMacro(PreviewCells, int);
  ///@}

protected:
  vtkBlockOptimizer();
  ~vtkBlockOptimizer() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Objective = MIN_ANGLE;
  int Algorithm = COMPASS;
  int MaximumEvaluations = 700;
  double Tolerance = 1.0e-3;
  double MaximumInterfaceRatio = 1.6;
  double DensityMultiplier = 1.0;
  double MaximumMemory = 0.0;
  bool Automatic = true;
  bool SkewDistributions = true;
  std::vector<std::string> FixedControlPoints;
  std::vector<std::pair<std::string, std::string>> ControlPointMoves;
  char* HandleControlPoint = nullptr;
  double HandlePosition[3] = { 0.0, 0.0, 0.0 };
  int PreviewCells = 8;
  vtkStringArray* ControlPointNames;
  double HandleControlPointPosition[3] = { 0.0, 0.0, 0.0 };
  /// The handle's control point as of the last update (its position is reported above).
  std::string LocatedControlPoint;

private:
  vtkBlockOptimizer(const vtkBlockOptimizer&) = delete;
  void operator=(const vtkBlockOptimizer&) = delete;
};

#endif
