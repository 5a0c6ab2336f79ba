"""Tetrahedralisation with gmsh, and the mesh-quality measure that sets the contact time step.

gmsh is imported inside the functions that use it (it is a large optional-feeling dependency and
its import is slow). Every gmsh call happens on the main thread inside :func:`_gmsh_session`,
which initialises gmsh only if nobody else has, works in a model of its own, and removes that
model (and finalises gmsh if it initialised it) even when meshing fails.

Mesh size. The default element size is ``nominal_diameter / 3.8`` (the constant
``DEFAULT_DIVISIONS_PER_NOMINAL_DIAMETER``) with ``nominal_diameter = volume ** (1/3)``. Because it
scales with the body, the tetrahedron count does not depend on the body's size: about 300-600
tetrahedra for a rock of moderate elongation (up to ~700 at 2.5 : 1 : 0.5), about 600 for a cube.
A volume-based rule is used rather than a fraction of the bounding-box diagonal because an
elongated or flat body would otherwise get far fewer tetrahedra across its thickness.

Slivers. The contact stiffness of a tetrahedron scales with 1 / (its smallest height), so one
flat tetrahedron on the boundary sets a tiny stable time step for the whole run. Every mesh made
here is optimised by gmsh (its default optimiser and Netgen's); if the minimum signed inverse
condition number (SICN, 1 for a regular tetrahedron, 0 for a flat one) is still below
``OPTIMISE_BELOW_QUALITY``, further optimisation passes run, and a mesh whose minimum stays below
``MIN_ACCEPTED_QUALITY`` is rejected with a :class:`MeshError`. :func:`min_boundary_height` gives
the length the contact time step uses.
"""
from __future__ import annotations

import contextlib
import itertools
import threading
from collections.abc import Callable, Iterator

import numpy as np

from riprap.errors import CaseFileError, MeshError, RiprapError
from riprap.geometry.tetmesh import _OUTWARD_FACES, TetMesh

# Element size = nominal diameter / 3.8 gives ~300-600 tetrahedra for random rocks of elongation
# 1-2.5 (measured over seeds in tests/unit/test_geometry_shapes.py) and ~500 for a cube.
DEFAULT_DIVISIONS_PER_NOMINAL_DIAMETER = 3.8

# Surfaces from files are split into patches where neighbouring triangles meet at more than this
# angle; such edges (box edges, rock ridges) are kept sharp, gentler ones may be smoothed by the
# remeshing (new vertices still lie on the input surface).
DEFAULT_FEATURE_ANGLE_DEG = 40.0

# Minimum SICN that triggers extra optimisation passes. Below ~0.1 a tetrahedron is a sliver whose
# smallest height is a few percent of its edges; gmsh's optimisers usually lift the minimum to 0.3+.
OPTIMISE_BELOW_QUALITY = 0.1

# Minimum SICN accepted after optimisation; lower is rejected with MeshError (gmsh's own
# "very poor quality" warnings start around here).
MIN_ACCEPTED_QUALITY = 0.05

# Sizes riprap accepts for a body, in m, checked before gmsh is called: gmsh/OpenCASCADE crash
# (segfault) or hang on absurd sizes (a sphere of radius 1e308), and nothing riprap models (sand
# grains to caisson-sized units) lies outside this range.
MIN_BODY_LENGTH = 1e-5
MAX_BODY_LENGTH = 1e4
#: Largest coordinate (m) anywhere in a case or mesh file: the earth's radius is 6.4e6 m, and
#: float64 still resolves 1e-9 m at this distance from the origin, well below any contact overlap.
LARGEST_COORDINATE = 1.0e7

# A shape is refused before meshing if its estimated tetrahedron count exceeds this: 2e6
# tetrahedra take minutes and gigabytes in gmsh, and contact on them would be hopeless.
MAX_TETRAHEDRA_PER_SHAPE = 2_000_000

# Estimated tetrahedra per (volume / mesh_size^3): 6 is a lower estimate (a regular tetrahedron
# of edge h has volume h^3 / 8.5; gmsh gives ~11 V / h^3 for a cube, ~5.5 for a sphere).
TETRAHEDRA_PER_CUBED_MESH_SIZE = 6.0

# Feature angles tried after the requested one when gmsh cannot re-parametrise the patches.
_FEATURE_ANGLE_RETRY_OFFSETS_DEG = (0.0, 10.0, -10.0, 20.0, -20.0)

