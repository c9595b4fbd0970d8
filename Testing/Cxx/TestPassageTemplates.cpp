// Blade-passage templates (Templates/axial_passage_h.yaml, Templates/axial_passage_oh.yaml)
// on both turbomachinery data sets (Data/rotor37/turbogrid: 36 blades, CM; Data/distributor:
// 16 guide vanes leaning the other way, M), with the same parameters. Every grid must be
// periodic (low side rotated by one pitch = high side), have its hub, shroud and blade
// nodes on those surfaces, no inverted cell, the named patches, the passage volume
// (computed here from the input point sets, independently of the carriers) and be the
// same bit for bit when made again. The test also prints the MinAngle classes and the time
// to apply each template (medians of 5) for the report.
#include "CarrierGeometry.h"
#include "Mesher.h"
#include "ModelDocument.h"
#include "Quality.h"
#include "Template.h"

#include "TurboPointSets.h"

#include <Eigen/Geometry>
#include "TestHelpers.h"
#include "TestPassageGeometry.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
using test::Pi;

struct DataSet
{
  std::string name;
  std::string inf;
};

const std::vector<DataSet>& dataSets()
{
  static const std::vector<DataSet> sets = { { "rotor37",
                                               std::string(BLOCKFORGE_SOURCE_DIR) +
                                                 "/Data/rotor37/turbogrid/BladeGen.inf" },
    { "distributor", std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/distributor/BladeGen.inf" } };
  return sets;
}

std::string templatePath(const std::string& name)
{
  return test::templatePath(name + ".yaml");
}

using test::Grid;
using test::meshAll;
using test::readTemplateInputs;

using test::faceNodes;
using test::gridVolume;

/// Radius of a meridional contour (z increasing) at z, linear between its points.
double contourRadius(const std::vector<Vec3>& contour, double z)
{
  auto r = [](const Vec3& p) { return std::hypot(p.x(), p.y()); };
  if (z <= contour.front().z())
    return r(contour.front());
  for (std::size_t k = 1; k < contour.size(); ++k)
  {
    if (z <= contour[k].z())
    {
      const double dz = contour[k].z() - contour[k - 1].z();
      const double w = dz > 0.0 ? (z - contour[k - 1].z()) / dz : 1.0;
      return (1.0 - w) * r(contour[k - 1]) + w * r(contour[k]);
    }
  }
  return r(contour.back());
}

/**
 * The passage volume between the axial planes z0 and z1 from the input point sets alone:
 * the annular sector pitch/2 * integral of (r_shroud^2 - r_hub^2) dz (Simpson, contours
 * interpolated linearly), minus the blade: the area of every section in its unwrapped
 * (z, r, r*theta) coordinates integrated over the radius of its centroid (trapezoids; the
 * first and last sections lie on the hub and the shroud in both data sets).
 */
double passageVolume(const TemplateInputs& inputs, double pitch, double z0, double z1)
{
  const auto& hub = inputs.pointSets[0].curves[0].points;
  const auto& shroud = inputs.pointSets[1].curves[0].points;
  const int n = 20000;
  double annulus = 0.0;
  for (int k = 0; k <= n; ++k)
  {
    const double z = z0 + (z1 - z0) * k / n;
    const double rh = contourRadius(hub, z), rs = contourRadius(shroud, z);
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    annulus += w * (rs * rs - rh * rh);
  }
  annulus *= (z1 - z0) / n / 3.0 * pitch / 2.0;
  std::vector<double> areas, radii;
  for (const InputCurve& section : inputs.pointSets[2].curves)
  {
    const auto& p = section.points;
    const double theta0 = std::atan2(p[0].y(), p[0].x());
    std::vector<Vec3> unwrapped;
    Vec3 centre = Vec3::Zero();
    for (const Vec3& q : p)
    {
      const double r = std::hypot(q.x(), q.y());
      double theta = std::atan2(q.y(), q.x()) - theta0;
      theta = std::remainder(theta, 2.0 * Pi);
      unwrapped.emplace_back(q.z(), r, r * theta);
      centre += unwrapped.back() / static_cast<double>(p.size());
    }
    Vec3 area = Vec3::Zero();
    for (std::size_t k = 0; k + 1 < unwrapped.size(); ++k)
    {
      area += (unwrapped[k] - centre).cross(unwrapped[k + 1] - centre) / 2.0;
    }
    area += (unwrapped.back() - centre).cross(unwrapped.front() - centre) / 2.0;
    areas.push_back(area.norm());
    radii.push_back(centre.y());
  }
  double blade = 0.0;
  for (std::size_t k = 1; k < areas.size(); ++k)
  {
    blade += 0.5 * (areas[k] + areas[k - 1]) * (radii[k] - radii[k - 1]);
  }
  if (std::getenv("BLOCKFORGE_PASSAGE_DEBUG"))
    std::printf("annulus %.6e blade %.6e z %.5f %.5f\n", annulus, blade, z0, z1);
  return annulus - std::abs(blade);
}

struct Checked
{
  std::array<long long, 5> classes{};
  double minJacobian = 0.0;
  long long cells = 0;
  double volumeError = 0.0;
};

/// Checks every property of the issue on one template and data set.
Checked checkPassage(const std::string& templateName, const DataSet& data,
  const ParameterOverrides& overrides = {})
{
  Checked result;
  SCOPED_TRACE(templateName + " on " + data.name);
  const TemplateInputs inputs = readTemplateInputs(data.inf);
  const BlockModel model = loadTemplate(templatePath(templateName), overrides, &inputs);
  const double pitch = 2.0 * Pi / model.machine.bladeCount;
  const Grid grid = meshAll(model);
  const CarrierGeometry geometry(model);
  const double chord = test::chordOf(inputs);

  // patches
  std::set<std::string> names;
  for (const Patch& patch : model.patches)
    names.insert(patch.name);
  const std::set<std::string> expected = { "hub", "shroud", "blade", "inlet", "outlet",
    "periodic_low", "periodic_high" };
  EXPECT_EQ(names, expected);
  auto patchNodes = [&](const std::string& name) {
    std::vector<Vec3> nodes;
    for (const Patch& patch : model.patches)
      if (patch.name == name)
        for (const BlockFace& face : patch.faces)
        {
          const auto f = faceNodes(grid, face);
          nodes.insert(nodes.end(), f.begin(), f.end());
        }
    return nodes;
  };

  // hub, shroud and blade nodes on their surfaces
  for (const std::string surface : { "hub", "shroud", "blade" })
  {
    const int carrier = model.findCarrier(surface);
    EXPECT_GE(carrier, 0) << surface;
    if (carrier < 0)
      continue;
    const auto nodes = patchNodes(surface);
    EXPECT_FALSE(nodes.empty()) << surface;
    double worst = 0.0;
    for (const Vec3& p : nodes)
    {
      worst = std::max(worst, test::surfaceDistance(geometry, carrier, p));
    }
    EXPECT_LT(worst, 1e-6 * chord) << surface;
  }

  // periodic: low rotated by one pitch lands on a high node
  {
    const auto low = patchNodes("periodic_low"), high = patchNodes("periodic_high");
    EXPECT_EQ(low.size(), high.size());
    double worst = 0.0;
    for (const Vec3& p : low)
    {
      const double c = std::cos(pitch), s = std::sin(pitch);
      const Vec3 q(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z());
      double best = 1e300;
      for (const Vec3& h : high)
        best = std::min(best, (q - h).norm() / std::max(h.norm(), 1e-300));
      worst = std::max(worst, best);
    }
    EXPECT_LT(worst, 1e-9);
  }

  // quality: no inverted cell; MinAngle classes for the report
  std::vector<StructuredBlock> blocks;
  for (std::size_t b = 0; b < grid.nodes.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  const auto quality = computeGridQuality(blocks);
  result.minJacobian = 1e300;
  for (std::size_t b = 0; b < quality.size(); ++b)
  {
    const auto& q = quality[b];
    double blockMin = 1e300;
    for (double v : q.scaledJacobian)
      blockMin = std::min(blockMin, v);
    EXPECT_GT(blockMin, 0.0) << "block " << model.blocks[b].name;
    result.minJacobian = std::min(result.minJacobian, blockMin);
    result.cells += static_cast<long long>(q.scaledJacobian.size());
  }
  EXPECT_GT(result.minJacobian, 0.0);
  result.classes = minAngleClasses(quality);

  // volume against the independent passage volume, between the inlet and outlet planes
  // (their corners are placed on the hub and shroud at the plane's axial position, and the
  // edges and faces between them are straight lines / TFI, so the patches are planar)
  double z0 = 0.0, z1 = 0.0;
  const auto inletNodes = patchNodes("inlet"), outletNodes = patchNodes("outlet");
  for (const Vec3& p : inletNodes)
    z0 += p.z() / static_cast<double>(inletNodes.size());
  for (const Vec3& p : outletNodes)
    z1 += p.z() / static_cast<double>(outletNodes.size());
  for (const Vec3& p : inletNodes)
    EXPECT_NEAR(p.z(), z0, 1e-9 * chord) << "inlet is an axial plane";
  for (const Vec3& p : outletNodes)
    EXPECT_NEAR(p.z(), z1, 1e-9 * chord) << "outlet is an axial plane";
  const double expectedVolume = passageVolume(inputs, pitch, z0, z1);
  const double volume = gridVolume(grid);
  result.volumeError = volume / expectedVolume - 1.0;
  EXPECT_LT(std::abs(result.volumeError), 0.005)
    << "grid " << volume << " passage " << expectedVolume;

  // the same template and parameters: the same grid bit for bit
  const BlockModel again = loadTemplate(templatePath(templateName), overrides, &inputs);
  const Grid second = meshAll(again);
  EXPECT_EQ(second.xyz.size(), grid.xyz.size());
  if (second.xyz.size() != grid.xyz.size())
    return result;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    EXPECT_EQ(second.xyz[b].size(), grid.xyz[b].size());
    if (second.xyz[b].size() != grid.xyz[b].size())
      continue;
    EXPECT_EQ(std::memcmp(second.xyz[b].data(), grid.xyz[b].data(),
                grid.xyz[b].size() * sizeof(double)),
      0)
      << "block " << b;
  }
  return result;
}

double medianLoadSeconds(const std::string& templateName, const DataSet& data)
{
  const TemplateInputs inputs = readTemplateInputs(data.inf);
  std::vector<double> times;
  for (int run = 0; run < 5; ++run)
  {
    const auto start = std::chrono::steady_clock::now();
    const BlockModel model = loadTemplate(templatePath(templateName), {}, &inputs);
    times.push_back(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    EXPECT_FALSE(model.blocks.empty());
  }
  std::sort(times.begin(), times.end());
  return times[2];
}

void report(const std::string& templateName, const DataSet& data, const Checked& c)
{
  const double seconds = medianLoadSeconds(templateName, data);
  std::printf("FIGURES %s %s cells %lld MinAngle[0-20,20-40,40-60,60-80,80-90] %lld %lld %lld "
              "%lld %lld minScaledJacobian %.4f volumeError %.2e templateSeconds(median of 5) "
              "%.4f\n",
    templateName.c_str(), data.name.c_str(), c.cells, c.classes[0], c.classes[1], c.classes[2],
    c.classes[3], c.classes[4], c.minJacobian, c.volumeError, seconds);
}
} // namespace

TEST(PassageTemplates, AxialPassageHRotor37)
{
  report("axial_passage_h", dataSets()[0], checkPassage("axial_passage_h", dataSets()[0]));
}

TEST(PassageTemplates, AxialPassageHDistributor)
{
  report("axial_passage_h", dataSets()[1], checkPassage("axial_passage_h", dataSets()[1]));
}

TEST(PassageTemplates, AxialPassageOHRotor37)
{
  report("axial_passage_oh", dataSets()[0], checkPassage("axial_passage_oh", dataSets()[0]));
}

TEST(PassageTemplates, AxialPassageOHDistributor)
{
  report("axial_passage_oh", dataSets()[1], checkPassage("axial_passage_oh", dataSets()[1]));
}

// The carriers loadTemplate hands over (used by the BlockTemplate preview and, through the
// document cache, by BlockMesher) give the grid a fresh build of the carriers gives, bit for
// bit, and the model document read back gives it too.
TEST(PassageTemplates, HandedOverCarriersGiveTheSameGrid)
{
  const TemplateInputs inputs = readTemplateInputs(dataSets()[1].inf);
  CarrierGeometry carriers;
  const BlockModel model =
    loadTemplate(templatePath("axial_passage_oh"), {}, &inputs, &carriers);
  const BlockModel reread = readModelDocument(writeModelDocument(model));
  MultiBlockMesher handed(model, carriers, 1.0), fresh(reread, 1.0);
  handed.computeBoundaries();
  fresh.computeBoundaries();
  ASSERT_EQ(handed.blockCount(), fresh.blockCount());
  for (int b = 0; b < handed.blockCount(); ++b)
  {
    const auto n = handed.nodeCounts(b);
    ASSERT_EQ(n, fresh.nodeCounts(b));
    std::vector<double> a(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]), c(a.size());
    handed.meshBlock(b, a.data());
    fresh.meshBlock(b, c.data());
    EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0)
      << "block " << model.blocks[b].name;
  }
}

