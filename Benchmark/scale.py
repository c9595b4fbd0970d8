#!/usr/bin/python3
"""Scale benchmark of the user's path on the distributor (Data/distributor with
Templates/axial_passage_oh.yaml): reader -> BlockTemplate -> BlockMesher -> GridQuality in
ParaView (pvpython, or pvbatch under mpiexec), at about 1e5, 1e6 and 1e7 grid nodes.

For each size and each configuration
- 1 rank, 1 thread  (VTK_SMP_BACKEND_IN_USE=Sequential),
- 1 rank, 2 threads (STDThread, VTK_SMP_MAX_THREADS=2),
- 2 ranks, 1 thread each (mpiexec -n 2 pvbatch),
it reports medians of several runs (each in a fresh process; the configurations take
turns, so a change of load on a shared machine hits them alike) of
- mesh: BlockMesher.UpdatePipeline() (the template is applied before the clock starts);
- mesh info: the data information ParaView gathers after it (GetDataInformation(), what
  Apply costs besides the filter; under MPI it also waits for the slower rank);
- quality, quality info: the same for GridQuality;
- nodes per second of mesh + mesh info, and the peak RSS of the process (of all ranks
  together under MPI);
and the speed-ups of 2 threads and 2 ranks over 1 rank with 1 thread (of mesh + mesh info
+ quality + quality info, and of meshing alone), measured and, since on a shared machine
other sessions take the cores, estimated from CPU times (the process's and its main
thread's: what ran on one core plus half of what ran on threads; rank 0's share), plus
the time per node across sizes and
a least-squares line time = a + b * nodes through the 1-thread runs (linear growth: the
per-node time falls to b as the fixed part a is spread). Every run checks that the grid
and quality arrays are the same bits as the first configuration's (a hash of them all,
up to 2 M cells). The 1-minute load average is recorded before every run; --quiet L waits
(up to --wait seconds) for it to fall below L first.

The template's default has 12 cells from hub to shroud; from density 8.8 on it folds a few
cells of block O_b at the trailing edge (a limit of its grading, issue 8). The benchmark
uses n_span = 24 (--parameters), which reaches 1e7 nodes at density 8.0, where every cell
is valid (the mesher refuses folded grids; here it must not have to).

Usage: source build/blockforge-env.sh; Benchmark/scale.py [--runs N] [--sizes 1e5,1e6,1e7]
       [--parameters n_span=24] [--quiet 1.0] [--output Benchmark/SCALE.md]
       Benchmark/scale.py --largest 5e7 [--density 8 --parameters n_span=120]
       (one run, 1 rank with 2 threads, at that size: time and memory)
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import uuid
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEMPLATE = ROOT / "Templates" / "axial_passage_oh.yaml"
INPUT = ROOT / "Data" / "distributor" / "BladeGen.inf"
# Nodes ~ this * density^3 on the distributor with n_span = 24 (10,198,892 at density 8).
NODES_AT_DENSITY_1 = 19920.0
CELL_HASH_LIMIT = 2_000_000


def process_peaks(token):
    """Peak RSS (MiB) summed over the processes of this run (every rank under MPI: the
    ranks share this machine), found by the run's token on their command line."""
    total = 0.0
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes().split(b"\0")
            if token.encode() not in command or b"--worker" not in command:
                continue
            for line in (entry / "status").read_text().splitlines():
                if line.startswith("VmHWM:"):
                    total += float(line.split()[1]) / 1024.0
        except OSError:
            continue
    return total


