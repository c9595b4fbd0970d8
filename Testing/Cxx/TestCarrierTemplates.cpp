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
using test::expectError;
using test::Grid;
using test::lineContaining;
using test::meshAll;
using test::Pi;
using test::readText;
using test::replaced;
using test::sameBits;

std::string dataPath(const std::string& name)
{
  return test::sourcePath("Testing/Data/" + name);
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
  EXPECT_EQ(model.requiredFormat(), 3); // an intersection vertex: a rule of format 3
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

namespace
{
/// Writes the model document and reads it back: the same document again, and the same
/// carrier definitions to the bit (points, parameters, distances). Returns the model read.
BlockModel documentRoundTrip(const BlockModel& model)
{
  const std::string document = writeModelDocument(model);
  BlockModel reread = readModelDocument(document);
  EXPECT_EQ(writeModelDocument(reread), document);
  EXPECT_EQ(reread.carriers.size(), model.carriers.size());
  for (std::size_t c = 0; c < std::min(model.carriers.size(), reread.carriers.size()); ++c)
  {
    const Carrier &a = model.carriers[c], &b = reread.carriers[c];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.refs, b.refs) << a.name;
    EXPECT_EQ(a.distance, b.distance) << a.name;
    EXPECT_EQ(a.nodes, b.nodes) << a.name; // the aligned sections' parameters
    EXPECT_EQ(a.points, b.points) << a.name;
  }
  return reread;
}
} // namespace

TEST(CarrierTemplates, DocumentRoundTripAndDeterminism)
{
  const BlockModel model = loadPassage();
  const std::string document = writeModelDocument(model);
  EXPECT_NE(document.find("blockforge_model: 3"), std::string::npos);
  EXPECT_NE(document.find("carriers:"), std::string::npos);
  const BlockModel reread = documentRoundTrip(model);
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

// ------------------------------------------------------------------ format-2 features:
// definitions, extrema of expressions within windows, vertices at (axial, theta) on a
// surface of revolution, offset carriers, aligned blade sections
namespace
{
/// The message of the TemplateError `action` throws (a test failure and "" if none).
std::string errorOf(const std::function<void()>& action)
{
  try
  {
    action();
  }
  catch (const TemplateError& error)
  {
    return error.what();
  }
  ADD_FAILURE() << "no TemplateError thrown";
  return "";
}

/// A format-2 template "feature.yaml": `head` (sections above the vertices), `vertices`
/// and the unit box far from the test geometry, the box block, then `tail` (sections
/// below the blocks).
std::string featureText(
  const std::string& head, const std::string& vertices, const std::string& tail = "")
{
  return "blockforge: 2\nname: feature\n" + head + "vertices:\n" + vertices + BoxVertices +
    "blocks:\n  box: {vertices: [a, b, c, d, e, f, g, h], cells: [4, 4, 4]}\n" + tail;
}

BlockModel parseFeature(const std::string& text, const TemplateInputs* inputs = nullptr)
{
  return parseTemplate(text, "feature.yaml", {}, inputs);
}

/// "feature.yaml:<line of needle>: ", the start of a message about that line.
std::string featureLine(const std::string& text, const std::string& needle)
{
  return "feature.yaml:" + std::to_string(lineContaining(text, needle)) + ": ";
}

const Vertex& vertexNamed(const BlockModel& model, const std::string& name)
{
  const int v = model.findVertex(name);
  EXPECT_GE(v, 0) << name;
  return model.vertices.at(v < 0 ? 0 : v);
}

/// `{interpolate: [...]}` points of the circle of radius r about `centre` in the plane
/// z = centre.z, `count` points from angle `start` on, the first repeated at the end
/// (a closed loop), 17 digits.
std::string circlePoints(const Vec3& centre, double r, int count, double start)
{
  std::ostringstream text;
  text.precision(17);
  std::ostringstream first;
  first.precision(17);
  text << "[";
  for (int k = 0; k < count; ++k)
  {
    const double phi = start + 2.0 * Pi * k / count;
    std::ostringstream point;
    point.precision(17);
    point << "[" << centre.x() + r * std::cos(phi) << ", " << centre.y() + r * std::sin(phi) << ", "
          << centre.z() << "]";
    if (k == 0)
    {
      first << point.str();
    }
    text << point.str() << ", ";
  }
  text << first.str() << "]";
  return text.str();
}
} // namespace

TEST(CarrierTemplates, DefinitionsResolveLazilyInAnyOrder)
{
  // The definitions section comes last in the file; vertices use definitions, definitions
  // use later definitions, parameters, machine values and vertex queries.
  const std::string text = featureText("machine: {blade_count: 8}\n"
                                       "parameters:\n  R: 2\n"
                                       "carriers:\n"
                                       "  line: {interpolate: [[1, 0, 0], [1, 0, 2]]}\n"
                                       "  cyl: {revolve: line, axis: machine}\n",
    "  p: {cylindrical: [z_mid, R, half_pitch]}\n"
    "  q: {on_surface: cyl, at: [0.25, t_q]}\n"
    "  r: [q_far, q_s2, 0]\n",
    "definitions:\n"
    "  q_far: \"q.radius + r_extra\"     # a vertex query and a definition further down\n"
    "  r_extra: \"2*R + z_mid\"\n"
    "  z_mid: \"R/4\"\n"
    "  half_pitch: \"pitch/2\"\n"
    "  t_q: \"0.5 + blade_count/100\"\n"
    "  q_s2: \"2*q.s\"\n");
  const BlockModel model = parseFeature(text);
  // p: (axial 0.5, radius 2, theta pi/8)
  const Vec3 p = vertexNamed(model, "p").position;
  EXPECT_NEAR(p.x(), 2.0 * std::cos(Pi / 8), 1e-15);
  EXPECT_NEAR(p.y(), 2.0 * std::sin(Pi / 8), 1e-15);
  EXPECT_EQ(p.z(), 0.5);
  // q: on the cylinder r = 1 at s = 0.25 (z = 0.5), t = 0.58 (theta = -pi + 2 pi 0.58)
  const Vertex& q = vertexNamed(model, "q");
  EXPECT_EQ(q.constraint.t, 0.58);
  EXPECT_NEAR(q.position.z(), 0.5, 1e-15);
  EXPECT_NEAR(radius(q.position), 1.0, 1e-15);
  EXPECT_NEAR(std::atan2(q.position.y(), q.position.x()), -Pi + 2.0 * Pi * 0.58, 1e-14);
  // r: q.radius + 2 R + R/4 = 1 + 4 + 0.5, 2 q.s = 0.5
  const Vec3 r = vertexNamed(model, "r").position;
  EXPECT_NEAR(r.x(), 5.5, 1e-14);
  EXPECT_NEAR(r.y(), 0.5, 1e-15);
  // The document of the model has resolved numbers only: it reads back without the
  // definitions.
  const BlockModel reread = readModelDocument(writeModelDocument(model));
  EXPECT_EQ(reread.vertices[reread.findVertex("r")].position, r);
  // Blocks may use definitions too: 2 q_s2 + 4 = 5 cells.
  const BlockModel counted =
    parseFeature(replaced(text, "cells: [4, 4, 4]", "cells: [\"2*q_s2 + 4\", 4, 4]"));
  EXPECT_EQ(counted.blocks[0].cells[0], 5);
}

TEST(CarrierTemplates, DefinitionErrors)
{
  const std::string head = "parameters:\n  R: 2\n";
  // The error of a template with these vertices and definitions, expected on the line
  // that starts with `marker`; `edit` may change the text first.
  auto check = [&](const std::string& vertices, const std::string& definitions,
                 const std::string& marker, const std::string& expected,
                 const std::function<std::string(const std::string&)>& edit = nullptr) {
    std::string text = featureText(head, vertices, definitions);
    if (edit)
    {
      text = edit(text);
    }
    EXPECT_EQ(errorOf([&] { parseFeature(text); }), featureLine(text, marker) + expected);
  };
  // d1 uses d2 uses d1: the chain, with d1's line (d1 is resolved first)
  check("  p: [d1, 0, 0]\n", "definitions:\n  d1: \"d2 + 1\"\n  d2: \"2*d1\"\n", "  d1:",
    "definition 'd1': is defined in terms of itself: definition 'd1' -> definition 'd2' "
    "-> definition 'd1'");
  // a definition through a vertex query of a vertex that uses the definition
  check("  p: [d, 0, 0]\n", "definitions:\n  d: \"p.x + 1\"\n", "  d: \"",
    "definition 'd': is defined in terms of itself: definition 'd' -> vertex 'p' -> "
    "definition 'd'");
  // the name of a parameter, of a function, of a machine value
  check("  p: [R, 0, 0]\n", "definitions:\n  R: 3\n", "  R: 3",
    "definition 'R': a parameter has this name already");
  for (const std::string reserved : { "sin", "pi", "pitch" })
  {
    check("  p: [R, 0, 0]\n", "definitions:\n  " + reserved + ": 3\n", "  " + reserved + ": 3",
      "definition '" + reserved + "': '" + reserved +
        "' is a built-in constant, function or machine value; choose another name");
  }
  // an unknown name inside a definition
  check("  p: [d, 0, 0]\n", "definitions:\n  d: \"R + foo\"\n", "  d: \"",
    "definition 'd': unknown name 'foo' in 'R + foo'; parameters available here: axis_x, "
    "axis_y, axis_z, R");
  // a definition given twice, a definition that is not an expression
  {
    const std::string twice = featureText(head, "  p: [d, 0, 0]\n", "definitions:\n  d: 3\n  d: 4\n");
    check("  p: [d, 0, 0]\n", "definitions:\n  d: 3\n  d: 4\n", "  d: 4",
      "definition 'd': defined twice (first on line " +
        std::to_string(lineContaining(twice, "  d: 3")) + ")");
  }
  check("  p: [d, 0, 0]\n", "definitions:\n  d: [1, 2]\n", "  d: [1, 2]",
    "definition 'd': expected an expression (a number or a quoted formula)");
  // format 1 has no definitions
  check("  p: [R, 0, 0]\n", "definitions:\n  d: 3\n", "definitions:",
    "the 'definitions' section needs template format 2: write 'blockforge: 2' at the top",
    [](const std::string& text) { return replaced(text, "blockforge: 2", "blockforge: 1"); });
}

namespace
{
/// The circle of radius 1 about (3, 0, 0.5) in the plane z = 0.5, interpolated through 64
/// points from phi = 0.1 on (closed loop, chord-length parameters: u_k = k / 64, so
/// phi(u) = 0.1 + 2 pi u at the data points).
const Vec3 CircleCentre(3.0, 0.0, 0.5);
constexpr double CircleStart = 0.1;

std::string circleCarrier()
{
  return "  circle: {interpolate: " + circlePoints(CircleCentre, 1.0, 64, CircleStart) + "}\n";
}

Vec3 onCircle(double phi)
{
  return CircleCentre + Vec3(std::cos(phi), std::sin(phi), 0.0);
}

/// The parameter of the largest value of f on [from, to] of the carrier curve: 20001
/// samples, then golden-section search (brute force, for comparison).
double bruteMaximum(const CarrierGeometry& geometry, int curve,
  const std::function<double(const Vec3&)>& f, double from, double to)
{
  const int samples = 20000;
  int best = 0;
  for (int k = 1; k <= samples; ++k)
  {
    if (f(geometry.point(curve, from + (to - from) * k / samples)) >
      f(geometry.point(curve, from + (to - from) * best / samples)))
    {
      best = k;
    }
  }
  double a = from + (to - from) * std::max(0, best - 1) / samples;
  double b = from + (to - from) * std::min(samples, best + 1) / samples;
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int iteration = 0; iteration < 100; ++iteration)
  {
    const double c = b - ratio * (b - a), d = a + ratio * (b - a);
    if (f(geometry.point(curve, c)) > f(geometry.point(curve, d)))
    {
      b = d;
    }
    else
    {
      a = c;
    }
  }
  return 0.5 * (a + b);
}
} // namespace

