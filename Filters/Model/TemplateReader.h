/**
 * @file TemplateReader.h
 * @brief Private to the template engine (not installed): the reader of one template text.
 * Its work is spread by responsibility: TemplateReader.cpp (sections: header, edges,
 * blocks, patches, faces), TemplateMachine.cpp (machine, inputs, parameters, definitions,
 * lazy resolution), TemplateCarriers.cpp (carriers from point sets and other carriers),
 * TemplateVertices.cpp (vertex rules and the queries on points and carriers); placement
 * itself is Placement.h's.
 */
#pragma once

#include "CarrierGeometry.h"
#include "ModelSyntax.h"
#include "Placement.h"
#include "Template.h"
#include "TemplateExpressions.h"

#include <Eigen/Geometry>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <limits>
#include <locale>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <sys/stat.h>

namespace blockforge
{
namespace model
{
namespace detail
{
using syntax::entity;
using syntax::lineOf;
using syntax::MapEntry;

/// The newest template format this build reads.
constexpr int TemplateFormatVersion = 2;
/// Cells per block direction; keeps node arrays well inside int range.
constexpr double MaxCellsPerDirection = 1.0e6;
constexpr double MaxBladeCount = 1.0e5;

/// The trailing `# comment` of a line, ignoring '#' inside quotes or glued to a word.
inline std::string trailingComment(const std::string& line)
{
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i)
  {
    const char c = line[i];
    if (quote)
    {
      quote = c == quote ? 0 : quote;
    }
    else if (c == '"' || c == '\'')
    {
      quote = c;
    }
    else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t'))
    {
      const std::size_t first = line.find_first_not_of(" \t#", i);
      if (first == std::string::npos)
      {
        return "";
      }
      const std::size_t last = line.find_last_not_of(" \t\r");
      return line.substr(first, last - first + 1);
    }
  }
  return "";
}

using syntax::shortNumber;

inline std::string fileStem(const std::string& path)
{
  std::string base = path.substr(path.find_last_of("/\\") + 1);
  const std::size_t dot = base.rfind('.');
  return dot == std::string::npos || dot == 0 ? base : base.substr(0, dot);
}

/// Reads one template text into a BlockModel; every failure is a located TemplateError.

class TemplateReader
{
public:
  TemplateReader(const std::string& text, const std::string& file,
    const ParameterOverrides& overrides, const TemplateInputs* inputs)
    : Text(text)
    , Overrides(overrides)
    , Inputs(inputs)
  {
    Report.file = file;
  }

  BlockModel readModel();

  /// The carriers built while reading (valid after readModel()).
  const CarrierGeometry& geometry() const { return Geometry; }

  std::vector<ParameterInfo> readParameterInfos();

private:
  // --- locations and messages ---------------------------------------------------------
  [[noreturn]] void fail(int line, const std::string& entityText, const std::string& what) const;

  SourceLocation where(int line) const { return SourceLocation{ Report.file, line }; }

  int lineOrFallback(const YAML::Node& node, int fallback) const;

  // --- values -----------------------------------------------------------------------
  double number(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what);

  syntax::NumberReader numberReader(const std::string& entityText);
  syntax::EdgeReader edgeReader(const std::string& entityText);

  Vec3 vector3(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what);

  std::string name(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what);

  std::vector<std::string> vertexNames() const;

  int vertexRef(const YAML::Node& node, int line, const std::string& entityText);

  /// The named edge called by `node` (`what` names the reference in messages, `advice`
  /// ends the message for an unknown name).
  int edgeRef(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what, const std::string& advice);

  void checkEntityName(const MapEntry& entry, const std::string& kind);

  // --- sections -----------------------------------------------------------------------
  void readHeader();

  const MapEntry* section(const std::string& key) const;

  void readParameters();

  void readVertices();

