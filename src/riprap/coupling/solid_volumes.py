"""How much of each body lies in each fluid cell: exact solid volumes on the Cartesian fluid grid.

The seed paper finds the solid volume fraction of each fluid element from a supermesh of the solid
and fluid meshes (Xiang et al., section 2.3; it is what the drag source terms of their eqs. 4, 11
and 12 are weighted by). Here the fluid elements are the cells of a :class:`FluidGrid`. Two exact
ways, equal to round-off (``tests/unit/test_solid_cell_volumes.py``): :func:`body_cell_volumes`
clips every tetrahedron against the cells (``riprap/coupling/kernels/tet_cell_volumes.py``, the
reference); :func:`surface_cell_volumes` integrates the boundary triangles over each column of cells
(``riprap/coupling/kernels/surface_cell_volumes.py``), so the interior tetrahedra never enter: 17
times faster on the paper's mound (``bench/solid_volumes.py``), and what the coupling uses
(:func:`rigid_body_cell_volumes`). The result keeps each body apart, as a block of cells around
it, since the coupling needs both the solid fraction of every cell and, per body, the cells whose
fluid force acts on it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.coupling.kernels import surface_cell_volumes as surface_kernels
from riprap.coupling.kernels import tet_cell_volumes
from riprap.errors import CaseFileError
from riprap.fluid.grid import FluidGrid
from riprap.solid.kernels.geometry_ops import rotation_matrix

__all__ = ["BodyCellVolumes", "body_cell_volumes", "surface_cell_volumes", "rigid_body_cell_volumes",
           "rigid_body_half_cell_volumes", "half_cell_volumes", "merge_blocks", "add_block",
           "widened_strip"]


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
    #: Optional (``rigid_body_half_cell_volumes``): per cell of every block the solid volume in
    #: its lower and upper half along each axis, flat as values with 6 per cell (axis, side).
    halves: np.ndarray | None = None

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
            add_block(total, *self.block(body), self.grid.periodic_y)
        return total

    def solid_fraction(self) -> np.ndarray:
        """Share of every cell's volume taken by solid, 0..1 (bodies pressed into each other by
        contact can overlap by a little; the share is capped at 1)."""
        return np.minimum(self.solid_volume() / self.grid.cell_size ** 3, 1.0)


def add_block(target, origin, block, periodic_y: bool = False) -> None:
    """``target`` (the grid's cells) += a body's ``block`` of cells from ``origin``; on a
    periodic y the block's cells past 0 or ny are the strip's other side (a block is never
    wider than the strip, so no cell is met twice)."""
    i, j, k = (int(n) for n in origin)
    bi, bj, bk = block.shape
    if periodic_y and (j < 0 or j + bj > target.shape[1]):
        target[i:i + bi, (j + np.arange(bj)) % target.shape[1], k:k + bk] += block
    else:
        target[i:i + bi, j:j + bj, k:k + bk] += block


def widened_strip(grid: FluidGrid, solids) -> tuple[FluidGrid, int]:
    """A periodic strip's grid widened in y by the bodies' reach on either side (cells), and that
    reach: clipped on it, a body across the strip's side keeps all its cells (``add_block``
    folds them back). Its cells lie where the strip's do, to round-off."""
    h = grid.cell_size
    solids.finalize()
    reach = float(solids.bounding_radius[solids.shape_index].max(initial=0.0))
    margin = int(np.ceil(reach / h)) + 2
    lower, upper = list(grid.lower), list(grid.upper)
    lower[1] -= margin * h
    upper[1] += margin * h
    cells = (grid.cells[0], grid.cells[1] + 2 * margin, grid.cells[2])
    return FluidGrid(lower=tuple(lower), upper=tuple(upper), cells=cells), margin


