"""The Brazilian test (issue 16): a concrete disc squeezed across a diameter between two strips
splits along that diameter (``riprap.deformable.joints``: joints between all tets).

Source: the splitting tensile test (ASTM C496; Timoshenko & Goodier's disc under diametral
loads): at the centre of the loaded diameter the horizontal stress is 2 P / (pi D t), tension,
nearly uniform along it, so the disc splits there when it reaches the tensile strength.

Set-up: D = 0.1 m, t = 0.02 m, E = 30 GPa, nu = 0.2, f_t = 3 MPa, G_I = 10 J/m^2 (a disc three
times Hillerborg's characteristic length E G_I / f_t^2 = 0.033 m: a tougher disc carries load past
its first crack and its nominal strength rises above f_t, Rocco et al. 1999, Mater. Struct. 32:
210), loaded by strips an eighth of D wide moving together at 0.01 m/s each; a square-to-disc
mapped mesh of 8 x 8 and 12 x 12 cells (384 and 864 tets).

Tolerances (issue 16): the peak load's 2 P / (pi D t) within ``STRENGTH_TOLERANCE`` = 20 % of f_t at
both meshes (measured 2.73 MPa, -9 %, on 8 x 8 and 3.17 MPa, +6 %, on 12 x 12: the convergence the
issue asks to state); when the load has dropped to 80 % of its peak, at least
``SPLIT_SHARE`` = 80 % of the broken joints' area lies within D/10 of the loaded diameter.
"""
import numpy as np
import pytest

from riprap.deformable.joints import FracturingBody, JointMaterial
from riprap.deformable.material import ElasticMaterial
from riprap.geometry.structured import box_mesh

STRENGTH_TOLERANCE = 0.20
SPLIT_SHARE = 0.80
DIAMETER, THICKNESS = 0.1, 0.02
TENSILE = 3.0e6
SPEED = 0.01
STRIP = DIAMETER / 8


def _disc(points):
    """The square [-R, R]^2 (x, z) onto the disc of radius R."""
    radius = DIAMETER / 2
    x, z = points[:, 0] / radius, points[:, 2] / radius
    out = points.copy()
    out[:, 0] = radius * x * np.sqrt(1.0 - z * z / 2.0)
    out[:, 2] = radius * z * np.sqrt(1.0 - x * x / 2.0)
    return out


def _split(cells):
    radius = DIAMETER / 2
    nodes, tets = box_mesh((DIAMETER, THICKNESS, DIAMETER), (cells, 1, cells),
                           origin=(-radius, 0.0, -radius), mapping=_disc)
    material = ElasticMaterial(young_modulus=30.0e9, density=2400.0, poisson_ratio=0.2,
                               constitutive_model="neo_hookean")
    joints = JointMaterial(tensile_strength=TENSILE, cohesion=2 * TENSILE, friction_angle=30.0,
                           fracture_energy_mode_i=10.0, fracture_energy_mode_ii=100.0,
                           joint_penalty=3.0e11)
    body = FracturingBody(nodes, tets, material, joints, name="disc")
    p = body.positions
    rim = np.sqrt(radius ** 2 - (STRIP / 2) ** 2) - 1e-9
    under_strip = np.abs(p[:, 0]) <= STRIP / 2 + 1e-9
    top = np.flatnonzero(under_strip & (p[:, 2] > rim))
    bottom = np.flatnonzero(under_strip & (p[:, 2] < -rim))
    body.prescribe_velocity(top, -SPEED, components=(2,))
    body.prescribe_velocity(bottom, SPEED, components=(2,))
    body.fix([bottom[0]], components=(0, 1))
    peak, split = 0.0, None
    for block in range(20000):
        body.step(20)
        load = (body.internal_forces() + body.joint_forces())[top, 2].sum()  # the strip pushes down
        peak = max(peak, load)
        if split is None and body.joint_broken.any() and load < 0.8 * peak:
            split = body.joint_broken.copy()
        if split is not None and load < 0.05 * peak and block % 10 == 0 \
                and len(np.unique(body.fragments())) >= 2:
            break
    return body, peak, split


@pytest.fixture(scope="module", params=[8, 12], ids=["8x8", "12x12"])
def disc(request):
    return _split(request.param)


def test_the_disc_fails_at_the_splitting_strength(disc):
    _, peak, _ = disc
    nominal = 2.0 * peak / (np.pi * DIAMETER * THICKNESS)
    assert abs(nominal / TENSILE - 1.0) < STRENGTH_TOLERANCE, nominal


def test_it_splits_along_the_loaded_diameter(disc):
    body, _, split = disc
    assert split is not None and split.any()
    middles = body.positions[body.joints[split, :3]].mean(axis=1)
    areas = body.joint_areas[split]
    near = np.abs(middles[:, 0]) < DIAMETER / 10
    assert areas[near].sum() / areas.sum() >= SPLIT_SHARE
    assert len(np.unique(body.fragments())) >= 2
