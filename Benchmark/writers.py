#!/usr/bin/python3
"""Solver-format writers against OpenFOAM's blockMesh, as a user runs them.

1. 1 million cells (cylinder_in_box: n_around 50, n_radial 50, n_depth 100) as a binary
   polyMesh through the native command line `blockforge ... -o case/c.foam`, the whole
   process, against `blockMesh` generating and writing the same grid (its blockMeshDict is
   written from BlockForge's resolved model by Benchmark/benchmark.py), the whole process.
   The Python command line (`python3 -m blockforge`, which also measures the quality of
   every cell) is shown too. Medians of the runs, interleaved, every run into a fresh case.
2. Every format at the same size: wall time of the native command line (whole process)
   and bytes written, beside blockMesh's polyMesh; .vtm through both command lines (the
   native one writes the points only, the Python one adds the quality arrays).
3. Cross-check (not timed): checkMesh on BlockForge's case ("Mesh OK"), the same number of
   points, faces and internal faces as blockMesh's.

Writes Benchmark/WRITERS.md. Needs a build (build/bin/blockforge, build/blockforge-env.sh)
and OpenFOAM (Debian `openfoam`). Usage: writers.py [--runs N] [--build DIR]
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import benchmark  # noqa: E402  (blockMeshDict from the model, OpenFOAM environment, timing)

PARAMETERS = benchmark.SIZES["1e6"]
TEMPLATE = ROOT / "Templates" / "cylinder_in_box.yaml"


def folder_bytes(path):
    path = Path(path)
    if path.is_file():
        return path.stat().st_size
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def parameter_arguments():
    arguments = []
    for name, value in PARAMETERS.items():
        arguments += ["-p", f"{name}={value}"]
    return arguments


def timed(command, env=None):
    wall, peak, status = benchmark.run_measured(command, env=env)
    if status != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed ({status})")
    return wall, peak


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5, help="runs per measurement (blockMesh: 3)")
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--output", default=str(HERE / "WRITERS.md"))
    args = parser.parse_args()
    cli = Path(args.build) / "bin" / "blockforge"
    if not cli.exists():
        sys.exit(f"{cli} not found: build first (scripts/setup.sh)")
    env = benchmark.openfoam_environment()
    if env is None:
        sys.exit("blockMesh not found: install the Debian package openfoam (scripts/setup.sh)")
    python_env = dict(os.environ)
    machine = benchmark.machine_info()
    work = Path(tempfile.mkdtemp(prefix="blockforge-writers-"))
    started = time.time()
    try:
        # blockMesh case from the resolved model.
        document = benchmark.run_worker("document", parameters=PARAMETERS,
                                        template=str(TEMPLATE))["document"]
        dictionary, cells, _ = benchmark.block_mesh_dict(document)
        case = work / "blockMesh_case"
        (case / "system").mkdir(parents=True)
        (case / "constant").mkdir()
        (case / "system" / "blockMeshDict").write_text(dictionary)
        (case / "system" / "controlDict").write_text(benchmark.CONTROL_DICT)
        (case / "system" / "fvSchemes").write_text(benchmark.FV_SCHEMES)
        (case / "system" / "fvSolution").write_text(benchmark.FV_SOLUTION)

        native = [str(cli), str(TEMPLATE)] + parameter_arguments()
        python = [sys.executable, "-m", "blockforge", str(TEMPLATE)] + parameter_arguments()
        ours_case = work / "ours"

        def run_native(output, extra=()):
            target = work / output
            shutil.rmtree(target.parent if output.endswith(".foam") else target,
                          ignore_errors=True)
            if target.exists():
                target.unlink()
            result = timed(native + ["-o", str(target)] + list(extra))
            written = target.parent if output.endswith(".foam") else target
            size = folder_bytes(written / "constant" / "polyMesh") if output.endswith(".foam") \
                else folder_bytes(target.parent) if output.endswith(".vtm") \
                else folder_bytes(target) + (folder_bytes(target.with_suffix(".nmf"))
                                             if output.endswith(".xyz") else 0)
            return result[0], result[1], size

        # 1. The headline, interleaved: blockMesh, native, Python.
        theirs, ours, ours_python = [], [], []
        for run in range(args.runs):
            if run < 3:
                shutil.rmtree(case / "constant" / "polyMesh", ignore_errors=True)
                theirs.append(timed(["blockMesh", "-case", str(case)], env=env))
            ours.append(run_native("ours/c.foam"))
            shutil.rmtree(work / "python", ignore_errors=True)
            ours_python.append(timed(python + ["-o", str(work / "python" / "c.foam")],
                                     env=python_env))
            benchmark.log(f"run {run}: blockMesh {theirs[-1][0] if run < 3 else '-'} s, "
                          f"native {ours[-1][0]:.3f} s, python {ours_python[-1][0]:.3f} s")
        t_theirs = benchmark.median([t for t, _ in theirs])
        t_ours = benchmark.median([t for t, _, _ in ours])
        t_python = benchmark.median([t for t, _ in ours_python])
        polymesh_bytes = folder_bytes(case / "constant" / "polyMesh")

        # 2. Every format.
        formats = [("OpenFOAM polyMesh, binary", "formats/foam_bin/c.foam", ()),
                   ("OpenFOAM polyMesh, ASCII", "formats/foam_ascii/c.foam", ("--ascii",)),
                   ("Plot3D .xyz + .nmf, binary", "formats/grid_bin.xyz", ()),
                   ("Plot3D .xyz + .nmf, ASCII", "formats/grid_ascii.xyz", ("--ascii",)),
                   ("CGNS (HDF5)", "formats/grid.cgns", ()),
                   ("VTK .vtm (points only, raw binary)", "formats/vtm/grid.vtm", ())]
        format_rows = []
        for label, output, extra in formats:
            runs = [run_native(output, extra) for _ in range(args.runs)]
            format_rows.append((label, benchmark.median([r[0] for r in runs]), runs[-1][2]))
            benchmark.log(f"{label}: {[round(r[0], 3) for r in runs]} s, {runs[-1][2]} bytes")
        vtm_runs = []
        for _ in range(args.runs):
            shutil.rmtree(work / "vtm", ignore_errors=True)
            vtm_runs.append(timed(python + ["-o", str(work / "vtm" / "grid.vtm")], env=python_env))
        vtm_bytes = folder_bytes(work / "vtm")

        # 3. Cross-check.
        check = subprocess.run(["checkMesh", "-case", str(ours_case)], env=env,
                               capture_output=True, text=True).stdout
        theirs_check = subprocess.run(["checkMesh", "-case", str(case)], env=env,
                                      capture_output=True, text=True).stdout

        def counts(text):
            return {key: int(re.search(rf"^\s*{key}:\s+(\d+)", text, re.M).group(1))
                    for key in ("points", "faces", "internal faces", "cells")}

        same = counts(check) == counts(theirs_check)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    fmt = benchmark.fmt_seconds
    mib = benchmark.fmt_bytes
    lines = [
        "# Solver-format writers: BlockForge against blockMesh",
        "",
        f"Machine: {machine['nproc']} cores, {machine['cpu']}; load average at start "
        f"{machine['load'][0]:.2f}. Commit {machine['commit']}. Generated by "
        f"Benchmark/writers.py in {time.time() - started:.0f} s; medians of {args.runs} runs "
        f"(blockMesh: {min(args.runs, 3)}), runs interleaved, every run into a fresh case.",
        "",
        f"Grid: cylinder_in_box, {cells} cells in 4 blocks (n_around {PARAMETERS['n_around']}, "
        f"n_radial {PARAMETERS['n_radial']}, n_depth {PARAMETERS['n_depth']}).",
        "",
        "| whole process, generate + write 1M cells as a binary polyMesh | wall time | peak RSS | vs blockMesh |",
        "|---|---|---|---|",
        f"| `blockMesh` (OpenFOAM v1912) | {fmt(t_theirs)} | "
        f"{mib(benchmark.median([p for _, p in theirs]))} | 1x |",
        f"| `blockforge ... -o case/c.foam` (native command line) | {fmt(t_ours)} | "
        f"{mib(benchmark.median([p for _, p, _ in ours]))} | **{t_theirs / t_ours:.1f}x faster** "
        f"(target >= 25x: {benchmark.verdict(t_theirs / t_ours >= 25)}) |",
        f"| `python3 -m blockforge ... -o case/c.foam` (also measures every cell's quality) | "
        f"{fmt(t_python)} | {mib(benchmark.median([p for _, p in ours_python]))} | "
        f"{t_theirs / t_python:.1f}x faster |",
        "",
        "| format, 1M cells, native command line (whole process) | wall time | bytes written |",
        "|---|---|---|",
        f"| blockMesh's polyMesh (binary), for comparison | {fmt(t_theirs)} | {mib(polymesh_bytes)} |",
    ]
    for label, seconds, size in format_rows:
        lines.append(f"| {label} | {fmt(seconds)} | {mib(size)} |")
    lines.append(f"| VTK .vtm (python3 -m blockforge, with the quality arrays) | "
                 f"{fmt(benchmark.median([t for t, _ in vtm_runs]))} | {mib(vtm_bytes)} |")
    lines += ["",
              f"Cross-check: checkMesh on BlockForge's case: "
              f"{'Mesh OK' if 'Mesh OK' in check else 'FAILED'}; points, faces, internal faces "
              f"and cells equal to blockMesh's: {same} ({counts(check)}).", ""]
    text = "\n".join(lines)
    print(text)
    Path(args.output).write_text(text)


if __name__ == "__main__":
    main()
