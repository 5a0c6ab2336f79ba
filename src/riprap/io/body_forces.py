"""``body_forces.csv`` of a coupled run: at every frame, one row per body with its position,
velocity and the forces on it (N): the fluid's, split into pressure and viscous (with advection)
parts, and the contacts'. Appended frame by frame and flushed, so a killed run keeps every row
written; a restart appends."""
from __future__ import annotations

from pathlib import Path

from riprap.io.output_folder import naming_the_file

__all__ = ["BODY_FORCE_COLUMNS", "BodyForceTable"]

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
