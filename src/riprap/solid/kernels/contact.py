"""Munjiza's distributed potential contact between rigid tetrahedral bodies: the fast path.

Symbols (Munjiza 2004; seed paper eq. 6):

============  ===============================================================
``p``         contact penalty (Pa), ``contact_penalty``
``phi``       potential of a tet: 4 min_k lambda_k (0 on its faces, 1 at its centroid)
``lam``       barycentric coordinates lambda_k of a point in a tet
``n``         unit outward normal of a boundary triangle
============  ===============================================================

The force on body A from body B is  F_A = p sum_{c in A, t in B} int_{c cap t} (grad phi_c - grad
phi_t) dV.  By the divergence theorem it equals the boundary form

    F_A = -p int_{dA cap B} phi_B n_A dS  +  p int_{dB cap A} phi_A n_B dS,

where phi_B is the piecewise potential of B's tets. Faces shared by two tets of the same body cancel
(same points, same phi, opposite normals), so only the *boundary* triangles of each body enter. The
moments agree too (int x x grad phi dV = oint phi x x n dS), so force and torque are exact, not an
approximation of the volume form: ``kernels/reference.py`` evaluates the volume form tet by tet and
the tests require agreement to round-off. The integrand is linear on each (triangle, sub-tet) piece
and is integrated in closed form.

For rigid bodies everything is evaluated in the frame of the body whose potential is used, where the
barycentric maps, triangle clusters and the tet lookup grid are precomputed (``solid/shape.py``).
"""
import numpy as np

from riprap._jit import kernel, leaf_kernel
from riprap.solid.kernels.bundles import PairWork, Scratch
from riprap.solid.kernels.geometry_ops import (MAX_POLYGON, clip_polygon, integrate_linear_on_polygon,
                                               integrate_tet_potential_on_polygon,
                                               integrate_tet_potential_on_triangle, mat3_mul_transposed,
                                               mat3_vec, mat3_transposed_vec)

MAX_CANDIDATE_TETS = 1024
# (triangle, tet) pieces one pair may list: a buffer per thread, overflow is reported.
MAX_PAIR_PIECES = 65536
# Output of a pair evaluation: [0:3] force on A, [3:6] torque on A, [6:9] torque on B, [9:12]
# contact point, [12] stiffness, [13] overflow, [14] contact area (m^2, mean of the two surfaces).
OUT_SIZE = 22
# [15:21] second moment of the contact pressure about the contact point (world; xx, yy, zz, xy,
# xz, yz; N m^2 per unit... weighted by p phi dS), [21] total weight p int phi dS.
# Result layout of one directional evaluation (surface of S in the potential of P), in P's frame.
R_FORCE = 0        # 3: force on the surface body
R_MOMENT = 3       # 3: moment of that force about P's centroid
R_WEIGHT = 6       # p int phi dS (force-weighted point denominator)
R_POINT = 7        # 3: p int x phi dS
R_STIFFNESS = 10   # p int |grad phi . n| dS
R_AREA = 11        # area of the surface inside P
R_OVERFLOW = 12    # > 0 if the candidate buffer overflowed
R_TRIANGLES = 13   # diagnostics: triangles that reached the tet lookup
R_CANDIDATES = 14  # diagnostics: candidate tets tested
R_CLIPPED = 15     # diagnostics: (triangle, tet) pairs integrated
R_SECOND = 16      # 6: p sum M1 M1^T / M0 over pieces (xx, yy, zz, xy, xz, yz): second moment of
                   # the contact pressure with each piece lumped at its centroid
R_SIZE = 22


@kernel
def make_scratch(max_tets):
    """Work arrays of one thread (:class:`~riprap.solid.kernels.bundles.Scratch`), allocated once
    per batch of pairs (allocation inside the pair loop costs more than the geometry)."""
    work = PairWork(np.empty(MAX_POLYGON), np.zeros(6), np.empty((3, 3)), np.empty((3, 4)),
                    np.empty(3), np.empty((3, MAX_POLYGON, 2)), np.zeros(R_SIZE))
    return Scratch(np.empty((MAX_POLYGON, 7)), np.empty((MAX_POLYGON, 7)),
                   np.empty((MAX_POLYGON, 7)), work, np.empty(3),
                   np.empty(MAX_CANDIDATE_TETS, dtype=np.int64),
                   np.full(max(max_tets, 1), -1, dtype=np.int64), np.zeros(1, dtype=np.int64),
                   np.empty(3), np.empty(3), np.empty(3, dtype=np.int64),
                   np.empty(3, dtype=np.int64), np.empty(4),
                   np.empty((MAX_PAIR_PIECES, 2), dtype=np.int64))


