"""Compiled kernel of the joint (cohesive) elements between the tets of an exploded mesh: Munjiza's
combined single and smeared crack model (Munjiza, Andrews & White 1999, Int. J. Numer. Meth.
Engng 44: 41; the form of Y3D's 6-node joint).

A joint holds face A of one tet to the matching face B of its neighbour: nodes ``joints[j, 0:3]``
(A) and ``joints[j, 3:6]`` (B, node k paired with A's node k), ordered so that the mid-surface
normal points from A to B. At three points (the mid-surface's mid-edges) the separation
delta = x_B - x_A gives the opening o = delta . n and the slip vector s = delta - o n; their
stresses (tension and shear positive) pull A towards B with the traction sigma n + tau s / |s|
over a third of the mid-surface's area each, shared by the point's two vertices.

Per point, with f_t the tensile strength, c the cohesion, o_p = 2 h f_t / p and s_p = 2 h c / p
the openings at the strengths (h the joint's size, p the joint penalty), o_t, s_t the softening
lengths:

    damage  D = max(D_before, sqrt(max(o - o_p, 0)^2 / o_t^2 + max(|s| - s_p, 0)^2 / s_t^2)), <= 1
    sigma   = 2 (o / o_p) f_t in compression (o < 0, undamaged: the faces may not interpenetrate)
            = (2 r - r^2) z(D) f_t,  r = o / o_p,  for 0 <= o < o_p
            = z(D) f_t                             for o >= o_p
    tau     likewise with |s|, s_p, c; plus friction (below)
    z(D)    = [1 - (a + b - 1)/(a + b) exp(D (a + c b)/((a + b)(1 - a - b)))] [a (1 - D) + b (1 - D)^c]

with a = 0.63, b = 1.8, c = 6 (Hordijk's curve). Friction adds to tau: a spring of stiffness p / h
from an anchor (per point, in multiples of the joint's edges), no stronger than tan(phi) times the
compression; where it would be, the anchor moves with the slip (Coulomb's law with a stick
range, as in the contact). The joint's shear strength is so c z(D) + tan(phi) (-sigma): Munjiza's
f_s = c - tan(phi) sigma, but its friction part dissipates, and it survives the cohesion's
softening. (Munjiza's law with f_s in the softening curve returns shear work along another path
than it took it: a unit crushing on a rock gained 881 J from its joints; docs/fracture.md.)
The compressive penalty acts only while the slip is below h. A joint whose points reach D = 1 at
two of the three breaks: it then carries no tension or shear, only the compressive penalty and
the friction, applied to both faces at one place, until its faces have slid h apart
(``_broken_joint``).
"""
import math

from riprap._jit import inline_kernel, kernel, leaf_kernel
from riprap.deformable.kernels.slots import corner_joint_force

SOFTENING_A = 0.63
SOFTENING_B = 1.8
SOFTENING_C = 6.0


#: exp(D (a + c b) / ((a + b)(1 - a - b))) is taken as exp(x)^8 with x an eighth of the exponent
#: (in [-0.41, 0]), exp(x) by its Taylor series to x^14 (the first term left out: 2e-18 of it).
_EXPONENT_EIGHTH = ((SOFTENING_A + SOFTENING_C * SOFTENING_B)
                    / ((SOFTENING_A + SOFTENING_B) * (1.0 - SOFTENING_A - SOFTENING_B)) / 8.0)
_DROP = (SOFTENING_A + SOFTENING_B - 1.0) / (SOFTENING_A + SOFTENING_B)


@inline_kernel
def softening(damage):
    """z(D) of the module docstring: 1 at D = 0, 0 at D = 1 (c = 6: (1 - D)^c as products).

    Written without calls or branches (the exponential as a polynomial, within 2e-15 of
    ``math.exp``'s curve), so that the joints' law runs on vector registers (``_law_block``):
    numba has no vector ``exp``, and its scalar ``exp`` in the loop kept the whole loop scalar."""
    x = damage * _EXPONENT_EIGHTH
    e = 1.0 / 87178291200.0
    e = e * x + 1.0 / 6227020800.0
    e = e * x + 1.0 / 479001600.0
    e = e * x + 1.0 / 39916800.0
    e = e * x + 1.0 / 3628800.0
    e = e * x + 1.0 / 362880.0
    e = e * x + 1.0 / 40320.0
    e = e * x + 1.0 / 5040.0
    e = e * x + 1.0 / 720.0
    e = e * x + 1.0 / 120.0
    e = e * x + 1.0 / 24.0
    e = e * x + 1.0 / 6.0
    e = e * x + 0.5
    e = e * x + 1.0
    e = e * x + 1.0
    e = e * e
    e = e * e
    e = e * e
    rest = 1.0 - damage
    rest_2 = rest * rest
    z = (1.0 - _DROP * e) * (SOFTENING_A * rest + SOFTENING_B * (rest_2 * rest_2 * rest_2))
    z = 0.0 if damage >= 1.0 else z
    return 1.0 if damage <= 0.0 else z


