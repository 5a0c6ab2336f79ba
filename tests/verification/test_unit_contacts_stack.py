"""Contact statistics of a stack of three cubes resting on a plane (riprap.analysis).

Source: statics. Three 1 m concrete cubes (2400 kg/m^3, weight W = 23,544 N each) stacked on a
plane and settled (0.5 s, local damping 0.3): the plane carries 3 W on the bottom cube, the bottom
cube 2 W on the middle one, the middle one W on the top one. Coordination numbers: bottom 2 (plane,
middle), middle 2, top 1. With the cubes in one group and the plane as underlayer, the bottom
cube's largest unit-unit force is 2 W and its largest unit-underlayer force 3 W.

Tolerance: forces within ``FORCE_TOLERANCE`` = 1 % of the static values (the stack still breathes
by a fraction of its static overlaps after settling); coordination numbers exact.
"""
import numpy as np
import pytest

from riprap.analysis import unit_contacts
from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

FORCE_TOLERANCE = 0.01
SIDE = 1.0
DENSITY = 2400.0
WEIGHT = DENSITY * SIDE ** 3 * 9.81


@pytest.fixture(scope="module")
def stack():
    solver = SolidSolver(gravity=(0.0, 0.0, -9.81), local_damping=0.3)
    k = solver.add_shape(RigidShape.from_mesh(shapes.cube(side=SIDE, mesh_size=0.4 * SIDE)))
    m = solver.add_material(Material(name="concrete", density=DENSITY, friction_coefficient=0.6,
                                     restitution=0.5, contact_penalty=1.0e8))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="concrete"))
    for level in range(3):
        solver.add_body(shape=k, material=m, position=(0.02 * level, 0.0, 0.5 + level * 1.001 + 0.001))
    solver.finalize()
    solver.advance(int(round(0.5 / solver.time_step)))
    return solver


def test_coordination_numbers_and_contact_forces_of_a_stack(stack):
    stats = unit_contacts(stack.n_bodies, stack.contacts)
    assert stats.coordination_number.tolist() == [2, 2, 1]
    expected_largest = np.array([3.0, 2.0, 1.0]) * WEIGHT
    assert np.allclose(stats.max_contact_force, expected_largest, rtol=FORCE_TOLERANCE)
    # In one group, the plane is the only underlayer: only the bottom cube touches it.
    assert stats.max_contact_force_unit_underlayer[0] == pytest.approx(3.0 * WEIGHT, rel=FORCE_TOLERANCE)
    assert stats.max_contact_force_unit_underlayer[1:].tolist() == [0.0, 0.0]
    assert np.allclose(stats.max_contact_force_unit_unit, np.array([2.0, 2.0, 1.0]) * WEIGHT,
                       rtol=FORCE_TOLERANCE)
    # Each cube at rest: the contact forces on it carry its weight.
    assert np.allclose(stats.total_contact_force[:, 2], WEIGHT, rtol=FORCE_TOLERANCE)


def test_groups_split_unit_and_underlayer_contacts(stack):
    # The bottom cube as an underlayer rock: the middle cube's contact with it is unit-underlayer.
    stats = unit_contacts(stack.n_bodies, stack.contacts, group=[0, 1, 1])
    assert stats.max_contact_force_unit_underlayer[1] == pytest.approx(2.0 * WEIGHT, rel=FORCE_TOLERANCE)
    assert stats.max_contact_force_unit_unit[1] == pytest.approx(WEIGHT, rel=FORCE_TOLERANCE)
    with pytest.raises(ValueError, match="group has shape"):
        unit_contacts(stack.n_bodies, stack.contacts, group=[0, 1])
