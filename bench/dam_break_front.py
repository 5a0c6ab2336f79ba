"""Surge front of the collapsing column, end to end, for the side-by-side with interFoam.

The 2D (or, with ``--across``, 3D) Martin & Moyce column of ``../shared/peers/cfd/RESULTS.md``
(a = 0.05715 m, 2a high, tank 5a x 2.52a, open top, no-slip walls) run to T = t sqrt(2g/a) = 3.6.
Prints the front Z = x/a (the peers' Z_contig: the furthest floor cell with water fraction > 0.5
in the run from the left wall) every 0.2 in T beside the experiment (Martin & Moyce Fig. 3,
a = 2.25 in, the peers' interpolation) and interFoam's a/50 front at maxCo 1 (the peers' table
3a), then the wall time and the step count. Last line: ``METRIC dam_break_front_lead_T3 <lead> a``,
riprap's lead over the experiment at T = 3.

interFoam beside it (OpenFOAM v1912: ``apt-get install openfoam``, then from
``../shared/peers/cfd/openfoam``): ``bash run_mm.sh /tmp/of 1 --n2 2 --H 2.5 --N 50 [--maxCo 0.3]``.

    python bench/dam_break_front.py                         # a/50, sigma 0.07 as interFoam's case
    python bench/dam_break_front.py --cells-per-a 16 --across 20     # the peers' 3D case
"""
from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from dam_break import A, column          # the same column as the speed bench

G = 9.81
TIMES = np.round(np.arange(0.0, 3.61, 0.2), 2)
# Martin & Moyce (1952) Fig. 3, n^2 = 2, a = 2.25 in, interpolated at TIMES (peers' table 3a).
EXPERIMENT = np.array([1.00, 1.05, 1.10, 1.16, 1.21, 1.33, 1.46, 1.66, 1.87, 2.08, 2.30, 2.55, 2.81,
                       3.07, 3.36, 3.64, 3.93, 4.20, 4.43])
# interFoam v1912, 2D a/50, maxCo 1, sigma 0.07 (peers' table 3a; reproduced here 2026-11-24).
INTERFOAM = np.array([0.99, 1.01, 1.09, 1.21, 1.35, 1.51, 1.69, 1.89, 2.09, 2.33, 2.57, 2.81, 3.09,
                      3.35, 3.63, 3.93, 4.21, 4.51, 4.83])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells-per-a", type=int, default=50)
    parser.add_argument("--across", type=int, default=1, help="cells across the tank (1: 2D)")
    parser.add_argument("--surface-tension", type=float, default=0.07, help="N/m")
    parser.add_argument("--courant-number", type=float, default=0.3)
    args = parser.parse_args()
    solver = column(args.cells_per_a, args.across, args.surface_tension,
                    courant_number=args.courant_number)
    h = solver.h
    nx, _, nz = solver.grid.cells
    print(f"{nx} x {args.across} x {nz} cells of a/{args.cells_per_a}, surface tension "
          f"{args.surface_tension} N/m, Courant number {args.courant_number}, "
          f"{numba.get_num_threads()} thread(s)")
    print("   T   riprap  experiment  interFoam(maxCo 1)   riprap lead")
    fronts = []
    start = time.perf_counter()
    for T, measured, peer in zip(TIMES, EXPERIMENT, INTERFOAM):
        target = T / np.sqrt(2 * G / A)
        while solver.time < target - 1e-12:
            solver.step(min(solver.stable_time_step(), target - solver.time))
        wet = solver.fraction[:, args.across // 2, 0] > 0.5
        first_dry = int(np.argmin(wet)) if not wet.all() else len(wet)
        front = (first_dry - 0.5) * h / A
        fronts.append(front)
        print(f"{T:5.1f} {front:7.2f} {measured:9.2f} {peer:12.2f} {front - measured:+17.2f}")
    wall = time.perf_counter() - start
    lead = fronts[int(np.argmin(np.abs(TIMES - 3.0)))] - EXPERIMENT[TIMES == 3.0][0]
    print(f"wall {wall:.1f} s, {solver.step_count} steps, water volume error "
          f"{solver.last_report.water_volume_error:.1e}")
    print(f"METRIC dam_break_front_lead_T3 {lead:.3f} a")


if __name__ == "__main__":
    main()