@inline_kernel
def _rising(ratio):
    """2 r - r^2, the curve up to the strength (slope 2 at 0, 0 at the peak)."""
    return (2.0 - ratio) * ratio


@inline_kernel
def _edge_coordinates(rx, ry, rz, e1x, e1y, e1z, e2x, e2y, e2z, inverse_gram):
    """(a, b) with r = a e1 + b e2, for r in the plane of e1 and e2 (``inverse_gram`` =
    1 / |e1 x e2|^2, the inverse of their Gram determinant)."""
    on_1 = rx * e1x + ry * e1y + rz * e1z
    on_2 = rx * e2x + ry * e2y + rz * e2z
    g11 = e1x * e1x + e1y * e1y + e1z * e1z
    g12 = e1x * e2x + e1y * e2y + e1z * e2z
    g22 = e2x * e2x + e2y * e2y + e2z * e2z
    return (on_1 * g22 - on_2 * g12) * inverse_gram, (on_2 * g11 - on_1 * g12) * inverse_gram


@inline_kernel
def _friction(tx, ty, tz, compression, tan_phi, penalty_over_h, e1x, e1y, e1z, e2x, e2y, e2z,
              inverse_gram, anchors, j, q):
    """Friction stress (pulling face A towards B) at point ``q`` of joint ``j``, slipped by t
    in the joint's plane and pressed by ``compression`` (<= 0): a spring of stiffness p / h from
    the point's anchor, no stronger than tan(phi) (-compression); where it would be, the anchor
    follows the slip (it slides: the work is dissipated, as in the contact's friction). The
    anchor is held in multiples of the joint's edges e1, e2, so it turns (and stretches) with the
    joint.

    16 arguments: scalars of one joint point, inlined per point.
    """
    if compression == 0.0:
        # faces not pressed together: no friction, and none kept (NaN: it starts afresh where
        # they are pressed again; looked at first: a store would dirty the line)
        if anchors[j, q, 0] == anchors[j, q, 0]:
            anchors[j, q, 0] = math.nan
        return 0.0, 0.0, 0.0
    first = anchors[j, q, 0]
    second = anchors[j, q, 1]
    if first != first:
        first, second = _edge_coordinates(tx, ty, tz, e1x, e1y, e1z, e2x, e2y, e2z,
                                          inverse_gram)
        anchors[j, q, 0] = first
        anchors[j, q, 1] = second
    ux = tx - first * e1x - second * e2x
    uy = ty - first * e1y - second * e2y
    uz = tz - first * e1z - second * e2z
    limit = -tan_phi * compression
    squared = (ux * ux + uy * uy + uz * uz) * penalty_over_h * penalty_over_h
    if squared > limit * limit:
        # slides: the spring keeps tan(phi) sigma, the anchor comes to the slip minus the
        # spring's stretch
        scale = limit / math.sqrt(squared)
        ux *= scale
        uy *= scale
        uz *= scale
        anchors[j, q, 0], anchors[j, q, 1] = _edge_coordinates(
            tx - ux, ty - uy, tz - uz, e1x, e1y, e1z, e2x, e2y, e2z, inverse_gram)
    return penalty_over_h * ux, penalty_over_h * uy, penalty_over_h * uz


@inline_kernel
def _put_vertex(buffer, j, k, fx, fy, fz):
    """Force on face A's vertex k, and its opposite on B's vertex k (into their rows of
    ``buffer``: 6 j + k and 6 j + 3 + k)."""
    a = 6 * j + k
    b = a + 3
    buffer[a, 0] = fx
    buffer[a, 1] = fy
    buffer[a, 2] = fz
    buffer[b, 0] = -fx
    buffer[b, 1] = -fy
    buffer[b, 2] = -fz


@inline_kernel
def _corner(positions, joints, j, k, d):
    """Coordinate ``d`` of joint ``j``'s vertex ``k`` (0-2 face A, 3-5 face B)."""
    return positions[joints[j, k], d]


