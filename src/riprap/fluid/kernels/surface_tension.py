"""Surface tension as a balanced continuum surface force, curvature from height functions.

Force: F = sigma kappa grad f on every face (Brackbill, Kothe & Zemach 1992), with grad f the
same two-cell difference as the pressure gradient of the projection. A pressure jump sigma kappa
across an interface of constant curvature then cancels the force exactly (the balanced-force
discretisation of Francois et al. 2006, J. Comput. Phys. 213: 141), so a drop at rest stays at rest
up to the error of the curvature estimate instead of stirring "parasitic currents".

Curvature: from height functions (Cummins, Francois & Kothe 2005, Comput. Struct. 83: 425;
Popinet 2009, J. Comput. Phys. 228: 5838). In a cell near the interface, take the axis d along
which the interface normal is largest; through the cell and its neighbours across d, run columns
along d out to the first full cell on the water side and the first empty cell on the air side (at
most 5 cells each way): the water in a column is the height of the interface in it. Second-order
differences of the heights give kappa = div n (n the unit normal from water to air; a water drop
has kappa > 0):

    kappa = -(H_aa (1 + H_b^2) + H_bb (1 + H_a^2) - 2 H_ab H_a H_b) / (1 + H_a^2 + H_b^2)^(3/2)

whichever side of the columns the water lies (both the heights and their second derivatives
change sign together). Where the columns along d do not close, those along the next axis the
normal leans towards are tried. Where none close (thin films and tips, corners of drops a few cells
across), in this order: the mean of the height-function curvatures of the cut cells around; the
cell's own columns closed loosely (ends within 1e-2 of full or empty); the mean of those second
values around; the divergence of Youngs' normals. |kappa| is capped at 1 / h: a grid cannot carry
a surface curved on a smaller scale, and larger estimates come from under-resolved tips where
they only make noise.

Outside the domain the fraction continues with zero gradient, which is a contact angle of 90
degrees on walls.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange
from riprap.fluid.kernels.plic import clamp_index, interface_normal

__all__ = ["cell_curvature", "face_forces", "NO_CURVATURE", "HEIGHT_FUNCTION", "FALLBACK"]

_HALF_COLUMN = 5                     # columns of up to 11 cells
# A cell this close to 0 or 1 ends a column; loosely only where neither strict columns nor strict
# neighbours give a curvature (drops a few cells across have no strictly full corner columns).
_PURE_STRICT = 1e-6
_PURE_LOOSE = 1e-2
# columns along an axis the normal leans towards by less than this (1-norm share) are not tried:
# the surface would be too steep across them for three columns to see it
_MIN_COLUMN_COMPONENT = 0.2
_MIXED = 1e-9                        # 0 < f < 1 beyond this: a cell the interface cuts
# cell status in the curvature pass
NO_CURVATURE = 0                     # not next to the interface
HEIGHT_FUNCTION = 1                  # kappa from closed height-function columns
FALLBACK = 2                         # columns not closed: kappa from the neighbours or normals


@kernel
def _value(f, i, j, k):
    nx, ny, nz = f.shape
    return f[clamp_index(i, nx), clamp_index(j, ny), clamp_index(k, nz)]


@kernel
def _along(f, i, j, k, axis, m):
    """The fraction m cells from (i, j, k) along ``axis`` (zero gradient past the domain)."""
    if axis == 0:
        return _value(f, i + m, j, k)
    if axis == 1:
        return _value(f, i, j + m, k)
    return _value(f, i, j, k + m)


@kernel
def _column(f, i, j, k, axis, water_low, pure):
    """Position of the interface along ``axis`` in the column through (i, j, k), in cells from the
    centre of (i, j, k) towards the air, and whether the column is closed.

    The column runs from the cell out to the first full cell on the water side and the first empty
    cell on the air side, at most ``_HALF_COLUMN`` cells each way (Popinet 2009): a fixed stencil
    would cut off the interface in the corner columns of a steep normal. Not closed where either
    end is not reached."""
    towards_air = 1 if water_low else -1
    water_end = 0
    wet = False
    while True:
        value = _along(f, i, j, k, axis, -towards_air * water_end)
        if value >= 1.0 - pure:
            break
        if value > pure:
            wet = True
        elif wet:
            return 0.0, False              # back into air: the column crosses the surface twice
        water_end += 1
        if water_end > _HALF_COLUMN:
            return 0.0, False
    air_end = 0
    dry = False
    while True:
        value = _along(f, i, j, k, axis, towards_air * air_end)
        if value <= pure:
            break
        if value < 1.0 - pure:
            dry = True
        elif dry:
            return 0.0, False              # back into water
        air_end += 1
        if air_end > _HALF_COLUMN:
            return 0.0, False
    if water_end == 0 and air_end == 0:
        return 0.0, False                  # cannot be both full and empty
    total = 0.0
    for m in range(-water_end, air_end + 1):
        total += _along(f, i, j, k, axis, towards_air * m)
    # the water-end cell's far face is water_end + 1/2 cells below the centre
    return total - water_end - 0.5, True


@kernel
def _offset(i, j, k, axis, step):
    if axis == 0:
        return i + step, j, k
    if axis == 1:
        return i, j + step, k
    return i, j, k + step


@kernel
def _curvature_along(f, i, j, k, h, two_dimensional, axis, water_low, pure, heights):
    """(kappa, closed) from the heights of the columns along ``axis`` through (i, j, k) and its
    neighbours across ``axis``."""
    if axis == 0:
        t1, t2 = 2, 1
    elif axis == 1:
        t1, t2 = 0, 2
    else:
        t1, t2 = 0, 1
    if two_dimensional:
        t2 = -1
    for a in range(-1, 2):
        ia, ja, ka = _offset(i, j, k, t1, a)
        for b in range(-1, 2):
            if t2 < 0 and b != 0:
                continue
            if t2 >= 0:
                ib, jb, kb = _offset(ia, ja, ka, t2, b)
            else:
                ib, jb, kb = ia, ja, ka
            height, closed = _column(f, ib, jb, kb, axis, water_low, pure)
            if not closed:
                return 0.0, False
            heights[a + 1, b + 1] = height
    ha = 0.5 * (heights[2, 1] - heights[0, 1])
    haa = (heights[2, 1] - 2.0 * heights[1, 1] + heights[0, 1]) / h
    if t2 < 0:
        return -haa / (1.0 + ha * ha) ** 1.5, True
    hb = 0.5 * (heights[1, 2] - heights[1, 0])
    hbb = (heights[1, 2] - 2.0 * heights[1, 1] + heights[1, 0]) / h
    hab = (heights[2, 2] - heights[2, 0] - heights[0, 2] + heights[0, 0]) / (4.0 * h)
    numerator = haa * (1.0 + hb * hb) + hbb * (1.0 + ha * ha) - 2.0 * hab * ha * hb
    return -numerator / (1.0 + ha * ha + hb * hb) ** 1.5, True


@kernel
def _height_function_curvature(f, i, j, k, h, two_dimensional, pure, heights):
    """(kappa, closed) in cell (i, j, k) from height functions: columns along the axis the normal
    is closest to, or, where those do not close (steep corners of small drops), along the next
    axis the normal leans towards (Popinet 2009). closed False where none closes. ``heights``
    (3, 3) is work space."""
    n1, n2, n3 = interface_normal(f, i, j, k)
    if two_dimensional:
        n2 = 0.0
    # axes in order of falling |n| (ties: lower axis first), by three compare-and-swaps
    first, second, third = 0, 1, 2
    size = (abs(n1), abs(n2), abs(n3))
    if size[second] > size[first]:
        first, second = second, first
    if size[third] > size[second]:
        second, third = third, second
    if size[second] > size[first]:
        first, second = second, first
    components = (n1, n2, n3)
    for rank in range(3):
        axis = first if rank == 0 else (second if rank == 1 else third)
        component = components[axis]
        if abs(component) < _MIN_COLUMN_COMPONENT:
            break
        curvature, closed = _curvature_along(f, i, j, k, h, two_dimensional, axis,
                                             component > 0.0, pure, heights)
        if closed:
            return curvature, True
    return 0.0, False


@kernel
def _normal_divergence_curvature(f, i, j, k, h, two_dimensional):
    """kappa = div n with n = -grad f / |grad f| at the cell's corners (Youngs' gradients)."""
    total = 0.0
    corners_b = 1 if two_dimensional else 2
    for ca in range(2):
        for cb in range(corners_b):
            for cc in range(2):
                gx = 0.0
                gy = 0.0
                gz = 0.0
                # the corner at (i + ca - 1/2, j + cb - 1/2, k + cc - 1/2): cells i+ca-1, i+ca ...
                for p in range(2):
                    for q in range(corners_b):
                        for r in range(2):
                            jj = j if two_dimensional else j + cb - 1 + q
                            value = _value(f, i + ca - 1 + p, jj, k + cc - 1 + r)
                            gx += (2 * p - 1) * value
                            gz += (2 * r - 1) * value
                            if not two_dimensional:
                                gy += (2 * q - 1) * value
                norm = np.sqrt(gx * gx + gy * gy + gz * gz)
                if norm == 0.0:
                    continue
                # n = -g/|g|; the outward direction of this corner from the cell centre
                total += -((2 * ca - 1) * gx + (2 * cc - 1) * gz) / norm
                if not two_dimensional:
                    total += -((2 * cb - 1) * gy) / norm
    # Gauss: div n = (1/h^3) sum over faces of the face-mean normal times h^2; each face mean is
    # the mean of its 2 (2D) or 4 (3D) corners, each corner counted once per face it bounds.
    return total / ((2.0 if two_dimensional else 4.0) * h)


@parallel_kernel
def cell_curvature(f, h, two_dimensional, kappa, status):
    """Curvature (1/m) in every cell the interface cuts or borders; ``status`` says how it was
    found (``HEIGHT_FUNCTION``, ``FALLBACK``) or that the cell has none (``NO_CURVATURE``)."""
    nx, ny, nz = f.shape
    cap = 1.0 / h
    for outer in prange(nx):
        i = np.int64(outer)          # prange counts in uint64; mixed with int64 it gives floats
        heights = np.empty((3, 3))
        for j in range(ny):
            for k in range(nz):
                kappa[i, j, k] = 0.0
                status[i, j, k] = NO_CURVATURE
                value = f[i, j, k]
                near = _MIXED < value < 1.0 - _MIXED
                if not near:
                    for axis in range(3):
                        if axis == 1 and two_dimensional:
                            continue
                        for step in (-1, 1):
                            a, b, c = _offset(i, j, k, axis, step)
                            if 0 <= a < nx and 0 <= b < ny and 0 <= c < nz:
                                if abs(f[a, b, c] - value) > _MIXED:
                                    near = True
                if not near:
                    continue
                curvature, closed = _height_function_curvature(f, i, j, k, h, two_dimensional,
                                                               _PURE_STRICT, heights)
                if closed:
                    kappa[i, j, k] = min(cap, max(-cap, curvature))
                    status[i, j, k] = HEIGHT_FUNCTION
                else:
                    status[i, j, k] = FALLBACK
    # Cells whose strict columns did not close: the mean of the strict values of the cut cells
    # around them, else their own loosely closed columns (written to a side array: neighbours read
    # only pass-1 values, so the threads do not race).
    loose = np.zeros_like(kappa)
    level = np.zeros(f.shape, dtype=np.int8)         # 1 neighbour mean, 2 loose columns, 3 neither
    # (level 0: not a fallback cell)
    for outer in prange(nx):
        i = np.int64(outer)
        heights = np.empty((3, 3))
        for j in range(ny):
            for k in range(nz):
                if status[i, j, k] != FALLBACK:
                    continue
                total, count = _neighbour_mean(f, kappa, status, loose, level, i, j, k, False)
                if count > 0:
                    loose[i, j, k] = total / count
                    level[i, j, k] = 1
                    continue
                curvature, closed = _height_function_curvature(f, i, j, k, h, two_dimensional,
                                                               _PURE_LOOSE, heights)
                if closed:
                    loose[i, j, k] = min(cap, max(-cap, curvature))
                    level[i, j, k] = 2
                else:
                    level[i, j, k] = 3
    # The rest: the mean of any column-based value around them, failing that Youngs' normals.
    for outer in prange(nx):
        i = np.int64(outer)
        for j in range(ny):
            for k in range(nz):
                if status[i, j, k] != FALLBACK:
                    continue
                if level[i, j, k] < 3:
                    kappa[i, j, k] = loose[i, j, k]
                    continue
                total, count = _neighbour_mean(f, kappa, status, loose, level, i, j, k, True)
                if count > 0:
                    kappa[i, j, k] = total / count
                else:
                    curvature = _normal_divergence_curvature(f, i, j, k, h, two_dimensional)
                    kappa[i, j, k] = min(cap, max(-cap, curvature))


@kernel
def _neighbour_mean(f, kappa, status, loose, level, i, j, k, with_loose):
    """Sum and count of the column-based curvatures of the cut cells in the 3x3x3 block around
    (i, j, k): strict ones, and with ``with_loose`` also the second-pass ones (neighbour means and
    loosely closed columns)."""
    nx, ny, nz = f.shape
    total = 0.0
    count = 0
    for a in range(max(i - 1, 0), min(i + 2, nx)):
        for b in range(max(j - 1, 0), min(j + 2, ny)):
            for c in range(max(k - 1, 0), min(k + 2, nz)):
                if not _MIXED < f[a, b, c] < 1.0 - _MIXED:
                    continue
                if status[a, b, c] == HEIGHT_FUNCTION:
                    total += kappa[a, b, c]
                    count += 1
                elif with_loose and status[a, b, c] == FALLBACK and level[a, b, c] < 3:
                    total += loose[a, b, c]
                    count += 1
    return total, count


@kernel
def _face_curvature(f0, f1, kappa0, kappa1):
    """Curvature on the face between two cells: the mean over the cells the interface cuts, or of
    both where it runs along the face itself."""
    w0 = 1.0 if _MIXED < f0 < 1.0 - _MIXED else 0.0
    w1 = 1.0 if _MIXED < f1 < 1.0 - _MIXED else 0.0
    if w0 + w1 == 0.0:
        return 0.5 * (kappa0 + kappa1)
    return (w0 * kappa0 + w1 * kappa1) / (w0 + w1)


@parallel_kernel
def _face_forces_from_curvature(f, kappa, h, sigma, two_dimensional, force_x, force_y, force_z):
    nx, ny, nz = f.shape
    for outer in prange(nx):
        i = np.int64(outer)          # prange counts in uint64; mixed with int64 it gives floats
        for j in range(ny):
            for k in range(nz):
                here = f[i, j, k]
                if i > 0:
                    there = f[i - 1, j, k]
                    if there != here:
                        curvature = _face_curvature(there, here, kappa[i - 1, j, k], kappa[i, j, k])
                        force_x[i, j, k] = sigma * curvature * (here - there) / h
                if j > 0 and not two_dimensional:
                    there = f[i, j - 1, k]
                    if there != here:
                        curvature = _face_curvature(there, here, kappa[i, j - 1, k], kappa[i, j, k])
                        force_y[i, j, k] = sigma * curvature * (here - there) / h
                if k > 0:
                    there = f[i, j, k - 1]
                    if there != here:
                        curvature = _face_curvature(there, here, kappa[i, j, k - 1], kappa[i, j, k])
                        force_z[i, j, k] = sigma * curvature * (here - there) / h


def face_forces(fraction, h, sigma, two_dimensional, force_x, force_y, force_z):
    """Surface-tension force density (N/m^3) on every interior face: sigma kappa (f1 - f0) / h.

    ``force_x/y/z`` have the shapes of u, v, w and must be zero on entry; boundary faces stay
    zero. Returns the cell curvature (1/m) and its status array for output and tests.
    """
    kappa = np.empty_like(fraction)
    status = np.empty(fraction.shape, dtype=np.int8)
    cell_curvature(fraction, float(h), bool(two_dimensional), kappa, status)
    _face_forces_from_curvature(fraction, kappa, float(h), float(sigma), bool(two_dimensional),
                                force_x, force_y, force_z)
    return kappa, status
