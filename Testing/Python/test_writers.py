"""The solver-format writers through `import blockforge`, the Python command line and the
native command line `blockforge`: Plot3D read back by VTK's vtkMultiBlockPLOT3DReader
node for node, ASCII and binary polyMesh alike, both command lines writing the same bytes,
and failures (no model, an unwritable folder, a full disk) that leave no partial grid
and keep an older one."""
import filecmp
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import unittest

import numpy as np

import blockforge
from blockforge import writers
from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet, vtkStructuredGrid
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkIOParallel import vtkMultiBlockPLOT3DReader
from vtkmodules.vtkIOGeometry import vtkOpenFOAMReader

import bftest
from bftest import CYLINDER, DISTRIBUTOR_INF, ROTOR37_INF, SOURCE

AXIAL_OH = os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml")
CLI = os.environ.get("BLOCKFORGE_CLI", "")
POLYMESH_FILES = ("points", "faces", "owner", "neighbour", "boundary")


def mesh(template, inf=None, density=1.0):
    return blockforge.mesh_template(template, density_multiplier=density,
                                    input_file=inf).GetOutputDataObject(0)


def read_plot3d(path, binary):
    reader = vtkMultiBlockPLOT3DReader()
    reader.SetXYZFileName(path)
    reader.SetBinaryFile(binary)
    reader.SetMultiGrid(True)
    reader.SetHasByteCount(binary)
    reader.SetDoublePrecision(True)
    reader.SetIBlanking(False)
    reader.SetByteOrderToLittleEndian()
    reader.AutoDetectFormatOff()
    reader.Update()
    output = reader.GetOutput()
    return [output.GetBlock(b) for b in range(output.GetNumberOfBlocks())]


# Run by `unshare -rm python3 -c`: mounts the tmpfs, writes a small grid and then a large
# one into it per case, and prints one JSON line: exit codes, errors, whether every file of
# the small grid is unchanged, and the hidden staging entries left.
NO_SPACE_SCRIPT = """
import hashlib, json, os, shutil, subprocess, sys
disk = {disk}
if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", disk]).returncode:
    sys.exit(77)
def snapshot():
    return {{os.path.join(root, name): hashlib.sha256(open(os.path.join(root, name), "rb").read()).hexdigest()
            for root, dirs, names in os.walk(disk) for name in names}}
results = []
for label, command, output in {cases}:
    for entry in os.listdir(disk):
        path = os.path.join(disk, entry)
        shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
    target = os.path.join(disk, output)
    small = subprocess.run(command + [{template}, "-d", "0.5", "--no-optimize", "-o", target],
                           capture_output=True, text=True)
    before = snapshot()
    big = subprocess.run(command + [{template}, "-d", "3", "--no-optimize", "-o", target],
                         capture_output=True, text=True)
    results.append({{"label": label, "output": output, "small": small.returncode,
                    "small_err": small.stderr[-2000:], "files": len(before),
                    "big": big.returncode, "big_err": big.stderr[-2000:],
                    "kept": snapshot() == before,
                    "leftovers": [os.path.join(root, name) for root, dirs, names in os.walk(disk)
                                  for name in dirs + names if name.startswith(".")]}})
print(json.dumps(results))
"""


def limited_file_size(limit):
    """A preexec_fn: files may not grow beyond `limit` bytes (writes fail with EFBIG)."""
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def read_bytes(path):
    with open(path, "rb") as stream:
        return stream.read()


def leftovers(folder):
    """Hidden staging entries (.NAME.XXXXXX) left in a folder tree."""
    return [os.path.join(root, name) for root, dirs, files in os.walk(folder)
            for name in dirs + files if name.startswith(".")]


