/**
 * @class   vtkBlockTemplateSource
 * @brief   Applies a parameter-only BlockForge template (paper steps 1-2): reads the
 *          template file, evaluates its parameters (with overrides) and outputs a coarse
 *          preview of every block together with the block model.
 *
 * The output is a vtkMultiBlockDataSet with one named vtkStructuredGrid per block (at
 * most PreviewCells cells per direction) and, in its field data, the string array
 * "BlockForgeModel": the resolved model as a versioned document that vtkBlockMesher
 * rebuilds the model from (also after saving to .vtm and reading back).
 * The model is checked before output (shared-edge node counts, inside-out blocks,
 * interfaces, patches); a failure is reported with vtkErrorMacro naming the template
 * file, line and entity, and the output is left empty. Templates that read point sets
 * (an `inputs:` section) need vtkBlockTemplate instead.
 *
 * @sa vtkBlockTemplate vtkBlockMesher vtkGridQuality
 */
#ifndef vtkBlockTemplateSource_h
#define vtkBlockTemplateSource_h

#include "BlockForgeFiltersModule.h"
#include "vtkBlockTemplateAlgorithm.h"

class BLOCKFORGEFILTERS_EXPORT vtkBlockTemplateSource : public vtkBlockTemplateAlgorithm
{
public:
  static vtkBlockTemplateSource* New();
  vtkTypeMacro(vtkBlockTemplateSource, vtkBlockTemplateAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkBlockTemplateSource();
  ~vtkBlockTemplateSource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkBlockTemplateSource(const vtkBlockTemplateSource&) = delete;
  void operator=(const vtkBlockTemplateSource&) = delete;
};

#endif
