// Templates of format 2 (Filters/Model): point-set inputs, carriers (interpolation,
// surfaces of revolution, Gordon surfaces, networks, Coons patches, curves on surfaces,
// intersections), vertex constraints (on curve, on surface, projected, periodic,
// intersection), carrier edges and faces, periodic copies, the extended model check and the
// model document, all against analytic geometry.
#include "CarrierGeometry.h"
#include "Mesher.h"
#include "ModelDocument.h"
#include "Template.h"

#include "TurboPointSets.h"

#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
using test::Pi;

std::string dataPath(const std::string& name)
{
  return std::string(BLOCKFORGE_SOURCE_DIR) + "/Testing/Data/" + name;
}

std::string readText(const std::string& path)
{
  std::ifstream stream(path);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to)
{
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos)
  {
    text.replace(at, from.size(), to);
  }
  return text;
}

using test::lineContaining;

void expectError(const std::function<void()>& action, const std::vector<std::string>& pieces)
{
  try
  {
    action();
    ADD_FAILURE() << "no TemplateError thrown; expected one containing " << pieces.front();
  }
  catch (const TemplateError& error)
  {
    const std::string message = error.what();
    for (const std::string& piece : pieces)
    {
      EXPECT_NE(message.find(piece), std::string::npos)
        << "message \"" << message << "\" lacks \"" << piece << "\"";
    }
  }
}

bool sameBits(const std::vector<double>& a, const std::vector<double>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

double radius(const Vec3& p)
{
  return std::hypot(p.x(), p.y());
}

Vec3 cylindricalPoint(double z, double r, double theta)
{
  return Vec3(r * std::cos(theta), r * std::sin(theta), z);
}

/// Hub: the cone r = 0.5 + 0.1 z, shroud: the cylinder r = 1, both for z in [-0.2, 1.2]
/// and at meridional angles other than 0 (the template maps them to theta = 0).
double hubRadius(double z)
{
  return 0.5 + 0.1 * z;
}

TemplateInputs passageInputs(int bladeCount = 12)
{
  TemplateInputs inputs;
  InputPointSet hub, shroud;
  hub.name = "Hub";
  shroud.name = "Shroud";
  InputCurve hubCurve, shroudCurve;
  for (int k = 0; k <= 7; ++k)
  {
    const double z = -0.2 + 1.4 * k / 7.0;
    hubCurve.points.push_back(cylindricalPoint(z, hubRadius(z), 0.3));
    shroudCurve.points.push_back(cylindricalPoint(z, 1.0, -0.2));
  }
  hub.curves.push_back(hubCurve);
  shroud.curves.push_back(shroudCurve);
  inputs.pointSets = { hub, shroud };
  inputs.hasMachine = true;
  inputs.axis = Vec3::UnitZ();
  inputs.bladeCount = bladeCount;
  return inputs;
}

struct Grid
{
  std::vector<std::array<int, 3>> nodes;
  std::vector<std::vector<double>> xyz;
  Vec3 at(int block, int i, int j, int k) const
  {
    const auto& n = nodes[block];
    const double* p = &xyz[block][3 * ((static_cast<std::size_t>(k) * n[1] + j) * n[0] + i)];
    return Vec3(p[0], p[1], p[2]);
  }
};

Grid meshAll(const BlockModel& model, double multiplier = 1.0, int cap = 0)
{
  MultiBlockMesher mesher(model, multiplier);
  mesher.setCellCap(cap);
  mesher.computeBoundaries();
  Grid grid;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    grid.nodes.push_back(mesher.nodeCounts(b));
    const auto& n = grid.nodes.back();
    grid.xyz.emplace_back(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    mesher.meshBlock(b, grid.xyz.back().data());
  }
  return grid;
}

BlockModel loadPassage(const TemplateInputs& inputs = passageInputs(),
  const ParameterOverrides& overrides = {})
{
  return loadTemplate(dataPath("annular_passage.yaml"), overrides, &inputs);
}

/// A minimal format-2 template around literal carriers: one box whose bottom face lies on
/// `surface` (a carrier defined in `carriers`), vertices given in `vertices`.
std::string boxOnSurface(const std::string& carriers, const std::string& vertices,
  const std::string& extra = "")
{
  return "blockforge: 2\nname: box\nparameters:\n  n: 4\ncarriers:\n" + carriers +
    "vertices:\n" + vertices +
    "blocks:\n  box: {vertices: [a, b, c, d, e, f, g, h], cells: [n, n, n]}\n" + extra;
}
} // namespace

