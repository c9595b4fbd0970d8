#!/usr/bin/python3
"""End-to-end BlockForge benchmark on the cylinder_in_box template (one run, medians).

1. blockMesh (OpenFOAM) against BlockForge at 1 million cells: the same 4-block O-grid,
   same cells per block and the same radial grading (the blockMeshDict is written from
   BlockForge's resolved model document), both writing their grid to disk in binary.
   Wall time and peak RSS of each, the ratio; the two grids are cross-checked (cells,
   merged points, block edge nodes) and checkMesh validates the blockMesh grid once.
2. vtkGridQuality (seven measures, interfaces matched) against vtkMeshQuality (hex scaled
   Jacobian only) on the same grids: cells/s and the ratio; the scaled Jacobians agree.
3. Peak memory of BlockForge meshing against the grid's own arrays (points 24 B/node,
   BlockId 4 B/cell) at 1e6 and 1e7 cells.

Every measurement runs in a fresh subprocess of this script (``--worker``), so memory
is clean and the Python/VTK import is outside the timed region (the whole-process wall
time is reported as well). Prints a Markdown table and writes it to RESULTS.md next to
this script. Needs the build environment: ``source build/blockforge-env.sh``.

Usage: benchmark.py [--quick] [--core-json bench_core.json] [--output FILE]
"""
import argparse
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEMPLATE = ROOT / "Templates" / "cylinder_in_box.yaml"
OPENFOAM_BASHRC = "/usr/share/openfoam/etc/bashrc"

# Cells = 4 * n_around * n_radial * n_depth exactly; k_wall stays at the template's 1.1.
SIZES = {
    "1e5": {"n_around": 25, "n_radial": 25, "n_depth": 40},
    "1e6": {"n_around": 50, "n_radial": 50, "n_depth": 100},
    "1e7": {"n_around": 100, "n_radial": 100, "n_depth": 250},
}

# glibc malloc backs its large allocations with transparent huge pages: first-touch page
# faults are expensive on virtual machines; used for an extra, informational measurement.
HUGE_PAGES = {"GLIBC_TUNABLES": "glibc.malloc.hugetlb=1"}


def with_huge_pages(env=None):
    return dict(env if env is not None else os.environ, **HUGE_PAGES)


# Targets of the issue.
TARGET_MESHER_NODES_PER_S = 50e6
TARGET_BLOCKMESH_RATIO = 25.0
TARGET_QUALITY_RATIO = 5.0
TARGET_MEMORY_RATIO = 2.0


# ----------------------------------------------------------------------------- helpers
def log(message):
    print(message, file=sys.stderr, flush=True)


def median(values):
    return statistics.median(values) if values else float("nan")


def read_status():
    """VmHWM and VmRSS of this process, bytes."""
    values = {}
    with open("/proc/self/status") as status:
        for line in status:
            key, _, rest = line.partition(":")
            if key in ("VmHWM", "VmRSS"):
                values[key] = int(rest.split()[0]) * 1024
    return values


def reset_peak():
    """Resets VmHWM to the current RSS (Linux >= 4.0)."""
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")


def run_measured(command, env=None, stdout=None, cwd=None):
    """Runs a command; returns (wall seconds, peak RSS bytes, exit status)."""
    start = time.perf_counter()
    process = subprocess.Popen(command, env=env, stdout=stdout or subprocess.DEVNULL,
                               stderr=subprocess.STDOUT, cwd=cwd)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    process.returncode = os.waitstatus_to_exitcode(status)
    return wall, usage.ru_maxrss * 1024, process.returncode


def run_worker(task, env=None, **arguments):
    """Runs `task` in a fresh interpreter (environment `env`, default ours); returns its
    JSON result plus the wall time of the whole process."""
    command = [sys.executable, str(Path(__file__).resolve()), "--worker",
               json.dumps(dict(arguments, task=task))]
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               env=env)
    out, err = process.communicate()
    wall = time.perf_counter() - start
    if process.returncode != 0:
        raise RuntimeError(f"worker {task} failed ({process.returncode}):\n"
                           f"{err.decode(errors='replace')[-3000:]}")
    result = json.loads(out.decode().strip().splitlines()[-1])
    result["process_wall"] = wall
    return result


def fmt_rate(value):
    for scale, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(value) >= scale:
            return f"{value / scale:.1f} {suffix}"
    return f"{value:.0f} "


def fmt_bytes(value):
    return f"{value / 2**20:.0f} MiB"


def fmt_seconds(value):
    return f"{value * 1e3:.0f} ms" if value < 1 else f"{value:.2f} s"


