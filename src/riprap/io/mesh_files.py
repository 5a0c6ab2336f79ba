"""Reading body shapes from mesh files and writing surfaces.

Surface files (.stl, .obj, .ply, .off) are checked with
:func:`~riprap.geometry.surface_checks.check_closed_surface` and filled with tetrahedra by
:func:`~riprap.geometry.meshing.tetrahedralize_surface`; volume files (.msh, .vtu, .vtk, .mesh)
are taken as they are (their 'tetra' cells) and checked with
:meth:`~riprap.geometry.tetmesh.TetMesh.check`. Every failure is a :class:`MeshError` that names
the file.
"""
from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

from riprap.errors import MeshError
from riprap.geometry.meshing import (LARGEST_COORDINATE, MAX_BODY_LENGTH, MIN_BODY_LENGTH,
                                      tetrahedralize_surface)
from riprap.geometry.surface_checks import check_closed_surface
from riprap.geometry.tetmesh import TetMesh

SURFACE_SUFFIXES = (".stl", ".obj", ".ply", ".off")
VOLUME_SUFFIXES = (".msh", ".vtu", ".vtk", ".mesh")

# How many bad faces, tetrahedra or vertices an error message lists before "and N more".
_MAX_LISTED = 5


def _read_with_meshio(path: Path) -> object:
    """``meshio.read(path)``; every failure, including meshio's ``sys.exit(1)`` on files it cannot
    parse (empty or truncated .vtu/.ply), becomes a :class:`MeshError` naming the file."""
    import meshio

    if path.is_dir():
        raise MeshError(f"mesh file '{path}' is a folder; give the mesh file itself")
    if not path.is_file():
        raise MeshError(f"mesh file '{path}' does not exist (looked in {path.resolve().parent})")
    try:
        size = path.stat().st_size
    except OSError as error:
        raise MeshError(f"mesh file '{path}' cannot be read: {error.strerror}") from None
    if size == 0:
        raise MeshError(f"mesh file '{path}' is empty (0 bytes); export or copy the mesh again")
    # meshio prints why a reader failed, then calls sys.exit(1); keep what it says for the message.
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            mesh = meshio.read(path)
    except (Exception, SystemExit) as error:
        # meshio raises several unrelated types (and SystemExit) for unreadable files
        detail = " ".join(said.getvalue().split())
        if not isinstance(error, SystemExit):
            detail = f"{type(error).__name__}: {error}" + (f" ({detail})" if detail else "")
        raise MeshError(
            f"mesh file '{path}' could not be read by meshio ({detail or 'no reason given'}); the "
            f"file is probably truncated, corrupt or not a {path.suffix} file, export it again"
        ) from None
    return mesh


