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

from numba import prange

from riprap._jit import inline_kernel, kernel, leaf_kernel, parallel_kernel
from riprap.solid.kernels.contact import plane_section
from riprap.solid.kernels.pair_rule import pair_friction

MAX_VERTICES = 16
N_COLUMNS = 10
# Columns of a triangle-in-tet polygon: 3-5 N_v of the triangle, 6-9 lambda_k of the tet.
_N = 3
_LAMBDA = 6


@leaf_kernel
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


@leaf_kernel
def product_integrals(polygon, n_vertices, a_column, b_first, n_b, out, out_first):
    """out[out_first + j] += int polygon[:, a_column] * polygon[:, b_first + j] dA for j < n_b
    over a planar convex polygon (exact: edge-midpoint rule on each fan triangle). Returns the
    area. (An offset, not a slice of ``out``: a slice per call cost an atomic reference count
    each way, most of a contact pair's time.)"""
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
                out[out_first + j] += area / 3.0 * a_mid * b_mid
    return total_area


@leaf_kernel
def barycentric_map(positions, tets, t, out):
    """Rows k = (a_k, b_k) with lambda_k(x) = a_k . x + b_k for the current corners of tet
    ``tets[t]``, (4, 4). Returns False for a flat tet."""
    n0 = tets[t, 0]
    x0 = positions[n0, 0]
    y0 = positions[n0, 1]
    z0 = positions[n0, 2]
    # columns: edges from corner 0 to corners 1, 2, 3
    a00 = positions[tets[t, 1], 0] - x0
    a10 = positions[tets[t, 1], 1] - y0
    a20 = positions[tets[t, 1], 2] - z0
    a01 = positions[tets[t, 2], 0] - x0
    a11 = positions[tets[t, 2], 1] - y0
    a21 = positions[tets[t, 2], 2] - z0
    a02 = positions[tets[t, 3], 0] - x0
    a12 = positions[tets[t, 3], 1] - y0
    a22 = positions[tets[t, 3], 2] - z0
    # cofactors c_ij of the edge matrix; its inverse is c^T / det
    c00 = a11 * a22 - a12 * a21
    c01 = a12 * a20 - a10 * a22
    c02 = a10 * a21 - a11 * a20
    det = a00 * c00 + a01 * c01 + a02 * c02
    if det == 0.0:
        return False
    inv = 1.0 / det
    out[1, 0] = c00 * inv
    out[1, 1] = (a02 * a21 - a01 * a22) * inv
    out[1, 2] = (a01 * a12 - a02 * a11) * inv
    out[2, 0] = c01 * inv
    out[2, 1] = (a00 * a22 - a02 * a20) * inv
    out[2, 2] = (a02 * a10 - a00 * a12) * inv
    out[3, 0] = c02 * inv
    out[3, 1] = (a01 * a20 - a00 * a21) * inv
    out[3, 2] = (a00 * a11 - a01 * a10) * inv
    for k in range(1, 4):
        out[k, 3] = -(out[k, 0] * x0 + out[k, 1] * y0 + out[k, 2] * z0)
    for c in range(4):
        out[0, c] = -(out[1, c] + out[2, c] + out[3, c])
    out[0, 3] += 1.0
    return True


@leaf_kernel
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


@leaf_kernel
def polygon_normal(polygon):
    """Unnormalised normal (x1 - x0) x (x2 - x0) of the first three vertices and its length."""
    nx = ((polygon[1, 1] - polygon[0, 1]) * (polygon[2, 2] - polygon[0, 2])
          - (polygon[1, 2] - polygon[0, 2]) * (polygon[2, 1] - polygon[0, 1]))
    ny = ((polygon[1, 2] - polygon[0, 2]) * (polygon[2, 0] - polygon[0, 0])
          - (polygon[1, 0] - polygon[0, 0]) * (polygon[2, 2] - polygon[0, 2]))
    nz = ((polygon[1, 0] - polygon[0, 0]) * (polygon[2, 1] - polygon[0, 1])
          - (polygon[1, 1] - polygon[0, 1]) * (polygon[2, 0] - polygon[0, 0]))
    return nx, ny, nz, np.sqrt(nx * nx + ny * ny + nz * nz)