TEST(CarrierTemplates, CurveExtremumOfAnExpressionWithinAWindow)
{
  const std::string text = featureText("parameters:\n  phi0: 100deg\ncarriers:\n" + circleCarrier(),
    "  top: {on_curve: circle, at: {max: \"x + y\"}}\n"
    "  tilt: {on_curve: circle, at: {max: \"cos(phi0)*x + sin(phi0)*y\"}}\n"
    "  tilt_def: {on_curve: circle, at: {min: \"dx*x + dy*y\"}}\n"
    "  cyl: {on_curve: circle, at: {max: \"radius*sin(theta) - axial\"}}\n"
    "  widest: {on_curve: circle, at: {max: theta}}\n"
    "  local: {on_curve: circle, at: {max: \"y^2 + 0.2*(x - 3) + 0.1*y\", within: [0.65, 0.85]}}\n"
    "  global: {on_curve: circle, at: {max: \"y^2 + 0.2*(x - 3) + 0.1*y\"}}\n"
    "  start: {on_curve: circle, at: {max: \"x + y\", within: [0.3, 0.6]}}\n"
    "  end: {on_curve: circle, at: {min: \"x + y\", within: [0.2, 0.5]}}\n"
    "  seam: {on_curve: circle, at: {max: \"x + y\", within: [0.9, 1.2]}}\n"
    "  seam_end: {on_curve: circle, at: {max: \"x + y\", within: [0.9, 1.05]}}\n"
    "  turn: {on_curve: circle, at: {max: \"x + y\", within: [0.6, 1.6]}}\n"
    "  before: {on_curve: circle, at: {max: \"x + y\", within: [-0.95, -0.8]}}\n",
    "definitions:\n  dx: \"cos(angle)\"\n  dy: \"sin(angle)\"\n  angle: \"phi0 + 40deg\"\n");
  const BlockModel model = parseFeature(text);
  const CarrierGeometry geometry(model);
  const int circle = model.findCarrier("circle");
  ASSERT_TRUE(geometry.closedS(circle));
  auto parameterOf = [&](const std::string& name) { return vertexNamed(model, name).constraint.s; };
  auto positionOf = [&](const std::string& name) { return vertexNamed(model, name).position; };

  // Against the exact circle: the interpolation through 64 points is off the circle by
  // up to 2.6e-6 (near the seam, where it is only C0), and its tangent is off by O(h^3),
  // which moves the extremum of a linear function along the curve: measured 0.8e-6 to
  // 7.5e-6 (tilt); all extrema here lie at least 40 degrees from the seam.
  double worstRadius = 0.0;
  for (int k = 0; k <= 4096; ++k)
  {
    const Vec3 p = geometry.point(circle, k / 4096.0);
    worstRadius = std::max(worstRadius, std::abs((p - CircleCentre).norm() - 1.0));
  }
  EXPECT_LE(worstRadius, 5e-6);
  auto expectAt = [&](const std::string& name, const Vec3& expected) {
    EXPECT_LE((positionOf(name) - expected).norm(), 1e-5) << name;
  };
  expectAt("top", onCircle(Pi / 4));
  expectAt("tilt", onCircle(100.0 * Pi / 180.0));
  expectAt("tilt_def", onCircle(140.0 * Pi / 180.0 + Pi));
  expectAt("cyl", onCircle(Pi / 2));
  expectAt("widest", std::sqrt(8.0) * Vec3(std::sqrt(8.0) / 3.0, 1.0 / 3.0, 0.0) + Vec3(0, 0, 0.5));
  // y^2 + 0.2 (x - 3) + 0.1 y = sin^2 + 0.2 cos + 0.1 sin: the global maximum near
  // +84 degrees, a lower local one near -84 degrees, where f' = sin 2phi - 0.2 sin phi +
  // 0.1 cos phi = 0
  auto localMaximum = [](double phi) {
    for (int iteration = 0; iteration < 50; ++iteration)
    {
      const double d1 = std::sin(2 * phi) - 0.2 * std::sin(phi) + 0.1 * std::cos(phi);
      const double d2 = 2 * std::cos(2 * phi) - 0.2 * std::cos(phi) - 0.1 * std::sin(phi);
      phi -= d1 / d2;
    }
    return phi;
  };
  expectAt("local", onCircle(localMaximum(-84.0 * Pi / 180.0)));
  expectAt("global", onCircle(localMaximum(84.0 * Pi / 180.0)));
  // Against the interpolated curve itself (brute force): the same value to rounding; the
  // parameter of a smooth extremum is only defined to about the square root of the
  // rounding (measured 5e-10 here).
  auto objective = [](const Vec3& p) { return p.y() * p.y() + 0.2 * (p.x() - 3) + 0.1 * p.y(); };
  const double local = bruteMaximum(geometry, circle, objective, 0.65, 0.85);
  EXPECT_NEAR(parameterOf("local"), local, 1e-7);
  EXPECT_NEAR(objective(positionOf("local")), objective(geometry.point(circle, local)), 1e-14);
  auto sum = [](const Vec3& p) { return p.x() + p.y(); };
  const double top = bruteMaximum(geometry, circle, sum, 0.0, 1.0);
  EXPECT_NEAR(parameterOf("top"), top, 1e-7);
  // a window whose extremum is at its end: the end itself
  EXPECT_EQ(parameterOf("start"), 0.3);
  EXPECT_EQ(parameterOf("end"), 0.5);
  // windows across the seam of the closed curve: the maximum at u = 1.109 is 0.109 (the
  // positions agree to 4.8e-8, the values to rounding); a window [0.9, 1.05] ends before
  // it: 1.05 is 0.05
  EXPECT_NEAR(parameterOf("seam"), parameterOf("top"), 1e-7);
  EXPECT_LE((positionOf("seam") - positionOf("top")).norm(), 1e-7);
  EXPECT_NEAR(sum(positionOf("seam")), sum(positionOf("top")), 1e-15);
  EXPECT_NEAR(parameterOf("seam_end"), 0.05, 1e-15);
  EXPECT_LE((positionOf("turn") - positionOf("top")).norm(), 1e-7);
  EXPECT_NEAR(sum(positionOf("turn")), sum(positionOf("top")), 1e-15);
  EXPECT_LE((positionOf("before") - positionOf("top")).norm(), 1e-7);
  for (const std::string name : { "seam", "seam_end", "turn", "before" })
  {
    EXPECT_GE(parameterOf(name), 0.0);
    EXPECT_LT(parameterOf(name), 1.0);
  }
}

