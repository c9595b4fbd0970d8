// OpenFOAM polyMesh assembly on hand-made block grids with analytic volumes: a box, two
// blocks joined through a turned face, a wedge (prism cells, collapsed in the model or only
// by coincident nodes) and a periodic pair.
#include "PolyMesh.h"
#include "StagedOutput.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

using namespace blockforge;
using namespace blockforge::exporting;

namespace
{
constexpr double Pi = 3.14159265358979323846;

/// Node storage of a block built from a point function of (i, j, k).
struct OwnedBlock
{
  std::vector<double> xyz;
  GridBlock view;
};

OwnedBlock makeBlock(const std::string& name, std::array<int, 3> nodes,
  const std::function<Vec3(int, int, int)>& at)
{
  OwnedBlock block;
  for (int k = 0; k < nodes[2]; ++k)
    for (int j = 0; j < nodes[1]; ++j)
      for (int i = 0; i < nodes[0]; ++i)
      {
        const Vec3 p = at(i, j, k);
        block.xyz.insert(block.xyz.end(), { p.x(), p.y(), p.z() });
      }
  block.view.name = name;
  block.view.nodes = nodes;
  return block;
}

ExportGrid gridOf(std::vector<OwnedBlock>& blocks)
{
  ExportGrid grid;
  for (OwnedBlock& block : blocks)
  {
    block.view.xyz = block.xyz.data();
    grid.blocks.push_back(block.view);
  }
  grid.collapsedEdges.assign(blocks.size(), std::array<bool, 12>{});
  grid.collapsedFaces.assign(blocks.size(), std::array<bool, 6>{});
  return grid;
}

Vec3 point(const PolyMesh& mesh, int p)
{
  return Vec3(mesh.points[3 * p], mesh.points[3 * p + 1], mesh.points[3 * p + 2]);
}

/// Face centre (mean of the corners) and area vector (triangle fan around it).
std::pair<Vec3, Vec3> faceGeometry(const PolyMesh& mesh, int f)
{
  const int begin = mesh.faceOffsets[f], end = mesh.faceOffsets[f + 1];
  Vec3 centre = Vec3::Zero();
  for (int n = begin; n < end; ++n)
    centre += point(mesh, mesh.faceNodes[n]);
  centre /= end - begin;
  Vec3 area = Vec3::Zero();
  for (int n = begin; n < end; ++n)
  {
    const int next = n + 1 < end ? n + 1 : begin;
    area += 0.5 * (point(mesh, mesh.faceNodes[n]) - centre).cross(point(mesh, mesh.faceNodes[next]) - centre);
  }
  return { centre, area };
}

/// Per cell: volume by the divergence theorem and the sum of its outward area vectors
/// (zero for a closed cell); also checks the upper-triangular order of internal faces.
struct CellSums
{
  std::vector<double> volume;
  std::vector<Vec3> closure;
};

CellSums cellSums(const PolyMesh& mesh)
{
  CellSums sums;
  sums.volume.assign(mesh.cellCount, 0.0);
  sums.closure.assign(mesh.cellCount, Vec3::Zero());
  for (int f = 0; f < mesh.faceCount(); ++f)
  {
    const auto [centre, area] = faceGeometry(mesh, f);
    sums.volume[mesh.owner[f]] += centre.dot(area) / 3.0;
    sums.closure[mesh.owner[f]] += area;
    if (f < mesh.internalFaceCount())
    {
      EXPECT_LT(mesh.owner[f], mesh.neighbour[f]);
      if (f > 0)
      {
        EXPECT_TRUE(mesh.owner[f - 1] < mesh.owner[f] ||
          (mesh.owner[f - 1] == mesh.owner[f] && mesh.neighbour[f - 1] < mesh.neighbour[f]))
          << "face " << f << " breaks the upper-triangular order";
      }
      sums.volume[mesh.neighbour[f]] -= centre.dot(area) / 3.0;
      sums.closure[mesh.neighbour[f]] -= area;
    }
  }
  return sums;
}

double totalVolume(const PolyMesh& mesh)
{
  const CellSums sums = cellSums(mesh);
  double total = 0.0;
  for (int c = 0; c < mesh.cellCount; ++c)
  {
    EXPECT_GT(sums.volume[c], 0.0) << "cell " << c;
    EXPECT_LT(sums.closure[c].norm(), 1e-12) << "cell " << c << " is not closed";
    total += sums.volume[c];
  }
  return total;
}

const FoamPatch& patchNamed(const PolyMesh& mesh, const std::string& name)
{
  for (const FoamPatch& patch : mesh.patches)
    if (patch.name == name)
      return patch;
  ADD_FAILURE() << "no patch " << name;
  return mesh.patches.front();
}
} // namespace

