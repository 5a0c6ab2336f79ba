"""The flume test's stability report (``riprap.analysis.stability_report``): the stability number of
the measured incident waves beside Hudson's (K_D from shared/validation/armour_design.md §5.2) and,
for cubes, Van der Meer's N_od; the incident height taken from the three-gauge splits when there
are any, else from the Goda-Suzuki pairs. Constructed reports with known answers (exact arithmetic)."""
import pytest

from riprap.analysis.design_formulas import van_der_meer_cubes_damage
from riprap.analysis.stability_report import flume_stability

LAYER = {"units_displaced": [3, 7], "damage_number_nod": 0.25, "damage_threshold_over_dn": 1.0}


def test_core_loc_layer_against_hudson_with_the_incident_height():
    waves = {"gauges": {"g1": {"Hm0_m": 1.5, "Tz_s": 3.1, "waves": 40}},
             "reflection": [{"incident_Hm0_m": 1.1}, {"incident_Hm0_m": 1.3}]}
    report = flume_stability(waves, LAYER, unit_kind="core_loc_like", nominal_diameter=0.5,
                             armour_density=2400.0, water_density=1000.0, slope_cot=1.33)
    assert report["Hm0_m"] == pytest.approx(1.2)
    assert report["stability_number"] == pytest.approx(1.2 / (1.4 * 0.5))
    assert report["hudson"]["stability_number"] == pytest.approx((16.0 * 1.33) ** (1 / 3))
    assert report["hudson"]["ratio"] == pytest.approx(report["stability_number"] / (16 * 1.33) ** (1 / 3))
    assert report["units_displaced"] == 2 and report["damage_number_nod"] == 0.25
    assert "Goda-Suzuki" in report["wave_height_source"]
    waves["reflection_three_gauge"] = [{"incident_Hm0_m": 1.0}, {"incident_Hm0_m": 1.1}]
    report = flume_stability(waves, LAYER, unit_kind="core_loc_like", nominal_diameter=0.5,
                             armour_density=2400.0, water_density=1000.0, slope_cot=1.33)
    assert report["Hm0_m"] == pytest.approx(1.05) and "Mansard-Funke" in report["wave_height_source"]


def test_cubes_get_van_der_meer_and_no_gauge_gives_a_note():
    waves = {"gauges": {"g1": {"Hm0_m": 2.0, "Tz_s": 6.0, "waves": 1000}}, "reflection": []}
    report = flume_stability(waves, LAYER, unit_kind="cube", nominal_diameter=1.0,
                             armour_density=2400.0, water_density=1025.0, slope_cot=1.5)
    assert "hudson" not in report
    expected = van_der_meer_cubes_damage(hs=2.0, tm=6.0, waves=1000, delta=2400 / 1025 - 1,
                                         nominal_diameter=1.0)
    assert report["van_der_meer_cubes"]["N_od"] == pytest.approx(expected)
    empty = flume_stability({"gauges": {}}, LAYER, unit_kind="cube", nominal_diameter=1.0,
                            armour_density=2400.0, water_density=1025.0, slope_cot=1.5)
    assert "note" in empty and "stability_number" not in empty


def test_hudsons_number_is_given_without_waves_as_with_them():
    """Hudson's N_s depends on the unit and the slope only: a survey that measured no wave gives
    it as the series' table does (issue 52), only the measured / Hudson ratio is missing."""
    empty = flume_stability({"gauges": {}}, LAYER, unit_kind="core_loc_like", nominal_diameter=0.5,
                            armour_density=2400.0, water_density=1000.0, slope_cot=1.33)
    assert "stability_number" not in empty
    assert empty["hudson"]["stability_number"] == pytest.approx((16.0 * 1.33) ** (1 / 3))
    assert "ratio" not in empty["hudson"]