TEST(CarrierTemplates, CurveExtremumErrors)
{
  const std::string head = "parameters:\n  w: 0.5\ncarriers:\n" + circleCarrier() +
    "  arc: {interpolate: [[0, 0, 0], [1, 1, 0], [2, 0, 0]]}\n";
  auto check = [&](const std::string& vertex, const std::string& expected) {
    const std::string text = featureText(head, "  v: " + vertex + "\n");
    const std::string message = errorOf([&] { parseFeature(text); });
    EXPECT_EQ(message, featureLine(text, "  v: ") + "vertex 'v': " + expected);
  };
  check("{on_curve: circle, at: {max: x, within: [w, w]}}",
    "'within: [0.5, 0.5]' must have u0 < u1 and span at most the whole closed curve (1)");
  check("{on_curve: circle, at: {max: x, within: [0.7, 0.2]}}",
    "'within: [0.7, 0.2]' must have u0 < u1 and span at most the whole closed curve (1)");
  check("{on_curve: circle, at: {max: x, within: [0.2, 1.3]}}",
    "'within: [0.2, 1.3]' must have u0 < u1 and span at most the whole closed curve (1)");
  check("{on_curve: arc, at: {max: y, within: [-0.1, 0.5]}}",
    "'within: [-0.1, 0.5]' must have u0 < u1 inside the curve's parameter range [0, 1]");
  check("{on_curve: arc, at: {max: y, within: [0.5, 1.2]}}",
    "'within: [0.5, 1.2]' must have u0 < u1 inside the curve's parameter range [0, 1]");
  check("{on_curve: arc, at: {length: 0.5, within: [0.1, 0.5]}}",
    "'at' takes one of length, min or max (min and max may add 'within: [u0, u1]')");
  check("{on_curve: arc, at: {min: x, max: y}}",
    "'at' takes one of length, min or max (min and max may add 'within: [u0, u1]')");
  check("{on_curve: arc, at: {max: y, within: 0.5}}",
    "'within' expects [u0, u1], parameters of the curve");
  check("{on_curve: arc, at: {max: \"x + foo\"}}",
    "max: unknown name 'foo' in 'x + foo'; a function of the point may use x, y, z, axial, "
    "radius, theta and the parameters and definitions: axis_x, axis_y, axis_z, w");
  check("{on_curve: arc, at: {max: \"x + ww\"}}",
    "max: unknown name 'ww' in 'x + ww' (did you mean 'w'?); a function of the point may use "
    "x, y, z, axial, radius, theta and the parameters and definitions: axis_x, axis_y, "
    "axis_z, w");
  // a definition (or parameter) named like a point variable hides it
  const std::string text =
    featureText(head, "  v: {on_curve: arc, at: {max: \"x + y\"}}\n", "definitions:\n  y: 2\n");
  EXPECT_EQ(errorOf([&] { parseFeature(text); }),
    featureLine(text, "  v: ") +
      "vertex 'v': max: 'y' is a parameter or definition of this template, so it cannot be "
      "the point variable of 'x + y'; rename it");
}

TEST(CarrierTemplates, VertexAtAxialAndThetaOnASurfaceOfRevolution)
{
  // The cone r = 0.5 + 0.1 z from z = -0.2 to 1.2, its contour drawn at theta = 0.3 (the
  // meridional mapping puts it at theta = 0) and running against the axis (z decreasing).
  std::ostringstream contour;
  contour.precision(17);
  for (double z : { 1.2, -0.2 })
  {
    const Vec3 p = cylindricalPoint(z, hubRadius(z), 0.3);
    contour << (z > 0 ? "[" : ", ") << "[" << p.x() << ", " << p.y() << ", " << p.z() << "]";
  }
  contour << "]";
  const std::string text = featureText("parameters:\n  th: 0.4\ncarriers:\n"
                                       "  cone_line: {interpolate: " +
      contour.str() +
      "}\n"
      "  cone: {revolve: cone_line, axis: machine}\n",
    "  v1: {on_surface: cone, axial: 0.37, theta: th}\n"
    "  v2: {on_surface: cone, axial: \"-0.2\", theta: -3}\n"
    "  v3: {on_surface: cone, axial: 1.2, theta: pi}\n"
    "  v4: {on_surface: cone, axial: \"v1.axial + 1/3\", theta: \"v1.theta - 1/7\"}\n"
    "  v5: {on_surface: cone, axial: 0.1, theta: \"-pi\"}\n");
  const BlockModel model = parseFeature(text);
  const CarrierGeometry geometry(model);
  const int cone = model.findCarrier("cone");
  const double size = geometry.size(cone);
  struct Expected
  {
    const char* name;
    double axial, theta;
  };
  for (const Expected& e :
    { Expected{ "v1", 0.37, 0.4 }, Expected{ "v2", -0.2, -3.0 }, Expected{ "v3", 1.2, Pi },
      Expected{ "v4", 0.37 + 1.0 / 3.0, 0.4 - 1.0 / 7.0 }, Expected{ "v5", 0.1, -Pi } })
  {
    SCOPED_TRACE(e.name);
    const Vertex& v = vertexNamed(model, e.name);
    // measured: axial within 1.3e-14, radius within 1.4e-15
    EXPECT_LE(std::abs(v.position.z() - e.axial), 1e-12 * size);
    EXPECT_NEAR(radius(v.position), hubRadius(e.axial), 1e-12 * size);
    // theta: the same angle (pi and -pi are one)
    const double theta = std::atan2(v.position.y(), v.position.x());
    EXPECT_NEAR(std::remainder(theta - e.theta, 2 * Pi), 0.0, 1e-12);
    // a control point of the cone at its (s, t)
    EXPECT_EQ(v.constraint.carrier, cone);
    EXPECT_LE((geometry.point(cone, v.constraint.s, v.constraint.t) - v.position).norm(), 1e-15);
    double s = 0.0, t = 0.0, distance = 1.0;
    geometry.project(cone, v.position, s, t, distance);
    EXPECT_LE(distance, 1e-12 * size);
  }
  checkModel(model);

  // A curved contour (r = 0.6 + 0.1 sin 2z through 12 points, cubic): on the axial plane
  // and on the surface all the same.
  std::ostringstream bump;
  bump.precision(17);
  for (int k = 0; k < 12; ++k)
  {
    const double z = -0.5 + k / 11.0;
    bump << (k ? ", " : "[") << "[" << 0.6 + 0.1 * std::sin(2 * z) << ", 0, " << z << "]";
  }
  bump << "]";
  const BlockModel curved =
    parseFeature(featureText("carriers:\n  bump_line: {interpolate: " + bump.str() +
        "}\n"
        "  bump: {revolve: bump_line, axis: machine}\n",
      "  w1: {on_surface: bump, axial: 0.123, theta: 2.5}\n"
      "  w2: {on_surface: bump, axial: \"-0.4321\", theta: \"-1\"}\n"));
  const CarrierGeometry curvedGeometry(curved);
  const int surface = curved.findCarrier("bump");
  for (const Expected& e : { Expected{ "w1", 0.123, 2.5 }, Expected{ "w2", -0.4321, -1.0 } })
  {
    SCOPED_TRACE(e.name);
    const Vertex& v = vertexNamed(curved, e.name);
    EXPECT_LE(std::abs(v.position.z() - e.axial), 1e-12 * curvedGeometry.size(surface));
    EXPECT_NEAR(std::atan2(v.position.y(), v.position.x()), e.theta, 1e-12);
    double s = 0.0, t = 0.0, distance = 1.0;
    curvedGeometry.project(surface, v.position, s, t, distance);
    EXPECT_LE(distance, 1e-12 * curvedGeometry.size(surface));
    EXPECT_NEAR(radius(v.position), 0.6 + 0.1 * std::sin(2 * e.axial), 1e-4); // interpolated
  }
}

// Regression (fixed): 'axial' and 'theta' accept a surface of revolution whose axis is
// parallel to the machine axis but does not pass through the machine's axis point (only the
// direction is compared), and then place the vertex neither on the axial plane nor at theta:
// here z = 0.50471, theta = 0.36352 instead of 0.5 and 0.4. Either an error or the exact
// point would do.
TEST(CarrierTemplates, VertexAtAxialAndThetaNeedsTheMachineAxisItself)
{
  const std::string text =
    featureText("carriers:\n"
                "  cone_line: {interpolate: [[0.48, 0, -0.2], [0.62, 0, 1.2]]}\n"
                "  shifted: {revolve: cone_line, axis: [0, 0, 1], origin: [0.3, 0, 0], "
                "meridional: false}\n",
      "  v: {on_surface: shifted, axial: 0.5, theta: 0.4}\n");
  try
  {
    const BlockModel model = parseFeature(text);
    const Vec3 p = vertexNamed(model, "v").position;
    EXPECT_NEAR(p.z(), 0.5, 1e-12);
    EXPECT_NEAR(std::atan2(p.y(), p.x()), 0.4, 1e-12);
  }
  catch (const TemplateError& error)
  {
    EXPECT_NE(std::string(error.what()).find("vertex 'v'"), std::string::npos) << error.what();
  }
}

// Regression (fixed): a theta outside the angle range of a partial surface of
// revolution is silently clamped: theta 2.5 on a surface spanning theta 0 to 1 gives a
// vertex at theta 1 (the axial-range check has no angle counterpart).
TEST(CarrierTemplates, VertexAtAxialAndThetaOutsideThePartialSurface)
{
  const std::string text =
    featureText("carriers:\n"
                "  cone_line: {interpolate: [[0.48, 0, -0.2], [0.62, 0, 1.2]]}\n"
                "  part: {revolve: cone_line, axis: machine, angle: [0, 1]}\n",
      "  v: {on_surface: part, axial: 0.5, theta: 2.5}\n");
  const std::string message = errorOf([&] { parseFeature(text); });
  EXPECT_EQ(message.rfind(featureLine(text, "  v: ") + "vertex 'v': ", 0), 0u) << message;
}

