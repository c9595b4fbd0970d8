#include "vtkTurboPointSetsReader.h"

#include "TurboPointSets.h"

#include "BlockForgeFileStamps.h"
#include "BlockForgeModelIO.h"

#include <vtkCellArray.h>
#include <vtkCompositeDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>

#include <string>

vtkStandardNewMacro(vtkTurboPointSetsReader);

namespace
{
void addString(vtkFieldData* fields, const char* name, const std::string& value)
{
  vtkNew<vtkStringArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fields->AddArray(array);
}

std::string closureName(blockforge::io::Closure closure, blockforge::io::EdgeCap cap)
{
  switch (closure)
  {
    case blockforge::io::Closure::Open:
      return "open";
    case blockforge::io::Closure::Joined:
      return "joined";
    case blockforge::io::Closure::Segment:
      return "segment";
    case blockforge::io::Closure::Capped:
      return cap == blockforge::io::EdgeCap::Rounded ? "capped rounded" : "capped straight";
    default:
      return "closed";
  }
}

void addInt(vtkFieldData* fields, const char* name, int value)
{
  vtkNew<vtkIntArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fields->AddArray(array);
}

void addDoubles(vtkFieldData* fields, const char* name, const double* values, int count)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfComponents(count);
  array->InsertNextTuple(values);
  fields->AddArray(array);
}

/// One polyline through the points, scaled to metres, with its origin in field data.
vtkSmartPointer<vtkPolyData> makeCurve(const blockforge::io::PointSet& set, double scale)
{
  const vtkIdType count = static_cast<vtkIdType>(set.points.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(count);
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfValues(count);
  for (vtkIdType i = 0; i < count; ++i)
  {
    const Eigen::Vector3d p = set.points[static_cast<std::size_t>(i)] * scale;
    points->SetPoint(i, p.x(), p.y(), p.z());
    connectivity->SetValue(i, i);
  }
  vtkNew<vtkIdTypeArray> offsets;
  offsets->InsertNextValue(0);
  offsets->InsertNextValue(count);
  vtkNew<vtkCellArray> lines;
  lines->SetData(offsets, connectivity);

  auto curve = vtkSmartPointer<vtkPolyData>::New();
  curve->SetPoints(points);
  curve->SetLines(lines);
  addString(curve->GetFieldData(), "SourceFile", set.file);
  addInt(curve->GetFieldData(), "FirstLine", set.firstLine);
  return curve;
}

std::string text(const char* value)
{
  return value ? value : "";
}
} // namespace

struct vtkTurboPointSetsReader::Internals
{
  blockforge::vtkglue::FileStamps Stamps;
};

vtkTurboPointSetsReader::vtkTurboPointSetsReader()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SetAxis("Z");
  this->SetUnits("M");
}

vtkTurboPointSetsReader::~vtkTurboPointSetsReader()
{
  this->SetFileName(nullptr);
  this->SetHubFile(nullptr);
  this->SetShroudFile(nullptr);
  this->SetProfileFile(nullptr);
  this->SetAxis(nullptr);
  this->SetUnits(nullptr);
}

int vtkTurboPointSetsReader::CanReadFile(const char* fileName)
{
  return fileName && blockforge::io::canReadTurboPointSets(fileName) ? 1 : 0;
}

vtkMTimeType vtkTurboPointSetsReader::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->Internal->Stamps.changeTime());
}

int vtkTurboPointSetsReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // The curves are small: piece 0 carries them, other pieces only the block structure.
  outputVector->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
  // Read once here too (the files are small) so that the values found in them are known
  // before the first Apply; errors are reported by RequestData.
  try
  {
    this->ReadSets(nullptr, false);
  }
  catch (const std::exception&)
  {
  }
  return 1;
}

