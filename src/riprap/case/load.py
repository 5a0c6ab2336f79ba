"""Load and validate a case file into a frozen :class:`Case`.

Every check comes from the key table in :mod:`riprap.schema`. All problems found are
collected and raised together as one :class:`~riprap.errors.CaseFileError`; each line of its
message reads ``<file>:<line>: <key path> = <value>: <what was expected>``, sorted by line, at most
:data:`~riprap.schema.MAXIMUM_REPORTED_PROBLEMS` of them. The error's ``problems`` attribute
holds every message, including those left out of the text.

``tomllib`` keeps no line numbers, so :class:`_LineLocator` scans the (already valid) TOML text
once and records the line of every table header, key and array element; a problem is reported at
the line of its key, or of the nearest enclosing table or array entry that was found.
"""

from __future__ import annotations

import bisect
import difflib
import math
import os
import re
import tomllib
from pathlib import Path

from riprap import schema
from riprap.case.cross_rules import check_cross_rules
# The specs are generated from the schema in riprap.case.specs; named here too, where the loaded
# case's parts have always been imported from.
from riprap.case.specs import (ArmourSpec, ArmourStoneSpec, BodyGridSpec, BodySpec, Case,
                               DeformableSpec, FluidSpec, FrictionSpec, GaugeSpec, MaterialSpec,
                               OutputSettings, PlacementSpec, PorousZoneSpec, RegionSpec,
                               SeriesSpec, SeriesStepSpec, ShapeSpec, SimulationSettings,
                               SlopeSpec, UnderlayerSpec, WallSpec, WavesSpec)
from riprap.errors import CaseFileError
from riprap.io.case_text import PACK_HEADER, read_case_text
from riprap.schema import Key, Table, describe_expected, format_toml_value

__all__ = [
    "Case",
    "SimulationSettings",
    "MaterialSpec",
    "ShapeSpec",
    "BodySpec",
    "BodyGridSpec",
    "WallSpec",
    "OutputSettings",
    "load_case",
    "parse_case",
]


def load_case(path: str | os.PathLike) -> Case:
    """Read and validate a case file.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML case file. Relative paths inside it are resolved against its folder.

    Returns
    -------
    Case

    Raises
    ------
    CaseFileError
        Listing every problem found, each as ``<file>:<line>: <key path> = <value>: <expected>``.
    """
    text = read_case_text(path)
    return parse_case(text, source=os.fspath(path), base_dir=Path(path).resolve().parent)


