"""Rock armour stability formulas (``riprap.analysis.rock_formulas``).

Hand-computed points: each expected value is written out below from the paper's equation with
numbers, not by calling the code under test; tolerance 1e-9 relative (``ARITHMETIC``), the two
sides being the same arithmetic in another order. Published test values: Deltares-research/
coastal-structures-toolbox, ``tests/structural/stability_rock_armour/vandermeer2021_test.py`` and
``etemadshahidi2020_test.py`` (rho_w = 1025 kg/m^3, D_n50 = (M50 / rho)^(1/3)), tolerance 0.01
on S and 0.001 m on D_n50, the source's own.

Sources of the formulas: Van der Meer (2021), J. Waterway, Port, Coastal, Ocean Eng. 147(4);
Van Gent, Smale & Kuiper (2003), Proc. Coastal Structures 2003; Etemad-Shahidi, Bali & van Gent
(2020), Coastal Engineering 158, 103655, and its 2022 corrigendum; damage classes: The Rock
Manual (2007), Table 5.22.
"""
import doctest
import math

import pytest

from riprap.analysis import rock_formulas
from riprap.analysis.rock_formulas import (EtemadShahidi2020Rock, VanDerMeer2021Rock,
                                           etemad_shahidi_2020_cautions,
                                           etemad_shahidi_2020_damage,
                                           etemad_shahidi_2020_diameter,
                                           etemad_shahidi_permeability_coefficient,
                                           notional_permeability, rock_damage_class,
                                           van_der_meer_2021_cautions, van_der_meer_2021_damage,
                                           van_der_meer_2021_diameter, van_gent_2003_cautions,
                                           van_gent_2003_damage, van_gent_2003_diameter)
from riprap.errors import CaseFileError

#: Pure arithmetic, the same operations in another order: rounding only.
ARITHMETIC = 1e-9
#: The toolbox's tests state S to 0.01 and D_n50 to 0.001 m.
TOOLBOX_S = 0.01
TOOLBOX_DN50 = 1e-3

G = 9.81
DELTA = 2650.0 / 1025.0 - 1.0          # 1.5853658...
SEA = dict(hs=2.0, spectral_period=6.0, waves=3000, slope_cot=3.0, armour_density=2650.0,
           water_density=1025.0)


def _close(value, expected):
    assert abs(value - expected) <= ARITHMETIC * abs(expected)


# ---------------------------------------------------------------------------------------------
# Van der Meer (2021): N_s = 6.49 P^0.18 (S/sqrt N)^0.2 xi^-0.5 (plunging),
#                      N_s = 0.97 P^-0.13 (S/sqrt N)^0.2 sqrt(cot a) xi^P (surging)

def test_van_der_meer_2021_plunging_by_hand():
    # H_s 2 m, T_m-1,0 6 s, cot a 3, P 0.4, N 3000, D_n50 0.7 m
    xi = (1 / 3) / math.sqrt(2 * math.pi * 2.0 / (9.81 * 6.0 ** 2))       # 1.7671
    xi_cr = (6.49 / 0.97 * 0.4 ** 0.31 * math.sqrt(1 / 3)) ** (1 / 0.9)  # 3.27: plunging
    assert xi < xi_cr
    ns = 2.0 / (DELTA * 0.7)                                              # 1.8022
    expected = (ns / (6.49 * 0.4 ** 0.18 * xi ** -0.5)) ** 5 * math.sqrt(3000)
    _close(van_der_meer_2021_damage(**SEA, permeability=0.4, nominal_diameter=0.7), expected)


def test_van_der_meer_2021_surging_by_hand():
    # cot a 2, T_m-1,0 14 s: xi = 0.5 / sqrt(2 pi 2 / (9.81 196)) = 6.18 above xi_cr = 4.10
    xi = 0.5 / math.sqrt(2 * math.pi * 2.0 / (9.81 * 14.0 ** 2))
    xi_cr = (6.49 / 0.97 * 0.4 ** 0.31 * math.sqrt(0.5)) ** (1 / 0.9)
    assert xi > xi_cr
    ns = 2.0 / (DELTA * 0.6)
    expected = (ns / (0.97 * 0.4 ** -0.13 * math.sqrt(2.0) * xi ** 0.4)) ** 5 * math.sqrt(3000)
    inputs = {**SEA, "spectral_period": 14.0, "slope_cot": 2.0}
    _close(van_der_meer_2021_damage(**inputs, permeability=0.4, nominal_diameter=0.6), expected)
    assert not VanDerMeer2021Rock(2.0, 14.0, 3000, 2.0, 0.4, DELTA).plunging


