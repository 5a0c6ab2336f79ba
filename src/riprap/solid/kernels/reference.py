"""Slow, obvious reference evaluation of Munjiza's distributed potential contact.

This module is the yardstick that the fast contact kernels are tested against. It favours being
plainly right over being quick: every tetrahedron pair whose bounding boxes overlap is evaluated
by exact convex clipping, with no early-outs beyond the bounding-box test.

Potential and force (Munjiza 2004, ch. 2; Munjiza & Andrews 2000, eq. 6)
-----------------------------------------------------------------------
Every tetrahedron carries the potential ``phi(x) = 4 min_k lambda_k(x)``, with ``lambda_k`` the
barycentric coordinate that is 1 at vertex ``k`` and 0 on the face opposite it: ``phi`` is 0 on the
surface and 1 at the centroid. The tetrahedron splits into four sub-tetrahedra, sub-tet ``k`` being
the face opposite vertex ``k`` plus the centroid, inside which ``phi = 4 lambda_k`` and
``grad phi = 4 grad lambda_k`` is constant. The force on body A from body B is

    F_A = p sum_c sum_t integral over (c ∩ t) of (grad phi_c - grad phi_t) dV,
    M_A = p sum_c sum_t integral over (c ∩ t) of x × (grad phi_c - grad phi_t) dV,

with ``c`` the tetrahedra of A, ``t`` those of B and the moment taken about the world origin. As the
integrand is constant on each (sub-tet of c) ∩ (sub-tet of t), the integral is a finite sum over 16
sub-tet pairs of volume and first moment of volume, both computed exactly by clipping.

A wall is the half-space ``{x : n·(x - point) < 0}``, ``n`` pointing into the free space, with the
potential ``phi_W = -n·(x - point) / h_W`` (``h_W`` = ``wall_potential_depth``).

Clipping as a "tet soup"
------------------------
A convex region is held as a list of small tetrahedra. Clipping by a plane splits each tetrahedron
by the signs of its four signed distances: kept whole, dropped, one tetrahedron (one vertex
inside), or a wedge cut into three tetrahedra (two or three vertices inside). Sub-tet ``k`` of
``c`` is clipped by the four face planes of sub-tet ``l`` of ``t``, so at most ``3**4 = 81``
pieces exist; the buffers hold ``SOUP_CAPACITY`` and the kernels still return an overflow flag
that the wrappers turn into :class:`~riprap.errors.KernelOverflowError`.

All geometry of a tetrahedron pair is computed relative to the first vertex of the contactor, so
round-off scales with the tetrahedron size and not with the distance from the world origin.

Symbols used inside the kernels
-------------------------------
=================  ==========================================================
``tet_c, tet_t``   contactor / target tetrahedron vertices (4, 3), local frame
``grads_c``        ``4 grad lambda_k`` of the contactor, row k (4, 3), 1/m
``snap``           signed distances below this are treated as exactly 0, m
``soup_*``         tet-soup buffers (SOUP_CAPACITY, 4, 3), m
``result``         force integral (0:3, m^2) and moment integral (3:6, m^3)
=================  ==========================================================

Set ``NUMBA_DISABLE_JIT=1`` to run everything as plain Python for debugging.

References
----------
A. Munjiza (2004), *The Combined Finite-Discrete Element Method*, Wiley.
A. Munjiza, K. R. F. Andrews (2000), "Penalty function method for combined finite-discrete element
systems comprising large number of separate bodies", *IJNME*, eq. 6.
"""
import numpy as np

from riprap._jit import kernel
from riprap.errors import CaseFileError, KernelOverflowError, MeshError

__all__ = [
    "SOUP_CAPACITY",
    "brute_force_overlapping_tet_pairs",
    "reference_body_contact",
    "reference_wall_contact",
    "tet_intersection_volume_centroid",
]

# Four successive plane clips can triple the piece count each time (3**4 = 81); a little headroom.
SOUP_CAPACITY = 96
# Signed distances within this fraction of the pair's size are set to 0, so that a vertex lying on
# a clipping plane (shared faces, coincident meshes) does not spawn slivers of round-off volume.
# It is ~500 times the round-off of a distance computed from coordinates of that size.
_SNAP_RELATIVE = 1e-13
# Tetrahedra with |6 V| below this fraction of size**3 are degenerate (zero volume up to round-off).
_DEGENERATE_RELATIVE = 1e-14


