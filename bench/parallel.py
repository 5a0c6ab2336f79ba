"""One run over two processes against one: the same work, time per step, and what the processes
said to each other (issue 39).

The case: the 3D collapse of a water column (Martin & Moyce geometry, as bench/dam_break.py) at
0.89 M cells (a/40: 200 x 44 x 101 cells, open top, no surface tension), ``--warmup`` steps from
the start and then ``--steps`` steps timed, first on one process, then over two
(``mpiexec -n 2``), each process on one thread (NUMBA_NUM_THREADS=1). The split run's state is
checked against the one process's, bit for bit, at the end. The small placed layer of the issue's
second case is not run: bodies do not yet run over several processes.

Prints per run: seconds per step, the pressure solve's share, and per process the halo/ghost
exchanges and reductions (messages, bytes and seconds per step). Last line:
``METRIC parallel_efficiency_2 <value> ratio`` = time per step on 1 / (2 x time per step on 2).

    python bench/parallel.py [--steps 20] [--warmup 10]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

A = 0.05715
CELLS_PER_A, ACROSS = 40, 44


def column():
    import numpy as np

    from riprap.fluid.grid import FluidGrid
    from riprap.fluid.solver import FluidSolver

    h = A / CELLS_PER_A
    nx, nz = 5 * CELLS_PER_A, int(np.ceil(2.52 * CELLS_PER_A))
    grid = FluidGrid(lower=(0, 0, 0), upper=(nx * h, ACROSS * h, nz * h), cells=(nx, ACROSS, nz),
                     boundaries={"z_high": "open"})
    solver = FluidSolver(grid, courant_number=0.3)
    solver.add_water_box((0, 0, 0), (A, ACROSS * h, 2 * A))
    return solver


def worker(warmup: int, steps: int, state_file: str) -> None:
    """One run (on this process or over the processes of the launcher); prints a JSON line."""
    import numpy as np

    from riprap.fluid.slab_solver import split_fluid
    from riprap.parallel.communicator import world

    comm = world()
    solver = column()
    if comm.size > 1:
        solver = split_fluid(solver, comm)
    for _ in range(warmup):
        solver.step()
    if comm.size > 1:
        comm.barrier()
        before = json.loads(json.dumps(comm.traffic))
    pressure = 0.0
    started = time.perf_counter()
    for _ in range(steps):
        solver.step()
        pressure += solver.last_pressure_seconds
    if comm.size > 1:
        comm.barrier()
    wall = time.perf_counter() - started
    state = solver.state_arrays() if comm.size == 1 else solver.gather_whole(solver.state_arrays())
    result = {"processes": comm.size, "rank": comm.rank, "seconds_per_step": wall / steps,
              "pressure_share": pressure / wall,
              "iterations": solver.last_report.pressure_iterations,
              "time": solver.time}
    if comm.size > 1:
        result["traffic_per_step"] = {
            kind: {key: (comm.traffic[kind][key] - before[kind][key]) / steps
                   for key in ("messages", "bytes", "seconds")} for kind in comm.traffic}
        result["slabs"] = list(solver.cut.starts)
    if comm.rank == 0:
        if comm.size == 1:
            np.savez(state_file, **{k: state[k] for k in ("fraction", "u", "v", "w", "pressure")})
        else:
            reference = np.load(state_file)
            result["bit_for_bit"] = all(np.array_equal(reference[k], state[k])
                                        for k in ("fraction", "u", "v", "w", "pressure"))
    for line in comm.all_values(json.dumps(result)) if comm.size > 1 else [json.dumps(result)]:
        if comm.rank == 0:
            print("RESULT " + line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--warmup", type=int, default=10)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--state", default="bench_out/parallel_state.npz")
    args = parser.parse_args()
    if args.worker:
        worker(args.warmup, args.steps, args.state)
        return
    Path(args.state).parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    me = [sys.executable, __file__, "--worker", "--steps", str(args.steps), "--warmup",
          str(args.warmup), "--state", args.state]
    mpiexec = str(Path(sys.executable).parent / "mpiexec")
    runs = {}
    for processes, command in ((1, me), (2, [mpiexec, "-n", "2", *me])):
        output = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
        results = [json.loads(line[7:]) for line in output.stdout.splitlines()
                   if line.startswith("RESULT ")]
        runs[processes] = results
        slowest = max(r["seconds_per_step"] for r in results)
        print(f"{processes} process(es): {slowest:.3f} s per step, pressure "
              f"{results[0]['pressure_share']:.0%} of it, {results[0]['iterations']} iterations "
              f"at the last step, t = {results[0]['time']:.4f} s", flush=True)
        for r in results:
            if "traffic_per_step" in r:
                t = r["traffic_per_step"]
                print(f"  process {r['rank']} (slabs {r['slabs']}): " + "; ".join(
                    f"{kind} {v['messages']:.0f} messages, {v['bytes'] / 1e6:.2f} MB, "
                    f"{v['seconds'] * 1e3:.1f} ms per step" for kind, v in t.items()))
        if processes == 2:
            print(f"  the same state as one process, bit for bit: {results[0]['bit_for_bit']}")
    one = max(r["seconds_per_step"] for r in runs[1])
    two = max(r["seconds_per_step"] for r in runs[2])
    print(f"METRIC parallel_efficiency_2 {one / (2.0 * two):.3f} ratio")


if __name__ == "__main__":
    main()
