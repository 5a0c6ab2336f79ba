"""The files that every process of a run over several processes writes itself: its piece of each
checkpoint and of each fluid frame (``riprap/models/slab_fluid.py``, ``slab_coupled.py``).

Why pieces: the grid's arrays are then written by the processes together, each its own planes,
without a gather of the whole grid to process 0 for a checkpoint; the checkpoint named
(``checkpoint.npz``, written by process 0 once every piece is on disk) lists its pieces, and
``riprap.io.checkpoint.load_checkpoint`` joins them, so that a restart on any number of processes
reads the whole grid's arrays as one process wrote them.
"""
from __future__ import annotations

from pathlib import Path

from riprap.io.checkpoint import save_checkpoint, save_checkpoint_piece

__all__ = ["save_checkpoint_in_pieces", "FramePiece"]


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
    ``whole`` the whole grid (for the frame's size and corner); ``comm`` the processes."""

    def __init__(self, block, whole_grid, comm):
        self.block = block
        self.whole_grid = whole_grid
        self.comm = comm
        self.planes = slice(block.low, block.low + block.owned)
        self.first = block.first