_model_counter = itertools.count()


def default_mesh_size(volume: float) -> float:
    """Default element size for a body of the given volume.

    Parameters
    ----------
    volume : float
        Body volume in m^3.

    Returns
    -------
    float
        ``volume ** (1/3) / DEFAULT_DIVISIONS_PER_NOMINAL_DIAMETER`` in metres.
    """
    return float(abs(volume)) ** (1.0 / 3.0) / DEFAULT_DIVISIONS_PER_NOMINAL_DIAMETER


def boundary_tet_heights(mesh: TetMesh) -> np.ndarray:
    """Smallest centroid-to-face distance of every tetrahedron that owns a boundary face.

    Parameters
    ----------
    mesh : TetMesh

    Returns
    -------
    numpy.ndarray, shape (n_boundary_tets,)
        ``min_k 3 V / (4 A_k)`` in metres for each boundary tetrahedron, where ``A_k`` are its
        face areas and ``V`` its volume (the distance from the centroid to face ``k`` is a quarter
        of the height over that face).
    """
    tet_indices = mesh.boundary_tet_indices()
    tets = mesh.tets[tet_indices]
    volumes = np.abs(mesh.volumes()[tet_indices])
    corners = mesh.nodes[tets[:, _OUTWARD_FACES]]  # (n, 4 faces, 3 nodes, 3)
    normals = np.cross(corners[:, :, 1] - corners[:, :, 0], corners[:, :, 2] - corners[:, :, 0])
    areas = 0.5 * np.linalg.norm(normals, axis=2)
    return (3.0 * volumes[:, None] / (4.0 * areas)).min(axis=1)


def min_boundary_height(mesh: TetMesh) -> float:
    """Smallest distance from a boundary tetrahedron's centroid to one of its faces.

    This is the length that sets the stable time step of Munjiza's potential contact (the
    potential gradient, so the contact stiffness, scales with its inverse).

    Parameters
    ----------
    mesh : TetMesh

    Returns
    -------
    float
        Distance in metres.
    """
    return float(boundary_tet_heights(mesh).min())


@contextlib.contextmanager
def _gmsh_session(name: str) -> Iterator[object]:
    """Yield the gmsh module with a fresh current model; clean up whatever happens."""
    if threading.current_thread() is not threading.main_thread():
        raise RiprapError(
            f"meshing '{name}': gmsh may only be called from the main thread; mesh the shapes "
            f"before starting worker threads"
        )
    import gmsh

    initialised_here = not gmsh.isInitialized()
    if initialised_here:
        # interruptible=False: gmsh must not install its own SIGINT handler inside a library.
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    previous_model = gmsh.model.getCurrent() if not initialised_here else None
    model_name = f"riprap_{next(_model_counter)}"
    saved_options = {}
    try:
        for option, value in (("General.Terminal", 0), ("General.Verbosity", 1)):
            saved_options[option] = gmsh.option.getNumber(option)
            gmsh.option.setNumber(option, value)
        gmsh.model.add(model_name)
        yield gmsh
    finally:
        with contextlib.suppress(Exception):
            gmsh.model.setCurrent(model_name)
            gmsh.model.remove()
        if initialised_here:
            gmsh.finalize()
        else:
            for option, value in saved_options.items():
                gmsh.option.setNumber(option, value)
            if previous_model:
                with contextlib.suppress(Exception):
                    gmsh.model.setCurrent(previous_model)


def _set_size_options(gmsh: object, mesh_size: float) -> None:
    # Only MeshSizeMax controls the size: gmsh would otherwise take sizes from the input points
    # (the spacing of an input triangulation) or refine at curvature.
    gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)