@leaf_kernel
def collect_pieces(surface_shape, potential_shape, rotation, translation, skin, shapes, scratch,
                   pieces, n_pieces, result):
    """List the (boundary triangle of the surface body, tet of the potential body) pairs that
    can overlap, appending rows (local triangle, local tet) to ``pieces`` from row ``n_pieces``;
    returns the new row count. ``shapes``: :class:`~riprap.solid.kernels.bundles.Shapes`;
    ``scratch``: ``make_scratch``'s work arrays.

    With ``skin`` > 0 every test is widened by ``skin`` (m): the list then holds every pair that can
    overlap after the surface body has moved, relative to the potential body, by up to ``skin`` at
    every point, so that it can be reused for as long as the relative motion stays below that.
    Widening only adds pairs, whose integral is exactly zero, so the force does not depend on it.
    Rows come out ordered by triangle, then tet, whatever the skin.

    A leaf kernel (no reference counts): it is called twice per pair, and taking a reference to
    each of the bundles' arrays on every call would cost more than reading them.
    """
    node_offset, nodes, tet_offset, tets, barycentric, triangle_offset, triangles, \
        triangle_normals = shapes.mesh
    (triangle_centres, triangle_radii, cluster_offset, cluster_begin, cluster_end, cluster_centres,
     cluster_radii, grid_origin, grid_cell_size, grid_dims, cell_offset, cell_start_offset,
     cell_start, cell_tets_offset, cell_tets, cell_clearance, local_box_min, local_box_max, _,
     tet_boxes, _) = shapes.lookup
    sp = potential_shape
    ss = surface_shape
    origin = grid_origin[sp]
    cell = grid_cell_size[sp]
    nx = grid_dims[sp, 0]
    ny = grid_dims[sp, 1]
    nz = grid_dims[sp, 2]
    coff = cell_offset[sp]
    csoff = cell_start_offset[sp]
    ctoff = cell_tets_offset[sp]
    noff_s = node_offset[ss]
    noff_p = node_offset[sp]
    toff_p = tet_offset[sp]
    troff = triangle_offset[ss]
    capacity = pieces.shape[0]

    _, _, vertices, lam, normal, _, _ = scratch.work
    (_, _, _, _, centre, candidates, stamp, counter, tri_lo, tri_hi, i_lo, i_hi, _,
     _) = scratch
    # the potential body's box, taken once: a slice per call in the loops below cost an atomic
    # reference count each way, shared by the threads
    shape_lo = local_box_min[sp]
    shape_hi = local_box_max[sp]
    # stamp[t] == counter means tet t is already listed for the current triangle: O(1)
    # de-duplication; the counter keeps growing across calls so stale stamps never match.

    for cl in range(cluster_offset[ss], cluster_offset[ss + 1]):
        for c in range(3):
            centre[c] = (rotation[c, 0] * cluster_centres[cl, 0] + rotation[c, 1] * cluster_centres[cl, 1]
                         + rotation[c, 2] * cluster_centres[cl, 2] + translation[c])
        if _sphere_far(centre, cluster_radii[cl] + skin, origin, cell, nx, ny, nz,
                       cell_clearance, coff, shape_lo, shape_hi):
            continue
        for tri_local in range(cluster_begin[cl], cluster_end[cl]):
            tri = troff + tri_local
            for c in range(3):
                centre[c] = (rotation[c, 0] * triangle_centres[tri, 0] + rotation[c, 1] * triangle_centres[tri, 1]
                             + rotation[c, 2] * triangle_centres[tri, 2] + translation[c])
            if _sphere_far(centre, triangle_radii[tri] + skin, origin, cell, nx, ny, nz,
                           cell_clearance, coff, shape_lo, shape_hi):
                continue
            _place_triangle(rotation, translation, nodes, noff_s, triangles, triangle_normals, tri,
                            vertices, normal)
            # Candidate tets: those listed in the grid cells the triangle's (widened) box touches.
            n_candidates = 0
            counter[0] += 1
            mark = counter[0]
            for c in range(3):
                lo = min(vertices[0, c], min(vertices[1, c], vertices[2, c])) - skin
                hi = max(vertices[0, c], max(vertices[1, c], vertices[2, c])) + skin
                tri_lo[c] = lo
                tri_hi[c] = hi
                a = int(np.floor((lo - origin[c]) / cell))
                b = int(np.floor((hi - origin[c]) / cell))
                n_axis = grid_dims[sp, c]
                i_lo[c] = max(a, 0)
                i_hi[c] = min(b, n_axis - 1)
            if i_lo[0] > i_hi[0] or i_lo[1] > i_hi[1] or i_lo[2] > i_hi[2]:
                continue
            result[R_TRIANGLES] += 1.0
            for ix in range(i_lo[0], i_hi[0] + 1):
                for iy in range(i_lo[1], i_hi[1] + 1):
                    for iz in range(i_lo[2], i_hi[2] + 1):
                        cell_id = (ix * ny + iy) * nz + iz
                        for e in range(cell_start[csoff + cell_id], cell_start[csoff + cell_id + 1]):
                            t = cell_tets[ctoff + e]
                            if stamp[t] == mark:
                                continue
                            stamp[t] = mark
                            tb = toff_p + t
                            if (tet_boxes[tb, 0] > tri_hi[0] or tet_boxes[tb, 3] < tri_lo[0]
                                    or tet_boxes[tb, 1] > tri_hi[1] or tet_boxes[tb, 4] < tri_lo[1]
                                    or tet_boxes[tb, 2] > tri_hi[2] or tet_boxes[tb, 5] < tri_lo[2]):
                                continue
                            if _separated(barycentric, toff_p + t, vertices, normal, nodes, noff_p,
                                          tets, skin, lam):
                                continue
                            if n_candidates < MAX_CANDIDATE_TETS:
                                candidates[n_candidates] = t
                                n_candidates += 1
                            else:
                                result[R_OVERFLOW] += 1.0
            result[R_CANDIDATES] += n_candidates
            # Ascending tet order: the integration order (and so the round-off) is then the same
            # whatever cells, skin or earlier poses produced the list.
            for q in range(1, n_candidates):
                value = candidates[q]
                r = q - 1
                while r >= 0 and candidates[r] > value:
                    candidates[r + 1] = candidates[r]
                    r -= 1
                candidates[r + 1] = value
            for q in range(n_candidates):
                if n_pieces < capacity:
                    pieces[n_pieces, 0] = tri_local
                    pieces[n_pieces, 1] = candidates[q]
                    n_pieces += 1
                else:
                    result[R_OVERFLOW] += 1.0
    return n_pieces