@inline_kernel
def _mid_corner(positions, joints, j, k, d):
    """Coordinate ``d`` of the mid-surface's corner ``k``: midway from A's vertex k to B's."""
    return _corner(positions, joints, j, k, d) + 0.5 * (_corner(positions, joints, j, 3 + k, d)
                                                        - _corner(positions, joints, j, k, d))


@inline_kernel
def _face_edges(positions, joints, j, face):
    """x1 - x0 and x2 - x0 of joint ``j``'s face (vertices ``face``..``face + 2``)."""
    x0 = _corner(positions, joints, j, face, 0)
    y0 = _corner(positions, joints, j, face, 1)
    z0 = _corner(positions, joints, j, face, 2)
    return (_corner(positions, joints, j, face + 1, 0) - x0,
            _corner(positions, joints, j, face + 1, 1) - y0,
            _corner(positions, joints, j, face + 1, 2) - z0,
            _corner(positions, joints, j, face + 2, 0) - x0,
            _corner(positions, joints, j, face + 2, 1) - y0,
            _corner(positions, joints, j, face + 2, 2) - z0)


@inline_kernel
def _add_weighted(buffer, j, k, weight, fx, fy, fz):
    row = 6 * j + k
    buffer[row, 0] += weight * fx
    buffer[row, 1] += weight * fy
    buffer[row, 2] += weight * fz


@inline_kernel
def _spread_on_face(buffer, j, positions, joints, face, q, wx, wy, wz, fx, fy, fz):
    """Force (fx, fy, fz) on the face of joint ``j`` whose vertices are ``face``..``face + 2``
    (0: face A, 3: face B), at the point ``w`` away (in the face's plane) from the midpoint of
    its edge from vertex ``q`` to the next: shared by the vertices' barycentric coordinates
    there. (Scalars, no arrays: the joints' one-thread loop allocates nothing, so that it runs
    without reference counts, ``joint_forces``.)"""
    ux, uy, uz, vx, vy, vz = _face_edges(positions, joints, j, face)
    cx = uy * vz - uz * vy
    cy = uz * vx - ux * vz
    cz = ux * vy - uy * vx
    c2 = cx * cx + cy * cy + cz * cz
    # the edge's two vertices take half each: q and the next
    w0 = 0.5 if q == 0 or q == 2 else 0.0
    w1 = 0.5 if q == 0 or q == 1 else 0.0
    w2 = 0.5 if q == 1 or q == 2 else 0.0
    if c2 > 0.0:
        shift_1 = ((wy * vz - wz * vy) * cx + (wz * vx - wx * vz) * cy + (wx * vy - wy * vx) * cz) / c2
        shift_2 = ((uy * wz - uz * wy) * cx + (uz * wx - ux * wz) * cy + (ux * wy - uy * wx) * cz) / c2
        w0 -= shift_1 + shift_2
        w1 += shift_1
        w2 += shift_2
    _add_weighted(buffer, j, face, w0, fx, fy, fz)
    _add_weighted(buffer, j, face + 1, w1, fx, fy, fz)
    _add_weighted(buffer, j, face + 2, w2, fx, fy, fz)


#: A broken joint whose faces have turned from each other beyond this cosine (about 25 degrees)
#: or interpenetrate deeper than this fraction of its size is released (``_broken_joint``).
RELEASE_FACE_COSINE = 0.9
RELEASE_PENETRATION = 0.01


@inline_kernel
def _face_normal(positions, joints, j, face):
    """(x1 - x0) x (x2 - x0) of joint ``j``'s face (vertices ``face``..``face + 2``)."""
    ax, ay, az, bx, by, bz = _face_edges(positions, joints, j, face)
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@inline_kernel
def _face_cosine(positions, joints, j):
    """Cosine of the angle between the normals of joint ``j``'s faces A and B."""
    ax, ay, az = _face_normal(positions, joints, j, 0)
    bx, by, bz = _face_normal(positions, joints, j, 3)
    lengths = math.sqrt((ax * ax + ay * ay + az * az) * (bx * bx + by * by + bz * bz))
    if lengths <= 0.0:
        return -1.0
    return (ax * bx + ay * by + az * bz) / lengths


@inline_kernel
def _point_separation(positions, joints, j, q):
    """x_B - x_A at point ``q`` of joint ``j`` (the midpoint of the edge from vertex q to the
    next, on both faces)."""
    r = (q + 1) % 3
    return (0.5 * (_corner(positions, joints, j, 3 + q, 0) + _corner(positions, joints, j, 3 + r, 0)
                   - _corner(positions, joints, j, q, 0) - _corner(positions, joints, j, r, 0)),
            0.5 * (_corner(positions, joints, j, 3 + q, 1) + _corner(positions, joints, j, 3 + r, 1)
                   - _corner(positions, joints, j, q, 1) - _corner(positions, joints, j, r, 1)),
            0.5 * (_corner(positions, joints, j, 3 + q, 2) + _corner(positions, joints, j, 3 + r, 2)
                   - _corner(positions, joints, j, q, 2) - _corner(positions, joints, j, r, 2)))


