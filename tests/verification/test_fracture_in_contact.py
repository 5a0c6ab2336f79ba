"""Fracture inside a :class:`riprap.deformable.system.DeformableSystem` (issue 16, item 2): the
joints' forces in the compiled step, the faces of a parted joint turned into contact surfaces,
the pieces counted as bodies of their own, and energy accounted.

A bar 0.2 m long, 0.05 m square (E = 30 GPa, f_t = 3 MPa, G_I = 100 J/m^2, joint penalty 10 E,
no viscosity, no damping), on 8 x 2 x 2 cells:

- flying apart (each half at 2 m/s outwards): it breaks through one section and the energy
  balance kinetic + stored elastic + taken by the joints (minus their work on the nodes) holds
  to ``ENERGY_TOLERANCE`` (the first law; measured 2e-4 of the initial kinetic energy with the
  trapezoidal work; the central-difference velocities at half steps make it oscillate, not
  drift); the joints took G_I times the section (Hillerborg's definition of the fracture energy)
  within ``FRACTURE_ENERGY_TOLERANCE`` (measured -0.8 %, the intact joints' elastic energy at the
  moment of measurement included), momentum conserved to 1e-9.
- cut through its middle section beforehand (the joints there broken, the halves two fragments)
  and its left half thrown at the right one at 1 m/s: the cut faces meet through their broken
  joints (which keep faces that face each other from passing through). Two equal elastic bars
  meeting end on exchange their momentum (St Venant's impact: the striker stops after 2 L / c);
  measured 93 % transferred after three wave transits, allowed ``MOMENTUM_SHARE`` = 85 %, total
  momentum to 1e-9, and the faces do not pass through each other.
- cut the same way, the right half moved beside the left one (2 mm apart) and thrown at it
  sideways at 1 m/s: the two pieces meet along their long sides, tets that never shared a node, so
  only the contact between fragments can stop them: the struck half takes at least
  ``SIDE_MOMENTUM_SHARE`` = 40 % of the momentum (measured 88 %; rigid pieces of equal mass with
  the default restitution 0.5 would share (1 + e) / 2 = 75 %; without the contact, 0 %), total
  conserved to 1e-9, and they do not pass through each other.
"""
import numpy as np
import pytest

from riprap.deformable.joints import FracturingBody, JointMaterial
from riprap.deformable.material import ElasticMaterial
from riprap.deformable.system import DeformableSystem
from riprap.geometry.structured import box_mesh

YOUNG = 30e9
DENSITY = 2400.0
FRACTURE_ENERGY = 100.0
SECTION = 0.05 * 0.05
ENERGY_TOLERANCE = 2e-3
FRACTURE_ENERGY_TOLERANCE = 0.05
MOMENTUM_SHARE = 0.85
SIDE_MOMENTUM_SHARE = 0.40


def _bar():
    nodes, tets = box_mesh((0.2, 0.05, 0.05), (8, 2, 2))
    nodes[:, 0] -= 0.1
    material = ElasticMaterial(young_modulus=YOUNG, poisson_ratio=0.2, density=DENSITY,
                               constitutive_model="neo_hookean")
    joints = JointMaterial(tensile_strength=3e6, cohesion=6e6, friction_angle=30.0,
                           fracture_energy_mode_i=FRACTURE_ENERGY, fracture_energy_mode_ii=1000.0,
                           joint_penalty=10 * YOUNG)
    body = FracturingBody(nodes, tets, material, joints, name="bar")
    return body, DeformableSystem([body])


def _element_side(body):
    """+1 for the nodes of tets right of x = 0, -1 left of it."""
    centres = body.positions[body.elements.elements].mean(axis=1)[:, 0]
    return np.repeat(np.sign(centres), 4)


def test_a_bar_flying_apart_breaks_once_and_accounts_for_its_energy():
    body, system = _bar()
    body.velocities[:, 0] = 2.0 * _element_side(body)
    kinetic_start = system.kinetic_energy()
    momentum_start = (body.masses[:, None] * body.velocities).sum(axis=0)
    balances = []
    for _ in range(8):
        system.step(250)
        balances.append(system.kinetic_energy() + body.stored_energy() - system.joint_work[0])
    balances = np.array(balances)
    assert np.abs(balances / kinetic_start - 1.0).max() < ENERGY_TOLERANCE
    taken = -system.joint_work[0]
    assert taken == pytest.approx(FRACTURE_ENERGY * SECTION, rel=FRACTURE_ENERGY_TOLERANCE)
    summary = body.breakage_summary()
    assert body.joint_broken.sum() == 8 and body.joint_parted.sum() == 8
    assert summary["fragments"] == 2
    assert summary["broken_area_m2"] == pytest.approx(SECTION)
    table = body.fragment_table()
    assert table["mass"].sum() == pytest.approx(body.mass, rel=1e-12)
    assert table["mass_fraction"] == pytest.approx([0.5, 0.5])
    assert np.sort(table["velocity"][:, 0]) == pytest.approx([-2.0, 2.0], abs=0.2)
    momentum = (body.masses[:, None] * body.velocities).sum(axis=0)
    assert np.abs(momentum - momentum_start).max() < 1e-9 * body.mass * 2.0
    # the cut faces are contact surfaces now: 2 x 8 triangles more
    assert system.surface_rebuilds == 1
    assert len(system.triangles) == 144 + 16


def _cut_bar():
    body, system = _bar()
    corners_x = body.positions[body.joints[:, :3]][:, :, 0]
    cut = np.all(np.abs(corners_x) < 1e-12, axis=1)
    assert cut.sum() == 8
    body.joint_broken[cut] = True
    system.update_fragments()
    assert body.joint_parted[cut].all() and len(np.unique(body.fragments())) == 2
    return body, system


def test_the_faces_of_a_cut_meet_again():
    body, system = _cut_bar()
    left = _element_side(body) < 0
    body.velocities[left, 0] = 1.0
    momentum_start = float((body.masses * body.velocities[:, 0]).sum())
    wave_speed = np.sqrt(YOUNG / DENSITY)
    steps = int(round(3 * 0.2 / wave_speed / system.time_step))
    deepest = 0.0
    for _ in range(10):
        system.step(steps // 10)
        gap = body.positions[~left, 0].min() - body.positions[left, 0].max()
        deepest = min(deepest, gap)
    momentum = body.masses * body.velocities[:, 0]
    assert momentum.sum() == pytest.approx(momentum_start, rel=1e-9)
    assert momentum[~left].sum() > MOMENTUM_SHARE * momentum_start
    # the overlap stays a small part of the tets' size (0.025 m)
    assert deepest > -0.0025


def test_pieces_of_a_body_meet_in_contact_elsewhere():
    body, system = _cut_bar()
    right = _element_side(body) > 0
    # the right half beside the left one: x in [-0.1, 0], y from 0.052 (2 mm apart)
    body.positions[right] += np.array([-0.1, 0.052, 0.0])
    body.velocities[right, 1] = -1.0
    momentum_start = float((body.masses * body.velocities[:, 1]).sum())
    deepest = 0.0
    for _ in range(80):
        system.step(100)
        gap = body.positions[right, 1].min() - body.positions[~right, 1].max()
        deepest = min(deepest, gap)
    momentum = body.masses * body.velocities[:, 1]
    assert momentum.sum() == pytest.approx(momentum_start, rel=1e-9)
    assert momentum[~right].sum() / momentum_start > SIDE_MOMENTUM_SHARE
    assert deepest > -0.0025
