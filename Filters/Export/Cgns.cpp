#include "Cgns.h"

#include "StagedOutput.h"

#include <cgnslib.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace blockforge
{
namespace exporting
{
namespace
{
/// Dimensional exponents (mass, length, time, temperature, angle) of lengths and angles.
const float LengthExponents[5] = { 0.0f, 1.0f, 0.0f, 0.0f, 0.0f };
const float AngleExponents[5] = { 0.0f, 0.0f, 0.0f, 0.0f, 1.0f };

/// CGNS names have at most 32 characters.
std::string cgnsName(const std::string& text)
{
  return text.size() > 32 ? text.substr(0, 32) : text;
}

/// Closes the file on every path; errors become exceptions naming `path`.
class CgnsFile
{
public:
  CgnsFile(const std::string& staging, const std::string& target)
    : Target(target)
    , Staging(staging)
  {
    check(cg_set_file_type(CG_FILE_HDF5));
    check(cg_open(staging.c_str(), CG_MODE_WRITE, &Number));
    Open = true;
  }
  ~CgnsFile()
  {
    if (Open)
    {
      cg_close(Number);
    }
  }
  void check(int status) const
  {
    if (status != CG_OK)
    {
      // HDF5 says only that a write failed: add why (a full disk, the file-size limit).
      const int error = errno;
      const std::string why = writeFailureReason(Staging, error);
      throw std::runtime_error("could not write " + Target + ": " + cg_get_error() +
        (why.empty() ? std::string() : " (" + why + ")"));
    }
  }
  void close()
  {
    Open = false;
    check(cg_close(Number));
  }
  int number() const { return Number; }

private:
  std::string Target, Staging;
  int Number = -1;
  bool Open = false;
};

CGNS_ENUMT(BCType_t) bcType(const std::string& templateType)
{
  if (templateType == "wall")
    return CGNS_ENUMV(BCWall);
  if (templateType == "inlet")
    return CGNS_ENUMV(BCInflow);
  if (templateType == "outlet")
    return CGNS_ENUMV(BCOutflow);
  if (templateType == "symmetry" || templateType == "symmetryPlane")
    return CGNS_ENUMV(BCSymmetryPlane);
  return CGNS_ENUMV(BCTypeUserDefined);
}

/// 1-based (i, j, k) of node (a, b) of a block face.
std::array<cgsize_t, 3> faceIndex(const GridBlock& block, int face, int a, int b)
{
  const std::array<int, 2> directions = model::faceDirections(face);
  std::array<cgsize_t, 3> index{};
  index[face / 2] = face % 2 == 0 ? 1 : block.nodes[face / 2];
  index[directions[0]] = a + 1;
  index[directions[1]] = b + 1;
  return index;
}

/// PointRange of a whole block face: begin (i, j, k), end (i, j, k), 1-based.
std::array<cgsize_t, 6> faceRange(const GridBlock& block, int face)
{
  const std::array<int, 2> n = faceNodeCounts(block, face);
  const std::array<cgsize_t, 3> first = faceIndex(block, face, 0, 0);
  const std::array<cgsize_t, 3> last = faceIndex(block, face, n[0] - 1, n[1] - 1);
  return { first[0], first[1], first[2], last[0], last[1], last[2] };
}

/**
 * The 1-to-1 connection of `match.from` (this zone) to `match.to` (the donor): range,
 * donor range and the transform vector (index direction d of this zone runs along
 * donor direction |t[d]| - 1, reversed when t[d] < 0).
 */
void writeConnection(const CgnsFile& file, int base, const ExportGrid& grid,
  const FaceMatch& match, const std::vector<int>& zones, int& connection)
{
  const GridBlock& here = grid.blocks[match.from.block];
  const GridBlock& there = grid.blocks[match.to.block];
  const std::array<int, 2> n = faceNodeCounts(here, match.from.face);
  const std::array<int, 2> m = faceNodeCounts(there, match.to.face);
  const std::array<cgsize_t, 6> range = faceRange(here, match.from.face);
  const std::array<int, 2> first = mapFaceNode(match.transform, 0, 0, m[0], m[1]);
  const std::array<int, 2> last = mapFaceNode(match.transform, n[0] - 1, n[1] - 1, m[0], m[1]);
  const std::array<cgsize_t, 3> donorFirst = faceIndex(there, match.to.face, first[0], first[1]);
  const std::array<cgsize_t, 3> donorLast = faceIndex(there, match.to.face, last[0], last[1]);
  const std::array<cgsize_t, 6> donorRange{ donorFirst[0], donorFirst[1], donorFirst[2],
    donorLast[0], donorLast[1], donorLast[2] };

  const std::array<int, 2> hereDirections = model::faceDirections(match.from.face);
  const std::array<int, 2> thereDirections = model::faceDirections(match.to.face);
  const FaceTransform t = match.transform;
  int transform[3];
  // In-face directions: a -> a' (or b' when swapped), b -> b' (or a').
  transform[hereDirections[0]] = t.swap() ? (t.flipB() ? -1 : 1) * (thereDirections[1] + 1)
                                          : (t.flipA() ? -1 : 1) * (thereDirections[0] + 1);
  transform[hereDirections[1]] = t.swap() ? (t.flipA() ? -1 : 1) * (thereDirections[0] + 1)
                                          : (t.flipB() ? -1 : 1) * (thereDirections[1] + 1);
  // Normal: leaving this zone through a max face enters the donor through a min face in
  // the donor's increasing direction, and the other way round.
  const bool sameSide = match.from.face % 2 == match.to.face % 2;
  transform[match.from.face / 2] = (sameSide ? -1 : 1) * (match.to.face / 2 + 1);

  const std::string name = cgnsName(std::string(model::faceName(match.from.face)) + "_" +
    there.name);
  file.check(cg_1to1_write(file.number(), base, zones[match.from.block], name.c_str(),
    cgnsName(there.name).c_str(), range.data(), donorRange.data(), transform, &connection));
}
} // namespace

std::string cgnsBoundaryType(const std::string& templateType)
{
  return BCTypeName[bcType(templateType)];
}

void writeCgns(const ExportGrid& grid, const std::string& path,
  const std::function<void(double)>& progress)
{
  StagedOutput staged(path, StagedOutput::Kind::File);
  {
    CgnsFile file(staged.path(), path);
    const int fn = file.number();
    int base = 0;
    file.check(cg_base_write(fn, cgnsName(grid.name.empty() ? "Base" : grid.name).c_str(), 3, 3, &base));
    // Dimensional data in SI units; periodic angles in radians.
    file.check(cg_goto(fn, base, "end"));
    file.check(cg_dataclass_write(CGNS_ENUMV(Dimensional)));
    file.check(cg_units_write(CGNS_ENUMV(Kilogram), CGNS_ENUMV(Meter), CGNS_ENUMV(Second),
      CGNS_ENUMV(Kelvin), CGNS_ENUMV(Radian)));

    // One family per patch, with the BC type of its template type.
    for (const GridPatch& patch : grid.patches)
    {
      int family = 0, familyBc = 0;
      file.check(cg_family_write(fn, base, cgnsName(patch.name).c_str(), &family));
      if (patch.partner < 0)
      {
        file.check(cg_fambc_write(fn, base, family, "FamBC", bcType(patch.type), &familyBc));
      }
    }

    std::vector<int> zones(grid.blocks.size());
    std::vector<double> coordinates;
    for (std::size_t b = 0; b < grid.blocks.size(); ++b)
    {
      const GridBlock& block = grid.blocks[b];
      const cgsize_t size[9] = { block.nodes[0], block.nodes[1], block.nodes[2],
        block.nodes[0] - 1, block.nodes[1] - 1, block.nodes[2] - 1, 0, 0, 0 };
      file.check(cg_zone_write(fn, base, cgnsName(block.name).c_str(), size,
        CGNS_ENUMV(Structured), &zones[b]));
      const std::size_t count = static_cast<std::size_t>(block.nodeCount());
      coordinates.resize(count);
      const char* names[3] = { "CoordinateX", "CoordinateY", "CoordinateZ" };
      for (int c = 0; c < 3; ++c)
      {
        for (std::size_t p = 0; p < count; ++p)
        {
          coordinates[p] = block.xyz[3 * p + c];
        }
        int index = 0;
        file.check(cg_coord_write(fn, base, zones[b], CGNS_ENUMV(RealDouble), names[c],
          coordinates.data(), &index));
        file.check(cg_goto(fn, base, "Zone_t", zones[b], "GridCoordinates_t", 1, "DataArray_t",
          index, "end"));
        file.check(cg_exponents_write(CGNS_ENUMV(RealSingle), LengthExponents));
      }
      if (progress)
      {
        progress(0.9 * double(b + 1) / grid.blocks.size());
      }
    }

    // Boundary conditions: one BC per patch face, its family naming the patch.
    for (const GridPatch& patch : grid.patches)
    {
      if (patch.partner >= 0)
      {
        continue;
      }
      for (const model::BlockFace& face : patch.faces)
      {
        if (grid.collapsedFaces[face.block][face.face])
        {
          continue;
        }
        const std::array<cgsize_t, 6> range = faceRange(grid.blocks[face.block], face.face);
        const std::string name = cgnsName(patch.name + "_" + model::faceName(face.face));
        int bc = 0;
        file.check(cg_boco_write(fn, base, zones[face.block], name.c_str(),
          CGNS_ENUMV(FamilySpecified), CGNS_ENUMV(PointRange), 2, range.data(), &bc));
        file.check(cg_goto(fn, base, "Zone_t", zones[face.block], "ZoneBC_t", 1, "BC_t", bc, "end"));
        file.check(cg_famname_write(cgnsName(patch.name).c_str()));
      }
    }

    // Interfaces, in both zones.
    for (const FaceMatch& match : grid.interfaces)
    {
      int connection = 0;
      writeConnection(file, base, grid, match, zones, connection);
      writeConnection(file, base, grid, FaceMatch{ match.to, match.from, inverse(match.transform) },
        zones, connection);
    }
    // Periodic pairs: each face's connection to its partner, with the rotation that
    // takes this zone's points to the donor's.
    for (const GridPatch& patch : grid.patches)
    {
      if (patch.partner < 0)
      {
        continue;
      }
      const float centre[3] = { float(patch.axisPoint.x()), float(patch.axisPoint.y()),
        float(patch.axisPoint.z()) };
      const Vec3 angles = patch.angle * patch.axis.normalized();
      const float angle[3] = { float(angles.x()), float(angles.y()), float(angles.z()) };
      const float translation[3] = { 0.0f, 0.0f, 0.0f };
      for (const FaceMatch& match : patch.images)
      {
        int connection = 0;
        writeConnection(file, base, grid, match, zones, connection);
        file.check(cg_1to1_periodic_write(fn, base, zones[match.from.block], connection, centre,
          angle, translation));
        // RotationCenter, RotationAngle, Translation: their units.
        for (int array = 1; array <= 3; ++array)
        {
          file.check(cg_goto(fn, base, "Zone_t", zones[match.from.block],
            "ZoneGridConnectivity_t", 1, "GridConnectivity1to1_t", connection,
            "GridConnectivityProperty_t", 1, "Periodic_t", 1, "DataArray_t", array, "end"));
          file.check(cg_exponents_write(
            CGNS_ENUMV(RealSingle), array == 2 ? AngleExponents : LengthExponents));
        }
      }
    }
    file.close();
  }
  staged.publish();
  if (progress)
  {
    progress(1.0);
  }
}
} // namespace exporting
} // namespace blockforge
