"""pvpython tests of the BlockTemplate proxy (templates of format 2 applied to point sets)
through paraview.simple: point sets built in Python and saved as .vtm, and the real Rotor 37
export read by the TurboPointSetsReader, each -> BlockTemplate -> BlockMesher.

Run by CTest with pvpython; BLOCKFORGE_PLUGIN is the plugin library of the build tree.
"""
import math
import os
import unittest

from paraview import servermanager
from paraview.simple import Delete, OpenDataFile
from paraview.vtk.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIntArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkMultiBlockDataSet, vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter
import numpy as np

import bftest
from bftest import DATA, DISTRIBUTOR_INF, ROTOR37_INF, SOURCE, leaves, node_array, rotate_z

PASSAGE = os.path.join(DATA, "annular_passage.yaml")

# Defines TurboPointSetsReader, BlockTemplate, BlockMesher, ... in this module.
bftest.load_plugin(globals())


def polyline(points):
    data = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetDataTypeToDouble()
    for p in points:
        vtk_points.InsertNextPoint(*p)
    lines = vtkCellArray()
    lines.InsertNextCell(len(points))
    for k in range(len(points)):
        lines.InsertCellPoint(k)
    data.SetPoints(vtk_points)
    data.SetLines(lines)
    return data


def hub_radius(z):
    return 0.5 + 0.1 * z


def point_sets(blade_count=12):
    """Hub cone r = 0.5 + 0.1 z and shroud cylinder r = 1, at meridional angles 0.3 and
    -0.2, as named polylines with the reader's machine field data."""
    zs = [-0.2 + 1.4 * k / 7 for k in range(8)]
    hub = [(hub_radius(z) * math.cos(0.3), hub_radius(z) * math.sin(0.3), z) for z in zs]
    shroud = [(math.cos(-0.2), math.sin(-0.2), z) for z in zs]
    root = vtkMultiBlockDataSet()
    for index, (name, points) in enumerate((("Hub", hub), ("Shroud", shroud))):
        root.SetBlock(index, polyline(points))
        root.GetMetaData(index).Set(vtkMultiBlockDataSet.NAME(), name)
    count = vtkIntArray()
    count.SetName("BladeCount")
    count.InsertNextValue(blade_count)
    axis = vtkDoubleArray()
    axis.SetName("Axis")
    axis.SetNumberOfComponents(3)
    axis.InsertNextTuple3(0.0, 0.0, 1.0)
    root.GetFieldData().AddArray(count)
    root.GetFieldData().AddArray(axis)
    return root


def save_point_sets(name, blade_count=12):
    path = bftest.output_path(name)
    writer = vtkXMLMultiBlockDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(point_sets(blade_count))
    writer.Write()
    return path


