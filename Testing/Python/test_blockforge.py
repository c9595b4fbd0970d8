"""Plain-Python tests of the BlockForge VTK classes through `import blockforge`.

Run by CTest with /usr/bin/python3 and PYTHONPATH pointing at the build tree.
"""
import contextlib
import io
import math
import os
import shutil
import unittest

import blockforge
import blockforge.output
from blockforge.__main__ import main as blockforge_main
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.util.misc import calldata_type
from vtkmodules.vtkCommonCore import VTK_STRING, vtkCommand
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet
from vtkmodules.vtkFiltersVerdict import vtkMeshQuality
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader, vtkXMLMultiBlockDataWriter
import numpy as np

import bftest
from bftest import (CYLINDER, DATA, DISTRIBUTOR_INF, OUTPUT, ROTOR37_INF, SOURCE,
                    ErrorCollector, named_leaves, node_array, points, rotate_z)

AXIAL_OH = os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml")


def pipeline(template, parameters=None, density=1.0):
    source = blockforge.vtkBlockTemplateSource()
    source.SetTemplateFile(template)
    for name, value in (parameters or {}).items():
        source.SetParameter(name, str(value))
    mesher = blockforge.vtkBlockMesher()
    mesher.SetInputConnection(source.GetOutputPort())
    mesher.SetDensityMultiplier(density)
    return source, mesher


class ClassesTest(unittest.TestCase):
    def test_classes_are_importable(self):
        for name in ("vtkBlockTemplateSource", "vtkBlockMesher", "vtkGridQuality"):
            self.assertTrue(hasattr(blockforge, name), name)
            instance = getattr(blockforge, name)()
            self.assertEqual(instance.GetClassName(), name)


class CylinderInBoxTest(unittest.TestCase):
    R, B, D = 0.5, 2.0, 1.0
    AROUND, RADIAL, DEPTH = 16, 16, 8

    def mesh(self, parameters=None, density=1.0):
        source, mesher = pipeline(CYLINDER, parameters, density)
        errors = ErrorCollector(source, mesher)
        mesher.Update()
        self.assertEqual(errors.messages, [])
        return source, mesher, mesher.GetOutput()

    def test_block_names_and_cell_count(self):
        _, _, grid = self.mesh()
        blocks = named_leaves(grid)
        self.assertEqual(len(blocks), 4)
        self.assertTrue(all(name for name, _ in blocks))
        cells = sum(block.GetNumberOfCells() for _, block in blocks)
        self.assertEqual(cells, 4 * self.AROUND * self.RADIAL * self.DEPTH)

    def test_wall_nodes_on_exact_radius(self):
        _, _, grid = self.mesh()
        xyz = np.concatenate([points(block) for _, block in named_leaves(grid)])
        radius = np.hypot(xyz[:, 0], xyz[:, 1])
        wall = radius < self.R * (1 + 1e-6)
        # 4 blocks, each with (AROUND+1) x (DEPTH+1) wall nodes
        self.assertEqual(int(wall.sum()), 4 * (self.AROUND + 1) * (self.DEPTH + 1))
        self.assertLess(np.max(np.abs(radius[wall] - self.R)) / self.R, 1e-9)
        # box walls at |x| = B or |y| = B, depth between 0 and D
        self.assertAlmostEqual(np.max(np.abs(xyz[:, :2])), self.B, places=12)
        self.assertAlmostEqual(xyz[:, 2].min(), 0.0, places=12)
        self.assertAlmostEqual(xyz[:, 2].max(), self.D, places=12)

    def test_parameter_override_and_density(self):
        _, _, grid = self.mesh({"R": 0.6, "n_around": "2*8"}, density=2.0)
        xyz = np.concatenate([points(block) for _, block in named_leaves(grid)])
        self.assertAlmostEqual(np.hypot(xyz[:, 0], xyz[:, 1]).min(), 0.6, places=12)
        cells = sum(block.GetNumberOfCells() for _, block in named_leaves(grid))
        self.assertEqual(cells, 4 * 32 * 32 * 16)

    def test_deterministic_bit_for_bit(self):
        _, _, first = self.mesh()
        _, _, second = self.mesh()
        for (_, a), (_, b) in zip(named_leaves(first), named_leaves(second)):
            self.assertEqual(points(a).tobytes(), points(b).tobytes())

    def test_model_survives_vtm_round_trip(self):
        source, mesher, direct = self.mesh()
        path = bftest.output_path("cylinder_preview.vtm")
        writer = vtkXMLMultiBlockDataWriter()
        writer.SetInputConnection(source.GetOutputPort())
        writer.SetFileName(path)
        self.assertEqual(writer.Write(), 1)
        reader = vtkXMLMultiBlockDataReader()
        reader.SetFileName(path)
        remesher = blockforge.vtkBlockMesher()
        remesher.SetInputConnection(reader.GetOutputPort())
        errors = ErrorCollector(remesher)
        remesher.Update()
        self.assertEqual(errors.messages, [])
        reloaded = remesher.GetOutput()
        self.assertEqual(len(named_leaves(reloaded)), len(named_leaves(direct)))
        for (name_a, a), (name_b, b) in zip(named_leaves(direct), named_leaves(reloaded)):
            self.assertEqual(name_a, name_b)
            self.assertEqual(points(a).tobytes(), points(b).tobytes())

    def test_preview_is_coarse(self):
        source, _, _ = self.mesh()
        source.SetPreviewCells(4)
        source.Update()
        for _, block in named_leaves(source.GetOutput()):
            self.assertTrue(all(d - 1 <= 4 for d in block.GetDimensions()))


