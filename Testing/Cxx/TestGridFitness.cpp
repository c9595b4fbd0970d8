// Grid fitness of every blade-passage template on every machine in Data/, at the density
// multipliers 0.5, 1, 2 and 4 (issue 8): no inverted cell, neighbour cells across every
// block interface within the size-ratio bound, hub, shroud and blade nodes on their
// surfaces within 1e-6 of the chord, periodic sides matching within 1e-9, the passage
// volume within 0.5 %. One CTest entry per machine (Testing/CMakeLists.txt), so two run at
// once. Prints one FITNESS line per case for the README's table.
#include "CarrierGeometry.h"
#include "InvertedCells.h"
#include "Mesher.h"
#include "Quality.h"
#include "Template.h"

#include "TestPassageGeometry.h"
#include "TestTurboInputs.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

using namespace blockforge;
using namespace blockforge::model;

namespace
{
using test::Grid;
using test::Pi;

/**
 * Largest neighbour cell size ratio across block interfaces accepted, per template (see
 * checkFitness). Issue 8 asks for about 1.5. axial_passage_h grades every edge with the
 * `match` law (end cells from the edges continuing it across interfaces); measured on the
 * four machines at densities 0.5-4: 1.11-1.48, but 1.76 on the distributor at density 4,
 * across the leading-edge plane between the upstream and blade blocks (the blade side
 * leaves the round leading edge across the pitch: the blade block's first cells there
 * are short along the axis once they are smaller than the edge's radius).
 * axial_passage_oh grades every O-grid arc and every H edge with `match` (the blade sides'
 * O arcs with `flat`: the law `ends`' shape between the matched end cells), the periodic
 * lines beside the sides `ends`, and the blade arcs of all four O blocks as the normal feet
 * of their outer arcs' nodes (`project_from`): at an O corner whose radial line starts on
 * a fan (a thin nose, a sharp tip, a cap's corner) the blade's first cells on both sides
 * of it are feet of the fan alike. Before (the sides graded `ends` on the blade, only the
 * edge block's cells feet of its fanning outer cells, whose width on the blade shrinks
 * with the square of the density) Rotor 37 reached 8.5-22.9, the distributor 3.5-4.2, the
 * turbine 3.3-3.7, the compressor 5.0-20.5; 28-570 before any grading. Measured now
 * (density 0.5-4, no optimizer, stop 14): Rotor 37 1.30-1.43 and the distributor 1.35-1.47
 * (U_L against M_L, M_L against D_L); the turbine 2.62-2.78 (D_L against D_M, where the O
 * arc leaves its corner oa_r nearly along the interface; stop 15 below), the compressor 1.66-1.89 (U_L
 * against U_M, D_M against D_R; its fans against the sides 1.34-1.39: stop 15 grades the
 * sides' feet up from the fan's wall cell, joinFeet's gradeBesideFan, where the feet on the
 * sharp tip widened to a 25th of the next cell gave 2.17-3.48). What brought Rotor 37 from 4.13: the blade faces'
 * guard holds their cells to the parameter grid's (O_te against O_b), the O-grid's outer
 * faces follow the blade faces (`follow: opposite`; O_a against M_L 2.47 -> 1.36). The
 * turbine's D_L against D_M went 3.14-3.53 -> 2.62-2.78 with `interpolation: end_cells` on
 * U_L, U_R, D_L, D_R (their interior lines keep their edges' end cells); at density 0.5
 * the template's min_cells keep the few cells the match laws need (the distributor's
 * upstream blocks were 2.54, the compressor's 3.73). Stop 15: the turbine 2.67 / 2.62 /
 * 2.73 / 2.78 -> 2.17 / 1.68 / 1.57 / 1.29 at densities 0.5 / 1 / 2 / 4: its capped
 * trailing edge is sheared (`shear_camber` 1 by default: the camber there is more
 * staggered than the blade near it), which opens the wake block's corners at oa_r/ob_r
 * (7 / 14.5 deg: D_L against D_M 2.6-2.8 -> 1.2), and U_M / D_M blend their lines from the
 * O-grid `adaptive` (in front of the round nose U_M's middle lines are half as long as its
 * sides: O_le against U_M 1.80-1.90 -> 1.27-1.29, O_te against D_M 1.66-1.80 -> 1.22-1.36);
 * left: O_a against O_te at the cap's corner (2.17 at density 0.5). Rotor 37 and the
 * distributor are the same grids. Stop 16, the turbine: 2.17 / 1.68 / 1.57 / 1.29 ->
 * 1.36 / 1.36 / 1.35 / 1.29: at side a's cap corner the O corner oa_r (the sheared edge's
 * partner) has its foot 0.06-0.09 mm before the corner at every density, so O_te's first
 * wall cell is that piece of flank; joinFeet's one cut of O_a's foot, held to half its next
 * cell, left 1.68 at density 1; where that cut stays above FanSideRatio the side's feet
 * are now graded up from the corner as beside a fan (rampFeet: O_a against O_te 1.36 /
 * 1.35 / 1.35 / under 1.2; the worst now O_te against D_M at density 1). Rotor 37, the
 * distributor and the compressor are the same grids. Stop 16, the compressor: at its sharp
 * trailing edge the wake block's outlet edge starts from cells at most its mean cell
 * (`at_most`: checkMesh's face tets by the outlet gone), and at both sharp edges the
 * mid-passage points leave the
 * middle of the line across the passage so that its squeezed corners come out about equal
 * (M_R at ob_f 2.1 -> 16.7 deg at the shroud; min scaled Jacobian 0.034 -> 0.156 at
 * density 2): 1.85 / 1.66 / 1.79 / 1.89 -> 1.85 / 1.69 / 1.84 / 1.93 (U_L against U_M,
 * D_M against D_R: U_M's and D_M's corners at the fans' O corners, 10-15 deg, whose O arc
 * leaves nearly along the H line, pinch their first column mid-way to the inlet / outlet,
 * where the linear blend of the inlet's and the O arc's first cells, pointing nearly
 * opposite ways along the interface, is shortest). Stop 16, issue 8: U_M and D_M
 * interpolate across `end_widths` (their first and last columns lifted to 0.8 of the blend
 * of their ends' widths where one comes out under 0.7 of it): 1.85 / 1.69 / 1.84 / 1.93 ->
 * 1.54 / 1.39 / 1.40 / 1.42 (bound 2.0 -> 1.6); a few of the turbine's U_M / D_M faces are
 * lifted a little (ratio the same); Rotor 37 and the distributor are the same grids. The bounds, per machine, fail when
 * the grading gets worse.
 */
double maxNeighbourRatio(const std::string& templateName, const std::string& machine)
{
  if (templateName == "axial_passage_h")
    return 1.5;
  static const std::map<std::string, double> oh = { { "rotor37", 1.5 }, { "distributor", 1.5 },
    { "turbine", 1.4 }, { "compressor", 1.6 } };
  return oh.at(machine);
}

struct Machine
{
  std::string name, file;
};

const std::vector<Machine>& machines()
{
  static const std::vector<Machine> list = {
    { "rotor37", test::sourcePath("Data/rotor37/turbogrid/BladeGen.inf") },
    { "distributor", test::sourcePath("Data/distributor/BladeGen.inf") },
    { "turbine", test::sourcePath("Data/turbine/Info.txt") },
    { "compressor", test::sourcePath("Data/compressor/rotor.inf") },
  };
  return list;
}

/// Cylindrical coordinates about the machine axis (through the origin).
struct Cylindrical
{
  Vec3 axis, e1, e2;
  explicit Cylindrical(const Vec3& a)
    : axis(a.normalized())
  {
    const Vec3 trial = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    e1 = (trial - trial.dot(axis) * axis).normalized();
    e2 = axis.cross(e1);
  }
  double axial(const Vec3& p) const { return p.dot(axis); }
  double radius(const Vec3& p) const { return (p - axial(p) * axis).norm(); }
  double theta(const Vec3& p) const { return std::atan2(p.dot(e2), p.dot(e1)); }
};

/// Radius of a meridional contour at an axial position (linear between its points,
/// constant beyond its ends).
double contourRadius(const std::vector<Vec3>& contour, const Cylindrical& c, double a)
{
  std::vector<std::pair<double, double>> ar;
  for (const Vec3& p : contour)
    ar.emplace_back(c.axial(p), c.radius(p));
  std::sort(ar.begin(), ar.end());
  if (a <= ar.front().first)
    return ar.front().second;
  for (std::size_t k = 1; k < ar.size(); ++k)
    if (a <= ar[k].first)
    {
      const double w = (a - ar[k - 1].first) / std::max(ar[k].first - ar[k - 1].first, 1e-300);
      return (1 - w) * ar[k - 1].second + w * ar[k].second;
    }
  return ar.back().second;
}

/// Width of a closed polygon of (axial, r theta) points along the line axial = a (the
/// even-odd sum of its crossings).
double widthAt(const std::vector<Eigen::Vector2d>& polygon, double a)
{
  std::vector<double> ys;
  for (std::size_t k = 0; k < polygon.size(); ++k)
  {
    const Eigen::Vector2d& p = polygon[k];
    const Eigen::Vector2d& q = polygon[(k + 1) % polygon.size()];
    if ((p.x() <= a) != (q.x() <= a))
    {
      ys.push_back(p.y() + (a - p.x()) / (q.x() - p.x()) * (q.y() - p.y()));
    }
  }
  std::sort(ys.begin(), ys.end());
  double width = 0.0;
  for (std::size_t k = 0; k + 1 < ys.size(); k += 2)
  {
    width += ys[k + 1] - ys[k];
  }
  return width;
}

/**
 * The passage volume between the axial planes a0 and a1 from the input point sets alone:
 * the annular sector (pitch / 2) * integral of (r_shroud^2 - r_hub^2) da (Simpson), minus
 * the blade: at every radius between the walls, the area of the blade section there (the
 * two nearest sections' unwrapped (axial, r theta) outlines, each cut to the axial range
 * where that radius lies between hub and shroud, blended linearly in the radius),
 * integrated over the radius. Sections reaching past the walls and walls that are not
 * cylinders at the blade are thus counted as the grid sees them.
 */
double passageVolume(const TemplateInputs& inputs, const Cylindrical& c, double pitch,
  double a0, double a1)
{
  const auto& hub = inputs.pointSets[0].curves[0].points;
  const auto& shroud = inputs.pointSets[1].curves[0].points;
  const int n = 20000;
  double annulus = 0.0;
  for (int k = 0; k <= n; ++k)
  {
    const double a = a0 + (a1 - a0) * k / n;
    const double rh = contourRadius(hub, c, a), rs = contourRadius(shroud, c, a);
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    annulus += w * (rs * rs - rh * rh);
  }
  annulus *= (a1 - a0) / n / 3.0 * pitch / 2.0;
  std::vector<std::vector<Eigen::Vector2d>> outlines;
  std::vector<double> radii;
  for (const InputCurve& section : inputs.pointSets[2].curves)
  {
    const auto& p = section.points;
    const double theta0 = c.theta(p[0]);
    double r = 0.0;
    std::vector<Eigen::Vector2d> outline;
    for (const Vec3& x : p)
    {
      const double rx = c.radius(x);
      outline.emplace_back(c.axial(x), rx * std::remainder(c.theta(x) - theta0, 2.0 * Pi));
      r += rx / p.size();
    }
    outlines.push_back(outline);
    radii.push_back(r);
  }
  auto cutArea = [&](const std::vector<Eigen::Vector2d>& outline, double r) {
    double low = 1e300, high = -1e300;
    for (const auto& q : outline)
    {
      low = std::min(low, q.x());
      high = std::max(high, q.x());
    }
    const int m = 400;
    double area = 0.0;
    for (int k = 0; k < m; ++k)
    {
      const double a = low + (high - low) * (k + 0.5) / m;
      if (contourRadius(hub, c, a) <= r && r <= contourRadius(shroud, c, a))
      {
        area += widthAt(outline, a) * (high - low) / m;
      }
    }
    return area;
  };
  double rLow = 1e300, rHigh = -1e300;
  for (const auto& outline : outlines)
    for (const auto& q : outline)
    {
      rLow = std::min(rLow, contourRadius(hub, c, q.x()));
      rHigh = std::max(rHigh, contourRadius(shroud, c, q.x()));
    }
  double blade = 0.0;
  const int steps = 300;
  for (int k = 0; k < steps; ++k)
  {
    const double r = rLow + (rHigh - rLow) * (k + 0.5) / steps;
    std::size_t upper = 1;
    while (upper + 1 < radii.size() && radii[upper] < r)
      ++upper;
    const double w = std::clamp((r - radii[upper - 1]) / (radii[upper] - radii[upper - 1]), 0.0, 1.0);
    blade += ((1 - w) * cutArea(outlines[upper - 1], r) + w * cutArea(outlines[upper], r)) *
      (rHigh - rLow) / steps;
  }
  return annulus - blade;
}

/// Inverted cells (the mesher's sign test), cell quality, its smallest scaled Jacobian.
struct Validity
{
  long long inverted = 0, cells = 0;
  double minJacobian = 1e300;
  std::vector<CellQualityArrays> quality;
};

Validity validity(const Grid& grid)
{
  Validity result;
  std::vector<StructuredBlock> blocks;
  for (std::size_t b = 0; b < grid.nodes.size(); ++b)
  {
    const auto& n = grid.nodes[b];
    result.inverted += findInvertedCells(grid.xyz[b].data(), n[0], n[1], n[2]).count;
    blocks.push_back({ grid.xyz[b].data(), n[0], n[1], n[2] });
  }
  result.quality = computeGridQuality(blocks);
  for (const auto& q : result.quality)
  {
    for (double v : q.scaledJacobian)
      result.minJacobian = std::min(result.minJacobian, v);
    result.cells += static_cast<long long>(q.scaledJacobian.size());
  }
  return result;
}

void checkFitness(const std::string& templateName, const Machine& machine)
{
  const TemplateInputs inputs = test::readTemplateInputs(machine.file);
  const auto start = std::chrono::steady_clock::now();
  const BlockModel model = loadTemplate(test::templatePath(templateName + ".yaml"), {}, &inputs);
  const double templateSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Cylindrical cyl(inputs.axis);
  const double pitch = 2.0 * Pi / model.machine.bladeCount;
  const double chord = test::chordOf(inputs);
  const CarrierGeometry geometry(model);
  for (double density : { 0.5, 1.0, 2.0, 4.0 })
  {
    SCOPED_TRACE(templateName + " on " + machine.name + " at density " + std::to_string(density));
    const Grid grid = test::meshAll(model, density);
    // no inverted cell
    const Validity valid = validity(grid);
    EXPECT_EQ(valid.inverted, 0);
    EXPECT_GT(valid.minJacobian, 0.0);
    const long long cells = valid.cells;
    const double minJacobian = valid.minJacobian;
    const auto classes = minAngleClasses(valid.quality);

    // patch nodes on their surfaces; periodic sides; inlet and outlet planes
    auto patchNodes = [&](const std::string& name) {
      std::vector<Vec3> nodes;
      for (const Patch& patch : model.patches)
        if (patch.name == name)
          for (const BlockFace& face : patch.faces)
          {
            const auto f = test::faceNodes(grid, face);
            nodes.insert(nodes.end(), f.begin(), f.end());
          }
      return nodes;
    };
    double offSurface = 0.0;
    for (const std::string surface : { "hub", "shroud", "blade" })
    {
      const int carrier = model.findCarrier(surface);
      ASSERT_GE(carrier, 0) << surface;
      const auto nodes = patchNodes(surface);
      ASSERT_FALSE(nodes.empty());
      for (std::size_t k = 0; k < nodes.size(); k += density > 2 ? 3 : 1)
      {
        offSurface = std::max(offSurface, test::surfaceDistance(geometry, carrier, nodes[k]) / chord);
      }
    }
    EXPECT_LT(offSurface, 1e-6);
    const auto low = patchNodes("periodic_low"), high = patchNodes("periodic_high");
    ASSERT_EQ(low.size(), high.size());
    const Eigen::AngleAxisd rotation(pitch, cyl.axis);
    double periodic = 0.0;
    for (std::size_t k = 0; k < low.size(); ++k)
    {
      // the faces are rotated copies: node k of one matches node k of the other
      periodic = std::max(periodic, (rotation * low[k] - high[k]).norm() / chord);
    }
    EXPECT_LT(periodic, 1e-9);
    double a0 = 0.0, a1 = 0.0;
    const auto inlet = patchNodes("inlet"), outlet = patchNodes("outlet");
    for (const Vec3& p : inlet)
      a0 += cyl.axial(p) / inlet.size();
    for (const Vec3& p : outlet)
      a1 += cyl.axial(p) / outlet.size();
    const double volumeError =
      test::gridVolume(grid) / passageVolume(inputs, cyl, pitch, a0, a1) - 1.0;
    EXPECT_LT(std::abs(volumeError), 0.005);

    // neighbour cells across block interfaces
    const test::NeighbourRatio jump =
      test::neighbourSizeRatio(grid, model, cyl.axis, pitch, chord);
    EXPECT_GT(jump.pairs, 0u);
    EXPECT_LE(jump.ratio, maxNeighbourRatio(templateName, machine.name)) << jump.where;

    const double expansion = test::maxExpansionInBlocks(grid);
    std::printf("FITNESS %s %s density %.1f cells %lld MinAngle %lld %lld %lld %lld %lld "
                "minScaledJacobian %.4f maxNeighbourRatio %.3f (%s) maxExpansion %.3f "
                "volumeError %.2e offSurface %.1e periodic %.1e templateSeconds %.3f\n",
      templateName.c_str(), machine.name.c_str(), density, cells, classes[0], classes[1],
      classes[2], classes[3], classes[4], minJacobian, jump.ratio, jump.where.c_str(),
      expansion, volumeError, offSurface, periodic, templateSeconds);
  }
}

class GridFitness : public ::testing::TestWithParam<int>
{
};
} // namespace

