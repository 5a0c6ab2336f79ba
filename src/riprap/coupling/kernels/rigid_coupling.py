"""Kernels of the rigidity-constraint coupling: bodies as regions of the one-fluid velocity field.

Every body is held on the staggered fluid grid as blocks of exact cell volumes
(``tet_cell_volumes``). The solid fraction of a face's control volume (half of each neighbouring
cell) is the mean of the two cells' fractions. With ``c`` a cell's solid fraction of one body, each
of the cell's two faces along an axis receives ``c / 2``; sums over a body's faces are therefore
done cell by cell, half to each face, which needs no face-sized block per body.

Symbols (``docs/coupling.md``): phi the face's total solid fraction, capped at 1 (each body's share
scaled down by the same factor where bodies overlap); ``x = (U, omega)`` a body's rigid motion;
``J = [e_a, rho x e_a]`` the map from x to the velocity component a at a face at ``rho = r - X``.
Interior faces only: wall faces keep their boundary velocity.
"""
import numpy as np

from riprap._jit import kernel

#: A body density that stands for the fluid's on each face: fixed bodies take it, so that water
#: at rest around them stays exactly at rest (their own density never matters: they do not move).
FOLLOWS_FLUID = -1.0


@kernel
def face_fractions(origin, shape, offset, values, cell_volume, cells, phi_x, phi_y, phi_z):
    """Add every body's solid fraction to the faces: phi_a (face arrays, zeroed by the caller)."""
    for b in range(origin.shape[0]):
        i0, j0, k0 = origin[b, 0], origin[b, 1], origin[b, 2]
        bi, bj, bk = shape[b, 0], shape[b, 1], shape[b, 2]
        base = offset[b]
        for p in range(bi):
            for q in range(bj):
                for s in range(bk):
                    c = values[base + (p * bj + q) * bk + s] / cell_volume
                    if c == 0.0:
                        continue
                    i, j, k = i0 + p, j0 + q, k0 + s
                    half = 0.5 * c
                    phi_x[i, j, k] += half
                    phi_x[i + 1, j, k] += half
                    phi_y[i, j, k] += half
                    phi_y[i, j + 1, k] += half
                    phi_z[i, j, k] += half
                    phi_z[i, j, k + 1] += half


@kernel
def _face_position(axis, i, j, k, lower, h, out):
    out[0] = lower[0] + (i + (0.0 if axis == 0 else 0.5)) * h
    out[1] = lower[1] + (j + (0.0 if axis == 1 else 0.5)) * h
    out[2] = lower[2] + (k + (0.0 if axis == 2 else 0.5)) * h


@kernel
def _jacobian(axis, rho, out):
    """J = [e_a, rho x e_a] (6,)."""
    for m in range(6):
        out[m] = 0.0
    out[axis] = 1.0
    if axis == 0:
        out[4] = rho[2]
        out[5] = -rho[1]
    elif axis == 1:
        out[3] = -rho[2]
        out[5] = rho[0]
    else:
        out[3] = rho[1]
        out[4] = -rho[0]


@kernel
def _interior(axis, i, j, k, cells):
    index = i if axis == 0 else (j if axis == 1 else k)
    return 0 < index < cells[axis]


@kernel
def _pick(axis, i, j, k, on_x, on_y, on_z):
    """The value of the face (axis, i, j, k) from the face arrays of the three axes."""
    if axis == 0:
        return on_x[i, j, k]
    if axis == 1:
        return on_y[i, j, k]
    return on_z[i, j, k]


@kernel
def _add(axis, i, j, k, value, on_x, on_y, on_z):
    """Add value to the face (axis, i, j, k) of the face arrays of the three axes."""
    if axis == 0:
        on_x[i, j, k] += value
    elif axis == 1:
        on_y[i, j, k] += value
    else:
        on_z[i, j, k] += value


@kernel
def _body_faces(origin, shape, offset, values, cell_volume, cells, b):
    """The interior faces that body b's cells touch, once per (cell, face): axes (m,), indices
    (m, 3) and the half cell fraction each receives (m,)."""
    bi, bj, bk = shape[b, 0], shape[b, 1], shape[b, 2]
    count = 0
    for n in range(bi * bj * bk):
        if values[offset[b] + n] != 0.0:
            count += 6
    axes = np.empty(count, dtype=np.int64)
    indices = np.empty((count, 3), dtype=np.int64)
    halves = np.empty(count)
    m = 0
    for p in range(bi):
        for q in range(bj):
            for s in range(bk):
                c = values[offset[b] + (p * bj + q) * bk + s] / cell_volume
                if c == 0.0:
                    continue
                for axis in range(3):
                    for side in range(2):
                        i = origin[b, 0] + p + (side if axis == 0 else 0)
                        j = origin[b, 1] + q + (side if axis == 1 else 0)
                        k = origin[b, 2] + s + (side if axis == 2 else 0)
                        if not _interior(axis, i, j, k, cells):
                            continue
                        axes[m] = axis
                        indices[m, 0], indices[m, 1], indices[m, 2] = i, j, k
                        halves[m] = 0.5 * c
                        m += 1
    return axes[:m], indices[:m], halves[:m]


