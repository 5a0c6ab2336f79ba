"""The armour-layer description of a pack (``layer.json``) and its contact table (``contacts.csv``).

``riprap place`` writes both beside ``pack.toml``; ``riprap analyse`` reads them back:

- ``layer.json``: which bodies of the pack are armour units (``unit_bodies``, in the order of the
  pack's ``[[bodies]]``), their placement rows and design positions, the unit kind, size and
  named axes (in the frame of the unit's mesh as stored in ``shapes/``), the slope and the
  underlayer top. ``format`` and ``format_version`` say what the file is.
- ``contacts.csv``: one row per touching pair at the moment the pack was written, with the
  forces on ``body_i`` (N) and ``body_j = -1 - w`` for wall ``w`` (walls in the order of the
  pack's ``[[walls]]``). The forces include the tangential (friction) forces, which depend on
  the history of the run and cannot be found again from the poses alone.

Every problem is named with the file: a missing file, a missing field, a field of the wrong
size, a file of another format version.
"""
from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file
from riprap.io.json_files import strict_loads, write_json
from riprap.solid.solver import ContactRecords

__all__ = ["LAYER_FILE_NAME", "CONTACTS_FILE_NAME", "LAYER_FORMAT", "LAYER_FORMAT_VERSION",
           "write_layer_file", "read_layer_file", "write_contact_table", "read_contact_table",
           "CONTACT_COLUMNS"]

LAYER_FILE_NAME = "layer.json"
CONTACTS_FILE_NAME = "contacts.csv"
LAYER_FORMAT = "riprap armour layer"
LAYER_FORMAT_VERSION = 1

#: Columns of a contact table, in order.
CONTACT_COLUMNS = ("body_i", "body_j", "point_x_m", "point_y_m", "point_z_m",
                   "normal_force_x_N", "normal_force_y_N", "normal_force_z_N",
                   "tangential_force_x_N", "tangential_force_y_N", "tangential_force_z_N")

# Fields of layer.json: name -> (kind, meaning), all required.
_FIELDS = {
    "unit_kind": ("string", "armour unit kind"),
    "unit_shape": ("shape_names", "name of the units' shape in pack.toml (a list of names for "
                                  "rock armour's stones)"),
    "nominal_diameter_m": ("number", "D_n of a unit"),
    "unit_volume_m3": ("number", "volume of a unit"),
    "unit_height_m": ("number", "height H of a unit"),
    "unit_axes": ("axes", "named unit vectors in the unit mesh's frame, the primary first "
                          "('nose' of a unit, 'long' of a stone)"),
    "slope": ("slope", "cotangent, width, length, toe_x, toe_level, toe_stop_distance (and "
                       "periodic: true on a periodic strip; absent: false)"),
    "underlayer_top_m": ("number", "underlayer top above the face"),
    "unit_bodies": ("integers", "body index of each unit"),
    "rows": ("integers", "placement row of each unit"),
    "design_positions": ("points", "design centroid of each unit"),
    "design": ("mapping", "design packing density coefficient, layer thickness, porosity"),
}
_SLOPE_FIELDS = ("cotangent", "width", "length", "toe_x", "toe_level", "toe_stop_distance")


def _finite_list(values) -> list:
    return [float(v) for v in np.asarray(values, dtype=float).reshape(-1)]


def write_layer_file(directory, layer) -> Path:
    """Write ``layer`` (:class:`riprap.analysis.layer_state.LayerDescription`) as ``layer.json``."""
    slope = layer.slope
    data = {
        "format": LAYER_FORMAT,
        "format_version": LAYER_FORMAT_VERSION,
        "unit_kind": layer.unit_kind,
        "unit_shape": (layer.unit_shape if isinstance(layer.unit_shape, str)
                       else list(layer.unit_shape)),
        "nominal_diameter_m": float(layer.nominal_diameter),
        "unit_volume_m3": float(layer.unit_volume),
        "unit_height_m": float(layer.unit_height),
        "unit_axes": {name: _finite_list(axis) for name, axis in layer.unit_axes.items()},
        "slope": {**{name: float(getattr(slope, name)) for name in _SLOPE_FIELDS},
                  "periodic": bool(slope.periodic)},
        "underlayer_top_m": float(layer.underlayer_top),
        "unit_bodies": [int(b) for b in layer.unit_bodies],
        "rows": [int(r) for r in layer.rows],
        "design_positions": [_finite_list(p) for p in np.asarray(layer.design_positions).reshape(-1, 3)],
        "design": {name: float(value) for name, value in layer.design.items()},
    }
    path = Path(directory) / LAYER_FILE_NAME
    return write_json(path, data, indent=1)


