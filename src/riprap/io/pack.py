"""Pack files: a placed (or settled) set of bodies saved as an ordinary riprap case.

A pack is a folder::

    pack/
      pack.toml          format_version = 1 case file: [simulation], [[materials]], [[friction]],
                         [[shapes]], [[bodies]], [[walls]], [output]
      shapes/<name>.vtu  one tetrahedral mesh per shape (meshio, float64 coordinates)

so ``riprap run pack/pack.toml`` starts a run from it, and ``riprap.case.load.load_case`` reads
it back (there is no separate pack reader).

Frames. Each shape is written in the frame the caller gives (normally ``RigidShape.mesh``, the
principal frame the solver works in), and each body's ``orientation`` is the rotation from that
mesh as written into the world, ``position`` its centroid. On loading, the solver re-derives the
principal frame of the written mesh and composes it with the orientation
(``SolidSolver.add_body(frame="shape")``), so the world position of every node is
``position + R(orientation) (node - centroid of the mesh)`` whatever principal axes the
re-derivation picks: a cube or a sphere, whose principal moments are equal and whose axes are
therefore arbitrary, comes back in the same place (``tests/unit/test_pack_file.py``).

Numbers are written with ``repr`` (the shortest text that reads back as the same float64), so
poses round-trip to rounding: the loader normalises quaternions and wall normals again, which may
change their last bit.
"""
from __future__ import annotations

import datetime
import difflib
import importlib.metadata
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap import schema
from riprap.errors import CaseFileError
from riprap.geometry.tetmesh import TetMesh
from riprap.io.case_text import PACK_HEADER
from riprap.io.contact_history import CONTACT_HISTORY_FILE_NAME, write_contact_history
from riprap.io.mesh_files import write_volume_mesh

__all__ = ["PackBody", "write_pack", "riprap_version", "PACK_FILE_NAME", "PACK_HEADER", "SHAPES_FOLDER",
           "DEFAULT_PACK_SIMULATION", "DEFAULT_PACK_OUTPUT"]

#: Name of the case file inside a pack folder.
PACK_FILE_NAME = "pack.toml"
#: Sub-folder of a pack holding the shapes' meshes.
SHAPES_FOLDER = "shapes"

#: ``[simulation]`` keys written when the caller does not give them. A pack is usually the start
#: of a settling or loading run, so it stops once every free body is slower than 1 mm/s.
DEFAULT_PACK_SIMULATION = {"end_time": 1.0, "rest_speed": 1.0e-3}

#: ``[output]`` keys written when the caller does not give them (the case-file defaults).
DEFAULT_PACK_OUTPUT = {"directory": schema.default_of("output", "directory"),
                       "paraview": schema.default_of("output", "paraview"),
                       "picture": schema.default_of("output", "picture")}

# Characters kept in a shape's file name; others become "_" (the TOML name is kept as it is).
_UNSAFE_FILE_CHARACTERS = re.compile(r"[^A-Za-z0-9_.-]")


def _float_tuple(value, length: int, field: str, body: str) -> tuple[float, ...]:
    try:
        array = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise CaseFileError(f"{body}: {field} must be {length} numbers, got {value!r}") from None
    if array.size != length:
        raise CaseFileError(f"{body}: {field} must be {length} numbers, got {array.size}: "
                            f"{array.tolist()}")
    if not np.isfinite(array).all():
        raise CaseFileError(f"{body}: {field} = {array.tolist()} is not finite")
    return tuple(float(item) for item in array)


