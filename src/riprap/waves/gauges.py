"""Gauges of a numerical flume: surface elevation and velocity at named places, every fluid step.

A surface gauge (a wave gauge of the laboratory) reads the water depth of its cell column: the sum
of the column's water fractions times the cell size, less the still water depth, i.e. the
elevation eta (m) above the still water level, exact for a single-valued surface (a column that
holds a plunging jet's air pocket counts only its water). A velocity gauge reads (u, v, w) at its
point, each component interpolated linearly between the faces that carry it.

An overtopping gauge stands on a plane x = const (the crest's landward edge, where EurOtop
measures q): it reads the water volume that crossed the plane above the crest's surface there in
each step per metre of flume width (the volume-of-fluid step's own face fluxes, so exactly the
water that went over), summed into the overtopped volume per metre V (m^3/m), and that step's mean
discharge q (m^3/s per m). The crest's surface is found in each cell row along y from what the
fluid holds solid or porous in the two cell columns beside the plane (``crest_rows``): the count
starts at the first cell row above the highest cell that is an obstacle or at least half inside a
porous zone, so a tongue one cell thick running over the crest counts, and the flow through a
porous crest under its surface does not (EurOtop's q is the water over the crest; the water that
sinks into a permeable crest is what its crest-width factor takes off). Where the plane has
neither, the count starts at the cell row holding the crest level z of the gauge's ``position``.
Bodies (armour units, a pack's fixed rocks) are no part of that surface: the water between units
above it counts.

A run-up gauge reads, between x = ``position`` x and ``to_x``, the highest level the water reaches
on the slope: in each cell column the top of the water resting on the column's bed (its obstacle
cells, or the box's bottom; cells more than half water counted up from there, plus the part of
the next), the highest over the columns, above the still water level (m). Spray above the tongue
and films thinner than half a cell are not counted; in a porous zone the water in the pores
counts (the surface inside the core).

The records live in the fluid's state (``FluidSolver.state_arrays``): a restart continues them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError

__all__ = ["Gauge", "GaugeSet", "crest_rows", "SURFACE", "VELOCITY", "OVERTOPPING", "RUN_UP",
           "KINDS"]

SURFACE = "surface"
VELOCITY = "velocity"
OVERTOPPING = "overtopping"
RUN_UP = "run_up"
KINDS = (SURFACE, VELOCITY, OVERTOPPING, RUN_UP)


@dataclass(frozen=True)
class Gauge:
    """``kind`` "surface" (eta at x, y of ``position``; its z is not used), "velocity" (u, v, w
    at ``position``), "overtopping" (through the plane x = ``position`` x) or "run_up" (from
    ``position`` x to ``to_x``, in the cell row at ``position`` y), named ``name``."""

    name: str
    kind: str
    position: tuple
    to_x: float | None = None

    @property
    def columns(self) -> list[str]:
        if self.kind == SURFACE:
            return [f"{self.name}_eta_m"]
        if self.kind == OVERTOPPING:
            return [f"{self.name}_q_m3_s_m", f"{self.name}_volume_m3_m"]
        if self.kind == RUN_UP:
            return [f"{self.name}_level_m"]
        return [f"{self.name}_u_m_s", f"{self.name}_v_m_s", f"{self.name}_w_m_s"]


def _index_and_weight(coordinate, first, spacing, count):
    """(i, weight of i + 1) for linear interpolation on points first + i spacing, i < count."""
    s = (coordinate - first) / spacing
    i = int(min(max(math.floor(s), 0), max(count - 2, 0)))
    return i, (min(max(s - i, 0.0), 1.0) if count > 1 else 0.0)


class GaugeSet:
    """The gauges of a flume and their records. ``still_water_level`` (m) is the z from which
    surface gauges measure eta."""

    def __init__(self, gauges, still_water_level: float):
        self.gauges = list(gauges)
        names = [g.name for g in self.gauges]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise CaseFileError(f"gauges: names must differ; repeated: {', '.join(repeated)}")
        for gauge in self.gauges:
            if gauge.kind not in KINDS:
                raise CaseFileError(f"gauge {gauge.name!r}: kind must be one of {', '.join(KINDS)}, "
                                    f"got {gauge.kind!r}")
            if gauge.kind == RUN_UP and not (gauge.to_x is not None and gauge.to_x > gauge.position[0]):
                raise CaseFileError(f"gauge {gauge.name!r}: a run-up gauge reads from x = "
                                    f"{gauge.position[0]} m to to_x, which must be larger; got "
                                    f"{gauge.to_x!r}")
        self.still_water_level = float(still_water_level)
        self.columns = [c for g in self.gauges for c in g.columns]
        # Append-only buffers: the first ``count`` rows never change, so the state handed to the
        # run loop after every step can be views of them (no copy of a growing record per step).
        self.count = 0
        self._times = np.zeros(1024)
        self._values = np.zeros((1024, len(self.columns)))
        self._where = None
        # per overtopping gauge (its index), the first cell row counted in each row along y: set
        # on the first reading, from the fluid read (the crest does not move)
        self._crest_rows = {}

    def check_in_grid(self, grid) -> None:
        """Refuse a gauge outside the fluid box, naming it."""
        lower, upper = np.asarray(grid.lower), np.asarray(grid.upper)
        for gauge in self.gauges:
            p = np.asarray(gauge.position, dtype=float)
            # an overtopping gauge's z is its crest level: inside the box too
            axes = (0, 1, 2) if gauge.kind in (VELOCITY, OVERTOPPING) else (0, 1)
            outside = [a for a in axes if not lower[a] <= p[a] <= upper[a]]
            if gauge.kind == RUN_UP and not gauge.to_x <= upper[0]:
                outside.append(0)
            if outside:
                raise CaseFileError(f"gauge {gauge.name!r} at {list(gauge.position)} m is outside the "
                                    f"fluid box {list(grid.lower)} .. {list(grid.upper)} m")

    def _locate(self, fluid):
        self.locate_on(fluid.grid)

    def locate_on(self, grid):
        """Find each gauge's cells on ``grid`` (the whole grid's, also for a split run's
        gauges, which then read them from the block that holds them: ``BlockGauges``)."""
        h = grid.cell_size
        lower = np.asarray(grid.lower, dtype=float)
        cells = grid.cells
        where = []
        for gauge in self.gauges:
            p = np.asarray(gauge.position, dtype=float)
            column = [int(min(max((p[a] - lower[a]) // h, 0), cells[a] - 1)) for a in range(3)]
            if gauge.kind == SURFACE:
                where.append(column[:2])
                continue
            if gauge.kind == OVERTOPPING:
                # the x face nearest the plane, and the cell row holding the crest level (where the
                # fluid holds no crest at the plane)
                where.append((int(min(max(round((p[0] - lower[0]) / h), 0), cells[0])), column[2]))
                continue
            if gauge.kind == RUN_UP:
                last = int(min(max((gauge.to_x - lower[0]) // h, 0), cells[0] - 1))
                where.append((column[0], last, column[1]))
                continue
            # component a on faces along a (first face at lower[a]), at centres across
            stencils = []
            for a in range(3):
                stencil = []
                for b in range(3):
                    if b == a:
                        stencil.append(_index_and_weight(p[b], lower[b], h, cells[b] + 1))
                    else:
                        stencil.append(_index_and_weight(p[b], lower[b] + 0.5 * h, h, cells[b]))
                stencils.append(stencil)
            where.append(stencils)
        self._where = (where, h, float(lower[2]))
        self._crest_rows = {}

    def read(self, fluid) -> np.ndarray:
        """The gauges' values now, in ``columns`` order."""
        if self._where is None:
            self._locate(fluid)
        where, h, bottom = self._where
        values = []
        for index, (gauge, place) in enumerate(zip(self.gauges, where)):
            if gauge.kind == SURFACE:
                i, j = place
                values.append(bottom + h * float(fluid.fraction[i, j].sum()) - self.still_water_level)
                continue
            if gauge.kind == OVERTOPPING:
                column = self.columns.index(gauge.columns[0])
                rows = self._crest_rows.get(index)
                if rows is None:
                    rows = self._crest_rows[index] = crest_rows(fluid, place[0], place[1])
                crossed = _water_crossed_per_width(fluid, place[0], rows)
                previous = self._values[self.count - 1, column + 1] if self.count else 0.0
                step = fluid.time_step
                values.extend((crossed / step if step > 0 else 0.0, previous + crossed))
                continue
            if gauge.kind == RUN_UP:
                first, last, j = place
                values.append(_highest_contiguous_water(fluid, first, last, j, h, bottom)
                              - self.still_water_level)
                continue
            for array, stencil in zip((fluid.u, fluid.v, fluid.w), place):
                value = 0.0
                (i, wi), (j, wj), (k, wk) = stencil
                for di, fi in ((0, 1.0 - wi), (1, wi)):
                    for dj, fj in ((0, 1.0 - wj), (1, wj)):
                        for dk, fk in ((0, 1.0 - wk), (1, wk)):
                            weight = fi * fj * fk
                            if weight:
                                value += weight * array[min(i + di, array.shape[0] - 1),
                                                        min(j + dj, array.shape[1] - 1),
                                                        min(k + dk, array.shape[2] - 1)]
                values.append(float(value))
        return np.array(values)

    def _grow(self, needed: int) -> None:
        if needed > self._times.size:
            capacity = max(needed, 2 * self._times.size)
            times, values = np.zeros(capacity), np.zeros((capacity, len(self.columns)))
            times[:self.count], values[:self.count] = self._times[:self.count], self._values[:self.count]
            self._times, self._values = times, values

    def record(self, fluid) -> None:
        """Append the gauges' readings at the fluid's present time."""
        self._grow(self.count + 1)
        self._times[self.count] = fluid.time
        self._values[self.count] = self.read(fluid)
        self.count += 1

    @property
    def times(self) -> np.ndarray:
        return self._times[:self.count]

    @property
    def values(self) -> np.ndarray:
        """(records, columns)."""
        return self._values[:self.count]

    def record_arrays(self) -> dict:
        """The records as checkpoint arrays (views: valid until the records are reloaded)."""
        return {"gauge_times": self.times, "gauge_values": self.values}

    def load_record_arrays(self, arrays: dict) -> None:
        values = arrays.get("gauge_values")
        if values is None:
            self.count = 0
            return
        if values.ndim != 2 or values.shape[1] != len(self.columns):
            raise CaseFileError(f"checkpoint: gauge records have {values.shape[-1]} columns, this "
                                f"case's gauges {len(self.columns)}")
        count = values.shape[0]
        times = np.array(arrays["gauge_times"], dtype=float)
        values = np.array(values, dtype=float)
        self.count = 0
        self._grow(count)
        self._times[:count], self._values[:count] = times, values
        self.count = count

    def series(self, column: str) -> tuple[np.ndarray, np.ndarray]:
        """(times, values) of one column."""
        return self.times.copy(), self.values[:, self.columns.index(column)].copy()


