"""What the Python tests of BlockForge share: paths of the source tree and of the test
output, loading the plugin into a test module, walking multiblock data sets, collecting
VTK error messages and running the unittest cases.

Imported as `import bftest` by the test scripts of this directory, which is on sys.path
because the scripts are run by path (`pvpython <dir>/test_x.py`, `pvbatch <dir>/test_mpi.py`
under mpiexec, `python3 <dir>/test_blockforge.py`). It needs only VTK and numpy, never
paraview, so /usr/bin/python3 can import it as well (see load_plugin).

CTest sets BLOCKFORGE_SOURCE_DIR, BLOCKFORGE_TEST_OUTPUT and BLOCKFORGE_PLUGIN
(Testing/Python/CMakeLists.txt).
"""
import math
import os
import sys
import unittest

import numpy as np
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkCommand

SOURCE = os.environ.get("BLOCKFORGE_SOURCE_DIR",
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
OUTPUT = os.environ.get("BLOCKFORGE_TEST_OUTPUT", "/tmp/blockforge-test-output")
DATA = os.path.join(SOURCE, "Testing", "Data")
CYLINDER = os.path.join(SOURCE, "Templates", "cylinder_in_box.yaml")
ROTOR37_INF = os.path.join(SOURCE, "Data", "rotor37", "turbogrid", "BladeGen.inf")
DISTRIBUTOR_INF = os.path.join(SOURCE, "Data", "distributor", "BladeGen.inf")


def output_path(name):
    """The path of a file `name` in the test output directory, which is created if needed."""
    os.makedirs(OUTPUT, exist_ok=True)
    return os.path.join(OUTPUT, name)


def load_plugin(namespace):
    """Loads the plugin library BLOCKFORGE_PLUGIN (pvpython or pvbatch only) and defines
    the constructors of its proxies (BlockTemplateSource, BlockTemplate, BlockMesher,
    GridQuality, TurboPointSetsReader) in `namespace`: pass the test module's globals().

    The plugin is loaded on the client (remote=False), which for the builtin connection
    of pvpython and pvbatch, also under MPI, is the process that runs the pipeline.
    """
    from paraview.simple import LoadPlugin  # not at the top: python3 has no paraview

    LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=namespace)


def mpi_ranks(failures, expected=2):
    """The number of ranks of the running pvbatch (ParaView's global controller); appends
    to `failures` when it is not `expected`."""
    from paraview import servermanager  # not at the top: python3 has no paraview

    controller = servermanager.vtkProcessModule.GetProcessModule().GetGlobalController()
    ranks = controller.GetNumberOfProcesses()
    if ranks != expected:
        failures.append(f"expected {expected} MPI ranks, got {ranks}")
    return ranks


def optimized_pipeline(namespace, template, input_file=None, density=1.0):
    """reader -> BlockTemplate (or BlockTemplateSource without input) -> BlockOptimizer ->
    BlockMesher -> GridQuality, built from the proxy constructors load_plugin put in
    `namespace`, and updated. The optimizer runs at the mesher's density, as
    blockforge.mesh_template does, so a serial mesh_template run is the reference."""
    if input_file:
        reader = namespace["TurboPointSetsReader"](FileName=input_file)
        model = namespace["BlockTemplate"](Input=reader, TemplateFile=template)
    else:
        model = namespace["BlockTemplateSource"](TemplateFile=template)
    model = namespace["BlockOptimizer"](Input=model, DensityMultiplier=density)
    grid = namespace["BlockMesher"](Input=model, DensityMultiplier=density)
    quality = namespace["GridQuality"](Input=grid)
    quality.UpdatePipeline()
    return quality


def check_written_by_every_rank(label, folder, ranks, failures):
    """Appends to `failures` unless ParaView's parallel .vtm writer wrote blocks of every
    rank into `folder` (it names a block's file <name>_<block>_<rank>.vts), which shows the
    blocks were shared out between the ranks."""
    writers = sorted({name.rsplit("_", 1)[1].split(".")[0] for name in os.listdir(folder)})
    if writers != [str(r) for r in range(ranks)]:
        failures.append(f"{label}: blocks written by ranks {writers}, expected every rank")