// ------------------------------------------------------------------ the annular passage
TEST(CarrierTemplates, AnnularPassageFromPointSets)
{
  const BlockModel model = loadPassage();
  EXPECT_EQ(model.requiredFormat(), 2);
  EXPECT_EQ(model.machine.bladeCount, 12);
  const double pitch = 2.0 * Pi / 12.0;
  EXPECT_EQ(model.blocks.size(), 2u);
  // hidden meridional contours for the two surfaces of revolution
  EXPECT_GE(model.findCarrier("hub.contour"), 0);
  EXPECT_GE(model.findCarrier("shroud.contour"), 0);

  const Grid grid = meshAll(model);
  const double size = 2.0;
  for (int b = 0; b < 2; ++b)
  {
    const auto& n = grid.nodes[b];
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        const Vec3 hub = grid.at(b, i, j, 0);
        const Vec3 shroud = grid.at(b, i, j, n[2] - 1);
        EXPECT_NEAR(radius(hub), hubRadius(hub.z()), 1e-9 * size) << b << " " << i << " " << j;
        EXPECT_NEAR(radius(shroud), 1.0, 1e-9 * size) << b << " " << i << " " << j;
      }
    }
    // periodic: the high side (i = max) is the low side (i = 0) rotated by one pitch
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        const Vec3 low = grid.at(b, 0, j, k);
        const Vec3 high = grid.at(b, n[0] - 1, j, k);
        const Vec3 rotated = rotateAboutAxis(low, Vec3::Zero(), Vec3::UnitZ(), pitch);
        EXPECT_LE((rotated - high).norm(), 1e-9 * size) << b << " " << j << " " << k;
      }
    }
  }
  // the theta extent of the passage is one pitch, centred on theta_low + pitch/2 = 0
  const Vec3 lowHub = grid.at(0, 0, 0, 0), highHub = grid.at(0, grid.nodes[0][0] - 1, 0, 0);
  EXPECT_NEAR(std::atan2(lowHub.y(), lowHub.x()), -pitch / 2, 1e-12);
  EXPECT_NEAR(std::atan2(highHub.y(), highHub.x()), pitch / 2, 1e-12);
  // shared face between the blocks: bit-identical nodes
  const auto& n0 = grid.nodes[0];
  for (int k = 0; k < n0[2]; ++k)
  {
    for (int i = 0; i < n0[0]; ++i)
    {
      const Vec3 a = grid.at(0, i, n0[1] - 1, k), b = grid.at(1, i, 0, k);
      EXPECT_EQ(0, std::memcmp(a.data(), b.data(), sizeof(double) * 3));
    }
  }
}

TEST(CarrierTemplates, ControlPointsLieOnTheirCarriers)
{
  const BlockModel model = loadPassage();
  const CarrierGeometry geometry(model);
  int controlPoints = 0;
  for (const Vertex& vertex : model.vertices)
  {
    if (vertex.constraint.carrier < 0)
    {
      continue;
    }
    ++controlPoints;
    const Vec3 p = geometry.point(vertex.constraint.carrier, vertex.constraint.s, vertex.constraint.t);
    EXPECT_LE((p - vertex.position).norm(), 1e-12) << vertex.name;
  }
  // the six low vertices and lo_h_mid2, plus the images of the five low vertices on a
  // surface of revolution, which keep their surface parameters (the periodic offset); the
  // image of lo_s_mid (on a radial line) is only periodic
  EXPECT_EQ(controlPoints, 7 + 5);
  EXPECT_EQ(model.vertices[model.findVertex("hi_s_mid")].constraint.carrier, -1);
  const Vertex& loHubIn = model.vertices[model.findVertex("lo_h_in")];
  const Vertex& hiHubIn = model.vertices[model.findVertex("hi_h_in")];
  EXPECT_EQ(hiHubIn.constraint.periodicSource, model.findVertex("lo_h_in"));
  EXPECT_EQ(hiHubIn.constraint.carrier, loHubIn.constraint.carrier);
  EXPECT_DOUBLE_EQ(hiHubIn.constraint.s, loHubIn.constraint.s);
  // hub: full turn, t = (theta + pi) / (2 pi): one pitch is 1/12 in t
  EXPECT_NEAR(hiHubIn.constraint.t - loHubIn.constraint.t, 1.0 / 12.0, 1e-15);
  const Vertex& loShroud = model.vertices[model.findVertex("lo_s_in")];
  const Vertex& hiShroud = model.vertices[model.findVertex("hi_s_in")];
  EXPECT_NEAR(hiShroud.constraint.t - loShroud.constraint.t, (2 * Pi / 12) / Pi, 1e-15);
  // projections: the shroud vertex is at the axial position of the hub vertex, radius 1
  EXPECT_NEAR(loShroud.position.z(), loHubIn.position.z(), 1e-14);
  EXPECT_NEAR(radius(loShroud.position), 1.0, 1e-14);
  // the projection of (z=0, r=0.6) onto the cone r = 0.5 + 0.1 z in the meridional plane
  const double zFoot = (0.0 + 0.1 * (0.6 - 0.5)) / (1.0 + 0.01);
  EXPECT_NEAR(loHubIn.position.z(), zFoot, 1e-12);
  EXPECT_NEAR(radius(loHubIn.position), hubRadius(zFoot), 1e-12);
  // intersection of the radial line with the shroud, and the on_curve vertex at its start
  const Vertex& loShroudMid = model.vertices[model.findVertex("lo_s_mid")];
  const Vertex& loHubMid = model.vertices[model.findVertex("lo_h_mid")];
  EXPECT_NEAR(radius(loShroudMid.position), 1.0, 1e-12);
  EXPECT_NEAR(loShroudMid.position.z(), loHubMid.position.z(), 1e-14);
  EXPECT_LE((model.vertices[model.findVertex("lo_h_mid2")].position - loHubMid.position).norm(),
    1e-15);
}

