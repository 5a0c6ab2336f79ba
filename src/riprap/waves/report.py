"""The flume's wave analysis: per surface gauge its heights and periods, per pair and per triple of
neighbouring surface gauges the incident and reflected waves (Goda-Suzuki, Mansard-Funke), per overtopping gauge the overtopped volume and
mean discharge, per run-up gauge R_max and R2%, beside the target wave (``waves_report.json``).

Each record is analysed from the time the wave train has arrived: the ramp, plus the travel from
the generation zone at the group velocity of the (peak) period, plus two periods
(``riprap.waves.analysis_window``). What could not be computed is said, with the reason, in
``not_computed``; statistics from one to three waves carry a ``caution`` (and are listed in
``cautions``).
"""
from __future__ import annotations

import math

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.analysis import (separate_incident_reflected, separate_regular_wave,
                                   separate_three_gauges, wave_statistics)
from riprap.waves.analysis_window import few_waves_caution
from riprap.waves.gauges import OVERTOPPING, RUN_UP, SURFACE
from riprap.waves.theory import group_velocity

__all__ = ["flume_report", "group_velocity", "arrival_time", "closing_time", "run_up_statistics",
           "overtopping_statistics"]


def arrival_time(wave_source, x: float) -> float:
    """When the steady wave train made by ``wave_source`` (a WaveRelaxation or a
    BoundaryWaveMaker) has reached ``x`` (s)."""
    wave = wave_source.wave
    speed = group_velocity(wave.period, wave.depth, wave.wave_length)
    return wave_source.ramp_time + max(x - wave_source.origin, 0.0) / speed + 2.0 * wave.period


def closing_time(wave_source, x: float) -> float:
    """When the last wave of a sea that stops (``stop_time`` > 0: a test step's) has passed ``x``
    (s): the stop time plus the travel from the wave maker; infinite for a sea that runs to the
    end. Each gauge's analysis window closes then, so that the calm water after the sea does not
    count as a sea."""
    stop = float(getattr(wave_source, "stop_time", 0.0) or 0.0)
    if wave_source is None or wave_source.wave is None or stop <= 0:
        return math.inf
    wave = wave_source.wave
    speed = group_velocity(wave.period, wave.depth, wave.wave_length)
    return stop + max(x - wave_source.origin, 0.0) / speed


def run_up_statistics(times, level) -> dict:
    """R_max and R2% (m above the still water level) of a run-up record: the peaks are the highest
    levels between successive up-crossings of the record's mean; R2% is exceeded by 2 % of them."""
    times, level = np.asarray(times, dtype=float), np.asarray(level, dtype=float)
    if level.size < 3:
        return {"note": "record too short"}
    mean = level.mean()
    crossings = np.flatnonzero((level[:-1] < mean) & (level[1:] >= mean))
    peaks = np.array([level[a:b + 1].max() for a, b in zip(crossings[:-1], crossings[1:])])
    result = {"R_max_m": float(level.max()), "run_up_waves": int(peaks.size)}
    if peaks.size:
        ranked = np.sort(peaks)[::-1]
        position = 0.02 * ranked.size - 0.5
        result["R2%_m"] = (float(np.interp(position, np.arange(ranked.size), ranked))
                           if position > 0 else float(ranked[0]))
    return result


def overtopping_statistics(times, volume) -> dict:
    """Overtopped volume per metre (m^3/m) over the record and the mean discharge q (m^3/s per m,
    and in l/s per m as EurOtop tabulates it)."""
    times, volume = np.asarray(times, dtype=float), np.asarray(volume, dtype=float)
    if times.size < 2 or times[-1] <= times[0]:
        return {"note": "record too short"}
    overtopped = float(volume[-1] - volume[0])
    q = overtopped / float(times[-1] - times[0])
    return {"volume_m3_per_m": overtopped, "q_m3_s_per_m": q, "q_l_s_per_m": 1e3 * q,
            "duration_s": float(times[-1] - times[0])}