def verdict(ok):
    return "met" if ok else "**not met**"


# ------------------------------------------------------------------- worker (subprocess)
def build_pipeline(parameters, template):
    import blockforge

    source = blockforge.vtkBlockTemplateSource()
    source.SetTemplateFile(str(template))
    for name, value in parameters.items():
        source.SetParameter(str(name), str(value))
    mesher = blockforge.vtkBlockMesher()
    mesher.SetInputConnection(source.GetOutputPort())
    return source, mesher


def grid_counts(grid):
    nodes = cells = blocks = 0
    for index in range(grid.GetNumberOfBlocks()):
        block = grid.GetBlock(index)
        if block is None:
            continue
        blocks += 1
        nodes += block.GetNumberOfPoints()
        cells += block.GetNumberOfCells()
    return nodes, cells, blocks


def check_errors(*algorithms):
    from vtkmodules.vtkCommonCore import vtkCommand

    errors = []

    def collect(_caller, _event):
        errors.append(True)

    for algorithm in algorithms:
        algorithm.AddObserver(vtkCommand.ErrorEvent, collect)
    return errors


def worker_document(args):
    source, _ = build_pipeline(args["parameters"], args["template"])
    source.Update()
    document = source.GetModelDocument()
    if not document:
        raise RuntimeError("the template failed (no model document)")
    return {"document": document}


def worker_generate(args):
    """Generate (template + mesh) and write .vtm; time and peak memory of each."""
    import blockforge  # noqa: F401  (imports before the baseline)
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter

    output = args.get("output")
    source, mesher = build_pipeline(args["parameters"], args["template"])
    writer = vtkXMLMultiBlockDataWriter()
    baseline = read_status()["VmRSS"]
    reset_peak()
    start = time.perf_counter()
    source.Update()
    mesher.Update()
    generated = time.perf_counter()
    peak_generate = read_status()["VmHWM"]
    grid = mesher.GetOutput()
    nodes, cells, blocks = grid_counts(grid)
    if cells == 0:
        raise RuntimeError("the mesher produced no cells")
    result = {"generate": generated - start, "baseline_rss": baseline,
              "peak_generate": peak_generate - baseline, "nodes": nodes, "cells": cells,
              "blocks": blocks, "rss_peak": peak_generate}
    if output:
        reset_peak()
        before_write = read_status()["VmRSS"]
        write_start = time.perf_counter()
        writer.SetInputData(grid)
        writer.SetFileName(output)
        writer.SetDataModeToAppended()
        writer.EncodeAppendedDataOff()
        writer.SetCompressorTypeToNone()
        if not writer.Write():
            raise RuntimeError(f"could not write {output}")
        end = time.perf_counter()
        result["write"] = end - write_start
        result["peak_write"] = read_status()["VmHWM"] - before_write
        result["rss_peak"] = max(peak_generate, read_status()["VmHWM"])
        result["generate_write"] = end - start
        directory = Path(output).with_suffix("")
        result["bytes_written"] = Path(output).stat().st_size + sum(
            f.stat().st_size for f in directory.rglob("*") if f.is_file())
    return result


def worker_quality(args):
    """vtkGridQuality against vtkMeshQuality (hex scaled Jacobian), interleaved runs."""
    import numpy
    from vtkmodules.numpy_interface import dataset_adapter  # noqa: F401
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersVerdict import vtkMeshQuality

    import blockforge

    source, mesher = build_pipeline(args["parameters"], args["template"])
    mesher.Update()
    grid = mesher.GetOutput()
    _, cells, _ = grid_counts(grid)
    grid_quality_times, mesh_quality_times = [], []
    last = {}
    for _ in range(args["runs"]):
        quality = blockforge.vtkGridQuality()
        quality.SetInputData(grid)
        errors = check_errors(quality)
        start = time.perf_counter()
        quality.Update()
        grid_quality_times.append(time.perf_counter() - start)
        if errors:
            raise RuntimeError("vtkGridQuality reported an error")
        reference = vtkMeshQuality()
        reference.SetInputData(grid)
        reference.SetHexQualityMeasureToScaledJacobian()
        start = time.perf_counter()
        reference.Update()
        mesh_quality_times.append(time.perf_counter() - start)
        last = {"ours": quality.GetOutputDataObject(0), "theirs": reference.GetOutputDataObject(0)}
        del quality, reference
    # The two scaled Jacobians must agree.
    largest_difference = 0.0
    minimum = float("inf")
    ours, theirs = last["ours"], last["theirs"]
    for index in range(ours.GetNumberOfBlocks()):
        a = vtk_to_numpy(ours.GetBlock(index).GetCellData().GetArray("ScaledJacobian"))
        b = vtk_to_numpy(theirs.GetBlock(index).GetCellData().GetArray("Quality"))
        largest_difference = max(largest_difference, float(numpy.max(numpy.abs(a - b))))
        minimum = min(minimum, float(a.min()))
    statistics_table = ours.GetFieldData()
    summary = {}
    for name in ("NonOrthogonality", "Skewness", "MinAngle"):
        array = statistics_table.GetArray(name + "Summary")
        if array is not None:
            summary[name] = list(array.GetTuple3(0))
    return {"cells": cells, "grid_quality": grid_quality_times,
            "mesh_quality": mesh_quality_times, "jacobian_difference": largest_difference,
            "jacobian_min": minimum, "summary": summary}