TEST(CarrierTemplates, VertexAtAxialAndThetaErrors)
{
  const std::string head = "carriers:\n"
                           "  cone_line: {interpolate: [[0.48, 0, -0.2], [0.62, 0, 1.2]]}\n"
                           "  cone: {revolve: cone_line, axis: machine}\n"
                           "  radial: {interpolate: [[0, 1, 0], [0, 2, 0]]}\n"
                           "  disc_x: {revolve: radial, axis: [1, 0, 0]}\n"
                           "  bottom: {interpolate: [[0, 0, 5], [2, 0, 5]]}\n"
                           "  right: {interpolate: [[2, 0, 5], [2, 1, 5]]}\n"
                           "  top: {interpolate: [[0, 1, 5], [2, 1, 5]]}\n"
                           "  left: {interpolate: [[0, 0, 5], [0, 1, 5]]}\n"
                           "  quad: {coons: [bottom, right, top, left]}\n";
  auto check = [&](const std::string& vertex, const std::string& expected) {
    const std::string text = featureText(head, "  v: " + vertex + "\n");
    EXPECT_EQ(
      errorOf([&] { parseFeature(text); }), featureLine(text, "  v: ") + "vertex 'v': " + expected);
  };
  check("{on_surface: cone, axial: 1.5, theta: 0}",
    "surface 'cone' does not reach axial = 1.5 (its contour spans axial -0.2 to 1.2)");
  check("{on_surface: cone, axial: \"-0.3\", theta: 0}",
    "surface 'cone' does not reach axial = -0.3 (its contour spans axial -0.2 to 1.2)");
  check("{on_surface: quad, axial: 5, theta: 0}",
    "'axial' and 'theta' place a vertex on a surface of revolution about the machine axis; "
    "'quad' is not one");
  check("{on_surface: disc_x, axial: 0.5, theta: 0}",
    "'axial' and 'theta' place a vertex on a surface of revolution about the machine axis; "
    "'disc_x' is not one");
  check("{on_surface: cone, axial: 0.5}", "on_surface with 'axial' needs 'theta' too");
  check("{on_surface: cone_line, axial: 0.5, theta: 0}",
    "on_surface: 'cone_line' is a curve, a surface is needed");
}

namespace
{
/// Distance from p to curve `curve` of `geometry`: the nearest of `samples` points, then
/// golden-section search on the squared distance in the neighbouring sample intervals.
double distanceToCurve(
  const CarrierGeometry& geometry, int curve, const Vec3& p, int samples = 4096)
{
  int best = 0;
  for (int k = 1; k <= samples; ++k)
  {
    if ((geometry.point(curve, static_cast<double>(k) / samples) - p).squaredNorm() <
      (geometry.point(curve, static_cast<double>(best) / samples) - p).squaredNorm())
    {
      best = k;
    }
  }
  const bool closed = geometry.closedS(curve);
  auto f = [&](double u) { return (geometry.point(curve, u) - p).squaredNorm(); };
  double a = static_cast<double>(best - 1) / samples, b = static_cast<double>(best + 1) / samples;
  if (!closed)
  {
    a = std::max(a, 0.0);
    b = std::min(b, 1.0);
  }
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int iteration = 0; iteration < 200 && b - a > 1e-15; ++iteration)
  {
    const double c = b - ratio * (b - a), d = a + ratio * (b - a);
    if (f(c) < f(d))
    {
      b = d;
    }
    else
    {
      a = c;
    }
  }
  return std::sqrt(std::min({ f(0.5 * (a + b)), f(a), f(b) }));
}

/// `[[s, t], ...]`: `count` points of the ellipse s = 0.5 + 0.25 cos phi,
/// t = 0.5 + 0.05 sin phi, the first repeated at the end (a closed loop).
std::string parameterEllipse(int count)
{
  std::ostringstream text;
  text.precision(17);
  text << "[";
  for (int k = 0; k <= count; ++k)
  {
    const double phi = 2.0 * Pi * (k % count) / count;
    text << (k ? ", " : "") << "[" << 0.5 + 0.25 * std::cos(phi) << ", "
         << 0.5 + 0.05 * std::sin(phi) << "]";
  }
  text << "]";
  return text.str();
}
} // namespace

TEST(CarrierTemplates, OffsetCarrierWithinAPlaneSurfaceOfRevolution)
{
  // The annulus 1 <= r <= 3 in the plane z = 0 (a radial line revolved about z): flat, so
  // the offset in the tangent plane is the offset within the surface. The curve: a closed
  // loop in its (s, t) space (r from 1.5 to 2.5, theta within +-0.1 pi), offset outwards
  // (distance > 0) and inwards (< 0).
  const std::string loopText =
    "  loop: {surface_curve: annulus, through: " + parameterEllipse(24) + "}\n";
  const std::string text = featureText("carriers:\n"
                                       "  radial: {interpolate: [[1, 0, 0], [3, 0, 0]]}\n"
                                       "  annulus: {revolve: radial, axis: machine}\n" +
      loopText +
      "  outer: {offset: loop, on: annulus, distance: d}\n"
      "  inner: {offset: loop, on: annulus, distance: -d}\n",
    "  p: {on_curve: outer, at: 0.3}\n", "parameters:\n  d: 0.1\n");
  const BlockModel model = parseFeature(text);
  const CarrierGeometry geometry(model);
  const int loop = model.findCarrier("loop");
  ASSERT_TRUE(geometry.closedS(loop));
  // The loop is an interpolating (not periodic) spline in (s, t): its seam u = 0 = 1 is a
  // corner (about 4.9 degrees here). The offset takes the mean normal there, so on the
  // concave side the seam's offset point is only d cos(kink / 2) from the loop.
  const Vec3 t0 = geometry.curve(loop)->derivative(0.0).normalized();
  const Vec3 t1 = geometry.curve(loop)->derivative(1.0).normalized();
  const double kink = std::acos(std::min(1.0, t0.dot(t1)));
  const double d = 0.1;
  for (const std::string name : { "outer", "inner" })
  {
    SCOPED_TRACE(name);
    const int offset = model.findCarrier(name);
    ASSERT_GE(offset, 0);
    EXPECT_EQ(model.carriers[offset].kind, Carrier::Kind::Offset);
    EXPECT_EQ(
      model.carriers[offset].refs, (std::vector<int>{ loop, model.findCarrier("annulus") }));
    EXPECT_TRUE(geometry.closedS(offset));
    // Measured: on the plane exactly; |distance - d| below 6e-7 away from the seam (the
    // interpolation of the offset samples), 3.6e-6 (outer) and 9.7e-5 (inner) at the seam.
    double worstPlane = 0.0, worstDistance = 0.0, worstSeam = 0.0;
    for (int k = 0; k < 1000; ++k)
    {
      const double u = k / 1000.0;
      const Vec3 p = geometry.point(offset, u);
      worstPlane = std::max(worstPlane, std::abs(p.z()));
      const double error = std::abs(distanceToCurve(geometry, loop, p) - d);
      double& worst = u < 0.02 || u > 0.98 ? worstSeam : worstDistance;
      worst = std::max(worst, error);
    }
    EXPECT_EQ(worstPlane, 0.0);
    EXPECT_LE(worstDistance, 1e-6);
    EXPECT_LE(worstSeam, 1.5 * d * (1.0 - std::cos(kink / 2.0)) + 1e-5);
    // outwards is away from the loop's centre (r = 2, theta = 0)
    const Vec3 centre(2.0, 0.0, 0.0);
    double loopMean = 0.0, offsetMean = 0.0;
    for (int k = 0; k < 100; ++k)
    {
      loopMean += (geometry.point(loop, k / 100.0) - centre).norm() / 100.0;
      offsetMean += (geometry.point(offset, k / 100.0) - centre).norm() / 100.0;
    }
    EXPECT_NEAR(offsetMean - loopMean, name == "outer" ? d : -d, 0.2 * d);
  }
  // a vertex on the offset carrier is a control point on it
  const Vertex& p = vertexNamed(model, "p");
  EXPECT_EQ(p.constraint.carrier, model.findCarrier("outer"));
  EXPECT_EQ(p.position, geometry.point(model.findCarrier("outer"), 0.3));
}