@leaf_kernel
def triangle_in_tet(positions, triangles, tri, tets, t, lam_map, penalty, forces, polygon, work,
                    signed, integrals, piece, node_force, velocities, masses, friction_coefficient,
                    damping_ratio, tangential_stiffness, time_step, springs, q):
    """Forces of the potential of tet ``tets[t]`` on the boundary triangle ``triangles[tri]``
    (outward, counter-clockwise) of another body: added to ``forces`` at the triangle's and the
    tet's nodes; the pair's tangential spring is ``springs[q]``. ``polygon`` .. ``node_force`` are
    scratch arrays (``make_scratch``). Returns (force on the triangle's body along its...
    magnitude p int phi dS, contact area). (Rows are passed by index, never as slices: each
    slice cost an atomic reference count each way, most of a pair's time.)

    22 arguments: a leaf kernel called per (triangle, tet) piece with the scratch arrays one by one
    (see above); a bundle would add nothing the compiled code needs.
    """
    # quick rejection: all three corners outside the same face of the tet
    for k in range(4):
        outside = 0
        for v in range(3):
            node = triangles[tri, v]
            if (lam_map[k, 0] * positions[node, 0] + lam_map[k, 1] * positions[node, 1]
                    + lam_map[k, 2] * positions[node, 2] + lam_map[k, 3]) < 0.0:
                outside += 1
        if outside == 3:
            return 0.0, 0.0
    # the triangle's plane normal (outward, unit) and its vertices with N_v and lambda_k
    for v in range(3):
        node = triangles[tri, v]
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
    area = 0.0
    # node weights of the normal force: [0:3] the triangle's nodes, [3:7] the tet's
    for i in range(7):
        node_force[i] = 0.0
    for j in range(4):
        mj = smallest_region(polygon, m, j, _LAMBDA, N_COLUMNS, piece, work, signed)
        if mj < 3:
            continue
        for i in range(7):
            integrals[i] = 0.0
        area += product_integrals(piece, mj, _LAMBDA + j, _N, 3, integrals, 0)
        product_integrals(piece, mj, _LAMBDA + j, _LAMBDA, 4, integrals, 3)
        for i in range(7):
            node_force[i] += 4.0 * penalty * integrals[i]
    weight = node_force[0] + node_force[1] + node_force[2]
    if weight <= 0.0:
        return 0.0, area
    for v in range(3):
        node = triangles[tri, v]
        forces[node, 0] -= node_force[v] * nx
        forces[node, 1] -= node_force[v] * ny
        forces[node, 2] -= node_force[v] * nz
    for k in range(4):
        node = tets[t, k]
        forces[node, 0] += node_force[3 + k] * nx
        forces[node, 1] += node_force[3 + k] * ny
        forces[node, 2] += node_force[3 + k] * nz
    if friction_coefficient > 0.0 or damping_ratio > 0.0:
        # tangential stiffness: a share of the normal one, p A / h with h the tet's potential depth
        apply_friction(triangles, tri, tets, t, node_force, weight, nx, ny, nz, velocities,
                       masses, friction_coefficient, tangential_stiffness * area, damping_ratio,
                       time_step, springs, q, forces)
    return weight, area