def parse_case(text: str, *, source: str = "<string>", base_dir: Path | None = None) -> Case:
    """Validate the text of a case file.

    Parameters
    ----------
    text : str
        TOML text.
    source : str
        Name used for the file in error messages.
    base_dir : pathlib.Path or None
        Folder that relative file paths (``mesh_file`` shapes) are resolved against; the current
        directory when None.

    Returns
    -------
    Case

    Raises
    ------
    CaseFileError
        Listing every problem found (TOML syntax errors alone, since nothing else can be checked).

    Examples
    --------
    >>> case = parse_case('''
    ... format_version = 1
    ... [simulation]
    ... end_time = 1.0
    ... [[materials]]
    ... name = "rock"
    ... [[shapes]]
    ... name = "ball"
    ... type = "sphere"
    ... radius = 0.1
    ... [[bodies]]
    ... shape = "ball"
    ... material = "rock"
    ... position = [0, 0, 1]
    ... ''')
    >>> case.bodies[0].position, case.materials[0].density
    ((0.0, 0.0, 1.0), 2650.0)
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise CaseFileError(_syntax_message(error, text, source)) from None
    base_dir = Path.cwd() if base_dir is None else Path(base_dir).resolve()
    problems = _Problems(source, _LineLocator(text))
    case = _Validator(problems, source, base_dir).case(data)
    problems.raise_if_any()
    return case


def _syntax_message(error: tomllib.TOMLDecodeError, text: str, source: str) -> str:
    message = str(error)
    lines = text.split("\n")
    position = re.search(r"\s*\(at line (\d+), column (\d+)\)\s*$", message)
    if position is not None:
        line = int(position.group(1))
        reason = f"{message[:position.start()]} (column {position.group(2)})"
    else:
        reason = re.sub(r"\s*\(at end of document\)\s*$", "", message) + " (at the end of the file)"
        line = max(1, len(text.rstrip("\n").split("\n")))
    near = lines[line - 1].strip() if 0 < line <= len(lines) else ""
    hint = f" in: {near}" if near else ""
    return f"{source}:{line}: TOML syntax error: {reason}{hint}"


class _LineLocator:
    """Line numbers of table headers, keys and array elements of valid TOML text.

    Paths are tuples of key names and array indices, e.g. ``("bodies", 2, "position")`` for the
    ``position`` key of the third ``[[bodies]]`` table (or of the third inline table of a
    ``bodies = [...]`` array).
    """

    _BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
    _SCALAR = re.compile(r"[^,\]}#\n]*")

    def __init__(self, text: str) -> None:
        self._text = text
        self._line_starts = [0] + [match.end() for match in re.finditer("\n", text)]
        self._lines: dict[tuple, int] = {}
        self._array_counts: dict[tuple, int] = {}
        self._position = 0
        try:
            self._scan_document()
        except (IndexError, ValueError):
            # Only a gap in this small scanner gets here (tomllib accepted the text); the lines
            # recorded so far are right and the others fall back to an enclosing table's line.
            pass

    def line_of(self, path: tuple) -> int:
        """Line of ``path``, else of its nearest recorded parent, else 1."""
        path = tuple(path)
        while path:
            if path in self._lines:
                return self._lines[path]
            path = path[:-1]
        return 1

    def _record(self, path: tuple, line: int) -> None:
        self._lines.setdefault(path, line)

    def _line_here(self) -> int:
        return bisect.bisect_right(self._line_starts, self._position)

    def _starts_with(self, token: str) -> bool:
        return self._text.startswith(token, self._position)

    def _skip_blank(self, *, newlines: bool) -> None:
        text = self._text
        while self._position < len(text):
            character = text[self._position]
            if character in " \t\r" or (newlines and character == "\n"):
                self._position += 1
            elif character == "#":
                end = text.find("\n", self._position)
                self._position = len(text) if end < 0 else end
            else:
                return

    def _resolve(self, names: tuple[str, ...]) -> tuple:
        # A header such as [bodies.extra] refers to the latest [[bodies]] entry.
        path: tuple = ()
        for number, name in enumerate(names):
            path = path + (name,)
            if number < len(names) - 1 and path in self._array_counts:
                path = path + (self._array_counts[path] - 1,)
        return path

    def _scan_document(self) -> None:
        prefix: tuple = ()
        text = self._text
        while True:
            self._skip_blank(newlines=True)
            if self._position >= len(text):
                return
            line = self._line_here()
            if self._starts_with("[["):
                self._position += 2
                path = self._resolve(self._scan_key())
                self._skip_blank(newlines=False)
                self._position += 2
                index = self._array_counts.get(path, 0)
                self._array_counts[path] = index + 1
                prefix = path + (index,)
                self._record(path, line)
                self._record(prefix, line)
            elif self._starts_with("["):
                self._position += 1
                prefix = self._resolve(self._scan_key())
                self._skip_blank(newlines=False)
                self._position += 1
                for length in range(1, len(prefix) + 1):
                    self._record(prefix[:length], line)
            else:
                self._scan_pair(prefix)

    def _scan_pair(self, prefix: tuple) -> None:
        line = self._line_here()
        names = self._scan_key()
        path = prefix + names
        self._skip_blank(newlines=False)
        if self._text[self._position] != "=":
            raise ValueError("expected '='")
        self._position += 1
        # A dotted key such as position.x = 1 also defines "position" on this line.
        for length in range(len(prefix) + 1, len(path) + 1):
            self._record(path[:length], line)
        self._skip_blank(newlines=False)
        self._scan_value(path)

    def _scan_key(self) -> tuple[str, ...]:
        parts = []
        while True:
            self._skip_blank(newlines=False)
            if self._text[self._position] in "\"'":
                start = self._position
                self._scan_string()
                parts.append(tomllib.loads("key = " + self._text[start:self._position])["key"])
            else:
                match = self._BARE_KEY.match(self._text, self._position)
                if match is None:
                    raise ValueError("expected a key")
                parts.append(match.group())
                self._position = match.end()
            self._skip_blank(newlines=False)
            if self._text[self._position] != ".":
                return tuple(parts)
            self._position += 1

    def _scan_string(self) -> None:
        text = self._text
        start = self._position
        if text.startswith('"""', start) or text.startswith("'''", start):
            delimiter = text[start:start + 3]
            index = start + 3
            while not text.startswith(delimiter, index):
                index += 2 if (delimiter == '"""' and text[index] == "\\") else 1
            end = index + 3
            # Up to two quote characters may end the content right before the delimiter.
            while end < len(text) and text[end] == delimiter[0] and end - index < 5:
                end += 1
            self._position = end
        elif text[start] == '"':
            index = start + 1
            while text[index] != '"':
                index += 2 if text[index] == "\\" else 1
            self._position = index + 1
        else:
            self._position = text.index("'", start + 1) + 1

    def _scan_value(self, path: tuple) -> None:
        character = self._text[self._position]
        if character in "\"'":
            self._scan_string()
        elif character == "[":
            self._position += 1
            index = 0
            while True:
                self._skip_blank(newlines=True)
                if self._text[self._position] == "]":
                    self._position += 1
                    return
                self._record(path + (index,), self._line_here())
                self._scan_value(path + (index,))
                self._skip_blank(newlines=True)
                if self._text[self._position] == ",":
                    self._position += 1
                index += 1
        elif character == "{":
            self._position += 1
            while True:
                self._skip_blank(newlines=True)
                if self._text[self._position] == "}":
                    self._position += 1
                    return
                self._scan_pair(path)
                self._skip_blank(newlines=True)
                if self._text[self._position] == ",":
                    self._position += 1
        else:
            self._position = self._SCALAR.match(self._text, self._position).end()


