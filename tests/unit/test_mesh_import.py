"""Reading bodies from mesh files, and the surface checks that guard it."""
import meshio
import numpy as np
import pytest

from riprap.errors import MeshError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.surface_checks import check_closed_surface, find_self_intersections, orient_outward
from riprap.geometry.tetmesh import TetMesh
from riprap.io.mesh_files import read_mesh, write_surface_stl, write_volume_mesh

# STL stores float32; a unit cube survives exactly, other values to ~1e-7 relative.
FLOAT32_RELATIVE = 1e-6


def cube_surface(side=1.0, offset=(0.0, 0.0, 0.0)):
    """8 vertices and 12 outward triangles of an axis-aligned cube with its min corner at offset."""
    vertices = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    return vertices * side + np.asarray(offset), triangles


def uv_sphere(n_latitude, n_longitude):
    """A closed, outward latitude-longitude sphere of radius 1 (2 n_lon (n_lat - 1) triangles)."""
    theta = np.linspace(0.0, np.pi, n_latitude + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, n_longitude, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    vertices = np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    south = len(vertices) - 1

    def index(i, j):
        return 1 + i * n_longitude + j % n_longitude

    triangles = []
    for j in range(n_longitude):
        triangles.append((0, index(0, j), index(0, j + 1)))
        triangles.append((south, index(n_latitude - 2, j + 1), index(n_latitude - 2, j)))
        for i in range(n_latitude - 2):
            triangles.append((index(i, j), index(i + 1, j), index(i + 1, j + 1)))
            triangles.append((index(i, j), index(i + 1, j + 1), index(i, j + 1)))
    return vertices, np.array(triangles)


def test_cube_surface_helper_is_valid():
    vertices, triangles = cube_surface()
    check_closed_surface(vertices, triangles, "helper cube")


def test_read_mesh_tetrahedralizes_closed_stl(tmp_path):
    path = tmp_path / "block.stl"
    vertices, triangles = cube_surface(side=0.5)
    write_surface_stl(path, vertices, triangles)
    mesh = read_mesh(path, mesh_size=0.15)
    mesh.check()
    assert str(path) in mesh.name
    properties = mass_properties(mesh)
    assert abs(properties.volume - 0.125) < FLOAT32_RELATIVE
    assert np.abs(properties.centroid - 0.25).max() < FLOAT32_RELATIVE


def test_read_mesh_names_file_of_open_stl(tmp_path):
    path = tmp_path / "open_cube.stl"
    vertices, triangles = cube_surface()
    write_surface_stl(path, vertices, triangles[2:])  # top face (two triangles) removed
    with pytest.raises(MeshError) as raised:
        read_mesh(path)
    message = str(raised.value)
    assert str(path) in message
    assert "not closed" in message
    assert "4 open edges" in message


def test_read_mesh_names_file_of_inward_stl(tmp_path):
    path = tmp_path / "inside_out.stl"
    vertices, triangles = cube_surface()
    write_surface_stl(path, vertices, triangles[:, ::-1])
    with pytest.raises(MeshError) as raised:
        read_mesh(path)
    assert str(path) in str(raised.value)
    assert "oriented inward" in str(raised.value)
    assert "orient_outward" in str(raised.value)


def test_read_mesh_names_file_of_self_intersecting_stl(tmp_path):
    path = tmp_path / "two_cubes.stl"
    first, triangles = cube_surface()
    second, _ = cube_surface(offset=(0.5, 0.4, 0.3))
    write_surface_stl(path, np.vstack([first, second]), np.vstack([triangles, triangles + 8]))
    with pytest.raises(MeshError) as raised:
        read_mesh(path)
    assert str(path) in str(raised.value)
    assert "intersects itself" in str(raised.value)


def test_read_mesh_names_file_of_vtu_with_inverted_tet(tmp_path):
    path = tmp_path / "inverted.vtu"
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    tets = np.array([[0, 1, 2, 3], [1, 3, 2, 4]])  # the second is inverted
    meshio.write_points_cells(path, nodes, [("tetra", tets)])
    with pytest.raises(MeshError) as raised:
        read_mesh(path)
    message = str(raised.value)
    assert str(path) in message
    assert "inverted" in message
    assert "tets 1 (volume" in message


def test_read_mesh_round_trips_volume_mesh(tmp_path):
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    original = TetMesh(nodes=nodes, tets=np.array([[0, 1, 2, 3], [1, 2, 3, 4]]), name="two tets")
    original.check()
    for suffix in (".vtu", ".msh"):
        path = tmp_path / f"two_tets{suffix}"
        write_volume_mesh(path, original)
        loaded = read_mesh(path)
        assert loaded.name == str(path)
        assert np.array_equal(loaded.tets, original.tets)
        assert np.abs(loaded.nodes - original.nodes).max() < 1e-12


def test_read_mesh_names_missing_and_unsupported_files(tmp_path):
    with pytest.raises(MeshError, match="nowhere.stl' does not exist"):
        read_mesh(tmp_path / "nowhere.stl")
    path = tmp_path / "body.step"
    path.write_text("not a mesh")
    with pytest.raises(MeshError, match="body.step' has an unsupported suffix"):
        read_mesh(path)
    with pytest.raises(MeshError, match="volume mesh.*mesh_size"):
        read_mesh(tmp_path / "x.vtu", mesh_size=0.1)


def test_check_closed_surface_reports_inconsistent_orientation():
    vertices, triangles = cube_surface()
    triangles = triangles.copy()
    triangles[5] = triangles[5][::-1]
    with pytest.raises(MeshError, match="'flipped one' is inconsistently oriented.*triangles \\["):
        check_closed_surface(vertices, triangles, "flipped one")


def test_check_closed_surface_reports_non_manifold_edge():
    vertices, triangles = cube_surface()
    # A fin: an extra pair of triangles hanging off the cube's edge 0-1 (used by 3 triangles then
    # 4 counting the fin's back face).
    vertices = np.vstack([vertices, [[0.5, -1.0, -1.0]]])
    fin = np.array([[0, 1, 8], [1, 0, 8]])
    with pytest.raises(MeshError, match="'finned' has 1 non-manifold edges.*\\[0, 1\\]"):
        check_closed_surface(vertices, np.vstack([triangles, fin]), "finned")


def test_check_closed_surface_reports_zero_area_triangle():
    vertices, triangles = cube_surface()
    vertices = np.vstack([vertices, [[0.5, 0.0, 0.0]]])  # on edge 0-1
    sliver = np.array([[0, 8, 1]])
    with pytest.raises(MeshError, match="'needle' has 1 zero-area triangles.*12 \\(vertices \\[0, 8, 1\\]"):
        check_closed_surface(vertices, np.vstack([triangles, sliver]), "needle")


def test_orient_outward_flips_inward_surface():
    vertices, triangles = cube_surface()
    fixed = orient_outward(vertices, triangles[:, ::-1])
    check_closed_surface(vertices, fixed, "flipped back")
    assert np.array_equal(fixed, triangles[:, ::-1][:, ::-1])


def test_self_intersection_search_has_no_false_positives_on_20k_triangle_sphere():
    vertices, triangles = uv_sphere(71, 142)
    assert len(triangles) > 19_000
    check_closed_surface(vertices, triangles, "uv sphere")
    pairs, count = find_self_intersections(vertices, triangles)
    assert count == 0 and len(pairs) == 0


def test_self_intersection_search_finds_pushed_in_vertex():
    vertices, triangles = uv_sphere(12, 16)
    # Push the north pole through the sphere: its fan of triangles now crosses the far side.
    vertices = vertices.copy()
    vertices[0] = [0.0, 0.0, -1.5]
    pairs, count = find_self_intersections(vertices, triangles)
    assert count > 0
    fan = set(np.flatnonzero((triangles == 0).any(axis=1)).tolist())
    assert all(int(i) in fan or int(j) in fan for i, j in pairs)
