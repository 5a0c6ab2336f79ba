"""``solver_log.csv``: per frame interval, what the fluid's and the bodies' solvers did
(:mod:`riprap.io.solver_log` says what the columns are); the same rows go into ``summary.json``
(``solver_log``). Why: a projection that silently stops at its iteration cap, or a run whose
cost per step grows under the waves, shows there frame by frame, not only in the run's means."""
from __future__ import annotations

from riprap.io.solver_log import SolverLogTable
from riprap.outputs.base import Writer

__all__ = ["SolverLogWriter"]


class SolverLogWriter(Writer):
    """Rows from ``model.take_solver_log_row()`` (None: no step since the last row)."""

    name = "solver_log"

    def __init__(self, schedule=None):
        super().__init__(schedule)
        self._table = None

    def open(self, model, directory, *, append):
        self._table = SolverLogTable(directory / "solver_log.csv", append=append)

    def write(self, model, entry):
        row = model.take_solver_log_row()
        if row is not None:
            self._table.append_row(row)

    def close(self, model):
        return {"solver_log": str(self._table.path)}
