#include "vtkBlockOptimizer.h"

#include "BlockForgeModelIO.h"

#include "../Model/CarrierGeometry.h"
#include "../Model/ModelDocument.h"
#include "../Model/Optimize/Optimizer.h"

#include <vtkCharArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtkTable.h>

#include <sstream>

vtkStandardNewMacro(vtkBlockOptimizer);

namespace
{
namespace optimize = blockforge::optimize;

/// "0.3" or "0.25 0.5" (spaces or commas) as numbers; throws naming the point otherwise.
std::vector<double> parseParameters(const std::string& name, const std::string& text)
{
  std::string spaced = text;
  for (char& c : spaced)
  {
    c = c == ',' ? ' ' : c;
  }
  std::istringstream stream(spaced);
  stream.imbue(std::locale::classic());
  std::vector<double> values;
  double value = 0.0;
  while (stream >> value)
  {
    values.push_back(value);
  }
  if (!stream.eof() || values.empty())
  {
    throw std::runtime_error("ControlPointMoves: the parameters of '" + name + "' are '" +
      text + "'; expected numbers: 's' on a curve or 's t' on a surface");
  }
  return values;
}

vtkSmartPointer<vtkIdTypeArray> classArray(
  const char* name, const optimize::GridMeasures& measures)
{
  vtkNew<vtkIdTypeArray> array;
  array->SetName(name);
  for (long long count : measures.classes)
  {
    array->InsertNextValue(static_cast<vtkIdType>(count));
  }
  return array.Get();
}

vtkSmartPointer<vtkDoubleArray> scalarArray(const char* name, double value)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  return array.Get();
}
} // namespace

vtkBlockOptimizer::vtkBlockOptimizer()
  : ControlPointNames(vtkStringArray::New())
{
  this->SetNumberOfOutputPorts(2);
}

vtkBlockOptimizer::~vtkBlockOptimizer()
{
  this->SetHandleControlPoint(nullptr);
  this->ControlPointNames->Delete();
}

void vtkBlockOptimizer::AddFixedControlPoint(const char* name)
{
  if (name && *name)
  {
    this->FixedControlPoints.emplace_back(name);
    this->Modified();
  }
}

void vtkBlockOptimizer::ClearFixedControlPoints()
{
  if (!this->FixedControlPoints.empty())
  {
    this->FixedControlPoints.clear();
    this->Modified();
  }
}

void vtkBlockOptimizer::SetControlPointMove(const char* name, const char* parameters)
{
  if (!name || !*name)
  {
    return;
  }
  const std::string value = parameters ? parameters : "";
  for (auto& move : this->ControlPointMoves)
  {
    if (move.first == name)
    {
      if (move.second != value)
      {
        move.second = value;
        this->Modified();
      }
      return;
    }
  }
  this->ControlPointMoves.emplace_back(name, value);
  this->Modified();
}

void vtkBlockOptimizer::ClearControlPointMoves()
{
  if (!this->ControlPointMoves.empty())
  {
    this->ControlPointMoves.clear();
    this->Modified();
  }
}

int vtkBlockOptimizer::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  return 1;
}

int vtkBlockOptimizer::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
  {
    return this->Superclass::FillOutputPortInformation(port, info);
  }
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkTable");
  return 1;
}

