"""pvpython tests of the BlockOptimizer proxy through paraview.simple: the known optimum,
manual moves (ControlPointMoves and the handle), the history table, the class counts and
a blade passage.

Run by CTest with pvpython; BLOCKFORGE_PLUGIN is the plugin library of the build tree.
"""
import math
import os
import unittest

from paraview import servermanager
from paraview.simple import Delete
import numpy as np

import bftest
from bftest import DATA, DISTRIBUTOR_INF, SOURCE, leaves, points

bftest.load_plugin(globals())

SYMMETRIC = os.path.join(DATA, "optimizer_symmetric.yaml")
SKEW = os.path.join(DATA, "optimizer_skew.yaml")
AXIAL_OH = os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml")


def field_values(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    return [array.GetVariantValue(i).ToDouble() for i in range(array.GetNumberOfTuples())]


def corner_angle(offset):
    """The smallest element angle of the symmetric template with the control point
    `offset` (model units) away from x = 1."""
    return math.degrees(math.atan2(1.0, abs(offset)))


class OptimizerProxyTest(unittest.TestCase):
    def test_skew_distributions(self):
        # Off: nothing to move in a model without control points.
        source = BlockTemplateSource(TemplateFile=SKEW)
        optimizer = BlockOptimizer(Input=source, Tolerance=1e-12)
        self.assertEqual(optimizer.SkewDistributions, 1)
        optimizer.SkewDistributions = 0
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        before = field_values(model, "MinAngleBefore")[0]
        self.assertLess(before, 85.0)
        self.assertEqual(field_values(model, "MinAngleAfter")[0], before)
        # On (the default): the lower block's i-direction is skewed until the shared edge's nodes lie
        # under the top edge's geometric ones (every element angle 90 degrees).
        optimizer.SkewDistributions = 1
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        names = model.GetFieldData().GetAbstractArray("ControlPointNames")
        self.assertEqual([names.GetValue(i) for i in range(names.GetNumberOfValues())],
                         ["lower.skew_i"])
        self.assertGreater(field_values(model, "MinAngleAfter")[0], 90.0 - 1e-4)
        quality = GridQuality(Input=BlockMesher(Input=optimizer))
        quality.UpdatePipeline()
        grid = servermanager.Fetch(quality)
        self.assertAlmostEqual(grid.GetFieldData().GetArray("MinAngleSummary").GetTuple3(0)[0],
                               field_values(model, "MinAngleAfter")[0], places=9)
        for proxy in (quality, optimizer, source):
            Delete(proxy)

    def test_finds_the_symmetric_optimum(self):
        source = BlockTemplateSource(TemplateFile=SYMMETRIC)
        optimizer = BlockOptimizer(Input=source, Tolerance=1e-12)
        self.assertEqual(optimizer.Objective, "MinAngle")
        self.assertEqual(optimizer.MaximumEvaluations, 700)
        self.assertAlmostEqual(optimizer.MaximumInterfaceRatio, 1.6)
        self.assertEqual(optimizer.Algorithm, "Compass")
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        self.assertAlmostEqual(field_values(model, "MinAngleBefore")[0], corner_angle(0.4),
                               places=9)
        self.assertGreater(field_values(model, "MinAngleAfter")[0], 90.0 - 1e-3)
        # the cells along the skewed shared face are in 60-80, the others right-angled
        self.assertEqual(field_values(model, "MinAngleClassCountsBefore"), [0, 0, 0, 68, 60])
        self.assertEqual(field_values(model, "MinAngleClassCountsAfter"), [0, 0, 0, 0, 128])
        names = model.GetFieldData().GetAbstractArray("ControlPointNames")
        self.assertEqual([names.GetValue(i) for i in range(names.GetNumberOfValues())], ["m0.s"])
        # the preview's nodes of the shared face are at x = 1
        xyz = np.concatenate([points(block) for block in leaves(model)])
        self.assertAlmostEqual(float(np.abs(xyz[:, 0] - 1.0).min()), 0.0, places=5)
        # history table on port 1: one row per evaluation, the first is the start
        history = servermanager.Fetch(optimizer, idx=1)
        rows = history.GetNumberOfRows()
        self.assertEqual(rows, int(field_values(model, "OptimizerEvaluations")[0]))
        self.assertGreater(rows, 3)
        self.assertEqual([history.GetColumnName(c) for c in range(history.GetNumberOfColumns())],
                         ["Evaluation", "Objective", "MinAngle", "Time", "Feasible"])
        self.assertAlmostEqual(history.GetValue(0, 2).ToDouble(), corner_angle(0.4), places=9)
        # the result is one of the evaluations (the best by the smooth objective)
        angles = [history.GetValue(r, 2).ToDouble() for r in range(rows)]
        self.assertIn(field_values(model, "MinAngleAfter")[0], angles)
        # the mesher meshes the optimized model; GridQuality agrees
        quality = GridQuality(Input=BlockMesher(Input=optimizer))
        quality.UpdatePipeline()
        grid = servermanager.Fetch(quality)
        low = grid.GetFieldData().GetArray("MinAngleSummary").GetTuple3(0)[0]
        self.assertAlmostEqual(low, field_values(model, "MinAngleAfter")[0], places=9)
        Delete(quality)
        Delete(optimizer)
        Delete(source)

    def test_manual_move_and_handle(self):
        source = BlockTemplateSource(TemplateFile=SYMMETRIC)
        optimizer = BlockOptimizer(Input=source, Automatic=0)
        optimizer.ControlPointMoves = ["m0", "0.42"]
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        self.assertAlmostEqual(field_values(model, "MinAngleAfter")[0], corner_angle(0.16),
                               places=9)
        # the history holds the start and the moved model
        history = servermanager.Fetch(optimizer, idx=1)
        self.assertEqual(history.GetNumberOfRows(), 2)
        self.assertEqual(field_values(model, "OptimizerEvaluations"), [2])
        self.assertEqual([history.GetValue(r, 0).ToInt() for r in range(2)], [1, 2])
        self.assertAlmostEqual(history.GetValue(0, 2).ToDouble(), corner_angle(0.4), places=9)
        self.assertAlmostEqual(history.GetValue(1, 2).ToDouble(), corner_angle(0.16), places=9)
        self.assertEqual([history.GetValue(r, 4).ToInt() for r in range(2)], [1, 1])
        self.assertLess(history.GetValue(1, 1).ToDouble(), history.GetValue(0, 1).ToDouble())
        # held by the automatic run
        optimizer.Automatic = 1
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        self.assertAlmostEqual(field_values(model, "MinAngleAfter")[0], corner_angle(0.16),
                               places=9)
        # the handle: a newly chosen point is located first (nothing moves) ...
        optimizer.ControlPointMoves = []
        optimizer.Automatic = 0
        optimizer.HandleControlPoint = "m0"
        optimizer.HandlePosition = [0.7, 0.3, -0.2]
        optimizer.UpdatePipeline()
        optimizer.UpdatePropertyInformation()
        names = optimizer.GetProperty("ControlPointNamesInfo")
        self.assertEqual(sorted(names[i] for i in range(len(names))), ["a0", "b1", "m0"])
        located = optimizer.GetProperty("HandleControlPointPositionInfo")
        np.testing.assert_allclose([located[i] for i in range(3)], [0.6, 0.0, 0.0], atol=1e-12)
        model = servermanager.Fetch(optimizer)
        self.assertAlmostEqual(field_values(model, "MinAngleAfter")[0], corner_angle(0.4),
                               places=9)
        # ... then dragged: its position is projected onto the carrier (y = z = 0)
        optimizer.HandlePosition = [0.7, 0.3, -0.25]
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        self.assertAlmostEqual(field_values(model, "MinAngleAfter")[0], corner_angle(0.3),
                               places=9)
        optimizer.UpdatePropertyInformation()
        located = optimizer.GetProperty("HandleControlPointPositionInfo")
        np.testing.assert_allclose([located[i] for i in range(3)], [0.7, 0.0, 0.0], atol=1e-12)
        Delete(optimizer)
        Delete(source)

    def test_bad_move_gives_empty_output(self):
        source = BlockTemplateSource(TemplateFile=SYMMETRIC)
        optimizer = BlockOptimizer(Input=source)
        optimizer.ControlPointMoves = ["a2", "0.5"]
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        self.assertEqual(model.GetNumberOfBlocks(), 0)
        Delete(optimizer)
        Delete(source)

    def test_distributor_passage(self):
        reader = TurboPointSetsReader(FileName=DISTRIBUTOR_INF)
        template = BlockTemplate(Input=reader, TemplateFile=AXIAL_OH)
        optimizer = BlockOptimizer(Input=template, MaximumEvaluations=80)
        optimizer.UpdatePipeline()
        model = servermanager.Fetch(optimizer)
        before = field_values(model, "MinAngleBefore")[0]
        after = field_values(model, "MinAngleAfter")[0]
        self.assertGreater(after, before)
        self.assertEqual(sum(field_values(model, "MinAngleClassCountsAfter")), 12288)
        self.assertEqual(len(leaves(model)), 12)
        Delete(optimizer)
        Delete(template)
        Delete(reader)


if __name__ == "__main__":
    bftest.run_tests()
