"""``riprap campaign``: the independent members of a test campaign (test series of other seeds,
other designs) as tasks of Dask's distributed scheduler (``dask.distributed``;
``docs/campaign.md``).

One member is one test series (``riprap.workflows.series.run_series``) in its own folder under
the campaign's (``<case name>_seed<k>``), complete on its own; one member runs per worker process,
with ``threads`` numba threads of its own. The scheduler is a ``LocalCluster`` on this machine by
default, or the one at ``scheduler`` (``tcp://host:8786``; a SLURM or PBS cluster made with
dask-jobqueue gives one); ``client`` takes a ``dask.distributed.Client`` the caller made.

Resuming and growing: the campaign folder records the riprap version, the run mode (smoke or
full) and its members (``campaign.json``); a folder of another version, or whose members were run
from other cases, is refused before anything starts. Members may be added (``--seeds 0 1 2`` after
``0 1``: only seed 2 runs), not dropped. Every member resumes on its own (``run_series``):
finished steps are not run again, a step that was cut off goes on from its last checkpoint, smoke
steps are run again in full, and a change of a survey key only surveys the steps again. So a
campaign killed or lost, or a member whose worker died, is started again with the same command.
A smoke campaign (``RIPRAP_SMOKE=1``) over a full one is refused; the mode is handed to every
worker (a remote worker's own environment does not decide it).

Dask is optional: ``python3 -m pip install '.[campaign]'`` in riprap's folder (as the README
installs riprap; or ``python3 -m pip install distributed``); riprap and single runs work without
it.

Progress: every member keeps its messages, its steps' progress and its warnings in its
``series.log``; the campaign follows those logs and says each line with the member's name, on the
terminal and in the campaign folder's ``campaign.log`` (a warning once, however many members
give it).
"""
from __future__ import annotations

import math
import os
import time as wallclock
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap.case.load import load_case
from riprap.errors import CaseFileError, RiprapError
from riprap.io.json_files import read_json_object, write_json
from riprap.io.output_folder import prepare_output_folder
from riprap.io.pack import riprap_version
from riprap.io.csv_tables import write_columns_csv
from riprap.io.log_file import append_log_lines, log_size, read_new_log_lines
from riprap.work_estimate import duration_words, warning_line
from riprap.workflows.series import check_series, run_series, series_wall_seconds
from riprap.case.series_steps import step_seas
from riprap.workflows.series_calibration import (calibrate_step, calibration_cost_seconds,
                                                 calibration_folder,
                                                 read_calibration, write_calibration)
from riprap.workflows.series_progress import SERIES_LOG
from riprap.workflows.series_record import (RUN_MODES, mode_words, run_mode, series_fingerprint,
                                            smoke_note)

__all__ = ["Member", "members_of", "run_campaign", "campaign_cost", "CAMPAIGN_RECORD",
           "CAMPAIGN_LOG", "SCHEDULER_TIMEOUT_S"]

CAMPAIGN_RECORD = "campaign.json"
#: Its format: 2 records the run mode and lets members be added (2026-12).
CAMPAIGN_FORMAT = 2
#: Seconds a scheduler address is given to answer before the campaign is refused.
SCHEDULER_TIMEOUT_S = 5.0
#: The campaign folder's log: the campaign's messages and its members' progress and warnings.
CAMPAIGN_LOG = "campaign.log"
#: Wall seconds between two looks at the members' logs while they run.
POLL_S = 2.0


@dataclass(frozen=True)
class Member:
    """One member: a series case and the offset added to its steps' seeds."""

    case_file: Path
    seed_offset: int

    @property
    def name(self) -> str:
        return f"{self.case_file.stem}_seed{self.seed_offset}"


