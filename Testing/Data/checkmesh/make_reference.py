#!/usr/bin/python3
"""Writes cylinder_in_box.txt: OpenFOAM checkMesh's per-cell non-orthogonality and
skewness on the cylinder grid that Benchmark/benchmark.py builds with blockMesh, for
TestCheckMeshReference (GridQuality must agree cell by cell).

The grid is Templates/cylinder_in_box.yaml with n_depth = 2 (2,048 cells), written as a
blockMeshDict from BlockForge's model document by the benchmark's own writer and meshed by
blockMesh. The reference holds blockMesh's grid as structured blocks (each BlockForge node
mapped to the nearest blockMesh point; blockMesh interpolates block interiors slightly
differently from BlockForge's TFI, so the test measures blockMesh's own nodes), then per
cell, in blockMesh's order (block by block, i fastest), checkMesh's nonOrthoAngle and
skewness (checkMesh -writeFields) and the cell centre (postProcess writeCellCentres).

Run from the source tree with the build environment and OpenFOAM (Debian `openfoam`;
not needed by the tests themselves):
    source build/blockforge-env.sh && /usr/bin/python3 Testing/Data/checkmesh/make_reference.py
"""
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent.parent
sys.path.insert(0, str(ROOT / "Benchmark"))
import benchmark  # noqa: E402  (the blockMeshDict writer and OpenFOAM environment)

PARAMETERS = {"n_depth": 2}
OUTPUT = HERE / "cylinder_in_box.txt"

CONTROL_DICT = benchmark.CONTROL_DICT.replace("writeFormat     binary;", "writeFormat     ascii;")


def run(command, case, env):
    result = subprocess.run(command + ["-case", str(case)], env=env, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(" ".join(command) + " failed:\n" + result.stdout + result.stderr)
    return result.stdout


def foam_list(path):
    """The first parenthesised list of an ascii OpenFOAM file, as a list of strings."""
    text = Path(path).read_text()
    if "internalField" in text:
        text = text[text.index("internalField"):]
    match = re.search(r"\n(\d+)\s*\n\(", text)
    count = int(match.group(1))
    body = text[match.end():]
    items = re.findall(r"\([^()]*\)|[-+\d.eE]+", body[: body.index("\n)")])
    if len(items) != count:
        raise RuntimeError(f"{path}: {len(items)} items, expected {count}")
    return items


def field(case, name):
    """A field file checkMesh or postProcess wrote (in constant/ or the time 0)."""
    for directory in ("constant", "0"):
        if (case / directory / name).exists():
            return case / directory / name
    raise RuntimeError(f"no field {name} written in {case}")


def vectors(items):
    return np.array([[float(v) for v in item.strip("()").split()] for item in items])


def main():
    env = benchmark.openfoam_environment()
    if env is None:
        sys.exit("OpenFOAM not found (/usr/share/openfoam/etc/bashrc, blockMesh)")
    source, mesher = benchmark.build_pipeline(PARAMETERS, benchmark.TEMPLATE)
    source.Update()
    mesher.Update()
    document = source.GetModelDocument()
    dictionary, expected_cells, _ = benchmark.block_mesh_dict(document)
    grid = mesher.GetOutput()
    blocks = []
    for index in range(grid.GetNumberOfBlocks()):
        block = grid.GetBlock(index)
        name = grid.GetMetaData(index).Get(grid.NAME())
        points = np.array([block.GetPoint(p) for p in range(block.GetNumberOfPoints())])
        dims = [0, 0, 0]
        block.GetDimensions(dims)
        blocks.append((name, dims, points))

    with tempfile.TemporaryDirectory() as work:
        case = Path(work)
        (case / "system").mkdir()
        (case / "system" / "blockMeshDict").write_text(dictionary)
        (case / "system" / "controlDict").write_text(CONTROL_DICT)
        (case / "system" / "fvSchemes").write_text(benchmark.FV_SCHEMES)
        (case / "system" / "fvSolution").write_text(benchmark.FV_SOLUTION)
        run(["blockMesh"], case, env)
        check = run(["checkMesh", "-writeFields", "(nonOrthoAngle skewness)"], case, env)
        run(["postProcess", "-func", "writeCellCentres"], case, env)
        version = re.search(r"Build\s*:\s*(.+)", check)
        foam_points = vectors(foam_list(case / "constant" / "polyMesh" / "points"))
        non_orthogonality = [float(v) for v in foam_list(field(case, "nonOrthoAngle"))]
        skewness = [float(v) for v in foam_list(field(case, "skewness"))]
        centres = vectors(foam_list(field(case, "C")))
    if len(non_orthogonality) != expected_cells or len(skewness) != expected_cells:
        raise RuntimeError("checkMesh wrote fields of another size than the grid")

    lines = ["# checkMesh per-cell reference for TestCheckMeshReference; written by",
             "# Testing/Data/checkmesh/make_reference.py (see there). OpenFOAM "
             + (version.group(1) if version else "?") + ", Templates/cylinder_in_box.yaml "
             + " ".join(f"{k}={v}" for k, v in PARAMETERS.items()) + ".",
             f"blocks {len(blocks)}"]
    worst = 0.0
    for name, dims, points in blocks:
        lines.append(f"block {name} {dims[0]} {dims[1]} {dims[2]}")
        for p in points:
            distance = np.linalg.norm(foam_points - p, axis=1)
            nearest = int(np.argmin(distance))
            worst = max(worst, float(distance[nearest]))
            lines.append(" ".join(f"{v:.17g}" for v in foam_points[nearest]))
    lines.append(f"cells {expected_cells}")
    for n in range(expected_cells):
        lines.append(f"{non_orthogonality[n]:.17g} {skewness[n]:.17g} "
                     + " ".join(f"{v:.17g}" for v in centres[n]))
    OUTPUT.write_text("\n".join(lines) + "\n")
    print(f"wrote {OUTPUT} ({expected_cells} cells); BlockForge and blockMesh nodes differ by "
          f"up to {worst:.3g} m")


if __name__ == "__main__":
    main()
