"""Multigrid-preconditioned conjugate gradients (MGPCG) for the variable-coefficient pressure equation.

Why: the projection step of the two-phase solver needs ``div(beta grad p) = rhs`` with
``beta = 1/rho`` jumping by 1000 across the water surface, on every time step with new
coefficients. Plain multigrid loses its grid-independent rate at such jumps; conjugate gradients
with one multigrid V-cycle as preconditioner keeps a small, nearly grid-independent iteration count
and needs no matrix assembly (Tatebe 1993, "The multigrid preconditioned conjugate gradient
method", 6th Copper Mountain Conf. on Multigrid Methods, NASA CP-3224; McAdams, Sifakis & Teran
2010, "A parallel multigrid Poisson solver for fluids simulation on large grids", Proc. ACM
SIGGRAPH/Eurographics SCA; Popinet's Basilisk ``poisson.h`` likewise works on a cell-centred
hierarchy whose coarse face coefficients are averages of the fine ones).

Discretisation (level 0, cubic cells of side h; arrays indexed [i, j, k] for x, y, z):

    (A p)_c = sum over the six faces f of c of  beta_f (p_n(f) - p_c) / h^2          interior face
                                              + beta_f (0 - p_c) / (h/2) / h          boundary face

A boundary face with ``beta_f > 0`` is a Dirichlet boundary at which p = 0 *on the face*, half a
cell from the centre: its flux is ``beta_f (0 - p_c) / (h/2)`` through area h^2 over volume h^3,
i.e. ``-2 beta_f p_c / h^2`` (equivalently a ghost value ``-p_c`` one cell out). A face with
``beta_f = 0`` carries no flux: on the boundary it is a wall (zero normal gradient), inside it
disconnects two cells; a cell whose six faces are all zero is *inactive* (a solid obstacle) and
keeps p = 0. The kernels work with the positive semi-definite form ``L = -A``:

    (L x)_c = d_c x_c - sum_{interior f} g_f x_n(f),   g_f = beta_f / h_axis^2,
    d_c = sum_{interior f} g_f + 2 sum_{boundary f} g_f,

and CG solves ``L p = -rhs``. L is symmetric (g_f is shared by the two cells of a face) and
diagonally dominant with d_c >= 0, so positive semi-definite; it is definite on every connected set
of active cells that touches a Dirichlet face.

Hierarchy: level l+1 agglomerates blocks of ``f_x x f_y x f_z`` cells of level l, f = 2 along every
axis with more than one cell and 1 along an axis that has one (the y axis of a 2D x-z problem, or
an axis that has run out). Odd sizes give coarse cells with fewer children: the missing children
are inactive padding (zero coefficients, zero residual), so no array is actually padded.

- Restriction R = c P^T (sum of the children's residuals times c = 1/(f_x f_y f_z)), prolongation P
  = injection (the coarse correction added to every child). The same c everywhere (not the mean of
  the children present) keeps R proportional to P^T, hence the preconditioner symmetric, and keeps
  the sum of a closed tank's residual zero on every level.
- Coarse operator by rediscretisation with averaged coefficients: the coarse face coefficient is
  the sum of the fine face coefficients over the ``f_y f_z`` fine face slots it covers (missing
  padding faces count as 0) divided by the number of slots, and the coarse spacing is f_x h. Why
  this scaling: the Galerkin product with piecewise-constant transfers, c P^T L P, couples two coarse
  cells by c sum g_f = avg(beta) / (f_x h^2) across an x face; rediscretisation gives avg(beta) /
  (f_x h)^2, i.e. the Galerkin value divided by f_x = 2. That factor is the known over-estimate of
  the coarse energy by piecewise-constant interpolation, which rediscretisation removes; along an
  axis that is not coarsened (f = 1) the two agree. The same holds for a Dirichlet face (2 avg(beta)
  / (f_x h)^2), so Dirichlet stays Dirichlet. On an odd axis the last fine boundary face lies
  inside the last coarse cell, not on a coarse face; it is still used as that coarse cell's
  boundary face (its beta is what reaches the boundary). Coarse coefficients cost one pass over the
  fine faces: no matrix is assembled on any level but the coarsest.
- Smoother: red-black Gauss-Seidel, colours (i + j + k) mod 2, ``sweeps`` x (red, black) before the
  coarse correction and ``sweeps`` x (black, red) after: the post-smoother is the adjoint of the
  pre-smoother, which with R ~ P^T and a symmetric coarsest solve makes the V-cycle a symmetric
  positive (semi-)definite preconditioner, as CG requires (Tatebe 1993). Each colour update reads only
  the other colour, so the parallel sweep is race-free and bit-for-bit deterministic.
- Coarsest level (at most a few hundred cells): banded Cholesky of L in natural order (bandwidth
  n_y n_z), factored once per solve. A pivot below ``PIVOT_TOLERANCE`` times the largest diagonal
  marks a cell whose equation is dependent on the others (the constant null space of a closed
  tank, a cavity with no Dirichlet face, an inactive cell): it is pinned (correction 0) and the
  rest is solved exactly, which keeps the coarse solve symmetric positive semi-definite.

Closed tank (no Dirichlet face): L is singular with the constant (over the active cells) as null
vector. The driver removes the active-cell mean from the right-hand side (its compatible part),
and the mean is removed from every preconditioned residual and from the solution, so the result
has zero mean. Only the constant over *all* active cells is removed: a region cut off from the
rest by zero faces and with no Dirichlet face of its own is not treated (CG then stalls or breaks
down and the driver reports it).

Coarse levels: below the two finest levels each level gets four times the sweeps of the one above
(at most 16 times the finest's), smoothed on one thread where a level is small. Why: with 2 sweeps
everywhere, the coarse levels' averaged coefficients near obstacle cells (the inside of a
breakwater's core) cost CG 5 extra iterations: on the water of examples/06 with its 17,641 obstacle
cells 16 iterations from zero against 11 without them. A V-cycle that solved level 2 exactly needed
9, one that solved level 3 exactly 13, so the error comes from levels 2 and below; smoothing them
more is cheap, since they are small (variable V-cycle: Bramble, Pasciak & Xu 1991): 2, 2, 8, 32
sweeps gave 11 iterations (and 8 for the water without obstacles, against 11), where a W-cycle
below level 1 or 2 made it worse (20, 24). Measured time per solve on that water: 178-193 ms against
224-232 ms.

Local smoothing: a caller may list level-0 cells that get extra Gauss-Seidel sweeps before the
pre-smoothing and after the post-smoothing (the adjoint order, so B stays symmetric). Why: a heavy
island in light fluid (a concrete unit in air, density ratio 2000) has pressure modes of its own,
nearly decoupled from the air around it, that averaged coarse coefficients cannot see; the coarse
grid then leaves them to CG, one iteration each. Sweeps on the island's cells alone remove them at
a few per cent of a V-cycle's cost (measured in ``riprap/fluid/pressure.py``).

Reductions (dot products, norms, means) are summed per x-slab in parallel and the slabs are then
added in order on one thread, so results do not depend on the number of threads.
"""
from collections import namedtuple

