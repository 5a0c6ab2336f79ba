"""The per-wave table of a flume run's folder (``per_wave.csv``; ``docs/campaign.md``): its
gauges' records and its units' tracks read, the table made by
``riprap.analysis.per_wave_table``. ``riprap analyse`` writes it for every flume run with surface
gauges, ``riprap series`` for every step (displacements from the series' start)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riprap.analysis.per_wave_table import FlumeLayout, UnitTracks, per_wave_table
from riprap.io.body_forces import read_body_tracks
from riprap.io.gauge_files import read_gauges_csv
from riprap.waves.gauges import Gauge

__all__ = ["run_per_wave_table", "read_run_gauges", "EVENT_THRESHOLD"]

#: Overtopping events smaller than this (m^3 per m of crest) are not counted (traces of water
#: that the VOF field carries over the crest; EurOtop counts waves that overtop, not spray).
EVENT_THRESHOLD = 1.0e-6


def read_run_gauges(folder: Path, case) -> tuple[np.ndarray, dict] | None:
    """The flume run's ``gauges.csv`` in ``folder`` (run of ``case``; None where it wrote none),
    refused naming the file and the column where a column of the case's gauges is missing."""
    columns = [name for spec in case.gauges
               for name in Gauge(name=spec.name, kind=spec.type, position=()).columns]
    return read_gauges_csv(Path(folder) / "gauges.csv", required=columns)


def run_per_wave_table(folder: Path, case, *, units, nominal_diameter: float,
                       section_width: float, threshold_dn: float = 1.0,
                       reference_run: Path | None = None, periodic: bool = False) -> dict | None:
    """The per-wave table of the flume run in ``folder`` (run of ``case``; None where it has no
    gauges.csv or fewer than two surface gauges): waves counted at the toe (the run-up gauge's
    start, else the surface gauge nearest the structure), the units' (body indices ``units``)
    displacements counted from the first rows of ``body_forces.csv`` of ``reference_run`` (a test
    series' first step; default this run's own); ``periodic``: the section is a periodic strip
    ``section_width`` wide (the tracks are unwrapped across its side)."""
    gauges = read_run_gauges(folder, case)
    if gauges is None or case.waves is None or case.fluid is None:
        return None
    times, columns = gauges
    surface = sorted((g for g in case.gauges if g.type == "surface"),
                     key=lambda g: g.parameters["position"][0])
    if len(surface) < 2:
        return None
    run_up = next((g for g in case.gauges if g.type == "run_up"), None)
    over = next((g for g in case.gauges if g.type == "overtopping"), None)
    waves = case.waves
    depth = waves.still_water_level - case.fluid.lower[2]
    toe = run_up.parameters["position"][0] if run_up else surface[-1].parameters["position"][0]
    tracks = None
    rows = read_body_tracks(folder / "body_forces.csv", units) if len(units) else None
    first = Path(reference_run) if reference_run is not None else folder
    start = read_body_tracks(first / "body_forces.csv", units) if len(units) else None
    if rows is not None and start is not None and len(rows["body"]) and len(start["body"]):
        reference = np.full((int(np.max(units)) + 1, 3), np.nan)
        first_rows = start["time_s"] == start["time_s"].min()
        reference[start["body"][first_rows]] = start["position_m"][first_rows]
        tracks = UnitTracks(unit=rows["body"], time=rows["time_s"], position=rows["position_m"],
                            peak_force=rows["peak_fluid_force_N"],
                            nominal_diameter=nominal_diameter, section_width=section_width,
                            reference=reference, period_y=section_width if periodic else 0.0)
    armour_x = float(np.mean(tracks.position[:, 0])) if tracks is not None else None
    layout = FlumeLayout(
        gauge_positions=tuple(g.parameters["position"][0] for g in surface), toe_x=toe,
        depth=depth, peak_period=waves.parameters.get("peak_period") or waves.parameters["period"],
        run_up_x=toe if run_up else None,
        overtopping_x=over.parameters["position"][0] if over else None, armour_x=armour_x)
    return per_wave_table(
        times, [columns[f"{g.name}_eta_m"] for g in surface], layout,
        run_up=columns.get(f"{run_up.name}_level_m") if run_up else None,
        overtopping_volume=columns.get(f"{over.name}_volume_m3_m") if over else None,
        tracks=tracks, threshold_dn=threshold_dn, event_threshold=EVENT_THRESHOLD)