# --------------------------------------------------------------------------------------------
# kernels
# --------------------------------------------------------------------------------------------
@kernel
def _signed_volume_times_six(p0, p1, p2, p3):
    ax = p1[0] - p0[0]
    ay = p1[1] - p0[1]
    az = p1[2] - p0[2]
    bx = p2[0] - p0[0]
    by = p2[1] - p0[1]
    bz = p2[2] - p0[2]
    cx = p3[0] - p0[0]
    cy = p3[1] - p0[1]
    cz = p3[2] - p0[2]
    return ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)


@kernel
def _tet_size(tet):
    """Largest bounding-box extent of a (4, 3) tetrahedron, m."""
    size = 0.0
    for axis in range(3):
        low = tet[0, axis]
        high = tet[0, axis]
        for v in range(1, 4):
            low = min(low, tet[v, axis])
            high = max(high, tet[v, axis])
        size = max(size, high - low)
    return size


@kernel
def _boxes_overlap(tet_a, tet_b):
    """Closed bounding-box overlap test of two (4, 3) tetrahedra."""
    for axis in range(3):
        low_a = min(min(tet_a[0, axis], tet_a[1, axis]), min(tet_a[2, axis], tet_a[3, axis]))
        high_a = max(max(tet_a[0, axis], tet_a[1, axis]), max(tet_a[2, axis], tet_a[3, axis]))
        low_b = min(min(tet_b[0, axis], tet_b[1, axis]), min(tet_b[2, axis], tet_b[3, axis]))
        high_b = max(max(tet_b[0, axis], tet_b[1, axis]), max(tet_b[2, axis], tet_b[3, axis]))
        if low_a > high_b or low_b > high_a:
            return False
    return True


@kernel
def _set_cut_point(target, row, source, i, j, distances):
    """Point where edge i-j of ``source`` crosses the plane (distances of opposite sign or 0)."""
    # distances[i] > 0 >= distances[j], so the denominator is >= distances[i] > 0.
    t = distances[i] / (distances[i] - distances[j])
    for axis in range(3):
        target[row, axis] = source[i, axis] + t * (source[j, axis] - source[i, axis])


@kernel
def _emit_wedge(wedge, soup_out, count_out):
    """Three tetrahedra filling the convex wedge with triangles wedge[0:3], wedge[3:6].

    Lateral edges join wedge[i] and wedge[i + 3]. The split (p0 p1 p2 q2), (p0 p1 q1 q2),
    (p0 q0 q1 q2) uses quad diagonals that all start at the lower-numbered triangle, which is a
    valid triangulation of any convex wedge with planar quad faces.
    """
    corners = ((0, 1, 2, 5), (0, 1, 4, 5), (0, 3, 4, 5))
    for piece in range(3):
        for v in range(4):
            for axis in range(3):
                soup_out[count_out + piece, v, axis] = wedge[corners[piece][v], axis]


@kernel
def _clip_soup_by_plane(soup_in, count_in, normal, offset, snap, soup_out, distances, wedge, order):
    """Keep the part of a tet soup where ``normal·y - offset > 0``.

    Returns (number of tetrahedra written to ``soup_out``, overflow flag). Vertices within ``snap``
    of the plane count as on it, and on-plane vertices are grouped with the removed side, which
    makes an edge from a kept vertex to an on-plane vertex cut exactly at that vertex.
    """
    capacity = soup_out.shape[0]
    count_out = 0
    for s in range(count_in):
        n_inside = 0
        n_outside = 0
        for v in range(4):
            d = (normal[0] * soup_in[s, v, 0] + normal[1] * soup_in[s, v, 1]
                 + normal[2] * soup_in[s, v, 2] - offset)
            if abs(d) <= snap:
                d = 0.0
            distances[v] = d
            if d > 0.0:
                n_inside += 1
            elif d < 0.0:
                n_outside += 1
        if n_inside == 0:
            continue
        needed = 1 if (n_outside == 0 or n_inside == 1) else 3
        if count_out + needed > capacity:
            return count_out, True
        if n_outside == 0:
            for v in range(4):
                for axis in range(3):
                    soup_out[count_out, v, axis] = soup_in[s, v, axis]
            count_out += 1
            continue
        first_kept = 0
        first_removed = n_inside
        for v in range(4):
            if distances[v] > 0.0:
                order[first_kept] = v
                first_kept += 1
            else:
                order[first_removed] = v
                first_removed += 1
        source = soup_in[s]
        if n_inside == 1:
            a = order[0]
            for axis in range(3):
                wedge[0, axis] = source[a, axis]
            for m in range(1, 4):
                _set_cut_point(wedge, m, source, a, order[m], distances)
            for v in range(4):
                for axis in range(3):
                    soup_out[count_out, v, axis] = wedge[v, axis]
            count_out += 1
        elif n_inside == 2:
            a = order[0]
            b = order[1]
            c = order[2]
            d_ = order[3]
            for axis in range(3):
                wedge[0, axis] = source[a, axis]
                wedge[3, axis] = source[b, axis]
            _set_cut_point(wedge, 1, source, a, c, distances)
            _set_cut_point(wedge, 2, source, a, d_, distances)
            _set_cut_point(wedge, 4, source, b, c, distances)
            _set_cut_point(wedge, 5, source, b, d_, distances)
            _emit_wedge(wedge, soup_out, count_out)
            count_out += 3
        else:
            removed = order[3]
            for m in range(3):
                for axis in range(3):
                    wedge[m, axis] = source[order[m], axis]
                _set_cut_point(wedge, m + 3, source, order[m], removed, distances)
            _emit_wedge(wedge, soup_out, count_out)
            count_out += 3
    return count_out, False


