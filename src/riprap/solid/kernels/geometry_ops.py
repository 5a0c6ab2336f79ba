"""Small compiled helpers shared by the contact kernels: quaternions, polygon clipping, integrals.

A clipped polygon is a (MAX_POLYGON, 7) array: columns 0-2 the position, columns 3-6 the four
barycentric coordinates of the tet whose potential is integrated (linear along edges, so clipping
interpolates them exactly).
"""
import numpy as np

from riprap._jit import kernel, leaf_kernel

MAX_POLYGON = 16


@kernel
def rotation_matrix(q):
    """Rotation matrix of the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    r = np.empty((3, 3))
    r[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    r[0, 1] = 2.0 * (x * y - w * z)
    r[0, 2] = 2.0 * (x * z + w * y)
    r[1, 0] = 2.0 * (x * y + w * z)
    r[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    r[1, 2] = 2.0 * (y * z - w * x)
    r[2, 0] = 2.0 * (x * z - w * y)
    r[2, 1] = 2.0 * (y * z + w * x)
    r[2, 2] = 1.0 - 2.0 * (x * x + y * y)
    return r


@kernel
def rotation_matrices(quaternions):
    """Rotation matrices (n, 3, 3) of n unit quaternions (n, 4), each as :func:`rotation_matrix`."""
    out = np.empty((quaternions.shape[0], 3, 3))
    for b in range(quaternions.shape[0]):
        out[b] = rotation_matrix(quaternions[b])
    return out


@leaf_kernel
def clip_polygon(polygon, n_vertices, signed, out):
    """Keep the part of a convex polygon where ``signed`` (one value per vertex) is >= 0.

    Returns the number of vertices written to ``out`` (0 if nothing is left). Sutherland-Hodgman;
    all 7 columns are interpolated linearly, which is exact for positions and barycentrics.
    """
    m = 0
    for i in range(n_vertices):
        j = i + 1
        if j == n_vertices:
            j = 0
        si = signed[i]
        sj = signed[j]
        if si >= 0.0:
            for c in range(7):
                out[m, c] = polygon[i, c]
            m += 1
        if (si >= 0.0) != (sj >= 0.0):
            t = si / (si - sj)
            for c in range(7):
                out[m, c] = polygon[i, c] + t * (polygon[j, c] - polygon[i, c])
            m += 1
    return m


@leaf_kernel
def integrate_linear_on_polygon(polygon, n_vertices, value_column, scale, normal, moments):
    """Integrate f = scale * polygon[:, value_column] over a planar convex polygon.

    Adds to ``moments``: [0] the integral of f dA, [1:4] the integral of x f dA, [4] the area, using
    exact formulas for a linear function on each fan triangle. ``normal`` orients the signed area
    (the polygon lies in a plane with that normal and its vertices are counter-clockwise about it).
    """
    if n_vertices < 3:
        return
    x0 = polygon[0, 0]
    y0 = polygon[0, 1]
    z0 = polygon[0, 2]
    f0 = scale * polygon[0, value_column]
    for i in range(1, n_vertices - 1):
        ax = polygon[i, 0] - x0
        ay = polygon[i, 1] - y0
        az = polygon[i, 2] - z0
        bx = polygon[i + 1, 0] - x0
        by = polygon[i + 1, 1] - y0
        bz = polygon[i + 1, 2] - z0
        cx = ay * bz - az * by
        cy = az * bx - ax * bz
        cz = ax * by - ay * bx
        area = 0.5 * (cx * normal[0] + cy * normal[1] + cz * normal[2])
        if area <= 0.0:
            continue
        f1 = scale * polygon[i, value_column]
        f2 = scale * polygon[i + 1, value_column]
        fsum = f0 + f1 + f2
        moments[0] += area * fsum / 3.0
        # integral of x f over a triangle = A/12 * (sum f * sum x + sum f_i x_i)
        for c in range(3):
            xsum = polygon[0, c] + polygon[i, c] + polygon[i + 1, c]
            weighted = f0 * polygon[0, c] + f1 * polygon[i, c] + f2 * polygon[i + 1, c]
            moments[1 + c] += area / 12.0 * (fsum * xsum + weighted)
        moments[4] += area


@leaf_kernel
def integrate_tet_potential_on_polygon(polygon, n_vertices, gradients, normal, work_a, work_b,
                                       signed, moments):
    """Integrate a tet's potential phi = 4 min_k lambda_k over the part of a planar polygon inside
    the tet; the polygon carries the tet's barycentric coordinates in columns 3-6.

    ``gradients`` (4, 3): grad lambda_k. Adds to ``moments`` [0] int phi dA, [1:4] int x phi dA,
    [4] area, [5] int |grad phi . normal| dA (the rate at which the integral grows with a normal
    push: the contact's stiffness per unit penalty). ``polygon`` is overwritten.
    """
    # First the whole tet (lambda_k >= 0 for all k): most polygons that reach here only graze it.
    # Results ping-pong between work_a and work_b; ``in_a`` says where the current polygon is.
    m = n_vertices
    for i in range(m):
        for c in range(7):
            work_b[i, c] = polygon[i, c]
    in_a = False
    for k in range(4):
        all_in = True
        for i in range(m):
            value = work_a[i, 3 + k] if in_a else work_b[i, 3 + k]
            signed[i] = value
            if value < 0.0:
                all_in = False
        if all_in:
            continue
        if in_a:
            m = clip_polygon(work_a, m, signed, work_b)
        else:
            m = clip_polygon(work_b, m, signed, work_a)
        in_a = not in_a
        if m < 3:
            return
    for i in range(m):
        for c in range(7):
            polygon[i, c] = work_a[i, c] if in_a else work_b[i, c]
    inside = m
    # Then the four sub-tets: region k is lambda_j - lambda_k >= 0 for j != k.
    for k in range(4):
        m = inside
        for i in range(m):
            for c in range(7):
                work_b[i, c] = polygon[i, c]
        in_a = False
        for j in range(4):
            if j == k:
                continue
            all_in = True
            any_in = False
            for i in range(m):
                if in_a:
                    value = work_a[i, 3 + j] - work_a[i, 3 + k]
                else:
                    value = work_b[i, 3 + j] - work_b[i, 3 + k]
                signed[i] = value
                if value < 0.0:
                    all_in = False
                else:
                    any_in = True
            if all_in:
                continue
            if not any_in:
                m = 0
                break
            if in_a:
                m = clip_polygon(work_a, m, signed, work_b)
            else:
                m = clip_polygon(work_b, m, signed, work_a)
            in_a = not in_a
            if m < 3:
                break
        if m < 3:
            continue
        before = moments[4]
        if in_a:
            integrate_linear_on_polygon(work_a, m, 3 + k, 4.0, normal, moments)
        else:
            integrate_linear_on_polygon(work_b, m, 3 + k, 4.0, normal, moments)
        sub_area = moments[4] - before
        g = 4.0 * (gradients[k, 0] * normal[0] + gradients[k, 1] * normal[1]
                   + gradients[k, 2] * normal[2])
        moments[5] += sub_area * abs(g)


@leaf_kernel
def integrate_tet_potential_on_triangle(lam, vertices, barycentric, t, normal, polygons, signed,
                                        moments):
    """Integrate a tet's potential phi = 4 min_k lambda_k over the part of a triangle inside the
    tet, adding to ``moments`` the same quantities as :func:`integrate_tet_potential_on_polygon`
    (which it replaces for boundary triangles: same integrals, a fraction of the work).

    The clipping is done in the triangle's own affine coordinates (mu1, mu2), x = V0 + mu1 (V1 -
    V0) + mu2 (V2 - V0): every lambda_k is affine in them, so a polygon is two columns, a clipping
    line three numbers, and dA = 2 A dmu with A the triangle's area. ``lam`` (3, 4): barycentrics
    of the three vertices; ``barycentric[t, k, 0:3]``: grad lambda_k (the tet's row, not a slice of
    it: a slice per piece cost an atomic reference count each way); ``polygons`` (3, MAX_POLYGON, 2)
    and ``signed`` (MAX_POLYGON,): work arrays. The triangle is counter-clockwise about ``normal``.
    """
    ex = vertices[1, 0] - vertices[0, 0]
    ey = vertices[1, 1] - vertices[0, 1]
    ez = vertices[1, 2] - vertices[0, 2]
    fx = vertices[2, 0] - vertices[0, 0]
    fy = vertices[2, 1] - vertices[0, 1]
    fz = vertices[2, 2] - vertices[0, 2]
    jacobian = ((ey * fz - ez * fy) * normal[0] + (ez * fx - ex * fz) * normal[1]
                + (ex * fy - ey * fx) * normal[2])          # 2 A
    if jacobian <= 0.0:
        return
    # The unit triangle, counter-clockwise in (mu1, mu2); then the part inside the tet.
    polygons[0, 0, 0] = 0.0
    polygons[0, 0, 1] = 0.0
    polygons[0, 1, 0] = 1.0
    polygons[0, 1, 1] = 0.0
    polygons[0, 2, 0] = 0.0
    polygons[0, 2, 1] = 1.0
    m = 3
    current = 0
    for k in range(4):
        # lambda_k(mu) = c0 + c1 mu1 + c2 mu2
        c0 = lam[0, k]
        c1 = lam[1, k] - c0
        c2 = lam[2, k] - c0
        target = 1 if current == 0 else 0
        m, moved = _clip_by_line(polygons, current, target, m, c0, c1, c2, signed)
        if m < 3:
            return
        if moved:
            current = target
    inside = current
    area_mu = 0.0
    integral = 0.0
    first_1 = 0.0
    first_2 = 0.0
    stiffness = 0.0
    # The sub-tet regions {lambda_k <= lambda_j for all j} are convex: when every vertex of the
    # (convex) polygon has the same smallest lambda, the whole polygon lies in that one sub-tet.
    # This is the usual case of a shallow contact, and it needs no further clipping.
    common = -1
    for i in range(m):
        u = polygons[inside, i, 0]
        v = polygons[inside, i, 1]
        smallest = np.inf
        which = 0
        for k in range(4):
            value = lam[0, k] + (lam[1, k] - lam[0, k]) * u + (lam[2, k] - lam[0, k]) * v
            if value < smallest:
                smallest = value
                which = k
        if i == 0:
            common = which
        elif which != common:
            common = -1
            break
    first_spare = 1 if inside == 0 else 0
    second_spare = 3 - inside - first_spare
    for k in range(4):
        if common >= 0 and k != common:
            continue
        # Sub-tet k: lambda_j - lambda_k >= 0 for every j != k; there phi = 4 lambda_k.
        current = inside
        count = m
        if common < 0:
            for j in range(4):
                if j == k:
                    continue
                d0 = lam[0, j] - lam[0, k]
                d1 = (lam[1, j] - lam[1, k]) - d0
                d2 = (lam[2, j] - lam[2, k]) - d0
                target = first_spare if current != first_spare else second_spare
                count, moved = _clip_by_line(polygons, current, target, count, d0, d1, d2, signed)
                if count < 3:
                    break
                if moved:
                    current = target
            if count < 3:
                continue
        piece_integral, piece_1, piece_2, piece_area = _integrate_fan(
            polygons, current, count, 4.0 * lam[0, k], 4.0 * (lam[1, k] - lam[0, k]),
            4.0 * (lam[2, k] - lam[0, k]))
        integral += piece_integral
        first_1 += piece_1
        first_2 += piece_2
        area_mu += piece_area
        g = 4.0 * (barycentric[t, k, 0] * normal[0] + barycentric[t, k, 1] * normal[1]
                   + barycentric[t, k, 2] * normal[2])
        stiffness += piece_area * abs(g)
    # Back to x: dA = jacobian dmu, x = V0 + mu1 e + mu2 f.
    moments[0] += jacobian * integral
    moments[1] += jacobian * (vertices[0, 0] * integral + ex * first_1 + fx * first_2)
    moments[2] += jacobian * (vertices[0, 1] * integral + ey * first_1 + fy * first_2)
    moments[3] += jacobian * (vertices[0, 2] * integral + ez * first_1 + fz * first_2)
    moments[4] += jacobian * area_mu
    moments[5] += jacobian * stiffness


@leaf_kernel
def _integrate_fan(polygons, current, count, c0, c1, c2):
    """Integrals of f = c0 + c1 mu1 + c2 mu2 over the convex polygon ``polygons[current]`` (mu
    coordinates): (int f, int mu1 f, int mu2 f, area), exactly, over its fan triangles."""
    u0 = polygons[current, 0, 0]
    v0 = polygons[current, 0, 1]
    f0 = c0 + c1 * u0 + c2 * v0
    integral = 0.0
    first_1 = 0.0
    first_2 = 0.0
    total_area = 0.0
    for i in range(1, count - 1):
        u1 = polygons[current, i, 0]
        v1 = polygons[current, i, 1]
        u2 = polygons[current, i + 1, 0]
        v2 = polygons[current, i + 1, 1]
        area = 0.5 * ((u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0))
        if area <= 0.0:
            continue
        f1 = c0 + c1 * u1 + c2 * v1
        f2 = c0 + c1 * u2 + c2 * v2
        fsum = f0 + f1 + f2
        integral += area * fsum / 3.0
        # integral of mu f over a triangle = A/12 (sum f sum mu + sum f_i mu_i)
        first_1 += area / 12.0 * (fsum * (u0 + u1 + u2) + f0 * u0 + f1 * u1 + f2 * u2)
        first_2 += area / 12.0 * (fsum * (v0 + v1 + v2) + f0 * v0 + f1 * v1 + f2 * v2)
        total_area += area
    return integral, first_1, first_2, total_area


@leaf_kernel
def _clip_by_line(polygons, source, target, n_vertices, c0, c1, c2, signed):
    """Keep the part of convex polygon ``polygons[source]`` (mu coordinates) where c0 + c1 mu1 +
    c2 mu2 >= 0. Returns (vertex count, whether it was written to ``polygons[target]``); a polygon
    wholly inside is left where it is."""
    all_in = True
    any_in = False
    for i in range(n_vertices):
        value = c0 + c1 * polygons[source, i, 0] + c2 * polygons[source, i, 1]
        signed[i] = value
        if value < 0.0:
            all_in = False
        else:
            any_in = True
    if all_in:
        return n_vertices, False
    if not any_in:
        return 0, False
    m = 0
    for i in range(n_vertices):
        j = i + 1
        if j == n_vertices:
            j = 0
        si = signed[i]
        sj = signed[j]
        if si >= 0.0:
            polygons[target, m, 0] = polygons[source, i, 0]
            polygons[target, m, 1] = polygons[source, i, 1]
            m += 1
        if (si >= 0.0) != (sj >= 0.0):
            t = si / (si - sj)
            polygons[target, m, 0] = polygons[source, i, 0] + t * (polygons[source, j, 0] - polygons[source, i, 0])
            polygons[target, m, 1] = polygons[source, i, 1] + t * (polygons[source, j, 1] - polygons[source, i, 1])
            m += 1
    return m, True


@kernel
def mat3_vec(a, v):
    out = np.empty(3)
    for i in range(3):
        out[i] = a[i, 0] * v[0] + a[i, 1] * v[1] + a[i, 2] * v[2]
    return out


@kernel
def mat3_transposed_vec(a, v):
    out = np.empty(3)
    for i in range(3):
        out[i] = a[0, i] * v[0] + a[1, i] * v[1] + a[2, i] * v[2]
    return out


@kernel
def mat3_mul_transposed(a, b):
    """a^T b for 3x3 matrices."""
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            out[i, j] = a[0, i] * b[0, j] + a[1, i] * b[1, j] + a[2, i] * b[2, j]
    return out


@kernel
def surface_clearance(points, nodes, triangles, tets, barycentric, cell_of_point_tets_start,
                      cell_of_point_tets):
    """Distance from each point to a closed tetrahedral body: 0 inside, else the exact distance
    to the nearest boundary triangle. Candidate tets for the inside test come in CSR form."""
    n = points.shape[0]
    out = np.empty(n)
    for p in range(n):
        x = points[p]
        inside = False
        for e in range(cell_of_point_tets_start[p], cell_of_point_tets_start[p + 1]):
            t = cell_of_point_tets[e]
            ok = True
            for k in range(4):
                lam = (barycentric[t, k, 0] * x[0] + barycentric[t, k, 1] * x[1]
                       + barycentric[t, k, 2] * x[2] + barycentric[t, k, 3])
                if lam < 0.0:
                    ok = False
                    break
            if ok:
                inside = True
                break
        if inside:
            out[p] = 0.0
            continue
        best = np.inf
        for f in range(triangles.shape[0]):
            d = _point_triangle_distance(x, nodes[triangles[f, 0]], nodes[triangles[f, 1]],
                                         nodes[triangles[f, 2]])
            if d < best:
                best = d
        out[p] = best
    return out


@kernel
def _point_triangle_distance(p, a, b, c):
    """Exact distance from point p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5)."""
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = ab @ ap
    d2 = ac @ ap
    if d1 <= 0.0 and d2 <= 0.0:
        return np.sqrt(ap @ ap)
    bp = p - b
    d3 = ab @ bp
    d4 = ac @ bp
    if d3 >= 0.0 and d4 <= d3:
        return np.sqrt(bp @ bp)
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        q = a + v * ab - p
        return np.sqrt(q @ q)
    cp = p - c
    d5 = ab @ cp
    d6 = ac @ cp
    if d6 >= 0.0 and d5 <= d6:
        return np.sqrt(cp @ cp)
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        q = a + w * ac - p
        return np.sqrt(q @ q)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        q = b + w * (c - b) - p
        return np.sqrt(q @ q)
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    q = a + ab * v + ac * w - p
    return np.sqrt(q @ q)
