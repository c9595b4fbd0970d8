/**
 * @class   vtkBlockTemplate
 * @brief   Applies a BlockForge template to point sets (paper steps 1-2, section 2.2): the
 *          template engine of vtkBlockTemplateSource, fed with the hub, shroud and blade
 *          sections of its input.
 *
 * Input: a vtkMultiBlockDataSet of named point sets, as vtkTurboPointSetsReader writes it:
 * blocks "Hub" and "Shroud" (a vtkPolyData polyline each) and "Profiles" (a
 * vtkMultiBlockDataSet of one polyline per blade section, field data "SpanFraction"); the
 * root's field data "BladeCount" and "Axis" give the machine. Any other named polydata
 * or multiblock of polydata works the same way: the template's `inputs:` section binds
 * its names to the block names. Points are taken in polyline order (point order without
 * lines).
 *
 * The template (format 2, Templates/README.md) builds carriers from the point sets
 * (interpolated curves, surfaces of revolution, Gordon surfaces, intersections), attaches
 * vertices to them (the control points of the optimizer) and defines the blocks. Output:
 * like vtkBlockTemplateSource, a preview grid of every block (at most PreviewCells cells
 * per direction) and the model document in the field data array "BlockForgeModel", which
 * carries the carriers' definitions with their points, so vtkBlockMesher (also after a
 * .vtm round trip) rebuilds the same geometry bit for bit.
 *
 * Output port 1 ("Carriers") shows the carriers the template declares, one named block
 * each: curves as polylines, surfaces as sampled structured grids over their (s, t) range
 * (piece 0 only).
 *
 * Errors (template, unknown point set, vertex off its carrier, periodic mismatch, ...) are
 * reported with vtkErrorMacro as "file:line: entity: what" and leave the output empty.
 * Every MPI rank requests the whole input (the point sets are small) and previews its
 * share of the blocks.
 *
 * @sa vtkTurboPointSetsReader vtkBlockTemplateSource vtkBlockMesher
 */
#ifndef vtkBlockTemplate_h
#define vtkBlockTemplate_h

#include "BlockForgeFiltersModule.h"
#include "vtkBlockTemplateAlgorithm.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockTemplate : public vtkBlockTemplateAlgorithm
{
public:
  static vtkBlockTemplate* New();
  vtkTypeMacro(vtkBlockTemplate, vtkBlockTemplateAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkBlockTemplate();
  ~vtkBlockTemplate() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkBlockTemplate(const vtkBlockTemplate&) = delete;
  void operator=(const vtkBlockTemplate&) = delete;
};

#endif
