"""The fluid grid: a uniform Cartesian grid of cubic cells, staggered (MAC) like Harlow & Welch (1965).

Layout (every fluid array is C-ordered and indexed [i, j, k] for x, y, z; z is up):

- cell centres hold the pressure ``p`` and the water fraction ``f``: shape (nx, ny, nz);
- face centres hold the normal velocity: ``u`` (nx+1, ny, nz) on x-faces (``u[i]`` between cells
  i-1 and i), ``v`` (nx, ny+1, nz), ``w`` (nx, ny, nz+1).

A 2D problem (the x-z plane of a flume) is ``ny == 1``: ``v`` stays zero and nothing moves in y.
Cells are cubes: a domain whose lengths are not whole numbers of one cell size is refused, since
the volume-of-fluid sweeps and the multigrid levels assume equal spacing in every direction.

Boundaries: each side of the box is ``"no_slip"`` or ``"free_slip"`` (a wall, no flow through
it), and the top may be ``"open"`` (the atmosphere: pressure 0 there, air and water may leave or
enter). The two y sides may together be ``"periodic"`` (a strip across the flume that stands for a
wide one: what leaves at y = upper comes in at y = lower). Then face ``ny`` of ``v`` is face 0 again:
both entries are kept and always equal, and cell ``ny - 1`` is the neighbour of cell 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of

__all__ = ["BlockGrid", "FluidGrid", "BOUNDARY_KINDS", "SIDES"]

#: Sides of the box, in the order of the ``boundaries`` mapping.
SIDES = ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high")
#: Kinds of boundary; ``open`` only on ``z_high``, ``periodic`` only on both y sides together.
BOUNDARY_KINDS = ("no_slip", "free_slip", "open", "periodic")
# Cell lengths that differ by less than this (relative) are the same cube side.
_CUBE_TOLERANCE = 1e-9
# Multigrid and the sweeps are fine with any size, but a grid this small has no interior.
_MINIMUM_CELLS = 2


def _default_boundaries() -> dict:
    """Each side's kind when not given: the case file's [fluid] default (riprap.schema)."""
    return {side: default_of("fluid", side) for side in SIDES}


@dataclass(frozen=True)
class FluidGrid:
    """A box ``lower`` .. ``upper`` (m) cut into ``cells`` = (nx, ny, nz) cubic cells.

    ``boundaries``: side -> kind (``SIDES``, ``BOUNDARY_KINDS``); missing sides take the default
    (walls with no slip, open top). ``ny == 1`` is a 2D problem in the x-z plane.
    """

    lower: tuple
    upper: tuple
    cells: tuple
    boundaries: dict = field(default_factory=_default_boundaries)

    def __post_init__(self):
        lower = np.asarray(self.lower, dtype=float).reshape(-1)
        upper = np.asarray(self.upper, dtype=float).reshape(-1)
        cells = np.asarray(self.cells).reshape(-1)
        if lower.size != 3 or upper.size != 3 or not (np.isfinite(lower).all() and np.isfinite(upper).all()):
            raise CaseFileError(f"fluid grid: lower {self.lower!r} and upper {self.upper!r} must be "
                                "3 finite numbers each (m)")
        if cells.size != 3 or cells.dtype.kind not in "iu":
            raise CaseFileError(f"fluid grid: cells = {self.cells!r} must be 3 integers [nx, ny, nz]")
        if np.any(upper <= lower):
            raise CaseFileError(f"fluid grid: upper {upper.tolist()} must exceed lower "
                                f"{lower.tolist()} in every direction")
        if cells[0] < _MINIMUM_CELLS or cells[2] < _MINIMUM_CELLS or cells[1] < 1:
            raise CaseFileError(f"fluid grid: cells = {cells.tolist()}: nx and nz need at least "
                                f"{_MINIMUM_CELLS} cells, ny at least 1 (1 for a 2D flume)")
        sizes = (upper - lower) / cells
        h = sizes[0]
        directions = [0, 2] if cells[1] == 1 else [0, 1, 2]
        if any(abs(sizes[d] - h) > _CUBE_TOLERANCE * h for d in directions):
            suggestion = np.maximum(np.round((upper - lower) / h).astype(int), 1)
            fitted = lower + suggestion * h
            raise CaseFileError(
                f"fluid grid: cells must be cubes, but the box {(upper - lower).tolist()} m in "
                f"{cells.tolist()} cells gives cells of {sizes.tolist()} m; for cells of {h:.6g} m "
                f"use cells = {suggestion.tolist()} and upper = "
                f"[{', '.join(f'{v:.6g}' for v in fitted)}]")
        boundaries = _default_boundaries()
        for side, kind in dict(self.boundaries).items():
            if side not in SIDES:
                raise CaseFileError(f"fluid grid: unknown side '{side}'; sides: {', '.join(SIDES)}")
            if kind not in BOUNDARY_KINDS:
                raise CaseFileError(f"fluid grid: boundary {side} = '{kind}' is not one of "
                                    f"{', '.join(BOUNDARY_KINDS)}")
            if kind == "open" and side != "z_high":
                raise CaseFileError(f"fluid grid: boundary {side} = 'open': only the top (z_high) "
                                    "can be open to the atmosphere")
            if kind == "periodic" and side not in ("y_low", "y_high"):
                raise CaseFileError(f"fluid grid: boundary {side} = 'periodic': only the y sides "
                                    "(across the flume) can be periodic")
            boundaries[side] = kind
        periodic_sides = [side for side in ("y_low", "y_high") if boundaries[side] == "periodic"]
        if len(periodic_sides) == 1:
            raise CaseFileError(f"fluid grid: boundary {periodic_sides[0]} = 'periodic' needs the "
                                "other y side periodic too (what leaves at one comes in at the "
                                "other)")
        if periodic_sides and (cells[1] < 2 or cells[1] % 2):
            raise CaseFileError(
                f"fluid grid: a periodic y needs an even number of cells across (ny = "
                f"{int(cells[1])}): the pressure solve's red-black sweeps meet across the "
                "boundary; a multiple of 4 lets its multigrid coarsen y as well")
        object.__setattr__(self, "lower", tuple(float(v) for v in lower))
        object.__setattr__(self, "upper", tuple(float(v) for v in upper))
        object.__setattr__(self, "cells", tuple(int(v) for v in cells))
        object.__setattr__(self, "boundaries", boundaries)

    @property
    def cell_size(self) -> float:
        """Side of a cubic cell (m)."""
        return (self.upper[0] - self.lower[0]) / self.cells[0]

    @property
    def shape(self) -> tuple:
        return self.cells

    @property
    def two_dimensional(self) -> bool:
        return self.cells[1] == 1

    @property
    def n_cells(self) -> int:
        return self.cells[0] * self.cells[1] * self.cells[2]

    @property
    def cell_volume(self) -> float:
        """Volume of a cell (m^3); in 2D, per the cell's width in y (the box's)."""
        h = self.cell_size
        return h * h * (self.upper[1] - self.lower[1] if self.two_dimensional else h)

    @property
    def periodic_y(self) -> bool:
        """The y sides are one periodic boundary (module docstring)."""
        return self.boundaries["y_low"] == "periodic"

    @property
    def open_top(self) -> bool:
        return self.boundaries["z_high"] == "open"

    @property
    def whole_grid(self) -> FluidGrid:
        """The grid of the whole box: this one (a :class:`BlockGrid` answers its whole's)."""
        return self

    def centres(self, axis: int) -> np.ndarray:
        """Cell-centre coordinates along ``axis`` (m)."""
        n = self.cells[axis]
        step = (self.upper[axis] - self.lower[axis]) / n
        return self.lower[axis] + (np.arange(n) + 0.5) * step

    def faces(self, axis: int) -> np.ndarray:
        """Face coordinates along ``axis`` (m)."""
        n = self.cells[axis]
        return np.linspace(self.lower[axis], self.upper[axis], n + 1)

    def cell_of(self, point) -> tuple:
        """Index (i, j, k) of the cell holding ``point``, or raise naming the point."""
        point = np.asarray(point, dtype=float)
        index = []
        for axis in range(3):
            step = (self.upper[axis] - self.lower[axis]) / self.cells[axis]
            i = math.floor((point[axis] - self.lower[axis]) / step)
            if not 0 <= i < self.cells[axis]:
                raise CaseFileError(f"point {point.tolist()} lies outside the fluid box "
                                    f"{list(self.lower)} .. {list(self.upper)}")
            index.append(i)
        return tuple(index)

    def block(self, first: int, stop: int, *, boundaries: dict | None = None) -> BlockGrid:
        """The x-planes ``first`` .. ``stop`` - 1 of this grid as a grid of their own, whose
        coordinates are this grid's to the bit (:class:`BlockGrid`); ``boundaries`` replaces
        the sides' kinds (a block's ends inside the grid are no walls of the box)."""
        if not (isinstance(first, (int, np.integer)) and isinstance(stop, (int, np.integer))
                and 0 <= first < stop <= self.cells[0]):
            raise CaseFileError(f"fluid grid: a block of x-planes {first!r} .. {stop!r} does not "
                                f"lie within the grid's 0 .. {self.cells[0]}")
        faces = self.faces(0)
        lower = (float(faces[first]),) + self.lower[1:]
        upper = (float(faces[stop]),) + self.upper[1:]
        return BlockGrid(lower=lower, upper=upper, cells=(int(stop - first),) + self.cells[1:],
                         boundaries=dict(self.boundaries if boundaries is None else boundaries),
                         whole=self, first=int(first))


@dataclass(frozen=True)
class BlockGrid(FluidGrid):
    """Some x-planes of a grid (``whole``), from plane ``first`` on (``FluidGrid.block``): a
    grid of their own whose cell size, centres, faces and cells of points are the whole grid's,
    to the bit, so that whatever is built on the block (water, obstacles, porous zones, waves)
    is what the whole grid builds on those planes. Its ``lower`` and ``upper`` along x are the
    whole grid's faces at its ends."""

    whole: FluidGrid | None = None
    first: int = 0

    def __post_init__(self):
        super().__post_init__()
        if not isinstance(self.whole, FluidGrid) or isinstance(self.whole, BlockGrid):
            raise CaseFileError("a block grid needs the whole FluidGrid it is part of")

    @property
    def cell_size(self) -> float:
        return self.whole.cell_size

    @property
    def whole_grid(self) -> FluidGrid:
        return self.whole

    @property
    def stop(self) -> int:
        """The whole grid's x-plane after the block's last."""
        return self.first + self.cells[0]

    def centres(self, axis: int) -> np.ndarray:
        if axis != 0:
            return self.whole.centres(axis)
        return self.whole.centres(0)[self.first:self.stop]

    def faces(self, axis: int) -> np.ndarray:
        if axis != 0:
            return self.whole.faces(axis)
        return self.whole.faces(0)[self.first:self.stop + 1]

    def cell_of(self, point) -> tuple:
        i, j, k = self.whole.cell_of(point)
        if not self.first <= i < self.stop:
            raise CaseFileError(f"point {np.asarray(point, dtype=float).tolist()} lies outside "
                                f"the block {list(self.lower)} .. {list(self.upper)} (x-planes "
                                f"{self.first} .. {self.stop - 1} of the fluid box)")
        return i - self.first, j, k