@inline_kernel
def _broken_joint(j, positions, joints, sizes, properties, joint_material, released, anchors,
                  buffer):
    """Forces of broken joint ``j``: the intact joint's compressive penalty and friction at each
    point (opening below zero), but acting on both faces at one place, midway between the point
    of A and the point of B, by each face's barycentric coordinates there. The two forces then lie
    on one line and turn neither piece (but for the friction's couple across the penetration
    depth): at the points themselves they would make a couple of the slip times the force once
    the faces have slid (examples/11: four broken joints put 66 J into pieces sliding on their
    cracks).

    The joint is ``released`` for good (no force ever after) once its faces no longer face each
    other: a point has slid h or more, or the faces have turned more than about 25 degrees
    (``RELEASE_FACE_COSINE``) from each other, or a point lies deeper than
    ``RELEASE_PENETRATION`` h in the other face (a penalty that deep would press with p / 100, far
    beyond any concrete's strength: the faces got there without it, by sliding or turning, and
    switching it on would throw them apart). Unreleased, joints whose slip came back under h, or
    whose faces had turned, put up to 25 kJ into a unit dropped from 1 m in a single step."""
    for k in range(6):
        for d in range(3):
            buffer[6 * j + k, d] = 0.0
    # the mid-surface, as for an intact joint (``_joint``)
    m0x = _mid_corner(positions, joints, j, 0, 0)
    m0y = _mid_corner(positions, joints, j, 0, 1)
    m0z = _mid_corner(positions, joints, j, 0, 2)
    e1x = _mid_corner(positions, joints, j, 1, 0) - m0x
    e1y = _mid_corner(positions, joints, j, 1, 1) - m0y
    e1z = _mid_corner(positions, joints, j, 1, 2) - m0z
    e2x = _mid_corner(positions, joints, j, 2, 0) - m0x
    e2y = _mid_corner(positions, joints, j, 2, 1) - m0y
    e2z = _mid_corner(positions, joints, j, 2, 2) - m0z
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    twice_area = math.sqrt(nx * nx + ny * ny + nz * nz)
    if twice_area <= 0.0 or released[j]:
        return
    inverse = 1.0 / twice_area
    nx *= inverse
    ny *= inverse
    nz *= inverse
    inverse_gram = inverse * inverse
    row = joint_material[j]
    tan_phi = properties[row, 2]
    h = sizes[j]
    penalty_over_h = properties[row, 3] / h
    if _face_cosine(positions, joints, j) < RELEASE_FACE_COSINE:
        released[j] = True
        return
    for q in range(3):
        sx, sy, sz = _point_separation(positions, joints, j, q)
        opening = sx * nx + sy * ny + sz * nz
        tx = sx - opening * nx
        ty = sy - opening * ny
        tz = sz - opening * nz
        if tx * tx + ty * ty + tz * tz >= h * h or opening < -RELEASE_PENETRATION * h:
            released[j] = True
            return
    share = twice_area / 6.0       # a third of the area per point
    for q in range(3):
        sx, sy, sz = _point_separation(positions, joints, j, q)
        opening = sx * nx + sy * ny + sz * nz
        compression = min(opening, 0.0) * penalty_over_h    # < 0: pushes A away from B
        gx = gy = gz = 0.0
        if tan_phi > 0.0:
            # the crack's faces keep the joint's friction while they are pressed together
            gx, gy, gz = _friction(sx - opening * nx, sy - opening * ny, sz - opening * nz,
                                   compression, tan_phi, penalty_over_h, e1x, e1y, e1z, e2x, e2y,
                                   e2z, inverse_gram, anchors, j, q)
        if compression == 0.0:
            continue
        fx = share * (compression * nx + gx)
        fy = share * (compression * ny + gy)
        fz = share * (compression * nz + gz)
        _spread_on_face(buffer, j, positions, joints, 0, q, 0.5 * sx, 0.5 * sy, 0.5 * sz,
                        fx, fy, fz)
        _spread_on_face(buffer, j, positions, joints, 3, q, -0.5 * sx, -0.5 * sy,
                        -0.5 * sz, -fx, -fy, -fz)


