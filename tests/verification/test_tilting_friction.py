"""Tilting test: a cube resting on a fixed box of the same material, dry, starts to slide where
its pair's friction coefficient says, the coefficient given by a ``[[friction]]`` entry of the
case file (issue 51 item 3).

Source: Coulomb's law of dry friction (Coulomb 1785; any mechanics text, e.g. Meriam & Kraige,
Engineering Mechanics: Statics, ch. 6): a block on a plane tilted by theta sticks while
tan(theta) < mu and slides once tan(theta) > mu, so it starts to slide at the friction angle
atan(mu), whatever its size, mass or contact stiffness. The cube does not tip first: it would tip
at 45 degrees (its centroid over the lower edge), above both friction angles tested.

Set-up: a case file read by the case loader and built as ``riprap run`` builds it: one material
"concrete" (2400 kg/m^3, friction_coefficient 0.4, restitution 0.5, contact penalty 1e8 Pa); a
cube of 0.1 m resting on a fixed 0.4 x 0.4 x 0.05 m box of the same material (both meshed at 5 cm:
their faces are flat); a ``[[friction]]`` entry gives concrete on concrete mu = 0.55 (28.81
degrees) or 0.25 (14.04 degrees), either differing from the material's own 0.4 (21.80 degrees) by
7 degrees, so the test shows the table reaching the contact kernel in both directions. Gravity
(9.81 m/s^2) is vertical for ``SETTLE`` = 0.05 s, turns about y over ``RAMP`` = 0.3 s to
``START_BELOW_DEG`` = 2.25 degrees below atan(mu), then steps up by ``STEP_DEG`` = 0.5 degrees,
each tilt held ``HOLD`` = 0.2 s: the steps fall 0.25 degree either side of atan(mu).

A slide is a downslope displacement of more than ``SLIDE_DISTANCE`` = 0.4 mm over one step. A
cube held well below atan(mu) moves by the change of its tangential spring (1e-8 m); within about
2 degrees below atan(mu) = 0.55 (tan(theta) above 0.93 mu) it creeps by up to 0.18 mm a step,
rocking on its lower edge in a stick-slip of the penalty contact (measured; none at mu = 0.25,
where the load sits nearer the face's middle); 0.25 degree above atan(mu) it slides by 0.9-1.2 mm
a step, accelerating at g (sin(theta) - mu cos(theta)).

Tolerance: the cube holds at every tilt below atan(mu), and the first tilt at which it slides lies
within ``TOLERANCE_DEG`` = 1 degree above atan(mu) (the steps put it 0.25 degree above). About
25 s a case on one thread.
"""
import math

import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import parse_case

OWN_FRICTION = 0.4
TOLERANCE_DEG = 1.0
STEP_DEG = 0.5
START_BELOW_DEG = 2.25
SETTLE = 0.05           # s, gravity vertical
RAMP = 0.3              # s, gravity turning to the first tilt
HOLD = 0.2              # s, each tilt
SLIDE_DISTANCE = 4e-4   # m, over one step
GRAVITY = 9.81

CASE = """format_version = 1
[simulation]
end_time = 100.0
[[materials]]
name = "concrete"
density = 2400.0
friction_coefficient = {own}
restitution = 0.5
contact_penalty = 1.0e8
[[friction]]
materials = ["concrete", "concrete"]
friction_coefficient = {pair}
[[shapes]]
name = "cube"
type = "cube"
side = 0.1
mesh_size = 0.05
[[shapes]]
name = "plane"
type = "box"
lengths = [0.4, 0.4, 0.05]
mesh_size = 0.05
[[bodies]]
shape = "plane"
material = "concrete"
position = [0.0, 0.0, -0.025]
fixed = true
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.0, 0.0, 0.05]
"""


def _tilt(solver, degrees: float) -> None:
    theta = math.radians(degrees)
    solver.gravity = np.array([GRAVITY * math.sin(theta), 0.0, -GRAVITY * math.cos(theta)])


def _advance(solver, duration: float) -> None:
    solver.advance(max(1, int(round(duration / solver.time_step))))


def _sliding_angle(pair_friction: float):
    """The first tilt (degrees) at which the cube slides, and the tilts it held at."""
    sim = build_simulation(parse_case(CASE.format(own=OWN_FRICTION, pair=pair_friction)),
                           progress=False)
    sim.prepare()
    solver = sim.solver
    _advance(solver, SETTLE)
    start = math.degrees(math.atan(pair_friction)) - START_BELOW_DEG
    turns = 100
    for k in range(1, turns + 1):
        _tilt(solver, start * k / turns)
        _advance(solver, RAMP / turns)
    held = []
    for k in range(round(2 * START_BELOW_DEG / STEP_DEG) + 1):
        angle = start + k * STEP_DEG
        _tilt(solver, angle)
        before = solver.positions[1, 0]
        _advance(solver, HOLD)
        if solver.positions[1, 0] - before > SLIDE_DISTANCE:
            return angle, held
        held.append(angle)
    return math.inf, held


@pytest.mark.parametrize("pair_friction", [0.55, 0.25])
def test_a_cube_slides_at_the_friction_angle_of_its_friction_pair(pair_friction):
    friction_angle = math.degrees(math.atan(pair_friction))
    own_angle = math.degrees(math.atan(OWN_FRICTION))
    assert abs(friction_angle - own_angle) > 2 * TOLERANCE_DEG    # the pair's, not the material's
    sliding, held = _sliding_angle(pair_friction)
    assert friction_angle < sliding <= friction_angle + TOLERANCE_DEG, (sliding, friction_angle)
    assert len(held) == math.ceil(START_BELOW_DEG / STEP_DEG), held    # every tilt below held
