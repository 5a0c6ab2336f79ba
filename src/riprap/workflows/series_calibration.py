"""The wave maker's calibration of a test series (``[series] wave_calibration``; docs/campaign.md,
Calibrated seas).

A laboratory calibrates its wave maker before a test series: it runs each sea state with the
structure out of the flume, measures the incident waves where the toe will be and corrects the
wave maker's gain until the sea asked arrives there. A flume loses height between the wave maker
and the toe (the grid's damping of the shortest waves, the analysis band, the generation's own
transfer); without this, riprap's first damage curve ran its steps 6-11 % below the asked Hm0.

How it is done here, per step of the series:

1. The step's case without its bodies (no pack, no bodies, no walls of bodies: the porous core,
   the obstacles, the wave maker and the surface gauges stay), and, where nothing in the flume
   varies across it, one cell wide: the waves are the same in every plane across the flume, so
   a strip of one cell makes the same waves at a fraction of the cost.
2. Run it with the wave maker at gain g (Hm0 x g) and Tp x p; measure the incident Hm0 and Tp
   at the toe by the very analysis the step's survey uses (``riprap.analysis.stability_report``:
   Mansard & Funke's three-gauge split, Tp by Read's Fp5 of the incident spectrum).
3. Until Hm0 is within ``HEIGHT_TOLERANCE`` and Tp within ``PERIOD_TOLERANCE`` of the asked
   values: g from the runs so far (the ratio after one run, the secant through the last two
   after that), p by the ratio. At most ``MAX_TRIES`` runs; a gain beyond ``MAX_GAIN``, a
   height that stops growing with the gain, or a calibrated sea the flume cannot carry is a
   wave maker that cannot reach the asked height: an error naming the step.

The calibration is made with the seeds of the series as written (member 0 of a campaign) and
kept in its folder: ``step_01.json``, ... as each step is calibrated (so a cut calibration
resumes, and a campaign calibrates its steps on its workers at once), with each try's run folder
(``step_01_try_1``, ...), and ``calibration.json``, the whole. Every file records the flume it
was made in (a fingerprint of the keys that make the waves) and its step's sea; a folder of
another flume, or a step of another sea, is refused naming what differs. Every member and seed of
the series reuses it: the gain is the wave maker's transfer for that sea state, not for one
realisation of it.

Smoke runs (``RIPRAP_SMOKE=1``) cut every run to a second or two, too short to measure a sea: a
smoke series makes no calibration and runs its steps at gain 1, and says so.
"""
from __future__ import annotations

import hashlib
import json
import math
import time as wallclock
import tomllib
from dataclasses import dataclass
from pathlib import Path

from riprap.analysis.stability_report import incident_at_toe, incident_peak_period_at_toe
from riprap.case.build import smoke_mode
from riprap.case.build_fluid import build_fluid_run, build_fluid_solver
from riprap.case.load import parse_case
from riprap.case.series_steps import StepSea, case_text, step_case_data, step_seas
from riprap.errors import CaseFileError, InstabilityError
from riprap.io.json_files import read_json_object, write_json
from riprap.io.output_folder import prepare_output_folder
from riprap.io.pack import riprap_version
from riprap.work_estimate import flume_run_seconds

__all__ = ["CALIBRATION_FILE", "HEIGHT_TOLERANCE", "PERIOD_TOLERANCE", "MAX_TRIES", "MAX_GAIN",
           "StepCalibration", "calibration_case_text", "calibrate_step", "calibrate_series",
           "read_calibration", "calibration_folder", "calibration_cost_seconds",
           "flume_fingerprint"]

CALIBRATION_FILE = "calibration.json"
CALIBRATION_FORMAT = 1
#: The step's incident Hm0 at the toe within this fraction of the asked one (issue 54).
HEIGHT_TOLERANCE = 0.03
#: Its Tp within this fraction.
PERIOD_TOLERANCE = 0.05
#: Times a calibration run that became unstable goes on from its last good state, each with the
#: Courant number halved, before the step is refused.
UNSTABLE_RETRIES = 2
#: Runs of the flume per step at most.
MAX_TRIES = 4
#: The largest gain accepted: a flume that needs the wave maker at twice the asked height
#: loses more than a flume should (breaking, or a grid too coarse for the waves).
MAX_GAIN = 2.0
#: The tables of a step's case that make the waves without the structure's bodies.
_FLUME_TABLES = ("format_version", "simulation", "fluid", "water_regions", "obstacles", "waves",
                 "gauges", "porous_zones", "output")