#: Joints whose law is evaluated together (``_law_block``), and the rows of their scratch: one
#: row of ``JOINT_BLOCK`` numbers per quantity, so that each quantity lies contiguous and at a
#: distance known when compiling from the others (with rows a run-time stride apart, LLVM would
#: need more overlap checks than it makes, and kept the loop scalar).
JOINT_BLOCK = 64
_SEPARATIONS = 0        # 9 rows: x_B - x_A at vertices 0, 1, 2 (x, y, z each)
_EDGES = 9              # 6 rows: the mid-surface's edges e1, e2 from its corner 0
_SIZE = 15              # h
_DAMAGE_BEFORE = 16     # 3 rows, one per point
_TRACTIONS = 19         # 9 rows: each point's cohesive traction with the compressive penalty
_SHARE = 28             # a sixth of the area (0 for a joint of no area)
_DAMAGE = 29            # 3 rows: each point's damage after the step
_SLIPS = 32             # 12 rows: per point, slip vector (3) and compression (1)
_INVERSE_GRAM = 44      # 1 / |e1 x e2|^2
SCRATCH_ROWS = 45
#: Numbers of scratch one thread needs for the joints (``joint_forces``, ``joint_range``).
JOINT_SCRATCH_SIZE = SCRATCH_ROWS * JOINT_BLOCK


@inline_kernel
def _at(row, i):
    """Index of joint ``i`` of a block in its ``row`` of the scratch."""
    return row * JOINT_BLOCK + i


@inline_kernel
def _read3(scratch, row, i):
    """Joint ``i``'s three numbers in rows ``row`` .. ``row + 2`` of the scratch."""
    return scratch[_at(row, i)], scratch[_at(row + 1, i)], scratch[_at(row + 2, i)]


@inline_kernel
def _write3(scratch, row, i, x, y, z):
    scratch[_at(row, i)] = x
    scratch[_at(row + 1, i)] = y
    scratch[_at(row + 2, i)] = z


@inline_kernel
def _point_law(sx, sy, sz, nx, ny, nz, h, tensile, cohesion, penalty_over_h, slip_peak,
               opening_peak, inverse_opening_peak, inverse_slip_peak, tensile_over_energy_i,
               inverse_energy_ii, before):
    """Cohesive traction with the compressive penalty (pulling face A towards B) at a point of an
    intact joint whose faces are apart by (sx, sy, sz), mid-surface normal n, damage ``before``
    the step. Returns the traction, the damage after it, the slip vector and the compression (for
    the friction, ``_friction``). Every case is computed and one chosen (no branches), so that the
    loop of ``_law_block`` runs on vector registers.

    17 arguments: scalars only, inlined into the vectorised law loop (arrays would stop it running
    on vector registers).
    """
    opening = sx * nx + sy * ny + sz * nz
    tx = sx - opening * nx
    ty = sy - opening * ny
    tz = sz - opening * nz
    slip = math.sqrt(tx * tx + ty * ty + tz * tz)
    # the faces may not pass through each other (sigma = p o / h) while they face each other
    compression = opening * penalty_over_h if (opening < 0.0) & (slip < h) else 0.0
    excess_o = max(opening - opening_peak, 0.0) * tensile_over_energy_i
    excess_s = max(slip - slip_peak, 0.0) * cohesion * inverse_energy_ii
    damage = max(before, min(math.sqrt(excess_o * excess_o + excess_s * excess_s), 1.0))
    z = softening(damage)
    sigma = z * tensile
    ratio = opening * inverse_opening_peak
    sigma = _rising(ratio) * z * tensile if opening < opening_peak else sigma
    sigma = compression if opening < 0.0 else sigma
    # tau / slip: the cohesive shear traction along the slip vector; below the peak
    # (2 - r) r z c / slip with r = slip / slip_peak and c / slip_peak = p / (2 h)
    shear_over_slip = z * cohesion / slip if slip > 0.0 else 0.0
    shear_over_slip = ((2.0 - slip * inverse_slip_peak) * z * 0.5 * penalty_over_h
                       if slip < slip_peak else shear_over_slip)
    return (sigma * nx + shear_over_slip * tx, sigma * ny + shear_over_slip * ty,
            sigma * nz + shear_over_slip * tz, damage, tx, ty, tz, compression)


