"""Torque-free rotation of an asymmetric rigid box (no gravity, no walls).

Sources: Euler's equations of a free rigid body, I1 w1' = (I2 - I3) w2 w3 (and cyclic), integrated
here with scipy's ``solve_ivp`` at rtol 1e-13; conservation of world angular momentum L and kinetic
energy; the stability of rotation about the major and minor principal axes and the instability
about the intermediate one (tennis-racket theorem; Landau & Lifshitz, Mechanics, section 37). The
integrator is the symplectic splitting of Dullweber, Leimkuhler & McLachlan (1997).

Body: box 0.3 x 0.2 x 0.1 m, 2400 kg/m^3 (principal moments 0.060, 0.120, 0.156 kg m^2), spin
(3, 5, 7) rad/s in the principal frame turned by 40 degrees about (1, 2, 3): about ten rotations at the
automatic time step.

Quantities and tolerances (absolute, relative to |L0|, E0, |w0|):

- L: ``ANGULAR_MOMENTUM_TOLERANCE`` = 1e-12. The drift leaves L untouched and no torque acts, so L
  is conserved exactly; any error is round-off.
- kinetic energy: ``ENERGY_TOLERANCE`` = 1e-8 over ten rotations. The splitting is symplectic, so the
  energy error is a bounded O(dt^2) oscillation, measured at 3.3e-10; the margin is 30. The
  order is checked too: ten times the step gives ``ENERGY_ORDER_RANGE`` (50-200) times the error
  (second order gives 100).
- body-frame angular velocity against Euler's equations: ``EULER_TOLERANCE`` = 1e-8 (measured
  1.1e-9 after ten rotations: phase error of a second-order method at w dt = 1.8e-4).
- stable spin about the major / minor axis, 10 rad/s with a 0.01 rad/s wobble on every axis: the
  axis stays within ``STABLE_CONE_DEGREES`` = 1 degree of L (the exact motion keeps a cone of
  0.06-0.2 degrees); the same wobble about the intermediate axis grows past
  ``FLIP_DEGREES`` = 45 degrees within ten rotations (measured 83 degrees).
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

ANGULAR_MOMENTUM_TOLERANCE = 1e-12   # exact conservation, round-off only
ENERGY_TOLERANCE = 1e-8              # measured 3.3e-10 at the automatic step, margin 30
ENERGY_ORDER_RANGE = (50.0, 200.0)   # error ratio for 10x the step; second order gives 100
EULER_TOLERANCE = 1e-8               # measured 1.1e-9 over ten rotations
STABLE_CONE_DEGREES = 1.0            # exact motion stays within 0.2 degrees
FLIP_DEGREES = 45.0                  # measured 83 degrees within ten rotations
N_ROTATIONS = 10
N_SAMPLES = 40
SPIN = (3.0, 5.0, 7.0)               # rad/s, principal frame


@pytest.fixture(scope="module")
def box_shape():
    return RigidShape.from_mesh(shapes.box(lengths=(0.3, 0.2, 0.1), mesh_size=0.1))


def _spinning_box(shape, spin_principal, orientation, time_step_factor=1.0):
    solver = SolidSolver(gravity=(0.0, 0.0, 0.0))
    k = solver.add_shape(shape)
    m = solver.add_material(Material(name="concrete", density=2400.0, contact_penalty=1.0e8))
    rotation = _matrix(orientation)
    solver.add_body(shape=k, material=m, position=(0.0, 0.0, 0.0), orientation=orientation,
                    frame="principal", angular_velocity=rotation @ np.asarray(spin_principal))
    solver.time_step = time_step_factor * solver.stable_time_step()
    solver.finalize()
    return solver


def _matrix(q):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _orientation():
    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    half = np.radians(40.0) / 2.0
    return (np.cos(half), *(np.sin(half) * axis))


def _run_sampled(solver, total_steps, sample):
    per_sample = total_steps // N_SAMPLES
    values = []
    for _ in range(N_SAMPLES):
        solver.advance(per_sample)
        values.append(sample(solver))
    return np.array(values)


def _period_steps(solver):
    period = 2.0 * np.pi / np.linalg.norm(solver.angular_velocities[0])
    return int(N_ROTATIONS * period / solver.time_step)


def test_angular_momentum_energy_and_euler_equations(box_shape):
    solver = _spinning_box(box_shape, SPIN, _orientation())
    inertia = solver.principal_inertia[0]
    angular_momentum0 = solver.angular_momenta[0].copy()
    energy0 = solver.kinetic_energy()
    omega0_body = solver.rotation_matrices()[0].T @ solver.angular_velocities[0]
    n_steps = _period_steps(solver)

    def euler(_, w):
        return [(inertia[1] - inertia[2]) * w[1] * w[2] / inertia[0],
                (inertia[2] - inertia[0]) * w[2] * w[0] / inertia[1],
                (inertia[0] - inertia[1]) * w[0] * w[1] / inertia[2]]

    exact = solve_ivp(euler, [0.0, n_steps * solver.time_step], omega0_body, rtol=1e-13,
                      atol=1e-13 * np.linalg.norm(omega0_body), dense_output=True)
    samples = _run_sampled(solver, n_steps, lambda s: np.concatenate([
        s.angular_momenta[0], [s.kinetic_energy(), s.time],
        s.rotation_matrices()[0].T @ s.angular_velocities[0]]))
    momentum_error = np.abs(samples[:, 0:3] - angular_momentum0).max()
    assert momentum_error <= ANGULAR_MOMENTUM_TOLERANCE * np.linalg.norm(angular_momentum0)
    energy_error = np.abs(samples[:, 3] - energy0).max()
    assert energy_error <= ENERGY_TOLERANCE * energy0
    euler_error = max(np.abs(row[5:8] - exact.sol(row[4])).max() for row in samples)
    assert euler_error <= EULER_TOLERANCE * np.linalg.norm(omega0_body)


def test_energy_error_is_second_order(box_shape):
    errors = []
    for factor in (10.0, 100.0):
        solver = _spinning_box(box_shape, SPIN, _orientation(), time_step_factor=factor)
        energy0 = solver.kinetic_energy()
        energies = _run_sampled(solver, max(_period_steps(solver), N_SAMPLES),
                                lambda s: s.kinetic_energy())
        errors.append(np.abs(energies - energy0).max())
    ratio = errors[1] / errors[0]
    assert ENERGY_ORDER_RANGE[0] <= ratio <= ENERGY_ORDER_RANGE[1]


@pytest.mark.parametrize("axis, stable", [(0, True), (1, False), (2, True)],
                         ids=["minor-axis", "intermediate-axis", "major-axis"])
def test_spin_stability_about_principal_axes(box_shape, axis, stable):
    spin = np.full(3, 0.01)
    spin[axis] = 10.0
    solver = _spinning_box(box_shape, spin, _orientation())
    direction = solver.angular_momenta[0] / np.linalg.norm(solver.angular_momenta[0])
    angles = _run_sampled(solver, _period_steps(solver), lambda s: np.degrees(
        np.arccos(min(1.0, abs(s.rotation_matrices()[0][:, axis] @ direction)))))
    if stable:
        assert angles.max() <= STABLE_CONE_DEGREES
    else:
        assert angles.max() >= FLIP_DEGREES
