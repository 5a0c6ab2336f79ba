"""``riprap series`` (and ``riprap run`` on a case with ``[series]``): a test series, the unit of
work of a hydraulic stability study (``docs/campaign.md``).

The steps run one after the other, each in its own folder (``step_01``, ``step_02``, ...), each an
ordinary run folder with its own case file (``step.toml``, written by
``riprap.case.series_steps``): step k starts from the bodies where step k-1 left them (at rest,
contact history kept: ``Simulation.start_bodies_at_rest_from``) and from still water. After each
step its *survey*: the layer analysis of its last frame with displacements and the eroded area
counted from the series' start (``survey/``: units.csv, layer_summary.json, profiles and face
pictures, report.html) with its *per-wave table* (``survey/per_wave.csv``). At the end the damage curves
(``damage_curve.csv``, ``damage_curve.png``, ``series_results.json``, ``report.html``) beside the
design formulas.

Resuming: the series folder records the riprap version, the run mode (smoke or full), the case's
keys and a fingerprint of them (``series.json``, ``riprap.workflows.series_record``); a folder of
another version, or one whose steps were run from other keys, is refused before anything runs,
naming each changed key with its old and new values. A step with its ``summary.json`` is done and
is not run again; a step with a checkpoint is continued from it; the others start from the step
before. Smoke steps (``RIPRAP_SMOKE=1``) are never taken for results: a full run sets them aside
(``smoke_run/``) and runs the steps again, and a smoke run over full steps is refused. When only
a survey key changed (``[series] displacement_threshold``) the finished steps are surveyed again,
their own files untouched. Every step is checked (the flume can carry its sea) before the first
one runs.
"""
from __future__ import annotations

import math
import time as wallclock
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap.analysis.series_damage import ROCK_FORMULA_COLUMNS, rock_formula_curves, series_curve
from riprap.case.build_fluid import build_fluid_run, build_fluid_solver
from riprap.case.load import parse_case
from riprap.case.series_steps import mean_zero_crossing_period, step_case_text, step_seas
from riprap.errors import CaseFileError
from riprap.io.json_files import read_json_object, write_json
from riprap.io.output_folder import prepare_output_folder, remove_folder
from riprap.io.csv_tables import read_columns_csv, write_columns_csv
from riprap.io.series_report import write_series_report
from riprap.workflows.analyse import analyse
from riprap.work_estimate import duration_words, flume_run_seconds
from riprap.workflows.series_calibration import (HEIGHT_TOLERANCE, PERIOD_TOLERANCE,
                                                 calibrate_series, calibration_cost_seconds,
                                                 calibration_folder, read_calibration)
from riprap.workflows.series_progress import SERIES_LOG, SeriesLog, StepProgress
from riprap.workflows.series_record import (SERIES_RECORD, claim_series_folder, run_mode,
                                            smoke_note, series_fingerprint, series_record,
                                            set_smoke_steps_aside)

__all__ = ["run_series", "check_series", "series_wall_seconds", "series_summary_lines",
           "series_fingerprint",
           "SERIES_RECORD", "step_folder"]

def step_folder(out: Path, number: int) -> Path:
    """The folder of step ``number`` (from 1)."""
    return Path(out) / f"step_{number:02d}"


@dataclass(frozen=True)
class _Step:
    sea: object
    text: str
    case: object
    folder: Path
    maker: object = None        # the wave maker's calibration of the step (None: gain 1)


