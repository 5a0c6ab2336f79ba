"""Built-in body shapes as tetrahedral meshes.

Every function returns a checked :class:`~riprap.geometry.tetmesh.TetMesh` in the shape's own
frame (described in each docstring), with lengths in metres. The default ``mesh_size`` follows
:func:`~riprap.geometry.meshing.default_mesh_size` (nominal diameter / 3.8), capped where a shape
has a thin part so that there are always elements across it; built-in shapes get roughly 200-1500
tetrahedra at the default and no slivers (every tetrahedron has gmsh SICN >= 0.05).

Sizes are checked before gmsh is called (gmsh crashes on absurd ones): every body length must be
finite and within ``MIN_BODY_LENGTH`` .. ``MAX_BODY_LENGTH`` (1e-5 m .. 1e4 m), and a
``mesh_size`` whose estimated tetrahedron count (``6 volume / mesh_size^3``) exceeds
``MAX_TETRAHEDRA_PER_SHAPE`` (2e6) is refused with the estimate
(:mod:`riprap.geometry.meshing`); each error is a :class:`CaseFileError` naming the keyword.
"""
from __future__ import annotations

import numpy as np

from riprap.errors import CaseFileError
from riprap.geometry.meshing import (
    check_body_length,
    check_tetrahedron_estimate,
    default_mesh_size,
    mesh_occ_shape,
    tetrahedralize_surface,
)
from riprap.geometry.tetmesh import TetMesh
from riprap.schema import default_of

# Sphere element size as a fraction of the radius. The generic rule (nominal diameter / 3.8 =
# 0.42 r) would lose about 6 % of the volume to the inscribed polyhedral surface; 0.3 r keeps the
# loss near 3 % at ~850 tetrahedra.
_SPHERE_MESH_SIZE_PER_RADIUS = 0.3

# Random rocks: relative jitter of the sample radii (points lie within +-10 % of the ellipsoid,
# giving flat facets and ridges rather than a smooth ellipsoid) and the minimum angular spacing of
# the sample directions as a fraction of the mean spacing sqrt(4 pi / n) (no two hull vertices
# nearly coincide, so the hull has no tiny facets that would force tiny elements).
_ROCK_RADIAL_JITTER = 0.10
_ROCK_MIN_SPACING_FRACTION = 0.6

# Tetrapod proportions (riprap's own choice, see tetrapod()).
_TETRAPOD_TIP_TO_BASE_DIAMETER = 0.6
_TETRAPOD_DEFAULT_LEG_DIAMETER_RATIO = 0.4
_TETRAPOD_CONE_SETBACK = 0.25  # fraction of the base radius


# Random rocks: most hull points accepted (24 is the default; thousands of points only make tiny
# hull facets that gmsh remeshes away, and the spacing search would run for hours at 1e8).
_ROCK_MAX_VERTICES = 2000

# Random rocks: axis ratios (elongation, flatness) beyond these make needles or sheets that no
# mesh size resolves.
_ROCK_MIN_AXIS_RATIO = 0.01
_ROCK_MAX_AXIS_RATIO = 100.0


def _positive(value: float, parameter: str, shape: str) -> float:
    """A body length, finite and within ``MIN_BODY_LENGTH`` .. ``MAX_BODY_LENGTH`` m."""
    return check_body_length(value, parameter, shape)


