"""Regular waves in an empty flume (issue 15): made in a relaxation zone, carried along the flume,
absorbed at its end (``riprap.waves``; the case is ``examples/09_regular_waves/case.toml``: a
linear wave H = 4 cm, T = 1.2 s in d = 0.4 m, L = 1.936 m, on 2 cm cells, 20 periods).

Sources and tolerances (issue 15's acceptance figures):

- Height: the mean zero-down-crossing height at every gauge of the working section, which spans
  more than three wave lengths, within ``HEIGHT_TOLERANCE`` = 5 % of the target H (linear
  theory; measured within 1.2 %).
- Wave length: the phase of the wave's harmonic along the gauges gives k; within
  ``LENGTH_TOLERANCE`` = 1 % of the dispersion relation omega^2 = g k tanh(k d) (Dean &
  Dalrymple 1991, eq. 3.34).
- Reflection from the absorbing end: the two-gauge split of Goda & Suzuki (1976) on neighbouring
  gauges, every pair below ``REFLECTION_LIMIT`` = 5 %; the same for the three-gauge split of
  Mansard & Funke (1980) of every neighbouring triple in the flume's own report.
- Water volume over 20 periods: its mean over the last period differs from the still flume's by
  less than ``VOLUME_DRIFT_LIMIT`` = 0.1 %.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_solver
from riprap.case.load import load_case
from riprap.waves.analysis import harmonic_amplitude, separate_regular_wave, zero_down_crossing_heights
from riprap.waves.gauges import Gauge, GaugeSet
from riprap.waves.report import arrival_time, flume_report

CASE = Path(__file__).resolve().parents[2] / "examples" / "09_regular_waves" / "case.toml"
HEIGHT_TOLERANCE = 0.05
LENGTH_TOLERANCE = 0.01
REFLECTION_LIMIT = 0.05
VOLUME_DRIFT_LIMIT = 1e-3
PERIODS = 20


@pytest.fixture(scope="module")
def flume():
    case = load_case(CASE)
    fluid = build_fluid_solver(case)
    wave = fluid.relaxation.wave
    length = wave.wave_length
    first = fluid.relaxation.zones[0].end + 0.05 * length
    last = fluid.relaxation.zones[1].start - 0.25 * length
    positions = np.arange(first, last, length / 5.0)
    fluid.gauges = GaugeSet([Gauge(f"x{n}", "surface", (x, 0.01, 0.0))
                             for n, x in enumerate(positions)], fluid.relaxation.still_water_level)
    volumes, times = [], []
    while fluid.time < PERIODS * wave.period - 1e-9:
        fluid.step()
        volumes.append(fluid.water_volume())
        times.append(fluid.time)
    start = arrival_time(fluid.relaxation, positions[-1])
    return fluid, wave, positions, start, np.array(times), np.array(volumes)


def test_the_working_section_spans_three_wave_lengths(flume):
    _, wave, positions, start, times, _ = flume
    assert positions[-1] - positions[0] >= 3.0 * wave.wave_length
    assert times[-1] - start >= 8.0 * wave.period        # enough steady waves to analyse


def test_wave_height_along_the_flume_is_the_target(flume):
    fluid, wave, positions, start, _, _ = flume
    gauges = fluid.gauges
    chosen = gauges.times >= start
    for n in range(len(positions)):
        heights, _ = zero_down_crossing_heights(gauges.values[chosen, n])
        error = heights.mean() / wave.height - 1.0
        assert abs(error) < HEIGHT_TOLERANCE, (positions[n], heights.mean())


def test_wave_length_is_that_of_the_dispersion_relation(flume):
    fluid, wave, positions, start, _, _ = flume
    gauges = fluid.gauges
    chosen = gauges.times >= start
    phases = np.unwrap([np.angle(harmonic_amplitude(gauges.times[chosen], gauges.values[chosen, n],
                                                    wave.period)) for n in range(len(positions))])
    # Z = a e^{i k x}: the phase grows by k per metre
    slope = np.polyfit(positions, phases, 1)[0]
    assert abs(slope / wave.wave_number - 1.0) < LENGTH_TOLERANCE


def test_the_absorbing_end_reflects_less_than_five_percent(flume):
    fluid, wave, positions, start, _, _ = flume
    gauges = fluid.gauges
    chosen = gauges.times >= start
    coefficients = []
    for n in range(len(positions) - 1):
        split = separate_regular_wave(gauges.times[chosen], gauges.values[chosen, n],
                                      gauges.values[chosen, n + 1], positions[n + 1] - positions[n],
                                      wave.depth, wave.period)
        coefficients.append(split.reflection_coefficient)
        assert abs(split.incident_hm0 / wave.height - 1.0) < HEIGHT_TOLERANCE
    assert max(coefficients) < REFLECTION_LIMIT, coefficients
    # the flume's own report: Mansard & Funke's three-gauge split of every neighbouring triple
    report = flume_report(gauges, fluid.relaxation)
    triples = report["reflection_three_gauge"]
    assert len(triples) == len(positions) - 2
    for entry in triples:
        assert entry["reflection_coefficient"] < REFLECTION_LIMIT, entry
        assert abs(entry["incident_height_m"] / wave.height - 1.0) < HEIGHT_TOLERANCE, entry


def test_water_volume_does_not_drift(flume):
    fluid, wave, _, _, times, volumes = flume
    still = fluid.initial_water_volume
    last_period = times >= times[-1] - wave.period
    assert abs(volumes[last_period].mean() / still - 1.0) < VOLUME_DRIFT_LIMIT
    assert math.isfinite(fluid.last_report.water_volume_error)
