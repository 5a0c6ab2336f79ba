"""A plain-text log a long piece of work appends to as it goes (a series' ``series.log``, a
campaign's ``campaign.log``): one line per message, each with the wall-clock time it was written,
flushed at once so that a killed run keeps every line; and the reading of what another process
appended since (a campaign follows its members' logs)."""
from __future__ import annotations

import time
from pathlib import Path

from riprap.io.output_folder import naming_the_file

__all__ = ["append_log_lines", "read_new_log_lines", "log_size", "LOG_STAMP_SEPARATOR"]

#: Between a log line's time stamp and its message.
LOG_STAMP_SEPARATOR = "  "


def append_log_lines(path, lines) -> None:
    """Append ``lines`` (messages without a newline) to the log at ``path``, each after the local
    wall-clock time (``2026-12-02 17:20:01``)."""
    lines = list(lines)
    if not lines:
        return
    stamp = time.strftime("%Y-%m-%d %H:%M:%S")
    path = Path(path)
    with naming_the_file(path):
        with open(path, "a", encoding="utf-8") as stream:
            stream.writelines(f"{stamp}{LOG_STAMP_SEPARATOR}{line}\n" for line in lines)


def log_size(path) -> int:
    """Bytes in the log at ``path`` now (0 when there is none): where reading new lines starts."""
    path = Path(path)
    return path.stat().st_size if path.is_file() else 0


def read_new_log_lines(path, offset: int) -> tuple[list[str], int]:
    """The messages of the whole lines appended to the log at ``path`` after byte ``offset``
    (without their time stamps; a line still being written is left for the next call) and the
    offset to read on from."""
    path = Path(path)
    if not path.is_file():
        return [], offset
    with naming_the_file(path):
        with open(path, "rb") as stream:
            stream.seek(offset)
            data = stream.read()
    end = data.rfind(b"\n") + 1
    lines = data[:end].decode("utf-8", errors="replace").splitlines()
    return ([line.split(LOG_STAMP_SEPARATOR, 1)[-1] for line in lines], offset + end)
