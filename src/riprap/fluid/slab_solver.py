"""The fluid of one run split over processes: each process steps a slab of x-planes, giving what
one process's ``FluidSolver`` gives, bit for bit.

How (deep halos): each process holds its slab and ``halo`` planes of each neighbour's slab on
either side (a *block*), and runs the one-process solver's own step on the whole block. Every
kernel of the step but the pressure solve reads only cells a few planes away, so after the step
the slab's own cells are exactly what one process computes, and only the halo planes (which the
block's false ends spoil a few planes deep) are wrong; they are copied again from the neighbours
after every step (``exchange_halos``). The pressure solve is the one global step: it runs over the
slabs of all processes together (``riprap/fluid/slab_pressure.py``). The largest speed, the water
volume and the water let in are reduced over the processes in the one process's order.

Why deep halos rather than an exchange inside every kernel: the step's dozen kernels (three PLIC
sweeps, momentum, surface tension's height functions, porous friction, the sharp densities) stay
exactly the one-process code, so nothing of the physics is written twice and the split cannot
drift from it; the price is the step's work on 2 x ``halo`` extra planes per process (measured in
``docs/parallel.md``).

``HALO_PLANES``: how far one step's kernels reach along x before the pressure (measured by
``tests/parallel``: the results differ from one process's with fewer planes).
"""
from __future__ import annotations

import numpy as np

from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid.kernels.plane_sums import plane_sums
from riprap.fluid.pressure_window import PressureWindow, fits
from riprap.fluid.slab_pressure import DISTRIBUTED_LEVELS, SlabPressureSolver
from riprap.fluid.solver import FluidSolver, boundary_inflow_planes
from riprap.parallel.slabs import cut_slabs

__all__ = ["SlabFluidSolver", "split_fluid", "HALO_PLANES", "PLANE_ARRAYS"]

#: Planes of each neighbour's slab a block holds on either side.
HALO_PLANES = 8

# The arrays of the state, and whether each lives on the cells or on the faces of an axis.
_STATE = (("fraction", None), ("u", 0), ("v", None), ("w", None), ("pressure", None))
#: The arrays of a checkpoint whose first axis is the grid's x-planes (written in pieces).
PLANE_ARRAYS = tuple(name for name, _ in _STATE) + ("solid",)


class _BlockPressure:
    """The pressure solve of a block: its slab's cells with one ghost plane each side, solved
    over all the processes (``SlabPressureSolver``), the block's other planes kept. Given a
    ``window`` (``riprap/fluid/pressure_window.py``), the solve runs on the pressure's own slabs
    and the planes between the two cuts move before and after it."""

    def __init__(self, slab_solver: SlabPressureSolver, low: int, owned: int, high: int,
                 window: PressureWindow | None = None):
        self.slab = slab_solver
        ghost_low = 1 if low else 0
        ghost_high = 1 if high else 0
        self.first = low - ghost_low                      # block plane of the window's plane 0
        self.cells = slice(self.first, low + owned + ghost_high)
        self.faces = slice(self.first, low + owned + ghost_high + 1)
        self.low, self.owned = low, owned
        self.tolerance = slab_solver.tolerance
        self.window = window

    def solve(self, beta_x, beta_y, beta_z, rhs, p_initial=None, listed_cells=None,
              time_step=None):
        if self.window is not None:
            return self._solve_in_window(beta_x, beta_y, beta_z, rhs, p_initial, listed_cells,
                                         time_step)
        cells = self.cells
        listed = None
        if listed_cells is not None:
            listed = self._window_cells(np.asarray(listed_cells, dtype=np.int64), rhs.shape)
        window, report = self.slab.solve(beta_x[self.faces], beta_y[cells], beta_z[cells],
                                         rhs[cells],
                                         p_initial=None if p_initial is None else p_initial[cells],
                                         listed_cells=listed, time_step=time_step)
        pressure = np.zeros(rhs.shape) if p_initial is None else np.array(p_initial, copy=True)
        pressure[cells] = window
        return pressure, report

    def _window_cells(self, listed, shape):
        """Block flat indices of the slab's own cells, as flat indices of the window."""
        i, j, k = np.unravel_index(listed, shape)
        own = (i >= self.low) & (i < self.low + self.owned)
        window_shape = (self.cells.stop - self.cells.start,) + tuple(shape[1:])
        return np.ravel_multi_index((i[own] - self.first, j[own], k[own]), window_shape)

    def _solve_in_window(self, beta_x, beta_y, beta_z, rhs, p_initial, listed_cells, time_step):
        move = self.window
        listed = (None if listed_cells is None
                  else move.listed(np.asarray(listed_cells, dtype=np.int64), rhs.shape))
        guess = np.zeros(rhs.shape) if p_initial is None else p_initial
        solved, report = self.slab.solve(
            move.window(beta_x, faces=True), move.window(beta_y), move.window(beta_z),
            move.window(rhs), p_initial=None if p_initial is None else move.window(guess),
            listed_cells=listed, time_step=time_step)
        pressure = np.array(guess, copy=True)
        move.to_block(solved, pressure)
        return pressure, report