def _generate_and_extract(gmsh: object, name: str) -> TetMesh:
    """Mesh the current model in 3D, optimise slivers away and return the tetrahedra."""
    gmsh.model.mesh.generate(3)
    element_tags, _ = gmsh.model.mesh.getElementsByType(4)
    if len(element_tags) == 0:
        raise MeshError(
            f"meshing '{name}': gmsh produced no tetrahedra; the surface is probably not closed "
            f"or self-intersects (check it with check_closed_surface)"
        )
    quality = gmsh.model.mesh.getElementQualities(element_tags, "minSICN")
    if quality.min() < OPTIMISE_BELOW_QUALITY:
        gmsh.model.mesh.optimize("Netgen")
        gmsh.model.mesh.optimize("")
        element_tags, _ = gmsh.model.mesh.getElementsByType(4)
        quality = gmsh.model.mesh.getElementQualities(element_tags, "minSICN")
    if quality.min() < MIN_ACCEPTED_QUALITY:
        worst = np.argsort(quality)[: min(5, int((quality < MIN_ACCEPTED_QUALITY).sum()))]
        listed = ", ".join(f"{int(element_tags[k])} (SICN {quality[k]:.3f})" for k in worst)
        raise MeshError(
            f"meshing '{name}': {int((quality < MIN_ACCEPTED_QUALITY).sum())} tetrahedra remain "
            f"slivers after optimisation (minimum SICN below {MIN_ACCEPTED_QUALITY}): gmsh "
            f"elements {listed}; use a smaller mesh_size or clean tiny facets from the surface"
        )
    node_tags, coordinates, _ = gmsh.model.mesh.getNodes()
    _, element_nodes = gmsh.model.mesh.getElementsByType(4)
    coordinates = np.asarray(coordinates, dtype=np.float64).reshape(-1, 3)
    node_tags = np.asarray(node_tags, dtype=np.int64)
    element_nodes = np.asarray(element_nodes, dtype=np.int64).reshape(-1, 4)
    used_tags = np.unique(element_nodes)
    lookup = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    lookup[node_tags] = np.arange(len(node_tags))
    nodes = coordinates[lookup[used_tags]]
    compact = np.full(int(used_tags.max()) + 1, -1, dtype=np.int64)
    compact[used_tags] = np.arange(len(used_tags))
    mesh = TetMesh.from_arrays(nodes, compact[element_nodes], name=name, fix_orientation=True)
    mesh.check()
    return mesh


def _check_mesh_size(mesh_size: float, name: str) -> float:
    try:
        mesh_size = float(mesh_size)
    except (TypeError, ValueError):
        raise MeshError(
            f"meshing '{name}': mesh_size must be a length in m (a number), got {mesh_size!r}"
        ) from None
    if not (np.isfinite(mesh_size) and mesh_size > 0.0):
        raise MeshError(f"meshing '{name}': mesh_size must be a positive length in m, got {mesh_size}")
    return mesh_size


def check_body_length(value: object, parameter: str, where: str) -> float:
    """A body size (radius, edge, height, nominal diameter, ...) as a float, checked.

    Parameters
    ----------
    value : float
        The length in m.
    parameter : str
        Its keyword (named in the error).
    where : str
        The shape or function (named in the error).

    Returns
    -------
    float

    Raises
    ------
    CaseFileError
        If ``value`` is not a number, not finite, or outside ``MIN_BODY_LENGTH`` ..
        ``MAX_BODY_LENGTH`` (gmsh would crash or hang on it).
    """
    if isinstance(value, (bool, np.bool_)):
        raise CaseFileError(f"{where}: {parameter} must be a length in m (a number), got {value!r}")
    try:
        length = float(value)
    except (TypeError, ValueError):
        raise CaseFileError(
            f"{where}: {parameter} must be a length in m (a number), got {value!r}"
        ) from None
    if not np.isfinite(length) or length <= 0.0:
        raise CaseFileError(
            f"{where}: {parameter} must be a positive length in m (finite), got {length}"
        )
    if not MIN_BODY_LENGTH <= length <= MAX_BODY_LENGTH:
        raise CaseFileError(
            f"{where}: {parameter} = {length:g} m is outside the sizes riprap meshes "
            f"({MIN_BODY_LENGTH:g} m to {MAX_BODY_LENGTH:g} m); give the size in metres"
        )
    return length


