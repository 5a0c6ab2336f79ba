"""Rock armour in the flume test's stability report (issue 55): the measured S, its Rock Manual
class, P from the layers, the three formulas and their band, where the profile eroded."""
import math

import numpy as np
import pytest

from riprap.analysis.rock_stability import RockSection, eroded_zone, rock_stability
from riprap.analysis.stability_report import flume_stability, incident_spectral_period_at_toe

SECTION = RockSection(filter_dn50=0.04 / 2.3, core_dn50=0.84 * 0.01,
                      core_note="porous core", grading_ratio=1.3, water_depth=0.5)
WAVES = {"hs": 0.1, "spectral_period": 1.5, "waves": 1000, "slope_cot": 2.0,
         "armour_density": 2650.0, "water_density": 1000.0, "nominal_diameter": 0.04}


def test_the_three_formulas_by_hand_and_their_band():
    result = rock_stability(**WAVES, damage=3.0, section=SECTION)
    formulas = {f["name"]: f for f in result["formulas"]}
    delta, dn, hs, n = 1.65, 0.04, 0.1, 1000
    ns = hs / (delta * dn)
    # Van Gent et al. (2003): N_s = 1.75 sqrt(cot) (1 + Dn_core/Dn) (S/sqrt N)^0.2
    van_gent = (ns / (1.75 * math.sqrt(2.0) * (1 + 0.84 * 0.01 / dn))) ** 5 * math.sqrt(n)
    assert formulas["Van Gent et al. (2003)"]["S"] == pytest.approx(van_gent, rel=1e-12)
    # Van der Meer (2021), armour on a filter on a permeable core: P = 0.4; xi_m-1,0 from
    # s_m-1,0 = 2 pi H / (g T^2); plunging N_s = 6.49 P^0.18 (S/sqrt N)^0.2 xi^-0.5
    assert result["notional_permeability"] == 0.4
    xi = 0.5 / math.sqrt(2 * math.pi * hs / (9.81 * 1.5 ** 2))
    assert xi < (6.49 / 0.97 * 0.4 ** 0.31 * math.sqrt(0.5)) ** (1 / (0.4 + 0.5))
    vdm = (ns / (6.49 * 0.4 ** 0.18 * xi ** -0.5)) ** 5 * math.sqrt(n)
    assert formulas["Van der Meer (2021)"]["S"] == pytest.approx(vdm, rel=1e-3)
    values = [f["S"] for f in result["formulas"]]
    assert result["formula_band_S"] == [min(values), max(values)]
    assert result["measured_against_band"] == ("below" if 3.0 < min(values) else "above"
                                               if 3.0 > max(values) else "inside")
    # S 3 on 1:2: start of damage (Rock Manual Table 5.22: 2 / 4-6 / 8)
    assert result["damage_class"] == "start of damage"
    assert result["damage_class_thresholds"]["failure"] == 8.0


def test_short_tests_and_an_impermeable_core_are_said():
    impermeable = RockSection(filter_dn50=0.017, core_dn50=0.0, core_note="no core zone")
    result = rock_stability(**{**WAVES, "waves": 50}, damage=1.0, section=impermeable)
    assert result["notional_permeability"] == 0.1
    formulas = {f["name"]: f for f in result["formulas"]}
    # Etemad-Shahidi's data start at N = 500 and S = 2
    cautions = " ".join(formulas["Etemad-Shahidi et al. (2020)"]["cautions"])
    assert "N = 50 is below" in cautions and "S = 1 is below" in cautions
    # the permeable core gives less damage than the impermeable one in every core formula
    permeable = rock_stability(**{**WAVES, "waves": 50}, damage=1.0, section=SECTION)
    for name in ("Van Gent et al. (2003)", "Etemad-Shahidi et al. (2020)",
                 "Van der Meer (2021)"):
        less = {f["name"]: f["S"] for f in permeable["formulas"]}[name]
        assert less < formulas[name]["S"], name


def test_without_a_period_only_van_gent_is_given():
    result = rock_stability(**{**WAVES, "spectral_period": None}, damage=None, section=SECTION)
    assert [f["name"] for f in result["formulas"]] == ["Van Gent et al. (2003)"]
    assert "no T_m-1,0" in result["not_computed"][0]
    assert "damage_class" not in result


