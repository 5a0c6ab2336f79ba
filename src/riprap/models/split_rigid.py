"""Rigid bodies without a fluid over several processes: every process steps every body, each
evaluates the contact pairs it owns and all join their rows after every force evaluation
(``SolidSolver.split_contacts_over``), so every process holds the one process's bodies, bit for
bit; process 0 writes the files.

Why the bodies are not cut by space: the contacts are the work (a Core-Loc pair's narrow phase
costs thousands of times a body's integration), and sharing them out by pair needs no migration
of bodies or springs when units move, keeps the cut balanced as a pack settles, and keeps the
results those of one process; every process integrating every body costs microseconds a step
for thousands of bodies.
"""
from __future__ import annotations

from riprap.models.rigid import RigidModel

__all__ = ["SplitRigidModel"]


class SplitRigidModel(RigidModel):
    """``RigidModel`` whose contact pairs are shared among ``processes``."""

    def __init__(self, solver, *, processes, **options):
        super().__init__(solver, **options)
        self.processes = processes
        solver.split_contacts_over(processes)

    @property
    def writes_files(self) -> bool:
        return self.processes.rank == 0

    def advance(self, until: float) -> None:
        super().advance(until)
        # the next chunk's length follows the wall time, which differs between processes: all
        # take process 0's, so that every process steps the same steps together
        self._chunk = self.processes.broadcast(self._chunk)

    def split_lines(self) -> list[str]:
        return [f"process {rank}: every body, the contact pairs whose key falls to it"
                for rank in range(self.processes.size)]

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = super().summary_fields(wall_time, steps)
        fields["processes"] = {"count": self.processes.size, "split": "contact pairs"}
        return fields
