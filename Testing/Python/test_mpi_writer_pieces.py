"""A solver writer with GatherPieces on, in plain VTK on every rank (`pvbatch --symmetric`
on 2 ranks): the writer asks the pipeline for this rank's piece, so each rank meshes only
its share of the blocks (checked on the mesher's output), and rank 0 writes the gathered
grid, equal byte for byte to the one the same writer writes with GatherPieces off from a
pipeline of its own (the whole grid, no communication). A rank whose input has no grid
fails the write on every rank instead of leaving one waiting.
"""
import filecmp
import os
import shutil

import blockforge
from vtkmodules.vtkCommonCore import vtkCommand, vtkIntArray
from vtkmodules.vtkParallelCore import vtkMultiProcessController

import bftest

controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId()
ranks = controller.GetNumberOfProcesses()
failures = []
if ranks != 2:
    failures.append(f"expected 2 MPI ranks, got {ranks}")


def pipeline(template):
    source = blockforge.vtkBlockTemplateSource()
    source.SetTemplateFile(template)
    mesher = blockforge.vtkBlockMesher()
    mesher.SetInputConnection(source.GetOutputPort())
    return mesher


def meshed_blocks(mesher):
    return sum(1 for block in bftest.leaves(mesher.GetOutputDataObject(0))
               if block is not None and block.GetNumberOfPoints() > 0)


def write(mesher, path, gather):
    writer = blockforge.vtkBlockFoamWriter()
    writer.SetInputConnection(mesher.GetOutputPort())
    writer.SetFileName(path)
    writer.SetGatherPieces(gather)
    errors = []
    writer.AddObserver(vtkCommand.ErrorEvent, lambda *_: errors.append(1))
    return writer.Write(), errors


template = os.path.join(bftest.SOURCE, "Templates", "cylinder_in_box.yaml")
root = bftest.output_path("mpi_writer_pieces")
if rank == 0:
    shutil.rmtree(root, ignore_errors=True)
controller.Barrier()

# Gathered: each rank meshes its share, rank 0 writes.
mesher = pipeline(template)
status, errors = write(mesher, os.path.join(root, "gathered", "c.foam"), True)
local = meshed_blocks(mesher)
total = mesher.GetOutputDataObject(0).GetNumberOfBlocks()
if not status or errors:
    failures.append(f"rank {rank}: the gathered write failed")
if not 0 < local < total:
    failures.append(f"rank {rank}: meshed {local} of {total} blocks (expected a share)")
mine, everyone = vtkIntArray(), vtkIntArray()
mine.InsertNextValue(local)
everyone.SetNumberOfValues(ranks)
controller.AllGather(mine, everyone)
if sum(everyone.GetValue(r) for r in range(ranks)) != total:
    failures.append(f"ranks meshed {[everyone.GetValue(r) for r in range(ranks)]} blocks, "
                    f"{total} in the model")

# Rank 0 alone, GatherPieces off: the whole grid in one process, no communication.
if rank == 0:
    whole = pipeline(template)
    status, errors = write(whole, os.path.join(root, "serial", "c.foam"), False)
    if meshed_blocks(whole) != total or not status or errors:
        failures.append("the serial write did not mesh and write every block")
    polymesh = os.path.join("constant", "polyMesh")
    for name in ("points", "faces", "owner", "neighbour", "boundary"):
        if not filecmp.cmp(os.path.join(root, "gathered", polymesh, name),
                           os.path.join(root, "serial", polymesh, name), shallow=False):
            failures.append(f"{name} of the gathered grid differs from the serial one")

# One rank's input has no grid (a file name only rank 1 cannot use): every rank returns
# a failure.
path = os.path.join(root, "refused", "c.foam") if rank == 0 else ""
status, errors = write(pipeline(template), path, True)
if status:
    failures.append(f"rank {rank}: the write succeeded although rank 1 had no file name")
if rank == 0 and os.path.exists(path):
    failures.append(f"{path} was written although rank 1 failed")

# An exception makes pvbatch fail; sys.exit would skip MPI_Finalize and abort the job.
if failures:
    raise RuntimeError("\n".join(failures))
print(f"rank {rank}: meshed {local} of {total} blocks; rank 0 wrote the gathered grid, "
      "equal to the serial one")