def worker_crosscheck(args):
    """BlockForge grid against the blockMesh points: merged point count, block edges."""
    import numpy
    from scipy.spatial import cKDTree
    from vtkmodules.util.numpy_support import vtk_to_numpy

    foam_points = read_foam_points(args["points"])
    _, mesher = build_pipeline(args["parameters"], args["template"])
    mesher.Update()
    grid = mesher.GetOutput()
    all_points, edge_points = [], []
    per_block = []
    for index in range(grid.GetNumberOfBlocks()):
        block = grid.GetBlock(index)
        dims = block.GetDimensions()
        xyz = vtk_to_numpy(block.GetPoints().GetData()).reshape(dims[2], dims[1], dims[0], 3)
        all_points.append(xyz.reshape(-1, 3))
        per_block.append({"dims": list(dims), "cells": block.GetNumberOfCells()})
        for a in (0, -1):
            for b in (0, -1):
                edge_points += [xyz[a, b, :, :], xyz[a, :, b, :], xyz[:, a, b, :]]
    points = numpy.concatenate(all_points)
    merged = numpy.unique(points, axis=0)
    edges = numpy.concatenate(edge_points)
    tree = cKDTree(foam_points)
    edge_distance, _ = tree.query(edges)
    distance, _ = tree.query(merged)
    size = float(numpy.max(points.max(axis=0) - points.min(axis=0)))
    return {"merged_points": int(merged.shape[0]), "foam_points": int(foam_points.shape[0]),
            "edge_max_distance": float(edge_distance.max()) / size,
            "max_distance": float(distance.max()) / size,
            "median_distance": float(numpy.median(distance)) / size,
            "per_block": per_block}


def read_foam_points(path):
    """Points of an OpenFOAM polyMesh/points file written in binary (label 32, scalar 64)."""
    import numpy

    data = Path(path).read_bytes()
    header_end = data.index(b"}", data.index(b"FoamFile")) + 1
    header = data[:header_end].decode(errors="replace")
    if "binary" not in header:
        raise RuntimeError(f"{path} is not binary")
    if "scalar=32" in header:
        raise RuntimeError(f"{path}: single-precision OpenFOAM is not supported")
    match = re.compile(rb"(\d+)\s*\(").search(data, header_end)
    count = int(match.group(1))
    values = numpy.frombuffer(data, dtype="<f8", count=3 * count, offset=match.end())
    return values.reshape(count, 3)


WORKERS = {"document": worker_document, "generate": worker_generate,
           "quality": worker_quality, "crosscheck": worker_crosscheck}


# ------------------------------------------------------------------------ blockMeshDict
BLOCKMESH_EDGE_ORDER = [0, 2, 6, 4, 3, 1, 5, 7, 8, 9, 10, 11]  # blockMesh slot -> model edge
FOAM_FACES = {"i0": (0, 4, 7, 3), "i1": (1, 2, 6, 5), "j0": (0, 1, 5, 4),
              "j1": (3, 7, 6, 2), "k0": (0, 3, 2, 1), "k1": (4, 5, 6, 7)}
FOAM_PATCH_TYPES = {"wall": "wall", "symmetry": "symmetry", "empty": "empty"}


def edge_direction(edge):
    """0 = i, 1 = j, 2 = k for model edge 0..11 (Transfinite.h numbering)."""
    return 2 if edge >= 8 else edge % 2


def vec(values):
    return "(" + " ".join(repr(float(v)) for v in values) + ")"


def expansion_ratio(law, cells):
    """blockMesh's expansion ratio (last cell / first cell) of a model distribution law."""
    if law in ("uniform", None):
        return 1.0
    if isinstance(law, dict) and "geometric" in law:
        # Eq. 7: successive cells grow by k in the local edge direction.
        return float(law["geometric"]) ** (cells - 1)
    raise RuntimeError(f"no blockMesh equivalent written for law {law!r}")


