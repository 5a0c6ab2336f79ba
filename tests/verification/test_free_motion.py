"""Free flight under gravity: free fall and a spinning projectile.

Source: Newton's second law with a constant force, x(t) = x0 + v0 t + g t^2 / 2, v(t) = v0 + g t.

Quantity: centroid position and velocity after N steps, t = N dt.

Tolerance: 1e-12 relative (absolute: 1e-12 times the size of the compared quantity). Velocity
Verlet (kick-drift-kick, ``kernels/integrate.py``) is exact for a constant force: the half kicks add
g dt/2 twice and the drift moves by dt (v + g dt/2), which sums to the parabola exactly. What is left
is round-off: one rounding per operation (2.2e-16) accumulated over a few hundred steps gives
~1e-14-1e-13 relative, so 1e-12 leaves a margin of ten while still catching any O(dt) or O(dt^2)
error (which would be ~1e-3-1e-6 here). Spin does not couple into the centroid motion of a free body,
so a tumbling rock must follow the same parabola exactly.
"""
import numpy as np
import pytest

from riprap.geometry import shapes

# Round-off only (see the module docstring): ~1e-13 expected after a few hundred steps.
RELATIVE_ROUND_OFF = 1e-12
GRAVITY = np.array([0.0, 0.0, -9.81])
TIME_STEP = 1.0e-3   # s; free flight has no stability limit, a coarse step shows exactness best
N_STEPS = 500


@pytest.fixture(scope="module")
def rock_mesh():
    return shapes.random_rock(size=0.3, elongation=1.5, seed=3)


def _check_parabola(solver, position0, velocity0):
    t = solver.time
    assert t == pytest.approx(N_STEPS * TIME_STEP, rel=1e-15)
    expected_position = position0 + velocity0 * t + 0.5 * GRAVITY * t ** 2
    expected_velocity = velocity0 + GRAVITY * t
    position_tolerance = RELATIVE_ROUND_OFF * np.linalg.norm(expected_position)
    velocity_tolerance = RELATIVE_ROUND_OFF * np.linalg.norm(expected_velocity)
    assert np.abs(solver.positions[0] - expected_position).max() <= position_tolerance
    assert np.abs(solver.velocities[0] - expected_velocity).max() <= velocity_tolerance


def test_free_fall_is_exact(rock_mesh, body_on_plane):
    position0 = np.array([1.0, -2.0, 30.0])
    velocity0 = np.zeros(3)
    solver = body_on_plane(rock_mesh, position=position0, velocity=velocity0, gravity=GRAVITY,
                           plane=False, time_step=TIME_STEP)
    solver.advance(N_STEPS)
    _check_parabola(solver, position0, velocity0)
    # Nothing rotates a body in a uniform field.
    assert np.abs(solver.angular_momenta[0]).max() == 0.0


def test_spinning_projectile_follows_the_parabola(rock_mesh, body_on_plane):
    position0 = np.array([0.5, 0.25, 2.0])
    velocity0 = np.array([6.0, -2.0, 8.0])
    solver = body_on_plane(rock_mesh, position=position0, velocity=velocity0, gravity=GRAVITY,
                           plane=False, time_step=TIME_STEP, angular_velocity=(4.0, -7.0, 11.0))
    angular_momentum0 = solver.angular_momenta[0].copy()
    solver.advance(N_STEPS)
    _check_parabola(solver, position0, velocity0)
    # Gravity acts at the centroid: no torque, the world angular momentum stays exactly as it was.
    assert np.array_equal(solver.angular_momenta[0], angular_momentum0)