_NOT_GIVEN = object()
_INVALID = object()
_LONGEST_SHOWN_VALUE = 80


def _path_text(path: tuple) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


def _shown(value: object) -> str:
    text = format_toml_value(value)
    if len(text) > _LONGEST_SHOWN_VALUE:
        text = text[:_LONGEST_SHOWN_VALUE - 3] + "..."
    return text


def _type_name(value: object) -> str:
    if isinstance(value, bool):
        return "a boolean (true/false is not a number)"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a table"
    return "a date/time"


def _suggestion(name: str, candidates) -> str:
    candidates = list(candidates)
    # A shortened name ("friction" for "friction_coefficient") is a likelier slip than a
    # similar-looking one, and difflib's ratio ranks it low, so try abbreviations first.
    containing = sorted((candidate for candidate in candidates
                         if len(name) >= 3 and name in candidate), key=len)
    close = containing or difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'? " if close else ""


class _Problems:
    """Collects problems with their lines; raises them together."""

    def __init__(self, source: str, locator: _LineLocator) -> None:
        self._source = source
        self._locator = locator
        self._items: list[tuple[int, int, str]] = []

    def __bool__(self) -> bool:
        return bool(self._items)

    def line_of(self, path: tuple) -> int:
        return self._locator.line_of(path)

    def add(self, path: tuple, message: str, value: object = _NOT_GIVEN) -> None:
        line = self._locator.line_of(path)
        subject = _path_text(path)
        if value is not _NOT_GIVEN:
            subject += f" = {_shown(value)}"
        self._items.append((line, len(self._items), f"{self._source}:{line}: {subject}: {message}"))

    def raise_if_any(self) -> None:
        if not self._items:
            return
        raise CaseFileError.from_problems([text for _, _, text in sorted(self._items)],
                                          schema.MAXIMUM_REPORTED_PROBLEMS)


