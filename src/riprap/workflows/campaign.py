"""``riprap campaign``: the independent members of a test campaign (test series of other seeds,
other designs) as tasks of Dask's distributed scheduler (``dask.distributed``;
``docs/campaign.md``).

One member is one test series (``riprap.workflows.series.run_series``) in its own folder under
the campaign's (``<case name>_seed<k>``), complete on its own; one member runs per worker process,
with ``threads`` numba threads of its own. The scheduler is a ``LocalCluster`` on this machine by
default, or the one at ``scheduler`` (``tcp://host:8786``; a SLURM or PBS cluster made with
dask-jobqueue gives one); ``client`` takes a ``dask.distributed.Client`` the caller made.

Resuming: the campaign folder records the riprap version and its members (``campaign.json``); a
folder of another version or other members is refused before anything starts. Every member
resumes on its own (``run_series``): finished steps are not run again, a step that was cut off
goes on from its last checkpoint. So a campaign killed or lost, or a member whose worker died,
is started again with the same command.

Dask is optional: ``pip install 'riprap[campaign]'``; riprap and single runs work without it.
"""
from __future__ import annotations

import math
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
from riprap.workflows.series import check_series, run_series, series_fingerprint

__all__ = ["Member", "members_of", "run_campaign", "CAMPAIGN_RECORD", "SCHEDULER_TIMEOUT_S"]

CAMPAIGN_RECORD = "campaign.json"
CAMPAIGN_FORMAT = 1
#: Seconds a scheduler address is given to answer before the campaign is refused.
SCHEDULER_TIMEOUT_S = 5.0


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


def _run_member(case_file: str, folder: str, seed_offset: int, threads: int) -> dict:
    """A member on a worker: its series, with ``threads`` numba threads (no progress bar)."""
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    lines = []
    results = run_series(load_case(case_file), output_directory=folder, progress=False,
                         say=lines.append, seed_offset=seed_offset)
    results["log"] = lines
    return results


def _client(scheduler: str | None, workers: int, threads: int):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise RiprapError("a campaign runs its members on Dask (dask.distributed), which is not "
                          "installed: pip install 'riprap[campaign]' (or: pip install "
                          "distributed)") from None
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


def _claim(out: Path, members: list[Member], fingerprints: list[str], *,
           write: bool = True) -> None:
    """Refuse a campaign folder of another riprap version or other members (nothing in it is
    touched); otherwise record the campaign there (``write``)."""
    record = {"format": CAMPAIGN_FORMAT, "riprap_version": riprap_version(),
              "members": [{"name": m.name, "case_file": str(m.case_file),
                           "seed_offset": m.seed_offset, "fingerprint": f}
                          for m, f in zip(members, fingerprints)]}
    path = out / CAMPAIGN_RECORD
    if path.is_file():
        old = read_json_object(path, "campaign record", "riprap campaign wrote it")
        if old.get("format") != CAMPAIGN_FORMAT or old.get("riprap_version") != riprap_version():
            raise RiprapError(f"{path}: a campaign written by riprap {old.get('riprap_version')!r}, "
                              f"this is {riprap_version()}; nothing in it is resumed or "
                              "overwritten: give another --out folder")
        if old.get("members") != record["members"]:
            before = ", ".join(m.get("name", "?") for m in old.get("members", []))
            raise RiprapError(f"{path}: a campaign of other members or cases ({before}); "
                              "nothing in it is resumed or overwritten: give another --out "
                              "folder, or the same cases and seeds as before")
    if write:
        write_json(path, record)


def run_campaign(members: list[Member], out, *, workers: int = 2, threads: int = 1,
                 scheduler: str | None = None, client=None, say=print) -> dict:
    """Run ``members`` as Dask tasks; returns the campaign's results (``campaign_results.json``):
    per member its series results, and per step the spread of N_od and S over the members of
    each case."""
    out = Path(out)
    if workers < 1 or threads < 1:
        raise CaseFileError(f"workers ({workers}) and threads ({threads}) must be >= 1")
    cases = {member.case_file: load_case(member.case_file) for member in members}
    for member in members:
        case = cases[member.case_file]
        if not case.is_series:
            raise CaseFileError(f"{member.case_file}: a campaign member is a test series: the "
                                "case needs [series] and [[series_steps]]")
        check_series(case, out / member.name, member.seed_offset)
    fingerprints = [series_fingerprint(cases[m.case_file]) for m in members]
    _claim(out, members, fingerprints, write=False)      # before any worker starts
    own_cluster = None
    if client is None:
        client, own_cluster = _client(scheduler, workers, threads)
    try:
        prepare_output_folder(out)
        _claim(out, members, fingerprints)
        say(f"riprap: campaign of {len(members)} members on the Dask scheduler "
            f"{getattr(client.scheduler, 'address', '')}: " + ", ".join(m.name for m in members))
        futures = [client.submit(_run_member, str(m.case_file), str(out / m.name), m.seed_offset,
                                 threads, key=f"riprap-{m.name}", pure=False) for m in members]
        results, failed = {}, {}
        for member, future in zip(members, futures):
            try:
                results[member.name] = future.result()
                say(f"riprap: campaign member {member.name} done")
            except Exception as error:  # noqa: BLE001 - one member's failure ends only it
                failed[member.name] = f"{type(error).__name__}: {error}"
                say(f"riprap: campaign member {member.name} failed: {failed[member.name]}")
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()
    if failed:
        write_json(out / "campaign_results.json", {"members": results, "failed": failed})
        raise RiprapError(
            f"{len(failed)} of {len(members)} campaign members failed ("
            + "; ".join(f"{name}: {why}" for name, why in failed.items())
            + f"); the others are done. Their folders under {out} keep what was done: mend the "
            "cause and start the same command again to resume them")
    summary = _spread(members, results)
    write_json(out / "campaign_results.json", {"members": results, "spread": summary})
    for case_name, columns in summary.items():
        write_columns_csv(out / f"{case_name}_spread.csv", columns)
    return {"members": results, "spread": summary}


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
