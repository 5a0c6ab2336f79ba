"""Memory of one process of a run split over processes: the 3D collapse of a water column at
0.89 M cells (bench/parallel.py's column) through ``riprap run``'s own path (``build_fluid_run``,
its writers, a frame and a checkpoint at the end), on 1, 2 and 4 processes.

Per process it prints the peak resident memory (``VmHWM``) and the memory held after the run
(``VmRSS``): what a cluster job must give each process. Process 0 writes the tables and pictures
from the whole grid gathered there, so it holds more than the others.

    python bench/parallel_memory.py            # needs mpiexec (pip install 'riprap[mpi]')

Last line: ``METRIC parallel_peak_memory_4_over_1 <ratio> ratio``: the largest process's peak on 4
processes over the one process's peak (1/4 would be a perfect split; the Python interpreter,
numba's compiled code and the halos are repeated on every process).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CASE = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = {end_time}
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [{length}, {width}, {height}]
cells = [{nx}, {ny}, {nz}]
courant_number = 0.3
z_high = "open"
[[water_regions]]
type = "box"
lower = [0.0, 0.0, 0.0]
upper = [{column}, {width}, {column_height}]
{porous}
[output]
directory = "out"
paraview = true
picture = false
"""


POROUS = """[[porous_zones]]
type = "box"
porosity = 0.4
stone_diameter = 0.01
lower = [{start}, 0.0, 0.0]
upper = [{length}, {width}, {top}]
"""


def write_case(folder: Path, *, tiny: bool = False, porous: bool = False) -> Path:
    # bench/parallel.py's column: a = 0.05715 m, 40 cells across it, 44 cells wide (tiny: 8
    # cells across, 2 wide: what the interpreter and the compiled code take, without a grid)
    a, per_a, across = (0.05715, 8, 2) if tiny else (0.05715, 40, 44)
    h = a / per_a
    nx, nz = 5 * per_a, int(2.52 * per_a) + 1
    path = folder / ("tiny.toml" if tiny else "column.toml")
    # with porous: a porous bed (the rubble of a core) under the right half of the flume
    zone = POROUS.format(start=2.5 * a, length=nx * h, width=across * h, top=0.5 * a)
    path.write_text(CASE.format(end_time=2e-3, length=nx * h, width=across * h, height=nz * h,
                                nx=nx, ny=across, nz=nz, column=a, column_height=2 * a,
                                porous=zone if porous else ""))
    return path


def _memory_mb() -> dict:
    fields = {}
    for line in Path("/proc/self/status").read_text().splitlines():
        key, _, value = line.partition(":")
        if key in ("VmHWM", "VmRSS"):
            fields[key] = int(value.split()[0]) / 1024
    return fields


def worker(case_file: str, out: str, restart: str | None = None) -> None:
    from riprap.case.build_fluid import build_fluid_run
    from riprap.case.load import load_case
    from riprap.parallel.communicator import world

    comm = world()
    sim = build_fluid_run(load_case(case_file), output_directory=out, progress=False)
    summary = sim.run(restart_from=restart)
    memory = _memory_mb()
    result = {"rank": comm.rank, "processes": comm.size, "peak_mb": memory["VmHWM"],
              "cells": summary.cells,
              "held_mb": memory["VmRSS"], "steps": summary.steps}
    lines = comm.all_values(json.dumps(result))
    if comm.rank == 0:
        for line in lines:
            print("RESULT " + line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--processes", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--porous", action="store_true",
                        help="a porous bed under the right half of the flume")
    parser.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(*args.worker)
        return
    if min(args.processes) < 1:
        parser.error(f"--processes must be counts of 1 or more, got {args.processes}")
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        sys.exit("bench/parallel_memory.py needs mpiexec: python3 -m pip install 'riprap[mpi]'")
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    peaks = {}
    with tempfile.TemporaryDirectory() as folder:
        case = write_case(Path(folder), porous=args.porous)
        tiny = write_case(Path(folder), tiny=True)
        command = [mpiexec, "-n", "1", sys.executable, __file__, "--worker", str(tiny),
                   str(Path(folder) / "out_tiny")]
        text = subprocess.run(command, env=env, capture_output=True, text=True, check=True).stdout
        fixed = [json.loads(line[7:]) for line in text.splitlines() if line.startswith("RESULT ")]
        print(f"without a grid (a {fixed[0]['cells']}-cell run): peak {fixed[0]['peak_mb']:.0f} "
              "MB a process", flush=True)
        for processes in args.processes:
            command = [mpiexec, "-n", str(processes), sys.executable, __file__, "--worker",
                       str(case), str(Path(folder) / f"out_{processes}")]
            text = subprocess.run(command, env=env, capture_output=True, text=True, check=True).stdout
            results = [json.loads(line[7:]) for line in text.splitlines()
                       if line.startswith("RESULT ")]
            for r in results:
                grid_part = (r["peak_mb"] - fixed[0]["peak_mb"]) * 2 ** 20 / r["cells"]
                print(f"{processes} process(es), process {r['rank']}: peak {r['peak_mb']:.0f} MB, "
                      f"held after the run {r['held_mb']:.0f} MB ({r['steps']} steps); above the "
                      f"run without a grid: {grid_part:.0f} B per cell of the whole grid",
                      flush=True)
            peaks[processes] = max(r["peak_mb"] for r in results)
        if 4 in args.processes:
            # a restart of the 4 processes' run from its checkpoint (in pieces), on 4 processes
            # (it ends at once: the checkpoint is at the end time)
            command = [mpiexec, "-n", "4", sys.executable, __file__, "--worker", str(case),
                       str(Path(folder) / "out_4_restart"),
                       str(Path(folder) / "out_4" / "checkpoint.npz")]
            text = subprocess.run(command, env=env, capture_output=True, text=True,
                                  check=True).stdout
            for line in text.splitlines():
                if line.startswith("RESULT "):
                    r = json.loads(line[7:])
                    print(f"4 processes restarted from the checkpoint, process {r['rank']}: peak "
                          f"{r['peak_mb']:.0f} MB", flush=True)
    if 1 in peaks and 4 in peaks:
        print(f"METRIC parallel_peak_memory_4_over_1 {peaks[4] / peaks[1]:.3f} ratio")


if __name__ == "__main__":
    main()
