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
 * file, line and entity, and the output is left empty.
 *
 * @sa vtkBlockMesher vtkGridQuality
 */
#ifndef vtkBlockTemplateSource_h
#define vtkBlockTemplateSource_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

#include <map>
#include <string>

class BLOCKFORGEFILTERS_EXPORT vtkBlockTemplateSource : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkBlockTemplateSource* New();
  vtkTypeMacro(vtkBlockTemplateSource, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Path of the template file (YAML syntax, see Templates/README.md).
  vtkSetStringMacro(TemplateFile);
  vtkGetStringMacro(TemplateFile);
  ///@}

  ///@{
  /// Overrides a template parameter with an expression (for instance "R", "0.6" or
  /// "n_around", "2*16"). Unknown names are reported as errors when the template runs.
  void SetParameter(const char* name, const char* expression);
  void ClearParameters();
  /// Number of overrides set, and their names/expressions (for scripting).
  int GetNumberOfParameters() const;
  const char* GetParameterName(int index) const;
  const char* GetParameterExpression(int index) const;
  ///@}

  ///@{
  /// Largest number of preview cells per block direction (0 = full resolution).
  vtkSetClampMacro(PreviewCells, int, 0, 1000);
  vtkGetMacro(PreviewCells, int);
  ///@}

  /// The model document of the last successful run ("" before or after a failure).
  const char* GetModelDocument() const { return this->ModelDocument.c_str(); }

protected:
  vtkBlockTemplateSource();
  ~vtkBlockTemplateSource() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* TemplateFile = nullptr;
  int PreviewCells = 8;
  std::map<std::string, std::string> Parameters;
  std::string ModelDocument;

private:
  vtkBlockTemplateSource(const vtkBlockTemplateSource&) = delete;
  void operator=(const vtkBlockTemplateSource&) = delete;
};

#endif