def _steps(case, out: Path, seed_offset: int = 0, calibration: dict | None = None
           ) -> list[_Step]:
    """Every step's sea, case text and case, each checked as ``riprap run`` checks a flume (the
    flume can carry the sea) before anything runs; ``calibration``: the wave maker's per step
    (``riprap.workflows.series_calibration``), by step number."""
    steps = []
    for sea in step_seas(case, seed_offset):
        folder = step_folder(out, sea.number)
        maker = (calibration or {}).get(sea.number)
        text = (step_case_text(case, sea) if maker is None
                else step_case_text(case, sea, maker.gain, maker.period_factor))
        where = (f"{case.source} [[series_steps]] step {sea.number} (Hm0 = "
                 f"{sea.significant_height:g} m, Tp = {sea.peak_period:.3g} s)")
        try:
            step_case = parse_case(text, source=str(folder / "step.toml"), base_dir=folder)
            build_fluid_solver(step_case)
        except CaseFileError as error:
            message = str(error).replace(str(folder / "step.toml"), "step.toml")
            raise CaseFileError(f"{where}: {message}") from None
        steps.append(_Step(sea, text, step_case, folder, maker))
    return steps


def _record(case, steps: list[_Step], seed_offset: int = 0) -> dict:
    return series_record(case, [
        {"step": s.sea.number, "Hm0_m": s.sea.significant_height, "Tp_s": s.sea.peak_period,
         "peak_enhancement": s.sea.peak_enhancement, "seed": s.sea.seed, "waves": s.sea.waves,
         "sea_duration_s": s.sea.duration, "end_time_s": s.sea.end_time} for s in steps],
        seed_offset)


def check_series(case, output_directory=None, seed_offset: int = 0,
                 calibration_directory=None) -> list[str]:
    """Every check ``run_series`` makes before it runs (each step's flume, the bodies of the
    first step, the output folder's series record, a wave calibration kept before); returns what
    was checked, in words."""
    out = Path(output_directory or case.output.directory)
    steps = _steps(case, out, seed_offset)
    first = build_fluid_run(steps[0].case, output_directory=steps[0].folder, progress=False)
    claim = claim_series_folder(out, _record(case, steps, seed_offset))
    layer = first.filter_layer
    seconds, basis = series_wall_seconds(case, seed_offset)
    return [f"{len(steps)} steps: each step's sea in the flume (as [waves]), Hm0 "
            + ", ".join(f"{s.sea.significant_height:g}" for s in steps) + " m",
            f"cost: about {duration_words(seconds)} of wall time for the series ({basis}); a "
            "campaign runs one member (series) per worker at once",
            *_calibration_lines(case, out, calibration_directory),
            f"bodies of the first step ({case.body_count})",
            *([] if layer is None
              else [f"filter layer: {line}" for line in layer.lines(entries=False)]),
            f"the series folder {out} (a series of this case, run mode and riprap version, or "
            "none)" + (f": {claim.note}" if claim.note else "")]


def _calibration_lines(case, out: Path, calibration_directory=None) -> list[str]:
    """What wave calibration the series will run, and its cost, in words."""
    if case.series.wave_calibration == "none":
        return ["wave calibration: none ([series] wave_calibration = \"none\"): the wave maker "
                "makes the asked sea; the steps' incident Hm0 at the toe is what the flume lets "
                "through"]
    folder = Path(calibration_directory or calibration_folder(case, out))
    done = read_calibration(case, folder)       # refuses a folder of another flume or sea
    seconds, runs = calibration_cost_seconds(case)
    count = len(case.series_steps)
    return [f"wave calibration: each step's sea run first without the bodies until the incident "
            f"Hm0 at the toe is within {HEIGHT_TOLERANCE:.0%} and Tp within "
            f"{PERIOD_TOLERANCE:.0%} of the asked ones, kept in {folder}: "
            + (f"{len(done)} of {count} steps calibrated before; " if done else "")
            + f"about {runs} runs, {duration_words(seconds)} of wall time for the {count} "
            f"step{'s' if count > 1 else ''} "
            "(two runs a step, one cell across the flume where nothing varies across it)"]


