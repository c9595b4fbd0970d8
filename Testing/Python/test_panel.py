"""What the ParaView panel shows and does, through the proxies (pvpython): the template's
parameters with defaults, units and descriptions (information property TemplateParameters)
and the values of the last run; a template edited on disk is read again at the next
update, also after a failed run, and Reload / File > Reload Files re-read it; the reader
shows what its files say and marks the fallbacks; file hints on every file property and
.csv/.txt registered for File > Open; the first look is Surface With Edges, the class
chart has the classes on its x axis and only the cells as bars."""
import os
import shutil
import unittest

from paraview import servermanager
from paraview import simple

import bftest

bftest.load_plugin(globals())
TEMPLATE = bftest.CYLINDER


def information(proxy, name):
    proxy.UpdatePropertyInformation()
    return list(proxy.GetProperty(name))


def table(proxy):
    """The TemplateParameters rows as {name: (default, last run, unit, description)}."""
    values = information(proxy, "TemplateParameters")
    return {values[n]: tuple(values[n + 1:n + 5]) for n in range(0, len(values), 5)}


class TemplateParameters(unittest.TestCase):
    def test_listed_with_defaults_units_descriptions(self):
        source = BlockTemplateSource(TemplateFile=TEMPLATE)  # noqa: F821
        source.UpdatePipelineInformation()
        rows = table(source)
        self.assertEqual(list(rows)[:3], ["R", "B", "D"])
        self.assertEqual(rows["R"], ("0.5", "", "m", "cylinder radius"))
        self.assertEqual(rows["c45"][0], "cos(45deg)")
        self.assertEqual(rows["k_wall"][2], "-")
        self.assertEqual(len(rows), 8)
        source.Parameters = ["R", "0.6", "n_around", "2*8"]
        source.UpdatePipeline()
        rows = table(source)
        self.assertEqual(rows["R"][:2], ("0.5", "0.6"))
        self.assertEqual(rows["n_around"][1], "16")
        self.assertAlmostEqual(float(rows["c45"][1]), 0.5 ** 0.5, places=9)
        simple.Delete(source)

    def test_no_template_no_rows(self):
        source = BlockTemplateSource()  # noqa: F821
        self.assertEqual(information(source, "TemplateParameters"), [])
        simple.Delete(source)


class ReadAgain(unittest.TestCase):
    def setUp(self):
        self.path = bftest.output_path("edited_template.yaml")
        shutil.copyfile(TEMPLATE, self.path)

    def cells(self, proxy):
        """Cells of the proxy's output after an update of the pipeline where it runs (the
        client's data information is only refreshed when a property changes; a render in
        the GUI, like Fetch here, updates the pipeline)."""
        return servermanager.Fetch(proxy).GetNumberOfCells()

    def edit(self, old, new):
        with open(self.path) as stream:
            text = stream.read()
        self.assertIn(old, text)
        # Another size as well, so the edit is seen within one file-time tick.
        with open(self.path, "w") as stream:
            stream.write(text.replace(old, new) + "\n")

    def test_template_edited_on_disk_is_read_at_the_next_update(self):
        source = BlockTemplateSource(TemplateFile=self.path, PreviewCells=0)  # noqa: F821
        self.assertEqual(self.cells(source), 8192)
        self.edit("n_depth: 8 ", "n_depth: 4 ")
        self.assertEqual(self.cells(source), 4096)
        simple.Delete(source)

    def test_fixed_template_recovers_from_a_failed_run(self):
        self.edit("n_depth: 8 ", "n_depth: [8 ")  # YAML syntax error
        source = BlockTemplateSource(TemplateFile=self.path, PreviewCells=0)  # noqa: F821
        self.assertEqual(self.cells(source), 0)
        shutil.copyfile(TEMPLATE, self.path)
        with open(self.path, "a") as stream:
            stream.write("\n\n")
        self.assertEqual(self.cells(source), 8192)
        simple.Delete(source)

    def test_reload_files(self):
        source = BlockTemplateSource(TemplateFile=self.path, PreviewCells=0)  # noqa: F821
        self.assertEqual(self.cells(source), 8192)
        helper = servermanager.vtkSMReaderReloadHelper()
        self.assertTrue(helper.SupportsReload(source.SMProxy))
        self.assertTrue(helper.ReloadFiles(source.SMProxy))
        self.assertEqual(self.cells(source), 8192)
        simple.Delete(source)


