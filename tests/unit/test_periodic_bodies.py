"""Rigid bodies across a periodic side boundary (issue 53, item 2): ``SolidSolver.set_periodic``.

What leaves the strip [lower, upper) along y comes back at its other end, and every pair of
bodies is seen by minimum image (``riprap/solid/kernels/periodic.py``). The checks compare a
scene across the boundary with the same scene shifted to the middle of the strip (or with the
same body never wrapped), so the only differences are the round-off of coordinates that differ
by a period; each test states its tolerance and what was measured.

Cubes of side 0.1 m (bounding radius 0.0866 m, so the shortest period allowed is 0.346 m) in a
strip y in [0, 0.4) m.
"""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from riprap.errors import CaseFileError, OverlapError
from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver
from riprap.solid.stability import _contact_rates

ROOT = Path(__file__).resolve().parents[2]
LOWER, UPPER = 0.0, 0.4
PERIOD = UPPER - LOWER
SIDE = 0.1
#: the middle of the strip is this far from the boundary pair's place along y (m)
SHIFT = 0.2


@pytest.fixture(scope="module")
def cube():
    return RigidShape.from_mesh(shapes.cube(side=SIDE, mesh_size=0.05))


def _solver(cube, *, gravity=(0.0, 0.0, 0.0), periodic=True, time_step=None):
    solver = SolidSolver(gravity=gravity)
    solver.add_shape(cube)
    solver.add_material(Material(name="concrete", density=2400.0, friction_coefficient=0.3,
                                 restitution=0.3, contact_penalty=1e7))
    if periodic:
        solver.set_periodic(1, LOWER, UPPER)
    solver.time_step = time_step
    return solver


def _turn(angle, axis):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[np.cos(0.5 * angle)], np.sin(0.5 * angle) * axis])


def _wrapped_gap(a, b):
    """a - b along y by minimum image (m)."""
    d = a - b
    return d - PERIOD * np.floor(d / PERIOD + 0.5)


# ---------------------------------------------------------------------------------- 1. flight
def test_free_cube_crossing_the_boundary_keeps_its_motion(cube):
    """A spinning cube in free flight (no gravity) crosses y = upper twice as fast as it moves in
    x: its centre is wrapped into [lower, upper) after each drift, and it equals the never-wrapped
    twin's (same cube, no periodic axis) minus the period along y to 1e-12 m (measured 8e-15:
    the drift adds v dt to a coordinate that differs by L), x and z bit for bit; velocity,
    angular momentum and orientation are bit for bit the twin's (wrapping touches none), so
    momentum and spin are kept exactly, as in flight."""
    start = dict(shape=0, material="concrete", position=(0.1, 0.35, 0.2),
                 orientation=_turn(0.4, (1.0, 2.0, 3.0)), velocity=(0.3, 2.0, -0.1),
                 angular_velocity=(1.0, 2.0, 3.0))
    wrapped = _solver(cube, time_step=1e-4)
    free = _solver(cube, periodic=False, time_step=1e-4)
    wrapped.add_body(**start)
    free.add_body(**start)
    wrapped.finalize()
    momentum = wrapped.masses[0] * wrapped.velocities[0]
    spin = wrapped.angular_momenta[0].copy()
    crossed, worst = False, 0.0
    for _ in range(10):
        wrapped.advance(60)
        free.advance(60)
        assert LOWER <= wrapped.positions[0, 1] < UPPER
        crossed |= free.positions[0, 1] >= UPPER
        expected_y = free.positions[0, 1] - (PERIOD if free.positions[0, 1] >= UPPER else 0.0)
        worst = max(worst, abs(wrapped.positions[0, 1] - expected_y))
        assert abs(wrapped.positions[0, 1] - expected_y) < 1e-12
        assert wrapped.positions[0, 0] == free.positions[0, 0]
        assert wrapped.positions[0, 2] == free.positions[0, 2]
        for name in ("velocities", "angular_momenta", "quaternions"):
            assert np.array_equal(getattr(wrapped, name), getattr(free, name)), name
    print(f"worst difference along y: {worst:.3g} m")
    assert crossed, "the cube never crossed the boundary: the test did not test the wrap"
    assert np.array_equal(wrapped.masses[0] * wrapped.velocities[0], momentum)
    assert np.array_equal(wrapped.angular_momenta[0], spin)


