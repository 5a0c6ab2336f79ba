"""Armour stone gradings: EN 13383-1 classes, the Rosin-Rammler mass curve, drawn stones, grading
statistics and conformity, scaling to a laboratory model.

Sources: the class table (NLL, NUL, M_em) is shared/validation/armour_design.md section 5.3
(EN 13383-1:2002 via Sander-w/breakwater), ELL = 0.7 NLL and EUL = 1.5 NUL; the curve and the
scaling rule are those written out in riprap/geometry/armour_stone.py's notes. Hand values are
worked in the comments to 5 or more figures and compared to 1e-4 (relative) unless said.

Sampling tolerance: 20 000 stones, seed 1. Over 20 seeds the relative scatter (one standard
deviation) of the sample's mass-weighted M50, M85 / M15 and M_em was 0.33 %, 0.56 %, 0.20 % for HMA
300/1000 (n = 3.0) and 1.2 %, 2.0 %, 0.7 % for the wide LMA 15/300 (n = 1.2: few heavy stones
carry much of the mass); the tolerances below are four of them. Measured with seed 1: HMA 300/1000
+0.3 %, -1.0 %, +0.1 %; LMA 15/300 +2.0 %, +2.6 %, +1.5 %. Stones drawn by mass instead of by
count would put M50 far above (every stone a draw of the mass curve: the mass-weighted median of
such a set is the curve's M_0.71 or so).
"""
import math

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.geometry.armour_stone import (STANDARD_CLASS_NAMES, ArmourGrading, en13383_conformity,
                                          grading_statistics, standard_class, standard_grading,
                                          uniformity_index)
from riprap.geometry.rock_grading import RockGrading

HAND = 1e-4
SAMPLE_SIZE = 20_000


# -- the class table ----------------------------------------------------------------------------

@pytest.mark.parametrize("name, limits, effective_mean_mass_range", [
    # ELL = 0.7 NLL, NLL, NUL, EUL = 1.5 NUL; M_em range (armour_design.md 5.3)
    ("HMA 300/1000", (210.0, 300.0, 1000.0, 1500.0), (540.0, 690.0)),
    ("LMA 10/60", (7.0, 10.0, 60.0, 90.0), (20.0, 35.0)),
    ("LMA 15/300", (10.5, 15.0, 300.0, 450.0), (45.0, 135.0)),
    ("HMA 10000/15000", (7000.0, 10000.0, 15000.0, 22500.0), (12000.0, 13000.0)),
])
def test_class_table_values(name, limits, effective_mean_mass_range):
    grading_class = standard_class(name)
    assert grading_class.name == name
    assert (grading_class.extreme_lower_limit, grading_class.nominal_lower_limit,
            grading_class.nominal_upper_limit, grading_class.extreme_upper_limit) == limits
    assert grading_class.effective_mean_mass_range == effective_mean_mass_range


def test_every_class_is_known_and_its_extreme_limits_follow_the_rule():
    assert STANDARD_CLASS_NAMES == (
        "LMA 5/40", "LMA 10/60", "LMA 40/200", "LMA 15/300", "LMA 60/300", "HMA 300/1000",
        "HMA 1000/3000", "HMA 3000/6000", "HMA 6000/10000", "HMA 10000/15000")
    for name in STANDARD_CLASS_NAMES:
        grading_class = standard_class(name)
        assert grading_class.extreme_lower_limit == pytest.approx(
            0.7 * grading_class.nominal_lower_limit, rel=1e-12)
        assert grading_class.extreme_upper_limit == pytest.approx(
            1.5 * grading_class.nominal_upper_limit, rel=1e-12)
        low, high = grading_class.effective_mean_mass_range
        assert grading_class.nominal_lower_limit < low < high < grading_class.nominal_upper_limit


@pytest.mark.parametrize("written", ["LMA 10/60", "LMA10-60", "lma_10_60", "  Lma 10 / 60 kg ",
                                     "LMA-10-60"])
def test_class_names_written_as_engineers_write_them(written):
    assert standard_class(written).name == "LMA 10/60"
    assert standard_grading(written).standard_class.name == "LMA 10/60"