TEST_P(GridFitness, AxialPassageH)
{
  checkFitness("axial_passage_h", machines()[GetParam()]);
}

TEST_P(GridFitness, AxialPassageOH)
{
  checkFitness("axial_passage_oh", machines()[GetParam()]);
}

/**
 * Refining is what users do for a grid-convergence study (issue 8): axial_passage_h on the
 * two machines whose thin trailing edges folded it at density 8 (the spanwise
 * trailing-edge line cut across the edge between hub and shroud, so the blade face wrapped
 * round the edge past the trailing-edge plane; the blade is now aligned), at densities 6
 * and 8 (3.5 million cells): no inverted cell. A separate CTest entry (about 3.5 million
 * cells at once, a few seconds a density).
 */
TEST(GridFitnessHighDensity, AxialPassageH)
{
  for (int machine : { 0, 1 })
  {
    const auto& m = machines()[machine];
    const TemplateInputs inputs = test::readTemplateInputs(m.file);
    const BlockModel model = loadTemplate(test::templatePath("axial_passage_h.yaml"), {}, &inputs);
    for (double density : { 6.0, 8.0 })
    {
      SCOPED_TRACE(m.name + " at density " + std::to_string(density));
      const Validity valid = validity(test::meshAll(model, density));
      EXPECT_EQ(valid.inverted, 0);
      EXPECT_GT(valid.minJacobian, 0.0);
      std::printf("FITNESS axial_passage_h %s density %.1f cells %lld minScaledJacobian %.4f\n",
        m.name.c_str(), density, valid.cells, valid.minJacobian);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Machines, GridFitness, ::testing::Range(0, 4),
  [](const ::testing::TestParamInfo<int>& info) { return machines()[info.param].name; });