TEST(PolyMesh, BoxCountsOrientationAndPatches)
{
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("box", { 4, 3, 5 }, [](int i, int j, int k) {
    return Vec3(i * 0.5, j * 0.25 + 0.1 * i, k * 0.2);
  }));
  ExportGrid grid = gridOf(blocks);
  GridPatch inlet;
  inlet.name = "inlet";
  inlet.type = "inlet";
  inlet.faces = { { 0, 0 } };
  GridPatch walls;
  walls.name = "walls";
  walls.type = "wall";
  walls.faces = { { 0, 2 }, { 0, 3 } };
  grid.patches = { inlet, walls };
  const PolyMesh mesh = buildPolyMesh(grid);
  EXPECT_EQ(mesh.pointCount(), 60);
  EXPECT_EQ(mesh.cellCount, 3 * 2 * 4);
  // Internal faces: (ci - 1) cj ck + ci (cj - 1) ck + ci cj (ck - 1).
  EXPECT_EQ(mesh.internalFaceCount(), 2 * 2 * 4 + 3 * 1 * 4 + 3 * 2 * 3);
  EXPECT_EQ(mesh.faceCount() - mesh.internalFaceCount(), 2 * (2 * 4 + 3 * 4 + 3 * 2));
  ASSERT_EQ(mesh.patches.size(), 3u);
  EXPECT_EQ(patchNamed(mesh, "inlet").type, "patch");
  EXPECT_EQ(patchNamed(mesh, "inlet").faceCount, 8);
  EXPECT_EQ(patchNamed(mesh, "walls").type, "wall");
  EXPECT_EQ(patchNamed(mesh, "walls").faceCount, 24);
  EXPECT_EQ(patchNamed(mesh, "defaultFaces").faceCount, 8 + 6 + 6);
  EXPECT_EQ(mesh.patches.front().startFace, mesh.internalFaceCount());
  // A sheared box: 1.5 x 0.5 x 0.8.
  EXPECT_NEAR(totalVolume(mesh), 1.5 * 0.5 * 0.8, 1e-12);
  // Inlet faces (i = 0) point to -x.
  for (int f = 0; f < 8; ++f)
  {
    const Vec3 area = faceGeometry(mesh, mesh.internalFaceCount() + f).second;
    EXPECT_LT(area.x(), 0.0);
  }
}