class GridQualityTest(unittest.TestCase):
    def test_arrays_classes_and_scaled_jacobian_against_vtk(self):
        quality = blockforge.mesh_template(CYLINDER)
        grid = quality.GetOutputDataObject(0)
        total = 0
        for name, block in named_leaves(grid):
            cell_data = block.GetCellData()
            for array in ("MinAngle", "MaxAngle", "NonOrthogonality", "Skewness",
                          "AspectRatio", "ScaledJacobian", "CellDeterminant", "BlockId"):
                values = cell_data.GetArray(array)
                self.assertIsNotNone(values, f"{array} missing on {name}")
                self.assertEqual(values.GetNumberOfTuples(), block.GetNumberOfCells())
            reference = vtkMeshQuality()
            reference.SetInputData(block)
            reference.SetHexQualityMeasureToScaledJacobian()
            reference.Update()
            expected = np.array(dsa.WrapDataObject(reference.GetOutput())
                                .CellData["Quality"])
            ours = np.array(dsa.WrapDataObject(block).CellData["ScaledJacobian"])
            self.assertLess(np.max(np.abs(ours - expected)), 1e-9)
            min_angle = np.array(dsa.WrapDataObject(block).CellData["MinAngle"])
            max_angle = np.array(dsa.WrapDataObject(block).CellData["MaxAngle"])
            self.assertTrue(np.all(min_angle > 0) and np.all(min_angle <= 90))
            self.assertTrue(np.all(max_angle >= 90) and np.all(max_angle < 180))
            total += block.GetNumberOfCells()
        counts = grid.GetFieldData().GetArray("MinAngleClassCounts")
        self.assertEqual(sum(counts.GetValue(i) for i in range(5)), total)
        table = quality.GetOutputDataObject(1)
        self.assertEqual(table.GetNumberOfRows(), 5)
        self.assertEqual([table.GetValue(r, 0).ToString() for r in range(5)],
                         list(blockforge.MIN_ANGLE_CLASSES))
        self.assertEqual(sum(table.GetValue(r, 1).ToInt() for r in range(5)), total)
        self.assertEqual([table.GetValue(r, 2).ToDouble() for r in range(5)],
                         [10.0, 30.0, 50.0, 70.0, 85.0])
        percent = grid.GetFieldData().GetArray("MinAngleClassPercent")
        self.assertAlmostEqual(sum(percent.GetValue(i) for i in range(5)), 100.0)
        statistics = quality.GetOutputDataObject(2)
        self.assertEqual(statistics.GetNumberOfRows(), 7)
        self.assertEqual([statistics.GetValue(r, 0).ToString() for r in range(7)],
                         ["MinAngle", "MaxAngle", "NonOrthogonality", "Skewness",
                          "AspectRatio", "ScaledJacobian", "CellDeterminant"])
        summary = grid.GetFieldData().GetArray("ScaledJacobianSummary")
        low, mean, high = summary.GetTuple3(0)
        self.assertGreater(low, 0.0)
        self.assertLessEqual(high, 1.0 + 1e-12)
        self.assertTrue(low <= mean <= high)
        # The model document travels on through the quality filter.
        self.assertIsNotNone(grid.GetFieldData().GetAbstractArray("BlockForgeModel"))

    def test_unit_cubes_are_perfect(self):
        quality = blockforge.mesh_template(os.path.join(DATA, "two_blocks.yaml"))
        grid = quality.GetOutputDataObject(0)
        for _, block in named_leaves(grid):
            data = dsa.WrapDataObject(block).CellData
            np.testing.assert_allclose(data["MinAngle"], 90.0, atol=1e-9)
            np.testing.assert_allclose(data["MaxAngle"], 90.0, atol=1e-9)
            np.testing.assert_allclose(data["ScaledJacobian"], 1.0, atol=1e-12)
            np.testing.assert_allclose(data["AspectRatio"], 1.0, atol=1e-12)
            np.testing.assert_allclose(data["NonOrthogonality"], 0.0, atol=1e-6)
            np.testing.assert_allclose(data["Skewness"], 0.0, atol=1e-9)
            # 4 x 4 x 4 cubes per block, the two blocks side by side: 1 inside, 1/2 with one
            # boundary face, 1/4 with two, 1/8 with three (the interface counts as inside)
            determinant = np.asarray(data["CellDeterminant"])
            self.assertEqual(sorted(set(np.round(determinant, 12))), [0.125, 0.25, 0.5, 1.0])
        counts = grid.GetFieldData().GetArray("MinAngleClassCounts")
        self.assertEqual([counts.GetValue(i) for i in range(5)], [0, 0, 0, 0, 2 * 64])


    def test_periodic_faces_are_measured_like_interior_faces(self):
        # Testing/Data/sheared_periodic.yaml: across its periodic faces the cell centres
        # (the partner's rotated back by the model's angle) lean atan(1/2) from the normal.
        quality = blockforge.mesh_template(os.path.join(DATA, "sheared_periodic.yaml"))
        blocks = dict(named_leaves(quality.GetOutputDataObject(0)))
        low = np.array(dsa.WrapDataObject(blocks["low"]).CellData["NonOrthogonality"])
        low = low.reshape(4, 4, 2)  # cells (k, j, i)
        np.testing.assert_allclose(low[:, 0, :], math.degrees(math.atan(0.5)), atol=1e-9)
        np.testing.assert_allclose(low[:, 1:, :], 0.0, atol=1e-6)


