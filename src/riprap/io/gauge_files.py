"""Gauge records and the wave analysis on disk: ``gauges.csv`` (time and one column per gauge
reading), ``gauges.png`` (the surface gauges' records stacked), ``waves_report.json``."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.csv_tables import read_number_table
from riprap.io.json_files import write_json

__all__ = ["write_gauges_csv", "read_gauges_csv", "gauges_png", "write_waves_report"]


def write_gauges_csv(path, gauges) -> Path:
    """Every record of ``gauges`` (a GaugeSet), rewritten whole (a restart's records replace those
    written after its checkpoint)."""
    path = Path(path)
    table = np.column_stack([gauges.times, gauges.values]) if gauges.count else np.zeros((0, 1 + len(gauges.columns)))
    np.savetxt(path, table, delimiter=",", header=",".join(["time_s"] + gauges.columns),
               comments="", fmt="%.9g")
    return path


def read_gauges_csv(path, required=()) -> tuple[np.ndarray, dict] | None:
    """``(times (s), {column: values})`` of a run's ``gauges.csv`` (None where the run wrote none),
    checked: the header starts with ``time_s`` and holds every column of ``required`` (those of
    the case's gauges), every field is a finite number, the times increase (the file is
    rewritten whole at every frame). Errors name the file, the line and the column."""
    path = Path(path)
    if not path.is_file():
        return None
    advice = "run the case again (gauges.csv is rewritten whole at every frame)"
    header, table, lines = read_number_table(path, "gauge table", advice=advice)
    if header[0] != "time_s":
        raise CaseFileError(f"{path}:1: the first column is {header[0]!r}; gauges.csv starts with "
                            f"time_s; {advice}")
    missing = [name for name in required if name not in header]
    if missing:
        raise CaseFileError(f"{path}:1: no column {', '.join(repr(n) for n in missing)} (the "
                            f"case's gauges write {len(required)} columns; the file has "
                            f"{', '.join(header[1:]) or 'none'}); {advice}")
    times = table[:, 0]
    back = np.flatnonzero(np.diff(times) <= 0.0)
    if back.size:
        row = int(back[0]) + 1
        raise CaseFileError(f"{path}:{lines[row]}: time_s = {times[row]:g} s does not increase (the "
                            f"row before has {times[row - 1]:g} s); {advice}")
    return times, {name: table[:, k] for k, name in enumerate(header) if k > 0}


def gauges_png(path, gauges, report=None) -> Path:
    """The surface gauges' elevation records, one panel each, with the analysis window shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    surface = [g for g in gauges.gauges if g.kind == "surface"]
    path = Path(path)
    count = max(len(surface), 1)
    figure, axes = plt.subplots(count, 1, figsize=(9, 1.6 * count + 0.8), sharex=True, squeeze=False)
    for axis, gauge in zip(axes[:, 0], surface):
        times, eta = gauges.series(gauge.columns[0])
        axis.plot(times, 1e3 * eta, lw=0.8, color="tab:blue")
        entry = (report or {}).get("gauges", {}).get(gauge.name, {})
        label = f"{gauge.name}  x = {gauge.position[0]:g} m"
        opens = entry.get("analysed_from_s")
        if opens is not None and times.size and opens < times[-1]:
            axis.axvspan(opens, times[-1], color="0.92", zorder=0)
        elif opens is not None:
            # The record ends before the analysis window opens: nothing to shade, and say so.
            end = f"{times[-1]:.3g}" if times.size else "0"
            label += (f"   not analysed: the record ends at {end} s, the window opens at "
                      f"{opens:.3g} s")
        if "Hm0_m" in entry:
            label += f"   Hm0 {1e3 * entry['Hm0_m']:.1f} mm  H1/3 {1e3 * entry['H1/3_m']:.1f} mm"
            if "caution" in entry:
                label += f"   (from {entry['waves']} wave(s) only)"
        axis.set_title(label, fontsize=8, loc="left")
        axis.set_ylabel("eta (mm)", fontsize=8)
        axis.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("time (s)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def write_waves_report(path, report: dict) -> Path:
    """``waves_report.json``: standard JSON, a number that could not be computed as ``null``."""
    return write_json(path, report)