def members_of(case_files, seeds=(0,)) -> list[Member]:
    """Every case with every seed offset, in that order; names must differ."""
    members = [Member(Path(path).resolve(), int(seed)) for path in case_files for seed in seeds]
    if not members:
        raise CaseFileError("a campaign needs at least one series case")
    if any(seed < 0 for seed in seeds):
        raise CaseFileError(f"seeds must be >= 0 (offsets added to each step's seed), got "
                            f"{list(seeds)}")
    names = [member.name for member in members]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise CaseFileError(f"campaign members must differ: {', '.join(repeated)} given more than "
                            "once (two case files of one name, or a seed twice); rename a case "
                            "file or drop the repeated seed")
    return members


def _on_worker(threads: int, mode: str) -> None:
    """A worker set to the campaign's run ``mode`` and ``threads`` numba threads."""
    import numba

    if mode == "smoke":
        os.environ["RIPRAP_SMOKE"] = "1"
    else:
        os.environ.pop("RIPRAP_SMOKE", None)
    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def _run_member(case_file: str, folder: str, seed_offset: int, threads: int,
                mode: str = "full", calibration_directory: str | None = None) -> dict:
    """A member on a worker: its series, with ``threads`` numba threads (no progress bar), in the
    campaign's run ``mode`` whatever the worker's own environment says."""
    _on_worker(threads, mode)
    lines = []
    results = run_series(load_case(case_file), output_directory=folder, progress=False,
                         say=lines.append, seed_offset=seed_offset, log_warnings=True,
                         calibration_directory=calibration_directory)
    results["log"] = lines
    return results


def _calibrate_on_worker(case_file: str, folder: str, step: int, threads: int,
                         mode: str) -> list[str]:
    """One step's wave calibration on a worker; returns its messages."""
    _on_worker(threads, mode)
    case = load_case(case_file)
    lines = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # the checks said them before the workers started
        calibrate_step(case, step_seas(case, 0)[step - 1], folder, say=lines.append)
    return lines


def calibration_directories(members: list[Member], cases: dict, out: Path) -> dict:
    """Per case file whose series calibrates its waves, the calibration's folder: ``[series]
    wave_calibration_folder``, else ``calibration_<case name>`` in the campaign's folder (every
    member of the case shares it)."""
    folders = {}
    for member in members:
        case = cases[member.case_file]
        if case.series.wave_calibration != "none":
            folders[member.case_file] = (
                calibration_folder(case, out) if case.series.wave_calibration_folder
                else out / f"calibration_{member.case_file.stem}")
    return folders


def _calibrate(client, cases: dict, folders: dict, threads: int, logs) -> None:
    """Every step of every case's wave calibration as Dask tasks at once (the steps do not
    depend on each other), then each case's ``calibration.json``; a calibration kept before
    is read, not run again."""
    if run_mode() == "smoke" or not folders:
        if folders:
            logs.say("riprap: a smoke campaign makes no wave calibration: the steps run at the "
                     "wave maker's gain 1")
        return
    futures = {}
    for case_file, folder in folders.items():
        case = cases[case_file]
        done = read_calibration(case, folder)
        for sea in step_seas(case, 0):
            if sea.number not in done:
                futures[(case_file, sea.number)] = client.submit(
                    _calibrate_on_worker, str(case_file), str(folder), sea.number, threads,
                    run_mode(), key=f"riprap-calibrate-{case_file.stem}-{sea.number}", pure=False)
    if futures:
        logs.say(f"riprap: wave calibration of {len(futures)} steps on the workers first (the "
                 "members run after it)")
    failed = []
    for (case_file, number), future in futures.items():
        try:
            for line in future.result():
                logs.say(f"[{case_file.stem} calibration] {line}")
        except Exception as error:  # noqa: BLE001 - said with the step, then the campaign stops
            failed.append(f"{case_file.stem} step {number}: {error}")
    if failed:
        raise RiprapError("the wave calibration failed (" + "; ".join(failed) + "): no member "
                          "was started; mend the cause and start the same command again")
    for case_file, folder in folders.items():
        case = cases[case_file]
        made = read_calibration(case, folder)
        write_calibration(case, folder, [made[k] for k in sorted(made)])


