"""Munjiza's potential contact on deformed tetrahedra, with the forces spread to the nodes.

Boundary form (see ``riprap/solid/kernels/contact.py`` for the derivation): the force on body A
from body B is

    F_A = -p int_{dA cap B} phi_B n_A dS  +  p int_{dB cap A} phi_A n_B dS,

with phi_t = 4 min_k lambda_k the potential of tet t (lambda its barycentric coordinates) and n the
outward normal of a boundary triangle. Each elementary force -p phi_t n_T dS at a point x of a
boundary triangle T inside a tet t is applied to T's three nodes with T's linear shape functions
N_v(x) and, opposite, to t's four nodes with lambda_k(x). Both sets of weights sum to one and
interpolate x exactly, so the pair's forces are equal and opposite and their moments cancel: the
contact conserves linear and angular momentum to round-off, node by node.

On each (triangle, tet) piece the integrands phi N_v and phi lambda_k are products of two linear
functions once the piece is cut where another lambda becomes the smallest; they are integrated
exactly with the three edge-midpoint rule on the fan triangles of the piece.

Walls (half-spaces {x : n . (x - point) < 0}) act as for rigid bodies: the boundary triangles
inside the wall feel -p (depth / h_w) n_T, and the wall plane inside the body's tets pushes with
p phi_t n, h_w being the depth over which the wall's potential rises.

Polygon columns: 0-2 position, then the linear attributes of each use.
"""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels.contact import plane_section

MAX_VERTICES = 16
N_COLUMNS = 10
# Columns of a triangle-in-tet polygon: 3-5 N_v of the triangle, 6-9 lambda_k of the tet.
_N = 3
_LAMBDA = 6


@kernel
def clip(polygon, n_vertices, signed, n_columns, out):
    """Keep the part of a convex polygon where ``signed`` (per vertex) is >= 0 (Sutherland-Hodgman,
    all columns interpolated linearly). Returns the vertex count of ``out``."""
    m = 0
    for i in range(n_vertices):
        j = i + 1 if i + 1 < n_vertices else 0
        si = signed[i]
        sj = signed[j]
        if si >= 0.0:
            for c in range(n_columns):
                out[m, c] = polygon[i, c]
            m += 1
        if (si >= 0.0) != (sj >= 0.0) and m < MAX_VERTICES:
            t = si / (si - sj)
            for c in range(n_columns):
                out[m, c] = polygon[i, c] + t * (polygon[j, c] - polygon[i, c])
            m += 1
        if m >= MAX_VERTICES:
            break
    return m


@kernel
def product_integrals(polygon, n_vertices, a_column, b_first, n_b, out):
    """out[j] += int polygon[:, a_column] * polygon[:, b_first + j] dA for j < n_b over a planar
    convex polygon (exact: edge-midpoint rule on each fan triangle). Returns the area."""
    total_area = 0.0
    for i in range(1, n_vertices - 1):
        ax = polygon[i, 0] - polygon[0, 0]
        ay = polygon[i, 1] - polygon[0, 1]
        az = polygon[i, 2] - polygon[0, 2]
        bx = polygon[i + 1, 0] - polygon[0, 0]
        by = polygon[i + 1, 1] - polygon[0, 1]
        bz = polygon[i + 1, 2] - polygon[0, 2]
        cx = ay * bz - az * by
        cy = az * bx - ax * bz
        cz = ax * by - ay * bx
        area = 0.5 * np.sqrt(cx * cx + cy * cy + cz * cz)
        if area <= 0.0:
            continue
        total_area += area
        v0 = 0
        v1 = i
        v2 = i + 1
        # midpoints of the three edges
        for (p, q) in ((v0, v1), (v1, v2), (v2, v0)):
            a_mid = 0.5 * (polygon[p, a_column] + polygon[q, a_column])
            for j in range(n_b):
                b_mid = 0.5 * (polygon[p, b_first + j] + polygon[q, b_first + j])
                out[j] += area / 3.0 * a_mid * b_mid
    return total_area


