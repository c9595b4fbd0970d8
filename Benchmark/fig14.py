#!/usr/bin/python3
"""The paper's Fig. 14, ours: the axial force on a distributor vane and the torque about
the machine axis computed by simpleFoam on BlockForge grids of increasing density.

For every density multiplier the distributor passage (Templates/axial_passage_oh.yaml on
Data/distributor) is written as an OpenFOAM case by the native command line into a copy
of Testing/Data/openfoam/distributor_passage (swirling inlet at 1 m/s, outlet pressure,
walls, cyclic periodic sides, k-omega SST, water) and simpleFoam runs a fixed number of
iterations. The force and moment come from the case's `forces` function object on the
vane (patch blade, CofR on the axis): axial force = F_z, torque = M_z, per vane, each the
mean of the last quarter of the iterations (their spread is shown too).

Two series, as the paper's Fig. 14: the template's own grids (unoptimized, the native
command line) and the grids as the Python command line gives them by default, after the
BlockOptimizer moved the control points (`python3 -m blockforge`, which optimizes on the
template's grid and meshes at the density asked).

Writes doc/fig14_distributor.png and Benchmark/FIG14.md. Needs a build and OpenFOAM.
Usage: fig14.py [--densities 0.5,0.75,1,1.5,2] [--iterations 500]
       [--series unoptimized,optimized,non-orthogonality]
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

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CASE = ROOT / "Testing" / "Data" / "openfoam" / "distributor_passage"
TEMPLATE = ROOT / "Templates" / "axial_passage_oh.yaml"
INPUT = ROOT / "Data" / "distributor" / "BladeGen.inf"
BASHRC = "/usr/share/openfoam/etc/bashrc"
VANES = 16


def read_vectors(path):
    """Time and the total (first) vector of every line of a forces .dat file."""
    rows = []
    for line in Path(path).read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        numbers = re.findall(r"[-+0-9.eE]+", line)
        rows.append([float(x) for x in numbers[:4]])
    return np.array(rows)


SERIES = {"unoptimized": "unoptimized grids (template as placed)",
          "optimized": "optimized grids (BlockOptimizer, the default)",
          "non-orthogonality": "optimized for non-orthogonality (--objective non-orthogonality)"}


def mesh_command(build, series, density, case):
    """The command line writing the case's grid: the native one with --no-optimize for the
    template's own grid, the Python one (which runs the BlockOptimizer by default, as the
    native one now does too) for the optimized."""
    arguments = [str(TEMPLATE), "-i", str(INPUT), "-d", str(density),
                 "-o", str(case / "distributor.foam")]
    if series == "unoptimized":
        return [str(Path(build) / "bin" / "blockforge"), "--no-optimize"] + arguments
    if series == "non-orthogonality":
        arguments += ["--objective", "non-orthogonality"]
    return ["/usr/bin/python3", "-m", "blockforge"] + arguments


def python_environment(build):
    """The environment in which /usr/bin/python3 imports the build's blockforge."""
    environment = dict(os.environ)
    packages = sorted(Path(build, "lib").glob("python3*/*-packages"))
    if packages:
        environment["PYTHONPATH"] = os.pathsep.join(
            [str(packages[0])] + ([environment["PYTHONPATH"]] if "PYTHONPATH" in environment else []))
    return environment