TEST(PolyMesh, InterfaceThroughTurnedFaceMergesNodes)
{
  // Block A: [0,1]^3 with 3x4x5 cells; block B: [1,2] x [0,1]^2 whose own i runs along -y,
  // j along +x and k along z: face A.i1 is B.j0 with a and b roles swapped/reversed.
  const int ni = 4, nj = 5, nk = 6;
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("A", { ni, nj, nk }, [&](int i, int j, int k) {
    return Vec3(double(i) / (ni - 1), double(j) / (nj - 1), double(k) / (nk - 1));
  }));
  blocks.push_back(makeBlock("B", { nj, 3, nk }, [&](int i, int j, int k) {
    return Vec3(1.0 + 0.5 * j, 1.0 - double(i) / (nj - 1), double(k) / (nk - 1));
  }));
  ExportGrid grid = gridOf(blocks);
  // A.i1 (a = j, b = k) -> B.j0 (a = i, b = k): i_B = nj - 1 - j_A, k_B = k_A: reverse a.
  grid.interfaces.push_back(FaceMatch{ { 0, 1 }, { 1, 2 }, FaceTransform{ 1 } });
  const PolyMesh mesh = buildPolyMesh(grid);
  EXPECT_EQ(mesh.pointCount(), ni * nj * nk + nj * 3 * nk - nj * nk);
  const int cellsA = 3 * 4 * 5, cellsB = 4 * 2 * 5;
  EXPECT_EQ(mesh.cellCount, cellsA + cellsB);
  const int insideA = 2 * 4 * 5 + 3 * 3 * 5 + 3 * 4 * 4;
  const int insideB = 3 * 2 * 5 + 4 * 1 * 5 + 4 * 2 * 4;
  EXPECT_EQ(mesh.internalFaceCount(), insideA + insideB + 4 * 5);
  EXPECT_NEAR(totalVolume(mesh), 2.0, 1e-12);
  // The same with the interface given from B's side.
  grid.interfaces = { FaceMatch{ { 1, 2 }, { 0, 1 }, inverse(FaceTransform{ 1 }) } };
  const PolyMesh again = buildPolyMesh(grid);
  EXPECT_EQ(again.faceNodes, mesh.faceNodes);
  EXPECT_EQ(again.neighbour, mesh.neighbour);
}

TEST(PolyMesh, SquareSymmetriesInvert)
{
  for (int code = 0; code < 8; ++code)
  {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 5; ++b)
      {
        const bool swap = (code & 4) != 0;
        const std::array<int, 2> m = mapFaceNode(FaceTransform{ code }, a, b, swap ? 5 : 3, swap ? 3 : 5);
        const std::array<int, 2> back = mapFaceNode(inverse(FaceTransform{ code }), m[0], m[1], 3, 5);
        EXPECT_EQ(back[0], a);
        EXPECT_EQ(back[1], b);
      }
  }
}

TEST(PolyMesh, WedgeBlockGivesPrisms)
{
  // Pie slice of angle phi, radius R, height H: corners 0 = 3 and 4 = 7 on the axis
  // (local edges 3 and 7 collapse, face i0 is a line).
  const double phi = Pi / 3.0, R = 1.0, H = 0.5;
  const int nr = 5, na = 7, nh = 3;
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("core", { nr, na, nh }, [&](int i, int j, int k) {
    const double r = R * i / (nr - 1), t = phi * j / (na - 1);
    return Vec3(r * std::cos(t), r * std::sin(t), H * k / (nh - 1));
  }));
  ExportGrid grid = gridOf(blocks);
  grid.collapsedEdges[0][3] = grid.collapsedEdges[0][7] = true;
  grid.collapsedFaces[0][0] = true;
  GridPatch all;
  all.name = "outside";
  all.type = "wall";
  all.faces = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 0, 4 }, { 0, 5 } };
  grid.patches = { all };
  const PolyMesh mesh = buildPolyMesh(grid);
  // The axis keeps one node per level.
  EXPECT_EQ(mesh.pointCount(), (nr - 1) * na * nh + nh);
  // Triangles: the bottom and top faces of the axis cells, internal k faces too.
  const int axisCells = (na - 1) * (nh - 1);
  EXPECT_EQ(mesh.triangleFaces, (na - 1) * nh);
  EXPECT_EQ(patchNamed(mesh, "outside").faceCount,
    (na - 1) * (nh - 1) + 2 * (nr - 1) * (nh - 1) + 2 * (nr - 1) * (na - 1));
  (void)axisCells;
  // Polygonal sector: (na - 1) triangles of the chord polygon, times H.
  const double expected = (na - 1) * 0.5 * R * R * std::sin(phi / (na - 1)) * H;
  EXPECT_NEAR(totalVolume(mesh), expected, 1e-12);
}

