"""The record of a test series' folder (``series.json``, ``riprap.workflows.series``): what the
folder's steps were run from, so that a later run into the same folder resumes them, re-surveys
them, starts them again or refuses, and says why.

Three things are kept apart:

- the **run mode**: a smoke run (``RIPRAP_SMOKE=1``: every step cut to ``SMOKE_END_TIME`` s) gives
  no results. Its steps are never taken for a real run's: a real run over a smoke folder sets the
  smoke steps aside (into ``smoke_run/``) and runs the steps again; a smoke run over a folder of
  real steps is refused, so that they are not overwritten;
- the **run keys**: every key of the case file but the survey keys, and the pack file's content;
  a change of one refuses the folder, naming the key with its old and new values (the steps were
  run from the old ones);
- the **survey keys** (``SURVEY_KEYS``): they change only the surveys after the steps, so a change
  of one makes the finished steps' surveys again; the steps' own files are not touched.
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from riprap.case.build import SMOKE_END_TIME, smoke_mode
from riprap.errors import CaseFileError, RiprapError
from riprap.io.json_files import read_json_object
from riprap.io.output_folder import move_into
from riprap.io.pack import riprap_version

__all__ = ["SERIES_RECORD", "SERIES_FORMAT", "RUN_MODES", "SURVEY_KEYS", "SMOKE_FOLDER", "run_mode",
           "mode_words", "smoke_note", "series_fingerprint", "series_record", "claim_series_folder",
           "key_changes", "set_smoke_steps_aside", "Claim"]

#: The series folder's record: riprap version, run mode, case, fingerprint, steps.
SERIES_RECORD = "series.json"
#: Its format (a folder of another format is refused). 2: the run mode, the case's keys and the
#: survey keys recorded (2026-12).
SERIES_FORMAT = 2
#: The run modes a record may name.
RUN_MODES = ("full", "smoke")
#: Keys (table, key) that change only the surveys after the steps, not the steps' runs.
SURVEY_KEYS = (("series", "displacement_threshold"),)
#: Where a real run puts the smoke steps it replaces (inside the series folder).
SMOKE_FOLDER = "smoke_run"
#: What a series writes in its folder besides the steps (set aside with smoke steps).
SERIES_OUTPUTS = ("start", "series_results.json", "damage_curve.csv", "damage_curve.png",
                  "overtopping.png", "report.html", "series.log")


def run_mode() -> str:
    """``"smoke"`` (``RIPRAP_SMOKE=1``: every run cut short, no results) or ``"full"``."""
    return "smoke" if smoke_mode() else "full"


def mode_words(mode: str) -> str:
    """The run mode in words, for messages and reports."""
    if mode == "smoke":
        return (f"a smoke run (RIPRAP_SMOKE=1: every step cut to {SMOKE_END_TIME} s of simulated "
                "time, no results)")
    return "a full run"


def smoke_note() -> str:
    """What a smoke run's results are, for its records and reports."""
    return (f"every step was cut to {SMOKE_END_TIME} s of simulated time (RIPRAP_SMOKE=1): no "
            "results")