#: [simulation] keys that belong to bodies (a strip of bodies: there are none).
_BODY_SIMULATION_KEYS = ("periodic_y_low", "periodic_y_high")
#: [waves] keys that are the step's sea (the flume's fingerprint leaves them out).
_SEA_KEYS = ("significant_height", "peak_period", "peak_enhancement", "seed", "duration",
             "stop_time")


@dataclass(frozen=True)
class StepCalibration:
    """One step's calibration: the gain on Hm0 and the factor on Tp the wave maker is run at,
    and what came out at the toe with them (the last try); ``tries`` every run, in order."""

    step: int
    asked_hm0: float
    asked_tp: float
    gain: float
    period_factor: float
    measured_hm0: float
    measured_tp: float
    tries: tuple
    seed: int

    def as_dict(self) -> dict:
        return {"step": self.step, "asked_Hm0_m": self.asked_hm0, "asked_Tp_s": self.asked_tp,
                "seed": self.seed, "gain": self.gain, "period_factor": self.period_factor,
                "measured_Hm0_m": self.measured_hm0, "measured_Tp_s": self.measured_tp,
                "height_error": self.measured_hm0 / self.asked_hm0 - 1.0,
                "period_error": self.measured_tp / self.asked_tp - 1.0,
                "tries": list(self.tries)}

    @classmethod
    def from_dict(cls, entry: dict) -> "StepCalibration":
        return cls(step=int(entry["step"]), asked_hm0=float(entry["asked_Hm0_m"]),
                   asked_tp=float(entry["asked_Tp_s"]), gain=float(entry["gain"]),
                   period_factor=float(entry["period_factor"]),
                   measured_hm0=float(entry["measured_Hm0_m"]),
                   measured_tp=float(entry["measured_Tp_s"]), tries=tuple(entry["tries"]),
                   seed=int(entry["seed"]))


def calibration_folder(case, series_folder) -> Path:
    """Where the calibration of ``case``'s series lives: ``[series] wave_calibration_folder``, or
    ``calibration/`` in the series folder."""
    given = case.series.wave_calibration_folder
    return (Path(case.base_dir) / given).resolve() if given else Path(series_folder) / "calibration"


def _series_data(case) -> dict:
    path = Path(case.source)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise CaseFileError(f"{case.source}: cannot be read again for the wave calibration "
                            f"({error})") from None


def flume_fingerprint(case) -> tuple[str, dict]:
    """(fingerprint, keys) of what makes the waves at the toe in ``case``'s flume: the fluid box
    and its settings, the water, the porous zones and obstacles, the wave maker's keys other
    than the sea's, the surface gauges and gravity."""
    data = _series_data(case)
    waves = {k: v for k, v in data.get("waves", {}).items() if k not in _SEA_KEYS}
    keys = {"fluid": data.get("fluid", {}), "water_regions": data.get("water_regions", []),
            "porous_zones": data.get("porous_zones", []), "obstacles": data.get("obstacles", []),
            "waves": waves,
            "gauges": [g for g in data.get("gauges", []) if g.get("type") == "surface"],
            "gravity": data.get("simulation", {}).get("gravity")}
    text = json.dumps(keys, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16], json.loads(text)


def _sea_of(sea: StepSea) -> dict:
    return {"Hm0_m": sea.significant_height, "Tp_s": sea.peak_period,
            "peak_enhancement": sea.peak_enhancement, "seed": sea.seed,
            "sea_duration_s": sea.duration, "end_time_s": sea.end_time}


def _uniform_across(data: dict) -> bool:
    """Whether nothing in the flume varies across it (every porous zone and obstacle a polygon
    in x-z, or a box over the whole width), so that one cell across makes the same waves."""
    fluid = data["fluid"]
    low, high = fluid["lower"][1], fluid["upper"][1]
    for table in ("porous_zones", "obstacles"):
        for entry in data.get(table, []):
            if entry.get("type") == "polygon":
                continue
            if entry.get("type") == "box" and entry["lower"][1] <= low and entry["upper"][1] >= high:
                continue
            return False
    return True


