"""Exact volumes of tetrahedral meshes inside the cells of a uniform Cartesian grid.

The seed paper couples solids to the fluid through a supermesh: the intersection of every solid
element with every fluid element, which gives each fluid cell the exact volume of solid it holds
(Xiang et al., their section 2.3). On riprap's Cartesian grid the fluid elements are boxes, and the
intersection of a tetrahedron with a box is found by clipping: the tetrahedron is cut by the grid
planes one axis at a time (x slabs, then y rows of each slab piece, then z cells of each row
piece), and every cut of a tetrahedron by a plane leaves, on each side, a tetrahedron or a
triangular prism, which is split into three tetrahedra. The volumes of the pieces in a cell are
summed. Exact up to round-off; no sampling.

Work is per body: each body's tetrahedra fill a block of cells around the body (its bounding box
in cells), so bodies run in parallel without sharing any output, and the result does not depend on
the number of threads.

Arrays: ``nodes`` (n, 3) world positions (m), ``tets`` (m, 4) node indices, ``tet_start`` (bodies
+ 1) the first tetrahedron of each body; ``lower`` (3,) the grid's lower corner, ``h`` the cell size.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

__all__ = ["body_blocks", "fill_blocks", "clip_volume"]

# Pieces one tetrahedron may become inside one slab / row / cell: each cut at most triples them,
# two cuts per axis; a cut that leaves more is a bug, not a large body.
_MAX_PIECES = 3 ** 6


@kernel
def _work_arrays():
    """Cut points (4, 3), signed distances (4,), inside and outside corner lists (4,) each: made
    once per body, not per cut."""
    return (np.empty((4, 3)), np.empty(4), np.empty(4, dtype=np.int64),
            np.empty(4, dtype=np.int64))


@kernel
def _tet_volume(p):
    a = p[1] - p[0]
    b = p[2] - p[0]
    c = p[3] - p[0]
    return abs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0


@kernel
def _cut_point(p, q, dp, dq, out):
    """The point where the segment p-q crosses the plane (signed distances dp, dq of opposite
    signs)."""
    t = dp / (dp - dq)
    for a in range(3):
        out[a] = p[a] + t * (q[a] - p[a])


@kernel
def _push(pieces, count, p0, p1, p2, p3):
    for a in range(3):
        pieces[count, 0, a] = p0[a]
        pieces[count, 1, a] = p1[a]
        pieces[count, 2, a] = p2[a]
        pieces[count, 3, a] = p3[a]
    return count + 1


@kernel
def _push_prism(pieces, count, a, b, c, top_a, top_b, top_c):
    """A triangular prism a b c / top_a top_b top_c (top_x joined to x) as three tetrahedra."""
    count = _push(pieces, count, a, b, c, top_a)
    count = _push(pieces, count, b, c, top_a, top_b)
    return _push(pieces, count, c, top_a, top_b, top_c)


@kernel
def _keep_side(source, source_count, axis, value, keep_below, target, work):
    """Clip each tetrahedron of ``source`` by the plane x[axis] = value, keeping the part below
    (``keep_below``) or above it; the pieces go to ``target``. Returns their number."""
    count = 0
    sign = 1.0 if keep_below else -1.0
    scratch, distance, inside, outside = work
    for s in range(source_count):
        p = source[s]
        n_in = 0
        n_out = 0
        for v in range(4):
            distance[v] = sign * (p[v, axis] - value)
            if distance[v] <= 0.0:
                inside[n_in] = v
                n_in += 1
            else:
                outside[n_out] = v
                n_out += 1
        if n_in == 0:
            continue
        if n_in == 4:
            count = _push(target, count, p[0], p[1], p[2], p[3])
            continue
        if n_in == 1:
            a = inside[0]
            for e in range(3):
                o = outside[e]
                _cut_point(p[a], p[o], distance[a], distance[o], scratch[e])
            count = _push(target, count, p[a], scratch[0], scratch[1], scratch[2])
        elif n_in == 3:
            # the tetrahedron less its corner beyond the plane: a prism from the inside face
            o = outside[0]
            for e in range(3):
                v = inside[e]
                _cut_point(p[v], p[o], distance[v], distance[o], scratch[e])
            count = _push_prism(target, count, p[inside[0]], p[inside[1]], p[inside[2]],
                                scratch[0], scratch[1], scratch[2])
        else:
            # two inside (a, b), two outside (c, d): a prism a, a-c, a-d / b, b-c, b-d
            a = inside[0]
            b = inside[1]
            c = outside[0]
            d = outside[1]
            _cut_point(p[a], p[c], distance[a], distance[c], scratch[0])
            _cut_point(p[a], p[d], distance[a], distance[d], scratch[1])
            _cut_point(p[b], p[c], distance[b], distance[c], scratch[2])
            _cut_point(p[b], p[d], distance[b], distance[d], scratch[3])
            count = _push_prism(target, count, p[a], scratch[0], scratch[1], p[b], scratch[2],
                                scratch[3])
    return count


@kernel
def _extent(pieces, count, axis):
    """Smallest and largest coordinate along ``axis`` of the pieces' corners."""
    smallest = np.inf
    largest = -np.inf
    for s in range(count):
        for v in range(4):
            x = pieces[s, v, axis]
            smallest = min(smallest, x)
            largest = max(largest, x)
    return smallest, largest


