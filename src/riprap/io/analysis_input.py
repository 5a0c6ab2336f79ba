"""Reading the files ``riprap analyse`` analyses: a pack folder, or the frames of a run started
from one. These readers return what the files hold (frames, meshes, contact records, the case file
a run ran); rebuilding a layer's state from them (the case's shapes and materials, the poses fitted
to a frame) is :mod:`riprap.workflows.layer_input`.

- A pack (``riprap place``'s output folder, or its ``pack.toml``): poses from ``pack.toml``, shapes
  from ``shapes/*.vtu``, contact forces from ``contacts.csv``, the layer from ``layer.json``
  (:mod:`riprap.io.layer_file`).
- A run (the output folder of ``riprap run pack.toml``, or of a case that includes a pack with
  ``pack = "..."``, such as a pack put in water): its ``summary.json`` names the case it ran
  (``case_file``); a frame of ``bodies.pvd`` gives every body's world surface and the same frame of
  ``contacts.pvd`` the contacts with their forces. A coupled run (``fluid.pvd`` beside) writes
  ``contacts.pvd`` as a dry run does; one written by an older riprap has none.
"""
from __future__ import annotations

import contextlib
import io
import tomllib
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.json_files import read_json_object
from riprap.io.pack import PACK_FILE_NAME
from riprap.io.waves_report_file import read_waves_report
from riprap.solid.solver import ContactRecords

__all__ = ["is_run_folder", "pack_folder", "included_pack", "read_pvd_frames", "read_frame_mesh",
           "read_bodies_frame", "read_contacts_vtu", "no_contact_records", "run_case_file",
           "load_waves_report", "run_was_smoke"]


def pack_folder(path: Path) -> tuple[Path, Path]:
    """The folder and the ``pack.toml`` of a pack given as either."""
    if path.is_dir():
        return path, path / PACK_FILE_NAME
    return path.parent, path


def is_run_folder(path) -> bool:
    """Whether ``path`` is the output folder of a run (``bodies.pvd`` and ``summary.json``) and
    not a pack folder."""
    path = Path(path)
    return (path.is_dir() and (path / "bodies.pvd").is_file()
            and not (path / "pack.toml").is_file())


def run_was_smoke(path) -> bool:
    """Whether the run in folder ``path`` was a smoke run (its ``summary.json`` says so:
    ``RIPRAP_SMOKE=1``, cut short, no results); False for a pack or a run without a summary."""
    summary = Path(path) / "summary.json"
    if not (is_run_folder(path) and summary.is_file()):
        return False
    return read_json_object(summary, "run summary", "riprap run wrote it").get("smoke") is True


def included_pack(case_file: Path) -> Path | None:
    """The pack a case file takes its bodies from (top-level ``pack = "..."``), or None."""
    try:
        top = tomllib.loads(case_file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None                       # load_case names what is wrong with it
    pack = top.get("pack")
    return case_file.parent / pack if isinstance(pack, str) and pack else None


def read_pvd_frames(pvd: Path) -> list[tuple[float, str]]:
    """The (time, file) frames of a ParaView series, in time order."""
    if not pvd.is_file():
        raise CaseFileError(f"{pvd}: missing; the run folder lacks its ParaView series (was the "
                            "run written with paraview output off, or the file deleted?)")
    try:
        root = ElementTree.parse(pvd).getroot()
        frames = sorted((float(d.attrib["timestep"]), d.attrib["file"])
                        for d in root.iter("DataSet"))
    except (ElementTree.ParseError, KeyError, ValueError, OSError) as error:
        raise CaseFileError(f"{pvd}: cannot read the ParaView series: {error}") from None
    bad = [time for time, _ in frames if not np.isfinite(time)]
    if bad:
        raise CaseFileError(f"{pvd}: a frame has timestep {bad[0]!r}; times must be finite")
    return frames


def read_frame_mesh(path: Path, what: str):
    """``meshio.read`` of one frame file; a missing, empty or truncated file is a CaseFileError
    naming the frame (meshio itself would call ``sys.exit`` on some of them)."""
    import meshio

    if not path.is_file():
        raise CaseFileError(f"{path}: {what} is listed in the series but the file does not exist; "
                            "the run folder is incomplete (copied in part, or the run was cut off)")
    if path.stat().st_size == 0:
        raise CaseFileError(f"{path}: {what} is empty (0 bytes); the run was cut off while "
                            "writing it, analyse another frame (--frame)")
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            return meshio.read(path)
    except (Exception, SystemExit) as error:
        detail = " ".join(said.getvalue().split())
        if not isinstance(error, SystemExit):
            detail = f"{type(error).__name__}: {error}" + (f" ({detail})" if detail else "")
        raise CaseFileError(f"{path}: cannot read {what} ({detail or 'no reason given'}); the "
                            "file is truncated or corrupt, analyse another frame (--frame)") from None


def read_bodies_frame(frame_path: Path, what: str):
    """Points (n, 3), surface triangles (m, 3) and each triangle's body (m,) of one frame of
    ``bodies.pvd``, checked: finite 3D points, triangles within the points, body ids >= 0."""
    bodies_mesh = read_frame_mesh(frame_path, what)
    points = np.asarray(bodies_mesh.points, dtype=float)
    cells = bodies_mesh.cells_dict
    owner_data = bodies_mesh.cell_data_dict.get("body_id", {})
    if "triangle" not in cells or "triangle" not in owner_data:
        raise CaseFileError(f"{frame_path}: {what} has no body surfaces with 'body_id' (cell "
                            f"types {', '.join(sorted(cells)) or 'none'}); it is not a riprap "
                            "bodies frame, or was written by an older riprap")
    triangles = np.asarray(cells["triangle"], dtype=np.int64)
    owners = _integer_array(owner_data["triangle"], len(triangles), "body_id", frame_path)
    if points.ndim != 2 or points.shape[1] != 3 or not np.isfinite(points).all():
        raise CaseFileError(f"{frame_path}: {what} has non-finite or non-3D point coordinates")
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(points)):
        raise CaseFileError(f"{frame_path}: {what} has triangles with point indices outside "
                            f"0..{len(points) - 1}; the file is corrupt")
    if owners.size and owners.min() < 0:
        raise CaseFileError(f"{frame_path}: {what} has a negative body_id {int(owners.min())}")
    return points, triangles, owners