class Plot3DTest(unittest.TestCase):
    def test_read_back_node_for_node(self):
        for name, template, inf in (("cylinder", CYLINDER, None),
                                    ("distributor_oh", AXIAL_OH, DISTRIBUTOR_INF)):
            grid = mesh(template, inf)
            ours = bftest.leaves(grid)
            for binary in (True, False):
                with self.subTest(grid=name, binary=binary):
                    path = bftest.output_path(f"plot3d/{name}_{'bin' if binary else 'ascii'}.xyz")
                    writers.write_solver_grid(grid, path, binary=binary)
                    theirs = read_plot3d(path, binary)
                    self.assertEqual(len(theirs), len(ours))
                    for a, b in zip(ours, theirs):
                        self.assertEqual(bftest.node_array(a).shape, bftest.node_array(b).shape)
                        self.assertTrue(np.array_equal(bftest.points(a), bftest.points(b)))
                    self.assertTrue(os.path.exists(path[:-4] + ".nmf"))
            # The Neutral Map File lists every interface once and every periodic pair once.
            with open(path[:-4] + ".nmf") as stream:
                text = stream.read()
            pairs = 3 if name == "distributor_oh" else 0
            interfaces = {"cylinder": 4, "distributor_oh": 16}[name]
            self.assertEqual(text.count("'ONE_TO_ONE'"), interfaces + pairs)


class CgnsTest(unittest.TestCase):
    def test_cgnscheck_and_paraview_reader(self):
        for name, template, inf in (("cylinder", CYLINDER, None),
                                    ("wedge", os.path.join(SOURCE, "Templates", "wedge_sector.yaml"), None),
                                    ("distributor_oh", AXIAL_OH, DISTRIBUTOR_INF)):
            with self.subTest(grid=name):
                grid = mesh(template, inf)
                path = bftest.output_path(f"cgns/{name}.cgns")
                writers.write_solver_grid(grid, path)
                check = subprocess.run(["cgnscheck", path], capture_output=True, text=True)
                self.assertEqual(check.returncode, 0, check.stdout + check.stderr)
                self.assertNotIn("ERROR", check.stdout + check.stderr)
                self.assertNotIn("WARNING", check.stdout + check.stderr)
                zones = bftest.read_cgns_zones(path)
                ours = dict(bftest.named_leaves(grid))
                self.assertEqual(sorted(zones), sorted(ours))
                for zone, block in ours.items():
                    self.assertTrue(np.array_equal(bftest.points(block), bftest.points(zones[zone])),
                                    zone)


class FoamFormatsTest(unittest.TestCase):
    def test_ascii_and_binary_are_the_same_mesh(self):
        grid = mesh(AXIAL_OH, DISTRIBUTOR_INF, 0.5)
        result = []
        for binary in (True, False):
            case = bftest.output_path(f"foam_formats/{'bin' if binary else 'ascii'}")
            shutil.rmtree(case, ignore_errors=True)
            writers.write_solver_grid(grid, os.path.join(case, "d.foam"), binary=binary)
            reader = vtkOpenFOAMReader()
            reader.SetFileName(os.path.join(case, "d.foam"))
            reader.Update()
            internal = reader.GetOutput().GetBlock(0)
            result.append((internal.GetNumberOfCells(), bftest.points(internal)))
        self.assertEqual(result[0][0], 3696)  # density 0.5 (the template's min_cells: 1356 without; 2772 before min_span)
        self.assertEqual(result[0][0], result[1][0])
        self.assertTrue(np.array_equal(result[0][1], result[1][1]))


class VtmTest(unittest.TestCase):
    def test_raw_by_default_compressed_on_request(self):
        """`python3 -m blockforge -o grid.vtm` writes raw binary pieces (zlib took most of
        the time at 1M cells); --compress writes zlib pieces; both read back the same."""
        from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

        folder = bftest.output_path("vtm_compression")
        shutil.rmtree(folder, ignore_errors=True)
        grids = {}
        for switch in ([], ["--compress"]):
            path = os.path.join(folder, "zlib" if switch else "raw", "grid.vtm")
            run = subprocess.run([sys.executable, "-m", "blockforge", CYLINDER, "-d", "0.5",
                                  "--no-optimize", "-o", path] + switch,
                                 capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr)
            pieces = [os.path.join(root, name) for root, _, names in
                      os.walk(os.path.dirname(path)) for name in names if name.endswith(".vts")]
            self.assertEqual(len(pieces), 4)
            for piece in pieces:
                with open(piece, "rb") as stream:
                    header = stream.read(400)
                self.assertEqual(b'compressor="vtkZLibDataCompressor"' in header, bool(switch),
                                 header)
            reader = vtkXMLMultiBlockDataReader()
            reader.SetFileName(path)
            reader.Update()
            grids[bool(switch)] = [bftest.points(block) for block in bftest.leaves(reader.GetOutput())]
        self.assertEqual(len(grids[False]), 4)
        for raw, zlib in zip(grids[False], grids[True]):
            self.assertTrue(np.array_equal(raw, zlib))