class AxialPassageOHTest(unittest.TestCase):
    """mesh_template with input_file: TurboPointSetsReader -> BlockTemplate -> BlockMesher ->
    GridQuality on Templates/axial_passage_oh.yaml, for both bundled data sets."""
    BLOCKS = ["D_L", "D_M", "D_R", "M_L", "M_R", "O_a", "O_b", "O_le", "O_te",
              "U_L", "U_M", "U_R"]
    CELLS = 12288  # at density 1: the default cell counts of the template

    def check_grid(self, input_file, blade_count):
        quality = blockforge.mesh_template(AXIAL_OH, input_file=input_file)
        grid = quality.GetOutputDataObject(0)
        blocks = dict(named_leaves(grid))
        self.assertEqual(sorted(blocks), self.BLOCKS)
        cells = sum(block.GetNumberOfCells() for block in blocks.values())
        self.assertEqual(cells, self.CELLS)
        # no inverted or degenerate cell
        jacobian = np.concatenate([np.array(dsa.WrapDataObject(block).CellData["ScaledJacobian"])
                                   for block in blocks.values()])
        self.assertEqual(len(jacobian), cells)
        self.assertGreater(jacobian.min(), 0.0)
        low, _, high = grid.GetFieldData().GetArray("ScaledJacobianSummary").GetTuple3(0)
        self.assertAlmostEqual(low, jacobian.min(), places=12)
        self.assertLessEqual(high, 1.0 + 1e-12)
        # the MinAngle classes count every cell once (field data and table alike)
        counts = grid.GetFieldData().GetArray("MinAngleClassCounts")
        self.assertEqual(sum(counts.GetValue(i) for i in range(5)), cells)
        table = quality.GetOutputDataObject(1)
        self.assertEqual([table.GetValue(r, 1).ToInt() for r in range(5)],
                         [counts.GetValue(i) for i in range(5)])
        # inlet (j = 0 of the U blocks) and outlet (j = max of the D blocks): axial planes at
        # the ends of the grid; H blocks run i with theta, j with the axis
        z = np.concatenate([points(block)[:, 2] for block in blocks.values()])
        tolerance = 1e-9 * (z.max() - z.min())
        for name in ("U_L", "U_M", "U_R"):
            np.testing.assert_allclose(node_array(blocks[name])[:, 0, :, 2], z.min(),
                                       rtol=0, atol=tolerance)
        for name in ("D_L", "D_M", "D_R"):
            np.testing.assert_allclose(node_array(blocks[name])[:, -1, :, 2], z.max(),
                                       rtol=0, atol=tolerance)
        # periodic: i = max of the right H blocks is i = 0 of the left ones rotated by a pitch
        for low_name, high_name in (("U_L", "U_R"), ("M_L", "M_R"), ("D_L", "D_R")):
            low_side = node_array(blocks[low_name])[:, :, 0, :].reshape(-1, 3)
            high_side = node_array(blocks[high_name])[:, :, -1, :].reshape(-1, 3)
            np.testing.assert_allclose(rotate_z(low_side, 2 * math.pi / blade_count), high_side,
                                       rtol=0, atol=1e-12)

    def test_distributor(self):
        self.check_grid(DISTRIBUTOR_INF, 16)

    def test_rotor37(self):
        self.check_grid(ROTOR37_INF, 36)

    def test_shear_camber_lifts_the_turbines_trailing_edge(self):
        """`shear_camber` 1 (the default since stop 15; 0 before) decides an edge's shear by the
        larger stagger of the blade near the edge and its camber at the edge: the turbine's
        trailing edge (exit about 60 degrees) is sheared, and the wake block's corner cell
        there, the worst of the placed grid with 0, rises from 0.089 to 0.319 (density 1) and
        from 0.106 to 0.379 (2) (stop 17's O-grid, k_o 1.25 and k_span 1.1; 0.092 / 0.304 and
        0.096 / 0.376 before; 0.170 / 0.280 before U_M/D_M's `adaptive` interpolation)."""
        turbine = os.path.join(SOURCE, "Data", "turbine", "Info.txt")
        for density, default_low, sheared_low in ((1.0, 0.12, 0.15), (2.0, 0.12, 0.25)):
            lows = []
            for camber in (0, 1):
                grid = blockforge.mesh_template(
                    AXIAL_OH, input_file=turbine, optimize=False, density_multiplier=density,
                    parameters={"shear_camber": camber}).GetOutputDataObject(0)
                lows.append(grid.GetFieldData().GetArray("ScaledJacobianSummary").GetTuple3(0)[0])
            with self.subTest(density=density):
                self.assertLess(lows[0], default_low)
                self.assertGreater(lows[1], sheared_low)

    def test_bad_input_path_raises(self):
        missing = os.path.join(OUTPUT, "no_such_dir", "BladeGen.inf")
        with self.assertRaises(RuntimeError) as context:
            blockforge.mesh_template(AXIAL_OH, input_file=missing)
        self.assertIn(os.path.join("no_such_dir", "BladeGen.inf"), str(context.exception))

    def test_template_with_inputs_needs_input_file(self):
        with self.assertRaises(RuntimeError) as context:
            blockforge.mesh_template(AXIAL_OH)
        self.assertIn("axial_passage_oh.yaml", str(context.exception))


