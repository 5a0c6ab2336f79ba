"""The pressure equation of the projection step: div(beta grad p) = rhs, beta = 1/rho on the faces.

Why a solver of its own: the two-phase solver needs this solve on every time step, with face
coefficients that jump by the water/air density ratio (about 1000) across a moving surface. Conjugate
gradients preconditioned by one geometric multigrid V-cycle (MGPCG; McAdams, Sifakis & Teran 2010,
Proc. ACM SIGGRAPH/Eurographics SCA; Tatebe 1993, NASA CP-3224) converges in a small number of
iterations that barely grows with the grid, and rebuilding it for new coefficients is a few passes
over the arrays (no matrix is assembled except a few hundred cells on the coarsest level). The
method, the coarse coefficients and their derivation are in ``riprap/fluid/kernels/multigrid.py``.

Conventions (uniform grid of cubic cells of side ``cell_size`` h, arrays [i, j, k] for x, y, z):

- unknown ``p`` (nx, ny, nz) at the cell centres; ``beta_x`` (nx+1, ny, nz), ``beta_y``
  (nx, ny+1, nz), ``beta_z`` (nx, ny, nz+1) on the faces (m^3/kg when beta = 1/rho), ``rhs``
  (nx, ny, nz) in the units of div(beta grad p) (1/s^2 when p is in Pa and rhs = div(u*)/dt);
- the discrete operator, per cell: sum over its faces of beta_f (p_neighbour - p_cell) / h^2 on an
  interior face and beta_f (0 - p_cell) / (h/2) / h = -2 beta_f p_cell / h^2 on a boundary face;
  i.e. a boundary face with beta > 0 is a Dirichlet boundary with p = 0 *on the face*, and one
  with beta = 0 a wall (zero normal gradient);
- an interior face with beta = 0 separates its two cells; a cell with all six faces 0 is inactive
  (a solid obstacle): its p is returned as 0 and its rhs is ignored;
- a 2D problem in the x-z plane is ny == 1 with beta_y all zero;
- ``periodic_y``: the y faces 0 and ny are one face between the cells ny - 1 and 0 (a periodic
  strip; ny even, and y coarsened only while its cells stay even: ``level_shapes``);
- with no Dirichlet face at all (a closed tank) the operator is singular: the mean of rhs over the
  active cells is removed (only the compatible part is solved) and the returned p has zero mean
  over the active cells. One mean over all active cells: separate closed regions are not handled.

Stopping: ``||r||_2 <= tolerance ||rhs||_2`` with r = rhs - A p over the active cells (and rhs
its compatible part for a closed tank), the residual of the returned p evaluated directly; or,
given the step's ``time_step`` dt and a ``volume_tolerance``, as soon as ``dt^2 max|r| <=
volume_tolerance``. Why that second test: the projection's rhs is div(u*)/dt, so the corrected
velocity keeps div u = dt r and every cell's volume changes by dt^2 r of itself over the step;
bounding that by a fraction stops the solve when the flow is as incompressible as the volume of
fluid needs, not at a residual relative to a right-hand side that grows with the waves (Basilisk's
``poisson.h`` stops at the same bound, 1e-3 there). A solve that reaches ``max_iterations`` keeps
what it has and says so (``PressureSolveReport.capped``) unless it is still far off
(``CAPPED_RESIDUAL_LIMIT``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid.kernels import multigrid

__all__ = ["PressureSolver", "PressureSolveReport", "apply_operator", "build_hierarchy",
           "level_shapes", "build_levels", "outcome_report", "face_view", "cell_view",
           "listed_stencils_of"]

# Coarsening stops once a level has at most this many cells; the coarsest level is then factored
# directly (banded Cholesky, cost cells x (ny nz)^2: about a million operations for 8 x 8 x 8).
COARSEST_MAXIMUM_CELLS = 512
# Red-black Gauss-Seidel sweeps before and after each coarse correction on the two finest levels
# (more below them: ``multigrid.level_sweeps``). Measured on 128^3,
# 1024 x 1 x 128 and 200 x 40 x 60 with a 1000:1 wavy surface (2-core machine): one sweep needs
# about twice the iterations (20 against 9 on 128^3) and is slower; two, three and four sweeps
# take about the same time (fewer iterations, dearer V-cycles).
SMOOTHING_SWEEPS = 2
# Extra sweeps on the cells a caller lists (``solve(listed_cells=...)``: the coupled solver lists
# the cells of free bodies), before and after each V-cycle. Measured on the pressure problem of
# examples/06 as the bore reaches the layer (0.91 M cells, 46,628 cells of 25 concrete units partly
# in air), with the coarse levels' sweeps of ``multigrid.level_sweeps``: 22 CG iterations and
# 530-550 ms without; 16 and 426-455 ms with 2 sweeps; 14 and 402-410 ms with 4; 14 and 456 ms
# with 8. (With 2 sweeps on every level: 23 iterations without, 17 with 2 sweeps, 14 with an
# exact solve on those cells.)
LISTED_SWEEPS = 4
# A solve stopped by its iteration cap is kept (and reported) while its relative residual is below
# this; above it the step is refused as an instability: a pressure that far off is not a flow.
CAPPED_RESIDUAL_LIMIT = 1e-3


@dataclass(frozen=True)
class PressureSolveReport:
    """How a solve went: CG ``iterations``, the final ``relative_residual`` ||r|| / ||rhs||, the
    largest relative volume change of a cell over the step that the solve leaves (dt^2 max|r|;
    None when no time step was given), and whether it stopped at its iteration cap (``capped``)."""

    iterations: int
    relative_residual: float
    volume_change: float | None = None
    capped: bool = False


def _check_shapes(shape, beta_x, beta_y, beta_z, arrays):
    nx, ny, nz = shape
    expected = {"beta_x": (nx + 1, ny, nz), "beta_y": (nx, ny + 1, nz), "beta_z": (nx, ny, nz + 1)}
    given = {"beta_x": beta_x, "beta_y": beta_y, "beta_z": beta_z}
    given.update(arrays)
    for name, array in given.items():
        wanted = expected.get(name, (nx, ny, nz))
        if np.shape(array) != wanted:
            raise CaseFileError(f"pressure solve: {name} has shape {np.shape(array)}, expected "
                                f"{wanted} for a grid of {nx} x {ny} x {nz} cells")


def _listed_cells(cells, shape, parity: int = 0):
    """The flat cell indices of ``solve(listed_cells=...)``, checked, without repeats, red
    ((i + j + k) even) first, as int64; and how many are red. ``parity``: the global x index of
    plane 0 mod 2 (a slab of a split grid)."""
    n_cells = math.prod(shape)
    if cells is None:
        return np.zeros(0, dtype=np.int64), 0
    listed = np.unique(np.asarray(cells, dtype=np.int64).reshape(-1))
    if listed.size and (listed[0] < 0 or listed[-1] >= n_cells):
        raise CaseFileError(f"pressure solve: listed_cells must be flat cell indices in [0, "
                            f"{n_cells}), got [{listed[0]}, {listed[-1]}]")
    i, j, k = np.unravel_index(listed, shape)
    black = (i + parity + j + k) % 2 == 1
    return np.concatenate([listed[~black], listed[black]]), int(np.count_nonzero(~black))


def _as_float_array(array):
    return np.ascontiguousarray(array, dtype=np.float64)


def apply_operator(beta_x, beta_y, beta_z, p, cell_size, periodic_y=False) -> np.ndarray:
    """div(beta grad p) of the solver, exactly as discretised there (module docstring).

    ``p`` (nx, ny, nz); returns a new (nx, ny, nz) array. Use it to check a solution's residual and
    to correct velocities with the same face terms (flux beta_f (p_n - p_c) / h on interior faces,
    beta_f (0 - p_c) / (h/2) on Dirichlet boundary faces).
    """
    p = _as_float_array(p)
    if p.ndim != 3:
        raise CaseFileError(f"apply_operator: p must be a 3D array (nx, ny, nz), got shape {p.shape}")
    _check_shapes(p.shape, beta_x, beta_y, beta_z, {"p": p})
    if not cell_size > 0.0:
        raise CaseFileError(f"apply_operator: cell_size must be positive, got {cell_size}")
    inverse_h2 = 1.0 / float(cell_size) ** 2
    result = np.empty_like(p)
    multigrid.apply_positive_operator(_as_float_array(beta_x), _as_float_array(beta_y),
                                      _as_float_array(beta_z), inverse_h2, inverse_h2, inverse_h2,
                                      p, result, bool(periodic_y))
    np.negative(result, out=result)
    return result


def outcome_report(iterations, relative_residual, largest, outcome, dt2, tolerance,
                   shape) -> PressureSolveReport:
    """The report of a solve that ended with ``outcome`` (``multigrid`` codes); raises
    InstabilityError for one that failed and is not a usable capped solve."""
    volume_change = float(dt2 * largest) if dt2 > 0.0 else None
    capped = (outcome == multigrid.NOT_CONVERGED and relative_residual <= CAPPED_RESIDUAL_LIMIT)
    if outcome != multigrid.CONVERGED and not capped:
        reason = {
            multigrid.NOT_CONVERGED: "did not converge",
            multigrid.NON_FINITE: "met a non-finite value (check rhs and the coefficients)",
            multigrid.BREAKDOWN: ("broke down: the operator is not positive definite on the "
                                  "search direction (a region cut off by zero faces without a "
                                  "Dirichlet face?)"),
        }[outcome]
        raise InstabilityError(f"pressure solve {reason}: relative residual "
                               f"{relative_residual:.3e} after {iterations} iteration(s), "
                               f"tolerance {tolerance:.1e}, grid {tuple(shape)}")
    return PressureSolveReport(int(iterations), float(relative_residual), volume_change,
                               bool(capped))


def listed_stencils_of(betas, inverse_h2, cells, red, periodic_y=False) -> multigrid.ListedCells:
    """The ``multigrid.ListedCells`` of ``cells`` (flat indices, ``red`` of them first) with
    the face coefficients ``betas`` (three arrays) and ``inverse_h2`` (3,) 1/h^2."""
    n = len(cells)
    listed = multigrid.ListedCells(cells=cells, neighbours=np.zeros((n, 6), dtype=np.int64),
                                   couplings=np.zeros((n, 6)), inverse_diagonal=np.zeros(n),
                                   red=red)
    if n:
        multigrid.listed_stencils(*betas, *inverse_h2, cells, listed.neighbours, listed.couplings,
                                  listed.inverse_diagonal, bool(periodic_y))
    return listed


def level_shapes(shape, periodic_y: bool = False) -> tuple[list, list]:
    """The cells per axis of every multigrid level of a grid of ``shape``, and the children per
    coarse cell from each level to the next ((1, 1, 1) after the last): each level halves every
    axis with more than one cell, until a level has at most ``COARSEST_MAXIMUM_CELLS``.

    ``periodic_y``: y is halved only while the coarse count stays even (a multiple of 4 halves to
    an even count), since the red-black sweeps need the cells beside the wrapped face to be of two
    colours; after that y keeps its cells on the coarser levels."""
    shapes = [tuple(int(n) for n in shape)]
    factors = []
    while math.prod(shapes[-1]) > COARSEST_MAXIMUM_CELLS and max(shapes[-1]) > 1:
        factor = tuple(2 if n > 1 else 1 for n in shapes[-1])
        if periodic_y and shapes[-1][1] % 4:
            factor = (factor[0], 1, factor[2])
        if factor == (1, 1, 1):
            break
        factors.append(factor)
        shapes.append(tuple(-(-n // f) for n, f in zip(shapes[-1], factor)))
    factors.append((1, 1, 1))
    return shapes, factors


def build_hierarchy(shape, spacing, periodic_y: bool = False) -> multigrid.Hierarchy:
    """The multigrid levels (``level_shapes``) of a grid of ``shape`` cells of ``spacing`` (3,) m
    per axis, empty (``build_levels`` fills them); ``periodic_y`` as ``level_shapes``."""
    shapes, factors = level_shapes(shape, periodic_y)
    spacing = np.asarray(spacing, dtype=np.float64).reshape(3)
    spacings = [spacing.copy()]
    for factor in factors[:-1]:
        spacing = spacing * np.array(factor)
        spacings.append(spacing.copy())
    shapes_array = np.array(shapes, dtype=np.int64)
    cell_counts = shapes_array.prod(axis=1)
    face_counts = np.empty((len(shapes), 3), dtype=np.int64)
    for axis in range(3):
        face_shapes = shapes_array.copy()
        face_shapes[:, axis] += 1
        face_counts[:, axis] = face_shapes.prod(axis=1)
    cell_offsets = np.concatenate([[0], np.cumsum(cell_counts)]).astype(np.int64)
    face_offsets = np.vstack([np.zeros((1, 3), dtype=np.int64),
                              np.cumsum(face_counts, axis=0)]).astype(np.int64)
    coarsest = shapes[-1]
    return multigrid.Hierarchy(
        shapes=shapes_array,
        cell_offsets=cell_offsets,
        face_offsets=face_offsets,
        inverse_spacing_squared=1.0 / np.array(spacings) ** 2,
        factors=np.array(factors, dtype=np.int64),
        beta_x=np.zeros(face_offsets[-1, 0]),
        beta_y=np.zeros(face_offsets[-1, 1]),
        beta_z=np.zeros(face_offsets[-1, 2]),
        corrections=np.zeros(cell_offsets[-1]),
        residuals=np.zeros(cell_offsets[-1]),
        coarsest_factor=np.zeros((math.prod(coarsest), coarsest[1] * coarsest[2] + 1)),
        periodic_y=bool(periodic_y))


def face_view(hierarchy: multigrid.Hierarchy, level: int, axis: int) -> np.ndarray:
    """The face coefficients of ``axis`` on ``level`` as an array (a view of the flat storage)."""
    shape = list(hierarchy.shapes[level])
    shape[axis] += 1
    flat = (hierarchy.beta_x, hierarchy.beta_y, hierarchy.beta_z)[axis]
    return flat[hierarchy.face_offsets[level, axis]:hierarchy.face_offsets[level + 1, axis]] \
        .reshape(shape)


def cell_view(flat: np.ndarray, hierarchy: multigrid.Hierarchy, level: int) -> np.ndarray:
    """``level``'s cells in a flat cell array (``residuals`` or ``corrections``) as an array."""
    shape = tuple(int(n) for n in hierarchy.shapes[level])
    return flat[hierarchy.cell_offsets[level]:hierarchy.cell_offsets[level + 1]].reshape(shape)