@leaf_kernel
def spring_friction(springs, q, tx, ty, tz, nx, ny, nz, stiffness, limit, time_step):
    """Coulomb friction by an elastic tangential spring, as for rigid bodies: the spring
    ``springs[q]`` (3, updated in place) is turned into the present tangent plane, stretched by the
    relative tangential velocity (tx, ty, tz) times the step, and cut back to ``limit`` / ``stiffness``
    when it would pull harder than ``limit`` (sliding). Returns the force on the first side."""
    length = np.sqrt(springs[q, 0] ** 2 + springs[q, 1] ** 2 + springs[q, 2] ** 2)
    along = springs[q, 0] * nx + springs[q, 1] * ny + springs[q, 2] * nz
    for c, n in ((0, nx), (1, ny), (2, nz)):
        springs[q, c] -= along * n
    turned = np.sqrt(springs[q, 0] ** 2 + springs[q, 1] ** 2 + springs[q, 2] ** 2)
    if turned > 0.0:
        for c in range(3):
            springs[q, c] *= length / turned
    springs[q, 0] += tx * time_step
    springs[q, 1] += ty * time_step
    springs[q, 2] += tz * time_step
    pull = stiffness * np.sqrt(springs[q, 0] ** 2 + springs[q, 1] ** 2 + springs[q, 2] ** 2)
    if pull > limit:
        for c in range(3):
            springs[q, c] *= limit / pull
    return -stiffness * springs[q, 0], -stiffness * springs[q, 1], -stiffness * springs[q, 2]


@leaf_kernel
def reduced_mass(side_a, side_b):
    if np.isinf(side_b):
        return side_a
    if np.isinf(side_a):
        return side_b
    return side_a * side_b / (side_a + side_b)


@leaf_kernel
def apply_friction(triangles, tri, tets, t, node_force, weight, nx, ny, nz, velocities, masses,
                   friction_coefficient, stiffness, damping_ratio, time_step, springs, q, forces):
    """Friction and normal damping of one (triangle, tet) contact with normal force ``weight``
    spread over its nodes as ``node_force``: a tangential spring of ``stiffness`` (N/m) between the
    two sides at the force's centre (``springs[q]``) (:func:`spring_friction`), and a dashpot on their normal
    relative speed with ``damping_ratio`` of the contact's normal stiffness (taken as the tangential
    one over 2/7) and their lumped masses, clipped so that the contact never pulls; spread with the
    same weights, equal and opposite.

    18 arguments: a leaf kernel per contact piece; the normal (three scalars) and the piece's
    indices change every call.
    """
    rx = ry = rz = 0.0
    side_a = side_b = 0.0
    for v in range(3):
        share = node_force[v] / weight
        node = triangles[tri, v]
        rx += share * velocities[node, 0]
        ry += share * velocities[node, 1]
        rz += share * velocities[node, 2]
        side_a += share * masses[node]
    for k in range(4):
        share = node_force[3 + k] / weight
        node = tets[t, k]
        rx -= share * velocities[node, 0]
        ry -= share * velocities[node, 1]
        rz -= share * velocities[node, 2]
        side_b += share * masses[node]
    normal = rx * nx + ry * ny + rz * nz
    fx, fy, fz = spring_friction(springs, q, rx - normal * nx, ry - normal * ny, rz - normal * nz,
                                 nx, ny, nz, stiffness, friction_coefficient * weight, time_step)
    if damping_ratio > 0.0:
        # n points out of the triangle's body: approaching sides have normal > 0
        dashpot = -2.0 * damping_ratio * np.sqrt(3.5 * stiffness * reduced_mass(side_a, side_b)) * normal
        # along n the contact pushes the triangle's side with -weight: the sum never pulls
        dashpot = min(dashpot, weight)
        # on the triangle's side the contact pushes along -n
        fx += dashpot * nx
        fy += dashpot * ny
        fz += dashpot * nz
    for v in range(3):
        share = node_force[v] / weight
        node = triangles[tri, v]
        forces[node, 0] += share * fx
        forces[node, 1] += share * fy
        forces[node, 2] += share * fz
    for k in range(4):
        share = node_force[3 + k] / weight
        node = tets[t, k]
        forces[node, 0] -= share * fx
        forces[node, 1] -= share * fy
        forces[node, 2] -= share * fz