class CommandLineTest(unittest.TestCase):
    """python3 -m blockforge, run in-process through its main()."""

    def setUp(self):
        self.directory = os.path.join(OUTPUT, "command_line")
        shutil.rmtree(self.directory, ignore_errors=True)
        os.makedirs(self.directory)

    def run_main(self, *arguments):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = blockforge_main(list(arguments))
        return status, out.getvalue(), err.getvalue()

    def read_grid(self, path):
        reader = vtkXMLMultiBlockDataReader()
        reader.SetFileName(path)
        reader.Update()
        return reader.GetOutput()

    def pieces(self, path):
        """The pieces folder the .vtm *path* references (its base name) and its files."""
        folders = blockforge.output.referenced_folders(path)
        self.assertEqual(len(folders), 1, folders)
        folder = folders.pop()
        self.assertTrue(os.path.basename(folder).startswith(
            os.path.splitext(os.path.basename(path))[0] + ".pieces-"), folder)
        return os.path.basename(folder), sorted(os.listdir(folder))

    def test_input_writes_vtm_atomically(self):
        path = os.path.join(self.directory, "oh.vtm")
        status, out, err = self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-o", path)
        self.assertEqual(status, 0, err)
        self.assertIn("cells: 12288", out)
        self.assertIn("grid written to", out)
        # the .vtm and its pieces, nothing else (no temporary left behind)
        folder, files = self.pieces(path)
        self.assertEqual(sorted(os.listdir(self.directory)), [folder, "oh.vtm"])
        self.assertEqual(len(files), 12)
        grid = self.read_grid(path)
        self.assertEqual(len(named_leaves(grid)), 12)
        self.assertEqual(sum(block.GetNumberOfCells() for _, block in named_leaves(grid)), 12288)
        for _, block in named_leaves(grid):
            self.assertIsNotNone(block.GetCellData().GetArray("ScaledJacobian"))

        # a failing run over an existing grid leaves it untouched
        with open(path, "rb") as file:
            before = file.read()
        status, _, err = self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-p", "nosuch=1",
                                       "-o", path)
        self.assertEqual(status, 1)
        self.assertIn("nosuch", err)
        with open(path, "rb") as file:
            self.assertEqual(file.read(), before)
        self.assertEqual(sorted(os.listdir(self.directory)), [folder, "oh.vtm"])
        self.assertEqual(self.pieces(path), (folder, files))

        # a successful run replaces the older grid with its pieces (4 blocks, not 12), in a
        # fresh folder; the older folder is gone
        status, _, err = self.run_main(CYLINDER, "-o", path)
        self.assertEqual(status, 0, err)
        new_folder, new_files = self.pieces(path)
        self.assertNotEqual(new_folder, folder)
        self.assertEqual(sorted(os.listdir(self.directory)), [new_folder, "oh.vtm"])
        self.assertEqual(len(new_files), 4)
        self.assertEqual(len(named_leaves(self.read_grid(path))), 4)

    def test_inverted_cells_refused_unless_allowed(self):
        folded = os.path.join(DATA, "folded_spline.yaml")
        path = os.path.join(self.directory, "folded.vtm")
        status, out, err = self.run_main(folded, "-o", path)
        self.assertEqual(status, 1)
        self.assertIn("block 'bent'", err)
        self.assertIn("inverted cells of 512", err)
        self.assertIn("cell range i", err)
        self.assertEqual(os.listdir(self.directory), [])
        status, out, err = self.run_main(folded, "--allow-inverted-cells", "-o", path)
        self.assertEqual(status, 0, err)
        self.assertIn("warning: ", err)
        self.assertIn("block 'bent'", err)
        self.assertIn("grid written", out)
        grid = self.read_grid(path)
        jacobian = np.concatenate([dsa.WrapDataObject(block).CellData["ScaledJacobian"]
                                   for _, block in named_leaves(grid)])
        self.assertLess(float(jacobian.min()), 0.0)

    def test_failing_run_writes_nothing(self):
        path = os.path.join(self.directory, "failed.vtm")
        status, out, err = self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-p", "nosuch=1",
                                         "-o", path)
        self.assertEqual(status, 1)
        self.assertIn("nosuch", err)
        self.assertNotIn("grid written", out)
        self.assertEqual(os.listdir(self.directory), [])

    def test_output_must_be_vtm(self):
        path = os.path.join(self.directory, "grid")
        with self.assertRaises(SystemExit) as raised:
            self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-o", path)
        self.assertEqual(raised.exception.code, 2)
        self.assertEqual(os.listdir(self.directory), [])

    def test_failed_move_keeps_the_older_grid(self):
        """The new grid cannot be put in place (the .vtm path is a directory): the new
        pieces are removed and the error is reported; the pieces nothing references any
        more (their .vtm was removed) are cleaned up as leftovers."""
        path = os.path.join(self.directory, "kept.vtm")
        status, _, err = self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-o", path)
        self.assertEqual(status, 0, err)
        folder, files = self.pieces(path)
        os.remove(path)
        os.makedirs(os.path.join(path, "occupied"))
        status, out, err = self.run_main(AXIAL_OH, "-i", DISTRIBUTOR_INF, "-o", path)
        self.assertEqual(status, 1)
        self.assertIn("error:", err)
        self.assertNotIn("grid written", out)
        self.assertEqual(len(files), 12)
        self.assertEqual(sorted(os.listdir(self.directory)), ["kept.vtm"])
        self.assertEqual(os.listdir(path), ["occupied"])

    def test_bad_input_path(self):
        path = os.path.join(self.directory, "bad_input.vtm")
        missing = os.path.join(self.directory, "no_such.inf")
        status, _, err = self.run_main(AXIAL_OH, "-i", missing, "-o", path)
        self.assertEqual(status, 1)
        self.assertIn("no_such.inf", err)
        self.assertEqual(os.listdir(self.directory), [])


