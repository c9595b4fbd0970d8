"""Hostile input through `import blockforge` and the command line (issue 12): messages that
survive any bytes, memory refusals, validated densities, the template reader's small cases,
and verified atomic writing under a file size limit and kills between its steps.

Run by CTest with /usr/bin/python3 and PYTHONPATH pointing at the build tree.
"""
import contextlib
import io
import os
import resource
import shutil
import subprocess
import sys
import textwrap
import time
import unittest

import blockforge
import blockforge.output
from blockforge.__main__ import main as blockforge_main
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

import bftest
from bftest import CYLINDER, DATA, DISTRIBUTOR_INF, OUTPUT, SOURCE, named_leaves

AXIAL_OH = os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml")
PYTHONPATH = os.environ.get("PYTHONPATH", "")


def run_main(*arguments):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = blockforge_main([os.fspath(a) for a in arguments])
    return status, out.getvalue(), err.getvalue()


def fresh_directory(name):
    directory = os.path.join(OUTPUT, "hardening", name)
    shutil.rmtree(directory, ignore_errors=True)
    os.makedirs(directory)
    return directory


def read_grid(path):
    reader = vtkXMLMultiBlockDataReader()
    reader.SetFileName(os.fsencode(path))
    reader.Update()
    return named_leaves(reader.GetOutput())


class MessagesTest(unittest.TestCase):
    """Stray bytes that are not UTF-8 reach the user escaped, never as a traceback."""

    def setUp(self):
        self.directory = fresh_directory("messages")
        with open(CYLINDER, "rb") as stream:
            text = stream.read()
        # a stray byte in a block name, in a file whose name has one too
        self.template = os.path.join(os.fsencode(self.directory), b"bad\xfe.yaml")
        with open(self.template, "wb") as stream:
            stream.write(text.replace(b"blocks:", b"blocks:\n  b\xff: {}", 1))
        # a stray byte at the end of a curve file line
        self.data = os.path.join(self.directory, "distributor")
        shutil.copytree(os.path.dirname(DISTRIBUTOR_INF), self.data)
        with open(os.path.join(self.data, "hub.curve"), "rb") as stream:
            lines = stream.read().split(b"\n")
        lines[4] += b"\xff"
        with open(os.path.join(self.data, "hub.curve"), "wb") as stream:
            stream.write(b"\n".join(lines))

    def test_template_name_and_file_name(self):
        with self.assertRaises(RuntimeError) as raised:
            blockforge.mesh_template(os.fsdecode(self.template))
        message = str(raised.exception)
        self.assertIn("bad\\xfe.yaml:", message)
        self.assertIn("block 'b\\xff'", message)
        status, _, err = run_main(os.fsdecode(self.template))
        self.assertEqual(status, 1)
        self.assertTrue(err.startswith("error: "), err)
        self.assertIn("block 'b\\xff'", err)
        self.assertNotIn("Traceback", err)

    def test_curve_file_line(self):
        status, _, err = run_main(AXIAL_OH, "-i", os.path.join(self.data, "BladeGen.inf"))
        self.assertEqual(status, 1)
        self.assertRegex(err, r"^error: .*hub\.curve:5: .*\\xff")

    def test_output_path(self):
        """A stray byte in the output name: the grid is written and readable (its pieces
        folder is named without the byte, so the .vtm stays valid UTF-8 XML)."""
        path = os.fsdecode(os.path.join(os.fsencode(self.directory), b"grid\xff.vtm"))
        status, out, err = run_main(CYLINDER, "-o", path)
        self.assertEqual(status, 0, err)
        self.assertIn("grid written to", out)
        self.assertIn("grid\\xff.vtm", out)
        self.assertEqual(len(read_grid(path)), 4)
        folder = blockforge.output.referenced_folders(path).pop()
        self.assertTrue(os.path.basename(folder).startswith("grid_.pieces-"), folder)

    def test_output_window_gets_the_escaped_text(self):
        """ParaView's Output Messages show what VTK's output window receives."""
        window = vtkStringOutputWindow()
        previous = vtkOutputWindow.GetInstance()
        vtkOutputWindow.SetInstance(window)
        try:
            source = blockforge.vtkBlockTemplateSource()
            source.SetTemplateFile(self.template)  # bytes: passed on unchanged
            source.Update()
        finally:
            vtkOutputWindow.SetInstance(previous)
        text = window.GetOutput()
        self.assertIsNotNone(text)
        self.assertIn("block 'b\\xff'", text)
        self.assertIn("bad\\xfe.yaml", text)

    def test_message_helper_never_fails(self):
        self.assertEqual(blockforge._message(None), "a message that is not valid UTF-8 text")
        self.assertEqual(blockforge.printable(b"a\xffb"), "a\\xffb")
        self.assertEqual(blockforge.printable(os.fsdecode(b"a\xffb")), "a\\xffb")


