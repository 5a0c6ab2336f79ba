"""The fast boundary-form contact kernels agree with the slow volume-form reference.

Source: Munjiza's distributed potential contact, F_A = p sum_{c in A, t in B} int_{c cap t}
(grad phi_c - grad phi_t) dV (Munjiza & Andrews 2000, eq. 6), with a half-space wall carrying
phi_W = -n.(x - point) / h_W. ``kernels/reference.py`` evaluates this volume form tet pair by tet
pair with exact clipping; ``kernels/contact.py`` evaluates the equivalent boundary form (divergence
theorem) over boundary triangles. The two are the same integral, so they must agree to round-off.

Cases: random rocks (several seeds, elongations and random orientations) overlapping by 1-5 % of
their size (shallow: few triangles and tets, the culling grids and bounding spheres decide what is
seen) and by 20-35 % (deep: whole clusters inside the other body), a non-convex tetrapod pair
with interlocking legs, and rocks and a tetrapod cut by a wall with random normals at shallow and
deep penetration.

Quantity: force on A, torque on A about its centroid and on B about its centroid (fast), converted
to moments about the world origin and compared with the reference (which returns the moment on A;
B receives the opposite). Wall: force and moment on the body.

Tolerance: ``RELATIVE_TOLERANCE`` = 1e-9 of the scale |F| (force) and |F| r + |M_centroid|
(moments, r the bounding radius). Both sides are sums of ~1e2-1e4 closed-form pieces of size up
to |F|; the pieces differ between the two forms (surface pieces against volume pieces), so the
sums agree to the round-off of the largest partial sums, ~1e-13-1e-12 relative. 1e-9 leaves three
orders of magnitude and still catches any missing triangle or tet (a single boundary piece of a
shallow contact is ~1e-3-1e-1 of the total).
"""
import numpy as np
import pytest
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from riprap.geometry import shapes
from riprap.solid.kernels.contact import body_pair_potential_force, body_wall_potential_force
from riprap.solid.kernels.reference import reference_body_contact, reference_wall_contact
from riprap.solid.shape import RigidShape, ShapeTable

RELATIVE_TOLERANCE = 1e-9
PENALTY = 1.0e8          # Pa; the comparison is relative, so its value is free
ROCK_SIZE = 0.3          # m
TETRAPOD_HEIGHT = 0.6    # m


@pytest.fixture(scope="module")
def table():
    rock_meshes = [shapes.random_rock(size=ROCK_SIZE, elongation=1.0 + 0.2 * seed, seed=seed,
                                      mesh_size=ROCK_SIZE / 2.5) for seed in range(4)]
    tetrapod = shapes.tetrapod(height=TETRAPOD_HEIGHT)
    rigid = [RigidShape.from_mesh(mesh) for mesh in rock_meshes + [tetrapod]]
    return rigid, ShapeTable.build(rigid)


def _world_nodes(shape, position, rotation):
    return shape.mesh.nodes @ rotation.T + position


def _support(shape, rotation, direction):
    """Largest extent of the rotated shape along ``direction`` from its centroid (m)."""
    return float((shape.mesh.nodes @ rotation.T @ direction).max())


def _random_rotation(rng):
    return Rotation.random(random_state=rng).as_matrix()


def _touching_distance(shape_a, rotation_a, shape_b, rotation_b, direction):
    """Largest s such that B at x_A + s u touches A's convex hull: the bodies' hulls overlap iff
    x_B - x_A lies in {R_A p - R_B q}, so s is the radial distance of that Minkowski difference."""
    points = ((shape_a.mesh.nodes @ rotation_a.T)[:, None, :]
              - (shape_b.mesh.nodes @ rotation_b.T)[None, :, :]).reshape(-1, 3)
    hull = ConvexHull(points)
    normals, offsets = hull.equations[:, :3], hull.equations[:, 3]   # n.x + d <= 0 inside
    towards = normals @ direction
    return float(np.min(-offsets[towards > 0.0] / towards[towards > 0.0]))


def _reference_pair(rigid, a, b, position_a, rotation_a, position_b, rotation_b):
    return reference_body_contact(
        _world_nodes(rigid[a], position_a, rotation_a), rigid[a].mesh.tets,
        _world_nodes(rigid[b], position_b, rotation_b), rigid[b].mesh.tets, penalty=PENALTY)


