"""``body_forces.csv`` of a coupled run: at every frame, one row per body with its position,
velocity and the forces on it (N): the fluid's, split into pressure and viscous (with advection)
parts, and the contacts'. Appended frame by frame and flushed, so a killed run keeps every row
written; a restart appends."""
from __future__ import annotations

from pathlib import Path

from riprap.io.output_folder import naming_the_file

__all__ = ["BODY_FORCE_COLUMNS", "BodyForceTable", "read_body_forces"]

BODY_FORCE_COLUMNS = ("body", "time_s", "x_m", "y_m", "z_m", "vx_m_per_s", "vy_m_per_s",
                      "vz_m_per_s", "pressure_force_x_N", "pressure_force_y_N",
                      "pressure_force_z_N", "viscous_force_x_N", "viscous_force_y_N",
                      "viscous_force_z_N", "contact_force_x_N", "contact_force_y_N",
                      "contact_force_z_N")


class BodyForceTable:
    """Rows appended to ``path`` (written with its header unless ``append`` and it exists)."""

    def __init__(self, path, *, append: bool = False):
        self.path = Path(path)
        if not (append and self.path.is_file()):
            with naming_the_file(self.path):
                self.path.write_text(",".join(BODY_FORCE_COLUMNS) + "\n")

    def append(self, rows) -> None:
        with naming_the_file(self.path), open(self.path, "a") as stream:
            stream.write("".join(row + "\n" for row in rows))
            stream.flush()


def read_body_forces(path, n_bodies: int | None = None) -> dict:
    """``{column: values}`` of a run's ``body_forces.csv``, checked: its header, finite numbers,
    ``body`` a whole number from 0 (below ``n_bodies`` when given), ``time_s`` >= 0. Rows may
    repeat a time (a restart appends from its checkpoint). Errors name the file, line, column."""
    import math

    import numpy as np

    from riprap.errors import CaseFileError
    from riprap.io.csv_tables import read_number_table

    path = Path(path)
    advice = "run the case again, or restart it from a checkpoint"
    _, table, lines = read_number_table(path, "body force table", columns=BODY_FORCE_COLUMNS,
                                 advice=advice)
    data = {name: table[:, k] for k, name in enumerate(BODY_FORCE_COLUMNS)}
    body, time = data["body"], data["time_s"]
    limit = math.inf if n_bodies is None else n_bodies
    bad = np.flatnonzero((body != np.round(body)) | (body < 0) | (body >= limit) | (time < 0))
    if bad.size:
        row = int(bad[0])
        what = (f"time_s = {time[row]:g}: expected a time >= 0 s" if time[row] < 0 else
                f"body = {body[row]:g}: expected a whole body number from 0"
                + (f" to {n_bodies - 1} (the run has {n_bodies} bodies)" if n_bodies is not None
                   else ""))
        raise CaseFileError(f"{path}:{lines[row]}: {what}; {advice}")
    data["body"] = body.astype(np.int64)
    return data
