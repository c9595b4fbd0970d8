// Unit tests of the point-set reader (Filters/IO, no VTK): the two real NASA Rotor 37
// exports in Data/rotor37, the variations other exports have, and the error messages.
#include "TurboPointSets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using blockforge::io::canReadTurboPointSets;
using blockforge::io::parseAxis;
using blockforge::io::PointSet;
using blockforge::io::ReadError;
using blockforge::io::ReadOptions;
using blockforge::io::readPointFile;
using blockforge::io::readTurboPointSets;
using blockforge::io::TurboPointSets;
using blockforge::io::unitScale;

namespace
{
const fs::path dataDir = fs::path(BLOCKFORGE_SOURCE_DIR) / "Data" / "rotor37";
const fs::path datDir = dataDir / "dat";
const fs::path turboGridDir = dataDir / "turbogrid";

/// A fresh folder per test, removed afterwards.
class TempDir : public ::testing::Test
{
protected:
  void SetUp() override
  {
    static std::atomic<int> counter{ 0 };
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    this->Dir = fs::temp_directory_path() /
      ("blockforge-tps-" + std::to_string(stamp) + "-" + std::to_string(counter++));
    fs::create_directories(this->Dir);
  }
  void TearDown() override
  {
    std::error_code ignored;
    fs::remove_all(this->Dir, ignored);
  }

public:
  /// Writes `text` to the file `name` of the folder (public: helpers take the fixture).
  std::string write(const std::string& name, const std::string& text)
  {
    const fs::path path = this->Dir / name;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  fs::path Dir;
};

/// Runs @p body, which must throw a ReadError; returns it.
template <typename Body>
ReadError expectReadError(Body body)
{
  try
  {
    body();
  }
  catch (const ReadError& error)
  {
    return error;
  }
  ADD_FAILURE() << "no ReadError thrown";
  return ReadError("", 0, "");
}

bool contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

double axial(const Eigen::Vector3d& point, const TurboPointSets& sets)
{
  return point.dot(sets.axis) * sets.scale;
}

double radius(const Eigen::Vector3d& point, const TurboPointSets& sets)
{
  return (point - point.dot(sets.axis) * sets.axis).norm() * sets.scale;
}

/// Radius of a meridional contour at an axial position, by linear interpolation between
/// the samples (which the exports give in increasing axial order).
double radiusAt(const PointSet& contour, const TurboPointSets& sets, double z)
{
  const auto& p = contour.points;
  for (std::size_t i = 0; i + 1 < p.size(); ++i)
  {
    const double z0 = axial(p[i], sets);
    const double z1 = axial(p[i + 1], sets);
    if (z0 <= z && z <= z1 && z1 > z0)
    {
      const double t = (z - z0) / (z1 - z0);
      return (1 - t) * radius(p[i], sets) + t * radius(p[i + 1], sets);
    }
  }
  ADD_FAILURE() << "axial position " << z << " outside the contour";
  return 0.0;
}

void expectRotor37Dat(const TurboPointSets& sets)
{
  EXPECT_EQ(sets.bladeCount, 36);
  EXPECT_EQ(sets.axisName, "X");
  EXPECT_TRUE(sets.axis.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_EQ(sets.units, "CM");
  EXPECT_DOUBLE_EQ(sets.scale, 0.01);
  EXPECT_EQ(fs::path(sets.descriptionFile).filename(), "Info.txt");
  EXPECT_EQ(sets.keys.at("No of blades"), "36");
  EXPECT_EQ(sets.keys.at("RPM"), "17189");

  ASSERT_EQ(sets.hub.points.size(), 30u);
  ASSERT_EQ(sets.shroud.points.size(), 30u);
  EXPECT_EQ(fs::path(sets.hub.file).filename(), "hub_R37.dat");
  EXPECT_EQ(fs::path(sets.shroud.file).filename(), "shroud_R37.dat");
  EXPECT_EQ(sets.hub.points.front(), Eigen::Vector3d(-4.19, 0, 17.52590003));
  EXPECT_EQ(sets.hub.points.back(), Eigen::Vector3d(10.67, 0, 19.31559995));
  EXPECT_EQ(sets.shroud.points.front(), Eigen::Vector3d(-4.19, 0, 25.66310001));

  ASSERT_EQ(sets.profiles.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k)
  {
    const auto& section = sets.profiles[k];
    EXPECT_EQ(section.points.size(), 301u) << section.name;
    EXPECT_EQ(section.number, static_cast<int>(k) + 1);
    EXPECT_TRUE(section.spanGiven);
    EXPECT_DOUBLE_EQ(section.spanPercent, 20.0 * k);
    EXPECT_EQ(section.firstLine, 1 + 302 * static_cast<int>(k));
    // Closed loops.
    EXPECT_LT((section.points.front() - section.points.back()).norm(), 1e-6) << section.name;
  }
  EXPECT_EQ(sets.profiles[0].name, "Profile 1 (0%)");
  EXPECT_EQ(sets.profiles[5].name, "Profile 6 (100%)");
  EXPECT_EQ(sets.profiles[0].points.front(), Eigen::Vector3d(0.030697324, -2.09768896, 17.6667508));
  // The file ends without a line end, inside a row that ends with a tab.
  EXPECT_EQ(sets.profiles[5].points.back(), Eigen::Vector3d(0.639089285, -2.51258719, 25.1066809));
  EXPECT_TRUE(sets.warnings.empty());
}
} // namespace

//------------------------------------------------------------------------------------------
// The real data sets

TEST(TurboPointSetsRotor37, DatSetOpenedByItsProfileFile)
{
  expectRotor37Dat(readTurboPointSets((datDir / "profile_R37.dat").string()));
}

TEST(TurboPointSetsRotor37, DatSetOpenedByInfoTxt)
{
  expectRotor37Dat(readTurboPointSets((datDir / "Info.txt").string()));
}

TEST(TurboPointSetsRotor37, DatSetOpenedByItsHubFile)
{
  expectRotor37Dat(readTurboPointSets((datDir / "hub_R37.dat").string()));
}

TEST(TurboPointSetsRotor37, DatSetIgnoresFallbackOptionsTheFilesOverride)
{
  ReadOptions options;
  options.bladeCount = 7;
  options.axis = "Y";
  options.units = "IN";
  expectRotor37Dat(readTurboPointSets((datDir / "Info.txt").string(), options));
}

TEST(TurboPointSetsRotor37, TurboGridSet)
{
  std::vector<double> fractions;
  const TurboPointSets sets = readTurboPointSets(
    (turboGridDir / "BladeGen.inf").string(), {}, [&](double f) { fractions.push_back(f); });
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);

