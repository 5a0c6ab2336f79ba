"""Mass properties: closed-form tetrahedron integrals against analytic bodies and a voxel count."""
import numpy as np
import pytest

from riprap.errors import MeshError
from riprap.geometry import shapes
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh

# The integrals are exact for the meshed body; only float64 round-off over ~1000 tetrahedra remains.
EXACT_RELATIVE = 1e-10

# The sphere mesh is a polyhedron inscribed in the sphere. At the default mesh size (0.3 r) its
# volume is 3 % low and its moment of inertia per mass and r^2 about 2 % low (second-order error
# of the inscribed facets, ~(h / r)^2 / 4); 3 % bounds the latter with room for gmsh versions.
SPHERE_INERTIA_TOLERANCE = 0.03

# Monte Carlo count with 10^6 uniform points in the bounding box: 64 % fall inside, so the
# standard error of the volume is sqrt(0.36 / 0.64 / 10^6) = 0.075 % and that of the inertia
# terms similar; 1 % is more than 5 standard errors.
VOXEL_TOLERANCE = 0.01


def test_mass_properties_of_corner_tet_match_hand_integration():
    nodes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    properties = mass_properties(TetMesh(nodes=nodes, tets=np.array([[0, 1, 2, 3]])), density=2.0)
    # Canonical tet: int x^2 = 1/60, int xy = 1/120, V = 1/6, centroid 1/4; shifted to the
    # centroid int x^2 = 1/160, int xy = -1/480, so I_xx = 2 rho / 160 and I_xy = rho / 480.
    expected = 2.0 * np.array([[1 / 80, 1 / 480, 1 / 480], [1 / 480, 1 / 80, 1 / 480], [1 / 480, 1 / 480, 1 / 80]])
    assert abs(properties.volume - 1.0 / 6.0) < 1e-15
    assert abs(properties.mass - 2.0 / 6.0) < 1e-15
    assert np.abs(properties.centroid - 0.25).max() < 1e-15
    assert np.abs(properties.inertia_tensor - expected).max() < 1e-15


def test_mass_properties_of_box_match_analytic_inertia():
    lengths = np.array([0.4, 0.25, 0.1])
    density = 2650.0
    properties = mass_properties(shapes.box(lengths=tuple(lengths)), density=density)
    mass = density * lengths.prod()
    a, b, c = lengths
    expected = mass / 12.0 * np.array([b**2 + c**2, a**2 + c**2, a**2 + b**2])
    assert abs(properties.mass - mass) < EXACT_RELATIVE * mass
    assert np.abs(properties.centroid).max() < EXACT_RELATIVE * a
    assert np.abs(properties.inertia_tensor - np.diag(expected)).max() < EXACT_RELATIVE * expected.max()
    assert np.abs(properties.principal_moments - np.sort(expected)).max() < EXACT_RELATIVE * expected.max()
    # Ascending moments: the smallest belongs to the longest (x) axis.
    assert abs(abs(properties.principal_axes[0, 0]) - 1.0) < EXACT_RELATIVE


def test_mass_properties_of_unit_cube():
    properties = mass_properties(shapes.cube(side=1.0), density=1.0)
    assert abs(properties.volume - 1.0) < EXACT_RELATIVE
    assert np.abs(properties.principal_moments - 1.0 / 6.0).max() < EXACT_RELATIVE


def test_mass_properties_of_sphere_within_discretisation_error():
    radius = 0.2
    density = 1000.0
    mesh = shapes.sphere(radius=radius)
    properties = mass_properties(mesh, density=density)
    faces = mesh.nodes[mesh.boundary_faces()]
    normals = np.cross(faces[:, 1] - faces[:, 0], faces[:, 2] - faces[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    inner_radius = np.einsum("ti,ti->t", normals, faces[:, 0]).min()
    # Rigorous bracket: the mesh lies between the balls of radius inner_radius and radius.
    assert 4.0 / 3.0 * np.pi * inner_radius**3 <= properties.volume <= 4.0 / 3.0 * np.pi * radius**3
    for moment in properties.principal_moments:
        assert 8.0 / 15.0 * np.pi * density * inner_radius**5 * (1 - 1e-9) <= moment
        assert moment <= 8.0 / 15.0 * np.pi * density * radius**5
        assert abs(moment / (0.4 * properties.mass * radius**2) - 1.0) < SPHERE_INERTIA_TOLERANCE


def test_mass_properties_are_invariant_under_rigid_motion():
    mesh = shapes.l_shape(length=0.5, width=0.2, thickness=0.1)
    rotation, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    if np.linalg.det(rotation) < 0.0:
        rotation[:, 0] = -rotation[:, 0]
    translation = np.array([120.0, -40.0, 7.5])  # far from the origin, to test precision
    before = mass_properties(mesh, density=2400.0)
    after = mass_properties(mesh.transformed(rotation, translation), density=2400.0)
    scale = before.principal_moments.max()
    assert abs(after.mass - before.mass) < EXACT_RELATIVE * before.mass
    assert np.abs(after.centroid - (rotation @ before.centroid + translation)).max() < 1e-9
    assert np.abs(after.inertia_tensor - rotation @ before.inertia_tensor @ rotation.T).max() < 1e-9 * scale
    assert np.abs(after.principal_moments - before.principal_moments).max() < 1e-9 * scale


def test_mass_properties_principal_axes_form_a_right_handed_rotation():
    properties = mass_properties(shapes.random_rock(size=0.3, elongation=1.6, flatness=0.6, seed=4), density=2650.0)
    axes = properties.principal_axes
    assert abs(np.linalg.det(axes) - 1.0) < 1e-12
    assert np.abs(axes.T @ axes - np.eye(3)).max() < 1e-12
    diagonal = axes.T @ properties.inertia_tensor @ axes
    assert np.abs(diagonal - np.diag(properties.principal_moments)).max() < 1e-12 * properties.principal_moments.max()
    assert np.all(np.diff(properties.principal_moments) >= 0.0)


def test_mass_properties_of_l_shape_match_monte_carlo_count():
    length, width, thickness = 1.0, 0.4, 0.2
    properties = mass_properties(shapes.l_shape(length=length, width=width, thickness=thickness), density=1.0)
    samples = np.random.default_rng(11).uniform(-0.5, 0.5, size=(1_000_000, 3)) * [length, length, thickness]
    x, y = samples[:, 0], samples[:, 1]
    # The L is the bounding box minus the corner square beyond the arms' width.
    inside = (x <= -length / 2 + width) | (y <= -length / 2 + width)
    points = samples[inside]
    cell = length * length * thickness / len(samples)
    volume = len(points) * cell
    centroid = points.mean(axis=0)
    relative = points - centroid
    second = cell * relative.T @ relative
    inertia = np.trace(second) * np.eye(3) - second
    assert abs(properties.volume - (2 * length - width) * width * thickness) < EXACT_RELATIVE
    assert abs(volume / properties.volume - 1.0) < VOXEL_TOLERANCE
    assert np.abs(properties.centroid - centroid).max() < VOXEL_TOLERANCE * length
    assert np.abs(properties.inertia_tensor - inertia).max() < VOXEL_TOLERANCE * np.abs(inertia).max()


def test_mass_properties_rejects_inverted_mesh():
    nodes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(MeshError, match="upside down.*non-positive volume"):
        mass_properties(TetMesh(nodes=nodes, tets=np.array([[0, 2, 1, 3]]), name="upside down"))