def series_wall_seconds(case, seed_offset: int = 0) -> tuple[float, str]:
    """The wall seconds the series of ``case`` is likely to take on 2 cores
    (``riprap.work_estimate.flume_run_seconds`` over every step's simulated time) and what the
    estimate stands on, in words."""
    fluid = case.fluid
    cells = int(np.prod(fluid.cells))
    cell_size = float(min((high - low) / count for high, low, count
                          in zip(fluid.upper, fluid.lower, fluid.cells)))
    depth = case.waves.still_water_level - fluid.lower[2]
    simulated = sum(sea.end_time for sea in step_seas(case, seed_offset))
    seconds = flume_run_seconds(simulated_time=simulated, cells=cells, cell_size=cell_size,
                                depth=depth, gravity=float(-case.simulation.gravity[2]))
    return seconds, (f"{simulated:.4g} s simulated on {cells:,} cells of {cell_size:.3g} m in "
                     f"{depth:.3g} m of water, at examples/10's measured pace on 2 cores, "
                     "within a factor of 2-3")


def run_series(case, *, output_directory=None, progress: bool = True, say=print,
               seed_offset: int = 0, log_warnings: bool = False,
               calibration_directory=None) -> dict:
    """Run the test series of ``case`` (a case with ``[series]``) into ``output_directory``
    (default ``[output] directory``), every step's seed raised by ``seed_offset`` (a campaign's
    member); returns the series results (``series_results.json``). Every message is said
    (``say``) and kept in the folder's ``series.log`` with each step's progress;
    ``log_warnings``: warnings go there too, as ``riprap: warning:`` lines, instead of being
    printed by Python (a campaign's worker). ``calibration_directory``: the wave calibration's
    folder (``[series] wave_calibration``; default ``series_calibration.calibration_folder``)."""
    log = SeriesLog(say)
    if not log_warnings:
        return _run_series(case, output_directory, progress, log, seed_offset,
                           calibration_directory)
    with log.warnings_logged():
        return _run_series(case, output_directory, progress, log, seed_offset,
                           calibration_directory)


def _run_series(case, output_directory, progress: bool, say: SeriesLog,
                seed_offset: int, calibration_directory=None) -> dict:
    if not case.is_series:
        raise CaseFileError(f"{case.source}: has no [series] table: run it with riprap run")
    out = Path(output_directory or case.output.directory)
    steps = _steps(case, out, seed_offset)
    record = _record(case, steps, seed_offset)
    claim = claim_series_folder(out, record)
    prepare_output_folder(out)
    if claim.note:
        say(f"riprap: series folder {out}: {claim.note}")
    if claim.set_smoke_aside:
        set_smoke_steps_aside(out)
    say.open(out / SERIES_LOG)
    write_json(out / SERIES_RECORD, record)
    if case.series.wave_calibration != "none":
        folder = Path(calibration_directory or calibration_folder(case, out))
        made = {c.step: c for c in calibrate_series(case, folder, say=say)}
        if made:
            steps = _steps(case, out, seed_offset, made)
    total = sum(s.sea.end_time for s in steps)
    simulated, wall = 0.0, 0.0
    for index, step in enumerate(steps):
        sea = step.sea
        done = (step.folder / "summary.json").is_file()
        if done:
            say(f"riprap: series step {sea.number}/{len(steps)}: done before, not run again "
                f"({step.folder})")
            # its pace counts in the estimate of the time to go (a resumed step's summary has
            # the wall time of its last part only: the estimate is then a little short)
            wall += float(read_json_object(step.folder / "summary.json", "step summary",
                                           "delete the step's folder to run it again")
                          .get("wall_time", 0.0))
        else:
            to_go = ("" if simulated == 0 or wall == 0 else
                     f"; about {duration_words((total - simulated) * wall / simulated)} of the "
                     "series to go at the pace so far")
            say(f"riprap: series step {sea.number}/{len(steps)}: Hm0 = {sea.significant_height:g} "
                f"m, Tp = {sea.peak_period:.3g} s, {sea.duration:.4g} s of sea"
                + (f" (~{sea.waves} waves)" if sea.waves else "")
                + ("" if step.maker is None else
                   f", the wave maker at Hm0 x {step.maker.gain:.3f}, Tp x "
                   f"{step.maker.period_factor:.3f} (calibrated)")
                + f", {sea.end_time:.4g} s simulated{to_go}")
            started = wallclock.perf_counter()
            _run_step(step, steps[index - 1] if index else None, len(steps), progress,
                      StepProgress(say, label=f"series step {sea.number}/{len(steps)}",
                                   end_time=sea.end_time, sea_duration=sea.duration,
                                   waves=sea.waves or sea.duration / mean_zero_crossing_period(
                                       sea.peak_period, sea.peak_enhancement),
                                   later_simulated_s=total - simulated - sea.end_time))
            wall += wallclock.perf_counter() - started
        simulated += sea.end_time
        if index == 0 and not (out / "start" / "layer_summary.json").is_file():
            # the layer as built, before the first wave: the "before" of every survey's pictures
            analyse(step.folder, out=out / "start", frame=0)
        _survey(step, steps[0].folder, case, say)
    results = _series_results(out, steps, case)
    write_json(out / "series_results.json", results)
    write_columns_csv(out / "damage_curve.csv", results["curve"])
    results["outputs"] = write_series_report(out, results)
    write_json(out / "series_results.json", results)
    return results