def calibration_case_text(case, sea: StepSea, gain: float, period_factor: float,
                          courant_number: float | None = None) -> str:
    """The case of one calibration run: the step's case with the wave maker at Hm0 x ``gain``
    and Tp x ``period_factor``, without the structure's bodies, one cell wide where nothing
    varies across the flume; ``courant_number``: a lower one than the case's (a run continued
    after it became unstable)."""
    data = step_case_data(case, sea, gain, period_factor)
    if courant_number is not None:
        data["fluid"]["courant_number"] = courant_number
    data = {name: value for name, value in data.items() if name in _FLUME_TABLES}
    for key in _BODY_SIMULATION_KEYS:
        data["simulation"].pop(key, None)
    data["simulation"]["output_interval"] = sea.end_time     # no frames of an empty flume
    data["gauges"] = [g for g in data.get("gauges", []) if g.get("type") == "surface"]
    data.get("output", {}).pop("body_forces_interval", None)
    fluid = data["fluid"]
    fluid.pop("contact_only_below_cells", None)     # no bodies: nothing is contact-only
    if _uniform_across(data):
        cells = list(fluid["cells"])
        low = float(fluid["lower"][1])
        size = (float(fluid["upper"][1]) - low) / int(cells[1])
        cells[1] = 1
        fluid["cells"] = cells
        fluid["upper"] = [fluid["upper"][0], low + size, fluid["upper"][2]]
        for side in ("y_low", "y_high"):
            fluid.pop(side, None)              # free-slip walls: a plane of the flume
        for gauge in data["gauges"]:
            gauge["position"] = [gauge["position"][0], low + 0.5 * size, gauge["position"][2]]
    return case_text(data, f"riprap wave calibration of {Path(case.source).name}: step "
                           f"{sea.number}, the wave maker at Hm0 {sea.significant_height:g} m x "
                           f"{gain:.4f}, Tp {sea.peak_period:.4g} s x {period_factor:.4f}, "
                           "without the structure's bodies; written by riprap")


def _measure(case, sea: StepSea, gain: float, factor: float, folder: Path) -> tuple[float, float]:
    """(incident Hm0, Tp) at the toe of one calibration run in ``folder`` (run, continued from
    its checkpoint, or read when done before)."""
    report_file = folder / "waves_report.json"
    if not (folder / "summary.json").is_file():
        prepare_output_folder(folder)
        checkpoint = folder / "checkpoint.npz"
        restart = checkpoint if checkpoint.is_file() else None
        courant = None
        for attempt in range(UNSTABLE_RETRIES + 1):
            text = calibration_case_text(case, sea, gain, factor, courant)
            (folder / "case.toml").write_text(text, encoding="utf-8")
            run_case = parse_case(text, source=str(folder / "case.toml"), base_dir=folder)
            simulation = build_fluid_run(run_case, output_directory=folder, progress=False)
            simulation.case_file = str((folder / "case.toml").resolve())
            try:
                simulation.run(restart_from=restart)
                break
            except InstabilityError as error:
                # the flume without its armour: the waves break on the bare core and overtop
                # it harder than the structure lets them (the ladder's blew up in the spray
                # over the crest); on from the last scheduled checkpoint with the Courant number
                # halved. Not from failure_checkpoint.npz: the flow is tested for non-finite
                # values only, so the "last good state" can hold speeds of 1e74 m/s already
                if attempt == UNSTABLE_RETRIES:
                    raise CaseFileError(
                        f"{case.source} [[series_steps]] step {sea.number}: its calibration run "
                        f"({folder}) became unstable {attempt + 1} time(s), the last at "
                        f"[fluid] courant_number = {run_case.fluid.courant_number:g}: "
                        f"{str(error).splitlines()[0]}") from None
                courant = 0.5 * run_case.fluid.courant_number
                restart = checkpoint if checkpoint.is_file() else None
    report = read_json_object(report_file, "calibration run's waves report",
                              "delete the run's folder to run it again")
    height = incident_at_toe(report)[0]
    period = incident_peak_period_at_toe(report)
    if height is None or period is None or not math.isfinite(height) or height <= 0:
        raise CaseFileError(
            f"{case.source} [[series_steps]] step {sea.number}: its calibration run ({folder}) "
            "measured no incident wave at the toe: the series case needs three surface gauges "
            "seaward of the structure that the waves reach for four peak periods or more")
    return float(height), float(period)


def _next_gain(tries: list[dict], asked: float) -> float:
    """The gain to try next: the ratio after one run; after more, the secant through the last
    two (the flume's transfer is not quite linear: the highest waves lose more)."""
    last = tries[-1]
    if len(tries) >= 2:
        before = tries[-2]
        slope = ((last["measured_Hm0_m"] - before["measured_Hm0_m"])
                 / (last["gain"] - before["gain"]) if last["gain"] != before["gain"] else 0.0)
        if slope > 0:
            return last["gain"] + (asked - last["measured_Hm0_m"]) / slope
    return last["gain"] * asked / last["measured_Hm0_m"]


