"""Exact volumes of closed triangulated bodies inside the cells of a uniform Cartesian grid, from
their boundary alone.

By the divergence theorem with the field (0, 0, clamp(z - z_k, 0, h)) over the body cut to the
column of cell (i, j, k) (the column's side walls carry no flux), the body's volume in that cell is

    V_ijk = sum over boundary triangles T of  integral over (T projected on the column's square) of
            clamp(z_T(x, y) - z_k, 0, h)  dA_signed,

with dA_signed the projected area taken positive where T's outward normal points up and negative
where it points down. A triangle piece wholly above a cell gives it its signed area times h; one
that the cell's planes cut gives H(z_k) - H(z_k + h), H(t) = the integral of max(z - t, 0) over the
piece, exact for a planar piece by a fan of triangles (the mean of a linear function over a
triangle is its mean at the corners). So only the boundary is clipped (against the columns, then
against the few planes the piece spans), the interior tetrahedra never enter, and the cells below
a piece get its share by one suffix sum along the column. Exact up to round-off, as
``tet_cell_volumes`` (which clips every tetrahedron and stays as the reference).

Round-off: all coordinates are taken relative to the body's block, so sizes are of order h. Below
the lowest surface point of a column the body is absent: those cells are set to exactly 0 (the
column's signed areas cancel there only to round-off). Between two parts of a concave body, a
cell's pieces cancel to round-off too: values within ``_ZERO_FRACTION`` of a cell are set to 0.

Arrays: ``nodes`` (n, 3) world positions (m), ``triangles`` (m, 3) node indices, outward by the
right-hand rule, ``triangle_start`` (bodies + 1) the first triangle of each body; ``lower`` (3,) the
grid's lower corner, ``h`` the cell size; blocks as ``tet_cell_volumes.body_blocks``.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

__all__ = ["fill_blocks", "halve_block"]

# A triangle cut by the 4 sides of a column has at most 7 corners, one more plane adds one.
_MAX_CORNERS = 16
#: Cell volumes below this share of a cell are round-off of cancelling pieces (they are ~1e-16).
_ZERO_FRACTION = 1e-13


@kernel
def _clip(source, count, axis, value, keep_below, target):
    """Sutherland-Hodgman: the part of the polygon ``source`` (count corners (x, y, z), in order)
    with x[axis] <= value (``keep_below``) or >= value, into ``target``; returns its corners.
    Keeps the polygon's orientation."""
    n = 0
    sign = 1.0 if keep_below else -1.0
    for c in range(count):
        nxt = c + 1 if c + 1 < count else 0
        d0 = sign * (source[c, axis] - value)
        d1 = sign * (source[nxt, axis] - value)
        if d0 <= 0.0:
            for a in range(3):
                target[n, a] = source[c, a]
            n += 1
        if (d0 < 0.0 < d1) or (d1 < 0.0 < d0):
            t = d0 / (d0 - d1)
            for a in range(3):
                target[n, a] = source[c, a] + t * (source[nxt, a] - source[c, a])
            target[n, axis] = value             # on the plane exactly
            n += 1
    return n


@kernel
def _height_integral(poly, count, level):
    """The integral of (z - level) over the polygon (signed by its orientation, projected on xy):
    its fan of triangles, each its signed area times the mean of the corners' z - level."""
    total = 0.0
    x0, y0, d0 = poly[0, 0], poly[0, 1], poly[0, 2] - level
    for c in range(1, count - 1):
        ax, ay = poly[c, 0] - x0, poly[c, 1] - y0
        bx, by = poly[c + 1, 0] - x0, poly[c + 1, 1] - y0
        area = 0.5 * (ax * by - ay * bx)
        total += area * (d0 + (poly[c, 2] - level) + (poly[c + 1, 2] - level)) / 3.0
    return total


@kernel
def _signed_area(poly, count):
    total = 0.0
    x0, y0 = poly[0, 0], poly[0, 1]
    for c in range(1, count - 1):
        total += ((poly[c, 0] - x0) * (poly[c + 1, 1] - y0)
                  - (poly[c, 1] - y0) * (poly[c + 1, 0] - x0))
    return 0.5 * total


@kernel
def _add_piece(piece, count, h, bk, column, below, lowest, work):
    """Add one piece (a polygon in a column, block coordinates) to its column's cells: the cells
    its z range spans by H(z_k) - H(z_k + h), those below it by its signed area times h (through
    ``below``, summed later); ``lowest`` (1,) keeps the column's lowest surface point; ``work`` a
    buffer of _MAX_CORNERS corners."""
    z_low = np.inf
    z_high = -np.inf
    for c in range(count):
        z_low = min(z_low, piece[c, 2])
        z_high = max(z_high, piece[c, 2])
    lowest[0] = min(lowest[0], z_low)
    first = int(np.floor(z_low / h))
    last = int(np.floor(z_high / h))
    area = _signed_area(piece, count)
    if area == 0.0:
        return
    below[min(max(first, 0), bk)] += area * h
    if last < 0 or first >= bk:
        return
    upper = _height_integral(piece, count, first * h)       # H at the piece's lowest plane
    for s in range(first, last + 1):
        top = (s + 1) * h
        if s == last:
            lower_of_next = 0.0
        else:
            n = _clip(piece, count, 2, top, False, work)
            lower_of_next = _height_integral(work, n, top) if n >= 3 else 0.0
        if 0 <= s < bk:
            column[s] += upper - lower_of_next
        upper = lower_of_next


