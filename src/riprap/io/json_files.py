"""Every JSON file riprap writes or reads, in standard (strict) JSON.

JSON has no NaN or Infinity: ``json.dumps`` would write the non-standard tokens ``NaN`` and
``Infinity``, which strict readers (``jq``, JavaScript's ``JSON.parse``, most other languages)
refuse. Every non-finite float is written as ``null``, numpy scalars and arrays as plain numbers
and lists, and the text is made with ``allow_nan=False`` so that anything missed fails at once
instead of writing a file others cannot read (docs/outputs.md). Reading is as strict: a file with
``NaN`` in it was not written by riprap and is refused with the file named.
"""
from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.output_folder import naming_the_file

__all__ = ["plain_json", "json_text", "write_json", "strict_loads", "read_json_object"]


def plain_json(value):
    """``value`` as plain JSON types; non-finite floats become None (``null``)."""
    if isinstance(value, dict):
        return {str(k): plain_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [plain_json(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain_json(value.tolist())
    if isinstance(value, np.generic):
        return plain_json(value.item())
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def json_text(data, *, indent: int | None = 2, sort_keys: bool = False) -> str:
    """Standard JSON text of ``data`` (non-finite numbers as ``null``)."""
    return json.dumps(plain_json(data), indent=indent, allow_nan=False, sort_keys=sort_keys)


def write_json(path, data, *, indent: int | None = 2) -> Path:
    """Write ``data`` as standard JSON, atomically (a temporary file moved over ``path``).

    Non-finite floats (NaN, +-inf), also inside numpy arrays and scalars, are written as
    ``null``.
    """
    path = Path(path)
    temporary = path.with_name(path.name + ".tmp")
    with naming_the_file(path):
        temporary.write_text(json_text(data, indent=indent) + "\n", encoding="utf-8")
        os.replace(temporary, path)
    return path


def _refuse_constant(name):
    raise ValueError(f"{name} is not a JSON number (JSON has no NaN or Infinity)")


def strict_loads(text: str):
    """``json.loads`` that refuses ``NaN``, ``Infinity`` and ``-Infinity`` (ValueError)."""
    return json.loads(text, parse_constant=_refuse_constant)


def read_json_object(path, what: str, advice: str) -> dict:
    """The JSON object in ``path``, read strictly (no ``NaN`` or ``Infinity``), or a
    CaseFileError naming the file (and line), ``what`` it should be and ``advice``."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise CaseFileError(f"{path}: cannot read the {what} ({error}); {advice}") from None
    try:
        value = strict_loads(text)
    except json.JSONDecodeError as error:
        raise CaseFileError(f"{path}: cannot read the {what}: line {error.lineno} is not valid "
                            f"JSON ({error.msg}); {advice}") from None
    except ValueError as error:
        match = re.search(r"(?<![\w\"])-?(NaN|Infinity)\b", text)
        line = f"line {text.count(chr(10), 0, match.start()) + 1}: " if match else ""
        raise CaseFileError(f"{path}: cannot read the {what}: {line}{error}; {advice}") from None
    except RecursionError:
        raise CaseFileError(f"{path}: cannot read the {what}: nested too deeply to be riprap's; "
                            f"{advice}") from None
    if not isinstance(value, dict):
        raise CaseFileError(f"{path}: not a {what} (a JSON object {{...}} is expected, the file "
                            f"holds a {type(value).__name__}); {advice}")
    return value