@inline_kernel
def _law_block(scratch, count, tensile, cohesion, penalty, two_over_penalty,
               half_over_tensile, half_over_cohesion, tensile_over_energy_i, inverse_energy_ii):
    """The law of ``count`` intact joints of one material, from their separations, edges, sizes
    and damage in ``scratch`` (rows ``_SEPARATIONS`` .. ``_DAMAGE_BEFORE``) to their points'
    tractions, damage, slips and compressions (rows ``_TRACTIONS`` .. ``_INVERSE_GRAM``). Reads
    and writes the scratch only, at distances known when compiling, and has no branches or
    calls: LLVM runs it on vector registers (eight joints at once with AVX-512)."""
    for i in range(count):
        d0x, d0y, d0z = _read3(scratch, _SEPARATIONS, i)
        d1x, d1y, d1z = _read3(scratch, _SEPARATIONS + 3, i)
        d2x, d2y, d2z = _read3(scratch, _SEPARATIONS + 6, i)
        e1x, e1y, e1z = _read3(scratch, _EDGES, i)
        e2x, e2y, e2z = _read3(scratch, _EDGES + 3, i)
        h = scratch[_at(_SIZE, i)]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        twice_area = math.sqrt(nx * nx + ny * ny + nz * nz)
        has_area = twice_area > 0.0
        inverse = 1.0 / twice_area if has_area else 0.0
        nx *= inverse
        ny *= inverse
        nz *= inverse
        penalty_over_h = penalty / h
        two_h_over_p = h * two_over_penalty
        opening_peak = two_h_over_p * tensile
        slip_peak = two_h_over_p * cohesion
        inverse_opening_peak = penalty_over_h * half_over_tensile
        inverse_slip_peak = penalty_over_h * half_over_cohesion
        # point q sits midway between vertices q and q + 1
        f0x, f0y, f0z, damage_0, t0x, t0y, t0z, c0 = _point_law(
            0.5 * (d0x + d1x), 0.5 * (d0y + d1y), 0.5 * (d0z + d1z), nx, ny, nz, h, tensile,
            cohesion, penalty_over_h, slip_peak, opening_peak, inverse_opening_peak,
            inverse_slip_peak, tensile_over_energy_i, inverse_energy_ii,
            scratch[_at(_DAMAGE_BEFORE, i)])
        f1x, f1y, f1z, damage_1, t1x, t1y, t1z, c1 = _point_law(
            0.5 * (d1x + d2x), 0.5 * (d1y + d2y), 0.5 * (d1z + d2z), nx, ny, nz, h, tensile,
            cohesion, penalty_over_h, slip_peak, opening_peak, inverse_opening_peak,
            inverse_slip_peak, tensile_over_energy_i, inverse_energy_ii,
            scratch[_at(_DAMAGE_BEFORE + 1, i)])
        f2x, f2y, f2z, damage_2, t2x, t2y, t2z, c2 = _point_law(
            0.5 * (d2x + d0x), 0.5 * (d2y + d0y), 0.5 * (d2z + d0z), nx, ny, nz, h, tensile,
            cohesion, penalty_over_h, slip_peak, opening_peak, inverse_opening_peak,
            inverse_slip_peak, tensile_over_energy_i, inverse_energy_ii,
            scratch[_at(_DAMAGE_BEFORE + 2, i)])
        _write3(scratch, _TRACTIONS, i, f0x, f0y, f0z)
        _write3(scratch, _TRACTIONS + 3, i, f1x, f1y, f1z)
        _write3(scratch, _TRACTIONS + 6, i, f2x, f2y, f2z)
        # a third of the area per point, half of that to each of the point's two vertices
        scratch[_at(_SHARE, i)] = twice_area / 12.0
        # a joint of no area keeps its damage (and gets no force: its share is 0)
        scratch[_at(_DAMAGE, i)] = damage_0 if has_area else scratch[_at(_DAMAGE_BEFORE, i)]
        scratch[_at(_DAMAGE + 1, i)] = damage_1 if has_area else scratch[_at(_DAMAGE_BEFORE + 1, i)]
        scratch[_at(_DAMAGE + 2, i)] = damage_2 if has_area else scratch[_at(_DAMAGE_BEFORE + 2, i)]
        _write3(scratch, _SLIPS, i, t0x, t0y, t0z)
        scratch[_at(_SLIPS + 3, i)] = c0
        _write3(scratch, _SLIPS + 4, i, t1x, t1y, t1z)
        scratch[_at(_SLIPS + 7, i)] = c1
        _write3(scratch, _SLIPS + 8, i, t2x, t2y, t2z)
        scratch[_at(_SLIPS + 11, i)] = c2
        # for the friction anchors: the Gram determinant of the edges is |e1 x e2|^2
        scratch[_at(_INVERSE_GRAM, i)] = inverse * inverse