TEST(CarrierTemplates, OffsetCarrierOnACylinder)
{
  // The cylinder r = 1, 0 <= z <= 2. A circular arc (z = 1, from t = 0.2 to 0.8) is offset
  // along the axis: exactly d away, in the surface. A line along the axis (theta = 0) is
  // offset in the tangent plane along theta and projected back: it lies at theta =
  // +-atan(d / r), r atan(d / r) away along the surface, not d.
  const std::string text =
    featureText("parameters:\n  d: 0.3\ncarriers:\n"
                "  line: {interpolate: [[1, 0, 0], [1, 0, 2]]}\n"
                "  cyl: {revolve: line, axis: machine}\n"
                "  arc: {surface_curve: cyl, through: [[0.5, 0.2], [0.5, 0.8]]}\n"
                "  along: {surface_curve: cyl, through: [[0.2, 0.5], [0.8, 0.5]]}\n"
                "  arc_up: {offset: arc, on: cyl, distance: d}\n"
                "  arc_down: {offset: arc, on: cyl, distance: -d}\n"
                "  along_a: {offset: along, on: cyl, distance: d}\n"
                "  along_b: {offset: along, on: cyl, distance: -d}\n",
      "");
  const BlockModel model = parseFeature(text);
  const CarrierGeometry geometry(model);
  const int up = model.findCarrier("arc_up"), down = model.findCarrier("arc_down");
  const int a = model.findCarrier("along_a"), b = model.findCarrier("along_b");
  double worst = 0.0;
  for (int k = 0; k <= 200; ++k)
  {
    const double u = k / 200.0;
    const Vec3 pu = geometry.point(up, u), pd = geometry.point(down, u);
    worst = std::max({ worst, std::abs(radius(pu) - 1.0), std::abs(radius(pd) - 1.0),
      std::abs(std::abs(pu.z() - 1.0) - 0.3), std::abs(pu.z() + pd.z() - 2.0) });
    const Vec3 pa = geometry.point(a, u), pb = geometry.point(b, u);
    const double ta = std::atan2(pa.y(), pa.x()), tb = std::atan2(pb.y(), pb.x());
    worst = std::max({ worst, std::abs(radius(pa) - 1.0), std::abs(radius(pb) - 1.0),
      std::abs(std::abs(ta) - std::atan(0.3)), std::abs(ta + tb) });
    worst =
      std::max({ worst, std::abs(pa.z() - (0.4 + 1.2 * u)), std::abs(pb.z() - (0.4 + 1.2 * u)) });
  }
  EXPECT_LE(worst, 1e-12);
  // the two sides are opposite
  EXPECT_GT(std::abs(geometry.point(up, 0.5).z() - geometry.point(down, 0.5).z()), 0.5);
}

// Regression (fixed): the offset is interpolated in the (s, t) space of the surface,
// so a curve crossing the seam theta = +-pi of a full surface of revolution gets an offset
// that jumps from t = 1 to t = 0 and runs the other way round the axis: here its middle
// is at theta = 0.0055 instead of pi and its points are up to 1.62 from the arc, not 0.3.
TEST(CarrierTemplates, OffsetAcrossTheSeamOfASurfaceOfRevolution)
{
  const std::string text =
    featureText("carriers:\n"
                "  line: {interpolate: [[1, 0, 0], [1, 0, 2]]}\n"
                "  cyl: {revolve: line, axis: machine}\n"
                "  arc: {surface_curve: cyl, through: [[0.5, 0.9], [0.5, 1.1]]}\n"
                "  up: {offset: arc, on: cyl, distance: 0.3}\n",
      "");
  const BlockModel model = parseFeature(text);
  const CarrierGeometry geometry(model);
  const int up = model.findCarrier("up");
  for (int k = 0; k <= 100; ++k)
  {
    const Vec3 p = geometry.point(up, k / 100.0);
    EXPECT_NEAR(radius(p), 1.0, 1e-12) << k;
    EXPECT_NEAR(std::abs(p.z() - 1.0), 0.3, 1e-12) << k;
    EXPECT_GE(std::abs(std::atan2(p.y(), p.x())), 0.8 * Pi - 1e-9) << k;
  }
}

TEST(CarrierTemplates, OffsetCarrierErrors)
{
  const std::string carriers = "carriers:\n"
                               "  radial: {interpolate: [[1, 0, 0], [3, 0, 0]]}\n"
                               "  annulus: {revolve: radial, axis: machine}\n"
                               "  loop: {surface_curve: annulus, through: " +
    parameterEllipse(24) +
    "}\n"
    "  above: {interpolate: [[1.5, 0, 0.25], [2.5, 0, 0.25]]}\n";
  auto check = [&](const std::string& offset, const std::string& expected) {
    const std::string text =
      featureText("parameters:\n  d: 0.1\n" + carriers + "  o: " + offset + "\n", "");
    EXPECT_EQ(errorOf([&] { parseFeature(text); }),
      featureLine(text, "  o: ") + "carrier 'o': " + expected);
  };
  check(
    "{offset: loop, on: annulus, distance: \"d - 0.1\"}", "the offset distance must not be zero");
  check("{offset: above, on: annulus, distance: d}",
    "curve 'above' does not lie on 'annulus' (a point is 0.25 away from it); offset a curve "
    "on its own surface");
  check("{offset: loop, on: above, distance: d}", "on: 'above' is a curve, a surface is needed");
  check("{offset: annulus, on: annulus, distance: d}",
    "offset: 'annulus' is a surface, a curve is needed");
  check("{offset: loop, on: annulus}",
    "offset needs 'on: <surface the curve lies on>' and 'distance: <length>', e.g. "
    "{offset: blade_hub, on: hub, distance: 0.01}");
  // inwards by more than the loop's smallest radius of curvature (about 0.4): folds back
  const std::string text = featureText(
    "parameters:\n  d: 0.1\n" + carriers + "  o: {offset: loop, on: annulus, distance: -0.8}\n",
    "");
  const std::string message = errorOf([&] { parseFeature(text); });
  const std::string start = featureLine(text, "  o: ") +
    "carrier 'o': offset on a surface: the offset by -0.8 folds back near u = ";
  EXPECT_EQ(message.rfind(start, 0), 0u) << message;
  EXPECT_NE(message.find("use a smaller distance"), std::string::npos) << message;
}

namespace
{
struct AlignedSection
{
  double leadingParameter, trailingParameter;     // of the smallest / largest axial position
  double leadingAxialExcess, trailingAxialExcess; // axial at s = 0.25 above the minimum, ...
  double leadingOffset, trailingOffset;           // |P(0.25) - P(leading)|, |P(0.75) - P(trailing)|
  double worstInput;                              // largest distance of an input point
  std::vector<double> inputDistances;
};

/// The extreme axial points of blade section carrier `section` (brute force on the curve)
/// and the distances of the section's input points from it.
AlignedSection measureSection(const CarrierGeometry& geometry, int section,
  const std::vector<Vec3>& inputPoints, const Vec3& axis)
{
  AlignedSection result{};
  auto axial = [&](const Vec3& p) { return p.dot(axis); };
  result.leadingParameter = bruteMaximum(
    geometry, section, [&](const Vec3& p) { return -axial(p); }, 0.0, 1.0);
  result.trailingParameter = bruteMaximum(geometry, section, axial, 0.0, 1.0);
  const Vec3 leading = geometry.point(section, result.leadingParameter);
  const Vec3 trailing = geometry.point(section, result.trailingParameter);
  result.leadingAxialExcess = axial(geometry.point(section, 0.25)) - axial(leading);
  result.trailingAxialExcess = axial(trailing) - axial(geometry.point(section, 0.75));
  result.leadingOffset = (geometry.point(section, 0.25) - leading).norm();
  result.trailingOffset = (geometry.point(section, 0.75) - trailing).norm();
  for (const Vec3& p : inputPoints)
  {
    result.inputDistances.push_back(distanceToCurve(geometry, section, p, 8192));
    result.worstInput = std::max(result.worstInput, result.inputDistances.back());
  }
  return result;
}

BlockModel loadAlignedBlade(
  const TemplateInputs& inputs, const std::string& replace = "", const std::string& with = "")
{
  const std::string text = readText(dataPath("feature_aligned_blade.yaml"));
  return parseTemplate(replace.empty() ? text : replaced(text, replace, with),
    "feature_aligned_blade.yaml", {}, &inputs);
}
} // namespace

TEST(CarrierTemplates, AlignedSectionsPlateBlade)
{
  // The plate blade's sections are ellipses z = 0.5 + 0.2 cos phi, theta = 0.05 sin phi
  // (40 points from phi = 0, uniform parameters): leading edge z = 0.3, trailing edge 0.7.
  const TemplateInputs inputs = bladeInputs();
  const BlockModel model = loadAlignedBlade(inputs);
  const CarrierGeometry geometry(model);
  const int blade = model.findCarrier("blade");
  const double size = geometry.size(blade);
  EXPECT_TRUE(geometry.closedS(blade));
  for (int k = 0; k < 4; ++k)
  {
    SCOPED_TRACE(k);
    const int section = model.findCarrier("blade.section" + std::to_string(k + 1));
    ASSERT_GE(section, 0);
    EXPECT_EQ(model.carriers[section].nodes.size(), model.carriers[section].points.size());
    const AlignedSection m =
      measureSection(geometry, section, inputs.pointSets[2].curves[k].points, Vec3::UnitZ());
    // measured: parameters within 1.1e-9 (the brute-force search resolves about 1e-9),
    // input points within 1e-13 of the size
    EXPECT_NEAR(m.leadingParameter, 0.25, 1e-8);
    EXPECT_NEAR(m.trailingParameter, 0.75, 1e-8);
    EXPECT_NEAR(geometry.point(section, 0.25).z(), 0.3, 1e-12);
    EXPECT_NEAR(geometry.point(section, 0.75).z(), 0.7, 1e-12);
    EXPECT_LE(m.worstInput, 1e-9 * size);
    // the blade passes through the section: the section's t is k / 3 (span fractions)
    for (double s : { 0.0, 0.25, 0.6, 0.75 })
    {
      EXPECT_LE((geometry.point(blade, s, k / 3.0) - geometry.point(section, s)).norm(), 1e-14);
    }
  }
  // so s = 0.25 runs along the leading edge from hub to shroud on the blade
  for (double t : { -0.2, 0.5, 1.2 })
  {
    EXPECT_NEAR(geometry.point(blade, 0.25, t).z(), 0.3, 1e-12);
    EXPECT_NEAR(geometry.point(blade, 0.75, t).z(), 0.7, 1e-12);
  }
  // the cut with the hub: leading and trailing edge at s close to 0.25 and 0.75
  EXPECT_NEAR(vertexNamed(model, "le_h").position.z(), 0.3, 1e-9);
  EXPECT_NEAR(vertexNamed(model, "te_h").position.z(), 0.7, 1e-9);
}

