/**
 * @file Template.h
 * @brief The template engine: reads a BlockForge template (format version 1 or 2, YAML
 * syntax, the paper's "macro file"), evaluates its parameter expressions and builds the
 * BlockModel. The format is documented in Templates/README.md.
 */
#pragma once

#include "BlockModel.h"
#include "Errors.h"

#include <limits>
#include <stdexcept>

namespace blockforge
{
namespace model
{
/// Parameter overrides: name -> expression (may use other parameters).
using ParameterOverrides = std::map<std::string, std::string>;

/// One curve of input points (a hub contour, one blade section).
struct InputCurve
{
  std::string name;
  std::vector<Vec3> points;
  double span = std::numeric_limits<double>::quiet_NaN(); ///< sections: span fraction
};

/// A named point set of the filter input: one curve ("Hub") or a list ("Profiles").
struct InputPointSet
{
  std::string name;
  bool isList = false;
  std::vector<InputCurve> curves;
};

/**
 * The point data a template of format 2 is applied to (the paper's user input data):
 * what vtkBlockTemplate takes from the TurboPointSetsReader output, or what a test builds.
 */
struct TemplateInputs
{
  std::vector<InputPointSet> pointSets;
  bool hasMachine = false;   ///< the axis below is the machine's
  Vec3 axis = Vec3::UnitZ(); ///< machine axis (unit vector) through axisPoint
  Vec3 axisPoint = Vec3::Zero();
  int bladeCount = 0;        ///< 0: unknown
  std::string origin = "the filter input"; ///< for messages
};

class CarrierGeometry;

/// Reads and applies a template file. Throws TemplateError (missing file, YAML syntax
/// error, bad expression, unknown name, wrong count of vertices, ...). Templates with an
/// `inputs:` section need `inputs`. With `carriers`, the carriers built on the way are
/// handed over (the same bit for bit as CarrierGeometry(model); the blade intersections
/// are most of the work, so the caller need not build them again).
BlockModel loadTemplate(const std::string& path, const ParameterOverrides& overrides = {},
  const TemplateInputs* inputs = nullptr, CarrierGeometry* carriers = nullptr);

/// Same, from text; `fileName` is used in messages only.
BlockModel parseTemplate(const std::string& text, const std::string& fileName,
  const ParameterOverrides& overrides = {}, const TemplateInputs* inputs = nullptr,
  CarrierGeometry* carriers = nullptr);

/// A template parameter as declared (for GUIs and --help style listings).
struct ParameterInfo
{
  std::string name;
  std::string expression; ///< as written in the template
  double value = 0.0;     ///< evaluated with the overrides
  std::string comment;    ///< trailing comment (units), may be empty
};
std::vector<ParameterInfo> templateParameters(const std::string& path,
  const ParameterOverrides& overrides = {}, const TemplateInputs* inputs = nullptr);
} // namespace model
} // namespace blockforge
