"""What defines a run, kept in its checkpoints so that a restart continues the same run.

A restart continues the state of a checkpoint with the case as it is now. If the case changed in
anything but what may change, the restart would mix two runs (two sea states in one waves report,
one friction before and another after), so it is refused, naming the changed keys with their old
and new values. What may change (``RESTART_MAY_CHANGE``): how long the run goes on (end_time),
what it writes and how often (output_interval, checkpoint_interval, ``[output]``), and the time
step, so that a run that blew up can go on with a smaller one (time_step, time_step_safety,
``[fluid]`` courant_number and max_time_step). The list is in the README (Restarts) and
``docs/outputs.md``.

The record maps each key of the loaded case (defaults filled, packs included) to its value as
canonical JSON text; a file is recorded by its name (a project moved to another folder restarts).
Tables of more than ``_LISTED_ENTRIES`` entries (the bodies of a large pack) keep one fingerprint
per entry instead of every value, so the checkpoint stays small.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
from pathlib import Path

__all__ = ["RESTART_MAY_CHANGE", "RunDefinition", "case_record"]

#: Keys a restart may change, as ``(table, key)``; ``(table, None)``: the whole table.
RESTART_MAY_CHANGE = (("simulation", "end_time"), ("simulation", "output_interval"),
                      ("simulation", "checkpoint_interval"), ("simulation", "time_step"),
                      ("simulation", "time_step_safety"), ("fluid", "courant_number"),
                      ("fluid", "max_time_step"), ("output", None))

# Fields of Case that are not keys of the case file.
_NOT_KEYS = ("format_version", "source", "base_dir")
# Tables recorded only when the case has entries, so that a checkpoint written before they
# existed restarts (its record has no count of them).
_RECORDED_WHEN_GIVEN = ("friction",)
# Keys recorded only when given (not at their default, "off"), so that a checkpoint written
# before they existed restarts.
_KEYS_RECORDED_WHEN_GIVEN = {("fluid", "contact_only_below_cells"): 0.0,
                             ("fluid", "cut_faces"): "mixture"}
# Above this many entries, a [[table]] keeps one fingerprint per entry.
_LISTED_ENTRIES = 100


def _plain(value):
    if dataclasses.is_dataclass(value):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, os.PathLike):
        return Path(value).name
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if hasattr(value, "item"):           # numpy scalars
        return _plain(value.item())
    return value


def _text(value) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str)


def _may_change(table: str, key: str) -> bool:
    return (table, key) in RESTART_MAY_CHANGE or (table, None) in RESTART_MAY_CHANGE


def _entry_fields(entry: dict) -> dict:
    """An entry's keys as the case file has them: ``parameters`` are keys of the table."""
    fields = {k: v for k, v in entry.items() if k != "parameters"}
    fields.update(entry.get("parameters") or {})
    return fields


def _effective_waves(case, fields: dict) -> dict:
    """An irregular sea with duration 0 lasts the end time: record the duration it has, so that a
    changed end_time that changes the sea is refused (the waves report would mix two seas)."""
    if case.waves is not None and fields.get("type") == "irregular" and not fields.get("duration"):
        fields = dict(fields, duration=case.simulation.end_time)
    return fields


def case_record(case) -> dict[str, str]:
    """``{key: canonical JSON text}`` of every key of ``case`` a restart may not change; keys
    named as in the case file (``[simulation] seed``, ``[[materials]] 'rock' friction_coefficient``,
    ``[[bodies]] entry 3 position``)."""
    record = {}
    for field in dataclasses.fields(case):
        table = field.name
        if table in _NOT_KEYS:
            continue
        value = getattr(case, table)
        if value is None:
            continue
        if isinstance(value, tuple):
            if not value and table in _RECORDED_WHEN_GIVEN:
                continue
            entries = [_entry_fields(_plain(item)) for item in value]
            record[f"[[{table}]] count"] = _text(len(entries))
            for number, fields in enumerate(entries, start=1):
                name = fields.get("name") if isinstance(fields.get("name"), str) else None
                label = f"[[{table}]] '{name}'" if name else f"[[{table}]] entry {number}"
                if len(entries) > _LISTED_ENTRIES:
                    digest = hashlib.sha256(_text(fields).encode()).hexdigest()[:16]
                    record[label] = _text(f"fingerprint {digest}")
                    continue
                for key, item in fields.items():
                    record[f"{label} {key}"] = _text(item)
            continue
        fields = _entry_fields(_plain(value))
        if table == "waves":
            fields = _effective_waves(case, fields)
        for key, item in fields.items():
            if _KEYS_RECORDED_WHEN_GIVEN.get((table, key), ()) == item:
                continue
            if not _may_change(table, key):
                record[f"[{table}] {key}"] = _text(item)
    return record


def _is_fingerprint(text) -> bool:
    return isinstance(text, str) and text.startswith('"fingerprint ')


def _may_change_text() -> str:
    """``end_time, ... of [simulation], ... and [output]``, from RESTART_MAY_CHANGE."""
    tables = {}
    for table, key in RESTART_MAY_CHANGE:
        tables.setdefault(table, []).append(key)
    parts = [f"[{table}]" if None in keys else f"{_listed(keys)} of [{table}]"
             for table, keys in tables.items()]
    return "; ".join(parts)


def _listed(words) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


@dataclasses.dataclass(frozen=True)
class RunDefinition:
    """The record of a case (``values``) and what its restarts are checked against; a
    :class:`riprap.simulation.Simulation` built from a case carries one."""

    values: dict
    case_file: str = ""

    @classmethod
    def of(cls, case) -> "RunDefinition":
        return cls(values=case_record(case), case_file=str(case.source))

    def changes(self, recorded: dict) -> list[str]:
        """Each key whose value differs from the checkpoint's ``recorded`` one, as
        ``key: old -> new``, in the case's order."""
        keys = list(self.values) + [k for k in recorded if k not in self.values]
        changed = []
        for key in keys:
            old, new = recorded.get(key), self.values.get(key)
            if old != new and _is_fingerprint(old) and _is_fingerprint(new):
                changed.append(f"{key} changed (a table this large keeps a fingerprint of each "
                               "entry, not its values)")
            elif old != new:
                changed.append(f"{key} was {old if old is not None else '(not set)'}, is now "
                               f"{new if new is not None else '(not set)'}")
        return changed

    def refusal(self, checkpoint, recorded) -> str | None:
        """The message refusing a restart from ``checkpoint`` whose record is ``recorded``, or
        None when nothing but what may change has changed."""
        if not isinstance(recorded, dict):
            return None
        changed = self.changes(recorded)
        if not changed:
            return None
        shown = "; ".join(changed[:3]) + (f" (and {len(changed) - 3} more)" if len(changed) > 3
                                          else "")
        return (f"{checkpoint}: the case {self.case_file or ''} has changed since this checkpoint "
                f"was written: {shown}. A restart continues the same run and may change only "
                f"{_may_change_text()}; undo the change, or start the run again from the case "
                "file without --restart")