def calibrate_step(case, sea: StepSea, folder, *, say=print, start_gain: float = 1.0
                   ) -> StepCalibration:
    """Calibrate the wave maker for step ``sea`` of ``case``'s series in ``folder`` (the
    calibration folder); its result is kept as ``step_<k>.json`` there (and read back when done
    before, if made in the same flume for the same sea)."""
    folder = Path(folder)
    record = folder / f"step_{sea.number:02d}.json"
    fingerprint, _ = flume_fingerprint(case)
    where = (f"{case.source} [[series_steps]] step {sea.number} (Hm0 = "
             f"{sea.significant_height:g} m, Tp = {sea.peak_period:.3g} s)")
    if record.is_file():
        kept = read_json_object(record, "step calibration", "delete it to calibrate again")
        _same_flume_and_sea(kept, fingerprint, sea, record, where)
        return StepCalibration.from_dict(kept["calibration"])
    gain, factor, tries = float(start_gain), 1.0, []
    for attempt in range(1, MAX_TRIES + 1):
        try:
            build_fluid_solver(parse_case(calibration_case_text(case, sea, gain, factor),
                                          source=str(folder / "case.toml"), base_dir=folder))
        except CaseFileError as error:
            raise CaseFileError(f"{where}: the wave maker cannot reach the asked height: at "
                                f"Hm0 x {gain:.3f} = {sea.significant_height * gain:.4g} m {error}"
                                ) from None
        started = wallclock.perf_counter()
        height, period = _measure(case, sea, gain, factor,
                                  folder / f"step_{sea.number:02d}_try_{attempt}")
        tries.append({"gain": gain, "period_factor": factor, "measured_Hm0_m": height,
                      "measured_Tp_s": period,
                      "wall_s": round(wallclock.perf_counter() - started, 1)})
        height_error = height / sea.significant_height - 1.0
        period_error = period / sea.peak_period - 1.0
        say(f"riprap: wave calibration step {sea.number}, run {attempt}: wave maker Hm0 x "
            f"{gain:.4f}, Tp x {factor:.4f}: at the toe Hm0 {height:.4g} m ({height_error:+.1%} of "
            f"{sea.significant_height:g}), Tp {period:.4g} s ({period_error:+.1%})")
        if abs(height_error) <= HEIGHT_TOLERANCE and abs(period_error) <= PERIOD_TOLERANCE:
            result = StepCalibration(step=sea.number, asked_hm0=sea.significant_height,
                                     asked_tp=sea.peak_period, gain=gain, period_factor=factor,
                                     measured_hm0=height, measured_tp=period, tries=tuple(tries),
                                     seed=sea.seed)
            write_json(record, {"format": CALIBRATION_FORMAT, "riprap_version": riprap_version(),
                                "flume_fingerprint": fingerprint, "sea": _sea_of(sea),
                                "calibration": result.as_dict()})
            return result
        if abs(height_error) > HEIGHT_TOLERANCE:
            new_gain = _next_gain(tries, sea.significant_height)
            if (len(tries) >= 2 and tries[-1]["gain"] > tries[-2]["gain"]
                    and tries[-1]["measured_Hm0_m"] <= tries[-2]["measured_Hm0_m"]):
                new_gain = math.inf          # more stroke, no more height: the flume breaks it
            if not new_gain <= MAX_GAIN:
                raise CaseFileError(
                    f"{where}: the wave maker cannot reach the asked height: at Hm0 x {gain:.3f} "
                    f"the toe saw {height:.4g} m, and "
                    + ("a larger stroke gave no more height (the waves break or the flume "
                       "damps them)" if math.isinf(new_gain) else
                       f"it would need Hm0 x {new_gain:.3f} (at most x {MAX_GAIN:g} is accepted)")
                    + f"; runs in {folder}: lower the step's height, or deepen or refine the flume")
            gain = new_gain
        if abs(period_error) > PERIOD_TOLERANCE:
            factor *= sea.peak_period / period
    raise CaseFileError(
        f"{where}: the wave maker's calibration did not reach Hm0 within "
        f"{HEIGHT_TOLERANCE:.0%} and Tp within {PERIOD_TOLERANCE:.0%} in {MAX_TRIES} runs ("
        + "; ".join(f"x {t['gain']:.3f}: {t['measured_Hm0_m']:.4g} m, {t['measured_Tp_s']:.4g} s"
                    for t in tries) + f"); runs in {folder}")


