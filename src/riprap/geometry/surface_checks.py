"""Checks that a triangle surface is the closed, outward-oriented boundary of one solid.

A surface read from an STL/OBJ/PLY file must pass :func:`check_closed_surface` before it is
filled with tetrahedra: an open, folded or self-intersecting surface gives gmsh an ill-defined
inside and the resulting body would have a wrong mass or overlapping elements.

The self-intersection test is a sweep-and-prune broad phase (triangles sorted by their lower
bound along the longest axis of the surface, then bounding-box overlap on the other two axes)
followed by an exact-sign triangle-triangle test built from orientation determinants: two
triangles that are not coplanar intersect if and only if an edge of one meets the other, and
coplanar triangles are tested in 2D. Triangles that share a vertex are neighbours and are not
tested (their contact at the shared vertex is legitimate). Both phases are numba kernels.
"""
from __future__ import annotations

import numpy as np

from riprap._jit import kernel
from riprap.errors import MeshError

# A triangle with area below this fraction of (bounding-box diagonal)^2 is degenerate; no tool
# makes such a triangle on purpose and its normal is meaningless.
DEGENERATE_AREA_FRACTION = 1e-12

_MAX_LISTED = 5


@kernel
def _orient3d(vertices, a, b, c, d):
    """Six times the signed volume of tetrahedron (a, b, c, d), vertex indices into ``vertices``."""
    ax = vertices[b, 0] - vertices[a, 0]
    ay = vertices[b, 1] - vertices[a, 1]
    az = vertices[b, 2] - vertices[a, 2]
    bx = vertices[c, 0] - vertices[a, 0]
    by = vertices[c, 1] - vertices[a, 1]
    bz = vertices[c, 2] - vertices[a, 2]
    cx = vertices[d, 0] - vertices[a, 0]
    cy = vertices[d, 1] - vertices[a, 1]
    cz = vertices[d, 2] - vertices[a, 2]
    return ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)


@kernel
def _orient2d(vertices, a, b, c, axis0, axis1):
    """Twice the signed area of (a, b, c) projected on the (axis0, axis1) plane."""
    return (vertices[b, axis0] - vertices[a, axis0]) * (vertices[c, axis1] - vertices[a, axis1]) - (
        vertices[b, axis1] - vertices[a, axis1]
    ) * (vertices[c, axis0] - vertices[a, axis0])


@kernel
def _on_segment_2d(vertices, p, q, r, axis0, axis1):
    """Whether r, known to be collinear with p-q, lies within the segment's bounding box."""
    return (
        min(vertices[p, axis0], vertices[q, axis0]) <= vertices[r, axis0] <= max(vertices[p, axis0], vertices[q, axis0])
        and min(vertices[p, axis1], vertices[q, axis1]) <= vertices[r, axis1] <= max(vertices[p, axis1], vertices[q, axis1])
    )


@kernel
def _segments_meet_2d(vertices, p, q, r, s, axis0, axis1):
    d1 = _orient2d(vertices, r, s, p, axis0, axis1)
    d2 = _orient2d(vertices, r, s, q, axis0, axis1)
    d3 = _orient2d(vertices, p, q, r, axis0, axis1)
    d4 = _orient2d(vertices, p, q, s, axis0, axis1)
    if ((d1 > 0.0 and d2 < 0.0) or (d1 < 0.0 and d2 > 0.0)) and (
        (d3 > 0.0 and d4 < 0.0) or (d3 < 0.0 and d4 > 0.0)
    ):
        return True
    if d1 == 0.0 and _on_segment_2d(vertices, r, s, p, axis0, axis1):
        return True
    if d2 == 0.0 and _on_segment_2d(vertices, r, s, q, axis0, axis1):
        return True
    if d3 == 0.0 and _on_segment_2d(vertices, p, q, r, axis0, axis1):
        return True
    if d4 == 0.0 and _on_segment_2d(vertices, p, q, s, axis0, axis1):
        return True
    return False


