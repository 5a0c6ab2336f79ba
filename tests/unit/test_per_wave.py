"""Wave-by-wave counting (``riprap/waves/per_wave.py``) on records whose answer is known by
construction: waves of given heights and periods, an incident and a reflected sea summed at
three gauges, overtopping bursts of given volumes."""
import math

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.waves.per_wave import (incident_elevation, lag_to, overtopping_events, shifted_windows,
                                   window_maxima, window_sums, zero_down_crossing_waves)
from riprap.waves.theory import wave_number


def _waves_record(heights, periods, samples_per_second=200.0):
    """Whole sine cycles, each starting at a zero down-crossing: wave i is
    -H_i / 2 sin(2 pi (t - t_i) / T_i)."""
    times, values, start = [], [], 0.0
    for height, period in zip(heights, periods):
        t = np.arange(0.0, period, 1.0 / samples_per_second)
        times.append(start + t)
        values.append(-0.5 * height * np.sin(2.0 * math.pi * t / period))
        start += period
    times.append([start])
    values.append([0.0])
    return np.concatenate(times), np.concatenate(values)


def test_zero_down_crossing_counts_known_waves():
    heights = [1.0, 0.4, 1.6, 0.8, 1.2]
    periods = [4.0, 2.5, 5.0, 3.5, 4.5]
    times, eta = _waves_record(heights, periods)
    eta = eta - eta.mean()          # the counter removes the mean; keep the crossings where built
    waves = zero_down_crossing_waves(times, eta)
    # the record starts on a crossing and ends on one: all but the last wave are whole
    assert len(waves) == len(heights) - 1
    # tolerance: the mean removed (a few mm) moves crossings by its share of a slope
    np.testing.assert_allclose(waves.height, heights[:-1], rtol=2e-3)
    np.testing.assert_allclose(waves.period, periods[:-1], atol=0.02)
    np.testing.assert_allclose(waves.start[1:], waves.end[:-1])


def test_a_record_with_one_crossing_has_no_whole_wave():
    assert len(zero_down_crossing_waves(np.arange(5.0), np.array([1.0, -1.0, -1.0, -1.0, -1.0]))) == 0
    with pytest.raises(CaseFileError, match="differ"):
        zero_down_crossing_waves(np.arange(5.0), np.zeros(4))


def test_incident_elevation_at_the_toe_from_three_gauges():
    """An irregular incident sea and its reflection (K_r = 0.4 with a phase) summed at three gauges;
    the incident record rebuilt at the toe matches the incident sea written there to 1 % of its
    rms (the frequencies lie on the record's own FFT grid, so the split is exact but for those
    where it is ill posed, which carry little energy here)."""
    depth, duration, dt = 2.0, 256.0, 0.05
    t = np.arange(0.0, duration, dt)
    rng = np.random.default_rng(4)
    frequencies = np.arange(20, 90) / duration            # 0.078 .. 0.35 Hz around fp = 0.25
    amplitudes = 0.2 * np.exp(-((frequencies - 0.25) / 0.06) ** 2)
    phases = rng.uniform(0.0, 2.0 * math.pi, frequencies.size)
    ks = np.array([wave_number(1.0 / f, depth) for f in frequencies])
    omega = 2.0 * math.pi * frequencies

    def sea(x, reflection):
        eta = np.zeros_like(t)
        for a, k, w, p in zip(amplitudes, ks, omega, phases):
            eta += a * np.cos(k * x - w * t + p)
            if reflection:
                eta += 0.4 * a * np.cos(-k * x - w * t + p + 1.0)
        return eta

    positions = [-5.0, -3.4, -1.8]
    records = [sea(x, True) for x in positions]
    t_out, eta_incident = incident_elevation(t, records, positions, depth, at=0.0,
                                             peak_period=4.0, band=(0.3, 1.5))
    expected = sea(0.0, False)
    error = np.sqrt(np.mean((eta_incident - np.interp(t_out, t, expected)) ** 2))
    assert error < 0.01 * np.sqrt(np.mean(expected ** 2))


def test_overtopping_events_add_up_to_the_gauge_total():
    t = np.linspace(0.0, 30.0, 3001)
    q = np.zeros_like(t)
    bursts = [(3.0, 1.0, 0.02), (11.0, 0.5, 0.05), (12.0, 0.8, 0.01), (25.0, 2.0, 0.03)]
    for start, length, peak in bursts:
        inside = (t > start) & (t < start + length)
        q[inside] = peak * np.sin(math.pi * (t[inside] - start) / length)
    volume = np.concatenate(([0.0], np.cumsum(0.5 * (q[1:] + q[:-1]) * np.diff(t))))
    events = overtopping_events(t, volume)
    assert len(events) == 4
    expected = [2.0 / math.pi * peak * length for _, length, peak in bursts]
    np.testing.assert_allclose(events.volume, expected, rtol=1e-3)   # trapezoids of 0.01 s
    assert events.volume.sum() == pytest.approx(volume[-1], rel=1e-12)
    # per wave, the events land in exactly one window each and add up again
    from riprap.waves.per_wave import Waves
    waves = Waves(np.array([0.0, 8.0, 16.0]), np.array([8.0, 16.0, 30.0]), np.ones(3), np.full(3, 8.0))
    start, end = shifted_windows(waves, lag=1.5)
    per_wave = window_sums(start, end, events.start, events.volume)
    np.testing.assert_allclose(per_wave, [expected[0], expected[1] + expected[2], expected[3]],
                               rtol=1e-3)
    assert per_wave.sum() == pytest.approx(volume[-1], rel=1e-12)
    largest = window_maxima(start, end, t, q)
    np.testing.assert_allclose(largest, [0.02, 0.05, 0.03], rtol=1e-3)


def test_lag_is_distance_over_the_linear_celerity():
    k = wave_number(4.0, 2.0)
    assert lag_to(8.0, 4.0, 2.0) == pytest.approx(8.0 / ((2 * math.pi / 4.0) / k))
    assert lag_to(-1.0, 4.0, 2.0) == 0.0