@pytest.mark.parametrize("name", ["HMA 300/1500", "CP 32/90", "LMB 10/60", "", 300])
def test_unknown_class_names_are_refused_with_the_known_ones(name):
    with pytest.raises(CaseFileError, match="name") as refusal:
        standard_class(name)
    assert repr(name) in str(refusal.value)
    assert "LMA 5/40" in str(refusal.value) and "HMA 10000/15000" in str(refusal.value)


# -- the curve -----------------------------------------------------------------------------------

def test_rosin_rammler_curve_by_hand():
    # M50 = 1000 kg, M85 / M15 = 2.25:
    #   n = ln(ln 0.15 / ln 0.85) / ln 2.25 = 2.457298 / 0.810930 = 3.030221
    grading = ArmourGrading.from_spread(dn50=(1000.0 / 2650.0) ** (1.0 / 3.0),
                                       dn85_over_dn15=2.25 ** (1.0 / 3.0))
    assert uniformity_index(2.25) == pytest.approx(3.030221, rel=HAND)
    assert grading.uniformity_index == pytest.approx(3.030221, rel=HAND)
    assert grading.m50 == pytest.approx(1000.0, rel=1e-12)
    # y(1500) = 1 - exp(ln 0.5 * 1.5^n) = 1 - exp(-0.693147 * 3.416610) = 1 - 0.093648
    #         = 0.906352
    assert grading.mass_passing(1500.0) == pytest.approx(0.906352, rel=HAND)
    # y(1000 / 1.5) = 1 - exp(-0.693147 * 0.292688) = 1 - 0.816380 = 0.183620
    assert grading.mass_passing(1000.0 / 1.5) == pytest.approx(0.183620, rel=HAND)
    assert grading.mass_passing(1000.0) == pytest.approx(0.5, rel=1e-12)
    # M15 = 1000 (ln 0.85 / ln 0.5)^(1/n) = 1000 * 0.234465^0.330009 = 619.613 kg
    # M85 = 1000 (ln 0.15 / ln 0.5)^(1/n) = 1000 * 2.736966^0.330009 = 1394.128 kg
    assert grading.mass_at(0.15) == pytest.approx(619.613, rel=HAND)
    assert grading.mass_at(0.85) == pytest.approx(1394.128, rel=HAND)
    assert grading.m85_over_m15 == pytest.approx(2.25, rel=1e-12)
    assert grading.dn85_over_dn15 == pytest.approx(2.25 ** (1.0 / 3.0), rel=1e-12)
    # D_n50 = (1000 / 2650)^(1/3) = 0.377358^(1/3) = 0.722633 m
    assert grading.dn50 == pytest.approx(0.722633, rel=HAND)
    assert grading.nominal_diameter_at(0.85) == pytest.approx((1394.128 / 2650.0) ** (1 / 3),
                                                              rel=HAND)


def test_standard_curve_by_hand():
    # HMA 300/1000, through NLL at 6 % and NUL at 90 %:
    #   n = ln(ln 0.10 / ln 0.94) / ln(1000 / 300) = ln 37.21325 / 1.203973 = 3.616665 / 1.203973
    #     = 3.003942
    #   M50 = 300 (ln 0.94 / ln 0.5)^(-1/n) = 300 * 0.0892673^-0.332896 = 300 * 2.235168
    #       = 670.550 kg
    grading = standard_grading("HMA 300/1000")
    assert grading.uniformity_index == pytest.approx(3.003942, rel=HAND)
    assert grading.m50 == pytest.approx(670.550, rel=HAND)
    assert grading.mass_passing(300.0) == pytest.approx(0.06, rel=1e-9)
    assert grading.mass_passing(1000.0) == pytest.approx(0.90, rel=1e-9)
    assert grading.density == 2650.0
    assert standard_grading("HMA 300/1000", density=3000.0).dn50 == pytest.approx(
        (670.550 / 3000.0) ** (1.0 / 3.0), rel=HAND)


