"""ParaView output: unstructured-grid ``.vtu`` files and ``.pvd`` time series.

Every file is written to a temporary name and moved into place with :func:`os.replace`, and a
series rewrites its ``.pvd`` index only after the frame it adds is complete. A run killed at any
moment therefore leaves a ``.pvd`` that ParaView opens and that lists only complete frames.

``.vtu`` files are binary with zlib compression (meshio's VTU writer), which ParaView and VTK read
directly.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import xml.etree.ElementTree as ElementTree
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.checkpoint import CheckpointError, _atomic_target
from riprap.io.vti import write_vti

__all__ = ["write_vtu", "write_contacts_vtu", "ParaViewSeries"]

# Nodes per cell for the cell types riprap writes (meshio names).
_NODES_PER_CELL = {"tetra": 4, "triangle": 3, "vertex": 1}


def _as_vtk_array(name: str, values, expected_rows: int, where: str, kind: str) -> np.ndarray:
    """Check one data array and convert it to a dtype the VTU format can store."""
    array = np.asarray(values)
    if array.ndim not in (1, 2) or array.shape[0] != expected_rows:
        raise CaseFileError(
            f"{where}: {kind} data {name!r} has shape {array.shape}, expected ({expected_rows},) "
            f"or ({expected_rows}, k), one row per {kind}."
        )
    if array.dtype == np.bool_:
        # VTK has no boolean array type; 0/1 bytes keep the meaning and the size.
        return array.astype(np.uint8)
    if array.dtype.kind not in "iuf":
        raise CaseFileError(
            f"{where}: {kind} data {name!r} has dtype {array.dtype}; VTU stores only integer, "
            "float and boolean arrays."
        )
    return np.ascontiguousarray(array)


def write_vtu(
    path: str | os.PathLike,
    *,
    points: np.ndarray,
    cells: np.ndarray,
    cell_type: str = "tetra",
    point_data: Mapping[str, np.ndarray] | None = None,
    cell_data: Mapping[str, np.ndarray] | None = None,
) -> None:
    """Write one unstructured grid as a binary, zlib-compressed ``.vtu`` file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        File to write; its folder is created if missing.
    points : numpy.ndarray, shape (n_points, 3)
        Point coordinates in metres.
    cells : numpy.ndarray of int, shape (n_cells, k)
        Point indices of each cell, zero-based; ``k`` is 4 for ``"tetra"``, 3 for
        ``"triangle"`` and 1 for ``"vertex"``.
    cell_type : {"tetra", "triangle", "vertex"}
        VTK cell type of every cell.
    point_data : mapping of str to numpy.ndarray, optional
        Arrays of shape ``(n_points,)`` (scalars) or ``(n_points, 3)`` (vectors), in SI units.
    cell_data : mapping of str to numpy.ndarray, optional
        Arrays of shape ``(n_cells,)`` or ``(n_cells, 3)``, in SI units.

    Raises
    ------
    CaseFileError
        If a shape, dtype or cell type is wrong, or a cell refers to a missing point.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> folder = tempfile.mkdtemp()
    >>> points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> write_vtu(f"{folder}/tet.vtu", points=points, cells=np.array([[0, 1, 2, 3]]),
    ...           cell_data={"body": np.array([7])})
    """
    import meshio

    path = Path(path)
    where = f"writing {path}"
    if cell_type not in _NODES_PER_CELL:
        raise CaseFileError(
            f"{where}: cell_type {cell_type!r} is not one of {sorted(_NODES_PER_CELL)}."
        )
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise CaseFileError(f"{where}: points have shape {points.shape}, expected (n_points, 3).")
    nodes_per_cell = _NODES_PER_CELL[cell_type]
    cells = np.asarray(cells)
    if cells.size == 0:
        cells = cells.reshape(0, nodes_per_cell)
    if cells.ndim != 2 or cells.shape[1] != nodes_per_cell or cells.dtype.kind not in "iu":
        raise CaseFileError(
            f"{where}: cells have shape {cells.shape} and dtype {cells.dtype}, expected integers "
            f"of shape (n_cells, {nodes_per_cell}) for cell_type {cell_type!r}."
        )
    if cells.size and (cells.min() < 0 or cells.max() >= len(points)):
        raise CaseFileError(
            f"{where}: cells refer to point indices {cells.min()}..{cells.max()}, but there are "
            f"{len(points)} points (indices are zero-based)."
        )

    mesh = meshio.Mesh(
        points,
        [(cell_type, cells.astype(np.int64))],
        point_data={
            name: _as_vtk_array(name, values, len(points), where, "point")
            for name, values in (point_data or {}).items()
        },
        cell_data={
            name: [_as_vtk_array(name, values, len(cells), where, "cell")]
            for name, values in (cell_data or {}).items()
        },
    )
    with _atomic_target(path) as temporary:
        meshio.write(temporary, mesh, file_format="vtu", binary=True, compression="zlib")


def write_contacts_vtu(
    path: str | os.PathLike,
    *,
    points: np.ndarray,
    normal_forces: np.ndarray,
    tangential_forces: np.ndarray,
    body_i: np.ndarray,
    body_j: np.ndarray,
) -> None:
    """Write contacts as vertex cells with force vectors, for glyphs in ParaView.

    Each contact becomes one point and one vertex cell. In ParaView, apply *Glyph* with
    orientation array ``normal_force`` (or ``tangential_force``) and scale by its magnitude.

    Parameters
    ----------
    path : str or os.PathLike
        File to write.
    points : numpy.ndarray, shape (n_contacts, 3)
        Contact points in metres.
    normal_forces : numpy.ndarray, shape (n_contacts, 3)
        Normal contact force on body ``body_i`` from body ``body_j``, in newtons.
    tangential_forces : numpy.ndarray, shape (n_contacts, 3)
        Tangential (friction) contact force on body ``body_i``, in newtons.
    body_i, body_j : numpy.ndarray of int, shape (n_contacts,)
        Indices of the two bodies in contact.

    Notes
    -----
    Point data fields: ``normal_force``, ``tangential_force`` (vectors, N),
    ``normal_force_magnitude``, ``tangential_force_magnitude`` (scalars, N), ``body_i``,
    ``body_j`` (int64). The same fields are written as cell data so that either kind of
    colouring works.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    count = len(points)
    normal_forces = np.asarray(normal_forces, dtype=np.float64).reshape(-1, 3)
    tangential_forces = np.asarray(tangential_forces, dtype=np.float64).reshape(-1, 3)
    fields = {
        "normal_force": normal_forces,
        "tangential_force": tangential_forces,
        "normal_force_magnitude": np.linalg.norm(normal_forces, axis=1),
        "tangential_force_magnitude": np.linalg.norm(tangential_forces, axis=1),
        "body_i": np.asarray(body_i, dtype=np.int64).reshape(-1),
        "body_j": np.asarray(body_j, dtype=np.int64).reshape(-1),
    }
    write_vtu(
        path,
        points=points,
        cells=np.arange(count, dtype=np.int64).reshape(count, 1),
        cell_type="vertex",
        point_data=fields,
        cell_data=fields,
    )