class _Validator:
    """Checks the parsed TOML against the schema, recording every problem in ``problems``."""

    def __init__(self, problems: _Problems, source: str, base_dir: Path) -> None:
        self._problems = problems
        self._source = source
        self._base_dir = base_dir

    # -- single values -------------------------------------------------------------------------

    def _convert(self, entry: Key, value: object, path: tuple) -> object:
        """The value converted to its plain Python form, or ``_INVALID`` after recording why."""
        expected = describe_expected(entry)
        converted, detail = self._convert_kind(entry, value)
        if converted is _INVALID:
            self._problems.add(path, f"expected {expected}, got {detail}", value)
            return _INVALID
        if entry.choices is not None and converted not in entry.choices:
            hint = _suggestion(converted, entry.choices)
            self._problems.add(path, f"not an allowed value; {hint}expected {expected}", value)
            return _INVALID
        components = converted if isinstance(converted, tuple) else (converted,)
        if entry.valid_range is not None:
            if not all(entry.valid_range.contains(item) for item in components):
                self._problems.add(path, f"out of range; expected {expected}", value)
                return _INVALID
        if entry.plausible is not None and any(entry.implausible(item) for item in components):
            self._problems.add(path, _implausible(entry), value)
            return _INVALID
        if entry.kind == "path":
            return self._check_path(entry, converted, path, value)
        return converted

    def _convert_kind(self, entry: Key, value: object) -> tuple[object, str]:
        kind = entry.kind
        if kind == "integer":
            if isinstance(value, bool) or not isinstance(value, int):
                return _INVALID, _type_name(value)
            if not _fits_64_bits(value):
                return _INVALID, _BEYOND_64_BITS
            return value, ""
        if kind == "number":
            return _as_number(value)
        if kind == "boolean":
            return (value, "") if isinstance(value, bool) else (_INVALID, _type_name(value))
        if kind in ("string", "path"):
            if not isinstance(value, str):
                return _INVALID, _type_name(value)
            return (value, "") if value.strip() else (_INVALID, "an empty string")
        if kind == "body_selection":
            if value == "all":
                return "all", ""
            if not isinstance(value, list):
                return _INVALID, _type_name(value)
            if not value:
                return _INVALID, "an empty list"
            for number, item in enumerate(value):
                if isinstance(item, bool) or not isinstance(item, int) or item < 0:
                    return _INVALID, f"{item!r} at item {number}"
                if not _fits_64_bits(item):
                    return _INVALID, f"{_BEYOND_64_BITS} at item {number}"
            if len(set(value)) != len(value):
                return _INVALID, "a body listed twice"
            return tuple(value), ""
        if kind in ("string_list", "name_pair"):
            if not isinstance(value, list):
                return _INVALID, _type_name(value)
            if not value:
                return _INVALID, "an empty list"
            if kind == "name_pair" and len(value) != 2:
                return _INVALID, f"a list of {len(value)} name{'' if len(value) == 1 else 's'}"
            for number, item in enumerate(value):
                if not isinstance(item, str) or not item.strip():
                    return _INVALID, f"{_type_name(item)} at item {number}"
            return tuple(value), ""
        if kind == "polygon_xz":
            if not isinstance(value, list):
                return _INVALID, _type_name(value)
            if len(value) < 3:
                return _INVALID, f"a list of {len(value)} point(s)"
            points = []
            for number, point in enumerate(value):
                if not isinstance(point, list) or len(point) != 2:
                    return _INVALID, f"{_type_name(point)} at point {number} (want [x, z])"
                pair = [_as_number(item) for item in point]
                if any(converted is _INVALID for converted, _ in pair):
                    return _INVALID, f"a non-number at point {number}"
                points.append((pair[0][0], pair[1][0]))
            return tuple(points), ""
        length = 4 if kind == "quaternion" else 3
        if not isinstance(value, list):
            return _INVALID, _type_name(value)
        if len(value) != length:
            return _INVALID, f"a list of {len(value)} item(s)"
        items = []
        for number, item in enumerate(value):
            if kind == "integer_vector":
                if isinstance(item, bool) or not isinstance(item, int):
                    return _INVALID, f"{_type_name(item)} at item {number}"
                if not _fits_64_bits(item):
                    return _INVALID, f"{_BEYOND_64_BITS} at item {number}"
                items.append(item)
            else:
                converted, detail = _as_number(item)
                if converted is _INVALID:
                    return _INVALID, f"{detail} at item {number}"
                items.append(converted)
        if kind == "quaternion":
            norm = math.hypot(*items)      # not sqrt(sum of squares): 1e308 squared overflows
            if norm < schema.MINIMUM_QUATERNION_NORM:
                return _INVALID, f"a quaternion of norm {norm:.3g}"
            items = [item / norm for item in items]
        if kind == "direction":
            norm = math.hypot(*items)
            if norm < schema.MINIMUM_DIRECTION_NORM:
                return _INVALID, "the zero vector"
            items = [item / norm for item in items]
        return tuple(items), ""

    def _check_path(self, entry: Key, name: str, path: tuple, value: object) -> object:
        resolved = Path(name)
        if not resolved.is_absolute():
            resolved = self._base_dir / resolved
        resolved = resolved.resolve()
        if entry.extensions and resolved.suffix.lower() not in entry.extensions:
            self._problems.add(
                path,
                f"unsupported file type {resolved.suffix or '(none)'!s}; "
                f"expected {describe_expected(entry)}",
                value,
            )
            return _INVALID
        if not resolved.is_file():
            self._problems.add(
                path,
                f"file not found at {resolved} (relative paths start from the case file's "
                f"folder {self._base_dir})",
                value,
            )
            return _INVALID
        return resolved

    # -- one table -----------------------------------------------------------------------------

    def _entry(self, part: Table, data: object, path: tuple) -> dict | None:
        """Validated values of one table (or array entry) by key name, defaults filled in."""
        if not isinstance(data, dict):
            self._problems.add(path, f"expected a table {part.header}, got {_type_name(data)}",
                               data)
            return None
        values: dict[str, object] = {}
        variant = None
        if part.variant_key is not None and part.variant_key in data:
            variant_entry = schema.key(part.name, part.variant_key)
            converted = self._convert(variant_entry, data[part.variant_key],
                                      path + (part.variant_key,))
            values[part.variant_key] = converted
            variant = None if converted is _INVALID else converted
        entries = schema.keys_of(part.name, variant=variant)
        for entry in entries:
            if entry.name in values:
                continue
            if entry.name in data:
                values[entry.name] = self._convert(entry, data[entry.name], path + (entry.name,))
            elif entry.required:
                where = f"this {part.header} entry" if part.is_array else part.header
                if not part.name:
                    where = "the top level of the file"
                self._problems.add(
                    path + (entry.name,),
                    f"missing required key in {where}; expected {describe_expected(entry)}",
                )
                values[entry.name] = _INVALID
            else:
                values[entry.name] = entry.default
        self._check_unknown_keys(part, data, path, variant, {entry.name for entry in entries})
        for entry in entries:
            if entry.greater_than is not None:
                self._check_greater(entry, values, path)
        return values

    def _check_unknown_keys(self, part: Table, data: dict, path: tuple, variant: str | None,
                            known: set[str]) -> None:
        all_keys = [entry for entry in schema.KEYS if entry.table == part.name]
        for name, value in data.items():
            if name in known:
                continue
            owners = [entry.variant for entry in all_keys
                      if entry.name == name and entry.variant is not None]
            if owners and variant is None:
                # The type is missing or invalid and already reported; no key can be judged.
                continue
            if owners:
                types = " or ".join(f'"{owner}"' for owner in owners)
                self._problems.add(
                    path + (name,),
                    f"'{name}' is a key of {part.header} with {part.variant_key} = {types}, not "
                    f'"{variant}"; remove it or change {part.variant_key}. Keys for "{variant}": '
                    + ", ".join(sorted(known)),
                    value,
                )
                continue
            candidates = sorted(known) if variant is not None or part.variant_key is None else \
                sorted({entry.name for entry in all_keys})
            where = f"in {part.header}" if part.name else "at the top level"
            self._problems.add(
                path + (name,),
                f"unknown key {where}; {_suggestion(name, candidates)}"
                f"allowed keys: {', '.join(candidates)}",
                value,
            )

    def _check_greater(self, entry: Key, values: dict, path: tuple) -> None:
        upper, lower = values.get(entry.name), values.get(entry.greater_than)
        if upper is _INVALID or lower is _INVALID or upper is None or lower is None:
            return
        if not all(high > low for high, low in zip(upper, lower)):
            self._problems.add(
                path + (entry.name,),
                f"must exceed {entry.greater_than} = {_shown(lower)} in every component",
                upper,
            )
            values[entry.name] = _INVALID

    # -- the whole case ------------------------------------------------------------------------

    def _top_level_keys(self, data: dict) -> dict | None:
        top = schema.table("")
        known_tables = [part.name for part in schema.TABLES if part.name]
        top_keys = [entry.name for entry in schema.keys_of("")]
        for name, value in data.items():
            if name in known_tables or name in top_keys:
                continue
            listing = ", ".join(top_keys + [schema.table(table_name).header
                                            for table_name in known_tables])
            self._problems.add(
                (name,),
                f"unknown top-level table or key; {_suggestion(name, known_tables + top_keys)}"
                f"allowed: {listing}",
                value,
            )
        return self._entry(top, {name: data[name] for name in top_keys if name in data}, ())

    def _array(self, part: Table, data: dict) -> list:
        # riprap place makes its own shapes and bodies: a placement case needs none; a fluid case
        # without bodies needs neither shapes nor materials.
        minimum = part.minimum_count
        if part.name == "shapes" and ("placement" in data or "armour_stone" in data):
            minimum = 0
        if part.name in ("shapes", "materials") and ("fluid" in data or "pack" in data):
            minimum = 0
        raw = data.get(part.name, _NOT_GIVEN)
        entries: list = []
        if raw is _NOT_GIVEN:
            entries = []
        elif isinstance(raw, dict):
            self._problems.add(
                (part.name,),
                f"expected an array of tables: write {part.header} before each entry, "
                f"not [{part.name}]",
            )
            return []
        elif not isinstance(raw, list):
            self._problems.add((part.name,), f"expected an array of tables {part.header}, got "
                               f"{_type_name(raw)}", raw)
            return []
        else:
            entries = raw
        if len(entries) < minimum:
            self._problems.add(
                (part.name,),
                f"at least {minimum} {part.header} entry needed, found {len(entries)}",
            )
        return [self._entry(part, entry, (part.name, number))
                for number, entry in enumerate(entries)]

    def _single(self, part: Table, data: dict) -> dict | None:
        if part.minimum_count == 0 and part.name not in data:
            return None          # an optional table that is absent
        raw = data.get(part.name, {})
        if isinstance(raw, list):
            self._problems.add(
                (part.name,),
                f"expected one table {part.header}, got an array of tables [[{part.name}]]",
            )
            return None
        return self._entry(part, raw, (part.name,))

    def _check_unique(self, tables: dict) -> None:
        for entry in schema.KEYS:
            if not entry.unique:
                continue
            first_use: dict = {}
            for number, values in enumerate(tables[entry.table]):
                if values is None or values.get(entry.name, _INVALID) is _INVALID:
                    continue
                value = values[entry.name]
                if value in first_use:
                    earlier = first_use[value]
                    line = self._problems.line_of((entry.table, earlier, entry.name))
                    self._problems.add(
                        (entry.table, number, entry.name),
                        f"duplicate {entry.name}; {entry.table}[{earlier}] (line {line}) already "
                        f"uses it; each [[{entry.table}]] {entry.name} must be unique",
                        value,
                    )
                else:
                    first_use[value] = number

    def _check_references(self, tables: dict, *, deferred: tuple = ()) -> None:
        """Names that refer to nothing; those of the tables ``deferred`` (which may name a
        pack's entries) are checked once the pack is joined (:meth:`_check_friction_of_pack`)."""
        for entry in schema.KEYS:
            if entry.references is None or entry.table in deferred:
                continue
            defined = [values["name"] for values in tables[entry.references]
                       if values is not None and values.get("name", _INVALID) is not _INVALID]
            table_values = tables[entry.table]
            if schema.table(entry.table).is_array:
                located = [((entry.table, number, entry.name), values)
                           for number, values in enumerate(table_values)]
            else:
                located = [((entry.table, entry.name), table_values)]
            for path, values in located:
                if values is None or values.get(entry.name, _INVALID) is _INVALID:
                    continue
                value = values[entry.name]
                names = value if isinstance(value, tuple) else (value,)
                for item_number, name in enumerate(names):
                    if name in defined:
                        continue
                    item_path = path + (item_number,) if isinstance(value, tuple) else path
                    self._add_unknown_name(item_path, name, entry.references, defined)

    def _add_unknown_name(self, path: tuple, name: str, references: str, defined: list) -> None:
        listing = ", ".join(format_toml_value(known) for known in dict.fromkeys(defined)) or "none"
        self._problems.add(path, f"no [[{references}]] entry has this name; "
                                 f"{_suggestion(name, defined)}defined names: {listing}", name)

    def _check_friction_pairs(self, entries: list) -> None:
        """Each pair of materials once in [[friction]], in either order."""
        first: dict = {}
        for number, values in enumerate(entries):
            names = None if values is None else values.get("materials", _INVALID)
            if names is None or names is _INVALID:
                continue
            pair = tuple(sorted(names))
            if pair in first:
                earlier = first[pair]
                line = self._problems.line_of(("friction", earlier, "materials"))
                self._problems.add(("friction", number, "materials"),
                                   f"the pair {pair[0]}-{pair[1]} is listed twice; friction[{earlier}] "
                                   f"(line {line}) already gives it; list each pair once", names)
            else:
                first[pair] = number

    def _check_friction_of_pack(self, own: tuple, case: Case, pack_path) -> None:
        """This file's [[friction]] pairs beside an included pack's: each name one of the
        materials of the two, and no pair the pack gives already."""
        defined = [material.name for material in case.materials]
        pack_pairs = {tuple(sorted(spec.materials)): spec
                      for spec in case.friction[:len(case.friction) - len(own)]}
        for number, spec in enumerate(own):
            path = ("friction", number, "materials")
            for item_number, name in enumerate(spec.materials):
                if name not in defined:
                    self._add_unknown_name(path + (item_number,), name, "materials", defined)
            pair = tuple(sorted(spec.materials))
            if pair in pack_pairs:
                self._problems.add(path, f"the pack {pack_path} gives the pair {pair[0]}-{pair[1]} "
                                   f"already (friction_coefficient = "
                                   f"{pack_pairs[pair].friction_coefficient:g}); a pack keeps its "
                                   "pairs: remove this entry", spec.materials)

    def _check_body_count(self, tables: dict, top: dict | None = None) -> None:
        total, named = len(tables["bodies"]), False
        for number, values in enumerate(tables["body_grids"]):
            counts = None if values is None else values.get("counts", _INVALID)
            count = 1 if counts is None or counts is _INVALID else math.prod(counts)
            if count > schema.MAXIMUM_BODY_COUNT:
                # refused before anything is built: building them alone would take hours
                self._problems.add(
                    ("body_grids", number, "counts"),
                    f"{' x '.join(map(str, counts))} = {_count(count)} bodies, more than the "
                    f"{schema.MAXIMUM_BODY_COUNT:,} a case may create; use fewer", counts)
                named = True
            total += count
        if total > schema.MAXIMUM_BODY_COUNT:
            if not named:
                self._problems.add(("body_grids",), f"the case creates {_count(total)} bodies, more "
                                   f"than the {schema.MAXIMUM_BODY_COUNT:,} a case may create")
            return
        if (tables.get("placement") is not None or tables.get("armour_stone") is not None
                or tables.get("fluid") is not None):
            return               # riprap place makes the bodies; a fluid case needs none
        if top and top.get("pack") not in (None, "", _INVALID):
            return               # the pack brings its bodies
        if total < schema.MINIMUM_BODY_COUNT:
            self._problems.add(
                ("bodies",),
                f"the case creates {total} bodies, at least {schema.MINIMUM_BODY_COUNT} needed; "
                "add a [[bodies]] or [[body_grids]] entry",
            )

    def case(self, data: dict) -> Case | None:
        top = self._top_level_keys(data)
        tables: dict[str, object] = {}
        for part in schema.TABLES:
            if part.name:
                tables[part.name] = (self._array(part, data) if part.is_array
                                     else self._single(part, data))
        self._check_unique(tables)
        pack_given = bool(top) and top.get("pack") not in (None, "", _INVALID)
        self._check_references(tables, deferred=("friction",) if pack_given else ())
        self._check_friction_pairs(tables["friction"])
        self._check_body_count(tables, top)
        check_cross_rules(tables, self._problems.add, _INVALID)
        if self._problems:
            return None
        case = Case(
            format_version=top["format_version"],
            source=self._source,
            base_dir=self._base_dir,
            simulation=SimulationSettings(**tables["simulation"]),
            materials=tuple(MaterialSpec(**values) for values in tables["materials"]),
            friction=tuple(FrictionSpec(**values) for values in tables["friction"]),
            shapes=tuple(_with_parameters(ShapeSpec, "shapes", values)
                         for values in tables["shapes"]),
            bodies=tuple(BodySpec(**values) for values in tables["bodies"]),
            body_grids=tuple(BodyGridSpec(**values) for values in tables["body_grids"]),
            walls=tuple(_with_parameters(WallSpec, "walls", values)
                        for values in tables["walls"]),
            output=OutputSettings(**tables["output"]),
            slope=_optional(SlopeSpec, tables["slope"]),
            underlayer=_optional(UnderlayerSpec, tables["underlayer"]),
            armour=_optional(ArmourSpec, tables["armour"]),
            armour_stone=_optional(ArmourStoneSpec, tables["armour_stone"]),
            placement=_optional(PlacementSpec, tables["placement"]),
            fluid=_optional(FluidSpec, tables["fluid"]),
            deformable=_optional(DeformableSpec, tables["deformable"]),
            water_regions=tuple(_with_parameters(RegionSpec, "water_regions", values)
                                for values in tables["water_regions"]),
            obstacles=tuple(_with_parameters(RegionSpec, "obstacles", values)
                            for values in tables["obstacles"]),
            waves=(None if tables["waves"] is None
                   else _with_parameters(WavesSpec, "waves", tables["waves"])),
            gauges=tuple(_with_parameters(GaugeSpec, "gauges", values) for values in tables["gauges"]),
            porous_zones=tuple(_with_parameters(PorousZoneSpec, "porous_zones", values)
                               for values in tables["porous_zones"]),
            series=_optional(SeriesSpec, tables["series"]),
            series_steps=tuple(SeriesStepSpec(**values) for values in tables["series_steps"]),
        )
        if top.get("pack"):
            own = case.friction
            case = _with_pack(case, top["pack"])
            self._check_friction_of_pack(own, case, top["pack"])
        return case


