"""Structured tetrahedral meshes of blocks and mapped blocks, for tests, benchmarks and simple
bodies (bars, plates, membranes) that need no mesher.

Every hexahedron of the grid is split into six tets around its main diagonal (Kuhn's split): the
same split in every cell makes the faces of neighbouring cells match, so the mesh is conforming.
"""
from __future__ import annotations

import itertools

import numpy as np

# Kuhn's split: one tet per order in which the three axes are stepped from corner (0,0,0) to (1,1,1)
_STEP_ORDERS = list(itertools.permutations(range(3)))


def box_mesh(size, divisions, origin=(0.0, 0.0, 0.0), mapping=None) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (n, 3) and positively oriented tets (6 per cell) of a box.

    Parameters
    ----------
    size : 3 floats
        Edge lengths (m).
    divisions : 3 ints
        Cells along each edge.
    origin : 3 floats
        The corner with the smallest coordinates (m).
    mapping : callable or None
        Maps the (n, 3) node coordinates of the box to their final positions (e.g. a trapezoid);
        tets inverted by the mapping keep their orientation fixed by reordering.
    """
    divisions = [int(d) for d in divisions]
    if min(divisions) < 1:
        raise ValueError(f"box_mesh: divisions {divisions} must be >= 1")
    axes = [np.linspace(o, o + s, d + 1) for o, s, d in zip(origin, size, divisions)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    nx, ny, nz = (d + 1 for d in divisions)

    def index(i, j, k):
        return (i * ny + j) * nz + k

    i, j, k = np.meshgrid(*[np.arange(d) for d in divisions], indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    tets = []
    for order in _STEP_ORDERS:
        corner = np.zeros((len(i), 3), dtype=np.int64)
        nodes = [index(i, j, k)]
        for axis in order:
            corner[:, axis] += 1
            nodes.append(index(i + corner[:, 0], j + corner[:, 1], k + corner[:, 2]))
        tets.append(np.stack(nodes, axis=1))
    tets = np.concatenate(tets)
    nodes = grid if mapping is None else np.asarray(mapping(grid), dtype=np.float64)
    edges = nodes[tets[:, 1:]] - nodes[tets[:, :1]]
    negative = np.linalg.det(edges) < 0
    tets[negative] = tets[negative][:, [0, 1, 3, 2]]
    return np.ascontiguousarray(nodes), np.ascontiguousarray(tets)
