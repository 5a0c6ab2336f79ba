"""Command-line interface: parses arguments and calls the Python API, nothing else.

    riprap demo [--out DIR]            drop rocks and tetrapods into a box (embedded case)
    riprap run CASE.toml [--out DIR] [--restart CHECKPOINT]
    riprap check CASE.toml             validate a case file and report every problem
    riprap info                        versions and threads
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from riprap.errors import RiprapError


def _run_case(path: Path, out: str | None, restart: str | None, quiet: bool) -> int:
    from riprap.case.build import build_simulation
    from riprap.case.load import load_case

    case = load_case(path)
    print(f"riprap: case {path}: {case.body_count} bodies, {len(case.shapes)} shapes, "
          f"{len(case.walls)} wall entries")
    print("riprap: contact pairs combine materials by the smaller friction coefficient, the smaller "
          "restitution and the smaller contact_penalty")
    sim = build_simulation(case, output_directory=out, progress=not quiet)
    summary = sim.run(restart_from=restart)
    print(f"riprap: {summary.end_reason} at t = {summary.simulated_time:.4f} s after {summary.steps} "
          f"steps of {summary.time_step:.3e} s in {summary.wall_time:.1f} s "
          f"({summary.body_steps_per_second:,.0f} body-steps/s); {summary.contacts} contacts, "
          f"max speed {summary.max_speed:.3g} m/s")
    for key, value in summary.outputs.items():
        print(f"riprap: {key}: {value}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="riprap", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="drop rocks and tetrapods into a box until they rest")
    demo.add_argument("--out", default="riprap-demo", help="output directory (default riprap-demo)")
    demo.add_argument("--quiet", action="store_true", help="no progress bar")
    run = sub.add_parser("run", help="run a case file")
    run.add_argument("case", type=Path)
    run.add_argument("--out", default=None, help="output directory (default: [output] directory)")
    run.add_argument("--restart", default=None, help="continue from this checkpoint (.npz)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    check = sub.add_parser("check", help="validate a case file")
    check.add_argument("case", type=Path)
    sub.add_parser("info", help="versions and threads")
    args = parser.parse_args(argv)
    try:
        if args.command == "demo":
            from importlib.resources import as_file, files

            with as_file(files("riprap.data") / "demo.toml") as path:
                return _run_case(Path(path), args.out, None, args.quiet)
        if args.command == "run":
            return _run_case(args.case, args.out, args.restart, args.quiet)
        if args.command == "check":
            from riprap.case.load import load_case

            case = load_case(args.case)
            print(f"{args.case}: valid ({case.body_count} bodies)")
            return 0
        if args.command == "info":
            import numba
            import numpy

            import riprap

            print(f"riprap {riprap.__version__}, numpy {numpy.__version__}, numba {numba.__version__}, "
                  f"threads {numba.get_num_threads()}")
            return 0
    except RiprapError as error:
        print(f"riprap: error: {error}", file=sys.stderr)
        return 2
    return 1
