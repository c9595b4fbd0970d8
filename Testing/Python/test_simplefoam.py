"""A flow computed on a BlockForge grid: the distributor passage (axial_passage_oh on
Data/distributor, density 0.5) written as an OpenFOAM case and run by simpleFoam for a
bounded number of iterations (Testing/Data/openfoam/distributor_passage: axial inlet
velocity with swirl, outlet pressure, walls, cyclic periodic sides, k-omega SST).
Asserted: the solver ends normally and every residual falls."""
import os
import shutil
import unittest

import numpy as np

import blockforge
from blockforge import writers

import bftest
from bftest import DISTRIBUTOR_INF, SOURCE
import foamtools

CASE_SETUP = os.path.join(SOURCE, "Testing", "Data", "openfoam", "distributor_passage")
ITERATIONS = 60


class SimpleFoamTest(unittest.TestCase):
    def test_residuals_fall(self):
        case = bftest.output_path("simplefoam_distributor")
        shutil.rmtree(case, ignore_errors=True)
        shutil.copytree(CASE_SETUP, case)
        quality = blockforge.mesh_template(
            os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml"), density_multiplier=0.5,
            input_file=DISTRIBUTOR_INF)
        writers.write_solver_grid(quality.GetOutputDataObject(0),
                                  os.path.join(case, "distributor.foam"))
        # The case's own system/ files are kept by the writer.
        with open(os.path.join(case, "system", "controlDict")) as stream:
            self.assertIn("vaneForces", stream.read())
        status, log = foamtools.run_foam(["simpleFoam"], case, timeout=300)
        with open(os.path.join(case, "log.simpleFoam"), "w") as stream:
            stream.write(log)
        self.assertEqual(status, 0, log[-3000:])
        self.assertNotIn("FOAM FATAL", log)
        self.assertIn(f"\nTime = {ITERATIONS}\n", log)
        series = foamtools.residuals(log)
        self.assertEqual(set(series), {"Ux", "Uy", "Uz", "p", "k", "omega"})
        for field, values in series.items():
            with self.subTest(field=field):
                values = np.array(values)
                start = values[:5].max()
                # Two orders of magnitude down, and still falling over the last iterations
                # compared with the first third.
                self.assertLess(values[-1], 0.02 * start, values)
                third = len(values) // 3
                self.assertLess(np.median(values[-10:]), np.median(values[third:2 * third]))
        print("initial residuals, first -> last:",
              ", ".join(f"{f} {v[0]:.3g} -> {v[-1]:.3g}" for f, v in series.items()))


if __name__ == "__main__":
    bftest.run_tests()