@pytest.mark.parametrize("name", STANDARD_CLASS_NAMES)
def test_every_standard_curve_meets_its_class(name):
    grading = standard_grading(name)
    grading_class = grading.standard_class
    low, high = grading_class.effective_mean_mass_range
    assert low <= grading.effective_mean_mass() <= high
    assert grading.mass_passing(grading_class.extreme_lower_limit) <= 0.05
    assert grading.mass_passing(grading_class.nominal_lower_limit) <= 0.10
    assert grading.mass_passing(grading_class.nominal_upper_limit) >= 0.70
    assert grading.mass_passing(grading_class.extreme_upper_limit) >= 0.97


def test_effective_mean_mass_by_hand_and_against_the_published_ratio():
    # n = 2, every stone counted: the count density is the mass density over M, and
    #   M_mean = M50 / ((ln 2)^(1/2) Gamma(1/2)) = 1000 / sqrt(pi ln 2) = 1000 / 1.475664 = 677.661
    grading = ArmourGrading(m50=1000.0, uniformity_index=2.0)
    assert grading.effective_mean_mass(1e-9) == pytest.approx(677.661, rel=HAND)
    # a limit L far above M50, u_L = ln 2 (L / M50)^n = 0.693147 * 25 = 17.3287: to first order in
    #   1 / u_L, M_em = L (1 + 1 / (n u_L)) = 5000 (1 + 1 / 34.6574) = 5144.27 kg (the next terms
    #   take off 0.15 %)
    assert grading.effective_mean_mass(5000.0) == pytest.approx(5144.27, rel=2e-3)
    # Wikipedia ("Armourstone", after EN 13383): for LMA 15/300 "M50 is 1.57 times the M_em"
    lma = standard_grading("LMA 15/300")
    assert lma.m50 / lma.effective_mean_mass() == pytest.approx(1.57, abs=0.02)


# -- a set of stones -----------------------------------------------------------------------------

TEN_STONES = [700.0, 100.0, 900.0, 300.0, 500.0, 1000.0, 200.0, 800.0, 400.0, 600.0]


def test_statistics_of_ten_stones_by_hand():
    # Sorted: 100 .. 1000 kg, total 5500 kg; mass no heavier than each stone:
    #   100, 300, 600, 1000, 1500, 2100, 2800, 3600, 4500, 5500 kg.
    # M50: 0.5 * 5500 = 2750 kg lies between 2100 (600 kg stone) and 2800 (700 kg stone):
    #   M50 = 600 + 100 (2750 - 2100) / (2800 - 2100) = 600 + 92.857 = 692.857 kg
    # M15: 825 kg between 600 (300 kg) and 1000 (400 kg): 300 + 100 * 225 / 400 = 356.25 kg
    # M85: 4675 kg between 4500 (900 kg) and 5500 (1000 kg): 900 + 100 * 175 / 1000 = 917.5 kg
    # M85 / M15 = 917.5 / 356.25 = 2.575439
    # M_em with ELL = 210 kg: the eight stones of 300..1000 kg, 5200 / 8 = 650 kg
    statistics = grading_statistics(TEN_STONES, density=2650.0, extreme_lower_limit=210.0)
    assert statistics.count == 10 and statistics.total_mass == 5500.0
    assert statistics.m50 == pytest.approx(692.857, rel=HAND)
    assert statistics.m15 == pytest.approx(356.25, rel=1e-12)
    assert statistics.m85 == pytest.approx(917.5, rel=1e-12)
    assert statistics.m85_over_m15 == pytest.approx(2.575439, rel=HAND)
    # D_n50 = (692.857 / 2650)^(1/3) = 0.261456^(1/3) = 0.639439 m;
    # D_n85 / D_n15 = 2.575439^(1/3) = 1.370725
    assert statistics.dn50 == pytest.approx(0.639439, rel=HAND)
    assert statistics.dn85_over_dn15 == pytest.approx(1.370725, rel=HAND)
    assert statistics.effective_mean_mass == 650.0
    # every stone counted: 5500 / 10
    assert grading_statistics(TEN_STONES).effective_mean_mass == 550.0


