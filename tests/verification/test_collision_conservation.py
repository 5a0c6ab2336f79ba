"""Conservation laws in an oblique collision of two free rocks (no gravity, no walls).

Sources: Newton's third law and the symmetry of the contact (the force on body j is minus the
force on body i, applied at the same contact point, and the kernel's torques are the exact moments
of the same potential force distribution), so total linear momentum and total angular momentum
about the origin are invariants; with no damping (restitution 1) and no friction the potential
contact is conservative (F = -grad of p times the overlap potential), so kinetic energy after
separation equals kinetic energy before, up to the time discretisation. A contact that has no
damping cannot create energy either, with or without friction (Coulomb slip only dissipates and an
elastic tangential spring only returns what it stored).

Set-up: random rocks of nominal size 0.30 m (seed 1, elongation 1.4) and 0.25 m (seed 2, 1.2),
400-430 tets each, 2650 kg/m^3, penalty 1e8 Pa, turned and spinning, approaching at 3.5 m/s with
an offset so that the collision is oblique and angular momentum about the origin is large.

Quantities and tolerances (absolute; the momentum scales are sum m |v| and
sum (m |v| 0.5 m + |L_spin|)):

- linear momentum, at every step of the run (friction 0.6, e = 0.5, so damping and sliding are
  active): ``MOMENTUM_TOLERANCE`` = 1e-10 of the scale. Velocity Verlet updates each body with
  equal and opposite impulses, so the error is round-off (measured 7e-16).
- angular momentum about the origin, same run: ``MOMENTUM_TOLERANCE``. The drift keeps x x v and
  the world spin unchanged, each kick changes the total by (dt/2) sum (x_i x F_i + tau_i) = 0
  (measured 3e-15).
- kinetic energy with e = 1 and friction 0: ``ELASTIC_ENERGY_TOLERANCE`` = 1e-6 relative (the
  contact lasts ~115 steps at the automatic step; measured 6.7e-8, 7e-10 at half the step).
- kinetic energy with e = 1 and friction 0.6 must not grow by more than
  ``ELASTIC_ENERGY_TOLERANCE``.
"""
import numpy as np
import pytest

from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

MOMENTUM_TOLERANCE = 1e-10        # round-off; measured < 3e-15
ELASTIC_ENERGY_TOLERANCE = 1e-6   # relative; time discretisation, measured 6.7e-8
MAX_STEPS = 20000
ARM = 0.5                          # m, length scale of the orbital angular momentum


@pytest.fixture(scope="module")
def rock_shapes():
    return (RigidShape.from_mesh(shapes.random_rock(size=0.30, elongation=1.4, seed=1)),
            RigidShape.from_mesh(shapes.random_rock(size=0.25, elongation=1.2, seed=2)))


def _collision(rock_shapes, *, friction, restitution):
    solver = SolidSolver(gravity=(0.0, 0.0, 0.0))
    a = solver.add_shape(rock_shapes[0])
    b = solver.add_shape(rock_shapes[1])
    m = solver.add_material(Material(name="rock", density=2650.0, friction_coefficient=friction,
                                     restitution=restitution, contact_penalty=1.0e8))
    solver.add_body(shape=a, material=m, position=(-0.35, 0.06, 0.02), velocity=(2.0, 0.3, 0.0),
                    angular_velocity=(1.0, -2.0, 3.0), orientation=(0.9, 0.1, 0.3, -0.2))
    solver.add_body(shape=b, material=m, position=(0.3, -0.05, -0.03), velocity=(-1.5, 0.0, 0.2),
                    angular_velocity=(-2.0, 0.5, 1.0), orientation=(0.5, -0.5, 0.5, 0.5))
    solver.finalize()
    return solver


def _momenta(solver):
    linear = solver.masses[:, None] * solver.velocities
    angular = np.cross(solver.positions, linear) + solver.angular_momenta
    return linear.sum(axis=0), angular.sum(axis=0)


def _run_until_separated(solver, each_step=None):
    first = None
    for n in range(1, MAX_STEPS + 1):
        solver.step()
        if each_step is not None:
            each_step(solver)
        if len(solver.contacts):
            first = n if first is None else first
            last = n
        elif first is not None and n > last + 2:
            return
    pytest.fail(f"the rocks did not collide and separate within {MAX_STEPS} steps")


def test_momentum_and_angular_momentum_are_conserved(rock_shapes):
    solver = _collision(rock_shapes, friction=0.6, restitution=0.5)
    linear0, angular0 = _momenta(solver)
    linear_scale = float(np.sum(solver.masses * np.linalg.norm(solver.velocities, axis=1)))
    angular_scale = linear_scale * ARM + float(np.sum(np.linalg.norm(solver.angular_momenta, axis=1)))
    energy0 = solver.kinetic_energy()
    errors = []

    def record(s):
        linear, angular = _momenta(s)
        errors.append((np.abs(linear - linear0).max(), np.abs(angular - angular0).max()))

    _run_until_separated(solver, record)
    errors = np.array(errors)
    assert errors[:, 0].max() <= MOMENTUM_TOLERANCE * linear_scale
    assert errors[:, 1].max() <= MOMENTUM_TOLERANCE * angular_scale
    # the collision did something: damping and friction took energy
    assert solver.kinetic_energy() < 0.9 * energy0


def test_frictionless_elastic_collision_conserves_kinetic_energy(rock_shapes):
    solver = _collision(rock_shapes, friction=0.0, restitution=1.0)
    energy0 = solver.kinetic_energy()
    velocities0 = solver.velocities.copy()
    _run_until_separated(solver)
    assert np.abs(solver.velocities - velocities0).max() > 0.1   # they did collide
    assert abs(solver.kinetic_energy() - energy0) <= ELASTIC_ENERGY_TOLERANCE * energy0


def test_undamped_frictional_collision_creates_no_energy(rock_shapes):
    solver = _collision(rock_shapes, friction=0.6, restitution=1.0)
    energy0 = solver.kinetic_energy()
    _run_until_separated(solver)
    assert solver.kinetic_energy() - energy0 <= ELASTIC_ENERGY_TOLERANCE * energy0
