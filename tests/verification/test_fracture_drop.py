"""A unit dropped from increasing heights (issue 16): the height at which it first breaks, and
breaking that does not depend on the time step.

A Core-Loc-like unit (riprap's armour library, H = 0.5 m, mesh_size 0.05 m: 2,479 tets, 4,392
joints; concrete: E = 30 GPa, nu = 0.2, 2400 kg/m^3, f_t = 3 MPa, c = 6 MPa, phi = 30 deg,
G_I = 100 J/m^2, G_II = 1000 J/m^2, joint penalty 10 E) turned 30 degrees about x, so that it
lands on the corner of one fluke, falls onto a rigid floor (friction 0.6, restitution 0.5) from
``HEIGHTS`` (started 0.2 mm above the floor at sqrt(2 g h)), followed for 3 ms after it lands,
with the stable step times 0.9 and times 0.45.

Stated, as the issue asks (measured on this machine, 2026-11-26 session 11, joints with friction
as a sliding spring, broken joints keeping it; step x 0.9 / x 0.45): from 3 cm no joint breaks;
from 5 cm 4 / 4 joints break at the fluke's corner (20 cm^2 of crack, still one piece); from
10 cm 21 / 21 joints, 88 cm^2, 6 pieces, the largest 99.8 % of the unit. It breaks first between
3 and 5 cm at both steps; at each height the broken area at the two steps agrees within
``AREA_TOLERANCE`` = 30 % (measured: the same joints break). (Before the joints' friction slid,
session 10, the first break was between 1 and 2 cm and drops from 10 cm stopped on an inverted
element: the elastic friction law pumped energy into the crushed corner.)

No published figure is compared: a corner landing on a rigid floor concentrates the contact
stress on a few tets, so the height of the first chip depends on the mesh (finer tets, higher
stress at the corner).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.deformable.joints import FracturingBody, JointMaterial
from riprap.deformable.material import ElasticMaterial
from riprap.deformable.system import DeformableSystem
from riprap.geometry.armour_units import armour_unit

YOUNG = 30e9
HEIGHTS = (0.03, 0.05, 0.1)
STEP_FACTORS = (0.9, 0.45)
AREA_TOLERANCE = 0.30
GAP = 2e-4
AFTER_LANDING = 0.003


@pytest.fixture(scope="module")
def drops():
    unit = armour_unit("core_loc_like", height=0.5, mesh_size=0.05).mesh
    rotation = Rotation.from_quat([0.2588, 0.0, 0.0, 0.9659]).as_matrix()
    nodes = (unit.nodes - unit.nodes.mean(axis=0)) @ rotation.T
    nodes[:, 2] -= nodes[:, 2].min() - GAP
    material = ElasticMaterial(young_modulus=YOUNG, poisson_ratio=0.2, density=2400.0)
    joints = JointMaterial(tensile_strength=3e6, cohesion=6e6, friction_angle=30.0,
                           fracture_energy_mode_i=100.0, fracture_energy_mode_ii=1000.0,
                           joint_penalty=10 * YOUNG)
    results = {}
    for factor in STEP_FACTORS:
        for height in HEIGHTS:
            body = FracturingBody(nodes, unit.tets, material, joints, name="unit",
                                  gravity=(0.0, 0.0, -9.81))
            system = DeformableSystem([body], walls=[((0, 0, 0), (0, 0, 1), 0.6)],
                                      gravity=(0.0, 0.0, -9.81))
            system.time_step = factor * system.stable_time_step()
            speed = np.sqrt(2 * 9.81 * height)
            body.velocities[:, 2] = -speed
            system.step(int((GAP / speed + AFTER_LANDING) / system.time_step))
            summary = body.breakage_summary()
            summary["broken"] = int(body.joint_broken.sum())
            summary["mass_sum"] = float(body.fragment_table()["mass"].sum() / body.mass)
            results[factor, height] = summary
            print(f"step x {factor}, h = {height} m: {summary}")
    return results


def _first_break(results, factor):
    return next((h for h in HEIGHTS if results[factor, h]["broken"] > 0), None)


def test_the_height_of_the_first_break_does_not_depend_on_the_step(drops):
    first = [_first_break(drops, factor) for factor in STEP_FACTORS]
    assert first[0] == first[1] == 0.05


def test_the_broken_area_does_not_depend_on_the_step(drops):
    for height in HEIGHTS[1:]:
        long, short = (drops[factor, height]["broken_area_m2"] for factor in STEP_FACTORS)
        assert long == pytest.approx(short, rel=AREA_TOLERANCE)
        assert drops[0.9, height]["largest_fragment_mass_fraction"] > 0.99


def test_no_mass_is_lost_to_the_pieces(drops):
    for summary in drops.values():
        assert summary["mass_sum"] == pytest.approx(1.0, abs=1e-12)
