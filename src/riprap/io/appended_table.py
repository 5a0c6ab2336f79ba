"""A CSV table a run appends to frame by frame (``body_forces.csv``, ``solver_log.csv``): written
with its header at the start, flushed row by row so a killed run keeps every row, and appended to
by a restart only when the file there has the same columns."""
from __future__ import annotations

from pathlib import Path

from riprap.errors import CaseFileError
from riprap.io.output_folder import naming_the_file

__all__ = ["AppendedTable"]


class AppendedTable:
    """Lines appended to ``path`` under the header ``columns`` (written unless ``append`` and the
    file exists; then its header must be ``columns``)."""

    def __init__(self, path, columns, *, append: bool = False):
        self.path = Path(path)
        self.columns = tuple(columns)
        if append and self.path.is_file():
            with open(self.path, encoding="utf-8", errors="replace") as stream:
                header = tuple(stream.readline().strip().split(","))
            if header != self.columns:
                raise CaseFileError(
                    f"{self.path}: its columns are not those this riprap writes (an older run's "
                    "file?); rows appended by the restart would not match them. Run the case "
                    "again from the start, or move the file away to start a new one")
        else:
            with naming_the_file(self.path):
                self.path.write_text(",".join(self.columns) + "\n")

    def append(self, lines) -> None:
        """Append ``lines`` (CSV text, one row each) and flush."""
        with naming_the_file(self.path), open(self.path, "a") as stream:
            stream.write("".join(line + "\n" for line in lines))
            stream.flush()