TEST(PolyMesh, CoincidentNodesGivePrismsWithoutCollapsedEdges)
{
  // The pie slice of WedgeBlockGivesPrisms, its axis nodes the same point per level but
  // the model saying nothing (no collapsed edge, face i0 an ordinary face in the patch):
  // a fan whose feet lie on one tip. The writer merges the coincident nodes itself and
  // writes the very mesh of the collapsed block.
  const double phi = Pi / 3.0, R = 1.0, H = 0.5;
  const int nr = 5, na = 7, nh = 3;
  auto slice = [&]() {
    std::vector<OwnedBlock> blocks;
    blocks.push_back(makeBlock("fan", { nr, na, nh }, [&](int i, int j, int k) {
      const double r = R * i / (nr - 1), t = phi * j / (na - 1);
      return Vec3(r * std::cos(t), r * std::sin(t), H * k / (nh - 1));
    }));
    return blocks;
  };
  std::vector<OwnedBlock> collapsedBlocks = slice(), plainBlocks = slice();
  ExportGrid collapsed = gridOf(collapsedBlocks);
  collapsed.collapsedEdges[0][3] = collapsed.collapsedEdges[0][7] = true;
  collapsed.collapsedFaces[0][0] = true;
  ExportGrid plain = gridOf(plainBlocks);
  GridPatch all;
  all.name = "outside";
  all.type = "wall";
  all.faces = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 0, 4 }, { 0, 5 } };
  collapsed.patches = { all };
  all.faces.insert(all.faces.begin(), { 0, 0 }); // the axis: no face survives
  plain.patches = { all };
  const PolyMesh expected = buildPolyMesh(collapsed);
  const PolyMesh mesh = buildPolyMesh(plain);
  EXPECT_EQ(mesh.pointCount(), (nr - 1) * na * nh + nh);
  EXPECT_EQ(mesh.triangleFaces, (na - 1) * nh);
  EXPECT_EQ(mesh.points, expected.points);
  EXPECT_EQ(mesh.faceNodes, expected.faceNodes);
  EXPECT_EQ(mesh.faceOffsets, expected.faceOffsets);
  EXPECT_EQ(mesh.owner, expected.owner);
  EXPECT_EQ(mesh.neighbour, expected.neighbour);
  ASSERT_EQ(mesh.patches.size(), 1u);
  EXPECT_EQ(mesh.patches[0].faceCount, expected.patches[0].faceCount);
  const double volume = (na - 1) * 0.5 * R * R * std::sin(phi / (na - 1)) * H;
  EXPECT_NEAR(totalVolume(mesh), volume, 1e-12);

  // Nodes a round-off apart are not merged: the cells stay what GridQuality measures.
  std::vector<OwnedBlock> nearBlocks = slice();
  for (int k = 0; k < nh; ++k)
    for (int j = 1; j < na; j += 2)
      nearBlocks[0].xyz[3 * (static_cast<std::size_t>(nr) * (j + na * k))] = 1e-15;
  ExportGrid near = gridOf(nearBlocks);
  near.patches = { all };
  const PolyMesh kept = buildPolyMesh(near);
  EXPECT_EQ(kept.pointCount(), nr * na * nh); // every other axis node moved: none merge
  EXPECT_EQ(kept.triangleFaces, 0);
}

