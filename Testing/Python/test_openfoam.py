"""OpenFOAM's own checkMesh on the polyMesh BlockForge writes, for every template and
every machine of Data/ at default parameters (plain Python: `import blockforge`, with
OpenFOAM from the Debian package `openfoam`): the passage grids both as users get them
(`mesh_template`'s default: the BlockOptimizer moves the control points first; cases
named *_optimized) and as the template places them (optimize=False).

Asserted: "Mesh OK"; periodic pairs written as cyclic patches whose points match under
the rotation; under -allGeometry -allTopology no failed check except the ones listed per
template (thin cells near walls and axes: the cell determinant); the per-cell
non-orthogonality and skewness checkMesh writes (-writeFields) equal GridQuality's.
"""
import os
import re
import shutil
import unittest

import numpy as np

import blockforge
from blockforge import writers
from vtkmodules.numpy_interface import dataset_adapter as dsa

import bftest
from bftest import DISTRIBUTOR_INF, ROTOR37_INF, SOURCE
import foamtools


def template(name):
    return os.path.join(SOURCE, "Templates", name + ".yaml")


MACHINES = (("distributor", DISTRIBUTOR_INF), ("rotor37", ROTOR37_INF),
            ("compressor", os.path.join(SOURCE, "Data", "compressor", "rotor.inf")),
            ("turbine", os.path.join(SOURCE, "Data", "turbine", "Info.txt")))

# (case name, template, input, optimize) for every template and every machine of Data/;
# the passages also optimized (the templates without inputs have no control points).
CASES = [("cylinder_in_box", "cylinder_in_box", None, False),
         ("annular_sector", "annular_sector", None, False),
         ("wedge_sector", "wedge_sector", None, False)] + [
    (f"{name}_{machine}{'_optimized' if optimize else ''}", name, inf, optimize)
    for optimize in (False, True)
    for name in ("axial_passage_h", "axial_passage_oh")
    for machine, inf in MACHINES]

# Checks that -allGeometry -allTopology may fail, and why (the grid, not the writer).
ALLOWED_FAILURES = {
    # The template asks for them (its header): 20 of the 60 prisms on the axis, in the
    # bottom and top layers, are slivers (aspect ratio 24-32).
    "wedge_sector": {"determinant"},
    # Thin cells on the blade (O-grid expansion k_o towards the wall, aspect ratio up to
    # 45). The O-grid's cells along the blade are graded (issue 8: `match`, `ends`,
    # `project_from`), so the interpolation weights and volume ratios that failed where the
    # edge blocks met the side blocks pass.
    "axial_passage_oh_distributor": {"determinant"},
    "axial_passage_oh_rotor37": {"determinant"},
    "axial_passage_oh_turbine": {"determinant"},
    # The transonic compressor's sharp edges keep their O corners on the tip: the edge
    # blocks are fans whose blade cells are the feet of their outer cells on an edge of
    # 0.8 micrometre, which leaves concave cells and faces whose decomposition tets are
    # poor (the template's grid, reported; every cell is valid: Mesh OK).
    # Since the blade sides' nodes are the feet of their O arcs' nodes (issue 8, stop 13)
    # the sides' first cells by a sharp tip are feet on the fan too, then the flank's:
    # in-block jumps that fail interpolation weights (48 faces placed, 26 optimized).
    "axial_passage_oh_compressor": {"determinant", "concave", "face tets",
                                    "interpolation weight"},
    # Optimized: the same thin wall cells, and on the compressor the fans' concave cells;
    # the turbine's optimized trailing-edge corner leaves 12 faces (O_te and O_a, feet by
    # the cap) under the interpolation weight since stop 13.
    "axial_passage_oh_distributor_optimized": {"determinant"},
    "axial_passage_oh_rotor37_optimized": {"determinant"},
    "axial_passage_oh_turbine_optimized": {"determinant", "interpolation weight"},
    "axial_passage_oh_compressor_optimized": {"determinant", "concave", "face tets",
                                              "interpolation weight"},
    # Every H grid passes, optimized or not. The turbine's blade side b meets the
    # circumferential trailing-edge line at 10-12 degrees (block AR): its wall cells there
    # failed with 4 cells (aspect ratio 11-13; optimized: 3 at the outlet, 15-25) until the
    # H template made its hub and shroud cells half the mean spanwise cell (span_wall).
}


