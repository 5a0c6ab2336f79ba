"""How much of each body lies in each fluid cell: exact solid volumes on the Cartesian fluid grid.

The seed paper finds the solid volume fraction of each fluid element from a supermesh of the solid
and fluid meshes (Xiang et al., section 2.3; it is what the drag source terms of their eqs. 4, 11
and 12 are weighted by). Here the fluid elements are the cells of a :class:`FluidGrid`, and each
body's tetrahedra are clipped against them exactly
(``riprap/coupling/kernels/tet_cell_volumes.py``). The result keeps each body apart, as a block of
cells around it, since the coupling needs both the solid fraction of every cell and, per body, the
cells whose fluid force acts on it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.coupling.kernels import tet_cell_volumes
from riprap.errors import CaseFileError
from riprap.fluid.grid import FluidGrid

__all__ = ["BodyCellVolumes", "body_cell_volumes", "rigid_body_cell_volumes", "merge_blocks"]


@dataclass(frozen=True)
class BodyCellVolumes:
    """Solid volume (m^3) of every body in every cell of its block.

    ``origin[b]``: the grid index (i, j, k) of body b's first cell; ``shape[b]``: its block's size
    in cells; ``values[offset[b]:offset[b + 1]]``: the block, C order. A body outside the grid has
    an empty block.
    """

    grid: FluidGrid
    origin: np.ndarray
    shape: np.ndarray
    offset: np.ndarray
    values: np.ndarray

    @property
    def n_bodies(self) -> int:
        return len(self.origin)

    def block(self, body: int) -> tuple[np.ndarray, np.ndarray]:
        """(origin (3,), volumes (bi, bj, bk)) of one body."""
        volumes = self.values[self.offset[body]:self.offset[body + 1]].reshape(self.shape[body])
        return self.origin[body], volumes

    def body_volume(self, body: int) -> float:
        """The body's volume inside the grid (m^3)."""
        return float(self.values[self.offset[body]:self.offset[body + 1]].sum())

    def solid_volume(self) -> np.ndarray:
        """Solid volume in every cell (nx, ny, nz), all bodies together (m^3)."""
        total = np.zeros(tuple(self.grid.cells))
        for body in range(self.n_bodies):
            (i, j, k), volumes = self.block(body)
            bi, bj, bk = volumes.shape
            total[i:i + bi, j:j + bj, k:k + bk] += volumes
        return total

    def solid_fraction(self) -> np.ndarray:
        """Share of every cell's volume taken by solid, 0..1 (bodies pressed into each other by
        contact can overlap by a little; the share is capped at 1)."""
        return np.minimum(self.solid_volume() / self.grid.cell_size ** 3, 1.0)


def body_cell_volumes(grid: FluidGrid, nodes, tets, tet_start) -> BodyCellVolumes:
    """Exact volumes of tetrahedral bodies in the cells of ``grid``.

    ``nodes`` (n, 3): world positions (m) of all bodies' nodes; ``tets`` (m, 4): node indices of
    all tetrahedra; ``tet_start`` (bodies + 1,): body b owns tets[tet_start[b]:tet_start[b + 1]].
    """
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    tets = np.ascontiguousarray(tets, dtype=np.int64)
    tet_start = np.ascontiguousarray(tet_start, dtype=np.int64)
    if nodes.ndim != 2 or nodes.shape[1] != 3 or tets.ndim != 2 or tets.shape[1] != 4:
        raise CaseFileError(f"solid volumes: nodes must be (n, 3) and tets (m, 4), got "
                            f"{nodes.shape} and {tets.shape}")
    if len(tets) and (tets.min() < 0 or tets.max() >= len(nodes)):
        raise CaseFileError(f"solid volumes: tets refer to nodes 0..{tets.max()}, but there are "
                            f"{len(nodes)} nodes")
    if tet_start[0] != 0 or tet_start[-1] != len(tets) or np.any(np.diff(tet_start) < 0):
        raise CaseFileError("solid volumes: tet_start must rise from 0 to the number of tets")
    if not np.isfinite(nodes).all():
        bad = int(np.argwhere(~np.isfinite(nodes))[0, 0])
        body = int(np.searchsorted(tet_start, np.argmax((tets == bad).any(axis=1)), side="right")) - 1
        raise CaseFileError(f"solid volumes: node {bad} (body {body}) is not finite")
    lower = np.asarray(grid.lower, dtype=np.float64)
    h = float(grid.cell_size)
    origin, shape, offset = tet_cell_volumes.body_blocks(nodes, tets, tet_start, lower, h,
                                                         grid.cells)
    values = np.zeros(offset[-1])
    tet_cell_volumes.fill_blocks(nodes, tets, tet_start, lower, h, origin, shape, offset, values)
    return BodyCellVolumes(grid=grid, origin=origin, shape=shape, offset=offset, values=values)


def rigid_body_cell_volumes(grid: FluidGrid, solver, bodies=None) -> BodyCellVolumes:
    """:func:`body_cell_volumes` of the bodies of a :class:`riprap.solid.solver.SolidSolver` at
    their present position and orientation: all of them, or those listed in ``bodies`` (the
    result's blocks are then in that order)."""
    if not solver._ready:
        solver.finalize()
    table = solver.table
    rotations = solver.rotation_matrices()
    node_parts, tet_parts, tet_start = [], [], [0]
    node_count = 0
    chosen = range(solver.n_bodies) if bodies is None else [int(b) for b in bodies]
    for body in chosen:
        s = solver.shape_index[body]
        local = table.nodes[table.node_offset[s]:table.node_offset[s + 1]]
        node_parts.append(local @ rotations[body].T + solver.positions[body])
        tet_parts.append(table.tets[table.tet_offset[s]:table.tet_offset[s + 1]] + node_count)
        node_count += len(local)
        tet_start.append(tet_start[-1] + len(tet_parts[-1]))
    if not node_parts:
        empty = np.zeros((0, 3), dtype=np.int64)
        return BodyCellVolumes(grid=grid, origin=empty, shape=empty.copy(),
                               offset=np.zeros(1, dtype=np.int64), values=np.zeros(0))
    return body_cell_volumes(grid, np.concatenate(node_parts), np.concatenate(tet_parts),
                             np.array(tet_start))


def merge_blocks(grid: FluidGrid, parts) -> BodyCellVolumes:
    """One :class:`BodyCellVolumes` from per-body (origin, volumes) blocks, in order."""
    origin = np.array([p[0] for p in parts], dtype=np.int64).reshape(-1, 3)
    shape = np.array([p[1].shape for p in parts], dtype=np.int64).reshape(-1, 3)
    sizes = [p[1].size for p in parts]
    offset = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    values = (np.concatenate([p[1].reshape(-1) for p in parts]) if parts else np.zeros(0))
    return BodyCellVolumes(grid=grid, origin=origin, shape=shape, offset=offset, values=values)
