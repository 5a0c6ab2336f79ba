"""Built-in shapes: valid closed outward meshes, sizes, no slivers, reproducible rocks."""
import threading

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from riprap.errors import CaseFileError, MeshError, RiprapError
from riprap.geometry import shapes
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.meshing import boundary_tet_heights, mesh_occ_shape, min_boundary_height

# Exact for meshes whose surface is flat (boxes, L): round-off only.
EXACT_RELATIVE = 1e-10

# Built-in shapes at their default mesh size (the brief's budget for simulation cost).
MIN_DEFAULT_TETS = 200
MAX_DEFAULT_TETS = 1500

# Sliver criterion: the smallest centroid-to-face distance of any boundary tetrahedron must be at
# least this fraction of the median of that quantity over boundary tetrahedra. It bounds how much
# one bad element can shrink the contact time step (which scales with that height) relative to a
# typical element; gmsh with Netgen optimisation gives 0.16-0.6 on all built-in shapes and 36 rocks
# sampled while tuning, so 0.1 leaves margin without admitting real slivers (~0.01).
SLIVER_HEIGHT_RATIO = 0.1

# Random rocks at size 0.3 m with elongation 1: the brief's tet budget.
ROCK_MIN_TETS = 300
ROCK_MAX_TETS = 600

# The remeshed rock surface cuts hull ridges gentler than 40 degrees: 0-3 % volume loss measured.
ROCK_VOLUME_TOLERANCE = 0.04

DEFAULT_SHAPES = {
    "sphere": lambda: shapes.sphere(radius=0.1),
    "box": lambda: shapes.box(lengths=(0.4, 0.2, 0.1)),
    "cube": lambda: shapes.cube(side=1.0),
    "random_rock": lambda: shapes.random_rock(size=0.3, elongation=1.8, flatness=0.6, seed=2),
    "tetrapod": lambda: shapes.tetrapod(height=1.0),
    "l_shape": lambda: shapes.l_shape(length=1.0, width=0.4, thickness=0.2),
}


@pytest.fixture(scope="module")
def default_meshes():
    return {name: build() for name, build in DEFAULT_SHAPES.items()}


@pytest.mark.parametrize("shape", sorted(DEFAULT_SHAPES))
def test_shape_boundary_is_closed_and_outward(default_meshes, shape):
    mesh = default_meshes[shape]
    mesh.check()  # closed 2-manifold boundary, positive tets
    faces = mesh.nodes[mesh.boundary_faces()] - mesh.nodes.mean(axis=0)
    enclosed = np.einsum("ti,ti->t", faces[:, 0], np.cross(faces[:, 1], faces[:, 2])).sum() / 6.0
    # Outward faces enclose exactly the tets' volume (inward ones would give its negative).
    assert abs(enclosed - mesh.volumes().sum()) < EXACT_RELATIVE * mesh.volumes().sum()
    assert shape.split("_")[0] in mesh.name


@pytest.mark.parametrize("shape", sorted(DEFAULT_SHAPES))
def test_shape_default_size_has_budgeted_tet_count_and_no_slivers(default_meshes, shape):
    mesh = default_meshes[shape]
    assert MIN_DEFAULT_TETS <= mesh.n_tets <= MAX_DEFAULT_TETS
    heights = boundary_tet_heights(mesh)
    assert min_boundary_height(mesh) == heights.min()
    assert heights.min() > SLIVER_HEIGHT_RATIO * np.median(heights)


def test_box_and_l_shape_volumes_are_exact(default_meshes):
    assert abs(default_meshes["box"].volumes().sum() - 0.4 * 0.2 * 0.1) < EXACT_RELATIVE * 0.008
    assert abs(default_meshes["l_shape"].volumes().sum() - (2.0 - 0.4) * 0.4 * 0.2) < EXACT_RELATIVE
    lower, upper = default_meshes["box"].nodes.min(axis=0), default_meshes["box"].nodes.max(axis=0)
    assert np.abs(lower + [0.2, 0.1, 0.05]).max() < EXACT_RELATIVE
    assert np.abs(upper - [0.2, 0.1, 0.05]).max() < EXACT_RELATIVE


def test_random_rock_is_reproducible_from_seed():
    first = shapes.random_rock(size=0.3, seed=7)
    second = shapes.random_rock(size=0.3, seed=7)
    other = shapes.random_rock(size=0.3, seed=8)
    assert np.array_equal(first.nodes, second.nodes)
    assert np.array_equal(first.tets, second.tets)
    assert first.nodes.shape != other.nodes.shape or not np.array_equal(first.nodes, other.nodes)


