"""Wave theories, the analysis of gauge records and the relaxation zones' pieces (``riprap.waves``).

Sources: the dispersion relation omega^2 = g k tanh(k d) (Dean & Dalrymple 1991, eq. 3.34) with
the tabulated deep- and shallow-water limits; Stokes' second order (D&D eqs. 11.35-11.37), which
is the linear wave plus a harmonic of amplitude (k H^2/16) cosh(kd)(2 + cosh 2kd)/sinh^3(kd);
JONSWAP's Hm0 = 4 sqrt(m0) (Hasselmann et al. 1973); Goda & Suzuki's (1976) split, exact for two
progressive waves; zero-crossing statistics of a pure sine.
"""
import math

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.fluid.grid import FluidGrid
from riprap.fluid.solver import FluidSolver
from riprap.waves.analysis import (harmonic_amplitude, separate_incident_reflected,
                                   separate_regular_wave, separate_three_gauges, wave_statistics)
from riprap.waves.checks import check_flume
from riprap.waves.gauges import Gauge, GaugeSet
from riprap.waves.relaxation import RelaxationZone, WaveRelaxation, relaxation_weight
from riprap.waves.theory import (IrregularWave, LinearWave, StokesSecondOrderWave, ramp,
                                 wave_length, wave_number)


def test_dispersion_relation_is_solved_to_round_off_and_has_its_limits():
    for period, depth in ((1.2, 0.4), (8.0, 10.0), (12.0, 3.0), (0.5, 50.0)):
        k = wave_number(period, depth)
        omega = 2 * math.pi / period
        assert abs(9.81 * k * math.tanh(k * depth) / omega ** 2 - 1.0) < 1e-13
    assert abs(wave_length(2.0, 100.0) / (9.81 * 4.0 / (2 * math.pi)) - 1.0) < 1e-9   # deep
    assert abs(wave_length(60.0, 1.0) / (60.0 * math.sqrt(9.81)) - 1.0) < 1e-3          # shallow


def test_linear_velocity_satisfies_continuity_and_the_kinematic_surface():
    wave = LinearWave(height=0.04, period=1.2, depth=0.4)
    x, z, t, e = 0.3, -0.1, 0.7, 1e-6
    u = lambda x, z: wave.velocity(x, z, t)       # noqa: E731
    divergence = (u(x + e, z)[0] - u(x - e, z)[0] + u(x, z + e)[1] - u(x, z - e)[1]) / (2 * e)
    assert abs(divergence) < 1e-8
    deta_dt = (wave.elevation(x, t + e) - wave.elevation(x, t - e)) / (2 * e)
    assert abs(wave.velocity(x, 0.0, t)[1] - deta_dt) < 1e-8
    grid_u, grid_w = wave.velocity_grid(np.array([0.1, 0.3]), np.array([-0.2, -0.1]), t)
    assert np.allclose(grid_u[1, 1], u(0.3, -0.1)[0]) and np.allclose(grid_w[0, 0], u(0.1, -0.2)[1])


def test_stokes_second_order_is_linear_plus_its_harmonic():
    linear = LinearWave(height=0.05, period=1.5, depth=0.5)
    stokes = StokesSecondOrderWave(height=0.05, period=1.5, depth=0.5)
    k, d = linear.wave_number, 0.5
    second = k * 0.05 ** 2 / 16 * math.cosh(k * d) * (2 + math.cosh(2 * k * d)) / math.sinh(k * d) ** 3
    x = np.linspace(0, 3, 7)
    theta = k * x - linear.angular_frequency * 0.4
    assert np.allclose(stokes.elevation(x, 0.4) - linear.elevation(x, 0.4), second * np.cos(2 * theta))
    assert stokes.elevation(0.0, 0.0) > linear.elevation(0.0, 0.0)          # sharper crest
    assert 0 < stokes.second_harmonic_ratio() < 0.25


def test_jonswap_sea_has_its_significant_height_and_peak():
    sea = IrregularWave(significant_height=0.1, peak_period=2.0, depth=1.0, duration=400.0, seed=3)
    t = np.arange(0.0, 400.0, 0.05)
    eta = np.array([sea.elevation(0.0, s) for s in t])
    statistics = wave_statistics(t, eta)
    assert abs(statistics.hm0 / 0.1 - 1.0) < 0.02
    assert abs(statistics.peak_period / 2.0 - 1.0) < 0.1
    u_grid, _ = sea.velocity_grid(np.array([0.0, 0.5]), np.array([-0.5, -0.1]), 3.0)
    assert np.isclose(u_grid[1, 0], sea.velocity(0.5, -0.5, 3.0)[0])
    with pytest.raises(CaseFileError, match="ten peak periods"):
        IrregularWave(significant_height=0.1, peak_period=2.0, depth=1.0, duration=10.0)