class ParaViewSeries:
    """A time series of ``.vtu`` frames indexed by a ``.pvd`` collection file.

    Frames are named ``<name>_<index:06d>.vtu`` and listed in ``<name>.pvd`` in the same folder;
    open the ``.pvd`` in ParaView to play the series.

    Parameters
    ----------
    directory : str or os.PathLike
        Folder of the series; created if missing.
    name : str
        Base name of the ``.pvd`` and ``.vtu`` files.
    append : bool
        ``False`` starts a new series, replacing any ``<name>.pvd`` already there. ``True``
        continues an existing series after a restart: the frames already listed are kept up to,
        but not including, the time of the first frame added now, and numbering continues after
        them. Frames at or after that time are dropped from the index and their files deleted.

    Raises
    ------
    CheckpointError
        With ``append=True``, if the existing ``.pvd`` cannot be read.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> series = ParaViewSeries(tempfile.mkdtemp(), name="bodies")
    >>> points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> for time in (0.0, 0.05):
    ...     _ = series.add(time, points=points, cells=np.array([[0, 1, 2, 3]]))
    >>> series.frames
    [(0.0, 'bodies_000000.vtu'), (0.05, 'bodies_000001.vtu')]
    """

    def __init__(self, directory: str | os.PathLike, name: str = "bodies", *, append: bool = False):
        if not name or re.search(r"[\\/]", name):
            raise CaseFileError(f"ParaViewSeries name {name!r} must be a non-empty file name.")
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.name = name
        self._frames: list[tuple[float, str]] = []
        # In append mode the old frames are trimmed only when the first new frame arrives,
        # because only then is the restart time known.
        self._trim_pending = False
        if append and self.pvd_path.exists():
            self._frames = self._read_pvd()
            self._trim_pending = True
        else:
            self._write_pvd()

    @property
    def pvd_path(self) -> Path:
        """Path of the ``.pvd`` collection file."""
        return self.directory / f"{self.name}.pvd"

    @property
    def frames(self) -> list[tuple[float, str]]:
        """``(time, file name)`` of every frame listed in the ``.pvd``, time in seconds."""
        return list(self._frames)

    def add(
        self,
        time: float,
        *,
        points: np.ndarray,
        cells: np.ndarray,
        cell_type: str = "tetra",
        point_data: Mapping[str, np.ndarray] | None = None,
        cell_data: Mapping[str, np.ndarray] | None = None,
    ) -> Path:
        """Write one frame and list it in the ``.pvd``.

        Parameters
        ----------
        time : float
            Simulated time of the frame, in seconds; must exceed the previous frame's time.
        points, cells, cell_type, point_data, cell_data
            As in :func:`write_vtu`.

        Returns
        -------
        pathlib.Path
            The ``.vtu`` file written.

        Raises
        ------
        CaseFileError
            If ``time`` is not finite or not later than the last frame's time.
        """
        return self._add_frame(time, "vtu", lambda path: write_vtu(
            path, points=points, cells=cells, cell_type=cell_type, point_data=point_data,
            cell_data=cell_data))

    def add_contacts(self, time: float, contacts) -> Path:
        """One frame of contacts (``ContactRecords``): a vertex per touching pair at its contact
        point, with ``normal_force``, ``tangential_force`` (N, on ``body_i``) and the pair
        (``body_i``, ``body_j``; ``body_j = -1 - w`` for wall ``w``), which ``riprap analyse``
        reads back."""
        return self.add(time, points=contacts.points,
                        cells=np.arange(len(contacts.body_i)).reshape(-1, 1), cell_type="vertex",
                        point_data={"normal_force": contacts.normal_forces,
                                    "tangential_force": contacts.tangential_forces,
                                    "body_i": contacts.body_i, "body_j": contacts.body_j})

    def add_image(self, time: float, *, origin, spacing: float, cells, cell_data) -> Path:
        """Write one frame of a uniform grid (``.vti``, :func:`riprap.io.vti.write_vti`) and list
        it in the ``.pvd``; ``cells`` = (nx, ny, nz), ``cell_data`` arrays of that shape (or with
        a trailing 3 for vectors)."""
        return self._add_frame(time, "vti", lambda path: write_vti(
            path, origin=origin, spacing=spacing, cells=cells, cell_data=cell_data))

    def next_frame_stem(self, time: float) -> str:
        """The name, without extension, that the frame at ``time`` will take (its checks and a
        restart's trimming done now): for a frame written in pieces by several processes before
        :meth:`list_frame` lists it."""
        time = self._checked_time(time)
        return f"{self.name}_{self._next_index():06d}"

    def list_frame(self, time: float, file_name: str) -> None:
        """List a frame written elsewhere (a ``.pvti`` and its pieces, named by
        :meth:`next_frame_stem`) in the ``.pvd``."""
        time = self._checked_time(time)
        self._frames.append((time, file_name))
        self._write_pvd()

    def _checked_time(self, time: float) -> float:
        time = float(time)
        if not math.isfinite(time):
            raise CaseFileError(f"{self.pvd_path}: frame time {time} is not finite.")
        if self._trim_pending:
            self._drop_frames_from(time)
            self._trim_pending = False
        if self._frames and time <= self._frames[-1][0]:
            raise CaseFileError(
                f"{self.pvd_path}: frame time {time!r} s is not after the last frame's time "
                f"{self._frames[-1][0]!r} s; times must increase (use append=True to restart "
                "a series from an earlier time)."
            )
        return time

    def _add_frame(self, time: float, extension: str, write) -> Path:
        file_name = f"{self.next_frame_stem(time)}.{extension}"
        path = self.directory / file_name
        write(path)
        self.list_frame(time, file_name)
        return path

    def _next_index(self) -> int:
        pattern = re.compile(rf"^{re.escape(self.name)}_(\d+)\.p?vt[ui]$")
        indices = [int(match.group(1)) for _, file_name in self._frames
                   if (match := pattern.match(file_name))]
        return max(indices, default=-1) + 1

    def _drop_frames_from(self, restart_time: float) -> None:
        kept = [frame for frame in self._frames if frame[0] < restart_time]
        dropped = [frame for frame in self._frames if frame[0] >= restart_time]
        self._frames = kept
        # Index first, files second: a crash in between leaves unlisted files, never a
        # listing that points at a deleted file.
        self._write_pvd()
        kept_names = {file_name for _, file_name in kept}
        for _, file_name in dropped:
            candidate = self.directory / file_name
            if file_name not in kept_names and candidate.parent == self.directory:
                candidate.unlink(missing_ok=True)
                pieces = candidate.with_suffix("")      # a .pvti's folder of pieces
                if candidate.suffix == ".pvti" and pieces.is_dir():
                    shutil.rmtree(pieces, ignore_errors=True)

    def _read_pvd(self) -> list[tuple[float, str]]:
        try:
            root = ElementTree.parse(self.pvd_path).getroot()
            frames = [
                (float(dataset.attrib["timestep"]), dataset.attrib["file"])
                for dataset in root.iter("DataSet")
            ]
        except (ElementTree.ParseError, KeyError, ValueError, OSError) as error:
            raise CheckpointError(
                f"cannot continue the ParaView series {self.pvd_path}: {error}. Repair or delete "
                "the .pvd, or create the series with append=False to start it again."
            ) from error
        if root.tag != "VTKFile" or root.attrib.get("type") != "Collection":
            raise CheckpointError(
                f"cannot continue the ParaView series {self.pvd_path}: it is not a VTK "
                "Collection file. Delete it or create the series with append=False."
            )
        return sorted(frames)

    def _write_pvd(self) -> None:
        root = ElementTree.Element(
            "VTKFile", type="Collection", version="0.1", byte_order="LittleEndian"
        )
        collection = ElementTree.SubElement(root, "Collection")
        for time, file_name in self._frames:
            # repr() gives the shortest text that reads back as the same float.
            ElementTree.SubElement(
                collection, "DataSet", timestep=repr(time), group="", part="0", file=file_name
            )
        ElementTree.indent(root)
        text = ElementTree.tostring(root, encoding="utf-8", xml_declaration=True)
        with _atomic_target(self.pvd_path) as temporary:
            temporary.write_bytes(text + b"\n")


class CombinedSeries:
    """One ``.pvd`` that lists the frames of several series as parts of one data set per time
    (e.g. ``run.pvd``: the fluid's grid as part 0 and the bodies' surfaces as part 1), so that
    ParaView opens them together from one file. Rewritten, atomically, after every frame."""

    def __init__(self, path, series: list[ParaViewSeries]):
        self.path = Path(path)
        self.series = list(series)

    def write(self) -> Path:
        root = ElementTree.Element(
            "VTKFile", type="Collection", version="0.1", byte_order="LittleEndian"
        )
        collection = ElementTree.SubElement(root, "Collection")
        for part, series in enumerate(self.series):
            for time, file_name in series.frames:
                ElementTree.SubElement(collection, "DataSet", timestep=repr(time), group="",
                                       part=str(part), file=file_name)
        ElementTree.indent(root)
        text = ElementTree.tostring(root, encoding="utf-8", xml_declaration=True)
        with _atomic_target(self.path) as temporary:
            temporary.write_bytes(text + b"\n")
        return self.path