@kernel
def _keep_slab(source, source_count, axis, low, high, middle, target, work):
    """Pieces of ``source`` with low <= x[axis] <= high (``middle`` is a work buffer). Planes that
    no piece crosses are not cut."""
    smallest, largest = _extent(source, source_count, axis)
    cut_low = smallest < low
    cut_high = largest > high
    if cut_low and cut_high:
        count = _keep_side(source, source_count, axis, low, False, middle, work)
        return _keep_side(middle, count, axis, high, True, target, work)
    if cut_low:
        return _keep_side(source, source_count, axis, low, False, target, work)
    if cut_high:
        return _keep_side(source, source_count, axis, high, True, target, work)
    target[:source_count] = source[:source_count]
    return source_count


@kernel
def _range_of(pieces, count, axis, lower, h, size):
    """Cells along ``axis`` that the pieces reach (first, last), clipped to 0..size-1."""
    smallest, largest = _extent(pieces, count, axis)
    first = int(np.floor((smallest - lower) / h))
    last = int(np.floor((largest - lower) / h))
    return max(first, 0), min(last, size - 1)


@kernel
def _inside_cell(corners, lower, h, i, j, k):
    """Whether all four corners lie in cell (i, j, k)."""
    index = (i, j, k)
    for v in range(4):
        for a in range(3):
            low = lower[a] + index[a] * h
            if corners[v, a] < low or corners[v, a] > low + h:
                return False
    return True


@kernel
def _add_tet(corners, lower, h, block_origin, block_shape, block, buffers, work):
    """Add the volume of one tetrahedron (corners (4, 3)) to the cells of ``block``."""
    slab, row, cell, middle = buffers[0], buffers[1], buffers[2], buffers[3]
    for v in range(4):
        for a in range(3):
            slab[0, v, a] = corners[v, a]
    end = block_origin + block_shape
    i0, i1 = _range_of(slab, 1, 0, lower[0], h, end[0])
    j0, j1 = _range_of(slab, 1, 1, lower[1], h, end[1])
    k0, k1 = _range_of(slab, 1, 2, lower[2], h, end[2])
    i0 = max(i0, block_origin[0])
    j0 = max(j0, block_origin[1])
    k0 = max(k0, block_origin[2])
    if i0 > i1 or j0 > j1 or k0 > k1:
        return                                   # outside the grid
    if i0 == i1 and j0 == j1 and k0 == k1 and _inside_cell(corners, lower, h, i0, j0, k0):
        # the whole tetrahedron in one cell (small elements in large cells): no clipping
        block[i0 - block_origin[0], j0 - block_origin[1], k0 - block_origin[2]] += _tet_volume(corners)
        return
    source = buffers[4]
    for v in range(4):
        for a in range(3):
            source[0, v, a] = corners[v, a]
    for i in range(i0, i1 + 1):
        x_low = lower[0] + i * h
        n_slab = _keep_slab(source, 1, 0, x_low, x_low + h, middle, slab, work)
        if n_slab == 0:
            continue
        ja, jb = _range_of(slab, n_slab, 1, lower[1], h, block_origin[1] + block_shape[1])
        for j in range(max(ja, j0), jb + 1):
            y_low = lower[1] + j * h
            n_row = _keep_slab(slab, n_slab, 1, y_low, y_low + h, middle, row, work)
            if n_row == 0:
                continue
            ka, kb = _range_of(row, n_row, 2, lower[2], h, block_origin[2] + block_shape[2])
            for k in range(max(ka, k0), kb + 1):
                z_low = lower[2] + k * h
                n_cell = _keep_slab(row, n_row, 2, z_low, z_low + h, middle, cell, work)
                volume = 0.0
                for s in range(n_cell):
                    volume += _tet_volume(cell[s])
                block[i - block_origin[0], j - block_origin[1], k - block_origin[2]] += volume