  EXPECT_EQ(sets.bladeCount, 36);
  EXPECT_EQ(sets.bladesPerSet, 1);
  EXPECT_EQ(sets.axisName, "Z");
  EXPECT_TRUE(sets.axis.isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_EQ(sets.units, "CM");
  EXPECT_DOUBLE_EQ(sets.scale, 0.01);
  EXPECT_EQ(sets.keys.at("Number of Blade Sets"), "36");
  EXPECT_EQ(sets.hub.points.size(), 211u);
  EXPECT_EQ(sets.shroud.points.size(), 209u);
  EXPECT_EQ(sets.hub.points.front(), Eigen::Vector3d(17.4036479, -2.06644903, -4.19));
  ASSERT_EQ(sets.profiles.size(), 6u);
  const double spans[] = { 0, 20, 40, 60, 80, 100 };
  for (std::size_t k = 0; k < 6; ++k)
  {
    EXPECT_EQ(sets.profiles[k].points.size(), 301u);
    EXPECT_DOUBLE_EQ(sets.profiles[k].spanPercent, spans[k]);
    EXPECT_EQ(sets.profiles[k].firstLine, 1 + 303 * static_cast<int>(k));
  }
  EXPECT_EQ(sets.profiles[2].name, "Profile 3 (40%)");
  EXPECT_TRUE(sets.warnings.empty());
}

TEST(TurboPointSetsRotor37, OpeningAMemberOfTheTurboGridSetReadsTheWholeSet)
{
  const TurboPointSets sets = readTurboPointSets((turboGridDir / "shroud.curve").string());
  EXPECT_EQ(fs::path(sets.descriptionFile).filename(), "BladeGen.inf");
  EXPECT_EQ(sets.hub.points.size(), 211u);
  EXPECT_EQ(sets.shroud.points.size(), 209u);
  EXPECT_EQ(sets.profiles.size(), 6u);
  EXPECT_EQ(sets.axisName, "Z");
}

// Both layouts describe the same rotor, with the axis on X in one and on Z in the other:
// in (axial, radius) coordinates they must agree.
TEST(TurboPointSetsRotor37, BothLayoutsDescribeTheSameRotor)
{
  const TurboPointSets dat = readTurboPointSets((datDir / "Info.txt").string());
  const TurboPointSets tg = readTurboPointSets((turboGridDir / "BladeGen.inf").string());

  // Blade sections: the same points, digit for digit up to the printed precision.
  ASSERT_EQ(dat.profiles.size(), tg.profiles.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < dat.profiles.size(); ++k)
  {
    ASSERT_EQ(dat.profiles[k].points.size(), tg.profiles[k].points.size());
    for (std::size_t i = 0; i < dat.profiles[k].points.size(); ++i)
    {
      const auto& a = dat.profiles[k].points[i];
      const auto& b = tg.profiles[k].points[i];
      worst = std::max(worst, std::abs(axial(a, dat) - axial(b, tg)));
      worst = std::max(worst, std::abs(radius(a, dat) - radius(b, tg)));
    }
  }
  EXPECT_LT(worst, 1e-8); // metres

  // Meridional contours: the .dat set samples them at 30 points as (x, 0, r); the TurboGrid
  // export at ~210 points, off the meridional plane. Same axial extent, same radius.
  for (const auto* parts : { &dat.hub, &dat.shroud })
  {
    const PointSet& coarse = *parts;
    const PointSet& fine = parts == &dat.hub ? tg.hub : tg.shroud;
    EXPECT_NEAR(axial(coarse.points.front(), dat), axial(fine.points.front(), tg), 1e-9);
    EXPECT_NEAR(axial(coarse.points.back(), dat), axial(fine.points.back(), tg), 1e-9);
    EXPECT_NEAR(axial(coarse.points.front(), dat), -0.0419, 1e-9);
    EXPECT_NEAR(axial(coarse.points.back(), dat), 0.1067, 1e-9);
    double deviation = 0.0;
    for (const auto& point : coarse.points)
    {
      deviation = std::max(
        deviation, std::abs(radius(point, dat) - radiusAt(fine, tg, axial(point, dat))));
    }
    // Measured: 6.2e-6 m on the hub, 3.4e-6 m on the shroud (the dense export is not
    // exactly the polyline through the coarse samples).
    EXPECT_LT(deviation, 1e-5) << coarse.name;
  }
  EXPECT_NEAR(radius(dat.hub.points.front(), dat), 0.1752590003, 1e-12);
  EXPECT_NEAR(radius(tg.hub.points.front(), tg), 0.1752590003, 1e-8);
}

TEST(TurboPointSetsRotor37, CanReadFile)
{
  EXPECT_TRUE(canReadTurboPointSets((turboGridDir / "BladeGen.inf").string()));
  EXPECT_TRUE(canReadTurboPointSets((turboGridDir / "profile.curve").string()));
  EXPECT_TRUE(canReadTurboPointSets((turboGridDir / "hub.curve").string()));
  EXPECT_TRUE(canReadTurboPointSets((datDir / "profile_R37.dat").string()));
  EXPECT_TRUE(canReadTurboPointSets((datDir / "hub_R37.dat").string()));
  EXPECT_TRUE(canReadTurboPointSets((datDir / "Info.txt").string()));
  EXPECT_FALSE(canReadTurboPointSets((datDir / "README.md").string()));
  EXPECT_FALSE(canReadTurboPointSets((datDir / "missing.dat").string()));
  EXPECT_FALSE(canReadTurboPointSets(""));
}

//------------------------------------------------------------------------------------------
// Variations of other exports

using TurboPointSetsVariations = TempDir;

TEST_F(TurboPointSetsVariations, InfWithCommentsExtraKeysSpacesLowerCaseUnitsRelativePaths)
{
  write("curves/Hub Contour.crv", "! hub\n0 0 1\n1 0 1\n2 0 1.1\n3 0 1.2\n");
  write("curves/shroud.crv", "0 0 2\n1 0 2\n2 0 2.1\n3 0 2.2\n");
  write("curves/profile.crv",
    "## Main Blade\n"
    "# Profile 1 at 0.0000%\n"
    "0.5 0 1.0\n1 0.1 1.0\n1.5 0 1.0\n1 -0.1 1.0\n"
    "\n"
    "# Profile 2 at 100.0%\n"
    "0.5 0 2.0\n1 0.1 2.0\n1.5 0 2.0\n1 -0.1 2.0\n");
  const std::string inf = write("export/BladeGen.inf",
    "!======  CFX-BladeGen Export  ========\n"
    "! written by hand\n"
    "Axis of Rotation:    x\n"
    "Number of Blade Sets:  17\n"
    "Number of Blades Per Set: 2\n"
    "Coordinate System Orientation: RightHanded\n"
    "Blade Loft Direction: Spanwise\n"
    "Geometry Units:   mm\n"
    "Hub Data File:  ../curves/Hub Contour.crv\n"
    "Shroud Data File: ../curves/shroud.crv\n"
    "Profile Data File: \"../curves/profile.crv\"\n");
  const TurboPointSets sets = readTurboPointSets(inf);
  EXPECT_EQ(sets.bladeCount, 17);
  EXPECT_EQ(sets.bladesPerSet, 2);
  EXPECT_EQ(sets.axisName, "X");
  EXPECT_EQ(sets.units, "MM");
  EXPECT_DOUBLE_EQ(sets.scale, 0.001);
  EXPECT_EQ(sets.keys.at("Coordinate System Orientation"), "RightHanded");
  EXPECT_EQ(sets.keys.at("Blade Loft Direction"), "Spanwise");
  EXPECT_EQ(sets.hub.points.size(), 4u);
  EXPECT_EQ(sets.hub.firstLine, 2);
  EXPECT_EQ(sets.shroud.points.size(), 4u);
  ASSERT_EQ(sets.profiles.size(), 2u);
  EXPECT_EQ(sets.profiles[0].blade, "Main Blade");
  EXPECT_EQ(sets.profiles[1].blade, "Main Blade");
  EXPECT_EQ(sets.profiles[1].name, "Profile 2 (100%)");
  EXPECT_EQ(sets.profiles[1].firstLine, 8);
  EXPECT_EQ(sets.profiles[1].points[1], Eigen::Vector3d(1, 0.1, 2.0));
}

TEST_F(TurboPointSetsVariations, UnitWordsInAnyCase)
{
  write("hub.curve", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const std::pair<const char*, double> cases[] = { { "M", 1.0 }, { "m", 1.0 }, { "Cm", 0.01 },
    { "MM", 0.001 }, { "in", 0.0254 }, { "IN", 0.0254 }, { "Ft", 0.3048 }, { "feet", 0.3048 },
    { "Millimetres", 0.001 } };
  for (const auto& unit : cases)
  {
    const std::string inf = write("a.inf",
      std::string("Axis of Rotation: Z\nGeometry Units: ") + unit.first +
        "\nHub Data File: hub.curve\n");
    const TurboPointSets sets = readTurboPointSets(inf);
    EXPECT_DOUBLE_EQ(sets.scale, unit.second) << unit.first;
  }
  double scale = 0;
  std::string name;
  EXPECT_TRUE(unitScale(" ft ", scale, name));
  EXPECT_EQ(name, "FT");
  EXPECT_FALSE(unitScale("furlong", scale, name));
  EXPECT_FALSE(unitScale("", scale, name));
}

TEST_F(TurboPointSetsVariations, AxisForms)
{
  Eigen::Vector3d axis;
  std::string name;
  ASSERT_TRUE(parseAxis("z", axis, name));
  EXPECT_EQ(name, "Z");
  ASSERT_TRUE(parseAxis("-Y", axis, name));
  EXPECT_EQ(name, "-Y");
  EXPECT_EQ(axis, Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(parseAxis("X-axis", axis, name));
  EXPECT_EQ(name, "X");
  ASSERT_TRUE(parseAxis("(0, 0, 2)", axis, name));
  EXPECT_EQ(axis, Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(parseAxis("W", axis, name));
  EXPECT_FALSE(parseAxis("0 0 0", axis, name));
}

TEST_F(TurboPointSetsVariations, WindowsPathsAndFileNameCase)
{
  write("Hub.CURVE", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  write("profile.curve", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const std::string inf = write("BladeGen.inf",
    "Hub Data File: C:\\Users\\someone\\Export\\hub.curve\r\n"
    "Profile Data File: .\\profile.curve\r\n"
    "Geometry Units: M\r\n");
  const TurboPointSets sets = readTurboPointSets(inf);
  EXPECT_EQ(fs::path(sets.hub.file).filename(), "Hub.CURVE");
  EXPECT_EQ(sets.profiles.size(), 1u);
  EXPECT_EQ(sets.bladeCount, 0);
  // An unknown blade count is no warning (0 says it), nor is the span of a lone section;
  // a part missing from the .inf is.
  ASSERT_EQ(sets.warnings.size(), 1u);
  EXPECT_TRUE(contains(sets.warnings[0], "names no shroud file")) << sets.warnings[0];
}

TEST_F(TurboPointSetsVariations, CsvWithColumnNamesAndOptions)
{
  const std::string csv = write("points.csv",
    "x,y,z\r\n1.0,2.0,3.0\r\n+1.5, 2.5e0, 3.5D0\r\n2;3;4\r\n 2.5\t3.5\t4.5 \r\n");
  ReadOptions options;
  options.bladeCount = 12;
  options.axis = "y";
  options.units = "in";
  const TurboPointSets sets = readTurboPointSets(csv, options);
  EXPECT_EQ(sets.bladeCount, 12);
  EXPECT_EQ(sets.axisName, "Y");
  EXPECT_EQ(sets.units, "IN");
  EXPECT_DOUBLE_EQ(sets.scale, 0.0254);
  EXPECT_TRUE(sets.descriptionFile.empty());
  EXPECT_TRUE(sets.hub.points.empty());
  ASSERT_EQ(sets.profiles.size(), 1u);
  ASSERT_EQ(sets.profiles[0].points.size(), 4u);
  EXPECT_EQ(sets.profiles[0].firstLine, 2);
  EXPECT_EQ(sets.profiles[0].points[1], Eigen::Vector3d(1.5, 2.5, 3.5));
  EXPECT_EQ(sets.profiles[0].points[3], Eigen::Vector3d(2.5, 3.5, 4.5));
}

TEST_F(TurboPointSetsVariations, BlankLinesSeparateSectionsWithoutHeaders)
{
  const std::string file = write("blade.dat",
    "0 0 1\n1 0 1\n2 0 1\n3 0 1\n\n\n0 0 2\n1 0 2\n2 0 2\n3 0 2\n\n0 0 3\n1 0 3\n2 0 3\n3 0 3\n");
  const TurboPointSets sets = readTurboPointSets(file);
  ASSERT_EQ(sets.profiles.size(), 3u);
  EXPECT_FALSE(sets.profiles[1].spanGiven);
  EXPECT_DOUBLE_EQ(sets.profiles[1].spanPercent, 50.0);
  EXPECT_EQ(sets.profiles[2].firstLine, 12);
  EXPECT_EQ(sets.profiles[2].name, "Profile 3 (100%)");
  EXPECT_EQ(sets.warnings.size(), 1u);
}

TEST_F(TurboPointSetsVariations, ByteOrderMarkLoneCarriageReturnsAndBareHashes)
{
  const std::string file = write("profile.crv",
    "\xEF\xBB\xBF##\r#\r# Profile 7 at 12.5 %\r0 0 1\r1 0 1\r2 0 1\r3 0 1\r"
    "#\tPROFILE\t8\r0 0 2\r1 0 2\r2 0 2\r3 0 2");
  const auto sections = readPointFile(file, true);
  ASSERT_EQ(sections.size(), 2u);
  EXPECT_EQ(sections[0].name, "Profile 7 (12.5%)");
  EXPECT_EQ(sections[0].firstLine, 3);
  EXPECT_EQ(sections[0].blade, "");
  EXPECT_EQ(sections[1].number, 8);
  EXPECT_FALSE(sections[1].spanGiven);
  EXPECT_EQ(sections[1].firstLine, 8);
  EXPECT_EQ(sections[1].points.back(), Eigen::Vector3d(3, 0, 2));
}

TEST_F(TurboPointSetsVariations, SeveralBladesNamedByDoubleHash)
{
  const std::string file = write("profile.curve",
    "## Main\n# Profile 1 at 0%\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n"
    "# Profile 2 at 100%\n0 0 2\n1 0 2\n2 0 2\n3 0 2\n"
    "## Splitter\n# Profile 1 at 0%\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const auto sections = readPointFile(file, true);
  ASSERT_EQ(sections.size(), 3u);
  EXPECT_EQ(sections[1].name, "Main: Profile 2 (100%)");
  EXPECT_EQ(sections[2].name, "Splitter: Profile 1 (0%)");
  EXPECT_EQ(sections[2].blade, "Splitter");
}

TEST_F(TurboPointSetsVariations, SiblingsOfTheSameSetArePaired)
{
  const std::string rows = "0 0 1\n1 0 1\n2 0 1\n3 0 1\n";
  write("hub_A.dat", rows);
  write("hub_B.dat", rows + "4 0 1\n5 0 1\n6 0 1\n7 0 1\n");
  write("shroud_B.dat", rows);
  const std::string profile = write("profile_B.dat", rows);
  write("Info.txt", "No of blades : 9\nAxis of rotation : -z\nCoordinates unit : FT\n");
  const TurboPointSets sets = readTurboPointSets(profile);
  EXPECT_EQ(fs::path(sets.hub.file).filename(), "hub_B.dat");
  EXPECT_EQ(sets.hub.points.size(), 8u);
  EXPECT_EQ(fs::path(sets.shroud.file).filename(), "shroud_B.dat");
  EXPECT_EQ(sets.bladeCount, 9);
  EXPECT_EQ(sets.axisName, "-Z");
  EXPECT_EQ(sets.units, "FT");

  // Opened by Info.txt, two hub files are ambiguous: a clear error, not a guess.
  const ReadError error =
    expectReadError([&] { readTurboPointSets((this->Dir / "Info.txt").string()); });
  EXPECT_TRUE(contains(error.what(), "several hub files")) << error.what();
  EXPECT_TRUE(contains(error.what(), "hub_A.dat, hub_B.dat")) << error.what();

  // ... which explicit files resolve (relative to the main file's folder).
  ReadOptions options;
  options.hubFile = "hub_A.dat";
  const TurboPointSets chosen = readTurboPointSets((this->Dir / "Info.txt").string(), options);
  EXPECT_EQ(chosen.hub.points.size(), 4u);
  EXPECT_EQ(chosen.profiles.size(), 1u);
}

TEST_F(TurboPointSetsVariations, CanReadRejectsOtherFormats)
{
  EXPECT_FALSE(canReadTurboPointSets(write("tecplot.dat",
    "TITLE = \"flow\"\nVARIABLES = \"X\", \"Y\", \"Z\", \"P\"\nZONE I=2\n1 2 3 4\n5 6 7 8\n")));
  EXPECT_FALSE(canReadTurboPointSets(write("four.dat", "1 2 3 4\n5 6 7 8\n")));
  EXPECT_FALSE(canReadTurboPointSets(write("setup.inf", "[Version]\nSignature=$CHICAGO$\n")));
  EXPECT_FALSE(canReadTurboPointSets(write("empty.dat", "")));
  EXPECT_TRUE(canReadTurboPointSets(write("ok.crv", "x y z\n1 2 3\n")));
}

//------------------------------------------------------------------------------------------
// Errors: clear messages naming file and line

using TurboPointSetsErrors = TempDir;

TEST_F(TurboPointSetsErrors, MalformedRow)
{
  const std::string file =
    write("profile.curve", "# Profile 1 at 0%\n0 0 1\n1 0 1\n2 0\n3 0 1\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(file); });
  EXPECT_EQ(error.file(), file);
  EXPECT_EQ(error.line(), 4);
  EXPECT_EQ(std::string(error.what()).rfind(file + ":4: ", 0), 0u) << error.what();
  EXPECT_TRUE(contains(error.what(), "expected 3 numbers (X Y Z), found 2 fields in '2 0'"))
    << error.what();
}

TEST_F(TurboPointSetsErrors, WordInARow)
{
  const std::string file = write("hub.dat", "0 0 1\r\n1 0 1\r\n2 zero 1\r\n3 0 1\r\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(file); });
  EXPECT_EQ(error.line(), 3);
  EXPECT_TRUE(contains(error.what(), "'zero' is not a number")) << error.what();
}

TEST_F(TurboPointSetsErrors, NaN)
{
  const std::string file = write("hub.dat", "0 0 1\n1 0 1\n2 0 1\n3 NaN 1\n4 0 1\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(file); });
  EXPECT_EQ(error.line(), 4);
  EXPECT_TRUE(contains(error.what(), file + ":4: 'NaN' is not a finite number")) << error.what();
  const std::string infinite = write("shroud.dat", "0 0 1\n1 0 inf\n2 0 1\n3 0 1\n");
  EXPECT_EQ(expectReadError([&] { readPointFile(infinite, false); }).line(), 2);
}

TEST_F(TurboPointSetsErrors, SectionWithThreePoints)
{
  const std::string file = write("profile.curve",
    "# Profile 1 at 0%\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n\n# Profile 2 at 50%\n0 0 2\n1 0 2\n2 0 2\n"
    "# Profile 3 at 100%\n0 0 3\n1 0 3\n2 0 3\n3 0 3\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(file); });
  EXPECT_EQ(error.line(), 7);
  EXPECT_TRUE(contains(error.what(), "section 'Profile 2 (50%)' has 3 points; at least 4"))
    << error.what();
  const std::string hub = write("hub.dat", "0 0 1\n1 0 1\n2 0 1\n");
  EXPECT_TRUE(contains(expectReadError([&] { readPointFile(hub, false); }).what(), "3 points"));
}

TEST_F(TurboPointSetsErrors, UnknownUnit)
{
  write("hub.curve", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const std::string inf = write("BladeGen.inf",
    "Axis of Rotation: Z\nNumber of Blade Sets: 3\nGeometry Units: furlong\n"
    "Hub Data File: hub.curve\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(inf); });
  EXPECT_EQ(error.file(), inf);
  EXPECT_EQ(error.line(), 3);
  EXPECT_TRUE(contains(error.what(), "unknown unit 'furlong' (expected M, CM, MM, IN or FT)"))
    << error.what();

  // The fallback unit, when the files give none, is checked as well.
  ReadOptions options;
  options.units = "furlong";
  const std::string plain = write("plain.csv", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const ReadError fallback = expectReadError([&] { readTurboPointSets(plain, options); });
  EXPECT_TRUE(contains(fallback.what(), "'furlong'")) << fallback.what();
}

TEST_F(TurboPointSetsErrors, MissingFileNamedInTheInf)
{
  write("hub.curve", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const std::string inf = write("BladeGen.inf",
    "! export\nHub Data File: hub.curve\nShroud Data File: casing.curve\n");
  const ReadError error = expectReadError([&] { readTurboPointSets(inf); });
  EXPECT_EQ(error.file(), inf);
  EXPECT_EQ(error.line(), 3);
  EXPECT_TRUE(contains(error.what(), "Shroud Data File 'casing.curve' not found")) << error.what();
}

TEST_F(TurboPointSetsErrors, BadValuesInTheDescription)
{
  write("hub.curve", "0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const std::string axis = write("a.inf", "Hub Data File: hub.curve\nAxis of Rotation: W\n");
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(axis); }).what(),
    "a.inf:2: unknown axis 'W'"));
  const std::string blades =
    write("b.inf", "Number of Blade Sets: many\nHub Data File: hub.curve\n");
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(blades); }).what(),
    "b.inf:1: blade count 'many' is not a positive whole number"));
  const std::string noColon = write("c.inf", "Hub Data File: hub.curve\nGeometry Units CM\n");
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(noColon); }).what(),
    "c.inf:2: expected 'Key: value'"));
}

TEST_F(TurboPointSetsErrors, OtherProblems)
{
  EXPECT_TRUE(contains(
    expectReadError([&] { readTurboPointSets((this->Dir / "nothing.inf").string()); }).what(),
    "no such file"));
  const std::string empty = write("empty.dat", "! nothing here\n\n");
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(empty); }).what(), "no points"));
  const std::string header = write("hub.crv", "# Profile 1 at 0%\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  const ReadError inHub = expectReadError([&] { readPointFile(header, false); });
  EXPECT_EQ(inHub.line(), 1);
  const std::string badSpan = write("p.crv", "# Profile 1 at half%\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n");
  EXPECT_TRUE(contains(expectReadError([&] { readPointFile(badSpan, true); }).what(),
    "p.crv:1: malformed section header"));
  const std::string noFiles = write("notes.inf", "Axis of Rotation: Z\n");
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(noFiles); }).what(),
    "no point files"));
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets(""); }).what(), "no point files"));
  ReadOptions options;
  options.profileFile = (this->Dir / "absent.crv").string();
  EXPECT_TRUE(contains(expectReadError([&] { readTurboPointSets("", options); }).what(),
    "cannot open the profile file"));
}