class ErrorsTest(unittest.TestCase):
    def test_grid_without_model(self):
        grid = vtkMultiBlockDataSet()
        block = vtkStructuredGrid()
        block.SetDimensions(2, 2, 2)
        points = vtkPoints()
        for k in range(2):
            for j in range(2):
                for i in range(2):
                    points.InsertNextPoint(i, j, k)
        block.SetPoints(points)
        grid.SetBlock(0, block)
        for extension in writers.SOLVER_WRITERS:
            path = bftest.output_path("no_model/grid" + extension)
            with self.assertRaisesRegex(RuntimeError, "carries no BlockForge model"):
                writers.write_solver_grid(grid, path)
            self.assertFalse(os.path.exists(path))

    def test_unwritable_folder(self):
        grid = mesh(CYLINDER, density=0.5)
        blocker = bftest.output_path("a_file")
        open(blocker, "w").close()
        for target in ("case/c.foam", "grid.xyz"):
            with self.assertRaisesRegex(RuntimeError, "a_file"):
                writers.write_solver_grid(grid, os.path.join(blocker, target))

    def test_no_space_left_keeps_the_older_grid(self):
        """A real full disk: a 2 MiB tmpfs (mounted in a user and mount namespace of its
        own, `unshare -rm`, no privileges needed) holds a small grid; writing a grid of
        221,184 cells there fails with "No space left on device", in every format and
        through both command lines, and the small grid stays byte for byte with nothing
        left over."""
        if not shutil.which("unshare"):
            self.skipTest("unshare (util-linux) not found")
        folder = bftest.output_path("no_space")
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(os.path.join(folder, "disk"))
        commands = [("python", [sys.executable, "-m", "blockforge"])]
        if CLI:
            commands.append(("native", [CLI]))
        cases = [(label, command, output) for label, command in commands
                 for output in ("case/c.foam", "grid.xyz", "grid.cgns", "grid.vtm")]
        script = NO_SPACE_SCRIPT.format(disk=repr(os.path.join(folder, "disk")),
                                        cases=repr(cases), template=repr(CYLINDER))
        run = subprocess.run(["unshare", "-rm", sys.executable, "-c", script],
                             capture_output=True, text=True, timeout=600)
        if run.returncode == 77:
            self.skipTest("no tmpfs in a user namespace here: " + run.stderr[-500:])
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        results = json.loads(run.stdout.splitlines()[-1])
        self.assertEqual(len(results), len(cases))
        for result in results:
            with self.subTest(command=result["label"], output=result["output"]):
                self.assertEqual(result["small"], 0, result["small_err"])
                self.assertGreater(result["files"], 0)
                self.assertNotEqual(result["big"], 0)
                self.assertIn("No space left on device", result["big_err"])
                self.assertTrue(result["kept"], "the older grid changed")
                self.assertEqual(result["leftovers"], [])

    def test_full_disk_keeps_the_older_grid(self):
        """A file-size limit makes the writes fail half way, as a full disk does: the
        command fails with the reason, the older grid stays, nothing is left over."""
        folder = bftest.output_path("full_disk")
        shutil.rmtree(folder, ignore_errors=True)
        commands = [("python", [sys.executable, "-m", "blockforge"])]
        if CLI:
            commands.append(("native", [CLI]))
        for label, command in commands:
            for output in ("case/c.foam", "grid.xyz", "grid.cgns", "grid.vtm"):
                with self.subTest(command=label, output=output):
                    target = os.path.join(folder, label, output)
                    small = subprocess.run(command + [CYLINDER, "-d", "0.5", "-o", target],
                                           capture_output=True, text=True)
                    self.assertEqual(small.returncode, 0, small.stderr)
                    written = (os.path.join(os.path.dirname(target), "constant", "polyMesh",
                                            "points") if output.endswith(".foam") else target)
                    before = read_bytes(written)
                    big = subprocess.run(command + [CYLINDER, "-d", "3", "-o", target],
                                         capture_output=True, text=True,
                                         preexec_fn=limited_file_size(len(before) + 1000))
                    self.assertNotEqual(big.returncode, 0)
                    self.assertIn("File too large", big.stderr)
                    self.assertEqual(read_bytes(written), before)
                    self.assertEqual(leftovers(os.path.join(folder, label)), [])