class BadInputTest(unittest.TestCase):
    """Every bad input gives a clear error naming file, line and entity; no crash."""

    def run_bad(self, template, parameters=None):
        source, mesher = pipeline(template, parameters)
        errors = ErrorCollector(source, mesher)
        mesher.Update()
        self.assertTrue(errors.messages, "no error reported")
        self.assertEqual(mesher.GetOutput().GetNumberOfBlocks(), 0)
        return errors.messages[0]

    def test_missing_file(self):
        message = self.run_bad(os.path.join(DATA, "no_such_template.yaml"))
        self.assertIn("no_such_template.yaml", message)

    def test_syntax_error(self):
        message = self.run_bad(os.path.join(DATA, "bad_syntax.yaml"))
        self.assertIn("bad_syntax.yaml:2", message)  # line 21 or 22

    def test_unknown_vertex(self):
        message = self.run_bad(os.path.join(DATA, "bad_unknown_vertex.yaml"))
        self.assertIn("bad_unknown_vertex.yaml:23", message)
        self.assertIn("a8", message)
        self.assertIn("left", message)

    def test_bad_expression(self):
        message = self.run_bad(os.path.join(DATA, "bad_expression.yaml"))
        self.assertIn("bad_expression.yaml:6", message)
        self.assertIn("'n'", message)

    def test_mismatched_node_counts(self):
        message = self.run_bad(os.path.join(DATA, "two_blocks.yaml"), {"n_right": 5})
        self.assertIn("left", message)
        self.assertIn("right", message)

    def test_inside_out_block(self):
        message = self.run_bad(os.path.join(DATA, "bad_inside_out.yaml"))
        self.assertIn("right", message)
        self.assertIn("inside-out", message)

    def test_unknown_parameter_override(self):
        message = self.run_bad(CYLINDER, {"no_such_parameter": 1})
        self.assertIn("no_such_parameter", message)

    def test_mesher_without_model(self):
        from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet
        mesher = blockforge.vtkBlockMesher()
        mesher.SetInputData(vtkMultiBlockDataSet())
        errors = ErrorCollector(mesher)
        mesher.Update()
        self.assertTrue(any("BlockForge model" in m for m in errors.messages))

    def test_mesh_template_allow_inverted_cells(self):
        folded = os.path.join(DATA, "folded_spline.yaml")
        with self.assertRaises(RuntimeError) as context:
            blockforge.mesh_template(folded)
        self.assertIn("inverted cell", str(context.exception))
        quality = blockforge.mesh_template(folded, allow_inverted_cells=True)
        grid = quality.GetOutputDataObject(0)
        count = grid.GetFieldData().GetArray("InvertedCellCount").GetValue(0)
        jacobian = np.concatenate([dsa.WrapDataObject(block).CellData["ScaledJacobian"]
                                   for _, block in named_leaves(grid)])
        # the mesher's count is GridQuality's count of negative scaled Jacobians
        self.assertGreater(count, 0)
        self.assertEqual(count, int((jacobian < 0).sum()))

    def test_mesh_template_raises(self):
        with self.assertRaises(RuntimeError) as context:
            blockforge.mesh_template(os.path.join(DATA, "bad_inside_out.yaml"))
        self.assertIn("inside-out", str(context.exception))


