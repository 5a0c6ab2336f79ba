"""riprap: numerical breakwater modelling. Armour units and rocks as rigid bodies with potential
contact, armour layers placed on a slope and analysed, air and water flow.

Commands (each has --help):
  riprap demo                      rocks and tetrapods dropped into a box (a minute the first time)
  riprap campaign CASE.toml... --seeds 0 1 2 --out DIR  members (series of other seeds or
                                   designs) on Dask workers, their spread; resumes when run again
  riprap place CASE.toml --out DIR build an armour layer on a slope: pack, pictures, summary
  riprap run CASE.toml --out DIR   run a case: bodies, a placed pack (DIR/pack.toml) or a fluid case
  riprap series CASE.toml --out DIR  a test series ([series]): rising sea states on one structure,
                                   a survey after each, damage curves beside the formulas
  riprap analyse PACK_OR_RUN       contact forces, coordination numbers, stereonet, factors of
                                   safety, packing density and a report.html (also: analyze)
  riprap check CASE.toml           every check that run or place makes, without running
  riprap info                      versions of riprap, Python and the libraries; threads

Case files are TOML; every key is in docs/case-file.md. Examples: examples/. Bad input gives one
line starting 'riprap: error:' and exit status 2; set RIPRAP_TRACEBACK=1 to see where an error came
from.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import riprap
from riprap.case.build import SMOKE_END_TIME, build_simulation, smoke_mode
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case
from riprap.errors import CaseFileError, RiprapError
from riprap.io.json_files import read_json_object
from riprap.io.output_folder import describe_os_error
from riprap.parallel.communicator import launched_processes, world
from riprap.solid.kernels.pair_rule import PAIR_RULE_TEXT
from riprap.work_estimate import warning_line
from riprap.workflows.analyse import analyse, compare_layers
from riprap.workflows.check import check_case
from riprap.workflows.place import run_placement


def _run_case(path: Path, out: str | None, restart: str | None, quiet: bool) -> int:
    case = load_case(path)
    _say_if_smoke()
    if case.is_placement:
        raise CaseFileError(f"{path} describes an armour placement: build the layer with "
                            f"'riprap place {path} --out DIR', then run DIR/pack.toml")
    if case.is_series:
        if restart is not None:
            raise CaseFileError(f"{path} is a test series: it resumes by itself from its steps' "
                                "checkpoints when run again into the same --out folder; drop "
                                "--restart")
        if launched_processes() > 1:
            raise CaseFileError(f"{path} is a test series: its steps run on one process each; "
                                "start it without mpiexec (riprap campaign spreads series over "
                                "machines)")
        return _series_case(path, case, out, quiet)
    if case.is_fluid:
        sim = build_fluid_run(case, output_directory=out, progress=not quiet)
        grid = sim.fluid.grid
        deformable = f" ({len(sim.deformable_bodies)} deformable)" if sim.deformable_bodies else ""
        bodies = (f", {sim.solver.n_bodies + len(sim.deformable_bodies)} bodies{deformable} "
                  "coupled to the flow" if sim.coupled else "")
        # (only process 0 prints, and only it holds the whole grid's water once split)
        water = sim.fluid.water_volume() if world().rank == 0 else 0.0
        print(f"riprap: fluid case {path}: {grid.cells[0]} x {grid.cells[1]} x {grid.cells[2]} "
              f"cells of {grid.cell_size:.4g} m ({'2D' if grid.two_dimensional else '3D'}), water "
              f"{water:.4g} m^3{bodies}")
        _say_filter_layer(sim.filter_layer)
    else:
        print(f"riprap: case {path}: {case.body_count} bodies, {len(case.shapes)} shapes, "
              f"{len(case.walls)} wall entries")
        sim = build_simulation(case, output_directory=out, progress=not quiet)
    if sim.solver.n_bodies:
        print(f"riprap: {PAIR_RULE_TEXT}")
    summary = sim.run(restart_from=restart)
    print(f"riprap: {summary.end_reason} at t = {summary.simulated_time:.4f} s after "
          f"{summary.steps} steps in {summary.wall_time:.1f} s")
    if summary.cells is not None:
        print(f"riprap: fluid: time steps {summary.time_step_min:.2e}..{summary.time_step_max:.2e} "
              f"s, {summary.cell_updates_per_second:,.0f} cell-updates/s; water volume error "
              f"{summary.water_volume_error:.1e}, pressure iterations "
              f"{summary.pressure_iterations_mean:.1f} (max {summary.pressure_iterations_max})")
    if summary.element_steps_per_second is not None:
        print(f"riprap: deformable bodies: {summary.bodies}, steps of {summary.time_step:.3e} s "
              f"({summary.element_steps_per_second:,.0f} element-steps/s), largest tensile "
              f"principal stress {summary.max_tensile_stress / 1e6:.3g} MPa (units.csv), fastest "
              f"node {summary.max_speed:.3g} m/s")
    elif summary.bodies is not None:
        steps = (f"steps of {summary.time_step:.3e} s" if summary.time_step is not None
                 else f"{summary.solid_substeps} contact sub-steps")
        print(f"riprap: bodies: {steps} ({summary.body_steps_per_second:,.0f} body-steps/s); "
              f"{summary.contacts} contacts, max speed {summary.max_speed:.3g} m/s")
    for key, value in summary.outputs.items():
        print(f"riprap: {key}: {value}")
    if "waves_report" in summary.outputs:
        _say_waves_report(Path(summary.outputs["waves_report"]))
    return 0


def _series_case(path: Path, case, out: str | None, quiet: bool) -> int:
    from riprap.workflows.series import run_series, series_summary_lines  # lazy: series only

    print(f"riprap: test series {path}: {len(case.series_steps)} steps, {case.body_count} bodies")
    results = run_series(case, output_directory=out, progress=not quiet)
    if results.get("run_mode") == "smoke":
        print(f"riprap: SMOKE RUN: {results['run_mode_note']}; the figures below are not a "
              "damage curve")
    for line in series_summary_lines(results):
        print(line)
    for key, value in results["outputs"].items():
        print(f"riprap: {key}: {value}")
    return 0


def _campaign(args) -> int:
    from riprap.workflows.campaign import members_of, run_campaign  # lazy: Dask is optional

    _say_if_smoke()
    members = members_of(args.cases, args.seeds)
    result = run_campaign(members, args.out, workers=args.workers, threads=args.threads,
                          scheduler=args.scheduler)
    for case_name, columns in result["spread"].items():
        for k, step in enumerate(columns["step"]):
            print(f"riprap: {case_name} step {step}: N_od {columns['N_od_mean'][k]:.3g} "
                  f"({columns['N_od_min'][k]:.3g}..{columns['N_od_max'][k]:.3g}) over "
                  f"{columns['members'][k]} members, S {columns['S_mean'][k]:.3g}")
    if result.get("run_mode") == "smoke":
        print(f"riprap: SMOKE RUN: {result['run_mode_note']}; the figures above are not results")
    print(f"riprap: campaign results: {Path(args.out) / 'campaign_results.json'}")
    return 0


def _say_waves_report(path: Path) -> None:
    """What the flume run's wave analysis could not compute, and its cautions (few waves)."""
    report = read_json_object(path, "waves report", "the run wrote it just now")
    for item in report.get("not_computed", []):
        print(f"riprap: waves: not computed: {item}")
    for item in report.get("cautions", []):
        print(f"riprap: waves: caution: {item}")