class BlockTemplateTest(unittest.TestCase):
    def check_passage(self, grid, pitch, hub_radius_of, shroud_radius, tolerance):
        blocks = leaves(grid)
        self.assertEqual(len(blocks), 2)
        for block in blocks:
            nodes = node_array(block)
            hub, shroud = nodes[0].reshape(-1, 3), nodes[-1].reshape(-1, 3)
            np.testing.assert_allclose(np.hypot(hub[:, 0], hub[:, 1]), hub_radius_of(hub[:, 2]),
                                       rtol=0, atol=tolerance)
            np.testing.assert_allclose(np.hypot(shroud[:, 0], shroud[:, 1]), shroud_radius(shroud[:, 2]),
                                       rtol=0, atol=tolerance)
            # periodic: the high side (i = max) is the low side (i = 0) rotated by a pitch
            low = nodes[:, :, 0, :].reshape(-1, 3)
            high = nodes[:, :, -1, :].reshape(-1, 3)
            np.testing.assert_allclose(rotate_z(low, pitch), high, rtol=0, atol=tolerance)

    def test_point_sets_to_grid(self):
        path = save_point_sets("passage_point_sets.vtm")
        points = OpenDataFile(path)
        template = BlockTemplate(Input=points, TemplateFile=PASSAGE)
        self.assertEqual(template.PreviewCells, 8)
        template.Parameters = ["n_pitch", "8"]
        template.UpdatePipeline()
        preview = servermanager.Fetch(template)
        self.assertEqual(preview.GetNumberOfBlocks(), 2)
        document = preview.GetFieldData().GetAbstractArray("BlockForgeModel").GetValue(0)
        self.assertIn("blockforge_model: 3", document)  # placement rules (projections)
        self.assertIn("kind: revolve", document)

        # port 1: the carriers the template declares, by name
        carriers = servermanager.Fetch(template, idx=1)
        names = [carriers.GetMetaData(i).Get(vtkMultiBlockDataSet.NAME())
                 for i in range(carriers.GetNumberOfBlocks())]
        self.assertEqual(names, ["hub_line", "shroud_line", "hub", "shroud", "radial_mid"])
        hub = dsa.WrapDataObject(carriers.GetBlock(2)).Points
        np.testing.assert_allclose(np.hypot(hub[:, 0], hub[:, 1]), hub_radius(hub[:, 2]),
                                   rtol=0, atol=1e-9)
        self.assertEqual(carriers.GetBlock(0).GetNumberOfPoints(), 257)

        mesher = BlockMesher(Input=template, DensityMultiplier=1.0)
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        cells = sum(b.GetNumberOfCells() for b in leaves(grid))
        self.assertEqual(cells, 2 * 8 * 5 * 4)
        self.check_passage(grid, 2 * math.pi / 12, hub_radius, lambda z: np.ones_like(z), 1e-9)
        for proxy in (mesher, template, points):
            Delete(proxy)

    def test_blade_count_from_input(self):
        path = save_point_sets("passage_point_sets_9.vtm", blade_count=9)
        points = OpenDataFile(path)
        template = BlockTemplate(Input=points, TemplateFile=PASSAGE)
        mesher = BlockMesher(Input=template)
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        self.check_passage(grid, 2 * math.pi / 9, hub_radius, lambda z: np.ones_like(z), 1e-9)
        for proxy in (mesher, template, points):
            Delete(proxy)

    def test_rotor37_passage(self):
        """The real Rotor 37 hub and shroud (cm, read in metres, 36 blades)."""
        reader = TurboPointSetsReader(FileName=ROTOR37_INF)
        template = BlockTemplate(Input=reader, TemplateFile=PASSAGE)
        template.Parameters = ["z_in", "0.0", "z_out", "0.04", "r_probe", "0.18", "r_outer", "0.25"]
        mesher = BlockMesher(Input=template)
        mesher.UpdatePipeline()
        grid = servermanager.Fetch(mesher)
        self.assertEqual(len(leaves(grid)), 2)
        # radii against the contours read by the reader, interpolated linearly (the
        # contours are dense: the spline and the polyline agree to well below 1e-4 m)
        data = servermanager.Fetch(reader)
        contours = {}
        for i in range(data.GetNumberOfBlocks()):
            name = data.GetMetaData(i).Get(vtkMultiBlockDataSet.NAME())
            if name in ("Hub", "Shroud"):
                p = np.array(dsa.WrapDataObject(data.GetBlock(i)).Points)
                contours[name] = (p[:, 2], np.hypot(p[:, 0], p[:, 1]))

        def radius_of(name):
            z, r = contours[name]
            return lambda q: np.interp(q, z, r)
        self.check_passage(grid, 2 * math.pi / 36, radius_of("Hub"), radius_of("Shroud"), 1e-4)
        for proxy in (mesher, template, reader):
            Delete(proxy)

    def test_rotor37_h_grid(self):
        """Templates/axial_passage_h.yaml on the Rotor 37 export: 8 blocks, periodic, sound."""
        reader = TurboPointSetsReader(FileName=ROTOR37_INF)
        template = BlockTemplate(Input=reader,
                                 TemplateFile=os.path.join(SOURCE, "Templates", "axial_passage_h.yaml"))
        mesher = BlockMesher(Input=template)
        quality = GridQuality(Input=mesher)
        quality.UpdatePipeline()
        grid = servermanager.Fetch(quality)
        blocks = {grid.GetMetaData(i).Get(vtkMultiBlockDataSet.NAME()): grid.GetBlock(i)
                  for i in range(grid.GetNumberOfBlocks())}
        self.assertEqual(sorted(blocks), ["AL", "AR", "BL", "BR", "DL", "DR", "UL", "UR"])
        jacobian = grid.GetFieldData().GetArray("ScaledJacobianSummary").GetTuple(0)
        self.assertGreater(jacobian[0], 0.0)
        for low, high in (("UL", "UR"), ("BL", "BR"), ("AL", "AR"), ("DL", "DR")):
            a, b = node_array(blocks[low]), node_array(blocks[high])
            np.testing.assert_allclose(rotate_z(a[:, :, 0, :].reshape(-1, 3), 2 * math.pi / 36),
                                       b[:, :, -1, :].reshape(-1, 3), rtol=0, atol=1e-12)
        for proxy in (quality, mesher, template, reader):
            Delete(proxy)

    def test_distributor_oh_grid(self):
        """Templates/axial_passage_oh.yaml on the distributor (16 vanes) through the proxies:
        TurboPointSetsReader -> BlockTemplate -> BlockMesher -> GridQuality."""
        reader = TurboPointSetsReader(FileName=DISTRIBUTOR_INF)
        template = BlockTemplate(Input=reader,
                                 TemplateFile=os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml"))
        mesher = BlockMesher(Input=template, DensityMultiplier=1.0)
        quality = GridQuality(Input=mesher)
        quality.UpdatePipeline()
        grid = servermanager.Fetch(quality)
        blocks = leaves(grid)
        self.assertEqual(len(blocks), 12)
        cells = sum(b.GetNumberOfCells() for b in blocks)
        self.assertEqual(cells, 12288)
        jacobian = np.concatenate([np.array(dsa.WrapDataObject(b).CellData["ScaledJacobian"])
                                   for b in blocks])
        self.assertEqual(len(jacobian), cells)
        self.assertGreater(jacobian.min(), 0.0)
        summary = grid.GetFieldData().GetArray("ScaledJacobianSummary").GetTuple(0)
        self.assertGreater(summary[0], 0.0)
        self.assertAlmostEqual(summary[0], jacobian.min(), places=12)
        counts = grid.GetFieldData().GetArray("MinAngleClassCounts")
        self.assertEqual(sum(counts.GetValue(i) for i in range(5)), cells)
        for proxy in (quality, mesher, template, reader):
            Delete(proxy)

    def test_errors_leave_empty_output(self):
        path = save_point_sets("passage_point_sets_err.vtm")
        points = OpenDataFile(path)
        broken = bftest.output_path("passage_bad_input.yaml")
        with open(PASSAGE) as source, open(broken, "w") as target:
            target.write(source.read().replace("hub: Hub ", "hub: Hbu "))
        template = BlockTemplate(Input=points, TemplateFile=broken)
        mesher = BlockMesher(Input=template)
        mesher.UpdatePipeline()
        self.assertEqual(servermanager.Fetch(template).GetNumberOfBlocks(), 0)
        self.assertEqual(servermanager.Fetch(mesher).GetNumberOfBlocks(), 0)
        for proxy in (mesher, template, points):
            Delete(proxy)


if __name__ == "__main__":
    bftest.run_tests()