int vtkBlockOptimizer::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* input = vtkDataObject::GetData(inputVector[0], 0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  auto* output = vtkMultiBlockDataSet::GetData(outInfo);
  auto* history = vtkTable::GetData(outputVector, 1);
  history->Initialize();
  const std::string document = blockforge::vtkglue::findModelDocument(input);
  if (document.empty())
  {
    vtkErrorMacro("The input carries no BlockForge model (field data array '"
      << blockforge::model::ModelDocumentArrayName
      << "'): connect a BlockTemplate or BlockTemplateSource, or a .vtm saved from one.");
    output->Initialize();
    return 0;
  }
  const blockforge::vtkglue::RequestedPiece request = blockforge::vtkglue::requestedPiece(outInfo);
  const int piece = request.piece, pieceCount = request.count;
  try
  {
    this->UpdateProgress(0.0);
    const blockforge::model::BlockModel model = blockforge::model::readModelDocument(document);
    blockforge::model::CarrierGeometry geometry(model);
    optimize::OptimizerSettings settings;
    settings.objective.kind = static_cast<optimize::ObjectiveKind>(this->Objective);
    const optimize::SearchAlgorithm algorithms[] = { optimize::SearchAlgorithm::Compass,
      optimize::SearchAlgorithm::Bobyqa, optimize::SearchAlgorithm::Cobyla,
      optimize::SearchAlgorithm::Subplex };
    settings.search.algorithm = algorithms[this->Algorithm];
    if (settings.search.algorithm != optimize::SearchAlgorithm::Compass)
    {
      settings.search.initialStep = 0.02; // NLopt's models do better with smaller first steps
    }
    settings.search.maxEvaluations = this->MaximumEvaluations;
    settings.search.tolerance = this->Tolerance;
    settings.objective.maximumInterfaceRatio = this->MaximumInterfaceRatio;
    settings.densityMultiplier = this->DensityMultiplier;
    settings.maximumMemory = this->MaximumMemory;
    settings.automatic = this->Automatic;
    settings.skewDistributions = this->SkewDistributions;
    settings.fixed = this->FixedControlPoints;
    for (const auto& move : this->ControlPointMoves)
    {
      settings.moves.push_back({ move.first, parseParameters(move.first, move.second) });
    }
    // The handle moves its point once it has been located (an update with the same point
    // reported where it is) and has been dragged away from there.
    const bool handleLocated = this->HandleControlPoint && *this->HandleControlPoint &&
      this->LocatedControlPoint == this->HandleControlPoint;
    const bool handleDragged = handleLocated &&
      (this->HandlePosition[0] != this->HandleControlPointPosition[0] ||
        this->HandlePosition[1] != this->HandleControlPointPosition[1] ||
        this->HandlePosition[2] != this->HandleControlPointPosition[2]);
    if (handleDragged)
    {
      const blockforge::Vec3 point(
        this->HandlePosition[0], this->HandlePosition[1], this->HandlePosition[2]);
      const optimize::ControlPointMove move =
        optimize::moveTowards(model, geometry, this->HandleControlPoint, point);
      bool replaced = false;
      for (optimize::ControlPointMove& existing : settings.moves)
      {
        if (existing.name == move.name)
        {
          existing = move;
          replaced = true;
        }
      }
      if (!replaced)
      {
        settings.moves.push_back(move);
      }
    }
    this->UpdateProgress(0.05);
    const optimize::OptimizerResult result = optimize::optimizeModel(model, geometry, settings,
      [this](double fraction) { this->UpdateProgress(0.05 + 0.85 * fraction); });
    if (!result.after.feasible)
    {
      vtkWarningMacro(<< "The optimized model still cannot be meshed without inverted cells: "
                      << blockforge::vtkglue::printable(result.after.failure.c_str()));
    }
    if (result.keptStep < 1.0)
    {
      vtkWarningMacro(<< "The optimizer measured a coarsened copy (density "
                      << result.densityMultiplier << "); at DensityMultiplier "
                      << this->DensityMultiplier << " its best model folds or is worse than the start, so "
                      << (result.keptStep > 0.0 ? "part of its move was kept ("
                                                : "the template's model is kept (")
                      << result.keptStep << " of the way)");
    }
    // For the GUI: the points a move can take, and where the handle's point is now.
    this->ControlPointNames->Initialize();
    for (const blockforge::model::Vertex& vertex : result.model.vertices)
    {
      if (vertex.rule.kind == blockforge::model::VertexRule::Kind::OnCarrier)
      {
        this->ControlPointNames->InsertNextValue(vertex.name);
      }
    }
    const int handle = this->HandleControlPoint
      ? result.model.findVertex(this->HandleControlPoint)
      : -1;
    for (int c = 0; c < 3; ++c)
    {
      this->HandleControlPointPosition[c] =
        handle >= 0 ? result.model.vertices[handle].position[c] : 0.0;
    }
    this->LocatedControlPoint = handle >= 0 ? this->HandleControlPoint : "";
    const std::string moved = blockforge::model::writeModelDocument(result.model);
    const std::string previewWarning = blockforge::vtkglue::meshModel(result.model, moved, 1.0,
      this->PreviewCells, piece, pieceCount, output,
      [this](double fraction) { this->UpdateProgress(0.9 + 0.1 * fraction); }, &geometry,
      blockforge::vtkglue::InvertedCellPolicy::Skip, nullptr, this->MaximumMemory);
    if (!previewWarning.empty())
    {
      vtkWarningMacro(<< "The optimized model: " << previewWarning);
    }
    vtkFieldData* fields = output->GetFieldData();
    fields->AddArray(classArray("MinAngleClassCountsBefore", result.before));
    fields->AddArray(classArray("MinAngleClassCountsAfter", result.after));
    fields->AddArray(scalarArray("MinAngleBefore", result.before.minAngle));
    fields->AddArray(scalarArray("MinAngleAfter", result.after.minAngle));
    vtkNew<vtkIdTypeArray> evaluations;
    evaluations->SetName("OptimizerEvaluations");
    evaluations->InsertNextValue(result.search.evaluations);
    fields->AddArray(evaluations);
    vtkNew<vtkStringArray> names;
    names->SetName("ControlPointNames");
    for (const optimize::ControlVariable& variable : result.variables)
    {
      names->InsertNextValue(variable.name);
    }
    fields->AddArray(names);

    vtkNew<vtkIntArray> evaluation;
    evaluation->SetName("Evaluation");
    vtkNew<vtkDoubleArray> objective, minAngle, time;
    objective->SetName("Objective");
    minAngle->SetName("MinAngle");
    time->SetName("Time");
    vtkNew<vtkCharArray> feasible;
    feasible->SetName("Feasible");
    for (const optimize::HistoryEntry& entry : result.search.history)
    {
      evaluation->InsertNextValue(entry.evaluation);
      objective->InsertNextValue(entry.objective);
      minAngle->InsertNextValue(entry.minAngle);
      time->InsertNextValue(entry.seconds);
      feasible->InsertNextValue(entry.feasible ? 1 : 0);
    }
    history->AddColumn(evaluation);
    history->AddColumn(objective);
    history->AddColumn(minAngle);
    history->AddColumn(time);
    history->AddColumn(feasible);
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    output->Initialize();
    history->Initialize();
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkBlockOptimizer::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Objective: " << this->Objective << "\n";
  os << indent << "Algorithm: " << this->Algorithm << "\n";
  os << indent << "MaximumEvaluations: " << this->MaximumEvaluations << "\n";
  os << indent << "Tolerance: " << this->Tolerance << "\n";
  os << indent << "MaximumInterfaceRatio: " << this->MaximumInterfaceRatio << "\n";
  os << indent << "DensityMultiplier: " << this->DensityMultiplier << "\n";
  os << indent << "MaximumMemory: " << this->MaximumMemory << "\n";
  os << indent << "Automatic: " << this->Automatic << "\n";
  os << indent << "SkewDistributions: " << this->SkewDistributions << "\n";
  for (const std::string& name : this->FixedControlPoints)
  {
    os << indent << "FixedControlPoint: " << name << "\n";
  }
  for (const auto& move : this->ControlPointMoves)
  {
    os << indent << "ControlPointMove: " << move.first << " -> " << move.second << "\n";
  }
  os << indent << "HandleControlPoint: "
     << (this->HandleControlPoint ? this->HandleControlPoint : "(none)") << "\n";
  os << indent << "PreviewCells: " << this->PreviewCells << "\n";
}