@kernel
def _soup_volume_moment(soup, count, moment):
    """Volume (m^3) of a tet soup; writes its first moment of volume (m^4) into ``moment``."""
    volume = 0.0
    moment[0] = 0.0
    moment[1] = 0.0
    moment[2] = 0.0
    for s in range(count):
        piece = abs(_signed_volume_times_six(soup[s, 0], soup[s, 1], soup[s, 2], soup[s, 3])) / 6.0
        volume += piece
        for axis in range(3):
            moment[axis] += piece * 0.25 * (soup[s, 0, axis] + soup[s, 1, axis]
                                            + soup[s, 2, axis] + soup[s, 3, axis])
    return volume


@kernel
def _clip_tet_by_tet(tet, clipper, snap, soup_a, soup_b, distances, wedge, order, normal, moment):
    """Volume of ``tet ∩ clipper`` (m^3); its first moment of volume goes to ``moment``.

    Returns (volume, overflow flag). The clipper may have either orientation: each of its face
    half-spaces is taken as the side containing the fourth vertex.
    """
    moment[0] = 0.0
    moment[1] = 0.0
    moment[2] = 0.0
    size = max(_tet_size(tet), _tet_size(clipper))
    if abs(_signed_volume_times_six(clipper[0], clipper[1], clipper[2], clipper[3])) \
            <= _DEGENERATE_RELATIVE * size * size * size:
        return 0.0, False
    for v in range(4):
        for axis in range(3):
            soup_a[0, v, axis] = tet[v, axis]
    count = 1
    for face in range(4):
        # Face ``face`` is opposite clipper vertex ``face``; its vertices are the other three.
        i0 = (face + 1) % 4
        i1 = (face + 2) % 4
        i2 = (face + 3) % 4
        ux = clipper[i1, 0] - clipper[i0, 0]
        uy = clipper[i1, 1] - clipper[i0, 1]
        uz = clipper[i1, 2] - clipper[i0, 2]
        vx = clipper[i2, 0] - clipper[i0, 0]
        vy = clipper[i2, 1] - clipper[i0, 1]
        vz = clipper[i2, 2] - clipper[i0, 2]
        normal[0] = uy * vz - uz * vy
        normal[1] = uz * vx - ux * vz
        normal[2] = ux * vy - uy * vx
        length = np.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
        side = 0.0
        for axis in range(3):
            side += normal[axis] * (clipper[face, axis] - clipper[i0, axis])
        scale = 1.0 / length if side > 0.0 else -1.0 / length
        offset = 0.0
        for axis in range(3):
            normal[axis] *= scale
            offset += normal[axis] * clipper[i0, axis]
        # Alternate buffers: after the four clips the soup is back in soup_a.
        if face % 2 == 0:
            count, overflow = _clip_soup_by_plane(soup_a, count, normal, offset, snap * size,
                                                  soup_b, distances, wedge, order)
        else:
            count, overflow = _clip_soup_by_plane(soup_b, count, normal, offset, snap * size,
                                                  soup_a, distances, wedge, order)
        if overflow:
            return 0.0, True
        if count == 0:
            return 0.0, False
    return _soup_volume_moment(soup_a, count, moment), False


