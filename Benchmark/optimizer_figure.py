"""The BlockOptimizer's figure, after the paper's Fig. 12: for every machine and template,
cells per MinAngle class before (template placement) and after the automatic run, side by
side, with the smallest element angle before -> after and the run's time.

Reads the CSV of ``bench_optimizer --csv`` (and, optionally, the whole-process times of
scripts/bench_optimizer.sh) and writes a PNG. Not a test.

Usage: /usr/bin/python3 Benchmark/optimizer_figure.py optimizer.csv out.png [process.csv]
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CLASSES = ["0-20", "20-40", "40-60", "60-80", "80-90"]
MACHINES = {"distributor": "distributor", "rotor37": "Rotor 37", "compressor": "compressor",
            "turbine": "turbine"}


def machine_of(path):
    for key, label in MACHINES.items():
        if key in path:
            return label
    return os.path.basename(os.path.dirname(path))


def read_process_times(path):
    """(template, input) -> (seconds with the optimizer, seconds without)."""
    times = {}
    if path and os.path.exists(path):
        with open(path, newline="") as handle:
            for row in csv.DictReader(handle):
                times[(row["template"], row["input"])] = (float(row["optimize_seconds"]),
                                                          float(row["no_optimize_seconds"]))
    return times


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    with open(argv[1], newline="") as handle:
        rows = list(csv.DictReader(handle))
    process = read_process_times(argv[3] if len(argv) > 3 else None)
    templates = sorted({row["template"] for row in rows}, reverse=True)  # OH first
    machines = []
    for row in rows:
        if machine_of(row["input"]) not in machines:
            machines.append(machine_of(row["input"]))
    figure, axes = plt.subplots(len(templates), len(machines), sharey=True,
                                figsize=(3.4 * len(machines), 3.3 * len(templates)),
                                squeeze=False)
    width = 0.38
    for row in rows:
        r = templates.index(row["template"])
        c = machines.index(machine_of(row["input"]))
        axis = axes[r][c]
        before = [int(v) for v in row["before_classes"].split()]
        after = [int(v) for v in row["after_classes"].split()]
        total = sum(before)
        positions = range(len(CLASSES))
        axis.bar([p - width / 2 for p in positions], [100.0 * v / total for v in before],
                 width, label="template", color="#b0b0b0")
        axis.bar([p + width / 2 for p in positions], [100.0 * v / total for v in after],
                 width, label="optimized", color="#2a6fb0")
        axis.set_xticks(list(positions))
        axis.set_xticklabels(CLASSES, fontsize=8)
        title = f"{row['template']}, {machine_of(row['input'])}"
        gained = float(row["after_min"]) - float(row["before_min"])
        note = (f"min angle {float(row['before_min']):.1f} -> {float(row['after_min']):.1f} deg"
                f" (+{gained:.1f})\n{int(row['evaluations'])} evaluations, "
                f"{float(row['seconds']):.2f} s ({float(row['cpu_seconds']):.2f} s CPU)")
        key = (row["template"], row["input"])
        if key in process:
            with_optimizer, without = process[key]
            note += f"\ncommand line {with_optimizer:.2f} s ({without:.2f} s without)"
        axis.set_title(title, fontsize=9)
        axis.text(0.02, 0.97, note, transform=axis.transAxes, fontsize=7, va="top")
        # Cells below 20 degrees are few: give their counts.
        for p, (b, a) in enumerate(zip(before, after)):
            if p == 0:
                axis.text(p, 2, f"{b} -> {a}", ha="center", fontsize=7)
        if c == 0:
            axis.set_ylabel("cells [%]")
        if r == len(templates) - 1:
            axis.set_xlabel("MinAngle class [deg]")
    axes[0][0].legend(fontsize=8, loc="center left")
    for axis in axes.flat:
        axis.set_ylim(0, 75)
    figure.suptitle("BlockOptimizer: cells per MinAngle class, template placement (grey) and "
                    "after the automatic run (blue)", fontsize=10)
    figure.tight_layout()
    figure.savefig(argv[2], dpi=110)
    print(f"wrote {argv[2]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