// Wide O-grid corners on the distributor's round leading edge: the leading-edge O block
// wraps 120 degrees of the nose, so the straight lines between its corners fold although
// its curved edges do not; the model check must let it through (by the edges' tangents),
// and the grid keeps every property.
TEST(PassageTemplates, AxialPassageOHWideCornersDistributor)
{
  const Checked c = checkPassage("axial_passage_oh", dataSets()[1], { { "o_corner", "60deg" } });
  EXPECT_GT(c.minJacobian, 0.0);
}

namespace
{
/// MinAngle classes and the smallest scaled Jacobian of a template applied to `inputs`.
std::pair<std::array<long long, 5>, double> qualityOf(
  const std::string& templateName, const TemplateInputs& inputs)
{
  const BlockModel model = loadTemplate(templatePath(templateName), {}, &inputs);
  const Grid grid = meshAll(model);
  std::vector<StructuredBlock> blocks;
  for (std::size_t b = 0; b < grid.nodes.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  const auto quality = computeGridQuality(blocks);
  double smallest = 1e300;
  for (const auto& q : quality)
    for (double v : q.scaledJacobian)
      smallest = std::min(smallest, v);
  return { minAngleClasses(quality), smallest };
}
} // namespace

// Wherever the export puts the blade around the axis (here the distributor turned so that
// its vane sits at theta = 180, -100 and 170 degrees, across the seam of the hub and shroud
// surfaces), both templates measure theta from the blade (machine: theta_zero) and give
// the same grid, turned.
TEST(PassageTemplates, AnyPlaceAroundTheAxis)
{
  const TemplateInputs original = readTemplateInputs(dataSets()[1].inf);
  for (const std::string name : { "axial_passage_h", "axial_passage_oh" })
  {
    const auto reference = qualityOf(name, original);
    for (const double degrees : { 180.0, -100.0, 170.0 })
    {
      SCOPED_TRACE(name + " turned by " + std::to_string(degrees));
      TemplateInputs turned = original;
      const double angle = degrees * Pi / 180.0;
      for (InputPointSet& set : turned.pointSets)
        for (InputCurve& curve : set.curves)
          for (Vec3& p : curve.points)
            p = Vec3(std::cos(angle) * p.x() - std::sin(angle) * p.y(),
              std::sin(angle) * p.x() + std::cos(angle) * p.y(), p.z());
      const auto quality = qualityOf(name, turned);
      EXPECT_NEAR(quality.second, reference.second, 1e-6);
      for (int c = 0; c < 5; ++c)
      {
        EXPECT_NEAR(quality.first[c], reference.first[c], 2) << "class " << c;
      }
    }
  }
}

// Short hub and shroud contours (the turbine row's end 10 % of a chord from the blade):
// the inlet and outlet go where the contours start and end, and the template says so;
// with `extend` the contours continue along their end tangents and the planes are where
// asked.
TEST(PassageTemplates, ShortContoursInletAndOutletAtTheirEndsOrExtended)
{
  const TemplateInputs inputs =
    readTemplateInputs(std::string(BLOCKFORGE_SOURCE_DIR) + "/Data/turbine/Info.txt");
  for (const std::string name : { "axial_passage_h", "axial_passage_oh" })
  {
    SCOPED_TRACE(name);
    const BlockModel model = loadTemplate(templatePath(name), {}, &inputs);
    ASSERT_EQ(model.notes.size(), 2u);
    EXPECT_NE(model.notes[0].find("the inlet is where the hub and shroud contours start"),
      std::string::npos)
      << model.notes[0];
    EXPECT_NE(model.notes[1].find("the outlet is where the hub and shroud contours end"),
      std::string::npos)
      << model.notes[1];
    // the inlet plane is a hair inside the contours' start (axis X, contours from
    // x = -0.0195219 m)
    const double inlet = model.vertices[model.findVertex("lo_in_h")].position.x();
    EXPECT_NEAR(inlet, -0.0195219, 1e-6);
    const BlockModel extended = loadTemplate(templatePath(name), { { "extend", "1" } }, &inputs);
    EXPECT_TRUE(extended.notes.empty());
    EXPECT_LT(extended.vertices[extended.findVertex("lo_in_h")].position.x(), -0.025);
    EXPECT_FALSE(test::meshAll(extended, 0.5).xyz.empty());
  }
  // Long contours: nothing to say.
  const TemplateInputs rotor = readTemplateInputs(dataSets()[0].inf);
  EXPECT_TRUE(loadTemplate(templatePath("axial_passage_oh"), {}, &rotor).notes.empty());
}

namespace
{
/// The angle (degrees) between the lines oa_f -> lo_f (across the passage from side a's
/// leading-edge O corner to the mid-passage point) and le -> mid-camber point (the blade
/// near its leading edge), in the unrolled (axial, r theta) plane of a layer (_h, _s).
double crossingAngleAtLeadingEdge(const BlockModel& model, const std::string& layer)
{
  auto position = [&](const std::string& name) {
    for (const auto& vertex : model.vertices)
      if (vertex.name == name + layer)
        return vertex.position;
    ADD_FAILURE() << "no vertex " << name + layer;
    return Vec3(0, 0, 0);
  };
  const Vec3 axis = model.machine.axis.normalized(), origin = model.machine.axisPoint;
  const Vec3 le = position("le");
  const Vec3 reference = (le - origin) - axis.dot(le - origin) * axis;
  const double rm = reference.norm();
  auto unrolled = [&](const Vec3& p) {
    const Vec3 radial = (p - origin) - axis.dot(p - origin) * axis;
    const double theta = std::atan2(axis.dot(reference.cross(radial)), reference.dot(radial));
    return Eigen::Vector2d(axis.dot(p - origin), rm * theta);
  };
  const Eigen::Vector2d chord =
    0.5 * (unrolled(position("fm")) + unrolled(position("bm"))) - unrolled(le);
  const Eigen::Vector2d crossing = unrolled(position("lo_f")) - unrolled(position("oa_f"));
  const double cosine = std::abs(chord.dot(crossing)) / (chord.norm() * crossing.norm());
  return std::acos(std::min(1.0, cosine)) * 180.0 / M_PI;
}
} // namespace

// Sheared O corners (o_shear): at Rotor 37's leading edge (stagger 62 degrees at the shroud,
// 48 at the hub) the line across the passage from side a's corner meets the blade at
// o_shear (45.0 degrees at hub and shroud when written) instead of
// about 90 - stagger: without the shear (o_shear 0) 36.8 at the hub, 24.4 at the shroud.
TEST(PassageTemplates, AxialPassageOHShearedCorners)
{
  const TemplateInputs inputs = readTemplateInputs(dataSets()[0].inf);
  const BlockModel sheared =
    loadTemplate(templatePath("axial_passage_oh"), { { "o_shear", "45deg" } }, &inputs);
  const BlockModel plain =
    loadTemplate(templatePath("axial_passage_oh"), { { "o_shear", "0" } }, &inputs);
  std::printf("SHEAR Rotor 37 leading edge: crossing at %.2f (hub) %.2f (shroud) deg, "
              "without the shear %.2f %.2f\n",
    crossingAngleAtLeadingEdge(sheared, "_h"), crossingAngleAtLeadingEdge(sheared, "_s"),
    crossingAngleAtLeadingEdge(plain, "_h"), crossingAngleAtLeadingEdge(plain, "_s"));
  EXPECT_NEAR(crossingAngleAtLeadingEdge(sheared, "_s"), 45.0, 0.5);
  EXPECT_NEAR(crossingAngleAtLeadingEdge(sheared, "_h"), 45.0, 0.5);
  EXPECT_LT(crossingAngleAtLeadingEdge(plain, "_s"), 30.0);
  EXPECT_GT(crossingAngleAtLeadingEdge(sheared, "_s"), crossingAngleAtLeadingEdge(plain, "_s") + 8.0);
}
