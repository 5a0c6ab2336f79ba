"""The pressure solve of a grid cut into slabs along x, one slab per process, giving what one
process's ``PressureSolver`` gives, bit for bit.

The method is the one of ``riprap/fluid/pressure.py`` (MGPCG: conjugate gradients preconditioned by
one multigrid V-cycle with red-black Gauss-Seidel smoothing). Over several processes:

- Each process holds its slab's planes of every distributed level with one ghost plane on each
  side that has a neighbour. Before every sweep of a colour, and before anything that reads a
  neighbour (the residual, the operator, the restriction), the ghost planes are refreshed from the
  neighbours (``Communicator.exchange``): a red cell reads only black ones, so a cell of the slab's
  edge sees the values the one process would have.
- The finest ``distributed_levels`` levels are split; the next level down is gathered whole onto
  every process (its planes joined in rank order, a few ten thousand cells) and solved there by the
  one-process V-cycle of the levels below, the same arithmetic on every process. Why gather: the
  coarse levels carry many sweeps (``multigrid.level_sweeps``) on small planes, where a message per
  sweep costs more than the sweep; every peer that scales (AMReX's MLMG, PETSc's GAMG, hypre)
  agglomerates its coarse levels onto fewer processes for the same reason.
- Dot products and norms are per-plane sums joined in plane order and added one by one
  (``Communicator.ordered_sum``), as the one process adds them: the same iterations, the same
  stopping step, the same pressure.

Slabs start at multiples of 2^distributed_levels planes, so that each distributed level's coarse
cells have their children in one slab (``riprap/parallel/slabs.py``: ``alignment``).
"""
from __future__ import annotations

import math

import numpy as np

from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid.kernels import multigrid
from riprap.fluid.pressure import (LISTED_SWEEPS, SMOOTHING_SWEEPS, PressureSolveReport,
                                   _listed_cells, build_hierarchy, build_levels, cell_view,
                                   face_view, level_shapes, listed_stencils_of,
                                   outcome_report)
from riprap.parallel.kernels.ordered import ordered_largest, ordered_total

__all__ = ["SlabPressureSolver", "DISTRIBUTED_LEVELS"]

#: Levels split over the processes; the next is gathered. Two: level 2 of a million-cell grid is
#: 16,000 cells (128 kB), gathered once per V-cycle, where its 8 sweeps of two colours before and
#: after would cost 32 exchanges.
DISTRIBUTED_LEVELS = 2


class _Level:
    """One distributed level's arrays on this process: its planes with ghost planes."""

    def __init__(self, shape, first, stop, low, high, spacing):
        self.first, self.stop = first, stop                # global planes first..stop-1
        self.low, self.high = low, high                    # ghost planes below and above
        self.owned = stop - first
        self.begin, self.end = low, low + self.owned       # local planes of the slab
        planes = low + self.owned + high
        ny, nz = shape[1], shape[2]
        self.x = np.zeros((planes, ny, nz))
        self.rhs = np.zeros((planes, ny, nz))
        self.beta = [np.zeros((planes + 1, ny, nz)), np.zeros((planes, ny + 1, nz)),
                     np.zeros((planes, ny, nz + 1))]
        self.inverse_h2 = 1.0 / np.asarray(spacing, dtype=float) ** 2
        # the global x index of local plane 0, mod 2: red and black are global colours
        self.parity = (first - low) % 2

    def colour(self, colour: int) -> int:
        """The local colour argument of the sweep kernels for the global ``colour``."""
        return (colour + self.parity) % 2