TEST(CarrierTemplates, DocumentRoundTripAndDeterminism)
{
  const BlockModel model = loadPassage();
  const std::string document = writeModelDocument(model);
  EXPECT_NE(document.find("blockforge_model: 2"), std::string::npos);
  EXPECT_NE(document.find("carriers:"), std::string::npos);
  const BlockModel reread = readModelDocument(document);
  EXPECT_EQ(writeModelDocument(reread), document);
  ASSERT_EQ(reread.carriers.size(), model.carriers.size());
  for (std::size_t c = 0; c < model.carriers.size(); ++c)
  {
    const Carrier &a = model.carriers[c], &b = reread.carriers[c];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.refs, b.refs);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t p = 0; p < a.points.size(); ++p)
    {
      EXPECT_EQ(0, std::memcmp(a.points[p].data(), b.points[p].data(), 3 * sizeof(double)));
    }
  }
  const Grid original = meshAll(model);
  const Grid again = meshAll(loadPassage());
  const Grid fromDocument = meshAll(reread);
  for (std::size_t b = 0; b < original.xyz.size(); ++b)
  {
    EXPECT_TRUE(sameBits(original.xyz[b], again.xyz[b])) << "determinism, block " << b;
    EXPECT_TRUE(sameBits(original.xyz[b], fromDocument.xyz[b])) << "document, block " << b;
  }
  // previews and density multipliers keep the surfaces and periodicity
  const Grid preview = meshAll(model, 2.0, 3);
  EXPECT_EQ(preview.nodes[0][0], 4);
  const Vec3 p = preview.at(1, 1, 1, 0);
  EXPECT_NEAR(radius(p), hubRadius(p.z()), 1e-9);
}

TEST(CarrierTemplates, MachineDataAndQueries)
{
  // The input's blade count wins over the template's machine section.
  const BlockModel model = loadPassage(passageInputs(9));
  EXPECT_EQ(model.machine.bladeCount, 9);
  const Grid grid = meshAll(model);
  const Vec3 low = grid.at(0, 0, 0, 0), high = grid.at(0, grid.nodes[0][0] - 1, 0, 0);
  EXPECT_NEAR(std::atan2(high.y(), high.x()) - std::atan2(low.y(), low.x()), 2 * Pi / 9, 1e-12);
  // Without a count in the input, the machine section gives it.
  const BlockModel fallback = loadPassage(passageInputs(0));
  EXPECT_EQ(fallback.machine.bladeCount, 12);
  // Without either, pitch is unavailable, and the message says why.
  const std::string text = replaced(readText(dataPath("annular_passage.yaml")),
    "machine:\n  blade_count: 12", "machine: {axis: [0, 0, 1]}");
  const TemplateInputs noCount = passageInputs(0);
  expectError([&] { parseTemplate(text, "passage.yaml", {}, &noCount); },
    { "passage.yaml:" + std::to_string(lineContaining(text, "theta_low:")) + ": parameter 'theta_low'",
      "'pitch'", "not available", "blade count is unknown" });
}

// ------------------------------------------------------------------ a blade from sections
namespace
{
/// Sections of a straight (radially stacked) plate blade: the same closed loop in (z, theta)
/// at radii 0.6 ... 0.9, short of the hub (r = 0.5 + 0.1 z) and the shroud (r = 1).
/// z = 0.5 + 0.2 cos(phi), theta = 0.05 sin(phi): leading edge z = 0.3, trailing edge 0.7.
TemplateInputs bladeInputs(bool openSecond = false)
{
  TemplateInputs inputs = passageInputs(12);
  InputPointSet profiles;
  profiles.name = "Profiles";
  profiles.isList = true;
  for (int k = 0; k < 4; ++k)
  {
    InputCurve section;
    section.name = "Profile " + std::to_string(k + 1);
    const double r = 0.6 + 0.1 * k;
    section.span = (r - 0.5) / 0.5;
    for (int p = 0; p < 40; ++p)
    {
      const double phi = 2.0 * Pi * p / 40.0;
      section.points.push_back(cylindricalPoint(0.5 + 0.2 * std::cos(phi), r, 0.05 * std::sin(phi)));
    }
    if (!(openSecond && k == 1))
    {
      section.points.push_back(section.points.front()); // closed loop
    }
    profiles.curves.push_back(section);
  }
  inputs.pointSets.push_back(profiles);
  return inputs;
}
} // namespace