TEST(CarrierTemplates, AlignedSectionsRotor37AndDistributor)
{
  // Real sections: an edge within a quarter of the data spacing of an input point is put
  // on that point (so the blade passes through every input point), else inserted; the
  // aligned section is a new interpolation, so its own axial extremum lies near, not
  // exactly at, s = 0.25 / 0.75: by at most about a quarter of the local data spacing.
  const std::vector<std::pair<std::string, TemplateInputs>> cases = {
    { "rotor37", rotor37Inputs() },
    { "distributor", test::readTemplateInputs(test::sourcePath("Data/distributor/BladeGen.inf")) }
  };
  for (const auto& data : cases)
  {
    SCOPED_TRACE(data.first);
    const BlockModel model = loadAlignedBlade(data.second);
    const CarrierGeometry geometry(model);
    const int blade = model.findCarrier("blade");
    const double size = geometry.size(blade);
    const InputPointSet& sections = data.second.pointSets[2];
    ASSERT_EQ(model.findCarrier("blade.section" + std::to_string(sections.curves.size() + 1)), -1);
    for (std::size_t k = 0; k < sections.curves.size(); ++k)
    {
      SCOPED_TRACE(k);
      const int section = model.findCarrier("blade.section" + std::to_string(k + 1));
      ASSERT_GE(section, 0);
      const AlignedSection m =
        measureSection(geometry, section, sections.curves[k].points, model.machine.axis);
      // measured worst: 1.6e-4 in s, 1.5e-4 and 1.0e-6 of the size (distributor section 2)
      EXPECT_NEAR(m.leadingParameter, 0.25, 5e-4);
      EXPECT_NEAR(m.trailingParameter, 0.75, 5e-4);
      EXPECT_LE(m.leadingOffset, 5e-4 * size);
      EXPECT_LE(m.trailingOffset, 5e-4 * size);
      EXPECT_LE(m.leadingAxialExcess, 5e-6 * size);
      EXPECT_LE(m.trailingAxialExcess, 5e-6 * size);
      // every input point is on the aligned section (edges near a point are moved onto it)
      EXPECT_LE(m.worstInput, 1e-9 * size);
    }
  }
}

// Regression: align: axial once dropped the input points within a quarter of their spacing
// of a section's leading or trailing edge or of its new seam (Rotor 37 section 5, input
// point 225 of 301, was 7.3e-6 of the blade size off the blade).
TEST(CarrierTemplates, AlignedSectionsPassThroughEveryInputPoint)
{
  const TemplateInputs inputs = rotor37Inputs();
  const BlockModel model = loadAlignedBlade(inputs);
  const CarrierGeometry geometry(model);
  const double size = geometry.size(model.findCarrier("blade"));
  const InputPointSet& sections = inputs.pointSets[2];
  for (std::size_t k = 0; k < sections.curves.size(); ++k)
  {
    const int section = model.findCarrier("blade.section" + std::to_string(k + 1));
    const std::vector<Vec3>& points = sections.curves[k].points;
    for (std::size_t p = 0; p < points.size(); ++p)
    {
      EXPECT_LE(distanceToCurve(geometry, section, points[p], 8192), 1e-9 * size)
        << "section " << k + 1 << " point " << p;
    }
  }
}

TEST(CarrierTemplates, AlignErrors)
{
  const TemplateInputs inputs = bladeInputs();
  const std::string text = readText(dataPath("feature_aligned_blade.yaml"));
  const std::string prefix =
    "feature_aligned_blade.yaml:" + std::to_string(lineContaining(text, "  blade: {gordon")) +
    ": carrier 'blade': ";
  EXPECT_EQ(
    errorOf([&] { loadAlignedBlade(inputs, "closed: true, align: axial", "align: axial"); }),
    prefix + "align needs closed: true and sections from an input (a blade)");
  EXPECT_EQ(errorOf([&] {
    loadAlignedBlade(inputs, "closed: true, align: axial", "closed: false, align: axial");
  }),
    prefix + "align needs closed: true and sections from an input (a blade)");
  EXPECT_EQ(errorOf([&] { loadAlignedBlade(inputs, "true, align: axial", "true, align: foo"); }),
    prefix + "align: expected 'axial', got 'foo'");
  // sections given as carriers: not from an input
  const std::string listed = replaced(text, "{gordon: sections,", "{gordon: [s1, s2],");
  const std::string withSections = replaced(listed, "carriers:\n",
    "carriers:\n  s1: {interpolate: " + circlePoints(Vec3(0, 0.6, 0.5), 0.1, 16, 0.0) +
      "}\n  s2: {interpolate: " + circlePoints(Vec3(0, 0.9, 0.5), 0.1, 16, 0.0) + "}\n");
  EXPECT_EQ(
    errorOf([&] { parseTemplate(withSections, "feature_aligned_blade.yaml", {}, &inputs); }),
    "feature_aligned_blade.yaml:" +
      std::to_string(lineContaining(withSections, "  blade: {gordon")) +
      ": carrier 'blade': align needs closed: true and sections from an input (a blade)");
}

TEST(CarrierTemplates, BladeCutOffsetOnHubAndShroud)
{
  // feature_aligned_blade.yaml on the plate blade: hub cone r = 0.5 + 0.1 z, shroud
  // cylinder r = 1; the blade cuts run from the leading edge z = 0.3 to the trailing edge
  // z = 0.7 at theta = 0, so chord_h = 0.4 and the offset distance 0.1 chord_h = 0.04.
  const TemplateInputs inputs = bladeInputs();
  const BlockModel model = loadAlignedBlade(inputs);
  const CarrierGeometry geometry(model);
  const double d = 0.04;
  const int oh = model.findCarrier("o_h"), os = model.findCarrier("o_s");
  const int bladeHub = model.findCarrier("blade_h"), bladeShroud = model.findCarrier("blade_s");
  EXPECT_NEAR(model.carriers[oh].distance, d, 1e-12);
  EXPECT_EQ(model.carriers[os].distance, model.carriers[oh].distance);
  EXPECT_TRUE(geometry.closedS(oh));
  // On the surfaces to 1e-9. Away from the blade by d in the tangent plane, projected
  // back: along the meridian (at the edges) exactly d; across it (the sides, r >= 0.53)
  // the chord 2 r sin(atan(d / r) / 2), at least d (1 - d^2 / (2 r^2)) = 0.99715 d.
  // Measured: between 0.99799 d and d on the hub, 0.99940 d and d on the shroud.
  double hubWorst = 0.0, shroudWorst = 0.0;
  double hubLow = 1.0, hubHigh = 0.0, shroudLow = 1.0, shroudHigh = 0.0;
  for (int k = 0; k < 400; ++k)
  {
    const Vec3 h = geometry.point(oh, k / 400.0), s = geometry.point(os, k / 400.0);
    hubWorst = std::max(hubWorst, std::abs(radius(h) - hubRadius(h.z())));
    shroudWorst = std::max(shroudWorst, std::abs(radius(s) - 1.0));
    const double dh = distanceToCurve(geometry, bladeHub, h) / d;
    const double ds = distanceToCurve(geometry, bladeShroud, s) / d;
    hubLow = std::min(hubLow, dh);
    hubHigh = std::max(hubHigh, dh);
    shroudLow = std::min(shroudLow, ds);
    shroudHigh = std::max(shroudHigh, ds);
  }
  EXPECT_LE(hubWorst, 1e-9);
  EXPECT_LE(shroudWorst, 1e-9);
  EXPECT_GE(hubLow, 1.0 - d * d / (2 * 0.53 * 0.53));
  EXPECT_LE(hubHigh, 1.0 + 1e-8);
  EXPECT_GE(shroudLow, 1.0 - d * d / 2);
  EXPECT_LE(shroudHigh, 1.0 + 1e-8);
  // The front of the hub offset near the leading edge (min axial within a window): the
  // leading edge moved by d up the cone's generator, slope 0.1.
  const Vec3 front = vertexNamed(model, "front_h").position;
  EXPECT_NEAR(front.z(), 0.3 - d / std::sqrt(1.01), 1e-9);
  EXPECT_NEAR(radius(front), hubRadius(0.3 - d / std::sqrt(1.01)), 1e-9);
  EXPECT_NEAR(std::atan2(front.y(), front.x()), 0.0, 1e-6);
  // Mid-chord, half a pitch beside the leading edge, on hub and shroud.
  for (const std::string name : { "mid_h", "mid_s" })
  {
    const Vertex& mid = vertexNamed(model, name);
    EXPECT_NEAR(mid.position.z(), 0.5, 1e-12) << name;
    EXPECT_NEAR(radius(mid.position), name == "mid_h" ? 0.55 : 1.0, 1e-12) << name;
    EXPECT_NEAR(std::atan2(mid.position.y(), mid.position.x()),
      std::atan2(vertexNamed(model, "le_h").position.y(), vertexNamed(model, "le_h").position.x()) +
        Pi / 12,
      1e-12)
      << name;
  }
  checkModel(model);
}

