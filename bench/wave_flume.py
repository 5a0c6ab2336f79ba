"""Cost of a hydraulic stability test: examples/10's flume (the small Core-Loc-like layer of
examples/06, 25 free units on 135 fixed rocks, on a porous core, 280 x 45 x 36 = 453,600 cells of
0.1 m, JONSWAP Hs = 1.2 m, Tp = 4 s) stepped for ``--periods`` peak periods from ``--start`` s
(carried there first, untimed).

Prints the cells, the wall seconds per wave period and their split between the fluid (its own
step: advection, momentum, pressure, porous friction, waves), the coupling (solid volumes and the
exchange) and the solids (contact sub-steps), the sub-steps per fluid step and the pressure
iterations; last ``METRIC wall_s_per_wave <seconds> s`` (issue 15's target: at most 120 s for a
layer of at least 25 units on this 2-core machine). The default period is the waves' first, before
they reach the structure (t = 0-4 s); the wave attack costs more (docs/waves.md: air blown out of
the armour sets the step from t = 16 s): ``--start 16`` measures it, after carrying the flume there
untimed (about 12 minutes here), and ends with ``METRIC wall_s_per_wave_attack <seconds> s``
(issue 37's target: at most 45 s, 3x cheaper than the 139 s measured before it).

    python bench/wave_flume.py [--periods N] [--start T]
"""
import argparse
import os
import time
from pathlib import Path

import numpy as np

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case

CASE = Path(__file__).resolve().parents[1] / "examples" / "10_breakwater_test" / "case.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--periods", type=float, default=1.0)
    parser.add_argument("--start", type=float, default=0.0,
                        help="simulated time (s) reached before the timing")
    args = parser.parse_args()
    load_before = os.getloadavg()
    case = load_case(CASE)
    simulation = build_fluid_run(case, output_directory="/tmp/riprap_bench_wave_flume",
                                 progress=False)
    simulation.prepare()
    coupled = simulation.model.solver
    fluid, solids = coupled.fluid, coupled.solids
    period = fluid.wave_source.wave.period
    print(f"examples/10: {fluid.grid.n_cells:,} cells ({' x '.join(map(str, fluid.grid.cells))}, "
          f"{fluid.h:g} m), {int((~solids.fixed).sum())} free units, {int(solids.fixed.sum())} "
          f"fixed bodies, contact sub-step {coupled.solid_time_step:.2e} s, Tp = {period:g} s")
    coupled.step(coupled.stable_time_step())              # compile outside the timing
    while coupled.time < args.start:
        coupled.step(coupled.stable_time_step())
    parts = np.zeros(4)
    steps = substeps = iterations = 0
    begin = coupled.time
    started = time.perf_counter()
    while coupled.time < begin + args.periods * period:
        before = time.perf_counter()
        report = coupled.step(coupled.stable_time_step())
        total = time.perf_counter() - before
        coupling = coupled.last_solid_volume_seconds + coupled.last_exchange_seconds
        parts += (total - coupling - coupled.last_solid_seconds, coupling, coupled.last_solid_seconds, 0)
        steps += 1
        substeps += report.solid_substeps
        iterations += report.pressure_iterations
    wall = time.perf_counter() - started
    simulated = coupled.time - begin
    per_wave = wall / simulated * period
    print(f"{steps} fluid steps over {simulated:.2f} s from t = {begin:.2f} s: {wall:.0f} s wall, "
          f"{wall / steps:.3f} s per step, {substeps / steps:.0f} contact sub-steps and "
          f"{iterations / steps:.1f} pressure iterations per step")
    for name, value in zip(("fluid", "coupling (solid volumes, exchange)", "solids (contact sub-steps)"),
                           parts[:3]):
        print(f"  {name}: {value / simulated * period:.0f} s per wave ({value / wall:.0%})")
    print(f"load average before {load_before[0]:.2f}, after {os.getloadavg()[0]:.2f}")
    # the waves' first period, and the attack once they reach the structure (issue 37's figure)
    name = "wall_s_per_wave_attack" if args.start > 0 else "wall_s_per_wave"
    print(f"METRIC {name} {per_wave:.1f} s")


if __name__ == "__main__":
    main()
