"""Threads through vtkSMPTools (plain Python, `import blockforge`): the grid and every
GridQuality array are the same bits on ParaView's STDThread backend with 2 threads as on
the Sequential backend, at a size where the mesher's faces, the quality pass and the
array ranges are split into chunks (cylinder_in_box at density 5: 4 blocks of 256,000
cells)."""
import hashlib
import os
import subprocess
import sys
import unittest

import bftest

WORKER = """
import hashlib, sys
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkSMPTools
import blockforge
quality = blockforge.mesh_template(sys.argv[1], density_multiplier=5.0)
grid = quality.GetOutputDataObject(0)
digest = hashlib.blake2b(digest_size=16)
iterator = grid.NewIterator()
iterator.InitTraversal()
while not iterator.IsDoneWithTraversal():
    block = iterator.GetCurrentDataObject()
    digest.update(vtk_to_numpy(block.GetPoints().GetData()).tobytes())
    data = block.GetCellData()
    for name in sorted(data.GetArrayName(n) for n in range(data.GetNumberOfArrays())):
        digest.update(vtk_to_numpy(data.GetArray(name)).tobytes())
    iterator.GoToNextItem()
print("BACKEND", vtkSMPTools.GetBackend(), vtkSMPTools.GetEstimatedNumberOfThreads())
print("DIGEST", digest.hexdigest(), grid.GetNumberOfCells())
"""


def run(backend, threads):
    environment = dict(os.environ, VTK_SMP_BACKEND_IN_USE=backend,
                       VTK_SMP_MAX_THREADS=str(threads))
    output = subprocess.run([sys.executable, "-c", WORKER, bftest.CYLINDER], env=environment,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=300).stdout
    lines = dict(line.split(" ", 1) for line in output.splitlines()
                 if line.startswith(("BACKEND", "DIGEST")))
    return lines.get("BACKEND", output[-2000:]), lines.get("DIGEST", "")


class Threads(unittest.TestCase):
    def test_two_threads_give_the_same_bits(self):
        sequential = run("Sequential", 1)
        threaded = run("STDThread", 2)
        self.assertEqual(sequential[0], "Sequential 1")
        self.assertEqual(threaded[0], "STDThread 2")
        self.assertTrue(sequential[1].endswith(" 1024000"), sequential)
        self.assertEqual(sequential[1], threaded[1])


if __name__ == "__main__":
    bftest.run_tests()