TEST(CarrierTemplates, OffsetAndAlignedCarriersSurviveTheDocument)
{
  const std::vector<std::pair<std::string, TemplateInputs>> cases = { { "plate", bladeInputs() },
    { "rotor37", rotor37Inputs() } };
  for (const auto& data : cases)
  {
    SCOPED_TRACE(data.first);
    const BlockModel model = loadAlignedBlade(data.second);
    EXPECT_NE(writeModelDocument(model).find("kind: offset"), std::string::npos);
    const BlockModel reread = documentRoundTrip(model);
    const CarrierGeometry original(model), again(reread);
    const std::vector<double> us = { 0.0, 0.1, 0.2500001, 0.37, 0.5, 0.75, 0.999 };
    std::vector<std::string> curves = { "o_h", "o_s", "blade_h", "blade_s" };
    for (std::size_t k = 1; model.findCarrier("blade.section" + std::to_string(k)) >= 0; ++k)
    {
      curves.push_back("blade.section" + std::to_string(k));
    }
    for (const std::string& name : curves)
    {
      const int c = model.findCarrier(name);
      ASSERT_GE(c, 0) << name;
      for (double u : us)
      {
        const Vec3 a = original.point(c, u), b = again.point(c, u);
        EXPECT_EQ(0, std::memcmp(a.data(), b.data(), 3 * sizeof(double))) << name << " " << u;
      }
    }
    const int blade = model.findCarrier("blade");
    for (double s : us)
    {
      for (double t : { -0.3, 0.0, 0.45, 1.0, 1.2 })
      {
        const Vec3 a = original.point(blade, s, t), b = again.point(blade, s, t);
        EXPECT_EQ(0, std::memcmp(a.data(), b.data(), 3 * sizeof(double))) << s << " " << t;
      }
    }
    for (std::size_t v = 0; v < model.vertices.size(); ++v)
    {
      EXPECT_EQ(model.vertices[v].position, reread.vertices[v].position) << model.vertices[v].name;
      EXPECT_EQ(model.vertices[v].constraint.carrier, reread.vertices[v].constraint.carrier);
      EXPECT_EQ(model.vertices[v].constraint.s, reread.vertices[v].constraint.s);
      EXPECT_EQ(model.vertices[v].constraint.t, reread.vertices[v].constraint.t);
    }
  }
}

// A follow edge is its source edge's shape between its own ends: here the box edge b -> f
// follows a spline a -> e bulging outwards, b and f being a and e moved by (1, 0, 0), so
// its nodes are the spline's nodes moved by (1, 0, 0).
TEST(CarrierTemplates, FollowEdgeIsItsSourceMoved)
{
  const std::string edges = "edges:\n"
                            "  bulge: {spline: [a, e], points: [[9.7, 0, 0.5]]}\n"
                            "  along: {follow: bulge, between: [b, f]}\n";
  const std::string text = featureText("", "", edges);
  const BlockModel model = parseFeature(text);
  const Grid grid = meshAll(model);
  const auto& n = grid.nodes[0];
  double worst = 0.0, bulge = 0.0;
  for (int k = 0; k < n[2]; ++k)
  {
    const Vec3 source = grid.at(0, 0, 0, k), moved = grid.at(0, n[0] - 1, 0, k);
    worst = std::max(worst, (moved - source - Vec3(1, 0, 0)).norm());
    bulge = std::max(bulge, 10.0 - source.x());
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(bulge, 0.2); // the source is curved, so the check means something
  // the document keeps it
  const BlockModel reread = documentRoundTrip(model);
  const Grid again = meshAll(reread);
  EXPECT_TRUE(sameBits(grid.xyz[0], again.xyz[0]));
  // running the other way along its source gives the same edge
  const Grid reversed = meshAll(parseFeature(replaced(text, "between: [b, f]", "between: [f, b]")));
  double apart = 0.0;
  for (std::size_t i = 0; i < grid.xyz[0].size(); ++i)
  {
    apart = std::max(apart, std::abs(grid.xyz[0][i] - reversed.xyz[0][i]));
  }
  EXPECT_LT(apart, 1e-12);
  // errors: a source below, an unknown source, 'at'
  auto errorFor = [&](const std::string& edgeLines) {
    return errorOf([&] { parseFeature(featureText("", "", "edges:\n" + edgeLines)); });
  };
  const std::string later = "  along: {follow: bulge, between: [b, f]}\n"
                            "  bulge: {spline: [a, e], points: [[9.7, 0, 0.5]]}\n";
  EXPECT_EQ(errorFor(later),
    featureLine(featureText("", "", "edges:\n" + later), "  along:") +
      "edge 'along': follow: unknown edge 'bulge'; the source edge must be defined above this "
      "one");
  const std::string withAt = "  bulge: {spline: [a, e], points: [[9.7, 0, 0.5]]}\n"
                             "  along: {follow: bulge, between: [b, f], at: [0, 1]}\n";
  EXPECT_EQ(errorFor(withAt),
    featureLine(featureText("", "", "edges:\n" + withAt), "  along:") +
      "edge 'along': a follow edge takes its shape from its source edge, not from 'at'");
}

// A face that follows the face opposite it ({follow: opposite}): its interior is the Coons
// patch of its own edges plus the opposite face's departure from the Coons patch of that
// face's edges. Here the box's i0 face lies on a dome whose boundary is the flat square
// x = 10 (the Coons patch of its edges is that plane) and whose middle bulges to x = 9.7;
// the i1 face's edges are the i0 face's moved by +1 in x, so i1 is i0 moved by +1 in x,
// bulge and all (without the face set it is the flat square x = 11).
TEST(CarrierTemplates, FollowingFaceKeepsTheOppositeFacesBulge)
{
  const std::string head = "carriers:\n"
                           "  c0: {interpolate: [[10, 0, 0], [10, 0.5, 0], [10, 1, 0]], degree: 2}\n"
                           "  c1: {interpolate: [[10, 0, 0.5], [9.7, 0.5, 0.5], [10, 1, 0.5]], degree: 2}\n"
                           "  c2: {interpolate: [[10, 0, 1], [10, 0.5, 1], [10, 1, 1]], degree: 2}\n"
                           "  dome: {gordon: [c0, c1, c2], blending: spline, at: [0, 0.5, 1]}\n";
  const std::string faces = "faces:\n"
                            "  wall: {on_surface: dome, faces: [box.i0]}\n"
                            "  outer: {follow: opposite, faces: [box.i1]}\n";
  const std::string text = featureText(head, "", faces);
  const BlockModel model = parseFeature(text);
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const Grid grid = meshAll(model, density);
    const auto& n = grid.nodes[0];
    double worst = 0.0, bulge = 0.0;
    for (int k = 0; k < n[2]; ++k)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        const Vec3 wall = grid.at(0, 0, j, k), outer = grid.at(0, n[0] - 1, j, k);
        worst = std::max(worst, (outer - wall - Vec3(1, 0, 0)).norm());
        bulge = std::max(bulge, 10.0 - wall.x());
      }
    }
    EXPECT_LT(worst, 1e-12);
    EXPECT_GT(bulge, 0.25); // the wall bulges, so the check means something
  }
  // without the set the outer face is the flat square
  const Grid flat = meshAll(parseFeature(featureText(head, "",
    "faces:\n  wall: {on_surface: dome, faces: [box.i0]}\n")));
  const auto& n = flat.nodes[0];
  EXPECT_EQ(flat.at(0, n[0] - 1, n[1] / 2, n[2] / 2).x(), 11.0);
  // the document keeps it
  const Grid grid = meshAll(model);
  const Grid again = meshAll(documentRoundTrip(model));
  EXPECT_TRUE(sameBits(grid.xyz[0], again.xyz[0]));
  // errors
  auto errorFor = [&](const std::string& faceLines) {
    return errorOf([&] { parseFeature(featureText(head, "", "faces:\n" + faceLines)); });
  };
  const std::string same = "  outer: {follow: same, faces: [box.i1]}\n";
  EXPECT_EQ(errorFor(same), featureLine(featureText(head, "", "faces:\n" + same), "  outer:") +
      "face set 'outer': 'follow' must be 'opposite' (each face follows the face opposite it in "
      "its block)");
  const std::string both = "  outer: {follow: opposite, on_surface: dome, faces: [box.i1]}\n";
  EXPECT_EQ(errorFor(both), featureLine(featureText(head, "", "faces:\n" + both), "  outer:") +
      "face set 'outer': has both 'on_surface' and 'follow': give one");
  const std::string chain = "  outer: {follow: opposite, faces: [box.i1, box.i0]}\n";
  EXPECT_EQ(errorFor(chain), featureLine(featureText(head, "", "faces:\n" + chain), "  box:") +
      "block 'box': face box.i0 follows a face that follows another: the face a following face "
      "follows must lie on a surface or come from its edges");
}

