/**
 * @file BlockForgeModelIO.h
 * @brief Private glue between the VTK pipeline and the block model: the model travels as
 * a versioned text document in a field-data string array, which survives saving to .vtm,
 * client-server transfers and MPI.
 */
#pragma once

#include "../Model/BlockModel.h"
#include "../Model/GridCheck.h"

#include <string>

class vtkDataObject;
class vtkFieldData;
class vtkInformation;

namespace blockforge
{
namespace model
{
struct TemplateInputs;
class CarrierGeometry;
}
namespace vtkglue
{
/**
 * The point sets of a filter input for a template (format 2 `inputs:`): every named block
 * of the root multiblock that is a vtkPolyData becomes one curve (points in polyline
 * order), every named multiblock of polydata a list of curves (with their "SpanFraction"),
 * a null block an empty set; the root's field data "Axis" and "BladeCount" give the
 * machine. Throws std::runtime_error when the input is not a multiblock.
 */
void readTemplateInputs(vtkDataObject* input, model::TemplateInputs& inputs);

/// Stores the model document in `fieldData` (replacing an older one).
void attachModel(vtkFieldData* fieldData, const std::string& document);
/// The model document carried by `object`'s field data, or "" if none.
std::string findModelDocument(vtkDataObject* object);

/// The piece an output request asks for and of how many: (0, 1) when the request does
/// not say (a plain VTK pipeline), as ParaView's ranks each ask for their own.
struct RequestedPiece
{
  int piece = 0;
  int count = 1;
};
RequestedPiece requestedPiece(vtkInformation* outInfo);
} // namespace vtkglue
} // namespace blockforge

#include <functional>
#include <string>
#include <vector>

class vtkMultiBlockDataSet;

namespace blockforge
{
namespace model
{
class MultiBlockMesher;
}
namespace vtkglue
{
/// What meshing does with a block grid that has inverted cells (model::checkBlockCells).
enum class InvertedCellPolicy
{
  Refuse, ///< throw the located error naming the block and the cell range (the default)
  Report, ///< keep the grid and add the message to the report list (inspection)
  Skip    ///< no check (coarse previews, whose capped cell counts are not the grid)
};

/**
 * Fills `output` with one named vtkStructuredGrid per model block (the points written
 * by the mesher directly into the VTK array, no second copy) and a BlockId cell array.
 * Blocks not assigned to this piece (model::balancedPieces: shared out by cells) are left
 * empty so every MPI rank has the same structure. `progress` gets a fraction in [0, 1].
 */
void fillMultiBlock(const model::BlockModel& model, const model::MultiBlockMesher& mesher,
  vtkMultiBlockDataSet* output, int piece, int pieceCount,
  const std::function<void(double)>& progress,
  InvertedCellPolicy policy = InvertedCellPolicy::Refuse,
  std::vector<model::InvertedCellReport>* reports = nullptr);

/**
 * Meshes `model` (density multiplier, optional cell cap for previews) into `output`
 * through fillMultiBlock and attaches `document` to the output's field data. Before any
 * grid memory is allocated, the memory this piece's grid needs is checked against the
 * available memory and `maximumMemoryGigabytes` (<= 0: no user limit). Throws
 * (TemplateError, GeometryError, ResourceError) on any problem, inverted cells included
 * unless `policy` says otherwise (then each block's message goes to `reports`); `output`
 * is only touched on success.
 *
 * A preview (`cellCap` > 0 or policy Skip) whose capped grid folds at a block corner
 * (model::FoldError) is no error: its cell counts are not the grid's, which BlockMesher
 * checks at the density it meshes. Then `output` holds the model document without
 * blocks, so the model is passed on, and the returned text (for a warning) says why the
 * preview is not drawn. Model errors and memory refusals stay errors. Returns "" when the
 * grid was drawn.
 */
std::string meshModel(const model::BlockModel& model, const std::string& document,
  double densityMultiplier, int cellCap, int piece, int pieceCount,
  vtkMultiBlockDataSet* output, const std::function<void(double)>& progress,
  const model::CarrierGeometry* carriers = nullptr,
  InvertedCellPolicy policy = InvertedCellPolicy::Refuse,
  std::vector<model::InvertedCellReport>* reports = nullptr,
  double maximumMemoryGigabytes = 0.0);

/// `text` with bytes that are not UTF-8 escaped (\xNN), for vtkErrorMacro: Python's error
/// observers and ParaView's Output Messages get a readable message whatever the input.
std::string printable(const char* text);
} // namespace vtkglue
} // namespace blockforge
