"""Writes the ParaView state doc/distributor.pvsm (pvpython, run from the repository root):
the distributor's point data -> axial_passage_oh -> BlockMesher -> GridQuality, shown as
- left: the decomposition (the template's blocks, coloured by block, with edges);
- right, top: the grid coloured by MinAngle (0-90 degrees), translucent, with the cells
  below 30 degrees picked out by a Threshold (opaque magenta, with edges);
- right, bottom: the paper's MinAngle classes as a bar chart (cells per class).
Both 3-D views look at the passage from outside the shroud, radially inwards, axis up.

Paths in the state are relative to the repository root: load it from there
(`paraview --state=doc/distributor.pvsm`, or File > Load State with ParaView started in
the repository root). Usage: pvpython scripts/distributor_state.py [OUTPUT.pvsm]
"""
import math
import os
import sys

from paraview.simple import (AssignViewToLayout, ColorBy, CreateLayout, CreateView,
                             GetColorTransferFunction, GetOpacityTransferFunction, LoadPlugin, OutputPort, SaveState,
                             SetActiveView, Show, Threshold)

LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=globals())
output = sys.argv[1] if len(sys.argv) > 1 else os.path.join("doc", "distributor.pvsm")

reader = TurboPointSetsReader(FileName=os.path.join("Data", "distributor", "BladeGen.inf"))  # noqa: F821
model = BlockTemplate(Input=reader,  # noqa: F821
                      TemplateFile=os.path.join("Templates", "axial_passage_oh.yaml"))
grid = BlockMesher(Input=model)  # noqa: F821
quality = GridQuality(Input=grid)  # noqa: F821
bad = Threshold(Input=quality, Scalars=["CELLS", "MinAngle"], LowerThreshold=0.0,
                UpperThreshold=30.0, ThresholdMethod="Between")
quality.UpdatePipeline()

layout = CreateLayout("BlockForge: distributor")
decomposition = CreateView("RenderView")
angles = CreateView("RenderView")
chart = CreateView("XYBarChartView")
AssignViewToLayout(view=decomposition, layout=layout, hint=0)
layout.SplitHorizontal(0, 0.5)
AssignViewToLayout(view=angles, layout=layout, hint=2)
layout.SplitVertical(2, 0.62)
AssignViewToLayout(view=chart, layout=layout, hint=6)
layout.SetSize(1600, 900)

x0, x1, y0, y1, z0, z1 = quality.GetDataInformation().GetBounds()
centre = [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]
size = max(x1 - x0, y1 - y0, z1 - z0)
radial = math.hypot(centre[0], centre[1]) or 1.0
for view in (decomposition, angles):
    view.OrientationAxesVisibility = 1
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0] + 3 * size * centre[0] / radial,
                           centre[1] + 3 * size * centre[1] / radial, centre[2]]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraParallelProjection = 1
    view.CameraParallelScale = 0.6 * (z1 - z0)

blocks = Show(OutputPort(model, 0), decomposition)
blocks.SetRepresentationType("Surface With Edges")
ColorBy(blocks, ("CELLS", "BlockId"))
block_colours = GetColorTransferFunction("BlockId")
block_colours.ApplyPreset("Jet", True)
block_colours.RescaleTransferFunction(0.0, 11.0)
block_colours.AutomaticRescaleRangeMode = "Never"
blocks.SetScalarBarVisibility(decomposition, False)

cells = Show(quality, angles)
cells.SetRepresentationType("Surface With Edges")
ColorBy(cells, ("CELLS", "MinAngle"))
cells.Opacity = 0.45
worst = Show(bad, angles)
worst.SetRepresentationType("Surface With Edges")
ColorBy(worst, None)
worst.DiffuseColor = [1.0, 0.0, 1.0]  # the cells below 30 degrees, in magenta
worst.AmbientColor = [1.0, 0.0, 1.0]
# After ColorBy, which rescales to the data: the full 0-90 degrees, fixed.
angle_colours = GetColorTransferFunction("MinAngle")
angle_colours.ApplyPreset("Rainbow Uniform", True)
angle_colours.AutomaticRescaleRangeMode = "Never"
angle_colours.RescaleTransferFunction(0.0, 90.0)
GetOpacityTransferFunction("MinAngle").RescaleTransferFunction(0.0, 90.0)
cells.SetScalarBarVisibility(angles, True)

bars = Show(OutputPort(quality, 1), chart)
bars.UseIndexForXAxis = 0
bars.XArrayName = "bin_extents"
bars.SeriesVisibility = ["Cells"]
chart.ChartTitle = "MinAngle classes"
chart.BottomAxisTitle = "MinAngle [deg]"
chart.LeftAxisTitle = "cells"
chart.ShowLegend = 0
chart.BottomAxisUseCustomRange = 1
chart.BottomAxisRangeMinimum = 0.0
chart.BottomAxisRangeMaximum = 95.0
chart.BottomAxisUseCustomLabels = 1
chart.BottomAxisLabels = ["10", "0-20", "30", "20-40", "50", "40-60", "70", "60-80",
                          "85", "80-90"]
SetActiveView(angles)
SaveState(output)
print(f"wrote {output}")