def worker(density, parameters, token):
    """Runs in pvpython/pvbatch: one pipeline at `density`; prints one JSON line."""
    import hashlib

    import numpy as np
    from paraview import servermanager
    from paraview.simple import LoadPlugin

    LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=globals())
    reader = TurboPointSetsReader(FileName=str(INPUT))  # noqa: F821
    model = BlockTemplate(Input=reader, TemplateFile=str(TEMPLATE))  # noqa: F821
    model.Parameters = parameters
    model.UpdatePipeline()
    mesher = BlockMesher(Input=model, DensityMultiplier=density)  # noqa: F821
    quality = GridQuality(Input=mesher)  # noqa: F821
    times = {}
    cpu, main_cpu = time.process_time(), time.thread_time()
    start = time.perf_counter()
    mesher.UpdatePipeline()
    times["mesh"] = time.perf_counter() - start
    start = time.perf_counter()
    info = mesher.GetDataInformation()
    nodes, cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
    times["mesh_info"] = time.perf_counter() - start
    start = time.perf_counter()
    quality.UpdatePipeline()
    times["quality"] = time.perf_counter() - start
    start = time.perf_counter()
    quality.GetDataInformation().GetNumberOfCells()
    times["quality_info"] = time.perf_counter() - start
    # CPU time of the process (all its threads) and of this thread alone: the threads of
    # vtkSMPTools' STDThread backend do the chunks while this one waits, so this thread's
    # CPU time is the part that ran on one core.
    times["cpu"] = time.process_time() - cpu
    times["main_cpu"] = time.thread_time() - main_cpu
    peak = max(process_peaks(token),
               resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    digest = ""
    if cells <= CELL_HASH_LIMIT:  # the bits of every array, gathered to this process
        data = servermanager.Fetch(quality)
        hasher = hashlib.blake2b(digest_size=8)
        iterator = data.NewIterator()
        iterator.InitTraversal()
        blocks = []
        while not iterator.IsDoneWithTraversal():
            name = iterator.GetCurrentMetaData().Get(data.NAME())
            blocks.append((name, iterator.GetCurrentDataObject()))
            iterator.GoToNextItem()
        for name, block in sorted(blocks, key=lambda item: item[0]):
            hasher.update(np.ascontiguousarray(_array(block.GetPoints().GetData())))
            cell_data = block.GetCellData()  # by name: gathering may reorder arrays
            for name in sorted(cell_data.GetArrayName(n)
                               for n in range(cell_data.GetNumberOfArrays())):
                hasher.update(np.ascontiguousarray(_array(cell_data.GetArray(name))))
        digest = hasher.hexdigest()
    print("RESULT " + json.dumps(dict(times, nodes=nodes, cells=cells, peak_mib=peak,
                                      digest=digest)), flush=True)


def _array(vtk_array):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    return vtk_to_numpy(vtk_array)


CONFIGURATIONS = {
    "1 rank, 1 thread": ([], {"VTK_SMP_BACKEND_IN_USE": "Sequential"}),
    "1 rank, 2 threads": ([], {"VTK_SMP_BACKEND_IN_USE": "STDThread",
                              "VTK_SMP_MAX_THREADS": "2"}),
    "2 ranks, 1 thread": (["mpiexec", "--allow-run-as-root", "--oversubscribe", "-n", "2"],
                          {"VTK_SMP_BACKEND_IN_USE": "Sequential"}),
}


def load_average():
    return os.getloadavg()[0]


def wait_for_quiet(limit, seconds):
    """Waits until the 1-minute load average is below `limit` (at most `seconds`)."""
    if limit <= 0:
        return
    deadline = time.time() + seconds
    while load_average() >= limit and time.time() < deadline:
        time.sleep(5)


def run(configuration, density, arguments):
    launcher, extra = CONFIGURATIONS[configuration]
    program = "pvbatch" if launcher else "pvpython"
    environment = dict(os.environ, **extra)
    # Plain pvpython/pvbatch are MPI singletons: keep the launcher's variables away.
    if not launcher:
        environment = {k: v for k, v in environment.items()
                       if not k.startswith(("OMPI_", "PMIX_", "PRTE_"))}
    token = uuid.uuid4().hex
    command = launcher + [program, "--force-offscreen-rendering", __file__, "--worker",
                          str(density), "--token", token, "--parameters",
                          arguments.parameters]
    wait_for_quiet(arguments.quiet, arguments.wait)
    load = load_average()
    start = time.perf_counter()
    output = subprocess.run(command, env=environment, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, timeout=1800).stdout
    wall = time.perf_counter() - start
    for line in output.splitlines():
        if line.startswith("RESULT "):
            result = json.loads(line[7:])
            result["process"] = wall
            result["load"] = load
            return result
    raise RuntimeError(f"{configuration} at density {density} failed:\n{output[-3000:]}")


def parse_parameters(text):
    pairs = []
    for item in filter(None, text.split(",")):
        name, _, value = item.partition("=")
        pairs += [name.strip(), value.strip()]
    return pairs


def total(row):
    return row["mesh"] + row["mesh_info"] + row["quality"] + row["quality_info"]


def table(rows, sizes, runs):
    lines = ["| nodes | cells | configuration | mesh [s] | mesh info [s] | quality [s] | "
             "quality info [s] | M nodes/s (mesh + info) | process [s] | peak RSS [MiB] | "
             "load (1 min) | same bits |", "|" + "---|" * 12]
    for row in rows:
        lines.append(
            f"| {row['nodes']:,} | {row['cells']:,} | {row['configuration']} | "
            f"{row['mesh']:.3f} | {row['mesh_info']:.3f} | {row['quality']:.3f} | "
            f"{row['quality_info']:.3f} | "
            f"{row['nodes'] / (row['mesh'] + row['mesh_info']) / 1e6:.2f} | "
            f"{row['process']:.2f} | {row['peak_mib']:.0f} | {row['load']:.1f} | "
            f"{row['same'] or '-'} |")
    lines += ["", "| nodes | speed-up, 2 threads: all (mesh) | 2 ranks: all (mesh) | "
              "from CPU times: 2 threads | 2 ranks | "
              "time per node [ns], 1 thread: mesh + info | all |",
              "|---|---|---|---|---|---|---|"]
    serial = []
    for size in sizes:
        by = {r["configuration"]: r for r in rows if r["size"] == size}
        base = by["1 rank, 1 thread"]
        mesh = lambda r: r["mesh"] + r["mesh_info"]  # noqa: E731
        threads, ranks = by["1 rank, 2 threads"], by["2 ranks, 1 thread"]
        # What 2 cores give without other load, from CPU times (all four phases): the
        # one-core part of the threaded run plus half of the rest; rank 0's CPU time
        # (its share; time spent waiting for rank 1 in MPI counts as well).
        threads_cpu = threads["main_cpu"] + (threads["cpu"] - threads["main_cpu"]) / 2.0
        lines.append(
            f"| {base['nodes']:,} | {total(base) / total(threads):.2f} "
            f"({mesh(base) / mesh(threads):.2f}) | {total(base) / total(ranks):.2f} "
            f"({mesh(base) / mesh(ranks):.2f}) | {base['cpu'] / threads_cpu:.2f} | "
            f"{base['cpu'] / ranks['cpu']:.2f} | {1e9 * mesh(base) / base['nodes']:.0f} | "
            f"{1e9 * total(base) / base['nodes']:.0f} |")
        serial.append((base["nodes"], total(base)))
    if len(serial) >= 2:
        count = len(serial)
        mean_x = sum(x for x, _ in serial) / count
        mean_y = sum(y for _, y in serial) / count
        slope = sum((x - mean_x) * (y - mean_y) for x, y in serial) / \
            sum((x - mean_x) ** 2 for x, _ in serial)
        intercept = mean_y - slope * mean_x
        worst = max(abs(intercept + slope * x - y) / y for x, y in serial)
        lines += ["", f"Least squares through the 1-thread totals: time = {intercept:.3f} s + "
                  f"{1e9 * slope:.0f} ns * nodes (largest deviation {100 * worst:.0f} % of "
                  f"the measured time)."]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--worker", type=float)
    parser.add_argument("--token", default="")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--sizes", default="1e5,1e6,1e7")
    parser.add_argument("--parameters", default="n_span=24")
    parser.add_argument("--quiet", type=float, default=0.0,
                        help="wait for a 1-minute load average below this before each run")
    parser.add_argument("--wait", type=float, default=300.0)
    parser.add_argument("--largest", type=float, default=0.0,
                        help="one serial run (1 rank, 2 threads) at about this many nodes")
    parser.add_argument("--density", type=float, default=0.0,
                        help="with --largest: this density instead (more nodes through the "
                             "parameters, e.g. n_span, where the density would fold cells)")
    parser.add_argument("--output", default=str(HERE / "SCALE.md"))
    arguments = parser.parse_args()
    if arguments.worker is not None:
        worker(arguments.worker, parse_parameters(arguments.parameters), arguments.token)
        return
    if arguments.largest > 0:
        density = arguments.density or \
            round((arguments.largest / NODES_AT_DENSITY_1) ** (1.0 / 3.0), 3)
        result = run("1 rank, 2 threads", density, arguments)
        print(json.dumps(dict(result, density=density)))
        return

    sizes = [float(s) for s in arguments.sizes.split(",")]
    rows = []
    for size in sizes:
        density = round((size / NODES_AT_DENSITY_1) ** (1.0 / 3.0), 3)
        results = {configuration: [] for configuration in CONFIGURATIONS}
        for _ in range(arguments.runs):
            for configuration in CONFIGURATIONS:
                results[configuration].append(run(configuration, density, arguments))
                print(configuration, density, json.dumps(results[configuration][-1]),
                      flush=True)
        reference = results["1 rank, 1 thread"][0]["digest"]
        for configuration, runs in results.items():
            median = {key: statistics.median(r[key] for r in runs)
                      for key in ("mesh", "mesh_info", "quality", "quality_info", "process",
                                  "peak_mib", "load", "cpu", "main_cpu")}
            same = ""
            if reference:
                same = "yes" if all(r["digest"] == reference for r in runs) else "NO"
            rows.append(dict(median, size=size, density=density, configuration=configuration,
                             nodes=runs[0]["nodes"], cells=runs[0]["cells"], same=same))
    text = table(rows, sizes, arguments.runs)
    print(text)
    Path(arguments.output).write_text(
        "# Scale benchmark (Benchmark/scale.py)\n\n" + __doc__.split("Usage:")[0].strip() +
        f"\n\nMedians of {arguments.runs} runs on {os.cpu_count()} cores "
        f"(parameters {arguments.parameters}).\n\n" + text)


if __name__ == "__main__":
    main()
