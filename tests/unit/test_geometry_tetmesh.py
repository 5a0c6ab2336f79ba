"""TetMesh: volumes, outward boundary faces, checks and their messages, rigid transforms."""
import numpy as np
import pytest

from riprap.errors import CaseFileError, MeshError
from riprap.geometry.meshing import boundary_tet_heights, min_boundary_height
from riprap.geometry.tetmesh import TetMesh

# Sums of a few products of O(1) coordinates: only round-off can differ.
ROUND_OFF = 1e-12

CORNER_NODES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def unit_cube_mesh(name="unit cube"):
    """The unit cube [0, 1]^3 as six positively oriented tetrahedra around the 0-7 diagonal."""
    nodes = np.array([[x, y, z] for z in (0.0, 1.0) for y in (0.0, 1.0) for x in (0.0, 1.0)])
    paths = [(1, 3), (3, 2), (2, 6), (6, 4), (4, 5), (5, 1)]
    tets = np.array([[0, a, b, 7] for a, b in paths])
    return TetMesh.from_arrays(nodes, tets, name=name, fix_orientation=True)


def test_tetmesh_volume_of_corner_tet_is_one_sixth():
    mesh = TetMesh(nodes=CORNER_NODES, tets=np.array([[0, 1, 2, 3]]))
    assert abs(mesh.volumes()[0] - 1.0 / 6.0) < ROUND_OFF


def test_tetmesh_boundary_faces_point_outward_and_skip_shared_faces():
    mesh = unit_cube_mesh()
    faces = mesh.boundary_faces()
    assert faces.shape == (12, 3)  # two triangles per cube face; inner faces are shared
    corners = mesh.nodes[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = corners.mean(axis=1) - 0.5
    assert np.all(np.einsum("ti,ti->t", normals, outward) > 0.0)
    enclosed = np.einsum("ti,ti->t", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0
    assert abs(enclosed - 1.0) < ROUND_OFF


def test_tetmesh_check_accepts_valid_mesh_with_unused_node():
    mesh = unit_cube_mesh()
    nodes = np.vstack([mesh.nodes, [[5.0, 5.0, 5.0]]])
    TetMesh(nodes=nodes, tets=mesh.tets, name="cube plus unused node").check()
    assert abs(mesh.volumes().sum() - 1.0) < ROUND_OFF


def test_tetmesh_check_names_inverted_tet_and_suggests_swap():
    mesh = unit_cube_mesh()
    tets = mesh.tets.copy()
    tets[3] = tets[3][[0, 1, 3, 2]]
    with pytest.raises(MeshError) as raised:
        TetMesh(nodes=mesh.nodes, tets=tets, name="bad block").check()
    message = str(raised.value)
    assert "bad block" in message
    assert "inverted" in message
    assert "tets 3 (volume -1.667e-01" in message
    assert "reverse two node indices" in message


def test_tetmesh_from_arrays_fixes_orientation_when_asked():
    tets = np.array([[0, 2, 1, 3]])
    assert TetMesh.from_arrays(CORNER_NODES, tets).volumes()[0] < 0.0
    fixed = TetMesh.from_arrays(CORNER_NODES, tets, fix_orientation=True)
    fixed.check()
    assert abs(fixed.volumes()[0] - 1.0 / 6.0) < ROUND_OFF


def test_tetmesh_check_rejects_degenerate_tet():
    nodes = CORNER_NODES.copy()
    nodes[3] = [0.3, 0.3, 1e-13]  # nearly in the plane of the other three
    with pytest.raises(MeshError, match="flat corner.*degenerate"):
        TetMesh(nodes=nodes, tets=np.array([[0, 1, 2, 3]]), name="flat corner").check()


def test_tetmesh_check_rejects_non_finite_coordinates():
    nodes = CORNER_NODES.copy()
    nodes[2, 1] = np.nan
    with pytest.raises(MeshError, match="nan corner.*non-finite.*nodes 2"):
        TetMesh(nodes=nodes, tets=np.array([[0, 1, 2, 3]]), name="nan corner").check()


def test_tetmesh_check_rejects_tets_touching_along_an_edge():
    # Two tets sharing only the edge 0-1: that edge is used by four boundary faces.
    nodes = np.vstack([CORNER_NODES, [[0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]])
    mesh = TetMesh.from_arrays(nodes, np.array([[0, 1, 2, 3], [0, 1, 4, 5]]), name="bow tie", fix_orientation=True)
    with pytest.raises(MeshError) as raised:
        mesh.check()
    assert "bow tie" in str(raised.value)
    assert "closed 2-manifold" in str(raised.value)
    assert "[0, 1] (used by 4 boundary faces)" in str(raised.value)


def test_tetmesh_rejects_out_of_range_indices():
    with pytest.raises(MeshError, match="short.*node indices outside 0..3"):
        TetMesh(nodes=CORNER_NODES, tets=np.array([[0, 1, 2, 4]]), name="short")


def test_tetmesh_transformed_keeps_volumes_and_moves_nodes():
    mesh = unit_cube_mesh()
    angle = 0.7
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    translation = np.array([10.0, -2.0, 3.0])
    moved = mesh.transformed(rotation, translation)
    assert np.abs(moved.volumes() - mesh.volumes()).max() < ROUND_OFF
    assert np.abs(moved.nodes[7] - (rotation @ mesh.nodes[7] + translation)).max() < ROUND_OFF
    moved.check()


def test_tetmesh_transformed_refuses_reflection():
    with pytest.raises(CaseFileError, match="proper rotation"):
        unit_cube_mesh().transformed(np.diag([1.0, 1.0, -1.0]), np.zeros(3))


def test_min_boundary_height_of_corner_tet_is_centroid_to_slanted_face():
    mesh = TetMesh(nodes=CORNER_NODES, tets=np.array([[0, 1, 2, 3]]))
    # The centroid (1/4, 1/4, 1/4) is (1 - 3/4) / sqrt(3) from the face x + y + z = 1.
    assert abs(min_boundary_height(mesh) - 0.25 / np.sqrt(3.0)) < ROUND_OFF
    assert boundary_tet_heights(unit_cube_mesh()).shape == (6,)
