"""Air and water over several processes (``riprap/fluid/slab_solver.py``), as a model of the run
loop: every process steps its block; the frames, the tables and the summary are those of one
process's run, written by process 0 from the whole grid gathered there when they are due; the
frames' fields and the checkpoints are written in pieces, each process its own planes
(``riprap/models/over_processes.py``).

Why gather for the tables and pictures: a run's files are then the same whichever number of
processes made them, and every reader of riprap's outputs (``riprap analyse``, the series, the
reports) reads them unchanged. The gather costs one message of the slab's planes per output
entry, not per step.
"""
from __future__ import annotations

from riprap.models.fluid import FluidModel
from riprap.models.over_processes import OverProcesses

__all__ = ["SlabFluidModel"]


class SlabFluidModel(OverProcesses, FluidModel):
    """``FluidModel`` of a block (``SlabFluidSolver``); ``whole`` the whole grid's FluidSolver
    that the writers read (refreshed by ``prepare_outputs``), whose arrays only process 0 keeps
    (``FluidSolver.drop_cell_arrays`` on the others)."""

    kind = "riprap fluid run"          # its checkpoints are one process's: any number restarts
    name = "fluid"

    def __init__(self, block, whole):
        super().__init__(block)
        self.whole = whole
        self.processes = block.comm
        if self.processes.rank != 0:
            # only process 0 writes from the whole grid; the others hold their block alone
            whole.drop_cell_arrays()

    @property
    def fluid(self):
        # the writers' and the reports' fluid: the whole grid (its clock is the block's)
        return self.whole

    @property
    def block(self):
        return self.solver

    def prepare_outputs(self) -> None:
        """The whole grid's state on process 0 from every process's slab (every process calls
        it)."""
        self._gather_onto(self.whole)

    def split_lines(self) -> list[str]:
        """The split of the run over the processes, a line per process (printed at the start)."""
        cells = self.whole.grid.cells
        return self.solver.cut.describe(cells[1] * cells[2])