@kernel
def _potential_gradients(tet, centroid, grads):
    """``grads[k] = 4 grad lambda_k`` (1/m) and the centroid of a (4, 3) tetrahedron."""
    e1x = tet[1, 0] - tet[0, 0]
    e1y = tet[1, 1] - tet[0, 1]
    e1z = tet[1, 2] - tet[0, 2]
    e2x = tet[2, 0] - tet[0, 0]
    e2y = tet[2, 1] - tet[0, 1]
    e2z = tet[2, 2] - tet[0, 2]
    e3x = tet[3, 0] - tet[0, 0]
    e3y = tet[3, 1] - tet[0, 1]
    e3z = tet[3, 2] - tet[0, 2]
    det = _signed_volume_times_six(tet[0], tet[1], tet[2], tet[3])
    # grad lambda_1 = (e2 × e3) / det etc., since it must be 1 along e1 and 0 along e2 and e3.
    factor = 4.0 / det
    grads[1, 0] = (e2y * e3z - e2z * e3y) * factor
    grads[1, 1] = (e2z * e3x - e2x * e3z) * factor
    grads[1, 2] = (e2x * e3y - e2y * e3x) * factor
    grads[2, 0] = (e3y * e1z - e3z * e1y) * factor
    grads[2, 1] = (e3z * e1x - e3x * e1z) * factor
    grads[2, 2] = (e3x * e1y - e3y * e1x) * factor
    grads[3, 0] = (e1y * e2z - e1z * e2y) * factor
    grads[3, 1] = (e1z * e2x - e1x * e2z) * factor
    grads[3, 2] = (e1x * e2y - e1y * e2x) * factor
    for axis in range(3):
        grads[0, axis] = -(grads[1, axis] + grads[2, axis] + grads[3, axis])
        centroid[axis] = 0.25 * (tet[0, axis] + tet[1, axis] + tet[2, axis] + tet[3, axis])


@kernel
def _accumulate_tet_pair_contact(tet_c, tet_t, sub_c, sub_t, grads_c, grads_t, centroid_c,
                                 centroid_t, soup_a, soup_b, distances, wedge, order, normal,
                                 moment, result):
    """Add the contact integrals of one tetrahedron pair to ``result`` (6,).

    ``result[0:3] += sum over c ∩ t of (grad phi_c - grad phi_t) dV`` (m^2) and
    ``result[3:6] +=`` the same with ``y ×`` (m^3), ``y`` in the frame of ``tet_c``/``tet_t``.
    Returns the overflow flag.

    16 arguments: the reference evaluation's work arrays one by one, as :func:`_sum_body_contact`.
    """
    _potential_gradients(tet_c, centroid_c, grads_c)
    _potential_gradients(tet_t, centroid_t, grads_t)
    for k in range(4):
        for v in range(4):
            for axis in range(3):
                sub_c[v, axis] = centroid_c[axis] if v == k else tet_c[v, axis]
        for m in range(4):
            for v in range(4):
                for axis in range(3):
                    sub_t[v, axis] = centroid_t[axis] if v == m else tet_t[v, axis]
            if not _boxes_overlap(sub_c, sub_t):
                continue
            volume, overflow = _clip_tet_by_tet(sub_c, sub_t, _SNAP_RELATIVE, soup_a, soup_b,
                                                distances, wedge, order, normal, moment)
            if overflow:
                return True
            if volume == 0.0:
                continue
            gx = grads_c[k, 0] - grads_t[m, 0]
            gy = grads_c[k, 1] - grads_t[m, 1]
            gz = grads_c[k, 2] - grads_t[m, 2]
            result[0] += volume * gx
            result[1] += volume * gy
            result[2] += volume * gz
            result[3] += moment[1] * gz - moment[2] * gy
            result[4] += moment[2] * gx - moment[0] * gz
            result[5] += moment[0] * gy - moment[1] * gx
    return False