def run_density(build, series, density, iterations, work):
    case = work / f"{series}_d{density:g}"
    shutil.copytree(CASE, case)
    control = case / "system" / "controlDict"
    control.write_text(re.sub(r"endTime\s+\d+;", f"endTime         {iterations};",
                              control.read_text()))
    mesh = subprocess.run(mesh_command(build, series, density, case), capture_output=True,
                          text=True, env=python_environment(build))
    if mesh.returncode != 0:
        raise RuntimeError(mesh.stderr)
    cells = int(re.search(r"cells: (\d+)", mesh.stdout).group(1))
    start = time.perf_counter()
    solve = subprocess.run(["bash", "-c", f"source {BASHRC} >/dev/null 2>&1; simpleFoam -case '{case}'"],
                           capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if solve.returncode != 0:
        raise RuntimeError(solve.stdout[-3000:] + solve.stderr[-3000:])
    folder = case / "postProcessing" / "vaneForces" / "0"
    force = read_vectors(folder / "force.dat")
    moment = read_vectors(folder / "moment.dat")
    tail = max(1, len(force) // 4)
    residual = re.findall(r"Solving for p, Initial residual = ([0-9.eE+-]+)", solve.stdout)
    return {"series": series, "density": density, "cells": cells,
            "settled": settled_iteration(force[:, 0], force[:, 3], force[-tail:, 3].mean()), "seconds": seconds,
            "axial": force[-tail:, 3].mean(), "axial_spread": np.ptp(force[-tail:, 3]),
            "torque": moment[-tail:, 3].mean(), "torque_spread": np.ptp(moment[-tail:, 3]),
            "p_residual": float(residual[-1]) if residual else float("nan"),
            "history": (force[:, 0], force[:, 3], moment[:, 3])}


def settled_iteration(iterations, values, final, tolerance=0.005):
    """The first iteration from which *values* stay within *tolerance* (relative) of
    *final*: how fast the force converges on the grid (the paper's point of Fig. 14)."""
    outside = np.nonzero(np.abs(values - final) > tolerance * abs(final))[0]
    if len(outside) == 0:
        return int(iterations[0])
    if outside[-1] + 1 >= len(iterations):
        return None
    return int(iterations[outside[-1] + 1])


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--densities", default="0.5,0.75,1,1.5,2")
    parser.add_argument("--iterations", type=int, default=500)
    parser.add_argument("--series", default="unoptimized,optimized,non-orthogonality",
                        help="comma-separated, of: " + ", ".join(SERIES))
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--png", default=str(ROOT / "doc" / "fig14_distributor.png"))
    parser.add_argument("--table", default=str(HERE / "FIG14.md"))
    args = parser.parse_args()
    cli = Path(args.build) / "bin" / "blockforge"
    if not cli.exists() or not Path(BASHRC).exists():
        sys.exit("needs build/bin/blockforge and OpenFOAM (scripts/setup.sh)")
    densities = [float(d) for d in args.densities.split(",")]
    series = args.series.split(",")
    unknown = sorted(set(series) - set(SERIES))
    if unknown:
        sys.exit(f"unknown series {unknown} (known: {', '.join(SERIES)})")
    work = Path(tempfile.mkdtemp(prefix="blockforge-fig14-"))
    started = time.time()
    try:
        results = {name: [] for name in series}
        for density in densities:
            for name in series:
                result = run_density(args.build, name, density, args.iterations, work)
                results[name].append(result)
                print(f"{name}, density {density:g}: {result['cells']} cells, axial force "
                      f"{result['axial']:.2f} N, torque {result['torque']:.2f} N m "
                      f"({result['seconds']:.0f} s)", file=sys.stderr, flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    for axis, key, label in ((axes[0], "axial", "axial force on a vane F_z [N]"),
                             (axes[1], "torque", "torque about the axis M_z [N m]")):
        for name, marker in zip(series, "os^"):
            rows = results[name]
            axis.errorbar([r["cells"] for r in rows], [r[key] for r in rows],
                          yerr=[r[key + "_spread"] / 2 for r in rows], marker=marker,
                          capsize=3, label=SERIES[name])
        axis.set_xscale("log")
        axis.set_xlabel("cells (one passage)")
        axis.set_ylabel(label)
        axis.grid(True, which="both", alpha=0.3)
    # One legend below both plots: inside either it hides the points of the coarse grids.
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(series), fontsize="small")
    fig.suptitle("Distributor passage, axial_passage_oh, simpleFoam k-omega SST "
                 f"({args.iterations} iterations)")
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    Path(args.png).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.png, dpi=110)

    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    lines = ["# Fig. 14, ours: vane force and torque against grid density", "",
             f"Distributor passage (Templates/axial_passage_oh.yaml on Data/distributor, 16 "
             f"vanes), simpleFoam k-omega SST, {args.iterations} iterations, values per vane "
             f"(whole row: x{VANES}), mean of the last quarter of the iterations (± half the "
             f"spread, max - min, over it); \"from finest\": relative to the finest grid of the "
             f"same series. Unoptimized grids: the native command line (`blockforge --no-optimize`, "
             f"the template's vertices as placed); optimized: `python3 -m blockforge`, which runs "
             f"the BlockOptimizer by default (its objective the smallest element angle); optimized for non-orthogonality: `python3 -m blockforge --objective non-orthogonality` (OpenFOAM's largest non-orthogonality minimised). Commit {commit}. Generated by Benchmark/fig14.py in "
             f"{time.time() - started:.0f} s (nice'd, on a 2-core machine shared with other "
             f"jobs: solver times are only indicative)."]
    for name in series:
        rows = results[name]
        finest = rows[-1]
        lines += ["", f"## {SERIES[name][0].upper()}{SERIES[name][1:]}", "",
                  "| density | cells | axial force F_z [N] | from finest | torque M_z [N m] | from finest | F_z within 0.5 % from iteration | final p residual | solver time |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            lines.append(
                f"| {r['density']:g} | {r['cells']} | {r['axial']:.3f} (±{r['axial_spread'] / 2:.3f}) | "
                f"{100 * (r['axial'] / finest['axial'] - 1):+.2f} % | {r['torque']:.3f} "
                f"(±{r['torque_spread'] / 2:.3f}) | {100 * (r['torque'] / finest['torque'] - 1):+.2f} % | "
                f"{r['settled'] if r['settled'] is not None else 'not settled'} | "
                f"{r['p_residual']:.2g} | {r['seconds']:.0f} s |")
    for other in series[1:]:
        lines += ["", f"## {SERIES[other][0].upper()}{SERIES[other][1:]} against {series[0]}, "
                  "density by density", "",
                  f"| density | cells | axial force: {other} - {series[0]} | torque: {other} - "
                  f"{series[0]} | final p residual ({series[0]} / {other}) |",
                  "|---|---|---|---|---|"]
        for a, b in zip(results[series[0]], results[other]):
            lines.append(
                f"| {a['density']:g} | {a['cells']} | {100 * (b['axial'] / a['axial'] - 1):+.2f} % | "
                f"{100 * (b['torque'] / a['torque'] - 1):+.2f} % | "
                f"{a['p_residual']:.2g} / {b['p_residual']:.2g} |")
    lines += ["", f"![force and torque against cells](../doc/{Path(args.png).name})", ""]
    text = "\n".join(lines)
    Path(args.table).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