@dataclass(frozen=True)
class PackBody:
    """One body of a pack.

    Parameters
    ----------
    shape : str
        Name of its shape (a key of ``write_pack``'s ``shapes``).
    material : str
        Name of its material.
    position : (3,) float
        Centroid (m).
    orientation : (4,) float
        Unit quaternion (w, x, y, z) rotating the shape's mesh, as written, into the world.
    velocity : (3,) float
        Velocity of the centroid (m/s).
    angular_velocity : (3,) float
        Angular velocity in the world frame (rad/s).
    fixed : bool
        A fixed body never moves.

    Vectors are stored as tuples of float; the quaternion's norm must be at least
    :data:`~riprap.schema.MINIMUM_QUATERNION_NORM` (it is written as given and normalised
    when the pack is loaded).
    """

    shape: str
    material: str
    position: tuple
    orientation: tuple = schema.default_of("bodies", "orientation")
    velocity: tuple = schema.default_of("bodies", "velocity")
    angular_velocity: tuple = schema.default_of("bodies", "angular_velocity")
    fixed: bool = schema.default_of("bodies", "fixed")

    def __post_init__(self) -> None:
        label = f"pack body (shape '{self.shape}')"
        for field in ("shape", "material"):
            value = getattr(self, field)
            if not isinstance(value, str) or not value.strip():
                raise CaseFileError(f"{label}: {field} must be a non-empty name, got {value!r}")
        object.__setattr__(self, "position", _float_tuple(self.position, 3, "position", label))
        orientation = _float_tuple(self.orientation, 4, "orientation", label)
        norm = math.sqrt(sum(item * item for item in orientation))
        if norm < schema.MINIMUM_QUATERNION_NORM:
            raise CaseFileError(f"{label}: orientation = {list(orientation)} has norm {norm:.3g}, "
                                f"below {schema.MINIMUM_QUATERNION_NORM:g}; not a rotation")
        object.__setattr__(self, "orientation", orientation)
        object.__setattr__(self, "velocity", _float_tuple(self.velocity, 3, "velocity", label))
        object.__setattr__(self, "angular_velocity",
                           _float_tuple(self.angular_velocity, 3, "angular_velocity", label))
        if not isinstance(self.fixed, (bool, np.bool_)):
            raise CaseFileError(f"{label}: fixed must be True or False, got {self.fixed!r}")
        object.__setattr__(self, "fixed", bool(self.fixed))


