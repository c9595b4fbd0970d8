#!/usr/bin/python3
"""Where checkMesh's cell-determinant failures sit: per block of a BlockForge grid.

Meshes TEMPLATE (with the native command line `blockforge`) twice, as an OpenFOAM case and
as Plot3D (whose blocks and their cell order the polyMesh writer follows: block by block, i
fastest), runs OpenFOAM's `checkMesh -writeFields '(cellDeterminant aspectRatio)'` and
prints, per block, the cells under checkMesh's threshold (0.001) with their aspect ratio
and the cell layers (j, k) they lie in. Used to tell the thin cells a template asks for
(its wall layers and the cells matched to them) from cells that are thin or skewed for
another reason (README, "Solver-ready grids", cell determinant).

Usage: /usr/bin/python3 Benchmark/determinant_cells.py TEMPLATE [blockforge options...]
  e.g. Benchmark/determinant_cells.py Templates/axial_passage_oh.yaml
       -i Data/compressor/rotor.inf --no-optimize
Environment: BLOCKFORGE_CLI (default build/bin/blockforge); OpenFOAM's bashrc at
/usr/share/openfoam/etc/bashrc.
"""
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import interface_ratios  # noqa: E402  (Plot3D and block-name readers)

THRESHOLD = 1e-3  # checkMesh's cell determinant limit


def read_field(path):
    """The internal field of a binary or ASCII OpenFOAM volScalarField."""
    data = Path(path).read_bytes()
    body = data[data.index(b"internalField"):]
    match = re.search(rb"nonuniform List<scalar>\s*(\d+)\s*\(", body)
    if not match:
        raise RuntimeError(f"{path}: no nonuniform internal field")
    count = int(match.group(1))
    start = match.end()
    if b"format      binary" in data[:1000] or b"format binary" in data[:1000]:
        return np.frombuffer(body[start:start + 8 * count], dtype="<f8")
    return np.array(body[start:body.index(b")", start)].split(), dtype=float)


def split_by_block(names, counts, determinant):
    """(cells under THRESHOLD in the O-grid's blocks O_* (the template's wall layers),
    {other block: its cells under THRESHOLD, where any}) for blocks `names` of `counts`
    cells each, whose cells `determinant` holds block by block."""
    offset, o_grid, others = 0, 0, {}
    for name, count in zip(names, counts):
        failing = int(np.count_nonzero(determinant[offset:offset + count] < THRESHOLD))
        offset += count
        if name.startswith("O_"):
            o_grid += failing
        elif failing:
            others[name] = failing
    return o_grid, others


def measure(argv, all_checks=False):
    """Meshes with `blockforge ARGV` as an OpenFOAM case and as Plot3D, runs checkMesh
    -writeFields '(cellDeterminant aspectRatio)' (with -allGeometry -allTopology when
    `all_checks`) and returns the command line's output, checkMesh's, the determinant and
    aspect ratio per cell, the Plot3D blocks and their names. Raises
    subprocess.CalledProcessError when blockforge fails."""
    cli = os.environ.get("BLOCKFORGE_CLI", str(HERE.parent / "build" / "bin" / "blockforge"))
    with tempfile.TemporaryDirectory(prefix="blockforge-determinant-") as work:
        case = os.path.join(work, "case", "grid.foam")
        grid = os.path.join(work, "grid.xyz")
        for output in (case, grid):
            run = subprocess.run([cli, *argv, "-o", output], check=True, capture_output=True,
                                 text=True)
        checks = "-allGeometry -allTopology " if all_checks else ""
        # (checkMesh exits 1 when a check fails: the fields are written all the same)
        report = subprocess.run(
            ["bash", "-c", "source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1; "
             f"checkMesh -case \"$0\" {checks}-writeFields '(cellDeterminant aspectRatio)'",
             os.path.dirname(case)], capture_output=True, text=True).stdout
        constant = os.path.join(os.path.dirname(case), "constant")
        determinant = read_field(os.path.join(constant, "cellDeterminant"))
        aspect = read_field(os.path.join(constant, "aspectRatio"))
        blocks = interface_ratios.read_plot3d(grid)
        names = interface_ratios.block_names(grid, len(blocks))
    cells = sum((g.shape[0] - 1) * (g.shape[1] - 1) * (g.shape[2] - 1) for g in blocks)
    if cells != determinant.size:
        raise RuntimeError(f"{cells} cells in the Plot3D blocks, {determinant.size} in the "
                           "polyMesh (prisms or another cell order)")
    return run.stdout, report, determinant, aspect, blocks, names


def main(argv):
    if not argv:
        print(__doc__)
        return 1
    _, _, determinant, aspect, blocks, names = measure(argv)
    cells = determinant.size
    failing = int((determinant < THRESHOLD).sum())
    print(f"cells {cells}, under the determinant threshold {failing}")
    offset = 0
    for name, g in zip(names, blocks):
        ni, nj, nk = (s - 1 for s in g.shape[:3])
        count = ni * nj * nk
        d = determinant[offset:offset + count].reshape(nk, nj, ni)
        a = aspect[offset:offset + count].reshape(nk, nj, ni)
        offset += count
        bad = d < THRESHOLD
        if not bad.any():
            continue
        k, j, i = np.nonzero(bad)
        print(f"  {name:>6} {int(bad.sum()):5d} of {count:6d}  aspect ratio "
              f"{a[bad].min():5.1f}-{a[bad].max():5.1f}  per i {np.bincount(i, minlength=ni).tolist()}"
              f"  per j {np.bincount(j, minlength=nj).tolist()}"
              f"  per k {np.bincount(k, minlength=nk).tolist()}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