def _mesh_points(mesh: object, path: Path) -> np.ndarray:
    try:
        points = np.asarray(mesh.points, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise MeshError(
            f"mesh file '{path}': its point coordinates are not numbers ({error})"
        ) from None
    if points.ndim != 2 or len(points) == 0:
        raise MeshError(f"mesh file '{path}' has no points; export the mesh again")
    if points.shape[1] != 3:
        raise MeshError(
            f"mesh file '{path}' has {points.shape[1]}-dimensional points; riprap needs 3D "
            f"coordinates (x, y, z) in m"
        )
    return points


def _check_indices(cells: np.ndarray, n_points: int, first_cell: int, what: tuple[str, str],
                   path: Path, one_based: bool) -> None:
    """Refuse cells (faces or tetrahedra) whose vertex indices are not vertices of the file."""
    bad = np.flatnonzero(((cells < 0) | (cells >= n_points)).any(axis=1))
    if not bad.size:
        return
    offset = 1 if one_based else 0
    listed = []
    for k in bad[:_MAX_LISTED]:
        index = int(cells[k][(cells[k] < 0) | (cells[k] >= n_points)][0]) + offset
        listed.append(f"{what[0]} {first_cell + k + offset} (vertex {index})")
    more = f" and {bad.size - _MAX_LISTED} more" if bad.size > _MAX_LISTED else ""
    numbering = (f"numbered 1..{n_points}; relative (negative) indices are not read"
                 if one_based else f"numbered 0..{n_points - 1}")
    raise MeshError(
        f"mesh file '{path}': vertex indices out of range in {bad.size} "
        f"{what[0] if bad.size == 1 else what[1]}: {', '.join(listed)}{more}; the file has "
        f"{n_points} vertices ({numbering}); it is corrupt or was written with another "
        f"numbering, export it again"
    )


# A mesh file may be in another unit than metres (a shape's scale converts it): its sizes are
# checked against riprap's body sizes widened by this factor, the scaled body against them exactly.
_FILE_UNITS = 1.0e3


def _check_finite_points(points: np.ndarray, used: np.ndarray, path: Path, one_based: bool) -> None:
    _check_finite(points, used, path, one_based)
    # Sizes and places the numerics can carry: a body 1e300 m across overflows its inertia, one
    # 1e-300 m across or 1e300 m from the origin has tetrahedra of no volume in float64. The file
    # may be in millimetres (a shape's scale converts it), hence the factor.
    corners = points[used]
    farthest = float(np.abs(corners).max(initial=0.0))
    if farthest > _FILE_UNITS * LARGEST_COORDINATE:
        raise MeshError(f"mesh file '{path}': a vertex lies {farthest:.3g} from the origin, beyond "
                        f"{_FILE_UNITS * LARGEST_COORDINATE:g} (even in millimetres); move the body "
                        "near the origin (bodies are placed by their centroid)")
    extent = float(np.ptp(corners, axis=0).max()) if len(corners) else 0.0
    if not MIN_BODY_LENGTH / _FILE_UNITS <= extent <= MAX_BODY_LENGTH * _FILE_UNITS:
        raise MeshError(f"mesh file '{path}': the body is {extent:.3g} across, outside the sizes "
                        f"riprap meshes ({MIN_BODY_LENGTH:g} m to {MAX_BODY_LENGTH:g} m, in any "
                        "unit a shape's scale converts from); write the file in metres")


def _check_finite(points: np.ndarray, used: np.ndarray, path: Path, one_based: bool) -> None:
    bad = used[~np.isfinite(points[used]).all(axis=1)]
    if bad.size:
        offset = 1 if one_based else 0
        listed = [f"{int(i) + offset} {points[i].tolist()}" for i in bad[:_MAX_LISTED]]
        more = f" and {bad.size - _MAX_LISTED} more" if bad.size > _MAX_LISTED else ""
        raise MeshError(
            f"mesh file '{path}': non-finite coordinates (nan or inf) at {bad.size} "
            f"{'vertex' if bad.size == 1 else 'vertices'}: {', '.join(listed)}{more}; fix the file "
            f"or the program that wrote it"
        )


def _merge_coincident_vertices(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices with identical coordinates and drop unused ones.

    STL files store every triangle's corners separately; without merging, every edge would look
    open.
    """
    used = np.unique(triangles)
    unique_points, inverse = np.unique(points[used], axis=0, return_inverse=True)
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[used] = inverse.reshape(-1)
    return unique_points, renumber[triangles]


def _cell_indices(data: np.ndarray, path: Path, what: str) -> np.ndarray:
    """A cell block's index array as int64 rows; float or text indices are refused."""
    if data.size and not np.issubdtype(data.dtype, np.integer):
        raise MeshError(f"mesh file '{path}': {what} indices are not integers")
    return data.astype(np.int64).reshape(len(data), -1)


def _joined(blocks: list[np.ndarray], mesh: object, path: Path, wanted: str, hint: str) -> np.ndarray:
    """The blocks stacked; none, or all empty, is refused naming the cell types the file has."""
    if sum(len(block) for block in blocks) == 0:
        kinds = sorted({block.type for block in mesh.cells}) or ["none"]
        raise MeshError(f"mesh file '{path}' has no {wanted} (cell types: {', '.join(kinds)}); {hint}")
    return np.concatenate(blocks)


def _surface_triangles(mesh: object, path: Path, n_points: int) -> np.ndarray:
    """Triangles of a surface file, quads split; faces are numbered in file order in errors."""
    one_based = path.suffix.lower() == ".obj"
    blocks = []
    first_face = 0
    for block in mesh.cells:
        data = np.asarray(block.data)
        if block.type in ("vertex", "line"):
            continue
        if block.type not in ("triangle", "quad"):
            corners = f"{data.shape[1]} corners" if data.ndim == 2 else "several corners"
            raise MeshError(
                f"mesh file '{path}' has {len(data)} faces of type '{block.type}' ({corners}), "
                f"from face {first_face + int(one_based)} on; riprap reads triangle and quad faces "
                f"only, triangulate the surface when exporting"
            )
        data = _cell_indices(data, path, "face vertex")
        _check_indices(data, n_points, first_face, ("face", "faces"), path, one_based)
        first_face += len(data)
        if block.type == "triangle":
            blocks.append(data)
        else:
            # Split along the 0-2 diagonal; both halves keep the quad's orientation.
            blocks.append(data[:, [0, 1, 2]])
            blocks.append(data[:, [0, 2, 3]])
    return _joined(blocks, mesh, path, "triangle or quad faces",
                   "export the closed surface of the body")


# Volume cells riprap cannot use: taking only the tetrahedra of a file that also has these would
# silently drop part of the body.
_OTHER_VOLUME_CELL_PREFIXES = ("hexahedron", "wedge", "pyramid", "polyhedron")


def _is_tetra(cell_type: str) -> bool:
    """'tetra' and the higher-order Lagrange tetrahedra ('tetra10', 'tetra20', ...), whose first
    four nodes are the corners."""
    return cell_type == "tetra" or (cell_type.startswith("tetra") and cell_type[5:].isdigit())


def _volume_tets(mesh: object, path: Path, n_points: int) -> np.ndarray:
    """Tetrahedra of a volume file (corner nodes of quadratic ones), tetrahedra numbered in file
    order in errors."""
    others = sorted({block.type for block in mesh.cells
                     if block.type.startswith(_OTHER_VOLUME_CELL_PREFIXES)})
    if others:
        raise MeshError(
            f"mesh file '{path}' has volume cells of type {', '.join(others)}; riprap needs a mesh "
            f"of tetrahedra only (taking the tetrahedra alone would drop part of the body), "
            f"remesh it with tetrahedra"
        )
    blocks = []
    for block in mesh.cells:
        if not _is_tetra(block.type):
            continue
        data = _cell_indices(np.asarray(block.data), path, "tetrahedron node")[:, :4]
        _check_indices(data, n_points, sum(len(b) for b in blocks), ("tetrahedron", "tetrahedra"),
                       path, False)
        blocks.append(data)
    return _joined(blocks, mesh, path, "tetrahedra", "riprap needs a tetrahedral volume mesh, "
                   "or give the closed surface as .stl")


def read_mesh(path: str | Path, *, mesh_size: float | None = None) -> TetMesh:
    """Read a body from a surface or volume mesh file.

    Parameters
    ----------
    path : str or pathlib.Path
        A surface (.stl, .obj, .ply, .off) that is the closed boundary of one solid, or a
        tetrahedral volume mesh (.msh, .vtu, .vtk, .mesh). Coordinates in metres.
    mesh_size : float, optional
        Largest element edge in metres when a surface is tetrahedralised; default as
        :func:`~riprap.geometry.meshing.tetrahedralize_surface`. Not allowed for volume meshes,
        which are used as they are.

    Returns
    -------
    TetMesh
        Checked mesh named after the file.

    Raises
    ------
    MeshError
        Naming the file: unreadable, unsupported suffix, open/inward/self-intersecting surface,
        no tetrahedra, inverted or degenerate tetrahedra.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    name = str(path)
    if suffix in SURFACE_SUFFIXES:
        mesh = _read_with_meshio(path)
        points = _mesh_points(mesh, path)
        triangles = _surface_triangles(mesh, path, len(points))
        _check_finite_points(points, np.unique(triangles), path, suffix == ".obj")
        vertices, triangles = _merge_coincident_vertices(points, triangles)
        check_closed_surface(vertices, triangles, name=name)
        return tetrahedralize_surface(vertices, triangles, mesh_size=mesh_size, name=name)
    if suffix in VOLUME_SUFFIXES:
        if mesh_size is not None:
            raise MeshError(
                f"mesh file '{path}' is a volume mesh and is used as it is; mesh_size applies only "
                f"to surface files (.stl, .obj, .ply, .off), leave it out"
            )
        mesh = _read_with_meshio(path)
        points = _mesh_points(mesh, path)
        tets = _volume_tets(mesh, path, len(points))
        _check_finite_points(points, np.unique(tets), path, False)
        body = TetMesh.from_arrays(points, tets, name=name, fix_orientation=False)
        body.check()
        return body
    raise MeshError(
        f"mesh file '{path}' has an unsupported suffix '{path.suffix}'; use a surface "
        f"({', '.join(SURFACE_SUFFIXES)}) or a tetrahedral volume mesh ({', '.join(VOLUME_SUFFIXES)})"
    )


def write_surface_stl(path: str | Path, vertices: np.ndarray, triangles: np.ndarray) -> None:
    """Write a triangle surface as a binary STL file.

    Parameters
    ----------
    path : str or pathlib.Path
        Output file; parent folders must exist.
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Vertex coordinates in metres (stored as float32, as STL requires).
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle, ordered so that normals point outward.
    """
    import meshio

    vertices = np.asarray(vertices, dtype=np.float64)
    triangles = np.asarray(triangles, dtype=np.int64)
    meshio.write_points_cells(Path(path), vertices, [("triangle", triangles)], file_format="stl", binary=True)


def write_volume_mesh(path: str | Path, mesh: TetMesh) -> None:
    """Write a tetrahedral mesh in a format meshio knows from the suffix (.vtu, .msh, ...).

    Parameters
    ----------
    path : str or pathlib.Path
        Output file; parent folders must exist.
    mesh : TetMesh
        Mesh to write (nodes in metres).
    """
    import meshio

    meshio.write_points_cells(Path(path), np.asarray(mesh.nodes), [("tetra", np.asarray(mesh.tets))])