import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

#: A coarsest-level pivot below this times the largest diagonal pins its cell (see module docstring).
#: Measured on 1000:1 problems from 37 x 23 x 29 to 128^3 (coarsest 480-512 cells): the null pivot
#: of a closed tank is 1e-15 to 7e-15 of the largest diagonal, the smallest genuine pivot 2e-4.
PIVOT_TOLERANCE = 1e-10

#: Levels with fewer cells are smoothed on one thread (a parallel launch costs more than the sweep).
PARALLEL_SWEEP_CELLS = 32768

#: Outcome codes of ``solve_pcg``.
CONVERGED = 0
NOT_CONVERGED = 1
NON_FINITE = 2
BREAKDOWN = 3

#: The multigrid levels in flat storage (level 0 is the fine grid):
#: shapes (n_levels, 3) int64 cells per axis; cell_offsets (n_levels + 1,) and face_offsets
#: (n_levels + 1, 3) int64 start of each level in the flat cell and face arrays;
#: inverse_spacing_squared (n_levels, 3) 1/h_axis^2 (1/m^2); factors (n_levels, 3) int64 children
#: per coarse cell along each axis from level l to l + 1 (last row unused);
#: beta_x, beta_y, beta_z flat face coefficients (m^3/kg); corrections, residuals flat cell arrays
#: (the V-cycle's x and right-hand side on each level); coarsest_factor (n_coarsest, bandwidth + 1)
#: banded Cholesky factor, coarsest_factor[r, t] = L[r, r - t]; periodic_y (bool) the y axis
#: periodic on every level (its faces 0 and ny one face, cells ny - 1 and 0 neighbours).
Hierarchy = namedtuple("Hierarchy", ["shapes", "cell_offsets", "face_offsets",
                                     "inverse_spacing_squared", "factors", "beta_x", "beta_y",
                                     "beta_z", "corrections", "residuals", "coarsest_factor",
                                     "periodic_y"])


# --------------------------------------------------------------------------------------------------
# Level views
# --------------------------------------------------------------------------------------------------

@kernel
def cell_array(flat, hierarchy, level):
    """The (nx, ny, nz) view of ``level`` in a flat cell array."""
    shape = hierarchy.shapes[level]
    start = hierarchy.cell_offsets[level]
    stop = hierarchy.cell_offsets[level + 1]
    return flat[start:stop].reshape((shape[0], shape[1], shape[2]))


@kernel
def face_array(flat, hierarchy, level, axis):
    """The view of ``level`` in a flat face array of ``axis`` (one more entry along ``axis``)."""
    shape = hierarchy.shapes[level]
    nx, ny, nz = shape[0], shape[1], shape[2]
    if axis == 0:
        nx += 1
    elif axis == 1:
        ny += 1
    else:
        nz += 1
    start = hierarchy.face_offsets[level, axis]
    stop = hierarchy.face_offsets[level + 1, axis]
    return flat[start:stop].reshape((nx, ny, nz))


# --------------------------------------------------------------------------------------------------
# The operator on one cell
# --------------------------------------------------------------------------------------------------

@kernel
def diagonal_and_neighbour_sum(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x,
                               i, j, k, periodic_y=False):
    """(d_c, sum_f g_f x_n(f)) of the positive form L at cell (i, j, k): (L x)_c = d_c x_c - sum.

    A boundary face enters the diagonal twice (Dirichlet face half a cell away) and no neighbour;
    with beta = 0 it is a wall and enters nothing. On a ``periodic_y`` the y faces 0 and ny are
    the one face between cells ny - 1 and 0 (an even ny keeps them of two colours).
    """
    nx, ny, nz = x.shape
    diagonal = 0.0
    neighbours = 0.0
    g = beta_x[i, j, k] * inverse_hx2
    if i > 0:
        diagonal += g
        neighbours += g * x[i - 1, j, k]
    else:
        diagonal += 2.0 * g
    g = beta_x[i + 1, j, k] * inverse_hx2
    if i < nx - 1:
        diagonal += g
        neighbours += g * x[i + 1, j, k]
    else:
        diagonal += 2.0 * g
    g = beta_y[i, j, k] * inverse_hy2
    if j > 0:
        diagonal += g
        neighbours += g * x[i, j - 1, k]
    elif periodic_y:
        diagonal += g
        neighbours += g * x[i, ny - 1, k]
    else:
        diagonal += 2.0 * g
    g = beta_y[i, j + 1, k] * inverse_hy2
    if j < ny - 1:
        diagonal += g
        neighbours += g * x[i, j + 1, k]
    elif periodic_y:
        diagonal += g
        neighbours += g * x[i, 0, k]
    else:
        diagonal += 2.0 * g
    g = beta_z[i, j, k] * inverse_hz2
    if k > 0:
        diagonal += g
        neighbours += g * x[i, j, k - 1]
    else:
        diagonal += 2.0 * g
    g = beta_z[i, j, k + 1] * inverse_hz2
    if k < nz - 1:
        diagonal += g
        neighbours += g * x[i, j, k + 1]
    else:
        diagonal += 2.0 * g
    return diagonal, neighbours


