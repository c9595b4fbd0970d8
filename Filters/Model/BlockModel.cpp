#include "BlockModel.h"

#include <algorithm>

namespace blockforge
{
namespace model
{
const std::vector<std::string>& carrierKindNames()
{
  static const std::vector<std::string> names = { "interpolate", "revolve", "gordon", "network",
    "coons", "surface_curve", "intersect", "offset" };
  return names;
}

int BlockModel::findVertex(const std::string& vertexName) const
{
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    if (vertices[i].name == vertexName)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

int BlockModel::findBlock(const std::string& blockName) const
{
  for (std::size_t i = 0; i < blocks.size(); ++i)
  {
    if (blocks[i].name == blockName)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

int BlockModel::findCarrier(const std::string& carrierName) const
{
  for (std::size_t i = 0; i < carriers.size(); ++i)
  {
    if (carriers[i].name == carrierName)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

int BlockModel::requiredFormat() const
{
  for (const Vertex& vertex : vertices)
  {
    if (vertex.rule.expressions.form != PlacementExpressions::Form::None)
    {
      return 4;
    }
  }
  for (const Edge& edge : edges)
  {
    if (!edge.atFollows.empty())
    {
      return 4;
    }
  }
  for (const Carrier& carrier : carriers)
  {
    for (const int vertex : carrier.throughVertices)
    {
      if (vertex >= 0)
      {
        return 4;
      }
    }
  }
  for (const Vertex& vertex : vertices)
  {
    // Rules the constraint does not imply travel as such from format 3 on.
    if (vertex.rule.kind != impliedRule(vertex.constraint).kind)
    {
      return 3;
    }
  }
  if (machine.defined || !carriers.empty() || !surfaceFaces.empty())
  {
    return 2;
  }
  for (const Vertex& vertex : vertices)
  {
    if (vertex.constraint.carrier >= 0 || vertex.constraint.periodicSource >= 0)
    {
      return 2;
    }
  }
  for (const Edge& edge : edges)
  {
    if (edge.kind != Edge::Kind::Line && edge.kind != Edge::Kind::Arc &&
      edge.kind != Edge::Kind::Spline)
    {
      return 2;
    }
  }
  for (const Patch& patch : patches)
  {
    if (patch.pitches != 0)
    {
      return 2;
    }
  }
  return 1;
}

double Machine::pitch() const
{
  return bladeCount > 0 ? 2.0 * 3.14159265358979323846 / bladeCount : 0.0;
}

int BlockModel::findEdge(int a, int b) const
{
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    const Edge& edge = edges[i];
    if ((edge.from == a && edge.to == b) || (edge.from == b && edge.to == a))
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

int BlockModel::findNamedEdge(const std::string& edgeName) const
{
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    if (edges[i].name == edgeName)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

namespace
{
const char* const FaceNames[6] = { "i0", "i1", "j0", "j1", "k0", "k1" };

// Tables follow the local numbering of Transfinite.h (paper Fig. 7, 0-based).
const std::array<int, 2> EdgeVertexTable[12] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 },
  { 4, 5 }, { 5, 6 }, { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 2, 6 }, { 3, 7 } };
const std::array<int, 4> FaceCornerTable[6] = { { 0, 3, 7, 4 }, { 1, 2, 6, 5 },
  { 0, 1, 5, 4 }, { 3, 2, 6, 7 }, { 0, 1, 2, 3 }, { 4, 5, 6, 7 } };
const std::array<int, 4> FaceEdgeTable[6] = { { 3, 7, 8, 11 }, { 1, 5, 9, 10 },
  { 0, 4, 8, 9 }, { 2, 6, 11, 10 }, { 0, 2, 3, 1 }, { 4, 6, 7, 5 } };
const std::array<int, 2> FaceDirectionTable[6] = { { 1, 2 }, { 1, 2 }, { 0, 2 }, { 0, 2 },
  { 0, 1 }, { 0, 1 } };
}

const std::vector<std::string>& edgeKindNames()
{
  static const std::vector<std::string> names = { "line", "arc", "spline", "on_curve",
    "on_surface", "project", "periodic", "follow" };
  return names;
}

bool edgeKindFromName(const std::string& name, Edge::Kind& kind)
{
  const std::vector<std::string>& names = edgeKindNames();
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end())
  {
    return false;
  }
  kind = static_cast<Edge::Kind>(found - names.begin());
  return true;
}

const std::vector<std::string>& carrierEdgeKindNames()
{
  static const std::vector<std::string> names(
    edgeKindNames().begin() + static_cast<int>(Edge::Kind::OnCurve), edgeKindNames().end());
  return names;
}

VertexRule impliedRule(const VertexConstraint& constraint)
{
  VertexRule rule;
  rule.kind = constraint.periodicSource >= 0 ? VertexRule::Kind::Periodic
    : constraint.carrier >= 0                ? VertexRule::Kind::OnCarrier
                                             : VertexRule::Kind::Fixed;
  return rule;
}

const std::vector<std::string>& vertexRuleNames()
{
  static const std::vector<std::string> names = { "fixed", "on_carrier", "intersection",
    "projected", "periodic", "rotated" };
  return names;
}

const char* faceName(int face)
{
  return face >= 0 && face < 6 ? FaceNames[face] : "?";
}

int faceFromName(const std::string& name)
{
  for (int f = 0; f < 6; ++f)
  {
    if (name == FaceNames[f])
    {
      return f;
    }
  }
  return -1;
}

std::array<int, 4> faceCorners(int face)
{
  return FaceCornerTable[face];
}

std::array<int, 2> edgeVertices(int edge)
{
  return EdgeVertexTable[edge];
}

int edgeDirection(int edge)
{
  return edge < 8 ? (edge % 2 == 0 ? 0 : 1) : 2;
}

std::array<int, 4> faceEdges(int face)
{
  return FaceEdgeTable[face];
}

std::array<int, 2> faceDirections(int face)
{
  return FaceDirectionTable[face];
}
} // namespace model
} // namespace blockforge
