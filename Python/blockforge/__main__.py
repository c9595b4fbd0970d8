"""Command line: ``python3 -m blockforge TEMPLATE [-i POINTS] [-o grid.vtm] [-p NAME=EXPR ...]
[-d DENSITY] [-m GB] [--ascii] [--compress] [--allow-inverted-cells] [--no-optimize]
[--objective NAME] [--max-evaluations N]``.

Applies a template (to the point data of -i, read by the TurboPointSetsReader, for a
template with inputs), optimizes its control points (the BlockOptimizer; --no-optimize
skips it), meshes it, prints a quality summary (cell count, the paper's
MinAngle classes, min/mean/max of every measure) and writes the grid with its quality
arrays. The grid (x.vtm and a fresh folder of pieces x.pieces-<id>/) is written beside the
target, read back, and published by renaming x.vtm into place; the older grid's pieces are
removed after. A failing or killed run leaves no partial grid and keeps an older one;
leftovers of killed runs are removed by the next run. Exit status 1 with the error
message on failure (also for a grid that would need more memory than available or than
--max-memory).
"""
import argparse
import sys
import time

import blockforge
import blockforge.output
from blockforge import printable
from blockforge import writers


def _parse_parameter(text):
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=EXPRESSION, got '{printable(text)}'")
    return name.strip(), value.strip()


def _parse_evaluations(text):
    try:
        count = int(text)
    except ValueError:
        count = 0
    if not 1 <= count <= 1000000:
        raise argparse.ArgumentTypeError(
            f"needs a whole number from 1 to 1000000, got '{printable(text)}'")
    return count


def _parse_interface_ratio(text):
    try:
        ratio = float(text)
    except ValueError:
        ratio = -1.0
    if not (ratio == 0.0 or 1.0 <= ratio < float("inf")):
        raise argparse.ArgumentTypeError(
            f"needs 0 (not held) or a number >= 1, got '{printable(text)}'")
    return ratio


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
        percent = 100.0 * count / cells if cells else 0.0
        lines.append(f"  {label:>8}              {count:8d}   {percent:6.2f}")
    lines.extend(optimizer_lines(quality))
    lines.append("measure                 min        mean         max")
    for row in range(statistics.GetNumberOfRows()):
        name = statistics.GetValue(row, 0).ToString()
        values = [statistics.GetValue(row, c).ToDouble() for c in (1, 2, 3)]
        lines.append(f"  {name:<18}{values[0]:10.4g}  {values[1]:10.4g}  {values[2]:10.4g}")
    return lines


def write_grid(data_object, path, compress=False):
    """Writes *data_object* (a vtkMultiBlockDataSet) as the .vtm *path* plus a fresh folder
    of its pieces beside it, checked after writing and published with one rename
    (:func:`blockforge.output.write_vtm`); the older grid at *path* stays whole until then.
    :raises RuntimeError: when writing fails or what was written is incomplete."""
    blockforge.output.write_vtm(data_object, path, compress)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m blockforge", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("template", help="BlockForge template file (.yaml)")
    parser.add_argument("-i", "--input", metavar="FILE",
                        help="point data for a template with inputs (BladeGen .inf, Info.txt "
                             "or point file, read by the TurboPointSetsReader)")
    parser.add_argument("-o", "--output", help="grid file to write: .vtm, or DIR/NAME.foam "
                        "(OpenFOAM case)")
    parser.add_argument("--ascii", action="store_true",
                        help="ASCII instead of binary where the format has both")
    parser.add_argument("--compress", action="store_true",
                        help=".vtm: compress the pieces (zlib; smaller, several times slower "
                             "to write; default: raw binary)")
    parser.add_argument("-p", "--parameter", action="append", type=_parse_parameter,
                        default=[], metavar="NAME=EXPR", help="override a template parameter")
    parser.add_argument("-d", "--density", type=float, default=1.0,
                        help="grid density multiplier (scales every cell count); above 0, at "
                             "most 1000, at most 1,000,000 cells per block direction")
    parser.add_argument("-m", "--max-memory", type=float, default=0.0, metavar="GB",
                        help="refuse grids that would need more memory than this, in GB "
                             "(2^30 bytes); default 0: what the machine has available")
    parser.add_argument("--allow-inverted-cells", action="store_true",
                        help="output a grid with inverted cells anyway, for inspection "
                             "(default: an error naming the block and the cell range)")
    parser.add_argument("--objective", choices=sorted(blockforge.OBJECTIVES), default="min-angle",
                        help="what the optimizer improves (default min-angle: the smallest "
                             "element angle; non-orthogonality: OpenFOAM's largest)")
    parser.add_argument("--max-evaluations", type=_parse_evaluations, default=None, metavar="N",
                        help="the optimizer's trial budget (vtkBlockOptimizer's "
                             "MaximumEvaluations; default 700, 1 to 1000000)")
    parser.add_argument("--max-interface-ratio", type=_parse_interface_ratio, default=None,
                        metavar="R",
                        help="the optimizer refuses trials whose neighbour cells across a "
                             "block interface differ more than R times, or than the placed "
                             "grid's largest ratio if more (vtkBlockOptimizer's "
                             "MaximumInterfaceRatio; default 1.6, 0: not held)")
    parser.add_argument("--no-optimize", action="store_true",
                        help="mesh the template's vertices as placed (default: the "
                             "BlockOptimizer moves the control points first)")
    args = parser.parse_args(argv)
    if args.output and not (args.output.endswith(".vtm") or writers.is_solver_format(args.output)):
        parser.error(f"the output must be .vtm or {', '.join(writers.SOLVER_WRITERS)}, "
                     f"got '{printable(args.output)}'")
    if not (args.max_memory >= 0.0) or args.max_memory == float("inf"):
        parser.error(f"--max-memory must be a number of GB >= 0 (0: no limit), got "
                     f"{args.max_memory}")

    timings = {}
    warnings = []
    try:
        quality = blockforge._run_pipeline(args.template, dict(args.parameter), args.density,
                                           args.input, timings, args.allow_inverted_cells,
                                           warnings, args.max_memory,
                                           optimize=not args.no_optimize,
                                           objective=args.objective,
                                           maximum_evaluations=args.max_evaluations,
                                           maximum_interface_ratio=args.max_interface_ratio)
    except (RuntimeError, MemoryError) as error:
        print(f"error: {printable(error) if str(error) else 'out of memory'}", file=sys.stderr)
        return 1
    finally:
        for warning in warnings:
            print(f"warning: {printable(warning)}", file=sys.stderr)
    print(f"template: {printable(args.template)}")
    if args.input:
        print(f"input: {printable(args.input)}")
    for line in summary_lines(quality):
        print(line)
    print("time [s]: " + ", ".join(f"{key} {seconds:.3f}" for key, seconds in timings.items())
          + f", total {sum(timings.values()):.3f}")
    if args.output:
        start = time.perf_counter()
        try:
            if writers.is_solver_format(args.output):
                writers.write_solver_grid(quality.GetOutputDataObject(0), args.output,
                                          binary=not args.ascii)
            else:
                write_grid(quality.GetOutputDataObject(0), args.output, args.compress)
        except (RuntimeError, OSError, ValueError) as error:
            print(f"error: {printable(error)}", file=sys.stderr)
            return 1
        print(f"grid written to {printable(args.output)} ({time.perf_counter() - start:.3f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