@kernel
def _face_jacobian(axis, i, j, k, lower, h, centre, position, rho, jac):
    _face_position(axis, i, j, k, lower, h, position)
    for m in range(3):
        rho[m] = position[m] - centre[m]
    _jacobian(axis, rho, jac)


@kernel
def accumulate_rigid(origin, shape, offset, values, cell_volume, cells, lower, h, centres, motions,
                     weights, phi_x, phi_y, phi_z, fluid_x, fluid_y, fluid_z, out_x, out_y, out_z):
    """out_a += sum over bodies of weight_b phi_b' (J x_b)_a on interior faces, phi_b' the body's
    share scaled by 1 / max(1, phi): the rigid part of a blended velocity (weights 1) or of the
    momentum density (weights rho_b). A negative weight stands for the fluid's density on the face
    (``FOLLOWS_FLUID``)."""
    position = np.empty(3)
    rho = np.empty(3)
    jac = np.empty(6)
    for b in range(origin.shape[0]):
        if weights[b] == 0.0:
            continue
        axes, indices, halves = _body_faces(origin, shape, offset, values, cell_volume, cells, b)
        for f in range(axes.shape[0]):
            axis, i, j, k = axes[f], indices[f, 0], indices[f, 1], indices[f, 2]
            share = halves[f] / max(1.0, _pick(axis, i, j, k, phi_x, phi_y, phi_z))
            weight = (_pick(axis, i, j, k, fluid_x, fluid_y, fluid_z) if weights[b] < 0.0
                      else weights[b])
            _face_jacobian(axis, i, j, k, lower, h, centres[b], position, rho, jac)
            value = 0.0
            for m in range(6):
                value += jac[m] * motions[b, m]
            value *= weight * share
            _add(axis, i, j, k, value, out_x, out_y, out_z)


@kernel
def accumulate_density(origin, shape, offset, values, cell_volume, cells, densities, phi_x, phi_y,
                       phi_z, fluid_x, fluid_y, fluid_z, out_x, out_y, out_z):
    """out_a += sum over bodies of phi_b' rho_b on interior faces (the solid part of the mixture
    density); a negative density stands for the fluid's on the face (``FOLLOWS_FLUID``)."""
    for b in range(origin.shape[0]):
        axes, indices, halves = _body_faces(origin, shape, offset, values, cell_volume, cells, b)
        for f in range(axes.shape[0]):
            axis, i, j, k = axes[f], indices[f, 0], indices[f, 1], indices[f, 2]
            rho = (_pick(axis, i, j, k, fluid_x, fluid_y, fluid_z) if densities[b] < 0.0
                   else densities[b])
            value = halves[f] * rho / max(1.0, _pick(axis, i, j, k, phi_x, phi_y, phi_z))
            _add(axis, i, j, k, value, out_x, out_y, out_z)


@kernel
def momentum_systems(origin, shape, offset, values, cell_volume, cells, lower, h, centres,
                     densities, phi_x, phi_y, phi_z, fluid_x, fluid_y, fluid_z, u, v, w, c_x, c_y,
                     c_z, matrices, body_matrices, rhs):
    """For every body the 6 x 6 system M x = r of its rigid motion after the projection:

        M = sum_f w_f J_f^T J_f,  r = sum_f J_f^T (w_f u_f - C_f phi_b' / phi),
        w_f = phi_b' ((1 - phi) rho_fluid + rho_b),

    which makes the momentum and angular momentum of fluid and body together (the fluid's share
    of every face at the blended velocity, the body's at its rigid one) equal those before the
    coupling, up to the pressure's impulse on the walls (``docs/coupling.md``). ``C`` is the
    mixture's momentum density that the blending before the projection left unaccounted.
    ``body_matrices``: the body's own part of M (weights phi_b' rho_b), whose product with a motion
    is the body's momentum on the grid."""
    position = np.empty(3)
    rho = np.empty(3)
    jac = np.empty(6)
    volume = h * h * h
    for b in range(origin.shape[0]):
        for m in range(6):
            rhs[b, m] = 0.0
            for n in range(6):
                matrices[b, m, n] = 0.0
                body_matrices[b, m, n] = 0.0
        axes, indices, halves = _body_faces(origin, shape, offset, values, cell_volume, cells, b)
        for f in range(axes.shape[0]):
            axis, i, j, k = axes[f], indices[f, 0], indices[f, 1], indices[f, 2]
            phi = _pick(axis, i, j, k, phi_x, phi_y, phi_z)
            rho_f = _pick(axis, i, j, k, fluid_x, fluid_y, fluid_z)
            velocity = _pick(axis, i, j, k, u, v, w)
            unaccounted = _pick(axis, i, j, k, c_x, c_y, c_z)
            share = halves[f] / max(1.0, phi)
            capped = min(phi, 1.0)
            own = rho_f if densities[b] < 0.0 else densities[b]
            weight = share * ((1.0 - capped) * rho_f + own) * volume
            own_weight = share * own * volume
            source = weight * velocity - unaccounted * volume * share / capped
            _face_jacobian(axis, i, j, k, lower, h, centres[b], position, rho, jac)
            for m in range(6):
                if jac[m] == 0.0:
                    continue
                rhs[b, m] += jac[m] * source
                for n in range(6):
                    matrices[b, m, n] += weight * jac[m] * jac[n]
                    body_matrices[b, m, n] += own_weight * jac[m] * jac[n]

