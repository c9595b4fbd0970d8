"""pvbatch under MPI (2 ranks): blocks are shared out between the ranks, and the grid
and GridQuality's class counts and statistics are global and equal a serial run."""
from paraview import servermanager

import blockforge

import bftest

bftest.load_plugin(globals())
template = bftest.CYLINDER

controller = servermanager.vtkProcessModule.GetProcessModule().GetGlobalController()
ranks = controller.GetNumberOfProcesses()

model = BlockTemplateSource(TemplateFile=template)  # noqa: F821
grid = BlockMesher(Input=model)  # noqa: F821
quality = GridQuality(Input=grid)  # noqa: F821
quality.UpdatePipeline()
parallel_grid = servermanager.Fetch(quality)
parallel_classes = servermanager.Fetch(quality, idx=1)
parallel_statistics = servermanager.Fetch(quality, idx=2)

# The same pipeline in plain VTK, one process, no pieces.
serial = blockforge.mesh_template(template)
serial_classes = serial.GetOutputDataObject(1)
serial_statistics = serial.GetOutputDataObject(2)

failures = []
if ranks != 2:
    failures.append(f"expected 2 MPI ranks, got {ranks}")
serial_cells = serial.GetOutputDataObject(0).GetNumberOfCells()
if parallel_grid.GetNumberOfCells() != serial_cells:
    failures.append(f"cells {parallel_grid.GetNumberOfCells()} != serial {serial_cells}")
for row in range(5):
    a = parallel_classes.GetValue(row, 1).ToInt()
    b = serial_classes.GetValue(row, 1).ToInt()
    if a != b:
        failures.append(f"MinAngle class {row}: {a} cells under MPI, {b} serial")
for row in range(serial_statistics.GetNumberOfRows()):
    name = serial_statistics.GetValue(row, 0).ToString()
    for column in (1, 3):  # min and max; means differ by summation order only
        a = parallel_statistics.GetValue(row, column).ToDouble()
        b = serial_statistics.GetValue(row, column).ToDouble()
        if abs(a - b) > 1e-9 * max(1.0, abs(b)):
            failures.append(f"{name} column {column}: {a} under MPI, {b} serial")

# An exception makes pvbatch fail; sys.exit would skip MPI_Finalize and abort the job.
if failures:
    raise RuntimeError("\n".join(failures))
print(f"MPI run on {ranks} ranks equals the serial run")