def no_contact_records():
    """Contact records of a state without contacts."""
    return ContactRecords(body_i=np.zeros(0, np.int64), body_j=np.zeros(0, np.int64),
                          points=np.zeros((0, 3)), normal_forces=np.zeros((0, 3)),
                          tangential_forces=np.zeros((0, 3)), stiffness=np.zeros(0))


def _integer_array(values, count: int, name: str, path: Path) -> np.ndarray:
    values = np.asarray(values).reshape(-1)
    if values.size != count:
        raise CaseFileError(f"{path}: '{name}' has {values.size} values for {count} points")
    if not np.issubdtype(values.dtype, np.integer):
        exact = np.isfinite(values) & (values == np.round(values))
        if not exact.all():
            k = int(np.flatnonzero(~exact)[0])
            raise CaseFileError(f"{path}: '{name}' of point {k} is {values[k]!r}, not an integer "
                                "body index")
    return values.astype(np.int64)


def _finite_vectors(values, count: int, name: str, path: Path) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    if values.size != 3 * count:
        raise CaseFileError(f"{path}: '{name}' has {values.size} numbers for {count} points "
                            "(expected 3 each)")
    values = values.reshape(count, 3)
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    if bad.size:
        raise CaseFileError(f"{path}: '{name}' of point {int(bad[0])} is {values[bad[0]].tolist()} "
                            f"(not finite; {bad.size} such points)")
    return values


def read_contacts_vtu(path: Path, what: str = "the contacts frame"):
    """Contact records of one frame of ``contacts.pvd`` (``body_i``, ``body_j``, forces)."""
    if path.is_file() and path.stat().st_size > 0:
        # meshio cannot read a VTU without points: a frame with no contacts.
        try:
            pieces = [piece.attrib.get("NumberOfPoints") for piece in
                      ElementTree.parse(path).getroot().iter("Piece")]
        except (ElementTree.ParseError, OSError):
            pieces = []
        if pieces and all(count == "0" for count in pieces):
            return no_contact_records()
    mesh = read_frame_mesh(path, what)
    data = mesh.point_data
    missing = [name for name in ("body_i", "body_j", "normal_force", "tangential_force")
               if name not in data]
    if missing:
        raise CaseFileError(f"{path}: the contacts frame lacks {', '.join(missing)} (written by an "
                            "older riprap?); analyse the pack instead")
    count = len(mesh.points)
    return ContactRecords(
        body_i=_integer_array(data["body_i"], count, "body_i", path),
        body_j=_integer_array(data["body_j"], count, "body_j", path),
        points=_finite_vectors(mesh.points, count, "points", path),
        normal_forces=_finite_vectors(data["normal_force"], count, "normal_force", path),
        tangential_forces=_finite_vectors(data["tangential_force"], count, "tangential_force",
                                          path),
        stiffness=np.zeros(count))


def load_waves_report(run_folder) -> dict | None:
    """The ``waves_report.json`` of a flume run's folder, every field checked
    (:mod:`riprap.io.waves_report_file`), or None when the run wrote none."""
    return read_waves_report(run_folder)


def run_case_file(run_folder: Path) -> Path:
    """The case a run folder's ``summary.json`` says the run ran."""
    summary_path = run_folder / "summary.json"
    summary = read_json_object(summary_path, "run summary", "the analysis of a run needs it to "
                                                            "find the case the run was started from")
    case_file = summary.get("case_file")
    if not isinstance(case_file, (str, type(None))):
        raise CaseFileError(f"{summary_path}: 'case_file' must be a path (a string), got "
                            f"{case_file!r}")
    if not case_file:
        raise CaseFileError(f"{summary_path}: no 'case_file' (runs of this riprap version record "
                            "the case they ran); analyse the pack instead, or run it again")
    return Path(case_file)