class SlabFluidSolver(FluidSolver):
    """A ``FluidSolver`` on one process's block of a grid split over processes (module docstring).

    Made by ``split_fluid``; ``whole_cells`` is the whole grid's (nx, ny, nz), ``first`` .. ``stop``
    the slab's x-planes, ``low`` and ``high`` the halo planes below and above it in the block.
    """

    def _new_pressure_solver(self, shape, cell_size, tolerance, volume_tolerance):
        return None          # set by split_fluid: the block's slab of the split solve

    # ------------------------------------------------------------------ reductions
    def _pore_speed(self) -> float:
        # The block's ends see one cell beside their faces and read a speed no larger than the
        # one process's there, so the largest over the blocks is the one process's.
        return self.comm.max(super()._pore_speed())

    def water_volume(self) -> float:
        planes = self.water_volume_planes()[self.low:self.low + self.owned]
        return float(self.comm.ordered_sum(planes, self.cut.counts())) * self.h ** 3

    def _boundary_inflow(self, fluxes) -> float:
        # the x-low face is the first slab's, the x-high face the last's; the sides' per plane
        comm, flux_x = self.comm, fluxes[0]
        mine = (float(plane_sums(flux_x[:1])[0]) if comm.rank == 0 else 0.0,
                float(plane_sums(flux_x[-1:])[0]) if comm.rank == comm.size - 1 else 0.0)
        every = comm.all_values(mine)
        ends = every[0][0] - every[-1][1]
        _, sides = boundary_inflow_planes(fluxes)
        return ends + float(comm.ordered_sum(sides[self.low:self.low + self.owned],
                                             self.cut.counts()))

    # ------------------------------------------------------------------ the step
    def finish_step(self, u, v, w, pressure, report, dt: float, courant: float):
        result = super().finish_step(u, v, w, pressure, report, dt, courant)
        self.exchange_halos()
        return result

    def exchange_halos(self) -> None:
        """The halo planes of the state from the neighbours' slabs."""
        for name, axis in _STATE:
            self.exchange_planes(getattr(self, name), on_x_faces=axis == 0)

    def exchange_planes(self, array: np.ndarray, *, on_x_faces: bool = False) -> None:
        """The halo planes of a block array (of the cells, or of the faces of x) from the
        neighbours' slabs, in place. The x-face between two slabs is each side's own and not
        sent (both compute it alike)."""
        low, owned, high = self.low, self.owned, self.high
        faces = 1 if on_x_faces else 0
        self.comm.exchange(array, slice(low + faces, low + faces + low),
                           slice(0, low), slice(low + owned - high, low + owned),
                           slice(low + owned + faces, low + owned + faces + high))

    def _grid_index(self, index) -> list:
        return [int(index[0]) + self.first - self.low] + [int(i) for i in index[1:]]

    def _check_finite(self) -> None:
        message = ""
        try:
            super()._check_finite()
        except InstabilityError as error:
            message = f"{error} ({self.comm.name})"
        messages = [text for text in self.comm.all_values(message) if text]
        if messages:
            raise InstabilityError(messages[0])

    # ------------------------------------------------------------------ the whole grid's state
    def owned_state(self, state: dict) -> dict:
        """The slab's own planes of a block state (``state_arrays``); faces of x: the slab's
        lower faces, and the last slab its top face too."""
        low, owned = self.low, self.owned
        last = self.comm.rank == self.comm.size - 1
        out = {}
        for name, axis in _STATE + (("solid", None),):
            array = state[name]
            stop = low + owned + (1 if (axis == 0 and last) else 0)
            out[name] = np.ascontiguousarray(array[low:stop])
        return out

    def state_piece(self, state: dict) -> dict:
        """This process's piece of a checkpoint of ``state``: its own planes of the grid (the
        pieces of all processes joined in order are ``gather_whole``'s arrays)."""
        return self.owned_state(state)

    def gather_whole(self, state: dict, *, on_first: bool = False) -> dict | None:
        """The whole grid's arrays of ``state`` (a block's ``state_arrays``) on every process
        (``on_first``: on process 0 only, None on the others): the slabs' own planes joined in
        order. What is not a grid array (the clock, gauges) is every process's own copy, the
        same on all."""
        counts = self.cut.counts()
        face_counts = list(counts)
        face_counts[-1] += 1
        own = self.owned_state(state)
        gather = self.comm.gather_planes_on_first if on_first else self.comm.gather_planes
        whole = dict(state)
        for name, axis in _STATE + (("solid", None),):
            values = own[name].astype(np.float64)
            gathered = gather(values, face_counts if axis == 0 else counts)
            if gathered is not None:    # (every process joins every gather)
                whole[name] = gathered.astype(bool) if name == "solid" else gathered
        return whole if not on_first or self.comm.rank == 0 else None

    def checkpoint_planes(self) -> tuple[int, int]:
        """The whole grid's x-planes this block reads from a checkpoint: its slab and halos, and
        the x-face above them."""
        return self.first - self.low, self.stop + self.high + 1

    def block_of(self, whole: dict) -> dict:
        """A block state from a whole grid's (a checkpoint of a run on any number of
        processes)."""
        block = dict(whole)
        begin = self.first - self.low
        for name, axis in _STATE + (("solid", None),):
            stop = self.stop + self.high + (1 if axis == 0 else 0)
            block[name] = np.ascontiguousarray(whole[name][begin:stop])
        return block

    def load_state_arrays(self, arrays: dict) -> None:
        """A block state, or a whole grid's (then cut to this block)."""
        if arrays["fraction"].shape[0] == self.whole_cells[0] and \
                self.whole_cells[0] != self.fraction.shape[0]:
            arrays = self.block_of(arrays)
        super().load_state_arrays(arrays)


