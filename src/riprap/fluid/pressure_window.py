"""The pressure solve of a split fluid on slabs of its own: the planes moved between the fluid's
cut and the pressure's before and after each solve.

Why: with bodies in the flow the fluid's cut gives the slab holding the armour fewer planes (its
cells cost more: the coupling), but the pressure solve, a third to a half of the step, waits at
every dot product for the slowest slab; on slabs of equal planes it waits for none. The solve
gives the same pressure whatever the cut (its sums are per plane, added in plane order), so
only the planes at each cut move: each process sends its neighbour the planes of the right-hand
side, the face coefficients and the first guess that the neighbour's pressure slab holds and its
fluid slab does not, and after the solve the pressures back, a few planes each way.

Planes are global x indices. A process's fluid slab is [first, stop) of the fluid's cut; its
block holds those planes and ``low`` planes below (``riprap/fluid/slab_solver.py``); its window
of the pressure is its pressure slab with one ghost plane on each side that has a neighbour.
Every plane outside the fluid slab comes from the process whose fluid slab holds it, so what
the solve reads is what one process would hand it.
"""
from __future__ import annotations

import numpy as np

__all__ = ["PressureWindow", "fits"]


def fits(fluid_cut, pressure_cut) -> bool:
    """Whether every window of ``pressure_cut`` (slab and ghosts) and every block's planes and
    ghost lie within a process's fluid slab and its two neighbours' (the planes move between
    neighbours only)."""
    size = fluid_cut.processes
    for rank in range(size):
        low_start = fluid_cut.first(rank - 1) if rank > 0 else 0
        high_stop = fluid_cut.stop(rank + 1) if rank < size - 1 else fluid_cut.cells
        window = _window(pressure_cut, rank)
        if window[0] < low_start or window[1] > high_stop:
            return False
        need = (fluid_cut.first(rank) - (rank > 0), fluid_cut.stop(rank) + (rank < size - 1))
        own_low = pressure_cut.first(rank - 1) if rank > 0 else 0
        own_high = pressure_cut.stop(rank + 1) if rank < size - 1 else pressure_cut.cells
        if need[0] < own_low or need[1] > own_high:
            return False
    return True


def _window(cut, rank: int) -> tuple[int, int]:
    """The cells [start, stop) of ``rank``'s pressure slab with its ghost planes."""
    return (cut.first(rank) - (1 if rank > 0 else 0),
            cut.stop(rank) + (1 if rank < cut.processes - 1 else 0))


