"""One run over two processes against one: the same work, time per step, and what the processes
said to each other (issue 39).

The case: the 3D collapse of a water column (Martin & Moyce geometry, as bench/dam_break.py) at
0.89 M cells (a/40: 200 x 44 x 101 cells, open top, no surface tension), ``--warmup`` steps from
the start and then ``--steps`` steps timed, first on one process, then over two
(``mpiexec -n 2``), each process on one thread (NUMBA_NUM_THREADS=1). The split run's state is
checked against the one process's, bit for bit, at the end.

The second case: the small placed layer of examples/06 (25 Core-Loc-like units on 135 fixed
rocks and a fixed core) in its dam-break flume on cells of 0.05 m instead of 0.1 m (140 x 90 x
72 = 0.91 M cells, 11 cells across a unit), ``--layer-warmup`` steps and then ``--layer-steps``
timed; the split run's bodies and fluid are compared with one process's within round-off (the
bodies' sums are added slab by slab: ``riprap/coupling/slab_coupled.py``).

Prints per run: seconds per step, the pressure solve's share, and per process the halo/ghost
exchanges and reductions (messages, bytes and seconds per step). Then ``METRIC parallel_efficiency_2_fluid`` (the column alone) and, last,
``METRIC parallel_efficiency_2 <value> ratio`` of the run with the layer, each time per step on 1
/ (2 x time per step on 2).

    python bench/parallel.py [--steps 20] [--warmup 10] [--layer-steps 10] [--layer-warmup 3]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
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


LAYER_CASE = Path(__file__).resolve().parent.parent / "examples" / "06_layer_in_wave" / "case.toml"


def layer_worker(warmup: int, steps: int, state_file: str) -> None:
    """The placed layer in its flume on 0.05 m cells (one process or the launcher's); prints a
    JSON line per process."""
    import tempfile

    import numpy as np

    from riprap.case.build_fluid import build_fluid_run
    from riprap.case.load import load_case
    from riprap.parallel.communicator import world

    comm = world()
    text = LAYER_CASE.read_text().replace("cells = [70, 45, 36]", "cells = [140, 90, 72]")
    case_file = LAYER_CASE.parent / f".bench_parallel_{comm.rank}_{os.getpid()}.toml"
    case_file.write_text(text)
    try:
        with tempfile.TemporaryDirectory() as out:
            sim = build_fluid_run(load_case(case_file), output_directory=out, progress=False)
            sim.prepare()
    finally:
        case_file.unlink()
    solver = sim.model.solver
    for _ in range(warmup):
        solver.step()
    comm.barrier()
    before = json.loads(json.dumps(getattr(comm, "traffic", {})))
    parts = dict.fromkeys(("pressure", "solid_volumes", "exchange", "contact_substeps"), 0.0)
    substeps = 0
    split = solver.solids._split
    contacts_before = dict(split.seconds) if split is not None else {}
    started = time.perf_counter()
    for _ in range(steps):
        report = solver.step()
        parts["pressure"] += solver.last_pressure_seconds
        parts["solid_volumes"] += solver.last_solid_volume_seconds
        parts["exchange"] += solver.last_exchange_seconds
        parts["contact_substeps"] += solver.last_solid_seconds
        substeps += report.solid_substeps
    comm.barrier()
    wall = time.perf_counter() - started
    split = solver.solids._split
    if split is not None:
        parts.update({f"contacts: {name}": value - contacts_before[name]
                      for name, value in split.seconds.items()})
    fluid = solver.fluid
    state = fluid.state_arrays() if comm.size == 1 else fluid.gather_whole(fluid.state_arrays())
    names = ("fraction", "u", "v", "w", "pressure")
    result = {"processes": comm.size, "rank": comm.rank, "seconds_per_step": wall / steps,
              "shares": {name: value / wall for name, value in parts.items()},
              "substeps_per_step": substeps / steps, "time": solver.time,
              "cells": int(np.prod(fluid.whole_cells if comm.size > 1 else fluid.grid.cells)),
              "bodies": int(solver.solids.n_bodies),
              "peak_memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}
    if comm.size > 1:
        result["traffic_per_step"] = {
            kind: {key: (comm.traffic[kind][key] - before[kind][key]) / steps
                   for key in ("messages", "bytes", "seconds")} for kind in comm.traffic}
        result["slabs"] = list(fluid.cut.starts)
    if comm.rank == 0:
        if comm.size == 1:
            np.savez(state_file, positions=solver.solids.positions, **{k: state[k] for k in names})
        else:
            reference = np.load(state_file)
            worst = {k: float(np.abs(reference[k] - state[k]).max()
                              / max(np.abs(reference[k]).max(), 1e-300)) for k in names}
            worst["positions"] = float(np.abs(reference["positions"] - solver.solids.positions).max()
                                       / np.abs(reference["positions"]).max())
            result["largest_relative_difference"] = worst
    for line in comm.all_values(json.dumps(result)) if comm.size > 1 else [json.dumps(result)]:
        if comm.rank == 0:
            print("RESULT " + line, flush=True)


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
              "peak_memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
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
    parser.add_argument("--layer-steps", type=int, default=10)
    parser.add_argument("--layer-warmup", type=int, default=3)
    parser.add_argument("--worker", choices=("column", "layer"), help=argparse.SUPPRESS)
    parser.add_argument("--state", default="bench_out/parallel_state.npz")
    parser.add_argument("--repeats", type=int, default=3,
                        help="runs of each count of processes, in turn; the fastest is taken")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats must be 1 or more, got {args.repeats}")
    if args.worker == "column":
        worker(args.warmup, args.steps, args.state)
        return
    if args.worker == "layer":
        layer_worker(args.warmup, args.steps, args.state)
        return
    Path(args.state).parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    me = [sys.executable, __file__, "--worker", "column", "--steps", str(args.steps), "--warmup",
          str(args.warmup), "--state", args.state]
    mpiexec = str(Path(sys.executable).parent / "mpiexec")
    print("the water column alone (0.89 M cells):", flush=True)
    column = _compare(me, mpiexec, env, lambda r: f"  the same state as one process, bit for "
                                                 f"bit: {r['bit_for_bit']}", args.repeats)
    print(f"METRIC parallel_efficiency_2_fluid {column:.3f} ratio", flush=True)
    layer_state = str(Path(args.state).with_name("parallel_layer_state.npz"))
    me = [sys.executable, __file__, "--worker", "layer", "--steps", str(args.layer_steps),
          "--warmup", str(args.layer_warmup), "--state", layer_state]
    print("the placed layer in its dam-break flume (0.91 M cells, 161 bodies):", flush=True)
    layer = _compare(me, mpiexec, env, lambda r: "  largest difference from one process, of "
                     "each array's largest value: " + ", ".join(
                         f"{k} {v:.1e}" for k, v in r["largest_relative_difference"].items()),
                     args.repeats)
    print(f"METRIC parallel_efficiency_2 {layer:.3f} ratio")


def _compare(me, mpiexec, env, check_line, repeats: int) -> float:
    """Run ``me`` on one process and on two, in turn, ``repeats`` times each; print what the
    fastest run of each did; the efficiency from the fastest runs (this shared 2-core machine's
    noise only ever slows a run down)."""
    runs = {1: None, 2: None}
    for _ in range(repeats):
        for processes, command in ((1, me), (2, [mpiexec, "-n", "2", *me])):
            output = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
            results = [json.loads(line[7:]) for line in output.stdout.splitlines()
                       if line.startswith("RESULT ")]
            slowest = max(r["seconds_per_step"] for r in results)
            if runs[processes] is None or slowest < max(r["seconds_per_step"]
                                                        for r in runs[processes]):
                runs[processes] = results
    for processes in (1, 2):
        results = runs[processes]
        slowest = max(r["seconds_per_step"] for r in results)
        text = (f"{processes} process(es): {slowest:.3f} s per step, peak memory "
                f"{max(r['peak_memory_mb'] for r in results):.0f} MB a process, ")
        if "pressure_share" in results[0]:
            text += (f"pressure {results[0]['pressure_share']:.0%} of it, "
                     f"{results[0]['iterations']} iterations at the last step, ")
        print(text + f"t = {results[0]['time']:.4f} s", flush=True)
        for r in results:
            if "traffic_per_step" in r:
                t = r["traffic_per_step"]
                print(f"  process {r['rank']} (slabs {r['slabs']}): " + "; ".join(
                    f"{kind} {v['messages']:.0f} messages, {v['bytes'] / 1e6:.2f} MB, "
                    f"{v['seconds'] * 1e3:.1f} ms per step" for kind, v in t.items()))
            if "shares" in r:
                print(f"  process {r['rank']}: {r['substeps_per_step']:.0f} contact sub-steps a "
                      "step; shares of the step: " + ", ".join(
                          f"{k} {v:.0%}" for k, v in r["shares"].items()), flush=True)
        if processes == 2:
            print(check_line(results[0]), flush=True)
    one = max(r["seconds_per_step"] for r in runs[1])
    two = max(r["seconds_per_step"] for r in runs[2])
    return one / (2.0 * two)


if __name__ == "__main__":
    main()