def crest_rows(fluid, face: int, fallback_row: int) -> np.ndarray:
    """(ny,) for each cell row along y, the first cell row (k) whose water crossing the x faces of
    index ``face`` is overtopping: the row above the highest cell of the two cell columns beside
    the faces that is an obstacle (``fluid.solid``) or at least half inside the fluid's porous
    zones (their cover, not the porosity, so that a zone's own porosity does not matter), i.e.
    the crest's surface; ``fallback_row`` (the cell row holding the gauge's crest level) where
    the two columns hold neither. Works on a block of a split grid too (``fluid.grid`` a
    ``BlockGrid``): the cover is computed on the whole grid's planes the block holds."""
    nx, ny, nz = fluid.fraction.shape
    first, stop = max(face - 1, 0), min(face + 1, nx)
    crest = np.asarray(fluid.solid[first:stop], dtype=bool).copy()
    porous = getattr(fluid, "porous", None)
    if porous is not None and porous.zones:
        grid = fluid.grid
        whole = grid.whole_grid
        offset = getattr(grid, "first", 0) if grid is not whole else 0
        columns = whole.block(offset + first, offset + stop)
        cover = np.zeros((stop - first, ny, nz))
        for zone in porous.zones:
            part = zone.cover(columns)
            cover = cover * (1.0 - part) + part          # the union of the zones' covers
        crest |= cover >= 0.5
    rows = np.full(ny, int(fallback_row), dtype=np.int64)
    for j in range(ny):
        solid_rows = np.flatnonzero(crest[:, j, :].any(axis=0))
        if solid_rows.size:
            rows[j] = int(solid_rows[-1]) + 1
    return rows