class PressureWindow:
    """Moves planes between a process's block (the fluid's cut) and its window of the pressure
    (``pressure_cut``), over ``comm`` (``exchange_planes``)."""

    def __init__(self, fluid_cut, pressure_cut, comm, block_low: int):
        self.comm = comm
        rank, size = comm.rank, comm.size
        self.first, self.stop = fluid_cut.first(rank), fluid_cut.stop(rank)
        self.block_start = self.first - block_low        # global plane of the block's plane 0
        self.start, self.end = _window(pressure_cut, rank)
        below = _window(pressure_cut, rank - 1) if rank > 0 else (0, 0)
        above = _window(pressure_cut, rank + 1) if rank < size - 1 else (0, 0)
        # the cells moved in before the solve: from below [start, first), from above
        # [stop, end); sent to the process below [first, its end), above [its start, stop)
        self.cells_in = ((self.start, self.first), (self.stop, self.end))
        self.cells_out = ((self.first, below[1]), (above[0], self.stop))
        # after the solve the block wants its slab and a ghost plane each side: from below
        # [want start, start), from above [end, want stop); the process below wants from here
        # [its window's end, first + 1), the one above [stop - 1, its window's start)
        self.want = (self.first - (1 if rank > 0 else 0),
                     self.stop + (1 if rank < size - 1 else 0))
        self.pressure_in = ((self.want[0], self.start), (self.end, self.want[1]))
        self.pressure_out = ((below[1], self.first + 1) if rank > 0 else (0, 0),
                             (self.stop - 1, above[0]) if rank < size - 1 else (0, 0))

    # ------------------------------------------------------------------ before the solve
    def window(self, array: np.ndarray, faces: bool = False) -> np.ndarray:
        """The window's planes of the block's ``array`` (cells; ``faces``: x-faces, one more
        plane), the planes outside the fluid slab from the neighbours."""
        extra = 1 if faces else 0
        out = np.empty((self.end - self.start + extra,) + array.shape[1:])
        # own planes: cells [first, stop), faces [first, stop] (both ends computed here)
        own = (max(self.first, self.start), min(self.stop + extra, self.end + extra))
        _put(out, self.start, own, _planes(array, self.block_start, own))
        (below_in, above_in), (below_out, above_out) = self.cells_in, self.cells_out
        from_below, from_above = self.comm.swap_planes(
            _planes(array, self.block_start, (below_out[0] + extra, below_out[1] + extra)),
            _planes(array, self.block_start, above_out), _length(below_in), _length(above_in))
        _put(out, self.start, below_in, from_below)
        _put(out, self.start, (above_in[0] + extra, above_in[1] + extra), from_above)
        return out

    def listed(self, listed_block_cells: np.ndarray, block_shape) -> np.ndarray:
        """The listed cells of the whole grid that fall in the window's own planes (its
        pressure slab), as flat indices of the window: each process lists its fluid slab's,
        and all are joined."""
        i, j, k = np.unravel_index(np.asarray(listed_block_cells, dtype=np.int64), block_shape)
        plane = i + self.block_start
        own = (plane >= self.first) & (plane < self.stop)
        mine = np.stack([plane[own], j[own], k[own]], axis=1)
        every = np.concatenate([np.asarray(rows, dtype=np.int64).reshape(-1, 3)
                                for rows in self.comm.all_values(mine)])
        ghost_low = self.start + (1 if self.comm.rank > 0 else 0)
        ghost_high = self.end - (1 if self.comm.rank < self.comm.size - 1 else 0)
        inside = (every[:, 0] >= ghost_low) & (every[:, 0] < ghost_high)
        every = every[inside]
        shape = (self.end - self.start,) + tuple(block_shape[1:])
        return np.ravel_multi_index((every[:, 0] - self.start, every[:, 1], every[:, 2]), shape)

    # ------------------------------------------------------------------ after the solve
    def to_block(self, window_pressure: np.ndarray, block_pressure: np.ndarray) -> None:
        """The solved pressure into the block's slab and its ghost planes, those outside the
        window from the neighbours' windows."""
        mine = (max(self.want[0], self.start), min(self.want[1], self.end))
        _put(block_pressure, self.block_start, mine, _planes(window_pressure, self.start, mine))
        (below_in, above_in), (below_out, above_out) = self.pressure_in, self.pressure_out
        from_below, from_above = self.comm.swap_planes(
            _planes(window_pressure, self.start, below_out),
            _planes(window_pressure, self.start, above_out), _length(below_in),
            _length(above_in))
        _put(block_pressure, self.block_start, below_in, from_below)
        _put(block_pressure, self.block_start, above_in, from_above)


def _planes(array: np.ndarray, origin: int, span) -> np.ndarray:
    """The planes [span) of ``array``, whose plane 0 is global plane ``origin`` (none when the
    span is empty)."""
    lo, hi = span
    if hi <= lo:
        return np.empty((0,) + array.shape[1:])
    return array[lo - origin:hi - origin]


def _put(target: np.ndarray, origin: int, span, planes) -> None:
    """``planes`` into [span) of ``target``, whose plane 0 is global plane ``origin``."""
    lo, hi = span
    if planes is not None and hi > lo:
        target[lo - origin:hi - origin] = planes


def _length(span) -> int:
    return max(0, span[1] - span[0])