@kernel
def interior_diagonal_and_neighbour_sum(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2,
                                        inverse_hz2, x, i, j, k, two_dimensional):
    """``diagonal_and_neighbour_sum`` for a cell away from the x and z boundaries and away from the
    y boundaries or in a 2D problem (ny == 1, both y faces on the boundary).

    Why separate: without branches per face the sweeps run three times faster (measured on
    128^3); callers test ``0 < i < nx - 1``, ``0 < j < ny - 1 or ny == 1`` once per row of k.
    """
    gxm = beta_x[i, j, k]
    gxp = beta_x[i + 1, j, k]
    gym = beta_y[i, j, k]
    gyp = beta_y[i, j + 1, k]
    gzm = beta_z[i, j, k]
    gzp = beta_z[i, j, k + 1]
    neighbours = ((gxm * x[i - 1, j, k] + gxp * x[i + 1, j, k]) * inverse_hx2
                  + (gzm * x[i, j, k - 1] + gzp * x[i, j, k + 1]) * inverse_hz2)
    if two_dimensional:
        y_diagonal = 2.0 * (gym + gyp) * inverse_hy2
    else:
        y_diagonal = (gym + gyp) * inverse_hy2
        neighbours += (gym * x[i, j - 1, k] + gyp * x[i, j + 1, k]) * inverse_hy2
    return (gxm + gxp) * inverse_hx2 + y_diagonal + (gzm + gzp) * inverse_hz2, neighbours


@kernel
def interior_row(i, j, shape):
    """True if every cell (i, j, 0 < k < nz - 1) may use ``interior_diagonal_and_neighbour_sum``."""
    return 0 < i < shape[0] - 1 and (0 < j < shape[1] - 1 or shape[1] == 1)


@kernel
def is_active(beta_x, beta_y, beta_z, i, j, k):
    """True if any face of cell (i, j, k) has a non-zero (so positive) coefficient."""
    # Coefficients are non-negative (checked on entry), so a positive sum means one is non-zero.
    return (beta_x[i, j, k] + beta_x[i + 1, j, k] + beta_y[i, j, k] + beta_y[i, j + 1, k]
            + beta_z[i, j, k] + beta_z[i, j, k + 1]) > 0.0


# --------------------------------------------------------------------------------------------------
# Whole-grid operations (parallel over the x index, deterministic)
# --------------------------------------------------------------------------------------------------

@parallel_kernel
def apply_positive_operator(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x,
                            result, periodic_y=False):
    """result = L x = -div(beta grad x) (1/m^2 times the units of beta x)."""
    nx, ny, nz = x.shape
    two_dimensional = ny == 1
    for i in prange(nx):
        for j in range(ny):
            row_is_interior = interior_row(i, j, x.shape)
            for k in range(nz):
                if row_is_interior and 0 < k < nz - 1:
                    diagonal, neighbours = interior_diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                        two_dimensional)
                else:
                    diagonal, neighbours = diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                        periodic_y)
                result[i, j, k] = diagonal * x[i, j, k] - neighbours


@kernel
def is_valid_coefficient(value):
    """True for a finite, non-negative face coefficient (False for NaN)."""
    return 0.0 <= value < np.inf


@parallel_kernel
def copy_coefficients(source, target, row_counts):
    """target = source (face coefficients into level 0); returns how many are negative or not finite.

    ``row_counts`` (at least source.shape[0], 2) int64 is scratch.
    """
    nx, ny, nz = source.shape
    for i in prange(nx):
        invalid = 0
        for j in range(ny):
            for k in range(nz):
                value = source[i, j, k]
                target[i, j, k] = value
                if not is_valid_coefficient(value):
                    invalid += 1
        row_counts[i, 0] = invalid
    total = 0
    for i in range(nx):
        total += row_counts[i, 0]
    return total


@parallel_kernel
def prepare_system(beta_x, beta_y, beta_z, rhs, pressure, system_rhs, row_sums):
    """system_rhs = -rhs and pressure kept on active cells, both 0 on inactive cells.

    Returns (active cells, sum of system_rhs, sum of pressure over the active cells); the sums give
    a closed tank's means. ``row_sums`` (at least nx, 3) is scratch.
    """
    nx, ny, nz = rhs.shape
    for i in prange(nx):
        active = 0
        rhs_sum = 0.0
        pressure_sum = 0.0
        for j in range(ny):
            for k in range(nz):
                if is_active(beta_x, beta_y, beta_z, i, j, k):
                    active += 1
                    system_rhs[i, j, k] = -rhs[i, j, k]
                    rhs_sum -= rhs[i, j, k]
                    pressure_sum += pressure[i, j, k]
                else:
                    system_rhs[i, j, k] = 0.0
                    pressure[i, j, k] = 0.0
        row_sums[i, 0] = active
        row_sums[i, 1] = rhs_sum
        row_sums[i, 2] = pressure_sum
    active_total = 0
    rhs_total = 0.0
    pressure_total = 0.0
    for i in range(nx):
        active_total += int(row_sums[i, 0])
        rhs_total += row_sums[i, 1]
        pressure_total += row_sums[i, 2]
    return active_total, rhs_total, pressure_total


