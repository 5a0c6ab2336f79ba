"""Gauge records and the wave analysis on disk: ``gauges.csv`` (time and one column per gauge
reading), ``gauges.png`` (the surface gauges' records stacked), ``waves_report.json``."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

__all__ = ["write_gauges_csv", "read_gauges_csv", "gauges_png", "write_waves_report"]


def write_gauges_csv(path, gauges) -> Path:
    """Every record of ``gauges`` (a GaugeSet), rewritten whole (a restart's records replace those
    written after its checkpoint)."""
    path = Path(path)
    table = np.column_stack([gauges.times, gauges.values]) if gauges.count else np.zeros((0, 1 + len(gauges.columns)))
    np.savetxt(path, table, delimiter=",", header=",".join(["time_s"] + gauges.columns),
               comments="", fmt="%.9g")
    return path


def read_gauges_csv(path):
    """(times (s), ``{column: values}``) of a ``gauges.csv``, or None when there is no such file.
    A file that is not one names the file and the line (CaseFileError)."""
    from riprap.errors import CaseFileError
    from riprap.io.case_text import read_text_file

    path = Path(path)
    if not path.is_file():
        return None
    lines = read_text_file(path, what="gauge records table", extension=".csv").splitlines()
    header = lines[0].strip().split(",") if lines else []
    if not header or header[0] != "time_s" or len(set(header)) != len(header):
        raise CaseFileError(f"{path}: line 1 is not the header of a riprap gauges.csv ('time_s' "
                            "and one column per gauge reading); move the file away to analyse "
                            "without the gauge records")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        try:
            row = [float(value) for value in line.split(",")]
        except ValueError:
            row = []
        if len(row) != len(header) or not np.isfinite(row[0]):
            raise CaseFileError(f"{path}, line {number}: expected {len(header)} numbers "
                                f"({', '.join(header[:3])}...), got '{line[:60]}'; the file is "
                                "corrupt")
        rows.append(row)
    table = np.array(rows, dtype=float).reshape(-1, len(header))
    if np.any(np.diff(table[:, 0]) <= 0.0):
        number = int(np.flatnonzero(np.diff(table[:, 0]) <= 0.0)[0]) + 3
        raise CaseFileError(f"{path}, line {number}: the time does not increase; the file is "
                            "corrupt")
    return table[:, 0], {name: table[:, k] for k, name in enumerate(header) if k}


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
        if "analysed_from_s" in entry and times.size:
            axis.axvspan(entry["analysed_from_s"], times[-1], color="0.92", zorder=0)
        label = f"{gauge.name}  x = {gauge.position[0]:g} m"
        if "Hm0_m" in entry:
            label += f"   Hm0 {1e3 * entry['Hm0_m']:.1f} mm  H1/3 {1e3 * entry['H1/3_m']:.1f} mm"
        axis.set_title(label, fontsize=8, loc="left")
        axis.set_ylabel("eta (mm)", fontsize=8)
        axis.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("time (s)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def write_waves_report(path, report: dict) -> Path:
    path = Path(path)
    path.write_text(json.dumps(report, indent=2, default=float) + "\n")
    return path
