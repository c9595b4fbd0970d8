"""pvpython tests of the TurboPointSetsReader proxy on the real NASA Rotor 37 exports in
Data/rotor37 (TurboGrid/BladeGen .inf + .curve, and the multi-section .dat set).

Run by CTest with pvpython; BLOCKFORGE_PLUGIN is the plugin library of the build tree.
"""
import os
import unittest

from paraview import servermanager
from paraview.simple import Delete, OpenDataFile
import numpy as np

import bftest
from bftest import ROTOR37_INF, SOURCE, points

ROTOR37 = os.path.join(SOURCE, "Data", "rotor37")
DAT = os.path.join(ROTOR37, "dat")

bftest.load_plugin(globals())


def named_blocks(multiblock):
    return {multiblock.GetMetaData(i).Get(multiblock.NAME()): multiblock.GetBlock(i)
            for i in range(multiblock.GetNumberOfBlocks())}


def field(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    if array is None:
        return None
    if array.IsA("vtkStringArray"):
        return array.GetValue(0)
    values = array.GetTuple(0)
    return values[0] if len(values) == 1 else values


def axial_radius(xyz, axis):
    axis = np.asarray(axis)
    axial = xyz @ axis
    radial = np.linalg.norm(xyz - np.outer(axial, axis), axis=1)
    return axial, radial


def read(proxy):
    proxy.UpdatePipeline()
    return servermanager.Fetch(proxy)


class ReaderTest(unittest.TestCase):
    def check_rotor37(self, data, hub_points, shroud_points, axis_name):
        blocks = named_blocks(data)
        self.assertEqual(list(blocks), ["Hub", "Shroud", "Profiles"])
        self.assertEqual(blocks["Hub"].GetNumberOfPoints(), hub_points)
        self.assertEqual(blocks["Hub"].GetNumberOfLines(), 1)
        self.assertEqual(blocks["Shroud"].GetNumberOfPoints(), shroud_points)
        profiles = blocks["Profiles"]
        self.assertEqual(profiles.GetNumberOfBlocks(), 6)
        sections = named_blocks(profiles)
        self.assertEqual(list(sections), ["Profile %d (%d%%)" % (k + 1, 20 * k) for k in range(6)])
        for k, section in enumerate(sections.values()):
            self.assertEqual(section.GetNumberOfPoints(), 301)
            self.assertEqual(section.GetNumberOfLines(), 1)
            self.assertAlmostEqual(field(section, "SpanFraction"), 0.2 * k, places=12)
            self.assertEqual(field(section, "SpanGiven"), 1)
        self.assertEqual(field(data, "BladeCount"), 36)
        self.assertEqual(field(data, "Units"), "CM")
        self.assertEqual(field(data, "UnitScale"), 0.01)
        self.assertEqual(field(data, "AxisName"), axis_name)
        return blocks

    def test_open_turbogrid_inf(self):
        reader = OpenDataFile(ROTOR37_INF)
        self.assertIsNotNone(reader)
        self.assertEqual(reader.GetXMLLabel(), "Turbo Point Sets Reader")
        self.assertEqual(reader.FileName, ROTOR37_INF)
        data = read(reader)
        blocks = self.check_rotor37(data, 211, 209, "Z")
        self.assertEqual(field(data, "Axis"), (0.0, 0.0, 1.0))
        # Metres: the export is in cm.
        np.testing.assert_allclose(points(blocks["Hub"])[0], [0.174036479, -0.0206644903, -0.0419],
                                   rtol=0, atol=1e-15)
        self.assertTrue(field(blocks["Hub"], "SourceFile").endswith("hub.curve"))
        Delete(reader)

    def test_open_dat_set(self):
        # Every member of the set, and its Info.txt, opens the whole set with this reader
        # (not the Tecplot readers that also claim .dat, nor the CSV reader for .txt).
        for name in ("profile_R37.dat", "hub_R37.dat", "Info.txt"):
            reader = OpenDataFile(os.path.join(DAT, name))
            self.assertEqual(reader.GetXMLLabel(), "Turbo Point Sets Reader", name)
            data = read(reader)
            blocks = self.check_rotor37(data, 30, 30, "X")
            self.assertEqual(field(data, "Axis"), (1.0, 0.0, 0.0))
            np.testing.assert_allclose(points(blocks["Hub"])[0], [-0.0419, 0, 0.1752590003],
                                       rtol=0, atol=1e-15)
            Delete(reader)

    def test_both_layouts_are_the_same_rotor(self):
        tg_reader = OpenDataFile(ROTOR37_INF)
        dat_reader = OpenDataFile(os.path.join(DAT, "profile_R37.dat"))
        tg, dat = read(tg_reader), read(dat_reader)
        tg_blocks, dat_blocks = named_blocks(tg), named_blocks(dat)
        for a, b in zip(named_blocks(dat_blocks["Profiles"]).values(),
                        named_blocks(tg_blocks["Profiles"]).values()):
            za, ra = axial_radius(points(a), field(dat, "Axis"))
            zb, rb = axial_radius(points(b), field(tg, "Axis"))
            np.testing.assert_allclose(za, zb, rtol=0, atol=1e-8)
            np.testing.assert_allclose(ra, rb, rtol=0, atol=1e-8)
        for part in ("Hub", "Shroud"):
            z_dat, r_dat = axial_radius(points(dat_blocks[part]), field(dat, "Axis"))
            z_tg, r_tg = axial_radius(points(tg_blocks[part]), field(tg, "Axis"))
            self.assertAlmostEqual(z_dat[0], z_tg[0], places=12)
            self.assertAlmostEqual(z_dat[-1], z_tg[-1], places=12)
            deviation = np.abs(np.interp(z_dat, z_tg, r_tg) - r_dat).max()
            self.assertLess(deviation, 1e-5, part)  # metres; measured 6e-6
        Delete(tg_reader)
        Delete(dat_reader)

    def test_properties_fallbacks_and_domains(self):
        path = bftest.output_path("reader_points.csv")
        with open(path, "w") as stream:
            stream.write("x,y,z\n0,0,10\n1,0,10\n2,0,11\n3,0,12\n")
        reader = TurboPointSetsReader(FileName=path)  # noqa: F821 (from LoadPlugin)
        self.assertEqual(reader.BladeCount, 0)
        self.assertEqual(reader.Axis, "Z")
        self.assertEqual(reader.Units, "M")
        units = reader.GetProperty("Units").SMProperty.GetDomain("list")
        self.assertEqual([units.GetString(i) for i in range(units.GetNumberOfStrings())],
                         ["M", "CM", "MM", "IN", "FT"])
        reader.BladeCount = 5
        reader.Axis = "X"
        reader.Units = "MM"
        data = read(reader)
        self.assertEqual(field(data, "BladeCount"), 5)
        self.assertEqual(field(data, "AxisName"), "X")
        self.assertEqual(field(data, "UnitScale"), 0.001)
        blocks = named_blocks(data)
        self.assertIsNone(blocks["Hub"])
        profile = named_blocks(blocks["Profiles"])["Profile 1 (0%)"]
        np.testing.assert_allclose(points(profile)[-1], [0.003, 0, 0.012], rtol=0, atol=1e-15)
        # Replacing the hub file.
        reader.HubFile = os.path.join(DAT, "hub_R37.dat")
        self.assertEqual(named_blocks(read(reader))["Hub"].GetNumberOfPoints(), 30)
        Delete(reader)

    def test_tecplot_dat_still_goes_to_tecplot(self):
        path = bftest.output_path("reader_tecplot.dat")
        with open(path, "w") as stream:
            stream.write('TITLE = "t"\nVARIABLES = "X", "Y", "Z"\n'
                         'ZONE I=2, F=POINT\n0 0 0\n1 0 0\n')
        reader = OpenDataFile(path)
        self.assertNotEqual(reader.GetXMLLabel(), "Turbo Point Sets Reader")
        Delete(reader)

    def test_open_sections_of_the_turbine_are_capped_as_asked(self):
        turbine = os.path.join(SOURCE, "Data", "turbine", "Info.txt")
        reader = TurboPointSetsReader(FileName=turbine)  # noqa: F821
        self.assertEqual(reader.TrailingEdgeCap, "Straight")
        sections = named_blocks(named_blocks(read(reader))["Profiles"])
        self.assertEqual(len(sections), 9)
        for name, section in sections.items():
            self.assertEqual(field(section, "Closure"), "capped straight", name)
            self.assertAlmostEqual(field(section, "GapFraction"), 0.0146, delta=2e-4)
            xyz = points(section)
            np.testing.assert_array_equal(xyz[0], xyz[-1])
        straight = points(sections["Profile 1 (0%)"])
        reader.TrailingEdgeCap = "Rounded"
        sections = named_blocks(named_blocks(read(reader))["Profiles"])
        rounded = points(sections["Profile 1 (0%)"])
        self.assertEqual(field(sections["Profile 1 (0%)"], "Closure"), "capped rounded")
        # The same sides, another cap: the rounded one reaches further downstream (+x).
        np.testing.assert_array_equal(rounded[:159], straight[:159])
        self.assertGreater(rounded[:, 0].max(), straight[:, 0].max() + 5e-6)
        Delete(reader)

    def test_compressor_export_style(self):
        compressor = os.path.join(SOURCE, "Data", "compressor", "rotor.inf")
        data = read(TurboPointSetsReader(FileName=compressor))  # noqa: F821
        self.assertEqual(field(data, "AxisName"), "Y")
        self.assertEqual(field(data, "Units"), "IN")
        self.assertEqual(field(data, "UnitScale"), 0.0254)
        sections = named_blocks(named_blocks(data)["Profiles"])
        self.assertEqual(len(sections), 25)
        self.assertIn("Profile 3 (8.33333%)", sections)
        for name, section in sections.items():
            self.assertEqual(field(section, "Closure"), "joined", name)
            self.assertAlmostEqual(field(section, "GapFraction"), 2e-4, delta=1e-6)

    def test_error_names_file_and_line_and_leaves_output_empty(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow
        import blockforge

        path = bftest.output_path("reader_bad_profile.curve")
        with open(path, "w") as stream:
            stream.write("# Profile 1 at 0%\n0 0 1\n1 0 1\nnan 0 1\n3 0 1\n")
        reader = blockforge.vtkTurboPointSetsReader()
        reader.SetFileName(path)
        errors = bftest.ErrorCollector(reader).messages
        vtkOutputWindow.GetInstance().SetDisplayModeToNever()
        try:
            reader.Update()
        finally:
            vtkOutputWindow.GetInstance().SetDisplayModeToDefault()
        self.assertEqual(reader.GetOutput().GetNumberOfBlocks(), 0)
        self.assertEqual(len(errors), 1, errors)
        self.assertIn(path + ":4: 'nan' is not a finite number", errors[0])
        self.assertEqual(reader.CanReadFile(ROTOR37_INF), 1)
        self.assertEqual(reader.CanReadFile(os.path.join(DAT, "README.md")), 0)

        # Through the proxy: empty output, no crash.
        proxy = TurboPointSetsReader(FileName=path)  # noqa: F821
        self.assertEqual(read(proxy).GetNumberOfBlocks(), 0)
        Delete(proxy)


if __name__ == "__main__":
    bftest.run_tests()
