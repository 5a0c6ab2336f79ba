"""Checkpoints: the full state in one ``.npz`` file, written so a crash never destroys the last one.

A checkpoint is a plain numpy ``.npz`` archive holding named arrays, plus one reserved entry
(``__riprap_metadata__``) with a JSON string of metadata (simulated time, step count, case file
name, ...). The metadata always carries ``"checkpoint_format": 1``; a file written by a
different format version is refused with a message saying so instead of being half-read.

The archive is first written to a temporary file in the same folder and then moved over the
target with :func:`os.replace`, which is atomic on POSIX and Windows when both paths are on the
same file system. A run killed while writing therefore leaves either the previous complete
checkpoint or the new complete one, never a truncated file under the checkpoint's name.

A run over several processes writes its checkpoint in pieces: each process the arrays of its own
planes of the grid (:func:`save_checkpoint_piece`, into ``<name>_pieces/`` beside the checkpoint,
named by the step), then process 0 the checkpoint itself with the rest and the list of pieces
(``save_checkpoint(..., pieces=...)``), then the pieces of older checkpoints are removed. So the
checkpoint named always has all its pieces, whenever a run is killed. :func:`load_checkpoint` joins
the pieces' arrays along their first axis, in the order listed: what it returns is the whole
grid's, as one process writes it, and restarts on any number of processes.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import zipfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError, RiprapError
from riprap.io.output_folder import naming_the_file

__all__ = ["CheckpointError", "CHECKPOINT_FORMAT", "save_checkpoint", "load_checkpoint",
           "remove_stale_temporaries", "save_checkpoint_piece"]

#: Version of the checkpoint layout written by :func:`save_checkpoint`.
CHECKPOINT_FORMAT = 1

_METADATA_KEY = "__riprap_metadata__"


class CheckpointError(RiprapError):
    """A checkpoint or restart file is missing, corrupt, or written in another format version."""


@contextlib.contextmanager
def _atomic_target(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` only if the block succeeds.

    The temporary file lives in the same folder so that :func:`os.replace` stays on one file
    system and is atomic. On any exception the temporary file is removed and ``path`` is left
    untouched.

    Parameters
    ----------
    path : str or os.PathLike
        Final location of the file. Its parent folder is created if missing.

    Yields
    ------
    pathlib.Path
        Where the caller must write the complete file.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        with naming_the_file(target):
            yield temporary
        # Flush to disk before the rename so that a power loss cannot leave the new name
        # pointing at an empty file.
            with open(temporary, "rb+") as handle:
                os.fsync(handle.fileno())
            os.replace(temporary, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            temporary.unlink()


# The temporary files of _atomic_target: ".<name>.<pid>.tmp".
_TEMPORARY = re.compile(r"^\..+\.(\d+)\.tmp$")


def _process_alive(pid: int) -> bool:
    """Whether a process of this id runs on this machine (one of another user's counts)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True
    return True


def remove_stale_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove the temporary files (``.<name>.<pid>.tmp``) that a run killed while writing a
    checkpoint left in ``folder``: those of processes no longer running (a file of a running
    process, or of an id now reused, is kept). Returns the files removed."""
    folder = Path(folder)
    removed = []
    if not folder.is_dir():
        return removed
    for path in folder.iterdir():
        found = _TEMPORARY.match(path.name)
        if found and path.is_file() and not _process_alive(int(found.group(1))):
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
                removed.append(path)
    return removed


def _json_default(value):
    """Convert numpy scalars and arrays met in metadata to plain JSON types."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def save_checkpoint(
    path: str | os.PathLike,
    *,
    arrays: Mapping[str, np.ndarray],
    metadata: Mapping[str, object],
    pieces: list[str] | None = None,
) -> Path:
    """Write arrays and metadata to one ``.npz`` checkpoint, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Checkpoint file to write (conventionally ending in ``.npz``; the name is used as given).
        Its folder is created if missing. An existing file is replaced only once the new one is
        complete.
    arrays : mapping of str to numpy.ndarray
        State arrays of any shape and any numeric or boolean dtype, e.g. ``positions
        (n_bodies, 3)``, ``quaternions (n_bodies, 4)``. They are stored bit-exactly. Object
        arrays are refused because loading them would need pickle.
    metadata : mapping of str to JSON-serialisable values
        Scalars, strings, lists and dicts (numpy scalars are converted). The key
        ``"checkpoint_format"`` is set to :data:`CHECKPOINT_FORMAT`.
    pieces : list of str, optional
        The pieces of this checkpoint already written by :func:`save_checkpoint_piece` (their
        names as it returned them, in the order their arrays join); once the checkpoint is in
        place, the other files of its folder of pieces are removed.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    CaseFileError
        If an array name is reserved, an array has object dtype, or the metadata cannot be
        written as JSON.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> folder = tempfile.mkdtemp()
    >>> path = save_checkpoint(f"{folder}/state.npz", arrays={"positions": np.zeros((2, 3))},
    ...                        metadata={"time": 0.5})
    >>> arrays, metadata = load_checkpoint(path)
    >>> arrays["positions"].shape, metadata["time"], metadata["checkpoint_format"]
    ((2, 3), 0.5, 1)
    """
    path = Path(path)
    if _METADATA_KEY in arrays:
        raise CaseFileError(
            f"checkpoint {path}: the array name {_METADATA_KEY!r} is reserved for riprap's "
            "metadata; rename that array."
        )
    stored: dict[str, np.ndarray] = {}
    for name, array in arrays.items():
        array = np.asarray(array)
        if array.dtype.hasobject:
            raise CaseFileError(
                f"checkpoint {path}: array {name!r} has dtype object, which cannot be stored "
                "without pickle; convert it to a numeric, boolean or fixed-width string array."
            )
        stored[name] = array

    full_metadata = dict(metadata)
    full_metadata["checkpoint_format"] = CHECKPOINT_FORMAT
    if pieces is not None:
        full_metadata[_PIECES_KEY] = list(pieces)
    try:
        # allow_nan=False: NaN and infinity are not JSON and other readers would reject them.
        text = json.dumps(full_metadata, default=_json_default, allow_nan=False, sort_keys=True)
    except (TypeError, ValueError, RecursionError) as error:
        raise CaseFileError(
            f"checkpoint {path}: metadata cannot be written as JSON ({error}); keep metadata to "
            "finite numbers, strings, lists and dicts, and put arrays in `arrays`."
        ) from error
    stored[_METADATA_KEY] = np.array(text)

    with _atomic_target(path) as temporary:
        # A file object, not a name: np.savez would append ".npz" to a name lacking it.
        with open(temporary, "wb") as handle:
            np.savez(handle, **stored)
    # the pieces of this checkpoint's earlier writes (and all of them where it is now whole: a
    # run restarted on one process) are no longer named by it
    _remove_other_pieces(path, pieces or [])
    return path