def _say_if_smoke() -> None:
    if smoke_mode():
        print(f"riprap: SMOKE MODE (RIPRAP_SMOKE=1): every run is cut to {SMOKE_END_TIME} s of "
              "simulated time; its figures are not results", file=sys.stderr)


def _place_case(path: Path, out: str | None, quiet: bool) -> int:
    case = load_case(path)
    _say_if_smoke()
    if case.armour and case.slope:      # else run_placement says which tables are missing
        print(f"riprap: placement case {path}: {case.armour.unit} units on a "
              f"1:{case.slope.cotangent} slope")
    summary = run_placement(case, output_directory=out, progress=not quiet)
    if case.armour_stone is not None:
        _say_stone_layer(summary)
        return 0
    if summary.get("smoke"):
        print(f"riprap: SMOKE MODE: {summary['units_placed']} units placed on "
              f"{summary['underlayer_rocks']} rocks; {summary['smoke_note']}, so none are "
              "reported here (summary.json has \"smoke\": true)")
        for key, value in summary["outputs"].items():
            print(f"riprap: {key}: {value}")
        return 0
    print(f"riprap: {summary['units_placed']} units placed, {summary['units_at_rest']} at rest, "
          f"{len(summary['units_rolled_off'])} rolled off; {_layer_figures(summary)}, "
          f"largest overlap {100 * summary['max_overlap_over_dn']:.2f} % of Dn")
    for key, value in summary["outputs"].items():
        print(f"riprap: {key}: {value}")
    return 0


