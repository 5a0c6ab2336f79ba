"""Reading what ``riprap analyse`` analyses: a pack folder, or one frame of a run started from one.

- A pack (``riprap place``'s output folder, or its ``pack.toml``): poses from ``pack.toml``, shapes
  from ``shapes/*.vtu``, contact forces from ``contacts.csv``, the layer from ``layer.json``
  (:mod:`riprap.io.layer_file`).
- A run (the output folder of ``riprap run pack.toml``, or of a case that includes a pack with
  ``pack = "..."``, such as a pack put in water): its ``summary.json`` names the case it ran
  (``case_file``), which must be a pack or include one (whose ``layer.json`` says which bodies are
  units); a frame of ``bodies.pvd`` gives every body's world surface, from which its pose is
  fitted exactly (the rotation that carries the stored mesh's surface nodes onto the frame's,
  Kabsch 1976, Acta Cryst. A32: 922), and the same frame of ``contacts.pvd`` gives the contacts
  with their forces. Frame 0 of ``bodies.pvd`` is the reference the units' displacements are
  measured from. A coupled run (``fluid.pvd`` beside) writes ``contacts.pvd`` as a dry run does;
  one written by an older riprap has none: its state has no contacts and says so
  (``contacts_recorded`` False).
"""
from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.errors import CaseFileError
from riprap.io.json_files import read_json_object

__all__ = ["load_layer_state", "load_pack_state", "load_run_state", "is_run_folder",
           "load_waves_report", "load_run_case"]


def _pack_folder(path: Path) -> tuple[Path, Path]:
    from riprap.io.pack import PACK_FILE_NAME

    if path.is_dir():
        return path, path / PACK_FILE_NAME
    return path.parent, path


def is_run_folder(path) -> bool:
    """Whether ``path`` is the output folder of a run (``bodies.pvd`` and ``summary.json``) and
    not a pack folder."""
    path = Path(path)
    return (path.is_dir() and (path / "bodies.pvd").is_file()
            and not (path / "pack.toml").is_file())


def load_layer_state(path, *, frame: int = -1):
    """A :class:`~riprap.analysis.layer_state.LayerState` from a pack folder or file, or from
    frame ``frame`` (index into the run's frames, -1 the last) of a run folder."""
    path = Path(path)
    if not path.exists():
        raise CaseFileError(f"{path}: no such pack or run folder")
    if is_run_folder(path):
        return load_run_state(path, frame=frame)
    return load_pack_state(path)


def _case_parts(pack_file: Path):
    """Case, shape meshes and centroids, materials, walls of a pack file."""
    from riprap.case.build import build_material, build_shape
    from riprap.case.load import load_case
    from riprap.geometry.mass_properties import mass_properties

    case = load_case(pack_file)
    if case.body_grids:
        raise CaseFileError(f"{pack_file}: has [[body_grids]]; a pack lists every body in [[bodies]]")
    shape_names = [spec.name for spec in case.shapes]
    meshes = [build_shape(spec) for spec in case.shapes]
    centroids = np.array([mass_properties(mesh, density=1.0).centroid for mesh in meshes])
    materials = [build_material(spec) for spec in case.materials]
    material_names = [m.name for m in materials]
    planes = [w for w in case.walls if w.type == "plane"]
    if len(planes) != len(case.walls):
        raise CaseFileError(f"{pack_file}: the analysis reads plane walls only (a pack writes its "
                            "container as planes); found a box wall")
    walls = (np.array([w.parameters["point"] for w in planes], dtype=float).reshape(-1, 3),
             np.array([w.parameters["normal"] for w in planes], dtype=float).reshape(-1, 3),
             np.array([material_names.index(w.material) for w in planes], dtype=np.int64))
    return case, shape_names, meshes, centroids, materials, walls


def _rotation_matrices(quaternions) -> np.ndarray:
    q = np.asarray(quaternions, dtype=float).reshape(-1, 4)
    if len(q) == 0:
        return np.zeros((0, 3, 3))
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()