def check_tetrahedron_estimate(volume: float, mesh_size: float, name: str,
                               error: type[RiprapError] = MeshError) -> float:
    """Refuse a mesh_size that would fill ``volume`` with an absurd number of tetrahedra.

    Parameters
    ----------
    volume : float
        Volume of the body in m^3 (its absolute value is used).
    mesh_size : float
        Largest element edge in m.
    name : str
        Shape or file named in the error.
    error : type
        The :class:`RiprapError` subclass raised (``CaseFileError`` for API arguments).

    Returns
    -------
    float
        The estimate ``TETRAHEDRA_PER_CUBED_MESH_SIZE * volume / mesh_size ** 3``.

    Raises
    ------
    RiprapError
        ``error``, with the estimate, when it exceeds ``MAX_TETRAHEDRA_PER_SHAPE``.
    """
    volume = abs(float(volume))
    mesh_size = float(mesh_size)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore", under="ignore"):
        # numpy floats: a mesh_size of 1e308 or 1e-308 gives 0 or inf, not Python's OverflowError
        # or ZeroDivisionError
        estimate = float(TETRAHEDRA_PER_CUBED_MESH_SIZE * np.float64(volume)
                         / np.float64(mesh_size) ** 3)
    if not estimate <= MAX_TETRAHEDRA_PER_SHAPE:
        smallest = (TETRAHEDRA_PER_CUBED_MESH_SIZE * volume
                    / MAX_TETRAHEDRA_PER_SHAPE) ** (1.0 / 3.0)
        raise error(
            f"meshing '{name}': mesh_size = {mesh_size:g} m would make about {estimate:.3g} "
            f"tetrahedra ({TETRAHEDRA_PER_CUBED_MESH_SIZE:g} x volume {volume:.3g} m^3 / "
            f"mesh_size^3), more than riprap's limit of {MAX_TETRAHEDRA_PER_SHAPE:.0e} per shape; "
            f"use mesh_size >= {smallest:.3g} m or leave it out for the default"
        )
    return float(estimate)


