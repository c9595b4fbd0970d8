"""Renders a template's grid coloured by MinAngle (pvpython under xvfb-run -a).

Usage: xvfb-run -a pvpython scripts/render.py TEMPLATE OUTPUT.png [-i INPUT] [NAME=EXPR ...]

With -i (point data for templates with inputs, e.g. Data/distributor/BladeGen.inf) the
camera looks at the passage from outside the shroud, radially inwards, the axis up.
"""
import math
import os
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             LoadPlugin, ResetCamera, SaveScreenshot, Show)

LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=globals())

template, output = sys.argv[1], sys.argv[2]
arguments = sys.argv[3:]
input_file = None
if "-i" in arguments:
    at = arguments.index("-i")
    input_file = arguments[at + 1]
    del arguments[at:at + 2]
overrides = []
for item in arguments:
    name, _, value = item.partition("=")
    overrides += [name, value]
if input_file:
    points = TurboPointSetsReader(FileName=input_file)  # noqa: F821
    model = BlockTemplate(Input=points, TemplateFile=template, Parameters=overrides)  # noqa: F821
else:
    model = BlockTemplateSource(TemplateFile=template, Parameters=overrides)  # noqa: F821
grid = BlockMesher(Input=model)  # noqa: F821
quality = GridQuality(Input=grid)  # noqa: F821
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1200, 900]
view.OrientationAxesVisibility = 1
display = Show(quality, view)
display.SetRepresentationType("Surface With Edges")
ColorBy(display, ("CELLS", "MinAngle"))
lut = GetColorTransferFunction("MinAngle")
lut.ApplyPreset("Rainbow Uniform", True)
lut.RescaleTransferFunction(0.0, 90.0)
display.SetScalarBarVisibility(view, True)
if input_file:
    quality.UpdatePipeline()
    x0, x1, y0, y1, z0, z1 = quality.GetDataInformation().GetBounds()
    centre = [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]
    radial = math.hypot(centre[0], centre[1]) or 1.0
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0] * 4.0, centre[1] * 4.0, centre[2]]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraParallelProjection = 1
else:
    view.CameraPosition = [3.0, -6.0, 8.0]
    view.CameraFocalPoint = [0.0, 0.0, 0.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
ResetCamera(view)
if input_file:
    view.CameraParallelScale = 0.72 * view.CameraParallelScale
SaveScreenshot(output, view, ImageResolution=[1200, 900])
print(f"wrote {output}")
