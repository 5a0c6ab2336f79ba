"""The speeds that bound the time step, face by face, and a cap on the air's.

A face's pore speed is |u| / n_face, n_face the smaller porosity of the cells beside it (1 outside
porous zones): the speed at which the water in those pores moves, which the volume-of-fluid step
needs under its Courant limit (``plic.advect_sweep`` cuts the slab of a cell at |u| dt / (n h)).
Taking the smallest porosity of the whole grid instead, as a global bound would, holds a breaking
wave in open water to the step of the core's pores (2.5 times shorter at n = 0.4).

A face touches water when a cell beside it holds more than a trace (f > ``WET_FRACTION``): only
through such faces does the volume-of-fluid step move more than traces of water; a face beside
traces alone may be capped, which moves those traces slower and keeps every sum of water exact
(the sweeps move water in flux form). Face ``index`` along ``axis`` lies between cells ``index - 1``
and ``index``; a boundary face has one cell beside it. Arrays: ``f`` and ``porosity`` (nx, ny,
nz); ``q`` the velocity component along ``axis`` on its faces (one more entry along ``axis``),
C-ordered float64.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

#: A cell holds water, for the step's Courant number and the air cap, when its water fraction is
#: above this. Spray and the round-off traces the sweeps leave (fractions of 1e-30 beside air
#: moving at 10 m/s) are air here: under attack in examples/10 they set 43 % of the steps, the
#: step falling to 2.5 ms for a face beside f = 5e-7. OpenFOAM's interFoam takes its interface
#: Courant number over 0.01 < alpha < 0.99 for the same reason (``nearInterface``).
WET_FRACTION = 1e-2


@kernel
def _beside(cells, axis, i, j, k, periodic_y):
    """(value of the cell before the face or -1.0, value of the cell after it or -1.0) for
    non-negative cell fields; on a ``periodic_y`` the y faces 0 and ny lie between the cells
    ny - 1 and 0, so that the two stay alike."""
    n = cells.shape[axis]
    index = i if axis == 0 else (j if axis == 1 else k)
    if periodic_y and axis == 1:
        return cells[i, (j - 1 + n) % n, k], cells[i, j % n, k]
    after = cells[i, j, k] if index < n else -1.0
    before = -1.0
    if index > 0:
        if axis == 0:
            before = cells[i - 1, j, k]
        elif axis == 1:
            before = cells[i, j - 1, k]
        else:
            before = cells[i, j, k - 1]
    return before, after


@kernel
def _touches_water(f, axis, i, j, k, periodic_y):
    before, after = _beside(f, axis, i, j, k, periodic_y)
    return before > WET_FRACTION or after > WET_FRACTION


@kernel
def _open_part(porosity, axis, i, j, k, periodic_y):
    """The smaller porosity of the cells beside the face."""
    before, after = _beside(porosity, axis, i, j, k, periodic_y)
    if before < 0.0:
        return after
    if after < 0.0:
        return before
    return min(before, after)


@parallel_kernel
def largest_pore_speed(f, q, axis, porosity, water_only, periodic_y=False):
    """Largest |q| / n_face over the faces of ``axis`` (only those that touch water if
    ``water_only``); 0.0 if none."""
    nx, ny, nz = q.shape
    largest = np.zeros(nx)
    for outer in prange(nx):
        i = np.int64(outer)
        best = 0.0
        for j in range(ny):
            for k in range(nz):
                speed = abs(q[i, j, k])
                if speed == 0.0 or speed <= best:
                    continue
                if water_only and not _touches_water(f, axis, i, j, k, periodic_y):
                    continue
                speed /= _open_part(porosity, axis, i, j, k, periodic_y)
                if speed > best:
                    best = speed
        largest[i] = best
    return largest.max() if nx > 0 else 0.0


@parallel_kernel
def limit_air_faces(f, q, axis, porosity, pore_speed_limit, periodic_y=False):
    """Clip the pore speed |q| / n_face to ``pore_speed_limit`` (m/s) on the faces of ``axis``
    that touch no water, in place. Returns (faces clipped, largest |q| among them before)."""
    nx, ny, nz = q.shape
    clipped = np.zeros(nx, dtype=np.int64)
    largest = np.zeros(nx)
    for outer in prange(nx):
        i = np.int64(outer)
        count = 0
        best = 0.0
        for j in range(ny):
            for k in range(nz):
                value = q[i, j, k]
                if (abs(value) <= pore_speed_limit * 1e-3
                        or _touches_water(f, axis, i, j, k, periodic_y)):
                    continue
                limit = pore_speed_limit * _open_part(porosity, axis, i, j, k, periodic_y)
                if abs(value) > limit:
                    count += 1
                    best = max(best, abs(value))
                    q[i, j, k] = limit if value > 0.0 else -limit
        clipped[i] = count
        largest[i] = best
    return clipped.sum(), (largest.max() if nx > 0 else 0.0)


@kernel
def listed_pore_speed(f, face_axis, face_index, values, porosity, water_only, periodic_y=False):
    """``largest_pore_speed`` over listed faces (axis ``face_axis[n]``, (i, j, k)
    ``face_index[n]``, velocity ``values[n]``)."""
    best = 0.0
    for n in range(values.size):
        axis, i, j, k = face_axis[n], face_index[n, 0], face_index[n, 1], face_index[n, 2]
        if water_only and not _touches_water(f, axis, i, j, k, periodic_y):
            continue
        best = max(best, abs(values[n]) / _open_part(porosity, axis, i, j, k, periodic_y))
    return best


@kernel
def limit_listed_faces(f, face_axis, face_index, values, porosity, pore_speed_limit,
                       periodic_y=False):
    """``limit_air_faces`` over listed faces, in place; returns the number clipped."""
    count = 0
    for n in range(values.size):
        axis, i, j, k = face_axis[n], face_index[n, 0], face_index[n, 1], face_index[n, 2]
        if _touches_water(f, axis, i, j, k, periodic_y):
            continue
        limit = pore_speed_limit * _open_part(porosity, axis, i, j, k, periodic_y)
        if abs(values[n]) > limit:
            values[n] = limit if values[n] > 0.0 else -limit
            count += 1
    return count
