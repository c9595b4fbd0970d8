"""Renders a template's grid coloured by MinAngle (pvpython under xvfb-run -a).

Usage: xvfb-run -a pvpython scripts/render.py TEMPLATE OUTPUT.png [NAME=EXPR ...]
"""
import os
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             LoadPlugin, ResetCamera, SaveScreenshot, Show)

LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=globals())

template, output = sys.argv[1], sys.argv[2]
overrides = []
for item in sys.argv[3:]:
    name, _, value = item.partition("=")
    overrides += [name, value]
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
view.CameraPosition = [3.0, -6.0, 8.0]
view.CameraFocalPoint = [0.0, 0.0, 0.5]
view.CameraViewUp = [0.0, 0.0, 1.0]
ResetCamera(view)
SaveScreenshot(output, view, ImageResolution=[1200, 900])
print(f"wrote {output}")