@kernel
def _point_in_triangle_2d(vertices, p, a, b, c, axis0, axis1):
    o1 = _orient2d(vertices, a, b, p, axis0, axis1)
    o2 = _orient2d(vertices, b, c, p, axis0, axis1)
    o3 = _orient2d(vertices, c, a, p, axis0, axis1)
    return (o1 >= 0.0 and o2 >= 0.0 and o3 >= 0.0) or (o1 <= 0.0 and o2 <= 0.0 and o3 <= 0.0)


@kernel
def _projection_axes(vertices, a, b, c):
    """The two axes to keep when projecting the plane of (a, b, c): drop its normal's largest."""
    ux = vertices[b, 0] - vertices[a, 0]
    uy = vertices[b, 1] - vertices[a, 1]
    uz = vertices[b, 2] - vertices[a, 2]
    vx = vertices[c, 0] - vertices[a, 0]
    vy = vertices[c, 1] - vertices[a, 1]
    vz = vertices[c, 2] - vertices[a, 2]
    nx = abs(uy * vz - uz * vy)
    ny = abs(uz * vx - ux * vz)
    nz = abs(ux * vy - uy * vx)
    if nx >= ny and nx >= nz:
        return 1, 2
    if ny >= nz:
        return 0, 2
    return 0, 1


@kernel
def _segment_meets_triangle_2d(vertices, p, q, a, b, c):
    axis0, axis1 = _projection_axes(vertices, a, b, c)
    if _point_in_triangle_2d(vertices, p, a, b, c, axis0, axis1):
        return True
    return (
        _segments_meet_2d(vertices, p, q, a, b, axis0, axis1)
        or _segments_meet_2d(vertices, p, q, b, c, axis0, axis1)
        or _segments_meet_2d(vertices, p, q, c, a, axis0, axis1)
    )


@kernel
def _segment_meets_triangle(vertices, p, q, a, b, c):
    """Whether segment p-q meets triangle (a, b, c), touching included."""
    op = _orient3d(vertices, a, b, c, p)
    oq = _orient3d(vertices, a, b, c, q)
    if op == 0.0 and oq == 0.0:
        return _segment_meets_triangle_2d(vertices, p, q, a, b, c)
    if (op > 0.0 and oq > 0.0) or (op < 0.0 and oq < 0.0):
        return False
    s1 = _orient3d(vertices, p, q, a, b)
    s2 = _orient3d(vertices, p, q, b, c)
    s3 = _orient3d(vertices, p, q, c, a)
    return (s1 >= 0.0 and s2 >= 0.0 and s3 >= 0.0) or (s1 <= 0.0 and s2 <= 0.0 and s3 <= 0.0)


@kernel
def _triangles_intersect(vertices, a0, a1, a2, b0, b1, b2):
    """Whether triangles (a0, a1, a2) and (b0, b1, b2) share at least one point."""
    d0 = _orient3d(vertices, a0, a1, a2, b0)
    d1 = _orient3d(vertices, a0, a1, a2, b1)
    d2 = _orient3d(vertices, a0, a1, a2, b2)
    if (d0 > 0.0 and d1 > 0.0 and d2 > 0.0) or (d0 < 0.0 and d1 < 0.0 and d2 < 0.0):
        return False
    e0 = _orient3d(vertices, b0, b1, b2, a0)
    e1 = _orient3d(vertices, b0, b1, b2, a1)
    e2 = _orient3d(vertices, b0, b1, b2, a2)
    if (e0 > 0.0 and e1 > 0.0 and e2 > 0.0) or (e0 < 0.0 and e1 < 0.0 and e2 < 0.0):
        return False
    if d0 == 0.0 and d1 == 0.0 and d2 == 0.0:
        axis0, axis1 = _projection_axes(vertices, a0, a1, a2)
        if (
            _point_in_triangle_2d(vertices, a0, b0, b1, b2, axis0, axis1)
            or _point_in_triangle_2d(vertices, b0, a0, a1, a2, axis0, axis1)
        ):
            return True
        for p, q in ((a0, a1), (a1, a2), (a2, a0)):
            for r, s in ((b0, b1), (b1, b2), (b2, b0)):
                if _segments_meet_2d(vertices, p, q, r, s, axis0, axis1):
                    return True
        return False
    # Not coplanar: the intersection is a segment whose ends lie on an edge of one triangle.
    return (
        _segment_meets_triangle(vertices, a0, a1, b0, b1, b2)
        or _segment_meets_triangle(vertices, a1, a2, b0, b1, b2)
        or _segment_meets_triangle(vertices, a2, a0, b0, b1, b2)
        or _segment_meets_triangle(vertices, b0, b1, a0, a1, a2)
        or _segment_meets_triangle(vertices, b1, b2, a0, a1, a2)
        or _segment_meets_triangle(vertices, b2, b0, a0, a1, a2)
    )


