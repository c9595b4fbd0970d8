"""Client-server mode: pvpython connects to a pvserver on localhost (2 MPI ranks), loads
the plugin on the server, runs reader -> BlockTemplate -> BlockOptimizer -> BlockMesher ->
GridQuality there and fetches the result: every array of every cell equals the serial run
in this process, the class table arrives, and errors come back to the client with the
template's file and line. The first look is Surface With Edges coloured by block (not Outline).

Run by pvpython; starts `mpiexec -n 2 pvserver` itself and stops it at the end.
"""
import os
import socket
import subprocess
import time
import unittest

import numpy as np
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
from paraview import servermanager
from paraview import simple

import blockforge

import bftest

PLUGIN = os.environ["BLOCKFORGE_PLUGIN"]
TEMPLATE = os.path.join(bftest.SOURCE, "Templates", "axial_passage_oh.yaml")


def free_port():
    with socket.socket() as probe:
        probe.bind(("localhost", 0))
        return probe.getsockname()[1]


class ClientServer(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.port = free_port()
        command = ["mpiexec", "--allow-run-as-root", "--oversubscribe", "-n", "2", "pvserver",
                   f"--server-port={cls.port}", "--force-offscreen-rendering"]
        cls.log = bftest.output_path("pvserver.log")
        with open(cls.log, "w") as log:
            # pvpython is an MPI singleton: its Open MPI variables would make mpiexec's
            # children join it instead of starting a job of their own.
            environment = {key: value for key, value in os.environ.items()
                           if not key.startswith(("OMPI_", "PMIX_", "OPAL_", "PRTE_"))}
            cls.server = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT,
                                          env=environment)
        # The server prints "Accepting connection(s)" once it listens (no probe connection:
        # pvserver takes the first one as its client).
        deadline = time.time() + 60
        while time.time() < deadline and cls.server.poll() is None:
            with open(cls.log) as log:
                if "Accepting connection" in log.read():
                    break
            time.sleep(0.2)
        cls.connection = simple.Connect("localhost", cls.port)
        if not cls.connection:
            raise RuntimeError(f"no connection to pvserver on port {cls.port} (log {cls.log})")
        simple.LoadPlugin(PLUGIN, remote=True, ns=globals())

    @classmethod
    def tearDownClass(cls):
        simple.Disconnect()
        cls.server.terminate()
        try:
            cls.server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            cls.server.kill()

    def test_server_has_two_ranks(self):
        info = self.connection.GetNumberOfDataPartitions()
        self.assertEqual(info, 2)

    def test_pipeline_on_server_equals_serial(self):
        reader = TurboPointSetsReader(FileName=bftest.DISTRIBUTOR_INF)  # noqa: F821
        model = BlockTemplate(Input=reader, TemplateFile=TEMPLATE)  # noqa: F821
        # The serial run (mesh_template) optimizes by default: so does the server.
        optimized = BlockOptimizer(Input=model)  # noqa: F821
        grid = BlockMesher(Input=optimized)  # noqa: F821
        quality = GridQuality(Input=grid)  # noqa: F821
        quality.UpdatePipeline()
        fetched = servermanager.Fetch(quality)
        serial = blockforge.mesh_template(TEMPLATE, input_file=bftest.DISTRIBUTOR_INF)
        reference = dict(bftest.named_leaves(serial.GetOutputDataObject(0)))
        blocks = dict(bftest.named_leaves(fetched))
        self.assertEqual(sorted(blocks), sorted(reference))
        for name, block in reference.items():
            mine = blocks[name]
            np.testing.assert_array_equal(bftest.points(mine), bftest.points(block))
            for array in ("MinAngle", "MaxAngle", "NonOrthogonality", "Skewness",
                          "AspectRatio", "ScaledJacobian", "CellDeterminant", "BlockId"):
                a = np.asarray(mine.GetCellData().GetArray(array))
                b = np.asarray(block.GetCellData().GetArray(array))
                np.testing.assert_array_equal(a, b, err_msg=f"{name} {array}")
        classes = servermanager.Fetch(quality, idx=1)
        self.assertEqual(classes.GetNumberOfRows(), 5)
        self.assertEqual(sum(classes.GetValue(r, 1).ToInt() for r in range(5)), 12288)
        for proxy in (quality, grid, optimized, model, reader):
            simple.Delete(proxy)

    def test_solver_writers_on_the_server(self):
        """SaveData of BlockForge's writers: the server's ranks mesh their shares, its rank
        0 gathers and writes the serial run's bytes (annular sector: cyclic periodic)."""
        import filecmp
        import shutil
        from blockforge import writers

        template = os.path.join(bftest.SOURCE, "Templates", "annular_sector.yaml")
        source = BlockTemplateSource(TemplateFile=template)  # noqa: F821
        optimized = BlockOptimizer(Input=source)  # noqa: F821
        grid = BlockMesher(Input=optimized)  # noqa: F821
        quality = GridQuality(Input=grid)  # noqa: F821
        root = bftest.output_path("client_server_writers")
        shutil.rmtree(root, ignore_errors=True)
        serial = blockforge.mesh_template(template).GetOutputDataObject(0)
        for extension, files in (("foam", ["constant/polyMesh/" + name for name in (
                "points", "faces", "owner", "neighbour", "boundary")]),
                                 ("xyz", ["grid.xyz", "grid.nmf"])):
            simple.SaveData(os.path.join(root, "server", extension, "grid." + extension),
                            proxy=quality)
            writers.write_solver_grid(
                serial, os.path.join(root, "serial", extension, "grid." + extension))
            for name in files:
                self.assertTrue(filecmp.cmp(os.path.join(root, "server", extension, name),
                                            os.path.join(root, "serial", extension, name),
                                            shallow=False), name)
        for proxy in (quality, grid, optimized, source):
            simple.Delete(proxy)

    def test_error_reaches_the_client(self):
        source = BlockTemplateSource(  # noqa: F821
            TemplateFile=os.path.join(bftest.DATA, "bad_unknown_vertex.yaml"))
        messages = vtkStringOutputWindow()
        previous = vtkOutputWindow.GetInstance()
        vtkOutputWindow.SetInstance(messages)
        try:
            source.UpdatePipeline()
        finally:
            vtkOutputWindow.SetInstance(previous)
        self.assertEqual(source.GetDataInformation().GetNumberOfPoints(), 0)
        self.assertIn("bad_unknown_vertex.yaml:23: block 'left': unknown vertex 'a8'",
                      messages.GetOutput())
        simple.Delete(source)


if __name__ == "__main__":
    bftest.run_tests()
