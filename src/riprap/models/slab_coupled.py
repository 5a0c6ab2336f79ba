"""Bodies in a flow over several processes (``riprap/coupling/slab_coupled.py``), as models of
the run loop: every process steps its block of the fluid and every body; the frames, the tables
and the summary are those of one process's run, written by process 0 from the whole grid
gathered there when they are due (as ``riprap/models/slab_fluid.py`` does for the fluid alone);
the frames' fields and the checkpoints in pieces, each process its own planes.
"""
from __future__ import annotations

import numpy as np

from riprap.models.deformable_coupled import DeformableCoupledModel
from riprap.models.fluid import CoupledModel
from riprap.models.over_processes import OverProcesses

__all__ = ["SlabCoupledModel", "SlabDeformableCoupledModel"]


class _CoupledOverProcesses(OverProcesses):
    """What a coupled model over a block adds to its one-process model: the whole grid for the
    writers, the gathers when outputs are due (``OverProcesses`` the rest). ``whole`` is the
    whole grid's coupling, whose fluid the writers read (refreshed by ``prepare_outputs``) and
    whose bodies are the block's."""

    whole = None

    @property
    def fluid(self):
        # the writers' and the reports' fluid: the whole grid (its clock is the block's)
        return self.whole.fluid

    @property
    def block(self):
        return self.solver.fluid

    @property
    def step_count(self) -> int:
        return self.solver.fluid.step_count

    #: Whether the processes other than 0 hold the whole grid's fluid arrays (the deformable
    #: bodies' surfaces read the whole grid's solid cells on every process).
    whole_fluid_everywhere = False

    def prepare_outputs(self) -> None:
        """The whole grid's state on process 0 (on every process with
        ``whole_fluid_everywhere``) from every process's slab, and the loads that only the
        outputs read, summed over the processes (every process calls it)."""
        self._gather_onto(self.whole.fluid, on_first=not self.whole_fluid_everywhere)
        self.solver.fixed_body_loads   # noqa: B018 - summed now, on every process together

    def _hold_the_whole_on_first_only(self) -> None:
        """On the processes other than 0, let go of the whole grid's arrays: they step their
        block and write none of the whole grid's files."""
        if self.processes.rank != 0 and not self.whole_fluid_everywhere:
            self.whole.fluid.drop_cell_arrays()
            self.whole.drop_grid_arrays()

    def split_lines(self) -> list[str]:
        """The split of the run over the processes, a line per process (printed at the start)."""
        block = self.solver.fluid
        grid = self.whole.fluid.grid
        centres = self.solver.solids.positions
        planes = np.floor((centres[:, 0] - grid.lower[0]) / grid.cell_size)
        lines = block.cut.describe(grid.cells[1] * grid.cells[2], planes.astype(int))
        if hasattr(self.solver.solids, "bodies_split_lines"):
            # the contacts' own slabs (``riprap/solid/bodies_over_processes.py``)
            lines += [line.replace("process", "  contacts of process", 1)
                      for line in self.solver.solids.bodies_split_lines()]
        return lines

    def body_fraction(self):
        return self.whole.body_fraction()


class SlabCoupledModel(_CoupledOverProcesses, CoupledModel):
    """``CoupledModel`` of a block (``SlabCoupledSolver``)."""

    kind = "riprap coupled run"     # its checkpoints are one process's: any number restarts
    name = "coupled"

    def __init__(self, coupled, whole):
        super().__init__(coupled)
        self.whole = whole
        self.processes = coupled.comm
        self._hold_the_whole_on_first_only()


class SlabDeformableCoupledModel(_CoupledOverProcesses, DeformableCoupledModel):
    """``DeformableCoupledModel`` of a block (``SlabDeformableCoupledSolver``); ``stresses``
    keeps the stress records on every process alike (every process steps every body)."""

    kind = "riprap deformable coupled run"
    name = "deformable_coupled"
    whole_fluid_everywhere = True

    def __init__(self, coupled, stresses, whole):
        super().__init__(coupled, stresses)
        self.whole = whole
        self.processes = coupled.comm