TEST(CarrierTemplates, BladeFromSectionsMeetsHubAndShroud)
{
  const TemplateInputs inputs = bladeInputs();
  for (const std::string blending : { "spline", "lagrange" })
  {
    SCOPED_TRACE(blending);
    const std::string text = replaced(
      readText(dataPath("plate_blade.yaml")), "blending: spline", "blending: " + blending);
    const BlockModel model = parseTemplate(text, "plate_blade.yaml", {}, &inputs);
    const CarrierGeometry geometry(model);
    const int blade = model.findCarrier("blade");
    ASSERT_GE(blade, 0);
    EXPECT_TRUE(geometry.closedS(blade));
    // The surface passes through every section (eq. 4 at the nodes t_j).
    for (int k = 0; k < 4; ++k)
    {
      const int section = model.findCarrier("blade.section" + std::to_string(k + 1));
      ASSERT_GE(section, 0);
      for (double s : { 0.0, 0.1, 0.37, 0.5, 0.9 })
      {
        EXPECT_LE((geometry.point(blade, s, k / 3.0) - geometry.point(section, s)).norm(), 1e-14);
      }
    }
    // Linear in the radius between sections: exact for both blendings, also extended.
    for (double t : { -0.4, 0.5, 1.3 })
    {
      const Vec3 p = geometry.point(blade, 0.25, t);
      EXPECT_NEAR(radius(p), 0.6 + 0.3 * t, 1e-12) << t;
    }
    // The intersection curves lie on the hub and on the shroud.
    const int bladeHub = model.findCarrier("blade_hub");
    const int bladeShroud = model.findCarrier("blade_shroud");
    EXPECT_TRUE(geometry.closedS(bladeHub));
    for (int k = 0; k <= 50; ++k)
    {
      const Vec3 h = geometry.point(bladeHub, k / 50.0);
      const Vec3 s = geometry.point(bladeShroud, k / 50.0);
      EXPECT_NEAR(radius(h), hubRadius(h.z()), 1e-9);
      EXPECT_NEAR(radius(s), 1.0, 1e-9);
    }
    // Leading edge at the smallest axial position, trailing edge at the seam.
    const Vertex& le = model.vertices[model.findVertex("le_hub")];
    const Vertex& te = model.vertices[model.findVertex("te_shroud")];
    EXPECT_NEAR(le.position.z(), 0.3, 1e-4);
    EXPECT_NEAR(std::atan2(le.position.y(), le.position.x()), 0.0, 1e-4);
    EXPECT_NEAR(te.position.z(), 0.7, 1e-12);
    EXPECT_NEAR(radius(te.position), 1.0, 1e-12);

    // The block: blade face on the blade, hub and shroud faces on their surfaces.
    const Grid grid = meshAll(model);
    const auto& n = grid.nodes[0];
    for (int k = 0; k < n[2]; ++k)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        double s = 0.0, t = 0.0, distance = 0.0;
        geometry.project(blade, grid.at(0, i, 0, k), s, t, distance);
        EXPECT_LE(distance, 1e-9) << i << " " << k;
      }
    }
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        const Vec3 h = grid.at(0, i, j, 0), s = grid.at(0, i, j, n[2] - 1);
        EXPECT_NEAR(radius(h), hubRadius(h.z()), 1e-9);
        EXPECT_NEAR(radius(s), 1.0, 1e-9);
      }
    }
    // and the model survives its document, grid bit for bit
    const BlockModel reread = readModelDocument(writeModelDocument(model));
    const Grid again = meshAll(reread);
    EXPECT_TRUE(sameBits(grid.xyz[0], again.xyz[0]));
  }
}

TEST(CarrierTemplates, BladeMustBeClosed)
{
  const TemplateInputs inputs = bladeInputs(true);
  const std::string text = readText(dataPath("plate_blade.yaml"));
  expectError([&] { parseTemplate(text, "plate_blade.yaml", {}, &inputs); },
    { "plate_blade.yaml:" + std::to_string(lineContaining(text, "  blade: {gordon")) +
        ": carrier 'blade'",
      "section 2 ('Profile 2') is open" });
  // A model whose closed blade was reopened after the template ran fails the model check.
  const TemplateInputs good = bladeInputs();
  BlockModel model = parseTemplate(text, "plate_blade.yaml", {}, &good);
  Carrier& section = model.carriers[model.findCarrier("blade.section3")];
  section.points.back() += Vec3(0.0, 0.0, 1e-3);
  expectError([&] { checkModel(model); }, { "carrier 'blade'", "not closed", "section 3" });
}

// ------------------------------------------------------------------ carriers, analytically
namespace
{
/// A unit box of free vertices far from the test geometry (a model needs a block).
const std::string BoxVertices = R"(  a: [10, 0, 0]
  b: [11, 0, 0]
  c: [11, 1, 0]
  d: [10, 1, 0]
  e: [10, 0, 1]
  f: [11, 0, 1]
  g: [11, 1, 1]
  h: [10, 1, 1]
)";

BlockModel parseBox(const std::string& carriers, const std::string& vertices,
  const std::string& extra = "")
{
  return parseTemplate(boxOnSurface(carriers, vertices + BoxVertices, extra), "box.yaml");
}

const Vec3& vertexAt(const BlockModel& model, const std::string& name)
{
  const int v = model.findVertex(name);
  EXPECT_GE(v, 0) << name;
  return model.vertices[v].position;
}
} // namespace

