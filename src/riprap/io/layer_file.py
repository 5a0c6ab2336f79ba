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
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file

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
    "unit_shape": ("string", "name of the units' shape in pack.toml"),
    "nominal_diameter_m": ("number", "D_n of a unit"),
    "unit_volume_m3": ("number", "volume of a unit"),
    "unit_height_m": ("number", "height H of a unit"),
    "unit_axes": ("axes", "named unit vectors in the unit mesh's frame, 'nose' at least"),
    "slope": ("slope", "cotangent, width, length, toe_x, toe_level, toe_stop_distance"),
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
        "unit_shape": layer.unit_shape,
        "nominal_diameter_m": float(layer.nominal_diameter),
        "unit_volume_m3": float(layer.unit_volume),
        "unit_height_m": float(layer.unit_height),
        "unit_axes": {name: _finite_list(axis) for name, axis in layer.unit_axes.items()},
        "slope": {name: float(getattr(slope, name)) for name in _SLOPE_FIELDS},
        "underlayer_top_m": float(layer.underlayer_top),
        "unit_bodies": [int(b) for b in layer.unit_bodies],
        "rows": [int(r) for r in layer.rows],
        "design_positions": [_finite_list(p) for p in np.asarray(layer.design_positions).reshape(-1, 3)],
        "design": {name: float(value) for name, value in layer.design.items()},
    }
    path = Path(directory) / LAYER_FILE_NAME
    temporary = path.with_name(path.name + ".partial")
    temporary.write_text(json.dumps(data, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    os.replace(temporary, path)
    return path


def _check_field(name, value, kind, problems) -> None:
    if kind == "string" and not (isinstance(value, str) and value):
        problems.append(f"'{name}' must be a non-empty string, got {value!r}")
    elif kind == "number" and not (isinstance(value, (int, float)) and math.isfinite(value)):
        problems.append(f"'{name}' must be a finite number, got {value!r}")
    elif kind == "integers" and not (isinstance(value, list)
                                     and all(isinstance(v, int) for v in value)):
        problems.append(f"'{name}' must be a list of integers")
    elif kind == "points" and not (isinstance(value, list) and all(
            isinstance(p, list) and len(p) == 3 for p in value)):
        problems.append(f"'{name}' must be a list of [x, y, z] points")
    elif kind == "axes":
        if not isinstance(value, dict) or "nose" not in value:
            problems.append(f"'{name}' must map axis names to [x, y, z], with a 'nose' axis")
        elif any(not (isinstance(v, list) and len(v) == 3) for v in value.values()):
            problems.append(f"'{name}': every axis must be [x, y, z]")
    elif kind == "slope":
        missing = [f for f in _SLOPE_FIELDS if not isinstance(value, dict) or f not in value]
        if missing:
            problems.append(f"'slope' lacks {', '.join(missing)}")
    elif kind == "mapping" and not isinstance(value, dict):
        problems.append(f"'{name}' must be a table of numbers")


def read_layer_file(directory, n_bodies: int | None = None):
    """Read ``layer.json`` of a pack folder into a
    :class:`~riprap.analysis.layer_state.LayerDescription`; ``n_bodies``: the pack's body count,
    to check the body indices against."""
    from riprap.analysis.layer_state import LayerDescription
    from riprap.placement.slope import Slope

    path = Path(directory) / LAYER_FILE_NAME
    if not path.is_file():
        raise CaseFileError(
            f"{path}: missing. The analysis needs the layer description that 'riprap place' writes "
            "beside pack.toml (which bodies are armour units, their rows and design positions, the "
            "slope); this pack was written without it (by an older riprap or by hand). Place the "
            "layer again with this version, or write layer.json (riprap.io.layer_file.write_layer_file).")
    try:
        data = json.loads(read_text_file(path, what="layer file", extension=".json"))
    except json.JSONDecodeError as error:
        raise CaseFileError(f"{path}:{error.lineno}: not valid JSON: {error.msg}") from None
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
        problems.append("missing field(s): " + ", ".join(
            f"'{name}' ({_FIELDS[name][1]})" for name in missing))
    for name, (kind, _) in _FIELDS.items():
        if name in data:
            _check_field(name, data[name], kind, problems)
    if not problems:
        n_units = len(data["unit_bodies"])
        for name in ("rows", "design_positions"):
            if len(data[name]) != n_units:
                problems.append(f"'{name}' has {len(data[name])} entries, 'unit_bodies' {n_units}")
        if n_bodies is not None:
            bad = [b for b in data["unit_bodies"] if not 0 <= b < n_bodies]
            if bad:
                problems.append(f"'unit_bodies' names bodies {bad[:5]} but the pack has {n_bodies} "
                                "bodies (indices from 0)")
        if len(set(data["unit_bodies"])) != n_units:
            problems.append("'unit_bodies' lists a body twice")
    if problems:
        raise CaseFileError.from_problems([f"{path}: {p}" for p in problems], 20)
    slope = Slope(**{name: float(data["slope"][name]) for name in _SLOPE_FIELDS})
    return LayerDescription(
        unit_kind=data["unit_kind"], unit_shape=data["unit_shape"],
        nominal_diameter=float(data["nominal_diameter_m"]), unit_volume=float(data["unit_volume_m3"]),
        unit_height=float(data["unit_height_m"]),
        unit_axes={name: np.asarray(axis, dtype=float) for name, axis in data["unit_axes"].items()},
        slope=slope, underlayer_top=float(data["underlayer_top_m"]),
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


def read_contact_table(path):
    """Read a contact table written by :func:`write_contact_table` into ``ContactRecords``."""
    from riprap.solid.solver import ContactRecords

    path = Path(path)
    if not path.is_file():
        raise CaseFileError(
            f"{path}: missing. The analysis needs the contact forces of the pack (written by "
            "'riprap place' beside pack.toml); without them the friction forces, which depend on "
            "the run's history, are unknown.")
    rows = []
    header_seen = False
    for number, line in enumerate(read_text_file(path, what="contact table", extension=".csv").splitlines(), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        if not header_seen:
            columns = tuple(name.strip() for name in text.split(","))
            if columns != CONTACT_COLUMNS:
                raise CaseFileError(f"{path}:{number}: columns {', '.join(columns)}; expected "
                                    f"{', '.join(CONTACT_COLUMNS)}")
            header_seen = True
            continue
        fields = text.split(",")
        try:
            values = [float(v) for v in fields]
        except ValueError:
            raise CaseFileError(f"{path}:{number}: not all fields are numbers: {text!r}") from None
        if len(values) != len(CONTACT_COLUMNS) or not all(math.isfinite(v) for v in values):
            raise CaseFileError(f"{path}:{number}: expected {len(CONTACT_COLUMNS)} finite numbers, "
                                f"got {text!r}")
        rows.append(values)
    table = np.asarray(rows, dtype=float).reshape(-1, len(CONTACT_COLUMNS))
    return ContactRecords(body_i=table[:, 0].astype(np.int64), body_j=table[:, 1].astype(np.int64),
                          points=table[:, 2:5].copy(), normal_forces=table[:, 5:8].copy(),
                          tangential_forces=table[:, 8:11].copy(), stiffness=np.zeros(len(table)))