def _client(scheduler: str | None, workers: int, threads: int):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise RiprapError("a campaign runs its members on Dask (dask.distributed), which is not "
                          "installed: python3 -m pip install '.[campaign]' in riprap's "
                          "folder (or: python3 -m pip install distributed)") from None
    if scheduler:
        try:
            return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s"), None
        except (OSError, TimeoutError) as error:
            raise RiprapError(f"the Dask scheduler at {scheduler} does not answer within "
                              f"{SCHEDULER_TIMEOUT_S:g} s ({type(error).__name__}: {error}); "
                              "nothing was started. Start it (dask scheduler, or a "
                              "dask-jobqueue cluster) or drop --scheduler for a local one") from None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           memory_limit=0, dashboard_address=None)
    return Client(cluster), cluster


def _claim(out: Path, members: list[Member], fingerprints: list[str]) -> str:
    """Refuse a campaign folder of another riprap version, a smoke campaign over a full one, or
    one whose members were run from other cases or that this campaign would drop (nothing in it
    is touched); returns what this campaign adds to it, in words ("" when nothing)."""
    mode = run_mode()
    path = out / CAMPAIGN_RECORD
    if not path.is_file():
        return ""
    old = read_json_object(path, "campaign record", "riprap campaign wrote it")
    if old.get("format") != CAMPAIGN_FORMAT or old.get("riprap_version") != riprap_version():
        raise RiprapError(f"{path}: a campaign written by riprap {old.get('riprap_version')!r} "
                          f"(format {old.get('format')!r}), this is {riprap_version()} (format "
                          f"{CAMPAIGN_FORMAT}); nothing in it is resumed or overwritten: give "
                          "another --out folder")
    if old.get("run_mode") not in RUN_MODES:
        raise RiprapError(f"{path}: run_mode = {old.get('run_mode')!r} is not one riprap writes "
                          f"({' or '.join(RUN_MODES)}): the record was edited or damaged; nothing "
                          "in it is resumed or overwritten: give another --out folder")
    if mode == "smoke" and old.get("run_mode") != "smoke":
        raise RiprapError(f"{path}: a campaign run in full; {mode_words('smoke')} would "
                          "overwrite its members' steps: give the smoke campaign another --out "
                          "folder, or run without RIPRAP_SMOKE")
    new = {m.name: (m, f) for m, f in zip(members, fingerprints)}
    before = {entry.get("name"): entry for entry in old.get("members", [])}
    dropped = [name for name in before if name not in new]
    if dropped:
        raise RiprapError(f"{path}: this campaign holds the members {', '.join(dropped)}, not "
                          "given now; a campaign grows, it does not shrink: give them too (the "
                          "same cases and --seeds as before, and any new ones), or another --out "
                          "folder")
    changed = []
    for name, entry in before.items():
        member, fingerprint = new[name]
        if entry.get("case_file") != str(member.case_file):
            changed.append(f"{name}: case file {entry.get('case_file')} -> {member.case_file}")
        elif (entry.get("fingerprint") != fingerprint and old.get("run_mode") == mode):
            changed.append(f"{name}: its case {member.case_file} changed since (its series.json "
                           "holds the keys it was run from)")
    if changed:
        raise RiprapError(f"{path}: members run from other cases ({'; '.join(changed)}); nothing "
                          "in it is resumed or overwritten: give another --out folder, or restore "
                          "the cases")
    added = [name for name in new if name not in before]
    return f"members added: {', '.join(added)} (the others resume)" if added else ""


def _record(members: list[Member], fingerprints: list[str]) -> dict:
    return {"format": CAMPAIGN_FORMAT, "riprap_version": riprap_version(), "run_mode": run_mode(),
            "members": [{"name": m.name, "case_file": str(m.case_file),
                         "seed_offset": m.seed_offset, "fingerprint": f}
                        for m, f in zip(members, fingerprints)]}


