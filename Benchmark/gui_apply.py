"""Time from Apply to a rendered grid in the ParaView GUI (run by the GUI itself:
`xvfb-run -a paraview --dr --script=Benchmark/gui_apply.py --exit`, with PV_PLUGIN_PATH
naming the plugin to measure and BLOCKFORGE_SOURCE_DIR the source tree).

Applies the distributor's pipeline (reader -> BlockTemplate -> BlockMesher) and, for a
mesher at about 1 M cells, measures what Apply does: update the pipeline, gather the data
information, create the representation (surface extraction) and render
(BLOCKFORGE_REPRESENTATION forces a representation type). Medians of 5 (the
density alternates between 4.70 and 4.71 so that every Apply meshes again). Appends one
JSON line to $BLOCKFORGE_GUI_OUTPUT/gui_apply.jsonl.
"""
import json
import os
import statistics
import time

from paraview.simple import (Delete, GetActiveViewOrCreate, Hide, LoadPlugin, Render, Show)

source = os.environ["BLOCKFORGE_SOURCE_DIR"]
# Autoloaded already; this defines the proxies' constructors in this script.
LoadPlugin(os.path.join(os.environ["PV_PLUGIN_PATH"].split(":")[0], "BlockForge.so"),
           remote=False, ns=globals())
reader = TurboPointSetsReader(  # noqa: F821 (the autoloaded plugin's proxy)
    FileName=os.path.join(source, "Data", "distributor", "BladeGen.inf"))
model = BlockTemplate(Input=reader,  # noqa: F821
                      TemplateFile=os.path.join(source, "Templates", "axial_passage_oh.yaml"))
model.UpdatePipeline()
view = GetActiveViewOrCreate("RenderView")
# "" keeps the plugin's default first look; e.g. "Surface With Edges" forces one.
representation = os.environ.get("BLOCKFORGE_REPRESENTATION", "")
apply_times, mesh_times = [], []
parts = {"mesh": [], "data_information": [], "show": [], "first_render": [], "render_again": []}
cells = 0
shown_as = ""
for run in range(5):
    mesher = BlockMesher(Input=model, DensityMultiplier=4.70 + 0.01 * (run % 2))  # noqa: F821
    start = time.perf_counter()
    mesher.UpdatePipeline()
    meshed = time.perf_counter()
    cells = mesher.GetDataInformation().GetNumberOfCells()
    informed = time.perf_counter()
    display = Show(mesher, view)
    if representation:
        display.SetRepresentationType(representation)
    shown = time.perf_counter()
    Render(view)
    rendered = time.perf_counter()
    apply_times.append(rendered - start)
    mesh_times.append(meshed - start)
    Render(view)  # what every later interaction costs (a camera move renders again)
    parts["mesh"].append(meshed - start)
    parts["data_information"].append(informed - meshed)
    parts["show"].append(shown - informed)
    parts["first_render"].append(rendered - shown)
    parts["render_again"].append(time.perf_counter() - rendered)
    shown_as = str(display.GetPropertyValue("Representation"))
    Hide(mesher, view)
    Delete(mesher)
result = {"plugin": os.environ.get("PV_PLUGIN_PATH", ""), "cells": cells,
          "representation": representation or "default", "shown_as": shown_as,
          "apply_to_render_s": statistics.median(apply_times),
          "mesh_s": statistics.median(mesh_times),
          "parts_s": {key: statistics.median(values) for key, values in parts.items()},
          "load": os.getloadavg()[0]}
with open(os.path.join(os.environ["BLOCKFORGE_GUI_OUTPUT"], "gui_apply.jsonl"), "a") as stream:
    stream.write(json.dumps(result) + "\n")
