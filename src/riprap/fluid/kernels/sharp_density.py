"""The density the pressure sees on each face: water and air by where the interface cuts the line
between the two cell centres, not by the mixture in the face's control volume.

Why: a face's pressure gradient is the difference of two cell-centre pressures over h, and
hydrostatic balance holds on it only if the face density is the density of the fluid actually
lying between those two centres. The control volume's mixed density (the half cells beside the
face) counts the water of a mixed cell that lies below its centre as lying above it: the pressure at
the centre of a mostly-air cell then carries water's weight, neighbouring columns whose interface
sits at different heights in their cells differ by a fraction of rho_water g h in the interface
row, and that difference, divided by the low density of the air faces there, accelerates the air
just above every wave without bound (0.2 m/s in 0.2 s above a 5 mm/s slosh on 5 cm cells). With
the segment density, a plane interface gives exactly hydrostatic cell pressures in both fluids
(the ghost-fluid idea, e.g. Kang, Fedkiw & Liu 2000, J. Sci. Comput. 15: 323, and for free-surface
flows Vukcevic, Jasak & Gatin 2017, Comput. Fluids 153: 1; here without a jump condition, the
density itself made sharp).

Each half of the segment lies in one cell: ``theta`` is the fraction of it below that cell's
PLIC plane (``plic.interface_normal`` and ``plic.plane_constant``, the same reconstruction the
advection uses); full and empty cells give 1 and 0 without one. The face density is
``theta rho_water + (1 - theta) rho_air`` with ``theta`` the mean of the two halves.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange
from riprap.fluid.kernels.faces import cells_beside_face
from riprap.fluid.kernels.plic import interface_normal, plane_constant


@parallel_kernel
def cell_planes(f, planes, periodic_y=False):
    """``planes[i, j, k] = (n1, n2, n3, alpha)``, the PLIC plane of every mixed cell (0 < f < 1;
    a zero normal where the neighbourhood shows no gradient); other cells are left as they are
    (never read). Why once per step: each mixed cell's plane serves its six half segments on the
    three axes, and the normal (a 27-cell stencil) and the plane constant were most of
    ``face_densities``' cost when each face computed them again (measured on examples/10 under
    wave attack: 26 ms of a 760 ms step on one thread)."""
    nx, ny, nz = f.shape
    for outer in prange(nx):
        i = np.int64(outer)
        for j in range(ny):
            for k in range(nz):
                fraction = f[i, j, k]
                if 0.0 < fraction < 1.0:
                    n1, n2, n3 = interface_normal(f, i, j, k, periodic_y)
                    planes[i, j, k, 0] = n1
                    planes[i, j, k, 1] = n2
                    planes[i, j, k, 2] = n3
                    planes[i, j, k, 3] = plane_constant(n1, n2, n3, fraction)


@kernel
def _half_segment_water(f, planes, i, j, k, axis, toward_high):
    """Fraction of the segment from the centre of cell (i, j, k) to its face along ``axis`` (the
    high face if ``toward_high``) lying in water (``planes`` of ``cell_planes``)."""
    fraction = f[i, j, k]
    if fraction <= 0.0:
        return 0.0
    if fraction >= 1.0:
        return 1.0
    n1, n2, n3 = planes[i, j, k, 0], planes[i, j, k, 1], planes[i, j, k, 2]
    if n1 == 0.0 and n2 == 0.0 and n3 == 0.0:
        return fraction
    alpha = planes[i, j, k, 3]
    # water where n . x <= alpha; along the half segment n . x is linear, from the centre on
    start = 0.5 * (n1 + n2 + n3) - alpha
    along = n1 if axis == 0 else (n2 if axis == 1 else n3)
    end = start + (0.5 * along if toward_high else -0.5 * along)
    if start <= 0.0 and end <= 0.0:
        return 1.0
    if start > 0.0 and end > 0.0:
        return 0.0
    crossing = start / (start - end)
    return crossing if start <= 0.0 else 1.0 - crossing


@parallel_kernel
def face_densities(f, planes, axis, water_density, air_density, out, periodic_y=False):
    """``out`` (the face array of ``axis``): the segment density of every interior face; the
    boundary faces along ``axis`` get the density of their one cell's half segment (on a
    ``periodic_y``, the y faces 0 and ny are interior faces between cells ny - 1 and 0).
    ``planes``: ``cell_planes(f, planes)`` of the same ``f``."""
    inside_only = periodic_y and axis == 1
    n_along = f.shape[axis]
    face_nx, face_ny, face_nz = out.shape
    for outer in prange(face_nx):
        i = np.int64(outer)
        for j in range(face_ny):
            for k in range(face_nz):
                s = i if axis == 0 else (j if axis == 1 else k)
                il, jl, kl, ih, jh, kh = cells_beside_face(axis, i, j, k, n_along, periodic_y)
                if inside_only:
                    theta = 0.5 * (_half_segment_water(f, planes, il, jl, kl, axis, True)
                                   + _half_segment_water(f, planes, ih, jh, kh, axis, False))
                elif s == 0:
                    theta = _half_segment_water(f, planes, ih, jh, kh, axis, False)
                elif s == n_along:
                    theta = _half_segment_water(f, planes, il, jl, kl, axis, True)
                else:
                    theta = 0.5 * (_half_segment_water(f, planes, il, jl, kl, axis, True)
                                   + _half_segment_water(f, planes, ih, jh, kh, axis, False))
                out[i, j, k] = theta * water_density + (1.0 - theta) * air_density


__all__ = ["cell_planes", "face_densities"]
