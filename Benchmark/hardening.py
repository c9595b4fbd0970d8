"""Benchmark of the hardening (issue 12), not a test: how fast bad input is refused,
measured as a user runs it (the command line as a whole process), against a normal run of
the same template as the peer; and what checking the written grid costs (blockforge.output
against the plain VTK writer, in process). Medians of --runs runs.

Usage: source build/blockforge-env.sh; /usr/bin/python3 Benchmark/hardening.py [--runs 5]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
CYLINDER = os.path.join(SOURCE, "Templates", "cylinder_in_box.yaml")
TWO_BLOCKS = os.path.join(SOURCE, "Testing", "Data", "two_blocks.yaml")
OH = os.path.join(SOURCE, "Templates", "axial_passage_oh.yaml")
DISTRIBUTOR = os.path.join(SOURCE, "Data", "distributor")


def cli_seconds(arguments, runs, expect):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = subprocess.run([sys.executable, "-m", "blockforge"] + arguments,
                                capture_output=True, text=True)
        times.append(time.perf_counter() - start)
        if result.returncode != expect:
            raise SystemExit(f"unexpected exit {result.returncode}: {result.stderr}")
    return statistics.median(times), (result.stderr or result.stdout).strip().splitlines()[-1]


def scaled_hub(directory):
    """The distributor with four hub coordinates scaled by 1000 (the issue's slow case)."""
    copy = os.path.join(directory, "scaled_hub")
    shutil.copytree(DISTRIBUTOR, copy)
    path = os.path.join(copy, "hub.curve")
    with open(path, encoding="utf-8") as stream:
        rows = [line.split() for line in stream.read().splitlines()]
    for row, column in ((34, 2), (205, 0), (65, 0), (126, 1)):
        rows[row][column] = repr(float(rows[row][column]) * 1000.0)
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("\n".join("  ".join(row) for row in rows) + "\n")
    return os.path.join(copy, "BladeGen.inf")


def write_seconds(runs, directory):
    import blockforge
    import blockforge.output
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter

    quality = blockforge.mesh_template(OH, density_multiplier=2.0,
                                       input_file=os.path.join(DISTRIBUTOR, "BladeGen.inf"))
    grid = quality.GetOutputDataObject(0)
    plain, checked = [], []
    for run in range(runs):
        start = time.perf_counter()
        writer = vtkXMLMultiBlockDataWriter()
        writer.SetInputData(grid)
        writer.SetFileName(os.path.join(directory, f"plain{run}.vtm"))
        writer.SetDataModeToAppended()
        writer.EncodeAppendedDataOff()
        writer.Write()
        plain.append(time.perf_counter() - start)
        start = time.perf_counter()
        blockforge.output.write_vtm(grid, os.path.join(directory, f"checked{run}.vtm"))
        checked.append(time.perf_counter() - start)
    cells = sum(grid.GetBlock(b).GetNumberOfCells() for b in range(grid.GetNumberOfBlocks()))
    return cells, statistics.median(plain), statistics.median(checked)


def in_process_refusal(runs):
    """Seconds of mesh_template refusing the cylinder at -d 1000 (8.2e12 nodes), in process
    (template, model check, estimate: nothing allocated), against meshing it at -d 1."""
    import blockforge

    refused, normal = [], []
    for _ in range(runs):
        start = time.perf_counter()
        try:
            blockforge.mesh_template(CYLINDER, density_multiplier=1000.0)
            raise SystemExit("not refused")
        except RuntimeError:
            refused.append(time.perf_counter() - start)
        start = time.perf_counter()
        blockforge.mesh_template(CYLINDER)
        normal.append(time.perf_counter() - start)
    return statistics.median(refused), statistics.median(normal)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    runs = parser.parse_args().runs
    directory = tempfile.mkdtemp(prefix="blockforge-hardening-bench-")
    try:
        rows = []
        normal, _ = cli_seconds([CYLINDER], runs, 0)
        rows.append(("cylinder_in_box, normal run (peer)", normal, "8192 cells"))
        for label, arguments in (("cylinder_in_box -d 1000 (refused)", [CYLINDER, "-d", "1000"]),
                                 ("two_blocks -p n=10000 (refused)", [TWO_BLOCKS, "-p", "n=10000"])):
            seconds, message = cli_seconds(arguments, runs, 1)
            rows.append((label, seconds, message))
        inf = os.path.join(DISTRIBUTOR, "BladeGen.inf")
        normal_oh, _ = cli_seconds([OH, "-i", inf], runs, 0)
        rows.append(("axial_passage_oh, distributor (peer)", normal_oh, "9600 cells"))
        seconds, message = cli_seconds([OH, "-i", scaled_hub(directory)], runs, 1)
        rows.append(("axial_passage_oh, 4 hub coordinates x1000", seconds, message))
        print(f"whole command-line process, median of {runs} runs")
        for label, seconds, detail in rows:
            print(f"  {label:<44} {seconds:6.3f} s   {detail[:110]}")
        refused, normal = in_process_refusal(runs)
        print(f"in process: refusing cylinder_in_box -d 1000 (8.2e12 nodes) {refused * 1e3:.1f} ms, "
              f"meshing it at -d 1 (10404 nodes) {normal * 1e3:.1f} ms")
        cells, plain, checked = write_seconds(runs, directory)
        print(f"writing the distributor OH grid at -d 2 ({cells} cells), median of {runs}: "
              f"plain vtkXMLMultiBlockDataWriter {plain:.3f} s, blockforge.output.write_vtm "
              f"(staged, read back, fsync, published) {checked:.3f} s, ratio "
              f"{checked / plain:.2f}")
    finally:
        shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    main()