def test_van_der_meer_2021_gentle_slope_is_plunging_by_hand():
    # cot a 4, T 14 s, P 0.5: xi = 0.25 / 0.080848 = 3.09 above xi_cr = 2.70, yet plunging
    # (cot a >= 4)
    xi = 0.25 / math.sqrt(2 * math.pi * 2.0 / (9.81 * 14.0 ** 2))
    xi_cr = (6.49 / 0.97 * 0.5 ** 0.31 * math.sqrt(0.25)) ** (1 / 1.0)
    assert xi > xi_cr
    ns = 2.0 / (DELTA * 0.8)
    expected = (ns / (6.49 * 0.5 ** 0.18 * xi ** -0.5)) ** 5 * math.sqrt(1000)
    inputs = {**SEA, "spectral_period": 14.0, "slope_cot": 4.0, "waves": 1000}
    _close(van_der_meer_2021_damage(**inputs, permeability=0.5, nominal_diameter=0.8), expected)


def test_van_der_meer_2021_switches_at_the_transition_and_is_continuous():
    rock = VanDerMeer2021Rock(2.0, 6.0, 3000, 3.0, 0.4, DELTA)
    # the period that puts xi on xi_cr: xi = tan a T sqrt(g / (2 pi H)) -> T = xi_cr / (...)
    period = rock.xi_transition / ((1 / 3) * math.sqrt(9.81 / (2 * math.pi * 2.0)))
    below = VanDerMeer2021Rock(2.0, period * (1 - 1e-7), 3000, 3.0, 0.4, DELTA)
    above = VanDerMeer2021Rock(2.0, period * (1 + 1e-7), 3000, 3.0, 0.4, DELTA)
    assert below.plunging and not above.plunging
    # the two forms meet at xi_cr, the point the transition is defined by
    assert abs(below.damage(0.7) / above.damage(0.7) - 1) < 1e-5


@pytest.mark.parametrize("slope_cot, permeability, density, waves, period, hs, mass, expected", [
    (3.0, 0.4, 2650, 3000, 6.0, 2.0, 1000.0, 0.730), (2.0, 0.4, 2650, 3000, 6.0, 2.0, 1000.0, 2.01),
    (3.0, 0.5, 2650, 3000, 6.0, 2.0, 1000.0, 0.597), (3.0, 0.4, 2850, 3000, 6.0, 2.0, 1000.0, 0.461),
    (3.0, 0.4, 2650, 6000, 6.0, 2.0, 1000.0, 1.03), (3.0, 0.4, 2650, 3000, 14.0, 2.0, 1000.0, 2.15),
    (3.0, 0.4, 2650, 3000, 6.0, 2.5, 1000.0, 1.69), (3.0, 0.4, 2650, 3000, 6.0, 2.0, 1200.0, 0.539),
    (4.0, 0.4, 2650, 3000, 6.0, 2.0, 1000.0, 0.356), (4.0, 0.4, 2650, 3000, 14.0, 2.0, 1000.0, 2.96),
])
def test_van_der_meer_2021_toolbox_values(slope_cot, permeability, density, waves, period, hs,
                                          mass, expected):
    damage = van_der_meer_2021_damage(
        hs=hs, spectral_period=period, waves=waves, slope_cot=slope_cot, permeability=permeability,
        armour_density=density, water_density=1025.0, nominal_diameter=(mass / density) ** (1 / 3))
    assert abs(damage - expected) < TOOLBOX_S


def test_van_der_meer_2021_inverse_round_trip():
    for period, slope_cot in ((6.0, 3.0), (14.0, 2.0), (14.0, 4.0)):
        inputs = {**SEA, "spectral_period": period, "slope_cot": slope_cot, "permeability": 0.4}
        diameter = van_der_meer_2021_diameter(**inputs, damage=2.0)
        _close(van_der_meer_2021_damage(**inputs, nominal_diameter=diameter), 2.0)
    # toolbox vandermeer2021_test.py, test_Dn50_backward, first row: S 2 -> D_n50 0.591 m
    assert abs(van_der_meer_2021_diameter(**SEA, permeability=0.4, damage=2.0) - 0.591) < TOOLBOX_S


# ---------------------------------------------------------------------------------------------
# Van Gent, Smale & Kuiper (2003): H_s/(Delta D) = 1.75 sqrt(cot a) (1 + D_core/D) (S/sqrt N)^0.2

