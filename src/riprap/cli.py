"""Command-line interface: parses arguments and calls the Python API, nothing else.

    riprap demo [--out DIR]            drop rocks and tetrapods into a box (embedded case)
    riprap run CASE.toml [--out DIR] [--restart CHECKPOINT]
    riprap place CASE.toml [--out DIR]   build an armour layer on a slope (pack, pictures, summary)
    riprap analyse PACK_OR_RUN [MORE ...] --out DIR   per-unit contact forces, coordination
                                       numbers, stereonet, factors of safety, report.html
    riprap check CASE.toml             validate a case file and report every problem
    riprap info                        versions and threads
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from riprap.errors import CaseFileError, RiprapError


def _run_case(path: Path, out: str | None, restart: str | None, quiet: bool) -> int:
    from riprap.case.build import build_simulation
    from riprap.case.load import load_case

    case = load_case(path)
    if case.is_fluid:
        return _run_fluid_case(case, path, out, restart, quiet)
    if case.is_placement and case.body_count == 0:
        raise CaseFileError(f"{path} describes an armour placement and has no bodies of its own: "
                            f"run it with 'riprap place {path}'")
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


def _run_fluid_case(case, path: Path, out: str | None, restart: str | None, quiet: bool) -> int:
    from riprap.case.build_fluid import build_fluid_run

    if case.body_count > 0:
        raise CaseFileError(f"{path}: has [fluid] and bodies; solids in the fluid (two-way "
                            "coupling) are not available yet: run them as separate cases")
    run = build_fluid_run(case, output_directory=out, progress=not quiet)
    grid = run.solver.grid
    print(f"riprap: fluid case {path}: {grid.cells[0]} x {grid.cells[1]} x {grid.cells[2]} cells of "
          f"{grid.cell_size:.4g} m ({'2D' if grid.two_dimensional else '3D'}), water "
          f"{run.solver.water_volume():.4g} m^3")
    summary = run.run(restart_from=restart)
    print(f"riprap: {summary.end_reason} at t = {summary.simulated_time:.4f} s after {summary.steps} "
          f"steps ({summary.time_step_min:.2e}..{summary.time_step_max:.2e} s) in "
          f"{summary.wall_time:.1f} s ({summary.cell_updates_per_second:,.0f} cell-updates/s); "
          f"water volume error {summary.water_volume_error:.1e}, pressure iterations "
          f"{summary.pressure_iterations_mean:.1f} (max {summary.pressure_iterations_max})")
    for key, value in summary.outputs.items():
        print(f"riprap: {key}: {value}")
    return 0


def _place_case(path: Path, out: str | None, quiet: bool) -> int:
    from riprap.case.build_placement import run_placement
    from riprap.case.load import load_case

    case = load_case(path)
    print(f"riprap: placement case {path}: {case.armour.unit if case.armour else '?'} units on a "
          f"1:{case.slope.cotangent if case.slope else '?'} slope")
    summary = run_placement(case, output_directory=out, progress=not quiet)
    print(f"riprap: {summary['units_placed']} units placed, {summary['units_at_rest']} at rest, "
          f"{len(summary['units_rolled_off'])} rolled off; packing density coefficient "
          f"{summary['packing_density_coefficient']:.3f} (design "
          f"{summary['design_packing_density_coefficient']:.3f}), porosity "
          f"{summary['porosity']:.3f}, layer thickness {summary['layer_thickness_m']:.3f} m, "
          f"largest overlap {100 * summary['max_overlap_over_dn']:.2f} % of Dn")
    for key, value in summary["outputs"].items():
        print(f"riprap: {key}: {value}")
    return 0


def _analyse(paths: list[Path], out: str | None, frame: int, labels: list[str] | None) -> int:
    from riprap.analysis import analyse, compare_layers

    if len(paths) == 1:
        out = out or str((paths[0] if paths[0].is_dir() else paths[0].parent) / "analysis")
        analysis = analyse(paths[0], out=out, frame=frame)
        layer = analysis.layer
        print(f"riprap: analysed {layer['source']}: {layer['units']} {layer['unit']} units on "
              f"{layer['underlayer_bodies']} underlayer bodies")
        print(f"riprap: coordination number {layer['coordination_number_min']}..."
              f"{layer['coordination_number_max']} (mean {layer['coordination_number_mean']:.2f}); "
              f"largest contact force {layer['max_contact_force_N']:.4g} N "
              f"({layer['max_contact_force_N'] / max(layer['unit_weight_N'], 1e-300):.2f} unit "
              f"weights); smallest factor of safety {layer['factor_of_safety_min']:.3f}, "
              f"{len(layer['units_below_factor_of_safety_1'])} unit(s) below 1")
        print(f"riprap: packing density coefficient {layer['packing_density_coefficient']:.3f} "
              f"(design {layer['design_packing_density_coefficient']:.3f}), porosity "
              f"{layer['porosity']:.3f}, layer thickness {layer['layer_thickness_m']:.3f} m")
        print(f"riprap: report: {layer['outputs']['report']}")
        return 0
    if out is None:
        raise RiprapError("riprap analyse with several packs compares them: give --out DIR")
    analyses = compare_layers(paths, out=out, labels=labels, frame=frame)
    for analysis in analyses:
        layer = analysis.layer
        print(f"riprap: {layer['source']}: packing density {layer['packing_density_coefficient']:.3f}, "
              f"mean coordination {layer['coordination_number_mean']:.2f}, largest contact force "
              f"{layer['max_contact_force_N']:.4g} N, smallest FoS {layer['factor_of_safety_min']:.3f}")
    print(f"riprap: comparison: {Path(out) / 'comparison.html'}")
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
    place = sub.add_parser("place", help="build an armour layer on a slope (POSITIT)")
    place.add_argument("case", type=Path)
    place.add_argument("--out", default=None, help="output directory (default: [output] directory)")
    place.add_argument("--quiet", action="store_true", help="no progress bar")
    analyse = sub.add_parser(
        "analyse", help="analyse an armour layer (a pack folder or a run started from one); "
                        "two or more are compared side by side")
    analyse.add_argument("paths", type=Path, nargs="+", metavar="PACK_OR_RUN")
    analyse.add_argument("--out", default=None,
                         help="output directory (default: PACK/analysis for one pack)")
    analyse.add_argument("--frame", type=int, default=-1,
                         help="frame of a run to analyse (0 the first, -1 the last; default -1)")
    analyse.add_argument("--labels", nargs="+", default=None,
                         help="names of the compared layers (default: their folder names)")
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
        if args.command == "place":
            return _place_case(args.case, args.out, args.quiet)
        if args.command == "analyse":
            return _analyse(args.paths, args.out, args.frame, args.labels)
        if args.command == "check":
            from riprap.case.load import load_case

            case = load_case(args.case)
            what = ("an armour placement" if case.is_placement else
                    f"air and water on {'x'.join(map(str, case.fluid.cells))} cells" if case.is_fluid
                    else f"{case.body_count} bodies")
            print(f"{args.case}: valid ({what})")
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