//------------------------------------------------------------------------------------------
// What real exports do: other section headers, open sections, sections out of span order,
// kinked rows

namespace
{
using blockforge::io::Closure;
using blockforge::io::EdgeCap;

class TurboPointSetsRepairs : public TempDir
{
};

constexpr double Pi = 3.14159265358979323846;

/// Rows "x y z" of a blade section about the z axis at radius r: an ellipse of chord 1
/// and thickness `thickness` in the (axial z, r theta) plane centred at z = 0, from the
/// trailing edge (z = 0.5) over the suction side, round the leading edge and back, left
/// open at the trailing edge by `gap` (0: the first row repeated at the end). Rows
/// `reverseFrom` .. `reverseFrom + reverseCount - 1` are written in reverse order.
std::string sectionRows(double r, double thickness, double gap, int n = 40,
  int reverseFrom = 0, int reverseCount = 0)
{
  const double start = gap > 0 ? std::asin(gap / thickness) : 0.0;
  std::vector<std::string> rows;
  for (int i = 0; i <= n; ++i)
  {
    const double phi = start + (2 * Pi - 2 * start) * i / n;
    const double z = 0.5 * std::cos(phi), y = 0.5 * thickness * std::sin(phi);
    std::ostringstream row;
    row.precision(17);
    row << r * std::cos(y / r) << " " << r * std::sin(y / r) << " " << z << "\n";
    rows.push_back(row.str());
  }
  if (gap == 0)
  {
    rows.back() = rows.front();
  }
  std::reverse(rows.begin() + reverseFrom, rows.begin() + reverseFrom + reverseCount);
  std::string text;
  for (const auto& row : rows)
  {
    text += row;
  }
  return text;
}

/// A meridional contour at radius r from z = -1 to 1 (x = r, y = 0), 9 rows.
std::string contourRows(double r)
{
  std::string text;
  for (int i = 0; i <= 8; ++i)
  {
    text += std::to_string(r) + " 0 " + std::to_string(-1.0 + 0.25 * i) + "\n";
  }
  return text;
}

/// Reads `profile` with a hub at radius 0.9 and a shroud at 1.5 (axis Z).
TurboPointSets readWithContours(TempDir& dir, const std::string& profile,
  EdgeCap cap = EdgeCap::Straight, const std::string& hub = contourRows(0.9))
{
  ReadOptions options;
  options.hubFile = dir.write("hub.curve", hub);
  options.shroudFile = dir.write("shroud.curve", contourRows(1.5));
  options.profileFile = dir.write("profile.curve", profile);
  options.cap = cap;
  return readTurboPointSets("", options);
}
} // namespace

