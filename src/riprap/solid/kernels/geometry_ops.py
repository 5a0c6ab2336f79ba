"""Small compiled helpers shared by the contact kernels: quaternions, polygon clipping, integrals.

A clipped polygon is a (MAX_POLYGON, 7) array: columns 0-2 the position, columns 3-6 the four
barycentric coordinates of the tet whose potential is integrated (linear along edges, so clipping
interpolates them exactly).
"""
import numpy as np

from riprap._jit import kernel

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


@kernel
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


@kernel
def integrate_tet_potential_on_polygon(polygon, n_vertices, gradients, normal, work_a, work_b,
                                       signed, moments):
    """Integrate a tet's potential phi = 4 min_k lambda_k over a polygon that lies in the tet's
    barycentric columns 3-6, splitting it into the four sub-tet regions.

    ``gradients`` (4, 3): grad lambda_k. Adds to ``moments`` [0] int phi dA, [1:4] int x phi dA,
    [4] area, [5] int |grad phi . normal| dA (the rate at which the integral grows with a normal
    push: the contact's stiffness per unit penalty).
    """
    for k in range(4):
        # Region of sub-tet k: lambda_k >= 0 and lambda_j - lambda_k >= 0 for j != k.
        for i in range(n_vertices):
            for c in range(7):
                work_a[i, c] = polygon[i, c]
        m = n_vertices
        for i in range(m):
            signed[i] = work_a[i, 3 + k]
        m = clip_polygon(work_a, m, signed, work_b)
        source = work_b
        target = work_a
        for j in range(4):
            if j == k or m < 3:
                continue
            for i in range(m):
                signed[i] = source[i, 3 + j] - source[i, 3 + k]
            m = clip_polygon(source, m, signed, target)
            source, target = target, source
        if m < 3:
            continue
        before = moments[4]
        integrate_linear_on_polygon(source, m, 3 + k, 4.0, normal, moments)
        sub_area = moments[4] - before
        g = 4.0 * (gradients[k, 0] * normal[0] + gradients[k, 1] * normal[1]
                   + gradients[k, 2] * normal[2])
        moments[5] += sub_area * abs(g)


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