def split_fluid(whole: FluidSolver, comm, *, halo: int = HALO_PLANES, plane_costs=None,
                add_parts=None) -> SlabFluidSolver:
    """This process's block of ``whole`` (built the same on every process), cut into slabs of
    x-planes balancing ``plane_costs``. The block's arrays are copies of ``whole``'s; its ends
    inside the grid are walls that only the halo sees. ``add_parts(block, whole)`` gives the
    block whole's porous zones, waves and gauges (``riprap/models/slab_features.py``); without
    it a fluid that has any is refused."""
    unsupported = [name for name, present in (
        ("porous zones", whole.porous is not None), ("waves", whole.wave_source is not None),
        ("gauges", whole.gauges is not None)) if present]
    if unsupported and add_parts is None:
        raise CaseFileError(f"a fluid with {', '.join(unsupported)} cannot yet run over several "
                            "processes; run it on one (without mpiexec)")
    nx, ny, nz = whole.grid.cells
    alignment = 2 ** DISTRIBUTED_LEVELS
    cut = cut_slabs(nx, comm.size, alignment=alignment, thinnest=max(halo, alignment),
                    plane_costs=plane_costs)
    rank = comm.rank
    first, stop = cut.first(rank), cut.stop(rank)
    low = halo if rank > 0 else 0
    high = halo if rank < comm.size - 1 else 0
    h = whole.h
    boundaries = dict(whole.grid.boundaries)
    if low:
        boundaries["x_low"] = "free_slip"
    if high:
        boundaries["x_high"] = "free_slip"
    # the block's coordinates are the whole grid's to the bit (FluidGrid.block)
    grid = whole.grid.block(first - low, stop + high, boundaries=boundaries)
    block = SlabFluidSolver(
        grid, water=whole.water, air=whole.air, gravity=whole.gravity,
        courant_number=whole.courant_number, pressure_tolerance=whole.pressure_solver.tolerance,
        pressure_volume_tolerance=whole.pressure_solver.volume_tolerance,
        max_time_step=whole.max_time_step, surface_tension=whole.surface_tension,
        limit_air_speed=whole.limit_air_speed)
    block.comm, block.cut, block.halo = comm, cut, halo
    block.whole_cells = (nx, ny, nz)
    block.first, block.stop, block.low, block.high = first, stop, low, high
    block.owned = stop - first
    # the pressure on slabs of equal planes where the fluid's are not (bodies' work weighed in)
    # and the planes between the cuts can move between neighbours (pressure_window.py)
    pressure_cut = cut_slabs(nx, comm.size, alignment=cut.alignment,
                             thinnest=max(halo, cut.alignment))
    window = None
    if pressure_cut.starts != cut.starts and fits(cut, pressure_cut):
        window = PressureWindow(cut, pressure_cut, comm, low)
    else:
        pressure_cut = cut
    slab = SlabPressureSolver((nx, ny, nz), h, pressure_cut, comm,
                              tolerance=whole.pressure_solver.tolerance,
                              max_iterations=whole.pressure_solver.max_iterations,
                              volume_tolerance=whole.pressure_solver.volume_tolerance,
                              periodic_y=whole.grid.periodic_y)
    block.pressure_solver = _BlockPressure(slab, low, stop - first, high, window)
    block.pressure_cut = pressure_cut
    block.obstacle_boxes = list(whole.obstacle_boxes)
    if add_parts is not None:
        add_parts(block, whole)
    # whole's own arrays, not copies: the block copies its planes only, and the whole grid's
    # arrays never written (zeros) then take no memory on any process
    block.load_state_arrays(block.block_of(whole.state_arrays(copy=False)))
    block.water_added = whole.water_added
    block.initial_water_volume = whole.initial_water_volume
    return block