def arc_point(start, end, centre):
    """Midpoint of the circular arc from start to end about centre (arc < 180 degrees)."""
    import numpy

    start, end, centre = (numpy.asarray(p, dtype=float) for p in (start, end, centre))
    radius = numpy.linalg.norm(start - centre)
    middle = 0.5 * (start + end) - centre
    return centre + radius * middle / numpy.linalg.norm(middle)


def block_mesh_dict(document):
    """The blockMeshDict of a BlockForge model document (density multiplier 1)."""
    import yaml

    model = yaml.safe_load(document)
    names = [v["name"] for v in model["vertices"]]
    index = {name: n for n, name in enumerate(names)}
    position = {v["name"]: v["position"] for v in model["vertices"]}
    lines = ["FoamFile", "{", "    version 2.0;", "    format ascii;",
             "    class dictionary;", "    object blockMeshDict;", "}", "",
             f"// Written by Benchmark/benchmark.py from the BlockForge model '{model['name']}'",
             "convertToMeters 1;", "", "vertices", "("]
    lines += [f"    {vec(position[name])} // {n} {name}" for n, name in enumerate(names)]
    lines += [");", "", "blocks", "("]
    expected_cells = 0
    for block in model["blocks"]:
        cells = block["cells"]
        expected_cells += cells[0] * cells[1] * cells[2]
        laws = block.get("laws") or ["uniform"] * 12
        ratios = [expansion_ratio(laws[e], cells[edge_direction(e)]) for e in range(12)]
        grading = [ratios[e] for e in BLOCKMESH_EDGE_ORDER]
        if all(grading[4 * d + m] == grading[4 * d] for d in range(3) for m in range(4)):
            grading_text = "simpleGrading " + vec(grading[0::4])
        else:
            grading_text = "edgeGrading " + vec(grading)
        vertex_text = " ".join(str(index[v]) for v in block["vertices"])
        lines.append(f"    hex ({vertex_text}) {block['name']} ({cells[0]} {cells[1]} {cells[2]}) "
                     f"{grading_text}")
    lines += [");", "", "edges", "("]
    for edge in model.get("edges") or []:
        a, b = edge["from"], edge["to"]
        if edge["kind"] == "arc":
            if "centre" in edge:
                through = arc_point(position[a], position[b], edge["centre"])
            else:
                through = edge["through"]
            lines.append(f"    arc {index[a]} {index[b]} {vec(through)} // {edge['name']}")
        elif edge["kind"] == "spline":
            points = " ".join(vec(p) for p in edge["points"])
            lines.append(f"    spline {index[a]} {index[b]} ({points}) // {edge['name']}")
    lines += [");", "", "boundary", "("]
    blocks = {block["name"]: block for block in model["blocks"]}
    for patch in model.get("patches") or []:
        faces = []
        for face in patch["faces"]:
            block_name, _, face_name = face.rpartition(".")
            vertices = blocks[block_name]["vertices"]
            faces.append("(" + " ".join(str(index[vertices[c]]) for c in FOAM_FACES[face_name]) + ")")
        lines += [f"    {patch['name']}", "    {",
                  f"        type {FOAM_PATCH_TYPES.get(patch['type'], 'patch')};",
                  "        faces (" + " ".join(faces) + ");", "    }"]
    lines += [");", "", "defaultPatch { name unnamed; type patch; }", "",
              "mergePatchPairs ();", ""]
    radial = [expansion_ratio(laws[3], cells[1]) for laws, cells in
              ((b.get("laws") or ["uniform"] * 12, b["cells"]) for b in model["blocks"])]
    return "\n".join(lines), expected_cells, radial


CONTROL_DICT = """FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application     blockMesh;
startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         1;
deltaT          1;
writeControl    timeStep;
writeInterval   1;
writeFormat     binary;
writePrecision  17;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable false;
"""
FV_SCHEMES = """FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes { default none; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
"""
FV_SOLUTION = """FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }
solvers {}
"""


def openfoam_environment():
    if not Path(OPENFOAM_BASHRC).exists() or not shutil.which("blockMesh", path="/usr/bin"):
        return None
    dump = subprocess.run(["bash", "-c", f"source {OPENFOAM_BASHRC} >/dev/null 2>&1; env -0"],
                          capture_output=True, check=True).stdout
    env = dict(item.split("=", 1) for item in dump.decode().split("\0") if "=" in item)
    return env


def parse_block_mesh_log(text):
    values = {}
    for key in ("nPoints", "nCells", "nFaces", "nInternalFaces"):
        match = re.search(rf"{key}\s*:\s*(\d+)", text)
        if match:
            values[key] = int(match.group(1))
    return values