@kernel
def make_scratch():
    return (np.empty((MAX_VERTICES, N_COLUMNS)), np.empty((MAX_VERTICES, N_COLUMNS)),
            np.empty(MAX_VERTICES), np.zeros(7), np.empty((MAX_VERTICES, N_COLUMNS)), np.zeros(7))


@kernel
def pair_forces(positions, triangles, tets, pairs, forces, velocities, masses, laws, time_step,
                springs):
    """Forces of every candidate (boundary triangle, tet) pair, (n, 2) indices into ``triangles``
    and ``tets``, under ``laws`` (:class:`~riprap.deformable.kernels.bundles.SurfaceLaws`); the
    friction coefficient of a pair is the smaller of its triangle's and its tet's
    (``solid/kernels/pair_rule.py``), likewise its normal damping ratio; its tangential stiffness
    ``tet_stiffness[tet]`` (N/m per m^2 of contact) times its contact area, its spring
    ``springs[pair]`` (zeroed while the pair does not touch). Returns (total p int phi dS, contact
    area)."""
    penalty, _, triangle_friction, tet_friction, triangle_damping, tet_damping, tet_stiffness = laws
    polygon, work, signed, integrals, piece, node_force = make_scratch()
    lam_map = np.empty((4, 4))
    weight = 0.0
    area = 0.0
    last = -1
    valid = False
    for q in range(pairs.shape[0]):
        t = pairs[q, 1]
        if t != last:
            valid = barycentric_map(positions, tets, t, lam_map)
            last = t
        if not valid:
            continue
        tri = pairs[q, 0]
        w, a = triangle_in_tet(positions, triangles, tri, tets, t, lam_map, penalty, forces,
                               polygon, work, signed, integrals, piece, node_force, velocities,
                               masses, pair_friction(triangle_friction[tri], tet_friction[t]),
                               min(triangle_damping[tri], tet_damping[t]), tet_stiffness[t],
                               time_step, springs, q)
        if w == 0.0:
            springs[q, 0] = springs[q, 1] = springs[q, 2] = 0.0
        weight += w
        area += a
    return weight, area


#: The pairs are cut into this many runs for the parallel evaluation (a fixed number, not the
#: number of threads, so that the forces' sums, and a run, do not depend on the machine).
PAIR_CHUNKS = 4


@parallel_kernel
def pair_forces_parallel(positions, triangles, tets, pairs, forces, velocities, masses, laws,
                         time_step, springs):
    """:func:`pair_forces` on ``PAIR_CHUNKS`` runs of the pairs at once, each into a force buffer
    of its own (a node may sit in pairs of several runs), summed in a fixed order."""
    n_pairs = pairs.shape[0]
    buffers = np.zeros((PAIR_CHUNKS, positions.shape[0], 3))
    weights = np.zeros(PAIR_CHUNKS)
    areas = np.zeros(PAIR_CHUNKS)
    for c in prange(PAIR_CHUNKS):
        first = c * n_pairs // PAIR_CHUNKS
        last = (c + 1) * n_pairs // PAIR_CHUNKS
        weights[c], areas[c] = pair_forces(positions, triangles, tets, pairs[first:last],
                                           buffers[c], velocities, masses, laws, time_step,
                                           springs[first:last])
    for n in prange(positions.shape[0]):
        for i in range(3):
            total = forces[n, i]
            for c in range(PAIR_CHUNKS):
                total += buffers[c, n, i]
            forces[n, i] = total
    return weights.sum(), areas.sum()


