"""PLIC volume-of-fluid kernels (``riprap.fluid.kernels.plic``): plane/volume relations of
Scardovelli & Zaleski (2000, J. Comput. Phys. 164: 228), the mixed Youngs-centred normal of
Aulisa et al. (2007, J. Comput. Phys. 225: 2301) and the conservative split advection of
Weymouth & Yue (2010, J. Comput. Phys. 229: 2853).

References used: the exact volume of a half-space clipped to a box (convex hull of the clipped
box's vertices, an independent computation), exact conservation and boundedness of the
Weymouth & Yue scheme for discretely divergence-free velocities at Courant numbers <= 1/2
(their stability analysis), exact translation of a shape by whole cells, and exactness of a flat
interface.
Each test names its quantity and tolerance.
"""
import math

import numba
import numpy as np
import pytest
from scipy.spatial import ConvexHull

from riprap.errors import InstabilityError
from riprap.fluid.kernels.plic import (CLIP_TOLERANCE, advect, advect_sweep, interface_normal,
                                       plane_constant, plane_volume, rectangle_volume)

# plane_constant and plane_volume are closed forms; composed they lose a few ulps (measured
# worst 1.7e-15 over 2e5 random cases, including components 1e-14 of the others).
INVERSE_TOLERANCE = 1e-12
# Convex-hull volumes of the clipped box are sums of ~10 tetrahedra of size <= 1: round-off 1e-15.
EXACT_VOLUME_TOLERANCE = 1e-12
# Mass: the flux differences telescope and the dilation terms cancel to round-off per cell and
# sweep (~1e-16 of a cell); over a few thousand cell updates that stays far below this.
MASS_TOLERANCE = 1e-12
# The scheme is bounded for Courant <= 1/2; what remains is round-off (clipped below this).
BOUND_TOLERANCE = CLIP_TOLERANCE


def _clipped_box_volume(normal, alpha, lower, size):
    """Volume of {x in box : normal . x <= alpha} from the convex hull of the box corners inside
    and the points where the plane cuts the box edges: independent of Scardovelli & Zaleski."""
    lower = np.asarray(lower, float)
    size = np.asarray(size, float)
    corners = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)], float)
    corners = lower + corners * size
    values = corners @ normal - alpha
    points = [corners[values <= 0.0]]
    for first in range(8):
        for second in range(first + 1, 8):
            if np.count_nonzero(corners[first] != corners[second]) != 1:
                continue          # not an edge
            if values[first] * values[second] < 0.0:
                t = values[first] / (values[first] - values[second])
                points.append((corners[first] + t * (corners[second] - corners[first]))[None])
    points = np.concatenate(points)
    if len(points) < 4:
        return 0.0
    return ConvexHull(points).volume


def _random_normal(rng):
    """A random normal, with zero, tiny or equal components part of the time (2D planes, nearly
    axis-aligned planes, the symmetric branches of the inversion)."""
    normal = rng.normal(size=3)
    choice = rng.random()
    if choice < 0.15:
        normal[rng.integers(3)] = 0.0
    elif choice < 0.25:
        normal[rng.integers(3)] *= 10.0 ** rng.uniform(-14, -4)
    elif choice < 0.3:
        normal[rng.permutation(3)[:2]] = 0.0
    elif choice < 0.4:
        normal[1] = normal[0] * (1.0 + rng.choice([0.0, 1e-14, 1e-8]))
    return normal


def test_plane_constant_inverts_plane_volume():
    """plane_volume(n, plane_constant(n, V)) == V to 1e-12 for 20 000 random normals (any signs,
    zero, tiny and equal components) and volumes (uniform, plus 0, 1, 1/2 and 1e-14 from them)."""
    rng = np.random.default_rng(11)
    worst = 0.0
    for _ in range(20000):
        normal = _random_normal(rng)
        volume = rng.random()
        if rng.random() < 0.1:
            volume = float(rng.choice([0.0, 1.0, 0.5, 1e-14, 1.0 - 1e-14, 0.5 + 1e-13]))
        alpha = plane_constant(normal[0], normal[1], normal[2], volume)
        worst = max(worst, abs(plane_volume(normal[0], normal[1], normal[2], alpha) - volume))
    assert worst < INVERSE_TOLERANCE


