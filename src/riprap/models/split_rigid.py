"""Rigid bodies without a fluid over several processes: each process owns the bodies whose
centre lies in its slab of x, finds and evaluates their contact pairs and adds up their forces;
all join the forces and every process integrates every body (``SolidSolver.
split_bodies_over``, ``riprap/solid/bodies_over_processes.py``), so every process holds the
one process's bodies, bit for bit; process 0 writes the files.
"""
from __future__ import annotations

from riprap.models.rigid import RigidModel

__all__ = ["SplitRigidModel"]


class SplitRigidModel(RigidModel):
    """``RigidModel`` whose contact pairs are shared among ``processes``."""

    def __init__(self, solver, *, processes, **options):
        super().__init__(solver, **options)
        self.processes = processes
        solver.split_bodies_over(processes)

    @property
    def writes_files(self) -> bool:
        return self.processes.rank == 0

    def advance(self, until: float) -> None:
        super().advance(until)
        # the next chunk's length follows the wall time, which differs between processes: all
        # take process 0's, so that every process steps the same steps together
        self._chunk = self.processes.broadcast(self._chunk)

    def split_lines(self) -> list[str]:
        return self.solver.bodies_split_lines()

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = super().summary_fields(wall_time, steps)
        fields["processes"] = {"count": self.processes.size, "split": "bodies by the x of their centre"}
        return fields