@unittest.skipUnless(CLI, "BLOCKFORGE_CLI not set")
class NativeCommandLineTest(unittest.TestCase):
    def test_same_bytes_as_the_python_pipeline(self):
        """Both command lines run the BlockOptimizer by default and skip it with
        --no-optimize; either way they write the same bytes."""
        folder = bftest.output_path("native_vs_python")
        shutil.rmtree(folder, ignore_errors=True)
        arguments = [AXIAL_OH, "-i", DISTRIBUTOR_INF]
        for switch in ([], ["--no-optimize"]):
            run_folder = os.path.join(folder, "no_optimize" if switch else "optimize")
            for label, command in (("python", [sys.executable, "-m", "blockforge"]),
                                   ("native", [CLI])):
                for output in ("case/c.foam", "grid.xyz"):
                    run = subprocess.run(command + arguments + switch +
                                         ["-o", os.path.join(run_folder, label, output)],
                                         capture_output=True, text=True)
                    self.assertEqual(run.returncode, 0, run.stderr)
                    self.assertEqual("optimizer: smallest element angle" in run.stdout,
                                     not switch, run.stdout)
            for name in POLYMESH_FILES:
                self.assertTrue(filecmp.cmp(
                    os.path.join(run_folder, "python/case/constant/polyMesh", name),
                    os.path.join(run_folder, "native/case/constant/polyMesh", name),
                    shallow=False), (switch, name))
            for name in ("grid.xyz", "grid.nmf"):
                self.assertTrue(filecmp.cmp(os.path.join(run_folder, "python", name),
                                            os.path.join(run_folder, "native", name),
                                            shallow=False), (switch, name))
        # The optimizer moved the grid's nodes (the connectivity stays).
        self.assertFalse(filecmp.cmp(os.path.join(folder, "optimize/native/grid.xyz"),
                                     os.path.join(folder, "no_optimize/native/grid.xyz"),
                                     shallow=False))
        self.assertTrue(filecmp.cmp(os.path.join(folder, "optimize/native/grid.nmf"),
                                    os.path.join(folder, "no_optimize/native/grid.nmf"),
                                    shallow=False))

    def test_objective_non_orthogonality(self):
        """--objective non-orthogonality: both command lines write the same bytes, and the
        grid's largest non-orthogonality is well below the placed grid's on the
        distributor's O-grid."""
        folder = bftest.output_path("objective")
        shutil.rmtree(folder, ignore_errors=True)
        arguments = [AXIAL_OH, "-i", DISTRIBUTOR_INF]
        largest = {}
        for objective in ("min-angle", "non-orthogonality"):
            for label, command in (("python", [sys.executable, "-m", "blockforge"]),
                                   ("native", [CLI])):
                run = subprocess.run(command + arguments + ["--objective", objective, "-o",
                                     os.path.join(folder, objective, label, "grid.xyz")],
                                     capture_output=True, text=True)
                self.assertEqual(run.returncode, 0, run.stderr)
                if label == "python":
                    line = next(l for l in run.stdout.splitlines()
                                if l.strip().startswith("NonOrthogonality"))
                    largest[objective] = float(line.split()[-1])
            self.assertTrue(filecmp.cmp(os.path.join(folder, objective, "python", "grid.xyz"),
                                        os.path.join(folder, objective, "native", "grid.xyz"),
                                        shallow=False), objective)
        # At the template's defaults (stop 14): 51.97 against 66.98 (64.37 as placed). With
        # n_span 8, as this test ran until stop 13 to save time, the grids of stop 14 give
        # 51.55 against 51.25: there the min-angle run does not raise it. Since stop 18
        # (U_M's inlet edge capped, n_up / n_down 12; the min-angle run's second search for
        # fewer cells failing checkMesh's determinant) the min-angle run no longer raises it
        # either (stop 17: 42.69 against 67.71), so the objective is held to lower it well
        # below the placed grid's, measured here.
        placed = subprocess.run([sys.executable, "-m", "blockforge"] + arguments +
                                ["--no-optimize", "-o", os.path.join(folder, "placed.xyz")],
                                capture_output=True, text=True)
        self.assertEqual(placed.returncode, 0, placed.stderr)
        line = next(l for l in placed.stdout.splitlines()
                    if l.strip().startswith("NonOrthogonality"))
        self.assertLess(largest["non-orthogonality"], float(line.split()[-1]) - 15.0, largest)
        run = subprocess.run([CLI, CYLINDER, "--objective", "smoothness", "-o", "x.foam"],
                             capture_output=True, text=True)
        self.assertEqual(run.returncode, 2)
        self.assertIn("--objective must be", run.stderr)

    def test_vtm_same_blocks_names_points_as_python(self):
        """The native .vtm (written without VTK) reads back with vtkXMLMultiBlockDataReader
        as the Python command line's .vtm: the same blocks in the same order, the same
        names, bit-identical points; pieces raw binary in a fresh NAME.pieces-ID/ folder;
        writing again replaces the older pieces folder; --compress is refused clearly."""
        from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

        folder = bftest.output_path("native_vtm")
        shutil.rmtree(folder, ignore_errors=True)
        cases = {"cylinder": [CYLINDER, "-d", "0.5"],
                 "axial_oh": [AXIAL_OH, "-i", DISTRIBUTOR_INF, "-p", "n_span=8"]}
        for case, arguments in cases.items():
            grids = {}
            for label, command in (("python", [sys.executable, "-m", "blockforge"]),
                                   ("native", [CLI])):
                path = os.path.join(folder, case, label, "grid.vtm")
                # pieces a killed run left (its process is gone) are removed by the next run
                os.makedirs(os.path.join(folder, case, label, "grid.pieces-999999999-0badf00d"))
                for _ in range(2):  # the second run replaces the first one's pieces
                    run = subprocess.run(command + arguments + ["--no-optimize", "-o", path],
                                         capture_output=True, text=True)
                    self.assertEqual(run.returncode, 0, run.stderr)
                entries = os.listdir(os.path.dirname(path))
                self.assertEqual(len(entries), 2, entries)
                pieces = next(e for e in entries if e != "grid.vtm")
                self.assertRegex(pieces, r"^grid\.pieces-\d+-[0-9a-f]+$")
                reader = vtkXMLMultiBlockDataReader()
                reader.SetFileName(path)
                reader.Update()
                grids[label] = [(name, block.GetExtent(), bftest.points(block))
                                for name, block in bftest.named_leaves(reader.GetOutput())]
            self.assertGreater(len(grids["native"]), 3, case)
            self.assertEqual(len(grids["native"]), len(grids["python"]), case)
            for (name, dims, xyz), (py_name, py_dims, py_xyz) in zip(grids["native"],
                                                                     grids["python"]):
                self.assertEqual(name, py_name, case)
                self.assertEqual(dims, py_dims, (case, name))
                self.assertEqual(xyz.dtype, np.float64)
                self.assertEqual(xyz.tobytes(), py_xyz.tobytes(), (case, name))
        run = subprocess.run([CLI, CYLINDER, "--compress", "-o", os.path.join(folder, "z.vtm")],
                             capture_output=True, text=True)
        self.assertEqual(run.returncode, 2)
        self.assertIn("--compress", run.stderr)
        self.assertFalse(os.path.exists(os.path.join(folder, "z.vtm")))
        blocker = os.path.join(folder, "a_file")
        open(blocker, "w").close()
        run = subprocess.run([CLI, CYLINDER, "-o", os.path.join(blocker, "grid.vtm")],
                             capture_output=True, text=True)
        self.assertEqual(run.returncode, 1)
        self.assertIn("a_file", run.stderr)

    def assert_refused(self, command, option, values, message, folder):
        """Each of *values* given to *option* is refused with exit status 2, naming the
        option and *message*, and writes no grid."""
        for bad in values:
            path = os.path.join(folder, "bad.xyz")
            run = subprocess.run(command + [CYLINDER, option, bad, "-o", path],
                                 capture_output=True, text=True)
            self.assertEqual(run.returncode, 2, (command[0], option, bad))
            self.assertIn(option, run.stderr)
            self.assertIn(message, run.stderr)
            self.assertFalse(os.path.exists(path), (option, bad))

    def test_max_evaluations(self):
        """--max-evaluations N: both command lines take the optimizer's trial budget and
        write the same bytes; a budget that is not a positive whole number is refused."""
        folder = bftest.output_path("max_evaluations")
        shutil.rmtree(folder, ignore_errors=True)
        arguments = [AXIAL_OH, "-i", DISTRIBUTOR_INF]
        for label, command in (("python", [sys.executable, "-m", "blockforge"]),
                               ("native", [CLI])):
            run = subprocess.run(command + arguments + ["--max-evaluations", "12", "-o",
                                 os.path.join(folder, label, "grid.xyz")],
                                 capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertIn("optimizer: smallest element angle", run.stdout)
            self.assertLessEqual(int(re.search(r"(\d+) evaluations", run.stdout).group(1)), 12)
            self.assert_refused(command, "--max-evaluations", ("0", "-3", "2.5", "many"),
                                "whole number from 1 to 1000000", folder)
        self.assertTrue(filecmp.cmp(os.path.join(folder, "python", "grid.xyz"),
                                    os.path.join(folder, "native", "grid.xyz"), shallow=False))

    def test_max_interface_ratio(self):
        """--max-interface-ratio R: the optimizer holds the neighbour cell-size ratio across
        block interfaces to max(R, the placed grid's); 0 lets it go. On Rotor 37 at density 1
        the unheld optimum jumped 3.24 between U_M and U_R at the inlet (stop 17), 2.76
        between D_L and D_M at the outlet (stop 18, 1.46 held at the default 1.6); since stop
        19's thicker O-grid outer cell it jumps 1.64 (O_b against M_R), hardly over the
        default 1.6, so the hold is shown at 1.3: the placed grid's ratio (1.34) is then the
        bound, and the held optimum stays within it (1.33). Both command lines pass it on
        alike."""
        sys.path.insert(0, os.path.join(SOURCE, "Benchmark"))
        try:
            import interface_ratios
        finally:
            sys.path.pop(0)
        folder = bftest.output_path("max_interface_ratio")
        shutil.rmtree(folder, ignore_errors=True)
        arguments = [AXIAL_OH, "-i", ROTOR37_INF]

        def largest_ratio(path):
            blocks = interface_ratios.read_plot3d(path)
            points = np.concatenate([g.reshape(-1, 3) for g in blocks])
            size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
            return max(interface_ratios.interface_ratios(blocks, size).values())

        ratios = {}
        for label, command, extra in (("placed", [CLI], ["--no-optimize"]),
                                      ("held", [CLI], ["--max-interface-ratio", "1.3"]),
                                      ("free", [CLI], ["--max-interface-ratio", "0"]),
                                      ("free_python", [sys.executable, "-m", "blockforge"],
                                       ["--max-interface-ratio", "0"])):
            path = os.path.join(folder, label, "grid.xyz")
            run = subprocess.run(command + arguments + extra + ["-o", path],
                                 capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr)
            ratios[label] = largest_ratio(path)
        bound = max(1.3, ratios["placed"])
        self.assertLessEqual(ratios["held"], bound + 1e-9)
        self.assertGreater(ratios["free"], bound + 0.1)
        self.assertFalse(filecmp.cmp(os.path.join(folder, "free", "grid.xyz"),
                                     os.path.join(folder, "held", "grid.xyz"), shallow=False))
        self.assertTrue(filecmp.cmp(os.path.join(folder, "free", "grid.xyz"),
                                    os.path.join(folder, "free_python", "grid.xyz"),
                                    shallow=False))
        for command in ([sys.executable, "-m", "blockforge"], [CLI]):
            self.assert_refused(command, "--max-interface-ratio",
                                ("0.5", "-1", "nan", "inf", "many"),
                                "0 (not held) or a number >= 1", folder)

    def test_errors_name_the_problem(self):
        run = subprocess.run([CLI, os.path.join(SOURCE, "Testing", "Data", "bad_syntax.yaml"),
                              "-o", bftest.output_path("bad/x.foam")], capture_output=True, text=True)
        self.assertEqual(run.returncode, 1)
        self.assertIn("bad_syntax.yaml:", run.stderr)
        run = subprocess.run([CLI, CYLINDER, "-o", "x.vtk"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 2)
        self.assertIn("must end in .foam", run.stderr)


if __name__ == "__main__":
    bftest.run_tests()
