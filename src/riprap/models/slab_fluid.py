"""Air and water over several processes (``riprap/fluid/slab_solver.py``), as a model of the run
loop: every process steps its block; the frames, the tables and the summary are those of one
process's run, written by process 0 from the whole grid gathered there when they are due; the
frames' fields and the checkpoints are written in pieces, each process its own planes
(``riprap/models/split_files.py``).

Why gather for the tables and pictures: a run's files are then the same whichever number of
processes made them, and every reader of riprap's outputs (``riprap analyse``, the series, the
reports) reads them unchanged. The gather costs one message of the slab's planes per output
entry, not per step.
"""
from __future__ import annotations

from riprap.models.fluid import FluidModel
from riprap.models.split_files import FramePiece, save_checkpoint_in_pieces

__all__ = ["SlabFluidModel"]


class SlabFluidModel(FluidModel):
    """``FluidModel`` of a block (``SlabFluidSolver``); ``whole`` the whole grid's FluidSolver
    that the writers read (refreshed by ``prepare_outputs``)."""

    kind = "riprap fluid run"          # its checkpoints are one process's: any number restarts
    name = "fluid"

    def __init__(self, block, whole):
        super().__init__(block)
        self.whole = whole
        self.processes = block.comm

    @property
    def fluid(self):
        # the writers' and the reports' fluid: the whole grid (its clock is the block's)
        return self.whole

    @property
    def writes_files(self) -> bool:
        return self.processes.rank == 0

    def _after_step(self, dt: float, report) -> None:
        self.whole.last_report = self.solver.last_report
        self.whole.last_air_limit = self.solver.last_air_limit
        super()._after_step(dt, report)

    def prepare_outputs(self) -> None:
        """The whole grid's state from every process's slab (every process calls it)."""
        block = self.solver
        whole_state = block.gather_whole(block.state_arrays())
        self.whole.load_state_arrays(whole_state)

    def split_lines(self) -> list[str]:
        """The split of the run over the processes, a line per process (printed at the start)."""
        cells = self.whole.grid.cells
        return self.solver.cut.describe(cells[1] * cells[2])

    def frame_piece(self) -> FramePiece:
        """This process's part of a fluid frame (``riprap/outputs/fluid.py`` writes it)."""
        return FramePiece(self.solver, self.whole.grid, self.processes)

    def save_checkpoint_in_pieces(self, path, arrays: dict, metadata: dict):
        """Every process its piece of the checkpoint (its own planes), process 0 the rest: it
        restarts on any number of processes."""
        return save_checkpoint_in_pieces(path, arrays, metadata,
                                         self.solver.state_piece(arrays), self.processes)

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = super().summary_fields(wall_time, steps)
        block = self.solver
        fields["processes"] = {"count": block.comm.size, "slabs": list(block.cut.starts),
                               "halo_planes": block.halo}
        return fields
