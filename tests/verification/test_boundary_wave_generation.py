"""Waves made by the flume's boundary (``[waves] generation = "boundary"``,
``riprap/waves/boundary_generation.py``): no generation zone; the x = lower faces impose the wave's
velocity and absorb what comes back (Schaffer & Klopman 2000; Higuera, Lara & Losada 2013).

The wave is examples/09's (linear, H = 4 cm, T = 1.2 s, d = 0.4 m: L = 1.936 m, k d = 1.30) on
the same 2 cm cells. Sources and tolerances:

- Open flume (absorbing zone of 2 L at the far end), 12 periods: the mean zero-down-crossing
  height at every gauge of a working section of three wave lengths within 5 % of H (linear theory;
  issue 15's figure for generated waves; measured within 1.3 %); the two-gauge split of Goda &
  Suzuki (1976) on neighbouring gauges: incident height within 5 % and reflection below 5 %
  (measured below 3 %); the water volume's mean over the last period within 0.1 % of the still
  flume's (measured 0.035 %).
- Flume closed by a wall three wave lengths from the boundary, 30 periods: the wall reflects
  everything, so after the first reflection has come back the gauges see a standing wave; the
  boundary must absorb the reflected wave while it keeps making the incident one. The incident
  height from the two-gauge split in every four-period window after the reflection's return
  (t >= 12 s) within 5 % of H (measured within 1.4 %). Without the absorption the incident wave
  grows with every round trip (measured: 1.9 times H by t = 36 s), and with the shallow-water
  factor sqrt(g/d) in place of the wave's celerity it settles 9 % low: this test fails for both.
  The water volume stays within 1 % of the still flume's (measured 0.5 %).
"""
import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_solver
from riprap.case.load import parse_case
from riprap.waves.analysis import separate_regular_wave, zero_down_crossing_heights
from riprap.waves.gauges import Gauge, GaugeSet
from riprap.waves.report import arrival_time

HEIGHT_TOLERANCE = 0.05
REFLECTION_LIMIT = 0.05
VOLUME_DRIFT_LIMIT = 1e-3
CLOSED_VOLUME_LIMIT = 1e-2
CONSERVATION_LIMIT = 1e-4

CASE = """
format_version = 1
[simulation]
end_time = 100.0
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [{length}, 0.02, 0.6]
cells = [{cells}, 1, 30]
x_low = "free_slip"
x_high = "free_slip"
z_low = "free_slip"
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.4
[waves]
type = "linear"
still_water_level = 0.4
height = 0.04
period = 1.2
generation = "boundary"
absorbing_end = {absorbing}
"""


def _flume(length, absorbing, positions, periods):
    text = CASE.format(length=length, cells=round(length / 0.02), absorbing=str(absorbing).lower())
    fluid = build_fluid_solver(parse_case(text, source="boundary_flume.toml"))
    fluid.gauges = GaugeSet([Gauge(f"x{n}", "surface", (x, 0.01, 0.0))
                             for n, x in enumerate(positions)], 0.4)
    wave = fluid.wave_source.wave
    volumes, times = [], []
    while fluid.time < periods * wave.period - 1e-9:
        fluid.step()
        volumes.append(fluid.water_volume())
        times.append(fluid.time)
    return fluid, wave, np.array(times), np.array(volumes)


LENGTH = 1.9363        # m, examples/09's wave length (checked in the fixtures)


@pytest.fixture(scope="module")
def open_flume():
    positions = np.arange(0.25 * LENGTH, 3.3 * LENGTH, LENGTH / 5.0)
    fluid, wave, times, volumes = _flume(10.7, True, positions, 12)
    assert abs(wave.wave_length / LENGTH - 1.0) < 1e-3
    return fluid, wave, positions, times, volumes


@pytest.fixture(scope="module")
def closed_flume():
    positions = np.array([0.5, 0.5 + LENGTH / 5.0, 2.0, 2.0 + LENGTH / 5.0])
    fluid, wave, times, volumes = _flume(5.84, False, positions, 30)
    return fluid, wave, positions, times, volumes