class MemoryTest(unittest.TestCase):
    """Grids too large are refused before anything is allocated, fast."""

    def refused(self, *arguments):
        start = time.perf_counter()
        status, out, err = run_main(*arguments)
        seconds = time.perf_counter() - start
        self.assertEqual(status, 1, out)
        self.assertNotIn("Traceback", err)
        return err, seconds

    def test_density_and_parameters(self):
        for arguments, needle in (
                (("-d", "1000"), "the grid would need 209 TB for 8.2e+12 nodes"),
                (("-p", "n_around=1e6"), "the grid would need"),
                (("-d", "20", "-m", "0.5"), "more than MaximumMemory (512 MB)")):
            err, seconds = self.refused(CYLINDER, *arguments)
            self.assertIn(needle, err)
            self.assertIn("lower the density multiplier or the cell counts", err)

    def test_huge_block(self):
        err, _ = self.refused(os.path.join(DATA, "two_blocks.yaml"), "-p", "n=10000")
        self.assertIn("the grid would need 51 TB for 2e+12 nodes", err)

    def test_densities_are_validated(self):
        for density in ("inf", "1e308", "0", "-1", "nan", "1000.5"):
            err, _ = self.refused(CYLINDER, "-d", density)
            self.assertIn("the density multiplier must be a number above 0 and at most 1000",
                          err)

    def test_quality_stage(self):
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(CYLINDER)
        mesher = blockforge.vtkBlockMesher()
        mesher.SetInputConnection(source.GetOutputPort())
        quality = blockforge.vtkGridQuality()
        quality.SetInputConnection(mesher.GetOutputPort())
        quality.SetMaximumMemory(1e-6)  # 1 kB: the 8192 cells need 480 kB
        errors = bftest.ErrorCollector(quality)
        quality.Update()
        self.assertTrue(errors.messages)
        self.assertIn("the quality measures would need 480 kB for 8.2e+03 cells, more than "
                      "MaximumMemory (1.05 kB)", blockforge._message(errors.messages[0]))

    def test_preview(self):
        source = blockforge.vtkBlockTemplateSource()
        source.SetTemplateFile(CYLINDER)
        source.SetPreviewCells(0)
        source.SetMaximumMemory(1e-6)
        errors = bftest.ErrorCollector(source)
        source.Update()
        self.assertIn("lower PreviewCells or the cell counts",
                      blockforge._message(errors.messages[0]))


@unittest.skipUnless(os.environ.get("BLOCKFORGE_CLI"), "BLOCKFORGE_CLI not set")
class NativeCommandLineTest(unittest.TestCase):
    """The native command line refuses and escapes like the Python one."""

    def run_native(self, *arguments):
        output = os.path.join(fresh_directory("native"), "case", "grid.foam")
        return subprocess.run([os.environ["BLOCKFORGE_CLI"]] + list(arguments) +
                              ["-o", output], capture_output=True, timeout=60)

    def test_refusals(self):
        for arguments, needle in (
                (["-d", "1000"], b"the grid would need 209 TB for 8.2e+12 nodes"),
                (["-d", "inf"], b"the density multiplier must be a number above 0"),
                (["-m", "0.00001"], b"more than MaximumMemory (10.5 kB)")):
            result = self.run_native(CYLINDER, *arguments)
            self.assertEqual(result.returncode, 1, result.stderr)
            self.assertIn(needle, result.stderr)

    def test_stray_bytes(self):
        template = os.path.join(fresh_directory("native_stray").encode(), b"bad\xfe.yaml")
        with open(CYLINDER, "rb") as stream:
            text = stream.read()
        with open(template, "wb") as stream:
            stream.write(text.replace(b"blocks:", b"blocks:\n  b\xff: {}", 1))
        result = self.run_native(os.fsdecode(template))
        self.assertEqual(result.returncode, 1)
        self.assertIn(b"bad\\xfe.yaml:", result.stderr)
        self.assertIn(b"block 'b\\xff'", result.stderr)
        result.stderr.decode("utf-8")  # valid UTF-8