@parallel_kernel
def fill_blocks(nodes, triangles, triangle_start, lower, h, origin, shape, offset, values):
    """Solid volume (m^3) in every cell of every body's block from its boundary triangles;
    ``values`` flat, zero on entry. Bodies run in parallel, each on its own block."""
    bodies = len(triangle_start) - 1
    for b in prange(bodies):
        bi, bj, bk = shape[b, 0], shape[b, 1], shape[b, 2]
        if bi == 0 or bj == 0 or bk == 0:
            continue
        block = values[offset[b]:offset[b + 1]].reshape((bi, bj, bk))
        below = np.zeros((bi, bj, bk + 1))
        lowest = np.full((bi, bj), np.inf)
        corner = np.empty(3)
        for a in range(3):
            corner[a] = lower[a] + origin[b, a] * h
        triangle = np.empty((_MAX_CORNERS, 3))
        strip = np.empty((_MAX_CORNERS, 3))
        piece = np.empty((_MAX_CORNERS, 3))
        work = np.empty((_MAX_CORNERS, 3))
        low_mark = np.empty(1)
        for t in range(triangle_start[b], triangle_start[b + 1]):
            for v in range(3):
                for a in range(3):
                    triangle[v, a] = nodes[triangles[t, v], a] - corner[a]
            if _signed_area(triangle, 3) == 0.0:
                continue                          # vertical: no flux through the column's ends
            x_low = min(triangle[0, 0], min(triangle[1, 0], triangle[2, 0]))
            x_high = max(triangle[0, 0], max(triangle[1, 0], triangle[2, 0]))
            p0 = max(int(np.floor(x_low / h)), 0)
            p1 = min(int(np.floor(x_high / h)), bi - 1)
            for p in range(p0, p1 + 1):
                n = _clip(triangle, 3, 0, p * h, False, work)
                n = _clip(work, n, 0, (p + 1) * h, True, strip)
                if n < 3:
                    continue
                y_low = np.inf
                y_high = -np.inf
                for c in range(n):
                    y_low = min(y_low, strip[c, 1])
                    y_high = max(y_high, strip[c, 1])
                q0 = max(int(np.floor(y_low / h)), 0)
                q1 = min(int(np.floor(y_high / h)), bj - 1)
                for q in range(q0, q1 + 1):
                    m = _clip(strip, n, 1, q * h, False, work)
                    m = _clip(work, m, 1, (q + 1) * h, True, piece)
                    if m < 3:
                        continue
                    low_mark[0] = lowest[p, q]
                    _add_piece(piece, m, h, bk, block[p, q], below[p, q], low_mark, work)
                    lowest[p, q] = low_mark[0]
        cell = h * h * h
        for p in range(bi):
            for q in range(bj):
                full = 0.0
                for s in range(bk - 1, -1, -1):
                    full += below[p, q, s + 1]
                    value = block[p, q, s] + full
                    if (s + 1) * h <= lowest[p, q] or abs(value) < _ZERO_FRACTION * cell:
                        value = 0.0
                    block[p, q, s] = value


@kernel
def halve_block(fine_origin, fine_volumes, origin, cells, halves):
    """Sum a block of volumes on the grid of half the cell size (starting at fine grid index
    ``fine_origin``) into the cells of the grid (``cells`` (bi, bj, bk), block starting at
    ``origin``) and into each cell's lower and upper halves along every axis (``halves``
    (bi, bj, bk, 3, 2)); both zero on entry."""
    fi, fj, fk = fine_volumes.shape
    for p in range(fi):
        gi = fine_origin[0] + p
        ci, si = gi // 2 - origin[0], gi % 2
        for q in range(fj):
            gj = fine_origin[1] + q
            cj, sj = gj // 2 - origin[1], gj % 2
            for r in range(fk):
                volume = fine_volumes[p, q, r]
                if volume == 0.0:
                    continue
                gk = fine_origin[2] + r
                ck, sk = gk // 2 - origin[2], gk % 2
                cells[ci, cj, ck] += volume
                halves[ci, cj, ck, 0, si] += volume
                halves[ci, cj, ck, 1, sj] += volume
                halves[ci, cj, ck, 2, sk] += volume