_PIECES_KEY = "pieces"


def _pieces_folder(path: Path) -> Path:
    return path.with_name(f"{path.stem}_pieces")


def save_checkpoint_piece(path: str | os.PathLike, *, step: int, process: int,
                          arrays: Mapping[str, np.ndarray]) -> str:
    """Write process ``process``'s piece of the checkpoint ``path`` at fluid step ``step``:
    ``arrays`` (every piece the same names, each joined with the other pieces' along its first
    axis). Returns its name relative to ``path``'s folder, for ``save_checkpoint(pieces=...)``."""
    path = Path(path)
    piece = _pieces_folder(path) / f"step{int(step):09d}_process{int(process):04d}.npz"
    save_checkpoint(piece, arrays=arrays, metadata={"piece_of": path.name, "step": int(step),
                                                    "process": int(process)})
    return f"{piece.parent.name}/{piece.name}"


def _remove_other_pieces(path: Path, pieces: list[str]) -> None:
    folder = _pieces_folder(path)
    if not folder.is_dir():
        return
    listed = {Path(name).name for name in pieces}
    for old in folder.glob("step*_process*.npz"):
        if old.name not in listed:
            with contextlib.suppress(FileNotFoundError):
                old.unlink()
    if not pieces:
        with contextlib.suppress(OSError):
            folder.rmdir()