@kernel
def barycentric_map(positions, tet, out):
    """Rows k = (a_k, b_k) with lambda_k(x) = a_k . x + b_k for the tet's current corners, (4, 4).
    Returns False for a flat tet."""
    x0 = positions[tet[0]]
    e = np.empty((3, 3))
    for k in range(3):
        for c in range(3):
            e[c, k] = positions[tet[k + 1], c] - x0[c]
    det = (e[0, 0] * (e[1, 1] * e[2, 2] - e[1, 2] * e[2, 1])
           - e[0, 1] * (e[1, 0] * e[2, 2] - e[1, 2] * e[2, 0])
           + e[0, 2] * (e[1, 0] * e[2, 1] - e[1, 1] * e[2, 0]))
    if det == 0.0:
        return False
    inv = np.linalg.inv(e)
    for k in range(3):
        b = 0.0
        for c in range(3):
            out[k + 1, c] = inv[k, c]
            b -= inv[k, c] * x0[c]
        out[k + 1, 3] = b
    for c in range(4):
        out[0, c] = -(out[1, c] + out[2, c] + out[3, c])
    out[0, 3] += 1.0
    return True


@kernel
def smallest_region(polygon, m, j, first_lambda, n_columns, piece, work, signed):
    """Copy into ``piece`` the part of ``polygon`` where barycentric coordinate j (column
    ``first_lambda + j``) is the smallest of the four, so the tet's potential is 4 lambda_j there.
    Returns the vertex count."""
    for v in range(m):
        for c in range(n_columns):
            piece[v, c] = polygon[v, c]
    mj = m
    for k in range(4):
        if k == j or mj < 3:
            continue
        for v in range(mj):
            signed[v] = piece[v, first_lambda + k] - piece[v, first_lambda + j]
        mj = clip(piece, mj, signed, n_columns, work)
        for v in range(mj):
            for c in range(n_columns):
                piece[v, c] = work[v, c]
    return mj


@kernel
def polygon_normal(polygon):
    """Unnormalised normal (x1 - x0) x (x2 - x0) of the first three vertices and its length."""
    nx = ((polygon[1, 1] - polygon[0, 1]) * (polygon[2, 2] - polygon[0, 2])
          - (polygon[1, 2] - polygon[0, 2]) * (polygon[2, 1] - polygon[0, 1]))
    ny = ((polygon[1, 2] - polygon[0, 2]) * (polygon[2, 0] - polygon[0, 0])
          - (polygon[1, 0] - polygon[0, 0]) * (polygon[2, 2] - polygon[0, 2]))
    nz = ((polygon[1, 0] - polygon[0, 0]) * (polygon[2, 1] - polygon[0, 1])
          - (polygon[1, 1] - polygon[0, 1]) * (polygon[2, 0] - polygon[0, 0]))
    return nx, ny, nz, np.sqrt(nx * nx + ny * ny + nz * nz)