def _is_number(value) -> bool:
    """A finite JSON number (true/false are not numbers, NaN/Infinity are not finite)."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value))


def _is_integer(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_point(value) -> bool:
    return isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value)


# Fields of layer.json that must be positive (sizes of a unit).
_POSITIVE_FIELDS = ("nominal_diameter_m", "unit_volume_m3", "unit_height_m")


def _check_field(name, value, kind, problems) -> None:
    """Append to ``problems`` what is wrong with field ``name`` (as ``(name, message)``)."""
    def bad(message):
        problems.append((name, message))

    if kind == "string":
        if not (isinstance(value, str) and value):
            bad(f"'{name}' must be a non-empty string, got {value!r}")
    elif kind == "number":
        if not _is_number(value):
            bad(f"'{name}' must be a finite number, got {value!r}")
        elif name in _POSITIVE_FIELDS and value <= 0:
            bad(f"'{name}' must be positive, got {value!r}")
    elif kind == "integers":
        if not isinstance(value, list):
            bad(f"'{name}' must be a list of integers, got {value!r}")
            return
        wrong = [k for k, v in enumerate(value) if not _is_integer(v) or v < 0]
        if wrong:
            k = wrong[0]
            bad(f"'{name}' must be a list of integers >= 0; entry {k} is {value[k]!r}"
                + (f" ({len(wrong)} bad entries)" if len(wrong) > 1 else ""))
    elif kind == "points":
        if not isinstance(value, list):
            bad(f"'{name}' must be a list of [x, y, z] points, got {value!r}")
            return
        wrong = [k for k, v in enumerate(value) if not _is_point(v)]
        if wrong:
            k = wrong[0]
            bad(f"'{name}' must be a list of [x, y, z] points (3 finite numbers each); entry {k} "
                f"is {value[k]!r}" + (f" ({len(wrong)} bad entries)" if len(wrong) > 1 else ""))
    elif kind == "shape_names":
        names = [value] if isinstance(value, str) else value
        if not (isinstance(names, list) and names
                and all(isinstance(v, str) and v for v in names)):
            bad(f"'{name}' must be a shape name or a non-empty list of them, got {value!r}")
    elif kind == "axes":
        if not isinstance(value, dict) or not value:
            bad(f"'{name}' must map axis names to [x, y, z] (the primary axis first: 'nose' of a "
                "unit, 'long' of a stone)")
            return
        for axis, vector in value.items():
            if not _is_point(vector):
                bad(f"'{name}': axis '{axis}' must be [x, y, z] (3 finite numbers), got {vector!r}")
            elif math.hypot(*vector) == 0.0:
                bad(f"'{name}': axis '{axis}' is the zero vector; give a direction")
    elif kind == "slope":
        if not isinstance(value, dict):
            bad(f"'slope' must be a table of {', '.join(_SLOPE_FIELDS)}, got {value!r}")
            return
        missing = [f for f in _SLOPE_FIELDS if f not in value]
        if missing:
            bad(f"'slope' lacks {', '.join(missing)}")
        for field in _SLOPE_FIELDS:
            if field in value and not _is_number(value[field]):
                bad(f"'slope': '{field}' must be a finite number, got {value[field]!r}")
        if not isinstance(value.get("periodic", False), bool):
            bad(f"'slope': 'periodic' must be true or false, got {value['periodic']!r}")
    elif kind == "mapping":
        if not isinstance(value, dict):
            bad(f"'{name}' must be a table of numbers, got {value!r}")
            return
        for key, number in value.items():
            if not _is_number(number):
                bad(f"'{name}': '{key}' must be a finite number, got {number!r}")


def _field_line(text: str, name: str) -> int | None:
    """Line of the first ``"name":`` in the JSON text (for messages), or None."""
    match = re.search(r'"' + re.escape(name) + r'"\s*:', text)
    return text.count("\n", 0, match.start()) + 1 if match else None


def read_layer_file(directory, n_bodies: int | None = None) -> dict:
    """Read ``layer.json`` of a pack folder, every field checked; ``n_bodies``: the pack's body
    count, to check the body indices against.

    Returns the fields of :class:`~riprap.analysis.layer_state.LayerDescription`
    (``LayerDescription.from_fields`` builds it) as plain data: numbers, arrays, ``slope`` a dict
    of its six numbers, and ``slope_source`` the file and line that a slope error names."""
    path = Path(directory) / LAYER_FILE_NAME
    if not path.is_file():
        raise CaseFileError(
            f"{path}: missing. The analysis needs the layer description that 'riprap place' writes "
            "beside pack.toml (which bodies are armour units, their rows and design positions, the "
            "slope); this pack was written without it (by an older riprap or by hand). Place the "
            "layer again with this version, or write layer.json (riprap.io.layer_file.write_layer_file).")
    text = read_text_file(path, what="layer file", extension=".json")
    if not text.strip():
        raise CaseFileError(f"{path}: is empty; write it again (riprap place, or "
                            "riprap.io.layer_file.write_layer_file)")
    try:
        data = strict_loads(text)
    except json.JSONDecodeError as error:
        raise CaseFileError(f"{path}:{error.lineno}: not valid JSON: {error.msg}") from None
    except ValueError as error:
        raise CaseFileError(f"{path}: not standard JSON: {error}; place the layer again") from None
    except RecursionError:
        raise CaseFileError(f"{path}: not valid JSON (nested too deeply)") from None
    if not isinstance(data, dict) or data.get("format") != LAYER_FORMAT:
        raise CaseFileError(f"{path}: not a riprap layer description (its 'format' is "
                            f"{data.get('format') if isinstance(data, dict) else None!r}, expected "
                            f"{LAYER_FORMAT!r})")
    version = data.get("format_version")
    if version != LAYER_FORMAT_VERSION:
        raise CaseFileError(f"{path}: format_version {version!r}; this riprap reads layer files of "
                            f"format_version {LAYER_FORMAT_VERSION}. Place the layer again with this "
                            "riprap version.")
    problems = []
    missing = [name for name in _FIELDS if name not in data]
    if missing:
        problems.append((None, "missing field(s): " + ", ".join(
            f"'{name}' ({_FIELDS[name][1]})" for name in missing)))
    for name, (kind, _) in _FIELDS.items():
        if name in data:
            _check_field(name, data[name], kind, problems)
    if not problems:
        n_units = len(data["unit_bodies"])
        if n_units == 0:
            problems.append(("unit_bodies", "'unit_bodies' is empty; a layer has at least one unit"))
        for name in ("rows", "design_positions"):
            if len(data[name]) != n_units:
                problems.append((name, f"'{name}' has {len(data[name])} entries, 'unit_bodies' "
                                       f"{n_units}"))
        if n_bodies is not None:
            bad = [b for b in data["unit_bodies"] if not 0 <= b < n_bodies]
            if bad:
                problems.append(("unit_bodies", f"'unit_bodies' names bodies {bad[:5]} but the pack "
                                                f"has {n_bodies} bodies (indices from 0)"))
        if data["unit_kind"] == "armour_stone":
            lacking = [k for k in ("layers", "dn50_m", "packing_density_coefficient",
                                   "layer_thickness_m") if k not in data["design"]]
            if lacking:
                problems.append(("design", "a rock layer's 'design' needs " + ", ".join(
                    f"'{k}'" for k in lacking) + " (riprap place of [armour_stone] writes them)"))
        if len(set(data["unit_bodies"])) != n_units:
            problems.append(("unit_bodies", "'unit_bodies' lists a body twice"))
    if problems:
        located = []
        for name, message in problems:
            line = _field_line(text, name) if name else None
            located.append(f"{path}:{line}: {message}" if line else f"{path}: {message}")
        raise CaseFileError.from_problems(located, 20)
    slope_line = _field_line(text, "slope")
    return dict(
        unit_kind=data["unit_kind"],
        unit_shape=(data["unit_shape"] if isinstance(data["unit_shape"], str)
                    else tuple(data["unit_shape"])),
        nominal_diameter=float(data["nominal_diameter_m"]), unit_volume=float(data["unit_volume_m3"]),
        unit_height=float(data["unit_height_m"]),
        unit_axes={name: np.asarray(axis, dtype=float) for name, axis in data["unit_axes"].items()},
        slope={**{name: float(data["slope"][name]) for name in _SLOPE_FIELDS},
               "periodic": bool(data["slope"].get("periodic", False))},
        slope_source=f"{path}{f':{slope_line}' if slope_line else ''}",
        underlayer_top=float(data["underlayer_top_m"]),
        unit_bodies=np.asarray(data["unit_bodies"], dtype=np.int64),
        rows=np.asarray(data["rows"], dtype=np.int64),
        design_positions=np.asarray(data["design_positions"], dtype=float).reshape(-1, 3),
        design={name: float(value) for name, value in data["design"].items()})


def write_contact_table(path, contacts) -> Path:
    """Write contact records (``ContactRecords``) as CSV, numbers with ``repr`` (exact)."""
    path = Path(path)
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    numbers = np.hstack([np.asarray(contacts.points, dtype=float).reshape(-1, 3),
                         np.asarray(contacts.normal_forces, dtype=float).reshape(-1, 3),
                         np.asarray(contacts.tangential_forces, dtype=float).reshape(-1, 3)])
    lines = ["# contacts: forces on body_i (N); body_j = -1 - w is wall w; points in m",
             ",".join(CONTACT_COLUMNS)]
    for k in range(len(body_i)):
        lines.append(f"{body_i[k]},{body_j[k]}," + ",".join(repr(float(v)) for v in numbers[k]))
    temporary = path.with_name(path.name + ".partial")
    temporary.write_text("\n".join(lines) + "\n", encoding="utf-8")
    os.replace(temporary, path)
    return path


def _body_index(text: str, column: str, where: str) -> int:
    """An integer body index, exactly (``1.7`` is refused, never truncated)."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        raise CaseFileError(f"{where}: {column} = {text.strip()!r} is not a number; body indices "
                            "are integers") from None
    if not (math.isfinite(value) and value.is_integer() and abs(value) < 2**53):
        raise CaseFileError(f"{where}: {column} = {text.strip()} is not an integer body index "
                            "(bodies count from 0; body_j = -1 - w for wall w)")
    return int(value)


