"""Joint elements (``riprap.deformable.joints``): the exploded mesh and its joints, the softening
curve, and bad joint input refused by name."""
import numpy as np
import pytest

from riprap.deformable.joints import SOFTENING_AREA, FracturingBody, JointMaterial, explode_mesh
from riprap.deformable.kernels.joints import softening
from riprap.deformable.material import ElasticMaterial
from riprap.errors import CaseFileError
from riprap.geometry.structured import box_mesh

GOOD = dict(tensile_strength=3e6, cohesion=6e6, friction_angle=30.0, fracture_energy_mode_i=100.0,
            fracture_energy_mode_ii=1000.0, joint_penalty=3e11)


def test_every_shared_face_gets_one_joint_with_its_nodes_paired():
    nodes, tets = box_mesh((0.2, 0.05, 0.05), (4, 2, 2))
    new_nodes, new_tets, joints, joint_tets, original = explode_mesh(nodes, tets)
    assert new_nodes.shape == (4 * len(tets), 3) and new_tets.shape == tets.shape
    # 96 tets, 384 faces, 80 on the box's surface: 152 shared
    assert len(joints) == (4 * len(tets) - 80) // 2 == 152
    assert np.array_equal(new_nodes[joints[:, :3]], new_nodes[joints[:, 3:]])
    assert np.array_equal(original[joints[:, :3]], original[joints[:, 3:]])
    corners = new_nodes[joints[:, :3]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = corners.mean(axis=1) - new_nodes[new_tets[joint_tets[:, 0]]].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", normal, outward) > 0)
    # each tet's nodes are its own
    assert np.array_equal(new_tets.ravel(), np.arange(new_nodes.shape[0]))


def test_the_softening_curve_falls_from_one_to_zero():
    damage = np.linspace(0.0, 1.0, 101)
    z = np.array([softening(d) for d in damage])
    assert z[0] == 1.0 and z[-1] == 0.0
    assert np.all(np.diff(z) <= 0.0)
    assert SOFTENING_AREA == pytest.approx(0.3863, abs=1e-4)


@pytest.mark.parametrize("key, value", [("tensile_strength", 0.0), ("cohesion", -1.0),
                                        ("fracture_energy_mode_i", 0.0),
                                        ("fracture_energy_mode_ii", float("nan")),
                                        ("joint_penalty", -3e11), ("friction_angle", 90.0)])
def test_bad_joint_input_is_refused_by_name(key, value):
    with pytest.raises(CaseFileError, match=key):
        JointMaterial(**{**GOOD, key: value})


def test_a_fracturing_body_needs_a_joint_material():
    nodes, tets = box_mesh((0.1, 0.1, 0.1), (1, 1, 1))
    with pytest.raises(CaseFileError, match="joint_material"):
        FracturingBody(nodes, tets, ElasticMaterial(), {"tensile_strength": 3e6})


def test_an_unloaded_body_keeps_its_joints_and_its_shape():
    nodes, tets = box_mesh((0.1, 0.1, 0.1), (2, 2, 2))
    body = FracturingBody(nodes, tets, ElasticMaterial(), JointMaterial(**GOOD))
    body.step(200)
    assert not body.joint_broken.any() and body.joint_damage.max() == 0.0
    assert np.abs(body.positions - body.elements.reference_nodes).max() < 1e-12
    assert len(np.unique(body.fragments())) == 1