def observe(algorithm):
    """(errors, warnings): the messages `algorithm` reports from now on."""
    found = {vtkCommand.ErrorEvent: [], vtkCommand.WarningEvent: []}
    for event, messages in found.items():
        collect = calldata_type(VTK_STRING)(lambda _caller, _event, message, into=messages:
                                            into.append(message))
        algorithm.AddObserver(event, collect)
    return found[vtkCommand.ErrorEvent], found[vtkCommand.WarningEvent]


class PreviewFoldTest(unittest.TestCase):
    """A coarse preview that folds at its capped cell counts where the grid does not is a
    warning: the model is passed on (BlockTemplate and BlockOptimizer share the preview
    path); errors of the model and memory refusals stay errors."""

    FOLD = os.path.join(DATA, "preview_fold.yaml")
    SYMMETRIC = os.path.join(DATA, "optimizer_symmetric.yaml")

    def check_model_passed_on(self, output, folded):
        self.assertEqual(output.GetNumberOfBlocks(), 1)
        self.assertEqual(output.GetMetaData(0).Get(vtkCompositeDataSet.NAME()), "swung")
        self.assertEqual(output.GetBlock(0) is None, folded)
        self.assertIsNotNone(output.GetFieldData().GetAbstractArray("BlockForgeModel"))

    def test_template_preview(self):
        for cells, folds in ((2, True), (4, True), (8, False)):
            source = blockforge.vtkBlockTemplateSource()
            source.SetTemplateFile(self.FOLD)
            source.SetPreviewCells(cells)
            errors, warnings = observe(source)
            source.Update()
            self.assertEqual(errors, [])
            self.check_model_passed_on(source.GetOutputDataObject(0), folds)
            if folds:
                self.assertEqual(len(warnings), 1, warnings)
                self.assertIn("the preview (at most %d cells per edge) folds and is not drawn; "
                              "the model is passed on" % cells, warnings[0])
                self.assertIn("preview_fold.yaml:23: block 'swung': the block folds at V0",
                              warnings[0])
            else:
                self.assertEqual(warnings, [])
            # the mesher judges the grid at the density it meshes (here: inverted cells)
            mesher = blockforge.vtkBlockMesher()
            mesher.SetInputConnection(source.GetOutputPort())
            mesher_errors, _ = observe(mesher)
            mesher.Update()
            self.assertEqual(len(mesher_errors), 1)
            self.assertIn("block 'swung': 662 inverted cells of 4096", mesher_errors[0])

    def test_optimizer_preview(self):
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(self.FOLD)
        optimizer = blockforge.vtkBlockOptimizer()
        optimizer.SetInputConnection(source.GetOutputPort())
        optimizer.SetAutomatic(False)
        optimizer.SetPreviewCells(2)
        errors, warnings = observe(optimizer)
        optimizer.Update()
        self.assertEqual(errors, [])
        self.check_model_passed_on(optimizer.GetOutputDataObject(0), True)
        self.assertTrue(any("The optimized model: the preview (at most 2 cells per edge) "
                            "folds" in w for w in warnings), warnings)

    def test_memory_refusals_stay_errors(self):
        # The template's preview (uncapped: 8192 cells) and the optimizer's: the optimizer
        # works at density 0.5 (54 nodes, 6.39 kB) but draws its uncapped preview at
        # density 1 (250 nodes, 20.4 kB), more than MaximumMemory allows.
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(CYLINDER)
        source.SetPreviewCells(0)
        source.SetMaximumMemory(1e-6)
        errors, _ = observe(source)
        source.Update()
        self.assertEqual(len(errors), 1)
        self.assertIn("lower PreviewCells or the cell counts", errors[0])
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(self.SYMMETRIC)
        optimizer = blockforge.vtkBlockOptimizer()
        optimizer.SetInputConnection(source.GetOutputPort())
        optimizer.SetDensityMultiplier(0.5)
        optimizer.SetPreviewCells(0)
        optimizer.SetMaximumMemory(1e-5)
        errors, _ = observe(optimizer)
        optimizer.Update()
        self.assertEqual(len(errors), 1)
        self.assertIn("the grid would need 20.4 kB for 2.5e+02 nodes, more than MaximumMemory "
                      "(10.5 kB); lower PreviewCells or the cell counts", errors[0])
        self.assertEqual(optimizer.GetOutputDataObject(0).GetNumberOfBlocks(), 0)


