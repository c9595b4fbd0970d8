"""Run by the ParaView GUI itself (`paraview --script=THIS`, under xvfb-run) from
test_gui_optimizer.py: drives BlockOptimizer's manual move through its 3-D handle and the
Properties panel, with Auto Apply on, the way a user does:

1. BlockTemplateSource (Testing/Data/optimizer_symmetric.yaml: the control point m0 on
   the straight carrier y = z = 0 of the bottom front edge, at x = 0.6) -> BlockOptimizer
   (Automatic off: manual moves only) -> BlockMesher, each output port shown in its
   preferred view as the panel's first Apply does (pqApplyBehavior: the grid in the
   render view, the optimizer's history table in a spreadsheet, by its view hint); the
   optimizer is the active source, so the panel shows its widgets with the handle.
2. HandleControlPoint = m0 and an update: the optimizer locates m0, and the panel widget
   (Plugin/pqBlockForgeHandleWidget) puts the handle on it and shows it.
3. The handle is dragged in the view with the mouse (interactor events at the handle's
   screen position, as Qt's mouse events arrive): the panel applies (Auto Apply), the
   optimizer projects the handle's position onto the carrier, and the mesher's grid
   follows.
4. Automatic on: the automatic run holds the moved point and fills the history table.
5. The first look of a small grid (Surface With Edges) and of one above 250,000 cells
   (Surface).

The steps run from a timer of the render window's interactor (Qt's event loop runs between
them: Auto Apply, renders). Results go to gui_optimizer_result.txt ("key value..." lines);
the process ends itself (os._exit) after writing them.
"""
import os
import traceback

from paraview import servermanager
from paraview.simple import (GetActiveViewOrCreate, GetSettingsProxy, GetViews, LoadPlugin,
                             Render, SetActiveSource, SetActiveView)
from vtkmodules.vtkRenderingCore import vtkCoordinate

source_dir = os.environ["BLOCKFORGE_SOURCE_DIR"]
output = os.environ["BLOCKFORGE_GUI_OUTPUT"]
results = []
manager = servermanager.vtkSMProxyManager.GetProxyManager().GetActiveSessionProxyManager()
results.append("plugin_loaded %d" % int(manager.GetPrototypeProxy("filters", "BlockOptimizer")
                                        is not None))
# Autoloaded already (PV_PLUGIN_PATH); this defines the proxies' constructors here.
LoadPlugin(os.path.join(os.environ["PV_PLUGIN_PATH"].split(":")[0], "BlockForge.so"),
           remote=False, ns=globals())

GetSettingsProxy("GeneralSettings").AutoApply = 1
view = GetActiveViewOrCreate("RenderView")
template = BlockTemplateSource(  # noqa: F821 (the plugin's proxy)
    TemplateFile=os.path.join(source_dir, "Testing", "Data", "optimizer_symmetric.yaml"))
optimizer = BlockOptimizer(Input=template, Automatic=0)  # noqa: F821
mesher = BlockMesher(Input=optimizer)  # noqa: F821
# Shown as the panel's Apply shows a new source (pqApplyBehavior): each output port in its
# preferred view (the proxies' hints: the history table of port 1 in a spreadsheet).
controller = servermanager.vtkSMParaViewPipelineControllerWithRendering()
for proxy, port in ((mesher, 0), (optimizer, 1)):
    controller.ShowInPreferredView(proxy.SMProxy, port, view.SMProxy)
Render(view)
view.ResetCamera()
SetActiveView(view)  # the spreadsheet became active; the handle lives in the render view
SetActiveSource(optimizer)


def handle():
    """The panel's 3-D handle: the widget proxy it adds to the render view."""
    hidden = view.GetProperty("HiddenRepresentations")
    for index in range(len(hidden)):
        if hidden[index].GetXMLName() == "HandleWidgetRepresentation":
            return hidden[index]
    return None


def record(key, *values):
    results.append(" ".join([key] + ["%.17g" % v if isinstance(v, float) else str(v)
                                      for v in values]))


def drag(pixels_x, pixels_y):
    """A left-button drag from the handle's screen position, as the view's interactor
    gets it from Qt's mouse events."""
    widget = handle()
    coordinate = vtkCoordinate()
    coordinate.SetCoordinateSystemToWorld()
    coordinate.SetValue(*widget.GetPropertyValue("WorldPosition"))
    x, y = coordinate.GetComputedDisplayValue(view.GetRenderer())
    interactor = view.GetInteractor()
    interactor.SetEventInformation(x, y, 0, 0, "\0", 0)
    interactor.MouseMoveEvent()
    interactor.LeftButtonPressEvent()
    for step in range(1, 11):
        interactor.SetEventInformation(int(x + pixels_x * step / 10),
                                       int(y + pixels_y * step / 10), 0, 0, "\0", 0)
        interactor.MouseMoveEvent()
    interactor.LeftButtonReleaseEvent()


def representation_of(proxy, port, view_type):
    """The visible representation of proxy's output port in a view of that type."""
    for candidate in GetViews():
        if candidate.GetXMLName() != view_type:
            continue
        for representation in candidate.Representations:
            producer = representation.GetProperty("Input")
            if producer is None or len(producer) == 0:
                continue
            if producer.GetProxy(0) == proxy.SMProxy and producer.GetOutputPortForConnection(0) == port \
                    and representation.GetPropertyValue("Visibility"):
                return representation
    return None