@leaf_kernel
def _place_triangle(rotation, translation, nodes, node_offset, triangles, triangle_normals, tri,
                    vertices, normal):
    """Vertices and unit normal of boundary triangle ``tri`` moved by (rotation, translation)."""
    for v in range(3):
        node = node_offset + triangles[tri, v]
        for c in range(3):
            vertices[v, c] = (rotation[c, 0] * nodes[node, 0] + rotation[c, 1] * nodes[node, 1]
                              + rotation[c, 2] * nodes[node, 2] + translation[c])
    for c in range(3):
        normal[c] = (rotation[c, 0] * triangle_normals[tri, 0] + rotation[c, 1] * triangle_normals[tri, 1]
                     + rotation[c, 2] * triangle_normals[tri, 2])


@leaf_kernel
def _separated(barycentric, t, vertices, normal, nodes, noff_p, tets, skin, lam):
    """True when triangle ``vertices`` stays more than ``skin`` away from tet ``t``: all three
    vertices beyond one face plane, or all four tet nodes on one side of the triangle's plane.
    When False, ``lam`` (3, 4) holds the barycentrics of the three vertices."""
    for k in range(4):
        # lambda_k < -skin |grad lambda_k| means more than ``skin`` beyond the face plane.
        limit = 0.0
        if skin > 0.0:
            limit = -skin * np.sqrt(barycentric[t, k, 0] ** 2 + barycentric[t, k, 1] ** 2
                                    + barycentric[t, k, 2] ** 2)
        all_out = True
        for v in range(3):
            value = (barycentric[t, k, 0] * vertices[v, 0] + barycentric[t, k, 1] * vertices[v, 1]
                     + barycentric[t, k, 2] * vertices[v, 2] + barycentric[t, k, 3])
            lam[v, k] = value
            if value > limit:
                all_out = False
        if all_out:
            return True
    # The triangle's own plane separates when all four tet nodes lie on one side.
    above = 0
    below = 0
    for k in range(4):
        node = noff_p + tets[t, k]
        side = ((nodes[node, 0] - vertices[0, 0]) * normal[0]
                + (nodes[node, 1] - vertices[0, 1]) * normal[1]
                + (nodes[node, 2] - vertices[0, 2]) * normal[2])
        if side > skin:
            above += 1
        elif side < -skin:
            below += 1
    return above == 4 or below == 4