def build_levels(hierarchy: multigrid.Hierarchy) -> None:
    """Coarse coefficients from level 0's, and the coarsest factor: O(cells) work."""
    levels = hierarchy.shapes.shape[0]
    for level in range(levels - 1):
        fine = [face_view(hierarchy, level, axis) for axis in range(3)]
        coarse = [face_view(hierarchy, level + 1, axis) for axis in range(3)]
        multigrid.coarsen_coefficients(*fine, *coarse, *(int(f) for f in hierarchy.factors[level]),
                                       0, int(hierarchy.shapes[level, 0]), 0,
                                       int(hierarchy.shapes[level + 1, 0]))
    last = levels - 1
    coarsest = [face_view(hierarchy, last, axis) for axis in range(3)]
    multigrid.factor_coarsest(*coarsest, *hierarchy.inverse_spacing_squared[last],
                              hierarchy.coarsest_factor, hierarchy.periodic_y)


class PressureSolver:
    """MGPCG solver of div(beta grad p) = rhs on a fixed grid, reused every time step.

    Parameters
    ----------
    shape : (nx, ny, nz)
        Cells per axis (ny == 1 for a 2D x-z problem). Any sizes, odd ones included.
    cell_size : float
        Side h of the cubic cells (m).
    tolerance : float
        Relative residual ||r||_2 / ||rhs||_2 at which a solve stops.
    max_iterations : int
        CG iterations at which a solve stops (``PressureSolveReport.capped``).
    volume_tolerance : float
        With ``solve(time_step=dt)``: a solve also stops once no cell's volume changes by more
        than this fraction over the step (dt^2 max|r|); 0 leaves that test out.
    periodic_y : bool
        The y faces 0 and ny are one face (module docstring); ny must be even.

    The multigrid levels are allocated once, by the first ``solve``; later solves only refill
    them. One instance is not safe to use from two threads at the same time.
    """

    def __init__(self, shape, cell_size, *, tolerance: float = 1e-8, max_iterations: int = 200,
                 volume_tolerance: float = 0.0, periodic_y: bool = False):
        shape = tuple(int(n) for n in shape)
        if len(shape) != 3 or min(shape) < 1:
            raise CaseFileError(f"PressureSolver: shape must be (nx, ny, nz) with every size >= 1, "
                                f"got {shape}")
        if periodic_y and shape[1] % 2:
            raise CaseFileError(f"PressureSolver: a periodic y needs an even ny, got {shape[1]}")
        if not (cell_size > 0.0 and math.isfinite(cell_size)):
            raise CaseFileError(f"PressureSolver: cell_size must be a positive length (m), got "
                                f"{cell_size}")
        if not 0.0 < tolerance < 1.0:
            raise CaseFileError(f"PressureSolver: tolerance must lie in (0, 1), got {tolerance}")
        if not (0.0 <= volume_tolerance < 1.0):
            raise CaseFileError(f"PressureSolver: volume_tolerance must lie in [0, 1), got "
                                f"{volume_tolerance}")
        if int(max_iterations) < 1:
            raise CaseFileError(f"PressureSolver: max_iterations must be >= 1, got {max_iterations}")
        self.shape = shape
        self.cell_size = float(cell_size)
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.volume_tolerance = float(volume_tolerance)
        self.periodic_y = bool(periodic_y)

        self.levels = [tuple(int(n) for n in row) for row in level_shapes(shape, periodic_y)[0]]
        self._hierarchy = None             # allocated by the first solve (_allocate)

    def _allocate(self) -> None:
        """The multigrid levels and the solve's work arrays, once, at the first solve: a solver
        that never solves (the whole grid's, when a run is split over processes and each solves
        its slab) holds none of them."""
        shape = self.shape
        self._hierarchy = build_hierarchy(shape, np.full(3, self.cell_size), self.periodic_y)
        self._system_rhs = np.zeros(shape)
        self._direction = np.zeros(shape)
        self._product = np.zeros(shape)
        self._row_sums = np.zeros((shape[0] + 1, 3))
        self._row_counts = np.zeros((shape[0] + 1, 2), dtype=np.int64)

    def _face_view(self, level, axis):
        return face_view(self._hierarchy, level, axis)

    def _build_levels(self):
        build_levels(self._hierarchy)

    def _listed_stencils(self, cells, red):
        """The ``multigrid.ListedCells`` of ``cells`` with level 0's present coefficients."""
        return listed_stencils_of([self._face_view(0, axis) for axis in range(3)],
                                  self._hierarchy.inverse_spacing_squared[0], cells, red,
                                  self.periodic_y)

    def solve(self, beta_x, beta_y, beta_z, rhs, p_initial=None, listed_cells=None,
              time_step=None):
        """Solve div(beta grad p) = rhs; returns (p, PressureSolveReport).

        ``p_initial`` (optional, e.g. the previous step's pressure) is the starting guess; it is not
        modified. ``listed_cells`` (optional flat indices into the (nx, ny, nz) cells, C order) get
        ``LISTED_SWEEPS`` extra smoothing sweeps per V-cycle: give the cells of bodies much heavier
        than the fluid around them (the result is the same, it comes in fewer iterations). The
        returned ``p`` is a new array, 0 on inactive cells. ``time_step`` (s): the step whose
        rhs this is (div(u*)/dt), for the volume test (module docstring).

        Raises InstabilityError if a coefficient is negative or not finite, if rhs or an iterate
        becomes non-finite, on a breakdown of CG, or if the solve stops at ``max_iterations``
        with a relative residual above ``CAPPED_RESIDUAL_LIMIT``; CaseFileError on wrong shapes.
        """
        arrays = {"rhs": rhs} if p_initial is None else {"rhs": rhs, "p_initial": p_initial}
        _check_shapes(self.shape, beta_x, beta_y, beta_z, arrays)
        if self._hierarchy is None:
            self._allocate()
        beta_x, beta_y, beta_z = (_as_float_array(beta) for beta in (beta_x, beta_y, beta_z))
        rhs = _as_float_array(rhs)
        listed_flat, red = _listed_cells(listed_cells, self.shape)
        pressure = (np.zeros(self.shape) if p_initial is None
                    else np.array(p_initial, dtype=np.float64, order="C", copy=True))

        invalid_faces = sum(multigrid.copy_coefficients(beta, self._face_view(0, axis),
                                                        self._row_counts)
                            for axis, beta in enumerate((beta_x, beta_y, beta_z)))
        if invalid_faces:
            raise InstabilityError(f"pressure solve: {invalid_faces} face coefficient(s) beta = "
                                   f"1/rho are negative or not finite; the density field has "
                                   f"become invalid")
        active_cells, rhs_sum, pressure_sum = multigrid.prepare_system(
            beta_x, beta_y, beta_z, rhs, pressure, self._system_rhs, self._row_sums)
        if active_cells == 0:
            return np.zeros(self.shape), PressureSolveReport(0, 0.0)
        self._build_levels()
        listed = self._listed_stencils(listed_flat, red)
        # (a periodic y's faces 0 and ny are inside faces, not Dirichlet ones)
        y_sides = not self.periodic_y and (beta_y[:, 0].any() or beta_y[:, -1].any())
        singular = not (beta_x[0].any() or beta_x[-1].any() or y_sides
                        or beta_z[:, :, 0].any() or beta_z[:, :, -1].any())
        if singular:
            view = self._face_view
            multigrid.subtract_on_active(view(0, 0), view(0, 1), view(0, 2), self._system_rhs,
                                         rhs_sum / active_cells)
            multigrid.subtract_on_active(view(0, 0), view(0, 1), view(0, 2), pressure,
                                         pressure_sum / active_cells)
        dt2 = float(time_step) ** 2 if time_step else 0.0
        largest_residual = self.volume_tolerance / dt2 if dt2 > 0.0 else 0.0
        iterations, relative_residual, largest, outcome = multigrid.solve_pcg(
            self._hierarchy, self._system_rhs, pressure, self._direction, self._product,
            self._row_sums, self.tolerance, self.max_iterations, SMOOTHING_SWEEPS, singular,
            active_cells, listed, LISTED_SWEEPS, largest_residual)
        return pressure, outcome_report(iterations, relative_residual, largest, outcome, dt2,
                                        self.tolerance, self.shape)
