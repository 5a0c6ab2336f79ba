"""Sums of a grid field per x-plane, each added in one fixed order.

Why: a grid split into slabs of x-planes over processes (``riprap/fluid/slab_solver.py``) adds the
same planes' sums in the same order as one process, so the water volume and the water let in
come out bit for bit the same however the grid is split."""
import numpy as np

from riprap._jit import parallel_kernel, prange


@parallel_kernel
def plane_sums(values):
    """(nx,) the sum over (j, k) of values[i, j, k] for every x-plane i, k fastest."""
    nx, ny, nz = values.shape
    out = np.zeros(nx)
    for i in prange(nx):
        total = 0.0
        for j in range(ny):
            for k in range(nz):
                total += values[i, j, k]
        out[i] = total
    return out


@parallel_kernel
def weighted_plane_sums(values, weights):
    """(nx,) the sum over (j, k) of weights * values per x-plane (the water in a porous zone's
    pores: porosity times water fraction)."""
    nx, ny, nz = values.shape
    out = np.zeros(nx)
    for i in prange(nx):
        total = 0.0
        for j in range(ny):
            for k in range(nz):
                total += weights[i, j, k] * values[i, j, k]
        out[i] = total
    return out