@leaf_kernel
def integrate_pieces(surface_shape, potential_shape, rotation, translation, penalty, mesh, work,
                     pieces, first, last):
    """Integrate the potential of ``potential_shape`` over the listed (triangle, tet) pieces of
    ``surface_shape``'s boundary (rows ``first:last`` of ``pieces``), at the relative pose
    ``rotation``, ``translation``. Adds to ``work.res`` (layout R_*) in the potential body's
    frame. ``mesh``: :class:`~riprap.solid.kernels.bundles.ShapeMesh`; ``work``:
    :class:`~riprap.solid.kernels.bundles.PairWork`. A leaf kernel: its bundles cost no reference
    counts, though it runs once per direction of every pair."""
    node_offset, nodes, tet_offset, tets, barycentric, triangle_offset, triangles, \
        triangle_normals = mesh
    signed, moments, vertices, lam, normal, polygons, result = work
    sp = potential_shape
    ss = surface_shape
    noff_s = node_offset[ss]
    noff_p = node_offset[sp]
    toff_p = tet_offset[sp]
    troff = triangle_offset[ss]
    current = -1
    for q in range(first, last):
        tri_local = pieces[q, 0]
        if tri_local != current:
            current = tri_local
            _place_triangle(rotation, translation, nodes, noff_s, triangles, triangle_normals,
                            troff + tri_local, vertices, normal)
        t = toff_p + pieces[q, 1]
        if _separated(barycentric, t, vertices, normal, nodes, noff_p, tets, 0.0, lam):
            continue
        for m in range(6):
            moments[m] = 0.0
        result[R_CLIPPED] += 1.0
        integrate_tet_potential_on_triangle(lam, vertices, barycentric, t, normal, polygons,
                                            signed, moments)
        if moments[0] <= 0.0:
            continue
        # Force on the surface body: -p phi n dS; moment about the potential body's centroid.
        result[R_FORCE + 0] += -penalty * moments[0] * normal[0]
        result[R_FORCE + 1] += -penalty * moments[0] * normal[1]
        result[R_FORCE + 2] += -penalty * moments[0] * normal[2]
        mx = moments[1]
        my = moments[2]
        mz = moments[3]
        result[R_MOMENT + 0] += -penalty * (my * normal[2] - mz * normal[1])
        result[R_MOMENT + 1] += -penalty * (mz * normal[0] - mx * normal[2])
        result[R_MOMENT + 2] += -penalty * (mx * normal[1] - my * normal[0])
        result[R_WEIGHT] += penalty * moments[0]
        result[R_POINT + 0] += penalty * mx
        result[R_POINT + 1] += penalty * my
        result[R_POINT + 2] += penalty * mz
        result[R_STIFFNESS] += penalty * moments[5]
        result[R_AREA] += moments[4]
        _add_second_moment(result, R_SECOND, penalty, moments)


@leaf_kernel
def _add_second_moment(target, at, penalty, moments):
    """Add p M1 M1^T / M0 of one integrated piece (lumped at its centroid)."""
    if moments[0] <= 0.0:
        return
    scale = penalty / moments[0]
    target[at + 0] += scale * moments[1] * moments[1]
    target[at + 1] += scale * moments[2] * moments[2]
    target[at + 2] += scale * moments[3] * moments[3]
    target[at + 3] += scale * moments[1] * moments[2]
    target[at + 4] += scale * moments[1] * moments[3]
    target[at + 5] += scale * moments[2] * moments[3]


