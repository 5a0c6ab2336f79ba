"""Number tables as CSV: reading back those a run writes (``gauges.csv``, ``body_forces.csv``),
checked: a header line of column names, then rows of as many finite numbers (a file changed by
hand or cut off is refused naming the file, the line and the column, never read as nonsense); and
writing a table of named columns (``units.csv``, ``per_wave.csv``, ``damage_curve.csv``) with
every number written back exactly (``repr``; ``nan`` where nothing was measured)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file

__all__ = ["read_number_table", "write_columns_csv", "read_columns_csv"]


def read_number_table(path, what: str, *, columns=None,
                      advice: str) -> tuple[list[str], np.ndarray, list[int]]:
    """``(column names, rows (n, columns), line number of each row)`` of the CSV table ``path``:
    ``what`` it is and
    ``advice`` go into the messages; ``columns``: the header it must have (None: any distinct,
    non-empty names). Lines starting with ``#`` are comments."""
    path = Path(path)
    if not path.is_file():
        raise CaseFileError(f"{path}: missing; {advice}")
    text = read_text_file(path, what=what, extension=".csv")
    header, rows, lines = None, [], []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = [field.strip() for field in stripped.split(",")]
        if header is None:
            header = fields
            _check_header(path, number, header, columns, advice)
            continue
        if len(fields) != len(header):
            raise CaseFileError(f"{path}:{number}: {len(fields)} fields, the header has "
                                f"{len(header)} ({', '.join(header)}); the {what} was cut off or "
                                f"changed; {advice}")
        row = []
        for name, field in zip(header, fields):
            try:
                value = float(field)
            except ValueError:
                raise CaseFileError(f"{path}:{number}: {name} = {field!r} is not a number; "
                                    f"{advice}") from None
            if not math.isfinite(value):
                raise CaseFileError(f"{path}:{number}: {name} = {field} is not finite; {advice}")
            row.append(value)
        rows.append(row)
        lines.append(number)
    if header is None:
        raise CaseFileError(f"{path}: is empty (no header line); {advice}")
    return header, np.asarray(rows, dtype=float).reshape(-1, len(header)), lines


def _check_header(path, number, header, columns, advice) -> None:
    if columns is not None and tuple(header) != tuple(columns):
        raise CaseFileError(f"{path}:{number}: columns {', '.join(header)}; expected "
                            f"{', '.join(columns)}; {advice}")
    if any(not name for name in header) or len(set(header)) != len(header):
        raise CaseFileError(f"{path}:{number}: the header names an empty or repeated column "
                            f"({', '.join(header)}); {advice}")


def _csv_number(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    number = float(value)
    if math.isnan(number):
        return "nan"
    if math.isinf(number):
        return "inf" if number > 0 else "-inf"
    return repr(number)


def write_columns_csv(path, columns: dict) -> Path:
    """One row per entry of the equally long ``columns`` (name -> values), in their order."""
    path = Path(path)
    names = list(columns)
    lines = [",".join(names)]
    for k in range(len(columns[names[0]]) if names else 0):
        lines.append(",".join(_csv_number(columns[name][k]) for name in names))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def read_columns_csv(path) -> dict:
    """The columns of a table :func:`write_columns_csv` wrote (numbers; ``nan`` kept)."""
    lines = [line for line in Path(path).read_text(encoding="utf-8").splitlines() if line.strip()]
    names = lines[0].split(",")
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]],
                    dtype=float).reshape(-1, len(names))
    return {name: rows[:, k] for k, name in enumerate(names)}