def _water_crossed_per_width(fluid, face: int, rows: np.ndarray) -> float:
    """Water volume per metre of width (m^3/m) that crossed the x faces of index ``face`` in the
    fluid's last step, in each cell row along y from cell row ``rows[j]`` up: the volume-of-fluid
    step's own fluxes, so that it is exactly the water that left one side and reached the other.
    0 before the first step."""
    fluxes = getattr(fluid, "last_water_fluxes", None)
    if fluxes is None or fluid.step_count == 0:
        return 0.0
    width = fluid.h * fluid.fraction.shape[1]
    plane = fluxes[0][face]
    return float(sum(np.sum(plane[j, rows[j]:]) for j in range(plane.shape[0]))) / width


def _highest_contiguous_water(fluid, first: int, last: int, j: int, h: float, bottom: float) -> float:
    """The highest water level (z, m) over columns first..last (row j): in each column the top of
    the water resting on its bed (the obstacle cells at its foot), counted up through the cells
    more than half water and the part of the first one above them; a column whose first cell
    above the bed is not half water is dry (a film thinner than half a cell is not seen). The
    bottom of the box if every column is dry."""
    fractions = fluid.fraction[first:last + 1, j, :]
    solid = fluid.solid[first:last + 1, j, :]
    nz = fractions.shape[1]
    highest = bottom
    for column in range(fractions.shape[0]):
        k = 0
        while k < nz and solid[column, k]:
            k += 1
        start = k
        while k < nz and fractions[column, k] > 0.5 and not solid[column, k]:
            k += 1
        if k == start:
            continue                                   # dry (or solid to the top)
        top = k + (fractions[column, k] if k < nz and not solid[column, k] else 0.0)
        highest = max(highest, bottom + h * top)
    return highest
