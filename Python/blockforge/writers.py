"""Solver-format writers of the command line: the output's extension picks the writer.

``.foam`` (OpenFOAM case: ``DIR/constant/polyMesh`` and an empty ``DIR/NAME.foam``),
``.xyz`` (Plot3D multi-grid, with patches and interfaces in ``NAME.nmf``), ``.cgns``
(CGNS with 1-to-1 and periodic connectivity, BCs by family);
``.vtm`` stays with :func:`blockforge.__main__.write_grid`. The C++ writers put their
files in place by a rename only when everything was written, so a failure leaves no
partial grid and keeps an older one.
"""
import os

#: extension -> name of the wrapped writer class
SOLVER_WRITERS = {".foam": "vtkBlockFoamWriter", ".xyz": "vtkBlockPlot3DWriter",
                  ".cgns": "vtkBlockCGNSWriter"}


def is_solver_format(path):
    """True when *path*'s extension names one of the solver formats."""
    return os.path.splitext(str(path))[1].lower() in SOLVER_WRITERS


def write_solver_grid(data_object, path, binary=True):
    """Writes *data_object* (the output of vtkBlockMesher or vtkGridQuality) to *path* in
    the format its extension names.

    :raises RuntimeError: with the writer's message (no model in the grid, an unwritable
        folder, a full disk); nothing at *path* is touched then.
    """
    import blockforge
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.vtkConstants import VTK_STRING
    from vtkmodules.vtkCommonCore import vtkCommand

    extension = os.path.splitext(str(path))[1].lower()
    if extension not in SOLVER_WRITERS:
        raise RuntimeError(f"no solver writer for '{path}' (known: "
                           f"{', '.join(sorted(SOLVER_WRITERS))})")
    writer = getattr(blockforge, SOLVER_WRITERS[extension])()
    errors = []

    @calldata_type(VTK_STRING)
    def collect(_caller, _event, message):
        errors.append(message)

    writer.AddObserver(vtkCommand.ErrorEvent, collect)
    writer.SetInputData(data_object)
    writer.SetFileName(os.path.abspath(str(path)))
    if hasattr(writer, "SetBinary"):
        writer.SetBinary(bool(binary))
    if not writer.Write() or errors:
        detail = blockforge._message(errors[0]) if errors else f"could not write {path}"
        raise RuntimeError(detail)