def _checked_cells(nodes, cells, cell_start, corners: int, what: str):
    """``nodes``, ``cells`` (m, corners) and ``cell_start`` as contiguous arrays, or an error that
    names what is wrong."""
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    cell_start = np.ascontiguousarray(cell_start, dtype=np.int64)
    if nodes.ndim != 2 or nodes.shape[1] != 3 or cells.ndim != 2 or cells.shape[1] != corners:
        raise CaseFileError(f"solid volumes: nodes must be (n, 3) and {what} (m, {corners}), got "
                            f"{nodes.shape} and {cells.shape}")
    if len(cells) and (cells.min() < 0 or cells.max() >= len(nodes)):
        raise CaseFileError(f"solid volumes: {what} refer to nodes 0..{cells.max()}, but there are "
                            f"{len(nodes)} nodes")
    if cell_start[0] != 0 or cell_start[-1] != len(cells) or np.any(np.diff(cell_start) < 0):
        raise CaseFileError(f"solid volumes: the start of each body's {what} must rise from 0 to "
                            f"the number of {what}")
    if not np.isfinite(nodes).all():
        bad = int(np.argwhere(~np.isfinite(nodes))[0, 0])
        body = int(np.searchsorted(cell_start, np.argmax((cells == bad).any(axis=1)), side="right")) - 1
        raise CaseFileError(f"solid volumes: node {bad} (body {body}) is not finite")
    return nodes, cells, cell_start


def _fill(grid: FluidGrid, fill, nodes, cells, cell_start) -> BodyCellVolumes:
    lower = np.asarray(grid.lower, dtype=np.float64)
    h = float(grid.cell_size)
    origin, shape, offset = tet_cell_volumes.body_blocks(nodes, cells, cell_start, lower, h,
                                                         grid.cells)
    values = np.zeros(offset[-1])
    fill(nodes, cells, cell_start, lower, h, origin, shape, offset, values)
    return BodyCellVolumes(grid=grid, origin=origin, shape=shape, offset=offset, values=values)


def body_cell_volumes(grid: FluidGrid, nodes, tets, tet_start) -> BodyCellVolumes:
    """Exact volumes of tetrahedral bodies in the cells of ``grid``, by clipping every tetrahedron.

    ``nodes`` (n, 3): world positions (m) of all bodies' nodes; ``tets`` (m, 4): node indices of
    all tetrahedra; ``tet_start`` (bodies + 1,): body b owns tets[tet_start[b]:tet_start[b + 1]].
    """
    nodes, tets, tet_start = _checked_cells(nodes, tets, tet_start, 4, "tets")
    return _fill(grid, tet_cell_volumes.fill_blocks, nodes, tets, tet_start)


def surface_cell_volumes(grid: FluidGrid, nodes, triangles, triangle_start) -> BodyCellVolumes:
    """Exact volumes of closed bodies in the cells of ``grid`` from their boundary triangles
    (outward by the right-hand rule): the same as :func:`body_cell_volumes` of any
    tetrahedralisation of the same bodies, to round-off.

    ``nodes`` (n, 3): world positions (m); ``triangles`` (m, 3): node indices of all bodies'
    boundary triangles; ``triangle_start`` (bodies + 1,): body b owns
    triangles[triangle_start[b]:triangle_start[b + 1]].
    """
    nodes, triangles, triangle_start = _checked_cells(nodes, triangles, triangle_start, 3,
                                                      "triangles")
    return _fill(grid, surface_kernels.fill_blocks, nodes, triangles, triangle_start)