@kernel
def _sum_body_contact(nodes_a, tets_a, nodes_b, tets_b, pairs, tet_c, tet_t, sub_c, sub_t,
                      grads_c, grads_t, centroid_c, centroid_t, soup_a, soup_b, distances, wedge,
                      order, normal, moment, pair_result, total):
    """Sum the contact integrals over tetrahedron ``pairs`` (k, 2) into ``total`` (6,).

    ``total[0:3]`` is the force integral (m^2), ``total[3:6]`` the moment integral about the world
    origin (m^3); multiply by the penalty for N and N m. Returns the index of the pair that
    overflowed the soup buffers, or -1.

    22 arguments: the reference (volume-form) evaluation for the tests, which passes its work
    arrays one by one to a compiled loop; it is not on the run's path.
    """
    for axis in range(6):
        total[axis] = 0.0
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        for v in range(4):
            for axis in range(3):
                tet_c[v, axis] = nodes_a[tets_a[i, v], axis] - nodes_a[tets_a[i, 0], axis]
                tet_t[v, axis] = nodes_b[tets_b[j, v], axis] - nodes_a[tets_a[i, 0], axis]
        for axis in range(6):
            pair_result[axis] = 0.0
        overflow = _accumulate_tet_pair_contact(tet_c, tet_t, sub_c, sub_t, grads_c, grads_t,
                                                centroid_c, centroid_t, soup_a, soup_b, distances,
                                                wedge, order, normal, moment, pair_result)
        if overflow:
            return p
        ox = nodes_a[tets_a[i, 0], 0]
        oy = nodes_a[tets_a[i, 0], 1]
        oz = nodes_a[tets_a[i, 0], 2]
        fx = pair_result[0]
        fy = pair_result[1]
        fz = pair_result[2]
        total[0] += fx
        total[1] += fy
        total[2] += fz
        # Moment about the world origin = origin × F + moment about the local origin.
        total[3] += oy * fz - oz * fy + pair_result[3]
        total[4] += oz * fx - ox * fz + pair_result[4]
        total[5] += ox * fy - oy * fx + pair_result[5]
    return -1


@kernel
def _sum_wall_contact(nodes, tets, point, normal, wall_potential_depth, tet_c, sub_c, grads_c,
                      centroid_c, soup_a, soup_b, distances, wedge, order, inward, moment, total):
    """Sum the wall contact integrals of every tetrahedron into ``total`` (6,).

    Same units and layout as :func:`_sum_body_contact`. Returns the index of the tetrahedron that
    overflowed the soup buffers, or -1.

    17 arguments: the reference evaluation's work arrays one by one, as :func:`_sum_body_contact`.
    """
    for axis in range(6):
        total[axis] = 0.0
    # Keep -n·(x - point) > 0; in the local frame y = x - origin that is
    # (-n)·y - n·(origin - point) > 0.
    for axis in range(3):
        inward[axis] = -normal[axis]
    for i in range(tets.shape[0]):
        offset = 0.0
        for v in range(4):
            for axis in range(3):
                tet_c[v, axis] = nodes[tets[i, v], axis] - nodes[tets[i, 0], axis]
        for axis in range(3):
            offset += normal[axis] * (nodes[tets[i, 0], axis] - point[axis])
        snap = _SNAP_RELATIVE * _tet_size(tet_c)
        _potential_gradients(tet_c, centroid_c, grads_c)
        fx = 0.0
        fy = 0.0
        fz = 0.0
        mx = 0.0
        my = 0.0
        mz = 0.0
        for k in range(4):
            for v in range(4):
                for axis in range(3):
                    soup_a[0, v, axis] = centroid_c[axis] if v == k else tet_c[v, axis]
            count, overflow = _clip_soup_by_plane(soup_a, 1, inward, offset, snap, soup_b,
                                                  distances, wedge, order)
            if overflow:
                return i
            if count == 0:
                continue
            volume = _soup_volume_moment(soup_b, count, moment)
            # grad phi_c - grad phi_W with grad phi_W = -n / h_W.
            gx = grads_c[k, 0] + normal[0] / wall_potential_depth
            gy = grads_c[k, 1] + normal[1] / wall_potential_depth
            gz = grads_c[k, 2] + normal[2] / wall_potential_depth
            fx += volume * gx
            fy += volume * gy
            fz += volume * gz
            mx += moment[1] * gz - moment[2] * gy
            my += moment[2] * gx - moment[0] * gz
            mz += moment[0] * gy - moment[1] * gx
        ox = nodes[tets[i, 0], 0]
        oy = nodes[tets[i, 0], 1]
        oz = nodes[tets[i, 0], 2]
        total[0] += fx
        total[1] += fy
        total[2] += fz
        total[3] += oy * fz - oz * fy + mx
        total[4] += oz * fx - ox * fz + my
        total[5] += ox * fy - oy * fx + mz
    return -1