// A face may follow the face opposite it when that face is a periodic image: the image is
// rotated from its partner before the following faces are made (a stale or empty image
// read otherwise). annular_sector with its periodic_low face in_1.j0 on a surface bulging
// by 0.03 into the block: in_3.j0 follows in_3.j1, the bulge's image, so its interior is
// its flat Coons patch plus the image's departure from its own (within 1e-12), in a whole
// run and in a run meshing in_3 alone (an MPI rank's share). An image cannot follow, and a
// face cannot follow the image of a following face.
TEST(CarrierTemplates, FollowingFaceOppositeAPeriodicImage)
{
  std::string base = test::readText(test::sourcePath("Templates/annular_sector.yaml"));
  base.replace(base.find("blockforge: 1"), 13, "blockforge: 2");
  const std::string carriers =
    "carriers:\n"
    "  c0: {interpolate: [[0.5, 0, 0], [0.625, 0, 0], [0.75, 0, 0]], degree: 2}\n"
    "  c1: {interpolate: [[0.5, 0, 0.2], [0.625, 0.03, 0.2], [0.75, 0, 0.2]], degree: 2}\n"
    "  c2: {interpolate: [[0.5, 0, 0.4], [0.625, 0, 0.4], [0.75, 0, 0.4]], degree: 2}\n"
    "  bulge: {gordon: [c0, c1, c2], blending: spline, at: [0, 0.5, 1]}\n";
  base.insert(base.find("\nvertices:") + 1, carriers);
  const std::string wall = "faces:\n  wall: {on_surface: bulge, faces: [in_1.j0]}\n";
  const auto parse = [&](const std::string& faces) {
    return model::parseTemplate(base + faces, "sector.yaml", {}, nullptr);
  };
  const BlockModel following = parse(wall + "  outer: {follow: opposite, faces: [in_3.j0]}\n");
  const int in3 = following.findBlock("in_3");
  ASSERT_GE(in3, 0);
  for (const double density : { 1.0, 2.0 })
  {
    SCOPED_TRACE(density);
    const Grid plain = meshAll(parse(""), density);
    const Grid bulged = meshAll(parse(wall), density);
    const Grid grid = meshAll(following, density);
    const auto& n = grid.nodes[in3];
    double worst = 0.0, bulge = 0.0;
    for (int k = 1; k + 1 < n[2]; ++k)
    {
      for (int i = 1; i + 1 < n[0]; ++i)
      {
        const Vec3 departure = bulged.at(in3, i, n[1] - 1, k) - plain.at(in3, i, n[1] - 1, k);
        bulge = std::max(bulge, departure.norm());
        worst = std::max(worst, (grid.at(in3, i, 0, k) - plain.at(in3, i, 0, k) - departure).norm());
      }
    }
    EXPECT_GT(bulge, 0.02); // the image bulges, so the check means something
    EXPECT_LT(worst, 1e-12);
    // in_3 alone (its image's source, in_1.j0, is another block's face)
    model::MultiBlockMesher mesher(following, density);
    mesher.computeBoundaries({ in3 });
    std::vector<double> alone(grid.xyz[in3].size());
    mesher.meshBlock(in3, alone.data());
    EXPECT_TRUE(sameBits(alone, grid.xyz[in3]));
  }
  const auto errorFor = [&](const std::string& faces) {
    return errorOf([&] { meshAll(parse(wall + faces)); });
  };
  EXPECT_NE(errorFor("  outer: {follow: opposite, faces: [in_3.j1]}\n")
              .find("face set 'outer': face in_3.j1 is a periodic image (its partner's face rotated): "
                    "it cannot follow the face opposite it"),
    std::string::npos);
  EXPECT_NE(errorOf([&] {
    meshAll(parse("faces:\n  outer: {follow: opposite, faces: [in_1.j0, in_3.j0]}\n"));
  }).find("face set 'outer': face in_3.j0 follows the periodic image of a face that follows another"),
    std::string::npos);
}

// A block's `interpolation` (Core/Transfinite.h Blending): read, written to the document,
// used by the mesher (a block whose i-edges end in cells of 0.025, its i1 face bulging out
// by 0.6: with end_cells in i the first cell of the middle i-line is 0.025 within 2e-3,
// linear gives it the edges' fraction of that longer line, 0.04), and its errors.
TEST(CarrierTemplates, InterpolationEndCells)
{
  const std::string edges = "edges:\n"
                            "  bulge: {spline: [b, f], points: [[11.6, 0, 0.5]]}\n"
                            "  bulge2: {spline: [c, g], points: [[11.6, 1, 0.5]]}\n";
  const std::string law = "grading: {i: {ends: [0.1, 0.1]}}";
  std::string text = featureText("", "", edges);
  text = replaced(text, "cells: [4, 4, 4]}", "cells: [4, 4, 4], " + law + "}");
  const auto firstCell = [](const BlockModel& model) {
    const Grid grid = meshAll(model);
    return (grid.at(0, 1, 2, 2) - grid.at(0, 0, 2, 2)).norm();
  };
  const BlockModel linear = parseFeature(text);
  const BlockModel ends = parseFeature(replaced(text, law + "}", law + ", interpolation: {i: end_cells}}"));
  EXPECT_EQ(ends.blocks[0].blending[0], Blending::EndCells);
  EXPECT_EQ(ends.blocks[0].blending[1], Blending::Linear);
  EXPECT_NEAR(firstCell(ends), 0.025, 2e-3);
  EXPECT_NEAR(firstCell(linear), 0.04, 2e-3);
  const BlockModel all = parseFeature(replaced(text, law + "}", law + ", interpolation: end_cells}"));
  EXPECT_EQ(all.blocks[0].blending[2], Blending::EndCells);
  // the document keeps it
  EXPECT_TRUE(sameBits(meshAll(ends).xyz[0], meshAll(documentRoundTrip(ends)).xyz[0]));
  EXPECT_EQ(documentRoundTrip(all).blocks[0].blending[1], Blending::EndCells);
  const std::string wrong = replaced(text, law + "}", law + ", interpolation: smooth}");
  EXPECT_EQ(errorOf([&] { parseFeature(wrong); }), featureLine(wrong, "  box:") +
      "block 'box': 'interpolation' must be 'linear' (the default: interior lines take the edges' "
      "fractions), 'end_cells' (interior lines keep the edges' end cells as lengths), "
      "'adaptive' (linear while the interior lines' lengths stay within 20 % of their edges', "
      "else towards end_cells so that their end cells do), 'end_widths' (linear, and on a "
      "face a cell next to a side that comes out under 0.7 of the width of that side's end "
      "cells is widened to 0.8 of it) or {i: .., j: .., k: ..} of those");
  // adaptive reads and writes back
  const BlockModel adaptive =
    parseFeature(replaced(text, law + "}", law + ", interpolation: {j: adaptive}}"));
  EXPECT_EQ(adaptive.blocks[0].blending[1], Blending::Adaptive);
  EXPECT_EQ(documentRoundTrip(adaptive).blocks[0].blending[1], Blending::Adaptive);
}

// A min/max objective that is NaN somewhere, or that gives several values, is an error
// naming the vertex (a NaN never compares smaller, so it would silently pick the window's
// start).
TEST(CarrierTemplates, CurveExtremumOfNaNOrSeveralValues)
{
  const std::string head = "carriers:\n" + circleCarrier();
  auto check = [&](const std::string& vertex, const std::string& expected) {
    const std::string text = featureText(head, "  v: " + vertex + "\n");
    const std::string message = errorOf([&] { parseFeature(text); });
    EXPECT_EQ(message.rfind(featureLine(text, "  v: ") + "vertex 'v': " + expected, 0), 0u)
      << message;
  };
  check("{on_curve: circle, at: {min: \"sqrt(-1) + axial\"}}",
    "min: 'sqrt(-1) + axial' is NaN at the curve point (");
  check("{on_curve: circle, at: {max: \"radius, axial\"}}",
    "max: 'radius, axial' gives 2 comma-separated values where one number is expected");
}

// The mesher checks the real corner cells: a spline edge that leaves its corner backwards
// (first node behind the corner) folds the corner cells although the straight block is
// right-handed; the error names the block, the corner and its vertex.
TEST(CarrierTemplates, FoldedCornerCellsAreAnError)
{
  const std::string text = featureText("", "",
    "edges:\n  back: {spline: [a, b], points: [[9.6, 0, 0], [10.4, 0, 0]]}\n");
  const BlockModel model = parseFeature(text); // the vertices are in a right-handed order
  MultiBlockMesher mesher(model, 1.0);
  const std::string message = errorOf([&] { mesher.computeBoundaries(); });
  EXPECT_EQ(message.rfind(featureLine(text, "  box:") + "block 'box': the block folds at V0 "
                                                        "(vertex 'a'): the edges leaving it "
                                                        "form a left-handed frame",
              0),
    0u)
    << message;
}

// machine: theta_zero sets where theta = 0 lies about the axis: a direction or the centroid
// of an input's points; along the axis it gives no angle.
TEST(CarrierTemplates, ThetaZero)
{
  {
    const std::string text = featureText("machine: {theta_zero: [0, 3, 0]}\n",
      "  p: {cylindrical: [0.5, 2, 0]}\n  q: {cylindrical: [0.5, 2, 90deg]}\n"
      "  r: [\"p.theta\", \"q.theta\", 0]\n");
    const BlockModel model = parseFeature(text);
    EXPECT_LT((vertexNamed(model, "p").position - Vec3(0, 2, 0.5)).norm(), 1e-15);
    EXPECT_LT((vertexNamed(model, "q").position - Vec3(-2, 0, 0.5)).norm(), 1e-15);
    EXPECT_NEAR(vertexNamed(model, "r").position.x(), 0.0, 1e-15);
    EXPECT_NEAR(vertexNamed(model, "r").position.y(), Pi / 2, 1e-15);
  }
  auto check = [&](const std::string& machine, const std::string& expected) {
    const std::string text = featureText("machine: {theta_zero: " + machine + "}\n", "");
    EXPECT_EQ(errorOf([&] { parseFeature(text); }),
      featureLine(text, "machine:") + "machine: " + expected);
  };
  check("[0, 0, 2]",
    "theta_zero: the direction is along the machine axis (or zero), so it gives no angle");
  check("nosuch",
    "theta_zero: 'nosuch' is neither a direction [x, y, z] nor an input of this template");
}