class Reader(unittest.TestCase):
    def test_values_found_in_the_files(self):
        reader = TurboPointSetsReader(FileName=bftest.DISTRIBUTOR_INF)  # noqa: F821
        reader.UpdatePipelineInformation()
        found = [information(reader, name)[0] for name in
                 ("BladeCountInFiles", "AxisInFiles", "UnitsInFiles")]
        self.assertEqual(found, ["16", "Z", "M"])
        self.assertTrue(information(reader, "DescriptionFileRead")[0].endswith("BladeGen.inf"))
        simple.Delete(reader)

    def test_fallbacks_are_marked(self):
        # A plain point file without a description beside it: the fallbacks are used.
        folder = bftest.output_path("plain_points")
        os.makedirs(folder, exist_ok=True)
        path = os.path.join(folder, "hub.csv")
        with open(path, "w") as stream:
            for k in range(10):
                stream.write(f"0, {1 + 0.01 * k}, {0.1 * k}\n")
        reader = TurboPointSetsReader(FileName=path, BladeCount=7)  # noqa: F821
        reader.UpdatePipelineInformation()
        self.assertEqual(information(reader, "BladeCountInFiles")[0],
                         "(not in the files: 7 used)")
        self.assertEqual(information(reader, "AxisInFiles")[0], "(not in the files: Z used)")
        simple.Delete(reader)

    def test_file_hints_and_reader_factory(self):
        reader = TurboPointSetsReader(FileName=bftest.DISTRIBUTOR_INF)  # noqa: F821
        for name in ("FileName", "HubFile", "ShroudFile", "ProfileFile"):
            hints = reader.GetProperty(name).GetHints()
            chooser = hints.FindNestedElementByName("FileChooser") if hints else None
            self.assertIsNotNone(chooser, name)
            self.assertIn("csv", chooser.GetAttribute("extensions"), name)
        factory = servermanager.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
        session = servermanager.ActiveConnection.Session
        for extension in ("inf", "curve", "crv", "dat", "csv", "txt"):
            self.assertIn(extension, factory.GetSupportedFileTypes(session), extension)
        hints = reader.SMProxy.GetHints().FindNestedElementByName("ReloadFiles")
        self.assertEqual(hints.GetAttribute("property"), "Reload")
        simple.Delete(reader)


class FirstLook(unittest.TestCase):
    def test_representations_and_chart(self):
        source = BlockTemplateSource(TemplateFile=TEMPLATE)  # noqa: F821
        grid = BlockMesher(Input=source)  # noqa: F821
        quality = GridQuality(Input=grid)  # noqa: F821
        view = simple.CreateView("RenderView")
        for proxy in (source, grid, quality):
            display = simple.Show(proxy, view)
            self.assertEqual(display.Representation, "Surface With Edges")
        # What ParaView colours by after Apply: the active cell scalars.
        for proxy, array in ((grid, "BlockId"), (quality, "MinAngle")):
            attributes = proxy.GetDataInformation().DataInformation.GetCellDataInformation()
            active = [attributes.GetArrayInformation(n).GetName()
                      for n in range(attributes.GetNumberOfArrays())
                      if attributes.IsArrayAnAttribute(n) == 0]
            self.assertEqual(active, [array])
        chart = simple.CreateView("XYBarChartView")
        bars = simple.Show(simple.OutputPort(quality, 1), chart)
        self.assertEqual(bars.UseIndexForXAxis, 0)
        self.assertEqual(bars.XArrayName, "bin_extents")
        self.assertEqual(list(bars.SeriesVisibility), ["Cells"])
        classes = servermanager.Fetch(quality, idx=1)
        self.assertEqual([classes.GetValue(r, 2).ToDouble() for r in range(5)],
                         [10.0, 30.0, 50.0, 70.0, 85.0])
        for proxy in (quality, grid, source):
            simple.Delete(proxy)


class CachedRanges(unittest.TestCase):
    def test_cached_ranges_equal_computed_ones(self):
        """The ranges cached for ParaView's data information and colour maps (all,
        finite, per component and of the norm) equal those VTK computes afresh."""
        import numpy as np
        source = BlockTemplateSource(TemplateFile=TEMPLATE)  # noqa: F821
        quality = GridQuality(Input=BlockMesher(Input=source))  # noqa: F821
        quality.UpdatePipeline()
        grid = quality.GetClientSideObject().GetOutputDataObject(0)
        from vtkmodules.vtkCommonCore import vtkPoints
        for block in bftest.leaves(grid):
            # The bounds set with the points equal those vtkPoints computes afresh.
            fresh = vtkPoints()
            fresh.SetDataTypeToDouble()
            fresh.DeepCopy(block.GetPoints())
            self.assertNotEqual(block.GetPoints().GetClassName(), "vtkPoints")
            self.assertEqual(block.GetPoints().GetBounds(), fresh.GetBounds())
            self.assertEqual(block.GetBounds(), fresh.GetBounds())
            values = np.asarray(block.GetPoints().GetData())
            self.assertEqual(list(block.GetBounds()),
                             [float(f(values[:, c])) for c in range(3) for f in (np.min, np.max)])
            arrays = [block.GetPoints().GetData()] + [
                block.GetCellData().GetArray(n) for n in range(block.GetCellData().GetNumberOfArrays())]
            for array in arrays:
                cached = [array.GetRange(c) for c in range(-1, array.GetNumberOfComponents())]
                cached_finite = [array.GetFiniteRange(c)
                                 for c in range(-1, array.GetNumberOfComponents())]
                values = np.asarray(array).reshape(array.GetNumberOfTuples(), -1)
                fresh = [(float(np.sqrt((values ** 2).sum(axis=1).min())),
                          float(np.sqrt((values ** 2).sum(axis=1).max())))
                         if values.shape[1] > 1 else (float(values.min()), float(values.max()))]
                fresh += [(float(values[:, c].min()), float(values[:, c].max()))
                          for c in range(values.shape[1])]
                for a, b in zip(cached, fresh):
                    self.assertAlmostEqual(a[0], b[0], delta=1e-12 * max(1.0, abs(b[0])))
                    self.assertAlmostEqual(a[1], b[1], delta=1e-12 * max(1.0, abs(b[1])))
                self.assertEqual(cached, cached_finite)
                array.Modified()  # VTK drops the cache: computed afresh, the same
                self.assertEqual([array.GetRange(c) for c in range(array.GetNumberOfComponents())],
                                 cached[1:], array.GetName())


if __name__ == "__main__":
    bftest.run_tests()
