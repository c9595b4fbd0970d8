"""GUI test: the ParaView GUI itself, under xvfb-run, autoloads the plugin
(PV_PLUGIN_PATH), loads the example state doc/distributor.pvsm and saves a screenshot of
its layout (gui_distributor_state.py, run with `paraview --script=... --exit`); the
screenshot must match the baseline Testing/Data/Baseline/distributor_gui.png within a
threshold (vtkTesting's comparison: vtkImageDifference, thresholded error), and the two
screenshots with the grid recoloured and meshed denser must not, which shows that the
test fails when the colouring or the grid changes.

Run by /usr/bin/python3 (CTest). BLOCKFORGE_UPDATE_BASELINE=1 replaces the baseline with
the new screenshot (after a deliberate change).
"""
import os
import shutil
import sys
import unittest

from vtkmodules.vtkImagingCore import vtkImageDifference  # noqa: F401 (module check)
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter

import bftest

BASELINE = os.path.join(bftest.SOURCE, "Testing", "Data", "Baseline", "distributor_gui.png")
SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gui_distributor_state.py")
# vtkTesting's default threshold is 10 (thresholded error summed over pixel differences
# above a tolerance, per pixel); a changed colour map or grid gives thousands.
THRESHOLD = 10.0


def read_png(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def image_error(path, baseline, difference_path=None):
    """vtkTesting-style error of the image at `path` against `baseline`."""
    from vtkmodules.vtkImagingCore import vtkImageDifference
    difference = vtkImageDifference()
    difference.SetInputData(read_png(path))
    difference.SetImageData(read_png(baseline))
    difference.Update()
    if difference_path:
        writer = vtkPNGWriter()
        writer.SetFileName(difference_path)
        writer.SetInputConnection(difference.GetOutputPort())
        writer.Write()
    return difference.GetThresholdedError()


class GuiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.output = bftest.output_path("gui")
        cls.log, lines = bftest.run_gui(SCRIPT, cls.output, "gui_result.txt")
        cls.results = {}
        for key, value in lines:
            cls.results.setdefault(key, []).append(value)

    def test_gui_ran_with_the_plugin(self):
        self.assertIn("plugin_loaded", self.results, self.log[-3000:])
        self.assertEqual(self.results["plugin_loaded"], ["1"])
        self.assertEqual(self.results["cells"], ["12288"])

    def test_screenshot_matches_baseline(self):
        shot = os.path.join(self.output, "distributor_gui.png")
        self.assertTrue(os.path.exists(shot), self.log[-3000:])
        if os.environ.get("BLOCKFORGE_UPDATE_BASELINE") == "1":
            os.makedirs(os.path.dirname(BASELINE), exist_ok=True)
            shutil.copyfile(shot, BASELINE)
        error = image_error(shot, BASELINE, os.path.join(self.output, "distributor_gui_diff.png"))
        print(f"screenshot error against the baseline: {error:.3g} (threshold {THRESHOLD})")
        self.assertLessEqual(error, THRESHOLD)

    def test_changes_are_noticed(self):
        for name in ("distributor_gui_recoloured.png", "distributor_gui_denser.png"):
            shot = os.path.join(self.output, name)
            self.assertTrue(os.path.exists(shot), name)
            error = image_error(shot, BASELINE)
            print(f"{name}: error {error:.3g}")
            self.assertGreater(error, 10 * THRESHOLD, name)


if __name__ == "__main__":
    bftest.run_tests()