@pytest.mark.parametrize("seed", range(5))
def test_random_rock_of_size_0_3_has_300_to_600_tets_and_nominal_diameter(seed):
    mesh = shapes.random_rock(size=0.3, seed=seed)
    assert ROCK_MIN_TETS <= mesh.n_tets <= ROCK_MAX_TETS
    properties = mass_properties(mesh)
    assert abs(properties.volume ** (1.0 / 3.0) / 0.3 - 1.0) < ROCK_VOLUME_TOLERANCE
    assert np.abs(properties.centroid).max() < ROCK_VOLUME_TOLERANCE * 0.3
    heights = boundary_tet_heights(mesh)
    assert heights.min() > SLIVER_HEIGHT_RATIO * np.median(heights)


def test_random_rock_tet_count_does_not_depend_on_size():
    small = shapes.random_rock(size=0.03, seed=1)
    large = shapes.random_rock(size=3.0, seed=1)
    assert ROCK_MIN_TETS <= small.n_tets <= ROCK_MAX_TETS
    assert ROCK_MIN_TETS <= large.n_tets <= ROCK_MAX_TETS


def test_random_rock_elongation_sets_axis_ratios():
    mesh = shapes.random_rock(size=0.3, elongation=2.0, flatness=0.5, seed=3)
    extent = mesh.nodes.max(axis=0) - mesh.nodes.min(axis=0)
    # Radii jitter +-10 % and the hull corners fall between samples: ratios within 25 %.
    assert abs(extent[0] / extent[1] / 2.0 - 1.0) < 0.25
    assert abs(extent[2] / extent[1] / 0.5 - 1.0) < 0.25


def test_tetrapod_is_non_convex_and_as_tall_as_asked(default_meshes):
    mesh = default_meshes["tetrapod"]
    volume = mesh.volumes().sum()
    assert volume > 0.0
    assert volume < 0.8 * ConvexHull(mesh.nodes).volume
    # The flat tip rims are polygons inscribed in circles: height within 1 % of the request.
    assert abs(np.ptp(mesh.nodes[:, 2]) - 1.0) < 0.01
    # One leg along +z, three below: the top is the +z tip, a quarter-turn symmetric body has its
    # centroid on the z axis.
    centroid = mass_properties(mesh).centroid
    assert np.hypot(centroid[0], centroid[1]) < 0.01


def test_l_shape_is_non_convex(default_meshes):
    mesh = default_meshes["l_shape"]
    assert mesh.volumes().sum() < 0.8 * ConvexHull(mesh.nodes).volume


@pytest.mark.parametrize(
    "build, message",
    [
        (lambda: shapes.sphere(radius=-1.0), "sphere: radius must be a positive length"),
        (lambda: shapes.box(lengths=(1.0, 0.0, 1.0)), "box: lengths must be a positive length"),
        (lambda: shapes.random_rock(size=0.3, n_vertices=5), "n_vertices must be an integer >= 8"),
        (lambda: shapes.tetrapod(height=1.0, leg_diameter_ratio=0.9), "leg_diameter_ratio must lie in"),
        (lambda: shapes.l_shape(length=0.3, width=0.4, thickness=0.1), "width .* must be less than length"),
    ],
)
def test_shapes_reject_bad_parameters_by_name(build, message):
    with pytest.raises(CaseFileError, match=message):
        build()


def test_mesh_occ_shape_refuses_two_separate_solids():
    def two_boxes(occ):
        occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
        occ.addBox(3.0, 0.0, 0.0, 1.0, 1.0, 1.0)

    with pytest.raises(MeshError, match="'pair of boxes' left 2 solids"):
        mesh_occ_shape(two_boxes, mesh_size=0.5, name="pair of boxes")


def test_meshing_leaves_a_caller_gmsh_session_alone():
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.model.add("caller model")
        gmsh.option.setNumber("General.Verbosity", 4)
        shapes.cube(side=1.0)
        assert gmsh.isInitialized()
        assert gmsh.model.getCurrent() == "caller model"
        assert gmsh.option.getNumber("General.Verbosity") == 4
    finally:
        gmsh.finalize()


def test_meshing_refuses_worker_threads():
    errors = []

    def work():
        try:
            shapes.cube(side=1.0)
        except RiprapError as error:
            errors.append(str(error))

    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    assert len(errors) == 1 and "main thread" in errors[0]
