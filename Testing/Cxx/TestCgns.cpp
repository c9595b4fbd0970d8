// The CGNS writer read back through the CGNS library: zones and coordinates bit for bit,
// and every GridConnectivity1to1 followed node by node through its transform lands on the
// same point (interfaces) or on the point rotated by its periodic rotation.
#include "Cgns.h"
#include "ExportModel.h"
#include "TestHelpers.h"
#include "TestTurboInputs.h"

#include <cgnslib.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

using namespace blockforge;

namespace
{
struct Written
{
  test::Grid grid;
  exporting::ExportGrid exported;
  std::string path;
};

Written writeModel(const model::BlockModel& model, const std::string& name)
{
  Written result;
  result.grid = test::meshAll(model);
  std::vector<exporting::GridBlock> blocks;
  for (std::size_t b = 0; b < model.blocks.size(); ++b)
  {
    exporting::GridBlock block;
    block.name = model.blocks[b].name;
    block.nodes = result.grid.nodes[b];
    block.xyz = result.grid.xyz[b].data();
    blocks.push_back(block);
  }
  result.exported = exporting::exportGrid(model, blocks);
  result.path = std::string(BLOCKFORGE_TEST_OUTPUT) + "/cgns/" + name + ".cgns";
  exporting::writeCgns(result.exported, result.path);
  return result;
}

void checkFile(const Written& written)
{
  const exporting::ExportGrid& grid = written.exported;
  int fn = 0;
  ASSERT_EQ(cg_open(written.path.c_str(), CG_MODE_READ, &fn), CG_OK) << cg_get_error();
  int zones = 0;
  ASSERT_EQ(cg_nzones(fn, 1, &zones), CG_OK);
  ASSERT_EQ(zones, static_cast<int>(grid.blocks.size()));
  std::vector<std::string> names;
  std::vector<std::vector<double>> xyz(zones);
  for (int z = 1; z <= zones; ++z)
  {
    char name[33];
    cgsize_t size[9];
    ASSERT_EQ(cg_zone_read(fn, 1, z, name, size), CG_OK);
    names.push_back(name);
  }
  int connections = 0, bcs = 0;
  for (int z = 1; z <= zones; ++z)
  {
    // Zones are stored sorted by name: find the block.
    const int b = static_cast<int>(std::find_if(grid.blocks.begin(), grid.blocks.end(),
      [&](const exporting::GridBlock& block) { return block.name == names[z - 1]; }) -
      grid.blocks.begin());
    ASSERT_LT(b, zones);
    const exporting::GridBlock& block = grid.blocks[b];
    const cgsize_t one[3] = { 1, 1, 1 };
    const cgsize_t last[3] = { block.nodes[0], block.nodes[1], block.nodes[2] };
    const std::size_t count = static_cast<std::size_t>(block.nodeCount());
    std::vector<double> coordinate(count);
    xyz[z - 1].resize(3 * count);
    const char* axes[3] = { "CoordinateX", "CoordinateY", "CoordinateZ" };
    for (int c = 0; c < 3; ++c)
    {
      ASSERT_EQ(cg_coord_read(fn, 1, z, axes[c], CGNS_ENUMV(RealDouble), one, last,
                  coordinate.data()), CG_OK);
      for (std::size_t p = 0; p < count; ++p)
      {
        ASSERT_TRUE(test::sameBits(coordinate[p], block.xyz[3 * p + c]));
        xyz[z - 1][3 * p + c] = coordinate[p];
      }
    }
    int bc = 0;
    ASSERT_EQ(cg_nbocos(fn, 1, z, &bc), CG_OK);
    bcs += bc;
  }
  for (int z = 1; z <= zones; ++z)
  {
    int count = 0;
    ASSERT_EQ(cg_n1to1(fn, 1, z, &count), CG_OK);
    connections += count;
    cgsize_t zoneSize[9];
    char zoneName[33];
    cg_zone_read(fn, 1, z, zoneName, zoneSize);
    for (int c = 1; c <= count; ++c)
    {
      char name[33], donor[33];
      cgsize_t range[6], donorRange[6];
      int t[3];
      ASSERT_EQ(cg_1to1_read(fn, 1, z, c, name, donor, range, donorRange, t), CG_OK);
      const int d = static_cast<int>(std::find(names.begin(), names.end(), donor) - names.begin());
      ASSERT_LT(d, zones) << donor;
      cgsize_t donorSize[9];
      char donorName[33];
      cg_zone_read(fn, 1, d + 1, donorName, donorSize);
      // Periodic rotation, if any.
      Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
      Vec3 centre = Vec3::Zero();
      float rc[3], ra[3], tr[3];
      if (cg_1to1_periodic_read(fn, 1, z, c, rc, ra, tr) == CG_OK)
      {
        const Vec3 angles(ra[0], ra[1], ra[2]);
        rotation = Eigen::AngleAxisd(angles.norm(), angles.normalized()).toRotationMatrix();
        centre = Vec3(rc[0], rc[1], rc[2]);
      }
      Eigen::Matrix3i matrix = Eigen::Matrix3i::Zero();
      for (int j = 0; j < 3; ++j)
      {
        matrix(std::abs(t[j]) - 1, j) = t[j] > 0 ? 1 : -1;
      }
      EXPECT_EQ(matrix.cast<double>().determinant(), 1.0) << zoneName << " " << name;
      double worst = 0.0;
      for (cgsize_t k = std::min(range[2], range[5]); k <= std::max(range[2], range[5]); ++k)
        for (cgsize_t j = std::min(range[1], range[4]); j <= std::max(range[1], range[4]); ++j)
          for (cgsize_t i = std::min(range[0], range[3]); i <= std::max(range[0], range[3]); ++i)
          {
            const Eigen::Vector3i offset(int(i - range[0]), int(j - range[1]), int(k - range[2]));
            const Eigen::Vector3i image = matrix * offset +
              Eigen::Vector3i(int(donorRange[0]), int(donorRange[1]), int(donorRange[2]));
            auto at = [&](int zone, const cgsize_t* size, long long ii, long long jj, long long kk) {
              const double* p = &xyz[zone][3 * ((ii - 1) + size[0] * ((jj - 1) + size[1] * (kk - 1)))];
              return Vec3(p[0], p[1], p[2]);
            };
            for (int a = 0; a < 3; ++a)
            {
              ASSERT_GE(image[a], 1);
              ASSERT_LE(image[a], donorSize[a]);
            }
            const Vec3 here = at(z - 1, zoneSize, i, j, k);
            const Vec3 there = at(d, donorSize, image[0], image[1], image[2]);
            worst = std::max(worst, (centre + rotation * (here - centre) - there).norm());
          }
      EXPECT_LT(worst, 1e-6) << zoneName << " " << name << " -> " << donor;
      // The donor range ends where the transform takes the range's end.
      const Eigen::Vector3i end = matrix *
          Eigen::Vector3i(int(range[3] - range[0]), int(range[4] - range[1]), int(range[5] - range[2])) +
        Eigen::Vector3i(int(donorRange[0]), int(donorRange[1]), int(donorRange[2]));
      EXPECT_EQ(end, Eigen::Vector3i(int(donorRange[3]), int(donorRange[4]), int(donorRange[5])));
    }
  }
  int expectedConnections = 2 * static_cast<int>(grid.interfaces.size());
  int expectedBcs = 0;
  for (const exporting::GridPatch& patch : grid.patches)
  {
    if (patch.partner >= 0)
    {
      expectedConnections += static_cast<int>(patch.images.size());
      continue;
    }
    for (const model::BlockFace& face : patch.faces)
    {
      expectedBcs += grid.collapsedFaces[face.block][face.face] ? 0 : 1;
    }
  }
  EXPECT_EQ(connections, expectedConnections);
  EXPECT_EQ(bcs, expectedBcs);
  int families = 0;
  cg_nfamilies(fn, 1, &families);
  EXPECT_EQ(families, static_cast<int>(grid.patches.size()));
  cg_close(fn);
}
} // namespace

TEST(Cgns, ExampleTemplatesReadBackWithConnectivity)
{
  for (const std::string& name : test::exampleTemplates())
  {
    SCOPED_TRACE(name);
    checkFile(writeModel(model::loadTemplate(test::templatePath(name)), name));
  }
}

TEST(Cgns, DistributorPassageWithPeriodicPairs)
{
  const model::TemplateInputs inputs =
    test::readTemplateInputs(test::sourcePath("Data/distributor/BladeGen.inf"));
  const model::BlockModel model =
    model::loadTemplate(test::templatePath("axial_passage_oh.yaml"), {}, &inputs);
  checkFile(writeModel(model, "axial_passage_oh_distributor"));
}

TEST(Cgns, BoundaryTypes)
{
  EXPECT_EQ(exporting::cgnsBoundaryType("wall"), "BCWall");
  EXPECT_EQ(exporting::cgnsBoundaryType("inlet"), "BCInflow");
  EXPECT_EQ(exporting::cgnsBoundaryType("outlet"), "BCOutflow");
  EXPECT_EQ(exporting::cgnsBoundaryType("symmetry"), "BCSymmetryPlane");
  EXPECT_EQ(exporting::cgnsBoundaryType("patch"), "UserDefined");
}