def _say_stone_layer(summary: dict) -> None:
    """A rock armour placement's layer beside its design, and its stones' grading."""
    measured, design = summary["measured"], summary["design"]
    grading = summary["grading"]
    smoke = " (SMOKE MODE: the runs were cut short; these figures are no layer's)" \
        if summary.get("smoke") else ""
    print(f"riprap: {measured['stones_placed']} stones in {design['layers']} layer(s), "
          f"{measured['stones_rolled_off']} rolled off{smoke}; layer thickness coefficient k_t "
          f"{_measured(measured['layer_thickness_coefficient'], '{:.3f}')} (design "
          f"{design['layer_thickness_coefficient']:g}), porosity "
          f"{_measured(measured['porosity'], '{:.3f}')} (design {design['porosity']:g}), stones "
          f"per m^2 {_measured(measured['stones_per_area'], '{:.4g}')} (design "
          f"{design['stones_per_area']:.4g})")
    berm = measured.get("toe_berm")
    if berm:
        print(f"riprap: toe berm {design['toe_berm_width_m']:g} m wide: {berm['stones']} stones, "
              f"top {berm['top_above_bed_m']:.3g} m above the bed (design "
              f"{berm['design_top_above_bed_m']:.3g} m), {berm['stones_off_the_bed']} ended on "
              "the face")
    print(f"riprap: the stones placed: M50 {grading['placed']['M50_kg']:.4g} kg, M85/M15 "
          f"{grading['placed']['M85_over_M15']:.3g} (the grading: {grading['asked']['M50_kg']:.4g}"
          f" kg, {grading['asked']['M85_over_M15']:.3g})")
    for key, value in summary["outputs"].items():
        print(f"riprap: {key}: {value}")


def _measured(value, form: str) -> str:
    """``value`` in ``form``, or "not measured" where it is null or NaN (summary.json's null)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value == value:
        return form.format(value)
    return "not measured"


def _layer_figures(layer: dict) -> str:
    """The layer's packing density coefficient, porosity and thickness (riprap place, riprap
    analyse), each "not measured" where it was not, and why."""
    text = (f"packing density coefficient {_measured(layer['packing_density_coefficient'], '{:.3f}')} "
            f"(design {_measured(layer.get('design_packing_density_coefficient'), '{:.3f}')}), "
            f"porosity {_measured(layer['porosity'], '{:.3f}')}, layer thickness "
            f"{_measured(layer['layer_thickness_m'], '{:.3f} m')}")
    why = layer.get("layer_figures_not_measured")
    return text + (f" (not measured: {why})" if why else "")


def _analyse(paths: list[Path], out: str | None, frame: int, labels: list[str] | None) -> int:
    if len(paths) == 1:
        out = out or str((paths[0] if paths[0].is_dir() else paths[0].parent) / "analysis")
        analysis = analyse(paths[0], out=out, frame=frame)
        layer = analysis.layer
        print(f"riprap: analysed {layer['source']}: {layer['units']} {layer['unit']} units on "
              f"{layer['underlayer_bodies']} underlayer bodies")
        if layer.get("coordination_number_mean") is not None:
            print(f"riprap: coordination number {layer['coordination_number_min']}..."
                  f"{layer['coordination_number_max']} (mean {layer['coordination_number_mean']:.2f}); "
                  f"largest contact force {layer['max_contact_force_N']:.4g} N "
                  f"({layer['max_contact_force_N'] / max(layer['unit_weight_N'], 1e-300):.2f} unit "
                  f"weights); smallest factor of safety {layer['factor_of_safety_min']:.3f}, "
                  f"{len(layer['units_below_factor_of_safety_1'])} unit(s) below 1")
        else:
            print("riprap: no contacts were recorded (a coupled run): no coordination numbers, "
                  "contact forces or factors of safety")
        if "max_displacement_m" in layer:
            print(f"riprap: displacements since {layer['displacement_reference']}: largest "
                  f"{layer['max_displacement_m']:.3g} m ({layer['max_displacement_over_dn']:.2f} Dn), "
                  f"mean {layer['mean_displacement_m']:.3g} m; {len(layer['units_moved'])} unit(s) "
                  "moved more than 0.1 Dn")
        print(f"riprap: {_layer_figures(layer)}")
        _say_flume_test(layer.get("flume_test"))
        print(f"riprap: report: {layer['outputs']['report']}")
        return 0
    if out is None:
        raise RiprapError("riprap analyse with several packs compares them: give --out DIR")
    analyses = compare_layers(paths, out=out, labels=labels, frame=frame)
    for analysis in analyses:
        layer = analysis.layer
        print(f"riprap: {layer['source']}: packing density "
              f"{_measured(layer['packing_density_coefficient'], '{:.3f}')}, "
              f"mean coordination {layer['coordination_number_mean']:.2f}, largest contact force "
              f"{layer['max_contact_force_N']:.4g} N, smallest FoS {layer['factor_of_safety_min']:.3f}")
    print(f"riprap: comparison: {Path(out) / 'comparison.html'}")
    return 0


def _say_flume_test(flume: dict | None) -> None:
    """The flume test's stability number, or what could not be computed and why; cautions."""
    if flume is None:
        return
    if flume.get("stability_number") is not None:
        hudson = flume.get("hudson")
        print(f"riprap: flume test: Hm0 {flume['Hm0_m']:.3g} m ({flume['wave_height_source']}), "
              f"stability number {flume['stability_number']:.3g}"
              + (f" (Hudson's {hudson['stability_number']:.3g})" if hudson else ""))
    for item in flume.get("not_computed", []):
        print(f"riprap: flume test: not computed: {item}")
    for item in flume.get("cautions", []):
        print(f"riprap: flume test: caution: {item}")