def cell_zone_sizes(path):
    """Cells of each cellZone of a polyMesh/cellZones file (ascii or binary)."""
    data = Path(path).read_bytes() if Path(path).exists() else b""
    pattern = re.compile(rb"(\w+)\s*\{\s*type\s+cellZone;\s*cellLabels\s+List<label>\s+(\d+)")
    return {m.group(1).decode(): int(m.group(2)) for m in pattern.finditer(data)}


def parse_check_mesh(text):
    values = {"ok": "Mesh OK" in text}
    for key, pattern in (("cells", r"^\s*cells:\s*(\d+)"), ("points", r"^\s*points:\s*(\d+)"),
                         ("max_non_orthogonality", r"Mesh non-orthogonality Max:\s*([-\d.eE+]+)"),
                         ("max_skewness", r"Max skewness = ([-\d.eE+]+)")):
        match = re.search(pattern, text, re.MULTILINE)
        if match:
            values[key] = float(match.group(1))
    return values


# ------------------------------------------------------------------------------ phases
def machine_info():
    model = "unknown"
    with open("/proc/cpuinfo") as cpuinfo:
        for line in cpuinfo:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    memory = 0
    with open("/proc/meminfo") as meminfo:
        for line in meminfo:
            if line.startswith("MemTotal"):
                memory = int(line.split()[1]) * 1024
    load = os.getloadavg()
    commit = os.environ.get("BLOCKFORGE_COMMIT", "")
    if not commit:
        try:
            commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                    capture_output=True, text=True, check=True).stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            commit = "unknown"
    return {"nproc": os.cpu_count(), "cpu": model, "memory": memory, "load": load,
            "kernel": platform.release(), "commit": commit}


def generate_runs(count, parameters, template, work, env=None):
    """BlockForge generate + write (.vtm, appended raw binary, no compression) runs."""
    results = []
    for run in range(count):
        output = work / "blockforge" / f"grid{run}.vtm"
        output.parent.mkdir(exist_ok=True)
        results.append(run_worker("generate", env=env, parameters=parameters,
                                  template=str(template), output=str(output)))
        shutil.rmtree(output.with_suffix(""), ignore_errors=True)
        output.unlink()
    return results


def block_mesh_runs(count, case, work, env):
    results = []
    for _ in range(count):
        shutil.rmtree(case / "constant" / "polyMesh", ignore_errors=True)
        with open(work / "blockMesh.log", "w") as out:
            wall, peak, status = run_measured(["blockMesh", "-case", str(case)], env=env,
                                              stdout=out)
        if status != 0:
            raise RuntimeError(f"blockMesh failed ({status}):\n"
                               f"{(work / 'blockMesh.log').read_text()[-3000:]}")
        results.append({"wall": wall, "peak": peak})
    return results


