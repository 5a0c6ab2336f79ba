"""The contacts' stability rate that sets the adaptive contact step (riprap.solid.stability):
sqrt(k w) / 2 with w the pair's inverse mass at the contact point, checked against the masses
and inertias written by hand for a cube pressed on a floor."""
import numpy as np
import pytest

from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver
from riprap.solid.stability import _contact_rates
from riprap.solid.walls import Wall

SIDE = 0.05
DENSITY = 2400.0


def cube_on_floor(*, tangential_ratio, tilt_deg=0.0, sink=1e-5):
    solids = SolidSolver(gravity=(0.0, 0.0, -9.81))
    shape = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=SIDE, mesh_size=SIDE / 2)))
    solids.add_material(Material(name="concrete", density=DENSITY, contact_penalty=1e7,
                                 tangential_stiffness_ratio=tangential_ratio))
    solids.add_walls([Wall(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="concrete")])
    t = np.radians(tilt_deg)
    # tilted about y: the lowest edge, not the face, touches the floor
    half = 0.5 * SIDE * (np.cos(t) + np.sin(t))
    orientation = (np.cos(t / 2), 0.0, np.sin(t / 2), 0.0)
    solids.add_body(shape=shape, material="concrete", position=(0.0, 0.0, half - sink),
                    orientation=orientation)
    solids.time_step = 1e-6
    solids.finalize()
    solids.advance(1)
    return solids


def test_a_cube_pressed_face_down_steps_by_its_mass_along_the_normal():
    """Face down on the floor, the contact point lies under the centre: along the normal the
    cube answers with its mass alone, w = 1/m; with a tangential spring of ratio 0.5 the
    tangential bound 0.5 (1/m + R^2 / I) = 0.5 (1 + 4.5) / m is larger (R^2 / I = (3/4 a^2) /
    (m a^2 / 6) = 4.5 / m for a cube of side a). The rate before session 25 used 4.5/m for both."""
    m = DENSITY * SIDE ** 3
    stiff = cube_on_floor(tangential_ratio=0.01)
    k = stiff.contacts.stiffness
    assert len(k) == 1 and k[0] > 0.0
    assert _contact_rates(stiff)[0] == pytest.approx(np.sqrt(k[0] / m) / 2.0, rel=1e-3)
    soft = cube_on_floor(tangential_ratio=0.5)
    k = soft.contacts.stiffness[0]
    assert _contact_rates(soft)[0] == pytest.approx(np.sqrt(k * 0.5 * 5.5 / m) / 2.0, rel=1e-6)


def test_a_cube_on_its_edge_steps_by_the_turn_the_lever_arm_gives():
    """Tilted 30 degrees about y on its lowest edge: the contact point sits off the line of the
    normal through the centre, and w = 1/m + (r x n)^2 / I along that line (I = m a^2 / 6 about
    any axis through a cube's centre), larger than for the face-down cube."""
    m = DENSITY * SIDE ** 3
    solids = cube_on_floor(tangential_ratio=0.01, tilt_deg=30.0)
    c = solids.contacts
    assert len(c) == 1
    arm = np.cross(c.points[0] - solids.positions[0], [0.0, 0.0, 1.0])
    w = 1.0 / m + arm @ arm / (m * SIDE ** 2 / 6.0)
    assert np.linalg.norm(arm) > 0.15 * SIDE      # a (cos 30 - sin 30) / 2 = 0.18 a
    assert _contact_rates(solids)[0] == pytest.approx(np.sqrt(c.stiffness[0] * w) / 2.0, rel=1e-9)