@kernel
def wall_forces(positions, triangles, tets, wall, wall_depths, forces, velocities, masses, laws,
                time_step, triangle_springs, tet_springs):
    """Forces of one half-space ``wall`` (7,: point, outward normal, friction coefficient) on
    boundary ``triangles`` and ``tets`` (only those near the surface need be listed), added to
    ``forces``; ``wall_depths[tri]`` is the depth over which the wall's potential rises for that
    triangle's body; friction as for body pairs under ``laws``
    (:class:`~riprap.deformable.kernels.bundles.SurfaceLaws`), with the coefficients given per
    triangle and per tet (the pair rule of that and the wall's acts), tangential springs per
    triangle and per tet of ``tangential_ratio`` p A / h_w and ``tet_stiffness`` A. Returns
    (normal force, contact area)."""
    wall_point = wall[0:3]
    wall_normal = wall[3:6]
    wall_friction = wall[6]
    (penalty, tangential_ratio, triangle_friction, tet_friction, triangle_damping, tet_damping,
     tet_stiffness) = laws
    polygon, work, signed, integrals, piece, node_force = make_scratch()
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
            for c in range(3):
                triangle_springs[tri, c] = 0.0
            continue
        nx, ny, nz, norm = polygon_normal(polygon)
        if norm == 0.0:
            continue
        m = clip(polygon, 3, signed, 7, work)
        if m < 3:
            continue
        for i in range(3):
            integrals[i] = 0.0
        piece_area = product_integrals(work, m, 3, 4, 3, integrals, 0)
        area += 0.5 * piece_area
        cosine = -(nx * wall_normal[0] + ny * wall_normal[1] + nz * wall_normal[2]) / norm
        pushed = 0.0
        for v in range(3):
            f = penalty / wall_depths[tri] * integrals[v] / norm
            node_force[v] = f * norm
            node = triangles[tri, v]
            forces[node, 0] -= f * nx
            forces[node, 1] -= f * ny
            forces[node, 2] -= f * nz
            pushed += f * norm * cosine
        total += pushed
        mu = pair_friction(triangle_friction[tri], wall_friction)
        if (mu > 0.0 or triangle_damping[tri] > 0.0) and pushed > 0.0:
            slide_on_wall(triangles, tri, 3, node_force, pushed, wall_normal, velocities, masses,
                          mu, tangential_ratio * penalty * piece_area / wall_depths[tri],
                          triangle_damping[tri], time_step, triangle_springs, tri, forces)
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
        if inside == 0:
            for c in range(3):
                tet_springs[t, c] = 0.0
        if inside == 0 or inside == 4:
            continue
        m = plane_section(positions, 0, tets, t, depths, wall_normal, polygon)
        if m < 3:
            continue
        for k in range(4):
            node_force[k] = 0.0
        section_area = 0.0
        for j in range(4):
            mj = smallest_region(polygon, m, j, 3, 7, piece, work, signed)
            if mj < 3:
                continue
            for i in range(4):
                integrals[i] = 0.0
            section_area += product_integrals(piece, mj, 3 + j, 3, 4, integrals, 0)
            for k in range(4):
                node_force[k] += 4.0 * penalty * integrals[k]
        pushed = 0.0
        for k in range(4):
            node = tets[t, k]
            for c in range(3):
                forces[node, c] += node_force[k] * wall_normal[c]
            pushed += node_force[k]
        total += pushed
        area += 0.5 * section_area
        mu = pair_friction(tet_friction[t], wall_friction)
        if (mu > 0.0 or tet_damping[t] > 0.0) and pushed > 0.0:
            slide_on_wall(tets, t, 4, node_force, pushed, wall_normal, velocities, masses, mu,
                          tet_stiffness[t] * section_area, tet_damping[t], time_step,
                          tet_springs, t, forces)
    return total, area