def _enclosed_volume(vertices: np.ndarray, triangles: np.ndarray) -> float:
    corners = vertices[triangles] - vertices.mean(axis=0)
    return float(np.einsum("ti,ti->t", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)


def tetrahedralize_surface(
    vertices: np.ndarray,
    triangles: np.ndarray,
    *,
    mesh_size: float | None = None,
    name: str = "surface",
    feature_angle_deg: float = DEFAULT_FEATURE_ANGLE_DEG,
) -> TetMesh:
    """Fill a closed triangle surface with tetrahedra using gmsh.

    The triangles are loaded as a discrete surface, split into patches at edges sharper than
    ``feature_angle_deg`` and re-parametrised, so that the surface is remeshed at ``mesh_size``
    (new vertices lie on the input surface). If gmsh cannot re-parametrise the surface, the input
    triangles are kept as the boundary and only the interior is meshed.

    Parameters
    ----------
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Surface vertex coordinates in metres.
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle of a closed, non-self-intersecting surface (check it with
        :func:`riprap.geometry.surface_checks.check_closed_surface`).
    mesh_size : float, optional
        Largest element edge length in metres. Default: :func:`default_mesh_size` of the enclosed
        volume (nominal diameter / 3.8, giving about 300-600 tetrahedra for a rock).
    name : str
        Name used in error messages and given to the mesh.
    feature_angle_deg : float
        Dihedral angle, in degrees, above which an edge is kept as a sharp feature.

    Returns
    -------
    TetMesh
        Checked mesh, positively oriented, no tetrahedron with SICN below ``MIN_ACCEPTED_QUALITY``.

    Raises
    ------
    MeshError
        If gmsh fails or the result is invalid, or the mesh would have more than
        ``MAX_TETRAHEDRA_PER_SHAPE`` tetrahedra (estimated before meshing), naming ``name``.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    triangles = np.asarray(triangles, dtype=np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or triangles.ndim != 2 or triangles.shape[1] != 3:
        raise MeshError(
            f"meshing '{name}': vertices must have shape (n, 3) and triangles (m, 3), got "
            f"{vertices.shape} and {triangles.shape}"
        )
    if len(triangles) < 4:
        raise MeshError(f"meshing '{name}': need at least 4 triangles, got {len(triangles)}")
    out_of_range = np.flatnonzero(((triangles < 0) | (triangles >= len(vertices))).any(axis=1))
    if out_of_range.size:
        listed = ", ".join(f"{k} {triangles[k].tolist()}" for k in out_of_range[:5])
        raise MeshError(
            f"meshing '{name}': {out_of_range.size} triangles have vertex indices outside "
            f"0..{len(vertices) - 1}: triangles {listed}"
        )
    bad_vertices = np.flatnonzero(~np.isfinite(vertices[np.unique(triangles)]).all(axis=1))
    if bad_vertices.size:
        listed = ", ".join(str(int(np.unique(triangles)[k])) for k in bad_vertices[:5])
        raise MeshError(
            f"meshing '{name}': vertex coordinates must be finite (nan or inf at vertices {listed})"
        )
    volume = _enclosed_volume(vertices, triangles)
    if mesh_size is None:
        mesh_size = default_mesh_size(volume)
    mesh_size = _check_mesh_size(mesh_size, name)
    check_tetrahedron_estimate(volume, mesh_size, name)
    used = np.unique(triangles)
    failures = []
    # gmsh's re-parametrisation sometimes fails on one particular patch layout ("wrong topology of
    # boundary mesh"); a slightly different feature angle changes the patches and usually works.
    for angle in feature_angle_deg + np.array(_FEATURE_ANGLE_RETRY_OFFSETS_DEG):
        if not 0.0 < angle < 180.0:
            continue
        try:
            return _mesh_discrete_surface(vertices, triangles, used, mesh_size, name, angle, True)
        except MeshError:
            raise
        except Exception as error:  # gmsh raises plain Exception with its own message
            failures.append(f"feature angle {angle:g} deg: {error}")
    try:
        return _mesh_discrete_surface(vertices, triangles, used, mesh_size, name, 0.0, False)
    except MeshError:
        raise
    except Exception as error:
        failures.append(f"keeping the input triangles: {error}")
        raise MeshError(
            f"meshing '{name}': gmsh failed ({'; '.join(failures)}); check the surface with "
            f"check_closed_surface"
        ) from error


def _mesh_discrete_surface(
    vertices: np.ndarray,
    triangles: np.ndarray,
    used: np.ndarray,
    mesh_size: float,
    name: str,
    feature_angle_deg: float,
    remesh: bool,
) -> TetMesh:
    with _gmsh_session(name) as gmsh:
        surface = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, surface, used + 1, vertices[used].ravel())
        gmsh.model.mesh.addElementsByType(surface, 2, [], (triangles + 1).ravel())
        if remesh:
            gmsh.model.mesh.classifySurfaces(
                np.deg2rad(feature_angle_deg), True, True, np.pi
            )
            gmsh.model.mesh.createGeometry()
            surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
        else:
            surfaces = [surface]
        loop = gmsh.model.geo.addSurfaceLoop(surfaces)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        _set_size_options(gmsh, mesh_size)
        return _generate_and_extract(gmsh, name)


def mesh_occ_shape(
    build: Callable[[object], None], *, mesh_size: float, name: str
) -> TetMesh:
    """Mesh a solid built with gmsh's OpenCASCADE kernel.

    Parameters
    ----------
    build : callable
        ``build(occ)`` receives ``gmsh.model.occ`` and must leave exactly one solid in the model
        (use ``occ.fuse`` for unions). It is called inside a gmsh session on the main thread.
    mesh_size : float
        Largest element edge length in metres.
    name : str
        Name of the mesh, used in error messages.

    Returns
    -------
    TetMesh
        Checked, optimised mesh.

    Raises
    ------
    MeshError
        If the build leaves no or several solids, the mesh would have more than
        ``MAX_TETRAHEDRA_PER_SHAPE`` tetrahedra (estimated before meshing), or gmsh fails.
    """
    mesh_size = _check_mesh_size(mesh_size, name)
    with _gmsh_session(name) as gmsh:
        try:
            build(gmsh.model.occ)
            gmsh.model.occ.removeAllDuplicates()
            gmsh.model.occ.synchronize()
        except Exception as error:
            raise MeshError(f"building shape '{name}' with gmsh/OpenCASCADE failed: {error}") from error
        volumes = gmsh.model.getEntities(3)
        if len(volumes) != 1:
            raise MeshError(
                f"building shape '{name}' left {len(volumes)} solids instead of one; fuse the parts "
                f"with occ.fuse"
            )
        check_tetrahedron_estimate(gmsh.model.occ.getMass(*volumes[0]), mesh_size, name)
        _set_size_options(gmsh, mesh_size)
        try:
            return _generate_and_extract(gmsh, name)
        except MeshError:
            raise
        except Exception as error:
            raise MeshError(f"meshing shape '{name}' with gmsh failed: {error}") from error
