"""Cell values at the porous faces only: the speed and viscosity the porous friction needs.

Why: the friction of a porous zone needs, on each of its faces, the mean of the two cells' speeds
and viscosities. Taken over the whole grid and then picked out (as ``porous.face_means`` does) it
cost a ninth of examples/10's fluid step, while the core holds a few percent of the faces.

Faces are flat indices into the face array of ``axis`` (``PorousMedium.faces``); a boundary face
takes its one cell's value, as ``porous.face_means``; on a periodic y its two cells are the
strip's last and first.
"""
import math

from riprap._jit import kernel, parallel_kernel, prange
from riprap.fluid.kernels.faces import cells_beside_face


@kernel
def _cell_speed(u, v, w, i, j, k):
    cu = 0.5 * (u[i, j, k] + u[i + 1, j, k])
    cv = 0.5 * (v[i, j, k] + v[i, j + 1, k])
    cw = 0.5 * (w[i, j, k] + w[i, j, k + 1])
    return math.sqrt(cu * cu + cv * cv + cw * cw)


@parallel_kernel
def face_speeds_and_viscosities(u, v, w, viscosity, axis, faces, speed_out, viscosity_out,
                                periodic_y=False):
    """``speed_out[n]``, ``viscosity_out[n]``: the means of the two cells beside face ``faces[n]``
    of the speed |U| at the cell centres (from the face velocities u, v, w) and of ``viscosity``."""
    nx, ny, nz = viscosity.shape
    face_ny = ny + 1 if axis == 1 else ny
    face_nz = nz + 1 if axis == 2 else nz
    n_along = viscosity.shape[axis]
    for n in prange(faces.shape[0]):
        flat = faces[n]
        i = flat // (face_ny * face_nz)
        j = (flat // face_nz) % face_ny
        k = flat % face_nz
        il, jl, kl, ih, jh, kh = cells_beside_face(axis, i, j, k, n_along, periodic_y)
        speed_out[n] = 0.5 * (_cell_speed(u, v, w, il, jl, kl) + _cell_speed(u, v, w, ih, jh, kh))
        viscosity_out[n] = 0.5 * (viscosity[il, jl, kl] + viscosity[ih, jh, kh])


__all__ = ["face_speeds_and_viscosities"]
