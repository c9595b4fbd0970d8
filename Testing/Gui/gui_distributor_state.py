"""Run by the ParaView GUI itself (`paraview --script=THIS --exit`, under xvfb-run) from
test_gui.py: checks that the BlockForge plugin was autoloaded (PV_PLUGIN_PATH), loads the
example state doc/distributor.pvsm (paths relative to the source tree) and saves
screenshots of its layout for test_gui.py to compare with the baseline:
- distributor_gui.png: the state as it is;
- distributor_gui_recoloured.png: the grid coloured by BlockId instead of MinAngle;
- distributor_gui_denser.png: the grid meshed with DensityMultiplier 1.5.
The last two must differ from the baseline: they show that the comparison notices a
change of colouring or of grid. Results go to gui_result.txt (one "key value" a line).
"""
import os

from paraview import servermanager
from paraview.simple import (ColorBy, FindSource, GetLayouts, GetRepresentation, GetViews,
                             LoadState, Render, SaveScreenshot, SetActiveSource)

source = os.environ["BLOCKFORGE_SOURCE_DIR"]
output = os.environ["BLOCKFORGE_GUI_OUTPUT"]
results = []
manager = servermanager.vtkSMProxyManager.GetProxyManager().GetActiveSessionProxyManager()
plugin_loaded = all(manager.GetPrototypeProxy(group, name) is not None for group, name in (
    ("filters", "BlockMesher"), ("filters", "GridQuality"), ("filters", "BlockTemplate"),
    ("sources", "BlockForgeTurboPointSetsReader")))
results.append(f"plugin_loaded {int(plugin_loaded)}")

os.chdir(source)
LoadState(os.path.join(source, "doc", "distributor.pvsm"))
layout = list(GetLayouts().values())[0]


def shot(name):
    for view in GetViews():
        Render(view)
    path = os.path.join(output, name)
    SaveScreenshot(path, layout, ImageResolution=[1600, 900])
    results.append(f"screenshot {path}")


# The Properties panel builds its widgets for the active source: BlockTemplate's include
# the template parameter table (Plugin/pqBlockForgeParametersWidget).
SetActiveSource(FindSource("BlockTemplate1"))
shot("distributor_gui.png")
quality = FindSource("GridQuality1")
results.append(f"cells {quality.GetDataInformation().GetNumberOfCells()}")
angles = [view for view in GetViews() if view.GetXMLName() == "RenderView"][1]
display = GetRepresentation(quality, angles)
ColorBy(display, ("CELLS", "BlockId"))
shot("distributor_gui_recoloured.png")
ColorBy(display, ("CELLS", "MinAngle"))
mesher = FindSource("BlockMesher1")
mesher.DensityMultiplier = 1.5
shot("distributor_gui_denser.png")

with open(os.path.join(output, "gui_result.txt"), "w") as stream:
    stream.write("\n".join(results) + "\n")