TEST(CarrierTemplates, InterpolatedCurveThroughItsPoints)
{
  const BlockModel model = parseBox(
    "  c: {interpolate: [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0], [4, 0, 1]], degree: 3, "
    "parameters: centripetal}\n",
    "  p0: {on_curve: c, at: 0}\n  p1: {on_curve: c, at: 1}\n"
    "  half: {on_curve: c, at: {length: 0.5}}\n  top: {on_curve: c, at: {max: z}}\n"
    "  near: {project: [2, -1, 0], onto: c}\n");
  const CarrierGeometry geometry(model);
  const auto* spline = dynamic_cast<const BSplineCurve*>(geometry.curve(0).get());
  ASSERT_NE(spline, nullptr);
  const std::vector<Vec3>& points = model.carriers[0].points;
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    EXPECT_LE((spline->point(spline->dataParameters()[k]) - points[k]).norm(), 1e-14) << k;
  }
  EXPECT_EQ(vertexAt(model, "p0"), Vec3(0, 0, 0));
  EXPECT_EQ(vertexAt(model, "p1"), Vec3(4, 0, 1));
  EXPECT_NEAR(vertexAt(model, "top").z(), 1.0, 1e-12);
  // the closest point to (2, -1, 0): near the data point (2, 0, 0), residual normal to
  // the curve
  const Vertex& near = model.vertices[model.findVertex("near")];
  EXPECT_LE((near.position - Vec3(2, 0, 0)).norm(), 0.05);
  EXPECT_NEAR((Vec3(2, -1, 0) - near.position).dot(spline->derivative(near.constraint.s).normalized()),
    0.0, 1e-10);
  // half the arc length: compare with a fine polyline
  double total = 0.0, toHalf = 0.0;
  const double uHalf = model.vertices[model.findVertex("half")].constraint.s;
  Vec3 previous = spline->point(0.0);
  for (int k = 1; k <= 20000; ++k)
  {
    const Vec3 p = spline->point(k / 20000.0);
    total += (p - previous).norm();
    if (k / 20000.0 <= uHalf)
    {
      toHalf = total;
    }
    previous = p;
  }
  EXPECT_NEAR(toHalf / total, 0.5, 1e-4);
}

TEST(CarrierTemplates, SurfaceOfRevolutionAndProjections)
{
  // A contour at theta = 0.5, revolved about z over [0, pi/2]: the cylinder r = 1.
  const BlockModel model = parseBox(
    "  line: {interpolate: [[\"cos(0.5)\", \"sin(0.5)\", 0], [\"cos(0.5)\", \"sin(0.5)\", 2]]}\n"
    "  cyl: {revolve: line, axis: [0, 0, 1], angle: [0, pi/2]}\n"
    "  raw: {revolve: line, axis: [0, 0, 1], angle: [0, pi/2], meridional: false}\n"
    "  pq: {surface_curve: cyl, through: [p, q]}\n",
    "  p: {on_surface: cyl, at: [0.25, 0.5]}\n"
    "  q: {project: [2, 2, 0.25], onto: cyl}\n"
    "  r: {on_surface: raw, at: [0.25, 0]}\n");
  const Vec3& p = vertexAt(model, "p");
  EXPECT_NEAR(p.x(), std::cos(Pi / 4), 1e-15);
  EXPECT_NEAR(p.y(), std::sin(Pi / 4), 1e-15);
  EXPECT_NEAR(p.z(), 0.5, 1e-15);
  const Vec3& q = vertexAt(model, "q");
  EXPECT_LE((q - Vec3(std::sqrt(0.5), std::sqrt(0.5), 0.25)).norm(), 1e-14);
  const Vertex& qv = model.vertices[model.findVertex("q")];
  EXPECT_NEAR(qv.constraint.t, 0.5, 1e-14);
  EXPECT_NEAR(qv.constraint.s, 0.125, 1e-14);
  // without the meridional mapping the contour keeps its own angle (theta = 0.5 at t = 0)
  const Vec3& r = vertexAt(model, "r");
  EXPECT_NEAR(std::atan2(r.y(), r.x()), 0.5, 1e-14);
  // the curve through p and q on the cylinder and the projected edge between them
  const CarrierGeometry geometry(model);
  const int pq = model.findCarrier("pq");
  for (int k = 0; k <= 20; ++k)
  {
    EXPECT_NEAR(radius(geometry.point(pq, k / 20.0)), 1.0, 1e-14);
  }
}