def _toml(value) -> str:
    """A value as TOML text; floats with repr so they read back as the same float64."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        number = float(value)
        if not math.isfinite(number):
            raise CaseFileError(f"cannot write the non-finite number {number!r} to a pack")
        return repr(number)
    if isinstance(value, str):
        return schema.format_toml_value(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml(item) for item in value) + "]"
    raise CaseFileError(f"cannot write {value!r} ({type(value).__name__}) to a pack")


def _suggestion(name: str, candidates) -> str:
    close = difflib.get_close_matches(str(name), list(candidates), n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'? " if close else ""


def _table_keys(table_name: str, given: Mapping | None, defaults: Mapping) -> dict:
    """``defaults`` updated with ``given``, every key checked against the case schema."""
    allowed = [entry.name for entry in schema.keys_of(table_name)]
    values = dict(defaults)
    for name, value in (given or {}).items():
        if name not in allowed:
            raise CaseFileError(f"write_pack: unknown [{table_name}] key '{name}'; "
                                f"{_suggestion(name, allowed)}allowed keys: {', '.join(allowed)}")
        values[name] = value
    return values


def _file_stems(names) -> dict[str, str]:
    """A distinct, file-system-safe file stem for every shape name."""
    stems: dict[str, str] = {}
    used: set[str] = set()
    for name in names:
        stem = _UNSAFE_FILE_CHARACTERS.sub("_", name).strip(".") or "shape"
        candidate, number = stem, 1
        while candidate.lower() in used:
            number += 1
            candidate = f"{stem}_{number}"
        used.add(candidate.lower())
        stems[name] = candidate
    return stems


def _check_references(shapes: Mapping, materials: Sequence, bodies: Sequence,
                      walls: Sequence, friction_pairs: Sequence = ()) -> None:
    problems = []
    material_names = [material.name for material in materials]
    for number, pair in enumerate(friction_pairs):
        for name in pair.materials:
            if name not in material_names:
                problems.append(f"friction_pairs[{number}] names material '{name}': no such "
                                f"material; {_suggestion(name, material_names)}materials: "
                                f"{', '.join(material_names)}")
    duplicates = sorted({name for name in material_names if material_names.count(name) > 1})
    if duplicates:
        problems.append(f"materials: names used twice: {', '.join(duplicates)}")
    if not materials:
        problems.append("materials: at least one material is needed")
    if not shapes:
        problems.append("shapes: at least one shape is needed")
    if not bodies:
        problems.append("bodies: at least one body is needed")
    for number, body in enumerate(bodies):
        if not isinstance(body, PackBody):
            problems.append(f"bodies[{number}]: expected a PackBody, got {type(body).__name__}")
            continue
        if body.shape not in shapes:
            problems.append(f"bodies[{number}].shape = '{body.shape}': no such shape; "
                            f"{_suggestion(body.shape, shapes)}shapes: {', '.join(shapes)}")
        if body.material not in material_names:
            problems.append(f"bodies[{number}].material = '{body.material}': no such material; "
                            f"{_suggestion(body.material, material_names)}materials: "
                            f"{', '.join(material_names)}")
    for number, wall in enumerate(walls):
        if wall.material not in material_names:
            problems.append(f"walls[{number}].material = '{wall.material}': no such material; "
                            f"{_suggestion(wall.material, material_names)}materials: "
                            f"{', '.join(material_names)}")
    for name, mesh in shapes.items():
        if not isinstance(name, str) or not name.strip():
            problems.append(f"shapes: name {name!r} must be a non-empty string")
        if not isinstance(mesh, TetMesh):
            problems.append(f"shapes['{name}']: expected a TetMesh (e.g. RigidShape.mesh), got "
                            f"{type(mesh).__name__}")
    if problems:
        shown = problems[:schema.MAXIMUM_REPORTED_PROBLEMS]
        if len(problems) > len(shown):
            shown.append(f"... and {len(problems) - len(shown)} more problem(s) not shown")
        error = CaseFileError("write_pack: " + "\n".join(shown))
        error.problems = tuple(problems)
        raise error


def riprap_version() -> str:
    """The installed riprap's version (from its package metadata: io stands below the package's
    ``__init__`` and does not import it)."""
    try:
        return importlib.metadata.version("riprap")
    except importlib.metadata.PackageNotFoundError:      # run from a source tree, not installed
        return "unknown"


def _header(comment: str, n_bodies: int, n_shapes: int) -> list[str]:
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    lines = [
        f"{PACK_HEADER} {n_bodies} bodies, {n_shapes} shapes; written by riprap "
        f"{riprap_version()} (riprap.io.pack.write_pack) on {now}",
        "# Start a run from it with: riprap run pack.toml",
        "# Each shape's mesh (shapes/*.vtu) is in the body's own frame; a body's orientation",
        "# rotates that mesh into the world and its position is the mesh centroid's place (m).",
    ]
    lines += [f"# {line}".rstrip() for line in comment.splitlines()]
    return lines


def _key_lines(values: Mapping) -> list[str]:
    return [f"{name} = {_toml(value)}" for name, value in values.items()]


def _material_values(material) -> dict:
    """Every ``[[materials]]`` key of the schema, read from the Material's fields."""
    return {entry.name: getattr(material, entry.name) for entry in schema.keys_of("materials")
            if hasattr(material, entry.name)}


def _write_atomically(path: Path, text: str) -> None:
    # A reader never sees half a pack file, and a failed write leaves the old one in place.
    temporary = path.with_name(path.name + ".partial")
    temporary.write_text(text, encoding="utf-8")
    os.replace(temporary, path)


