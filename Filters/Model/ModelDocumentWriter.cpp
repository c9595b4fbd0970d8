/**
 * @file ModelDocumentWriter.cpp
 * @brief writeModelDocument: the block model as the versioned YAML text that
 * readModelDocument (ModelDocumentReader.cpp) reads back to the same doubles.
 */
#include "ModelDocument.h"

#include "ModelSyntax.h"
#include "Placement.h"
#include "Errors.h"

#include <algorithm>
#include <cmath>

namespace blockforge
{
namespace model
{
namespace
{
using syntax::entity;
using syntax::formatNumber;
using syntax::ModelDocumentFile;

YAML::Emitter& emitVector(YAML::Emitter& out, const Vec3& value)
{
  out << YAML::Flow << YAML::BeginSeq;
  for (int c = 0; c < 3; ++c)
  {
    out << formatNumber(value[c]);
  }
  return out << YAML::EndSeq;
}

/// Source of an entity: its template line, and its file when not the model's source.
void emitWhere(YAML::Emitter& out, const SourceLocation& where, const BlockModel& model)
{
  if (where.file != model.sourceFile)
  {
    out << YAML::Key << "file" << YAML::Value << where.file;
  }
  out << YAML::Key << "line" << YAML::Value << where.line;
}

const std::string& vertexName(const BlockModel& model, int index, const std::string& user)
{
  if (index < 0 || index >= static_cast<int>(model.vertices.size()))
  {
    throw TemplateError(ModelDocumentFile, 0, user,
      "refers to vertex #" + std::to_string(index) + ", which does not exist");
  }
  return model.vertices[index].name;
}
} // namespace

std::string writeModelDocument(const BlockModel& model)
{
  YAML::Emitter out;
  out << YAML::Comment("BlockForge block model: resolved numbers, written by BlockForge");
  out << YAML::BeginMap;
  out << YAML::Key << "blockforge_model" << YAML::Value << model.requiredFormat();
  out << YAML::Key << "name" << YAML::Value << model.name;
  out << YAML::Key << "source" << YAML::Value << model.sourceFile;

  out << YAML::Key << "parameters" << YAML::Value << YAML::BeginMap;
  for (const auto& parameter : model.parameters)
  {
    out << YAML::Key << parameter.first << YAML::Value << formatNumber(parameter.second);
  }
  out << YAML::EndMap;

  const int carrierCount = static_cast<int>(model.carriers.size());
  auto carrierName = [&](int index, const std::string& user) -> const std::string& {
    if (index < 0 || index >= carrierCount)
    {
      throw TemplateError(ModelDocumentFile, 0, user,
        "refers to carrier #" + std::to_string(index) + ", which does not exist");
    }
    return model.carriers[index].name;
  };
  if (model.machine.defined)
  {
    out << YAML::Key << "machine" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "axis" << YAML::Value;
    emitVector(out, model.machine.axis);
    out << YAML::Key << "origin" << YAML::Value;
    emitVector(out, model.machine.axisPoint);
    out << YAML::Key << "blade_count" << YAML::Value << model.machine.bladeCount;
    out << YAML::EndMap;
  }
  if (!model.carriers.empty())
  {
    const std::vector<std::string>& kinds = carrierKindNames();
    static const char* const methods[] = { "uniform", "chord", "centripetal" };
    out << YAML::Key << "carriers" << YAML::Value << YAML::BeginSeq;
    for (const Carrier& carrier : model.carriers)
    {
      const std::string user = entity("carrier", carrier.name);
      auto refList = [&](const char* key, const std::vector<int>& refs) {
        if (refs.empty())
        {
          return;
        }
        out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (int ref : refs)
        {
          out << carrierName(ref, user);
        }
        out << YAML::EndSeq;
      };
      auto numberList = [&](const char* key, const std::vector<double>& values) {
        out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (double value : values)
        {
          out << formatNumber(value);
        }
        out << YAML::EndSeq;
      };
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << carrier.name;
      out << YAML::Key << "kind" << YAML::Value << kinds[static_cast<int>(carrier.kind)];
      switch (carrier.kind)
      {
        case Carrier::Kind::Interpolate:
          out << YAML::Key << "degree" << YAML::Value << carrier.degree;
          out << YAML::Key << "parameters" << YAML::Value
              << methods[std::max(0, std::min(2, carrier.parameterMethod))];
          out << YAML::Key << "points" << YAML::Value << YAML::BeginSeq;
          for (const Vec3& point : carrier.points)
          {
            emitVector(out, point);
          }
          out << YAML::EndSeq;
          if (!carrier.nodes.empty())
          {
            numberList("at", carrier.nodes);
          }
          break;
        case Carrier::Kind::Revolve:
          refList("refs", carrier.refs);
          out << YAML::Key << "axis" << YAML::Value;
          emitVector(out, carrier.axis);
          out << YAML::Key << "origin" << YAML::Value;
          emitVector(out, carrier.axisPoint);
          numberList("angle", { carrier.angleStart, carrier.angleEnd });
          break;
        case Carrier::Kind::Gordon:
        case Carrier::Kind::Network:
          refList("refs", carrier.refs);
          numberList("at", carrier.nodes);
          if (carrier.kind == Carrier::Kind::Network)
          {
            refList("cross_refs", carrier.crossRefs);
            numberList("cross_at", carrier.crossNodes);
          }
          out << YAML::Key << "blending" << YAML::Value
              << (carrier.blending == Carrier::Blending::Lagrange ? "lagrange" : "spline");
          out << YAML::Key << "closed" << YAML::Value << (carrier.closed ? "true" : "false");
          break;
        case Carrier::Kind::Coons:
          refList("refs", carrier.refs);
          break;
        case Carrier::Kind::SurfaceCurve:
          refList("refs", carrier.refs);
          out << YAML::Key << "points" << YAML::Value << YAML::Flow << YAML::BeginSeq;
          for (const Eigen::Vector2d& st : carrier.parameterPoints)
          {
            out << YAML::Flow << YAML::BeginSeq << formatNumber(st[0]) << formatNumber(st[1])
                << YAML::EndSeq;
          }
          out << YAML::EndSeq;
          if (std::any_of(carrier.throughVertices.begin(), carrier.throughVertices.end(),
                [](int v) { return v >= 0; }))
          {
            out << YAML::Key << "through" << YAML::Value << YAML::Flow << YAML::BeginSeq;
            for (const int v : carrier.throughVertices)
            {
              out << (v >= 0 ? vertexName(model, v, user) : std::string("-"));
            }
            out << YAML::EndSeq;
          }
          break;
        case Carrier::Kind::Intersect:
          refList("refs", carrier.refs);
          numberList("range", { carrier.rangeMin, carrier.rangeMax });
          out << YAML::Key << "samples" << YAML::Value << carrier.samples;
          break;
        case Carrier::Kind::Offset:
          refList("refs", carrier.refs);
          out << YAML::Key << "distance" << YAML::Value << formatNumber(carrier.distance);
          break;
      }
      emitWhere(out, carrier.where, model);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }

  out << YAML::Key << "vertices" << YAML::Value << YAML::BeginSeq;
  for (const Vertex& vertex : model.vertices)
  {
    const std::string user = entity("vertex", vertex.name);
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << vertex.name;
    out << YAML::Key << "position" << YAML::Value;
    emitVector(out, vertex.position);
    if (vertex.constraint.carrier >= 0)
    {
      out << YAML::Key << "on" << YAML::Value << carrierName(vertex.constraint.carrier, user);
      out << YAML::Key << "at" << YAML::Value << YAML::Flow << YAML::BeginSeq
          << formatNumber(vertex.constraint.s) << formatNumber(vertex.constraint.t)
          << YAML::EndSeq;
    }
    if (vertex.constraint.periodicSource >= 0)
    {
      out << YAML::Key << "periodic" << YAML::Value
          << vertexName(model, vertex.constraint.periodicSource, user);
      out << YAML::Key << "pitches" << YAML::Value << vertex.constraint.pitches;
    }
    if (vertex.rule.kind != impliedRule(vertex.constraint).kind)
    {
      out << YAML::Key << "rule" << YAML::Value
          << vertexRuleNames()[static_cast<int>(vertex.rule.kind)];
      if (vertex.rule.kind == VertexRule::Kind::Projected ||
        vertex.rule.kind == VertexRule::Kind::Rotated)
      {
        out << YAML::Key << "source" << YAML::Value << vertexName(model, vertex.rule.source, user);
      }
      if (vertex.rule.kind == VertexRule::Kind::Rotated)
      {
        out << YAML::Key << "origin" << YAML::Value;
        emitVector(out, vertex.rule.origin);
        out << YAML::Key << "axis" << YAML::Value;
        emitVector(out, vertex.rule.axis);
        out << YAML::Key << "angle" << YAML::Value << formatNumber(vertex.rule.angle);
      }
    }
    if (vertex.fixed)
    {
      out << YAML::Key << "fixed" << YAML::Value << "true";
    }
    const PlacementExpressions& expressions = vertex.rule.expressions;
    if (expressions.form != PlacementExpressions::Form::None)
    {
      out << YAML::Key << "expressions" << YAML::Value << YAML::Flow << YAML::BeginMap;
      out << YAML::Key << "form" << YAML::Value
          << (expressions.form == PlacementExpressions::Form::AxialTheta ? "axial_theta"
                                                                        : "curve_parameter");
      out << YAML::Key << "texts" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const std::string& text : expressions.texts)
      {
        out << YAML::DoubleQuoted << text;
      }
      out << YAML::EndSeq;
      out << YAML::Key << "follows" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const int followed : expressions.follows)
      {
        out << vertexName(model, followed, user);
      }
      out << YAML::EndSeq;
      out << YAML::Key << "base" << YAML::Value << YAML::Flow << YAML::BeginSeq
          << formatNumber(expressions.base[0]) << formatNumber(expressions.base[1]) << YAML::EndSeq;
      out << YAML::Key << "shift" << YAML::Value << YAML::Flow << YAML::BeginSeq
          << formatNumber(expressions.shift[0]) << formatNumber(expressions.shift[1])
          << YAML::EndSeq;
      out << YAML::EndMap;
    }
    emitWhere(out, vertex.where, model);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  out << YAML::Key << "edges" << YAML::Value << YAML::BeginSeq;
  for (const Edge& edge : model.edges)
  {
    const std::string user = entity("edge", edge.name);
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << edge.name;
    out << YAML::Key << "kind" << YAML::Value << edgeKindNames()[static_cast<int>(edge.kind)];
    out << YAML::Key << "from" << YAML::Value << vertexName(model, edge.from, user);
    out << YAML::Key << "to" << YAML::Value << vertexName(model, edge.to, user);
    if (edge.kind == Edge::Kind::Arc)
    {
      out << YAML::Key << (edge.arcHasCentre ? "centre" : "through") << YAML::Value;
      emitVector(out, edge.arcHasCentre ? edge.arcCentre : edge.arcThrough);
    }
    if (edge.kind == Edge::Kind::Spline)
    {
      out << YAML::Key << "points" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const Vec3& point : edge.splinePoints)
      {
        emitVector(out, point);
      }
      out << YAML::EndSeq;
    }
    if (edge.kind == Edge::Kind::OnCurve || edge.kind == Edge::Kind::OnSurface ||
      edge.kind == Edge::Kind::Project)
    {
      out << YAML::Key << "carrier" << YAML::Value << carrierName(edge.carrier, user);
      if (!edge.at.empty())
      {
        out << YAML::Key << "at" << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (double value : edge.at)
        {
          out << formatNumber(value);
        }
        out << YAML::EndSeq;
      }
      if (!edge.atFollows.empty())
      {
        out << YAML::Key << "at_expressions" << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (const std::string& text : edge.atExpressions)
        {
          out << YAML::DoubleQuoted << text;
        }
        out << YAML::EndSeq;
        out << YAML::Key << "at_follows" << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (const int vertex : edge.atFollows)
        {
          out << vertexName(model, vertex, user);
        }
        out << YAML::EndSeq;
      }
    }
    if (edge.kind == Edge::Kind::Periodic || edge.kind == Edge::Kind::Follow)
    {
      if (edge.source < 0 || edge.source >= static_cast<int>(model.edges.size()))
      {
        throw TemplateError(ModelDocumentFile, 0, user, "refers to an edge that does not exist");
      }
      out << YAML::Key << "source" << YAML::Value << model.edges[edge.source].name;
      if (edge.kind == Edge::Kind::Periodic)
      {
        out << YAML::Key << "pitches" << YAML::Value << edge.pitches;
      }
    }
    emitWhere(out, edge.where, model);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  out << YAML::Key << "blocks" << YAML::Value << YAML::BeginSeq;
  for (const Block& block : model.blocks)
  {
    const std::string user = entity("block", block.name);
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << block.name;
    out << YAML::Key << "vertices" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int vertex : block.vertices)
    {
      out << vertexName(model, vertex, user);
    }
    out << YAML::EndSeq;
    out << YAML::Key << "cells" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int cells : block.cells)
    {
      out << cells;
    }
    out << YAML::EndSeq;
    if (block.minCells != std::array<int, 3>{ 1, 1, 1 })
    {
      out << YAML::Key << "min_cells" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (int cells : block.minCells)
      {
        out << cells;
      }
      out << YAML::EndSeq;
    }
    out << YAML::Key << "laws" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const DistributionLaw& law : block.laws)
    {
      syntax::emitLaw(out, law, model);
    }
    out << YAML::EndSeq;
    syntax::emitBlending(out, block.blending);
    emitWhere(out, block.where, model);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  if (!model.surfaceFaces.empty())
  {
    out << YAML::Key << "faces" << YAML::Value << YAML::BeginSeq;
    for (const SurfaceFaces& set : model.surfaceFaces)
    {
      const std::string user = entity("face set", set.name);
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << set.name;
      if (set.followOpposite)
      {
        out << YAML::Key << "follow" << YAML::Value << "opposite";
      }
      else
      {
        out << YAML::Key << "on_surface" << YAML::Value << carrierName(set.carrier, user);
      }
      out << YAML::Key << "faces" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (const BlockFace& face : set.faces)
      {
        if (face.block < 0 || face.block >= static_cast<int>(model.blocks.size()))
        {
          throw TemplateError(ModelDocumentFile, 0, user,
            "refers to block #" + std::to_string(face.block) + ", which does not exist");
        }
        out << model.blocks[face.block].name + "." + faceName(face.face);
      }
      out << YAML::EndSeq;
      emitWhere(out, set.where, model);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }

  out << YAML::Key << "patches" << YAML::Value << YAML::BeginSeq;
  for (const Patch& patch : model.patches)
  {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << patch.name;
    out << YAML::Key << "type" << YAML::Value << patch.type;
    out << YAML::Key << "faces" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const BlockFace& face : patch.faces)
    {
      if (face.block < 0 || face.block >= static_cast<int>(model.blocks.size()))
      {
        throw TemplateError(ModelDocumentFile, 0, entity("patch", patch.name),
          "refers to block #" + std::to_string(face.block) + ", which does not exist");
      }
      out << model.blocks[face.block].name + "." + faceName(face.face);
    }
    out << YAML::EndSeq;
    if (patch.type == "periodic")
    {
      out << YAML::Key << "partner" << YAML::Value << patch.periodicPartner;
      out << YAML::Key << "axis" << YAML::Value;
      emitVector(out, patch.periodicAxis);
      out << YAML::Key << "origin" << YAML::Value;
      emitVector(out, patch.periodicAxisPoint);
      out << YAML::Key << "angle" << YAML::Value << formatNumber(patch.periodicAngle);
      if (patch.pitches != 0)
      {
        out << YAML::Key << "pitches" << YAML::Value << patch.pitches;
      }
    }
    emitWhere(out, patch.where, model);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  const ExpressionScope& scope = model.expressionScope;
  if (!scope.values.empty() || !scope.definitions.empty())
  {
    out << YAML::Key << "expression_scope" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "theta_zero" << YAML::Value;
    emitVector(out, scope.thetaZero);
    out << YAML::Key << "values" << YAML::Value << YAML::BeginMap;
    for (const auto& value : scope.values)
    {
      out << YAML::Key << value.first << YAML::Value << formatNumber(value.second);
    }
    out << YAML::EndMap;
    out << YAML::Key << "definitions" << YAML::Value << YAML::BeginMap;
    for (const auto& definition : scope.definitions)
    {
      out << YAML::Key << definition.first << YAML::Value << YAML::DoubleQuoted << definition.second;
    }
    out << YAML::EndMap;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  if (!out.good())
  {
    throw TemplateError(ModelDocumentFile, 0, entity("model", model.name),
      "cannot write the model document: " + out.GetLastError());
  }
  return std::string(out.c_str()) + "\n";
}
} // namespace model
} // namespace blockforge