class SlabPressureSolver:
    """``PressureSolver`` over the processes of ``communicator``, each holding slab ``cut`` of a
    grid of ``shape`` cells.

    ``solve`` takes and returns this process's planes with one ghost plane on each side that has a
    neighbour: ``rhs`` and ``p`` (low + n + high, ny, nz), the face coefficients with one more
    entry along their axis. The ghost planes of ``rhs`` are not read; those of the returned ``p``
    hold the neighbours' pressures (the velocity correction reads them).
    """

    def __init__(self, shape, cell_size, cut, communicator, *, tolerance: float = 1e-8,
                 max_iterations: int = 200, volume_tolerance: float = 0.0,
                 distributed_levels: int = DISTRIBUTED_LEVELS, periodic_y: bool = False):
        self.shape = tuple(int(n) for n in shape)
        #: the y faces 0 and ny one face (``PressureSolver``'s ``periodic_y``): within each slab
        self.periodic_y = bool(periodic_y)
        self.cell_size = float(cell_size)
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.volume_tolerance = float(volume_tolerance)
        self.comm = communicator
        self.cut = cut
        rank, size = communicator.rank, communicator.size
        if cut.processes != size or cut.cells != self.shape[0]:
            raise CaseFileError(f"slab pressure solve: a cut of {cut.cells} planes into "
                                f"{cut.processes} slabs for {size} processes and {self.shape[0]} "
                                "planes")
        shapes, factors = level_shapes(self.shape, self.periodic_y)
        split = 0
        while (split < min(distributed_levels, len(shapes) - 1) and factors[split][0] == 2
               and cut.alignment % (2 ** (split + 1)) == 0):
            split += 1
        if size > 1 and split == 0:
            raise CaseFileError(f"slab pressure solve: a grid of {self.shape} cells has no level "
                                "to split over processes (too small, or slabs not aligned)")
        self.split_levels = split
        low = 1 if rank > 0 else 0
        high = 1 if rank < size - 1 else 0
        spacing = np.full(3, self.cell_size)
        self.levels = []
        for level in range(split):
            scale = 2 ** level
            first = -(-cut.first(rank) // scale)
            stop = -(-cut.stop(rank) // scale)
            self.levels.append(_Level(shapes[level], first, stop, low, high, spacing))
            spacing = spacing * np.array(factors[level])
        self.counts = [cut.counts(level) for level in range(split + 1)]
        scale = 2 ** split
        self.gathered_first = -(-cut.first(rank) // scale)
        self.gathered_stop = -(-cut.stop(rank) // scale)
        self.factors = factors
        # the levels below the split, whole on every process
        self.gathered = build_hierarchy(shapes[split], spacing, self.periodic_y)
        if [tuple(int(n) for n in row) for row in self.gathered.shapes] != list(shapes[split:]):
            raise AssertionError("the gathered levels differ from the whole grid's")
        owned = self.gathered_stop - self.gathered_first
        ny, nz = shapes[split][1], shapes[split][2]
        self._coarse_beta = [np.zeros((owned + 1, ny, nz)), np.zeros((owned, ny + 1, nz)),
                             np.zeros((owned, ny, nz + 1))]
        self._coarse_rhs = np.zeros((owned, ny, nz))
        fine = self.levels[0]
        planes = fine.x.shape
        self._system_rhs = np.zeros(planes)
        self._direction = np.zeros(planes)
        self._product = np.zeros(planes)
        self._row_sums = np.zeros((planes[0] + 1, 3))
        self._row_counts = np.zeros((planes[0] + 2, 2), dtype=np.int64)
        self._no_cells = multigrid.ListedCells(
            cells=np.zeros(0, dtype=np.int64), neighbours=np.zeros((0, 6), dtype=np.int64),
            couplings=np.zeros((0, 6)), inverse_diagonal=np.zeros(0), red=0)

    # ------------------------------------------------------------------ communication
    def _exchange(self, level: _Level, array) -> None:
        """The ghost planes of a cell array of ``level`` from the neighbours."""
        b, e = level.begin, level.end
        self.comm.exchange(array, slice(b, b + level.low), slice(0, level.low),
                           slice(e - level.high, e), slice(e, e + level.high))

    def _sums(self, columns: int = 1):
        """The ordered global totals of row_sums' first ``columns`` columns over the slabs'
        planes; with 2 columns (total of column 0, largest of column 1)."""
        fine = self.levels[0]
        rows = self._row_sums[fine.begin:fine.end, :columns]
        everything = self.comm.ordered_rows(rows, self.counts[0])
        if columns == 1:
            return float(_ordered_total(everything[:, 0]))
        return float(_ordered_total(everything[:, 0])), float(_ordered_largest(everything[:, 1]))

    # ------------------------------------------------------------------ set-up per solve
    def _build_levels(self) -> None:
        for level in range(self.split_levels - 1):
            fine, coarse = self.levels[level], self.levels[level + 1]
            multigrid.coarsen_coefficients(*fine.beta, *coarse.beta,
                                           *(int(f) for f in self.factors[level]),
                                           fine.begin, fine.end, coarse.begin, coarse.end)
        last = self.levels[-1]
        owned = self.gathered_stop - self.gathered_first
        multigrid.coarsen_coefficients(*last.beta, *self._coarse_beta,
                                       *(int(f) for f in self.factors[self.split_levels - 1]),
                                       last.begin, last.end, 0, owned)
        counts = self.counts[self.split_levels]
        whole = self.gathered
        gathered_x = list(counts)
        gathered_x[-1] += 1
        is_last = self.comm.rank == self.comm.size - 1
        beta_x = self._coarse_beta[0] if is_last else self._coarse_beta[0][:-1]
        face_view(whole, 0, 0)[...] = self.comm.gather_planes(beta_x, gathered_x)
        face_view(whole, 0, 1)[...] = self.comm.gather_planes(self._coarse_beta[1], counts)
        face_view(whole, 0, 2)[...] = self.comm.gather_planes(self._coarse_beta[2], counts)
        build_levels(whole)

    def _listed_stencils(self, cells, red):
        fine = self.levels[0]
        return listed_stencils_of(fine.beta, fine.inverse_h2, cells, red, self.periodic_y)

    # ------------------------------------------------------------------ the V-cycle
    def _smooth(self, level: _Level, colour: int) -> None:
        self._exchange(level, level.x)
        multigrid.smooth(*level.beta, *level.inverse_h2, level.rhs, level.x, level.colour(colour),
                         level.begin, level.end, self.periodic_y)

    def _smooth_listed(self, listed, first, stop) -> None:
        fine = self.levels[0]
        self._exchange(fine, fine.x)
        multigrid.smooth_listed_cells(listed, fine.rhs, fine.x, first, stop)

    def _v_cycle(self, sweeps, listed, listed_sweeps) -> None:
        """levels[0].x = B levels[0].rhs on this slab (``multigrid.apply_v_cycle``'s cycle)."""
        red, stop = listed.red, listed.cells.shape[0]
        # every process sweeps (and exchanges) when any one lists cells
        local = listed_sweeps > 0 and self._any_listed
        for number, level in enumerate(self.levels):
            first_from_zero = True
            if number == 0 and local:
                level.x[:] = 0.0
                for _ in range(listed_sweeps):
                    self._smooth_listed(listed, 0, red)
                    self._smooth_listed(listed, red, stop)
                first_from_zero = False
            for sweep in range(multigrid.level_sweeps(sweeps, number)):
                if sweep == 0 and first_from_zero:
                    multigrid.smooth_first_red(*level.beta, *level.inverse_h2, level.rhs, level.x,
                                               level.begin, level.end, level.parity,
                                               self.periodic_y)
                else:
                    self._smooth(level, 0)
                self._smooth(level, 1)
            self._exchange(level, level.x)
            factors = [int(f) for f in self.factors[number]]
            if number + 1 < len(self.levels):
                coarse = self.levels[number + 1]
                multigrid.restrict_red_residual(*level.beta, *level.inverse_h2, level.rhs, level.x,
                                                coarse.rhs, *factors, level.begin, level.end,
                                                coarse.begin, coarse.end, level.parity,
                                                self.periodic_y)
            else:
                owned = self.gathered_stop - self.gathered_first
                multigrid.restrict_red_residual(*level.beta, *level.inverse_h2, level.rhs, level.x,
                                                self._coarse_rhs, *factors, level.begin, level.end,
                                                0, owned, level.parity, self.periodic_y)
        whole = self.gathered
        cell_view(whole.residuals, whole, 0)[...] = self.comm.gather_planes(
            self._coarse_rhs, self.counts[self.split_levels])
        multigrid.apply_v_cycle(whole, sweeps, self._no_cells, 0, self.split_levels)
        coarse_x = cell_view(whole.corrections, whole, 0)
        coarse_first = self.gathered_first
        for number in range(len(self.levels) - 1, -1, -1):
            level = self.levels[number]
            factors = [int(f) for f in self.factors[number]]
            multigrid.prolong_correction(coarse_x, level.x, *factors, level.begin, level.end,
                                         coarse_first)
            for _ in range(multigrid.level_sweeps(sweeps, number)):
                self._smooth(level, 1)
                self._smooth(level, 0)
            if number == 0 and local:
                for _ in range(listed_sweeps):
                    self._smooth_listed(listed, red, stop)
                    self._smooth_listed(listed, 0, red)
            coarse_x, coarse_first = level.x, level.begin

    def _precondition(self, sweeps, singular, active_cells, listed, listed_sweeps) -> None:
        self._v_cycle(sweeps, listed, listed_sweeps)
        if singular:
            fine = self.levels[0]
            multigrid.sum_of_entries(fine.x, self._row_sums)
            multigrid.subtract_on_active(*fine.beta, fine.x, self._sums() / active_cells)

    # ------------------------------------------------------------------ the solve
    def solve(self, beta_x, beta_y, beta_z, rhs, p_initial=None, listed_cells=None,
              time_step=None):
        """``PressureSolver.solve`` on this process's slab (class docstring); every process
        calls it together. ``listed_cells``: flat indices into this process's planes (ghost planes
        included, never listing a ghost cell)."""
        fine = self.levels[0]
        shape = fine.x.shape
        for name, array, wanted in (("beta_x", beta_x, fine.beta[0].shape),
                                    ("beta_y", beta_y, fine.beta[1].shape),
                                    ("beta_z", beta_z, fine.beta[2].shape), ("rhs", rhs, shape)):
            if np.shape(array) != wanted:
                raise CaseFileError(f"slab pressure solve: {name} has shape {np.shape(array)}, "
                                    f"expected {wanted} on {self.comm.name}")
        rhs = np.ascontiguousarray(rhs, dtype=np.float64)
        pressure = (np.zeros(shape) if p_initial is None
                    else np.array(p_initial, dtype=np.float64, order="C", copy=True))
        listed_flat, red = _listed_cells(listed_cells, shape, fine.parity)
        invalid = 0
        for axis, beta in enumerate((beta_x, beta_y, beta_z)):
            beta = np.ascontiguousarray(beta, dtype=np.float64)
            invalid += multigrid.copy_coefficients(beta, fine.beta[axis], self._row_counts)
        invalid = self.comm.sum_int(invalid)
        if invalid:
            raise InstabilityError(f"pressure solve: {invalid} face coefficient(s) beta = 1/rho "
                                   "are negative or not finite; the density field has become "
                                   "invalid")
        multigrid.prepare_system(*fine.beta, rhs, pressure, self._system_rhs, self._row_sums)
        rows = self.comm.ordered_rows(self._row_sums[fine.begin:fine.end], self.counts[0])
        active_cells = int(rows[:, 0].sum())
        if active_cells == 0:
            return np.zeros(shape), PressureSolveReport(0, 0.0)
        rhs_sum = float(_ordered_total(rows[:, 1]))
        pressure_sum = float(_ordered_total(rows[:, 2]))
        self._build_levels()
        listed = self._listed_stencils(listed_flat, red)
        self._any_listed = self.comm.any(len(listed_flat) > 0)
        singular = not self.comm.any(_has_dirichlet_face(fine, self.comm, self.periodic_y))
        if singular:
            multigrid.subtract_on_active(*fine.beta, self._system_rhs, rhs_sum / active_cells)
            multigrid.subtract_on_active(*fine.beta, pressure, pressure_sum / active_cells)
        dt2 = float(time_step) ** 2 if time_step else 0.0
        largest_residual = self.volume_tolerance / dt2 if dt2 > 0.0 else 0.0
        iterations, relative, largest, outcome = self._pcg(
            pressure, singular, active_cells, listed, largest_residual)
        self._exchange(fine, pressure)
        return pressure, outcome_report(iterations, relative, largest, outcome, dt2,
                                        self.tolerance, self.shape)

    def _pcg(self, pressure, singular, active_cells, listed, largest_residual):
        """``multigrid.solve_pcg`` over the slabs, step for step."""
        fine = self.levels[0]
        beta = fine.beta
        h2 = fine.inverse_h2
        system_rhs, direction, product = self._system_rhs, self._direction, self._product
        residual, preconditioned = fine.rhs, fine.x
        multigrid.dot(system_rhs, system_rhs, self._row_sums)
        rhs_norm = math.sqrt(self._sums())
        if not np.isfinite(rhs_norm):
            return 0, np.inf, np.inf, multigrid.NON_FINITE
        if rhs_norm == 0.0:
            pressure[:] = 0.0
            return 0, 0.0, 0.0, multigrid.CONVERGED

        def true_residual():
            self._exchange(fine, pressure)
            multigrid.compute_residual(*beta, *h2, system_rhs, pressure, residual, self._row_sums,
                                       self.periodic_y)
            return self._sums(2)

        squared, largest = true_residual()
        relative = math.sqrt(squared) / rhs_norm
        if not np.isfinite(relative):
            return 0, relative, largest, multigrid.NON_FINITE
        iterations = 0
        restart = True
        curvature_product = 0.0
        while relative > self.tolerance and largest > largest_residual \
                and iterations < self.max_iterations:
            self._precondition(SMOOTHING_SWEEPS, singular, active_cells, listed, LISTED_SWEEPS)
            multigrid.dot(residual, preconditioned, self._row_sums)
            new_product = self._sums()
            if not np.isfinite(new_product):
                return iterations, relative, largest, multigrid.NON_FINITE
            if restart:
                multigrid.copy_into(preconditioned, direction)
                restart = False
            else:
                multigrid.update_direction(direction, preconditioned,
                                           new_product / curvature_product)
            curvature_product = new_product
            self._exchange(fine, direction)
            multigrid.apply_operator_and_dot(*beta, *h2, direction, product, self._row_sums,
                                             self.periodic_y)
            curvature = self._sums()
            if not np.isfinite(curvature):
                return iterations, relative, largest, multigrid.NON_FINITE
            if curvature <= 0.0 or curvature_product <= 0.0:
                return iterations, relative, largest, multigrid.BREAKDOWN
            iterations += 1
            multigrid.step_solution_and_residual(pressure, residual, direction, product,
                                                 curvature_product / curvature, self._row_sums)
            squared, largest = self._sums(2)
            relative = math.sqrt(squared) / rhs_norm
            if not np.isfinite(relative):
                return iterations, relative, largest, multigrid.NON_FINITE
            if relative <= self.tolerance or largest <= largest_residual:
                squared, largest = true_residual()
                relative = math.sqrt(squared) / rhs_norm
                restart = True
        if singular:
            multigrid.sum_of_entries(pressure, self._row_sums)
            multigrid.subtract_on_active(*beta, pressure, self._sums() / active_cells)
        if relative <= self.tolerance or largest <= largest_residual:
            return iterations, relative, largest, multigrid.CONVERGED
        return iterations, relative, largest, multigrid.NOT_CONVERGED


def _has_dirichlet_face(fine: _Level, comm, periodic_y: bool) -> bool:
    """True if this slab holds a boundary face with a positive coefficient (an open boundary;
    a periodic y's faces are inside ones)."""
    beta_x, beta_y, beta_z = fine.beta
    b, e = fine.begin, fine.end
    y_sides = not periodic_y and bool(beta_y[b:e, 0].any() or beta_y[b:e, -1].any())
    found = bool(y_sides or beta_z[b:e, :, 0].any() or beta_z[b:e, :, -1].any())
    if comm.rank == 0:
        found = found or bool(beta_x[0].any())
    if comm.rank == comm.size - 1:
        found = found or bool(beta_x[-1].any())
    return found


def _ordered_total(values) -> float:
    return ordered_total(np.ascontiguousarray(values, dtype=np.float64))


def _ordered_largest(values) -> float:
    return ordered_largest(np.ascontiguousarray(values, dtype=np.float64))
