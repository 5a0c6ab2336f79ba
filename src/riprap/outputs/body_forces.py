"""``body_forces.csv`` of a run with bodies in a flow: one row per body at every entry of its
schedule (:mod:`riprap.io.body_forces` says what the columns are). The largest fluid force of each
row is the largest since the previous row, so a finer schedule than the frames' (``[output]
body_forces_interval``) samples the impacts more often without changing the peaks."""
from __future__ import annotations

from riprap.io.body_forces import BodyForceTable
from riprap.outputs.base import Writer

__all__ = ["BodyForcesWriter"]


class BodyForcesWriter(Writer):
    """Rows from ``model.body_force_rows()`` (CSV lines, one per body, at the model's time)."""

    name = "body_forces"

    def __init__(self, schedule=None):
        super().__init__(schedule)
        self._table = None

    def open(self, model, directory, *, append):
        self._table = BodyForceTable(directory / "body_forces.csv", append=append)

    def write(self, model, entry):
        self._table.append(model.body_force_rows())

    def close(self, model):
        return {"body_forces": str(self._table.path)}