def _joined_pieces(path: Path, contents: dict, pieces, planes=None, plane_arrays=()) -> None:
    """Add the arrays of ``path``'s pieces to ``contents``, each joined along its first axis.

    With ``planes`` = (first, stop), the arrays named in ``plane_arrays`` (a grid's, whose first
    axis is the x-planes) are read only from the pieces that hold planes first .. stop - 1; the
    joined array has the whole grid's shape, with zeros on the other planes, which numpy leaves
    unwritten and so take no memory: a process restarting its block reads its planes alone."""
    if not isinstance(pieces, list) or not pieces or not all(isinstance(p, str) for p in pieces):
        raise CheckpointError(f"checkpoint {path}: its list of pieces is damaged; restart from "
                              "an earlier checkpoint")
    opened = []
    try:
        for process, name in enumerate(pieces):
            piece = path.parent / name
            if not piece.is_file():
                raise CheckpointError(
                    f"checkpoint {path}: its piece {name} (process {process}) is missing; a "
                    f"checkpoint of a run over several processes needs its folder "
                    f"{_pieces_folder(path).name} beside it")
            archive, metadata = _open_piece(piece)
            opened.append((piece, archive))
            if metadata.get("process") != process:
                raise CheckpointError(f"checkpoint {path}: {name} is not the piece of process "
                                      f"{process}")
            if "clock" in contents and metadata.get("step") != int(contents["clock"][1]):
                raise CheckpointError(f"checkpoint {path}: its piece {name} is of step "
                                      f"{metadata.get('step')}, the checkpoint of step "
                                      f"{int(contents['clock'][1])}")
        names = _names(opened[0][1])
        for process, (_, archive) in enumerate(opened):
            if _names(archive) != names:
                raise CheckpointError(f"checkpoint {path}: the piece of process {process} holds "
                                      f"{sorted(_names(archive))}, the first {sorted(names)}")
        for name in sorted(names):
            if name in contents:
                raise CheckpointError(f"checkpoint {path}: {name!r} is both in it and in its "
                                      "pieces")
            if planes is not None and name in plane_arrays:
                contents[name] = _planes_of(opened, name, planes)
            else:
                contents[name] = np.concatenate([_member(piece, archive, name)
                                                 for piece, archive in opened])
    finally:
        for _, archive in opened:
            archive.close()


def _names(archive) -> set:
    return set(archive.files) - {_METADATA_KEY}


def _open_piece(piece: Path):
    """A piece's archive, whose members are read when asked (``_member``), and its
    metadata."""
    try:
        archive = np.load(piece, allow_pickle=False)
        if not isinstance(archive, np.lib.npyio.NpzFile) or _METADATA_KEY not in archive.files:
            raise CheckpointError(f"{piece} is not a piece of a riprap checkpoint")
        metadata = json.loads(str(archive[_METADATA_KEY]))
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise CheckpointError(f"checkpoint piece {piece} is truncated or corrupt "
                              f"({type(error).__name__}: {error}); restart from an earlier "
                              "checkpoint") from error
    if not isinstance(metadata, dict) or metadata.get("checkpoint_format") != CHECKPOINT_FORMAT:
        raise CheckpointError(f"checkpoint piece {piece}: not of checkpoint_format "
                              f"{CHECKPOINT_FORMAT}; restart from an earlier checkpoint")
    return archive, metadata


def _member(piece: Path, archive, name: str) -> np.ndarray:
    try:
        return archive[name]
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise CheckpointError(f"checkpoint piece {piece}: {name} is truncated or corrupt "
                              f"({type(error).__name__}: {error}); restart from an earlier "
                              "checkpoint") from error


def _member_shape(piece: Path, archive, name: str) -> tuple:
    """The shape and dtype of a member, from its header alone."""
    try:
        with archive.zip.open(f"{name}.npy") as stream:
            version = np.lib.format.read_magic(stream)
            read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                    else np.lib.format.read_array_header_2_0)
            shape, _, dtype = read(stream)
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise CheckpointError(f"checkpoint piece {piece}: {name} is truncated or corrupt "
                              f"({type(error).__name__}: {error}); restart from an earlier "
                              "checkpoint") from error
    return shape, dtype