@kernel
def find_intersecting_triangle_pairs(vertices, triangles, lower, upper, order, sweep_axis, pairs):
    """Find pairs of triangles that share no vertex yet intersect.

    Parameters
    ----------
    vertices : float64 array, shape (n_vertices, 3)
        Vertex coordinates.
    triangles : int64 array, shape (n_triangles, 3)
        Vertex indices of each triangle.
    lower, upper : float64 arrays, shape (n_triangles, 3)
        Bounding box of each triangle.
    order : int64 array, shape (n_triangles,)
        Triangle indices sorted by ``lower[:, sweep_axis]``.
    sweep_axis : int
        Axis of the sweep (the longest extent of the surface).
    pairs : int64 array, shape (capacity, 2)
        Output buffer; the first ``min(count, capacity)`` rows are filled.

    Returns
    -------
    int
        Total number of intersecting pairs found (may exceed ``capacity``; then the buffer holds
        only the first ``capacity``).
    """
    n = order.shape[0]
    capacity = pairs.shape[0]
    count = 0
    for position in range(n):
        i = order[position]
        i0 = triangles[i, 0]
        i1 = triangles[i, 1]
        i2 = triangles[i, 2]
        for next_position in range(position + 1, n):
            j = order[next_position]
            if lower[j, sweep_axis] > upper[i, sweep_axis]:
                break
            overlap = True
            for axis in range(3):
                if lower[j, axis] > upper[i, axis] or lower[i, axis] > upper[j, axis]:
                    overlap = False
            if not overlap:
                continue
            j0 = triangles[j, 0]
            j1 = triangles[j, 1]
            j2 = triangles[j, 2]
            if (
                j0 == i0 or j0 == i1 or j0 == i2
                or j1 == i0 or j1 == i1 or j1 == i2
                or j2 == i0 or j2 == i1 or j2 == i2
            ):
                continue
            if _triangles_intersect(vertices, i0, i1, i2, j0, j1, j2):
                if count < capacity:
                    pairs[count, 0] = min(i, j)
                    pairs[count, 1] = max(i, j)
                count += 1
    return count


def _format_point(point: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in point) + ")"


def _listing(items: list[str], total: int) -> str:
    text = "; ".join(items)
    if total > len(items):
        text += f"; and {total - len(items)} more"
    return text


def enclosed_volume(vertices: np.ndarray, triangles: np.ndarray) -> float:
    """Signed volume enclosed by a closed triangle surface.

    Parameters
    ----------
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Vertex coordinates in metres.
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle.

    Returns
    -------
    float
        Volume in m^3, positive when the triangle normals ``(x1 - x0) x (x2 - x0)`` point outward.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    corners = vertices[np.asarray(triangles, dtype=np.int64)] - vertices.mean(axis=0)
    return float(np.einsum("ti,ti->t", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)


def orient_outward(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The triangles with their vertex order reversed if the surface faces inward.

    Parameters
    ----------
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Vertex coordinates in metres.
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle of a closed, consistently oriented surface.

    Returns
    -------
    numpy.ndarray, shape (n_triangles, 3)
        A copy of ``triangles``, reversed (``[:, ::-1]``) if the enclosed volume was negative.
    """
    triangles = np.array(triangles, dtype=np.int64, copy=True)
    if enclosed_volume(vertices, triangles) < 0.0:
        triangles = np.ascontiguousarray(triangles[:, ::-1])
    return triangles