def run_gui(script, output, result_name, exit_after_script=True):
    """Runs the ParaView GUI under xvfb-run on `script` (`paraview --dr --script=...`, with
    `--exit` unless the script ends the process itself), the plugin autoloaded from
    BLOCKFORGE_PLUGIN's folder and BLOCKFORGE_GUI_OUTPUT = `output`. Returns the GUI's
    output and the lines the script wrote to `output`/`result_name` as (key, rest) pairs
    ([] when it wrote none). xvfb-run -a can lose a race for a display number with another
    X server starting at the same moment: it is tried again then."""
    import subprocess  # only the GUI tests need it

    os.makedirs(output, exist_ok=True)
    environment = dict(os.environ)
    environment["BLOCKFORGE_GUI_OUTPUT"] = output
    environment["PV_PLUGIN_PATH"] = os.path.dirname(os.environ["BLOCKFORGE_PLUGIN"])
    result = os.path.join(output, result_name)
    command = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", "paraview", "--dr",
               f"--script={script}"] + (["--exit"] if exit_after_script else [])
    log = ""
    for _ in range(3):
        if os.path.exists(result):
            os.remove(result)
        try:
            log = subprocess.run(command, cwd=SOURCE, env=environment, stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, text=True, timeout=300).stdout
        except subprocess.TimeoutExpired as error:
            log = str(error.output)
        if os.path.exists(result):
            break
    lines = []
    if os.path.exists(result):
        with open(result) as stream:
            lines = [tuple(line.strip().partition(" ")[::2]) for line in stream]
    return log, lines


def _leaf_iterators(multiblock):
    iterator = multiblock.NewIterator()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        yield iterator
        iterator.GoToNextItem()


def leaves(multiblock):
    """Every non-empty leaf data set of a multiblock, in order."""
    return [iterator.GetCurrentDataObject() for iterator in _leaf_iterators(multiblock)]


def named_leaves(multiblock):
    """(name, data set) of every non-empty leaf of a multiblock, in order."""
    return [(iterator.GetCurrentMetaData().Get(multiblock.NAME()),
             iterator.GetCurrentDataObject()) for iterator in _leaf_iterators(multiblock)]


def points(dataset):
    """The points of a data set as an array [n, xyz]."""
    return np.array(dsa.WrapDataObject(dataset).Points)


def node_array(block):
    """The nodes of a structured block as an array [k, j, i, xyz]."""
    nx, ny, nz = block.GetDimensions()
    return points(block).reshape(nz, ny, nx, 3)


def rotate_z(xyz, angle):
    """Points [n, xyz] turned by `angle` (radians) about the z axis."""
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack((c * xyz[:, 0] - s * xyz[:, 1], s * xyz[:, 0] + c * xyz[:, 1],
                            xyz[:, 2]))


class ErrorCollector:
    """Collects in `messages` the vtkErrorMacro messages of the observed algorithms."""

    def __init__(self, *algorithms):
        self.messages = []

        @calldata_type(VTK_STRING)
        def collect(_caller, _event, message):
            self.messages.append(message)

        for algorithm in algorithms:
            algorithm.AddObserver(vtkCommand.ErrorEvent, collect)


def run_tests():
    """Runs the unittest cases of the main script verbosely, then exits with 0 if they all
    passed, 1 otherwise."""
    result = unittest.main(module="__main__", verbosity=2, argv=[sys.argv[0]],
                           exit=False).result
    sys.exit(0 if result.wasSuccessful() else 1)


def read_cgns_zones(path):
    """{zone name: data set} of the first base of a CGNS file, as ParaView's CGNS reader
    (vtkCGNSReader) reads it."""
    from vtkmodules.vtkIOCGNSReader import vtkCGNSReader

    reader = vtkCGNSReader()
    reader.SetFileName(path)
    reader.UpdateInformation()
    reader.EnableAllBases()
    reader.Update()
    base = reader.GetOutput().GetBlock(0)
    return {base.GetMetaData(z).Get(base.NAME()): base.GetBlock(z)
            for z in range(base.GetNumberOfBlocks())}