  /// `{position: [x, y, z]}` or `{rotate: v, angle: a, axis: [..], origin: [..]}`: the
  /// mapping form leaves room for the constraints of later format versions.
  void readVertexMapping(const MapEntry& entry, const std::string& entityText, Vertex& vertex);
  /// The vertex's `fixed: true|false` marker (false without one): the optimizer holds it.
  bool fixedMark(const MapEntry& entry, const std::string& entityText);

  void readEdges();

  /// A rotation axis given as [x, y, z]: must not be zero; returned as a unit vector.
  /// `what` names it in the message ("the machine axis must not be zero").
  Vec3 unitAxis(const MapEntry& axis, const std::string& entityText, const std::string& what);

  /// Adds an edge unless another one already joins the same two vertices.
  void addEdge(const Edge& edge, int line, const std::string& entityText);

  void readBlocks();

  void readGrading(const MapEntry& grading, const std::string& entityText, Block& block);
  /// Pops Referenced (pushed before reading `what`) and fails when `what` refers to a
  /// vertex a move can shift (movableVertices): its value would not follow the move.
  void refuseMovableReferences(int line, const std::string& entityText, const std::string& what);

  /// Format 2 `notes`: `name: {when: <expression>, say: "text with {expression}s"}`; the
  /// text of every note whose `when` is not 0 goes to Model.notes, each {expression}
  /// replaced by its value (how a template says which of its choices it made).
  void readNotes();

  void readPatches();

  BlockFace faceRef(const YAML::Node& node, int line, const std::string& entityText);

  /// Completes each periodic pair: the partner named on one side is set on the other, and
  /// the rotation given on one side is inverted for the other.
  void resolvePeriodicPartners(const std::vector<int>& lines, const std::vector<bool>& hasRotation);

  // ===================================================================== format 2
  struct BoundInput
  {
    const InputPointSet* set = nullptr;
    int line = 0;
  };
  // --- machine and inputs -------------------------------------------------------
  static bool isMachineName(const std::string& text);

  /// Unit vector perpendicular to the machine axis from which theta is measured: the
  /// x axis projected (the y axis when the machine axis is close to x).
  /// The direction of theta = 0 about `axis`: x (y when the axis is x), made normal to it.
  static Vec3 defaultReference(const Vec3& axis);

  /// theta = 0 about the machine axis: `machine: {theta_zero: ...}`, else the default.
  Vec3 referenceDirection() const;

  void cylindrical(const Vec3& p, double& axial, double& radius, double& theta) const;

  Vec3 fromCylindrical(double axial, double radius, double theta) const;

  void readMachineAndInputs();

  void bindInputs(const MapEntry& inputs);

  /// `theta_zero: [x, y, z]` (a direction) or `theta_zero: <input>` (the centroid of that
  /// input's points): where theta = 0 lies about the machine axis. Templates that compute
  /// in theta put their passage there, away from the seam theta = +-pi.
  void readThetaZero(const MapEntry& entry);

  std::vector<std::string> inputNames() const;

  std::vector<std::string> carrierNames() const;

  // --- resolution order ---------------------------------------------------------
  std::string resolvingChain(const std::string& last) const;

  void readCarriersAndVertices();

  /// Format 2 `definitions`: named expressions that may use parameters, machine values,
  /// vertex queries and other definitions, resolved when first used (in any order).
  void readDefinitionNames();

  /**
   * Resolves entity `entries[index]` of kind `kind` once (format 2 names resolve in any
   * order): `resolve(entry, entityText)` runs with the entity marked in progress, so a
   * reference back to it is reported as a cycle with the chain of entities being resolved.
   */
  template <typename Resolve>
  void resolveOnce(std::vector<int>& state, const std::vector<MapEntry>& entries, int index,
    const char* kind, Resolve&& resolve)
  {
    if (index < 0 || index >= static_cast<int>(state.size()) || state[index] == 2)
    {
      return; // done, or (carriers) hidden ones, complete when created
    }
    const MapEntry& entry = entries[index];
    const std::string entityText = entity(kind, entry.key);
    const std::string item = std::string(kind) + " '" + entry.key + "'";
    if (state[index] == 1)
    {
      fail(entry.line, entityText, "is defined in terms of itself: " + resolvingChain(item));
    }
    state[index] = 1;
    Resolving.push_back(item);
    resolve(entry, entityText);
    Resolving.pop_back();
    state[index] = 2;
  }