def find_self_intersections(
    vertices: np.ndarray, triangles: np.ndarray, *, max_pairs: int = _MAX_LISTED
) -> tuple[np.ndarray, int]:
    """Pairs of triangles that share no vertex but intersect.

    Parameters
    ----------
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Vertex coordinates in metres.
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle.
    max_pairs : int
        How many pairs to return at most.

    Returns
    -------
    pairs : numpy.ndarray, shape (min(count, max_pairs), 2)
        Triangle indices of intersecting pairs (smaller index first).
    count : int
        Total number of intersecting pairs.
    """
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    triangles = np.ascontiguousarray(triangles, dtype=np.int64)
    corners = vertices[triangles]
    lower = np.ascontiguousarray(corners.min(axis=1))
    upper = np.ascontiguousarray(corners.max(axis=1))
    sweep_axis = int(np.argmax(vertices.max(axis=0) - vertices.min(axis=0)))
    order = np.argsort(lower[:, sweep_axis], kind="stable").astype(np.int64)
    pairs = np.zeros((max(int(max_pairs), 1), 2), dtype=np.int64)
    count = int(find_intersecting_triangle_pairs(vertices, triangles, lower, upper, order, sweep_axis, pairs))
    return pairs[: min(count, int(max_pairs))], count


def check_closed_surface(vertices: np.ndarray, triangles: np.ndarray, name: str = "surface") -> None:
    """Check that triangles form a closed, outward-oriented, non-self-intersecting surface.

    Checks, in order: array shapes and finite coordinates; degenerate (zero-area or repeated
    vertex) triangles; open edges (used by one triangle); non-manifold edges (used by more than
    two); inconsistent orientation between neighbours (an edge traversed in the same direction by
    both its triangles); inward orientation (negative enclosed volume); self-intersection.

    Parameters
    ----------
    vertices : numpy.ndarray, shape (n_vertices, 3)
        Vertex coordinates in metres. Coincident vertices must be merged first (otherwise every
        edge between them looks open).
    triangles : numpy.ndarray, shape (n_triangles, 3)
        Vertex indices of each triangle; ``(x1 - x0) x (x2 - x0)`` should point outward.
    name : str
        File or surface name, used in every error message.

    Raises
    ------
    MeshError
        Naming ``name``, the offending triangles, edges or vertices (with coordinates) and the
        likely fix.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    triangles = np.asarray(triangles)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or triangles.ndim != 2 or triangles.shape[1] != 3:
        raise MeshError(
            f"surface '{name}': vertices must have shape (n, 3) and triangles (m, 3), got "
            f"{vertices.shape} and {triangles.shape}"
        )
    if len(triangles) < 4:
        raise MeshError(
            f"surface '{name}' has {len(triangles)} triangles; a closed surface needs at least 4"
        )
    if not np.issubdtype(triangles.dtype, np.integer) and not (
        np.issubdtype(triangles.dtype, np.floating) and np.array_equal(triangles, np.round(triangles))
    ):
        raise MeshError(
            f"surface '{name}': triangle vertex indices must be integers, got dtype {triangles.dtype}"
        )
    triangles = triangles.astype(np.int64)
    out_of_range = np.flatnonzero(((triangles < 0) | (triangles >= len(vertices))).any(axis=1))
    if out_of_range.size:
        listed = [f"{k} (vertices {triangles[k].tolist()})" for k in out_of_range[:_MAX_LISTED]]
        raise MeshError(
            f"surface '{name}': {out_of_range.size} triangles refer to vertices that do not exist "
            f"(indices must lie in 0..{len(vertices) - 1}): triangles "
            f"{_listing(listed, out_of_range.size)}"
        )
    if not np.isfinite(vertices).all():
        bad = np.flatnonzero(~np.isfinite(vertices).all(axis=1))
        raise MeshError(
            f"surface '{name}' has non-finite vertex coordinates at vertices "
            f"{bad[:_MAX_LISTED].tolist()}; fix the file"
        )
    _check_degenerate_triangles(vertices, triangles, name)
    _check_edges(vertices, triangles, name)
    volume = enclosed_volume(vertices, triangles)
    if volume <= 0.0:
        raise MeshError(
            f"surface '{name}' is oriented inward (enclosed volume {volume:.6g} m^3 is not "
            f"positive): its triangle normals point into the body. Flip every triangle, e.g. "
            f"triangles = riprap.geometry.surface_checks.orient_outward(vertices, triangles) or "
            f"triangles[:, ::-1], or flip the normals in your CAD tool"
        )
    pairs, count = find_self_intersections(vertices, triangles)
    if count:
        listed = []
        for i, j in pairs:
            near = vertices[triangles[i]].mean(axis=0)
            listed.append(f"triangles {i} and {j} near {_format_point(near)}")
        raise MeshError(
            f"surface '{name}' intersects itself: {count} pairs of non-adjacent triangles "
            f"intersect ({_listing(listed, count)}); merge overlapping parts into one solid "
            f"(boolean union) or repair the surface"
        )


def _check_degenerate_triangles(vertices: np.ndarray, triangles: np.ndarray, name: str) -> None:
    used = vertices[np.unique(triangles)]
    diagonal = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    corners = vertices[triangles]
    areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    repeated = (
        (triangles[:, 0] == triangles[:, 1])
        | (triangles[:, 1] == triangles[:, 2])
        | (triangles[:, 2] == triangles[:, 0])
    )
    threshold = DEGENERATE_AREA_FRACTION * diagonal**2
    bad = np.flatnonzero(repeated | (areas <= threshold))
    if bad.size:
        listed = [
            f"{k} (vertices {triangles[k].tolist()}, area {areas[k]:.3e} m^2)" for k in bad[:_MAX_LISTED]
        ]
        raise MeshError(
            f"surface '{name}' has {bad.size} zero-area triangles (area below {threshold:.3e} m^2 "
            f"or a repeated vertex): triangles {_listing(listed, bad.size)}; remove them and "
            f"merge their vertices"
        )


def _check_edges(vertices: np.ndarray, triangles: np.ndarray, name: str) -> None:
    directed = triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    undirected = np.sort(directed, axis=1)
    edges, inverse, counts = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)

    def describe(edge: np.ndarray) -> str:
        a, b = int(edge[0]), int(edge[1])
        return f"[{a}, {b}] at {_format_point(vertices[a])}-{_format_point(vertices[b])}"

    open_edges = np.flatnonzero(counts == 1)
    if open_edges.size:
        listed = [describe(edges[k]) for k in open_edges[:_MAX_LISTED]]
        raise MeshError(
            f"surface '{name}' is not closed: {open_edges.size} open edges are used by only one "
            f"triangle, e.g. edges (vertex indices, coordinates in m) {_listing(listed, open_edges.size)}; "
            f"fill the holes, or merge duplicate vertices if the file stores them separately"
        )
    non_manifold = np.flatnonzero(counts > 2)
    if non_manifold.size:
        listed = [f"{describe(edges[k])} ({counts[k]} triangles)" for k in non_manifold[:_MAX_LISTED]]
        raise MeshError(
            f"surface '{name}' has {non_manifold.size} non-manifold edges used by more than two "
            f"triangles: {_listing(listed, non_manifold.size)}; split touching bodies into "
            f"separate files or merge them into one solid"
        )
    # On a consistently oriented closed surface each edge is traversed once in each direction, so
    # the two uses of an edge must differ in which end comes first.
    forward = directed[:, 0] < directed[:, 1]
    forward_count = np.bincount(inverse, weights=forward, minlength=len(edges))
    inconsistent = np.flatnonzero(forward_count != 1)
    if inconsistent.size:
        triangle_of_use = np.arange(len(directed)) // 3
        listed = []
        for k in inconsistent[:_MAX_LISTED]:
            owners = triangle_of_use[inverse == k].tolist()
            listed.append(f"edge {describe(edges[k])} of triangles {owners}")
        raise MeshError(
            f"surface '{name}' is inconsistently oriented: {inconsistent.size} edges are "
            f"traversed in the same direction by both of their triangles ({_listing(listed, inconsistent.size)}); "
            f"reverse the vertex order of the flipped triangles so all normals point outward"
        )
