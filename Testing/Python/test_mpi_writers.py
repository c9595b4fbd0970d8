"""The solver writers under MPI (pvbatch on 2 ranks): every rank meshes its share of the
blocks, rank 0 gathers them and writes, and the files are the same bytes as a serial run
(plain VTK, one process) writes: OpenFOAM case (binary and ASCII), Plot3D with its .nmf
(binary and ASCII). CGNS files are HDF5, which differ from run to run even serially
(object time stamps): they must be equal node for node and value for value (`cgnsdiff
-d`, tolerance 0: every node's name, label, dimensions and data).

Cases: the distributor (reader -> BlockTemplate -> BlockOptimizer -> BlockMesher ->
GridQuality with axial_passage_oh: 12 blocks, O/H interfaces, cyclic periodic sides), the
periodic annular sector and the wedge sector (prisms on the axis). Also: the blocks were
shared out between the ranks when the writers ran (the parallel .vtm writer of the same
pipeline names each block's file after its rank), and a target in a folder that cannot
be created fails on every rank, writes nothing and does not hang.
"""
import filecmp
import os
import shutil
import subprocess

from paraview.simple import SaveData

import blockforge
from blockforge import writers

import bftest

bftest.load_plugin(globals())

failures = []
ranks = bftest.mpi_ranks(failures)

# (extension, options of SaveData, binary flag of the serial writer)
FORMATS = [("foam", {}, True), ("foam", {"Binary": 0}, False),
           ("xyz", {}, True), ("xyz", {"Binary": 0}, False),
           ("cgns", {}, True)]


def files_under(folder):
    """Relative paths of every file under *folder*."""
    found = []
    for directory, _, names in os.walk(folder):
        found.extend(os.path.relpath(os.path.join(directory, name), folder) for name in names)
    return sorted(found)


def compare_folders(label, parallel, serial):
    names = files_under(serial)
    if files_under(parallel) != names:
        failures.append(f"{label}: files {files_under(parallel)} != serial {names}")
        return 0
    for name in names:
        mine, theirs = os.path.join(parallel, name), os.path.join(serial, name)
        if name.endswith(".cgns"):
            difference = subprocess.run(["cgnsdiff", "-d", mine, theirs], capture_output=True,
                                        text=True)
            if difference.returncode != 0 or difference.stdout.strip():
                failures.append(f"{label}: {name} differs from the serial run's: "
                                f"{difference.stdout[:500]}{difference.stderr[:500]}")
        elif not filecmp.cmp(mine, theirs, shallow=False):
            failures.append(f"{label}: {name} differs from the serial run's")
    return len(names)


def check_case(label, template, input_file=None):
    quality = bftest.optimized_pipeline(globals(), template, input_file)
    serial = blockforge.mesh_template(template, input_file=input_file).GetOutputDataObject(0)

    root = bftest.output_path(f"mpi_writers_{label}")
    shutil.rmtree(root, ignore_errors=True)
    compared = 0
    for extension, options, binary in FORMATS:
        kind = f"{extension}_{'binary' if binary else 'ascii'}"
        parallel_folder = os.path.join(root, "mpi", kind)
        serial_folder = os.path.join(root, "serial", kind)
        SaveData(os.path.join(parallel_folder, f"{label}.{extension}"), proxy=quality, **options)
        writers.write_solver_grid(serial, os.path.join(serial_folder, f"{label}.{extension}"),
                                  binary=binary)
        compared += compare_folders(f"{label} {kind}", parallel_folder, serial_folder)

    # The pipeline the writers ran on was shared out: the parallel .vtm writer names each
    # block's file <name>_<block>_<rank>.vts.
    vtm = os.path.join(root, "mpi", "pieces.vtm")
    SaveData(vtm, proxy=quality)
    bftest.check_written_by_every_rank(label, os.path.join(root, "mpi", "pieces"), ranks,
                                       failures)
    print(f"{label}: {compared} files written under MPI equal the serial run's", flush=True)
    return quality


distributor = check_case("distributor",
                         os.path.join(bftest.SOURCE, "Templates", "axial_passage_oh.yaml"),
                         bftest.DISTRIBUTOR_INF)
check_case("annular_sector", os.path.join(bftest.SOURCE, "Templates", "annular_sector.yaml"))
check_case("wedge_sector", os.path.join(bftest.SOURCE, "Templates", "wedge_sector.yaml"))

# A target whose folder cannot be created (a file is in the way): every rank returns
# (no rank waits for another), nothing is written.
blocker = bftest.output_path("mpi_writers_blocker")
with open(blocker, "w") as stream:
    stream.write("a file, not a folder\n")
for extension in ("foam", "xyz", "cgns"):
    target = os.path.join(blocker, "sub", f"grid.{extension}")
    try:
        SaveData(target, proxy=distributor)  # the writer's error goes to the log
    except RuntimeError:
        pass
    if os.path.exists(target):
        failures.append(f"{target} exists after a failed write")

# An exception makes pvbatch fail; sys.exit would skip MPI_Finalize and abort the job.
if failures:
    raise RuntimeError("\n".join(failures))
print(f"solver writers on {ranks} ranks write the serial run's bytes")
