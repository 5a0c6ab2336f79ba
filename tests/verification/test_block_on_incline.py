"""A box on a plane under tilted gravity (equivalent to a block on an incline), with Coulomb friction.

Source: rigid-body statics and dynamics with Coulomb friction (any mechanics text, e.g. Meriam &
Kraige, Engineering Mechanics: Dynamics, ch. 3): the block sticks when tan(theta) < mu, and
otherwise slides with a = g (sin(theta) - mu cos(theta)). A spinning block on a face is braked by
the friction torque of its contact area, M = mu N <r> (<r> = 0.3826 a, mean distance from the
centre of a uniformly loaded square of side a), so it stops after t = I w0 / M.

Set-up: box 0.2 x 0.2 x 0.1 m (~580 tets), 2400 kg/m^3, mu = 0.5, e = 0.5, penalty 1e8 Pa, resting on
its large face on the plane z = 0; gravity g = 9.81 m/s^2 tilted by theta about the y axis (the
"downslope" direction is +x). Automatic time step.

Quantities and tolerances (absolute):

1. theta = 20 degrees (tan = 0.36 < 0.5, sticks): the contact's tangential spring must carry
   m g sin(theta), so the block moves by the spring's deflection xi = m g sin(theta) / k_t
   (k_t = tangential_stiffness_ratio x the normal stiffness measured on the contact; xi ~ 8e-8 m),
   plus a little slip while the normal force builds up from zero during the first steps, and the
   suddenly applied load overshoots to twice the static deflection. Displacement (all components)
   over 0.5 s within ``STICK_DISPLACEMENT_FACTOR`` = 5 xi (downslope measured 2.1 xi). After the
   contact vibration has decayed (damping ratio 0.22, period ~0.5 ms) the block must not creep:
   displacement between 0.25 and 0.5 s within ``STICK_CREEP_FACTOR`` = 0.1 xi.
2. theta = 35 degrees (tan = 0.70 > 0.5, slides): a = g (sin - mu cos) = 1.609 m/s^2; the slope of a
   straight-line fit of the downslope velocity over 0.1-0.5 s (after the landing transient) within
   ``SLIDING_ACCELERATION_TOLERANCE`` = 1 % of it (measured 0.03 %; the sliding contact has a
   constant normal force, so only the contact vibration, ~1e-4 m/s, scatters the fit).
3. Box resting flat, gravity vertical, spinning about the vertical at w0 = 0.5 rad/s: M = 3.6 N m,
   I = 0.064 kg m^2, so it stops within 9 ms; after 0.1 s |w| must be below
   ``SPIN_STOP_FRACTION`` = 1 % of w0.
"""
import numpy as np
import pytest

from riprap.geometry import shapes
from riprap.solid.shape import RigidShape

STICK_DISPLACEMENT_FACTOR = 5.0         # x xi: overshoot 2x plus slip while N builds up
STICK_CREEP_FACTOR = 0.1                # x xi: a stuck block at rest does not move
SLIDING_ACCELERATION_TOLERANCE = 0.01   # relative; measured 3e-4
SPIN_STOP_FRACTION = 0.01               # of w0, after 11 stopping times
GRAVITY = 9.81
FRICTION = 0.5
HALF_HEIGHT = 0.05


@pytest.fixture(scope="module")
def box_shape():
    return RigidShape.from_mesh(shapes.box(lengths=(0.2, 0.2, 0.1)))


def _block(body_on_plane, box_shape, theta_degrees, angular_velocity=(0.0, 0.0, 0.0)):
    theta = np.radians(theta_degrees)
    return body_on_plane(None, shape=box_shape, position=(0.0, 0.0, HALF_HEIGHT),
                         gravity=(GRAVITY * np.sin(theta), 0.0, -GRAVITY * np.cos(theta)),
                         angular_velocity=angular_velocity, density=2400.0,
                         friction_coefficient=FRICTION, restitution=0.5, contact_penalty=1.0e8)


def _advance_to(solver, time):
    solver.advance(int(round((time - solver.time) / solver.time_step)))


def test_block_sticks_below_the_friction_angle(body_on_plane, box_shape):
    theta = np.radians(20.0)
    assert np.tan(theta) < FRICTION
    solver = _block(body_on_plane, box_shape, 20.0)
    start = solver.positions[0].copy()
    _advance_to(solver, 0.25)
    middle = solver.positions[0].copy()
    _advance_to(solver, 0.5)
    end = solver.positions[0].copy()
    contacts = solver.contacts
    assert len(contacts) == 1
    tangential_stiffness = 2.0 / 7.0 * contacts.stiffness[0]
    deflection = solver.masses[0] * GRAVITY * np.sin(theta) / tangential_stiffness
    assert np.linalg.norm(end - start) <= STICK_DISPLACEMENT_FACTOR * deflection
    assert np.linalg.norm(end - middle) <= STICK_CREEP_FACTOR * deflection


def test_block_slides_above_the_friction_angle(body_on_plane, box_shape):
    theta = np.radians(35.0)
    assert np.tan(theta) > FRICTION
    solver = _block(body_on_plane, box_shape, 35.0)
    _advance_to(solver, 0.1)
    times, speeds = [], []
    for _ in range(40):
        solver.advance(int(0.01 / solver.time_step))
        times.append(solver.time)
        speeds.append(solver.velocities[0, 0])
    acceleration = np.polyfit(times, speeds, 1)[0]
    expected = GRAVITY * (np.sin(theta) - FRICTION * np.cos(theta))
    assert abs(acceleration - expected) <= SLIDING_ACCELERATION_TOLERANCE * expected


def test_friction_stops_a_block_spinning_on_its_face(body_on_plane, box_shape):
    spin = 0.5
    solver = _block(body_on_plane, box_shape, 0.0, angular_velocity=(0.0, 0.0, spin))
    _advance_to(solver, 0.1)
    assert abs(solver.angular_velocities[0, 2]) <= SPIN_STOP_FRACTION * spin