TEST(CarrierTemplates, CurveOnSurfaceThroughVertices)
{
  const BlockModel model = parseBox(
    "  line: {interpolate: [[1, 0, 0], [1, 0, 2]]}\n"
    "  cyl: {revolve: line, axis: [0, 0, 1], angle: [0, pi]}\n"
    "  helix: {surface_curve: cyl, through: [p, [0.5, 0.5], q]}\n",
    "  p: {on_surface: cyl, at: [0, 0]}\n  q: {on_surface: cyl, at: [1, 1]}\n"
    "  mid: {on_curve: helix, at: 0.5}\n");
  const CarrierGeometry geometry(model);
  const int helix = model.findCarrier("helix");
  for (int k = 0; k <= 40; ++k)
  {
    EXPECT_NEAR(radius(geometry.point(helix, k / 40.0)), 1.0, 1e-14);
  }
  EXPECT_LE((geometry.point(helix, 0.0) - vertexAt(model, "p")).norm(), 1e-14);
  EXPECT_LE((geometry.point(helix, 1.0) - vertexAt(model, "q")).norm(), 1e-14);
  // (0.5, 0.5) in (s, t): z = 1, theta = pi/2
  EXPECT_LE((vertexAt(model, "mid") - Vec3(0, 1, 1)).norm(), 1e-12);
}

TEST(CarrierTemplates, GordonBlendings)
{
  // Sections P(s, t_j) = (s, t_j, t_j^3) at t = 0, 1/3, 2/3, 1: Lagrange blending of 4
  // sections reproduces the cubic, spline blending (natural) only approximates it; both
  // reproduce P = (s, t, 2 t) exactly.
  auto sections = [](const std::string& z) {
    std::string text;
    for (int j = 0; j < 4; ++j)
    {
      const std::string t = "(" + std::to_string(j) + "/3)";
      std::string zj = z;
      for (std::size_t at = zj.find('t'); at != std::string::npos; at = zj.find('t', at + t.size()))
      {
        zj.replace(at, 1, t);
      }
      text += "  c" + std::to_string(j) + ": {interpolate: [[0, " + t + ", \"" + zj + "\"], [1, " +
        t + ", \"" + zj + "\"]]}\n";
    }
    return text;
  };
  for (const std::string blending : { "lagrange", "spline" })
  {
    SCOPED_TRACE(blending);
    const BlockModel cubic = parseBox(sections("t^3") + "  g: {gordon: [c0, c1, c2, c3], blending: " +
        blending + ", at: [0, 1/3, 2/3, 1]}\n",
      "  p: {on_surface: g, at: [0.3, 0.5]}\n");
    const Vec3& p = vertexAt(cubic, "p");
    EXPECT_NEAR(p.x(), 0.3, 1e-15);
    EXPECT_NEAR(p.y(), 0.5, 1e-15);
    if (blending == "lagrange")
    {
      EXPECT_NEAR(p.z(), 0.125, 1e-15);
    }
    else
    {
      EXPECT_NEAR(p.z(), 0.125, 0.02);
      EXPECT_GT(std::abs(p.z() - 0.125), 1e-6);
    }
    const BlockModel linear = parseBox(sections("2*t") + "  g: {gordon: [c0, c1, c2, c3], blending: " +
        blending + "}\n",
      "  p: {on_surface: g, at: [0.3, 0.5]}\n  x: {on_surface: g, at: [0.3, 1.5]}\n");
    EXPECT_LE((vertexAt(linear, "p") - Vec3(0.3, 0.5, 1.0)).norm(), 1e-15);
    // extended past the last section
    EXPECT_LE((vertexAt(linear, "x") - Vec3(0.3, 1.5, 3.0)).norm(), 1e-14);
  }
}

TEST(CarrierTemplates, NetworkAndCoonsPatch)
{
  // P(s, t) = (s, t, s t): a network of lines in both directions (eq. 4), and a Coons
  // patch of a planar quadrilateral (eq. 3).
  const BlockModel model = parseBox(
    "  s0: {interpolate: [[0, 0, 0], [1, 0, 0]]}\n"
    "  s1: {interpolate: [[0, 0.5, 0], [1, 0.5, 0.5]]}\n"
    "  s2: {interpolate: [[0, 1, 0], [1, 1, 1]]}\n"
    "  t0: {interpolate: [[0, 0, 0], [0, 1, 0]]}\n"
    "  t1: {interpolate: [[1, 0, 0], [1, 1, 1]]}\n"
    "  net: {network: {along_s: [s0, s1, s2], at_t: [0, 0.5, 1], along_t: [t0, t1]}, blending: lagrange}\n"
    "  bottom: {interpolate: [[0, 0, 5], [2, 0, 5]]}\n"
    "  right: {interpolate: [[2, 0, 5], [2, 1, 5]]}\n"
    "  top: {interpolate: [[0, 1, 5], [2, 1, 5]]}\n"
    "  left: {interpolate: [[0, 0, 5], [0, 1, 5]]}\n"
    "  quad: {coons: [bottom, right, top, left]}\n",
    "  n: {on_surface: net, at: [0.3, 0.7]}\n  q: {on_surface: quad, at: [0.25, 0.5]}\n"
    "  pn: {project: [0.6, 0.2, 0.3], onto: net}\n");
  EXPECT_LE((vertexAt(model, "n") - Vec3(0.3, 0.7, 0.21)).norm(), 1e-15);
  EXPECT_LE((vertexAt(model, "q") - Vec3(0.5, 0.5, 5.0)).norm(), 1e-15);
  // projection onto the hyperbolic paraboloid z = x y: the residual is normal to it
  const Vec3& pn = vertexAt(model, "pn");
  EXPECT_NEAR(pn.z(), pn.x() * pn.y(), 1e-12);
  const Vec3 normal = Vec3(-pn.y(), -pn.x(), 1.0).normalized();
  const Vec3 residual = Vec3(0.6, 0.2, 0.3) - pn;
  EXPECT_NEAR(std::abs(residual.normalized().dot(normal)), 1.0, 1e-9);
}