@kernel
def triangle_in_tet(positions, triangle, tet, lam_map, penalty, forces, scratch):
    """Forces of the potential of ``tet`` on the boundary ``triangle`` (outward, counter-clockwise)
    of another body: added to ``forces`` at the triangle's and the tet's nodes. Returns
    (force on the triangle's body along its... magnitude p int phi dS, contact area)."""
    polygon, work, signed, integrals, piece = scratch
    # the triangle's plane normal (outward, unit) and its vertices with N_v and lambda_k
    for v in range(3):
        node = triangle[v]
        for c in range(3):
            polygon[v, c] = positions[node, c]
        for w in range(3):
            polygon[v, _N + w] = 1.0 if w == v else 0.0
        for k in range(4):
            polygon[v, _LAMBDA + k] = (lam_map[k, 0] * positions[node, 0] + lam_map[k, 1] * positions[node, 1]
                                       + lam_map[k, 2] * positions[node, 2] + lam_map[k, 3])
    nx, ny, nz, norm = polygon_normal(polygon)
    if norm == 0.0:
        return 0.0, 0.0
    nx /= norm
    ny /= norm
    nz /= norm
    # inside the tet: lambda_k >= 0 for all k
    m = 3
    for k in range(4):
        for v in range(m):
            signed[v] = polygon[v, _LAMBDA + k]
        m = clip(polygon, m, signed, N_COLUMNS, work)
        if m < 3:
            return 0.0, 0.0
        for v in range(m):
            for c in range(N_COLUMNS):
                polygon[v, c] = work[v, c]
    weight = 0.0
    area = 0.0
    for j in range(4):
        mj = smallest_region(polygon, m, j, _LAMBDA, N_COLUMNS, piece, work, signed)
        if mj < 3:
            continue
        for i in range(7):
            integrals[i] = 0.0
        area += product_integrals(piece, mj, _LAMBDA + j, _N, 3, integrals[0:3])
        product_integrals(piece, mj, _LAMBDA + j, _LAMBDA, 4, integrals[3:7])
        scale = 4.0 * penalty
        for v in range(3):
            node = triangle[v]
            f = scale * integrals[v]
            forces[node, 0] -= f * nx
            forces[node, 1] -= f * ny
            forces[node, 2] -= f * nz
            weight += f
        for k in range(4):
            node = tet[k]
            f = scale * integrals[3 + k]
            forces[node, 0] += f * nx
            forces[node, 1] += f * ny
            forces[node, 2] += f * nz
    return weight, area


@kernel
def make_scratch():
    return (np.empty((MAX_VERTICES, N_COLUMNS)), np.empty((MAX_VERTICES, N_COLUMNS)),
            np.empty(MAX_VERTICES), np.zeros(7), np.empty((MAX_VERTICES, N_COLUMNS)))


@kernel
def pair_forces(positions, triangles, tets, pairs, penalty, forces):
    """Forces of every candidate (boundary triangle, tet) pair, (n, 2) indices into ``triangles``
    and ``tets``. Returns (total p int phi dS, contact area)."""
    scratch = make_scratch()
    lam_map = np.empty((4, 4))
    weight = 0.0
    area = 0.0
    last = -1
    valid = False
    for q in range(pairs.shape[0]):
        t = pairs[q, 1]
        if t != last:
            valid = barycentric_map(positions, tets[t], lam_map)
            last = t
        if not valid:
            continue
        w, a = triangle_in_tet(positions, triangles[pairs[q, 0]], tets[t], lam_map, penalty, forces,
                               scratch)
        weight += w
        area += a
    return weight, area


@kernel
def wall_forces(positions, triangles, tets, wall_point, wall_normal, penalty, wall_depths,
                forces):
    """Forces of one half-space wall on boundary ``triangles`` and ``tets`` (only those near the
    surface need be listed), added to ``forces``; ``wall_depths[tri]`` is the depth over which the
    wall's potential rises for that triangle's body. Returns (normal force, contact area)."""
    polygon, work, signed, integrals, piece = make_scratch()
    total = 0.0
    area = 0.0
    # (i) boundary triangles inside the wall: -p depth / h_w n_T, spread with N_v
    for tri in range(triangles.shape[0]):
        inside = 0
        for v in range(3):
            node = triangles[tri, v]
            depth = 0.0
            for c in range(3):
                polygon[v, c] = positions[node, c]
                depth += wall_normal[c] * (wall_point[c] - positions[node, c])
            polygon[v, 3] = depth
            signed[v] = depth
            for w in range(3):
                polygon[v, 4 + w] = 1.0 if w == v else 0.0
            if depth > 0.0:
                inside += 1
        if inside == 0:
            continue
        nx, ny, nz, norm = polygon_normal(polygon)
        if norm == 0.0:
            continue
        m = clip(polygon, 3, signed, 7, work)
        if m < 3:
            continue
        for i in range(3):
            integrals[i] = 0.0
        area += 0.5 * product_integrals(work, m, 3, 4, 3, integrals[0:3])
        for v in range(3):
            f = penalty / wall_depths[tri] * integrals[v] / norm
            node = triangles[tri, v]
            forces[node, 0] -= f * nx
            forces[node, 1] -= f * ny
            forces[node, 2] -= f * nz
            total -= f * (nx * wall_normal[0] + ny * wall_normal[1] + nz * wall_normal[2])
    # (ii) the wall plane inside the body's tets: p phi_t n, spread with lambda_k
    depths = np.empty(4)
    for t in range(tets.shape[0]):
        inside = 0
        for k in range(4):
            node = tets[t, k]
            depth = 0.0
            for c in range(3):
                depth += wall_normal[c] * (wall_point[c] - positions[node, c])
            depths[k] = depth
            if depth > 0.0:
                inside += 1
        if inside == 0 or inside == 4:
            continue
        m = plane_section(positions, 0, tets, t, depths, wall_normal, polygon)
        if m < 3:
            continue
        for j in range(4):
            mj = smallest_region(polygon, m, j, 3, 7, piece, work, signed)
            if mj < 3:
                continue
            for i in range(4):
                integrals[i] = 0.0
            area += 0.5 * product_integrals(piece, mj, 3 + j, 3, 4, integrals[0:4])
            for k in range(4):
                f = 4.0 * penalty * integrals[k]
                node = tets[t, k]
                for c in range(3):
                    forces[node, c] += f * wall_normal[c]
                total += f
    return total, area


