"""The unit-breakage example (examples/11_unit_breakage: a Core-Loc-like unit, H = 1 m, landing at
2.43 m/s on six fixed rocks, 20 ms) run as shipped: its joints take energy from the unit and never
give more back than they took.

The joints' work on the nodes (``fracture_energy`` = minus that work: what they store and
dissipate) must be positive and at least G_I times the broken area (every broken joint has
released at least its mode I fracture energy in the mixed-mode law, Munjiza, Andrews & White
1999; here G_II = 10 G_I). Before broken joints pushed their faces apart at one place
(riprap/deformable/kernels/joints.py, ``_broken_joint``), four joints whose pieces slid along the
crack pumped 66 J into them in 6 ms: ``fracture_energy`` was -66 J. With friction_angle
30 degrees and Munjiza's elastic-like friction (f_s = c - tan(phi) sigma in the softening curve)
it was -881 J at 20 ms; with the friction as a sliding spring (kernels/joints.py), measured now
(20 ms, friction_angle 30, broken joints keeping their friction): +648 J against G_I A = 12 J
(86 joints, 0.115 m^2).
"""
from pathlib import Path

from riprap.case.build import build_simulation
from riprap.case.load import load_case

CASE = Path(__file__).resolve().parents[2] / "examples" / "11_unit_breakage" / "case.toml"
MODE_I_ENERGY = 100.0    # J/m^2, the example's [deformable] fracture_energy_mode_i


def test_the_breakage_example_joints_take_energy_and_give_none(tmp_path):
    case = load_case(CASE)
    assert case.deformable.fracture_energy_mode_i == MODE_I_ENERGY
    summary = build_simulation(case, output_directory=tmp_path, progress=False).run()
    assert summary.broken_joints > 0
    assert summary.fracture_energy >= MODE_I_ENERGY * summary.broken_area > 0.0