@leaf_kernel
def slide_on_wall(nodes, row, count, node_force, normal_force, wall_normal, velocities, masses,
                  friction_coefficient, stiffness, damping_ratio, time_step, springs, q, forces):
    """Friction and normal damping of the ``count`` nodes ``nodes[row]`` pressed on a still wall
    with ``normal_force`` spread as ``node_force``, as :func:`apply_friction` with a still,
    infinitely heavy second side (tangential spring ``springs[q]``).

    15 arguments: as :func:`apply_friction`, per node group on a wall.
    """
    total = 0.0
    for i in range(count):
        total += node_force[i]
    if total <= 0.0:
        return
    vx = vy = vz = 0.0
    mass = 0.0
    for i in range(count):
        share = node_force[i] / total
        node = nodes[row, i]
        vx += share * velocities[node, 0]
        vy += share * velocities[node, 1]
        vz += share * velocities[node, 2]
        mass += share * masses[node]
    normal = vx * wall_normal[0] + vy * wall_normal[1] + vz * wall_normal[2]
    fx, fy, fz = spring_friction(springs, q, vx - normal * wall_normal[0], vy - normal * wall_normal[1],
                                 vz - normal * wall_normal[2], wall_normal[0], wall_normal[1],
                                 wall_normal[2], stiffness, friction_coefficient * normal_force,
                                 time_step)
    if damping_ratio > 0.0:
        # the wall pushes along +n; moving into it (normal < 0) is resisted
        dashpot = -2.0 * damping_ratio * np.sqrt(3.5 * stiffness * mass) * normal
        dashpot = max(dashpot, -normal_force)
        fx += dashpot * wall_normal[0]
        fy += dashpot * wall_normal[1]
        fz += dashpot * wall_normal[2]
    for i in range(count):
        share = node_force[i] / total
        node = nodes[row, i]
        forces[node, 0] += share * fx
        forces[node, 1] += share * fy
        forces[node, 2] += share * fz


@inline_kernel
def _neighbours(triangle_origin, tri, tet_origin, tet):
    """Whether the tet owning triangle ``tri`` and tet ``tet`` shared a node before their mesh was
    split by joints (ids < 0: not split)."""
    if triangle_origin[tri, 0] < 0 or tet_origin[tet, 0] < 0:
        return False
    for a in range(4):
        for b in range(4):
            if triangle_origin[tri, a] == tet_origin[tet, b]:
                return True
    return False


@kernel
def candidate_pairs(positions, triangles, triangle_body, tets, tet_body, skin, first_rigid_body,
                    triangle_origin, tet_origin):
    """(triangle, tet) pairs of different bodies, not both rigid (bodies from
    ``first_rigid_body`` on), whose boxes, grown by ``skin``, overlap: sorted by tet. Sweep along x
    over the boxes of both sets. Pieces of one cracked body are bodies here; a triangle and a tet
    that were neighbours in its mesh (``triangle_origin``, ``tet_origin``: the original node ids
    of the triangle's tet and of the tet, -1 where not split) are left to their joints."""
    n_tri = triangles.shape[0]
    n_tet = tets.shape[0]
    # a rigid body's triangle or tet can only meet a deformable body near that body's box
    n_bodies = max(triangle_body.max(), tet_body.max()) + 1 if n_tri > 0 else 0
    deformable_boxes = np.empty((min(first_rigid_body, n_bodies), 6))
    for b in range(deformable_boxes.shape[0]):
        for c in range(3):
            deformable_boxes[b, c] = np.inf
            deformable_boxes[b, 3 + c] = -np.inf
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
    for i in range(n_tri):
        b = triangle_body[i]
        if b < first_rigid_body:
            for c in range(3):
                deformable_boxes[b, c] = min(deformable_boxes[b, c], boxes[i, c])
                deformable_boxes[b, 3 + c] = max(deformable_boxes[b, 3 + c], boxes[i, 3 + c])
    near = np.zeros(n_tri + n_tet, dtype=np.bool_)
    for i in range(n_tri + n_tet):
        body = triangle_body[i] if i < n_tri else tet_body[i - n_tri]
        if body < first_rigid_body:
            near[i] = True
            continue
        for b in range(deformable_boxes.shape[0]):
            if (boxes[i, 0] <= deformable_boxes[b, 3] and boxes[i, 3] >= deformable_boxes[b, 0]
                    and boxes[i, 1] <= deformable_boxes[b, 4] and boxes[i, 4] >= deformable_boxes[b, 1]
                    and boxes[i, 2] <= deformable_boxes[b, 5] and boxes[i, 5] >= deformable_boxes[b, 2]):
                near[i] = True
                break
    candidates = np.flatnonzero(near)
    order = candidates[np.argsort(boxes[candidates, 0])]
    capacity = 1024
    pairs = np.empty((capacity, 2), dtype=np.int64)
    count = 0
    active = np.empty(len(order), dtype=np.int64)
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
            if triangle_body[tri] >= first_rigid_body and tet_body[tet] >= first_rigid_body:
                continue
            if _neighbours(triangle_origin, tri, tet_origin, tet):
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