@parallel_kernel
def subtract_on_active(beta_x, beta_y, beta_z, x, value):
    """x -= value on the active cells (removes a closed tank's mean)."""
    nx, ny, nz = x.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                if is_active(beta_x, beta_y, beta_z, i, j, k):
                    x[i, j, k] -= value


@parallel_kernel
def sum_of_entries(x, row_sums):
    """sum of x (inactive cells hold 0, so this is the active-cell sum)."""
    nx, ny, nz = x.shape
    for i in prange(nx):
        total = 0.0
        for j in range(ny):
            for k in range(nz):
                total += x[i, j, k]
        row_sums[i, 0] = total
    total = 0.0
    for i in range(nx):
        total += row_sums[i, 0]
    return total


@parallel_kernel
def dot(a, b, row_sums):
    """sum of a * b."""
    nx, ny, nz = a.shape
    for i in prange(nx):
        total = 0.0
        for j in range(ny):
            for k in range(nz):
                total += a[i, j, k] * b[i, j, k]
        row_sums[i, 0] = total
    total = 0.0
    for i in range(nx):
        total += row_sums[i, 0]
    return total


@parallel_kernel
def compute_residual(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x,
                     residual, row_sums, periodic_y=False):
    """residual = rhs - L x; returns (||residual||_2^2, max |residual|)."""
    nx, ny, nz = x.shape
    two_dimensional = ny == 1
    for i in prange(nx):
        total = 0.0
        largest = 0.0
        for j in range(ny):
            row_is_interior = interior_row(i, j, x.shape)
            for k in range(nz):
                if row_is_interior and 0 < k < nz - 1:
                    diagonal, neighbours = interior_diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                        two_dimensional)
                else:
                    diagonal, neighbours = diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                        periodic_y)
                value = rhs[i, j, k] - (diagonal * x[i, j, k] - neighbours)
                residual[i, j, k] = value
                total += value * value
                largest = max(largest, abs(value))
        row_sums[i, 0] = total
        row_sums[i, 1] = largest
    return _summed_and_largest(row_sums, nx)


@parallel_kernel
def apply_operator_and_dot(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2,
                           direction, product, row_sums, periodic_y=False):
    """product = L direction; returns direction . product (the CG curvature)."""
    nx, ny, nz = direction.shape
    two_dimensional = ny == 1
    for i in prange(nx):
        total = 0.0
        for j in range(ny):
            row_is_interior = interior_row(i, j, direction.shape)
            for k in range(nz):
                if row_is_interior and 0 < k < nz - 1:
                    diagonal, neighbours = interior_diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, direction, i, j, k,
                        two_dimensional)
                else:
                    diagonal, neighbours = diagonal_and_neighbour_sum(
                        beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, direction, i, j,
                        k, periodic_y)
                value = diagonal * direction[i, j, k] - neighbours
                product[i, j, k] = value
                total += value * direction[i, j, k]
        row_sums[i, 0] = total
    total = 0.0
    for i in range(nx):
        total += row_sums[i, 0]
    return total


@parallel_kernel
def step_solution_and_residual(pressure, residual, direction, product, step, row_sums):
    """pressure += step direction, residual -= step product; returns (||residual||_2^2,
    max |residual|)."""
    nx, ny, nz = pressure.shape
    for i in prange(nx):
        total = 0.0
        largest = 0.0
        for j in range(ny):
            for k in range(nz):
                pressure[i, j, k] += step * direction[i, j, k]
                value = residual[i, j, k] - step * product[i, j, k]
                residual[i, j, k] = value
                total += value * value
                largest = max(largest, abs(value))
        row_sums[i, 0] = total
        row_sums[i, 1] = largest
    return _summed_and_largest(row_sums, nx)


@kernel
def _summed_and_largest(row_sums, n):
    """(sum of row_sums[:n, 0] in order, max of row_sums[:n, 1]): the per-slab reductions."""
    total = 0.0
    largest = 0.0
    for i in range(n):
        total += row_sums[i, 0]
        largest = max(largest, row_sums[i, 1])
    return total, largest


@parallel_kernel
def update_direction(direction, preconditioned, weight):
    """direction = preconditioned + weight direction (the CG conjugation)."""
    nx, ny, nz = direction.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                direction[i, j, k] = preconditioned[i, j, k] + weight * direction[i, j, k]


@parallel_kernel
def copy_into(source, target):
    """target = source (same shape)."""
    nx, ny, nz = source.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                target[i, j, k] = source[i, j, k]


# --------------------------------------------------------------------------------------------------
# Multigrid components
# --------------------------------------------------------------------------------------------------