def test_goda_suzuki_split_recovers_a_known_reflection():
    depth, period = 0.4, 1.2
    k, omega = wave_number(period, depth), 2 * math.pi / period
    t = np.arange(0.0, 40.0, 0.02)
    def eta(x):
        return 0.02 * np.cos(k * x - omega * t) + 0.005 * np.cos(-k * x - omega * t + 0.7)
    regular = separate_regular_wave(t, eta(0.0), eta(0.45), 0.45, depth, period)
    assert abs(regular.reflection_coefficient - 0.25) < 1e-6
    assert abs(regular.incident_hm0 - 0.04) < 1e-8
    spectral = separate_incident_reflected(t, eta(0.0), eta(0.45), 0.45, depth, period, band=(0.8, 1.25))
    assert abs(spectral.reflection_coefficient - 0.25) < 0.02
    with pytest.raises(CaseFileError, match="0.05..0.45"):
        separate_regular_wave(t, eta(0.0), eta(1.0), 1.0, depth, period)
    assert abs(abs(harmonic_amplitude(t, eta(0.0), period)) - abs(0.02 + 0.005 * np.exp(-0.7j))) < 1e-8


def test_three_gauge_split_recovers_a_known_reflection_where_one_pair_cannot():
    """Mansard & Funke (1980): a JONSWAP sea (Hm0 0.1 m, Tp 2 s, 1 m deep) reflected with K_r =
    0.35 and a phase lag, read at x = 0, 0.35 m and L/2 = 2.79 m (the first and third gauges half
    a peak wave length apart: the two-gauge split of that pair is singular at the peak). The
    incident Hm0 and K_r come back within 1 %; a regular wave to round-off."""
    depth, tp, kr = 1.0, 2.0, 0.35
    sea = IrregularWave(significant_height=0.1, peak_period=tp, depth=depth, duration=400.0, seed=5)
    t = np.arange(0.0, 400.0, 0.05)
    frequencies = np.fft.rfftfreq(t.size, 0.05)
    incident_at_0 = np.array([sea.elevation(0.0, s) for s in t])
    spectrum = np.fft.rfft(incident_at_0)
    wave_numbers = np.array([wave_number(1.0 / f, depth) if f > 0 else 0.0 for f in frequencies])
    def eta(x):     # incident + reflected, each frequency moved by its own wave number
        incident = np.fft.irfft(spectrum * np.exp(-1j * wave_numbers * x), t.size)
        reflected = np.fft.irfft(kr * spectrum * np.exp(1j * (wave_numbers * x + 0.9)), t.size)
        return incident + reflected
    half_wave_length = math.pi / wave_number(tp, depth)
    positions = [0.0, 0.35, half_wave_length]
    split = separate_three_gauges(t, [eta(x) for x in positions], positions, depth, tp)
    assert abs(split.reflection_coefficient / kr - 1.0) < 0.01
    incident_hm0 = wave_statistics(t, incident_at_0).hm0
    band = (frequencies >= 0.5 / tp) & (frequencies <= 2.0 / tp)
    in_band = 4.0 * math.sqrt(np.sum(0.5 * np.abs(2.0 * spectrum[band] / t.size) ** 2))
    assert abs(split.incident_hm0 / in_band - 1.0) < 0.01
    assert in_band / incident_hm0 > 0.95      # the band holds the sea
    with pytest.raises(CaseFileError, match="0.05..0.45"):
        separate_incident_reflected(t, eta(0.0), eta(half_wave_length), half_wave_length, depth, tp)
    period = 1.2
    k, omega = wave_number(period, depth), 2 * math.pi / period
    def regular(x):
        return 0.02 * np.cos(k * x - omega * t) + 0.006 * np.cos(-k * x - omega * t + 0.4)
    positions = [0.0, 0.3, math.pi / k]
    split = separate_three_gauges(t, [regular(x) for x in positions], positions, depth, period,
                                  regular=True)
    assert abs(split.reflection_coefficient - 0.3) < 1e-9 and abs(split.incident_hm0 - 0.04) < 1e-10
    with pytest.raises(CaseFileError, match="half wave lengths"):
        positions = [0.0, math.pi / k, 2 * math.pi / k]
        separate_three_gauges(t, [regular(x) for x in positions], positions, depth, period,
                              regular=True)