GENT = dict(hs=2.0, waves=3000, slope_cot=3.0, armour_density=2650.0, water_density=1025.0)


@pytest.mark.parametrize("hs, waves, slope_cot, diameter, core, expected", [
    # impermeable core: S = (2 / (1.58537 0.8) / (1.75 sqrt 3))^5 sqrt 3000
    (2.0, 3000, 3.0, 0.8, 0.0,
     (2.0 / (DELTA * 0.8) / (1.75 * math.sqrt(3.0))) ** 5 * math.sqrt(3000)),
    # permeable core, D_core / D = 0.24 / 0.8 = 0.3
    (2.0, 3000, 3.0, 0.8, 0.24,
     (2.0 / (DELTA * 0.8) / (1.75 * math.sqrt(3.0) * 1.3)) ** 5 * math.sqrt(3000)),
    # cot a 2, N 1000, H_s 1.5 m, D 0.5 m, D_core 0.1 m
    (1.5, 1000, 2.0, 0.5, 0.1,
     (1.5 / (DELTA * 0.5) / (1.75 * math.sqrt(2.0) * 1.2)) ** 5 * math.sqrt(1000)),
])
def test_van_gent_2003_by_hand(hs, waves, slope_cot, diameter, core, expected):
    _close(van_gent_2003_damage(hs=hs, waves=waves, slope_cot=slope_cot, armour_density=2650.0,
                                water_density=1025.0, nominal_diameter=diameter,
                                core_nominal_diameter=core), expected)


def test_van_gent_2003_inverse():
    # closed form: D = H_s / (Delta 1.75 sqrt(3) (2 / sqrt 3000)^0.2) - D_core
    expected = 2.0 / (DELTA * 1.75 * math.sqrt(3.0) * (2.0 / math.sqrt(3000)) ** 0.2) - 0.2
    diameter = van_gent_2003_diameter(**GENT, damage=2.0, core_nominal_diameter=0.2)
    _close(diameter, expected)
    _close(van_gent_2003_damage(**GENT, nominal_diameter=diameter, core_nominal_diameter=0.2), 2.0)
    with pytest.raises(CaseFileError, match="no positive D_n50"):
        van_gent_2003_diameter(**GENT, damage=2.0, core_nominal_diameter=5.0)


# ---------------------------------------------------------------------------------------------
# Etemad-Shahidi, Bali & van Gent (2020): N_s = 4.5 C_p N^-0.1 S^(1/6) xi^(-7/12) (plunging),
# 3.9 C_p N^-0.1 S^(1/6) xi^(-1/3) (surging), C_p = (1 + (D_core/D)^0.3)^0.6

def test_etemad_shahidi_permeability_coefficient_by_hand():
    _close(etemad_shahidi_permeability_coefficient(nominal_diameter=1.0, core_nominal_diameter=0.3),
           (1 + 0.3 ** 0.3) ** 0.6)                                        # 1.4086
    assert etemad_shahidi_permeability_coefficient(nominal_diameter=1.0,
                                                   core_nominal_diameter=0.0) == 1.0
    _close(etemad_shahidi_permeability_coefficient(nominal_diameter=0.5, core_nominal_diameter=0.5),
           2.0 ** 0.6)


def test_etemad_shahidi_2020_plunging_by_hand():
    # H_s 2, T 6, cot a 3: xi = 1.7671 < 1.8; D 0.7, D_core 0.21 (ratio 0.3)
    xi = (1 / 3) / math.sqrt(2 * math.pi * 2.0 / (9.81 * 36.0))
    assert xi < 1.8
    ns = 2.0 / (DELTA * 0.7)
    cp = (1 + 0.3 ** 0.3) ** 0.6
    expected = (ns / (4.5 * cp * xi ** (-7 / 12))) ** 6 * 3000 ** 0.6
    _close(etemad_shahidi_2020_damage(**SEA, nominal_diameter=0.7, core_nominal_diameter=0.21),
           expected)


def test_etemad_shahidi_2020_surging_by_hand():
    # T 8 s: xi = (1/3) / sqrt(2 pi 2 / (9.81 64)) = 2.356 >= 1.8; impermeable core, C_p = 1
    xi = (1 / 3) / math.sqrt(2 * math.pi * 2.0 / (9.81 * 64.0))
    assert xi >= 1.8
    ns = 2.0 / (DELTA * 0.7)
    expected = (ns / (3.9 * 1.0 * xi ** (-1 / 3))) ** 6 * 3000 ** 0.6
    inputs = {**SEA, "spectral_period": 8.0}
    _close(etemad_shahidi_2020_damage(**inputs, nominal_diameter=0.7, core_nominal_diameter=0.0),
           expected)