def _run_step(step: _Step, before: _Step | None, count: int, progress: bool,
              progress_log: StepProgress) -> None:
    folder = step.folder
    prepare_output_folder(folder)
    (folder / "step.toml").write_text(step.text, encoding="utf-8")
    sim = build_fluid_run(step.case, output_directory=folder, progress=progress)
    progress_log.run_ends_at(sim.end_time)
    sim.add_writer(progress_log)
    sim.case_file = str((folder / "step.toml").resolve())
    sea = step.sea
    sim.progress_label = (f"step {sea.number}/{count}, Hm0 {sea.significant_height:g} m"
                          + (f", {sea.waves} waves" if sea.waves else ""))
    checkpoint = folder / "checkpoint.npz"
    if checkpoint.is_file():
        sim.run(restart_from=checkpoint)
        return
    if before is not None:
        sim.start_bodies_at_rest_from(before.folder / "checkpoint.npz")
    sim.run()


def _survey(step: _Step, first: Path, case, say) -> None:
    """The survey after a step (``survey/``: the layer analysis from the series' start, with its
    ``per_wave.csv``), unless written before."""
    survey = step.folder / "survey"
    threshold = case.series.displacement_threshold
    if (survey / "layer_summary.json").is_file():
        before = read_json_object(survey / "layer_summary.json", "survey's layer summary",
                                  "delete the step's survey folder to make it again"
                                  ).get("damage_threshold_over_dn", threshold)
        if before == threshold:
            return
        say(f"riprap: series step {step.sea.number}: surveyed again, [series] "
            f"displacement_threshold {before:g} -> {threshold:g} (the step is not run again)")
        remove_folder(survey)
    analysis = analyse(step.folder, out=survey, reference_run=first,
                       displaced_threshold_dn=threshold)
    layer = analysis.layer
    say(f"riprap: series step {step.sea.number} survey: {len(layer.get('units_displaced', []))} "
        f"unit(s) displaced more than {threshold:g} Dn since the start, N_od = "
        f"{layer.get('damage_number_nod', math.nan):.3g}, S = "
        f"{layer.get('damage_level_s', math.nan):.3g}")