def flume_report(gauges, wave_source=None, water_density: float | None = None) -> dict:
    """The analysis of ``gauges`` (a GaugeSet) as a dict for JSON; ``wave_source`` (what makes the
    flume's waves: its WaveRelaxation or BoundaryWaveMaker, optional) gives the target and the
    analysis windows; ``water_density``
    (kg/m^3) is recorded for the stability report."""
    report = {"gauges": {}, "reflection": [], "not_computed": [], "cautions": []}
    record_end = float(gauges.times[-1]) if gauges.count else 0.0
    report["record_end_s"] = record_end
    if water_density is not None:
        report["water_density_kg_m3"] = float(water_density)
    wave = wave_source.wave if wave_source is not None and wave_source.wave is not None else None
    if wave is not None:
        target = {"type": type(wave).__name__, "height_m": wave.height, "period_s": wave.period,
                  "depth_m": wave.depth, "wave_length_m": wave.wave_length}
        report["target"] = target
    surface = [g for g in gauges.gauges if g.kind == SURFACE]
    windows = {}
    for gauge in surface:
        times, eta = gauges.series(gauge.columns[0])
        start = arrival_time(wave_source, gauge.position[0]) if wave is not None else times[0] if times.size else 0.0
        chosen = (times >= start) & (times <= closing_time(wave_source, gauge.position[0]))
        windows[gauge.name] = (times[chosen], eta[chosen])
        entry = {"x_m": gauge.position[0], "analysed_from_s": float(start),
                 "samples": int(chosen.sum())}
        if chosen.sum() >= 8 and (wave is None or times[-1] - start >= 2.0 * wave.period):
            entry.update(wave_statistics(times[chosen], eta[chosen]).as_dict())
            _caution(report, entry, gauge.name, entry["waves"])
        else:
            entry["note"] = "record too short after the wave train's arrival"
            report["not_computed"].append(
                f"{gauge.name}: wave heights and periods: {_too_short(record_end, start, wave, 2)}")
        report["gauges"][gauge.name] = entry
    for gauge in gauges.gauges:
        if gauge.kind not in (OVERTOPPING, RUN_UP):
            continue
        times, values = gauges.series(gauge.columns[-1])
        start = arrival_time(wave_source, gauge.position[0]) if wave is not None else (times[0] if times.size else 0.0)
        # the last waves' run-up and overtopping come a little after they pass the gauge's x
        closes = closing_time(wave_source, gauge.position[0]) + (2.0 * wave.period if wave else 0.0)
        chosen = (times >= start) & (times <= closes)
        entry = {"x_m": gauge.position[0], "analysed_from_s": float(start)}
        if gauge.kind == OVERTOPPING:
            entry.update(overtopping_statistics(times[chosen], values[chosen]))
            report.setdefault("overtopping", {})[gauge.name] = entry
        else:
            entry["to_x_m"] = gauge.to_x
            entry.update(run_up_statistics(times[chosen], values[chosen]))
            report.setdefault("run_up", {})[gauge.name] = entry
            _caution(report, entry, gauge.name, entry.get("run_up_waves"))
        if "note" in entry:
            what = "overtopping" if gauge.kind == OVERTOPPING else "run-up"
            report["not_computed"].append(f"{gauge.name}: {what}: "
                                          f"{_too_short(record_end, start, wave, 2)}")
    if wave is not None:
        regular = wave.regular
        ordered = sorted(surface, key=lambda g: g.position[0])
        for first, second in zip(ordered[:-1], ordered[1:]):
            t1, e1 = windows[second.name]
            if t1.size < 8 or t1[-1] - t1[0] < 4.0 * wave.period:
                start = report["gauges"][second.name]["analysed_from_s"]
                report["not_computed"].append(
                    f"{first.name}-{second.name}: incident and reflected waves: "
                    f"{_too_short(record_end, start, wave, 4)}")
                continue
            _, eta_1 = gauges.series(first.columns[0])
            times = gauges.times
            chosen = (times >= t1[0]) & (times <= t1[-1])
            spacing = second.position[0] - first.position[0]
            try:
                if regular:     # at its own frequency: its bound harmonics are not free waves
                    split = separate_regular_wave(times[chosen], eta_1[chosen], e1, spacing,
                                                  wave.depth, wave.period)
                else:
                    split = separate_incident_reflected(times[chosen], eta_1[chosen], e1, spacing,
                                                        wave.depth, wave.period)
            except CaseFileError as error:
                # spacing outside 0.05 .. 0.45 wave lengths: no split for this pair
                report["not_computed"].append(f"{first.name}-{second.name}: incident and reflected "
                                              f"waves: {error}")
                continue
            entry = {"gauges": [first.name, second.name], "spacing_m": spacing, **split.as_dict()}
            report["reflection"].append(_named_for(entry, regular))
        for triple in zip(ordered[:-2], ordered[1:-1], ordered[2:]):
            entry = _three_gauge_entry(gauges, windows, triple, wave, regular)
            if entry is not None:
                report.setdefault("reflection_three_gauge", []).append(entry)
    return report


def _too_short(record_end: float, start: float, wave, periods: float) -> str:
    """Why a record gave nothing: it ends before (or too soon after) its window opens."""
    if wave is None:
        return f"the record (to t = {record_end:g} s) is too short"
    needed = start + periods * wave.period
    if record_end <= start:
        return (f"the record ends at t = {record_end:g} s, before the analysis window opens at "
                f"{start:.3g} s (the wave train's arrival); run to at least {needed:.3g} s")
    return (f"the record ends at t = {record_end:g} s, {record_end - start:.3g} s after the analysis "
            f"window opens at {start:.3g} s; it needs {periods:g} periods ({periods * wave.period:.3g} s)"
            f": run to at least {needed:.3g} s")


def _caution(report: dict, entry: dict, name: str, waves) -> None:
    """A caution on ``entry`` (and in the report's list) for statistics from 1 to 3 waves."""
    caution = few_waves_caution(waves)
    if caution is not None:
        entry["caution"] = caution
        report["cautions"].append(f"{name}: {caution}")


def _three_gauge_entry(gauges, windows, triple, wave, regular):
    """Mansard & Funke's split of three neighbouring surface gauges over the last one's window
    (the train has reached all three), or None where it is too short or cannot be split."""
    t_last, _ = windows[triple[-1].name]
    if t_last.size < 8 or t_last[-1] - t_last[0] < 4.0 * wave.period:
        return None
    times = gauges.times
    chosen = (times >= t_last[0]) & (times <= t_last[-1])
    records = [gauges.series(g.columns[0])[1][chosen] for g in triple]
    positions = [g.position[0] for g in triple]
    try:
        split = separate_three_gauges(times[chosen], records, positions, wave.depth, wave.period,
                                      regular=regular)
    except CaseFileError:
        return None
    return _named_for({"gauges": [g.name for g in triple], "x_m": positions, **split.as_dict()},
                      regular)


def _named_for(entry: dict, regular: bool) -> dict:
    """A split's entry with a regular wave's heights named as heights (H = 2 a), not Hm0."""
    if regular:
        entry["incident_height_m"] = entry.pop("incident_Hm0_m")
        entry["reflected_height_m"] = entry.pop("reflected_Hm0_m")
    return entry
