"""Wave by wave: the incident waves at the toe, counted one by one, and what each did.

A flume test reports more than a sea state's totals: the damage develops wave by wave and EurOtop
(2018, ch. 1.4 and 5.2) reads overtopping as individual volumes, one per overtopping wave. This
module turns a run's records into those rows; it reads arrays, not files.

- **The incident elevation at the toe** (``incident_elevation``): the Mansard & Funke split of
  three gauges before the structure (``riprap.waves.analysis``) gives, per frequency, the incident
  wave's complex amplitude a_I at the first gauge; the incident record anywhere along the flume
  is sum_f Re(a_I e^{i(k (x - x_1) - omega t)}) (linear dispersion, which holds seaward of the
  toe where the gauges stand). Frequencies where the split is ill posed, or outside the band, are
  left out: the record carries the band's energy (0.5-3 f_p by default: 99 % of a JONSWAP
  spectrum with gamma = 3.3).
- **Waves** (``zero_down_crossing_waves``): a wave runs from one zero down-crossing of the
  (mean-free) record to the next, crossing times interpolated linearly between samples; its
  height is its highest crest minus its lowest trough, its period the time between its crossings
  (Goda 2010, ch. 2.1).
- **Overtopping events** (``overtopping_events``): a run of steps with water going over the crest
  (discharge above ``threshold``) is one event; its volume is the water that went over in it, so
  that the events add up to the gauge's total exactly (``tests/unit/test_per_wave.py``).
- **A wave's window at a place downstream** (``shifted_windows``): what a wave does on the slope
  and over the crest happens after it passes the toe; each wave's window is shifted by the time
  its crest takes to get there, taken at the linear celerity of the peak period at the toe's depth
  (an estimate: the wave slows on the slope; a window still starts where the last one ended, so
  that every moment of the record falls in exactly one wave).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.analysis import gauge_spectra, three_gauge_split
from riprap.waves.theory import GRAVITY, wave_length, wave_number

__all__ = ["Waves", "incident_elevation", "zero_down_crossing_waves", "OvertoppingEvents",
           "overtopping_events", "shifted_windows", "lag_to", "window_sums", "window_maxima"]


def incident_elevation(times, records, positions, depth: float, at: float,
                       peak_period: float | None = None, band=(0.5, 3.0),
                       gravity: float = GRAVITY) -> tuple[np.ndarray, np.ndarray]:
    """(t, eta_I): the incident wave's elevation at x = ``at`` on an even grid over the records
    (three gauges' ``records`` at ``positions``, m along the flume, in water ``depth`` m deep).
    ``band``: the frequencies kept, in multiples of the peak's (``peak_period``, default the
    spectral peak of the first gauge)."""
    positions = np.asarray(positions, dtype=float)
    if positions.size != 3 or len(records) != 3:
        raise CaseFileError(f"incident elevation: needs three gauges, got {positions.size}")
    offsets = positions - positions[0]
    t, frequencies, spectra, peak_period = gauge_spectra(times, records, peak_period)
    n = t.size
    fp = 1.0 / peak_period
    incident = np.zeros(frequencies.size, dtype=complex)
    kept = 0
    for m, f in enumerate(frequencies):
        if m == 0 or not band[0] * fp <= f <= band[1] * fp:
            continue
        k = wave_number(1.0 / f, depth, gravity)
        split = three_gauge_split(spectra[:, m], k, offsets)
        if split is None:
            continue
        incident[m] = split[0] * np.exp(1j * k * (at - positions[0]))
        kept += 1
    if kept == 0:
        raise CaseFileError(f"incident elevation: no frequency near the peak ({fp:.3g} Hz) can be "
                            f"split with gauges at x = {positions.tolist()} m")
    # back from amplitudes of exp(-i omega t) to numpy's convention
    spectrum = np.conj(incident) * n / 2.0
    return t, np.fft.irfft(spectrum, n)


@dataclass(frozen=True)
class Waves:
    """Zero-down-crossing waves of a record: per wave its start and end (s), height (m) and
    period (s)."""

    start: np.ndarray
    end: np.ndarray
    height: np.ndarray
    period: np.ndarray

    def __len__(self) -> int:
        return int(self.start.size)


def zero_down_crossing_waves(times, eta) -> Waves:
    """The zero-down-crossing waves of ``eta`` on ``times`` (its mean removed first)."""
    times = np.asarray(times, dtype=float)
    eta = np.asarray(eta, dtype=float)
    if times.shape != eta.shape or times.ndim != 1:
        raise CaseFileError(f"wave count: times {times.shape} and elevations {eta.shape} differ")
    level = eta - eta.mean()
    down = np.flatnonzero((level[:-1] >= 0.0) & (level[1:] < 0.0))
    if down.size < 2:
        empty = np.zeros(0)
        return Waves(empty, empty, empty, empty)
    # the crossing between samples a and a + 1, linearly
    share = level[down] / (level[down] - level[down + 1])
    crossing = times[down] + share * (times[down + 1] - times[down])
    heights = np.array([level[a:b + 2].max() - level[a:b + 2].min()
                        for a, b in zip(down[:-1], down[1:])])
    return Waves(crossing[:-1], crossing[1:], heights, np.diff(crossing))


@dataclass(frozen=True)
class OvertoppingEvents:
    """Individual overtopping events: start and end (s) and volume per metre of crest (m^3/m)."""

    start: np.ndarray
    end: np.ndarray
    volume: np.ndarray

    def __len__(self) -> int:
        return int(self.start.size)


def overtopping_events(times, volume, threshold: float = 0.0) -> OvertoppingEvents:
    """The events of an overtopping gauge's cumulative volume record ``volume`` (m^3/m at
    ``times``): runs of intervals in which more than ``threshold`` m^3/m went over. Each event's
    volume is the rise of the record over its intervals, so the events add up to the record's
    rise less what went over in intervals at or below the threshold."""
    times = np.asarray(times, dtype=float)
    volume = np.asarray(volume, dtype=float)
    if times.shape != volume.shape or times.ndim != 1:
        raise CaseFileError(f"overtopping events: times {times.shape} and volumes {volume.shape} "
                            "differ")
    rise = np.diff(volume)
    wet = rise > threshold
    edges = np.diff(np.concatenate(([0], wet.astype(np.int8), [0])))
    first = np.flatnonzero(edges == 1)
    last = np.flatnonzero(edges == -1)          # one past the event's last interval
    volumes = np.array([rise[a:b].sum() for a, b in zip(first, last)])
    return OvertoppingEvents(times[first], times[last], volumes.reshape(-1))


def shifted_windows(waves: Waves, lag: float) -> tuple[np.ndarray, np.ndarray]:
    """(start, end) of each wave's window ``lag`` s later (where it acts downstream). The last
    window is open-ended (+inf) and the first starts at -inf, so that every time of a record falls
    in exactly one window."""
    if len(waves) == 0:
        return np.zeros(0), np.zeros(0)
    start = waves.start + lag
    end = waves.end + lag
    start[0] = -math.inf
    end[-1] = math.inf
    return start, end


def lag_to(distance: float, peak_period: float, depth: float, gravity: float = GRAVITY) -> float:
    """Travel time (s) of a wave crest over ``distance`` m at the linear celerity of
    ``peak_period`` in water ``depth`` m deep."""
    return max(distance, 0.0) * peak_period / wave_length(peak_period, depth, gravity)


def window_sums(start, end, event_times, event_values) -> np.ndarray:
    """Per window [start, end) the sum of the events whose time falls in it."""
    event_times = np.asarray(event_times, dtype=float)
    index = np.searchsorted(np.asarray(end, dtype=float), event_times, side="right")
    sums = np.zeros(len(start))
    np.add.at(sums, np.minimum(index, len(start) - 1), np.asarray(event_values, dtype=float))
    return sums


def window_maxima(start, end, times, values) -> np.ndarray:
    """Per window [start, end) the largest value of a record in it (NaN where none)."""
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    index = np.searchsorted(np.asarray(end, dtype=float), times, side="right")
    maxima = np.full(len(start), -np.inf)
    np.maximum.at(maxima, np.minimum(index, len(start) - 1), values)
    maxima[~np.isfinite(maxima)] = np.nan
    return maxima