def test_etemad_shahidi_2020_depth_limited_by_hand():
    # foreshore 1:50, m = 0.02: factor 1 - 0.06 = 0.94 on N_s, so S / 0.94^6
    xi = (1 / 3) / math.sqrt(2 * math.pi * 2.0 / (9.81 * 36.0))
    ns = 2.0 / (DELTA * 0.7)
    cp = (1 + 0.3 ** 0.3) ** 0.6
    expected = (ns / (4.5 * cp * xi ** (-7 / 12) * 0.94)) ** 6 * 3000 ** 0.6
    _close(etemad_shahidi_2020_damage(**SEA, nominal_diameter=0.7, core_nominal_diameter=0.21,
                                      foreshore_slope_cot=50.0), expected)


def test_etemad_shahidi_2020_switches_at_xi_1_8():
    # xi = 1.8 exactly: T = 1.8 / ((1/3) sqrt(g / (2 pi H)))
    period = 1.8 / ((1 / 3) * math.sqrt(9.81 / (2 * math.pi * 2.0)))   # 6.1117 s
    above = EtemadShahidi2020Rock(2.0, period * (1 + 1e-9), 3000, 3.0, DELTA, 0.21)
    below = EtemadShahidi2020Rock(2.0, period * (1 - 1e-9), 3000, 3.0, DELTA, 0.21)
    assert not above.plunging and below.plunging
    ns = 2.0 / (DELTA * 0.7)
    cp = (1 + 0.3 ** 0.3) ** 0.6
    xi = 1.8 * (1 + 1e-9)                       # xi grows as T: xi = tan a T sqrt(g / (2 pi H))
    _close(above.damage(0.7), (ns / (3.9 * cp * xi ** (-1 / 3))) ** 6 * 3000 ** 0.6)
    xi = 1.8 * (1 - 1e-9)
    _close(below.damage(0.7), (ns / (4.5 * cp * xi ** (-7 / 12))) ** 6 * 3000 ** 0.6)


@pytest.mark.parametrize(
    "slope_cot, core_mass, density, core_density, waves, period, hs, mass, expected", [
    (3.0, 100.0, 2650, 2650, 3000, 6.0, 2.0, 1000.0, 0.372),
    (2.0, 100.0, 2650, 2650, 3000, 6.0, 2.0, 1000.0, 0.840),
    (3.0, 150.0, 2650, 2650, 3000, 6.0, 2.0, 1000.0, 0.348),
    (3.0, 100.0, 2850, 2650, 3000, 6.0, 2.0, 1000.0, 0.212),
    (3.0, 100.0, 2650, 2500, 3000, 6.0, 2.0, 1000.0, 0.368),
    (3.0, 100.0, 2650, 2650, 6000, 6.0, 2.0, 1000.0, 0.563),
    (3.0, 100.0, 2650, 2650, 3000, 14.0, 2.0, 1000.0, 2.033),
    (3.0, 100.0, 2650, 2650, 3000, 6.0, 2.5, 1000.0, 0.960),
    (3.0, 100.0, 2650, 2650, 3000, 6.0, 2.0, 1200.0, 0.266),
])
def test_etemad_shahidi_2020_toolbox_values(slope_cot, core_mass, density, core_density, waves,
                                            period, hs, mass, expected):
    damage = etemad_shahidi_2020_damage(
        hs=hs, spectral_period=period, waves=waves, slope_cot=slope_cot, armour_density=density,
        water_density=1025.0, nominal_diameter=(mass / density) ** (1 / 3),
        core_nominal_diameter=(core_mass / core_density) ** (1 / 3))
    assert abs(damage - expected) < TOOLBOX_S


def test_etemad_shahidi_2020_inverse_round_trip():
    for period, core, foreshore in ((6.0, 0.21, None), (8.0, 0.0, None), (6.0, 0.4, 30.0)):
        inputs = {**SEA, "spectral_period": period, "core_nominal_diameter": core,
                  "foreshore_slope_cot": foreshore}
        diameter = etemad_shahidi_2020_diameter(**inputs, damage=3.0)
        _close(etemad_shahidi_2020_damage(**inputs, nominal_diameter=diameter), 3.0)
    # toolbox etemadshahidi2020_test.py, test_Dn50_backward, first row: S 0.350 -> 0.731 m
    core = (100.0 / 2650.0) ** (1 / 3)
    diameter = etemad_shahidi_2020_diameter(**SEA, damage=0.350, core_nominal_diameter=core)
    assert abs(diameter - 0.731) < TOOLBOX_DN50


