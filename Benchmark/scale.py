#!/usr/bin/python3
"""Scale benchmark of the user's path on the distributor (Data/distributor with
Templates/axial_passage_oh.yaml): reader -> BlockTemplate -> BlockMesher -> GridQuality in
ParaView (pvpython, or pvbatch under mpiexec), at about 1e5, 1e6 and 1e7 grid nodes.

For each size and each configuration
- 1 rank, 1 thread  (VTK_SMP_BACKEND_IN_USE=Sequential),
- 1 rank, 2 threads (STDThread, VTK_SMP_MAX_THREADS=2),
- 2 ranks, 1 thread each (mpiexec -n 2 pvbatch),
it reports medians of several runs (each in a fresh process) of
- mesh: BlockMesher.UpdatePipeline() (the template is applied before the clock starts);
- mesh info: the data information ParaView gathers after it (GetDataInformation(), what
  Apply costs besides the filter), and the same for GridQuality (quality, quality info);
- nodes per second of meshing, and the peak RSS of the process (rank 0 under MPI);
and the speed-ups of 2 threads and 2 ranks over 1 rank with 1 thread, plus the meshing
time per node across sizes (linear growth keeps it flat). Every run checks that the grid
and quality arrays are the same bits as the first configuration's (a hash of them all).

Usage: source build/blockforge-env.sh; Benchmark/scale.py [--runs N] [--sizes 1e5,1e6,1e7]
       [--output Benchmark/SCALE.md]
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEMPLATE = ROOT / "Templates" / "axial_passage_oh.yaml"
INPUT = ROOT / "Data" / "distributor" / "BladeGen.inf"
# Nodes ~ this * density^3 on the distributor (784,472 at density 4.23).
NODES_AT_DENSITY_1 = 10360


def worker(density):
    """Runs in pvpython/pvbatch: one pipeline at `density`; prints one JSON line."""
    import hashlib

    import numpy as np
    from paraview import servermanager
    from paraview.simple import LoadPlugin

    LoadPlugin(os.environ["BLOCKFORGE_PLUGIN"], remote=False, ns=globals())
    reader = TurboPointSetsReader(FileName=str(INPUT))  # noqa: F821
    model = BlockTemplate(Input=reader, TemplateFile=str(TEMPLATE))  # noqa: F821
    model.UpdatePipeline()
    # From density 8.8 on (about 7 M nodes) the template folds a few cells of block O_b
    # at the trailing edge (a limit of the template, not of the mesher): the grid is
    # output anyway so that its cost is measured, and the folded cells are counted.
    mesher = BlockMesher(Input=model, DensityMultiplier=density,  # noqa: F821
                         AllowInvertedCells=1)
    quality = GridQuality(Input=mesher)  # noqa: F821
    times = {}
    start = time.perf_counter()
    mesher.UpdatePipeline()
    times["mesh"] = time.perf_counter() - start
    start = time.perf_counter()
    info = mesher.GetDataInformation()
    nodes, cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
    folded = info.GetFieldDataInformation().GetArrayInformation("InvertedCellCount")
    inverted = int(folded.GetComponentRange(0)[1]) if folded else 0
    times["mesh_info"] = time.perf_counter() - start
    start = time.perf_counter()
    quality.UpdatePipeline()
    times["quality"] = time.perf_counter() - start
    start = time.perf_counter()
    quality.GetDataInformation().GetNumberOfCells()
    times["quality_info"] = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    digest = ""
    if cells <= 2_000_000:  # the bits of every array, gathered to this process
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
                                      digest=digest, inverted=inverted)), flush=True)


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


def run(configuration, density):
    launcher, extra = CONFIGURATIONS[configuration]
    program = "pvbatch" if launcher else "pvpython"
    environment = dict(os.environ, **extra)
    # Plain pvpython/pvbatch are MPI singletons: keep the launcher's variables away.
    if not launcher:
        environment = {k: v for k, v in environment.items()
                       if not k.startswith(("OMPI_", "PMIX_", "PRTE_"))}
    command = launcher + [program, "--force-offscreen-rendering", __file__, "--worker",
                          str(density)]
    start = time.perf_counter()
    output = subprocess.run(command, env=environment, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, timeout=1800).stdout
    wall = time.perf_counter() - start
    for line in output.splitlines():
        if line.startswith("RESULT "):
            result = json.loads(line[7:])
            result["process"] = wall
            return result
    raise RuntimeError(f"{configuration} at density {density} failed:\n{output[-3000:]}")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--worker", type=float)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--sizes", default="1e5,1e6,1e7")
    parser.add_argument("--output", default=str(HERE / "SCALE.md"))
    arguments = parser.parse_args()
    if arguments.worker is not None:
        worker(arguments.worker)
        return

    sizes = [float(s) for s in arguments.sizes.split(",")]
    rows = []
    reference_digest = {}
    for size in sizes:
        density = round((size / NODES_AT_DENSITY_1) ** (1.0 / 3.0), 3)
        for configuration in CONFIGURATIONS:
            results = [run(configuration, density) for _ in range(arguments.runs)]
            median = {key: statistics.median(r[key] for r in results)
                      for key in ("mesh", "mesh_info", "quality", "quality_info", "process",
                                  "peak_mib")}
            digest = results[0]["digest"]
            same = ""
            if digest:
                reference_digest.setdefault(size, digest)
                same = "yes" if all(r["digest"] == reference_digest[size] for r in results) \
                    else "NO"
            rows.append(dict(median, size=size, density=density, configuration=configuration,
                             nodes=results[0]["nodes"], cells=results[0]["cells"], same=same,
                             inverted=results[0]["inverted"]))
            print(json.dumps(rows[-1]), flush=True)

    lines = ["| nodes | cells | configuration | mesh [s] | mesh info [s] | quality [s] | "
             "quality info [s] | M nodes/s meshing | process [s] | peak RSS [MiB] | "
             "same bits | folded cells |", "|" + "---|" * 12]
    for row in rows:
        lines.append(
            f"| {row['nodes']:,} | {row['cells']:,} | {row['configuration']} | "
            f"{row['mesh']:.3f} | {row['mesh_info']:.3f} | {row['quality']:.3f} | "
            f"{row['quality_info']:.3f} | {row['nodes'] / row['mesh'] / 1e6:.1f} | "
            f"{row['process']:.2f} | {row['peak_mib']:.0f} | {row['same'] or '-'} | "
            f"{row['inverted']} |")
    lines += ["", "| nodes | speed-up mesh+quality, 2 threads | 2 ranks | "
              "mesh time per node [ns], 1 thread |", "|---|---|---|---|"]
    for size in sizes:
        by = {r["configuration"]: r for r in rows if r["size"] == size}
        base = by["1 rank, 1 thread"]
        total = lambda r: r["mesh"] + r["quality"]  # noqa: E731
        lines.append(
            f"| {base['nodes']:,} | {total(base) / total(by['1 rank, 2 threads']):.2f} | "
            f"{total(base) / total(by['2 ranks, 1 thread']):.2f} | "
            f"{1e9 * base['mesh'] / base['nodes']:.0f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    Path(arguments.output).write_text(
        "# Scale benchmark (Benchmark/scale.py)\n\n" + __doc__.split("Usage:")[0].strip() +
        f"\n\nMedians of {arguments.runs} runs, {os.cpu_count()} cores shared with other work.\n\n"
        + text)


if __name__ == "__main__":
    main()