void vtkTurboPointSetsReader::ReadSets(vtkMultiBlockDataSet* result, bool holdsData)
{
  this->BladeCountFound.clear();
  this->AxisFound.clear();
  this->UnitsFound.clear();
  this->DescriptionFound.clear();
  // Watched for edits from now on, also when reading fails (fixing the file reads it).
  this->Internal->Stamps.remember({ text(this->FileName), text(this->HubFile),
    text(this->ShroudFile), text(this->ProfileFile) });
  blockforge::io::ReadOptions options;
  options.hubFile = text(this->HubFile);
  options.shroudFile = text(this->ShroudFile);
  options.profileFile = text(this->ProfileFile);
  options.bladeCount = this->BladeCount;
  options.axis = text(this->Axis);
  options.units = text(this->Units);
  options.cap = this->TrailingEdgeCap == Rounded ? blockforge::io::EdgeCap::Rounded
                                                 : blockforge::io::EdgeCap::Straight;
  if (text(this->FileName).empty() && options.hubFile.empty() && options.shroudFile.empty() &&
    options.profileFile.empty())
  {
    throw std::runtime_error("No FileName set: choose a BladeGen .inf, an Info.txt or a point "
                             "file (.curve, .crv, .dat, .csv).");
  }

  const blockforge::io::TurboPointSets sets = blockforge::io::readTurboPointSets(
    text(this->FileName), options, [this, result](double fraction) {
      if (result)
      {
        this->UpdateProgress(0.8 * fraction);
      }
    });
  auto fallback = [](const std::string& value)
  { return "(not in the files: " + value + " used)"; };
  this->BladeCountFound = sets.bladeCountFromFiles ? std::to_string(sets.bladeCount)
                                                   : fallback(std::to_string(sets.bladeCount));
  this->AxisFound = sets.axisFromFiles ? sets.axisName : fallback(sets.axisName);
  this->UnitsFound = sets.unitsFromFiles ? sets.units : fallback(sets.units);
  this->DescriptionFound = sets.descriptionFile;
  std::vector<std::string> filesRead = { text(this->FileName), text(this->HubFile),
    text(this->ShroudFile), text(this->ProfileFile), sets.descriptionFile, sets.hub.file,
    sets.shroud.file };
  for (const auto& section : sets.profiles)
  {
    filesRead.push_back(section.file);
  }
  this->Internal->Stamps.remember(filesRead);
  if (!result)
  {
    return;
  }
  for (const auto& warning : sets.warnings)
  {
    vtkWarningMacro(<< blockforge::vtkglue::printable(warning.c_str()));
  }

  result->SetNumberOfBlocks(3);
  const blockforge::io::PointSet* contours[2] = { &sets.hub, &sets.shroud };
  const char* contourNames[2] = { "Hub", "Shroud" };
  for (unsigned int i = 0; i < 2; ++i)
  {
    if (holdsData && !contours[i]->points.empty())
    {
      result->SetBlock(i, makeCurve(*contours[i], sets.scale));
    }
    result->GetMetaData(i)->Set(vtkCompositeDataSet::NAME(), contourNames[i]);
  }

  vtkNew<vtkMultiBlockDataSet> profiles;
  const unsigned int count = static_cast<unsigned int>(sets.profiles.size());
  profiles->SetNumberOfBlocks(count);
  for (unsigned int k = 0; k < count; ++k)
  {
    const auto& section = sets.profiles[k];
    if (holdsData)
    {
      vtkSmartPointer<vtkPolyData> curve = makeCurve(section, sets.scale);
      const double fraction = section.spanPercent / 100.0;
      addDoubles(curve->GetFieldData(), "SpanFraction", &fraction, 1);
      addInt(curve->GetFieldData(), "SpanGiven", section.spanGiven ? 1 : 0);
      addInt(curve->GetFieldData(), "ProfileNumber", section.number);
      addString(curve->GetFieldData(), "Closure", closureName(section.closure, options.cap));
      addDoubles(curve->GetFieldData(), "GapFraction", &section.gapFraction, 1);
      if (!section.blade.empty())
      {
        addString(curve->GetFieldData(), "BladeName", section.blade);
      }
      profiles->SetBlock(k, curve);
    }
    profiles->GetMetaData(k)->Set(vtkCompositeDataSet::NAME(), section.name.c_str());
    this->UpdateProgress(0.8 + 0.2 * (k + 1) / count);
  }
  result->SetBlock(2, profiles);
  result->GetMetaData(2u)->Set(vtkCompositeDataSet::NAME(), "Profiles");

  vtkFieldData* fields = result->GetFieldData();
  addInt(fields, "BladeCount", sets.bladeCount);
  addInt(fields, "BladesPerSet", sets.bladesPerSet);
  addDoubles(fields, "Axis", sets.axis.data(), 3);
  addString(fields, "AxisName", sets.axisName);
  addString(fields, "Units", sets.units);
  addDoubles(fields, "UnitScale", &sets.scale, 1);
  if (!sets.descriptionFile.empty())
  {
    addString(fields, "DescriptionFile", sets.descriptionFile);
  }
}

int vtkTurboPointSetsReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  auto* output = vtkMultiBlockDataSet::GetData(outInfo);
  const int piece = blockforge::vtkglue::requestedPiece(outInfo).piece;
  this->UpdateProgress(0.0);
  vtkNew<vtkMultiBlockDataSet> result;
  try
  {
    // Piece 0 holds the curves; the other pieces the same blocks with null leaves.
    this->ReadSets(result, piece == 0);
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< blockforge::vtkglue::printable(error.what()));
    output->Initialize();
    return 0;
  }
  output->ShallowCopy(result);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTurboPointSetsReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  auto show = [](const char* value) { return value && *value ? value : "(none)"; };
  os << indent << "FileName: " << show(this->FileName) << "\n";
  os << indent << "HubFile: " << show(this->HubFile) << "\n";
  os << indent << "ShroudFile: " << show(this->ShroudFile) << "\n";
  os << indent << "ProfileFile: " << show(this->ProfileFile) << "\n";
  os << indent << "BladeCount: " << this->BladeCount << "\n";
  os << indent << "Axis: " << show(this->Axis) << "\n";
  os << indent << "TrailingEdgeCap: " << this->TrailingEdgeCap << "\n";
  os << indent << "Units: " << show(this->Units) << "\n";
}