@kernel
def _second_moment_to_world(local, weight, first, rotation, translation, total):
    """Rotate and translate a second moment S = sum w x x^T (6 comps) with first moment ``first``
    (sum w x, local) and weight sum w into the world, adding to ``total`` (3x3)."""
    s = np.empty((3, 3))
    s[0, 0] = local[0]
    s[1, 1] = local[1]
    s[2, 2] = local[2]
    s[0, 1] = s[1, 0] = local[3]
    s[0, 2] = s[2, 0] = local[4]
    s[1, 2] = s[2, 1] = local[5]
    rf = mat3_vec(rotation, first)
    for i in range(3):
        for j in range(3):
            value = 0.0
            for a in range(3):
                for b in range(3):
                    value += rotation[i, a] * s[a, b] * rotation[j, b]
            total[i, j] += (value + rf[i] * translation[j] + translation[i] * rf[j]
                            + weight * translation[i] * translation[j])


@kernel
def _store_spread(total, weight, point, out):
    """out[15:21] = second moment about the contact point, out[21] = weight."""
    if weight <= 0.0:
        return
    out[15] = total[0, 0] - weight * point[0] * point[0]
    out[16] = total[1, 1] - weight * point[1] * point[1]
    out[17] = total[2, 2] - weight * point[2] * point[2]
    out[18] = total[0, 1] - weight * point[0] * point[1]
    out[19] = total[0, 2] - weight * point[0] * point[2]
    out[20] = total[1, 2] - weight * point[1] * point[2]
    out[21] = weight


@leaf_kernel
def _sphere_far(centre, radius, origin, cell, nx, ny, nz, clearance, coff, shape_lo, shape_hi):
    """True when a sphere cannot touch the body (outside its box, or in a cell far from it)."""
    gap2 = 0.0
    for c in range(3):
        if centre[c] < shape_lo[c]:
            d = shape_lo[c] - centre[c]
            gap2 += d * d
        elif centre[c] > shape_hi[c]:
            d = centre[c] - shape_hi[c]
            gap2 += d * d
    if gap2 > radius * radius:
        return True
    ix = int(np.floor((centre[0] - origin[0]) / cell))
    iy = int(np.floor((centre[1] - origin[1]) / cell))
    iz = int(np.floor((centre[2] - origin[2]) / cell))
    if ix < 0 or iy < 0 or iz < 0 or ix >= nx or iy >= ny or iz >= nz:
        return False
    return clearance[coff + (ix * ny + iy) * nz + iz] > radius


@kernel
def body_pair_potential_force(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b,
                              penalty, shapes, out):
    """Potential (normal) contact between two rigid bodies, both directions of the boundary form.
    ``shapes``: :class:`~riprap.solid.kernels.bundles.Shapes`.

    ``out`` (14,): [0:3] force on A (world), [3:6] torque on A about its centroid, [6:9] torque on B
    about its centroid, [9:12] force-weighted contact point, [12] stiffness (N/m), [13] overflow.
    """
    scratch = make_scratch(shapes.mesh.tets.shape[0])
    full = np.zeros(OUT_SIZE)
    pair_potential_force(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b, penalty,
                         shapes, scratch, full)
    for i in range(min(out.shape[0], OUT_SIZE)):
        out[i] = full[i]


@kernel
def pair_potential_force(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b,
                         penalty, shapes, scratch, out):
    """:func:`body_pair_potential_force` with caller-provided work arrays; ``out`` (OUT_SIZE,)."""
    pieces = scratch.pieces
    split, last, overflow = collect_pair_pieces(shape_a, shape_b, position_a, rotation_a,
                                                position_b, rotation_b, 0.0, shapes,
                                                scratch, pieces, 0)
    pair_force_from_pieces(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b,
                           penalty, shapes.mesh, scratch.work, pieces, 0, split, last, out)
    out[13] += overflow


@kernel
def relative_pose(position_a, rotation_a, position_b, rotation_b):
    """(rotation, translation) mapping A's frame into B's, and B's into A's."""
    d = position_a - position_b
    return (mat3_mul_transposed(rotation_b, rotation_a), mat3_transposed_vec(rotation_b, d),
            mat3_mul_transposed(rotation_a, rotation_b), mat3_transposed_vec(rotation_a, -d))


@kernel
def collect_pair_pieces(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b, skin,
                        shapes, scratch, pieces, first):
    """The (triangle, tet) pieces of both directions of a pair (:func:`collect_pieces`), written
    to ``pieces`` from row ``first``: A's triangles in B's tets, then B's in A's.
    Returns (row where the second direction starts, row after the last, overflow count)."""
    rotation_1, translation_1, rotation_2, translation_2 = relative_pose(position_a, rotation_a,
                                                                          position_b, rotation_b)
    counters = scratch.work.res
    counters[:] = 0.0
    split = collect_pieces(shape_a, shape_b, rotation_1, translation_1, skin, shapes, scratch,
                           pieces, first, counters)
    last = collect_pieces(shape_b, shape_a, rotation_2, translation_2, skin, shapes, scratch,
                          pieces, split, counters)
    return split, last, counters[R_OVERFLOW]