  void ensureDefinition(int index);

  void ensureVertex(int index);

  void defineVertexQueries(const Vertex& vertex);

  /// `revolve: ..., extend: f`: the contour continues straight along its end tangents by
  /// f times its length at both ends (short exports: inlet and outlet further out).
  void extendContour(std::vector<Vec3>& points, double fraction, int line,
    const std::string& entityText);

  /// `<revolve carrier>.axial_min` and `.axial_max`: where its contour starts and ends
  /// along the axis (an inlet or outlet plane must stay within them).
  void defineContourQueries(const Carrier& carrier, const std::vector<Vec3>& points);

  void ensureCarrier(int index);

  /// A carrier named in the template (declared or hidden), resolved; -1 if there is none.
  int findCarrierIndex(const std::string& carrierName);

  enum class Want
  {
    Curve,
    Surface,
    Any
  };

  int carrierRef(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what, Want want);

  /// Adds a fully defined carrier (sections of a Gordon surface, meridional contours).
  int addHiddenCarrier(Carrier carrier);
  // --- carriers -------------------------------------------------------------------
  /// A list of points [[x, y, z], ...] written in the template.
  std::vector<Vec3> pointList(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what);

  /// Input points without consecutive duplicates (exports often repeat a point where
  /// two pieces of a contour meet; interpolation needs distinct consecutive points).
  static std::vector<Vec3> withoutDuplicates(const std::vector<Vec3>& points);

  const BoundInput& inputRef(const std::string& inputName, int line, const std::string& entityText,
    const std::string& what);

  /// `degree` and `parameters` of an interpolation.
  void readInterpolationOptions(const std::vector<MapEntry>& keys, const std::string& entityText,
    Carrier& carrier);

  bool flag(const std::vector<MapEntry>& keys, const std::string& key, bool fallback,
    const std::string& entityText);

  /// Meridional image of a point: its (axial, radius) placed in the half-plane theta = 0.
  Vec3 meridional(const Vec3& p, const Vec3& axisPoint, const Vec3& axis) const;

  /// Parameters of a Gordon surface's sections: `at`, else the input's span fractions,
  /// else uniform.
  std::vector<double> sectionParameters(const MapEntry* at, std::size_t count,
    const std::vector<double>& spans, const std::string& entityText);

  void readCarrier(const MapEntry& entry, const std::string& entityText, int index, Carrier& carrier);

  /**
   * `align: axial`: re-parametrises a closed section so that s = 0.25 is its leading edge
   * (the smallest axial coordinate) and s = 0.75 its trailing edge (the largest), by chord
   * length between them and the seam s = 0 (half-way along the second side). Every section of the blade then has its edges at the same s, so lines of
   * constant s on the Gordon surface follow the edges from hub to shroud, and so do block
   * edges straight in the blade's (s, t) space.
   */
  void alignSection(Carrier& section);

  void checkClosedSection(const std::vector<Vec3>& points, const std::string& entityText,
    int line, const std::string& what);

  /// Tolerance for "lies on": 1e-9 of the larger of the vertices' and the carrier's size.
  double onTolerance(int carrier) const;

  double vertexSpan() const;

  void checkOnCarrier(int vertex, int carrier, double distance, int line, const std::string& entityText);
  // --- vertices (format 2) ----------------------------------------------------------
  /// A point given as [x, y, z], {cylindrical: [axial, radius, theta]} or a vertex name.
  Vec3 pointValue(const YAML::Node& node, int line, const std::string& entityText,
    const std::string& what);

