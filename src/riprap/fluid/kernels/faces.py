"""Which cells a face of the staggered grid lies between (shared by the face kernels)."""
from riprap._jit import kernel


@kernel
def cells_beside_face(axis, i, j, k, n_along, periodic_y=False):
    """The cells below and above face (i, j, k) of the face array of ``axis`` (``n_along`` cells
    along it), as (il, jl, kl, ih, jh, kh); a boundary face gives its one cell twice, but on a
    ``periodic_y`` the y faces 0 and ny lie between the cells ny - 1 and 0."""
    s = i if axis == 0 else (j if axis == 1 else k)
    low = s - 1 if s > 0 else 0
    high = s if s < n_along else n_along - 1
    if periodic_y and axis == 1:
        low = (s - 1 + n_along) % n_along
        high = s % n_along
    il, jl, kl = i, j, k
    ih, jh, kh = i, j, k
    if axis == 0:
        il, ih = low, high
    elif axis == 1:
        jl, jh = low, high
    else:
        kl, kh = low, high
    return il, jl, kl, ih, jh, kh


__all__ = ["cells_beside_face"]