TEST_F(TurboPointSetsRepairs, EveryCommentOrBlankLineBetweenRowsStartsASection)
{
  const std::string rows = sectionRows(1.0, 0.1, 0.0, 8);
  const std::string file = write("profile.curve",
    "# exported by a design tool\n# units: mm\n"
    "## Rotor1\n# Rotor1 Profile 1\n" + rows + "# Rotor1 Profile 2\n" + rows +
    "# IGV Profile 5\n" + rows +
    "# Profile 3 at 16.6667%\n" + rows +
    "# pressure and suction side, whatever this says\n" + rows +
    "\n\n" + rows +
    "! a bang comment\n" + rows + "#\n" + rows);
  const auto sections = readPointFile(file, true);
  ASSERT_EQ(sections.size(), 8u);
  EXPECT_EQ(sections[0].number, 1);
  EXPECT_EQ(sections[0].blade, "Rotor1");
  EXPECT_EQ(sections[0].firstLine, 4);
  EXPECT_EQ(sections[1].number, 2);
  EXPECT_EQ(sections[2].number, 5);
  EXPECT_FALSE(sections[2].spanGiven);
  EXPECT_EQ(sections[3].number, 3);
  EXPECT_TRUE(sections[3].spanGiven);
  EXPECT_DOUBLE_EQ(sections[3].spanPercent, 16.6667);
  for (const auto& section : sections)
  {
    EXPECT_EQ(section.points.size(), 9u) << section.name;
    ASSERT_EQ(section.lines.size(), 9u);
    EXPECT_EQ(section.lines.back() - section.lines.front(), 8) << section.name;
  }
  // Spans: "at s %", "s% span", and "at" without a number is an error.
  const std::string spans = write("spans.curve",
    "# Section 1 at 12.5 %\n" + rows + "# Profile 2 50% span\n" + rows);
  const auto two = readPointFile(spans, true);
  EXPECT_DOUBLE_EQ(two[0].spanPercent, 12.5);
  EXPECT_DOUBLE_EQ(two[1].spanPercent, 50.0);
  const std::string bad = write("bad.curve", "# Profile 2 at the hub\n" + rows);
  EXPECT_TRUE(contains(expectReadError([&] { readPointFile(bad, true); }).what(),
    "bad.curve:1: malformed section header"));
}

