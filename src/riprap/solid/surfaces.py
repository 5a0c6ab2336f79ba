"""World boundary surfaces of a solver's bodies, for pictures and ParaView frames."""
from __future__ import annotations

import numpy as np

__all__ = ["surface_arrays"]


def surface_arrays(solver):
    """Points (n, 3), triangles (m, 3) and the body of each triangle (m,) of every body of a
    :class:`riprap.solid.solver.SolidSolver`, in the world at its present pose."""
    rotations = solver.rotation_matrices()
    points, triangles, owners = [], [], []
    offset = 0
    for b in range(solver.n_bodies):
        shape = solver.shapes[solver.shape_index[b]]
        used = np.unique(shape.triangles)
        remap = np.full(len(shape.mesh.nodes), -1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        points.append(shape.mesh.nodes[used] @ rotations[b].T + solver.positions[b])
        triangles.append(remap[shape.triangles] + offset)
        owners.append(np.full(len(shape.triangles), b, dtype=np.int64))
        offset += len(used)
    return np.concatenate(points), np.concatenate(triangles), np.concatenate(owners)
