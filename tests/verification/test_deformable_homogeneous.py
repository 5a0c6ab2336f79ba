"""Finite-strain tetrahedra under homogeneous deformation: element stresses equal the closed-form
Cauchy stress of the seed paper's eq. 10 (and of the two hyperelastic forms) to round-off, and a
large rigid rotation gives no stress.

Source: eq. 10 of Xiang et al. (seed paper), T = mu/J (B - I) + lambda/(2J) tr(B - I) I + 2 eta D;
the hyperelastic forms of riprap.deformable.material (Bonet & Wood 2008, eq. 6.28; the volumetric-
isochoric split of deal.II's Cook's membrane). A homogeneous deformation x = F X is represented
exactly by both element types, so the only error is round-off: tolerance 1e-10 of the largest
stress. Interior nodes of a block carry no net internal force (equilibrium of a uniform stress),
and the forces on a face sum to sigma n a (Nanson: n a = J F^-T N A).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.deformable import DeformableBody, ElasticMaterial, box_mesh

MATERIAL = dict(density=2400.0, young_modulus=30e9, poisson_ratio=0.2, viscosity=2.0e5)


def closed_form_cauchy(model, material, F, L):
    mu, lam = material.shear_modulus, material.lame_lambda
    kappa = lam + 2 * mu / 3
    J = np.linalg.det(F)
    B = F @ F.T
    I = np.eye(3)
    D = 0.5 * (L + L.T)
    if model == "neo_hookean_seed":
        elastic = mu / J * (B - I) + lam / (2 * J) * np.trace(B - I) * I
    elif model == "neo_hookean":
        elastic = mu / J * (B - I) + lam * np.log(J) / J * I
    else:
        elastic = kappa / (2 * J) * (J * J - 1) * I + mu * J ** (-5 / 3) * (B - np.trace(B) / 3 * I)
    return elastic + 2 * material.viscosity * D


DEFORMATIONS = {
    "stretch": np.diag([1.3, 0.9, 1.05]),
    "shear": np.array([[1.0, 0.4, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
    "stretch and shear": np.array([[1.2, 0.3, -0.1], [0.05, 0.85, 0.2], [-0.15, 0.1, 1.1]]),
}
VELOCITY_GRADIENT = np.array([[0.3, -1.2, 0.4], [0.7, -0.2, 0.1], [0.0, 0.5, 0.6]])  # 1/s


def _deformed(body, F, L=np.zeros((3, 3))):
    body.positions[:] = body.elements.reference_nodes @ F.T + np.array([3.0, -2.0, 7.0])
    # x' = L x: spatial velocity gradient L
    body.velocities[:] = body.positions @ L.T
    return body


@pytest.mark.parametrize("element_type", ["tet4", "tet10"])
@pytest.mark.parametrize("model", ["neo_hookean_seed", "neo_hookean", "neo_hookean_decoupled"])
@pytest.mark.parametrize("deformation", list(DEFORMATIONS))
def test_block_stress_matches_closed_form(element_type, model, deformation):
    material = ElasticMaterial(constitutive_model=model, **MATERIAL)
    nodes, tets = box_mesh((0.4, 0.3, 0.5), (2, 3, 2))
    body = _deformed(DeformableBody(nodes, tets, material, element_type=element_type),
                     DEFORMATIONS[deformation], VELOCITY_GRADIENT)
    expected = closed_form_cauchy(model, material, DEFORMATIONS[deformation], VELOCITY_GRADIENT)
    stresses = body.cauchy_stresses()
    scale = np.abs(expected).max()
    assert np.abs(stresses - expected).max() < 1e-10 * scale

    forces = body.internal_forces()
    reference = body.elements.reference_nodes
    interior = np.all((reference > 1e-9) & (reference < np.array([0.4, 0.3, 0.5]) - 1e-9), axis=1)
    face_force = scale * 0.3 * 0.5
    assert interior.any()
    assert np.abs(forces[interior]).max() < 1e-10 * face_force
    # the face x = 0.4 (outward normal +X in the reference state): internal forces balance the
    # traction sigma n a, i.e. they sum to -J sigma F^-T N A
    F = DEFORMATIONS[deformation]
    on_face = np.abs(reference[:, 0] - 0.4) < 1e-9
    traction = np.linalg.det(F) * expected @ np.linalg.inv(F).T @ np.array([1.0, 0, 0]) * 0.3 * 0.5
    assert np.allclose(forces[on_face].sum(axis=0), -traction, rtol=0, atol=1e-10 * face_force)


@pytest.mark.parametrize("element_type", ["tet4", "tet10"])
@pytest.mark.parametrize("model", ["neo_hookean_seed", "neo_hookean", "neo_hookean_decoupled"])
def test_single_tet_stress_matches_closed_form(element_type, model):
    material = ElasticMaterial(constitutive_model=model, **MATERIAL)
    nodes = np.array([[0.0, 0, 0], [0.7, 0.1, 0], [0.2, 0.9, 0.1], [0.1, 0.2, 0.8]])
    F = DEFORMATIONS["stretch and shear"]
    body = _deformed(DeformableBody(nodes, [[0, 1, 2, 3]], material, element_type=element_type),
                     F, VELOCITY_GRADIENT)
    expected = closed_form_cauchy(model, material, F, VELOCITY_GRADIENT)
    assert np.abs(body.cauchy_stresses()[0] - expected).max() < 1e-10 * np.abs(expected).max()
    # a free tet's internal forces are self-equilibrated: no net force, no net moment
    forces = body.internal_forces()
    assert np.abs(forces.sum(axis=0)).max() < 1e-10 * np.abs(forces).max()
    moment = np.cross(body.positions - body.positions.mean(axis=0), forces).sum(axis=0)
    assert np.abs(moment).max() < 1e-10 * np.abs(forces).max()


@pytest.mark.parametrize("element_type", ["tet4", "tet10"])
@pytest.mark.parametrize("model", ["neo_hookean_seed", "neo_hookean", "neo_hookean_decoupled"])
def test_large_rigid_rotation_gives_no_stress(element_type, model):
    material = ElasticMaterial(constitutive_model=model, **MATERIAL)
    nodes, tets = box_mesh((0.4, 0.3, 0.5), (2, 2, 2))
    rotation = Rotation.from_rotvec(np.radians(150.0) * np.array([1.0, 2.0, -0.5]) / np.sqrt(5.25))
    body = _deformed(DeformableBody(nodes, tets, material, element_type=element_type),
                     rotation.as_matrix())
    # stresses of a 1 % stretch, for scale
    assert np.abs(body.cauchy_stresses()).max() < 1e-10 * material.young_modulus * 0.01
    assert np.abs(body.internal_forces()).max() < 1e-10 * material.young_modulus * 0.01 * 0.3 * 0.5
