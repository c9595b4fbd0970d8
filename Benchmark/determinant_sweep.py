#!/usr/bin/python3
"""checkMesh's cell-determinant failures of axial_passage_oh on every machine, split into the
O-grid's blocks (its wall layers, thin by the template's request) and the H blocks, with
the largest interface ratio, the smallest scaled Jacobian and MinAngle, any other check
-allGeometry -allTopology fails, and the optimizer's end angle when it runs.

Usage: /usr/bin/python3 Benchmark/determinant_sweep.py [blockforge options...]
  e.g. Benchmark/determinant_sweep.py --no-optimize -p k_o=1.4
Environment: BLOCKFORGE_CLI (default build/bin/blockforge), TEMPLATE (default
Templates/axial_passage_oh.yaml), MACHINES (default dist,r37,comp,turb); OpenFOAM's
bashrc at /usr/share/openfoam/etc/bashrc. Per-block detail: Benchmark/determinant_cells.py.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import determinant_cells  # noqa: E402
import interface_ratios  # noqa: E402

INPUTS = {"dist": "Data/distributor/BladeGen.inf", "r37": "Data/rotor37/turbogrid/BladeGen.inf",
          "comp": "Data/compressor/rotor.inf", "turb": "Data/turbine/Info.txt"}


def main(argv):
    template = os.environ.get("TEMPLATE", str(ROOT / "Templates" / "axial_passage_oh.yaml"))
    for machine in os.environ.get("MACHINES", "dist,r37,comp,turb").split(","):
        try:
            output, report, determinant, _, blocks, names = determinant_cells.measure(
                [template, "-i", str(ROOT / INPUTS[machine]), *argv], all_checks=True)
        except subprocess.CalledProcessError as error:
            print(f"{machine}: failed: {error.stderr.strip()[-300:]}")
            continue
        optimizer = re.search(r"optimizer: smallest element angle ([^,]*)", output)
        other = [line.strip() for line in re.findall(r"\*\*\*([^\n]*)", report)
                 if "eterminant" not in line]
        o_grid, h_blocks = determinant_cells.split_by_block(
            names, [int(np.prod([s - 1 for s in g.shape[:3]])) for g in blocks], determinant)
        points = np.concatenate([g.reshape(-1, 3) for g in blocks])
        size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        ratios = interface_ratios.interface_ratios(blocks, size)
        worst = max(ratios, key=ratios.get)
        jacobian = min(float(interface_ratios.scaled_jacobian(g)[0].min()) for g in blocks)
        angle = min(float(interface_ratios.min_angle(g).min()) for g in blocks)
        print(f"{machine:5s} determinant O-grid {o_grid:5d} H blocks {sum(h_blocks.values()):5d} "
              f"{h_blocks}  ratio {ratios[worst]:.2f} ({names[worst[0]]}|{names[worst[1]]})  "
              f"min ScaledJacobian {jacobian:.3f}  min angle {angle:.1f}  other checks {other}"
              + (f"  optimizer {optimizer.group(1)}" if optimizer else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