@kernel
def _collect_box_pairs(low_a, high_a, low_b, high_b, pairs):
    """Write index pairs of overlapping closed boxes into ``pairs``; return how many overlap.

    Call once with a (0, 2) ``pairs`` to count, then with an array of that length to fill.
    """
    count = 0
    capacity = pairs.shape[0]
    for i in range(low_a.shape[0]):
        for j in range(low_b.shape[0]):
            overlap = True
            for axis in range(3):
                if low_a[i, axis] > high_b[j, axis] or low_b[j, axis] > high_a[i, axis]:
                    overlap = False
                    break
            if overlap:
                if count < capacity:
                    pairs[count, 0] = i
                    pairs[count, 1] = j
                count += 1
    return count


# --------------------------------------------------------------------------------------------
# Python wrappers: validate, allocate buffers, call kernels, turn flags into errors
# --------------------------------------------------------------------------------------------
class _Workspace:
    """Fixed-size scratch buffers shared by the kernels of one call."""

    def __init__(self):
        self.tet_c = np.empty((4, 3))
        self.tet_t = np.empty((4, 3))
        self.sub_c = np.empty((4, 3))
        self.sub_t = np.empty((4, 3))
        self.grads_c = np.empty((4, 3))
        self.grads_t = np.empty((4, 3))
        self.centroid_c = np.empty(3)
        self.centroid_t = np.empty(3)
        self.soup_a = np.empty((SOUP_CAPACITY, 4, 3))
        self.soup_b = np.empty((SOUP_CAPACITY, 4, 3))
        self.distances = np.empty(4)
        self.wedge = np.empty((6, 3))
        self.order = np.empty(4, dtype=np.int64)
        self.normal = np.empty(3)
        self.moment = np.empty(3)
        self.pair_result = np.empty(6)
        self.total = np.empty(6)


def _overflow_message(what):
    return (f"the tet-soup buffer of {SOUP_CAPACITY} tetrahedra overflowed while clipping {what}; "
            "this should be impossible for four clipping planes (at most 81 pieces); raise "
            "SOUP_CAPACITY in riprap/solid/kernels/reference.py and report the input")


def _checked_tet(vertices, name):
    tet = np.ascontiguousarray(vertices, dtype=np.float64)
    if tet.shape != (4, 3):
        raise MeshError(f"{name} must have shape (4, 3) (four vertices, x y z in m), "
                        f"got {tet.shape}")
    if not np.all(np.isfinite(tet)):
        raise MeshError(f"{name} has non-finite coordinates: {tet.tolist()}")
    return tet


def _checked_mesh(nodes, tets, name):
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    tets = np.ascontiguousarray(tets)
    if nodes.ndim != 2 or nodes.shape[1] != 3:
        raise MeshError(f"{name}: nodes must have shape (n_nodes, 3), got {nodes.shape}")
    if tets.ndim != 2 or tets.shape[1] != 4:
        raise MeshError(f"{name}: tets must have shape (n_tets, 4), got {tets.shape}")
    if not np.issubdtype(tets.dtype, np.integer):
        raise MeshError(f"{name}: tets must hold integer node indices, got dtype {tets.dtype}")
    tets = tets.astype(np.int64)
    if tets.size and (tets.min() < 0 or tets.max() >= nodes.shape[0]):
        raise MeshError(f"{name}: tets refer to node indices outside 0..{nodes.shape[0] - 1}")
    if not np.all(np.isfinite(nodes)):
        raise MeshError(f"{name}: nodes hold non-finite coordinates")
    if tets.size:
        corners = nodes[tets]
        edges = corners[:, 1:] - corners[:, :1]
        six_volumes = np.einsum("ij,ij->i", edges[:, 0], np.cross(edges[:, 1], edges[:, 2]))
        sizes = np.ptp(corners, axis=1).max(axis=1)
        bad = np.flatnonzero(six_volumes <= _DEGENERATE_RELATIVE * sizes**3)
        if bad.size:
            first = bad[0]
            raise MeshError(
                f"{name}: tet {first} (nodes {tets[first].tolist()}) has volume "
                f"{six_volumes[first] / 6.0:.3e} m^3; tets must be positively oriented and "
                f"non-degenerate ({bad.size} bad tets); swap two nodes of inverted tets or remesh")
    return nodes, tets