def phase_blockmesh(work, runs, template, rows, notes, huge_pages):
    parameters = SIZES["1e6"]
    document = run_worker("document", parameters=parameters, template=str(template))["document"]
    dictionary, expected_cells, radial = block_mesh_dict(document)
    case = work / "blockMesh_case"
    (case / "system").mkdir(parents=True)
    (case / "constant").mkdir()
    (case / "system" / "blockMeshDict").write_text(dictionary)
    (case / "system" / "controlDict").write_text(CONTROL_DICT)
    (case / "system" / "fvSchemes").write_text(FV_SCHEMES)
    (case / "system" / "fvSolution").write_text(FV_SOLUTION)
    k_wall = 1.1
    log(f"blockMeshDict: {expected_cells} cells, radial simpleGrading {radial[0]:.6g} "
        f"(k_wall^(n_radial-1) = {k_wall ** (parameters['n_radial'] - 1):.6g}, from the "
        f"wall to the box)")

    ours = generate_runs(runs["cheap"], parameters, template, work)
    log(f"BlockForge generate+write: {[round(r['generate_write'], 3) for r in ours]} s")
    env = openfoam_environment()
    if env is None:
        notes.append("blockMesh not found (Debian package openfoam): comparison skipped.")
        return ours, {}
    theirs = block_mesh_runs(runs["expensive"], case, work, env)
    block_mesh_log = parse_block_mesh_log((work / "blockMesh.log").read_text())
    zones = cell_zone_sizes(case / "constant" / "polyMesh" / "cellZones")
    log(f"blockMesh: {[round(r['wall'], 3) for r in theirs]} s, {block_mesh_log}")
    polymesh_bytes = sum(f.stat().st_size for f in (case / "constant" / "polyMesh").rglob("*")
                         if f.is_file())

    # Validation (not timed): checkMesh once, then the point sets against each other.
    with open(work / "checkMesh.log", "w") as out:
        subprocess.run(["checkMesh", "-case", str(case)], env=env, stdout=out,
                       stderr=subprocess.STDOUT, check=False)
    check = parse_check_mesh((work / "checkMesh.log").read_text())
    cross = run_worker("crosscheck", parameters=parameters, template=str(template),
                       points=str(case / "constant" / "polyMesh" / "points"))
    log(f"checkMesh: {check}; cross-check: "
        f"{ {k: v for k, v in cross.items() if k != 'per_block'} }")

    t_ours = median([r["generate_write"] for r in ours])
    t_theirs = median([r["wall"] for r in theirs])
    cells = ours[0]["cells"]
    same_cells = (cells == expected_cells == block_mesh_log.get("nCells") ==
                  int(check.get("cells", -1)) and
                  [b["cells"] for b in cross["per_block"]] == list(zones.values()))
    same_points = cross["merged_points"] == cross["foam_points"] == block_mesh_log.get("nPoints")
    ratio = t_theirs / t_ours
    rows.append(("blockMesh vs BlockForge, 1M cells, both writing binary", "", "", "", ""))
    rows.append((f"grid: {cells} cells in 4 blocks, {ours[0]['nodes']} nodes (per block), "
                 f"{cross['merged_points']} merged points", "", "", "", ""))
    rows.append(("generate + write, wall time (BlockForge: generate + write)",
                 f"{fmt_seconds(t_ours)} ({fmt_seconds(median([r['generate'] for r in ours]))}"
                 f" + {fmt_seconds(median([r['write'] for r in ours]))})",
                 fmt_seconds(t_theirs), f"{ratio:.1f}x",
                 f">= {TARGET_BLOCKMESH_RATIO:.0f}x: {verdict(ratio >= TARGET_BLOCKMESH_RATIO)}"))
    t_process = median([r["process_wall"] for r in ours])
    rows.append(("same, whole process (BlockForge: + Python start and VTK import)",
                 fmt_seconds(t_process), fmt_seconds(t_theirs), f"{t_theirs / t_process:.1f}x",
                 ""))
    peak_ours = median([r["rss_peak"] for r in ours])
    peak_theirs = median([r["peak"] for r in theirs])
    rows.append(("peak RSS of the process", fmt_bytes(peak_ours), fmt_bytes(peak_theirs),
                 f"{peak_theirs / peak_ours:.1f}x less", ""))
    rows.append(("bytes written (.vtm + .vts / polyMesh)",
                 fmt_bytes(median([r["bytes_written"] for r in ours])),
                 fmt_bytes(polymesh_bytes), "", ""))
    rows.append(("cross-check", f"cells per block equal: {same_cells}; merged points equal: "
                 f"{same_points}", f"checkMesh: {'Mesh OK' if check.get('ok') else 'FAILED'}",
                 f"nodes within {cross['max_distance']:.0e}", ""))
    if huge_pages:
        ours_huge = generate_runs(runs["cheap"], parameters, template, work,
                                  env=with_huge_pages())
        theirs_huge = block_mesh_runs(runs["expensive"], case, work, with_huge_pages(env))
        t_ours_huge = median([r["generate_write"] for r in ours_huge])
        t_theirs_huge = median([r["wall"] for r in theirs_huge])
        log(f"huge pages: BlockForge {[round(r['generate_write'], 3) for r in ours_huge]} s, "
            f"blockMesh {[round(r['wall'], 3) for r in theirs_huge]} s")
        rows.append(("same with huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1), "
                     "for information",
                     f"{fmt_seconds(t_ours_huge)} "
                     f"({fmt_seconds(median([r['generate'] for r in ours_huge]))} + "
                     f"{fmt_seconds(median([r['write'] for r in ours_huge]))})",
                     fmt_seconds(t_theirs_huge), f"{t_theirs_huge / t_ours_huge:.1f}x", ""))
    interior = ("" if cross["max_distance"] < 1e-9 else
                " (blockMesh fills blocks by its own interpolation, not TFI)")
    notes.append(
        f"blockMesh case written from BlockForge's resolved model: 4 hex blocks "
        f"(n_around {parameters['n_around']}, n_radial {parameters['n_radial']}, n_depth "
        f"{parameters['n_depth']}), arc edges on the cylinder through the arc midpoints, "
        f"radial simpleGrading {radial[0]:.6g} = k_wall^(n_radial-1) from the wall to the "
        f"box, the template's patches; controlDict writeFormat binary, writeCompression "
        f"off. BlockForge writes vtkXMLMultiBlockDataWriter appended raw binary, no "
        f"compression. Node distances between the two grids, relative to the box size: "
        f"block edges max {cross['edge_max_distance']:.1e}, all merged points median "
        f"{cross['median_distance']:.1e}, max {cross['max_distance']:.1e}{interior}.")
    return ours, check