def _rock_curves(curve: dict, measured_at_toe: list, last: dict) -> dict:
    """A rock series' curve gains T_m-1,0 at the toe, the Rock Manual class of each step's S and
    the three rock formulas' S, cumulative over the steps (the structure's P and core from the
    last surveyed step's report); returns the formulas' record for the results."""
    rocks = [m.get("rock") or {} for m in measured_at_toe]
    curve["Tm_1_0_s"] = [_number(r.get("spectral_period_s")) for r in rocks]
    curve["rock_damage_class"] = [r.get("damage_class", "") for r in rocks]
    rock = last.get("rock") or {}
    if "notional_permeability" not in rock:
        for column in ROCK_FORMULA_COLUMNS:
            curve[column] = [math.nan] * len(rocks)
        return {"note": "no step's survey has the rock section (no waves measured at the toe)"}
    sea_states = [(h, t, n) for h, t, n in zip(curve["Hm0_m"], curve["Tm_1_0_s"],
                                                 curve["waves"])]
    curve.update(rock_formula_curves(
        sea_states, slope_cot=float(last["slope_cot"]), delta=float(last["relative_density"]),
        nominal_diameter=float(last["nominal_diameter_m"]),
        permeability=float(rock["notional_permeability"]),
        core_nominal_diameter=float(rock["core_dn50_m"])))
    return {"notional_permeability": rock["notional_permeability"],
            "notional_permeability_reason": rock.get("notional_permeability_reason"),
            "core_dn50_m": rock["core_dn50_m"], "core": rock.get("core"),
            "filter_dn50_m": rock.get("filter_dn50_m"),
            "damage_thresholds": rock.get("damage_class_thresholds"),
            "columns": ROCK_FORMULA_COLUMNS,
            "sources": "Van der Meer (2021) with T_m-1,0 and P; Van Gent et al. (2003) with "
                       "D_n50,core; Etemad-Shahidi et al. (2020, corrigendum 2022) with C_p; "
                       "damage carried between steps as equivalent waves (Van der Meer 1988); "
                       "damage classes: The Rock Manual (2007) Table 5.22"}


def _series_results(out: Path, steps: list[_Step], case) -> dict:
    """The damage curve from every step's survey and per-wave table, beside the formulas."""
    rows, flume, per_wave, counted_so_far, unmeasured = [], {}, {}, 0, {}
    measured_at_toe = []
    for step in steps:
        folder = step.folder
        layer = read_json_object(folder / "survey" / "layer_summary.json", "layer summary",
                                 "riprap series wrote it after the step")
        flume = layer.get("flume_test") or {}
        measured_at_toe.append(flume)
        if not isinstance(flume.get("Hm0_m"), (int, float)):
            unmeasured[step.sea.number] = _why_not_measured(flume)
        waves = {"overtopping_m3_per_m": [], "wave": []}
        if (folder / "survey" / "per_wave.csv").is_file():
            waves = read_columns_csv(folder / "survey" / "per_wave.csv")
        counted = len(waves["wave"])
        if counted:
            per_wave[step.sea.number] = {
                "cumulative_wave": [counted_so_far + int(w) for w in waves["wave"]],
                "N_od": [float(v) for v in waves["N_od"]]}
        counted_so_far += counted
        volume = float(np.nansum(waves["overtopping_m3_per_m"])) if counted else math.nan
        rows.append({"step": step.sea.number,
                     "Hm0_m": _number(flume.get("Hm0_m")),
                     "Tm_s": _number(flume.get("Tz_s")),
                     "waves": counted,
                     "units_displaced": len(layer.get("units_displaced", [])),
                     "N_od": _number(layer.get("damage_number_nod")),
                     "S": _number(layer.get("damage_level_s")),
                     "rocking_events": _number(layer.get("rocking_events")),
                     "q_m3_s_m": volume / step.sea.duration})
    over = next((g for g in case.gauges if g.type == "overtopping"), None)
    freeboard = (over.parameters["position"][2] - case.waves.still_water_level
                 if over is not None else None)
    crest_width, crest_width_source = _crest_width(over, flume)
    results = series_curve(rows, unit_kind=str(flume.get("unit", "")),
                           nominal_diameter=float(flume.get("nominal_diameter_m", math.nan)),
                           delta=float(flume.get("relative_density", math.nan)),
                           slope_cot=float(flume.get("slope_cot", math.nan)), freeboard=freeboard,
                           crest_width=crest_width, crest_width_source=crest_width_source)
    # asked against measured, per step (the wave maker's calibration, issue 54)
    curve = results["curve"]
    curve["asked_Hm0_m"] = [s.sea.significant_height for s in steps]
    curve["asked_Tp_s"] = [s.sea.peak_period for s in steps]
    curve["Tp_s"] = [_number(m.get("incident_Tp_s")) for m in measured_at_toe]
    curve["reflection_coefficient"] = [_number(m.get("reflection_coefficient"))
                                       for m in measured_at_toe]
    curve["wave_maker_gain"] = [s.maker.gain if s.maker is not None else 1.0 for s in steps]
    if flume.get("unit") == "armour_stone":
        results["formulas"]["rock"] = _rock_curves(curve, measured_at_toe, flume)
    results["wave_calibration"] = case.series.wave_calibration
    results["per_wave"] = per_wave
    results["run_mode"] = run_mode()
    if results["run_mode"] != "full":
        results["run_mode_note"] = smoke_note()
    results["case_file"] = str(Path(case.source).resolve())
    results["displacement_threshold_over_dn"] = case.series.displacement_threshold
    results["steps"] = [{"step": s.sea.number, "folder": str(s.folder),
                         "target_Hm0_m": s.sea.significant_height, "Tp_s": s.sea.peak_period,
                         "wave_maker": (None if s.maker is None else s.maker.as_dict()),
                         "target_waves": s.sea.waves, "sea_duration_s": s.sea.duration,
                         "wave_height_not_measured": unmeasured.get(s.sea.number)}
                        for s in steps]
    return results


