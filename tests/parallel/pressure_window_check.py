"""Run under ``mpiexec -n N``: the planes a process's pressure window takes from its block and its
neighbours (``riprap/fluid/pressure_window.py``) against the whole grid's arrays, on a fluid cut
made unequal (upper planes cost three times the lower) and the pressure's equal cut.

Each block holds the whole grid's numbers on its own planes only (cells of its slab, the x-faces
on both its ends) and NaN on every other plane, so a window that read a halo plane instead of
its owner's would hold a NaN. Checked, bit for bit: the window of the cells' and the faces'
arrays; the listed cells of the window (every process lists some of its block's cells, halo
cells included); the pressures put back into each block's slab and ghost planes. Prints one
line and exits 1 on any difference.
"""
import sys

import numpy as np

from riprap.fluid.pressure_window import PressureWindow, fits
from riprap.parallel.communicator import world
from riprap.parallel.slabs import cut_slabs

NX, NY, NZ = 96, 3, 4
HALO = 8


def main() -> int:
    comm = world()
    rank, size = comm.rank, comm.size
    costs = np.where(np.arange(NX) >= NX // 2, 3.0, 1.0)
    fluid_cut = cut_slabs(NX, size, alignment=4, thinnest=HALO, plane_costs=costs)
    pressure_cut = cut_slabs(NX, size, alignment=4, thinnest=HALO)
    if fluid_cut.starts == pressure_cut.starts or not fits(fluid_cut, pressure_cut):
        print(f"process {rank}: the cuts {fluid_cut.starts} and {pressure_cut.starts} do not "
              "check the window")
        return 1
    rng = np.random.default_rng(7)
    whole = {"cells": rng.standard_normal((NX, NY, NZ)),
             "faces": rng.standard_normal((NX + 1, NY, NZ)),
             "y_faces": rng.standard_normal((NX, NY + 1, NZ))}
    first, stop = fluid_cut.first(rank), fluid_cut.stop(rank)
    low = HALO if rank > 0 else 0
    high = HALO if rank < size - 1 else 0
    start = first - low

    def block_of(array, faces=False):
        block = np.full((stop + high - start + (1 if faces else 0),) + array.shape[1:], np.nan)
        own_stop = stop + (1 if faces else 0)
        block[first - start:own_stop - start] = array[first:own_stop]
        return block

    move = PressureWindow(fluid_cut, pressure_cut, comm, low)
    s, e = move.start, move.end
    failures = []
    for name, faces in (("cells", False), ("faces", True), ("y_faces", False)):
        got = move.window(block_of(whole[name], faces), faces=faces)
        want = whole[name][s:e + (1 if faces else 0)]
        if got.shape != want.shape or not np.array_equal(got, want):
            failures.append(name)
    # listed cells: every tenth cell of the whole grid; each block lists those of its planes
    listed_whole = np.arange(0, NX * NY * NZ, 10)
    i, j, k = np.unravel_index(listed_whole, (NX, NY, NZ))
    in_block = (i >= start) & (i < stop + high)
    block_shape = (stop + high - start, NY, NZ)
    listed_block = np.ravel_multi_index((i[in_block] - start, j[in_block], k[in_block]),
                                        block_shape)
    got = np.sort(move.listed(listed_block, block_shape))
    own = (i >= pressure_cut.first(rank)) & (i < pressure_cut.stop(rank))
    want = np.sort(np.ravel_multi_index((i[own] - s, j[own], k[own]), (e - s, NY, NZ)))
    if not np.array_equal(got, want):
        failures.append("listed cells")
    # the pressures back: the block's slab and a ghost plane each side
    pressure = whole["cells"] * 3.0
    block = np.full(block_shape, np.nan)
    move.to_block(pressure[s:e].copy(), block)
    lo, hi = first - (1 if rank > 0 else 0), stop + (1 if rank < size - 1 else 0)
    if not np.array_equal(block[lo - start:hi - start], pressure[lo:hi]):
        failures.append("pressure back")
    if failures:
        print(f"process {rank}: {', '.join(failures)} differ (fluid cut {fluid_cut.starts}, "
              f"pressure cut {pressure_cut.starts})")
        return 1
    print(f"process {rank}: bit for bit (fluid cut {fluid_cut.starts}, pressure cut "
          f"{pressure_cut.starts})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
