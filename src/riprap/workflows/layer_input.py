"""The layer state ``riprap analyse`` analyses, rebuilt from a pack folder or from one frame of a
run started from one (the files themselves are read by :mod:`riprap.io.analysis_input` and
:mod:`riprap.io.layer_file`).

- A pack: the case's shapes, materials and walls (``pack.toml`` loaded as a case), the poses of
  its ``[[bodies]]``, the contacts of ``contacts.csv`` and the layer of ``layer.json``.
- A run: its ``summary.json`` names the case it ran, which must be a pack or include one (whose
  ``layer.json`` says which bodies are units); each body's pose in a frame of ``bodies.pvd`` is
  fitted exactly to its world surface (the rotation that carries the stored mesh's surface nodes
  onto the frame's, Kabsch 1976, Acta Cryst. A32: 922). Frame 0 is the reference the units'
  displacements are measured from. A coupled run written by an older riprap has no
  ``contacts.pvd``: its state has no contacts and says so (``contacts_recorded`` False).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.analysis.layer_state import LayerDescription, LayerState
from riprap.case.build import build_friction_pairs, build_material, build_shape
from riprap.case.load import load_case
from riprap.errors import CaseFileError
from riprap.geometry.mass_properties import mass_properties
from riprap.io.analysis_input import (included_pack, is_run_folder, no_contact_records,
                                      pack_folder, read_bodies_frame, read_contacts_vtu,
                                      read_pvd_frames, run_case_file)
from riprap.io.layer_file import CONTACTS_FILE_NAME, read_contact_table, read_layer_file

__all__ = ["load_layer_state", "load_pack_state", "load_run_state", "load_run_case",
           "refuse_run_without_frames"]


def load_layer_state(path, *, frame: int = -1, reference_run=None):
    """A :class:`~riprap.analysis.layer_state.LayerState` from a pack folder or file, or from
    frame ``frame`` (index into the run's frames, -1 the last) of a run folder; ``reference_run``
    (a run folder of the same bodies, e.g. a test series' first step): the displacements and the
    eroded area count from its frame 0 instead of the run's own."""
    path = Path(path)
    refuse_run_without_frames(path)
    if is_run_folder(path):
        return load_run_state(path, frame=frame, reference_run=reference_run)
    return load_pack_state(path)


def refuse_run_without_frames(path) -> None:
    """A clear error for a path the analysis cannot read: none there, or a run folder that wrote
    no frames of its bodies (``[output] paraview = false``: no ``bodies.pvd``), which would
    otherwise be taken for a pack folder without its ``pack.toml``."""
    path = Path(path)
    if not path.exists():
        raise CaseFileError(f"{path}: no such pack or run folder")
    if (path.is_dir() and not is_run_folder(path) and not (path / "pack.toml").is_file()
            and (path / "summary.json").is_file() and (path / "checkpoint.npz").is_file()):
        raise CaseFileError(f"{path}: a run folder without bodies.pvd (the run had [output] "
                            "paraview = false): the analysis reads the bodies' poses from its "
                            "frames; run the case again with paraview = true")


def _case_parts(pack_file: Path):
    """Case, shape meshes and centroids, materials, walls of a pack file."""
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
    allowed = layer.unit_shape_names
    unknown = [name for name in allowed if name not in shape_names]
    if unknown:
        raise CaseFileError(f"{pack_file.parent / 'layer.json'}: unit_shape '{unknown[0]}' is "
                            f"not a shape of {pack_file} (shapes: {', '.join(shape_names)})")
    wrong = [int(b) for b in layer.unit_bodies if case.bodies[b].shape not in allowed]
    if wrong:
        names = "', '".join(allowed[:5]) + ("', ..." if len(allowed) > 5 else "'")
        raise CaseFileError(f"{pack_file.parent / 'layer.json'}: unit_bodies {wrong[:5]} are not "
                            f"'{names} bodies in {pack_file}")


def _check_contacts(contacts, n_bodies, n_walls, where) -> None:
    body_i, body_j = np.asarray(contacts.body_i), np.asarray(contacts.body_j)
    bad = (body_i < 0) | (body_i >= n_bodies) | (body_j >= n_bodies) | (body_j < -n_walls)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise CaseFileError(f"{where}: contact {row} joins body {int(body_i[row])} and "
                            f"{int(body_j[row])}, but there are {n_bodies} bodies and {n_walls} walls")


def _read_pack(pack_file: Path) -> dict:
    """Everything of a pack, or of a case that includes one, but the poses and contacts: the
    case's shapes, materials, walls and bodies, and the pack's layer description (checked against
    the case; the pack's bodies come first in a case that includes it, so its numbers hold)."""
    case, shape_names, meshes, centroids, materials, walls = _case_parts(pack_file)
    included = included_pack(pack_file)
    layer = LayerDescription.from_fields(
        read_layer_file((included or pack_file).parent, n_bodies=len(case.bodies)))
    _check_layer_against_case(layer, case, shape_names, pack_file)
    material_names = [m.name for m in materials]
    return {"case": case, "shape_names": shape_names, "meshes": meshes, "centroids": centroids,
            "materials": materials, "friction_pairs": build_friction_pairs(case),
            "walls": walls, "layer": layer,
            "shape_of_body": np.array([shape_names.index(b.shape) for b in case.bodies],
                                      dtype=np.int64),
            "material_of_body": np.array([material_names.index(b.material) for b in case.bodies],
                                         dtype=np.int64)}


def _layer_state(pack: dict, *, positions, rotations, contacts, time: float, source: str,
                 **reference):
    """``reference``: the keyword arguments of LayerState's reference and ``contacts_recorded``."""
    case, walls = pack["case"], pack["walls"]
    _check_contacts(contacts, len(case.bodies), len(walls[0]), source)
    return LayerState(
        positions=positions, rotations=rotations, shape_of_body=pack["shape_of_body"],
        shape_names=pack["shape_names"], meshes=pack["meshes"], mesh_centroids=pack["centroids"],
        material_of_body=pack["material_of_body"], materials=pack["materials"],
        fixed=np.array([b.fixed for b in case.bodies], dtype=bool),
        wall_points=walls[0], wall_normals=walls[1], wall_materials=walls[2],
        contacts=contacts, gravity=np.asarray(case.simulation.gravity, dtype=float),
        time=float(time), layer=pack["layer"], source=source,
        friction_pairs=pack["friction_pairs"], **reference)


def load_pack_state(path):
    """The state of a pack folder (or its ``pack.toml``)."""
    folder, pack_file = pack_folder(Path(path))
    pack = _read_pack(pack_file)
    bodies = pack["case"].bodies
    return _layer_state(
        pack, positions=np.array([b.position for b in bodies], dtype=float).reshape(-1, 3),
        rotations=_rotation_matrices([b.orientation for b in bodies]),
        contacts=read_contact_table(folder / CONTACTS_FILE_NAME), time=0.0,
        source=str(pack_file), reference_note="none: a pack on its own has no earlier state")


def _fit_pose(local, world, centroid):
    """Rotation R and position p with world = p + R (local - centroid), least squares (exact for a
    rigid motion)."""
    local_mean, world_mean = local.mean(axis=0), world.mean(axis=0)
    covariance = (world - world_mean).T @ (local - local_mean)
    u, _, vt = np.linalg.svd(covariance)
    d = np.sign(np.linalg.det(u @ vt))
    rotation = u @ np.diag([1.0, 1.0, d]) @ vt
    return rotation, world_mean - rotation @ (local_mean - centroid)


def load_run_state(run_folder, *, frame: int = -1, reference_run=None):
    """The state at frame ``frame`` (index into ``bodies.pvd``'s list, -1 the last) of a run
    started from a pack (or from a case that includes one), with frame 0's poses as the reference
    of the displacements."""
    run_folder = Path(run_folder)
    pack_file = run_case_file(run_folder)
    pack = _read_pack(pack_file)
    frames = read_pvd_frames(run_folder / "bodies.pvd")
    coupled = (run_folder / "fluid.pvd").is_file() and not (run_folder / "contacts.pvd").exists()
    contact_frames = {} if coupled else dict(read_pvd_frames(run_folder / "contacts.pvd"))
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
    own_reference = reference
    if reference_run is not None:
        # the rocking events stay counted from the run's own frame 0 (a unit tilted for good in
        # an earlier step does not rock in this one); the displacements count from the other's
        reference_run = Path(reference_run)
        reference = _reference_poses(reference_run, read_pvd_frames(reference_run / "bodies.pvd"),
                                     -1, pack, pack_file, now=None)
    if coupled:
        contacts = no_contact_records()
    else:
        contacts = read_contacts_vtu(run_folder / contact_frames[time],
                                      f"the contacts frame at t = {time:g} s (contacts.pvd)")
    history = _rotation_history(run_folder, frames, frame, pack, pack_file, own_reference,
                                rotations)
    return _layer_state(pack, positions=positions, rotations=rotations, contacts=contacts,
                        time=time, source=f"{run_folder}, frame {frame % len(frames)}"
                        + (" (the last)" if frame % len(frames) == len(frames) - 1 else "")
                        + f", t = {time:g} s",
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


def load_run_case(run_folder):
    """The case a run folder's run ran (its ``summary.json``'s ``case_file``), loaded."""
    return load_case(run_case_file(Path(run_folder)))


def _reference_poses(run_folder: Path, frames, frame: int, pack: dict, pack_file: Path, *,
                     now) -> dict:
    """LayerState's reference keywords: frame 0's poses (``now``, the poses of frame ``frame``,
    when that is frame 0), or none, with the reason, when frame 0 cannot be read."""
    time = frames[0][0]
    note = f"frame 0 of {run_folder / 'bodies.pvd'} (t = {time:g} s)"
    if now is not None and frame % len(frames) == 0:
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
    points, triangles, owners = read_bodies_frame(frame_path, what)
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