def test_plane_volume_matches_exact_clipped_cube():
    """plane_volume against the convex-hull volume of the cube clipped by the plane (exact to
    round-off), 300 random planes with every number of cut corners; tolerance 1e-12."""
    rng = np.random.default_rng(12)
    worst = 0.0
    for _ in range(300):
        normal = _random_normal(rng)
        alpha = normal @ rng.random(3)
        exact = _clipped_box_volume(normal, alpha, (0, 0, 0), (1, 1, 1))
        worst = max(worst, abs(plane_volume(normal[0], normal[1], normal[2], alpha) - exact))
    assert worst < EXACT_VOLUME_TOLERANCE


def test_plane_through_centre_halves_the_cube():
    """Symmetry V(a) = 1 - V(1 - a) of S&Z 2000: any plane through the cube centre leaves volume
    1/2 (to 1e-14) and plane_constant(n, 1/2) = n . (1/2, 1/2, 1/2) (to 1e-14 of |n|)."""
    rng = np.random.default_rng(13)
    for _ in range(2000):
        normal = _random_normal(rng)
        centre_alpha = 0.5 * normal.sum()
        assert abs(plane_volume(normal[0], normal[1], normal[2], centre_alpha) - 0.5) < 1e-14
        alpha = plane_constant(normal[0], normal[1], normal[2], 0.5)
        assert abs(alpha - centre_alpha) < 1e-14 * np.abs(normal).sum()


def test_rectangle_volume_matches_exact_clipped_box():
    """rectangle_volume (fraction of a sub-box below the plane) times the box volume against the
    convex-hull volume of the clipped sub-box; 300 random planes and slabs like those of the
    sweeps (one side 0.01-0.5 thick at either face) and random sub-boxes; tolerance 1e-12."""
    rng = np.random.default_rng(14)
    worst = 0.0
    for trial in range(300):
        normal = _random_normal(rng)
        alpha = normal @ rng.random(3)
        if trial % 2 == 0:
            axis = rng.integers(3)
            size = np.ones(3)
            size[axis] = rng.uniform(0.01, 0.5)
            lower = np.zeros(3)
            if rng.random() < 0.5:
                lower[axis] = 1.0 - size[axis]
        else:
            lower = rng.uniform(0.0, 0.5, 3)
            size = rng.uniform(0.05, 0.5, 3)
        fraction = rectangle_volume(normal[0], normal[1], normal[2], alpha, *lower, *size)
        exact = _clipped_box_volume(normal, alpha, lower, size)
        worst = max(worst, abs(fraction * size.prod() - exact))
    assert worst < EXACT_VOLUME_TOLERANCE


def _plane_fractions(normal, alpha, shape):
    """Exact cell fractions of {n . x <= alpha} on a block of unit cells (x in cell units)."""
    fractions = np.zeros(shape)
    for i in range(shape[0]):
        for j in range(shape[1]):
            for k in range(shape[2]):
                fractions[i, j, k] = plane_volume(normal[0], normal[1], normal[2],
                                                  alpha - normal @ np.array([i, j, k], float))
    return fractions


def _angle_deg(first, second):
    first = np.asarray(first) / np.linalg.norm(first)
    second = np.asarray(second) / np.linalg.norm(second)
    return math.degrees(math.acos(min(1.0, abs(first @ second)))) if first @ second > 0 else 180.0


