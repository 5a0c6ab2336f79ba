"""The damage curve's formulas (``riprap/analysis/series_damage.py``) against answers worked by
hand: Van der Meer's cumulative damage over sea states, EurOtop's mean overtopping and its
crest-width factor, and the step seas of a series (``riprap/case/series_steps.py``)."""
import math

import pytest

from riprap.analysis.design_formulas import van_der_meer_cubes_damage
from riprap.analysis.series_damage import (cumulative_damage, eurotop_crest_width_factor,
                                           eurotop_mean_overtopping, series_curve)
from riprap.case.series_steps import mean_zero_crossing_period
from riprap.errors import CaseFileError


def _cubes(hs, tm, waves):
    return van_der_meer_cubes_damage(hs=hs, tm=tm, waves=waves, delta=1.3, nominal_diameter=0.05)


def test_two_equal_sea_states_do_what_one_twice_as_long_does():
    # Van der Meer (1988): the damage so far carried as equivalent waves of the next sea state;
    # for two equal sea states that is the damage of their waves together
    split = cumulative_damage(_cubes, [(0.15, 1.3, 500), (0.15, 1.3, 500)])
    assert split[1] == pytest.approx(_cubes(0.15, 1.3, 1000), rel=1e-9)
    assert split[0] == pytest.approx(_cubes(0.15, 1.3, 500), rel=1e-12)


def test_a_higher_sea_carries_the_damage_as_its_equivalent_waves():
    # N_od = (b N^0.3 / 6.7)^2.5 = c N^0.75 at a given sea: worked by hand for step 2
    first = _cubes(0.12, 1.3, 300)
    c2 = _cubes(0.16, 1.3, 1.0)                       # N_od of one wave of the second sea
    equivalent = (first / c2) ** (1.0 / 0.75)
    expected = c2 * (equivalent + 300) ** 0.75
    assert cumulative_damage(_cubes, [(0.12, 1.3, 300), (0.16, 1.3, 300)])[1] == pytest.approx(
        expected, rel=1e-8)


def test_a_lower_sea_adds_nothing_below_its_threshold():
    # the second sea is below the formula's no-damage bracket (N_s s^0.1 < 1): damage kept
    damage = cumulative_damage(_cubes, [(0.15, 1.3, 500), (0.02, 1.3, 500)])
    assert damage[1] == damage[0] > 0


def test_eurotop_mean_overtopping_by_hand():
    # Hm0 = 2 m, Rc = 3 m, gamma_f = 0.5: q = 0.09 exp(-(1.5 * 3 / 1)^1.3) sqrt(9.81 * 8)
    expected = 0.09 * math.exp(-(4.5 ** 1.3)) * math.sqrt(9.81 * 8.0)
    assert eurotop_mean_overtopping(2.0, 3.0, 0.5) == pytest.approx(expected, rel=1e-12)
    assert math.isnan(eurotop_mean_overtopping(0.0, 3.0, 0.5))


@pytest.mark.parametrize("ratio, expected", [(0.0, 1.0), (1.0, 0.683), (2.0, 0.152)])
def test_eurotop_crest_width_factor_by_hand(ratio, expected):
    # EurOtop (2018) eq. 6.8: C_r = 3.06 exp(-1.5 G_c/Hm0), at most 1; 3.06 e^-1.5 = 0.6828,
    # 3.06 e^-3 = 0.1523 (to 3 figures, as worked by hand); Hm0 = 0.2 m
    assert eurotop_crest_width_factor(ratio * 0.2, 0.2) == pytest.approx(expected, abs=5e-4)


def test_eurotop_crest_width_factor_without_a_width_or_with_a_bad_one():
    assert eurotop_crest_width_factor(None, 0.2) == 1.0
    assert math.isnan(eurotop_crest_width_factor(0.3, math.nan))
    with pytest.raises(CaseFileError, match="crest_width"):
        eurotop_crest_width_factor(-0.1, 0.2)


def test_the_curve_applies_the_crest_width_factor_and_says_so():
    steps = [dict(step=k + 1, Hm0_m=h, Tm_s=1.2, waves=100, units_displaced=0, N_od=0.0, S=0.0,
                  rocking_events=0, q_m3_s_m=1e-4) for k, h in enumerate([0.1, 0.2])]
    common = dict(unit_kind="cube", nominal_diameter=0.05, delta=1.3, slope_cot=1.5,
                  freeboard=0.1)
    plain = series_curve(steps, **common)
    reduced = series_curve(steps, crest_width=0.2, crest_width_source="given", **common)
    factors = reduced["curve"]["eurotop_crest_width_factor"]
    assert factors == pytest.approx([3.06 * math.exp(-3.0), 3.06 * math.exp(-1.5)], rel=1e-12)
    assert plain["curve"]["eurotop_crest_width_factor"] == [1.0, 1.0]
    for k in range(2):
        assert reduced["curve"]["eurotop_q_m3_s_m"][k] == pytest.approx(
            factors[k] * plain["curve"]["eurotop_q_m3_s_m"][k], rel=1e-12)
    assert reduced["formulas"]["crest_width_m"] == 0.2
    assert reduced["formulas"]["crest_width_source"] == "given"
    assert plain["formulas"]["crest_width_m"] is None
    assert "C_r = 1" in plain["formulas"]["crest_width_source"]
    assert "eq. 6.8" in reduced["formulas"]["sources"]


def test_mean_zero_crossing_period_of_jonswap():
    # Goda (2010): Tp / Tm02 about 1.28-1.30 for gamma = 3.3 over the whole spectrum; over the
    # band 0.5-3 fp riprap's sea is made of, the tail beyond 3 fp is cut: a little longer Tm02
    ratio = 1.6 / mean_zero_crossing_period(1.6, 3.3)
    assert 1.20 < ratio < 1.30


def test_the_first_displacement_is_placed_on_the_curve():
    steps = [dict(step=k + 1, Hm0_m=h, Tm_s=1.2, waves=100, units_displaced=d, N_od=d / 4.0,
                  S=d * 0.3, rocking_events=0, q_m3_s_m=0.0)
             for k, (h, d) in enumerate([(0.08, 0), (0.12, 0), (0.16, 2), (0.2, 5)])]
    result = series_curve(steps, unit_kind="cube", nominal_diameter=0.05, delta=1.3,
                          slope_cot=1.5, freeboard=0.1)
    assert result["first_displacement"]["step"] == 3
    assert result["first_displacement"]["stability_number"] == pytest.approx(0.16 / 0.065)
    assert result["first_displacement"]["below"] == pytest.approx(0.12 / 0.065)
    assert result["curve"]["cumulative_waves"] == [100, 200, 300, 400]
    formula = result["curve"]["van_der_meer_cubes_N_od"]
    assert all(b >= a for a, b in zip(formula, formula[1:]))
    assert result["formulas"]["start_of_damage"]["single_layer_cubes_start"] == 2.9