TEST_F(TurboPointSetsRepairs, OpenSectionsAreJoinedCappedOrLeftOpen)
{
  const std::string profile = "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0.0) +
    "# Profile 2 at 33%\n" + sectionRows(1.1, 0.1, 5e-4) + "# Profile 3 at 67%\n" +
    sectionRows(1.2, 0.1, 0.015, 160) + "# Profile 4 at 100%\n" + sectionRows(1.3, 0.2, 0.08);
  const TurboPointSets sets = readWithContours(*this, profile);
  ASSERT_EQ(sets.profiles.size(), 4u);
  const auto& closed = sets.profiles[0];
  const auto& joined = sets.profiles[1];
  const auto& capped = sets.profiles[2];
  const auto& open = sets.profiles[3];
  EXPECT_EQ(closed.closure, Closure::Closed);
  EXPECT_EQ(closed.gapFraction, 0.0);
  EXPECT_EQ(joined.closure, Closure::Joined);
  EXPECT_EQ(capped.closure, Closure::Capped);
  EXPECT_EQ(open.closure, Closure::Open);
  // The chord is the largest distance between two points: a little below 1 here (from
  // the leading edge to the ends; 0.959 for the widely open one).
  EXPECT_NEAR(joined.gapFraction, 5e-4, 1e-5);
  EXPECT_NEAR(capped.gapFraction, 0.015, 3e-4);
  EXPECT_NEAR(open.gapFraction, 0.08 / 0.9591, 2e-4);
  EXPECT_EQ(joined.points.size(), 41u);
  EXPECT_EQ(joined.points.front(), joined.points.back());
  // The midpoint of the two ends.
  EXPECT_NEAR(joined.points.front().z(), 0.5 * std::cos(std::asin(5e-4 / 0.1)), 1e-12);
  EXPECT_NEAR(joined.points.front().y(), 0.0, 1e-12);
  EXPECT_EQ(capped.points.front(), capped.points.back());
  EXPECT_NE(open.points.front(), open.points.back());
  // A straight cap: points on the segment between the two ends, about as far apart as
  // the last points of the sides (0.0034 here: 0.015 across gives 4 segments).
  EXPECT_EQ(capped.points.size(), 161u + 4u);
  for (std::size_t i = 161; i < capped.points.size(); ++i)
  {
    EXPECT_NEAR(capped.points[i].z(), capped.points[160].z(), 1e-12);
  }
  EXPECT_EQ(capped.lines.size(), capped.points.size());
  EXPECT_EQ(capped.lines.back(), capped.lines[160]);
  // Reported: one warning per kind of repair, with the gaps.
  std::string all;
  for (const auto& warning : sets.warnings)
  {
    all += warning + "\n";
  }
  EXPECT_TRUE(contains(all, "1 section was open by 0.05 % of the chord (0.0005 M), from "
                            "rounding: their ends were joined (Profile 2 (33%))"))
    << all;
  EXPECT_TRUE(contains(all, "blunt trailing edge of 1.51 % of the chord (0.015 M)")) << all;
  EXPECT_TRUE(contains(all, "straight cap (Profile 3 (67%))")) << all;
  EXPECT_FALSE(contains(all, "Profile 4")) << all;

  // A file that does not repeat the first point: closed by repeating it.
  std::string rows = sectionRows(1.0, 0.1, 0.0);
  rows.erase(rows.rfind('\n', rows.size() - 2) + 1);
  const TurboPointSets unrepeated = readWithContours(*this,
    "# Profile 1 at 0%\n" + rows + "# Profile 2 at 100%\n" + sectionRows(1.3, 0.1, 0));
  const auto& linked = unrepeated.profiles[0];
  EXPECT_EQ(linked.closure, Closure::Segment);
  ASSERT_EQ(linked.points.size(), 41u);
  EXPECT_EQ(linked.points.back(), linked.points.front());
  EXPECT_TRUE(contains(unrepeated.warnings.back(), "1 section was open by about one point "
                                                   "spacing (0.995 % of the chord"))
    << unrepeated.warnings.back();
}