def run_campaign(members: list[Member], out, *, workers: int = 2, threads: int = 1,
                 scheduler: str | None = None, client=None, say=print) -> dict:
    """Run ``members`` as Dask tasks; returns the campaign's results (``campaign_results.json``):
    per member its series results, and per step the spread of N_od and S over the members of
    each case."""
    out = Path(out)
    if workers < 1 or threads < 1:
        raise CaseFileError(f"workers ({workers}) and threads ({threads}) must be >= 1")
    cases = {member.case_file: load_case(member.case_file) for member in members}
    with warnings.catch_warnings(record=True) as caught:
        for member in members:
            case = cases[member.case_file]
            if not case.is_series:
                raise CaseFileError(f"{member.case_file}: a campaign member is a test series: "
                                    "the case needs [series] and [[series_steps]]")
            check_series(case, out / member.name, member.seed_offset,
                         calibration_directories([member], cases, out).get(member.case_file))
    fingerprints = [series_fingerprint(cases[m.case_file]) for m in members]
    growth = _claim(out, members, fingerprints)      # before any worker starts
    own_cluster = None
    if client is None:
        client, own_cluster = _client(scheduler, workers, threads)
    try:
        prepare_output_folder(out)
        write_json(out / CAMPAIGN_RECORD, _record(members, fingerprints))
        logs = _MemberLogs(out, members, say)
        for warning in caught:          # the checks' warnings, once (the workers' are not said)
            logs.say_warning(warning_line(warning.message, warning.category))
        logs.say(f"riprap: campaign of {len(members)} members on the Dask scheduler "
                 f"{getattr(client.scheduler, 'address', '')}: "
                 + ", ".join(m.name for m in members) + (f"; {growth}" if growth else "")
                 + (f"; {mode_words('smoke')}" if run_mode() == "smoke" else "")
                 + f"; progress in {out / CAMPAIGN_LOG}")
        logs.say(f"riprap: {campaign_cost(members, cases, workers)}")
        calibrations = calibration_directories(members, cases, out)
        _calibrate(client, cases, calibrations, threads, logs)
        futures = [client.submit(_run_member, str(m.case_file), str(out / m.name), m.seed_offset,
                                 threads, run_mode(),
                                 None if m.case_file not in calibrations
                                 else str(calibrations[m.case_file]),
                                 key=f"riprap-{m.name}", pure=False)
                   for m in members]
        results, failed = {}, {}
        waiting = dict(zip(members, futures))
        while waiting:
            finished = [m for m, future in waiting.items() if future.done()]
            logs.follow()
            if not finished:
                wallclock.sleep(POLL_S)
                continue
            for member in finished:
                future = waiting.pop(member)
                try:
                    results[member.name] = future.result()
                    logs.follow()
                    logs.say(f"riprap: campaign member {member.name} done")
                except Exception as error:  # noqa: BLE001 - one member's failure ends only it
                    failed[member.name] = f"{type(error).__name__}: {error}"
                    logs.follow()
                    logs.say(f"riprap: campaign member {member.name} failed: "
                             f"{failed[member.name]}")
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()
    if failed:
        write_json(out / "campaign_results.json", {"run_mode": run_mode(), "members": results,
                                                   "failed": failed})
        raise RiprapError(
            f"{len(failed)} of {len(members)} campaign members failed ("
            + "; ".join(f"{name}: {why}" for name, why in failed.items())
            + f"); the others are done. Their folders under {out} keep what was done: mend the "
            "cause and start the same command again to resume them")
    summary = _spread(members, results)
    campaign = {"run_mode": run_mode(),
                **({"run_mode_note": smoke_note()} if run_mode() == "smoke" else {}),
                "members": results, "spread": summary}
    write_json(out / "campaign_results.json", campaign)
    for case_name, columns in summary.items():
        write_columns_csv(out / f"{case_name}_spread.csv", columns)
    return campaign


