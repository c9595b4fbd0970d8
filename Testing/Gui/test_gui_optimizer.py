"""GUI test of BlockOptimizer's manual move: the ParaView GUI itself, under xvfb-run, with
the plugin autoloaded, runs gui_optimizer.py, which drags the optimizer's 3-D handle in the
render view and lets the Properties panel apply (Auto Apply). Checked here, on the numbers
it reports:

- shown as the panel's first Apply shows it, the grid is in the render view and the
  optimizer's history table in a spreadsheet (its view hint);
- choosing the control point m0 puts the handle on it, exactly, and shows it (the panel
  widget Plugin/pqBlockForgeHandleWidget; ParaView's own handle would stay at the origin,
  hidden);
- dragging the handle moves m0 to the handle's position projected onto its carrier (the
  line y = z = 0): the optimizer's located position and the mesher's node of m0 in both
  blocks are (x, 0, 0) with x the dropped handle's x (to round-off), the field data
  MinAngleAfter is the analytic corner angle atan(1 / |x - 1|);
- the automatic run then holds the moved point, and the history table has a row per
  evaluation, the last one's MinAngle that angle;
- the first look: Surface With Edges for the small grid, Surface for a grid above
  250,000 cells (Plugin/pqBlockForgeFirstLook).

Run by /usr/bin/python3 (CTest).
"""
import math
import os
import unittest

import bftest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gui_optimizer.py")


def corner_angle(x):
    """Smallest element angle of the symmetric template with m0 at (x, 0, 0)."""
    return math.degrees(math.atan2(1.0, abs(x - 1.0)))


class GuiOptimizerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.output = bftest.output_path("gui_optimizer")
        # The script ends the process itself once its steps are done.
        cls.log, lines = bftest.run_gui(SCRIPT, cls.output, "gui_optimizer_result.txt",
                                        exit_after_script=False)
        cls.values = {key: rest.split(" ") for key, rest in lines}

    def number(self, key, index=0):
        self.assertIn(key, self.values, f"{key} not reported: {self.values} {self.log[-2000:]}")
        return float(self.values[key][index])

    def vector(self, key):
        return [self.number(key, c) for c in range(3)]

    def test_no_errors_in_the_gui_script(self):
        self.assertNotIn("exception", self.values, self.values.get("exception"))
        self.assertNotIn("timeout", self.values, self.values.get("timeout"))
        self.assertEqual(self.number("plugin_loaded"), 1)

    def test_grid_and_history_shown(self):
        self.assertEqual(self.number("handle_exists"), 1)
        self.assertEqual(self.number("handle_visible_before"), 0)  # no control point yet
        self.assertEqual(self.number("applied_cells"), 128)
        self.assertEqual(self.number("grid_shown"), 1)
        self.assertEqual(self.number("history_shown"), 1)
        # the template's position of m0 before any move
        self.assertEqual(self.vector("node_before"), [0.6, 0.0, 0.0])

    def test_handle_is_put_on_the_chosen_control_point(self):
        self.assertEqual(self.vector("located"), [0.6, 0.0, 0.0])
        self.assertEqual(self.vector("handle_placed"), [0.6, 0.0, 0.0])
        self.assertEqual(self.vector("handle_property"), [0.6, 0.0, 0.0])
        self.assertEqual(self.number("handle_visible"), 1)

    def test_drag_moves_the_grid_to_the_projected_handle(self):
        dropped = self.vector("handle_dropped")
        self.assertEqual(self.vector("handle_property_after"), dropped)
        x = dropped[0]
        # dragged to the right in the view: along +x, well inside the carrier (0..2)
        self.assertGreater(x - 0.6, 0.05)
        self.assertLess(x, 1.9)
        expected = [x, 0.0, 0.0]
        for key in ("located_after", "node_after", "node_after_right"):
            for value, reference in zip(self.vector(key), expected):
                self.assertAlmostEqual(value, reference, delta=1e-12, msg=key)
        self.assertAlmostEqual(self.number("min_angle_after"), corner_angle(x), delta=1e-9)

    def test_history_and_fields_show(self):
        self.assertEqual(self.values.get("history_columns"),
                         ["Evaluation", "Objective", "MinAngle", "Time", "Feasible"])
        # no search: the input and the model moved by the handle
        self.assertEqual(self.number("history_rows_manual"), 2)
        # the automatic run holds the point moved by hand; one row per evaluation
        self.assertEqual(self.vector("node_after_automatic"), self.vector("node_after"))
        self.assertGreaterEqual(self.number("history_rows"), 1)
        self.assertEqual(self.number("history_rows"), self.number("evaluations"))
        self.assertAlmostEqual(self.number("history_last_min_angle"),
                               corner_angle(self.number("handle_dropped")), delta=1e-9)
        self.assertEqual(self.number("history_shown_after"), 1)

    def test_first_look_of_small_and_large_grids(self):
        self.assertEqual(self.values.get("small_grid_representation"), ["Surface_With_Edges"])
        self.assertGreater(self.number("large_grid_cells"), 250000)
        self.assertEqual(self.values.get("large_grid_representation"), ["Surface"])


if __name__ == "__main__":
    bftest.run_tests()