def grid_node(block_name, i, j, k):
    """Node (i, j, k) of the mesher's block `block_name`, from the pipeline's output."""
    grid = mesher.GetClientSideObject().GetOutputDataObject(0)
    iterator = grid.NewIterator()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        if iterator.GetCurrentMetaData().Get(grid.NAME()) == block_name:
            block = iterator.GetCurrentDataObject()
            ni, nj, _ = block.GetDimensions()
            return block.GetPoint(i + ni * (j + nj * k))
        iterator.GoToNextItem()
    return None


def field_value(name):
    info = optimizer.GetDataInformation().GetFieldDataInformation().GetArrayInformation(name)
    return info.GetComponentRange(0)[0] if info else float("nan")


state = {"tick": 0, "step": 0, "wait": 0}


def step():
    """One step per timer tick; returns "next", "wait" (again at the next tick) or "done"."""
    number = state["step"]
    if number == 0:
        if mesher.GetDataInformation().GetNumberOfCells() == 0:
            return "wait"
        record("applied_cells", mesher.GetDataInformation().GetNumberOfCells())
        record("grid_shown", int(representation_of(mesher, 0, "RenderView") is not None))
        record("history_shown", int(representation_of(optimizer, 1, "SpreadSheetView")
                                    is not None))
        record("node_before", *grid_node("left", 4, 0, 0))
        widget = handle()
        record("handle_exists", int(widget is not None))
        record("handle_visible_before", widget.GetPropertyValue("Visibility"))
        optimizer.HandleControlPoint = "m0"  # the combo box's property
        Render(view)  # the update an Apply makes: the optimizer locates m0
    elif number == 1:
        widget = handle()
        optimizer.UpdatePropertyInformation()
        record("located", *optimizer.GetPropertyValue("HandleControlPointPositionInfo"))
        record("handle_placed", *widget.GetPropertyValue("WorldPosition"))
        record("handle_visible", widget.GetPropertyValue("Visibility"))
        record("handle_property", *optimizer.GetPropertyValue("HandlePosition"))
        state["before_drag"] = list(widget.GetPropertyValue("WorldPosition"))
        drag(60, 0)
    elif number == 2:
        widget = handle()
        dropped = list(widget.GetPropertyValue("WorldPosition"))
        optimizer.UpdatePropertyInformation()
        located = list(optimizer.GetPropertyValue("HandleControlPointPositionInfo"))
        if located == state["before_drag"]:
            return "wait"  # Auto Apply has not run yet
        record("handle_dropped", *dropped)
        record("handle_property_after", *optimizer.GetPropertyValue("HandlePosition"))
        record("located_after", *located)
        record("node_after", *grid_node("left", 4, 0, 0))
        record("node_after_right", *grid_node("right", 0, 0, 0))
        record("min_angle_after", field_value("MinAngleAfter"))
        record("history_rows_manual",
               optimizer.GetClientSideObject().GetOutputDataObject(1).GetNumberOfRows())
        # The automatic run (as the Automatic check box and Apply give it) holds the
        # point moved by the handle and fills the history.
        optimizer.Automatic = 1
        optimizer.MaximumEvaluations = 20
        Render(view)
    elif number == 3:
        record("node_after_automatic", *grid_node("left", 4, 0, 0))
        record("evaluations", field_value("OptimizerEvaluations"))
        history = optimizer.GetClientSideObject().GetOutputDataObject(1)
        record("history_rows", history.GetNumberOfRows())
        record("history_columns", *[history.GetColumnName(c)
                                     for c in range(history.GetNumberOfColumns())])
        if history.GetNumberOfRows() > 0:
            minimum = history.GetColumnByName("MinAngle")
            record("history_last_min_angle", minimum.GetValue(minimum.GetNumberOfTuples() - 1))
        record("history_shown_after", int(representation_of(optimizer, 1, "SpreadSheetView")
                                          is not None))
        # The first look (Plugin/pqBlockForgeFirstLook): the small grid with its edges, a
        # grid above 250,000 cells as Surface.
        record("small_grid_representation", representation_of(mesher, 0, "RenderView")
               .SMProxy.GetProperty("Representation").GetElement(0).replace(" ", "_"))
        large = BlockMesher(  # noqa: F821
            Input=BlockTemplateSource(  # noqa: F821
                TemplateFile=os.path.join(source_dir, "Templates", "cylinder_in_box.yaml")),
            DensityMultiplier=4.0)
        controller.ShowInPreferredView(large.SMProxy, 0, view.SMProxy)
        shown = representation_of(large, 0, "RenderView")
        record("large_grid_cells", large.GetDataInformation().GetNumberOfCells())
        record("large_grid_representation",
               shown.SMProxy.GetProperty("Representation").GetElement(0).replace(" ", "_"))
        return "done"
    return "next"


def tick(_caller, _event):
    try:
        state["tick"] += 1
        outcome = step()
        if outcome == "wait":
            state["wait"] += 1
            if state["wait"] < 40:
                return
            results.append("timeout step %d" % state["step"])
            for candidate in GetViews():
                results.append("view %s %s" % (candidate.GetXMLName(), [
                    r.GetXMLName() for r in candidate.Representations]))
            outcome = "done"
        state["wait"] = 0
        state["step"] += 1
        if outcome != "done" and state["tick"] < 200:
            return
    except Exception:  # reported to the test, which fails on it
        results.append("exception " + traceback.format_exc().replace("\n", " | "))
    with open(os.path.join(output, "gui_optimizer_result.txt"), "w") as stream:
        stream.write("\n".join(results) + "\n")
    os._exit(0)


interactor = view.GetInteractor()
interactor.AddObserver("TimerEvent", tick)
interactor.CreateRepeatingTimer(500)
