"""Reading a flume run's ``waves_report.json`` back (``riprap analyse``), checked field by field.

The file is riprap's own (``riprap.waves.report.flume_report``, written by
:func:`riprap.io.gauge_files.write_waves_report`), but it lies in a folder anyone can edit: a
height of ``NaN`` or ``-1``, a string where a number belongs or a list where a table belongs
would reach the stability number as nonsense or fail inside. Every field the analysis or its
report reads is checked here against what the writer writes, and the first wrong one is named
with the file, its place in the file (``gauges.g1.Hm0_m``) and its line. ``null`` stands for a
figure the run could not compute (a period of a record without two crossings) and is accepted for
computed figures; fields riprap does not know are left alone (a newer riprap's additions).
"""
from __future__ import annotations

import math
import re
from pathlib import Path

from riprap.errors import CaseFileError
from riprap.io.json_files import read_json_object

__all__ = ["WAVES_REPORT_FILE_NAME", "read_waves_report"]

WAVES_REPORT_FILE_NAME = "waves_report.json"

_ADVICE = "run the case again, or remove the file to analyse the layer alone"

# Kinds of value: (test, what is expected). A "?" after a kind in the tables below: null allowed.
_KINDS = {
    "coordinate": (lambda v: _is_number(v), "a finite number (m)"),
    "time": (lambda v: _is_number(v) and v >= 0, "a finite time >= 0 s"),
    "height": (lambda v: _is_number(v) and v >= 0, "a finite height >= 0 m"),
    "positive": (lambda v: _is_number(v) and v > 0, "a finite number > 0"),
    "ratio": (lambda v: _is_number(v) and v >= 0, "a finite number >= 0"),
    "signed": (lambda v: _is_number(v), "a finite number"),
    "count": (lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0,
              "a whole number >= 0"),
    "string": (lambda v: isinstance(v, str), "a string"),
    "strings": (lambda v: isinstance(v, list) and all(isinstance(s, str) for s in v),
                "a list of strings"),
    "numbers": (lambda v: isinstance(v, list) and all(_is_number(x) for x in v),
                "a list of finite numbers"),
}

_GAUGE = {"x_m": "coordinate", "analysed_from_s": "time", "samples": "count",
          "Hm0_m": "height?", "H1/3_m": "height?", "H2%_m": "height?", "Hmax_m": "height?",
          "Hmean_m": "height?", "waves": "count?", "Tp_s": "positive?", "Tm-1,0_s": "positive?",
          "Tz_s": "positive?", "note": "string", "caution": "string"}
_SPLIT = {"gauges": "strings", "spacing_m": "positive", "x_m": "numbers",
          "incident_Hm0_m": "height?", "reflected_Hm0_m": "height?",
          "incident_height_m": "height?", "reflected_height_m": "height?",
          "reflection_coefficient": "ratio?", "band_Hz": "numbers"}
_OVERTOPPING = {"x_m": "coordinate", "analysed_from_s": "time", "volume_m3_per_m": "signed?",
                "q_m3_s_per_m": "signed?", "q_l_s_per_m": "signed?", "duration_s": "positive?",
                "note": "string"}
_RUN_UP = {"x_m": "coordinate", "analysed_from_s": "time", "to_x_m": "coordinate?",
           "R_max_m": "signed?", "R2%_m": "signed?", "run_up_waves": "count?", "note": "string",
           "caution": "string"}
_TARGET = {"type": "string", "height_m": "positive", "period_s": "positive",
           "depth_m": "positive", "wave_length_m": "positive"}
# Top-level fields: a kind, or (container, fields of each entry): "table" maps names to entries,
# "list" lists entries, "object" is one entry.
_TOP = {"gauges": ("table", _GAUGE), "reflection": ("list", _SPLIT),
        "reflection_three_gauge": ("list", _SPLIT), "overtopping": ("table", _OVERTOPPING),
        "run_up": ("table", _RUN_UP), "target": ("object", _TARGET),
        "water_density_kg_m3": "positive", "record_end_s": "time", "not_computed": "strings",
        "cautions": "strings"}
_CONTAINERS = {"table": "a table {name: {...}}", "list": "a list [{...}, ...]",
               "object": "a table {...}"}


def _is_number(value) -> bool:
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value))


def _line_of(text: str, names) -> int | None:
    """Line of the field at ``names`` (keys and list indices), found key by key in order."""
    position, found = 0, None
    for name in names:
        if isinstance(name, int):
            position = _element_start(text, position, name)
            continue
        match = re.compile(r'"' + re.escape(name) + r'"\s*:').search(text, position)
        if match is None:
            break
        position, found = match.end(), match.start()
    return None if found is None else text.count("\n", 0, found) + 1


def _element_start(text: str, position: int, index: int) -> int:
    """Where element ``index`` of the JSON list opening at or after ``position`` starts (its end
    when the list is shorter), skipping strings and nested values."""
    start = text.find("[", position)
    if start < 0:
        return position
    depth, count, in_string, escaped = 0, 0, False, False
    for k in range(start, len(text)):
        char = text[k]
        if in_string:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                in_string = False
            continue
        if char == '"':
            in_string = True
        elif char in "[{":
            depth += 1
            if depth == 2 and count == index:
                return k
        elif char in "]}":
            depth -= 1
            if depth == 0:
                return k
        elif char == "," and depth == 1:
            count += 1
    return position


def _problem(path: Path, text: str, names, message: str) -> CaseFileError:
    where = ".".join(f"[{n}]" if isinstance(n, int) else str(n) for n in names).replace(".[", "[")
    line = _line_of(text, names)
    return CaseFileError(f"{path}{f':{line}' if line else ''}: {where} {message}; the file was "
                         f"changed after the run or is damaged: {_ADVICE}")


def _check_value(path, text, names, value, kind) -> None:
    nullable = kind.endswith("?")
    kind = kind.rstrip("?")
    if value is None and nullable:
        return
    test, expected = _KINDS[kind]
    if not test(value):
        raise _problem(path, text, names, f"= {_shown(value)}: expected {expected}"
                       + (" (or null: not computed)" if nullable else ""))


def _shown(value) -> str:
    import json

    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _check_entry(path, text, names, entry, fields) -> None:
    if not isinstance(entry, dict):
        raise _problem(path, text, names, f"= {_shown(entry)}: expected a table {{...}}")
    for key, kind in fields.items():
        if key in entry:
            _check_value(path, text, names + [key], entry[key], kind)


def read_waves_report(run_folder) -> dict | None:
    """The checked ``waves_report.json`` of a run folder, or None when the run wrote none."""
    run_folder = Path(run_folder)
    path = run_folder / WAVES_REPORT_FILE_NAME
    if not (run_folder.is_dir() and path.is_file()):
        return None
    report = read_json_object(path, "waves report", _ADVICE)
    text = path.read_text(encoding="utf-8")
    for key, spec in _TOP.items():
        if key not in report:
            continue
        value = report[key]
        if isinstance(spec, str):
            _check_value(path, text, [key], value, spec)
            continue
        container, fields = spec
        if container == "object":
            _check_entry(path, text, [key], value, fields)
            continue
        expected_type = dict if container == "table" else list
        if not isinstance(value, expected_type):
            raise _problem(path, text, [key], f"= {_shown(value)}: expected "
                                              f"{_CONTAINERS[container]}")
        items = value.items() if container == "table" else enumerate(value)
        for name, entry in items:
            _check_entry(path, text, [key, name], entry, fields)
    return report
