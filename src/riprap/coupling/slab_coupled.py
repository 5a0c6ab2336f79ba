"""Bodies in a flow split over processes: the coupling (``riprap/coupling/coupled.py``) on one
process's block of the fluid (``riprap/fluid/slab_solver.py``).

How: every process holds every body and integrates it alike (the contact sub-steps are split by
the bodies' places, ``riprap/solid/bodies_over_processes.py``, with every body's forces joined,
and take the same loads on every process, so the bodies stay the same to the bit everywhere).
Each process clips the bodies that reach its block against the *whole* grid and cuts the blocks
of cells to its own planes, so every cell's solid volume is the one process's number, bit for
bit; its face set is then the one process's, cut to the block. The per-face work (the blends,
the mixture densities, the scatter into the velocity) runs on the whole block, so the x-face
between two slabs, which both compute, takes the same value on both. Each body's sums (its 6 x 6
momentum system, the loads) count only the faces the process owns (the x-face between two slabs
once: the upper slab's) and are added over the processes in rank order (``sum_arrays``), so that
every process solves the same system and moves the bodies alike.

What is not bit for bit: a body's sums run over its faces in a different order than one process
adds them (each slab's part, then the parts), so its motion differs from one process's in the
last bits (about 1e-16 relative per step); the fluid, which every other step gives bit for bit,
then follows those bits. ``tests/parallel`` states the tolerance of each comparison.

The field that carries the water beside the bodies (the last projection's, ``_carried``) is
exchanged like the state's halos after every step: a block's halo faces are then its
neighbour's, as one process has them.
"""
from __future__ import annotations

import numpy as np

from riprap.coupling.coupled import CoupledSolver
from riprap.coupling.deformable_coupled import DeformableCoupledSolver
from riprap.coupling.kernels import rigid_coupling

__all__ = ["SlabCoupledSolver", "SlabDeformableCoupledSolver", "coupled_plane_costs",
           "BODY_CELL_COST"]

#: The coupling's work on a cell holding some body (clipping, the face set, the blends and sums)
#: beyond the fluid's own, in units of a fluid cell's whole step (the pressure solve included).
#: Measured (2026-11-28, bench/parallel.py's placed layer, one process): 0.15 s a step for
#: 137,000 such cells against 0.79 s of fluid for 907,000 cells, 1.1 against 0.87 us a cell.
BODY_CELL_COST = 1.2


def coupled_plane_costs(whole: CoupledSolver) -> np.ndarray:
    """The work of each x-plane of ``whole``'s grid for ``cut_slabs``: its cells, and its cells
    that hold bodies once more by ``BODY_CELL_COST`` (the contact pairs, which have their own cut,
    ``riprap/solid/bodies_over_processes.py``, do not enter)."""
    nx, ny, nz = (int(n) for n in whole.fluid.grid.cells)
    return ny * nz + BODY_CELL_COST * whole.body_cells_per_x_plane()


