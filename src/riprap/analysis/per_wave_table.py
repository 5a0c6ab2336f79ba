"""The per-wave table of a flume test: one row per incident wave at the toe, with what that wave
did on the structure (issue 38).

The waves are counted on the incident elevation at the toe (``riprap.waves.per_wave``); each
wave's window is shifted by the wave's travel time from the toe to where it acts (the run-up
gauge's start, the overtopping gauge's plane, the armour's mid-slope), so that a wave's run-up,
overtopping and forces are those it caused and not its predecessor's. Windows tile the record:
every interval of the overtopping record falls in exactly one wave, so the per-wave volumes add
up to the gauge's total (the first wave's window starts at the record's start, the last one's
ends at its end).

Columns (``PER_WAVE_COLUMNS``):

- ``wave``: 1, 2, ... in order of arrival; ``start_s``, ``end_s``: its zero down-crossings at the
  toe; ``height_m``, ``period_s``: its zero-down-crossing height and period;
- ``overtopping_m3_per_m``: the water that went over the crest in its window, per metre of crest;
  ``overtopping_events``: how many individual overtopping events began in it, and
  ``largest_event_m3_per_m`` the largest of them (EurOtop 2018, ch. 1.4: V_max);
- ``run_up_m``: the highest run-up level above still water in its window;
- ``largest_fluid_force_N``, ``force_unit``: the largest fluid force on any unit in its window
  (the bodies' recorded peaks, ``body_forces.csv``) and which unit took it;
- ``units_displaced``, ``N_od``: at the end of its window, the units whose centroid has moved
  more than ``threshold_dn`` nominal diameters from the start (of the run, or of the test series), and N_od = that count per Dn of
  section width (Van der Meer 1988) - the damage development N_od(N).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.analysis.damage import damage_number_nod
from riprap.errors import CaseFileError
from riprap.waves.per_wave import (incident_elevation, lag_to, overtopping_events, shifted_windows,
                                   window_maxima, window_sums, zero_down_crossing_waves)

__all__ = ["PER_WAVE_COLUMNS", "FlumeLayout", "UnitTracks", "per_wave_table"]

PER_WAVE_COLUMNS = ("wave", "start_s", "end_s", "height_m", "period_s", "overtopping_m3_per_m",
                    "overtopping_events", "largest_event_m3_per_m", "run_up_m",
                    "largest_fluid_force_N", "force_unit", "units_displaced", "N_od")


@dataclass(frozen=True)
class FlumeLayout:
    """Where things stand along the flume (m) and the sea they stand in."""

    gauge_positions: tuple        # x of the three wave gauges before the toe
    toe_x: float                  # where the waves are counted
    depth: float                  # water depth at the gauges and the toe (m)
    peak_period: float            # s
    run_up_x: float | None = None          # where the run-up gauge starts
    overtopping_x: float | None = None     # the overtopping gauge's plane
    armour_x: float | None = None          # the armour's mid-slope (forces, displacements)


@dataclass(frozen=True)
class UnitTracks:
    """The units' recorded states (rows of ``body_forces.csv`` for the free units): per row the
    unit, the time (s), the centroid (m, (n, 3)) and the peak fluid force since the last row (N).
    ``reference``: where each unit started (m, indexed by unit: a test series' start), or None
    for each unit's first row. ``period_y``: the width of a periodic strip (m; 0: walls): a unit's
    track across its side is unwrapped row by row."""

    unit: np.ndarray
    time: np.ndarray
    position: np.ndarray
    peak_force: np.ndarray
    nominal_diameter: float       # m
    section_width: float          # m, for N_od
    reference: np.ndarray | None = None
    period_y: float = 0.0


def _shifted(waves, layout, x):
    lag = lag_to((x if x is not None else layout.toe_x) - layout.toe_x, layout.peak_period,
                 layout.depth)
    return shifted_windows(waves, lag)


def per_wave_table(times, gauge_records, layout: FlumeLayout, *, run_up=None,
                   overtopping_volume=None, tracks: UnitTracks | None = None,
                   threshold_dn: float = 1.0, event_threshold: float = 0.0) -> dict:
    """The per-wave table as columns (``PER_WAVE_COLUMNS``; NaN where a record is missing).

    ``times``: the gauges' record times (s); ``gauge_records``: the three surface gauges'
    elevations at ``layout.gauge_positions``; ``run_up``: the run-up gauge's level (m) or None;
    ``overtopping_volume``: the overtopping gauge's cumulative volume (m^3/m) or None; ``tracks``:
    the units' states or None."""
    if not threshold_dn > 0:
        raise CaseFileError(f"per-wave table: threshold_dn = {threshold_dn!r} must be > 0 (Dn)")
    times = np.asarray(times, dtype=float)
    t, eta = incident_elevation(times, gauge_records, layout.gauge_positions, layout.depth,
                                at=layout.toe_x, peak_period=layout.peak_period)
    waves = zero_down_crossing_waves(t, eta)
    n = len(waves)
    table = {name: np.full(n, np.nan) for name in PER_WAVE_COLUMNS}
    table["wave"] = np.arange(1, n + 1)
    table["start_s"], table["end_s"] = waves.start, waves.end
    table["height_m"], table["period_s"] = waves.height, waves.period
    if n == 0:
        return table
    if overtopping_volume is not None:
        volume = np.asarray(overtopping_volume, dtype=float)
        start, end = _shifted(waves, layout, layout.overtopping_x)
        # each interval's rise belongs to the wave whose window holds the interval's end
        table["overtopping_m3_per_m"] = window_sums(start, end, times[1:], np.diff(volume))
        events = overtopping_events(times, volume, event_threshold)
        table["overtopping_events"] = window_sums(start, end, events.start, np.ones(len(events)))
        largest = window_maxima(start, end, events.start, events.volume)
        table["largest_event_m3_per_m"] = np.where(np.isnan(largest), 0.0, largest)
    if run_up is not None:
        start, end = _shifted(waves, layout, layout.run_up_x)
        table["run_up_m"] = window_maxima(start, end, times, run_up)
    if tracks is not None:
        _unit_columns(table, waves, layout, tracks, threshold_dn)
    return table


def _unit_columns(table, waves, layout, tracks, threshold_dn):
    if not (math.isfinite(tracks.nominal_diameter) and tracks.nominal_diameter > 0):
        raise CaseFileError(f"per-wave table: the units' nominal diameter "
                            f"{tracks.nominal_diameter!r} m must be finite and > 0")
    start, end = _shifted(waves, layout, layout.armour_x)
    units = np.unique(tracks.unit)
    forces = np.full((len(waves), units.size), np.nan)
    for column, unit in enumerate(units):
        rows = tracks.unit == unit
        forces[:, column] = window_maxima(start, end, tracks.time[rows], tracks.peak_force[rows])
    any_force = ~np.all(np.isnan(forces), axis=1)
    table["largest_fluid_force_N"][any_force] = np.nanmax(forces[any_force], axis=1)
    table["force_unit"][any_force] = units[np.nanargmax(forces[any_force], axis=1)]
    # displaced so far: at each window's end, from each unit's first recorded position
    displaced = np.zeros(len(waves))
    for unit in units:
        rows = np.flatnonzero(tracks.unit == unit)
        rows = rows[np.argsort(tracks.time[rows], kind="stable")]
        start = (tracks.position[rows[0]] if tracks.reference is None
                 else np.asarray(tracks.reference)[int(unit)])
        path = tracks.position[rows] - start
        if tracks.period_y > 0.0:
            # from the start to the first row, then from row to row, each to the nearest image
            steps = np.diff(path[:, 1], prepend=0.0)
            steps -= tracks.period_y * np.round(steps / tracks.period_y)
            path[:, 1] = np.cumsum(steps)
        moved = np.linalg.norm(path, axis=1)
        # the last record at or before each window's end (the last wave: the last record)
        last = np.searchsorted(tracks.time[rows], end, side="right") - 1
        known = last >= 0
        displaced[known] += moved[last[known]] > threshold_dn * tracks.nominal_diameter
    table["units_displaced"] = displaced
    table["N_od"] = np.array([damage_number_nod(int(d), tracks.section_width,
                                                tracks.nominal_diameter) for d in displaced])
