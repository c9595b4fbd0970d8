#include "vtkBlockTemplateAlgorithm.h"

#include "BlockForgeFileStamps.h"
#include "BlockForgeModelIO.h"

#include "../Model/CarrierGeometry.h"
#include "../Model/ModelDocument.h"
#include "../Model/Template.h"

#include <vtkCellArray.h>
#include <vtkCompositeDataSet.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtkFieldData.h>
#include <vtkStructuredGrid.h>

#include <iomanip>
#include <iterator>
#include <sstream>

namespace
{
std::string trimmed(const std::string& text)
{
  const std::size_t first = text.find_first_not_of(" \t");
  const std::size_t last = text.find_last_not_of(" \t");
  return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
}
} // namespace

struct vtkBlockTemplateAlgorithm::Internals
{
  blockforge::vtkglue::FileStamps TemplateStamp;
  /// The parameter table and what it was read from.
  vtkNew<vtkStringArray> ParameterTable;
  std::string TableFile;
  vtkMTimeType TableTime = 0;
  vtkMTimeType TableRunTime = 0;
  vtkTimeStamp RunTime;
};

vtkBlockTemplateAlgorithm::vtkBlockTemplateAlgorithm()
  : Internal(new Internals)
{
}

vtkMTimeType vtkBlockTemplateAlgorithm::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->Internal->TemplateStamp.changeTime());
}

vtkStringArray* vtkBlockTemplateAlgorithm::GetTemplateParameters()
{
  Internals& internal = *this->Internal;
  const std::string file = this->TemplateFile ? this->TemplateFile : "";
  const vtkMTimeType fileTime = internal.TemplateStamp.changeTime();
  if (file == internal.TableFile && fileTime == internal.TableTime &&
    internal.RunTime.GetMTime() == internal.TableRunTime)
  {
    return internal.ParameterTable;
  }
  internal.TableFile = file;
  internal.TableTime = fileTime;
  internal.TableRunTime = internal.RunTime.GetMTime();
  vtkStringArray* table = internal.ParameterTable;
  table->Initialize();
  if (file.empty())
  {
    return table;
  }
  try
  {
    for (const auto& parameter : blockforge::model::templateParameters(file))
    {
      table->InsertNextValue(parameter.name);
      table->InsertNextValue(parameter.expression);
      const auto value = this->ParameterValues.find(parameter.name);
      std::ostringstream text;
      if (value != this->ParameterValues.end())
      {
        text << std::setprecision(10) << value->second;
      }
      table->InsertNextValue(text.str());
      // The comment is the description, with the unit in its last [...].
      std::string description = parameter.comment;
      std::string unit;
      const std::size_t open = description.rfind('[');
      const std::size_t close = description.rfind(']');
      if (open != std::string::npos && close != std::string::npos && close > open)
      {
        unit = trimmed(description.substr(open + 1, close - open - 1));
        description = trimmed(description.substr(0, open) + description.substr(close + 1));
      }
      table->InsertNextValue(unit);
      table->InsertNextValue(description);
    }
  }
  catch (const std::exception&)
  {
    table->Initialize(); // the run reports the error, with file and line
  }
  return table;
}

vtkBlockTemplateAlgorithm::~vtkBlockTemplateAlgorithm()
{
  this->SetTemplateFile(nullptr);
}

void vtkBlockTemplateAlgorithm::SetParameter(const char* name, const char* expression)
{
  if (!name || !*name)
  {
    return;
  }
  const std::string value = expression ? expression : "";
  auto found = this->Parameters.find(name);
  if (found != this->Parameters.end() && found->second == value)
  {
    return;
  }
  this->Parameters[name] = value;
  this->Modified();
}

void vtkBlockTemplateAlgorithm::ClearParameters()
{
  if (!this->Parameters.empty())
  {
    this->Parameters.clear();
    this->Modified();
  }
}

int vtkBlockTemplateAlgorithm::GetNumberOfParameters() const
{
  return static_cast<int>(this->Parameters.size());
}

const char* vtkBlockTemplateAlgorithm::GetParameterName(int index) const
{
  if (index < 0 || index >= this->GetNumberOfParameters())
  {
    return nullptr;
  }
  return std::next(this->Parameters.begin(), index)->first.c_str();
}

const char* vtkBlockTemplateAlgorithm::GetParameterExpression(int index) const
{
  if (index < 0 || index >= this->GetNumberOfParameters())
  {
    return nullptr;
  }
  return std::next(this->Parameters.begin(), index)->second.c_str();
}

