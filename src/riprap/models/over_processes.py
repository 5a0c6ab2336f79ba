"""What every model of a run over several processes adds to its one-process model
(``riprap/models/slab_fluid.py``, ``slab_coupled.py``): process 0 writes the tables, pictures and
summary; every process writes its own piece of each checkpoint and of each fluid frame; the
summary names the split.

Why pieces: the grid's arrays are then written by the processes together, each its own planes,
without a gather of the whole grid to process 0; the checkpoint named (``checkpoint.npz``,
written by process 0 once every piece is on disk) lists its pieces, and
``riprap.io.checkpoint.load_checkpoint`` joins them, so that a restart on any number of processes
reads the whole grid's arrays as one process wrote them.
"""
from __future__ import annotations

from pathlib import Path

from riprap.fluid.slab_solver import PLANE_ARRAYS
from riprap.io.checkpoint import save_checkpoint, save_checkpoint_piece

__all__ = ["OverProcesses", "FramePiece", "save_checkpoint_in_pieces"]


class OverProcesses:
    """Mixed in before a one-process model. The model's ``fluid`` is the whole grid's (which the
    writers read), ``block`` this process's (a ``SlabFluidSolver``), ``processes`` the
    communicator, and its solver has ``state_piece(state)``: this process's arrays of a
    checkpoint."""

    processes = None

    @property
    def block(self):
        raise NotImplementedError

    @property
    def writes_files(self) -> bool:
        return self.processes.rank == 0

    def _after_step(self, dt: float, report) -> None:
        block, whole = self.block, self.fluid
        whole.last_report = block.last_report
        whole.last_air_limit = block.last_air_limit
        super()._after_step(dt, report)

    def _gather_onto(self, whole_fluid, *, on_first: bool = True) -> None:
        """``whole_fluid`` (the whole grid's FluidSolver the writers read) refreshed from every
        process's slab: on process 0 alone with ``on_first``, elsewhere only its clock (every
        process calls it)."""
        block = self.block
        state = block.gather_whole(block.state_arrays(), on_first=on_first)
        if state is not None:
            whole_fluid.load_state_arrays(state, copy=False)
        else:
            whole_fluid.time, whole_fluid.step_count = block.time, block.step_count

    def checkpoint_reading(self) -> dict:
        """How this process reads a checkpoint to restart: the grid's arrays from the pieces
        that hold its block's planes only (``riprap.io.checkpoint.load_checkpoint``)."""
        return {"planes": self.block.checkpoint_planes(), "plane_arrays": PLANE_ARRAYS}

    def frame_piece(self) -> FramePiece:
        """This process's part of a fluid frame (``riprap/outputs/fluid.py`` writes it)."""
        return FramePiece(self.block, self.fluid.grid, self.processes)

    def save_checkpoint_in_pieces(self, path, arrays: dict, metadata: dict) -> Path:
        """Every process its piece of the checkpoint (its own planes of the grid, and of a
        coupled run its own faces of the carrying field), process 0 the rest: it restarts on any
        number of processes."""
        return save_checkpoint_in_pieces(path, arrays, metadata, self.solver.state_piece(arrays),
                                         self.processes)

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = super().summary_fields(wall_time, steps)
        block = self.block
        fields["processes"] = {"count": block.comm.size, "slabs": list(block.cut.starts),
                               "pressure_slabs": list(block.pressure_cut.starts),
                               "halo_planes": block.halo}
        return fields


def save_checkpoint_in_pieces(path: Path, arrays: dict, metadata: dict, piece: dict,
                              comm) -> Path:
    """Every process calls it: its ``piece`` (the arrays of its own planes, by name) into the
    checkpoint's folder of pieces, then process 0 the checkpoint ``path`` of the other
    ``arrays`` and ``metadata``, naming the pieces in process order."""
    shared = {name: value for name, value in arrays.items() if name not in piece}
    step = int(arrays["clock"][1])
    name = save_checkpoint_piece(path, step=step, process=comm.rank, arrays=piece)
    names = comm.all_values(name)       # every piece is on disk before the checkpoint names it
    if comm.rank == 0:
        save_checkpoint(path, arrays=shared, metadata=metadata, pieces=names)
    return path


class FramePiece:
    """This process's part of a fluid frame: ``block`` its fluid (a ``SlabFluidSolver``), whose
    own planes ``planes`` (a slice of the block's) are the whole grid's x-cells from ``first``;
    ``whole_grid`` the whole grid (the frame's size and corner); ``comm`` the processes."""

    def __init__(self, block, whole_grid, comm):
        self.block = block
        self.whole_grid = whole_grid
        self.comm = comm
        self.planes = slice(block.low, block.low + block.owned)
        self.first = block.first