def _checked_penalty(penalty):
    penalty = float(penalty)
    if not (np.isfinite(penalty) and penalty > 0.0):
        raise CaseFileError(f"penalty must be a positive, finite number in Pa, got {penalty}")
    return penalty


def tet_intersection_volume_centroid(tet_a, tet_b):
    """Volume and centroid of the intersection of two tetrahedra, by exact convex clipping.

    Parameters
    ----------
    tet_a, tet_b : array_like, shape (4, 3)
        Vertex coordinates, m. Either orientation is accepted.

    Returns
    -------
    volume : float
        Volume of ``tet_a ∩ tet_b``, m^3 (0.0 when they do not overlap).
    centroid : ndarray, shape (3,)
        Centroid of the intersection, m; NaN when the volume is zero.

    Examples
    --------
    >>> import numpy as np
    >>> unit = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    >>> volume, centroid = tet_intersection_volume_centroid(unit, unit)
    >>> round(volume * 6, 12), np.round(centroid, 12).tolist()
    (1.0, [0.25, 0.25, 0.25])
    """
    tet_a = _checked_tet(tet_a, "tet_a")
    tet_b = _checked_tet(tet_b, "tet_b")
    if not _boxes_overlap(tet_a, tet_b):
        return 0.0, np.full(3, np.nan)
    work = _Workspace()
    origin = tet_a[0].copy()
    volume, overflow = _clip_tet_by_tet(tet_a - origin, tet_b - origin, _SNAP_RELATIVE,
                                        work.soup_a, work.soup_b, work.distances, work.wedge,
                                        work.order, work.normal, work.moment)
    if overflow:
        raise KernelOverflowError(_overflow_message("tet_a by tet_b"))
    if volume == 0.0:
        return 0.0, np.full(3, np.nan)
    return float(volume), origin + work.moment / volume


def brute_force_overlapping_tet_pairs(nodes_a, tets_a, nodes_b, tets_b):
    """All tetrahedron pairs of two meshes whose axis-aligned bounding boxes overlap.

    Every pair is tested (O(n_a n_b)); boxes that only touch count as overlapping.

    Parameters
    ----------
    nodes_a, nodes_b : array_like, shape (n_nodes, 3)
        Node coordinates, m.
    tets_a, tets_b : array_like of int, shape (n_tets, 4)
        Node indices of each tetrahedron.

    Returns
    -------
    ndarray of int64, shape (n_pairs, 2)
        ``[i, j]`` rows with ``i`` a tet of A and ``j`` a tet of B, sorted by ``i`` then ``j``.
    """
    nodes_a, tets_a = _checked_mesh(nodes_a, tets_a, "body A")
    nodes_b, tets_b = _checked_mesh(nodes_b, tets_b, "body B")
    return _box_pairs(nodes_a, tets_a, nodes_b, tets_b)


def _box_pairs(nodes_a, tets_a, nodes_b, tets_b):
    if tets_a.shape[0] == 0 or tets_b.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    corners_a = nodes_a[tets_a]
    corners_b = nodes_b[tets_b]
    low_a = np.ascontiguousarray(corners_a.min(axis=1))
    high_a = np.ascontiguousarray(corners_a.max(axis=1))
    low_b = np.ascontiguousarray(corners_b.min(axis=1))
    high_b = np.ascontiguousarray(corners_b.max(axis=1))
    count = _collect_box_pairs(low_a, high_a, low_b, high_b, np.empty((0, 2), dtype=np.int64))
    pairs = np.empty((count, 2), dtype=np.int64)
    _collect_box_pairs(low_a, high_a, low_b, high_b, pairs)
    return pairs