@parallel_kernel
def coarsen_coefficients(fine_beta_x, fine_beta_y, fine_beta_z, coarse_beta_x, coarse_beta_y,
                         coarse_beta_z, factor_x, factor_y, factor_z, fine_first, fine_stop,
                         coarse_first, coarse_stop):
    """Coarse face coefficients: the mean over the fine face slots each coarse face covers.

    Slots outside the fine grid (odd sizes) count as zero faces; the last coarse face along an axis
    takes the fine boundary face, wherever it lies (module docstring). The coarse spacing
    (factor x fine spacing) is applied by the caller through the inverse spacings.

    Along x only the coarse cells coarse_first..coarse_stop-1 (and their faces, both ends
    included) are made, from the fine cells fine_first..fine_stop-1: the whole grid is (0, nx,
    0, cx); a slab of a grid split over processes (``riprap/fluid/slab_pressure.py``) is its own
    cells, between ghost planes.
    """
    ny = fine_beta_x.shape[1]
    nz = fine_beta_x.shape[2]
    cy = coarse_beta_x.shape[1]
    cz = coarse_beta_x.shape[2]
    weight_x = 1.0 / (factor_y * factor_z)
    weight_y = 1.0 / (factor_x * factor_z)
    weight_z = 1.0 / (factor_x * factor_y)
    cx = coarse_stop
    for ci in prange(coarse_first, coarse_stop + 1):
        i_first = fine_first + (ci - coarse_first) * factor_x
        i_stop = min(i_first + factor_x, fine_stop)
        fine_face_x = i_first if ci < cx else fine_stop
        for cj in range(cy + 1):
            j_first = cj * factor_y
            j_stop = min(j_first + factor_y, ny)
            fine_face_y = j_first if cj < cy else ny
            for ck in range(cz + 1):
                k_first = ck * factor_z
                k_stop = min(k_first + factor_z, nz)
                fine_face_z = k_first if ck < cz else nz
                if cj < cy and ck < cz:
                    total = 0.0
                    for j in range(j_first, j_stop):
                        for k in range(k_first, k_stop):
                            total += fine_beta_x[fine_face_x, j, k]
                    coarse_beta_x[ci, cj, ck] = weight_x * total
                if ci < cx and ck < cz:
                    total = 0.0
                    for i in range(i_first, i_stop):
                        for k in range(k_first, k_stop):
                            total += fine_beta_y[i, fine_face_y, k]
                    coarse_beta_y[ci, cj, ck] = weight_y * total
                if ci < cx and cj < cy:
                    total = 0.0
                    for i in range(i_first, i_stop):
                        for j in range(j_first, j_stop):
                            total += fine_beta_z[i, j, fine_face_z]
                    coarse_beta_z[ci, cj, ck] = weight_z * total


@kernel
def _smooth_slab(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour, i,
                 from_zero, periodic_y):
    """Gauss-Seidel on the cells of colour ``colour`` in the x-slab i (from x = 0 there when
    ``from_zero``: rhs / d, without reading the neighbours).

    The interior/boundary branch is written out here as in the other sweeps: moving it into a
    shared helper made the whole solve four times slower (measured on examples/06's problem).
    """
    nx, ny, nz = x.shape
    two_dimensional = ny == 1
    for j in range(ny):
        row_is_interior = interior_row(i, j, x.shape)
        for k in range((i + j + colour) % 2, nz, 2):
            if row_is_interior and 0 < k < nz - 1:
                diagonal, neighbours = interior_diagonal_and_neighbour_sum(
                    beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                    two_dimensional)
            else:
                diagonal, neighbours = diagonal_and_neighbour_sum(
                    beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                    periodic_y)
            if from_zero:
                x[i, j, k] = rhs[i, j, k] / diagonal if diagonal > 0.0 else 0.0
            else:
                x[i, j, k] = (rhs[i, j, k] + neighbours) / diagonal if diagonal > 0.0 else 0.0


@parallel_kernel
def smooth_first_red(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, first,
                     stop, parity, periodic_y=False):
    """The first red sweep from x = 0: red cells rhs / d, black cells 0 (saves zeroing x), on the
    x-slabs first..stop-1; ``parity`` is the global x index of slab 0 mod 2 (0 for a whole grid)."""
    nx, ny, nz = x.shape
    for i in prange(first, stop):
        for j in range(ny):
            for k in range(nz):
                if (i + parity + j + k) % 2 == 1:
                    x[i, j, k] = 0.0
    for i in prange(first, stop):
        _smooth_slab(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, parity,
                     i, True, periodic_y)


@parallel_kernel
def smooth_colour(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour,
                  first, stop, periodic_y=False):
    """One Gauss-Seidel sweep over the cells of x-slabs first..stop-1 with (i + j + k) mod 2 ==
    colour (0 red, 1 black; a slab of a split grid passes its colour shifted by its parity)."""
    for i in prange(first, stop):
        _smooth_slab(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour,
                     i, False, periodic_y)


@kernel
def smooth_colour_serial(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x,
                         colour, first, stop, periodic_y=False):
    """``smooth_colour`` on one thread: on the small coarse levels a parallel launch costs more
    than the sweep (the same result: cells of one colour do not read each other)."""
    for i in range(first, stop):
        _smooth_slab(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour,
                     i, False, periodic_y)


@kernel
def smooth(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour, first,
           stop, periodic_y=False):
    """One colour's sweep over x-slabs first..stop-1, in parallel on levels of at least
    ``PARALLEL_SWEEP_CELLS`` cells."""
    if x.size >= PARALLEL_SWEEP_CELLS:
        smooth_colour(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x, colour,
                      first, stop, periodic_y)
    else:
        smooth_colour_serial(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x,
                             colour, first, stop, periodic_y)


@parallel_kernel
def restrict_red_residual(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, rhs, x,
                          coarse_rhs, factor_x, factor_y, factor_z, fine_first, fine_stop,
                          coarse_first, coarse_stop, parity, periodic_y=False):
    """coarse_rhs = c P^T (rhs - L x), c = 1 / (factor_x factor_y factor_z), after a black sweep.

    The last smoothing sweep solved every black cell's equation, so the black residuals are zero
    (to round-off) and only the red ones are evaluated and summed: the same linear map as summing
    all children, at half the cost. Each thread owns whole coarse x-slabs, so the sums are formed
    in a fixed order. Ranges and ``parity`` as in ``coarsen_coefficients`` and
    ``smooth_first_red``.
    """
    nx, ny, nz = x.shape
    two_dimensional = ny == 1
    scale = 1.0 / (factor_x * factor_y * factor_z)
    for ci in prange(coarse_first, coarse_stop):
        coarse_rhs[ci, :, :] = 0.0
        i_first = fine_first + (ci - coarse_first) * factor_x
        for i in range(i_first, min(i_first + factor_x, fine_stop)):
            for j in range(ny):
                row_is_interior = interior_row(i, j, x.shape)
                cj = j // factor_y
                for k in range((i + parity + j) % 2, nz, 2):
                    if row_is_interior and 0 < k < nz - 1:
                        diagonal, neighbours = interior_diagonal_and_neighbour_sum(
                            beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                            two_dimensional)
                    else:
                        diagonal, neighbours = diagonal_and_neighbour_sum(
                            beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, x, i, j, k,
                            periodic_y)
                    coarse_rhs[ci, cj, k // factor_z] += rhs[i, j, k] - (diagonal * x[i, j, k]
                                                                         - neighbours)
        coarse_rhs[ci, :, :] *= scale