def _check_layer_against_case(layer, case, shape_names, pack_file) -> None:
    if layer.unit_shape not in shape_names:
        raise CaseFileError(f"{pack_file.parent / 'layer.json'}: unit_shape '{layer.unit_shape}' is "
                            f"not a shape of {pack_file} (shapes: {', '.join(shape_names)})")
    wrong = [int(b) for b in layer.unit_bodies if case.bodies[b].shape != layer.unit_shape]
    if wrong:
        raise CaseFileError(f"{pack_file.parent / 'layer.json'}: unit_bodies {wrong[:5]} are not "
                            f"'{layer.unit_shape}' bodies in {pack_file}")


def _check_contacts(contacts, n_bodies, n_walls, where) -> None:
    body_i, body_j = np.asarray(contacts.body_i), np.asarray(contacts.body_j)
    bad = (body_i < 0) | (body_i >= n_bodies) | (body_j >= n_bodies) | (body_j < -n_walls)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise CaseFileError(f"{where}: contact {row} joins body {int(body_i[row])} and "
                            f"{int(body_j[row])}, but there are {n_bodies} bodies and {n_walls} walls")


def _included_pack(case_file: Path) -> Path | None:
    """The pack a case file takes its bodies from (top-level ``pack = "..."``), or None."""
    import tomllib

    try:
        top = tomllib.loads(case_file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None                       # load_case names what is wrong with it
    pack = top.get("pack")
    return case_file.parent / pack if isinstance(pack, str) and pack else None


def _read_pack(pack_file: Path) -> dict:
    """Everything of a pack, or of a case that includes one, but the poses and contacts: the
    case's shapes, materials, walls and bodies, and the pack's layer description (checked against
    the case; the pack's bodies come first in a case that includes it, so its numbers hold)."""
    from riprap.io.layer_file import read_layer_file

    case, shape_names, meshes, centroids, materials, walls = _case_parts(pack_file)
    included = _included_pack(pack_file)
    layer = read_layer_file((included or pack_file).parent, n_bodies=len(case.bodies))
    _check_layer_against_case(layer, case, shape_names, pack_file)
    material_names = [m.name for m in materials]
    return {"case": case, "shape_names": shape_names, "meshes": meshes, "centroids": centroids,
            "materials": materials, "walls": walls, "layer": layer,
            "shape_of_body": np.array([shape_names.index(b.shape) for b in case.bodies],
                                      dtype=np.int64),
            "material_of_body": np.array([material_names.index(b.material) for b in case.bodies],
                                         dtype=np.int64)}


def _layer_state(pack: dict, *, positions, rotations, contacts, time: float, source: str,
                 **reference):
    """``reference``: the keyword arguments of LayerState's reference and ``contacts_recorded``."""
    from riprap.analysis.layer_state import LayerState

    case, walls = pack["case"], pack["walls"]
    _check_contacts(contacts, len(case.bodies), len(walls[0]), source)
    return LayerState(
        positions=positions, rotations=rotations, shape_of_body=pack["shape_of_body"],
        shape_names=pack["shape_names"], meshes=pack["meshes"], mesh_centroids=pack["centroids"],
        material_of_body=pack["material_of_body"], materials=pack["materials"],
        fixed=np.array([b.fixed for b in case.bodies], dtype=bool),
        wall_points=walls[0], wall_normals=walls[1], wall_materials=walls[2],
        contacts=contacts, gravity=np.asarray(case.simulation.gravity, dtype=float),
        time=float(time), layer=pack["layer"], source=source, **reference)


def load_pack_state(path):
    """The state of a pack folder (or its ``pack.toml``)."""
    from riprap.io.layer_file import CONTACTS_FILE_NAME, read_contact_table

    folder, pack_file = _pack_folder(Path(path))
    pack = _read_pack(pack_file)
    bodies = pack["case"].bodies
    return _layer_state(
        pack, positions=np.array([b.position for b in bodies], dtype=float).reshape(-1, 3),
        rotations=_rotation_matrices([b.orientation for b in bodies]),
        contacts=read_contact_table(folder / CONTACTS_FILE_NAME), time=0.0,
        source=str(pack_file), reference_note="none: a pack on its own has no earlier state")


def _pvd_frames(pvd: Path) -> list[tuple[float, str]]:
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


def _read_frame_mesh(path: Path, what: str):
    """``meshio.read`` of one frame file; a missing, empty or truncated file is a CaseFileError
    naming the frame (meshio itself would call ``sys.exit`` on some of them)."""
    import contextlib
    import io

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


def _fit_pose(local, world, centroid):
    """Rotation R and position p with world = p + R (local - centroid), least squares (exact for a
    rigid motion)."""
    local_mean, world_mean = local.mean(axis=0), world.mean(axis=0)
    covariance = (world - world_mean).T @ (local - local_mean)
    u, _, vt = np.linalg.svd(covariance)
    d = np.sign(np.linalg.det(u @ vt))
    rotation = u @ np.diag([1.0, 1.0, d]) @ vt
    return rotation, world_mean - rotation @ (local_mean - centroid)


def _no_contact_records():
    from riprap.solid.solver import ContactRecords

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


def _read_contacts_vtu(path: Path, what: str = "the contacts frame"):
    """Contact records of one frame of ``contacts.pvd`` (``body_i``, ``body_j``, forces)."""
    from riprap.solid.solver import ContactRecords

    if path.is_file() and path.stat().st_size > 0:
        # meshio cannot read a VTU without points: a frame with no contacts.
        try:
            pieces = [piece.attrib.get("NumberOfPoints") for piece in
                      ElementTree.parse(path).getroot().iter("Piece")]
        except (ElementTree.ParseError, OSError):
            pieces = []
        if pieces and all(count == "0" for count in pieces):
            return _no_contact_records()
    mesh = _read_frame_mesh(path, what)
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


def load_run_state(run_folder, *, frame: int = -1):
    """The state at frame ``frame`` (index into ``bodies.pvd``'s list, -1 the last) of a run
    started from a pack (or from a case that includes one), with frame 0's poses as the reference
    of the displacements."""
    run_folder = Path(run_folder)
    pack_file = _run_case_file(run_folder)
    pack = _read_pack(pack_file)
    frames = _pvd_frames(run_folder / "bodies.pvd")
    coupled = (run_folder / "fluid.pvd").is_file() and not (run_folder / "contacts.pvd").exists()
    contact_frames = {} if coupled else dict(_pvd_frames(run_folder / "contacts.pvd"))
    if not frames:
        raise CaseFileError(f"{run_folder / 'bodies.pvd'}: lists no frames")
    if isinstance(frame, (bool, np.bool_)) or not isinstance(frame, (int, np.integer)):
        raise CaseFileError(f"{run_folder}: frame must be an integer (0..{len(frames) - 1}, or -1 "
                            f"for the last), got {frame!r}")
    if not -len(frames) <= frame < len(frames):
        raise CaseFileError(f"{run_folder}: frame {frame} does not exist; the run wrote "
                            f"{len(frames)} frames (0..{len(frames) - 1}, or -1 for the last)")
    time = frames[frame][0]
    if not coupled and time not in contact_frames:
        raise CaseFileError(f"{run_folder / 'contacts.pvd'}: no frame at t = {time!r} s")
    positions, rotations = _frame_poses(run_folder, frames, frame, pack, pack_file)
    reference = _reference_poses(run_folder, frames, frame, pack, pack_file,
                                 now=(positions, rotations))
    if coupled:
        contacts = _no_contact_records()
    else:
        contacts = _read_contacts_vtu(run_folder / contact_frames[time],
                                      f"the contacts frame at t = {time:g} s (contacts.pvd)")
    history = _rotation_history(run_folder, frames, frame, pack, pack_file, reference, rotations)
    return _layer_state(pack, positions=positions, rotations=rotations, contacts=contacts,
                        time=time, source=f"{run_folder} frame {frame} (t = {time:g} s)",
                        contacts_recorded=not coupled, rotation_history=history, **reference)


def _rotation_history(run_folder, frames, frame, pack, pack_file, reference, now_rotations):
    """(frames 0..frame, bodies) rotation angles (degrees) from frame 0's poses, or None when
    frame 0 could not be read."""
    if "reference_rotations" not in reference:
        return None
    last = frame % len(frames)
    reference_rotations = np.asarray(reference["reference_rotations"])
    history = []
    for index in range(last + 1):
        rotations = now_rotations if index == last else _frame_poses(run_folder, frames, index,
                                                                     pack, pack_file)[1]
        relative = rotations @ np.transpose(reference_rotations, (0, 2, 1))
        history.append(np.degrees(Rotation.from_matrix(relative).magnitude()))
    return np.array(history)


def load_waves_report(run_folder) -> dict | None:
    """The ``waves_report.json`` of a flume run's folder, every field checked
    (:mod:`riprap.io.waves_report_file`), or None when the run wrote none."""
    from riprap.io.waves_report_file import read_waves_report

    return read_waves_report(run_folder)


def load_run_case(run_folder):
    """The case a run folder's run ran (its ``summary.json``'s ``case_file``), loaded."""
    from riprap.case.load import load_case

    return load_case(_run_case_file(Path(run_folder)))


def _run_case_file(run_folder: Path) -> Path:
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


def _reference_poses(run_folder: Path, frames, frame: int, pack: dict, pack_file: Path, *,
                     now) -> dict:
    """LayerState's reference keywords: frame 0's poses (``now``, the poses of frame ``frame``,
    when that is frame 0), or none, with the reason, when frame 0 cannot be read."""
    time = frames[0][0]
    note = f"frame 0 of {run_folder / 'bodies.pvd'} (t = {time:g} s)"
    if frame % len(frames) == 0:
        positions, rotations = now
    else:
        try:
            positions, rotations = _frame_poses(run_folder, frames, 0, pack, pack_file)
        except CaseFileError as error:
            return {"reference_note": f"none: {note} cannot be read ({error})"}
    return {"reference_positions": positions, "reference_rotations": rotations,
            "reference_time": float(time), "reference_note": note}


def _frame_poses(run_folder: Path, frames, frame: int, pack: dict, pack_file: Path):
    """Every body's centroid and rotation in frame ``frame`` of ``bodies.pvd``, fitted to its
    surface nodes."""
    n_bodies = len(pack["case"].bodies)
    shape_names, meshes, centroids = pack["shape_names"], pack["meshes"], pack["centroids"]
    time, body_file = frames[frame]
    frame_path = run_folder / body_file
    what = f"frame {frame % len(frames)} of bodies.pvd (t = {time:g} s)"
    bodies_mesh = _read_frame_mesh(frame_path, what)
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
    shape_of_body = pack["shape_of_body"]
    if owners.max(initial=-1) + 1 != n_bodies:
        raise CaseFileError(f"{run_folder / body_file}: has {owners.max(initial=-1) + 1} bodies, "
                            f"{pack_file} {n_bodies}: the run was not started from this pack")
    rotations = np.empty((n_bodies, 3, 3))
    positions = np.empty((n_bodies, 3))
    order = np.argsort(owners, kind="stable")
    starts = np.searchsorted(owners[order], np.arange(n_bodies + 1))
    # A frame writes each body's surface nodes in the order of the stored mesh (Simulation.
    # surface_arrays), so the nodes pair up one to one.
    surface_nodes = [mesh.nodes[np.unique(mesh.boundary_faces())] for mesh in meshes]
    for b in range(n_bodies):
        world = points[np.unique(triangles[order[starts[b]:starts[b + 1]]])]
        k = shape_of_body[b]
        local = surface_nodes[k]
        if len(local) != len(world):
            raise CaseFileError(f"{run_folder / body_file}: body {b} has {len(world)} surface "
                                f"nodes, its shape '{shape_names[k]}' {len(local)}")
        rotations[b], positions[b] = _fit_pose(local, world, centroids[k])
    return positions, rotations