@kernel
def pair_force_from_pieces(shape_a, shape_b, position_a, rotation_a, position_b, rotation_b,
                           penalty, mesh, work, pieces, first, split, last, out):
    """Potential contact of a pair from its listed pieces (rows ``first:split`` A's triangles in
    B's tets, ``split:last`` B's in A's); ``out`` (OUT_SIZE,) as for
    :func:`body_pair_potential_force`. ``mesh``: the shapes'
    :class:`~riprap.solid.kernels.bundles.ShapeMesh` (not the whole ``Shapes``: called per pair,
    it takes a reference to each array it is given); ``work``: ``make_scratch``'s
    :class:`~riprap.solid.kernels.bundles.PairWork`.

    14 arguments: the two bodies' (shape, position, rotation) and the pair's penalty are per-pair
    scalars and views that change every call; bundling them would build a tuple per pair."""
    res = work.res
    for i in range(OUT_SIZE):
        out[i] = 0.0
    weight = 0.0
    point = np.zeros(3)
    stiffness = 0.0
    area = 0.0
    second = np.zeros((3, 3))
    d = position_a - position_b
    rotation_1, translation_1, rotation_2, translation_2 = relative_pose(position_a, rotation_a,
                                                                          position_b, rotation_b)
    # Direction 1: A's surface in B's potential, evaluated in B's frame.
    res[:] = 0.0
    integrate_pieces(shape_a, shape_b, rotation_1, translation_1, penalty, mesh, work, pieces,
                     first, split)
    force1 = mat3_vec(rotation_b, res[R_FORCE:R_FORCE + 3])          # on A
    moment1 = mat3_vec(rotation_b, res[R_MOMENT:R_MOMENT + 3])       # about B's centroid
    # torque on A about its centroid: moment about B's centroid + (x_B - x_A) x F
    torque_a = moment1 + np.cross(-d, force1)
    torque_b = -moment1
    force_a = force1.copy()
    if res[R_WEIGHT] > 0.0:
        weight += res[R_WEIGHT]
        point += mat3_vec(rotation_b, res[R_POINT:R_POINT + 3]) + position_b * res[R_WEIGHT]
        _second_moment_to_world(res[R_SECOND:R_SECOND + 6], res[R_WEIGHT],
                                res[R_POINT:R_POINT + 3], rotation_b, position_b, second)
    stiffness += res[R_STIFFNESS]
    area += res[R_AREA]
    # Direction 2: B's surface in A's potential, evaluated in A's frame.
    res[:] = 0.0
    integrate_pieces(shape_b, shape_a, rotation_2, translation_2, penalty, mesh, work, pieces,
                     split, last)
    force2 = mat3_vec(rotation_a, res[R_FORCE:R_FORCE + 3])          # on B
    moment2 = mat3_vec(rotation_a, res[R_MOMENT:R_MOMENT + 3])       # about A's centroid
    force_a -= force2
    torque_a -= moment2
    torque_b += moment2 + np.cross(d, force2)
    if res[R_WEIGHT] > 0.0:
        weight += res[R_WEIGHT]
        point += mat3_vec(rotation_a, res[R_POINT:R_POINT + 3]) + position_a * res[R_WEIGHT]
        _second_moment_to_world(res[R_SECOND:R_SECOND + 6], res[R_WEIGHT],
                                res[R_POINT:R_POINT + 3], rotation_a, position_a, second)
    stiffness += res[R_STIFFNESS]
    area += res[R_AREA]
    out[0:3] = force_a
    out[3:6] = torque_a
    out[6:9] = torque_b
    if weight > 0.0:
        out[9:12] = point / weight
        _store_spread(second, weight, out[9:12], out)
    out[12] = stiffness
    out[13] = 0.0
    out[14] = 0.5 * area