def test_the_boundary_needs_no_zone_and_keeps_the_absorbing_one(open_flume):
    fluid = open_flume[0]
    assert fluid.wave_maker is not None and fluid.relaxation.wave is None
    assert [zone.kind for zone in fluid.relaxation.zones] == ["absorption"]
    assert fluid.wave_source is fluid.wave_maker


def test_boundary_waves_keep_their_height_along_three_wave_lengths(open_flume):
    fluid, wave, positions, _, _ = open_flume
    gauges = fluid.gauges
    assert positions[-1] - positions[0] >= 3.0 * wave.wave_length - 1e-9
    start = arrival_time(fluid.wave_source, positions[-1])
    chosen = gauges.times >= start
    assert gauges.times[-1] - start >= 1.5 * wave.period
    for n, x in enumerate(positions):
        heights, _ = zero_down_crossing_heights(gauges.values[chosen, n])
        assert abs(heights.mean() / wave.height - 1.0) < HEIGHT_TOLERANCE, (x, heights.mean())
    for n in range(0, len(positions) - 1, 2):
        split = separate_regular_wave(gauges.times[chosen], gauges.values[chosen, n],
                                      gauges.values[chosen, n + 1], positions[n + 1] - positions[n],
                                      wave.depth, wave.period)
        assert abs(split.incident_hm0 / wave.height - 1.0) < HEIGHT_TOLERANCE, (n, split)
        assert split.reflection_coefficient < REFLECTION_LIMIT, (n, split)


def test_the_open_flume_keeps_its_water(open_flume):
    fluid, wave, _, times, volumes = open_flume
    last_period = times >= times[-1] - wave.period
    assert abs(volumes[last_period].mean() / fluid.initial_water_volume - 1.0) < VOLUME_DRIFT_LIMIT


def test_the_boundary_absorbs_what_a_wall_sends_back(closed_flume):
    fluid, wave, positions, times, volumes = closed_flume
    gauges = fluid.gauges
    window = 4.0 * wave.period
    starts = np.arange(12.0, times[-1] - window + 1e-9, window)
    assert starts.size >= 4
    for first, second in ((0, 1), (2, 3)):
        for start in starts:
            chosen = (gauges.times >= start) & (gauges.times < start + window)
            split = separate_regular_wave(gauges.times[chosen], gauges.values[chosen, first],
                                          gauges.values[chosen, second],
                                          positions[second] - positions[first], wave.depth,
                                          wave.period)
            # the wall's reflection is there (a standing wave) ...
            assert split.reflection_coefficient > 0.8, (start, split)
            # ... and the boundary still makes the incident wave it was asked for
            assert abs(split.incident_hm0 / wave.height - 1.0) < HEIGHT_TOLERANCE, (start, split)
    assert np.abs(volumes / fluid.initial_water_volume - 1.0).max() < CLOSED_VOLUME_LIMIT


def test_the_volume_error_counts_the_water_the_boundary_and_the_zone_let_in(closed_flume,
                                                                               open_flume):
    """Reference: the volume of fluid conserves water to round-off inside the flume (Weymouth &
    Yue 2010), so the water in it must equal the start's plus what came in through the boundary's
    faces and what the absorbing zone took (``FluidSolver.water_added``), while the water in the
    flume itself changes by the wave's own volume (more than 1e-3 of it here):
    ``water_volume_error`` is the conservation error, not the wave (issue 37). Tolerance 1e-4 of
    the flume's water: measured 2.1e-5 in the closed flume after 30 periods, against 0.5 % for the
    raw change (where the 2e-5 is lost is not traced yet: the boundary lets in water as water, and
    the sweeps clip fractions pushed past 1 there)."""
    for fluid, _, _, _, volumes in (closed_flume, open_flume):
        still = fluid.initial_water_volume
        assert np.abs(volumes / still - 1.0).max() > 1e-3
        error = (fluid.water_volume() - still - fluid.water_added) / still
        assert abs(error) <= CONSERVATION_LIMIT
        assert fluid.last_report.water_volume_error == pytest.approx(error, rel=1e-9, abs=1e-15)