TEST_F(TurboPointSetsRepairs, RoundedCapBulgesPastTheTrailingEdge)
{
  // A thick blunt edge: 4 % of the chord across, points 0.08 apart on the sides.
  const std::string profile = "# Profile 1 at 0%\n" + sectionRows(1.0, 0.2, 0.04, 40) +
    "# Profile 2 at 100%\n" + sectionRows(1.3, 0.2, 0.04, 40);
  const TurboPointSets sets = readWithContours(*this, profile, EdgeCap::Rounded);
  const auto& section = sets.profiles[0];
  EXPECT_EQ(section.closure, Closure::Capped);
  ASSERT_GT(section.points.size(), 42u);
  const Eigen::Vector3d first = section.points.front(), last = section.points[40];
  const Eigen::Vector3d middle = 0.5 * (first + last);
  const double radius = 0.5 * (first - last).norm();
  for (std::size_t i = 41; i + 1 < section.points.size(); ++i)
  {
    EXPECT_NEAR((section.points[i] - middle).norm(), radius, 1e-12);
    EXPECT_GT(section.points[i].z(), middle.z()); // beyond the edge, not into the blade
  }
  EXPECT_TRUE(contains(sets.warnings.back(), "rounded cap")) << sets.warnings.back();
}

TEST_F(TurboPointSetsRepairs, SectionsAreSortedByTheirHeaderSpans)
{
  const TurboPointSets sets = readWithContours(*this,
    "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0) + "# Profile 3 at 100%\n" +
      sectionRows(1.4, 0.1, 0) + "# Profile 2 at 50%\n" + sectionRows(1.2, 0.1, 0));
  ASSERT_EQ(sets.profiles.size(), 3u);
  EXPECT_EQ(sets.profiles[1].name, "Profile 2 (50%)");
  EXPECT_NEAR(sets.profiles[1].points[0].norm(), std::hypot(1.2, 0.5), 1e-6);
  ASSERT_EQ(sets.warnings.size(), 1u);
  EXPECT_TRUE(contains(sets.warnings[0], "sorted by the spans of their headers (file order: "
                                         "Profile 1 (0%), Profile 3 (100%), Profile 2 (50%))"))
    << sets.warnings[0];
}

