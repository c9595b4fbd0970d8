/**
 * @class   vtkBlockTemplateAlgorithm
 * @brief   What vtkBlockTemplateSource and vtkBlockTemplate share: the template file, the
 *          parameter overrides, the preview resolution and the run of the template engine
 *          (paper steps 1-2) into a preview of every block plus the model document.
 *
 * Abstract: use vtkBlockTemplateSource (parameter-only templates, no input) or
 * vtkBlockTemplate (templates that read point sets from their input).
 *
 * @sa vtkBlockTemplateSource vtkBlockTemplate vtkBlockMesher
 */
#ifndef vtkBlockTemplateAlgorithm_h
#define vtkBlockTemplateAlgorithm_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

#include <map>
#include <memory>
#include <string>

class vtkDataObject;
class vtkStringArray;

class BLOCKFORGEFILTERS_EXPORT vtkBlockTemplateAlgorithm : public vtkMultiBlockDataSetAlgorithm
{
public:
  vtkTypeMacro(vtkBlockTemplateAlgorithm, vtkMultiBlockDataSetAlgorithm);
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

  ///@{
  /// Largest memory the preview grid may take, in GB (2^30 bytes); 0 (default) = only
  /// what the machine has available (see vtkBlockMesher::SetMaximumMemory).
  vtkSetMacro(MaximumMemory, double);
  vtkGetMacro(MaximumMemory, double);
  ///@}

  /// The model document of the last successful run ("" before or after a failure).
  const char* GetModelDocument() const { return this->ModelDocument.c_str(); }

  /**
   * The parameters the template declares, five strings per parameter: name, default
   * expression (as written), value in the last successful run ("" before one), unit and
   * description (from the comment on the parameter's line, `# radius [m]`). Read from
   * TemplateFile when asked (again when the file changed); empty without a readable
   * template. ParaView's panel lists them (information property TemplateParameters).
   */
  vtkStringArray* GetTemplateParameters();

  /// Reads the template (and, for vtkBlockTemplate, gets the input) again at the next
  /// update, although nothing changed: ParaView's Reload Files.
  void Reload() { this->Modified(); }

  /// Also newer when the template file was edited on disk since it was last seen, so
  /// that an update reads the edited template.
  vtkMTimeType GetMTime() override;

protected:
  vtkBlockTemplateAlgorithm();
  ~vtkBlockTemplateAlgorithm() override;

  /**
   * Runs the template on `input` (the point sets of a TurboPointSetsReader; nullptr for a
   * parameter-only template) and fills output port 0 (block previews and the model
   * document) and, when the algorithm has a second output port, port 1 with the carriers
   * (curves as polylines, surfaces as sampled structured grids, one named block each).
   * Errors are reported with vtkErrorMacro ("file:line: entity: what") and leave the
   * outputs empty; returns 0 then.
   */
  int ApplyTemplate(vtkDataObject* input, vtkInformationVector* outputVector);

  char* TemplateFile = nullptr;
  int PreviewCells = 8;
  double MaximumMemory = 0.0;
  std::map<std::string, std::string> Parameters;
  std::string ModelDocument;
  /// Parameter values of the last successful run.
  std::map<std::string, double> ParameterValues;

  struct Internals;
  std::unique_ptr<Internals> Internal;

private:
  vtkBlockTemplateAlgorithm(const vtkBlockTemplateAlgorithm&) = delete;
  void operator=(const vtkBlockTemplateAlgorithm&) = delete;
};

#endif