@kernel
def body_wall_potential_force(shape, position, rotation, wall_point, wall_normal, penalty,
                              shapes, out):
    """Potential contact between a rigid body and a half-space wall (see
    :func:`wall_potential_force`)."""
    scratch = make_scratch(1)
    full = np.zeros(OUT_SIZE)
    wall_potential_force(shape, position, rotation, wall_point, wall_normal, penalty, shapes,
                         scratch, full)
    for i in range(min(out.shape[0], OUT_SIZE)):
        out[i] = full[i]


@kernel
def wall_potential_force(shape, position, rotation, wall_point, wall_normal, penalty,
                         shapes, scratch, out):
    """Potential contact between a rigid body and a half-space wall.

    The wall is {x : n.(x - point) < 0}; its potential rises linearly with depth over the body's
    ``wall_potential_depth`` (as if the wall were meshed like the body). Boundary form:
    F = -p int_{dA in wall} phi_W n_A dS + p int_{wall plane in A} phi_A n dS.
    ``shapes``: :class:`~riprap.solid.kernels.bundles.Shapes`; ``out`` as for
    :func:`body_pair_potential_force` with [6:9] unused.
    """
    area = 0.0
    local_second = np.zeros(6)
    (node_offset, nodes, tet_offset, tets, barycentric, triangle_offset, triangles,
     triangle_normals) = shapes.mesh
    triangle_centres = shapes.lookup.triangle_centres
    triangle_radii = shapes.lookup.triangle_radii
    wall_potential_depth = shapes.lookup.wall_potential_depth
    for i in range(OUT_SIZE):
        out[i] = 0.0
    # The plane in the body frame: n_b . y = offset; inside the wall where n_b . y < offset.
    n_b = mat3_transposed_vec(rotation, wall_normal)
    offset = 0.0
    for c in range(3):
        offset += wall_normal[c] * (wall_point[c] - position[c])
    h_wall = wall_potential_depth[shape]
    force = np.zeros(3)
    moment = np.zeros(3)
    point = np.zeros(3)
    weight = 0.0
    stiffness = 0.0
    polygon = scratch.polygon
    work_a = scratch.work_a
    work_b = scratch.work_b
    signed = scratch.work.signed
    moments = scratch.work.moments
    noff = node_offset[shape]
    # (i) boundary triangles inside the wall, weighted by the wall potential depth / h_wall.
    for tri in range(triangle_offset[shape], triangle_offset[shape + 1]):
        depth_centre = offset - (n_b[0] * triangle_centres[tri, 0] + n_b[1] * triangle_centres[tri, 1]
                                 + n_b[2] * triangle_centres[tri, 2])
        if depth_centre < -triangle_radii[tri]:
            continue
        for v in range(3):
            node = noff + triangles[tri, v]
            for c in range(3):
                polygon[v, c] = nodes[node, c]
            depth = offset - (n_b[0] * nodes[node, 0] + n_b[1] * nodes[node, 1] + n_b[2] * nodes[node, 2])
            polygon[v, 3] = depth
            for c in range(4, 7):
                polygon[v, c] = 0.0
            signed[v] = depth
        m = clip_polygon(polygon, 3, signed, work_a)
        if m < 3:
            continue
        for i in range(6):
            moments[i] = 0.0
        normal = triangle_normals[tri]
        integrate_linear_on_polygon(work_a, m, 3, 1.0 / h_wall, normal, moments)
        if moments[0] <= 0.0:
            continue
        for c in range(3):
            force[c] -= penalty * moments[0] * normal[c]
        moment[0] -= penalty * (moments[2] * normal[2] - moments[3] * normal[1])
        moment[1] -= penalty * (moments[3] * normal[0] - moments[1] * normal[2])
        moment[2] -= penalty * (moments[1] * normal[1] - moments[2] * normal[0])
        weight += penalty * moments[0]
        for c in range(3):
            point[c] += penalty * moments[1 + c]
        _add_second_moment(local_second, 0, penalty, moments)
        cos = abs(n_b[0] * normal[0] + n_b[1] * normal[1] + n_b[2] * normal[2])
        stiffness += penalty * moments[4] * cos / h_wall
        area += moments[4]
    # (ii) the wall plane inside the body's tets, weighted by the body's potential.
    toff = tet_offset[shape]
    depths = scratch.depths
    for t_local in range(tet_offset[shape + 1] - toff):
        t = toff + t_local
        n_in = 0
        for k in range(4):
            node = noff + tets[t, k]
            depths[k] = offset - (n_b[0] * nodes[node, 0] + n_b[1] * nodes[node, 1] + n_b[2] * nodes[node, 2])
            if depths[k] > 0.0:
                n_in += 1
        if n_in == 0 or n_in == 4:
            continue
        m = plane_section(nodes, noff, tets, t, depths, n_b, polygon)
        if m < 3:
            continue
        for i in range(6):
            moments[i] = 0.0
        integrate_tet_potential_on_polygon(polygon, m, barycentric[t, :, 0:3], n_b,
                                           work_a, work_b, signed, moments)
        if moments[0] <= 0.0:
            continue
        for c in range(3):
            force[c] += penalty * moments[0] * n_b[c]
        moment[0] += penalty * (moments[2] * n_b[2] - moments[3] * n_b[1])
        moment[1] += penalty * (moments[3] * n_b[0] - moments[1] * n_b[2])
        moment[2] += penalty * (moments[1] * n_b[1] - moments[2] * n_b[0])
        weight += penalty * moments[0]
        for c in range(3):
            point[c] += penalty * moments[1 + c]
        _add_second_moment(local_second, 0, penalty, moments)
        stiffness += penalty * moments[5]
        area += moments[4]
    out[0:3] = mat3_vec(rotation, force)
    out[3:6] = mat3_vec(rotation, moment)
    if weight > 0.0:
        out[9:12] = mat3_vec(rotation, point / weight) + position
        second = np.zeros((3, 3))
        _second_moment_to_world(local_second, weight, point, rotation, position, second)
        _store_spread(second, weight, out[9:12], out)
    out[12] = stiffness
    out[14] = 0.5 * area


