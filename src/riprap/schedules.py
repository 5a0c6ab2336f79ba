"""When a writer writes: every so many seconds of simulated time, or every so many steps.

A schedule counts its entries: entry ``i`` of ``Every(seconds=s)`` is due at ``i * s`` (so times land
exactly where the run's frames always landed: on multiples of the interval, not on sums of it), and
entry ``i`` of ``Every(steps=n)`` at step ``i * n``. Entry 0 is the start of the run. The run loop
(:meth:`riprap.simulation.Simulation.run`) asks each schedule for the next time it must land on
(:meth:`Every.next_time`), whether an entry is due (:meth:`Every.due`), and tells it when one was
written (:meth:`Every.written`); a restart gives the count back (:attr:`Every.index`).
"""
from __future__ import annotations

import math

from riprap.errors import CaseFileError, RiprapError

__all__ = ["Every"]


class Every:
    """Every ``seconds`` of simulated time (s), or every ``steps`` time steps; exactly one of the two."""

    def __init__(self, *, seconds: float | None = None, steps: int | None = None):
        if (seconds is None) == (steps is None):
            raise CaseFileError("Every: give seconds or steps (one of them)")
        if seconds is not None and not (isinstance(seconds, (int, float)) and math.isfinite(seconds)
                                        and seconds > 0):
            raise CaseFileError(f"Every(seconds={seconds!r}): expected a number > 0 s")
        if steps is not None and not (isinstance(steps, int) and not isinstance(steps, bool)
                                      and steps > 0):
            raise CaseFileError(f"Every(steps={steps!r}): expected a whole number > 0")
        self.seconds = None if seconds is None else float(seconds)
        self.steps = steps
        #: The entry due next (entries written so far, counting the skipped ones).
        self.index = 0

    def __repr__(self) -> str:
        return f"Every(seconds={self.seconds:g})" if self.seconds else f"Every(steps={self.steps})"

    def entry_time(self, index: int) -> float:
        return index * self.seconds

    def next_time(self, model) -> float:
        """The simulated time the model must land on for the next entry: a step schedule's, at
        the model's last time step (exact for the fixed steps of rigid and deformable runs)."""
        if self.seconds is not None:
            return self.entry_time(self.index)
        remaining = self.index * self.steps - model.step_count
        return model.time + max(remaining, 0) * model.last_time_step()

    def due(self, model) -> bool:
        if self.seconds is not None:
            return model.reached(self.entry_time(self.index))
        return model.step_count >= self.index * self.steps

    def written(self, model, most: int, name: str) -> None:
        """An entry was written now: the next is the first not yet reached (a chunk of work
        longer than the interval writes no entry twice). More than ``most`` entries skipped at
        once means a clock that left its schedule: an error, not a loop without end."""
        self.index += 1
        for _ in range(most + 2):
            if not self.due(model):
                return
            self.index += 1
        raise RiprapError(f"the schedule of {name} = {self} ran past {most} entries at "
                          f"t = {model.time:.6g} s; the run's clock has left its schedule, "
                          "report it")

    def entries_until(self, end_time: float) -> int:
        """How many entries a run to ``end_time`` from 0 writes (for the limits on outputs);
        unknown (0) for a step schedule."""
        if self.seconds is None:
            return 0
        return int(end_time / self.seconds + 1e-9) + 1
