"""pvpython: File > Save Data / SaveData offers BlockForge's OpenFOAM, Plot3D and CGNS
writers for the outputs of BlockMesher and GridQuality, and picks them by extension
(for .cgns before ParaView's own CGNS writer, which knows no block connectivity)."""
import os
import shutil
import unittest

from paraview import servermanager
from paraview.simple import SaveData

import bftest

bftest.load_plugin(globals())  # defines BlockTemplateSource, BlockMesher, GridQuality
ANNULAR = os.path.join(bftest.SOURCE, "Templates", "annular_sector.yaml")


class SaveDataTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        source = BlockTemplateSource(TemplateFile=ANNULAR)  # noqa: F821 (from the plugin)
        cls.mesher = BlockMesher(Input=source)  # noqa: F821
        cls.quality = GridQuality(Input=cls.mesher)  # noqa: F821

    def test_file_types_offered(self):
        factory = servermanager.vtkSMProxyManager.GetProxyManager().GetWriterFactory()
        for proxy in (self.mesher, self.quality):
            types = factory.GetSupportedFileTypes(proxy.SMProxy, 0)
            for description in ("BlockForge OpenFOAM case(*.foam )", "BlockForge Plot3D grid(*.xyz )",
                                "BlockForge CGNS grid(*.cgns )"):
                self.assertIn(description, types)

    def test_save_every_format(self):
        from vtkmodules.vtkIOGeometry import vtkOpenFOAMReader

        folder = bftest.output_path("save_data")
        shutil.rmtree(folder, ignore_errors=True)
        cells = 2592
        for label, proxy in (("mesher", self.mesher), ("quality", self.quality)):
            with self.subTest(output=label):
                case = os.path.join(folder, label, "case", "annular.foam")
                SaveData(case, proxy=proxy)
                reader = vtkOpenFOAMReader()
                reader.SetFileName(case)
                reader.Update()
                self.assertEqual(reader.GetOutput().GetBlock(0).GetNumberOfCells(), cells)
                SaveData(os.path.join(folder, label, "annular.xyz"), proxy=proxy, Binary=0)
                with open(os.path.join(folder, label, "annular.xyz")) as stream:
                    self.assertEqual(stream.readline().strip(), "6")
                self.assertTrue(os.path.exists(os.path.join(folder, label, "annular.nmf")))
                cgns = os.path.join(folder, label, "annular.cgns")
                SaveData(cgns, proxy=proxy)
                zones = bftest.read_cgns_zones(cgns)
                self.assertEqual(len(zones), 6)
                self.assertEqual(sum(zone.GetNumberOfCells() for zone in zones.values()), cells)


if __name__ == "__main__":
    bftest.run_tests()
