"""Reading body shapes from mesh files and writing surfaces.

Surface files (.stl, .obj, .ply, .off) are checked with
:func:`~riprap.geometry.surface_checks.check_closed_surface` and filled with tetrahedra by
:func:`~riprap.geometry.meshing.tetrahedralize_surface`; volume files (.msh, .vtu, .vtk, .mesh)
are taken as they are (their 'tetra' cells) and checked with
:meth:`~riprap.geometry.tetmesh.TetMesh.check`. Every failure is a :class:`MeshError` that names
the file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riprap.errors import MeshError
from riprap.geometry.meshing import tetrahedralize_surface
from riprap.geometry.surface_checks import check_closed_surface
from riprap.geometry.tetmesh import TetMesh

SURFACE_SUFFIXES = (".stl", ".obj", ".ply", ".off")
VOLUME_SUFFIXES = (".msh", ".vtu", ".vtk", ".mesh")


def _read_with_meshio(path: Path) -> object:
    import meshio

    if not path.is_file():
        raise MeshError(f"mesh file '{path}' does not exist (looked in {path.resolve().parent})")
    try:
        return meshio.read(path)
    except Exception as error:  # meshio raises several unrelated types for unreadable files
        raise MeshError(f"mesh file '{path}' could not be read by meshio: {error}") from error


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


def _surface_triangles(mesh: object, path: Path) -> np.ndarray:
    blocks = []
    for block in mesh.cells:
        data = np.asarray(block.data, dtype=np.int64)
        if block.type == "triangle":
            blocks.append(data)
        elif block.type == "quad":
            # Split along the 0-2 diagonal; both halves keep the quad's orientation.
            blocks.append(data[:, [0, 1, 2]])
            blocks.append(data[:, [0, 2, 3]])
    if not blocks:
        kinds = sorted({block.type for block in mesh.cells}) or ["none"]
        raise MeshError(
            f"mesh file '{path}' has no triangle or quad faces (cell types: {', '.join(kinds)}); "
            f"export the closed surface of the body"
        )
    return np.concatenate(blocks)


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
        triangles = _surface_triangles(mesh, path)
        vertices, triangles = _merge_coincident_vertices(np.asarray(mesh.points, dtype=np.float64), triangles)
        check_closed_surface(vertices, triangles, name=name)
        return tetrahedralize_surface(vertices, triangles, mesh_size=mesh_size, name=name)
    if suffix in VOLUME_SUFFIXES:
        if mesh_size is not None:
            raise MeshError(
                f"mesh file '{path}' is a volume mesh and is used as it is; mesh_size applies only "
                f"to surface files (.stl, .obj, .ply, .off), leave it out"
            )
        mesh = _read_with_meshio(path)
        blocks = [np.asarray(block.data, dtype=np.int64)[:, :4] for block in mesh.cells if block.type in ("tetra", "tetra10")]
        if not blocks:
            kinds = sorted({block.type for block in mesh.cells}) or ["none"]
            raise MeshError(
                f"mesh file '{path}' has no tetrahedra (cell types: {', '.join(kinds)}); riprap "
                f"needs a tetrahedral volume mesh, or give the closed surface as .stl"
            )
        tets = np.concatenate(blocks)
        points = np.asarray(mesh.points, dtype=np.float64)
        if points.ndim == 2 and points.shape[1] == 2:
            raise MeshError(f"mesh file '{path}' is two-dimensional; riprap needs 3D coordinates")
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