def phase_quality(sizes, runs, template, rows, notes, check=None, huge_pages=False):
    rows.append(("GridQuality (7 measures) vs vtkMeshQuality (hex scaled Jacobian), "
                 "cells/s (time)", "", "", "", ""))
    variants = [(label, None) for label in sizes]
    if huge_pages and "1e6" in sizes:
        variants.append(("1e6", with_huge_pages()))
    for label, env in variants:
        count = runs["cheap"] if label != "1e7" else runs["expensive"]
        result = run_worker("quality", env=env, parameters=SIZES[label],
                            template=str(template), runs=count)
        ours = median(result["grid_quality"])
        theirs = median(result["mesh_quality"])
        cells = result["cells"]
        ratio = theirs / ours
        log(f"quality {label}{' huge pages' if env else ''}: GridQuality "
            f"{[round(t, 3) for t in result['grid_quality']]}, vtkMeshQuality "
            f"{[round(t, 3) for t in result['mesh_quality']]}, "
            f"|dSJ| {result['jacobian_difference']:.1e}")
        if env:
            rows.append((f"{cells} cells with huge pages, for information",
                         f"{fmt_rate(cells / ours)}/s ({fmt_seconds(ours)})",
                         f"{fmt_rate(cells / theirs)}/s ({fmt_seconds(theirs)})",
                         f"{ratio:.1f}x", ""))
            continue
        rows.append((f"{cells} cells", f"{fmt_rate(cells / ours)}/s ({fmt_seconds(ours)})",
                     f"{fmt_rate(cells / theirs)}/s ({fmt_seconds(theirs)})", f"{ratio:.1f}x",
                     f">= {TARGET_QUALITY_RATIO:.0f}x: {verdict(ratio >= TARGET_QUALITY_RATIO)}"))
        if label == "1e6":
            notes.append(f"Quality: the scaled Jacobians of GridQuality and vtkMeshQuality "
                         f"agree within {result['jacobian_difference']:.1e} (1e6 grid, min "
                         f"{result['jacobian_min']:.3f}).")
            if check and "Skewness" in result["summary"]:
                notes.append(
                    f"GridQuality on the 1e6 grid: max NonOrthogonality "
                    f"{result['summary']['NonOrthogonality'][2]:.2f}, max Skewness "
                    f"{result['summary']['Skewness'][2]:.3f}; checkMesh on the blockMesh grid "
                    f"(same nodes): {check.get('max_non_orthogonality', float('nan')):.2f}, "
                    f"{check.get('max_skewness', float('nan')):.3f}.")


def phase_memory(sizes, runs, template, rows, previous=None):
    rows.append(("peak memory of meshing (template + vtkBlockMesher) vs the grid's arrays "
                 "(24 B/node + 4 B/cell)", "", "", "", ""))
    for label in sizes:
        if label == "1e6" and previous:
            results = previous
        else:
            count = runs["cheap"] if label != "1e7" else runs["expensive"]
            results = [run_worker("generate", parameters=SIZES[label], template=str(template))
                       for _ in range(count)]
        nodes, cells = results[0]["nodes"], results[0]["cells"]
        arrays = 24 * nodes + 4 * cells
        peak = median([r["peak_generate"] for r in results])
        ratio = peak / arrays
        rows.append((f"{cells} cells: peak above baseline / arrays", fmt_bytes(peak),
                     fmt_bytes(arrays), f"{ratio:.2f}",
                     f"<= {TARGET_MEMORY_RATIO:.0f}: {verdict(ratio <= TARGET_MEMORY_RATIO)}"))
        generate = median([r["generate"] for r in results])
        rows.append((f"{cells} cells: vtkBlockMesher pipeline in a fresh process "
                     f"(allocation included), nodes/s (time)",
                     f"{fmt_rate(nodes / generate)}/s ({fmt_seconds(generate)})", "", "", ""))
        if "peak_write" in results[0]:
            write_peak = median([r["peak_write"] for r in results])
            rows.append((f"{cells} cells: extra peak while writing .vtm", fmt_bytes(write_peak),
                         "", f"{write_peak / arrays:.2f}", ""))