  Vec3 cylindricalValue(const MapEntry& entry, const std::string& entityText);

  /// The values x, y, z, axial, radius, theta of a point, in that order.
  void pointVariables(const Vec3& p, double* values) const;

  /// Parameter u of curve `carrier` in [from, to] (which may pass the seam of a closed
  /// curve) where `value` is smallest (sign = 1) or largest (-1): a sample of 512 points,
  /// then golden-section search in the bracketing interval.
  double extremum(int carrier, const std::function<double(const Vec3&)>& value, double sign,
    double from, double to);

  /// The same on any curve point(u) (u wraps when `closed`).
  static double extremum(const std::function<Vec3(double)>& point, bool closed,
    const std::function<double(const Vec3&)>& value, double sign, double from, double to);

  /// Parameter u where curve `curve` meets surface `surface`.
  double curveSurfaceIntersection(int curve, int surface, const MapEntry* near,
    const std::string& entityText, int line);

  /// Parameters (s, t) of the point of a surface of revolution about the machine axis at
  /// the given axial position and angle theta: the contour's first crossing of the axial
  /// plane (bisection to rounding), then the exact meridional projection.
  void onRevolutionAt(int surface, double axial, double theta, const std::string& entityText,
    int line, double& s, double& t);

  /// `at: {length: f}`, `at: {min: q}` or `at: {max: q}` (q: x, y, z, axial, radius, theta
  /// or an expression of them), optionally `within: [u0, u1]`: a parameter of `curve`.
  double curveParameterQuery(const MapEntry& at, int curve, const std::string& entityText);

  void readVertexV2(const MapEntry& entry, const std::string& entityText, Vertex& vertex);

  /// Records the expressions `texts` that gave `vertex`'s parameters as its placement
  /// expressions when they referred to vertices (Referenced.back()).
  void recordPlacementExpressions(
    Vertex& vertex, PlacementExpressions::Form form, const std::vector<std::string>& texts);

  /// The template's expression scope, when some vertex follows others (after reading).
  void recordExpressionScope();
  // --- edges and faces (format 2) --------------------------------------------------
  bool isEdgeV2(const MapEntry& entry) const;

  void readEdgeV2(const MapEntry& entry, const std::string& entityText);

  /// Faces whose grids lie on surfaces: {on_surface: S, faces: [block.face | [4 vertices]]}.
  void readFaces();

  BlockFace faceByVertices(const YAML::Node& node, int line, const std::string& entityText);

  const std::string& Text;
  const ParameterOverrides& Overrides;
  const TemplateInputs* Inputs = nullptr;
  bool InfoOnly = false;
  int Version = 1;
  std::map<std::string, BoundInput> BoundInputs;
  CarrierGeometry Geometry;
  std::vector<MapEntry> CarrierEntries, VertexEntries;
  /// theta = 0 direction (machine: theta_zero); NaN: the default.
  Vec3 ThetaZero = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<MapEntry> DefinitionEntries;
  std::map<std::string, int> DefinitionIndex;
  std::vector<int> CarrierState, VertexState, DefinitionState; // 0 pending, 1 in progress, 2 done
  std::vector<std::string> Resolving;         // entities being resolved, for cycles
  /// Vertices the expressions being evaluated refer to, directly or through definitions
  /// (one set per entity being resolved, innermost last), and those of each definition:
  /// what a vertex placed by expressions follows (PlacementExpressions).
  std::vector<std::set<int>> Referenced;
  std::vector<std::set<int>> DefinitionVertices;
  /// movableVertices(Model), once the blocks' gradings need it.
  std::vector<char> Movable;
  syntax::Reporter Report;
  ExpressionEvaluator Evaluator;
  std::vector<MapEntry> Sections;
  std::string Name;
  BlockModel Model;
  std::vector<ParameterInfo> Infos;
};
} // namespace detail
} // namespace model
} // namespace blockforge