def test_statistics_of_a_sine():
    t = np.arange(0.0, 30.0, 0.01)
    s = wave_statistics(t, 0.03 * np.sin(2 * math.pi * t / 1.5))
    for height in (s.h_one_third, s.h_two_percent, s.h_max, s.h_mean):
        assert abs(height - 0.06) < 1e-4
    assert abs(s.hm0 - 4 * 0.03 / math.sqrt(2)) < 1e-3
    assert abs(s.mean_period - 1.5) < 0.01 and abs(s.peak_period - 1.5) < 0.05


def test_relaxation_weight_and_ramp():
    assert relaxation_weight(0.0) == 1.0 and abs(relaxation_weight(1.0)) < 1e-15
    assert np.all(np.diff(relaxation_weight(np.linspace(0, 1, 11))) < 0)
    assert ramp(0.0, 2.0) == 0.0 and ramp(2.0, 2.0) == 1.0 and ramp(5.0, 2.0) == 1.0
    zone = RelaxationZone("generation", 0.0, 2.0)
    assert zone.chi(2.0) == 0.0 and zone.chi(0.0) == 1.0
    with pytest.raises(CaseFileError, match="empty"):
        RelaxationZone("absorption", 3.0, 3.0)


def test_absorbing_zone_brings_a_disturbed_flume_to_rest_at_its_level():
    grid = FluidGrid(lower=(0, 0, 0), upper=(2.0, 0.05, 0.5), cells=(40, 1, 10))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.25)
    fluid.u[:] = 0.3
    fluid.relaxation = WaveRelaxation(None, 0.25, [RelaxationZone("absorption", 0.0, 2.0)])
    fluid.relaxation.apply(fluid)
    # each face keeps its weight's share of the flow (still water is the target)
    x_faces = grid.faces(0)[1:-1]
    expected = 0.3 * relaxation_weight(x_faces / 2.0)
    assert np.allclose(fluid.u[1:-1, 0, 0], expected)
    assert fluid.u[-2, 0, 0] < 0.15 * 0.3 and fluid.u[1, 0, 0] > 0.99 * 0.3
    # the water was at the target level already: it stays
    assert np.allclose(fluid.fraction[:, 0, :5], 1.0) and np.allclose(fluid.fraction[:, 0, 5:], 0.0)


def test_gauges_read_the_column_and_interpolate_velocity():
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.5, 0.5), cells=(10, 5, 5))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.23)
    x_faces = grid.faces(0)
    fluid.u[:] = (2.0 * x_faces)[:, None, None]                 # u = 2 x: linear, read exactly
    gauges = GaugeSet([Gauge("eta", "surface", (0.55, 0.25, 0.0)),
                       Gauge("probe", "velocity", (0.37, 0.25, 0.2))], still_water_level=0.2)
    values = gauges.read(fluid)
    assert abs(values[0] - 0.03) < 1e-12
    assert abs(values[1] - 0.74) < 1e-12 and values[2] == 0.0 and values[3] == 0.0
    gauges.record(fluid)
    fluid.time = 0.1
    gauges.record(fluid)
    saved = {name: array.copy() for name, array in gauges.record_arrays().items()}
    again = GaugeSet(gauges.gauges, 0.2)
    again.load_record_arrays(saved)
    assert again.count == 2 and np.array_equal(again.values, gauges.values)
    with pytest.raises(CaseFileError, match="outside the fluid box"):
        GaugeSet([Gauge("far", "surface", (3.0, 0.2, 0.0))], 0.2).check_in_grid(grid)
    with pytest.raises(CaseFileError, match="repeated: a"):
        GaugeSet([Gauge("a", "surface", (0.1, 0.1, 0)), Gauge("a", "surface", (0.2, 0.1, 0))], 0.2)