def campaign_cost(members: list[Member], cases: dict, workers: int) -> str:
    """The wall time a campaign of ``members`` is likely to take on ``workers`` workers (one
    member each at once), in words: each member's series estimate
    (``riprap.workflows.series.series_wall_seconds``), the longest first on the least busy
    worker."""
    costs = sorted((series_wall_seconds(cases[m.case_file], m.seed_offset)[0] for m in members),
                   reverse=True)
    busy = [0.0] * max(1, min(workers, len(members)))
    for cost in costs:
        busy[busy.index(min(busy))] += cost
    calibrated = {m.case_file for m in members
                  if cases[m.case_file].series.wave_calibration != "none"}
    calibration = sum(calibration_cost_seconds(cases[f])[0] for f in calibrated)
    workers_used = max(1, min(workers, sum(len(cases[f].series_steps) for f in calibrated) or 1))
    calibration_words = ("" if not calibrated else
                         f"; first the wave calibration, about "
                         f"{duration_words(calibration / workers_used)} on the workers")
    return (f"cost: about {duration_words(max(busy))} of wall time for the campaign: "
            f"{len(members)} members of about {duration_words(min(costs))}"
            + (f" to {duration_words(max(costs))}" if duration_words(max(costs))
               != duration_words(min(costs)) else "")
            + f" each (2 cores per member, examples/10's measured pace, within a factor of "
            f"2-3) on {len(busy)} worker{'s' if len(busy) > 1 else ''} at once"
            + calibration_words)


class _MemberLogs:
    """The campaign's terminal and ``campaign.log``: its own messages, and every member's
    progress and warnings as they are appended to the member's ``series.log`` (each line said
    with the member's name; a warning already said, by the checks or another member, is not
    said again)."""

    def __init__(self, out: Path, members: list[Member], say):
        self.path = out / CAMPAIGN_LOG
        self._say = say
        self._members = {m.name: out / m.name / SERIES_LOG for m in members}
        # a resumed campaign: what the members' logs held before is not said again
        self._offsets = {name: log_size(path) for name, path in self._members.items()}
        self._warnings = set()

    def say(self, line: str) -> None:
        self._say(line)
        append_log_lines(self.path, [line])

    def say_warning(self, line: str | None) -> None:
        if line is not None and line not in self._warnings:
            self._warnings.add(line)
            self.say(line)

    def follow(self) -> None:
        """Say what the members appended to their logs since the last call."""
        for name, path in self._members.items():
            lines, self._offsets[name] = read_new_log_lines(path, self._offsets[name])
            for line in lines:
                if line.startswith("riprap: warning"):
                    self.say_warning(line)
                else:
                    self.say(f"riprap: {name}: {line.removeprefix('riprap: ')}")


def _spread(members: list[Member], results: dict) -> dict:
    """Per case, per step: N_od and S as mean, smallest and largest over the case's seeds."""
    spread = {}
    for case_file in dict.fromkeys(m.case_file for m in members):
        curves = [results[m.name]["curve"] for m in members if m.case_file == case_file]
        steps = min(len(c["step"]) for c in curves)
        columns = {"step": list(range(1, steps + 1)), "members": [len(curves)] * steps}
        for name in ("stability_number", "N_od", "S", "q_m3_s_m"):
            values = np.array([[float(c[name][k]) for k in range(steps)] for c in curves])
            with warnings.catch_warnings():         # a step no member measured: NaN
                warnings.simplefilter("ignore", RuntimeWarning)
                columns[f"{name}_mean"] = [_finite(v) for v in np.nanmean(values, axis=0)]
                columns[f"{name}_min"] = [_finite(v) for v in np.nanmin(values, axis=0)]
                columns[f"{name}_max"] = [_finite(v) for v in np.nanmax(values, axis=0)]
        spread[case_file.stem] = columns
    return spread


def _finite(value) -> float:
    return float(value) if math.isfinite(value) else math.nan