def test_conformity_by_hand_one_requirement_failed():
    # HMA 300/1000 against the ten stones (total 5500 kg):
    #   lighter than ELL 210: 100 + 200 = 300 kg, 5.45 % > 5 %      fails
    #   lighter than NLL 300: the same 5.45 % <= 10 %               holds
    #   lighter than NUL 1000: 4500 kg, 81.8 % >= 70 %              holds
    #   lighter than EUL 1500: 100 % >= 97 %                        holds
    #   M_em = 650 kg in 540..690                                   holds
    conformity = en13383_conformity(TEN_STONES, "HMA 300/1000")
    measured = [requirement.measured for requirement in conformity.requirements]
    assert measured == pytest.approx([300 / 5500, 300 / 5500, 4500 / 5500, 1.0, 650.0],
                                     rel=1e-12)
    assert [requirement.passed for requirement in conformity.requirements] == [
        False, True, True, True, True]
    assert not conformity.passed
    assert conformity.failures[0].description.endswith("lighter than ELL = 210 kg")


def test_conformity_by_hand_every_requirement_held():
    # 250, 350, 450, 550, 600, 650, 700, 800, 900, 1100 kg, total 6350 kg:
    #   < 210: 0 %; < 300: 250 / 6350 = 3.94 %; < 1000: 5250 / 6350 = 82.7 %; < 1500: 100 %;
    #   M_em = 6350 / 10 = 635 kg
    stones = [250.0, 350.0, 450.0, 550.0, 600.0, 650.0, 700.0, 800.0, 900.0, 1100.0]
    conformity = standard_grading("HMA 300/1000").conformity(stones)
    assert conformity.passed and conformity.failures == ()
    assert [requirement.measured for requirement in conformity.requirements] == pytest.approx(
        [0.0, 250 / 6350, 5250 / 6350, 1.0, 635.0], rel=1e-12)


def test_conformity_fails_on_light_stones_and_on_the_effective_mean_mass():
    # all ten stones 400 kg: every limit holds but NUL (100 % lighter than 1000 kg holds too);
    # M_em = 400 kg < 540 kg fails
    conformity = en13383_conformity([400.0] * 10, standard_class("HMA 300/1000"))
    assert [requirement.passed for requirement in conformity.requirements] == [
        True, True, True, True, False]
    # all 2000 kg: 0 % lighter than NUL fails, 0 % lighter than EUL fails, M_em 2000 fails
    heavy = en13383_conformity([2000.0] * 10, "HMA 300/1000")
    assert [requirement.passed for requirement in heavy.requirements] == [
        True, True, False, False, False]


# -- drawn stones ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name, tolerances", [
    ("HMA 300/1000", (0.015, 0.025, 0.01)),
    ("LMA 15/300", (0.05, 0.08, 0.03)),
])
def test_a_large_sample_has_the_grading(name, tolerances):
    grading = standard_grading(name)
    masses = grading.sample_masses(SAMPLE_SIZE, np.random.default_rng(1))
    assert masses.shape == (SAMPLE_SIZE,)
    assert masses.min() >= grading.mass_at(0.001) * (1.0 - 1e-12)
    statistics = grading.statistics(masses)
    m50_tolerance, spread_tolerance, mean_tolerance = tolerances
    assert statistics.m50 == pytest.approx(grading.m50, rel=m50_tolerance)
    assert statistics.m85_over_m15 == pytest.approx(grading.m85_over_m15, rel=spread_tolerance)
    assert statistics.effective_mean_mass == pytest.approx(grading.effective_mean_mass(),
                                                           rel=mean_tolerance)
    assert statistics.dn50 == pytest.approx(grading.dn50, rel=m50_tolerance)


@pytest.mark.parametrize("name", ["HMA 300/1000", "LMA 10/60"])
def test_a_large_sample_of_a_class_conforms_to_it(name):
    grading = standard_grading(name)
    assert grading.conformity(grading.sample_masses(SAMPLE_SIZE, np.random.default_rng(2))).passed


def test_same_seed_same_stones_and_none_asked_none_drawn():
    grading = standard_grading("LMA 40/200")
    first = grading.sample_masses(7, np.random.default_rng(3))
    assert np.array_equal(first, grading.sample_masses(7, np.random.default_rng(3)))
    assert grading.sample_masses(0, np.random.default_rng(3)).shape == (0,)