def reference_body_contact(nodes_a, tets_a, nodes_b, tets_b, *, penalty):
    """Munjiza potential contact force and moment on body A from body B (slow reference).

    ``F_A = p sum_c sum_t ∫_{c ∩ t} (grad phi_c - grad phi_t) dV`` over the tetrahedra ``c`` of A
    and ``t`` of B, and ``M_A`` the same integral of ``x × (...)``. Body B receives ``-F_A`` and
    ``-M_A``. Evaluated exactly (up to round-off) by clipping each pair of sub-tetrahedra.

    Parameters
    ----------
    nodes_a, nodes_b : array_like, shape (n_nodes, 3)
        World coordinates of the nodes of A and B, m.
    tets_a, tets_b : array_like of int, shape (n_tets, 4)
        Positively oriented tetrahedra (node indices).
    penalty : float
        Contact penalty ``p``, Pa.

    Returns
    -------
    force : ndarray, shape (3,)
        Force on A, N.
    moment : ndarray, shape (3,)
        Moment on A about the world origin, N m.

    Raises
    ------
    MeshError
        If a mesh has the wrong shape, bad indices, or an inverted or degenerate tetrahedron.
    KernelOverflowError
        If the clipping buffer overflowed (not expected; see ``SOUP_CAPACITY``).

    References
    ----------
    Munjiza & Andrews (2000), eq. 6; Munjiza (2004), ch. 2.
    """
    penalty = _checked_penalty(penalty)
    nodes_a, tets_a = _checked_mesh(nodes_a, tets_a, "body A")
    nodes_b, tets_b = _checked_mesh(nodes_b, tets_b, "body B")
    pairs = _box_pairs(nodes_a, tets_a, nodes_b, tets_b)
    work = _Workspace()
    failed = _sum_body_contact(nodes_a, tets_a, nodes_b, tets_b, pairs, work.tet_c, work.tet_t,
                               work.sub_c, work.sub_t, work.grads_c, work.grads_t,
                               work.centroid_c, work.centroid_t, work.soup_a, work.soup_b,
                               work.distances, work.wedge, work.order, work.normal, work.moment,
                               work.pair_result, work.total)
    if failed >= 0:
        i, j = pairs[failed]
        raise KernelOverflowError(_overflow_message(f"tet {i} of body A against tet {j} of body B"))
    return penalty * work.total[:3].copy(), penalty * work.total[3:].copy()


def reference_wall_contact(nodes, tets, *, point, normal, wall_potential_depth, penalty):
    """Potential contact force and moment on a body from a half-space wall (slow reference).

    The wall is ``{x : n·(x - point) < 0}`` with potential ``phi_W = -n·(x - point) / h_W``, so
    ``F = p sum_c ∫_{c ∩ wall} (grad phi_c + n / h_W) dV`` and ``M`` the same integral of
    ``x × (...)``.

    Parameters
    ----------
    nodes : array_like, shape (n_nodes, 3)
        World coordinates of the nodes, m.
    tets : array_like of int, shape (n_tets, 4)
        Positively oriented tetrahedra (node indices).
    point : array_like, shape (3,)
        A point on the wall surface, m.
    normal : array_like, shape (3,)
        Normal of the wall surface pointing out of the wall into free space; normalised here.
    wall_potential_depth : float
        Depth ``h_W`` at which the wall potential reaches 1, m.
    penalty : float
        Contact penalty ``p``, Pa.

    Returns
    -------
    force : ndarray, shape (3,)
        Force on the body, N.
    moment : ndarray, shape (3,)
        Moment on the body about the world origin, N m.
    """
    penalty = _checked_penalty(penalty)
    nodes, tets = _checked_mesh(nodes, tets, "body")
    point = np.asarray(point, dtype=np.float64).reshape(-1)
    normal = np.asarray(normal, dtype=np.float64).reshape(-1)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise CaseFileError(f"wall point must be three finite coordinates in m, got {point}")
    length = np.linalg.norm(normal) if normal.shape == (3,) else 0.0
    if not (np.isfinite(length) and length > 0.0):
        raise CaseFileError(f"wall normal must be a non-zero finite 3-vector, got {normal}")
    normal = normal / length
    wall_potential_depth = float(wall_potential_depth)
    if not (np.isfinite(wall_potential_depth) and wall_potential_depth > 0.0):
        raise CaseFileError("wall_potential_depth must be a positive, finite length in m, "
                            f"got {wall_potential_depth}")
    work = _Workspace()
    failed = _sum_wall_contact(nodes, tets, point, normal, wall_potential_depth, work.tet_c,
                               work.sub_c, work.grads_c, work.centroid_c, work.soup_a,
                               work.soup_b, work.distances, work.wedge, work.order, work.normal,
                               work.moment, work.total)
    if failed >= 0:
        raise KernelOverflowError(_overflow_message(f"tet {failed} of the body by the wall"))
    return penalty * work.total[:3].copy(), penalty * work.total[3:].copy()
