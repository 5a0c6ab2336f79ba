"""The output folder of a run: made (with its parents) and proved writable before any work starts,
so that a read-only folder, a path under a file, a name too long or a full disk is one clear
error at the start, not a traceback after an hour of simulation."""
from __future__ import annotations

import contextlib
import errno
import os
import shutil
from pathlib import Path

from riprap.errors import RiprapError

__all__ = ["OutputFolderError", "prepare_output_folder", "check_output_folder",
           "describe_os_error", "naming_the_file", "move_into",
           "remove_folder"]


class OutputFolderError(RiprapError):
    """The output folder cannot be made or written."""


@contextlib.contextmanager
def naming_the_file(path):
    """Give an OSError raised while ``path`` is written (a full disk fails in ``write``, whose
    error names no file) the file's name, so that the user learns which file could not be
    written."""
    try:
        yield
    except OSError as error:
        if error.filename is None or str(error.filename).endswith(".tmp"):
            error.filename = str(path)
        raise


def describe_os_error(error: OSError) -> str:
    """An OSError in words an engineer can act on, naming the file."""
    where = (error.filename if error.filename is not None
             else "writing an output file (the system did not say which)")
    reason = error.strerror or str(error)
    hints = {errno.ENOSPC: "free some space or choose another --out folder",
             errno.EDQUOT: "free some space or choose another --out folder",
             errno.EACCES: "choose a folder you may write to (--out)",
             errno.EPERM: "choose a folder you may write to (--out)",
             errno.EROFS: "the file system is read-only: choose another --out folder",
             errno.ENAMETOOLONG: "use a shorter folder name",
             errno.ENOTDIR: "a part of the path is a file, not a folder",
             errno.EEXIST: "a file of that name is in the way"}
    hint = hints.get(error.errno)
    return f"{where}: {reason}" + (f" ({hint})" if hint else "")


def _refuse_a_file_in_the_way(folder: Path) -> None:
    if folder.exists() and not folder.is_dir():
        raise OutputFolderError(f"output folder {folder}: a file of that name exists; choose "
                                "another --out folder")


def check_output_folder(path) -> str:
    """Refuse an output folder that cannot be made or written, without making it (riprap check);
    returns what was checked."""
    folder = Path(path)
    _refuse_a_file_in_the_way(folder)
    existing = folder
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise OutputFolderError(f"output folder {folder}: {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise OutputFolderError(f"cannot write the output folder {folder}: {existing} is not "
                                "writable; choose a folder you may write to (--out)")
    return f"output folder {folder} can be written"


def prepare_output_folder(path) -> Path:
    """Make ``path`` (and its parents) and check that a file can be written in it.

    Raises
    ------
    OutputFolderError
        Naming the folder and the reason (not writable, under a file, name too long, disk full).
    """
    folder = Path(path)
    _refuse_a_file_in_the_way(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".riprap-write-test-{os.getpid()}"
        with open(probe, "wb") as stream:
            stream.write(b"riprap")
        probe.unlink()
    except OSError as error:
        raise OutputFolderError(f"cannot write the output folder {folder}: "
                                f"{describe_os_error(error)}") from None
    return folder


def move_into(folder, names, into) -> Path:
    """Move the entries ``names`` of ``folder`` into the folder ``into`` (made empty first: what
    it held is removed), keeping their names; the folder's other entries stay."""
    folder, into = Path(folder), Path(into)
    try:
        if into.exists():
            shutil.rmtree(into)
        into.mkdir(parents=True)
        for name in names:
            os.replace(folder / name, into / name)
    except OSError as error:
        raise OutputFolderError(f"cannot move {', '.join(names)} of {folder} into {into}: "
                                f"{describe_os_error(error)}") from None
    return into


def remove_folder(path) -> None:
    """Remove the folder ``path`` and what it holds (riprap's own outputs, made again)."""
    try:
        shutil.rmtree(path)
    except FileNotFoundError:
        pass
    except OSError as error:
        raise OutputFolderError(f"cannot remove {path} to write it again: "
                                f"{describe_os_error(error)}") from None