def _case_data(case) -> dict:
    """The case file's keys and values (as TOML data: not its comments or layout), without the
    output folder."""
    try:
        data = tomllib.loads(Path(case.source).read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise CaseFileError(f"{case.source}: cannot be read again to record the series ({error})"
                            ) from None
    output = data.get("output")
    if isinstance(output, dict):
        output.pop("directory", None)
        if not output:
            data.pop("output")
    return json.loads(json.dumps(data, default=str))


def _run_data(data: dict) -> dict:
    """``data`` without the survey keys."""
    data = json.loads(json.dumps(data))
    for table, key in SURVEY_KEYS:
        if isinstance(data.get(table), dict):
            data[table].pop(key, None)
    return data


def _pack_digest(case, data: dict) -> str | None:
    pack = data.get("pack")
    if not isinstance(pack, str):
        return None
    pack_path = (Path(case.base_dir) / pack).resolve()
    if not pack_path.is_file():
        return None
    return hashlib.sha256(pack_path.read_bytes()).hexdigest()


def _survey(case) -> dict:
    """The survey keys' values (defaults filled in), by ``table.key``."""
    return {f"{table}.{key}": getattr(getattr(case, table), key) for table, key in SURVEY_KEYS}


def series_fingerprint(case, mode: str | None = None) -> str:
    """A fingerprint of what the steps are run from: the case file's run keys (not the survey
    keys, the output folder, comments or layout), the pack it includes and the run mode (default
    this process's), so that a folder written for another case or mode is recognised."""
    data = _case_data(case)
    digest = hashlib.sha256()
    digest.update(json.dumps(_run_data(data), sort_keys=True).encode())
    digest.update(str(_pack_digest(case, data)).encode())
    digest.update((mode or run_mode()).encode())
    return digest.hexdigest()


def series_record(case, steps: list[dict], seed_offset: int = 0) -> dict:
    """The record of a series of ``case`` run now (``steps``: each step's sea)."""
    data = _case_data(case)
    mode = run_mode()
    return {"format": SERIES_FORMAT, "riprap_version": riprap_version(),
            "run_mode": mode, **({"smoke_end_time_s": SMOKE_END_TIME} if mode == "smoke" else {}),
            "case_file": str(Path(case.source).resolve()),
            "fingerprint": series_fingerprint(case, mode), "seed_offset": int(seed_offset),
            "case": data, "pack_sha256": _pack_digest(case, data), "survey": _survey(case),
            "steps": steps}


def _flat(data: dict) -> dict:
    """Every key of TOML ``data`` by its name in a case file: ``[table] key``, ``[[table]] n
    key`` (n from 1), top-level keys by their name."""
    flat = {}
    for name, value in data.items():
        if isinstance(value, dict):
            for key, entry in value.items():
                flat[f"[{name}] {key}"] = entry
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for number, table in enumerate(value, start=1):
                for key, entry in table.items():
                    flat[f"[[{name}]] {number} {key}"] = entry
            flat[f"[[{name}]] entries"] = len(value)
        else:
            flat[name] = value
    return flat


def _value(value) -> str:
    if value is _ABSENT:
        return "not given"
    if isinstance(value, float) and math.isfinite(value):
        return f"{value:g}"
    return json.dumps(value)


_ABSENT = object()


def key_changes(old: dict, new: dict) -> list[str]:
    """The keys whose values differ between two cases' TOML data, each as ``KEY: OLD -> NEW``."""
    old_flat, new_flat = _flat(old), _flat(new)
    changes = []
    for key in list(old_flat) + [k for k in new_flat if k not in old_flat]:
        before, after = old_flat.get(key, _ABSENT), new_flat.get(key, _ABSENT)
        if before != after:
            changes.append(f"{key}: {_value(before)} -> {_value(after)}")
    return changes


def _run_differences(old: dict, new: dict) -> list[str]:
    """What differs between two records in what the steps were run from."""
    differences = key_changes(_run_data(old.get("case", {})), _run_data(new["case"]))
    if old.get("pack_sha256") != new["pack_sha256"]:
        differences.append(f"the pack {new['case'].get('pack')!r}: its content changed")
    if old.get("seed_offset", 0) != new["seed_offset"]:
        differences.append(f"seed offset: {old.get('seed_offset', 0)} -> {new['seed_offset']}")
    return differences


def _step_folders(out: Path) -> list[Path]:
    return sorted(path for path in out.glob("step_*") if path.is_dir())


def _step_modes(out: Path) -> dict[Path, str]:
    """The run mode of every step folder with a ``summary.json`` (a finished step)."""
    modes = {}
    for folder in _step_folders(out):
        if (folder / "summary.json").is_file():
            summary = read_json_object(folder / "summary.json", "step summary",
                                       "delete the step's folder to run it again")
            modes[folder] = "smoke" if summary.get("smoke") else "full"
    return modes


@dataclass(frozen=True)
class Claim:
    """What a series run does about its folder's old content: ``note`` in words (the smoke steps
    it sets aside, the surveys it makes again; "" when it resumes or starts the folder) and
    whether it sets the smoke steps aside first."""

    note: str = ""
    set_smoke_aside: bool = False


def claim_series_folder(out: Path, record: dict) -> Claim:
    """Check that the series ``record`` may run in the folder ``out`` (nothing is changed here);
    returns what the run will do about the folder's old content.

    Refused, naming why: a folder written by another riprap version or format; one whose steps
    were run from other run keys (naming each key with its old and new values), another pack or
    other seeds; a smoke run over a folder of real steps; step folders without a record."""
    out = Path(out)
    path = out / SERIES_RECORD
    modes = _step_modes(out) if out.is_dir() else {}
    if not path.is_file():
        if out.is_dir() and _step_folders(out):
            raise RiprapError(f"{out}: holds step folders but no {SERIES_RECORD}: not a series "
                              "riprap wrote; give another --out folder")
        return Claim()
    old = read_json_object(path, "series record", "it was written by riprap series")
    if old.get("format") != SERIES_FORMAT or old.get("riprap_version") != riprap_version():
        raise RiprapError(
            f"{path}: this folder holds a series written by riprap "
            f"{old.get('riprap_version')!r} (format {old.get('format')!r}), this is "
            f"{riprap_version()} (format {SERIES_FORMAT}); its steps are not resumed or "
            "overwritten: give another --out folder")
    mode, old_mode = record["run_mode"], old.get("run_mode")
    if old_mode not in RUN_MODES:
        raise RiprapError(f"{path}: run_mode = {json.dumps(old_mode)} is not one riprap writes "
                          f"({' or '.join(RUN_MODES)}): the record was edited or damaged; its "
                          "steps are not resumed or overwritten: give another --out folder")
    if mode == "smoke":
        real_steps = sorted(folder.name for folder, step in modes.items() if step == "full")
        if real_steps or (old_mode != "smoke" and _step_folders(out)):
            raise RiprapError(
                f"{path}: this folder holds a series run in full (steps "
                f"{', '.join(real_steps) or 'begun'}); {mode_words('smoke')} would overwrite "
                "them: give the smoke run another --out folder, or run without RIPRAP_SMOKE")
    differences = _run_differences(old, record)
    smoke_run = old_mode == "smoke" or "smoke" in modes.values()
    if differences and not smoke_run:
        raise RiprapError(
            f"{path}: this folder holds the series of another case ({old.get('case_file')}) or "
            f"of the same file since changed: {'; '.join(differences)}. Its steps were run from "
            "the old values and are not resumed or overwritten: give another --out folder, or "
            "restore those values")
    if smoke_run and (differences or mode != "smoke"):
        smoke_steps = [folder.name for folder in _step_folders(out)] or ["(none begun)"]
        why = ("not results" if mode != "smoke" else "") + (
            f"{' and ' if mode != 'smoke' else ''}of the case before it changed "
            f"({'; '.join(differences)})" if differences else "")
        return Claim(f"the smoke steps {', '.join(smoke_steps)} (RIPRAP_SMOKE=1, cut to "
                     f"{SMOKE_END_TIME} s) are {why}: set aside into {out / SMOKE_FOLDER} and "
                     f"run again as {mode_words(mode)}", set_smoke_aside=True)
    old_survey = old.get("survey", {})
    resurveyed = [f"[{key.replace('.', '] ')}: {_value(old_survey.get(key, _ABSENT))} -> "
                  f"{_value(value)}" for key, value in record["survey"].items()
                  if old_survey.get(key) != value]
    if resurveyed:
        return Claim(f"{'; '.join(resurveyed)}: only the surveys change, so the finished steps "
                     "are surveyed again; their runs are not (their files are kept as they are)")
    return Claim()


def set_smoke_steps_aside(out: Path) -> None:
    """Move the smoke steps and what the series made of them into ``out/smoke_run/`` (an older
    one there is replaced: it held smoke steps too); the folder's other content stays."""
    out = Path(out)
    names = [folder.name for folder in _step_folders(out)] + [
        name for name in SERIES_OUTPUTS if (out / name).exists()]
    move_into(out, names, out / SMOKE_FOLDER)
