"""The interface between the run loop and a writer (one output family: a ParaView series, a
table, pictures), and the writer of a model of the older interface that wrote its own outputs.

A writer has a :attr:`Writer.schedule` (:class:`riprap.schedules.Every`, or None for the run's frame
schedule, ``[simulation] output_interval``). The loop calls :meth:`Writer.open` once (``append``
after a restart), :meth:`Writer.write` at every entry of its schedule (entry 0 at the start of a
run, not again after a restart), once more at the end when the run stopped between two entries,
and :meth:`Writer.close` at the end. A writer reads the model's data (its solver, or data methods
such as ``body_force_rows()``) and writes files through :mod:`riprap.io`.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["Writer", "ModelFrames"]


class Writer:
    """Base of every writer. ``name`` keys its schedule in checkpoints (so a restart goes on where
    the run stopped): give each writer of a run its own."""

    name = "writer"

    def __init__(self, schedule=None):
        #: When it writes (:class:`riprap.schedules.Every`); None: at the run's frames.
        self.schedule = schedule

    def open(self, model, directory: Path, *, append: bool) -> None:
        """Before the first entry; ``append``: a restart goes on with the files already there."""

    def write(self, model, entry: int) -> None:
        """Write entry number ``entry`` of the schedule, the model's state now."""
        raise NotImplementedError

    def close(self, model) -> dict:
        """After the last entry: final files; returns {name: path} for summary.json."""
        return {}


class ModelFrames(Writer):
    """The outputs of a model of the older interface, which writes them itself
    (``open_outputs``, ``write_frame``, ``close_outputs``); riprap's models give data to the
    writers of :mod:`riprap.outputs` instead."""

    name = "frames"

    def __init__(self, *, paraview: bool, picture: bool, schedule=None):
        super().__init__(schedule)
        self.paraview = paraview
        self.picture = picture

    def open(self, model, directory, *, append):
        model.open_outputs(directory, append=append, paraview=self.paraview, picture=self.picture)

    def write(self, model, entry):
        model.write_frame(entry)

    def close(self, model):
        return model.close_outputs()