# ---------------------------------------------------------------------------------- 2. a pair
def _pressed_pair(cube, y_a):
    """Two turned cubes, A at ``y_a`` and B below it along y, overlapping by 2 mm (A's -y face
    into B's +y face), offset in x and z and moving against each other, so that the pair has a
    normal force, damping, a tangential force and torques about both centres."""
    solver = _solver(cube, time_step=1e-5)
    y_b = y_a - (SIDE - 0.002)
    solver.add_body(shape=0, material="concrete", position=(0.0, y_a, 0.3),
                    orientation=_turn(0.03, (1.0, 0.5, 0.2)), velocity=(0.05, -0.02, 0.03),
                    angular_velocity=(0.3, -0.2, 0.1))
    solver.add_body(shape=0, material="concrete", position=(0.01, y_b, 0.31),
                    orientation=_turn(-0.02, (0.3, 1.0, -0.4)), velocity=(-0.04, 0.01, 0.0))
    solver.finalize()
    return solver


def _pair_results(solver):
    c = solver.contacts
    assert len(c) == 1 and (c.body_i[0], c.body_j[0]) == (0, 1)
    return {"forces": solver.forces.copy(), "torques": solver.torques.copy(),
            "normal": c.normal_forces[0].copy(), "tangential": c.tangential_forces[0].copy(),
            "point": c.points[0].copy(), "stiffness": c.stiffness[0],
            "rate": _contact_rates(solver).copy()}


def _relative_difference(a, b):
    scale = max(np.abs(a).max(), np.abs(b).max())
    return float(np.abs(a - b).max() / scale)


def test_pair_across_the_boundary_is_the_pair_in_the_middle(cube):
    """A pressed pair through the boundary (A at y = 0.03, B's centre at 0.332, a period away
    from A's image) against the same pair shifted to the middle (A at 0.23, B at 0.132): the
    forces and torques of both bodies (each about its own centre), the contact's normal and
    tangential forces, its stiffness and its stability rate (whose lever arms are taken by
    minimum image) agree to 1e-9 of their largest magnitude (measured 4e-17 at the start and
    2e-14 after the steps: the contact is computed from the relative pose, and the poses differ
    by the round-off of a period); the contact point lies beside A, the middle pair's point
    moved by the same shift, to 1e-12 m. Compared at the first evaluation and again 20 steps
    (0.2 ms) later, the cubes pushed apart but still in contact."""
    across = _pressed_pair(cube, 0.03)
    middle = _pressed_pair(cube, 0.03 + SHIFT)
    assert across.positions[1, 1] > 0.3         # B wrapped to the strip's other end
    for _ in range(2):
        got, want = _pair_results(across), _pair_results(middle)
        assert np.abs(got["normal"]).max() > 1.0 and np.abs(got["tangential"]).max() > 0.0
        for name in ("forces", "torques", "normal", "tangential", "rate"):
            assert _relative_difference(got[name], want[name]) < 1e-9, name
        assert abs(got["stiffness"] - want["stiffness"]) < 1e-9 * want["stiffness"]
        assert np.abs(got["point"] - (want["point"] - (0.0, SHIFT, 0.0))).max() < 1e-12
        across.advance(20)
        middle.advance(20)


def test_coincident_bodies_across_the_boundary_are_refused(cube):
    """Two cubes at y = 0.0005 and 0.3999 m: 0.6 mm apart through the boundary, they occupy the
    same place and are refused as a pair of coincident bodies, as inside the strip (their
    potential forces cancel, so the overlap test cannot see them)."""
    solver = _solver(cube, time_step=1e-5)
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.0005, 0.3))
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.3999, 0.3))
    solver.finalize()
    with pytest.raises(OverlapError, match="bodies 0 and 1"):
        solver.check_no_initial_overlap(1.0)