def _pair_case(rigid, a, b, overlap_range, rng):
    """Positions and rotations of shapes a and b whose convex hulls overlap by a fraction (drawn
    from ``overlap_range``) of the smaller bounding diameter along a random direction, redrawn
    until the meshes themselves overlap (a remeshed rock surface lies up to a few mm inside its
    hull; a tetrapod's legs may pass between the other's). Returns the case and the reference
    force and moment."""
    size = 2.0 * min(rigid[a].bounding_radius, rigid[b].bounding_radius)
    for _ in range(20):
        rotation_a, rotation_b = _random_rotation(rng), _random_rotation(rng)
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        touching = _touching_distance(rigid[a], rotation_a, rigid[b], rotation_b, direction)
        position_a = rng.uniform(-0.5, 0.5, size=3)
        position_b = position_a + (touching - rng.uniform(*overlap_range) * size) * direction
        case = (position_a, rotation_a, position_b, rotation_b)
        force, moment = _reference_pair(rigid, a, b, *case)
        if np.linalg.norm(force) > 0.0:
            return case, force, moment
    pytest.fail("no overlapping configuration found in 20 draws")


def _assert_pair_agrees(rigid, arrays, a, b, case, force, moment):
    position_a, rotation_a, position_b, rotation_b = case
    out = np.zeros(14)
    body_pair_potential_force(a, b, position_a, rotation_a, position_b, rotation_b, PENALTY,
                              arrays, out)
    force_scale = np.linalg.norm(force)
    moment_a = out[3:6] + np.cross(position_a, out[0:3])
    moment_b = out[6:9] + np.cross(position_b, -out[0:3])
    radius = max(rigid[a].bounding_radius, rigid[b].bounding_radius)
    moment_scale = force_scale * radius + np.linalg.norm(out[3:6]) + np.linalg.norm(out[6:9])
    assert np.abs(out[0:3] - force).max() <= RELATIVE_TOLERANCE * force_scale
    assert np.abs(moment_a - moment).max() <= RELATIVE_TOLERANCE * moment_scale
    assert np.abs(moment_b + moment).max() <= RELATIVE_TOLERANCE * moment_scale


@pytest.mark.parametrize("overlap_range", [(0.01, 0.02), (0.02, 0.05), (0.2, 0.35)],
                         ids=["1-2%", "2-5%", "deep-20-35%"])
@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_rock_pairs(table, seed, overlap_range):
    rigid, shape_table = table
    rng = np.random.default_rng(100 + seed)
    a, b = int(rng.integers(0, 4)), int(rng.integers(0, 4))
    case, force, moment = _pair_case(rigid, a, b, overlap_range, rng)
    _assert_pair_agrees(rigid, shape_table.kernel_arrays(), a, b, case, force, moment)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_interlocking_tetrapod_pair(table, seed):
    """Non-convex: hull overlaps of 25-35 %, so legs pass between legs."""
    rigid, shape_table = table
    tetrapod = len(rigid) - 1
    rng = np.random.default_rng(200 + seed)
    case, force, moment = _pair_case(rigid, tetrapod, tetrapod, (0.25, 0.35), rng)
    _assert_pair_agrees(rigid, shape_table.kernel_arrays(), tetrapod, tetrapod, case, force,
                        moment)


@pytest.mark.parametrize("depth_fraction", [0.01, 0.05, 0.3], ids=["1%", "5%", "deep-30%"])
@pytest.mark.parametrize("shape", [0, 3, 4], ids=["rock0", "rock3", "tetrapod"])
def test_body_against_wall(table, shape, depth_fraction):
    rigid, shape_table = table
    rng = np.random.default_rng(300 + shape)
    rotation = _random_rotation(rng)
    position = rng.uniform(-0.5, 0.5, size=3)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    # the wall surface cuts the body depth_fraction x its bounding diameter above its lowest point
    lowest = -_support(rigid[shape], rotation, -normal)
    wall_point = position + (lowest + depth_fraction * 2.0 * rigid[shape].bounding_radius) * normal
    out = np.zeros(14)
    body_wall_potential_force(shape, position, rotation, wall_point, normal, PENALTY,
                              shape_table.kernel_arrays(), out)
    force, moment = reference_wall_contact(
        _world_nodes(rigid[shape], position, rotation), rigid[shape].mesh.tets, point=wall_point,
        normal=normal, wall_potential_depth=shape_table.wall_potential_depth[shape],
        penalty=PENALTY)
    force_scale = np.linalg.norm(force)
    assert force_scale > 0.0
    moment_scale = force_scale * rigid[shape].bounding_radius + np.linalg.norm(out[3:6])
    assert np.abs(out[0:3] - force).max() <= RELATIVE_TOLERANCE * force_scale
    assert (np.abs(out[3:6] + np.cross(position, out[0:3]) - moment).max()
            <= RELATIVE_TOLERANCE * moment_scale)