TEST(PolyMesh, PeriodicPairIsCyclicInMatchingOrder)
{
  // A ring sector of 90 degrees: face j0 (theta = 0) rotated by +90 deg about z is j1.
  const int nr = 4, na = 6, nh = 3;
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("ring", { nr, na, nh }, [&](int i, int j, int k) {
    const double r = 1.0 + 0.5 * i / (nr - 1), t = 0.5 * Pi * j / (na - 1);
    return Vec3(r * std::cos(t), r * std::sin(t), 0.3 * k / (nh - 1) + 0.01 * i * k);
  }));
  ExportGrid grid = gridOf(blocks);
  GridPatch low, high;
  low.name = "periodic_low";
  low.type = "periodic";
  low.faces = { { 0, 2 } };
  low.partner = 1;
  low.angle = 0.5 * Pi;
  low.images = { FaceMatch{ { 0, 2 }, { 0, 3 }, FaceTransform{ 0 } } };
  high.name = "periodic_high";
  high.type = "periodic";
  high.faces = { { 0, 3 } };
  high.partner = 0;
  high.angle = -0.5 * Pi;
  high.images = { FaceMatch{ { 0, 3 }, { 0, 2 }, FaceTransform{ 0 } } };
  grid.patches = { low, high };
  const PolyMesh mesh = buildPolyMesh(grid);
  const FoamPatch& a = patchNamed(mesh, "periodic_low");
  const FoamPatch& b = patchNamed(mesh, "periodic_high");
  EXPECT_EQ(a.type, "cyclic");
  EXPECT_EQ(a.neighbourPatch, "periodic_high");
  EXPECT_EQ(b.neighbourPatch, "periodic_low");
  EXPECT_NEAR(a.rotationAngle, 90.0, 1e-12);
  ASSERT_EQ(a.faceCount, (nr - 1) * (nh - 1));
  ASSERT_EQ(b.faceCount, a.faceCount);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.5 * Pi, Vec3::UnitZ()).toRotationMatrix();
  for (int f = 0; f < a.faceCount; ++f)
  {
    const int fa = a.startFace + f, fb = b.startFace + f;
    const auto [ca, sa] = faceGeometry(mesh, fa);
    const auto [cb, sb] = faceGeometry(mesh, fb);
    EXPECT_LT((rotation * ca - cb).norm(), 1e-12) << "face " << f;
    EXPECT_LT((rotation * sa + sb).norm(), 1e-12) << "normals must be opposite";
    // First corners match, the loops run opposite ways.
    const int na0 = mesh.faceNodes[mesh.faceOffsets[fa]];
    const int nb0 = mesh.faceNodes[mesh.faceOffsets[fb]];
    EXPECT_LT((rotation * point(mesh, na0) - point(mesh, nb0)).norm(), 1e-12);
    const int na1 = mesh.faceNodes[mesh.faceOffsets[fa] + 1];
    const int nbLast = mesh.faceNodes[mesh.faceOffsets[fb + 1] - 1];
    EXPECT_LT((rotation * point(mesh, na1) - point(mesh, nbLast)).norm(), 1e-12);
  }
  EXPECT_GT(totalVolume(mesh), 0.0);
}

TEST(FoamCase, WritesBinaryAndAsciiAndReplacesAtomically)
{
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("box", { 3, 3, 3 }, [](int i, int j, int k) {
    return Vec3(i, j, k);
  }));
  ExportGrid grid = gridOf(blocks);
  const PolyMesh mesh = buildPolyMesh(grid);
  const std::string dir = std::string(BLOCKFORGE_TEST_OUTPUT) + "/foam_case";
  removeTree(dir);
  FoamWriteOptions ascii;
  ascii.binary = false;
  writeFoamCase(mesh, dir + "/box.foam", ascii);
  std::ifstream points(dir + "/constant/polyMesh/points");
  std::stringstream text;
  text << points.rdbuf();
  EXPECT_NE(text.str().find("format      ascii;"), std::string::npos);
  EXPECT_NE(text.str().find("27\n(\n(0 0 0)\n(1 0 0)\n"), std::string::npos);
  struct stat status;
  EXPECT_EQ(::stat((dir + "/box.foam").c_str(), &status), 0);
  writeFoamCase(mesh, dir + "/box.foam");
  std::ifstream again(dir + "/constant/polyMesh/faces");
  std::stringstream binary;
  binary << again.rdbuf();
  EXPECT_NE(binary.str().find("class       faceCompactList;"), std::string::npos);
  EXPECT_NE(binary.str().find("format      binary;"), std::string::npos);
  // No staging directory is left behind: constant/ holds polyMesh only.
  int entries = 0;
  if (DIR* folder = ::opendir((dir + "/constant").c_str()))
  {
    while (dirent* entry = ::readdir(folder))
      entries += entry->d_name[0] != '.' || std::string(entry->d_name).size() > 2 ? 1 : 0;
    ::closedir(folder);
  }
  EXPECT_EQ(entries, 1);
  // A case folder that cannot be made: an error naming it, nothing written.
  EXPECT_THROW(writeFoamCase(mesh, dir + "/box.foam/inside/x.foam"), std::runtime_error);
}

