"""pvpython tests of every BlockForge proxy through paraview.simple.

Run by CTest with pvpython; BLOCKFORGE_PLUGIN is the plugin library of the build tree.
"""
import os
import unittest

from paraview import servermanager
from paraview.simple import Delete, OpenDataFile, SaveData
import numpy as np

import bftest
from bftest import CYLINDER, DATA, leaves, points

# Defines BlockTemplateSource, BlockMesher, GridQuality, ... in this module.
bftest.load_plugin(globals())


def all_points(multiblock):
    return np.concatenate([points(b) for b in leaves(multiblock)])


class ProxyTest(unittest.TestCase):
    def test_source_properties_and_preview(self):
        source = BlockTemplateSource(TemplateFile=CYLINDER)
        self.assertEqual(source.PreviewCells, 8)
        source.PreviewCells = 4
        source.Parameters = ["R", "0.75"]
        source.UpdatePipeline()
        preview = servermanager.Fetch(source)
        self.assertEqual(preview.GetNumberOfBlocks(), 4)
        for block in leaves(preview):
            self.assertTrue(all(d - 1 <= 4 for d in block.GetDimensions()))
        xyz = all_points(preview)
        self.assertAlmostEqual(float(np.hypot(xyz[:, 0], xyz[:, 1]).min()), 0.75, places=12)
        self.assertIsNotNone(preview.GetFieldData().GetAbstractArray("BlockForgeModel"))
        Delete(source)

    def test_mesher_and_quality(self):
        source = BlockTemplateSource(TemplateFile=CYLINDER)
        mesher = BlockMesher(Input=source, DensityMultiplier=0.5)
        self.assertAlmostEqual(mesher.DensityMultiplier, 0.5)
        quality = GridQuality(Input=mesher)
        quality.UpdatePipeline()
        grid = servermanager.Fetch(quality)
        cells = sum(b.GetNumberOfCells() for b in leaves(grid))
        self.assertEqual(cells, 4 * 8 * 8 * 4)
        for block in leaves(grid):
            for name in ("MinAngle", "MaxAngle", "NonOrthogonality", "Skewness",
                         "AspectRatio", "ScaledJacobian", "CellDeterminant", "BlockId"):
                self.assertIsNotNone(block.GetCellData().GetArray(name), name)
        table = servermanager.Fetch(quality, idx=1)
        self.assertEqual(table.GetNumberOfRows(), 5)
        self.assertEqual(sum(table.GetValue(r, 1).ToInt() for r in range(5)), cells)
        counts = grid.GetFieldData().GetArray("MinAngleClassCounts")
        self.assertEqual(sum(counts.GetValue(i) for i in range(5)), cells)
        # Range of MinAngle seen by the client-side data information.
        info = quality.GetCellDataInformation().GetArray("MinAngle")
        low, high = info.GetRange()
        self.assertGreater(low, 20.0)
        self.assertLessEqual(high, 90.0 + 1e-9)
        Delete(quality)
        Delete(mesher)
        Delete(source)

    def test_save_and_reload_vtm(self):
        path = bftest.output_path("proxy_model.vtm")
        source = BlockTemplateSource(TemplateFile=os.path.join(DATA, "two_blocks.yaml"))
        SaveData(path, proxy=source)
        reloaded = OpenDataFile(path)
        mesher = BlockMesher(Input=reloaded)
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        self.assertEqual(sum(b.GetNumberOfCells() for b in leaves(grid)), 2 * 64)
        xyz = all_points(grid)
        np.testing.assert_allclose(xyz.min(axis=0), [0, 0, 0], atol=1e-15)
        np.testing.assert_allclose(xyz.max(axis=0), [2, 1, 1], atol=1e-15)
        for proxy in (mesher, reloaded, source):
            Delete(proxy)

    def test_mesher_refuses_inverted_cells_unless_allowed(self):
        source = BlockTemplateSource(TemplateFile=os.path.join(DATA, "folded_spline.yaml"))
        mesher = BlockMesher(Input=source)
        self.assertEqual(mesher.AllowInvertedCells, 0)
        mesher.UpdatePipeline()
        self.assertEqual(servermanager.Fetch(mesher).GetNumberOfBlocks(), 0)
        mesher.AllowInvertedCells = 1
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        self.assertEqual(grid.GetNumberOfBlocks(), 1)
        self.assertGreater(grid.GetFieldData().GetArray("InvertedCellCount").GetValue(0), 0)
        Delete(mesher)
        Delete(source)

    def test_bad_template_gives_empty_output(self):
        source = BlockTemplateSource(TemplateFile=os.path.join(DATA, "bad_inside_out.yaml"))
        mesher = BlockMesher(Input=source)
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        self.assertEqual(grid.GetNumberOfBlocks(), 0)
        Delete(mesher)
        Delete(source)


if __name__ == "__main__":
    bftest.run_tests()
