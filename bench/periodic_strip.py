"""Cost of a periodic strip's fluid step against the same box between walls (issue 53).

A wave flume's section: ``--cells`` (nx, ny, nz) cubic cells of ``--cell`` m, water to 60 % of the
height with a mound along x and across y (so the flow is three-dimensional and crosses the strip's
sides), stepped ``--steps`` times at the stable step, once with free-slip y walls and once with
y_low = y_high = "periodic", in turn (A B A B, ``--rounds`` times; the fastest round of each
counts: a shared 2-core machine is noisy). Prints seconds per step and per million cells of each,
and their ratio. Last line: ``METRIC periodic_cost_per_cell_ratio <value> ratio`` (periodic over
walled; the issue asks at most 1.10).

    python bench/periodic_strip.py                    # 96 x 32 x 48 cells, 20 steps, 3 rounds
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from riprap.fluid.grid import FluidGrid
from riprap.fluid.solver import FluidSolver


def flume(cells, cell, boundaries) -> FluidSolver:
    nx, ny, nz = cells
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(nx * cell, ny * cell, nz * cell), cells=cells,
                     boundaries=boundaries)
    solver = FluidSolver(grid, surface_tension=0.0, limit_air_speed=True,
                         pressure_volume_tolerance=1e-3)
    solver.set_still_water_level(0.6 * nz * cell)
    # a mound on a quarter of x and half of y: it falls and spreads across the strip's sides
    solver.add_water_box((0.2 * nx * cell, 0.6 * ny * cell, 0.0),
                         (0.45 * nx * cell, ny * cell, 0.85 * nz * cell))
    return solver


def seconds_per_step(solver, steps) -> float:
    started = time.perf_counter()
    for _ in range(steps):
        solver.step()
    return (time.perf_counter() - started) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, nargs=3, default=(96, 32, 48))
    parser.add_argument("--cell", type=float, default=0.025)
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    cells = tuple(args.cells)
    kinds = {"walled": {"y_low": "free_slip", "y_high": "free_slip"},
             "periodic": {"y_low": "periodic", "y_high": "periodic"}}
    best = dict.fromkeys(kinds, np.inf)
    for name, boundaries in kinds.items():       # compile, and the first steps' start-up
        seconds_per_step(flume(cells, args.cell, boundaries), 2)
    for _ in range(args.rounds):
        for name, boundaries in kinds.items():
            solver = flume(cells, args.cell, boundaries)
            seconds_per_step(solver, 3)           # past the first solves from rest
            best[name] = min(best[name], seconds_per_step(solver, args.steps))
    million = np.prod(cells) / 1e6
    for name in kinds:
        print(f"{name:9s}: {best[name] * 1e3:8.1f} ms per step, "
              f"{best[name] / million:6.3f} s per step and million cells")
    print(f"cells {cells}, {args.steps} steps a round, best of {args.rounds} rounds")
    print(f"METRIC periodic_cost_per_cell_ratio {best['periodic'] / best['walled']:.3f} ratio")


if __name__ == "__main__":
    main()