namespace
{
/// One block per carrier declared in the template (not the sections and contours made
/// along the way): curves as polylines of 257 points, surfaces as 65 x 65 grids.
void fillCarriers(const blockforge::model::BlockModel& model,
  const blockforge::model::CarrierGeometry& geometry, vtkMultiBlockDataSet* output)
{
  unsigned int block = 0;
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    const std::string& name = model.carriers[c].name;
    if (name.find('.') != std::string::npos)
    {
      continue;
    }
    const int index = static_cast<int>(c);
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    vtkSmartPointer<vtkDataObject> data;
    if (geometry.isSurface(index))
    {
      const int n = 65;
      const double t0 = 0.0;
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          const blockforge::Vec3 p = geometry.point(
            index, static_cast<double>(i) / (n - 1), t0 + static_cast<double>(j) / (n - 1));
          points->InsertNextPoint(p.data());
        }
      }
      vtkNew<vtkStructuredGrid> grid;
      grid->SetDimensions(n, n, 1);
      grid->SetPoints(points);
      data = grid;
    }
    else
    {
      const int n = 257;
      vtkNew<vtkCellArray> lines;
      lines->InsertNextCell(n);
      for (int i = 0; i < n; ++i)
      {
        const blockforge::Vec3 p = geometry.point(index, static_cast<double>(i) / (n - 1));
        points->InsertNextPoint(p.data());
        lines->InsertCellPoint(i);
      }
      vtkNew<vtkPolyData> curve;
      curve->SetPoints(points);
      curve->SetLines(lines);
      data = curve;
    }
    output->SetBlock(block, data);
    output->GetMetaData(block)->Set(vtkCompositeDataSet::NAME(), name.c_str());
    ++block;
  }
}
} // namespace

int vtkBlockTemplateAlgorithm::ApplyTemplate(
  vtkDataObject* input, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  auto* output = vtkMultiBlockDataSet::GetData(outInfo);
  vtkMultiBlockDataSet* carriers = this->GetNumberOfOutputPorts() > 1
    ? vtkMultiBlockDataSet::GetData(outputVector, 1)
    : nullptr;
  if (carriers)
  {
    carriers->Initialize();
  }
  this->ModelDocument.clear();
  this->ParameterValues.clear();
  this->Internal->RunTime.Modified();
  // Watched for edits from now on, also when it fails (fixing the file runs it again).
  this->Internal->TemplateStamp.remember(
    { this->TemplateFile ? std::string(this->TemplateFile) : std::string() });
  if (!this->TemplateFile || !*this->TemplateFile)
  {
    vtkErrorMacro("No TemplateFile set: choose a BlockForge template (.yaml).");
    output->Initialize();
    return 0;
  }
  const blockforge::vtkglue::RequestedPiece request = blockforge::vtkglue::requestedPiece(outInfo);
  const int piece = request.piece, pieceCount = request.count;
  try
  {
    this->UpdateProgress(0.0);
    blockforge::model::TemplateInputs inputs;
    const bool hasInput = input != nullptr;
    if (hasInput)
    {
      blockforge::vtkglue::readTemplateInputs(input, inputs);
    }
    this->UpdateProgress(0.05);
    blockforge::model::CarrierGeometry geometry;
    const blockforge::model::BlockModel blockModel = blockforge::model::loadTemplate(
      this->TemplateFile, this->Parameters, hasInput ? &inputs : nullptr, &geometry);
    this->UpdateProgress(0.4);
    const std::string document = blockforge::model::writeModelDocument(blockModel);
    const std::string previewWarning = blockforge::vtkglue::meshModel(blockModel, document,
      1.0, this->PreviewCells, piece, pieceCount, output,
      [this](double fraction) { this->UpdateProgress(0.4 + 0.55 * fraction); }, &geometry,
      // The preview's capped cell counts are not the grid: BlockMesher checks the cells.
      blockforge::vtkglue::InvertedCellPolicy::Skip, nullptr, this->MaximumMemory);
    if (!previewWarning.empty())
    {
      vtkWarningMacro(<< this->TemplateFile << ": " << previewWarning);
    }
    if (carriers && piece == 0)
    {
      fillCarriers(blockModel, geometry, carriers);
    }
    // What the template chose (its notes): a warning each, and the field data
    // TemplateNotes, so that the choice is seen in the GUI, in scripts and on the command line.
    vtkNew<vtkStringArray> notes;
    notes->SetName("TemplateNotes");
    for (const std::string& note : blockModel.notes)
    {
      vtkWarningMacro(<< this->TemplateFile << ": " << note);
      notes->InsertNextValue(note);
    }
    output->GetFieldData()->AddArray(notes);
    this->ModelDocument = document;
    for (const auto& parameter : blockModel.parameters)
    {
      this->ParameterValues[parameter.first] = parameter.second;
    }
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    output->Initialize();
    if (carriers)
    {
      carriers->Initialize();
    }
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkBlockTemplateAlgorithm::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TemplateFile: " << (this->TemplateFile ? this->TemplateFile : "(none)")
     << "\n";
  os << indent << "PreviewCells: " << this->PreviewCells << "\n";
  os << indent << "MaximumMemory: " << this->MaximumMemory << " GB\n";
  for (const auto& parameter : this->Parameters)
  {
    os << indent << "Parameter " << parameter.first << " = " << parameter.second << "\n";
  }
}
