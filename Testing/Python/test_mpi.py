"""pvbatch under MPI (2 ranks): blocks are shared out between the ranks, and the grid,
every GridQuality array of every cell (NonOrthogonality and Skewness included: the ranks
exchange the cells beside interfaces and periodic faces), the class counts, the
statistics and the written .vtm equal a serial run bit for bit.

Cases: the distributor (reader -> BlockTemplate -> BlockOptimizer -> BlockMesher ->
GridQuality with axial_passage_oh: O/H interfaces and periodic sides, 887 cells differed
when the ranks measured the faces between them as boundaries), the periodic annular
sector and the cylinder in a box.
"""
import os

import numpy as np
from paraview import servermanager
from paraview.simple import SaveData
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

import blockforge

import bftest

bftest.load_plugin(globals())

failures = []
ranks = bftest.mpi_ranks(failures)


def bits(array):
    """The stored bits of a numeric array (so -0.0 != 0.0 and NaN == the same NaN)."""
    values = np.ascontiguousarray(np.asarray(array))
    return values.view(np.uint8).tobytes(), values.dtype.str, values.shape


def compare_grids(label, parallel, serial):
    """Appends to `failures` every block, array and cell where `parallel` differs from
    `serial` (both multiblocks of named structured grids)."""
    parallel_blocks = dict(bftest.named_leaves(parallel))
    serial_blocks = dict(bftest.named_leaves(serial))
    if sorted(parallel_blocks) != sorted(serial_blocks):
        failures.append(f"{label}: blocks {sorted(parallel_blocks)} != {sorted(serial_blocks)}")
        return
    cells = 0
    for name, reference in serial_blocks.items():
        block = parallel_blocks[name]
        if block.GetDimensions() != reference.GetDimensions():
            failures.append(f"{label} {name}: dimensions differ")
            continue
        if bits(bftest.points(block)) != bits(bftest.points(reference)):
            failures.append(f"{label} {name}: points differ")
        data = reference.GetCellData()
        for a in range(data.GetNumberOfArrays()):
            array_name = data.GetArrayName(a)
            mine = dsa.WrapDataObject(block).CellData[array_name]
            theirs = dsa.WrapDataObject(reference).CellData[array_name]
            if isinstance(mine, dsa.VTKNoneArray):
                failures.append(f"{label} {name}: no cell array {array_name}")
                continue
            if bits(mine) != bits(theirs):
                differing = int(np.count_nonzero(np.asarray(mine) != np.asarray(theirs)))
                failures.append(f"{label} {name}: {array_name} differs in {differing} cells")
        if block.GetCellData().GetNumberOfArrays() != data.GetNumberOfArrays():
            failures.append(f"{label} {name}: cell arrays differ in number")
        cells += reference.GetNumberOfCells()
    return cells


def compare_fields(label, parallel, serial):
    """Class counts exactly, min and max of every measure exactly, means within the
    summation order."""
    mine = parallel.GetFieldData()
    theirs = serial.GetFieldData()
    counts = [mine.GetArray("MinAngleClassCounts").GetValue(c) for c in range(5)]
    reference = [theirs.GetArray("MinAngleClassCounts").GetValue(c) for c in range(5)]
    if counts != reference:
        failures.append(f"{label}: MinAngle classes {counts} != {reference}")
    for measure in ("MinAngle", "MaxAngle", "NonOrthogonality", "Skewness", "AspectRatio",
                    "ScaledJacobian", "CellDeterminant"):
        a = mine.GetArray(measure + "Summary").GetTuple3(0)
        b = theirs.GetArray(measure + "Summary").GetTuple3(0)
        if a[0] != b[0] or a[2] != b[2] or abs(a[1] - b[1]) > 1e-12 * max(1.0, abs(b[1])):
            failures.append(f"{label}: {measure} (min, mean, max) {a} != {b}")


def check_case(label, template, input_file=None, density=1.0):
    # Every rank optimizes the whole model (deterministic: the same on every rank and in
    # the serial run, which mesh_template optimizes by default, on the final grid).
    quality = bftest.optimized_pipeline(globals(), template, input_file, density)

    # The same pipeline in plain VTK, one process, no pieces.
    serial = blockforge.mesh_template(template, density_multiplier=density,
                                      input_file=input_file)
    serial_grid = serial.GetOutputDataObject(0)

    # What the client gets (gathered from both ranks) and what the parallel writer writes.
    fetched = servermanager.Fetch(quality)
    cells = compare_grids(label + " (fetched)", fetched, serial_grid)
    compare_fields(label + " (fetched)", fetched, serial_grid)
    path = bftest.output_path(f"mpi_{label}.vtm")
    SaveData(path, proxy=quality, DataMode="Binary", CompressorType="None")
    reader = vtkXMLMultiBlockDataReader()
    reader.SetFileName(path)
    reader.Update()
    compare_grids(label + " (written)", reader.GetOutput(), serial_grid)
    # Both ranks meshed and wrote a share: the parallel writer names a block's file
    # <name>_<block>_<rank>.vts.
    bftest.check_written_by_every_rank(
        label, os.path.join(os.path.dirname(path), f"mpi_{label}"), ranks, failures)

    print(f"{label}: {cells} cells equal the serial run in every array")

    # The class table (port 1) and statistics (port 2) are global.
    parallel_classes = servermanager.Fetch(quality, idx=1)
    serial_classes = serial.GetOutputDataObject(1)
    for row in range(5):
        a = parallel_classes.GetValue(row, 1).ToInt()
        b = serial_classes.GetValue(row, 1).ToInt()
        if a != b:
            failures.append(f"{label}: MinAngle class {row}: {a} cells under MPI, {b} serial")


check_case("distributor", os.path.join(bftest.SOURCE, "Templates", "axial_passage_oh.yaml"),
           bftest.DISTRIBUTOR_INF)
check_case("annular_sector", os.path.join(bftest.SOURCE, "Templates", "annular_sector.yaml"))
check_case("cylinder", bftest.CYLINDER, density=1.5)

# An exception makes pvbatch fail; sys.exit would skip MPI_Finalize and abort the job.
if failures:
    raise RuntimeError("\n".join(failures))
print(f"MPI run on {ranks} ranks equals the serial run")