def _say_filter_layer(layer, prefix: str = "riprap: ") -> None:
    """The contact-only bodies and the filter zones the flow sees in their place, if any."""
    if layer is None:
        return
    for line in layer.lines():
        print(f"{prefix}filter layer: {line}")


def _check(path: Path, out: str | None, restart: str | None = None) -> int:
    report = check_case(load_case(path), output_directory=out, restart=restart)
    print(f"{path}: valid ({report.description})")
    print(f"  checked: {'; '.join(report.checked)}")
    for item in report.not_checked:
        print(f"  not checked (only a run can tell): {item}")
    _say_filter_layer(report.filter_layer, prefix="  ")
    if report.friction:
        print("  friction of the pairs of materials that meet:")
        for pair in report.friction:
            print(f"    {'-'.join(pair.materials)}: {pair.friction_coefficient:g} ({pair.source})")
    return 0


def _info() -> int:
    import platform

    import gmsh
    import matplotlib
    import meshio
    import numba
    import numpy
    import scipy

    print(f"riprap {riprap.__version__} ({Path(riprap.__file__).parent})")
    print(f"Python {platform.python_version()} ({sys.executable}), {platform.platform()}")
    print(f"numpy {numpy.__version__}, numba {numba.__version__} ({numba.get_num_threads()} threads), "
          f"scipy {scipy.__version__}, gmsh {gmsh.__version__}, meshio {meshio.__version__}, "
          f"matplotlib {matplotlib.__version__}")
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="riprap", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    demo = sub.add_parser("demo", help="drop rocks and tetrapods into a box until they rest")
    demo.add_argument("--out", default="riprap-demo", help="output folder (default riprap-demo)")
    demo.add_argument("--quiet", action="store_true", help="no progress bar")
    run = sub.add_parser("run", help="run a case file (bodies, a placed pack, or air and water)")
    run.add_argument("case", type=Path, help="the case file (.toml), e.g. out/layer/pack.toml")
    run.add_argument("--out", default=None, help="output folder (default: [output] directory)")
    run.add_argument("--restart", default=None,
                     help="continue from this checkpoint (.npz) with the case's settings")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    series = sub.add_parser("series", help="run a test series ([series]: rising sea states on one "
                                           "structure, surveyed after each step)")
    series.add_argument("case", type=Path, help="a case file with [series] and [[series_steps]]")
    series.add_argument("--out", default=None, help="output folder (default: [output] directory)")
    series.add_argument("--quiet", action="store_true", help="no progress bar")
    campaign = sub.add_parser("campaign", help="test series of other seeds or designs as Dask "
                                               "tasks (dask.distributed), with their spread")
    campaign.add_argument("cases", type=Path, nargs="+", metavar="CASE",
                          help="series case files (each with [series])")
    campaign.add_argument("--seeds", type=int, nargs="+", default=[0],
                          help="offsets added to every step's seed, one member each (default 0)")
    campaign.add_argument("--out", required=True, help="the campaign's folder")
    campaign.add_argument("--workers", type=int, default=2,
                          help="worker processes of the local cluster (default 2)")
    campaign.add_argument("--threads", type=int, default=1,
                          help="numba threads of each member (default 1)")
    campaign.add_argument("--scheduler", default=None,
                          help="address of a running Dask scheduler (tcp://host:8786) instead of "
                               "a local cluster")
    place = sub.add_parser("place", help="build an armour layer on a slope (POSITIT)")
    place.add_argument("case", type=Path, help="a placement case file (.toml)")
    place.add_argument("--out", default=None, help="output folder (default: [output] directory)")
    place.add_argument("--quiet", action="store_true", help="no progress bar")
    analyse = sub.add_parser(
        "analyse", aliases=["analyze"],
        help="analyse an armour layer (a pack folder or a run started from one); two or more are "
             "compared side by side")
    analyse.add_argument("paths", type=Path, nargs="+", metavar="PACK_OR_RUN")
    analyse.add_argument("--out", default=None,
                         help="output folder (default: PACK/analysis for one pack)")
    analyse.add_argument("--frame", type=int, default=-1,
                         help="frame of a run to analyse (0 the first, -1 the last; default -1)")
    analyse.add_argument("--labels", nargs="+", default=None,
                         help="names of the compared layers (default: their folder names)")
    check = sub.add_parser("check", help="every check run or place makes, without running")
    check.add_argument("case", type=Path)
    check.add_argument("--out", default=None,
                       help="output folder to check (default: [output] directory)")
    check.add_argument("--restart", default=None,
                       help="also check a restart from this checkpoint (.npz), as run --restart")
    sub.add_parser("info", help="versions of riprap, Python and its libraries; threads")
    return parser