def series_summary_lines(results: dict) -> list[str]:
    """One line per step of the damage curve for the terminal, saying "not measured" (and why)
    where the flume gave nothing, never "nan"."""
    curve, lines = results["curve"], []
    why = {step["step"]: step.get("wave_height_not_measured") for step in results["steps"]}

    def shown(value, form: str, unit: str = "") -> str:
        value = _number(value)         # a null of series_results.json too
        return f"{value:{form}}{unit}" if math.isfinite(value) else "not measured"

    for k, step in enumerate(curve["step"]):
        if math.isfinite(_number(curve["Hm0_m"][k])):
            waves = (f"Hm0 {curve['Hm0_m'][k]:.3g} m, N_s {curve['stability_number'][k]:.3g}, "
                     f"{curve['waves'][k]} waves")
        else:
            waves = ("Hm0 and N_s not measured" + (f" ({why[step]})" if why.get(step) else ""))
        lines.append(f"riprap: step {step}: {waves}, N_od {shown(curve['N_od'][k], '.3g')}, S "
                     f"{shown(curve['S'][k], '.3g')}, q "
                     f"{shown(curve['q_m3_s_m'][k], '.3g', ' m3/s/m')}")
    return lines


def _why_not_measured(flume: dict) -> str:
    """Why a step's survey has no incident wave height at the toe, from its flume test."""
    reasons = [str(text) for text in flume.get("not_computed", [])
               if str(text).startswith("stability number")]
    if reasons:
        why = reasons[0].removeprefix("stability number: ").removeprefix("no incident wave height")
        return why.strip().removeprefix("(").removesuffix(")") or "no incident wave height"
    return str(flume.get("note") or "the step's survey has no flume test (no waves report)")


def _crest_width(over, flume: dict) -> tuple[float | None, str | None]:
    """G_c (m) of EurOtop's crest-width factor and where it came from: the overtopping gauge's
    ``crest_width``; when 0, the distance from the top of the placed layer's face (the survey's
    ``slope_crest_x_m``) to the gauge's plane; (None, None) without either (C_r = 1)."""
    if over is None:
        return None, None
    given = float(over.parameters.get("crest_width", 0.0))
    if given > 0:
        return given, f"[[gauges]] {over.name!r} crest_width"
    top = _number(flume.get("slope_crest_x_m"))
    if not math.isfinite(top):
        return None, None
    x = float(over.parameters["position"][0])
    return max(x - top, 0.0), (f"from the top of the placed layer's face (x = {top:.4g} m) to the "
                               f"overtopping gauge {over.name!r} (x = {x:.4g} m)")


def _number(value) -> float:
    return (float(value) if isinstance(value, (int, float)) and not isinstance(value, bool)
            else math.nan)