def write_pack(directory: str | os.PathLike, *, shapes: Mapping[str, TetMesh],
               materials: Sequence, bodies: Sequence[PackBody], walls: Sequence = (),
               simulation: Mapping | None = None, output: Mapping | None = None,
               comment: str = "", contact_history=None, friction_pairs: Sequence = ()) -> Path:
    """Save bodies, their shapes and materials, and plane walls as a pack folder.

    Parameters
    ----------
    directory : str or os.PathLike
        Pack folder; created if missing. ``pack.toml`` and ``shapes/<name>.vtu`` in it are
        overwritten.
    shapes : mapping of str to TetMesh
        Shape name to its mesh in the bodies' own frame (pass ``RigidShape.mesh``, the principal
        frame the solver uses, with the solver's quaternions). Each is written once as
        ``shapes/<name>.vtu`` (characters other than letters, digits, ``_ . -`` become ``_``) and
        referenced as a ``type = "mesh_file"`` shape.
    materials : sequence of riprap.solid.materials.Material
        Every field of the ``[[materials]]`` schema is written.
    bodies : sequence of PackBody
        At least one; shape and material names must exist.
    walls : sequence of riprap.solid.walls.Wall
        Written as ``type = "plane"`` walls (a box container comes back as its planes).
    simulation : mapping, optional
        ``[simulation]`` keys; keys not given take :data:`DEFAULT_PACK_SIMULATION`
        (``end_time = 1.0`` s, ``rest_speed = 1e-3`` m/s), then the case-file defaults.
    output : mapping, optional
        ``[output]`` keys; default :data:`DEFAULT_PACK_OUTPUT`.
    comment : str
        Extra lines for the header comment (what the pack is, which design it places).
    contact_history : riprap.io.contact_history.ContactHistory, optional
        The contacts the bodies rest in (spring state and overlap depths); written as
        ``contact_history.csv`` and named by ``[simulation] contact_history``, so that a run from
        the pack starts from them (:mod:`riprap.io.contact_history`).
    friction_pairs : sequence of riprap.solid.materials.FrictionPair
        Friction coefficients of named pairs of materials, written as ``[[friction]]`` entries
        so that a run from the pack keeps them.

    Returns
    -------
    pathlib.Path
        ``directory / "pack.toml"``.

    Raises
    ------
    CaseFileError
        Unknown shape or material names, duplicate material names, no bodies, unknown
        ``[simulation]`` or ``[output]`` keys, non-finite numbers. The written file is not read
        back here: :func:`riprap.workflows.place.write_checked_pack` does that through the case
        parser, naming ``pack.toml`` and its line for any value the schema rejects.
    """
    shapes = dict(shapes)
    materials = list(materials)
    bodies = list(bodies)
    walls = list(walls)
    friction_pairs = list(friction_pairs)
    _check_references(shapes, materials, bodies, walls, friction_pairs)
    simulation_values = _table_keys("simulation", simulation, DEFAULT_PACK_SIMULATION)
    output_values = _table_keys("output", output, DEFAULT_PACK_OUTPUT)

    folder = Path(directory)
    (folder / SHAPES_FOLDER).mkdir(parents=True, exist_ok=True)
    if contact_history is not None:
        write_contact_history(folder / CONTACT_HISTORY_FILE_NAME, contact_history)
        simulation_values["contact_history"] = CONTACT_HISTORY_FILE_NAME
    stems = _file_stems(shapes)
    lines = _header(comment, len(bodies), len(shapes))
    lines += ["", f"format_version = {schema.FORMAT_VERSION}", "", "[simulation]"]
    lines += _key_lines(simulation_values)
    for material in materials:
        lines += ["", "[[materials]]"] + _key_lines(_material_values(material))
    for pair in friction_pairs:
        lines += ["", "[[friction]]"] + _key_lines({
            "materials": list(pair.materials), "friction_coefficient": pair.friction_coefficient})
    for name, mesh in shapes.items():
        relative = f"{SHAPES_FOLDER}/{stems[name]}.vtu"
        write_volume_mesh(folder / relative, mesh)
        lines += ["", "[[shapes]]"] + _key_lines({"name": name, "type": "mesh_file",
                                                  "file": relative})
    for body in bodies:
        lines += ["", "[[bodies]]"] + _key_lines({
            "shape": body.shape, "material": body.material, "position": body.position,
            "orientation": body.orientation, "velocity": body.velocity,
            "angular_velocity": body.angular_velocity, "fixed": body.fixed})
    for wall in walls:
        lines += ["", "[[walls]]"] + _key_lines({"type": "plane", "material": wall.material,
                                                 "point": wall.point, "normal": wall.normal})
    lines += ["", "[output]"] + _key_lines(output_values)
    text = "\n".join(lines) + "\n"

    path = folder / PACK_FILE_NAME
    try:
        _write_atomically(path, text)
    except OSError as error:
        raise CaseFileError(f"{path}: cannot write the pack file: {error.strerror}") from None
    return path
