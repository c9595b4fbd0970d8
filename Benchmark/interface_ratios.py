#!/usr/bin/python3
"""Where a block grid's cell sizes jump: the neighbour size ratio across every block
interface, per pair of blocks, with the grid's MinAngle classes and min scaled Jacobian.

Reads a Plot3D grid as `blockforge ... -o grid.xyz` writes it (binary multi-grid) and the
block names from the Neutral Map File beside it (grid.nmf). The ratio is the measure of
Testing/Cxx/TestGridFitness.cpp (TestPassageGeometry.h neighbourSizeRatio): for two cells
sharing a face on a block interface, the larger over the smaller of their widths across
that face (distance from the shared face's centre to the centre of the cell's opposite
face). Interfaces are found by coincident face centres, so periodic pairs (rotated copies)
are not included. Pure numpy; used to see which interfaces of axial_passage_oh keep it far
from the 1.5 of issue 8 (README, "Every template on every machine").

Usage: /usr/bin/python3 Benchmark/interface_ratios.py grid.xyz [pairs to list, default 8]
"""
import os
import struct
import sys

import numpy as np


def read_plot3d(path):
    """Blocks of a binary Plot3D multi-grid file as arrays [i, j, k, xyz]."""
    with open(path, 'rb') as stream:
        data = stream.read()
    position = 0

    def record():
        nonlocal position
        length = struct.unpack_from('<i', data, position)[0]
        body = data[position + 4:position + 4 + length]
        position += 8 + length
        return body

    count = struct.unpack('<i', record())[0]
    dims = np.frombuffer(record(), dtype='<i4').reshape(count, 3)
    blocks = []
    for ni, nj, nk in dims:
        xyz = np.frombuffer(record(), dtype='<f8').reshape(3, nk, nj, ni)
        blocks.append(np.ascontiguousarray(xyz.transpose(3, 2, 1, 0)))
    return blocks


def block_names(path, count):
    """Names from the '# name' comments of the block table in the .nmf beside the grid."""
    nmf = os.path.splitext(path)[0] + '.nmf'
    names = [f'block{b + 1}' for b in range(count)]
    if os.path.exists(nmf):
        with open(nmf, encoding='utf-8') as stream:
            for line in stream:
                fields = line.split('#')
                head = fields[0].split()
                if len(fields) == 2 and len(head) == 4 and all(f.isdigit() for f in head):
                    names[int(head[0]) - 1] = fields[1].strip()
    return names


def hex_corners(g):
    return [g[:-1, :-1, :-1], g[1:, :-1, :-1], g[1:, 1:, :-1], g[:-1, 1:, :-1],
            g[:-1, :-1, 1:], g[1:, :-1, 1:], g[1:, 1:, 1:], g[:-1, 1:, 1:]]


def scaled_jacobian(g):
    """Smallest corner scaled Jacobian of every cell (VTK hexahedron order) and whether the
    cell is collapsed (an edge of zero length: the writers' prisms, e.g. axial_passage_oh's
    fans on a sharp tip). A corner on a zero-length edge spans no volume and is left out, as
    GridQuality leaves a prism's apex out; counted, every prism read as inverted."""
    c = hex_corners(g)
    collapsed = None
    neighbours = [(1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2), (6, 4, 3)]
    result = None
    for v, (a, b, d) in enumerate(neighbours):
        e1, e2, e3 = c[a] - c[v], c[b] - c[v], c[d] - c[v]
        det = np.einsum('...i,...i', e1, np.cross(e2, e3))
        norms = np.linalg.norm(e1, axis=-1) * np.linalg.norm(e2, axis=-1) * np.linalg.norm(e3, axis=-1)
        value = np.where(norms > 0.0, det / np.maximum(norms, 1e-300), np.inf)
        flat = norms == 0.0
        result = value if result is None else np.minimum(result, value)
        collapsed = flat if collapsed is None else collapsed | flat
    return result, collapsed


def min_angle(g):
    """Smallest corner angle of the six faces of every cell, degrees (GridQuality MinAngle)."""
    c = hex_corners(g)
    faces = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (3, 2, 6, 7), (0, 3, 7, 4), (1, 2, 6, 5)]
    result = None
    for face in faces:
        for m in range(4):
            u = c[face[m - 1]] - c[face[m]]
            w = c[face[(m + 1) % 4]] - c[face[m]]
            cosine = np.einsum('...i,...i', u, w) / np.maximum(
                np.linalg.norm(u, axis=-1) * np.linalg.norm(w, axis=-1), 1e-300)
            angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
            result = angle if result is None else np.minimum(result, angle)
    return result


def boundary_cells(g, face):
    """Face centres and widths across the face of the cells on block face 0..5."""
    d = face // 2
    n = g.shape[d]
    fixed, inner = (0, 1) if face % 2 == 0 else (n - 1, n - 2)

    def quad_centres(layer):
        return 0.25 * (layer[:-1, :-1] + layer[1:, :-1] + layer[:-1, 1:] + layer[1:, 1:])

    c0 = quad_centres(np.take(g, fixed, axis=d))
    c1 = quad_centres(np.take(g, inner, axis=d))
    return c0.reshape(-1, 3), np.linalg.norm(c1 - c0, axis=-1).reshape(-1)


def interface_ratios(blocks, size):
    """{(block a, block b): largest neighbour size ratio across their shared faces}."""
    centres, widths, owners = [], [], []
    for b, g in enumerate(blocks):
        for face in range(6):
            if g.shape[face // 2] < 2:
                continue
            c, w = boundary_cells(g, face)
            centres.append(c)
            widths.append(w)
            owners.append(np.full(len(w), b))
    centres, widths, owners = np.concatenate(centres), np.concatenate(widths), np.concatenate(owners)
    keys = np.round(centres / (1e-7 * size)).astype(np.int64)
    order = np.lexsort(keys.T[::-1])
    same = np.all(keys[order][1:] == keys[order][:-1], axis=1)
    pairs = {}
    for k in np.nonzero(same)[0]:
        a, b = order[k], order[k + 1]
        if owners[a] == owners[b]:
            continue
        ratio = max(widths[a], widths[b]) / max(min(widths[a], widths[b]), 1e-300)
        key = tuple(sorted((int(owners[a]), int(owners[b]))))
        pairs[key] = max(pairs.get(key, 1.0), ratio)
    return pairs


def main(argv):
    if not argv:
        print(__doc__)
        return 1
    blocks = read_plot3d(argv[0])
    listed = int(argv[1]) if len(argv) > 1 else 8
    names = block_names(argv[0], len(blocks))
    points = np.concatenate([g.reshape(-1, 3) for g in blocks])
    size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    measured = [scaled_jacobian(g) for g in blocks]
    jacobian = np.concatenate([value.ravel() for value, _ in measured])
    collapsed = int(sum(flat.sum() for _, flat in measured))
    angles = np.concatenate([min_angle(g).ravel() for g in blocks])
    classes = np.histogram(angles, bins=[0, 20, 40, 60, 80, 90.0001])[0]
    print(f'cells {jacobian.size}  min ScaledJacobian {jacobian.min():.4f}  inverted {(jacobian <= 0).sum()}  collapsed {collapsed}  '
          f'min angle {angles.min():.1f}  MinAngle classes {" / ".join(map(str, classes))}')
    pairs = sorted(interface_ratios(blocks, size).items(), key=lambda item: -item[1])
    for (a, b), ratio in pairs[:listed]:
        print(f'  {names[a]:>8} | {names[b]:<8} {ratio:8.2f}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