def test_eroded_zone_of_a_profile_by_hand():
    x = np.arange(0.0, 1.0, 0.01)
    before = 0.5 * x
    after = before.copy()
    # a trough 4 cm deep between x = 0.9 and 0.98 m... and a 2 cm mound lower down
    after[(x > 0.895) & (x < 0.985)] -= 0.04
    after[(x > 0.695) & (x < 0.745)] += 0.02
    zone = eroded_zone({"x_m": x.tolist(), "before_z_m": before.tolist(),
                        "after_z_m": after.tolist()}, nominal_diameter=0.04,
                       still_water_level=0.4, significant_height=0.1)
    assert zone["eroded_area_m2"] == pytest.approx(9 * 0.01 * 0.04)
    assert zone["accreted_area_m2"] == pytest.approx(5 * 0.01 * 0.02)
    assert zone["eroded_from_x_m"] == pytest.approx(0.90)
    assert zone["eroded_to_x_m"] == pytest.approx(0.98)
    # the deepest point is the trough's first (argmax): x 0.90, z 0.45, 0.05 m above the SWL
    assert zone["deepest_below_still_water_over_dn50"] == pytest.approx(-0.05 / 0.04)
    assert zone["eroded_area_above_still_water_m2"] == pytest.approx(zone["eroded_area_m2"])
    flat = eroded_zone({"x_m": x.tolist(), "before_z_m": before.tolist(),
                        "after_z_m": before.tolist()}, nominal_diameter=0.04,
                       still_water_level=0.4)
    assert flat["eroded_area_m2"] == 0.0 and "no point" in flat["note"]


def test_flume_stability_carries_rock_from_the_waves_report():
    waves_report = {"gauges": {"g1": {"Hm0_m": 0.11, "Tz_s": 1.2, "waves": 60,
                                      "Tm-1,0_s": 1.45}},
                    "reflection_three_gauge": [{"incident_Hm0_m": 0.1, "incident_Tp_s": 1.6,
                                                "incident_Tm-1,0_s": 1.5,
                                                "reflection_coefficient": 0.3}]}
    assert incident_spectral_period_at_toe(waves_report)[0] == 1.5
    layer = {"units_displaced": [3], "damage_number_nod": 0.2, "damage_level_s": 2.5,
             "damage_profiles": {"x_m": [0.0, 0.1], "before_z_m": [0.0, 0.05],
                                 "after_z_m": [0.0, 0.05]}}
    report = flume_stability(waves_report, layer, unit_kind="armour_stone",
                             nominal_diameter=0.04, armour_density=2650.0, water_density=1000.0,
                             slope_cot=2.0, rock_section=SECTION, still_water_level=0.5)
    rock = report["rock"]
    assert rock["S"] == 2.5 and rock["spectral_period_s"] == 1.5
    direct = rock_stability(**{**WAVES, "waves": 60}, damage=2.5, section=SECTION)
    assert [f["S"] for f in rock["formulas"]] == [f["S"] for f in direct["formulas"]]
    # concrete units get no rock section
    cubes = flume_stability(waves_report, layer, unit_kind="cube", nominal_diameter=0.04,
                            armour_density=2300.0, water_density=1000.0, slope_cot=1.5)
    assert "rock" not in cubes


def test_a_core_far_finer_than_the_armour_is_cautioned():
    fine = RockSection(filter_dn50=0.017, core_dn50=0.84 * 0.001, core_note="fine core")
    result = rock_stability(**WAVES, damage=2.0, section=fine)
    assert result["notional_permeability"] == 0.4
    assert "48 times finer" in result["cautions"][0]
    assert "cautions" not in rock_stability(**WAVES, damage=2.0, section=SECTION)


def test_rock_formula_curves_carry_damage_from_step_to_step():
    from riprap.analysis.rock_formulas import van_gent_2003_damage
    from riprap.analysis.series_damage import rock_formula_curves

    common = {"slope_cot": 2.0, "delta": 1.65, "nominal_diameter": 0.04, "permeability": 0.4,
              "core_nominal_diameter": 0.0084}
    one = rock_formula_curves([(0.1, 1.5, 50)], **common)
    two = rock_formula_curves([(0.1, 1.5, 50), (0.1, 1.5, 50)], **common)
    hundred = rock_formula_curves([(0.1, 1.5, 100)], **common)
    for name in one:
        # the same sea twice is that sea for twice the waves (Van der Meer's equivalent waves)
        assert two[name][1] == pytest.approx(hundred[name][0], rel=1e-6), name
        assert two[name][0] == pytest.approx(one[name][0]), name
    assert one["van_gent_2003_S"][0] == pytest.approx(van_gent_2003_damage(
        hs=0.1, waves=50, slope_cot=2.0, armour_density=2650.0, water_density=1000.0,
        nominal_diameter=0.04, core_nominal_diameter=0.0084))
    # a step without measured waves leaves the formulas uncomputed, not guessed
    assert all(math.isnan(v) for v in rock_formula_curves([(math.nan, 1.5, 50)],
                                                          **common)["van_gent_2003_S"])