#: The case files whose ``pack`` is being loaded, outermost first: a pack that includes itself,
#: directly or through other packs, is refused with this chain instead of recursing without end.
_PACKS_BEING_INCLUDED: list[Path] = []


def _with_pack(case: Case, pack_path) -> Case:
    """``case`` with the pack's materials, friction pairs, shapes, bodies and walls first, and its
    contact history unless the case names one (the history's body and wall numbers are the
    pack's, which stay first)."""
    import dataclasses

    including = Path(case.source).resolve()
    chain = _PACKS_BEING_INCLUDED + [including]
    if Path(pack_path).resolve() in chain:
        start = chain.index(Path(pack_path).resolve())
        files = " -> ".join(str(path) for path in chain[start:] + [Path(pack_path).resolve()])
        raise CaseFileError(f"{case.source}: pack = {str(pack_path)!r} includes itself through "
                            f"the chain {files}; a pack written by riprap place includes no "
                            "other pack: remove the 'pack' key from the included file")
    first_line = read_case_text(pack_path).split("\n", 1)[0]
    if not first_line.startswith(PACK_HEADER):
        raise CaseFileError(f"{case.source}: pack = {str(pack_path)!r} is not a pack written by "
                            f"riprap place (its first line does not begin {PACK_HEADER!r}); name "
                            "the pack.toml that 'riprap place CASE --out DIR' wrote in DIR, or "
                            "copy this file's tables into the case instead of including it")
    _PACKS_BEING_INCLUDED.append(including)
    try:
        pack = load_case(pack_path)
    finally:
        _PACKS_BEING_INCLUDED.pop()
    if pack.is_fluid or pack.is_placement:
        raise CaseFileError(f"{case.source}: pack = {str(pack_path)!r} is not a pack of bodies "
                            "(it has [fluid] or [placement])")
    for field in ("materials", "shapes"):
        ours = {item.name for item in getattr(case, field)}
        clash = sorted(ours & {item.name for item in getattr(pack, field)})
        if clash:
            raise CaseFileError(f"{case.source}: {field} {', '.join(map(repr, clash))} are in the "
                                f"pack {pack_path} and in this file; give this file's other names")
    simulation = case.simulation
    if not simulation.contact_history and pack.simulation.contact_history:
        simulation = dataclasses.replace(simulation,
                                         contact_history=pack.simulation.contact_history)
    return dataclasses.replace(case, simulation=simulation,
                               materials=pack.materials + case.materials,
                               friction=pack.friction + case.friction,
                               shapes=pack.shapes + case.shapes, bodies=pack.bodies + case.bodies,
                               body_grids=pack.body_grids + case.body_grids,
                               walls=pack.walls + case.walls)