// ------------------------------------------------------------------ errors
TEST(CarrierTemplates, ErrorsNameTheEntity)
{
  const std::string text = readText(dataPath("annular_passage.yaml"));
  const TemplateInputs inputs = passageInputs();
  auto expectPassageError = [&](const std::string& broken, const std::string& marker,
                              const std::string& entityText, std::vector<std::string> pieces,
                              const TemplateInputs* with) {
    pieces.insert(pieces.begin(),
      "passage.yaml:" + std::to_string(lineContaining(broken, marker)) + ": " + entityText);
    expectError([&] { parseTemplate(broken, "passage.yaml", {}, with); }, pieces);
  };
  // unknown input point set
  expectPassageError(replaced(text, "hub: Hub ", "hub: Hbu "), "hub: Hbu", "input 'hub'",
    { "no point set 'Hbu'", "did you mean 'Hub'", "it has: Hub, Shroud" }, &inputs);
  // no input at all (BlockTemplateSource)
  expectPassageError(text, "hub: Hub", "input 'hub'", { "BlockTemplate filter" }, nullptr);
  // unknown carrier
  expectPassageError(replaced(text, "onto: hub}\n  lo_h_out", "onto: hubb}\n  lo_h_out"),
    "  lo_h_in:", "vertex 'lo_h_in'", { "unknown carrier 'hubb'", "did you mean 'hub'" }, &inputs);
  // a curve where a surface is needed
  expectPassageError(replaced(text, "{on_surface: hub, at:", "{on_surface: hub_line, at:"),
    "  lo_h_mid:", "vertex 'lo_h_mid'", { "'hub_line' is a curve, a surface is needed" }, &inputs);
  // interpolate of an input that is not there
  expectPassageError(replaced(text, "{interpolate: shroud}", "{interpolate: casing}"),
    "  shroud_line:", "carrier 'shroud_line'", { "'casing' is neither a carrier nor an input" },
    &inputs);
  // cycles
  expectPassageError(replaced(text, "lo_h_in:  {project: {cylindrical: [z_in,",
                       "lo_h_in:  {project: {cylindrical: [lo_s_in.axial,"),
    "  lo_h_in:", "vertex 'lo_h_in'", { "defined in terms of itself", "vertex 'lo_s_in'" }, &inputs);
  // a parameter outside a curve
  expectPassageError(replaced(text, "{on_curve: radial_mid, at: 0}", "{on_curve: radial_mid, at: 1.5}"),
    "  lo_h_mid2:", "vertex 'lo_h_mid2'", { "outside the curve's parameter range" }, &inputs);
  // an edge on a surface its end is not on
  expectPassageError(replaced(text, "h_in:   {on_surface: hub,", "h_in:   {on_surface: shroud,"),
    "  h_in:", "edge 'h_in'", { "vertex 'lo_h_in' is not on carrier 'shroud'" }, &inputs);
  // periodic patches one pitch off
  expectPassageError(replaced(text, "partner: periodic_high, pitches: 1", "partner: periodic_high, pitches: 2"),
    "  periodic_low:", "patch 'periodic_low'", { "does not land on a face" }, &inputs);
  // format 1 has no carriers
  expectError([&] { parseTemplate(replaced(text, "blockforge: 2", "blockforge: 1"), "passage.yaml", {}, &inputs); },
    { "passage.yaml:" + std::to_string(lineContaining(text, "inputs:")), "needs template format 2" });
}

TEST(CarrierTemplates, ModelCheckAfterReload)
{
  const BlockModel model = loadPassage();
  const std::string text = readText(dataPath("annular_passage.yaml"));
  const std::string file = dataPath("annular_passage.yaml");
  // A control point moved off its carrier (as a broken optimizer might).
  {
    BlockModel broken = readModelDocument(writeModelDocument(model));
    broken.vertices[broken.findVertex("lo_h_in")].position += Vec3(0, 0, 1e-6);
    expectError([&] { checkModel(readModelDocument(writeModelDocument(broken))); },
      { file + ":" + std::to_string(lineContaining(text, "  lo_h_in:")) + ": vertex 'lo_h_in'",
        "away from its carrier 'hub'" });
  }
  // A periodic image that no longer matches its source.
  {
    BlockModel broken = model;
    broken.vertices[broken.findVertex("hi_s_mid")].position += Vec3(1e-6, 0, 0);
    expectError([&] { checkModel(broken); },
      { file + ":" + std::to_string(lineContaining(text, "  hi_s_mid:")) + ": vertex 'hi_s_mid'",
        "not the periodic image of vertex 'lo_s_mid'" });
  }
  // Moving a control point along its carrier (new parameters, position re-evaluated) keeps
  // the model valid: what the optimizer will do.
  {
    BlockModel moved = model;
    const CarrierGeometry geometry(moved);
    Vertex& vertex = moved.vertices[moved.findVertex("lo_s_mid")];
    vertex.constraint.s += 0.01;
    vertex.position = geometry.point(vertex.constraint.carrier, vertex.constraint.s);
    Vertex& image = moved.vertices[moved.findVertex("hi_s_mid")];
    image.position = rotateAboutAxis(vertex.position, Vec3::Zero(), Vec3::UnitZ(), 2 * Pi / 12);
    EXPECT_THROW(checkModel(moved), TemplateError); // lo_s_mid left the shroud: edges say so
  }
}