def _same_flume_and_sea(kept: dict, fingerprint: str, sea: StepSea, path: Path,
                        where: str) -> None:
    """Refuse a step calibration made in another flume or for another sea, naming what
    differs."""
    if kept.get("format") != CALIBRATION_FORMAT or "calibration" not in kept:
        raise CaseFileError(f"{where}: {path} is not a riprap step calibration of this version: "
                            "delete it (or the calibration folder) to calibrate again")
    if kept.get("flume_fingerprint") != fingerprint:
        raise CaseFileError(f"{where}: {path} is the calibration of another flume (its keys "
                            "that make the waves differ: [fluid], [waves], [[porous_zones]], "
                            "[[obstacles]], [[water_regions]] or the surface gauges); give "
                            "[series] wave_calibration_folder another folder, or delete this one "
                            "to calibrate again")
    asked = _sea_of(sea)
    changed = [f"{key} {kept['sea'].get(key)!r} -> {value!r}" for key, value in asked.items()
               if kept.get("sea", {}).get(key) != value]
    if changed:
        raise CaseFileError(f"{where}: {path} calibrates another sea ("
                            + ", ".join(changed) + "); delete it to calibrate the step again")


def calibrate_series(case, folder, *, say=print) -> list[StepCalibration]:
    """Every step of ``case``'s series calibrated (member 0's seeds), one after the other, each
    starting from the gain the step before needed; ``calibration.json`` written in ``folder``.
    In a smoke run nothing is made (an empty list: gain 1)."""
    if smoke_mode():
        say("riprap: a smoke run makes no wave calibration: the steps run at the wave maker's "
            "gain 1")
        return []
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    results, gain = [], 1.0
    for sea in step_seas(case, 0):
        result = calibrate_step(case, sea, folder, say=say, start_gain=gain)
        results.append(result)
        gain = result.gain
    write_calibration(case, folder, results)
    return results


def write_calibration(case, folder, results: list[StepCalibration]) -> Path:
    """``calibration.json``: the flume, its fingerprint and every step's calibration."""
    fingerprint, keys = flume_fingerprint(case)
    path = Path(folder) / CALIBRATION_FILE
    write_json(path, {"format": CALIBRATION_FORMAT, "riprap_version": riprap_version(),
                      "series_case": str(Path(case.source).resolve()),
                      "flume_fingerprint": fingerprint, "flume": keys,
                      "height_tolerance": HEIGHT_TOLERANCE, "period_tolerance": PERIOD_TOLERANCE,
                      "steps": [r.as_dict() for r in results]})
    return path


def read_calibration(case, folder) -> dict[int, StepCalibration]:
    """Every step's calibration kept in ``folder`` for ``case``'s series, by step number; each
    checked to be of this flume and this step's sea (else refused, naming what differs). A step
    not calibrated yet is missing from the answer."""
    folder = Path(folder)
    found = {}
    fingerprint, _ = flume_fingerprint(case)
    for sea in step_seas(case, 0):
        record = folder / f"step_{sea.number:02d}.json"
        if record.is_file():
            kept = read_json_object(record, "step calibration", "delete it to calibrate again")
            _same_flume_and_sea(kept, fingerprint, sea, record,
                                f"{case.source} [[series_steps]] step {sea.number}")
            found[sea.number] = StepCalibration.from_dict(kept["calibration"])
    return found


def calibration_cost_seconds(case) -> tuple[float, int]:
    """(wall seconds, runs) the calibration of ``case``'s series is likely to take on 2 cores:
    two runs a step (a first run and a check) of the step's flume without bodies, at
    examples/10's measured pace (``riprap.work_estimate.flume_run_seconds``)."""
    seconds, runs = 0.0, 0
    for sea in step_seas(case, 0):
        text = calibration_case_text(case, sea, 1.0, 1.0)
        run_case = parse_case(text, source=case.source, base_dir=case.base_dir)
        fluid = run_case.fluid
        cells = 1
        for count in fluid.cells:
            cells *= int(count)
        size = float(min((h - l) / n for h, l, n in zip(fluid.upper, fluid.lower, fluid.cells)))
        seconds += 2 * flume_run_seconds(
            simulated_time=sea.end_time, cells=cells, cell_size=size,
            depth=run_case.waves.still_water_level - fluid.lower[2],
            gravity=float(-run_case.simulation.gravity[2]))
        runs += 2
    return seconds, runs