@kernel
def place_rigid_nodes(positions, velocities, prescribed_velocities, first_node, local, node_body,
                      nodes, rotations, centres, body_velocities, angular_velocities):
    """world = R local + centre and velocity v + omega x (world - centre) for the listed rigid
    surface nodes (indices into ``local``; system node first_node + index)."""
    for q in range(nodes.shape[0]):
        n = nodes[q]
        b = node_body[n]
        r = rotations[b]
        ox = r[0, 0] * local[n, 0] + r[0, 1] * local[n, 1] + r[0, 2] * local[n, 2]
        oy = r[1, 0] * local[n, 0] + r[1, 1] * local[n, 1] + r[1, 2] * local[n, 2]
        oz = r[2, 0] * local[n, 0] + r[2, 1] * local[n, 1] + r[2, 2] * local[n, 2]
        w = angular_velocities[b]
        target = first_node + n
        positions[target, 0] = centres[b, 0] + ox
        positions[target, 1] = centres[b, 1] + oy
        positions[target, 2] = centres[b, 2] + oz
        vx = body_velocities[b, 0] + w[1] * oz - w[2] * oy
        vy = body_velocities[b, 1] + w[2] * ox - w[0] * oz
        vz = body_velocities[b, 2] + w[0] * oy - w[1] * ox
        prescribed_velocities[target, 0] = velocities[target, 0] = vx
        prescribed_velocities[target, 1] = velocities[target, 1] = vy
        prescribed_velocities[target, 2] = velocities[target, 2] = vz


@kernel
def rigid_node_loads(positions, contact_forces, first_node, node_body, centres, n_rigid):
    """(force (n_rigid, 3), torque about the centres (n_rigid, 3)) of the contact forces on the
    rigid surface nodes."""
    forces = np.zeros((n_rigid, 3))
    torques = np.zeros((n_rigid, 3))
    for n in range(node_body.shape[0]):
        b = node_body[n]
        i = first_node + n
        fx = contact_forces[i, 0]
        fy = contact_forces[i, 1]
        fz = contact_forces[i, 2]
        if fx == 0.0 and fy == 0.0 and fz == 0.0:
            continue
        rx = positions[i, 0] - centres[b, 0]
        ry = positions[i, 1] - centres[b, 1]
        rz = positions[i, 2] - centres[b, 2]
        forces[b, 0] += fx
        forces[b, 1] += fy
        forces[b, 2] += fz
        torques[b, 0] += ry * fz - rz * fy
        torques[b, 1] += rz * fx - rx * fz
        torques[b, 2] += rx * fy - ry * fx
    return forces, torques


@kernel
def carry_springs(old_pairs, old_springs, new_pairs, n_tets):
    """Springs of the new pair list: each pair keeps its spring if it was listed before."""
    keys = old_pairs[:, 0] * n_tets + old_pairs[:, 1]
    order = np.argsort(keys)
    sorted_keys = keys[order]
    springs = np.zeros((new_pairs.shape[0], 3))
    for q in range(new_pairs.shape[0]):
        key = new_pairs[q, 0] * n_tets + new_pairs[q, 1]
        at = np.searchsorted(sorted_keys, key)
        if at < sorted_keys.shape[0] and sorted_keys[at] == key:
            for c in range(3):
                springs[q, c] = old_springs[order[at], c]
    return springs