# ---------------------------------------------------------------------------------- 3. sliding
def _sliding_pair(cube, shift):
    """Two cubes side by side in x, pressed 0.2 mm into each other by frictionless walls at
    x = -0.0999 and 0.0999 m, on a floor (friction 0.3), sliding in +y at 1.0 and 0.9 m/s: the
    pair's friction (0.3) soon makes them slide together with a loaded tangential spring. A
    (1 cm ahead) crosses y = upper first, B after it, so that for a while the pair straddles the
    boundary. ``shift`` moves the start along y."""
    solver = _solver(cube, gravity=(0.0, 0.0, -9.81))
    solver.add_material(Material(name="glass", density=2400.0, friction_coefficient=0.0,
                                 restitution=0.3, contact_penalty=1e7))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                                 material="concrete"))
    solver.add_walls(walls.plane(point=(-0.0999, 0.0, 0.0), normal=(1.0, 0.0, 0.0),
                                 material="glass"))
    solver.add_walls(walls.plane(point=(0.0999, 0.0, 0.0), normal=(-1.0, 0.0, 0.0),
                                 material="glass"))
    solver.add_body(shape=0, material="concrete", position=(-0.0499, 0.34 + shift, 0.05),
                    velocity=(0.0, 1.0, 0.0))
    solver.add_body(shape=0, material="concrete", position=(0.0499, 0.33 + shift, 0.05),
                    velocity=(0.0, 0.9, 0.0))
    solver.time_step = solver.stable_time_step()
    solver.finalize()
    return solver


def _spring_of_pair(solver):
    body_i, body_j, springs = solver.contact_history()
    found = np.flatnonzero((body_i == 0) & (body_j == 1))
    return springs[found[0]] if len(found) else None


def test_sliding_cubes_across_the_boundary_follow_the_middle_ones(cube):
    """The sliding pair of ``_sliding_pair`` across the boundary against the same pair started
    0.2 m back (it slides in the middle of the strip and never crosses): step by step over
    0.12 s (2270 steps), the centres agree along y by minimum image (and in x, z) to 1e-9 m,
    velocities to 1e-9 m/s (measured 1.4e-15 m and 8e-14 m/s: the round-off of a period, carried
    by stiff contacts), and the contact history holds the same keys; the pair's spring
    (tangential force and twist) is the middle pair's to 1e-9 of its largest component (measured
    9e-11, where a component passes through zero) at every step, also
    the steps on which the pair straddles the boundary and those on which a body wraps, so the
    spring is kept across the wrap."""
    across = _sliding_pair(cube, 0.0)
    middle = _sliding_pair(cube, -SHIFT)
    straddled, wraps, springs_seen = 0, 0, 0
    worst = {"position": 0.0, "velocity": 0.0, "spring": 0.0}
    for _ in range(int(0.12 / across.time_step)):
        before = across.positions[:, 1].copy()
        across.step()
        middle.step()
        wrapped = np.abs(across.positions[:, 1] - before) > 0.5 * PERIOD
        wraps += int(wrapped.sum())
        gap = _wrapped_gap(across.positions[:, 1], middle.positions[:, 1] + SHIFT)
        worst["position"] = max(worst["position"], np.abs(gap).max(),
                                np.abs(across.positions[:, [0, 2]]
                                       - middle.positions[:, [0, 2]]).max())
        worst["velocity"] = max(worst["velocity"],
                                np.abs(across.velocities - middle.velocities).max())
        assert np.array_equal(across.history_keys, middle.history_keys)
        spring, spring_middle = _spring_of_pair(across), _spring_of_pair(middle)
        assert (spring is None) == (spring_middle is None)
        if spring is not None:
            springs_seen += 1
            size = np.abs(spring_middle[:4]).max()
            worst["spring"] = max(worst["spring"],
                                  np.abs(spring[:4] - spring_middle[:4]).max() / size)
            straddles = abs(across.positions[0, 1] - across.positions[1, 1]) > 0.5 * PERIOD
            straddled += int(straddles)
            if wrapped.any():
                assert size > 0.0, "the spring of the pair went to zero as a body wrapped"
    print(f"worst differences: {worst}, {straddled} steps straddling, {wraps} wraps")
    assert wraps == 2, "each cube wraps once"
    assert straddled > 10 and springs_seen > straddled
    assert worst["position"] < 1e-9
    assert worst["velocity"] < 1e-9
    assert worst["spring"] < 1e-9