TEST(FoamCase, StreamedBinaryEqualsTheMeshInMemory)
{
  // A wedge (prisms, triangles) whose two sides are a periodic pair: every kind of face.
  const double phi = Pi / 4.0;
  const int nr = 4, na = 5, nh = 3;
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("core", { nr, na, nh }, [&](int i, int j, int k) {
    const double r = double(i) / (nr - 1), t = phi * j / (na - 1);
    return Vec3(r * std::cos(t), r * std::sin(t), 0.4 * k / (nh - 1));
  }));
  ExportGrid grid = gridOf(blocks);
  grid.collapsedEdges[0][3] = grid.collapsedEdges[0][7] = true;
  grid.collapsedFaces[0][0] = true;
  GridPatch low, high, wall;
  low.name = "low";
  low.type = "periodic";
  low.faces = { { 0, 2 } };
  low.partner = 1;
  low.angle = phi;
  low.images = { FaceMatch{ { 0, 2 }, { 0, 3 }, FaceTransform{ 0 } } };
  high.name = "high";
  high.type = "periodic";
  high.faces = { { 0, 3 } };
  high.partner = 0;
  high.angle = -phi;
  high.images = { FaceMatch{ { 0, 3 }, { 0, 2 }, FaceTransform{ 0 } } };
  wall.name = "wall";
  wall.type = "wall";
  wall.faces = { { 0, 1 } };
  grid.patches = { low, high, wall };
  const std::string dir = std::string(BLOCKFORGE_TEST_OUTPUT) + "/foam_stream";
  removeTree(dir);
  const FoamSummary summary = writeFoamCase(grid, dir + "/streamed/s.foam");
  const PolyMesh mesh = buildPolyMesh(grid);
  writeFoamCase(mesh, dir + "/memory/m.foam");
  EXPECT_EQ(summary.faces, mesh.faceCount());
  EXPECT_EQ(summary.internalFaces, mesh.internalFaceCount());
  EXPECT_EQ(summary.points, mesh.pointCount());
  EXPECT_EQ(summary.triangleFaces, mesh.triangleFaces);
  EXPECT_GT(summary.triangleFaces, 0);
  ASSERT_EQ(summary.patches.size(), mesh.patches.size());
  for (const char* name : { "points", "faces", "owner", "neighbour", "boundary" })
  {
    auto read = [&](const std::string& folder) {
      std::ifstream stream(dir + "/" + folder + "/constant/polyMesh/" + name, std::ios::binary);
      std::stringstream text;
      text << stream.rdbuf();
      return text.str();
    };
    const std::string streamed = read("streamed");
    EXPECT_FALSE(streamed.empty()) << name;
    EXPECT_EQ(streamed, read("memory")) << name;
  }
}

TEST(FoamCase, LeftoversOfKilledRunsAreRemovedOthersKept)
{
  std::vector<OwnedBlock> blocks;
  blocks.push_back(makeBlock("box", { 2, 2, 2 }, [](int i, int j, int k) {
    return Vec3(i, j, k);
  }));
  const ExportGrid grid = gridOf(blocks);
  const std::string dir = std::string(BLOCKFORGE_TEST_OUTPUT) + "/foam_leftovers";
  removeTree(dir);
  makeDirectories(dir + "/constant");
  // Named as blockforge.output names staging folders: .NAME.<pid>-<token>.staging. This
  // process's own are stale (one process writes one target at a time); pid 1 runs.
  const std::string stale = dir + "/constant/.polyMesh." + std::to_string(::getpid()) + "-0badc0de.staging";
  const std::string running = dir + "/constant/.polyMesh.1-0badc0de.staging";
  const std::string unrelated = dir + "/constant/.polyMesh.notes";
  for (const std::string& path : { stale, running, unrelated })
    makeDirectories(path);
  writeFoamCase(grid, dir + "/box.foam");
  struct stat status;
  EXPECT_NE(::stat(stale.c_str(), &status), 0);
  EXPECT_EQ(::stat(running.c_str(), &status), 0);
  EXPECT_EQ(::stat(unrelated.c_str(), &status), 0);
  EXPECT_EQ(::stat((dir + "/constant/polyMesh/faces").c_str(), &status), 0);
}