# ---------------------------------------------------------------------------------------------
# Validity ranges

def test_cautions_empty_inside_the_ranges():
    assert van_der_meer_2021_cautions(**SEA, permeability=0.4, nominal_diameter=0.7, damage=2.0,
                                      water_depth=10.0, grading_ratio=1.5) == []
    assert van_gent_2003_cautions(**{**SEA, "spectral_period": 12.0}, nominal_diameter=0.7,
                                  core_nominal_diameter=0.2) == []
    assert etemad_shahidi_2020_cautions(**SEA, nominal_diameter=0.7, core_nominal_diameter=0.21,
                                        damage=4.0) == []


@pytest.mark.parametrize("change, label", [
    ({"slope_cot": 1.2}, "cot α = 1.2 is below Van der Meer's tested range 1.5-6"),
    ({"slope_cot": 7.0}, "cot α = 7 is above"),
    ({"waves": 9000}, "N = 9000 is above Van der Meer's tested maximum 7500"),
    ({"spectral_period": 3.0}, "s_m-1,0"),
    ({"armour_density": 2000.0}, "Δ = 0.951 is below"),
    ({"water_depth": 4.0}, "h/H_s = 2 is below Van der Meer's tested minimum 3"),
    ({"grading_ratio": 3.0}, "D_n85/D_n15 = 3 is above"),
    ({"damage": 60.0}, "S/√N"),
    ({"nominal_diameter": 0.2}, "N_s = H_s/(Δ D_n50) = 6.31 is above"),
])
def test_van_der_meer_2021_cautions_outside(change, label):
    inputs = {**SEA, "permeability": 0.4, "nominal_diameter": 0.7, "damage": 2.0,
              "water_depth": 10.0, "grading_ratio": 1.5, **change}
    cautions = van_der_meer_2021_cautions(**inputs)
    assert any(label in caution for caution in cautions), cautions


def test_van_gent_and_etemad_shahidi_cautions_outside():
    assert van_gent_2003_cautions(slope_cot=1.5) == [
        "cot α = 1.5 is below Van Gent et al. (2003)'s tested range 2-4"]
    assert van_gent_2003_cautions(nominal_diameter=0.5, core_nominal_diameter=0.25) == [
        "D_n50,core/D_n50 = 0.5 is above Van Gent et al. (2003)'s tested range 0-0.3"]
    cautions = etemad_shahidi_2020_cautions(**{**SEA, "waves": 300}, damage=0.5)
    assert "N = 300 is below Etemad-Shahidi et al. (2020)'s tested range 500-5000" in cautions
    assert "S = 0.5 is below Etemad-Shahidi et al. (2020)'s tested range 2-12" in cautions


def test_cautions_refuse_unknown_inputs():
    with pytest.raises(CaseFileError, match="unknown input 'slope'"):
        van_der_meer_2021_cautions(slope=2.0)


# ---------------------------------------------------------------------------------------------
# Bad input

@pytest.mark.parametrize("change, name", [
    ({"hs": -1.0}, "hs"), ({"slope_cot": 0.0}, "slope_cot"), ({"slope_cot": -2.0}, "slope_cot"),
    ({"spectral_period": -6.0}, "spectral_period"), ({"waves": 0}, "waves"),
])
def test_bad_sea_or_slope_refused(change, name):
    for call in (lambda: van_der_meer_2021_damage(**{**SEA, **change}, permeability=0.4,
                                                  nominal_diameter=0.7),
                 lambda: etemad_shahidi_2020_damage(**{**SEA, **change}, nominal_diameter=0.7,
                                                    core_nominal_diameter=0.2)):
        with pytest.raises(CaseFileError, match=name):
            call()
    if name != "spectral_period":
        inputs = {key: value for key, value in {**SEA, **change}.items()
                  if key != "spectral_period"}
        with pytest.raises(CaseFileError, match=name):
            van_gent_2003_damage(**inputs, nominal_diameter=0.7, core_nominal_diameter=0.2)


