"""``solver_log.csv`` of a fluid or coupled run: one row per frame interval with what the solvers
did in it (fluid steps, their lengths, pressure iterations, solves stopped at their iteration cap,
the largest volume change a solve left, the water volume error, contact sub-steps per fluid step
and the largest measured stability ratio of the contacts). Appended and flushed row by row, so a
killed run keeps what it wrote; a restart appends."""
from __future__ import annotations

from riprap.io.appended_table import AppendedTable

__all__ = ["SOLVER_LOG_COLUMNS", "SolverLogTable"]

SOLVER_LOG_COLUMNS = ("time_s", "fluid_steps", "time_step_mean_s", "time_step_min_s",
                      "pressure_iterations_mean", "pressure_iterations_max",
                      "pressure_capped_solves", "pressure_volume_change_max",
                      "water_volume_error", "contact_substeps_per_step",
                      "contact_stability_ratio_max")


class SolverLogTable(AppendedTable):
    """Rows (dicts keyed by ``SOLVER_LOG_COLUMNS``; None an empty field) appended to ``path``."""

    def __init__(self, path, *, append: bool = False):
        super().__init__(path, SOLVER_LOG_COLUMNS, append=append)

    def append_row(self, row: dict) -> None:
        self.append([",".join("" if row.get(name) is None else repr(row[name])
                              for name in SOLVER_LOG_COLUMNS)])
