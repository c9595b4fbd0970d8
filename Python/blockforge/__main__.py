"""Command line: ``python3 -m blockforge TEMPLATE [-i POINTS] [-o grid.vtm] [-p NAME=EXPR ...]
[-d DENSITY] [--allow-inverted-cells] [--no-optimize]``.

Applies a template (to the point data of -i, read by the TurboPointSetsReader, for a
template with inputs), optimizes its control points (the BlockOptimizer; --no-optimize
skips it), meshes it, prints a quality summary (cell count, the paper's
MinAngle classes, min/mean/max of every measure) and writes the grid with its quality
arrays. The grid file (x.vtm and its directory of pieces x/) is written next to the
target first and then moved into place, replacing older ones: a failing run leaves no
partial grid and keeps an older one. Exit status 1 with the error message on failure.
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

import blockforge


def _parse_parameter(text):
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=EXPRESSION, got '{text}'")
    return name.strip(), value.strip()


def optimizer_lines(quality):
    """What the BlockOptimizer upstream of *quality* did, if there is one."""
    algorithm = quality
    while algorithm is not None and algorithm.GetClassName() != "vtkBlockOptimizer":
        algorithm = (algorithm.GetInputAlgorithm()
                     if algorithm.GetNumberOfInputConnections(0) else None)
    if algorithm is None:
        return []
    fields = algorithm.GetOutputDataObject(0).GetFieldData()
    before = fields.GetArray("MinAngleBefore")
    if before is None:
        return []
    after = fields.GetArray("MinAngleAfter").GetValue(0)
    evaluations = fields.GetArray("OptimizerEvaluations").GetValue(0)
    moved = fields.GetAbstractArray("ControlPointNames").GetNumberOfValues()
    return [f"optimizer: smallest element angle {before.GetValue(0):.2f} -> {after:.2f} deg "
            f"({moved} control point parameters, {evaluations} evaluations)"]


def summary_lines(quality):
    """Human-readable quality summary of a vtkGridQuality after its update."""
    classes = quality.GetOutputDataObject(1)
    statistics = quality.GetOutputDataObject(2)
    grid = quality.GetOutputDataObject(0)
    cells = sum(classes.GetValue(row, 1).ToInt() for row in range(classes.GetNumberOfRows()))
    nodes = 0
    iterator = grid.NewIterator()
    iterator.InitTraversal()
    blocks = 0
    while not iterator.IsDoneWithTraversal():
        nodes += iterator.GetCurrentDataObject().GetNumberOfPoints()
        blocks += 1
        iterator.GoToNextItem()
    lines = [f"blocks: {blocks}   cells: {cells}   nodes (per block, shared faces counted "
             f"in each): {nodes}"]
    lines.append("MinAngle classes [deg]   cells   percent")
    for row in range(classes.GetNumberOfRows()):
        label = classes.GetValue(row, 0).ToString()
        count = classes.GetValue(row, 1).ToInt()
        percent = classes.GetValue(row, 2).ToDouble()
        lines.append(f"  {label:>8}              {count:8d}   {percent:6.2f}")
    lines.extend(optimizer_lines(quality))
    lines.append("measure                 min        mean         max")
    for row in range(statistics.GetNumberOfRows()):
        name = statistics.GetValue(row, 0).ToString()
        values = [statistics.GetValue(row, c).ToDouble() for c in (1, 2, 3)]
        lines.append(f"  {name:<18}{values[0]:10.4g}  {values[1]:10.4g}  {values[2]:10.4g}")
    return lines


def write_grid(data_object, path):
    """Writes *data_object* (a vtkMultiBlockDataSet) as the .vtm *path* plus the directory
    of its pieces (``x.vtm`` -> ``x/``), atomically per file: both are written into a
    temporary directory beside *path*, then moved into place, replacing older ones.
    :raises RuntimeError: when the writer fails (nothing at *path* is touched then)."""
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.vtkConstants import VTK_STRING
    from vtkmodules.vtkCommonCore import vtkCommand
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter

    path = os.path.abspath(path)
    directory, name = os.path.split(path)
    pieces = os.path.splitext(path)[0]  # the writer's directory of pieces
    os.makedirs(directory, exist_ok=True)
    staging = tempfile.mkdtemp(prefix=f".{name}.", suffix=".tmp", dir=directory)
    try:
        errors = []

        @calldata_type(VTK_STRING)
        def collect(_caller, _event, message):
            errors.append(message)

        writer = vtkXMLMultiBlockDataWriter()
        writer.AddObserver(vtkCommand.ErrorEvent, collect)
        writer.SetInputData(data_object)
        writer.SetFileName(os.path.join(staging, name))
        writer.SetDataModeToAppended()
        writer.EncodeAppendedDataOff()
        if not writer.Write() or errors:
            detail = f": {blockforge._message(errors[0])}" if errors else ""
            raise RuntimeError(f"could not write {path}{detail}")
        staged_pieces = os.path.join(staging, os.path.basename(pieces))
        # Pieces first, then the .vtm that references them; an older pieces directory is
        # moved into the staging directory (removed with it on success, moved back if
        # putting the new grid in place fails).
        old_pieces = None
        if os.path.lexists(pieces):
            old_pieces = os.path.join(staging, ".old-pieces")
            os.rename(pieces, old_pieces)
        try:
            if os.path.isdir(staged_pieces):
                os.rename(staged_pieces, pieces)
            os.replace(os.path.join(staging, name), path)
        except OSError:
            if old_pieces:
                if os.path.isdir(pieces) and not os.path.islink(pieces):
                    shutil.rmtree(pieces, ignore_errors=True)
                os.rename(old_pieces, pieces)
            raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m blockforge", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("template", help="BlockForge template file (.yaml)")
    parser.add_argument("-i", "--input", metavar="FILE",
                        help="point data for a template with inputs (BladeGen .inf, Info.txt "
                             "or point file, read by the TurboPointSetsReader)")
    parser.add_argument("-o", "--output", help="grid file to write (.vtm)")
    parser.add_argument("-p", "--parameter", action="append", type=_parse_parameter,
                        default=[], metavar="NAME=EXPR", help="override a template parameter")
    parser.add_argument("-d", "--density", type=float, default=1.0,
                        help="grid density multiplier (scales every cell count)")
    parser.add_argument("--allow-inverted-cells", action="store_true",
                        help="output a grid with inverted cells anyway, for inspection "
                             "(default: an error naming the block and the cell range)")
    parser.add_argument("--no-optimize", action="store_true",
                        help="mesh the template's vertices as placed (default: the "
                             "BlockOptimizer moves the control points first)")
    args = parser.parse_args(argv)
    if args.output and not args.output.endswith(".vtm"):
        parser.error(f"the output must be a .vtm file (a multiblock grid), got '{args.output}'")

    timings = {}
    warnings = []
    try:
        quality = blockforge._run_pipeline(args.template, dict(args.parameter), args.density,
                                           args.input, timings, args.allow_inverted_cells,
                                           warnings, optimize=not args.no_optimize)
    except RuntimeError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    finally:
        for warning in warnings:
            print(f"warning: {warning}", file=sys.stderr)
    print(f"template: {args.template}")
    if args.input:
        print(f"input: {args.input}")
    for line in summary_lines(quality):
        print(line)
    print("time [s]: " + ", ".join(f"{key} {seconds:.3f}" for key, seconds in timings.items())
          + f", total {sum(timings.values()):.3f}")
    if args.output:
        start = time.perf_counter()
        try:
            write_grid(quality.GetOutputDataObject(0), args.output)
        except (RuntimeError, OSError) as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
        print(f"grid written to {args.output} ({time.perf_counter() - start:.3f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
