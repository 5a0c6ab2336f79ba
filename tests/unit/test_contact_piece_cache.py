"""Reusing a pair's list of (triangle, tet) pieces while the bodies move less than the contact skin
must not change the result: the list is widened by the skin, ordered canonically, and the pieces it
holds beyond the exact set integrate to exactly zero. So a run with the cache must equal a run
without it bit for bit, whatever the skin.

Scene: eight random rocks (two shapes) dropped in a box so that they collide, bounce and come to
rest on each other and on the walls within the run: contacts start, slide and end, so lists are
made, reused and made again.
"""
import numpy as np
import pytest

from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

N_STEPS = 600


@pytest.fixture(scope="module")
def rocks():
    return [RigidShape.from_mesh(shapes.random_rock(size=0.2, elongation=1.3, seed=seed,
                                                    mesh_size=0.07))
            for seed in (3, 4)]


def _run(rocks, contact_skin):
    solver = SolidSolver(contact_skin=contact_skin)
    keys = [solver.add_shape(rock) for rock in rocks]
    solver.add_material(Material(name="rock", density=2650.0, friction_coefficient=0.6,
                                 restitution=0.3, contact_penalty=1e7))
    rng = np.random.default_rng(11)
    for b in range(8):
        x = 0.2 + 0.25 * (b % 2) + rng.uniform(-0.03, 0.03)
        y = 0.2 + 0.25 * ((b // 2) % 2) + rng.uniform(-0.03, 0.03)
        z = 0.2 + 0.3 * (b // 4)
        q = rng.normal(size=4)
        solver.add_body(shape=keys[b % 2], material="rock", position=(x, y, z),
                        orientation=q / np.linalg.norm(q), velocity=(0.0, 0.0, -1.0))
    solver.add_walls(walls.box(min=(0.0, 0.0, 0.0), max=(0.65, 0.65, 2.0), material="rock"))
    solver.time_step = 2.0 * solver.stable_time_step()
    reused = 0
    for _ in range(N_STEPS // 20):
        solver.advance(20)
        reused += len(solver._piece_cache[0])
    return solver, reused


def test_piece_cache_does_not_change_the_motion(rocks):
    exact, reused_none = _run(rocks, contact_skin=0.0)
    assert reused_none == 0
    assert len(exact.contacts) >= 6          # the rocks touch each other and the walls
    for skin in (None, 5e-3):
        cached, reused = _run(rocks, contact_skin=skin)
        assert reused > 0
        for name in ("positions", "quaternions", "velocities", "angular_momenta",
                     "history_springs"):
            assert np.array_equal(getattr(cached, name), getattr(exact, name)), (skin, name)


def test_negative_skin_is_refused():
    from riprap.errors import CaseFileError
    with pytest.raises(CaseFileError, match="contact_skin"):
        SolidSolver(contact_skin=-1.0)