def rigid_body_cell_volumes(grid: FluidGrid, solver, bodies=None, poses=None) -> BodyCellVolumes:
    """The cell volumes of the bodies of a :class:`riprap.solid.solver.SolidSolver` at their
    present position and orientation (:func:`surface_cell_volumes` of their boundary triangles):
    all of them, or those listed in ``bodies`` (the result's blocks are then in that order).
    ``poses`` (one row per chosen body: position (3), unit quaternion (4)) clips them there
    instead of at their present poses."""
    solver.finalize()
    table = solver.table
    node_parts, triangle_parts, triangle_start = [], [], [0]
    node_count = 0
    chosen = range(solver.n_bodies) if bodies is None else [int(b) for b in bodies]
    if poses is None:
        poses = np.concatenate([solver.positions, solver.quaternions], axis=1)[list(chosen)]
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 7)
    for place, body in enumerate(chosen):
        s = solver.shape_index[body]
        local = table.nodes[table.node_offset[s]:table.node_offset[s + 1]]
        node_parts.append(local @ rotation_matrix(poses[place, 3:]).T + poses[place, :3])
        triangle_parts.append(table.triangles[table.triangle_offset[s]:table.triangle_offset[s + 1]]
                              + node_count)
        node_count += len(local)
        triangle_start.append(triangle_start[-1] + len(triangle_parts[-1]))
    if not node_parts:
        empty = np.zeros((0, 3), dtype=np.int64)
        return BodyCellVolumes(grid=grid, origin=empty, shape=empty.copy(),
                               offset=np.zeros(1, dtype=np.int64), values=np.zeros(0))
    return surface_cell_volumes(grid, np.concatenate(node_parts), np.concatenate(triangle_parts),
                                np.array(triangle_start))


def rigid_body_half_cell_volumes(grid: FluidGrid, solver, bodies=None, poses=None) -> list:
    """:func:`half_cell_volumes` of the bodies of a :class:`riprap.solid.solver.SolidSolver`
    (all, or those in ``bodies``, at their present poses or at ``poses``)."""
    fine_grid = _half_grid(grid)
    return _halved(rigid_body_cell_volumes(fine_grid, solver, bodies=bodies, poses=poses))


def half_cell_volumes(grid: FluidGrid, nodes, triangles, triangle_start) -> list:
    """Per body (origin (3,), cell volumes (bi, bj, bk), half-cell volumes (bi, bj, bk, 3, 2)):
    :func:`surface_cell_volumes` on the grid of half the cell size, summed to the cells and to
    each cell's lower and upper half along every axis. A face of the staggered grid owns the
    upper half of the cell below it and the lower half of the cell above it, so these give the
    exact solid fraction of every face's control volume (``rigid_coupling.touched_faces``), one
    cell wide, where the mean of the two cells' fractions would smear the body over two."""
    return _halved(surface_cell_volumes(_half_grid(grid), nodes, triangles, triangle_start))


def _half_grid(grid: FluidGrid) -> FluidGrid:
    return FluidGrid(lower=grid.lower, upper=grid.upper, cells=tuple(2 * int(n) for n in grid.cells))


def _halved(fine: BodyCellVolumes) -> list:
    blocks = []
    for body in range(fine.n_bodies):
        fine_origin, volumes = fine.block(body)
        origin = fine_origin // 2
        shape = (fine_origin + np.asarray(volumes.shape) + 1) // 2 - origin
        if volumes.size == 0:
            shape = np.zeros(3, dtype=np.int64)
        cells = np.zeros(tuple(int(n) for n in shape))
        halves = np.zeros(cells.shape + (3, 2))
        surface_kernels.halve_block(fine_origin, volumes, origin, cells, halves)
        blocks.append((origin, cells, halves))
    return blocks


def merge_blocks(grid: FluidGrid, parts) -> BodyCellVolumes:
    """One :class:`BodyCellVolumes` from per-body (origin, volumes) or (origin, volumes, halves)
    blocks, in order (halves kept when every part has them)."""
    origin = np.array([p[0] for p in parts], dtype=np.int64).reshape(-1, 3)
    shape = np.array([p[1].shape for p in parts], dtype=np.int64).reshape(-1, 3)
    sizes = [p[1].size for p in parts]
    offset = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    values = (np.concatenate([p[1].reshape(-1) for p in parts]) if parts else np.zeros(0))
    halves = None
    if parts and all(len(p) > 2 for p in parts):
        halves = np.concatenate([p[2].reshape(-1) for p in parts])
    return BodyCellVolumes(grid=grid, origin=origin, shape=shape, offset=offset, values=values,
                           halves=halves)
