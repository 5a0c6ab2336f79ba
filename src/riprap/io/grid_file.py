"""Placement grid files: one row per armour unit, its centroid and optionally its pose and velocity.

A grid file is plain CSV that a coastal engineer can make in a spreadsheet or a script::

    # design grid, first row of Core-Locs on the 1:1.5 slope
    x, y, z, roll, pitch, yaw
    0.000, 0.00, 0.120, 0.0, 0.0, 90.0
    0.085, 0.00, 0.120, 0.0, 0.0, 45.0

Rules
-----
- Lines whose first non-space character is ``#`` are comments; blank lines are ignored.
- The first other line is the header: comma-separated column names, case-insensitive, spaces
  around them ignored.
- ``x, y, z`` (m, the unit's centroid) are required.
- Optional orientation, either ``qw, qx, qy, qz`` (a quaternion (w, x, y, z), all four or none,
  normalised on reading, norm at least :data:`~riprap.schema.MINIMUM_QUATERNION_NORM`) or
  ``roll, pitch, yaw`` in degrees (all three or none), never both. Roll, pitch and yaw are the
  aerospace (Tait-Bryan) angles: intrinsic rotations about z by yaw, then about the new y by
  pitch, then about the newest x by roll, so that the rotation from the unit's own frame to the
  world is ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (scipy ``Rotation.from_euler("ZYX", [yaw, pitch,
  roll], degrees=True)``).
- Optional ``vx, vy, vz`` (m/s, all three or none).
- Every row has as many comma-separated fields as the header, each a finite number.

All problems are reported at once by one :class:`~riprap.errors.CaseFileError`, each as
``<file>:<line>: <what is wrong>`` (at most :data:`~riprap.schema.MAXIMUM_REPORTED_PROBLEMS`
lines, then a count); its ``problems`` attribute holds every message.
"""
from __future__ import annotations

import difflib
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap import schema
from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file

__all__ = ["GridPoints", "read_grid_file", "write_grid_file", "POSITION_COLUMNS",
           "QUATERNION_COLUMNS", "ANGLE_COLUMNS", "VELOCITY_COLUMNS"]

POSITION_COLUMNS = ("x", "y", "z")
QUATERNION_COLUMNS = ("qw", "qx", "qy", "qz")
ANGLE_COLUMNS = ("roll", "pitch", "yaw")
VELOCITY_COLUMNS = ("vx", "vy", "vz")
_KNOWN_COLUMNS = POSITION_COLUMNS + QUATERNION_COLUMNS + ANGLE_COLUMNS + VELOCITY_COLUMNS

# A quaternion whose norm is this close to 1 is already unit to rounding; it is kept as written
# so that a grid written by write_grid_file reads back bit for bit (dividing by a norm of
# 1 - 1e-16 would change the last bit of some components and nothing else).
_UNIT_NORM_TOLERANCE = 4.0 * np.finfo(np.float64).eps


@dataclass(frozen=True, eq=False)
class GridPoints:
    """The rows of a placement grid file.

    Attributes
    ----------
    positions : numpy.ndarray, shape (n, 3)
        Centroids (m).
    orientations : numpy.ndarray, shape (n, 4), or None
        Unit quaternions (w, x, y, z) rotating each unit's own frame into the world; None when
        the file has no orientation columns.
    velocities : numpy.ndarray, shape (n, 3), or None
        Initial velocities (m/s); None when the file has no velocity columns.
    lines : numpy.ndarray, shape (n,)
        1-based line number of each row in the file, for later messages such as
        ``design.csv:17: unit starts outside the container``.
    source : str
        The file name as given.

    The arrays are read-only; equality is identity.
    """

    positions: np.ndarray
    orientations: np.ndarray | None
    velocities: np.ndarray | None
    lines: np.ndarray
    source: str = "<grid>"

    def __post_init__(self) -> None:
        for name in ("positions", "orientations", "velocities", "lines"):
            value = getattr(self, name)
            if value is None:
                continue
            array = np.array(value, dtype=np.int64 if name == "lines" else np.float64, copy=True)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    def __len__(self) -> int:
        return len(self.positions)

    def where(self, row: int) -> str:
        """``<file>:<line>`` of a row (0-based row index), for error messages."""
        return f"{self.source}:{int(self.lines[row])}"