@inline_kernel
def _gather_block(first, count, positions, joints, sizes, damage, scratch):
    """Separations, mid-surface edges, sizes and damage of joints ``first`` .. ``first + count -
    1`` into their rows of ``scratch`` (for ``_law_block``)."""
    for i in range(count):
        j = first + i
        a0, a1, a2 = joints[j, 0], joints[j, 1], joints[j, 2]
        b0, b1, b2 = joints[j, 3], joints[j, 4], joints[j, 5]
        for d in range(3):
            d0 = positions[b0, d] - positions[a0, d]
            d1 = positions[b1, d] - positions[a1, d]
            d2 = positions[b2, d] - positions[a2, d]
            m0 = positions[a0, d] + 0.5 * d0
            scratch[_at(_SEPARATIONS + d, i)] = d0
            scratch[_at(_SEPARATIONS + 3 + d, i)] = d1
            scratch[_at(_SEPARATIONS + 6 + d, i)] = d2
            scratch[_at(_EDGES + d, i)] = positions[a1, d] + 0.5 * d1 - m0
            scratch[_at(_EDGES + 3 + d, i)] = positions[a2, d] + 0.5 * d2 - m0
        scratch[_at(_SIZE, i)] = sizes[j]
        for q in range(3):
            scratch[_at(_DAMAGE_BEFORE + q, i)] = damage[j, q]


@inline_kernel
def _point_friction(scratch, i, q, tan_phi, penalty_over_h, inverse_gram, anchors, j):
    """``_friction`` at point ``q`` of joint ``i`` of the block (joint ``j``), from its slip and
    compression in the scratch."""
    return _friction(scratch[_at(_SLIPS + 4 * q, i)], scratch[_at(_SLIPS + 4 * q + 1, i)],
                     scratch[_at(_SLIPS + 4 * q + 2, i)], scratch[_at(_SLIPS + 4 * q + 3, i)],
                     tan_phi, penalty_over_h, scratch[_at(_EDGES, i)], scratch[_at(_EDGES + 1, i)],
                     scratch[_at(_EDGES + 2, i)], scratch[_at(_EDGES + 3, i)],
                     scratch[_at(_EDGES + 4, i)], scratch[_at(_EDGES + 5, i)], inverse_gram,
                     anchors, j, q)


@inline_kernel
def _scatter_block(first, count, tan_phi, penalty, damage, broken, anchors, buffer, scratch):
    """Joints ``first`` .. ``first + count - 1`` after ``_law_block``: for each intact one its
    damage, its friction (Coulomb's, from its anchors: ``_friction``) and its forces on its six
    nodes into their rows of ``buffer``; those with two or more points at D >= 1 are marked
    ``broken``. Returns the number broken now."""
    newly = 0
    for i in range(count):
        j = first + i
        if broken[j]:
            continue
        failed = 0
        for q in range(3):
            grown = scratch[_at(_DAMAGE + q, i)]
            failed += grown >= 1.0
            # stored only where it changed: most joints' damage stays, and a store would dirty
            # its line (written back to memory every step)
            if grown != damage[j, q]:
                damage[j, q] = grown
        share = scratch[_at(_SHARE, i)]
        t0x, t0y, t0z = _read3(scratch, _TRACTIONS, i)
        t1x, t1y, t1z = _read3(scratch, _TRACTIONS + 3, i)
        t2x, t2y, t2z = _read3(scratch, _TRACTIONS + 6, i)
        if share > 0.0:
            if failed >= 2:
                broken[j] = True
                newly += 1
            if tan_phi > 0.0:
                penalty_over_h = penalty / scratch[_at(_SIZE, i)]
                inverse_gram = scratch[_at(_INVERSE_GRAM, i)]
                g0x, g0y, g0z = _point_friction(scratch, i, 0, tan_phi, penalty_over_h,
                                                inverse_gram, anchors, j)
                g1x, g1y, g1z = _point_friction(scratch, i, 1, tan_phi, penalty_over_h,
                                                inverse_gram, anchors, j)
                g2x, g2y, g2z = _point_friction(scratch, i, 2, tan_phi, penalty_over_h,
                                                inverse_gram, anchors, j)
                t0x += g0x
                t0y += g0y
                t0z += g0z
                t1x += g1x
                t1y += g1y
                t1z += g1z
                t2x += g2x
                t2y += g2y
                t2z += g2z
        # vertex k takes the points on its two edges: q = k and q = k - 1
        _put_vertex(buffer, j, 0, share * (t0x + t2x), share * (t0y + t2y),
                    share * (t0z + t2z))
        _put_vertex(buffer, j, 1, share * (t0x + t1x), share * (t0y + t1y),
                    share * (t0z + t1z))
        _put_vertex(buffer, j, 2, share * (t1x + t2x), share * (t1y + t2y),
                    share * (t1z + t2z))
    return newly