def read_contact_table(path):
    """Read a contact table written by :func:`write_contact_table` into ``ContactRecords``.

    A table with its header and no rows is a state without contacts; an empty file, or one
    without the header line, is refused (it is not a table the writer makes). Every row must have
    integer body indices (``body_i >= 0``, ``body_j != body_i``) and finite numbers; errors name
    the file, the line and the column.
    """
    path = Path(path)
    if not path.is_file():
        raise CaseFileError(
            f"{path}: missing. The analysis needs the contact forces of the pack (written by "
            "'riprap place' beside pack.toml); without them the friction forces, which depend on "
            "the run's history, are unknown.")
    rows = []
    header_seen = False
    text_of_file = read_text_file(path, what="contact table", extension=".csv")
    for number, line in enumerate(text_of_file.splitlines(), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        where = f"{path}:{number}"
        if not header_seen:
            columns = tuple(name.strip() for name in text.split(","))
            if columns != CONTACT_COLUMNS:
                raise CaseFileError(f"{where}: columns {', '.join(columns)}; expected "
                                    f"{', '.join(CONTACT_COLUMNS)} (the header line comes first)")
            header_seen = True
            continue
        fields = text.split(",")
        try:
            values = [float(v) for v in fields]
        except ValueError:
            raise CaseFileError(f"{where}: not all fields are numbers: {text!r}") from None
        if len(fields) != len(CONTACT_COLUMNS):
            raise CaseFileError(f"{where}: expected {len(CONTACT_COLUMNS)} fields "
                                f"({', '.join(CONTACT_COLUMNS)}), got {len(fields)}: {text!r}")
        values = values[2:]
        for column, value in zip(CONTACT_COLUMNS[2:], values):
            if not math.isfinite(value):
                raise CaseFileError(f"{where}: {column} = {value} is not finite; expected "
                                    f"{len(CONTACT_COLUMNS)} finite numbers, got {text!r}")
        body_i = _body_index(fields[0], "body_i", where)
        body_j = _body_index(fields[1], "body_j", where)
        if body_i < 0:
            raise CaseFileError(f"{where}: body_i = {body_i}; body_i is a body (from 0), only "
                                "body_j may be a wall (-1 - w)")
        if body_j == body_i:
            raise CaseFileError(f"{where}: body_i and body_j are both {body_i}; a contact joins "
                                "two different bodies")
        rows.append([body_i, body_j] + values)
    if not header_seen:
        state = "is empty" if not text_of_file.strip() else "has no header line"
        raise CaseFileError(
            f"{path}: {state}; a contact table starts with the header "
            f"{','.join(CONTACT_COLUMNS)} (a table with the header and no rows means no "
            "contacts). Write it again (riprap place, or riprap.io.layer_file.write_contact_table).")
    body_i = np.array([row[0] for row in rows], dtype=np.int64)
    body_j = np.array([row[1] for row in rows], dtype=np.int64)
    table = np.asarray([row[2:] for row in rows], dtype=float).reshape(-1, len(CONTACT_COLUMNS) - 2)
    return ContactRecords(body_i=body_i, body_j=body_j,
                          points=table[:, 0:3].copy(), normal_forces=table[:, 3:6].copy(),
                          tangential_forces=table[:, 6:9].copy(), stiffness=np.zeros(len(table)))
