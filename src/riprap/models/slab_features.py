"""The parts of a fluid that live on its grid, given to one process's block
(``riprap/fluid/slab_solver.py``): porous zones, wave-making and absorbing zones, the boundary
wave maker and the gauges.

The porous zones and the relaxation zones are built on the block's own coordinates, which are
the whole grid's to the bit (``FluidGrid.block``), so their cells are the one process's; only the
block's two end x-faces differ (walls of the block, inside its halo). The boundary wave maker is
the first block's; each gauge is located on the whole grid and read by the block that holds it.
"""
from __future__ import annotations

import copy

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.gauges import OVERTOPPING, RUN_UP, SURFACE, GaugeSet

__all__ = ["BlockGauges", "add_parts_to_block"]


def add_parts_to_block(block, whole) -> None:
    """Give ``block`` (a ``SlabFluidSolver``) ``whole``'s porous zones, waves and gauges, cut to
    its planes."""
    begin, stop = block.first - block.low, block.stop + block.high
    if whole.porous is not None:
        # built on the block's coordinates, which are the whole grid's (FluidGrid.block)
        block.add_porous_zones(whole.porous.zones)
    if whole.relaxation is not None:
        block.relaxation = copy.copy(whole.relaxation)
        block.relaxation._cache = None
        block.relaxation._prepare(block)
    if whole.wave_maker is not None and block.comm.rank == 0:
        whole.wave_maker.attach(block)          # the x-low boundary is the first slab's
    if whole.gauges is not None:
        block.gauges = BlockGauges(whole.gauges, whole.grid, block.comm, block.cut, begin,
                                   block.stop, block.halo)


def _x_planes(gauge, place) -> list[int]:
    """The x-planes (cells, or faces for velocity components on x) a gauge reads."""
    if gauge.kind == SURFACE:
        return [place[0]]
    if gauge.kind == OVERTOPPING:
        return [place[0] - 1, place[0]]
    if gauge.kind == RUN_UP:
        return list(range(place[0], place[1] + 1))
    return [stencil[0][0] + step for stencil in place for step in (0, 1)]


def _shifted(gauge, place, offset: int):
    if gauge.kind == SURFACE:
        return (place[0] - offset, place[1])
    if gauge.kind == OVERTOPPING:
        return (place[0] - offset, place[1])
    if gauge.kind == RUN_UP:
        return (place[0] - offset, place[1] - offset, place[2])
    return [[(stencil[0][0] - offset, stencil[0][1]), stencil[1], stencil[2]] for stencil in place]


class BlockGauges:
    """The gauges of a split run. Each gauge is read by the process whose slab holds the plane
    it stands on (its block must hold every plane it reads, else the split is refused, naming
    the gauge); after every step the readings are joined on every process into ``whole``
    (the whole grid's GaugeSet, which the writers and the checkpoint read)."""

    def __init__(self, whole_gauges: GaugeSet, whole_grid, comm, cut, begin: int, stop: int,
                 halo: int):
        self.whole = whole_gauges
        self.comm = comm
        if whole_gauges._where is None:
            whole_gauges.locate_on(whole_grid)
        where, h, bottom = whole_gauges._where
        mine, places, self.owner = [], [], []
        for gauge, place in zip(whole_gauges.gauges, where):
            planes = _x_planes(gauge, place)
            owner = cut.owner_of_plane(planes[0])
            first = cut.first(owner) - (halo if owner > 0 else 0)
            last = cut.stop(owner) + (halo if owner < comm.size - 1 else 0)
            if min(planes) < max(first, 0) or max(planes) >= last + 1:
                raise CaseFileError(
                    f"gauge {gauge.name!r} reads x-planes {min(planes)} .. {max(planes)}, more "
                    f"than one process's slab and its halo ({first} .. {last - 1}) hold: run on "
                    "fewer processes, or shorten the run-up gauge's reach (to_x)")
            self.owner.append(owner)
            if owner == comm.rank:
                mine.append(gauge)
                places.append(_shifted(gauge, place, begin))
        self.local = GaugeSet(mine, whole_gauges.still_water_level)
        self.local._where = (places, h, bottom)
        self._mine = [k for k, owner in enumerate(self.owner) if owner == comm.rank]

    def record(self, fluid) -> None:
        self.local.record(fluid)
        row = self.local.values[-1] if self.local.count else np.zeros(0)
        rows = self.comm.all_values(row)
        whole = self.whole
        values = np.empty(len(whole.columns))
        offsets = np.cumsum([0] + [len(g.columns) for g in whole.gauges])
        taken = [0] * self.comm.size
        for k, owner in enumerate(self.owner):
            width = offsets[k + 1] - offsets[k]
            values[offsets[k]:offsets[k + 1]] = rows[owner][taken[owner]:taken[owner] + width]
            taken[owner] += width
        whole._grow(whole.count + 1)
        whole._times[whole.count] = fluid.time
        whole._values[whole.count] = values
        whole.count += 1

    def record_arrays(self) -> dict:
        return self.whole.record_arrays()

    def load_record_arrays(self, arrays: dict) -> None:
        self.whole.load_record_arrays(arrays)
        columns = [c for k in self._mine for c in self.whole.gauges[k].columns]
        indices = [self.whole.columns.index(c) for c in columns]
        self.local.load_record_arrays({"gauge_times": self.whole.times,
                                       "gauge_values": self.whole.values[:, indices]}
                                      if "gauge_values" in arrays else {})
