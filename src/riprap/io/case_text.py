"""Reading the text of a case file; the only place where a case file is opened.

The text, not the parsed TOML, is returned because :mod:`riprap.case.load` needs it to find the
line of each key for its error messages (``tomllib`` keeps no line numbers).
"""

from __future__ import annotations

import os
from pathlib import Path

from riprap.errors import CaseFileError

__all__ = ["read_case_text", "read_text_file", "PACK_HEADER"]

#: How the first line of every pack file begins: a case that includes a pack (``pack = "..."``)
#: refuses a file without it, which is a plain case, not a pack written by ``riprap place``.
PACK_HEADER = "# riprap pack:"  # (riprap/io/pack.py writes it)


def read_case_text(path: str | os.PathLike) -> str:
    """Read a case file as UTF-8 text.

    Parameters
    ----------
    path : str or os.PathLike
        The case file (TOML).

    Returns
    -------
    str
        The file's text, without a leading byte-order mark if it had one.

    Raises
    ------
    CaseFileError
        If the file does not exist, cannot be read, or is not UTF-8 text (the message then gives
        the line of the first bad byte).
    """
    return read_text_file(path, what="case file", extension=".toml")


def read_text_file(path: str | os.PathLike, *, what: str, extension: str) -> str:
    """Read a UTF-8 text input file (``what``: "case file", "grid file", ...), raising
    CaseFileError messages that name the file and, for a bad byte, its line."""
    path = Path(path)
    try:
        with open(path, "rb") as stream:
            raw = stream.read()
    except FileNotFoundError:
        raise CaseFileError(
            f"{path}: {what} not found (looked for {path.absolute()}); check the path"
        ) from None
    except IsADirectoryError:
        raise CaseFileError(f"{path}: is a folder, not a {what}; give the {extension} file") from None
    except OSError as error:
        raise CaseFileError(f"{path}: cannot read the {what}: {error.strerror}") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = raw.count(b"\n", 0, error.start) + 1
        raise CaseFileError(
            f"{path}:{line}: the {what} is not UTF-8 text (bad byte at offset {error.start}); "
            "save it with UTF-8 encoding"
        ) from None