def test_restart_of_a_periodic_run_is_bit_for_bit(cube):
    """The sliding pair run 2400 steps at once against 1200 steps (before either cube wrapped),
    its state arrays loaded into a fresh solver given the same period (as a case gives it
    again), and 1200 steps more (both wrap): every
    state array equal in every bit (the wrapped positions are in the state, the springs are
    keyed by (i, j), the piece lists are rebuilt to the same forces)."""
    whole = _sliding_pair(cube, 0.0)
    whole.advance(2400)
    first = _sliding_pair(cube, 0.0)
    first.advance(1200)
    assert first.positions[:, 1].min() > 0.3
    arrays = first.state_arrays()
    second = _sliding_pair(cube, 0.0)
    second.restore_state(arrays, first.time_step)
    second.advance(1200)
    assert whole.positions[:, 1].min() < 0.1            # both wrapped by then
    for name in SolidSolver.STATE_ARRAYS:
        assert np.array_equal(getattr(whole, name), getattr(second, name)), name


# ---------------------------------------------------------------------------------- 4. refusals
def test_period_shorter_than_twice_a_moving_body_s_diameter_is_refused(cube):
    """Period 0.3 m < 2 x 0.173 m (the cube's bounding diameter): refused, naming body 0, its
    shape and the width the strip needs (0.3464 m); a period of 0.35 m is accepted."""
    solver = _solver(cube, periodic=False, time_step=1e-5)
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.1, 0.3))
    with pytest.raises(CaseFileError, match=r"body 0 \(shape 0 .*moving.*at least 0.3464 m"):
        solver.set_periodic(1, 0.0, 0.3)
    solver = _solver(cube, periodic=False, time_step=1e-5)
    solver.set_periodic(1, 0.0, 0.3)       # no bodies yet: refused when the solver is built
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.1, 0.3))
    with pytest.raises(CaseFileError, match=r"period 0.3 m .*body 0"):
        solver.finalize()
    solver = _solver(cube, periodic=False, time_step=1e-5)
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.1, 0.3))
    solver.set_periodic(1, 0.0, 0.35)
    solver.finalize()


def test_period_too_short_for_a_large_fixed_body_names_both(cube):
    """A fixed cube of side 0.3 m beside the moving 0.1 m cubes: a pair of them reaches
    0.0866 + 0.26 m, so a period of 0.5 m (enough for the moving cubes alone) is refused, naming
    the moving body and the fixed one."""
    big = RigidShape.from_mesh(shapes.cube(side=0.3, mesh_size=0.15))
    solver = _solver(cube, periodic=False, time_step=1e-5)
    solver.add_shape(big)
    solver.add_body(shape=0, material="concrete", position=(0.0, 0.1, 0.5))
    solver.add_body(shape=1, material="concrete", position=(0.0, 0.2, 0.0), fixed=True)
    with pytest.raises(CaseFileError, match=r"body 0 .*moving.* body 1 \(shape 1 .*fixed"):
        solver.set_periodic(1, 0.0, 0.5)


@pytest.mark.parametrize("lower, upper", [(0.4, 0.4), (0.5, 0.4), (0.0, np.inf),
                                          (np.nan, 0.4)])