TEST(CarrierTemplates, ParameterListingWithoutInput)
{
  // GUIs list the parameters before any input is connected: machine values come from the
  // template's machine section, or are unknown (NaN) for the parameters that need them.
  const std::vector<ParameterInfo> infos = templateParameters(dataPath("annular_passage.yaml"));
  ASSERT_GE(infos.size(), 3u);
  EXPECT_EQ(infos[2].name, "theta_low");
  EXPECT_NEAR(infos[2].value, -Pi / 12, 1e-15);
  EXPECT_EQ(infos[2].comment, "angle of the low periodic side [rad]");
  const std::string text = replaced(readText(dataPath("annular_passage.yaml")),
    "machine:\n  blade_count: 12", "machine: {axis: [0, 0, 1]}");
  const std::string path = ::testing::TempDir() + "blockforge_no_count.yaml";
  {
    std::ofstream(path) << text;
  }
  const std::vector<ParameterInfo> unknown = templateParameters(path);
  EXPECT_TRUE(std::isnan(unknown[2].value));
  EXPECT_DOUBLE_EQ(unknown[3].value, 0.6);
}

// ------------------------------------------------------------------ Rotor 37, H-grid
namespace
{
/// The reader's data as vtkBlockTemplate passes it on (metres, machine data).
TemplateInputs rotor37Inputs()
{
  return test::readTemplateInputs(
    test::sourcePath("Data/rotor37/turbogrid/BladeGen.inf"));
}
} // namespace

TEST(CarrierTemplates, Rotor37AxialPassageH)
{
  const TemplateInputs inputs = rotor37Inputs();
  const BlockModel model = loadTemplate(
    std::string(BLOCKFORGE_SOURCE_DIR) + "/Templates/axial_passage_h.yaml", {}, &inputs);
  EXPECT_EQ(model.machine.bladeCount, 36);
  const CarrierGeometry geometry(model);
  const Grid grid = meshAll(model);
  ASSERT_EQ(grid.nodes.size(), 8u);
  const int hub = model.findCarrier("hub"), shroud = model.findCarrier("shroud");
  const int blade = model.findCarrier("blade");
  const double pitch = 2.0 * Pi / 36.0;
  auto distance = [&](int carrier, const Vec3& p) {
    double s = 0.0, t = 0.0, d = 0.0;
    geometry.project(carrier, p, s, t, d);
    return d;
  };
  double hubWorst = 0.0, shroudWorst = 0.0, bladeWorst = 0.0;
  for (std::size_t b = 0; b < grid.nodes.size(); ++b)
  {
    const auto& n = grid.nodes[b];
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        hubWorst = std::max(hubWorst, distance(hub, grid.at(static_cast<int>(b), i, j, 0)));
        shroudWorst =
          std::max(shroudWorst, distance(shroud, grid.at(static_cast<int>(b), i, j, n[2] - 1)));
      }
    }
  }
  // blade faces: BL.i1, AL.i1 (side a), BR.i0, AR.i0 (side b)
  const std::vector<std::pair<std::string, bool>> bladeFaces = { { "BL", true }, { "AL", true },
    { "BR", false }, { "AR", false } };
  for (const auto& face : bladeFaces)
  {
    const int b = model.findBlock(face.first);
    const auto& n = grid.nodes[b];
    const int i = face.second ? n[0] - 1 : 0;
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        bladeWorst = std::max(bladeWorst, distance(blade, grid.at(b, i, j, k)));
      }
    }
  }
  EXPECT_LE(hubWorst, 1e-9);
  EXPECT_LE(shroudWorst, 1e-9);
  EXPECT_LE(bladeWorst, 1e-9);
  // periodic sides: bit for bit the rotation of the low side
  for (const auto& pair : std::vector<std::pair<std::string, std::string>>{
         { "UL", "UR" }, { "BL", "BR" }, { "AL", "AR" }, { "DL", "DR" } })
  {
    const int low = model.findBlock(pair.first), high = model.findBlock(pair.second);
    const auto& n = grid.nodes[low];
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        const Vec3 rotated =
          rotateAboutAxis(grid.at(low, 0, j, k), Vec3::Zero(), Vec3::UnitZ(), pitch);
        EXPECT_LE((rotated - grid.at(high, grid.nodes[high][0] - 1, j, k)).norm(), 1e-12);
      }
    }
  }
}
