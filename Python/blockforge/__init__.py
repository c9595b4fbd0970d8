"""BlockForge: block-structured hexahedral grids from decomposition templates.

The VTK classes are importable directly::

    import blockforge
    source = blockforge.vtkBlockTemplateSource()

and :func:`mesh_template` runs the whole pipeline in one call.
"""
# The wrapped classes derive from these VTK modules; import them first so their
# Python types are registered.
import os

from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkCommonExecutionModel  # noqa: F401

from .BlockForgeFilters import (  # noqa: F401
    vtkBlockCGNSWriter,
    vtkBlockFoamWriter,
    vtkBlockGridWriter,
    vtkBlockMesher,
    vtkBlockOptimizer,
    vtkBlockPlot3DWriter,
    vtkBlockTemplate,
    vtkBlockTemplateAlgorithm,
    vtkBlockTemplateSource,
    vtkGridQuality,
    vtkTurboPointSetsReader,
)

__all__ = [
    "vtkBlockCGNSWriter",
    "vtkBlockFoamWriter",
    "vtkBlockGridWriter",
    "vtkBlockMesher",
    "vtkBlockOptimizer",
    "vtkBlockPlot3DWriter",
    "vtkBlockTemplate",
    "vtkBlockTemplateAlgorithm",
    "vtkBlockTemplateSource",
    "vtkGridQuality",
    "vtkTurboPointSetsReader",
    "mesh_template",
    "MIN_ANGLE_CLASSES",
]

#: Labels of the paper's MinAngle classes, in degrees.
MIN_ANGLE_CLASSES = ("0-20", "20-40", "40-60", "60-80", "80-90")


def printable(text):
    """*text* (str or bytes) as a str that can be printed anywhere: bytes that are not
    UTF-8 (and the surrogate escapes Python uses for them in file names and argv) are
    shown as \\xNN, like the C++ side does in its messages."""
    if isinstance(text, bytes):
        return text.decode("utf-8", "backslashreplace")
    text = str(text)
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def _message(text):
    """The text of a VTK error or warning without VTK's "ERROR: In file, line N" and
    "Class (0x...): " header. VTK hands Python None for a message that is not valid
    UTF-8 (BlockForge's own messages never are: they escape such bytes)."""
    if text is None:
        return "a message that is not valid UTF-8 text"
    text = printable(text).strip()
    if text.startswith(("ERROR: In ", "Warning: In ")):
        text = text.partition("\n")[2]
    head, sep, rest = text.partition("): ")
    if sep and " (0x" in head and "\n" not in head:
        text = rest
    return text.strip()


def _path_argument(path):
    """A file name for a VTK method: str, or bytes when it holds bytes that are not UTF-8
    (surrogate escapes), which VTK passes on unchanged."""
    path = os.fspath(path)
    if isinstance(path, bytes):
        return path
    try:
        path.encode("utf-8")
        return path
    except UnicodeEncodeError:
        return os.fsencode(path)


# The optimizer's objectives by their command-line names (vtkBlockOptimizer::Objective).
OBJECTIVES = {"min-angle": 0, "non-orthogonality": 1, "min-angle-and-size-ratio": 2}


def _run_pipeline(template_file, parameters=None, density_multiplier=1.0, input_file=None,
                  timings=None, allow_inverted_cells=False, warnings=None,
                  maximum_memory=0.0, optimize=True, objective="min-angle",
                  maximum_evaluations=None, maximum_interface_ratio=None):
    """:func:`mesh_template`; with a dict *timings*, also records the seconds of each
    stage under "read" (only with an input file), "template", "optimize" (unless
    *optimize* is false) and "mesh + quality"; with a list *warnings*, collects the stages'
    warnings (reader repairs, inverted cells let through) without VTK's header."""
    import time

    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.vtkConstants import VTK_STRING
    from vtkmodules.vtkCommonCore import vtkCommand

    stages = []  # (timing key, the algorithm whose update runs that stage)
    if input_file is not None:
        reader = vtkTurboPointSetsReader()
        reader.SetFileName(_path_argument(input_file))
        template = vtkBlockTemplate()
        template.SetInputConnection(reader.GetOutputPort())
        stages.append(("read", reader))
    else:
        template = vtkBlockTemplateSource()
    template.SetTemplateFile(_path_argument(template_file))
    template.SetMaximumMemory(float(maximum_memory))
    for name, value in (parameters or {}).items():
        template.SetParameter(_path_argument(str(name)), _path_argument(str(value)))
    stages.append(("template", template))
    model = template
    if optimize:
        optimizer = vtkBlockOptimizer()
        # The objective is measured on the final cells: the grid at the density asked for
        # (a coarsened copy above the optimizer's 1e5 nodes); a grid the mesher would
        # refuse for memory is refused before the optimizer works on it.
        optimizer.SetDensityMultiplier(float(density_multiplier))
        optimizer.SetMaximumMemory(float(maximum_memory))
        optimizer.SetObjective(OBJECTIVES[objective])
        if maximum_evaluations is not None:
            optimizer.SetMaximumEvaluations(int(maximum_evaluations))
        if maximum_interface_ratio is not None:
            ratio = float(maximum_interface_ratio)
            if not (ratio == 0.0 or 1.0 <= ratio < float("inf")):
                raise RuntimeError("maximum_interface_ratio needs 0 (not held) or a number "
                                   f">= 1, got {maximum_interface_ratio!r}")
            optimizer.SetMaximumInterfaceRatio(ratio)
        optimizer.SetInputConnection(template.GetOutputPort())
        stages.append(("optimize", optimizer))
        model = optimizer
    mesher = vtkBlockMesher()
    mesher.SetDensityMultiplier(float(density_multiplier))
    mesher.SetMaximumMemory(float(maximum_memory))
    mesher.SetAllowInvertedCells(bool(allow_inverted_cells))
    mesher.SetInputConnection(model.GetOutputPort(0))
    quality = vtkGridQuality()
    quality.SetInputConnection(mesher.GetOutputPort())
    quality.SetMaximumMemory(float(maximum_memory))
    stages.append(("mesh + quality", quality))

    errors = []
    failures = []  # the executives' "Algorithm ... returned failure" follow-ups

    @calldata_type(VTK_STRING)
    def collect(_caller, _event, message):
        errors.append(message)

    @calldata_type(VTK_STRING)
    def collect_failure(_caller, _event, message):
        failures.append(message)

    @calldata_type(VTK_STRING)
    def collect_warning(_caller, _event, message):
        if warnings is not None:
            warnings.append(_message(message))

    for algorithm in [stage for _, stage in stages] + [mesher]:
        algorithm.AddObserver(vtkCommand.ErrorEvent, collect)
        algorithm.AddObserver(vtkCommand.WarningEvent, collect_warning)
        algorithm.GetExecutive().AddObserver(vtkCommand.ErrorEvent, collect_failure)
    # Stage by stage, so that a failing stage stops the pipeline with its own message.
    for key, algorithm in stages:
        start = time.perf_counter()
        algorithm.Update()
        if timings is not None:
            timings[key] = time.perf_counter() - start
        if errors or failures:
            raise RuntimeError(_message((errors or failures)[0]))
    return quality