@parallel_kernel
def prolong_correction(coarse_x, x, factor_x, factor_y, factor_z, fine_first, fine_stop,
                       coarse_first):
    """x += P coarse_x: every fine cell gets its coarse cell's correction (piecewise constant), on
    the fine x-slabs fine_first..fine_stop-1 (coarse slab coarse_first holds the first's)."""
    nx, ny, nz = x.shape
    for i in prange(fine_first, fine_stop):
        ci = coarse_first + (i - fine_first) // factor_x
        for j in range(ny):
            cj = j // factor_y
            for k in range(nz):
                x[i, j, k] += coarse_x[ci, cj, k // factor_z]


@kernel
def factor_coarsest(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, factor,
                    periodic_y=False):
    """Banded Cholesky L = F F^T of the coarsest operator, natural order r = (i ny + j) nz + k.

    ``factor`` (n, bandwidth + 1), bandwidth = ny nz: factor[r, t] = F[r, r - t]. Dependent or
    inactive cells (pivot <= PIVOT_TOLERANCE x largest diagonal) get a zero column and pivot, i.e.
    correction 0 (module docstring). Returns the number of pinned active cells. Cost n bandwidth^2.
    """
    nx = beta_y.shape[0]
    ny = beta_x.shape[1]
    nz = beta_x.shape[2]
    n = nx * ny * nz
    bandwidth = ny * nz
    factor[:, :] = 0.0
    # Lower band of L: diagonal, and -g towards the k-1, j-1 and i-1 neighbours.
    dummy = np.zeros((nx, ny, nz))
    largest = 0.0
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                r = (i * ny + j) * nz + k
                diagonal, _ = diagonal_and_neighbour_sum(beta_x, beta_y, beta_z, inverse_hx2,
                                                         inverse_hy2, inverse_hz2, dummy, i, j, k,
                                                         periodic_y)
                factor[r, 0] = diagonal
                largest = max(largest, diagonal)
                if k > 0:
                    factor[r, 1] = -beta_z[i, j, k] * inverse_hz2
                if j > 0:
                    factor[r, nz] = -beta_y[i, j, k] * inverse_hy2
                if periodic_y and j == ny - 1 and ny > 1:
                    # the face ny (face 0) to cell (i, 0, k), (ny - 1) nz rows back: inside the
                    # band (added: with ny = 2 it is the j - 1 neighbour's slot again)
                    factor[r, (ny - 1) * nz] += -beta_y[i, ny, k] * inverse_hy2
                if i > 0:
                    factor[r, bandwidth] = -beta_x[i, j, k] * inverse_hx2
    threshold = PIVOT_TOLERANCE * largest
    pinned = 0
    for r in range(n):
        first = max(0, r - bandwidth)
        for c in range(first, r + 1):
            value = factor[r, r - c]
            for t in range(first, c):
                value -= factor[r, r - t] * factor[c, c - t]
            if c < r:
                pivot = factor[c, 0]
                factor[r, r - c] = value / pivot if pivot > 0.0 else 0.0
            elif value > threshold:
                factor[r, 0] = np.sqrt(value)
            else:
                if factor[r, 0] != 0.0:
                    pinned += 1
                factor[r, 0] = 0.0
    return pinned


@kernel
def solve_coarsest(factor, rhs, x):
    """x = (F F^T)^+ rhs with the banded factor of ``factor_coarsest``; pinned cells get 0."""
    n = factor.shape[0]
    bandwidth = factor.shape[1] - 1
    rhs_flat = rhs.reshape(n)
    x_flat = x.reshape(n)
    for r in range(n):
        value = rhs_flat[r]
        for t in range(max(0, r - bandwidth), r):
            value -= factor[r, r - t] * x_flat[t]
        pivot = factor[r, 0]
        x_flat[r] = value / pivot if pivot > 0.0 else 0.0
    for r in range(n - 1, -1, -1):
        value = x_flat[r]
        for t in range(r + 1, min(n, r + bandwidth + 1)):
            value -= factor[t, t - r] * x_flat[t]
        pivot = factor[r, 0]
        x_flat[r] = value / pivot if pivot > 0.0 else 0.0


@parallel_kernel
def zero_cells(x):
    """x = 0, in parallel."""
    for i in prange(x.shape[0]):
        x[i, :, :] = 0.0


#: Cells of level 0 with extra smoothing (flat indices, red ones first, then black): per cell its
#: six neighbours' flat indices (its own where a face has no neighbour), their couplings g_f
#: (0 across a boundary or wall face) and 1 / d_c (0 for an inactive cell); ``red`` cells first.
ListedCells = namedtuple("ListedCells", ["cells", "neighbours", "couplings", "inverse_diagonal",
                                         "red"])


@parallel_kernel
def listed_stencils(beta_x, beta_y, beta_z, inverse_hx2, inverse_hy2, inverse_hz2, cells,
                    neighbours, couplings, inverse_diagonal, periodic_y=False):
    """Fill the stencils of ``ListedCells`` for ``cells`` (flat indices) from level 0's faces.

    Why stored: a sweep over a list of scattered cells that derives every stencil from the faces
    (index arithmetic and six branches per cell) ran ten times slower per cell than the sweeps
    over the whole grid.
    """
    nx = beta_y.shape[0]
    ny = beta_x.shape[1]
    nz = beta_x.shape[2]
    for m in prange(cells.shape[0]):
        cell = cells[m]
        i = cell // (ny * nz)
        j = (cell // nz) % ny
        k = cell % nz
        faces = (beta_x[i, j, k] * inverse_hx2, beta_x[i + 1, j, k] * inverse_hx2,
                 beta_y[i, j, k] * inverse_hy2, beta_y[i, j + 1, k] * inverse_hy2,
                 beta_z[i, j, k] * inverse_hz2, beta_z[i, j, k + 1] * inverse_hz2)
        inside = (i > 0, i < nx - 1, j > 0, j < ny - 1, k > 0, k < nz - 1)
        steps = (-ny * nz, ny * nz, -nz, nz, -1, 1)
        diagonal = 0.0
        for f in range(6):
            if periodic_y and (f == 2 or f == 3) and not inside[f]:
                # across the periodic y: the cell at the strip's other side
                diagonal += faces[f]
                couplings[m, f] = faces[f]
                neighbours[m, f] = cell + (ny - 1) * nz * (1 if f == 2 else -1)
            elif inside[f]:
                diagonal += faces[f]
                couplings[m, f] = faces[f]
                neighbours[m, f] = cell + steps[f]
            else:
                diagonal += 2.0 * faces[f]
                couplings[m, f] = 0.0
                neighbours[m, f] = cell
        inverse_diagonal[m] = 1.0 / diagonal if diagonal > 0.0 else 0.0


@parallel_kernel
def smooth_listed_cells(listed, rhs, x, first, stop):
    """One Gauss-Seidel sweep over the listed cells first..stop-1 (all of one colour).

    Cells of one colour never neighbour each other, so the parallel sweep is race-free and does not
    depend on the number of threads.
    """
    rhs_flat = rhs.reshape(-1)
    x_flat = x.reshape(-1)
    for m in prange(first, stop):
        total = rhs_flat[listed.cells[m]]
        for f in range(6):
            total += listed.couplings[m, f] * x_flat[listed.neighbours[m, f]]
        x_flat[listed.cells[m]] = total * listed.inverse_diagonal[m]


@kernel
def level_sweeps(sweeps, level):
    """Smoothing sweeps on ``level``: ``sweeps`` on the two finest levels, four times more per level
    below them, at most 16 times (module docstring, "Coarse levels")."""
    if level < 2:
        return sweeps
    return sweeps * min(16, 4 ** (level - 1))


@kernel
def apply_v_cycle(hierarchy, sweeps, listed, listed_sweeps, first_level):
    """corrections[level 0] = B residuals[level 0], B one symmetric V-cycle (module docstring).

    The cells of ``listed`` (``ListedCells``) get ``listed_sweeps`` extra Gauss-Seidel sweeps (red,
    black) before the level's own pre-smoothing and the same in reverse order (black, red) after its
    post-smoothing, which keeps B symmetric (module docstring, "Local smoothing").
    ``first_level``: the level of the whole grid that this hierarchy's level 0 is (0 but for the
    coarse levels a split grid gathers: ``riprap/fluid/slab_pressure.py``), for the sweeps.
    """
    n_levels = hierarchy.shapes.shape[0]
    spacing = hierarchy.inverse_spacing_squared
    periodic = hierarchy.periodic_y
    local = listed_sweeps > 0 and listed.cells.shape[0] > 0
    red, stop = listed.red, listed.cells.shape[0]
    for level in range(n_levels - 1):
        beta_x = face_array(hierarchy.beta_x, hierarchy, level, 0)
        beta_y = face_array(hierarchy.beta_y, hierarchy, level, 1)
        beta_z = face_array(hierarchy.beta_z, hierarchy, level, 2)
        rhs = cell_array(hierarchy.residuals, hierarchy, level)
        x = cell_array(hierarchy.corrections, hierarchy, level)
        hx2, hy2, hz2 = spacing[level, 0], spacing[level, 1], spacing[level, 2]
        first_from_zero = True
        if level == 0 and local:
            zero_cells(x)
            for _ in range(listed_sweeps):
                smooth_listed_cells(listed, rhs, x, 0, red)
                smooth_listed_cells(listed, rhs, x, red, stop)
            first_from_zero = False
        nx = x.shape[0]
        for sweep in range(level_sweeps(sweeps, level + first_level)):
            if sweep == 0 and first_from_zero:
                smooth_first_red(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, 0, nx, 0, periodic)
            else:
                smooth(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, 0, 0, nx, periodic)
            smooth(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, 1, 0, nx, periodic)
        factors = hierarchy.factors[level]
        coarse_rhs = cell_array(hierarchy.residuals, hierarchy, level + 1)
        restrict_red_residual(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, coarse_rhs,
                              factors[0], factors[1], factors[2], 0, nx, 0, coarse_rhs.shape[0], 0,
                              periodic)
    last = n_levels - 1
    solve_coarsest(hierarchy.coarsest_factor, cell_array(hierarchy.residuals, hierarchy, last),
                   cell_array(hierarchy.corrections, hierarchy, last))
    for level in range(n_levels - 2, -1, -1):
        beta_x = face_array(hierarchy.beta_x, hierarchy, level, 0)
        beta_y = face_array(hierarchy.beta_y, hierarchy, level, 1)
        beta_z = face_array(hierarchy.beta_z, hierarchy, level, 2)
        rhs = cell_array(hierarchy.residuals, hierarchy, level)
        x = cell_array(hierarchy.corrections, hierarchy, level)
        hx2, hy2, hz2 = spacing[level, 0], spacing[level, 1], spacing[level, 2]
        factors = hierarchy.factors[level]
        nx = x.shape[0]
        prolong_correction(cell_array(hierarchy.corrections, hierarchy, level + 1), x,
                           factors[0], factors[1], factors[2], 0, nx, 0)
        for sweep in range(level_sweeps(sweeps, level + first_level)):
            smooth(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, 1, 0, nx, periodic)
            smooth(beta_x, beta_y, beta_z, hx2, hy2, hz2, rhs, x, 0, 0, nx, periodic)
        if level == 0 and local:
            for _ in range(listed_sweeps):
                smooth_listed_cells(listed, rhs, x, red, stop)
                smooth_listed_cells(listed, rhs, x, 0, red)


@kernel
def _precondition(hierarchy, sweeps, singular, active_cells, row_sums, listed, listed_sweeps):
    """z = B r in corrections[0] (r in residuals[0]); closed tank: z's active mean removed."""
    apply_v_cycle(hierarchy, sweeps, listed, listed_sweeps, 0)
    z = cell_array(hierarchy.corrections, hierarchy, 0)
    if singular:
        beta_x = face_array(hierarchy.beta_x, hierarchy, 0, 0)
        beta_y = face_array(hierarchy.beta_y, hierarchy, 0, 1)
        beta_z = face_array(hierarchy.beta_z, hierarchy, 0, 2)
        # Inactive cells of z are 0 (zero diagonal on every level), so the plain sum is theirs.
        subtract_on_active(beta_x, beta_y, beta_z, z, sum_of_entries(z, row_sums) / active_cells)


@kernel
def solve_pcg(hierarchy, system_rhs, pressure, direction, product, row_sums, tolerance,
              max_iterations, sweeps, singular, active_cells, listed, listed_sweeps, largest_residual):
    """Preconditioned conjugate gradients for L pressure = system_rhs, from the given pressure.

    Stops when ||r||_2 <= tolerance ||system_rhs||_2 or max |r| <= ``largest_residual`` (> 0;
    0 leaves that test out), with r re-evaluated as system_rhs - L pressure before stopping (CG
    restarts from it if the recurrence had drifted). Returns (iterations, relative residual of
    the returned pressure, its max |r|, outcome code).

    14 arguments: the ``Hierarchy`` bundle, the CG's own work arrays (written) and its settings;
    the work arrays are allocated once per solver, not per solve.
    """
    beta_x = face_array(hierarchy.beta_x, hierarchy, 0, 0)
    beta_y = face_array(hierarchy.beta_y, hierarchy, 0, 1)
    beta_z = face_array(hierarchy.beta_z, hierarchy, 0, 2)
    hx2 = hierarchy.inverse_spacing_squared[0, 0]
    hy2 = hierarchy.inverse_spacing_squared[0, 1]
    hz2 = hierarchy.inverse_spacing_squared[0, 2]
    residual = cell_array(hierarchy.residuals, hierarchy, 0)
    preconditioned = cell_array(hierarchy.corrections, hierarchy, 0)
    periodic = hierarchy.periodic_y

    rhs_norm = np.sqrt(dot(system_rhs, system_rhs, row_sums))
    if not np.isfinite(rhs_norm):
        return 0, np.inf, np.inf, NON_FINITE
    if rhs_norm == 0.0:
        pressure[:, :, :] = 0.0
        return 0, 0.0, 0.0, CONVERGED
    squared, largest = compute_residual(beta_x, beta_y, beta_z, hx2, hy2, hz2, system_rhs,
                                        pressure, residual, row_sums, periodic)
    relative = np.sqrt(squared) / rhs_norm
    if not np.isfinite(relative):
        return 0, relative, largest, NON_FINITE
    iterations = 0
    restart = True
    curvature_product = 0.0
    while (relative > tolerance and largest > largest_residual
           and iterations < max_iterations):
        _precondition(hierarchy, sweeps, singular, active_cells, row_sums, listed,
                      listed_sweeps)
        new_product = dot(residual, preconditioned, row_sums)
        if not np.isfinite(new_product):
            return iterations, relative, largest, NON_FINITE
        if restart:
            copy_into(preconditioned, direction)
            restart = False
        else:
            update_direction(direction, preconditioned, new_product / curvature_product)
        curvature_product = new_product
        curvature = apply_operator_and_dot(beta_x, beta_y, beta_z, hx2, hy2, hz2, direction,
                                           product, row_sums, periodic)
        if not np.isfinite(curvature):
            return iterations, relative, largest, NON_FINITE
        if curvature <= 0.0 or curvature_product <= 0.0:
            return iterations, relative, largest, BREAKDOWN
        iterations += 1
        squared, largest = step_solution_and_residual(
            pressure, residual, direction, product, curvature_product / curvature, row_sums)
        relative = np.sqrt(squared) / rhs_norm
        if not np.isfinite(relative):
            return iterations, relative, largest, NON_FINITE
        if relative <= tolerance or largest <= largest_residual:
            # Confirm with the true residual; restart from it if the recurrence has drifted.
            squared, largest = compute_residual(beta_x, beta_y, beta_z, hx2, hy2, hz2,
                                                system_rhs, pressure, residual, row_sums, periodic)
            relative = np.sqrt(squared) / rhs_norm
            restart = True
    if singular:
        subtract_on_active(beta_x, beta_y, beta_z, pressure,
                           sum_of_entries(pressure, row_sums) / active_cells)
    if relative <= tolerance or largest <= largest_residual:
        return iterations, relative, largest, CONVERGED
    return iterations, relative, largest, NOT_CONVERGED