# The commands a run over several processes (mpiexec -n N) carries out together; the others would
# each do the whole job on every process, writing the same files at once.
_SPLIT_COMMANDS = ("run", "demo")


def _dispatch(args) -> int:
    if launched_processes() > 1 and args.command not in _SPLIT_COMMANDS:
        raise CaseFileError(f"riprap {args.command} runs on one process: start it without mpiexec "
                            f"(only {' and '.join(_SPLIT_COMMANDS)} spread one run over several "
                            "processes)")
    if args.command == "demo":
        from importlib.resources import as_file, files

        with as_file(files("riprap.data") / "demo.toml") as path:
            return _run_case(Path(path), args.out, None, args.quiet)
    if args.command == "run":
        return _run_case(args.case, args.out, args.restart, args.quiet)
    if args.command == "series":
        case = load_case(args.case)
        if not case.is_series:
            raise CaseFileError(f"{args.case} has no [series] table: add [series] and "
                                "[[series_steps]], or run it with riprap run")
        _say_if_smoke()
        return _series_case(args.case, case, args.out, args.quiet)
    if args.command == "campaign":
        return _campaign(args)
    if args.command == "place":
        return _place_case(args.case, args.out, args.quiet)
    if args.command in ("analyse", "analyze"):
        return _analyse(args.paths, args.out, args.frame, args.labels)
    if args.command == "check":
        return _check(args.case, args.out, args.restart)
    return _info()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """riprap's own warnings as one line each; numpy's RuntimeWarnings are not shown (riprap checks
    that the state stays finite and names the body and time when it does not)."""
    text = warning_line(message, category)
    if text is not None:
        print(text, file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 done, 2 could not, 130 interrupted)."""
    import os
    import warnings

    args = _parser().parse_args(argv)
    several = launched_processes() > 1
    if several and world().rank != 0:
        # the other processes of a run over several say nothing but their errors
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - held for the process's life
    if os.environ.get("RIPRAP_TRACEBACK", "") == "1":
        return _dispatch(args)
    previous = warnings.showwarning
    warnings.showwarning = _show_warning if not (several and world().rank != 0) else _silent
    try:
        return _dispatch(args)
    except RiprapError as error:
        print(f"riprap: error: {error}", file=sys.stderr)
    except OSError as error:
        print(f"riprap: error: {describe_os_error(error)}", file=sys.stderr)
    except MemoryError:
        print("riprap: error: out of memory; use fewer bodies, tetrahedra or cells "
              "(riprap check estimates the size of a case)", file=sys.stderr)
    except KeyboardInterrupt:
        print("riprap: interrupted; frames and checkpoints written so far are complete",
              file=sys.stderr)
        return 130
    except SystemExit as error:
        # A library (meshio) calling sys.exit must not end riprap without a word.
        if error.code in (0, None):
            return 0
        print(f"riprap: error: a library stopped with: {error.code}", file=sys.stderr)
    except Exception as error:  # noqa: BLE001 - the last line of defence for the user
        print(f"riprap: error: {type(error).__name__}: {error} (riprap did not expect this: it may "
              "be an input riprap does not check yet, or a bug; RIPRAP_TRACEBACK=1 shows where, "
              "please report it)", file=sys.stderr)
    finally:
        warnings.showwarning = previous
    if several:
        # The other processes may be waiting for this one: end them all now, not at a timeout.
        processes = world()
        print(f"riprap: {processes.name} stopped the run (the error above); ending every "
              "process", file=sys.stderr, flush=True)
        processes.abort(2)
    return 2


def _silent(*args, **kwargs) -> None:
    """Warnings of the other processes of a split run: process 0 shows them once."""