def mesh_template(template_file, parameters=None, density_multiplier=1.0, input_file=None,
                  allow_inverted_cells=False, maximum_memory=0.0, optimize=True,
                  objective="min-angle", maximum_evaluations=None,
                  maximum_interface_ratio=None):
    """Applies a template, optimizes its control points, meshes it and measures the grid.

    Without *input_file* the pipeline is vtkBlockTemplateSource -> vtkBlockOptimizer ->
    vtkBlockMesher -> vtkGridQuality (templates without inputs); with it,
    vtkTurboPointSetsReader(input_file) -> vtkBlockTemplate -> vtkBlockOptimizer ->
    vtkBlockMesher -> vtkGridQuality (templates whose ``inputs:`` name point sets, e.g.
    Templates/axial_passage_oh.yaml).

    :param template_file: path of a BlockForge template (.yaml)
    :param parameters: dict of parameter overrides, name -> number or expression
    :param density_multiplier: scales every cell count of the template
    :param input_file: point data for a template with inputs: a file the
        vtkTurboPointSetsReader reads (a BladeGen .inf, an Info.txt or a point file);
        None for a template without inputs
    :param allow_inverted_cells: False (default): a grid with an inverted cell is an error
        naming the block and the cell range; True: the grid is returned anyway for
        inspection (field data ``InvertedCellCount``, a VTK warning per folded block)
    :param maximum_memory: largest memory in GB (2^30 bytes) a stage may allocate; 0:
        what the machine has available. A larger grid is refused before it is allocated
        ("the grid would need 48 GB for 2e+09 nodes; this machine has 23 GB available;
        lower the density multiplier or the cell counts").
    :param optimize: True (default): the vtkBlockOptimizer moves the control points along
        their carriers to maximise the smallest element angle (paper step 3); False: the
        template's vertices are meshed as placed
    :param objective: what the optimizer improves (a key of :data:`OBJECTIVES`):
        "min-angle" (default, the smallest element angle), "non-orthogonality" (OpenFOAM's
        largest non-orthogonality) or "min-angle-and-size-ratio"
    :param maximum_evaluations: the optimizer's trial budget (vtkBlockOptimizer's
        MaximumEvaluations, 1 to 1000000; default None: the optimizer's own, 700)
    :param maximum_interface_ratio: the optimizer refuses trials whose neighbour cells
        across a block interface differ more than this (or than the placed grid's largest
        ratio, if more); vtkBlockOptimizer's MaximumInterfaceRatio, 0: not held, else at
        least 1; default None: the optimizer's own, 1.6
    :returns: the vtkGridQuality algorithm after its update (port 0: the grid with the
        quality arrays; port 1: MinAngle class table; port 2: statistics table)
    :raises RuntimeError: when a stage (reader, template, mesher or quality) reports an
        error; the message is the first error reported, without VTK's
        "ERROR: In file, line" header (e.g. "<file>: no such file", or the template's
        "<template>:<line>: ..." message). No later stage runs after a failing one.
    """
    return _run_pipeline(template_file, parameters, density_multiplier, input_file,
                         allow_inverted_cells=allow_inverted_cells,
                         maximum_memory=maximum_memory, optimize=optimize,
                         objective=objective, maximum_evaluations=maximum_evaluations,
                         maximum_interface_ratio=maximum_interface_ratio)