def test_lower_not_below_upper_is_refused(cube, lower, upper):
    """lower >= upper (or either not finite): refused, naming both values."""
    solver = _solver(cube, periodic=False)
    with pytest.raises(CaseFileError, match="must be below upper"):
        solver.set_periodic(1, lower, upper)
    assert solver.periodic is None


def test_wall_across_the_periodic_direction_is_refused(cube):
    """A box of walls has two y walls (indices 2 and 3): refused, naming wall 2, whether the
    walls come before set_periodic or after (a tilted wall with a y component of its normal
    too); a floor and x walls are accepted, and a refused wall is not kept."""
    solver = _solver(cube, periodic=False)
    solver.add_walls(walls.box(min=(0, 0, 0), max=(1, 1, 1), material="concrete"))
    with pytest.raises(CaseFileError, match=r"wall 2 .*faces along y"):
        solver.set_periodic(1, LOWER, UPPER)
    assert solver.periodic is None          # the refused strip is not kept
    solver = _solver(cube)
    solver.add_walls(walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="concrete"))
    solver.add_walls(walls.plane(point=(0, 0, 0), normal=(1, 0, 0), material="concrete"))
    with pytest.raises(CaseFileError, match=r"wall 2 .*faces along y"):
        solver.add_walls(walls.plane(point=(0, 0, 0), normal=(1, 0.1, 0), material="concrete"))
    assert solver.periodic == (1, LOWER, UPPER) and len(solver.walls) == 2


@pytest.mark.parametrize("axis, words", [(3, "out of range"), (-1, "out of range"),
                                         (1.0, "out of range"), (True, "out of range"),
                                         (2, "z is the vertical")])
def test_axis_out_of_range_is_refused(cube, axis, words):
    """Axis 3, -1, a float or a bool: out of range; axis 2: z, the vertical, refused by name."""
    solver = _solver(cube, periodic=False)
    with pytest.raises(CaseFileError, match=words):
        solver.set_periodic(axis, LOWER, UPPER)


def test_second_periodic_direction_is_refused(cube):
    """y periodic, then x asked: refused (one periodic direction); y again with another strip
    replaces the first."""
    solver = _solver(cube)
    with pytest.raises(CaseFileError, match="one periodic direction"):
        solver.set_periodic(0, 0.0, 1.0)
    solver.set_periodic(1, -0.2, 0.3)
    assert solver.periodic == (1, -0.2, 0.3)


# ---------------------------------------------------------------------------------- 5. processes
@pytest.mark.parametrize("axis", [0, 1])
def test_periodic_bodies_over_two_processes_are_one_process_s(axis):
    """tests/parallel/periodic_bodies_split_check.py under ``mpiexec -n 2``: cubes sliding past
    each other along the periodic axis, across its boundary (with x periodic the boundary is
    where the first and last slabs meet), split over 2 processes by the x of their centre,
    against one process stepping the same cubes: positions, velocities, forces, springs and
    contact records equal in every bit on both processes; the script also checks that bodies
    wrapped, touched across the boundary and changed owner."""
    mpiexec = Path(sys.executable).parent / "mpiexec"
    # the test extra installs the mpich wheel, as tests/parallel/test_mpi_runs.py requires too
    assert mpiexec.exists(), "mpiexec not found: install the test extra (mpi4py and mpich)"
    script = [sys.executable, str(ROOT / "tests" / "parallel" / "periodic_bodies_split_check.py"),
              str(axis)]
    environment = {**os.environ, "NUMBA_NUM_THREADS": "1", "RIPRAP_SMOKE": "0"}
    # one process first: it compiles and caches the kernels, which two processes compiling at
    # once could write under each other
    for command in (script, [str(mpiexec), "-n", "2", *script]):
        result = subprocess.run(command, capture_output=True, text=True, timeout=900, cwd=ROOT,
                                env=environment)
        assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert result.stdout.count("bit for bit") == 2, result.stdout