def _planes_of(opened, name: str, planes) -> np.ndarray:
    first, stop = planes
    shapes = [_member_shape(piece, archive, name) for piece, archive in opened]
    counts = [shape[0] for shape, _ in shapes]
    whole = np.zeros((sum(counts),) + tuple(shapes[0][0][1:]), dtype=shapes[0][1])
    begin = 0
    for (piece, archive), count in zip(opened, counts):
        if begin < stop and begin + count > first:
            whole[begin:begin + count] = _member(piece, archive, name)
        begin += count
    return whole


def load_checkpoint(path: str | os.PathLike, *, piece: bool = False, planes=None,
                    plane_arrays=()) -> tuple[dict[str, np.ndarray], dict]:
    """Read a checkpoint written by :func:`save_checkpoint`.

    Parameters
    ----------
    path : str or os.PathLike
        Checkpoint file.
    piece : bool
        Read one process's piece (:func:`save_checkpoint_piece`) as it is; otherwise a piece is
        refused, naming its checkpoint.
    planes : (first, stop) or None
        Of a checkpoint in pieces, the x-planes a process needs: the arrays named in
        ``plane_arrays`` are read from the pieces holding those planes only, with zeros (which
        take no memory) on the other planes. None reads every piece whole.

    Returns
    -------
    arrays : dict of str to numpy.ndarray
        The stored arrays, with their original dtypes and shapes.
    metadata : dict
        The stored metadata, including ``"checkpoint_format"``.

    Raises
    ------
    CheckpointError
        If the file is missing, truncated or corrupt, is not a riprap checkpoint, or was
        written in another checkpoint format version.
    """
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(
            f"checkpoint {path} does not exist; check the path, or start the run from the case "
            "file instead of restarting."
        )
    with open(path, "rb") as handle:
        start = handle.read(4)
    # A checkpoint is a zip archive (np.savez); anything else (a case file, a picture, an empty
    # file) is named for what it is rather than by numpy's complaint about its bytes.
    if start and not start.startswith(b"PK"):
        raise CheckpointError(
            f"{path} is not a riprap checkpoint (a checkpoint.npz or failure_checkpoint.npz "
            "written by riprap run); pass one of those with --restart.")
    try:
        # allow_pickle=False: a checkpoint must never execute code when loaded.
        loaded = np.load(path, allow_pickle=False)
        if not isinstance(loaded, np.lib.npyio.NpzFile):
            raise CheckpointError(
                f"{path} holds a single numpy array, not a riprap checkpoint archive; pass a "
                "file written by riprap.io.checkpoint.save_checkpoint."
            )
        with loaded as archive:
            # Read every member now so that a damaged member fails here, inside the try.
            contents = {name: archive[name] for name in archive.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise CheckpointError(
            f"checkpoint {path} is truncated or corrupt ({type(error).__name__}: {error}); "
            "restart from an earlier checkpoint."
        ) from error

    if _METADATA_KEY not in contents:
        raise CheckpointError(
            f"{path} is a numpy archive but not a riprap checkpoint (no {_METADATA_KEY!r} "
            "entry); pass a file written by riprap.io.checkpoint.save_checkpoint."
        )
    try:
        metadata = json.loads(str(contents.pop(_METADATA_KEY)))
    except json.JSONDecodeError as error:
        raise CheckpointError(
            f"checkpoint {path}: the metadata is not valid JSON ({error}); the file is corrupt, "
            "restart from an earlier checkpoint."
        ) from error
    if not isinstance(metadata, dict):
        raise CheckpointError(
            f"checkpoint {path}: the metadata is not a JSON object; the file is corrupt, "
            "restart from an earlier checkpoint."
        )

    version = metadata.get("checkpoint_format")
    if version != CHECKPOINT_FORMAT:
        raise CheckpointError(
            f"checkpoint {path} has checkpoint_format {version!r}, but this riprap reads "
            f"checkpoint_format {CHECKPOINT_FORMAT}; use the riprap version that wrote it, or "
            "start the run again from the case file."
        )
    if "piece_of" in metadata and not piece:
        raise CheckpointError(f"{path} is one process's piece of the checkpoint "
                              f"{metadata['piece_of']}; restart from that checkpoint")
    if _PIECES_KEY in metadata:
        _joined_pieces(path, contents, metadata.pop(_PIECES_KEY), planes, plane_arrays)
    return contents, metadata