@pytest.mark.parametrize("damage", [0.0, -1.0])
def test_non_positive_damage_refused(damage):
    with pytest.raises(CaseFileError, match="damage"):
        van_der_meer_2021_diameter(**SEA, permeability=0.4, damage=damage)
    with pytest.raises(CaseFileError, match="damage"):
        van_gent_2003_diameter(**{k: v for k, v in SEA.items() if k != "spectral_period"},
                               damage=damage, core_nominal_diameter=0.0)
    with pytest.raises(CaseFileError, match="damage"):
        etemad_shahidi_2020_diameter(**SEA, damage=damage, core_nominal_diameter=0.0)


@pytest.mark.parametrize("permeability", [0.05, 0.7, -0.4])
def test_permeability_outside_van_der_meer_refused(permeability):
    with pytest.raises(CaseFileError, match="permeability"):
        van_der_meer_2021_damage(**SEA, permeability=permeability, nominal_diameter=0.7)
    with pytest.raises(CaseFileError, match="permeability"):
        van_der_meer_2021_cautions(permeability=permeability)


def test_bad_core_and_foreshore_refused():
    with pytest.raises(CaseFileError, match="core_nominal_diameter"):
        etemad_shahidi_2020_damage(**SEA, nominal_diameter=0.7, core_nominal_diameter=-0.1)
    with pytest.raises(CaseFileError, match="foreshore_slope_cot"):
        etemad_shahidi_2020_damage(**SEA, nominal_diameter=0.7, core_nominal_diameter=0.1,
                                   foreshore_slope_cot=2.0)


# ---------------------------------------------------------------------------------------------
# Notional permeability

@pytest.mark.parametrize("layers, expected", [
    (dict(filter_dn50=0.5, core_dn50=0.1, core_permeable=False), 0.1),
    (dict(filter_dn50=0.5, core_permeable=False), 0.1),
    (dict(filter_dn50=0.5, core_dn50=0.2), 0.4),
    (dict(core_dn50=1 / 3.2), 0.5),
    (dict(core_dn50=1 / 1.9), 0.5),
    (dict(core_dn50=1 / 1.7), 0.6),
    (dict(core_dn50=1.0), 0.6),
    (dict(), 0.6),
])
def test_notional_permeability(layers, expected):
    permeability, reason = notional_permeability(1.0, **layers)
    assert permeability == expected
    assert f"P = {expected:g}" in reason


def test_notional_permeability_says_when_the_core_is_much_finer():
    assert "less permeable" in notional_permeability(1.0, core_dn50=0.1)[1]


def test_notional_permeability_refuses_bad_layers():
    with pytest.raises(CaseFileError, match="core_dn50"):
        notional_permeability(1.0, core_dn50=-0.2)
    with pytest.raises(CaseFileError, match="armour_dn50"):
        notional_permeability(0.0)
    with pytest.raises(CaseFileError, match="core_permeable"):
        notional_permeability(1.0, core_permeable="no")


# ---------------------------------------------------------------------------------------------
# Damage classes (The Rock Manual, Table 5.22)

@pytest.mark.parametrize("damage, slope_cot, expected", [
    (1.9, 2.0, "none"), (2.0, 2.0, "start of damage"), (3.9, 2.0, "start of damage"),
    (4.0, 2.0, "intermediate"), (7.9, 2.0, "intermediate"), (8.0, 2.0, "failure"),
    (2.5, 4.0, "none"), (3.0, 4.0, "start of damage"), (12.0, 3.0, "failure"),
    (0.0, 6.0, "none"),
])
def test_rock_damage_class(damage, slope_cot, expected):
    assert rock_damage_class(damage, slope_cot)[0] == expected


def test_rock_damage_class_takes_the_steeper_row():
    _, between = rock_damage_class(7.0, 3.5)
    assert (between.slope_cot, between.start, between.intermediate, between.failure) == (
        3.0, 2.0, (6.0, 9.0), 12.0)
    assert "steeper row" in between.note
    _, steep = rock_damage_class(1.0, 1.2)
    assert steep.slope_cot == 1.5 and "steeper than the table" in steep.note
    _, gentle = rock_damage_class(1.0, 8.0)
    assert gentle.slope_cot == 6.0 and "gentler" in gentle.note
    with pytest.raises(CaseFileError, match="damage"):
        rock_damage_class(-1.0, 2.0)
    with pytest.raises(CaseFileError, match="slope_cot"):
        rock_damage_class(1.0, 0.0)


def test_docstring_examples():
    assert doctest.testmod(rock_formulas).failed == 0
