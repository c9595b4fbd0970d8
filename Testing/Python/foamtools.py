"""Running OpenFOAM's own tools (Debian package `openfoam`) on BlockForge cases, and
reading what they write: checkMesh summaries and failed checks, binary cell fields, solver
residuals. Shared by the OpenFOAM tests and the benchmark scripts."""
import os
import re
import subprocess

import numpy as np

OPENFOAM_BASHRC = "/usr/share/openfoam/etc/bashrc"


def have_openfoam():
    return os.path.exists(OPENFOAM_BASHRC)


def run_foam(arguments, case, timeout=600):
    """Runs an OpenFOAM application (a list: name and options) on *case* in a shell that
    sourced OpenFOAM's bashrc; returns (exit status, output)."""
    if not have_openfoam():
        raise RuntimeError(f"OpenFOAM is not installed ({OPENFOAM_BASHRC} missing): "
                           "run scripts/setup.sh")
    command = " ".join(["'" + a.replace("'", "'\\''") + "'" for a in arguments])
    script = f"source {OPENFOAM_BASHRC} >/dev/null 2>&1; {command} -case '{case}'"
    result = subprocess.run(["bash", "-c", script], capture_output=True, text=True,
                            timeout=timeout)
    return result.returncode, result.stdout + result.stderr


def check_mesh_summary(text):
    """The figures of a checkMesh output: cells by shape, max non-orthogonality, max
    skewness, max aspect ratio, the failed checks (their *** lines) and the verdict."""
    def number(pattern):
        match = re.search(pattern, text)
        return float(match.group(1)) if match else None

    failed = [line.strip() for line in text.splitlines() if line.strip().startswith("***")]
    return {
        "cells": number(r"\n\s*cells:\s+(\d+)"),
        "hexahedra": number(r"hexahedra:\s+(\d+)"),
        "prisms": number(r"prisms:\s+(\d+)"),
        "polyhedra": number(r"polyhedra:\s+(\d+)"),
        "non_orthogonality": number(r"Mesh non-orthogonality Max: ([0-9.eE+-]+)"),
        "skewness": number(r"Max skewness = ([0-9.eE+-]+)"),
        "aspect_ratio": number(r"Max aspect ratio = ([0-9.eE+-]+)"),
        "determinant_cells": number(r"small determinant \(< [0-9.]+\) found, number of cells: (\d+)"),
        "coupled_ok": "Coupled point location match" in text and
        re.search(r"Coupled point location match \(average [^)]*\) OK", text) is not None,
        "failed": failed,
        "ok": "Mesh OK." in text,
    }


def read_cell_field(path):
    """The internal field of a volScalarField written by OpenFOAM (binary or ASCII)."""
    with open(path, "rb") as stream:
        data = stream.read()
    at = data.index(b"internalField")
    match = re.compile(rb"internalField\s+nonuniform\s+List<scalar>\s+(\d+)\s*\(").match(data, at)
    if not match:
        uniform = re.compile(rb"internalField\s+uniform\s+([0-9.eE+-]+)").match(data, at)
        return np.array([float(uniform.group(1))])
    count = int(match.group(1))
    start = match.end()
    if b"format      binary" in data[:at] or b"format binary" in data[:at]:
        return np.frombuffer(data, dtype="<f8", count=count, offset=start).copy()
    end = data.index(b")", start)
    return np.array(data[start:end].split(), dtype=float)


def residuals(log_text):
    """Initial residuals per field and iteration from a solver log: {field: [values]}."""
    series = {}
    for match in re.finditer(r"Solving for (\w+), Initial residual = ([0-9.eE+-]+)", log_text):
        series.setdefault(match.group(1), []).append(float(match.group(2)))
    return series


def blocks_of(grid):
    """{block name: (block, node dimensions [ni, nj, nk])} of a BlockForge multiblock grid."""
    found = {}
    iterator = grid.NewIterator()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        block = iterator.GetCurrentDataObject()
        dims = [0, 0, 0]
        block.GetDimensions(dims)
        found[iterator.GetCurrentMetaData().Get(grid.NAME())] = (block, dims)
        iterator.GoToNextItem()
    return found


def row_cells(grid, names, array):
    """Cell array *array* on the cells next to the j = 0 face of the blocks in *names*."""
    from vtkmodules.numpy_interface import dataset_adapter as dsa
    values = []
    blocks = blocks_of(grid)
    for name in names:
        block, dims = blocks[name]
        cells = np.array(dsa.WrapDataObject(block).CellData[array])
        values.append(cells.reshape(dims[2] - 1, dims[1] - 1, dims[0] - 1)[:, 0, :].ravel())
    return np.concatenate(values)