class OptimizerTest(unittest.TestCase):
    """vtkBlockOptimizer through `import blockforge`, and the optimizer in mesh_template and
    the command line (on by default, --no-optimize / optimize=False to skip it)."""
    SYMMETRIC = os.path.join(DATA, "optimizer_symmetric.yaml")

    def min_angle(self, quality):
        grid = quality.GetOutputDataObject(0)
        return grid.GetFieldData().GetArray("MinAngleSummary").GetTuple3(0)[0]

    def test_vtk_pipeline(self):
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(self.SYMMETRIC)
        optimizer = blockforge.vtkBlockOptimizer()
        optimizer.SetInputConnection(source.GetOutputPort())
        optimizer.SetTolerance(1e-12)
        optimizer.SetControlPointMove("m0", "0.45")
        optimizer.SetAutomatic(False)
        optimizer.Update()
        fields = optimizer.GetOutputDataObject(0).GetFieldData()
        self.assertAlmostEqual(fields.GetArray("MinAngleAfter").GetValue(0),
                               math.degrees(math.atan2(1.0, 0.1)), places=9)
        optimizer.ClearControlPointMoves()
        optimizer.SetAutomatic(True)
        optimizer.Update()
        fields = optimizer.GetOutputDataObject(0).GetFieldData()
        self.assertGreater(fields.GetArray("MinAngleAfter").GetValue(0), 90.0 - 1e-3)
        history = optimizer.GetOutputDataObject(1)
        self.assertEqual(history.GetNumberOfRows(),
                         fields.GetArray("OptimizerEvaluations").GetValue(0))

    def test_mesh_template_optimizes_by_default(self):
        optimized = self.min_angle(blockforge.mesh_template(self.SYMMETRIC))
        placed = self.min_angle(blockforge.mesh_template(self.SYMMETRIC, optimize=False))
        self.assertAlmostEqual(placed, math.degrees(math.atan2(1.0, 0.4)), places=9)
        self.assertGreater(optimized, 89.9)

    def test_blade_row_at_other_densities(self):
        # The optimized model meshes at every density asked for: at 0.5 its coarse preview
        # (PreviewCells per edge) folds where the real grid does not, which must not stop
        # the pipeline; at 4 the optimizer measures a coarsened copy (above 1e5 nodes) and
        # steps back towards the start until the real grid is valid and no worse. The
        # template's lean limit is lifted (179deg): its blade-side cells then leave the
        # round leading edge across the pitch as before issue 8's limit, which is what
        # folds the coarse preview (with the limit, no preview of the four machines folds).
        # The interface-ratio bound is lifted too (0): held, the optimizer ends where the
        # preview no longer folds (stop 16).
        template = os.path.join(SOURCE, "Templates", "axial_passage_h.yaml")
        lifted = {"lean": "179deg"}
        for density in (0.5, 4.0):
            warnings = []
            placed = self.min_angle(blockforge.mesh_template(
                template, lifted, density_multiplier=density, input_file=ROTOR37_INF,
                optimize=False))
            optimized = self.min_angle(blockforge._run_pipeline(
                template, lifted, density_multiplier=density, input_file=ROTOR37_INF,
                warnings=warnings, maximum_interface_ratio=0))
            self.assertGreaterEqual(optimized, placed, density)
            if density == 0.5:
                self.assertTrue(any("preview" in w for w in warnings), warnings)
                self.assertGreater(optimized, placed + 3.0)

    def test_command_line_switch(self):
        for arguments, expected in (((), "optimize"), (("--no-optimize",), None)):
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                status = blockforge_main([self.SYMMETRIC, *arguments])
            self.assertEqual(status, 0, err.getvalue())
            timing = [line for line in out.getvalue().splitlines() if line.startswith("time")]
            self.assertEqual(len(timing), 1)
            if expected:
                self.assertIn(expected, timing[0])
                self.assertIn("optimizer: smallest element angle 68.20 -> 89.9", out.getvalue())
                self.assertIn("(1 control point parameters", out.getvalue())
            else:
                self.assertNotIn("optimize", timing[0])
                self.assertNotIn("optimizer:", out.getvalue())


if __name__ == "__main__":
    bftest.run_tests()