class TemplateFileTest(unittest.TestCase):
    """The template reader's small cases, through the command line."""

    def setUp(self):
        self.directory = fresh_directory("template_files")

    def error(self, template):
        status, _, err = run_main(template)
        self.assertEqual(status, 1)
        self.assertTrue(err.startswith("error: "), err)
        return err

    def test_folder_and_endless_file(self):
        self.assertIn("is a folder, not a template file", self.error(self.directory))
        self.assertIn("'/dev/zero' is larger than 16 MB", self.error("/dev/zero"))

    def test_lone_cr_and_second_document(self):
        with open(CYLINDER, "rb") as stream:
            text = stream.read()
        mac = os.path.join(self.directory, "mac.yaml")
        with open(mac, "wb") as stream:
            stream.write(text.replace(b"\n", b"\r"))
        status, out, err = run_main(mac)
        self.assertEqual(status, 0, err)
        self.assertIn("cells: 8192", out)
        two = os.path.join(self.directory, "two.yaml")
        with open(two, "wb") as stream:
            stream.write(text + b"---\nblockforge: 1\n")
        self.assertIn("a second YAML document", self.error(two))


# A subprocess that writes the cylinder grid to argv[1], with os.rename / os.replace /
# shutil.rmtree of the writer replaced by a kill (os._exit) at call number argv[2].
KILL_AT_STEP = textwrap.dedent("""
    import os, shutil, sys
    import blockforge.output as output
    calls = [0]
    def step(function):
        def wrapped(*args, **kwargs):
            calls[0] += 1
            if calls[0] == int(sys.argv[2]):
                os._exit(9)
            return function(*args, **kwargs)
        return wrapped
    output.os = type(os)("os_wrapper")
    output.os.__dict__.update(os.__dict__)
    output.os.rename = step(os.rename)
    output.os.replace = step(os.replace)
    output.shutil = type(shutil)("shutil_wrapper")
    output.shutil.__dict__.update(shutil.__dict__)
    output.shutil.rmtree = step(shutil.rmtree)
    from blockforge.__main__ import main
    sys.exit(main([sys.argv[3], "-o", sys.argv[1]] + sys.argv[4:]))
""")


