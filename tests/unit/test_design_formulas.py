"""Breakwater design formulas (``riprap.analysis.design_formulas``) against published test values.

Source: Deltares-research/coastal-structures-toolbox, ``tests/stability_rock_vandermeer1988_test.py``
(as listed in ``shared/research/coupling-waves-deformable.md`` §2.2): Van der Meer (1988) rock in
the H_2% form, c_pl = 8.68, c_s = 1.4, H_2% = 1.4 H_s, rho_w = 1025 kg/m^3; reference cot alpha =
3, P = 0.4, rho_r = 2650 kg/m^3, N = 3000, T_m = 6 s, H_s = 2 m, M50 = 1000 kg -> S = 0.918, and
the listed variations; inverse S = 2 -> D_n50 = 0.618 m and H_s = 2.46 m. Tolerance 0.01, the
source's. Hudson: (K_D cot alpha)^(1/3) = 2 for K_D = 4, cot alpha = 2 (exact). Cubes: the
formula and its inverse agree, and damage grows with the wave height.
"""
import math

import pytest

from riprap.analysis.design_formulas import (hudson_nominal_diameter, hudson_stability_number,
                                             van_der_meer_cubes_damage, van_der_meer_rock_damage,
                                             van_der_meer_rock_diameter,
                                             van_der_meer_rock_wave_height)
from riprap.errors import CaseFileError

REFERENCE = dict(hs=2.0, tm=6.0, waves=3000, slope_cot=3.0, permeability=0.4, armour_density=2650.0,
                 water_density=1025.0)
D_N50 = (1000.0 / 2650.0) ** (1.0 / 3.0)


@pytest.mark.parametrize("change, expected", [
    ({}, 0.918), ({"slope_cot": 2.0}, 2.53), ({"permeability": 0.5}, 0.751), ({"waves": 6000}, 1.30),
    ({"tm": 12.0}, 2.51), ({"hs": 2.5}, 2.12),
])
def test_van_der_meer_rock_damage_matches_the_published_values(change, expected):
    inputs = {**REFERENCE, **change}
    assert abs(van_der_meer_rock_damage(**inputs, nominal_diameter=D_N50) - expected) < 0.01


def test_van_der_meer_rock_inverse_forms():
    assert abs(van_der_meer_rock_diameter(**REFERENCE, damage=2.0) - 0.618) < 0.01
    others = {k: v for k, v in REFERENCE.items() if k != "hs"}
    assert abs(van_der_meer_rock_wave_height(**others, nominal_diameter=D_N50, damage=2.0) - 2.46) < 0.01


def test_hudson():
    assert hudson_stability_number(4.0, 2.0) == pytest.approx(2.0, rel=1e-12)
    assert hudson_nominal_diameter(3.0, 1.5, 4.0, 2.0) == pytest.approx(1.0, rel=1e-12)


def test_van_der_meer_cubes():
    delta, dn = 2400.0 / 1025.0 - 1.0, 1.0
    small = van_der_meer_cubes_damage(hs=2.5, tm=7.0, waves=1000, delta=delta, nominal_diameter=dn)
    large = van_der_meer_cubes_damage(hs=3.5, tm=7.0, waves=1000, delta=delta, nominal_diameter=dn)
    assert 0 < small < large
    steepness = 2 * math.pi * 3.5 / (9.81 * 49.0)
    ns = (6.7 * large ** 0.4 / 1000 ** 0.3 + 1.0) * steepness ** -0.1
    assert ns == pytest.approx(3.5 / (delta * dn), rel=1e-12)
    assert van_der_meer_cubes_damage(hs=0.5, tm=7.0, waves=1000, delta=delta, nominal_diameter=dn) == 0.0
    with pytest.raises(CaseFileError, match="hs must be a positive"):
        van_der_meer_cubes_damage(hs=-1.0, tm=7.0, waves=1000, delta=delta, nominal_diameter=dn)
