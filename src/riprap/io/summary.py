"""Small JSON outputs (run summaries).

JSON has no NaN or Infinity (``json.dumps`` would write the non-standard tokens ``NaN`` and
``Infinity``, which strict readers refuse). Every non-finite float is written as ``null`` and the
text is made with ``allow_nan=False``, so nothing else slips through (docs/outputs.md).
"""
import json
import math
import os
from pathlib import Path

import numpy as np

from riprap.io.output_folder import naming_the_file


def _plain(value):
    """``value`` as plain JSON types; non-finite floats become None (``null``)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path, data: dict) -> Path:
    """Write ``data`` as indented JSON, atomically.

    Non-finite floats (NaN, +-inf), also inside numpy arrays and scalars, are written as
    ``null``; the result is always standard JSON.
    """
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with naming_the_file(path):
        tmp.write_text(json.dumps(_plain(data), indent=2, allow_nan=False) + "\n",
                       encoding="utf-8")
        os.replace(tmp, path)
    return path