class _Problems:
    """Problems with their lines, raised together like those of a case file."""

    def __init__(self, source: str) -> None:
        self._source = source
        self._items: list[tuple[int, int, str]] = []

    def __bool__(self) -> bool:
        return bool(self._items)

    def add(self, line: int, message: str) -> None:
        self._items.append((line, len(self._items), f"{self._source}:{line}: {message}"))

    def raise_if_any(self) -> None:
        if not self._items:
            return
        raise CaseFileError.from_problems([text for _, _, text in sorted(self._items)],
                                          schema.MAXIMUM_REPORTED_PROBLEMS)


def _content_lines(text: str) -> list[tuple[int, str]]:
    """(line number, text) of every line that is neither blank nor a comment."""
    kept = []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            kept.append((number, line))
    return kept


def _suggestion(name: str) -> str:
    close = difflib.get_close_matches(name, _KNOWN_COLUMNS, n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'? " if close else ""


def _parse_header(line_number: int, line: str, problems: _Problems) -> list[str]:
    """Column names, lower case; problems of the header are recorded, not raised."""
    names = [field.strip().lower() for field in line.split(",")]
    allowed = ", ".join(_KNOWN_COLUMNS)
    if len(names) == 1 and (";" in names[0] or "\t" in names[0]):
        problems.add(line_number, f"header {line.strip()!r} has no commas; columns must be "
                     "separated by commas (not semicolons or tabs), e.g. 'x, y, z'")
        return names
    seen: dict[str, int] = {}
    for column, name in enumerate(names, start=1):
        if not name:
            problems.add(line_number, f"header field {column} is empty (a stray comma?); "
                         f"allowed columns: {allowed}")
        elif name in seen:
            problems.add(line_number, f"duplicate column '{name}' (fields {seen[name]} and "
                         f"{column}); each column may appear once")
        elif name not in _KNOWN_COLUMNS:
            problems.add(line_number, f"unknown column '{name}'; {_suggestion(name)}"
                         f"allowed columns: {allowed}")
        seen.setdefault(name, column)
    present = set(names)
    missing = [name for name in POSITION_COLUMNS if name not in present]
    if missing:
        problems.add(line_number, f"missing required column(s) {', '.join(missing)} (the "
                     "centroid in m); the header must name x, y and z")
    for group, meaning in ((QUATERNION_COLUMNS, "the orientation quaternion"),
                           (ANGLE_COLUMNS, "the orientation angles in degrees"),
                           (VELOCITY_COLUMNS, "the velocity in m/s")):
        given = [name for name in group if name in present]
        if given and len(given) < len(group):
            absent = [name for name in group if name not in present]
            problems.add(line_number, f"column(s) {', '.join(given)} given without "
                         f"{', '.join(absent)}; {meaning} needs all of {', '.join(group)} "
                         "or none")
    if present & set(QUATERNION_COLUMNS) and present & set(ANGLE_COLUMNS):
        problems.add(line_number, "both quaternion (qw, qx, qy, qz) and angle (roll, pitch, "
                     "yaw) columns given; keep one way of giving the orientation")
    return names


def _parse_rows(rows: list[tuple[int, str]], names: list[str], problems: _Problems
                ) -> tuple[np.ndarray, list[int]]:
    """A (n_rows, n_columns) array of the values; bad rows are recorded and left as nan."""
    values = np.full((len(rows), len(names)), np.nan)
    for row, (line_number, line) in enumerate(rows):
        fields = line.split(",")
        if len(fields) != len(names):
            problems.add(line_number, f"{len(fields)} field(s), expected {len(names)} "
                         f"({', '.join(names)})")
            continue
        for column, (name, field) in enumerate(zip(names, fields)):
            text = field.strip()
            try:
                number = float(text)
            except ValueError:
                problems.add(line_number, f"column '{name}' = {text!r}: not a number")
                continue
            if not math.isfinite(number):
                problems.add(line_number, f"column '{name}' = {text}: not a finite number")
                continue
            values[row, column] = number
    return values, [line_number for line_number, _ in rows]


def _columns(values: np.ndarray, names: list[str], group: tuple[str, ...]) -> np.ndarray | None:
    if group[0] not in names:
        return None
    return values[:, [names.index(name) for name in group]]


def _normalised_quaternions(quaternions: np.ndarray, lines: list[int],
                            problems: _Problems) -> np.ndarray:
    norms = np.linalg.norm(quaternions, axis=1)
    for row in np.flatnonzero(norms < schema.MINIMUM_QUATERNION_NORM):
        shown = ", ".join(repr(float(value)) for value in quaternions[row])
        problems.add(lines[row], f"quaternion (qw, qx, qy, qz) = ({shown}) has norm "
                     f"{norms[row]:.3g}, below {schema.MINIMUM_QUATERNION_NORM:g}; it is not a "
                     "rotation (use 1, 0, 0, 0 for the unit's own orientation)")
    scale = np.where(np.abs(norms - 1.0) <= _UNIT_NORM_TOLERANCE, 1.0, norms)
    scale = np.where(norms < schema.MINIMUM_QUATERNION_NORM, 1.0, scale)
    return quaternions / scale[:, None]


def _quaternions_from_angles(angles_deg: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of R = Rz(yaw) Ry(pitch) Rx(roll) from rows of (roll, pitch, yaw) in deg."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_euler("ZYX", angles_deg[:, ::-1], degrees=True).as_quat().T
    return np.stack([w, x, y, z], axis=1)


def _check_repeated_positions(positions: np.ndarray, lines: list[int], problems: _Problems) -> None:
    """Two rows with the same centroid would place two units in one place: the solver cannot
    part them (no direction to push), so the second row is refused, naming the first."""
    first_line: dict[tuple, int] = {}
    for row, line in enumerate(lines):
        key = tuple(positions[row].tolist())
        if not all(math.isfinite(value) for value in key):
            continue                      # already reported as not a number
        if key in first_line:
            shown = ", ".join(f"{value:g}" for value in key)
            problems.add(line, f"the centroid ({shown}) repeats line {first_line[key]}: two units "
                         "would start in the same place; remove one of the two rows")
        else:
            first_line[key] = line


def read_grid_file(path: str | os.PathLike) -> GridPoints:
    """Read a placement grid file (CSV; format in the module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    GridPoints
        One row per data line, in file order.

    Raises
    ------
    CaseFileError
        Every problem found, each as ``<file>:<line>: <message>`` naming the column and the bad
        value: missing, unknown (with a suggestion), duplicate or incomplete columns; rows with
        the wrong number of fields; values that are not finite numbers; zero quaternions; a
        file without a header or without rows; a file that cannot be read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "grid.csv").write_text(
    ...     "# two units\\nX, Y, Z, roll, pitch, yaw\\n"
    ...     "0, 0, 0.1, 0, 0, 90\\n0.2, 0, 0.1, 0, 0, 0\\n")
    >>> grid = read_grid_file(folder / "grid.csv")
    >>> grid.positions.shape, grid.lines.tolist(), grid.velocities is None
    ((2, 3), [3, 4], True)
    >>> [round(float(value), 6) for value in grid.orientations[0]]
    [0.707107, 0.0, 0.0, 0.707107]
    """
    path = Path(path)
    source = os.fspath(path)
    text = read_text_file(path, what="grid file", extension=".csv")
    content = _content_lines(text)
    problems = _Problems(source)
    if not content:
        last_line = max(1, len(text.splitlines()))
        problems.add(last_line, "empty grid file: no header line found; the first line that is "
                     "not blank or a comment must name the columns, e.g. 'x, y, z'")
        problems.raise_if_any()
    header_line, header = content[0]
    names = _parse_header(header_line, header, problems)
    problems.raise_if_any()
    rows = content[1:]
    if not rows:
        problems.add(header_line, "the header names the columns but no data rows follow; add "
                     "one row per unit")
        problems.raise_if_any()
    values, lines = _parse_rows(rows, names, problems)
    positions = _columns(values, names, POSITION_COLUMNS)
    orientations = _columns(values, names, QUATERNION_COLUMNS)
    if orientations is not None:
        valid = np.isfinite(orientations).all(axis=1)
        orientations[valid] = _normalised_quaternions(
            orientations[valid], [line for line, ok in zip(lines, valid) if ok], problems)
    angles = _columns(values, names, ANGLE_COLUMNS)
    if angles is not None:
        orientations = np.full((len(rows), 4), np.nan)
        valid = np.isfinite(angles).all(axis=1)
        if valid.any():
            orientations[valid] = _quaternions_from_angles(angles[valid])
    velocities = _columns(values, names, VELOCITY_COLUMNS)
    _check_repeated_positions(positions, lines, problems)
    problems.raise_if_any()
    return GridPoints(positions=positions, orientations=orientations, velocities=velocities,
                      lines=np.asarray(lines, dtype=np.int64), source=source)


def _checked_array(name: str, value, width: int, rows: int | None) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise CaseFileError(f"write_grid_file: {name} must be numbers, got {value!r}") from None
    if array.ndim != 2 or array.shape[1] != width:
        raise CaseFileError(f"write_grid_file: {name} must have shape (n, {width}), got "
                            f"{array.shape}")
    if rows is not None and len(array) != rows:
        raise CaseFileError(f"write_grid_file: {name} has {len(array)} rows, positions has "
                            f"{rows}; give one row per unit")
    bad = np.flatnonzero(~np.isfinite(array).all(axis=1))
    if bad.size:
        raise CaseFileError(f"write_grid_file: {name} row {int(bad[0])} = "
                            f"{array[bad[0]].tolist()} is not finite")
    return array


def write_grid_file(path: str | os.PathLike, positions, orientations=None,
                    velocities=None) -> Path:
    """Write a placement grid file that :func:`read_grid_file` reads back exactly.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file to write; its folder must exist.
    positions : array_like, shape (n, 3)
        Centroids (m), n >= 1.
    orientations : array_like, shape (n, 4), optional
        Quaternions (w, x, y, z) rotating each unit's own frame into the world, written as given
        (columns ``qw, qx, qy, qz``); each norm must be at least
        :data:`~riprap.schema.MINIMUM_QUATERNION_NORM`.
    velocities : array_like, shape (n, 3), optional
        Initial velocities (m/s), columns ``vx, vy, vz``.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    CaseFileError
        If an array has the wrong shape or row count, a value is not finite, a quaternion is
        (near) zero, or there are no rows.

    Notes
    -----
    Values are written with ``repr`` (shortest text that reads back as the same float64), so a
    read after a write returns identical arrays (quaternions of unit norm to rounding are not
    rescaled on reading).
    """
    positions = _checked_array("positions", positions, 3, None)
    if len(positions) == 0:
        raise CaseFileError("write_grid_file: positions has no rows; a grid needs at least one "
                            "unit")
    columns = [positions]
    names = list(POSITION_COLUMNS)
    if orientations is not None:
        orientations = _checked_array("orientations", orientations, 4, len(positions))
        norms = np.linalg.norm(orientations, axis=1)
        small = np.flatnonzero(norms < schema.MINIMUM_QUATERNION_NORM)
        if small.size:
            raise CaseFileError(
                f"write_grid_file: orientations row {int(small[0])} = "
                f"{orientations[small[0]].tolist()} has norm {norms[small[0]]:.3g}, below "
                f"{schema.MINIMUM_QUATERNION_NORM:g}; it is not a rotation")
        columns.append(orientations)
        names += QUATERNION_COLUMNS
    if velocities is not None:
        columns.append(_checked_array("velocities", velocities, 3, len(positions)))
        names += VELOCITY_COLUMNS
    table = np.hstack(columns)
    lines = ["# riprap placement grid: centroids x, y, z in m"
             + ("; orientation quaternion (w, x, y, z), own frame to world" if orientations
                is not None else "")
             + ("; velocity in m/s" if velocities is not None else ""),
             ", ".join(names)]
    lines += [", ".join(repr(float(value)) for value in row) for row in table]
    path = Path(path)
    try:
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    except OSError as error:
        raise CaseFileError(f"{path}: cannot write the grid file: {error.strerror}") from None
    return path
