"""The cut of a grid into slabs along x, one per process.

Why slabs first: a flume is long and narrow, so cutting along its length gives each process a
run of whole x-planes with two neighbours and the smallest number of messages; the fluid's
reductions are already formed per x-plane, so a sum over slabs adds exactly what one process adds
(``riprap/parallel/communicator.py``). Boxes would cut a wide basin's faces smaller; they are not
needed below a few tens of processes for the flumes riprap runs (``docs/parallel.md``).

Balance: each x-plane has a cost (its cells, plus its bodies' work: ``plane_costs``), and the cut
gives each process as nearly as it can an equal share, in steps of ``alignment`` planes (the
pressure solve's distributed multigrid levels need slabs that halve evenly).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError

__all__ = ["SlabCut", "cut_slabs"]


@dataclass(frozen=True)
class SlabCut:
    """Slab r holds the x-planes starts[r] .. starts[r + 1] - 1 of a grid of ``cells`` planes."""

    cells: int
    starts: tuple
    alignment: int

    @property
    def processes(self) -> int:
        return len(self.starts) - 1

    def first(self, rank: int) -> int:
        return self.starts[rank]

    def stop(self, rank: int) -> int:
        return self.starts[rank + 1]

    def counts(self, level: int = 0) -> list[int]:
        """Planes of each slab on multigrid ``level`` (every level halves x; the last slab takes
        the odd plane)."""
        scale = 2 ** level
        edges = [-(-start // scale) for start in self.starts]
        return [edges[r + 1] - edges[r] for r in range(self.processes)]

    def describe(self, plane_cells: int, body_planes=None) -> list[str]:
        """One line per slab: its x-planes and cells (``plane_cells`` per plane) and, given the
        x-plane of each body's centre, the bodies whose centre it holds."""
        owners = (None if body_planes is None else
                  np.bincount([self.owner_of_plane(p) for p in body_planes],
                              minlength=self.processes))
        lines = []
        for rank in range(self.processes):
            planes = self.stop(rank) - self.first(rank)
            text = (f"process {rank}: x-planes {self.first(rank)}..{self.stop(rank) - 1}, "
                    f"{planes * plane_cells:,} cells")
            if owners is not None:
                text += f", {owners[rank]} bodies' centres"
            lines.append(text)
        return lines

    def owner_of_plane(self, plane: int) -> int:
        """The process whose slab holds x-plane ``plane`` (clipped into the grid)."""
        plane = min(max(int(plane), 0), self.cells - 1)
        return int(np.searchsorted(np.asarray(self.starts[1:]), plane, side="right"))


def cut_slabs(cells: int, processes: int, *, alignment: int = 1, thinnest: int = 1,
              plane_costs=None) -> SlabCut:
    """Cut ``cells`` x-planes into ``processes`` slabs of at least ``thinnest`` planes, every cut
    at a multiple of ``alignment``, balancing ``plane_costs`` (one per plane; default: equal).

    Refuses, with the figures, a cut that cannot be made: more processes than slabs of the
    thinnest size fit."""
    cells, processes = int(cells), int(processes)
    alignment = max(1, int(alignment))
    thinnest = max(1, int(thinnest))
    step = -(-thinnest // alignment) * alignment
    if processes < 1:
        raise CaseFileError(f"slab cut: {processes} processes; at least 1 is needed")
    if processes > 1 and processes * step > cells + (step - 1):
        fitting = max(1, (cells + alignment - 1) // step)
        raise CaseFileError(
            f"the fluid grid's {cells} cells along x cannot be cut into {processes} slabs: each "
            f"process needs at least {step} x-planes (halo depth {thinnest}, multigrid alignment "
            f"{alignment}), so at most {fitting} process(es) fit; run on fewer processes or use "
            "a finer grid")
    costs = np.ones(cells) if plane_costs is None else np.asarray(plane_costs, dtype=float)
    if costs.shape != (cells,) or not np.all(np.isfinite(costs)) or np.any(costs < 0):
        raise CaseFileError(f"slab cut: plane costs must be {cells} finite non-negative numbers")
    cumulative = np.concatenate([[0.0], np.cumsum(costs + 1e-12)])
    starts = [0]
    for r in range(1, processes):
        target = cumulative[-1] * r / processes
        plane = int(np.searchsorted(cumulative, target))
        plane = int(round(plane / alignment)) * alignment
        low = starts[-1] + step
        high = cells - (processes - r) * step
        high -= high % alignment
        plane = min(max(plane, low), high)
        starts.append(plane)
    starts.append(cells)
    thinnest_made = min(starts[r + 1] - starts[r] for r in range(processes))
    if processes > 1 and thinnest_made < thinnest:
        raise CaseFileError(
            f"the fluid grid's {cells} cells along x cannot be cut into {processes} slabs of at "
            f"least {thinnest} planes each (the thinnest would have {thinnest_made}); run on fewer "
            "processes")
    return SlabCut(cells=cells, starts=tuple(starts), alignment=alignment)