TEST_F(TurboPointSetsRepairs, HeaderSpansThatContradictTheGeometryAreRefused)
{
  const ReadError error = expectReadError([&] {
    readWithContours(*this,
      "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0) + "# Profile 2 at 50%\n" +
        sectionRows(1.4, 0.1, 0) + "# Profile 3 at 100%\n" + sectionRows(1.2, 0.1, 0));
  });
  EXPECT_EQ(error.line(), 85); // the header of Profile 3
  EXPECT_TRUE(contains(error.what(), "section 'Profile 3 (100%)' lies at 50 % of the span "
                                     "measured between hub and shroud, not beyond section "
                                     "'Profile 2 (50%)' (line 43) at 83.3 %"))
    << error.what();
  EXPECT_TRUE(contains(error.what(), "(measured order: Profile 1 (0%) at 16.7 %, Profile 3 "
                                     "(100%) at 50 %, Profile 2 (50%) at 83.3 %)"))
    << error.what();
  const ReadError same = expectReadError([&] {
    readWithContours(*this,
      "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0) + "# Profile 2 at 0%\n" +
        sectionRows(1.4, 0.1, 0));
  });
  EXPECT_TRUE(contains(same.what(), "profile.curve:43: section 'Profile 2 (0%)' is at the "
                                    "same span as section 'Profile 1 (0%)' (line 1)"))
    << same.what();
}