@kernel
def plane_section(nodes, noff, tets, t, depths, normal, polygon):
    """Polygon where the plane depth = 0 cuts tet t, counter-clockwise about ``normal``, with the
    barycentric coordinates of each vertex in columns 3-6. Returns the vertex count (3 or 4)."""
    m = 0
    for a in range(4):
        for b in range(a + 1, 4):
            da = depths[a]
            db = depths[b]
            if (da > 0.0) != (db > 0.0):
                s = da / (da - db)
                na = noff + tets[t, a]
                nb = noff + tets[t, b]
                for c in range(3):
                    polygon[m, c] = nodes[na, c] + s * (nodes[nb, c] - nodes[na, c])
                for k in range(4):
                    polygon[m, 3 + k] = 0.0
                polygon[m, 3 + a] = 1.0 - s
                polygon[m, 3 + b] = s
                m += 1
    if m == 4:
        # Order the quadrilateral by angle about its centre in the plane.
        cx = 0.25 * (polygon[0, 0] + polygon[1, 0] + polygon[2, 0] + polygon[3, 0])
        cy = 0.25 * (polygon[0, 1] + polygon[1, 1] + polygon[2, 1] + polygon[3, 1])
        cz = 0.25 * (polygon[0, 2] + polygon[1, 2] + polygon[2, 2] + polygon[3, 2])
        ux = polygon[0, 0] - cx
        uy = polygon[0, 1] - cy
        uz = polygon[0, 2] - cz
        vx = normal[1] * uz - normal[2] * uy
        vy = normal[2] * ux - normal[0] * uz
        vz = normal[0] * uy - normal[1] * ux
        angles = np.empty(4)
        for i in range(4):
            px = polygon[i, 0] - cx
            py = polygon[i, 1] - cy
            pz = polygon[i, 2] - cz
            angles[i] = np.arctan2(px * vx + py * vy + pz * vz, px * ux + py * uy + pz * uz)
        order = np.argsort(angles)
        copy = polygon[:4, :].copy()
        for i in range(4):
            for c in range(7):
                polygon[i, c] = copy[order[i], c]
    elif m == 3:
        ax = polygon[1, 0] - polygon[0, 0]
        ay = polygon[1, 1] - polygon[0, 1]
        az = polygon[1, 2] - polygon[0, 2]
        bx = polygon[2, 0] - polygon[0, 0]
        by = polygon[2, 1] - polygon[0, 1]
        bz = polygon[2, 2] - polygon[0, 2]
        orient = ((ay * bz - az * by) * normal[0] + (az * bx - ax * bz) * normal[1]
                  + (ax * by - ay * bx) * normal[2])
        if orient < 0.0:
            for c in range(7):
                tmp = polygon[1, c]
                polygon[1, c] = polygon[2, c]
                polygon[2, c] = tmp
    return m