class WritingTest(unittest.TestCase):
    """What a failed or killed write leaves on disk: the older grid or the new one, whole."""

    def setUp(self):
        self.directory = fresh_directory("writing")
        self.path = os.path.join(self.directory, "grid.vtm")
        status, _, err = run_main(os.path.join(DATA, "two_blocks.yaml"), "-o", self.path)
        self.assertEqual(status, 0, err)
        with open(self.path, "rb") as stream:
            self.old_vtm = stream.read()
        self.old_listing = sorted(os.listdir(self.directory))

    def subprocess(self, arguments, limit=None):
        def set_limit():
            if limit is not None:
                resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        return subprocess.run([sys.executable] + arguments, capture_output=True, text=True,
                              errors="backslashreplace", preexec_fn=set_limit, timeout=120,
                              env=dict(os.environ, PYTHONPATH=PYTHONPATH))

    def assert_complete(self, expected_blocks):
        """The .vtm and exactly the pieces folder it references, readable and whole."""
        folders = blockforge.output.referenced_folders(self.path)
        self.assertEqual(len(folders), 1)
        leaves = read_grid(self.path)
        self.assertEqual(len(leaves), expected_blocks)
        for _, block in leaves:
            self.assertGreater(block.GetNumberOfCells(), 0)
            self.assertIsNotNone(block.GetCellData().GetArray("ScaledJacobian"))

    def test_file_size_limit(self):
        """A limit that cuts the pieces (or the .vtm) short: error, the old grid stays."""
        for limit in (100, 4000, 20000, 30000):  # the pieces are 38 kB each
            result = self.subprocess(["-m", "blockforge", CYLINDER, "-o", self.path], limit)
            self.assertEqual(result.returncode, 1, (limit, result.stdout, result.stderr))
            self.assertRegex(result.stderr, r"^error: could not write .*grid.vtm: ", limit)
            self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
            self.assertNotIn("Traceback", result.stderr)
            self.assertNotIn("grid written", result.stdout)
            with open(self.path, "rb") as stream:
                self.assertEqual(stream.read(), self.old_vtm, limit)
            self.assertEqual(sorted(os.listdir(self.directory)), self.old_listing, limit)
            self.assert_complete(2)

    def test_short_write_reported_as_success(self):
        """The XML writer can return success with error code 0 and pieces cut short (seen
        under a file size limit): the check of what was written refuses them."""
        import blockforge.output as output

        real = output._quiet_vtk

        class TruncateAfterWriting(real):
            def __exit__(self, *exc):
                for root, _, files in os.walk(self_test.directory):
                    for name in files:
                        if name.endswith(".vts") and ".staging" in root:
                            path = os.path.join(root, name)
                            os.truncate(path, os.path.getsize(path) // 2)
                return super().__exit__(*exc)

        self_test = self
        output._quiet_vtk = TruncateAfterWriting
        try:
            status, out, err = run_main(CYLINDER, "-o", self.path)
        finally:
            output._quiet_vtk = real
        self.assertEqual(status, 1)
        self.assertRegex(err, r"^error: .*_0.vts is incomplete after writing")
        self.assertNotIn("grid written", out)
        with open(self.path, "rb") as stream:
            self.assertEqual(stream.read(), self.old_vtm)
        self.assertEqual(sorted(os.listdir(self.directory)), self.old_listing)
        self.assert_complete(2)

    def test_kill_between_steps(self):
        """Killed at each rename or removal of the writer: the target is the old grid or
        the new one, whole; the next run removes what the killed one left."""
        script = os.path.join(self.directory, "..", "kill_at_step.py")
        with open(script, "w", encoding="utf-8") as stream:
            stream.write(KILL_AT_STEP)
        outcomes = []
        for step in range(1, 6):
            result = self.subprocess([script, self.path, str(step), CYLINDER])
            if result.returncode == 0:
                break  # every step passed: nothing left to kill
            self.assertEqual(result.returncode, 9, result.stderr)
            blocks = len(read_grid(self.path))
            self.assertIn(blocks, (2, 4))  # old (two blocks) or new (cylinder: four)
            self.assert_complete(blocks)
            outcomes.append(blocks)
            # the next run cleans up: only the .vtm and its pieces remain
            status, _, err = run_main(os.path.join(DATA, "two_blocks.yaml"), "-o", self.path)
            self.assertEqual(status, 0, err)
            folder = blockforge.output.referenced_folders(self.path).pop()
            self.assertEqual(sorted(os.listdir(self.directory)),
                             sorted(["grid.vtm", os.path.basename(folder)]))
        # steps: rename of the pieces, the publishing rename, removal of the old pieces,
        # removal of the staging folder
        self.assertEqual(outcomes, [2, 2, 4, 4])

    def test_leftovers_of_dead_processes_are_removed(self):
        dead = 2 ** 22 + 17  # above the default pid_max: no such process
        stale = [os.path.join(self.directory, f".grid.vtm.{dead}-abcd1234.staging"),
                 os.path.join(self.directory, f"grid.pieces-{dead}-abcd1234")]
        alive = os.path.join(self.directory, f"grid.pieces-{os.getppid()}-abcd1234")
        for folder in stale + [alive]:
            os.makedirs(folder)
        removed = blockforge.output.clean_leftovers(self.path)
        self.assertEqual(sorted(removed), sorted(stale))
        self.assertTrue(os.path.isdir(alive))  # a running process may still publish it
        shutil.rmtree(alive)
        self.assert_complete(2)


if __name__ == "__main__":
    bftest.run_tests()