@inline_kernel
def joint_range(start, stop, positions, joints, sizes, properties, joint_material, damage, broken,
                released, anchors, buffer, scratch):
    """Forces of joints ``start`` .. ``stop - 1`` into their rows of ``buffer`` (as in
    :func:`joint_forces`): first the broken ones (``_broken_joint``), then the intact ones, in
    blocks of up to ``JOINT_BLOCK`` joints of one material: their positions gathered into
    ``scratch`` (``JOINT_SCRATCH_SIZE`` numbers), their law evaluated there eight at a time
    (``_law_block``), their friction and forces scattered back (``_scatter_block``). Intact
    joints with two or more points at D >= 1 are marked ``broken`` (they act as broken joints
    from the next step on). Returns the number broken now. (Two loops: the broken joints' code
    inside the intact joints' loop made every joint about 15 % slower, though few joints ever
    break: bench/joint_kernel.py.)

    13 arguments: called per block inside the parallel element-and-joint loop, whose threads take
    plain arrays (``JointData``'s fields).
    """
    for j in range(start, stop):
        if broken[j]:
            _broken_joint(j, positions, joints, sizes, properties, joint_material, released,
                          anchors, buffer)
    newly = 0
    first = start
    one_material = properties.shape[0] == 1
    while first < stop:
        row = joint_material[first]
        last = min(first + JOINT_BLOCK, stop)
        if not one_material:
            last = first + 1
            while last < stop and last - first < JOINT_BLOCK and joint_material[last] == row:
                last += 1
        count = last - first
        _gather_block(first, count, positions, joints, sizes, damage, scratch)
        # properties (JointMaterial.kernel_row): f_t, c, tan phi, p, f_t A / G_I, A / G_II,
        # 2 / p, 1 / (2 f_t), 1 / (2 c)
        _law_block(scratch, count, properties[row, 0], properties[row, 1], properties[row, 3],
                   properties[row, 6], properties[row, 7], properties[row, 8],
                   properties[row, 4], properties[row, 5])
        newly += _scatter_block(first, count, properties[row, 2], properties[row, 3], damage,
                                broken, anchors, buffer, scratch)
        first = last
    return newly


@leaf_kernel
def joint_forces(positions, joints, sizes, properties, joint_material, damage, broken, released,
                 anchors, buffer, scratch):
    """Forces of every joint (``joint_range``) into ``buffer``; a joint with two or more points
    at D >= 1 is marked ``broken``. Returns the number broken now. ``scratch``: at least
    ``JOINT_SCRATCH_SIZE`` numbers (``np.empty``). (On threads, the joints run in the loop of the
    tets' forces: ``finite_strain.tet4_and_joint_forces``.)

    ``buffer`` (6 n_joints + 1, 3) holds joint j's force on its vertex k (0-2 face A, 3-5 face B)
    in row 6 j + k: each joint's six rows together, the joints in order (the rows are written
    one after the other, not scattered over the tets). The last row stays zero. The node update
    reads the rows at each node's (tet, corner) slots from a table (``slots.joint_slot_sum``,
    ``joints.slot_joint_rows``).

    Compiled without numba's reference counts (``leaf_kernel``: nothing in the joints' code
    allocates): with them, six atomic increments and decrements per joint took 65 % of this
    loop's time (``perf``)."""
    return joint_range(0, joints.shape[0], positions, joints, sizes, properties, joint_material,
                       damage, broken, released, anchors, buffer, scratch)


@kernel
def gather_joint_forces(buffer, node_offsets, node_slots, slot_rows, out):
    """out[node] = the joint forces on it: the buffer's rows (``slot_rows``) of its (tet, corner)
    slots (``node_slots[node_offsets[node]:node_offsets[node + 1]]``, see :func:`joint_forces`).
    (The time step sums them in the node update instead: ``finite_strain.update_node``.)"""
    for node in range(out.shape[0]):
        fx = fy = fz = 0.0
        for s in range(node_offsets[node], node_offsets[node + 1]):
            jx, jy, jz = corner_joint_force(node_slots[s], slot_rows, buffer)
            fx += jx
            fy += jy
            fz += jz
        out[node, 0], out[node, 1], out[node, 2] = fx, fy, fz