# -- custom gradings -------------------------------------------------------------------------------

def test_custom_gradings_by_masses_diameters_and_spread_agree():
    # the by-hand curve above: M15 = 619.613, M50 = 1000, M85 = 1394.128 kg
    by_masses = ArmourGrading.from_masses(m15=619.613, m50=1000.0, m85=1394.128)
    assert by_masses.uniformity_index == pytest.approx(3.030221, rel=HAND)
    diameters = [(mass / 2650.0) ** (1.0 / 3.0) for mass in (619.613, 1000.0, 1394.128)]
    by_diameters = ArmourGrading.from_nominal_diameters(*diameters)
    assert by_diameters.m50 == pytest.approx(1000.0, rel=1e-12)
    assert by_diameters.uniformity_index == pytest.approx(by_masses.uniformity_index, rel=1e-12)
    rock = by_masses.as_rock_grading()
    assert isinstance(rock, RockGrading)
    assert rock.dn50 == pytest.approx(by_masses.dn50, rel=1e-12)
    assert rock.dn85_over_dn15 == pytest.approx(2.25 ** (1.0 / 3.0), rel=HAND)
    assert by_masses.standard_class is None


# -- the model -------------------------------------------------------------------------------------

def test_scaling_to_the_model_by_hand():
    # HMA 300/1000 (M50 = 670.550 kg, rock 2650 kg/m^3, sea water 1025) at 1:40 in fresh water:
    #   Delta_p = 2650 / 1025 - 1 = 1.585366; D_n50,p = (670.550 / 2650)^(1/3) = 0.632502 m
    #   same stone density, Delta_m = 2650 / 1000 - 1 = 1.65:
    #     D_n50,m = 0.632502 * 1.585366 / (40 * 1.65) = 0.632502 * 0.0240207 = 0.0151931 m
    #     M50,m = 2650 * 0.0151931^3 = 9.29369e-3 kg; every mass times 1.38598e-5
    prototype = standard_grading("HMA 300/1000")
    model = prototype.to_model(40.0, model_density=2650.0, prototype_water_density=1025.0,
                               model_water_density=1000.0)
    assert model.dn50 == pytest.approx(0.0151931, rel=HAND)
    assert model.m50 == pytest.approx(9.29369e-3, rel=HAND)
    assert model.uniformity_index == prototype.uniformity_index
    assert model.standard_class.name == "HMA 300/1000 at 1:40"
    assert model.standard_class.nominal_upper_limit == pytest.approx(1000.0 * 1.38598e-5,
                                                                     rel=HAND)
    assert model.standard_class.effective_mean_mass_range[0] == pytest.approx(
        540.0 * 1.38598e-5, rel=HAND)
    #   denser model stones, 2900 kg/m^3: Delta_m = 1.9,
    #     D_n50,m = 0.632502 * 1.585366 / (40 * 1.9) = 0.0131940 m, M50,m = 2900 * D^3
    #     = 6.66087e-3 kg
    dense = prototype.to_model(40.0, model_density=2900.0, prototype_water_density=1025.0,
                               model_water_density=1000.0)
    assert dense.dn50 == pytest.approx(0.0131940, rel=HAND)
    assert dense.m50 == pytest.approx(6.66087e-3, rel=HAND)
    assert dense.density == 2900.0
    # equal Delta: D_n / lambda
    same = prototype.to_model(25.0, model_density=2650.0, prototype_water_density=1000.0,
                              model_water_density=1000.0)
    assert same.dn50 == pytest.approx(prototype.dn50 / 25.0, rel=1e-12)
    # drawn model stones conform to the scaled class
    assert model.conformity(model.sample_masses(SAMPLE_SIZE, np.random.default_rng(4))).passed


# -- refusals -----------------------------------------------------------------------------------

def _grading():
    return standard_grading("HMA 300/1000")