def _number(value: object, parameter: str, shape: str) -> float:
    if isinstance(value, (bool, np.bool_)):
        raise CaseFileError(f"{shape}: {parameter} must be a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise CaseFileError(f"{shape}: {parameter} must be a number, got {value!r}") from None


def _axis_ratio(value: object, parameter: str, shape: str) -> float:
    ratio = _number(value, parameter, shape)
    if not _ROCK_MIN_AXIS_RATIO <= ratio <= _ROCK_MAX_AXIS_RATIO:
        raise CaseFileError(
            f"{shape}: {parameter} = {ratio:g} is outside {_ROCK_MIN_AXIS_RATIO:g} .. "
            f"{_ROCK_MAX_AXIS_RATIO:g} (a ratio of the rock's semi-axes)"
        )
    return ratio


def _mesh_size(mesh_size: object, default: float, volume: float, shape: str) -> float:
    """The element size (given, or ``default``), refused when not a positive length or when the
    body of ``volume`` m^3 would get more than ``MAX_TETRAHEDRA_PER_SHAPE`` tetrahedra."""
    if mesh_size is None:
        mesh_size = default
    else:
        mesh_size = _number(mesh_size, "mesh_size", shape)
        if not (np.isfinite(mesh_size) and mesh_size > 0.0):
            raise CaseFileError(f"{shape}: mesh_size must be a positive length in m, got {mesh_size}")
    check_tetrahedron_estimate(volume, mesh_size, shape, error=CaseFileError)
    return float(mesh_size)


def sphere(*, radius: float, mesh_size: float | None = None) -> TetMesh:
    """A sphere centred at the origin.

    Parameters
    ----------
    radius : float
        Radius in metres.
    mesh_size : float, optional
        Largest element edge in metres; default ``0.3 * radius`` (about 850 tetrahedra, volume
        about 3 % below the exact sphere because the surface is a polyhedron inscribed in it).

    Returns
    -------
    TetMesh
    """
    radius = _positive(radius, "radius", "sphere")
    name = f"sphere(radius={radius:g})"
    mesh_size = _mesh_size(mesh_size, _SPHERE_MESH_SIZE_PER_RADIUS * radius,
                           4.0 / 3.0 * np.pi * radius**3, name)
    return mesh_occ_shape(
        lambda occ: occ.addSphere(0.0, 0.0, 0.0, radius), mesh_size=mesh_size, name=name
    )


def box(*, lengths: tuple[float, float, float], mesh_size: float | None = None) -> TetMesh:
    """A rectangular box centred at the origin, edges along the axes.

    Parameters
    ----------
    lengths : tuple of 3 float
        Edge lengths along x, y, z in metres.
    mesh_size : float, optional
        Largest element edge in metres; default nominal diameter / 3.8, but no more than the
        shortest edge.

    Returns
    -------
    TetMesh
    """
    if isinstance(lengths, (str, bytes)) or not hasattr(lengths, "__len__") or len(lengths) != 3:
        raise CaseFileError(f"box: lengths must be three edge lengths (x, y, z) in m, got {lengths!r}")
    lx, ly, lz = (_positive(length, "lengths", "box") for length in lengths)
    return _box(lx, ly, lz, mesh_size, f"box(lengths=({lx:g}, {ly:g}, {lz:g}))")


def _box(lx: float, ly: float, lz: float, mesh_size: float | None, name: str) -> TetMesh:
    mesh_size = _mesh_size(mesh_size, min(default_mesh_size(lx * ly * lz), lx, ly, lz),
                           lx * ly * lz, name)
    return mesh_occ_shape(
        lambda occ: occ.addBox(-lx / 2, -ly / 2, -lz / 2, lx, ly, lz), mesh_size=mesh_size, name=name
    )


def cube(*, side: float, mesh_size: float | None = None) -> TetMesh:
    """A cube centred at the origin, edges along the axes.

    Parameters
    ----------
    side : float
        Edge length in metres.
    mesh_size : float, optional
        Largest element edge in metres; default ``side / 3.8`` (about 600 tetrahedra).

    Returns
    -------
    TetMesh
    """
    side = _positive(side, "side", "cube")
    return _box(side, side, side, mesh_size, f"cube(side={side:g})")


def _spaced_directions(rng: np.random.Generator, count: int) -> np.ndarray:
    """``count`` random unit vectors, no two closer than a fraction of the mean spacing."""
    min_angle = _ROCK_MIN_SPACING_FRACTION * np.sqrt(4.0 * np.pi / count)
    min_dot = np.cos(min_angle)
    accepted = np.empty((count, 3))
    n_accepted = 0
    # Random sequential adsorption at this spacing covers ~30 % of the sphere, far below its
    # jamming limit, so a few candidates per point suffice; the bound only guards against a loop.
    for _ in range(1000 * count):
        candidate = rng.normal(size=3)
        candidate /= np.linalg.norm(candidate)
        if n_accepted == 0 or (accepted[:n_accepted] @ candidate).max() < min_dot:
            accepted[n_accepted] = candidate
            n_accepted += 1
            if n_accepted == count:
                break
    return accepted[:n_accepted]


def _hull_surface(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Convex hull as (vertices, outward triangles), unused points dropped."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    triangles = hull.simplices.astype(np.int64)
    corners = points[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    inward = np.einsum("ti,ti->t", normals, hull.equations[:, :3]) < 0.0
    triangles[inward] = triangles[inward][:, [0, 2, 1]]
    used = np.unique(triangles)
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[used] = np.arange(len(used))
    return points[used], renumber[triangles]


def _surface_volume_and_centroid(vertices: np.ndarray, triangles: np.ndarray) -> tuple[float, np.ndarray]:
    corners = vertices[triangles]
    volumes = np.einsum("ti,ti->t", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) / 6.0
    volume = float(volumes.sum())
    centroid = (volumes[:, None] * corners.sum(axis=1)).sum(axis=0) / (4.0 * volume)
    return volume, centroid


def random_rock(
    *,
    size: float,
    elongation: float = default_of("shapes", "elongation"),
    flatness: float = default_of("shapes", "flatness"),
    seed: int = default_of("shapes", "seed"),
    n_vertices: int = default_of("shapes", "n_vertices"),
    mesh_size: float | None = None,
) -> TetMesh:
    """A random convex rock: the convex hull of points near an ellipsoid.

    ``n_vertices`` directions are drawn with a minimum angular spacing (0.6 x the mean spacing
    ``sqrt(4 pi / n_vertices)``, so no tiny hull facets), placed at radius ``1 +- 10 %`` on an
    ellipsoid with semi-axes proportional to ``(elongation, 1, flatness)`` along (x, y, z), and
    the hull is scaled so that its nominal diameter ``volume ** (1/3)`` equals ``size`` exactly.
    The rock's frame has the hull centroid at the origin; the ellipsoid axes are the frame axes
    (close to, but not exactly, the principal axes). The hull is remeshed with gmsh, whose
    vertices lie on the hull, so the mesh volume is 0-3 % below ``size ** 3`` (ridges gentler than
    the 40 degree feature angle are cut slightly by the new surface triangles).

    Parameters
    ----------
    size : float
        Nominal diameter (volume ** (1/3)) in metres.
    elongation : float
        Ratio of the x semi-axis to the y semi-axis (>= 1 for elongated rocks).
    flatness : float
        Ratio of the z semi-axis to the y semi-axis (<= 1 for flat rocks).
    seed : int
        Seed of ``numpy.random.default_rng``; the same arguments give the same mesh.
    n_vertices : int
        Number of sampled points (at least 8); about as many hull vertices.
    mesh_size : float, optional
        Largest element edge in metres; default ``size / 3.8`` (about 300-600 tetrahedra for
        elongation up to ~1.5, up to ~700 for elongation 2.5 and flatness 0.5).

    Returns
    -------
    TetMesh
    """
    size = _positive(size, "size", "random_rock")
    elongation = _axis_ratio(elongation, "elongation", "random_rock")
    flatness = _axis_ratio(flatness, "flatness", "random_rock")
    vertex_count = _number(n_vertices, "n_vertices", "random_rock")
    if not (np.isfinite(vertex_count) and vertex_count == int(vertex_count) and vertex_count >= 8):
        raise CaseFileError(f"random_rock: n_vertices must be an integer >= 8, got {n_vertices}")
    if vertex_count > _ROCK_MAX_VERTICES:
        raise CaseFileError(
            f"random_rock: n_vertices = {vertex_count:g} is more than {_ROCK_MAX_VERTICES} hull "
            f"points; a rock needs a few dozen (default 24)"
        )
    n_vertices = int(vertex_count)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise CaseFileError(f"random_rock: seed must be a non-negative integer, got {seed!r}")
    seed = int(seed)
    name = (f"random_rock(size={size:g}, elongation={elongation:g}, flatness={flatness:g}, "
            f"seed={seed})")
    mesh_size = _mesh_size(mesh_size, default_mesh_size(size**3), size**3, name)
    rng = np.random.default_rng(seed)
    directions = _spaced_directions(rng, int(n_vertices))
    radii = 1.0 + rng.uniform(-_ROCK_RADIAL_JITTER, _ROCK_RADIAL_JITTER, size=len(directions))
    points = directions * radii[:, None] * np.array([elongation, 1.0, flatness])
    vertices, triangles = _hull_surface(points)
    volume, centroid = _surface_volume_and_centroid(vertices, triangles)
    vertices = (vertices - centroid) * (size / volume ** (1.0 / 3.0))
    return tetrahedralize_surface(vertices, triangles, mesh_size=mesh_size, name=name)


def tetrapod(
    *,
    height: float,
    leg_diameter_ratio: float = _TETRAPOD_DEFAULT_LEG_DIAMETER_RATIO,
    mesh_size: float | None = None,
) -> TetMesh:
    """A tetrapod-like armour unit: four tapered legs from a common centre.

    This is an approximation of the Tetrapod armour unit (a registered trademark), not its
    design drawing. The proportions are riprap's own choice, stated here:

    - the legs are truncated cones along the directions of a regular tetrahedron from the
      centre (origin), one leg along +z;
    - the leg diameter at the centre is ``leg_diameter_ratio * height`` (default 0.4) and at the
      flat tip 0.6 times that;
    - the leg axis length ``L`` (centre to tip centre) is chosen so that the unit standing on
      three legs is exactly ``height`` tall: ``height = 4 L / 3 + r_tip 2 sqrt(2) / 3``, the top
      at ``z = L`` and the lowest tip rim at ``z = L - height``.

    Resulting volumes: about 0.17 height^3 at the default ratio (0.40 of its convex hull), from
    0.026 height^3 at ratio 0.15 to 0.25 height^3 at ratio 0.5. Above 0.5 the buried cone ends
    would break through the surface, so the ratio is limited to 0.15-0.5. The real unit has a
    bulkier centre; match its mass by choosing ``height`` or ``leg_diameter_ratio``.

    The legs are fused with OpenCASCADE (gmsh), so the body is one non-convex solid.

    Parameters
    ----------
    height : float
        Height of the unit standing on three legs, in metres.
    leg_diameter_ratio : float
        Leg diameter at the centre divided by ``height`` (0.15-0.5).
    mesh_size : float, optional
        Largest element edge in metres; default nominal diameter / 3.8, but no more than the
        tip diameter so that the legs are resolved.

    Returns
    -------
    TetMesh
    """
    height = _positive(height, "height", "tetrapod")
    leg_diameter_ratio = _number(leg_diameter_ratio, "leg_diameter_ratio", "tetrapod")
    if not 0.15 <= leg_diameter_ratio <= 0.5:
        raise CaseFileError(
            f"tetrapod: leg_diameter_ratio must lie in 0.15..0.5 (leg diameter at the centre / "
            f"height), got {leg_diameter_ratio}"
        )
    base_radius = 0.5 * leg_diameter_ratio * height
    tip_radius = _TETRAPOD_TIP_TO_BASE_DIAMETER * base_radius
    leg_length = 0.75 * (height - tip_radius * 2.0 * np.sqrt(2.0) / 3.0)
    polar = np.arccos(-1.0 / 3.0)
    directions = [np.array([0.0, 0.0, 1.0])] + [
        np.array([np.sin(polar) * np.cos(a), np.sin(polar) * np.sin(a), np.cos(polar)])
        for a in (0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0)
    ]
    name = f"tetrapod(height={height:g}, leg_diameter_ratio={leg_diameter_ratio:g})"
    leg_volume = np.pi * leg_length / 3.0 * (base_radius**2 + base_radius * tip_radius + tip_radius**2)
    mesh_size = _mesh_size(mesh_size, min(default_mesh_size(4.0 * leg_volume), 2.0 * tip_radius),
                           4.0 * leg_volume, name)

    # The cones start a little behind the centre, widened to keep the radius at the centre, so
    # that their four base discs do not all pass through one point (OpenCASCADE's union fails on
    # that configuration for some radii). The discs stay buried inside the other legs.
    setback = _TETRAPOD_CONE_SETBACK * base_radius
    start_radius = base_radius + (base_radius - tip_radius) * setback / leg_length

    def build(occ: object) -> None:
        legs = [
            (3, occ.addCone(*(-setback * d), *((leg_length + setback) * d), start_radius, tip_radius))
            for d in directions
        ]
        occ.fuse(legs[:1], legs[1:])

    return mesh_occ_shape(build, mesh_size=mesh_size, name=name)


def l_shape(
    *, length: float, width: float, thickness: float, mesh_size: float | None = None
) -> TetMesh:
    """An L-shaped plate: two boxes fused at a right angle (non-convex).

    One arm spans ``[0, length] x [0, width]`` and the other ``[0, width] x [0, length]`` in the
    x-y plane, both ``thickness`` thick in z; the whole is then shifted so that its bounding box
    ``length x length x thickness`` is centred at the origin.

    Parameters
    ----------
    length : float
        Outer length of each arm in metres.
    width : float
        Width of each arm in metres (less than ``length``).
    thickness : float
        Thickness in z in metres.
    mesh_size : float, optional
        Largest element edge in metres; default nominal diameter / 3.8, but no more than the
        width or the thickness.

    Returns
    -------
    TetMesh
    """
    length = _positive(length, "length", "l_shape")
    width = _positive(width, "width", "l_shape")
    thickness = _positive(thickness, "thickness", "l_shape")
    if width >= length:
        raise CaseFileError(f"l_shape: width ({width:g} m) must be less than length ({length:g} m)")
    name = f"l_shape(length={length:g}, width={width:g}, thickness={thickness:g})"
    volume = (2.0 * length - width) * width * thickness
    mesh_size = _mesh_size(mesh_size, min(default_mesh_size(volume), width, thickness), volume, name)
    x0, y0, z0 = -length / 2, -length / 2, -thickness / 2

    def build(occ: object) -> None:
        first = occ.addBox(x0, y0, z0, length, width, thickness)
        second = occ.addBox(x0, y0, z0, width, length, thickness)
        occ.fuse([(3, first)], [(3, second)])

    return mesh_occ_shape(build, mesh_size=mesh_size, name=name)