TEST_F(TurboPointSetsRepairs, SectionsWithoutSpansAreSortedFromHubToShroud)
{
  // Written from the shroud down, with one out of place: sorted by where they lie.
  const TurboPointSets sets = readWithContours(*this,
    sectionRows(1.4, 0.1, 0) + "\n" + sectionRows(1.0, 0.1, 0) + "\n" +
      sectionRows(1.2, 0.1, 0));
  ASSERT_EQ(sets.profiles.size(), 3u);
  const double radii[3] = { 1.0, 1.2, 1.4 };
  const double spans[3] = { 0.0, 50.0, 100.0 };
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_NEAR(std::hypot(sets.profiles[k].points[0].x(), sets.profiles[k].points[0].y()),
      radii[k], 1e-12);
    EXPECT_DOUBLE_EQ(sets.profiles[k].spanPercent, spans[k]);
  }
  EXPECT_EQ(sets.profiles[0].name, "Profile 2 (0%)"); // numbered by file position
  EXPECT_TRUE(contains(sets.warnings.back(), "sorted by where they lie")) << sets.warnings.back();
}

TEST_F(TurboPointSetsRepairs, KinkedOrSelfCrossingCurvesAreRefusedNamingTheRows)
{
  // Hub contour with rows 4..6 written in reverse: z = -1, -0.75, -0.5, 0.25, 0, -0.25,
  // 0.5, ...: it turns back at line 4.
  std::string hub = contourRows(0.9);
  {
    std::istringstream stream(hub);
    std::vector<std::string> rows;
    for (std::string row; std::getline(stream, row);)
    {
      rows.push_back(row + "\n");
    }
    std::reverse(rows.begin() + 3, rows.begin() + 6);
    hub.clear();
    for (const auto& row : rows)
    {
      hub += row;
    }
  }
  const std::string closed = "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0) +
    "# Profile 2 at 100%\n" + sectionRows(1.4, 0.1, 0);
  const ReadError kinked =
    expectReadError([&] { readWithContours(*this, closed, EdgeCap::Straight, hub); });
  EXPECT_TRUE(contains(kinked.what(), "hub.curve:4: the Hub contour turns back at this row: "
                                      "by 180 degrees between lines 3 and 5"))
    << kinked.what();

  // Ten rows of a section reversed: the section crosses itself.
  const ReadError reversed = expectReadError([&] {
    readWithContours(*this,
      "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0, 40, 5, 10) + "# Profile 2 at 100%\n" +
        sectionRows(1.4, 0.1, 0));
  });
  EXPECT_TRUE(contains(reversed.what(), "profile.curve:")) << reversed.what();
  EXPECT_TRUE(contains(reversed.what(), "section 'Profile 1 (0%)'")) << reversed.what();
  EXPECT_TRUE(contains(reversed.what(), "crosses itself: the segment between lines 6 and 7 "
                                        "crosses the one between lines 16 and 17"))
    << reversed.what();

  // Two neighbouring rows swapped: a small zig-zag that crosses itself.
  const ReadError swapped = expectReadError([&] {
    readWithContours(*this,
      "# Profile 1 at 0%\n" + sectionRows(1.0, 0.1, 0, 40, 9, 2) + "# Profile 2 at 100%\n" +
        sectionRows(1.4, 0.1, 0));
  });
  EXPECT_TRUE(contains(swapped.what(), "section 'Profile 1 (0%)'")) << swapped.what();
}
