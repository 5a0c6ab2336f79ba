"""Speed of the fluid solver on the 3D collapse of a water column (Martin & Moyce geometry).

A column a = 0.05715 m wide and 2a high in a tank 5a x W x 2.52a (open top, no-slip walls), water
and air at 20 C, surface tension 0.0728 N/m (``--surface-tension``). Two grids: about 0.25 M cells (a/25, 32 cells across) and 2 M cells (a/50, 64
across). For each grid: ``--warmup`` steps from the start (the column starts to collapse and the
interface to deform), then a window of ``--steps`` steps timed on 1 thread and on all threads.
Prints cell-updates per second (cells x steps / wall seconds), the share of the time spent in the
pressure solve, the mean pressure iterations, the simulated time reached.
Last line: ``METRIC cell_updates_per_s <value> 1/s`` (the 2 M-cell grid, all threads).

Peer (../shared/peers/cfd/RESULTS.md): OpenFOAM v1912 interFoam on the same case in 3D, 64,000
cells, one core, clean run: 1.02e5 cell-steps/s (2D: 1.2-1.3e5).

    python bench/dam_break.py                    # both grids, a few minutes
    python bench/dam_break.py --grids small      # the 0.25 M grid only
"""
from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np

from riprap.fluid.grid import FluidGrid
from riprap.fluid.solver import FluidSolver

A = 0.05715
GRIDS = {"small": (25, 32), "large": (50, 64)}      # cells per a, cells across


def column(cells_per_a: int, across: int, surface_tension: float,
           courant_number: float = 0.3) -> FluidSolver:
    h = A / cells_per_a
    nx, nz = 5 * cells_per_a, int(np.ceil(2.52 * cells_per_a))
    grid = FluidGrid(lower=(0, 0, 0), upper=(nx * h, across * h, nz * h), cells=(nx, across, nz))
    solver = FluidSolver(grid, surface_tension=surface_tension, courant_number=courant_number)
    solver.add_water_box((0, 0, 0), (A, across * h, 2 * A))
    return solver


def window(solver: FluidSolver, steps: int) -> tuple[float, float, float]:
    """(cell-updates/s, pressure share, mean iterations) over ``steps`` steps."""
    pressure = 0.0
    iterations = []
    start = time.perf_counter()
    for _ in range(steps):
        report = solver.step()
        pressure += solver.last_pressure_seconds
        iterations.append(report.pressure_iterations)
    wall = time.perf_counter() - start
    return solver.grid.n_cells * steps / wall, pressure / wall, float(np.mean(iterations))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grids", nargs="+", default=["small", "large"], choices=list(GRIDS))
    parser.add_argument("--warmup", type=int, default=40)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--surface-tension", type=float, default=0.0728,
                        help="N/m (interFoam's case: 0.07; 0 leaves it out)")
    args = parser.parse_args()
    threads = numba.get_num_threads()
    result = None
    print(f"machine: {os.cpu_count()} cores, numba threads {threads}, load {os.getloadavg()[0]:.2f}; "
          f"surface tension {args.surface_tension} N/m")
    for name in args.grids:
        solver = column(*GRIDS[name], args.surface_tension)
        nx, ny, nz = solver.grid.cells
        start = time.perf_counter()
        for _ in range(args.warmup):
            solver.step()
        warm = time.perf_counter() - start
        scale = np.sqrt(2 * 9.81 / A)
        print(f"{name}: {nx} x {ny} x {nz} = {solver.grid.n_cells:,} cells; warm-up {args.warmup} "
              f"steps in {warm:.1f} s to T = {solver.time * scale:.2f}")
        for count in sorted({1, threads}):
            numba.set_num_threads(count)
            rate, share, iterations = window(solver, args.steps)
            print(f"  {count} thread(s): {rate:.3g} cell-updates/s, pressure {100 * share:.0f} % "
                  f"of the time, {iterations:.1f} iterations/step, T = {solver.time * scale:.2f}, "
                  f"water volume error {solver.last_report.water_volume_error:.1e}")
            if count == threads:
                result = rate
        numba.set_num_threads(threads)
    print(f"METRIC cell_updates_per_s {result:.4g} 1/s")


if __name__ == "__main__":
    main()
