"""Non-convex bodies dropped on a plane come to rest in their statically stable pose.

Sources: rigid-body statics: a body rests on a plane when its centroid projects inside the convex
hull of its contacts, and with the small drops used here only one pose is reachable.

- L-shaped plate (``shapes.l_shape``: arms 0.6 x 0.2 m, 0.1 m thick, ~770 tets), released 1 cm
  above the plane tilted 15-25 degrees about three horizontal axes: it must end lying flat, its
  thickness axis (mesh z) vertical, centroid at thickness / 2. The re-entrant corner of the L is
  where a wrong non-convex contact (e.g. a convex-hull shortcut) would show up.
- Tetrapod (``shapes.tetrapod(height=1)``, ~640 tets, four legs along the directions of a regular
  tetrahedron, leg 0 along mesh +z), released 2 cm above the plane in three random orientations: any
  rest pose of a tetrapod on a plane is three leg tips down and the fourth leg up, with the
  centroid at the geometric height of the unit standing upright (z_centroid - min z_node in the
  mesh frame, 0.333 H).

Bodies: 2400 kg/m^3, friction 0.6, restitution 0.3, ``local_damping`` = 0.3 (Cundall's numerical
damping, used here to settle quickly); penalty 1e8 Pa (L) and 1e9 Pa (tetrapod: its rim contacts
are small, the stiffer penalty keeps the overlap near 2 mm). Settling times 0.4 s (L) and 1.5 s
(tetrapod, which may tumble over a leg before it lands on three).

Quantities and tolerances (absolute):

- L: thickness axis within ``FLAT_TILT_DEGREES`` = 0.5 degrees of vertical (measured 2e-6 degrees;
  the face rests on the plane, overlap ~1e-7 m); centroid height within ``FLAT_HEIGHT_TOLERANCE`` =
  1e-4 m of 0.05 m (the static overlap of the face contact, W h / (p A) ~ 3e-7 m, and the contact
  vibration, are far below).
- tetrapod: the most vertical leg within ``UP_LEG_DEGREES`` = 2 degrees of vertical (measured
  0.05-0.45 degrees: the three rims are meshed slightly differently, a few mm over a 1 m
  span); centroid height within ``LEG_HEIGHT_TOLERANCE`` = 0.01 H of the geometric value (measured
  within 4 mm: rim overlap 1.6-1.8 mm at 1e9 Pa plus the small tilt).
- both: at rest after settling, every body point slower than ``REST_SPEED`` = 1e-3 m/s (|v| + |w| r,
  r the bounding radius). Local damping removes 30 % of every unbalanced force and torque
  component, and contact damping acts on every contact vibration, so nothing is left of the landing
  after 1 s; 1 mm/s is twenty times below the demo case's ``rest_speed`` (0.02 m/s).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

FLAT_TILT_DEGREES = 0.5
FLAT_HEIGHT_TOLERANCE = 1e-4      # m; static overlap ~3e-7 m
UP_LEG_DEGREES = 2.0              # measured <= 0.45 degrees
LEG_HEIGHT_TOLERANCE = 0.01       # x height; measured <= 4 mm for H = 1 m
REST_SPEED = 1e-3                 # m/s, at every point of the body
L_THICKNESS = 0.1
TETRAPOD_HEIGHT = 1.0
L_CASES = {"tilt15-about-x=y": ((1.0, 1.0, 0.0), 15.0),
           "tilt20-about-x=-y": ((1.0, -1.0, 0.0), 20.0),
           "tilt25-about-x": ((1.0, 0.0, 0.0), 25.0)}
TETRAPOD_SEEDS = (0, 1, 2)
_POLAR = np.arccos(-1.0 / 3.0)
TETRAPOD_LEGS = np.array([[0.0, 0.0, 1.0]] + [
    [np.sin(_POLAR) * np.cos(a), np.sin(_POLAR) * np.sin(a), np.cos(_POLAR)]
    for a in (0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0)])   # mesh frame, shapes.tetrapod


def _mesh_to_world(solver, shape):
    """Rotation taking mesh-frame directions to the world (body 0)."""
    return solver.rotation_matrices()[0] @ shape.frame_rotation.T


def _dropped(shape, orientation, *, clearance, penalty, settle_time):
    solver = SolidSolver(gravity=(0.0, 0.0, -9.81), local_damping=0.3)
    k = solver.add_shape(shape)
    m = solver.add_material(Material(name="concrete", density=2400.0, friction_coefficient=0.6,
                                     restitution=0.3, contact_penalty=penalty))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                                 material="concrete"))
    # orientation acts on the mesh as built; place the lowest node ``clearance`` above the plane
    rotation = Rotation.from_quat([*orientation[1:], orientation[0]]).as_matrix()
    lowest = ((shape.mesh.nodes @ shape.frame_rotation.T) @ rotation.T)[:, 2].min()
    solver.add_body(shape=k, material=m, orientation=orientation,
                    position=(0.0, 0.0, clearance - lowest))
    solver.finalize()
    solver.advance(int(round(settle_time / solver.time_step)))
    return solver


@pytest.fixture(scope="module")
def l_shape():
    return RigidShape.from_mesh(shapes.l_shape(length=0.6, width=0.2, thickness=L_THICKNESS))


@pytest.fixture(scope="module")
def tetrapod():
    return RigidShape.from_mesh(shapes.tetrapod(height=TETRAPOD_HEIGHT))


@pytest.fixture(scope="module")
def settled(l_shape, tetrapod):
    """Settled solvers by case name, simulated once per module."""
    cache = {}

    def get(case):
        if case not in cache:
            if case in L_CASES:
                axis, degrees = L_CASES[case]
                half = 0.5 * np.radians(degrees)
                axis = np.asarray(axis) / np.linalg.norm(axis)
                orientation = (np.cos(half), *(np.sin(half) * axis))
                cache[case] = _dropped(l_shape, orientation, clearance=0.01, penalty=1.0e8,
                                       settle_time=0.4)
            else:
                x, y, z, w = Rotation.random(random_state=int(case.split("-")[1])).as_quat()
                cache[case] = _dropped(tetrapod, (w, x, y, z), clearance=0.02, penalty=1.0e9,
                                       settle_time=1.5)
        return cache[case]

    return get


@pytest.mark.parametrize("case", list(L_CASES))
def test_l_shape_lies_flat(settled, l_shape, case):
    solver = settled(case)
    thickness_axis = _mesh_to_world(solver, l_shape)[:, 2]
    tilt = np.degrees(np.arccos(min(1.0, abs(thickness_axis[2]))))
    assert tilt <= FLAT_TILT_DEGREES
    assert abs(solver.positions[0, 2] - 0.5 * L_THICKNESS) <= FLAT_HEIGHT_TOLERANCE


@pytest.mark.parametrize("seed", TETRAPOD_SEEDS)
def test_tetrapod_stands_on_three_legs(settled, tetrapod, seed):
    solver = settled(f"tetrapod-{seed}")
    legs = TETRAPOD_LEGS @ _mesh_to_world(solver, tetrapod).T
    up = int(np.argmax(legs[:, 2]))
    assert np.degrees(np.arccos(min(1.0, legs[up, 2]))) <= UP_LEG_DEGREES
    assert np.all(np.delete(legs[:, 2], up) < 0.0)
    nodes_z = tetrapod.mesh.nodes @ tetrapod.frame_rotation.T   # mesh frame about the centroid
    upright_height = -nodes_z[:, 2].min()
    assert abs(solver.positions[0, 2] - upright_height) <= LEG_HEIGHT_TOLERANCE * TETRAPOD_HEIGHT


@pytest.mark.parametrize("case", list(L_CASES) + [f"tetrapod-{s}" for s in TETRAPOD_SEEDS])
def test_dropped_body_comes_to_rest(settled, case):
    solver = settled(case)
    radius = solver.bounding_radius[solver.shape_index[0]]
    speed = (np.linalg.norm(solver.velocities[0])
             + np.linalg.norm(solver.angular_velocities[0]) * radius)
    assert speed <= REST_SPEED