REFUSALS = [
    ("masses that do not nest", lambda: ArmourGrading.from_masses(600.0, 500.0, 1500.0),
     "m15 < m50 < m85.*m15 = 600"),
    ("an M50 off the curve", lambda: ArmourGrading.from_masses(100.0, 900.0, 1000.0),
     "m50 = 900"),
    ("a mass spread beyond 125", lambda: ArmourGrading.from_masses(1.0, 20.0, 500.0),
     "m85 / m15.*500"),
    ("diameters that do not nest", lambda: ArmourGrading.from_nominal_diameters(0.5, 0.4, 0.6),
     "dn15 < dn50 < dn85.*dn15 = 0.5"),
    ("a mass ratio typed as the diameter spread",
     lambda: ArmourGrading.from_spread(dn50=0.5, dn85_over_dn15=11.4), "dn85_over_dn15.*11.4"),
    ("one size", lambda: ArmourGrading.from_spread(dn50=0.5, dn85_over_dn15=1.0),
     "m85_over_m15 must exceed 1.*1.0"),
    ("a diameter spread beyond 5",
     lambda: ArmourGrading.from_nominal_diameters(0.125, 0.3, 1.0), "dn85 / dn15.*8"),
    ("a mass typed as a diameter", lambda: ArmourGrading.from_spread(dn50=670.0,
                                                                     dn85_over_dn15=1.3),
     "dn50 = 670"),
    ("a zero density", lambda: standard_grading("HMA 300/1000", density=0.0), "density.*0"),
    ("a negative density", lambda: ArmourGrading.from_masses(500.0, 1000.0, 1500.0,
                                                             density=-2650.0), "density.*-2650"),
    ("a density in t/m^3", lambda: ArmourGrading(m50=1000.0, uniformity_index=3.0, density=2.65),
     "density.*2.65"),
    ("a negative M50", lambda: ArmourGrading(m50=-1.0, uniformity_index=3.0), "m50.*-1"),
    ("a zero uniformity index", lambda: ArmourGrading(m50=1000.0, uniformity_index=0.0),
     "uniformity_index.*0"),
    ("too wide a uniformity index", lambda: ArmourGrading(m50=1000.0, uniformity_index=0.3),
     "uniformity_index.*0.3"),
    ("a zero length scale", lambda: _grading().to_model(0.0, model_density=2650.0,
                                                        prototype_water_density=1025.0),
     "length_scale.*0"),
    ("a negative length scale", lambda: _grading().to_model(-40.0, model_density=2650.0,
                                                            prototype_water_density=1025.0),
     "length_scale.*-40"),
    ("a zero model density", lambda: _grading().to_model(40.0, model_density=0.0,
                                                         prototype_water_density=1025.0),
     "model_density.*0"),
    ("model stones lighter than water", lambda: _grading().to_model(
        40.0, model_density=950.0, prototype_water_density=1025.0),
     "denser than the water.*950"),
    ("a zero water density", lambda: _grading().to_model(40.0, model_density=2650.0,
                                                         prototype_water_density=0.0),
     "prototype_water_density.*0"),
    ("a fraction of 1", lambda: _grading().mass_at(1.0), "mass fractions.*1"),
    ("a negative count", lambda: _grading().sample_masses(-1, np.random.default_rng(0)),
     "count.*-1"),
    ("a seed for a generator", lambda: _grading().sample_masses(5, 42), "rng.*int"),
    ("no stones", lambda: grading_statistics([]), "masses"),
    ("a negative stone", lambda: grading_statistics([100.0, -5.0]), "masses.*-5"),
    ("statistics with a zero density", lambda: grading_statistics([100.0], density=0.0),
     "density.*0"),
    ("a custom grading's conformity",
     lambda: ArmourGrading.from_masses(500.0, 1000.0, 1500.0).conformity([100.0]),
     "standard class"),
    ("a custom grading's M_em without a limit",
     lambda: ArmourGrading.from_masses(500.0, 1000.0, 1500.0).effective_mean_mass(),
     "lower_limit"),
    ("a class that is a number", lambda: en13383_conformity([100.0], 3), "grading_class.*int"),
]


@pytest.mark.parametrize("why, make, message", REFUSALS, ids=[row[0] for row in REFUSALS])
def test_bad_input_is_refused_naming_the_parameter_and_value(why, make, message):
    with pytest.raises(CaseFileError, match=message):
        make()