def body_blocks(nodes, tets, tet_start, lower, h, cells):
    """Per body the block of cells its bounding box reaches, clipped to the grid: (origin (b, 3),
    shape (b, 3), offset (b + 1,) into one flat array of all blocks). A body wholly outside the
    grid gets an empty block."""
    lower = np.asarray(lower, dtype=float)
    cells = np.asarray(cells, dtype=np.int64)
    bodies = len(tet_start) - 1
    origin = np.zeros((bodies, 3), dtype=np.int64)
    shape = np.zeros((bodies, 3), dtype=np.int64)
    for b in range(bodies):
        used = nodes[np.unique(tets[tet_start[b]:tet_start[b + 1]])]
        if len(used) == 0:
            continue
        first = np.floor((used.min(axis=0) - lower) / h).astype(np.int64)
        last = np.floor((used.max(axis=0) - lower) / h).astype(np.int64)
        first = np.clip(first, 0, cells)
        last = np.clip(last, -1, cells - 1)
        origin[b] = first
        shape[b] = np.maximum(last - first + 1, 0)
    offset = np.zeros(bodies + 1, dtype=np.int64)
    offset[1:] = np.cumsum(shape.prod(axis=1))
    return origin, shape, offset


@parallel_kernel
def fill_blocks(nodes, tets, tet_start, lower, h, origin, shape, offset, values):
    """Solid volume (m^3) in every cell of every body's block; ``values`` flat, zero on entry."""
    bodies = len(tet_start) - 1
    for b in prange(bodies):
        if shape[b, 0] == 0 or shape[b, 1] == 0 or shape[b, 2] == 0:
            continue
        block = values[offset[b]:offset[b + 1]].reshape((shape[b, 0], shape[b, 1], shape[b, 2]))
        buffers = np.empty((5, _MAX_PIECES, 4, 3))
        work = _work_arrays()
        corners = np.empty((4, 3))
        for t in range(tet_start[b], tet_start[b + 1]):
            for v in range(4):
                for a in range(3):
                    corners[v, a] = nodes[tets[t, v], a]
            _add_tet(corners, lower, h, origin[b], shape[b], block, buffers, work)


@kernel
def clip_volume(corners, box_lower, box_upper):
    """Volume of the tetrahedron ``corners`` (4, 3) inside the box box_lower..box_upper (for
    tests and single queries)."""
    buffers = np.empty((3, _MAX_PIECES, 4, 3))
    work = _work_arrays()
    for v in range(4):
        for a in range(3):
            buffers[0, 0, v, a] = corners[v, a]
    count = 1
    current = 0
    for axis in range(3):
        count = _keep_slab(buffers[current], count, axis, box_lower[axis], box_upper[axis],
                           buffers[2], buffers[1 - current], work)
        current = 1 - current
    volume = 0.0
    for s in range(count):
        volume += _tet_volume(buffers[current, s])
    return volume