def core_rows(path, rows):
    """Medians of bench_core's JSON output (--benchmark_out)."""
    data = json.loads(Path(path).read_text())
    medians = {}
    for entry in data.get("benchmarks", []):
        if entry.get("aggregate_name", "median") != "median":
            continue
        name = entry.get("run_name", entry["name"]).replace("/real_time", "")
        medians[name] = entry
    if not medians:
        return
    rows.append(("core, one thread, in memory (bench_core medians)", "", "", "", ""))
    for label in ("1e5", "1e6", "1e7"):
        mesher = medians.get(f"Mesher/{label}")
        blocks = medians.get(f"MeshBlocks/{label}")
        plain = medians.get(f"PlainTFI/{label}")
        tfi = medians.get(f"TransfiniteBlock/{label}")
        quality = medians.get(f"Quality/{label}")
        if mesher:
            rate = mesher["nodes/s"]
            reference = f"plain TFI {fmt_rate(plain['nodes/s'])}/s" if plain else ""
            rows.append((f"MultiBlockMesher, {int(mesher['nodes'])} nodes: nodes/s",
                         f"{fmt_rate(rate)}/s" + (f" (blocks only {fmt_rate(blocks['nodes/s'])}/s)"
                                                 if blocks else ""),
                         reference, f"{rate / plain['nodes/s']:.2f}x" if plain else "",
                         f">= 50 M/s: {verdict(rate >= TARGET_MESHER_NODES_PER_S)}"))
        if tfi:
            rows.append((f"transfiniteBlock on a cube, {int(tfi['nodes'])} nodes",
                         f"{fmt_rate(tfi['nodes/s'])}/s", "", "", ""))
        if quality:
            rows.append((f"computeGridQuality, {int(quality['cells'])} cells: cells/s",
                         f"{fmt_rate(quality['cells/s'])}/s", "", "", ""))


def markdown(machine, rows, notes, elapsed):
    lines = ["# BlockForge benchmark results", "",
             f"Machine: {machine['nproc']} cores, {machine['cpu']}, "
             f"{machine['memory'] / 2**30:.0f} GiB, Linux {machine['kernel']}; load average "
             f"at start {machine['load'][0]:.2f}. Commit {machine['commit']}. "
             "Template: cylinder_in_box (4 blocks, "
             "k_wall 1.1). Medians of the runs; generated by Benchmark/benchmark.py "
             f"on {time.strftime('%Y-%m-%d %H:%M')} in {elapsed:.0f} s.", "",
             "| measure | BlockForge | reference | ratio | target |",
             "|---|---|---|---|---|"]
    for row in rows:
        if all(cell == "" for cell in row[1:]):
            lines.append(f"| **{row[0]}** | | | | |")
        else:
            lines.append("| " + " | ".join(str(cell) for cell in row) + " |")
    lines.append("")
    lines += [f"- {note}" for note in notes]
    lines.append("")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--quick", action="store_true",
                        help="fewer runs (3 and 1), no 1e7 sizes: a smoke test")
    parser.add_argument("--core-json", help="bench_core --benchmark_out file to include")
    parser.add_argument("--template", default=str(TEMPLATE))
    parser.add_argument("--output", default=str(HERE / "RESULTS.md"),
                        help="Markdown file to write (default: Benchmark/RESULTS.md)")
    parser.add_argument("--no-huge-pages", action="store_true",
                        help="skip the informational runs with glibc huge pages")
    parser.add_argument("--keep", action="store_true", help="keep the temporary cases")
    args = parser.parse_args()

    if args.worker:
        arguments = json.loads(args.worker)
        result = WORKERS[arguments["task"]](arguments)
        print(json.dumps(result))
        return 0

    started = time.perf_counter()
    machine = machine_info()
    runs = {"cheap": 3, "expensive": 1} if args.quick else {"cheap": 5, "expensive": 3}
    sizes = ["1e5", "1e6"] if args.quick else ["1e5", "1e6", "1e7"]
    rows, notes = [], []
    template = Path(args.template)
    if args.core_json and Path(args.core_json).exists():
        core_rows(args.core_json, rows)
    work = Path(tempfile.mkdtemp(prefix="blockforge-bench-"))
    try:
        generate_1e6, check = phase_blockmesh(work, runs, template, rows, notes,
                                              not args.no_huge_pages)
        phase_quality(sizes, runs, template, rows, notes, check, not args.no_huge_pages)
        phase_memory([s for s in sizes if s != "1e5"], runs, template, rows, generate_1e6)
    finally:
        if args.keep:
            log(f"cases kept in {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    text = markdown(machine, rows, notes, time.perf_counter() - started)
    print(text)
    Path(args.output).write_text(text)
    log(f"written to {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