# No more concave cells than these where concave cells are allowed: the compressor's fans'
# wall cells on its sharp tips (their blade faces are the feet of the fan's outer nodes on a
# tip a micrometre long, so a face's plane warped by 1e-4 rad along the span passes the
# centre of the blade face: O_le and O_te, j = 0). 134 placed, 94 optimized since the sides'
# blade nodes are the feet of their O arcs' (issue 8, stop 13; 97 and 22 before).
CONCAVE_CELLS_AT_MOST = {"axial_passage_oh_compressor": 134,
                         "axial_passage_oh_compressor_optimized": 94}

# GridQuality follows OpenFOAM v1912's face centres (triangle fan weighted by area), so
# per cell it agrees with checkMesh to round-off: about 1e-10 degrees on the passage grids,
# optimized or not, 1.5e-6 degrees where the angle is near zero (acos near 1 keeps only
# about 1e-8 rad). The issue asks for 1e-3 degrees; the bound leaves room for round-off
# only. Weighting the fan triangles by their area projected on the face normal (later
# OpenFOAM.org versions) instead moves a cell's non-orthogonality by up to 0.037 degrees on
# the optimized distributor (1.2e-3 on the template's grids), which this test would catch.
# The periodic faces agree as well: with `transform rotational` and the axis and centre,
# OpenFOAM v1912 takes the rotation from the face centres furthest from the axis on both
# sides (cyclicPolyPatch::calcTransforms), which is exact for sides that are exact
# rotations of each other, as ours are.
CELL_QUALITY_BOUND = 1e-5

# The OpenFOAM patch type of every patch the writer writes, from the template's types
# (wall -> wall, inlet/outlet/patch -> patch, symmetry -> symmetry, periodic -> cyclic).
PASSAGE_PATCH_TYPES = {"hub": "wall", "shroud": "wall", "blade": "wall", "inlet": "patch",
                       "outlet": "patch", "periodic_low": "cyclic", "periodic_high": "cyclic"}
PATCH_TYPES = {
    "cylinder_in_box": {"cylinder": "wall", "inlet": "patch", "outlet": "patch",
                        "top": "symmetry", "bottom": "symmetry", "front": "patch",
                        "back": "patch"},
    "annular_sector": {"inner": "wall", "outer": "wall", "bottom": "wall", "top": "wall",
                       "periodic_low": "cyclic", "periodic_high": "cyclic"},
    "wedge_sector": {"wall": "wall", "bottom": "wall", "top": "wall", "side_low": "symmetry",
                     "side_high": "symmetry"},
}
# The case also written as ASCII and checked by checkMesh (the same figures as binary).
ASCII_CASE = "axial_passage_oh_distributor"


def patch_types(boundary):
    """{patch name: OpenFOAM type} of a polyMesh boundary file."""
    return dict(re.findall(r"\n\s*(\w+)\s*\{\s*type\s+(\w+);", boundary))


def block_cell_array(grid, name):
    """A cell array of every block, concatenated in block order (OpenFOAM's cell order)."""
    return np.concatenate([np.array(dsa.WrapDataObject(block).CellData[name])
                           for block in bftest.leaves(grid)])


class CheckMeshTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.results = {}
        for name, template_name, inf, optimize in CASES:
            quality = blockforge.mesh_template(template(template_name), input_file=inf,
                                               optimize=optimize)
            grid = quality.GetOutputDataObject(0)
            case = bftest.output_path(os.path.join("openfoam", name))
            shutil.rmtree(case, ignore_errors=True)
            writers.write_solver_grid(grid, os.path.join(case, name + ".foam"))
            status, plain = foamtools.run_foam(["checkMesh"], case)
            status_all, full = foamtools.run_foam(
                ["checkMesh", "-allGeometry", "-allTopology", "-writeFields",
                 "(nonOrthoAngle skewness)"], case)
            cls.results[name] = {
                "plain": foamtools.check_mesh_summary(plain), "plain_text": plain,
                "all": foamtools.check_mesh_summary(full), "all_text": full,
                "case": case, "grid": grid, "boundary":
                open(os.path.join(case, "constant", "polyMesh", "boundary")).read()}
            if name == ASCII_CASE:
                ascii_case = case + "_ascii"
                shutil.rmtree(ascii_case, ignore_errors=True)
                writers.write_solver_grid(grid, os.path.join(ascii_case, name + ".foam"),
                                          binary=False)
                status, text = foamtools.run_foam(["checkMesh"], ascii_case)
                cls.ascii = {"summary": foamtools.check_mesh_summary(text), "text": text,
                             "case": ascii_case}

    def test_mesh_ok(self):
        for name, *_ in CASES:
            with self.subTest(case=name):
                result = self.results[name]["plain"]
                self.assertTrue(result["ok"], self.results[name]["plain_text"][-3000:])
                self.assertEqual(result["failed"], [])
                self.assertEqual(result["cells"], sum(
                    b.GetNumberOfCells() for b in bftest.leaves(self.results[name]["grid"])))

    def test_patch_types(self):
        for name, template_name, *_ in CASES:
            with self.subTest(case=name):
                expected = PATCH_TYPES.get(template_name, PASSAGE_PATCH_TYPES)
                self.assertEqual(patch_types(self.results[name]["boundary"]), expected)

    def test_ascii_case_is_the_same_mesh(self):
        """The ASCII polyMesh passes checkMesh with the binary one's figures."""
        with open(os.path.join(self.ascii["case"], "constant", "polyMesh", "faces")) as stream:
            self.assertIn("format      ascii;", stream.read(1000))
        ascii_summary = dict(self.ascii["summary"])
        binary_summary = dict(self.results[ASCII_CASE]["plain"])
        self.assertTrue(ascii_summary["ok"], self.ascii["text"][-3000:])
        for key in ("cells", "hexahedra", "prisms", "non_orthogonality", "skewness",
                    "aspect_ratio", "coupled_ok", "failed"):
            self.assertEqual(ascii_summary[key], binary_summary[key], key)

    def test_wedge_cells_are_prisms(self):
        result = self.results["wedge_sector"]["plain"]
        self.assertEqual(result["prisms"], 60)  # n_around x n_height cells on the axis
        self.assertEqual(result["hexahedra"], 1140)
        # the thin prisms its header names: 20, no other cell
        self.assertEqual(self.results["wedge_sector"]["all"]["determinant_cells"], 20)

    def test_periodic_pairs_are_matched_cyclics(self):
        for name, *_ in CASES:
            boundary = self.results[name]["boundary"]
            if "periodic" not in boundary:
                continue
            with self.subTest(case=name):
                self.assertEqual(len(re.findall(r"type\s+cyclic;", boundary)), 2)
                self.assertIn("transform       rotational;", boundary)
                self.assertTrue(self.results[name]["all"]["coupled_ok"],
                                self.results[name]["all_text"][-3000:])

    def test_all_checks(self):
        for name, *_ in CASES:
            with self.subTest(case=name):
                failed = self.results[name]["all"]["failed"]
                kinds = set()
                for line in failed:
                    if "determinant" in line:
                        kinds.add("determinant")
                    elif "interpolation weight" in line:
                        kinds.add("interpolation weight")
                    elif "Concave cells" in line:
                        kinds.add("concave")
                        count = int(re.search(r"(\d+)\s*$", line).group(1))
                        self.assertLessEqual(count, CONCAVE_CELLS_AT_MOST[name], line)
                    elif "small volume ratio" in line:
                        kinds.add("volume ratio")
                    elif "face tets" in line:
                        kinds.add("face tets")
                    else:
                        kinds.add(line)
                self.assertLessEqual(kinds, ALLOWED_FAILURES.get(name, set()), failed)

    def test_cell_quality_equals_grid_quality(self):
        for name, *_ in CASES:
            with self.subTest(case=name):
                result = self.results[name]
                constant = os.path.join(result["case"], "constant")
                theirs = foamtools.read_cell_field(os.path.join(constant, "nonOrthoAngle"))
                ours = block_cell_array(result["grid"], "NonOrthogonality")
                self.assertEqual(theirs.shape, ours.shape)
                self.assertLess(np.max(np.abs(theirs - ours)), CELL_QUALITY_BOUND)
                theirs = foamtools.read_cell_field(os.path.join(constant, "skewness"))
                ours = block_cell_array(result["grid"], "Skewness")
                difference = np.abs(theirs - ours)
                self.assertLess(np.max(difference), CELL_QUALITY_BOUND, int(np.argmax(difference)))

    def test_compressor_fans_as_prisms(self):
        """The compressor with o_fan_prisms: 1: at its sharp edges both feet of each fan
        (edge blocks O_le, O_te) are one point on the tip, the fan's blade arc collapses into
        it, and the writer writes the fans' wall cells as prisms. checkMesh finds no concave
        cell (97 placed, 22 optimized by default); optimized, the thin-wall determinant is
        the only failed check; checkMesh and GridQuality agree cell by cell. GridQuality's
        MinAngle of a prism is its apex on the tip: the angle there between the radial lines
        of the fan's neighbouring nodes (10.8 degrees placed, where the default grid's
        hexahedra with blade faces of 1e-7 m show 75)."""
        fans = ("O_le", "O_te")
        for optimize in (False, True):
            with self.subTest(optimize=optimize):
                grid = blockforge.mesh_template(
                    template("axial_passage_oh"), input_file=MACHINES[2][1], optimize=optimize,
                    parameters={"o_fan_prisms": 1}).GetOutputDataObject(0)
                blocks = foamtools.blocks_of(grid)
                for fan in fans:
                    block, dims = blocks[fan]
                    points = np.array(dsa.WrapDataObject(block).Points).reshape(
                        dims[2], dims[1], dims[0], 3)
                    # the blade row of every layer is one point, bit for bit
                    self.assertTrue(np.all(points[:, 0] == points[:, 0, :1]), fan)
                case = bftest.output_path(os.path.join("openfoam", f"compressor_fan_prisms_{int(optimize)}"))
                shutil.rmtree(case, ignore_errors=True)
                writers.write_solver_grid(grid, os.path.join(case, "fans.foam"))
                status, plain = foamtools.run_foam(["checkMesh"], case)
                self.assertTrue(foamtools.check_mesh_summary(plain)["ok"], plain[-3000:])
                status, text = foamtools.run_foam(
                    ["checkMesh", "-allGeometry", "-allTopology", "-writeFields",
                     "(nonOrthoAngle skewness)"], case)
                summary = foamtools.check_mesh_summary(text)
                ni, _, nk = blocks["O_le"][1]
                prisms = 2 * (ni - 1) * (nk - 1)  # the wall cells of both fans
                self.assertEqual(summary["prisms"], prisms)
                cells = sum(b.GetNumberOfCells() for b in bftest.leaves(grid))
                self.assertEqual(summary["hexahedra"], cells - prisms)
                failed = summary["failed"]
                self.assertFalse([line for line in failed if "Concave" in line], failed)
                # left (stop 13): the thin wall cells' determinant; the interpolation weights
                # of the side cells next to the fans (issue 8's matched O arcs: the sides'
                # first cells on the blade are the fans' feet); placed, also face tets in
                # D_M's corner cells by the outlet (the fans' small cells carried there by
                # `match`)
                allowed = {"determinant", "interpolation weight"}
                if not optimize:
                    allowed.add("face tets")
                for line in failed:
                    self.assertTrue(any(kind in line and kind in allowed
                                        for kind in ("determinant", "face tets",
                                                     "interpolation weight")), line)
                constant = os.path.join(case, "constant")
                for field, array in (("nonOrthoAngle", "NonOrthogonality"), ("skewness", "Skewness")):
                    theirs = foamtools.read_cell_field(os.path.join(constant, field))
                    ours = block_cell_array(grid, array)
                    self.assertLess(np.max(np.abs(theirs - ours)), CELL_QUALITY_BOUND, field)
                # A prism's smallest angle is the apex of its triangles: on the tip, between
                # the radial lines to the fan's neighbouring nodes of the first layer.
                apex = []
                for fan in fans:
                    block, dims = blocks[fan]
                    points = np.array(dsa.WrapDataObject(block).Points).reshape(
                        dims[2], dims[1], dims[0], 3)
                    radial = points[:, 1] - points[:, 0]
                    radial /= np.linalg.norm(radial, axis=-1)[..., None]
                    angle = np.degrees(np.arccos(np.clip((radial[:, 1:] * radial[:, :-1]).sum(-1), -1, 1)))
                    apex.append(np.minimum(angle[1:], angle[:-1]).ravel())  # per cell: its two layers
                self.assertAlmostEqual(float(foamtools.row_cells(grid, fans, "MinAngle").min()),
                                       float(np.concatenate(apex).min()), delta=1e-9)
                self.assertGreater(float(foamtools.row_cells(grid, fans, "ScaledJacobian").min()), 0.8)


if __name__ == "__main__":
    bftest.run_tests()