@pytest.mark.parametrize("height, period, depth, cell, zones, message", [
    (0.04, 1.2, 0.4, 0.03, (2.0, 4.0), "cells of at most 0.02"),
    (0.04, 0.6, 0.4, 0.015, (2.0, 4.0), "wave length"),
    (0.04, 1.2, 0.4, 0.01, (0.5, 4.0), "generation zone"),
    (0.04, 1.2, 0.4, 0.01, (2.0, 1.0), "to absorb"),
    (0.35, 1.2, 0.4, 0.01, (2.0, 4.0), "breaks where it is made"),
    (0.05, 6.0, 0.4, 0.01, (20.0, 40.0), "Ursell"),
])
def test_waves_the_flume_cannot_carry_are_refused_with_the_figure(height, period, depth, cell,
                                                                    zones, message):
    wave = LinearWave(height=height, period=period, depth=depth)
    with pytest.raises(CaseFileError, match=message):
        check_flume(wave, cell, [RelaxationZone("generation", 0.0, zones[0]),
                                 RelaxationZone("absorption", 50.0, 50.0 + zones[1])])


def test_stream_function_wave_is_linear_when_small_and_stokes_when_moderate():
    from riprap.waves.stream_function import NO_EULERIAN_CURRENT, StreamFunctionWave

    small = StreamFunctionWave(height=0.001, period=1.2, depth=0.4)
    linear = LinearWave(height=0.001, period=1.2, depth=0.4)
    assert small.residual < 1e-12
    assert abs(small.wave_number / linear.wave_number - 1.0) < 1e-5
    x = np.linspace(0.0, 2.0, 9)
    assert np.allclose(small.elevation(x, 0.3), linear.elevation(x, 0.3), atol=2e-3 * 0.001)
    # within the closed flume's return current (second order: 3e-6 m/s against 2.3e-3)
    assert np.allclose(small.velocity(x, -0.1, 0.3)[0], linear.velocity(x, -0.1, 0.3)[0], rtol=2e-3,
                       atol=1e-5)
    # H/d = 0.3, kH/2 = 0.19: the celerity of Stokes' third order (no Eulerian current, Fenton
    # 1985 eq. 26 to second order in (ka)^2) within 0.1 %, a crest higher than H/2
    steep = StreamFunctionWave(height=0.12, period=1.2, depth=0.4, current=NO_EULERIAN_CURRENT)
    k, t = steep.wave_number, math.tanh(steep.wave_number * 0.4)
    stokes = math.sqrt(9.81 / k * t) * (1 + (k * 0.06) ** 2 * (9 - 10 * t ** 2 + 9 * t ** 4) / (16 * t ** 4))
    assert abs(steep.celerity / stokes - 1.0) < 1e-3
    assert steep.crest_elevation > 0.06 * 1.1
    assert abs(steep.celerity * 1.2 - steep.wave_length) < 1e-9
    # the surface series passes through the solved points; continuity holds in the flow
    e = 1e-6
    div = ((steep.velocity(0.3 + e, -0.2, 0.1)[0] - steep.velocity(0.3 - e, -0.2, 0.1)[0])
           + (steep.velocity(0.3, -0.2 + e, 0.1)[1] - steep.velocity(0.3, -0.2 - e, 0.1)[1])) / (2 * e)
    assert abs(div) < 1e-6
    with pytest.raises(CaseFileError, match="too close to breaking"):
        StreamFunctionWave(height=0.4, period=1.2, depth=0.4)


def test_every_case_file_wave_type_has_a_theory_and_each_says_what_it_is():
    """The schema's [waves] type choices are the registry's names (one place to add a theory),
    and each theory states whether it is regular, how its height is named and whether the
    Ursell limit applies (the flume checks and the report read these, not the class)."""
    from riprap.schema import key
    from riprap.waves.theories import WAVE_THEORIES, make_wave

    assert set(key("waves", "type").choices) == set(WAVE_THEORIES)
    parameters = {"height": 0.1, "period": 2.0, "phase": 0.0, "significant_height": 0.1,
                  "peak_period": 2.0, "duration": 100.0, "peak_enhancement": 3.3, "seed": 1}
    expected = {"linear": (True, "H", True), "stokes2": (True, "H", True),
                "stream_function": (True, "H", False), "irregular": (False, "Hm0", False)}
    for name in WAVE_THEORIES:
        wave = make_wave(name, parameters, 1.0, 50.0, 9.81)
        assert (wave.regular, wave.height_name, wave.ursell_limited) == expected[name]
        assert wave.wave_length > 0 and np.isfinite(wave.elevation(np.array([0.5]), 1.0)).all()
