// GridQuality against OpenFOAM's checkMesh, cell by cell: the per-cell nonOrthoAngle,
// skewness and cell centres that `checkMesh -writeFields` and `postProcess -func
// writeCellCentres` (OpenFOAM v1912, Debian's package) wrote for the blockMesh grid of
// Templates/cylinder_in_box.yaml, stored with that grid in
// Testing/Data/checkmesh/cylinder_in_box.txt by Testing/Data/checkmesh/make_reference.py
// (OpenFOAM is not needed to run this test).
#include "TestHelpers.h"

#include "../../Filters/Core/Quality.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>

using namespace blockforge;

namespace
{
struct Reference
{
  std::vector<std::string> names;
  std::vector<std::array<int, 3>> nodes;
  std::vector<std::vector<double>> xyz;
  std::vector<double> nonOrthogonality, skewness;
  std::vector<Vec3> centres;
};

Reference readReference(const std::string& path)
{
  Reference reference;
  std::ifstream file(path);
  EXPECT_TRUE(file.good()) << path;
  std::string word;
  while (file >> word && word[0] == '#')
  {
    std::getline(file, word);
  }
  int blocks = 0;
  EXPECT_EQ(word, "blocks");
  file >> blocks;
  for (int b = 0; b < blocks; ++b)
  {
    std::string name;
    std::array<int, 3> n{};
    file >> word >> name >> n[0] >> n[1] >> n[2];
    reference.names.push_back(name);
    reference.nodes.push_back(n);
    reference.xyz.emplace_back(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    for (double& value : reference.xyz.back())
    {
      file >> value;
    }
  }
  std::size_t cells = 0;
  file >> word >> cells;
  EXPECT_EQ(word, "cells");
  for (std::size_t c = 0; c < cells && file; ++c)
  {
    double nonOrthogonality = 0, skewness = 0;
    Vec3 centre;
    file >> nonOrthogonality >> skewness >> centre[0] >> centre[1] >> centre[2];
    reference.nonOrthogonality.push_back(nonOrthogonality);
    reference.skewness.push_back(skewness);
    reference.centres.push_back(centre);
  }
  EXPECT_TRUE(file.good() || file.eof());
  return reference;
}
} // namespace

TEST(CheckMeshReference, CylinderInBoxCellByCell)
{
  const Reference reference =
    readReference(test::sourcePath("Testing/Data/checkmesh/cylinder_in_box.txt"));
  ASSERT_EQ(reference.nodes.size(), 4u);
  ASSERT_EQ(reference.nonOrthogonality.size(), 2048u);

  // BlockForge's grid of the same template is blockMesh's (to round-off): the comparison
  // below is on what GridQuality measures after BlockMesher.
  const model::BlockModel model =
    model::loadTemplate(test::templatePath("cylinder_in_box.yaml"), { { "n_depth", "2" } });
  const test::Grid grid = test::meshAll(model);
  ASSERT_EQ(grid.nodes, reference.nodes);
  double nodeDifference = 0.0;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    EXPECT_EQ(model.blocks[b].name, reference.names[b]);
    for (std::size_t n = 0; n < grid.xyz[b].size(); ++n)
    {
      nodeDifference = std::max(nodeDifference, std::abs(grid.xyz[b][n] - reference.xyz[b][n]));
    }
  }
  EXPECT_LT(nodeDifference, 1e-12);

  std::vector<StructuredBlock> blocks;
  for (std::size_t b = 0; b < grid.xyz.size(); ++b)
  {
    blocks.push_back({ grid.xyz[b].data(), grid.nodes[b][0], grid.nodes[b][1], grid.nodes[b][2] });
  }
  const std::vector<CellQualityArrays> quality = computeGridQuality(blocks);
  std::size_t cell = 0;
  double worstAngle = 0.0, worstSkewness = 0.0, worstCentre = 0.0, largestAngle = 0.0;
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    const auto& n = grid.nodes[b];
    for (int k = 0; k + 1 < n[2]; ++k)
      for (int j = 0; j + 1 < n[1]; ++j)
        for (int i = 0; i + 1 < n[0]; ++i, ++cell)
        {
          const std::size_t local = i + (n[0] - 1) * (j + static_cast<std::size_t>(n[1] - 1) * k);
          const std::array<Vec3, 8> corners = { grid.at(b, i, j, k), grid.at(b, i + 1, j, k),
            grid.at(b, i + 1, j + 1, k), grid.at(b, i, j + 1, k), grid.at(b, i, j, k + 1),
            grid.at(b, i + 1, j, k + 1), grid.at(b, i + 1, j + 1, k + 1),
            grid.at(b, i, j + 1, k + 1) };
          const double angle = std::abs(quality[b].nonOrthogonality[local] - reference.nonOrthogonality[cell]);
          const double skew = std::abs(quality[b].skewness[local] - reference.skewness[cell]);
          const double centre = (hexCentre(corners) - reference.centres[cell]).norm();
          EXPECT_LE(angle, 1e-3) << "block " << b << " cell " << i << " " << j << " " << k;
          EXPECT_LE(skew, 1e-6) << "block " << b << " cell " << i << " " << j << " " << k;
          EXPECT_LE(centre, 1e-12) << "block " << b << " cell " << i << " " << j << " " << k;
          worstAngle = std::max(worstAngle, angle);
          worstSkewness = std::max(worstSkewness, skew);
          worstCentre = std::max(worstCentre, centre);
          largestAngle = std::max(largestAngle, reference.nonOrthogonality[cell]);
        }
  }
  EXPECT_EQ(cell, reference.nonOrthogonality.size());
  EXPECT_GT(largestAngle, 30.0); // the grid has non-orthogonal cells to compare
  std::cout << "largest difference to checkMesh: non-orthogonality " << worstAngle
            << " deg, skewness " << worstSkewness << ", cell centre " << worstCentre << " m\n";
}