def test_interface_normal_of_planes_3d_and_2d():
    """Mixed Youngs-centred normal of exact plane data (Aulisa et al. 2007): a planar interface
    through the centre cell of a 3x3x3 (or 3x1x3) block, 300 random planes each. Measured: 3D mean
    0.1 deg, worst 1.0 deg (Youngs alone: mean 1.3, worst 3.5); 2D mean 0.02 deg, worst 0.55.
    Asserted: 3D mean < 0.3 and worst < 2 deg; 2D mean < 0.1 and worst < 1 deg; the normal
    points from water to air (angle < 90 deg), and the 1-norm of the normal is 1."""
    rng = np.random.default_rng(15)
    for shape, mean_limit, worst_limit in (((3, 3, 3), 0.3, 2.0), ((3, 1, 3), 0.1, 1.0)):
        angles = []
        while len(angles) < 300:
            normal = rng.normal(size=3)
            point = np.array([1.5, 0.5, 1.5]) + rng.uniform(-0.5, 0.5, 3)
            if shape[1] == 1:
                normal[1] = 0.0
            else:
                point[1] = 1.5 + rng.uniform(-0.5, 0.5)
            fractions = _plane_fractions(normal, normal @ point, shape)
            centre = (1, shape[1] // 2, 1)
            if not 0.0 < fractions[centre] < 1.0:
                continue
            result = interface_normal(fractions, *centre)
            assert abs(sum(abs(c) for c in result) - 1.0) < 1e-14
            angles.append(_angle_deg(result, normal))
        assert np.mean(angles) < mean_limit and max(angles) < worst_limit


# --------------------------------------------------------------------------------------------
# Advection
# --------------------------------------------------------------------------------------------

def _ball_fractions(shape, centre, radius, samples=6):
    """Cell fractions of a ball (disc if ny == 1, a cylinder along y) by sampling each cell on a
    samples^3 grid (cell units)."""
    nx, ny, nz = shape
    offsets = (np.arange(samples) + 0.5) / samples
    x = (np.arange(nx)[:, None] + offsets[None, :]).reshape(-1)
    z = (np.arange(nz)[:, None] + offsets[None, :]).reshape(-1)
    if ny == 1:
        inside = ((x[:, None] - centre[0]) ** 2 + (z[None, :] - centre[2]) ** 2 <= radius ** 2)
        return inside.reshape(nx, samples, nz, samples).mean(axis=(1, 3))[:, None, :]
    y = (np.arange(ny)[:, None] + offsets[None, :]).reshape(-1)
    inside = ((x[:, None, None] - centre[0]) ** 2 + (y[None, :, None] - centre[1]) ** 2
              + (z[None, None, :] - centre[2]) ** 2 <= radius ** 2)
    return inside.reshape(nx, samples, ny, samples, nz, samples).mean(axis=(1, 3, 5))


def _uniform_velocities(shape, velocity):
    nx, ny, nz = shape
    return (np.full((nx + 1, ny, nz), float(velocity[0])),
            np.full((nx, ny + 1, nz), float(velocity[1])),
            np.full((nx, ny, nz + 1), float(velocity[2])))


def _vortex_velocities(shape, h):
    """Discretely divergence-free face velocities (m/s) in the closed box [0, n h]: the single
    vortex stream function psi = sin^2(pi x / L) sin^2(pi z / L) L / pi (LeVeque 1996) on the cell
    corners, u = dpsi/dz, w = -dpsi/dx by differences of corner values, so the cell divergence
    cancels term by term; psi = 0 on the walls gives zero normal velocity there. In 3D the x-z
    vortex is modulated along y and a second y-z vortex (modulated along x) is added; each is
    divergence-free on its own."""
    nx, ny, nz = shape
    length_x, length_z = nx * h, nz * h
    x_nodes = np.arange(nx + 1) * h
    z_nodes = np.arange(nz + 1) * h
    x_cells = (np.arange(nx) + 0.5) * h
    psi_xz = (np.sin(np.pi * x_nodes / length_x)[:, None] ** 2
              * np.sin(np.pi * z_nodes / length_z)[None, :] ** 2 * length_x / np.pi)
    u = np.zeros((nx + 1, ny, nz))
    v = np.zeros((nx, ny + 1, nz))
    w = np.zeros((nx, ny, nz + 1))
    if ny == 1:
        modulation = np.ones(1)
    else:
        y_cells = (np.arange(ny) + 0.5) * h
        modulation = 1.0 + 0.5 * np.sin(2.0 * np.pi * y_cells / (ny * h))
    psi = psi_xz[:, None, :] * modulation[None, :, None]          # (nx+1, ny, nz+1)
    u += (psi[:, :, 1:] - psi[:, :, :-1]) / h
    w += -(psi[1:, :, :] - psi[:-1, :, :]) / h
    if ny > 1:
        length_y = ny * h
        y_nodes = np.arange(ny + 1) * h
        psi_yz = (np.sin(np.pi * y_nodes / length_y)[:, None] ** 2
                  * np.sin(np.pi * z_nodes / length_z)[None, :] ** 2 * length_y / np.pi)
        modulation = 1.0 + 0.5 * np.cos(2.0 * np.pi * x_cells / length_x)
        psi = psi_yz[None, :, :] * modulation[:, None, None]
        v += (psi[:, :, 1:] - psi[:, :, :-1]) / h
        w += -(psi[:, 1:, :] - psi[:, :-1, :]) / h
    return u, v, w


def _run(fractions, u, v, w, dt, h, steps, start=0):
    """Advect ``steps`` steps; returns the largest overshoot seen."""
    largest = 0.0
    for step in range(start, start + steps):
        largest = max(largest, advect(fractions, u, v, w, dt, h, step).largest_overshoot)
    return largest


H = 0.01   # cell side (m) of the advection tests


@pytest.mark.parametrize("shape, velocity", [((40, 1, 40), (0.3, 0.0, -0.2)),
                                             ((24, 24, 24), (0.3, -0.2, 0.25))])
def test_advect_uniform_diagonal_flow_conserves_and_bounds(shape, velocity):
    """A ball (disc in 2D) of radius 5 cells in a uniform diagonal flow (Courant 0.3 / 0.2 / 0.25
    per axis), 40 steps (2D) or 24 (3D), centred on the box centre at mid-run and at least 3
    cells from the sides throughout: water volume unchanged to a relative 1e-12 (boundary faces
    carry air in and out), 0 <= f <= 1 to 1e-12 after every sweep (largest overshoot before
    clipping reported by the kernel)."""
    steps = 40 if shape[1] == 1 else 24
    travel = steps * np.array(velocity)
    centre = 0.5 * np.array(shape, float) - 0.5 * travel
    fractions = _ball_fractions(shape, centre, 5.0)
    initial_volume = fractions.sum()
    dt = 1.0
    u, v, w = _uniform_velocities(shape, np.array(velocity) * H / dt)
    overshoot = _run(fractions, u, v, w, dt, H, steps)
    assert overshoot < BOUND_TOLERANCE
    assert fractions.min() >= 0.0 and fractions.max() <= 1.0
    assert abs(fractions.sum() - initial_volume) < MASS_TOLERANCE * initial_volume


@pytest.mark.parametrize("shape, steps", [((64, 1, 64), 120), ((24, 24, 24), 30)])
def test_advect_vortex_flow_conserves_and_bounds(shape, steps):
    """A ball (radius 0.15 L) in the divergence-free single-vortex shear flow of
    ``_vortex_velocities`` (3D: two crossed, modulated vortices), Courant 0.5 (the limit), forward
    ``steps`` steps then back as many with the reversed velocity, in a closed box: water volume
    unchanged to a relative 1e-12, no fraction outside [0, 1] by more than 1e-12 before clipping,
    and the shape returns (L1 error: |f - f_initial| summed over cells, over the initial water
    volume in cells; measured 0.017 in 2D (64^2) and 0.062 in 3D (24^3); asserted < 0.03 and
    < 0.1)."""
    n = shape[0]
    u, v, w = _vortex_velocities(shape, H)
    speed = max(np.abs(u).max(), np.abs(v).max(), np.abs(w).max())
    dt = 0.5 * H / speed
    fractions = _ball_fractions(shape, (0.5 * n, 0.5 * shape[1], 0.72 * n), 0.15 * n)
    initial = fractions.copy()
    overshoot = _run(fractions, u, v, w, dt, H, steps)
    overshoot = max(overshoot, _run(fractions, -u, -v, -w, dt, H, steps, start=steps))
    assert overshoot < BOUND_TOLERANCE
    assert abs(fractions.sum() - initial.sum()) < MASS_TOLERANCE * initial.sum()
    shape_error = np.abs(fractions - initial).sum() / initial.sum()
    assert shape_error < (0.03 if shape[1] == 1 else 0.1), shape_error


@pytest.mark.parametrize("kind", ["disc", "square"])
def test_advect_translation_by_whole_cells_returns_the_shape(kind):
    """2D disc (radius 6 cells) or square (12 cells, edges on cell faces) moved by a uniform
    velocity of (0.25, 0.125) cells per step for 64 steps, i.e. exactly 16 cells in x and 8 in z,
    compared with the same shape drawn 16 and 8 cells further: L1 error (sum of |f - f_exact| over
    the water volume, in cells) measured 0.0077 (disc) and 0.049 (square: PLIC rounds its four
    corners, each losing ~0.8 of a cell to its sides; along x alone the square comes back within
    0.005), asserted < 0.015 (disc) and < 0.07 (square); volume to a relative 1e-12."""
    shape = (48, 1, 40)
    if kind == "disc":
        fractions = _ball_fractions(shape, (12.3, 0.5, 12.7), 6.0)
        expected = _ball_fractions(shape, (28.3, 0.5, 20.7), 6.0)
    else:
        fractions = np.zeros(shape)
        fractions[6:18, 0, 6:18] = 1.0
        expected = np.zeros(shape)
        expected[22:34, 0, 14:26] = 1.0
    initial_volume = fractions.sum()
    dt = 1.0
    u, v, w = _uniform_velocities(shape, np.array([0.25, 0.0, 0.125]) * H / dt)
    assert _run(fractions, u, v, w, dt, H, 64) < BOUND_TOLERANCE
    assert abs(fractions.sum() - initial_volume) < MASS_TOLERANCE * initial_volume
    error = np.abs(fractions - expected).sum() / expected.sum()
    assert error < (0.015 if kind == "disc" else 0.07), error


@pytest.mark.parametrize("shape, velocity", [((32, 1, 8), (0.3, 0.0, 0.0)),
                                             ((16, 16, 6), (0.3, 0.2, 0.0))])
def test_advect_flat_interface_stays_exactly_flat(shape, velocity):
    """A flat horizontal interface (water below, the interface layer 0.3 full) in a uniform flow
    along it, open side boundaries (air flows in at the upstream sides, as the kernel assumes
    outside the domain): beyond the cells the inflowing air can reach in 6 steps (2 cells per
    step, counted from the upstream sides) every fraction is bit-for-bit unchanged, i.e. the
    reconstructed plane is exactly flat and the fluxes through the two faces of a cell cancel."""
    fractions = np.zeros(shape)
    fractions[:, :, :2] = 1.0
    fractions[:, :, 2] = 0.3
    initial = fractions.copy()
    dt = 1.0
    u, v, w = _uniform_velocities(shape, np.array(velocity) * H / dt)
    steps = 6
    reach = 2 * steps + 1
    assert _run(fractions, u, v, w, dt, H, steps) < BOUND_TOLERANCE
    if shape[1] == 1:
        untouched = (slice(reach, None), slice(None), slice(None))
    else:
        untouched = (slice(reach, None), slice(reach, None), slice(None))
    assert np.array_equal(fractions[untouched], initial[untouched])
    # the upstream cells did change (air came in), so the comparison above is not empty
    assert not np.array_equal(fractions, initial)


def test_advect_full_and_empty_regions_stay_exactly_full_and_empty():
    """Away from the interface the water stays exactly 1 and the air exactly 0 (no round-off
    flotsam, so those cells keep the cheap path without a plane reconstruction): a half-filled
    2D box (interface on a cell face) in the vortex flow at Courant 0.5, 8 steps; every cell more
    than 8 + 2 layers below (above) the initial interface is bit-for-bit 1.0 (0.0)."""
    shape = (64, 1, 64)
    u, v, w = _vortex_velocities(shape, H)
    dt = 0.5 * H / max(np.abs(u).max(), np.abs(w).max())
    fractions = np.zeros(shape)
    fractions[:, :, :32] = 1.0
    steps = 8
    assert _run(fractions, u, v, w, dt, H, steps) < BOUND_TOLERANCE
    assert np.all(fractions[:, :, :32 - steps - 2] == 1.0)
    assert np.all(fractions[:, :, 32 + steps + 2:] == 0.0)
    assert np.count_nonzero((fractions > 0.0) & (fractions < 1.0)) > 0      # the interface moved


def test_advect_water_fluxes_are_the_volumes_used():
    """The returned face volumes explain the change of every cell: for a divergence-free
    velocity the dilation terms sum to zero over the sweeps, so f_new - f_old = -(sum over axes
    of the flux differences) / h^3 to round-off (1e-14), in the 3D vortex flow; and one sweep
    alone matches its update formula (with the dilation term) to 1e-15."""
    shape = (16, 16, 16)
    u, v, w = _vortex_velocities(shape, H)
    dt = 0.4 * H / max(np.abs(u).max(), np.abs(v).max(), np.abs(w).max())
    fractions = _ball_fractions(shape, (8.0, 8.0, 11.0), 3.5)
    before = fractions.copy()
    result = advect(fractions, u, v, w, dt, H, 1)
    divergence = (np.diff(result.water_flux_x, axis=0) + np.diff(result.water_flux_y, axis=1)
                  + np.diff(result.water_flux_z, axis=2))
    assert np.abs(fractions - before + divergence / H ** 3).max() < 1e-14
    assert np.abs(result.water_flux_x).max() > 0.0 and np.abs(result.water_flux_z).max() > 0.0

    fractions = before.copy()
    indicator = (fractions > 0.5).astype(float)
    flux = np.zeros_like(w)
    advect_sweep(fractions, w, indicator, dt, H, 2, flux, np.ones_like(fractions), False)
    expected = (before - np.diff(flux, axis=2) / H ** 3
                + indicator * dt / H * np.diff(w, axis=2))
    assert np.abs(fractions - np.clip(expected, 0.0, 1.0)).max() < 1e-15


def test_advect_open_top_mass_changes_by_the_boundary_flux():
    """Water leaving through the open top: the 2D disc crosses the top face in a uniform upward
    flow (air enters at the bottom); the volume lost equals the water volume flux through the top
    faces summed over the steps, to a relative 1e-12."""
    shape = (24, 1, 24)
    fractions = _ball_fractions(shape, (12.0, 0.5, 17.0), 5.0)
    initial_volume = fractions.sum() * H ** 3
    dt = 1.0
    u, v, w = _uniform_velocities(shape, np.array([0.0, 0.0, 0.4]) * H / dt)
    left_through_top = 0.0
    for step in range(20):
        result = advect(fractions, u, v, w, dt, H, step)
        left_through_top += result.water_flux_z[:, :, -1].sum()
        assert result.largest_overshoot < BOUND_TOLERANCE
    assert left_through_top > 0.3 * initial_volume
    remaining = fractions.sum() * H ** 3
    assert abs(remaining + left_through_top - initial_volume) < MASS_TOLERANCE * initial_volume


def test_advect_result_does_not_depend_on_thread_count():
    """Same 3D vortex advection on 1 thread and on all threads: bit-for-bit equal fractions and
    fluxes (each face and cell is written by one iteration only, no reductions over floats)."""
    shape = (16, 12, 14)
    u, v, w = _vortex_velocities(shape, H)
    dt = 0.5 * H / max(np.abs(u).max(), np.abs(v).max(), np.abs(w).max())
    start = _ball_fractions(shape, (8.0, 6.0, 9.0), 4.0)
    results = []
    threads = numba.get_num_threads()
    try:
        for count in (1, threads):
            numba.set_num_threads(count)
            fractions = start.copy()
            fluxes = [advect(fractions, u, v, w, dt, H, step) for step in range(6)]
            results.append((fractions, fluxes[-1]))
    finally:
        numba.set_num_threads(threads)
    assert np.array_equal(results[0][0], results[1][0])
    for axis in range(3):
        assert np.array_equal(results[0][1][axis], results[1][1][axis])


def test_advect_refuses_courant_number_above_one_half():
    """Weymouth & Yue's bound: max |u| dt / h = 0.6 > 1/2 raises InstabilityError naming the
    Courant number; the fractions are left untouched."""
    shape = (8, 1, 8)
    fractions = _ball_fractions(shape, (4.0, 0.5, 4.0), 2.0)
    before = fractions.copy()
    u, v, w = _uniform_velocities(shape, (0.0, 0.0, 0.6 * H))
    with pytest.raises(InstabilityError, match="0.6"):
        advect(fractions, u, v, w, 1.0, H, 0)
    assert np.array_equal(fractions, before)
