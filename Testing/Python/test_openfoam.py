"""OpenFOAM's own checkMesh on the polyMesh BlockForge writes, for every template and
every machine of Data/ at default parameters (plain Python: `import blockforge`, with
OpenFOAM from the Debian package `openfoam`): the passage grids both as users get them
(`mesh_template`'s default: the BlockOptimizer moves the control points first; cases
named *_optimized) and as the template places them (optimize=False).

Asserted: "Mesh OK"; periodic pairs written as cyclic patches whose points match under
the rotation; under -allGeometry -allTopology no failed check except the ones listed per
template (thin cells near walls and axes: the cell determinant); the per-cell
non-orthogonality, skewness and cell determinant checkMesh writes (-writeFields) equal
GridQuality's, and so does the number of cells under checkMesh's determinant limit.
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
    # 45), and H cells, at most H_DETERMINANT_AT_MOST (test_determinant_cells_by_block):
    # none on the optimized grids (stop 19), 2 / 0 / 5 / 0 placed. The O-grid's cells along the blade are graded (issue 8: `match`, `ends`,
    # `project_from`), so the interpolation weights and volume ratios that failed where the
    # edge blocks met the side blocks pass.
    "axial_passage_oh_distributor": {"determinant"},
    "axial_passage_oh_rotor37": {"determinant"},
    "axial_passage_oh_turbine": {"determinant"},
    # The transonic compressor's sharp edges (4-9 degree wedges) keep their O corners on the
    # tip: the edge blocks are fans, their feet one point on the tip and their wall cells
    # prisms (o_fan_prisms, the default since stop 14: no concave cell; as hexahedra whose
    # blade faces were the feet on a tip 0.8 micrometre long, 134 placed and 94 optimized).
    # Placed, the determinant alone since stop 16: the wake block D_M's outlet edge starts
    # from cells at most its mean cell at a sharp trailing edge (`at_most: wake_cap`); its
    # outlet cells were 0.08 mm across between end cells of 1 mm (its three outlet edges
    # matched to the geometric mean of their mean cells), 5 mm long and high, faces warped
    # along the span: 20 faces failed face tets at density 1.
    "axial_passage_oh_compressor": {"determinant"},
    # Optimized: the same thin wall cells, nothing else. The optimizer refuses a
    # configuration that fails more of checkMesh's interpolation-weight or volume-ratio
    # faces than the template placed (Filters/Model/Optimize/FaceChecks.h). Before, it moved
    # the compressor's fan corners along the O curve off the tip's arc while their feet
    # stayed on the tip (36 faces between O_le and O_b, O_a and O_te, and inside O_a, whose
    # first outer nodes then projected onto the tip), and the turbine's corner oa_r onto the
    # cap corner's fan (12 faces, one per spanwise layer, between O_a's wall cells i = 15
    # and 16, a wall cell under a 19th of its neighbour).
    "axial_passage_oh_distributor_optimized": {"determinant"},
    "axial_passage_oh_rotor37_optimized": {"determinant"},
    "axial_passage_oh_turbine_optimized": {"determinant"},
    "axial_passage_oh_compressor_optimized": {"determinant"},
    # Every H grid passes, optimized or not. The turbine's blade side b meets the
    # circumferential trailing-edge line at 10-12 degrees (block AR): its wall cells there
    # failed with 4 cells (aspect ratio 11-13; optimized: 3 at the outlet, 15-25) until the
    # H template made its hub and shroud cells half the mean spanwise cell (span_wall).
}


# No more failed faces than these where a check other than the determinant may fail
# (none left since stop 16: the compressor's face tets are gone).
FAILED_AT_MOST = {}

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

# checkMesh's cell determinant (cellDeterminant) against GridQuality's CellDeterminant:
# |det T| / 8 with T = sum (S_f/a)(S_f/a)^T over the internal and cyclic faces. Both take
# the same face area vectors to round-off (the fan of OpenFOAM v1912; a prism's triangle
# by OpenFOAM's 3-point formula, by GridQuality as a quad with a repeated corner) and sum
# the faces in another order, so T's entries, of order 1, differ by a few 1e-16; the
# determinant, a sum of triple products of order 1 to 10, then differs by some 1e-15
# absolute, a relative error that grows as the determinant falls. Measured (stop 17): at
# most 6.8e-15 absolute on every case; relative 3.9e-10 on the compressor's OH grid (a
# cell of 8e-6), 4.6e-11 optimized, 5.0e-12 on Rotor 37, under 2e-14 on the H grids
# and the three small templates. Hence relative 1e-9, plus 1e-13 absolute for cells far
# under checkMesh's limit (a determinant of 1e-7 and less, where only the count matters).
DETERMINANT_RELATIVE = 1e-9
DETERMINANT_ABSOLUTE = 1e-13
# checkMesh fails a cell whose determinant is under this (checkCellDeterminant's warnDet).
DETERMINANT_LIMIT = 1e-3

# Cells under checkMesh's determinant limit outside the O-grid (the H blocks of the OH
# passages), at most, at density 1 (stop 17, Benchmark/checkmesh.py's split). Issue 10
# allows the determinant only where a template asks for thin wall cells: the O-grid's
# layers round the blade (k_o towards the wall). The H cells left are those matched to the
# O-grid's outer cell across the interface (M_L / M_R beside the sides, the rows of U_M /
# D_M at the O-grid: as thin as that cell, issue 8's ratio about 1.5), on the hub and
# shroud, where the wall face leaves the cell one face short in the span, and at the inlet
# and outlet of U_M / D_M. Stop 16 had 341 / 86 / 913 / 63 placed and 127 / 66 / 340 / 51
# optimized; held here so that they do not grow back while issue 10 stays open. Since the
# optimizer refuses trials with more failing cells (all blocks) than its start (stop 17,
# FaceChecks), its searches take other paths: optimized H cells 41 / 34 / 146 / 7 -> 49 /
# 31 / 129 / 8 (all cells 474 / 311 / 1036 / 388 -> 483 / 309 / 925 / 355, placed 638 /
# 309 / 942 / 362). Stop 18: U_M's inlet edge and the wake edge capped at their mean cell
# (`in_at_most`, `out_at_most_round`), 12 cells up- and downstream, and the optimizer's
# second search for fewer failing cells away from walls: placed 78 / 24 / 180 / 16,
# optimized 24 / 4 / 67 / 3. Stop 19: a thicker O-grid outer cell (`k_o` 1.35, `n_o` 5) with
# the periodic lines following it (`period_follow` 1.28), end-wall layers (`span_wall` 0.5)
# and, at sharp staggered edges, a wider O-grid (`o_width_sharp`): placed 2 / 0 / 5 / 0
# (the distributor's M_R column beside O_b at the hub, det 9.5e-4; the compressor's M_L
# rows by oa_f at the shroud, 14-19 deg to the blade), optimized (the command line's
# default) none.
H_DETERMINANT_AT_MOST = {
    "axial_passage_oh_distributor": 2, "axial_passage_oh_rotor37": 0,
    "axial_passage_oh_compressor": 5, "axial_passage_oh_turbine": 0,
    "axial_passage_oh_distributor_optimized": 0, "axial_passage_oh_rotor37_optimized": 0,
    "axial_passage_oh_compressor_optimized": 0, "axial_passage_oh_turbine_optimized": 0,
}

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
                 "(nonOrthoAngle skewness cellDeterminant)"], case)
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
                    elif "small volume ratio" in line:
                        kinds.add("volume ratio")
                    elif "face tets" in line:
                        kinds.add("face tets")
                    else:
                        kinds.add(line)
                    for kind, most in FAILED_AT_MOST.get(name, {}).items():
                        if kind in line:
                            count = re.search(r"(\d+)\s*$", line) or re.search(r":\s*(\d+)", line)
                            self.assertLessEqual(int(count.group(1)), most, line)
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

    def test_cell_determinant_equals_grid_quality(self):
        """checkMesh's cellDeterminant field (-writeFields) is GridQuality's CellDeterminant
        cell for cell, and the cells under 1e-3 are the cells checkMesh counts as failing."""
        for name, *_ in CASES:
            with self.subTest(case=name):
                result = self.results[name]
                theirs = foamtools.read_cell_field(
                    os.path.join(result["case"], "constant", "cellDeterminant"))
                ours = block_cell_array(result["grid"], "CellDeterminant")
                self.assertEqual(theirs.shape, ours.shape)
                difference = np.abs(theirs - ours)
                allowed = DETERMINANT_RELATIVE * np.abs(theirs) + DETERMINANT_ABSOLUTE
                worst = int(np.argmax(difference / allowed))
                self.assertTrue(np.all(difference <= allowed),
                                f"cell {worst}: checkMesh {theirs[worst]!r}, "
                                f"GridQuality {ours[worst]!r}")
                failing = result["all"]["determinant_cells"] or 0
                self.assertEqual(int(np.count_nonzero(ours < DETERMINANT_LIMIT)), failing)
                self.assertEqual(int(np.count_nonzero(theirs < DETERMINANT_LIMIT)), failing)
                # not vacuous: the cases span well over a decade of determinants
                self.assertLess(float(theirs.min()), 0.5)
                self.assertGreater(float(theirs.max()), 0.5)

    def test_determinant_cells_by_block(self):
        """Cells under checkMesh's determinant limit (GridQuality's CellDeterminant, equal to
        checkMesh's: test_cell_determinant_equals_grid_quality) outside the O-grid: none on
        the grids without one but the wedge's 20, at most H_DETERMINANT_AT_MOST on the OH
        passages' H blocks."""
        for name, *_ in CASES:
            with self.subTest(case=name):
                grid = self.results[name]["grid"]
                failing = {block_name: int(np.count_nonzero(
                    np.array(dsa.WrapDataObject(block).CellData["CellDeterminant"]) < DETERMINANT_LIMIT))
                    for block_name, (block, _) in foamtools.blocks_of(grid).items()}
                outside = {block_name: count for block_name, count in failing.items()
                           if count and not block_name.startswith("O_")}
                if name == "wedge_sector":
                    self.assertEqual(sum(outside.values()), 20, outside)
                else:
                    self.assertLessEqual(sum(outside.values()),
                                         H_DETERMINANT_AT_MOST.get(name, 0), outside)
                if name.startswith("axial_passage_oh"):
                    # the O-grid's wall layers hold the rest: most of the cells that fail
                    inside = sum(count for block_name, count in failing.items()
                                 if block_name.startswith("O_"))
                    self.assertGreater(inside, sum(outside.values()), failing)

    def test_compressor_fans_are_prisms(self):
        """The compressor at default parameters (o_fan_prisms 1): at its sharp edges both
        feet of each fan (edge blocks O_le, O_te) are one point on the tip, the fan's blade
        arc collapses into it, and the writer writes the fans' wall cells as prisms
        (checkMesh: no concave cell, test_all_checks). GridQuality's MinAngle of a prism
        leaves out its apex on the tip (the angle between the radial lines of the fan's
        neighbouring nodes: geometry, the fan's cells share the tip's turn): it is the
        smallest of the other corners, here the triangles' base angles and the side faces'."""
        fans = ("O_le", "O_te")
        for name in ("axial_passage_oh_compressor", "axial_passage_oh_compressor_optimized"):
            with self.subTest(case=name):
                grid = self.results[name]["grid"]
                summary = self.results[name]["all"]
                blocks = foamtools.blocks_of(grid)
                apex = []
                for fan in fans:
                    block, dims = blocks[fan]
                    points = np.array(dsa.WrapDataObject(block).Points).reshape(
                        dims[2], dims[1], dims[0], 3)
                    # the blade row of every layer is one point, bit for bit
                    self.assertTrue(np.all(points[:, 0] == points[:, 0, :1]), fan)
                    radial = points[:, 1] - points[:, 0]
                    length = np.linalg.norm(radial, axis=-1)
                    unit = radial / length[..., None]
                    angle = np.degrees(np.arccos(np.clip((unit[:, 1:] * unit[:, :-1]).sum(-1), -1, 1)))
                    apex.append(angle.ravel())
                ni, _, nk = blocks["O_le"][1]
                prisms = 2 * (ni - 1) * (nk - 1)  # the wall cells of both fans
                self.assertEqual(summary["prisms"], prisms)
                cells = sum(b.GetNumberOfCells() for b in bftest.leaves(grid))
                self.assertEqual(summary["hexahedra"], cells - prisms)
                fan_min = float(foamtools.row_cells(grid, fans, "MinAngle").min())
                # the apex (12.7-13.2 degrees placed, 7.9-23.2 optimized) is not the cells'
                # MinAngle (76.3 placed, 28.9 optimized: the optimizer's smallest is 26.5)
                self.assertLess(float(np.concatenate(apex).min()), 15.0)
                self.assertGreater(fan_min, 25.0)
                self.assertLess(fan_min, 80.0)
                # ScaledJacobian 0.96 placed, 0.48 optimized
                self.assertGreater(float(foamtools.row_cells(grid, fans, "ScaledJacobian").min()), 0.4)


if __name__ == "__main__":
    bftest.run_tests()
