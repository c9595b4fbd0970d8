"""Grid change between two builds: every template of Templates/ on every data set of Data/
(as placed, no optimizer), at density multipliers 1 and 2.

  PYTHONPATH=build/lib/python3.11/dist-packages /usr/bin/python3 Benchmark/grid_change.py save DIR
      writes every block's nodes to DIR (one .npz per case)
  ... Benchmark/grid_change.py compare OLD NEW
      prints, per case, the largest node displacement relative to the shortest grid line
      at that node (its local cell edge) and to the model's size

Used to measure what a change of the arc-length rule does to the grids (issue 7).
"""
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy

import blockforge

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = {
    "rotor37_turbogrid": "Data/rotor37/turbogrid/BladeGen.inf",
    "rotor37_dat": "Data/rotor37/dat/Info.txt",
    "distributor": "Data/distributor/BladeGen.inf",
    "compressor": "Data/compressor/rotor.inf",
    "turbine": "Data/turbine/Info.txt",
}
PLAIN = ["annular_sector.yaml", "cylinder_in_box.yaml", "wedge_sector.yaml"]
PASSAGE = ["axial_passage_h.yaml", "axial_passage_oh.yaml"]


def cases():
    for name in PLAIN:
        yield name, None
    for name in PASSAGE:
        for data in DATA:
            yield name, data


def blocks(template, data, density):
    quality = blockforge.mesh_template(
        os.path.join(ROOT, "Templates", template), density_multiplier=density,
        input_file=os.path.join(ROOT, DATA[data]) if data else None, optimize=False)
    grid = quality.GetOutputDataObject(0)
    out = {}
    for b in range(grid.GetNumberOfBlocks()):
        block = grid.GetBlock(b)
        name = grid.GetMetaData(b).Get(grid.NAME())
        dims = block.GetDimensions()
        xyz = vtk_to_numpy(block.GetPoints().GetData()).reshape(dims[2], dims[1], dims[0], 3)
        out[name] = xyz.copy()
    return out


def save(folder):
    os.makedirs(folder, exist_ok=True)
    for template, data in cases():
        for density in (1, 2):
            grids = blocks(template, data, density)
            np.savez(os.path.join(folder, f"{template}-{data}-{density}.npz"), **grids)


def local_edge(xyz):
    """Shortest grid line at every node (its smallest neighbour distance, > 0)."""
    shortest = np.full(xyz.shape[:3], np.inf)
    for axis in range(3):
        if xyz.shape[axis] < 2:
            continue
        step = np.linalg.norm(np.diff(xyz, axis=axis), axis=-1)
        step = np.where(step > 0.0, step, np.inf)
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[axis] = slice(0, -1)
        hi[axis] = slice(1, None)
        shortest[tuple(lo)] = np.minimum(shortest[tuple(lo)], step)
        shortest[tuple(hi)] = np.minimum(shortest[tuple(hi)], step)
    return shortest


def compare(old_folder, new_folder):
    print(f"{'case':52s} {'max |dx|/cell':>14s} {'max |dx|/size':>14s} {'changed nodes':>14s}")
    for name in sorted(os.listdir(old_folder)):
        old = np.load(os.path.join(old_folder, name))
        new = np.load(os.path.join(new_folder, name))
        worst_cell = worst_size = 0.0
        changed = total = 0
        everything = np.concatenate([old[k].reshape(-1, 3) for k in old.files])
        size = np.linalg.norm(everything.max(axis=0) - everything.min(axis=0))
        for key in old.files:
            a, b = old[key], new[key]
            move = np.linalg.norm(b - a, axis=-1)
            worst_cell = max(worst_cell, float(np.max(move / local_edge(a))))
            worst_size = max(worst_size, float(np.max(move)) / size)
            changed += int(np.count_nonzero(move))
            total += move.size
        print(f"{name[:-4]:52s} {worst_cell:14.2e} {worst_size:14.2e} {changed:7d}/{total}")


if __name__ == "__main__":
    if sys.argv[1] == "save":
        save(sys.argv[2])
    else:
        compare(sys.argv[2], sys.argv[3])
