/**
 * @file ModelDocument.h
 * @brief The block model as a versioned text document, so it can travel between pipeline
 * stages in a field-data string array (surviving .vtm save/load, client-server and MPI).
 * Numbers are written with 17 significant digits: reading gives back the same doubles.
 */
#pragma once

#include "BlockModel.h"

namespace blockforge
{
namespace model
{
/// Name of the vtkStringArray in field data that carries the document.
constexpr const char* ModelDocumentArrayName = "BlockForgeModel";

std::string writeModelDocument(const BlockModel& model);
/// Throws TemplateError (file "<model document>") on a malformed or newer document.
BlockModel readModelDocument(const std::string& document);
} // namespace model
} // namespace blockforge