def _optional(spec_class, values: dict | None):
    return None if values is None else spec_class(**values)


def _implausible(entry: Key) -> str:
    """Why a value outside the key's plausible range is refused, with the range."""
    unit = "" if entry.unit == "-" else f" {entry.unit}"
    each = " for each component" if entry.kind == "vector" else ""
    return (f"far outside any physical value: plausible is {entry.plausible.describe()}{unit}"
            f"{each} (docs/case-file.md); check the unit and the exponent")


def _count(number: int) -> str:
    """A count as an engineer reads it: digits in groups of three, or powers of ten when long."""
    return f"{number:,}" if number < 10**12 else f"{number:.3g}"


_BEYOND_64_BITS = "an integer beyond 64 bits (more than 9.2e18 in size)"


def _fits_64_bits(value: int) -> bool:
    """Whether ``value`` fits a 64-bit signed integer, as every count and seed reaches numpy."""
    return -2**63 <= value < 2**63


def _as_number(value: object) -> tuple[object, str]:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return _INVALID, _type_name(value)
    number = float(value)
    if not math.isfinite(number):
        return _INVALID, f"the non-finite value {format_toml_value(number)}"
    return number, ""


def _with_parameters(spec_class, table_name: str, values: dict):
    common = {entry.name for entry in schema.keys_of(table_name)}
    fields = {name: value for name, value in values.items() if name in common}
    parameters = {name: value for name, value in values.items() if name not in common}
    return spec_class(**fields, parameters=parameters)