class SlabCoupledSolver(CoupledSolver):
    """A ``CoupledSolver`` of one process's block.

    Parameters
    ----------
    block : SlabFluidSolver
        This process's block, split (``split_fluid``) from ``whole``'s fluid after ``whole`` was
        built, so that it holds the fixed bodies' deep cells as obstacle cells.
    whole : CoupledSolver
        The coupling of the whole grid, built the same on every process: its bodies (which this
        solver steps), its walls, its checks and its closed cells are this solver's; it is not
        stepped (the outputs read the bodies' solid fraction from it).
    """

    def __init__(self, block, whole: CoupledSolver):
        self.whole = whole
        self.comm = block.comm
        #: The block's planes in the whole grid: begin .. end - 1.
        self._begin = block.first - block.low
        self._end = block.stop + block.high
        self._last = block.comm.rank == block.comm.size - 1
        self._summed = None
        self._start_coupling(block, whole)
        self.substep_ceiling = whole.substep_ceiling
        # rigid bodies split by the place of their centre for their contacts (deformable ones
        # are stepped whole on every process)
        if hasattr(self.solids, "split_bodies_over"):
            self.solids.split_bodies_over(self.comm)

    def _start_coupling(self, block, whole) -> None:
        CoupledSolver.__init__(self, block, whole.solids, solid_time_step=whole.solid_time_step,
                               wall_material=None, check_momentum=whole.check_momentum,
                               obstacle_bodies=whole.obstacle_bodies,
                               adaptive_substep=whole.adaptive_substep,
                               cut_faces=whole.cut_faces)

    # ------------------------------------------------------------------ set up from the whole
    def _check_bodies_in_grid(self) -> None:
        """The whole coupling checked the bodies against the whole box."""

    def _close_fixed_interiors(self) -> None:
        """The whole coupling closed the fixed bodies' deep cells (the block holds them as its
        obstacle cells); of the faces that close them, this block's own."""
        shut = self.whole._shut
        if shut is None:
            return
        body, axis, index, weight = shut
        local = index.copy()
        local[:, 0] -= self._begin
        mine = self._owned(axis, local[:, 0])
        self._shut = (body[mine], axis[mine], local[mine], weight[mine])

    def _owned(self, axis, i) -> np.ndarray:
        """Whether faces of ``axis`` at block plane ``i`` are this process's: the faces of its own
        cells, the x-face between two slabs the upper slab's, the grid's last x-face the last
        slab's."""
        block = self.fluid
        top = block.low + block.owned + ((np.asarray(axis) == 0) & self._last)
        return (i >= block.low) & (i < top)

    def _clip(self, stale) -> list:
        """The ``stale`` bodies' half-cell volume blocks on the whole grid (the one process's
        numbers), cut to the block's planes; a body that cannot reach the block gets an empty
        block and is not clipped."""
        stale = np.asarray(stale, dtype=np.int64)
        near = self._reaching(stale)
        blocks = [_EMPTY] * len(stale)
        if near.any():
            clipped = self._clip_on(self.whole.fluid.grid, stale[near])
            for place, block in zip(np.flatnonzero(near), clipped):
                blocks[place] = self._cut(block)
        return blocks

    def _reaching(self, stale) -> np.ndarray:
        """Whether each of the ``stale`` bodies may reach the block where it was last clipped
        (its centre within its bounding radius and a cell of the block's planes)."""
        whole_grid, h = self.whole.fluid.grid, self.fluid.h
        poses = self._block_poses[stale]
        radius = self.solids.bounding_radius[self.solids.shape_index[stale]] + h
        x0 = whole_grid.lower[0] + self._begin * h
        x1 = whole_grid.lower[0] + self._end * h
        return (poses[:, 0] + radius > x0) & (poses[:, 0] - radius < x1)

    def _cut(self, block):
        """A whole-grid block (origin, cell volumes, half-cell volumes) cut to this block's
        planes, its origin in the block's indices."""
        (i, j, k), cells, halves = block
        low, high = max(int(i), self._begin), min(int(i) + cells.shape[0], self._end)
        if high <= low:
            return _EMPTY
        return (np.array([low - self._begin, j, k], dtype=np.int64),
                cells[low - i:high - i], halves[low - i:high - i])

    # ------------------------------------------------------------------ sums over processes
    def _summed_entries(self, faces):
        if self._summed is None or self._summed[0] is not faces:
            mask = self._owned(faces.axis, faces.index[:, 0])
            entry_start, entry_face, entry_half = faces.entries
            keep = mask[entry_face]
            counted = np.concatenate([[0], np.cumsum(keep)]).astype(np.int64)
            entries = (counted[entry_start], entry_face[keep], entry_half[keep])
            self._summed = (faces, mask, entries)
        return self._summed

    def _summed_faces(self, faces) -> rigid_coupling.BodyFaces:
        _, _, entries = self._summed_entries(faces)
        return rigid_coupling.BodyFaces(*entries, faces.axis, faces.index, self._lower,
                                        self.fluid.h, self._period)

    def _summed_face_mask(self, faces) -> np.ndarray:
        return self._summed_entries(faces)[1]

    def _bodies_with_faces(self, faces) -> np.ndarray:
        counts = np.diff(self._summed_entries(faces)[2][0]).astype(np.float64)
        return self._totals(counts)[0] > 0.0

    def _totals(self, *arrays) -> tuple:
        """Each array added over the processes in rank order, in one message."""
        flat = np.concatenate([np.ravel(array) for array in arrays])
        total = self.comm.sum_arrays(flat)
        out, start = [], 0
        for array in arrays:
            out.append(total[start:start + array.size].reshape(array.shape))
            start += array.size
        return tuple(out)

    def _largest(self, value: float) -> float:
        return self.comm.max(value)

    # ------------------------------------------------------------------ the step
    def step(self, dt: float | None = None):
        report = super().step(dt)
        self._exchange_carried()
        return report

    def _exchange_carried(self) -> None:
        """The carrying field's values on the halo faces from the neighbours that own them."""
        axis, index, values = self._carried
        block = self.fluid
        for carried in (values, self._excess[1]):
            fields = (block.u.copy(), block.v.copy(), block.w.copy())
            rigid_coupling.scatter(axis, index, carried, *fields)
            for along, field in enumerate(fields):
                block.exchange_planes(field, on_x_faces=along == 0)
            rigid_coupling.gather(axis, index, *fields, carried)

    # ------------------------------------------------------------------ the whole run's state
    def state_piece(self, state: dict) -> dict:
        """This process's piece of a checkpoint of ``state`` (its ``state_arrays``): its own
        planes of the grid and its own faces of the carrying field in whole-grid indices; the
        pieces of all processes joined in order are one process's arrays (``load_checkpoint``)."""
        piece = self.fluid.owned_state(state)
        if "coupling_carried_axis" in state:
            piece.update(self._carried_piece(state))
        return piece

    def _carried_piece(self, state: dict) -> dict:
        axis = state["coupling_carried_axis"]
        index = state["coupling_carried_index"].copy()
        values = state["coupling_carried_values"]
        mine = self._owned(axis, index[:, 0])
        index[:, 0] += self._begin
        return {"coupling_carried_axis": axis[mine], "coupling_carried_index": index[mine],
                "coupling_carried_values": values[mine],
                "coupling_carried_excess": state["coupling_carried_excess"][mine]}

    def load_state_arrays(self, arrays: dict) -> None:
        """A block's state, or a whole grid's (a checkpoint of a run on any number of
        processes: then cut to this block)."""
        whole_cells = self.fluid.whole_cells
        if arrays["fraction"].shape[0] == whole_cells[0] != self.fluid.fraction.shape[0] \
                and "coupling_carried_axis" in arrays:
            arrays = dict(arrays)
            axis = np.asarray(arrays["coupling_carried_axis"])
            index = np.array(arrays["coupling_carried_index"], dtype=np.int64)
            i = index[:, 0] - self._begin
            planes = self._end - self._begin
            inside = (i >= 0) & (i < planes + (axis == 0))
            index[:, 0] = i
            arrays["coupling_carried_axis"] = axis[inside]
            arrays["coupling_carried_index"] = index[inside]
            arrays["coupling_carried_values"] = np.asarray(arrays["coupling_carried_values"])[inside]
            if "coupling_carried_excess" in arrays:
                arrays["coupling_carried_excess"] = np.asarray(
                    arrays["coupling_carried_excess"])[inside]
        super().load_state_arrays(arrays)
        self._summed = None


class SlabDeformableCoupledSolver(SlabCoupledSolver, DeformableCoupledSolver):
    """Deformable bodies (and rigid ones) in a flow over several processes: every process steps
    every body alike (the deformable bodies' elements are not split), the coupling's face work and
    sums as ``SlabCoupledSolver``; the pressure the bodies' surfaces read is the whole grid's,
    joined from the slabs after every step."""

    def _start_coupling(self, block, whole) -> None:
        DeformableCoupledSolver.__init__(self, block, whole.solids,
                                         check_momentum=whole.check_momentum)

    def _reaching(self, stale) -> np.ndarray:
        return np.ones(len(stale), dtype=bool)

    def _bodies_pressure(self):
        block = self.fluid
        counts = block.cut.counts()
        pressure = self.comm.gather_planes(block.pressure[block.low:block.low + block.owned],
                                           counts)
        whole = self.whole.fluid
        return pressure, np.asarray(whole.grid.lower, dtype=np.float64), whole.solid


#: The block of a body that does not reach this process's planes.
_EMPTY = (np.zeros(3, dtype=np.int64), np.zeros((0, 0, 0)), np.zeros((0, 0, 0, 3, 2)))
