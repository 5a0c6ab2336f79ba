"""The per-wave table (``riprap/analysis/per_wave_table.py``) on a synthetic flume whose answer
is known: an irregular sea with its reflection at three gauges, overtopping bursts, and two units
of which one is displaced at a known time."""
import math

import numpy as np
import pytest

from riprap.analysis.per_wave_table import FlumeLayout, UnitTracks, per_wave_table
from riprap.errors import CaseFileError
from riprap.waves.per_wave import lag_to, zero_down_crossing_waves
from riprap.waves.theory import wave_number

DEPTH, DURATION, DT = 2.0, 256.0, 0.05


def _flume():
    t = np.arange(0.0, DURATION, DT)
    rng = np.random.default_rng(7)
    frequencies = np.arange(20, 90) / DURATION
    amplitudes = 0.2 * np.exp(-((frequencies - 0.25) / 0.06) ** 2)
    phases = rng.uniform(0.0, 2.0 * math.pi, frequencies.size)
    ks = np.array([wave_number(1.0 / f, DEPTH) for f in frequencies])

    def sea(x, reflection):
        eta = np.zeros_like(t)
        for a, k, f, p in zip(amplitudes, ks, frequencies, phases):
            eta += a * np.cos(k * x - 2 * math.pi * f * t + p)
            if reflection:
                eta += 0.4 * a * np.cos(-k * x - 2 * math.pi * f * t + p + 1.0)
        return eta

    layout = FlumeLayout(gauge_positions=(-5.0, -3.4, -1.8), toe_x=0.0, depth=DEPTH,
                         peak_period=4.0, run_up_x=0.0, overtopping_x=5.0, armour_x=1.0)
    return t, sea, layout


def test_waves_overtopping_and_damage_wave_by_wave():
    t, sea, layout = _flume()
    records = [sea(x, True) for x in layout.gauge_positions]
    # overtopping: a burst of known volume every 30 s
    q = np.zeros_like(t)
    for start in np.arange(20.0, DURATION - 5.0, 30.0):
        inside = (t > start) & (t < start + 1.0)
        q[inside] = 0.02 * np.sin(math.pi * (t[inside] - start))
    volume = np.concatenate(([0.0], np.cumsum(0.5 * (q[1:] + q[:-1]) * DT)))
    run_up = np.maximum(sea(0.0, False), 0.0)
    # two units: unit 7 slides 1.5 Dn between t = 100 and 101 s, unit 8 rocks by 0.2 Dn
    dn, width = 0.5, 2.5
    track_t = np.arange(0.0, DURATION, 1.0)
    moved = dn * 1.5 * np.clip(track_t - 100.0, 0.0, 1.0)
    positions = np.concatenate([np.column_stack([moved, np.zeros_like(moved), np.zeros_like(moved)]),
                                np.column_stack([0.1 * dn * np.sin(track_t), np.zeros_like(moved),
                                                 np.zeros_like(moved)])])
    peak = np.concatenate([np.where(track_t == 60.0, 900.0, 100.0), np.full(track_t.size, 200.0)])
    tracks = UnitTracks(unit=np.repeat([7, 8], track_t.size), time=np.tile(track_t, 2),
                        position=positions, peak_force=peak, nominal_diameter=dn,
                        section_width=width)
    table = per_wave_table(t, records, layout, run_up=run_up, overtopping_volume=volume,
                           tracks=tracks)

    # the waves are those of the incident sea written at the toe (heights to 3 %: the split
    # drops the few ill-posed frequencies)
    expected = zero_down_crossing_waves(t, sea(0.0, False))
    assert len(table["wave"]) == len(expected)
    np.testing.assert_allclose(table["height_m"], expected.height, rtol=0.03, atol=0.01)
    np.testing.assert_allclose(table["period_s"], expected.period, atol=0.1)
    # every burst is in one wave and the table adds up to the gauge's total
    assert table["overtopping_m3_per_m"].sum() == pytest.approx(volume[-1], rel=1e-12)
    assert table["overtopping_events"].sum() == 8
    # each burst 0.02 sin over 1 s holds 0.04 / pi; trapezoids of 0.05 s take 0.2 % off it
    assert table["largest_event_m3_per_m"].max() == pytest.approx(0.04 / math.pi, rel=3e-3)
    # the run-up of each wave is at most the whole record's highest, and the largest is it
    assert np.nanmax(table["run_up_m"]) == pytest.approx(run_up.max())
    # the 900 N peak at t = 60 s is unit 7's, in the wave whose window (shifted by the travel
    # time to x = 1 m) holds t = 60 s
    lag = lag_to(1.0, 4.0, DEPTH)
    hit = np.flatnonzero((table["start_s"] + lag <= 60.0) & (table["end_s"] + lag > 60.0))
    assert table["largest_fluid_force_N"][hit] == 900.0 and table["force_unit"][hit] == 7
    # damage develops: 0 until the wave whose window ends after t = 101 s, then 1 unit for good
    displaced = table["units_displaced"]
    first = int(np.argmax(displaced > 0))
    assert table["end_s"][first] + lag >= 101.0 and table["end_s"][first - 1] + lag < 101.0
    assert np.all(displaced[first:] == 1) and np.all(displaced[:first] == 0)
    assert table["N_od"][-1] == pytest.approx(1 / (width / dn))


def test_bad_threshold_and_diameter_are_refused():
    t, sea, layout = _flume()
    records = [sea(x, True) for x in layout.gauge_positions]
    with pytest.raises(CaseFileError, match="threshold_dn"):
        per_wave_table(t, records, layout, threshold_dn=0.0)
    tracks = UnitTracks(np.array([1]), np.array([0.0]), np.zeros((1, 3)), np.zeros(1),
                        nominal_diameter=float("nan"), section_width=1.0)
    with pytest.raises(CaseFileError, match="nominal diameter"):
        per_wave_table(t, records, layout, tracks=tracks)
