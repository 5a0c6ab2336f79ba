"""``body_forces.csv`` of a coupled run: at every frame, one row per body with its position,
velocity and the forces on it (N): the fluid's, split into pressure and viscous (with advection)
parts, and the contacts'; and the largest fluid force on the body over the fluid steps since its
previous row, with its time (``peak_fluid_force_N``, ``peak_fluid_force_time_s``: an impact lasts
a few fluid steps, far less than the frames' interval). Appended frame by frame and flushed, so a
killed run keeps every row written; a restart appends. :func:`read_peak_fluid_forces` reads back
each body's largest fluid force for ``riprap analyse``."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file
from riprap.io.appended_table import AppendedTable

__all__ = ["BODY_FORCE_COLUMNS", "BodyForceTable", "read_peak_fluid_forces", "read_body_tracks"]

BODY_FORCE_COLUMNS = ("body", "time_s", "x_m", "y_m", "z_m", "vx_m_per_s", "vy_m_per_s",
                      "vz_m_per_s", "pressure_force_x_N", "pressure_force_y_N",
                      "pressure_force_z_N", "viscous_force_x_N", "viscous_force_y_N",
                      "viscous_force_z_N", "contact_force_x_N", "contact_force_y_N",
                      "contact_force_z_N", "peak_fluid_force_N", "peak_fluid_force_time_s")
#: The columns of the files riprap wrote before the peak force was recorded (still read).
_OLDER_COLUMNS = BODY_FORCE_COLUMNS[:-2]


class BodyForceTable(AppendedTable):
    """Rows appended to ``path`` (written with its header unless ``append`` and it exists)."""

    def __init__(self, path, *, append: bool = False):
        super().__init__(path, BODY_FORCE_COLUMNS, append=append)


def read_peak_fluid_forces(path, n_bodies: int, until: float = math.inf) -> dict | None:
    """Each body's largest fluid force over the run up to time ``until`` (N) and its time (s),
    from ``path`` (a ``body_forces.csv``): ``{"force_N": (n_bodies,), "time_s": (n_bodies,)}``,
    NaN for a body without a row; None when there is no such file. A file of an older riprap (no peak columns)
    gives the largest force at its rows' times. A row that cannot be read is a CaseFileError
    naming the file and the line."""
    path = Path(path)
    if not path.is_file():
        return None
    lines = read_text_file(path, what="body forces table", extension=".csv").splitlines()
    header = tuple(lines[0].strip().split(",")) if lines else ()
    if header not in (BODY_FORCE_COLUMNS, _OLDER_COLUMNS):
        raise CaseFileError(f"{path}: line 1 is not the header of a riprap body_forces.csv "
                            f"(expected '{','.join(BODY_FORCE_COLUMNS[:3])},...'); move the file "
                            "away to analyse without the fluid forces")
    force = np.full(n_bodies, np.nan)
    when = np.full(n_bodies, np.nan)
    has_peak = header == BODY_FORCE_COLUMNS
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != len(header):
            if number == len(lines):
                break           # the last row of a killed run, cut while it was written
            raise CaseFileError(f"{path}, line {number}: {len(fields)} values, the header has "
                                f"{len(header)}; the file is corrupt")
        try:
            body = int(fields[0])
            values = [float(v) for v in fields[1:]]
        except ValueError:
            raise CaseFileError(f"{path}, line {number}: '{line[:60]}' is not a row of numbers; "
                                "the file is corrupt") from None
        if not 0 <= body < n_bodies:
            raise CaseFileError(f"{path}, line {number}: body {body}, but the run has {n_bodies} "
                                "bodies (0.." f"{n_bodies - 1}); the file is not this run's")
        row = dict(zip(header[1:], values))
        if row["time_s"] > until:
            continue
        now = math.hypot(*(row[f"pressure_force_{a}_N"] + row[f"viscous_force_{a}_N"]
                           for a in "xyz"))
        peak, peak_time = ((row["peak_fluid_force_N"], row["peak_fluid_force_time_s"])
                           if has_peak else (now, row["time_s"]))
        if not (math.isfinite(peak) and peak >= 0.0):
            raise CaseFileError(f"{path}, line {number}: fluid force {peak!r} N on body {body} "
                                "is not a finite number >= 0; the run blew up or the file is "
                                "corrupt")
        if not force[body] >= peak:
            force[body], when[body] = peak, peak_time
    return {"force_N": force, "time_s": when}


def read_body_tracks(path, bodies) -> dict | None:
    """The rows of ``bodies`` (indices) in ``path`` (a ``body_forces.csv`` with the peak columns)
    as arrays: ``body``, ``time_s``, ``position_m`` (n, 3), ``peak_fluid_force_N``; None when there
    is no such file. Rows of other bodies are skipped; a row that cannot be read is a
    CaseFileError naming the file and the line (a last row cut by a killed run is left out)."""
    path = Path(path)
    if not path.is_file():
        return None
    lines = read_text_file(path, what="body forces table", extension=".csv").splitlines()
    header = tuple(lines[0].strip().split(",")) if lines else ()
    if header != BODY_FORCE_COLUMNS:
        raise CaseFileError(f"{path}: line 1 is not the header of a riprap body_forces.csv with "
                            f"the peak fluid force (expected '{','.join(BODY_FORCE_COLUMNS[:3])}"
                            f",...,{BODY_FORCE_COLUMNS[-1]}')")
    wanted = {int(b) for b in bodies}
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if not line.strip():
            continue
        if len(fields) != len(header):
            if number == len(lines):
                break
            raise CaseFileError(f"{path}, line {number}: {len(fields)} values, the header has "
                                f"{len(header)}; the file is corrupt")
        try:
            body = int(fields[0])
            if body not in wanted:
                continue
            values = [float(fields[k]) for k in (1, 2, 3, 4, 17)]
        except ValueError:
            raise CaseFileError(f"{path}, line {number}: '{line[:60]}' is not a row of numbers; "
                                "the file is corrupt") from None
        if not all(math.isfinite(v) for v in values):
            raise CaseFileError(f"{path}, line {number}: body {body} has a value that is not a "
                                "finite number; the run blew up or the file is corrupt")
        rows.append([body, *values])
    table = np.array(rows, dtype=float).reshape(-1, 6)
    return {"body": table[:, 0].astype(np.int64), "time_s": table[:, 1],
            "position_m": table[:, 2:5], "peak_fluid_force_N": table[:, 5]}