@kernel
def candidate_pairs(positions, triangles, triangle_body, tets, tet_body, skin):
    """(triangle, tet) pairs of different bodies whose boxes, grown by ``skin``, overlap: sorted by
    tet. Sweep along x over the boxes of both sets."""
    n_tri = triangles.shape[0]
    n_tet = tets.shape[0]
    boxes = np.empty((n_tri + n_tet, 6))
    for i in range(n_tri):
        for c in range(3):
            lo = min(positions[triangles[i, 0], c], positions[triangles[i, 1], c], positions[triangles[i, 2], c])
            hi = max(positions[triangles[i, 0], c], positions[triangles[i, 1], c], positions[triangles[i, 2], c])
            boxes[i, c] = lo - skin
            boxes[i, 3 + c] = hi + skin
    for t in range(n_tet):
        for c in range(3):
            lo = np.inf
            hi = -np.inf
            for k in range(4):
                lo = min(lo, positions[tets[t, k], c])
                hi = max(hi, positions[tets[t, k], c])
            boxes[n_tri + t, c] = lo
            boxes[n_tri + t, 3 + c] = hi
    order = np.argsort(boxes[:, 0])
    capacity = 1024
    pairs = np.empty((capacity, 2), dtype=np.int64)
    count = 0
    active = np.empty(n_tri + n_tet, dtype=np.int64)
    n_active = 0
    for idx in order:
        x_lo = boxes[idx, 0]
        # drop boxes that end before this one starts
        kept = 0
        for a in range(n_active):
            if boxes[active[a], 3] >= x_lo:
                active[kept] = active[a]
                kept += 1
        n_active = kept
        for a in range(n_active):
            other = active[a]
            if (idx < n_tri) == (other < n_tri):
                continue
            tri = idx if idx < n_tri else other
            tet = other - n_tri if idx < n_tri else idx - n_tri
            if triangle_body[tri] == tet_body[tet]:
                continue
            if (boxes[idx, 1] > boxes[other, 4] or boxes[other, 1] > boxes[idx, 4]
                    or boxes[idx, 2] > boxes[other, 5] or boxes[other, 2] > boxes[idx, 5]):
                continue
            if count == capacity:
                grown = np.empty((2 * capacity, 2), dtype=np.int64)
                grown[:count] = pairs[:count]
                pairs = grown
                capacity *= 2
            pairs[count, 0] = tri
            pairs[count, 1] = tet
            count += 1
        active[n_active] = idx
        n_active += 1
    result = pairs[:count]
    by_tet = np.argsort(result[:, 1], kind="mergesort")
    return result[by_tet].copy()
