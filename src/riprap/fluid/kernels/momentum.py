"""Momentum of the air-water mixture on the staggered grid, transported consistently with the water.

Why: with water 1000 times denser than air, a velocity advected on its own (not as momentum, or as
momentum with mass fluxes other than those that moved the water) puts water momentum into air
cells next to the interface, and those cells blow up under breaking. The cure (Rudman 1998,
Int. J. Numer. Meth. Fluids 28: 357; on staggered grids Vaudor et al. 2017, Comput. Fluids 152:
204; Arrufat et al. 2021, J. Comput. Phys. 446) is to move momentum with exactly the mass fluxes
of the volume-of-fluid step, and to divide by a density moved with the same fluxes: then a
uniform velocity stays exactly uniform whatever the density jump.

Here: the volume-of-fluid step gives, for every cell face, the water volume ``F`` that crossed it
during the step; the mass that crossed is ``M = rho_w F + rho_a (U - F)`` with ``U`` the total
volume (face velocity x dt x face area). The control volume of a face velocity spans half of each
of its two cells: the mass through its faces is the average of the two cell-face mass fluxes
beside it. Its density is moved by those mass fluxes (starting from the average of its two cells'
densities) and its momentum by the same fluxes times a van Leer-limited upwind face velocity
(van Leer 1979, J. Comput. Phys. 32: 101). Viscous stresses (explicit, Newtonian, variable
viscosity: div(mu (grad u + grad u^T))) and gravity are then added, and the velocity is the new
momentum over the new density.

Boundaries, per side (``boundary_kind[side]``, sides x_low, x_high, y_low, y_high, z_low, z_high):
0 wall with no slip (the tangential velocity is zero at the wall, half a cell from the node), 1 wall
with free slip (no shear), 2 open (zero gradient; no shear; mass may cross), 3 periodic (the y
sides only, both: cell ny - 1 is cell 0's neighbour, face ny of v is face 0, which is computed
and copied to face ny).

Arrays are indexed [i, j, k]; a velocity component along ``axis`` has one more entry along that
axis than the cells. Masses are in kg per step, densities kg/m^3, velocities m/s.
"""
from collections import namedtuple

import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

NO_SLIP = 0
FREE_SLIP = 1
OPEN = 2
PERIODIC = 3


@kernel
def wrapped_step(index, step, n):
    """The offset that takes ``index`` ``step`` places along a periodic axis of ``n`` entries
    (cells, or faces with face n being face 0): ((index + step) mod n) - index."""
    return (index + step + 2 * n) % n - index


@kernel
def _van_leer_face(q_upwind_upwind, q_upwind, q_downwind):
    """Face value from the upwind side, with the van Leer limiter (TVD, second order where smooth)."""
    jump = q_downwind - q_upwind
    if jump == 0.0:
        return q_upwind
    r = (q_upwind - q_upwind_upwind) / jump
    limiter = (r + abs(r)) / (1.0 + abs(r))
    return q_upwind + 0.5 * limiter * jump


def _strides(array) -> np.ndarray:
    """Element strides of a C-ordered 3D array."""
    return np.array([array.shape[1] * array.shape[2], array.shape[2], 1], dtype=np.int64)


def transport_component(q, axis, mass_x, mass_y, mass_z, velocity_x, velocity_y, velocity_z,
                        cell_density, cell_viscosity, boundary_kind, h, dt, gravity_component,
                        two_dimensional, q_out, density_out):
    """Advance the velocity component ``q`` along ``axis`` over one step (without pressure).

    ``mass_x/y/z``: mass (kg) that crossed each cell face during the step, positive along +x/y/z.
    ``velocity_x/y/z``: the face velocities at the start (for the viscous cross terms; ``q`` is one
    of them). ``cell_density``, ``cell_viscosity``: cell values at the start. Writes the new
    velocity (before the pressure correction) to ``q_out`` and the control volume's new density to
    ``density_out`` for every interior node; boundary nodes along ``axis`` are copied unchanged.
    All arrays C-contiguous float64.

    17 arguments: the solver's 3D fields as the public entry; it bundles them for
    :func:`_transport_flat`.
    """
    masses = (mass_x, mass_y, mass_z)
    velocities = (velocity_x, velocity_y, velocity_z)
    face_strides = np.stack([_strides(m) for m in masses])
    component = Component(q.reshape(-1), np.array(q.shape, dtype=np.int64), _strides(q), int(axis))
    faces = FaceFlow(mass_x.reshape(-1), mass_y.reshape(-1), mass_z.reshape(-1),
                     velocities[0].reshape(-1), velocities[1].reshape(-1),
                     velocities[2].reshape(-1), face_strides)
    cells = CellFields(cell_density.reshape(-1), cell_viscosity.reshape(-1),
                       np.array(cell_density.shape, dtype=np.int64), _strides(cell_density))
    _transport_flat(component, faces, cells, np.asarray(boundary_kind, dtype=np.int64), float(h),
                    float(dt), float(gravity_component), bool(two_dimensional), q_out.reshape(-1),
                    density_out.reshape(-1))


#: One velocity component in flat storage: its values, its nodes per axis (3,), its element
#: strides (3,) and the axis it points along.
Component = namedtuple("Component", ["values", "shape", "stride", "axis"])
#: The faces' flow over the step, flat: the mass (kg) across each x, y, z face, the face velocities
#: at the start, and the element strides of each face array (3, 3).
FaceFlow = namedtuple("FaceFlow", ["mass_x", "mass_y", "mass_z", "velocity_x", "velocity_y",
                                   "velocity_z", "stride"])
#: The cells' density and viscosity at the start, flat, with their count per axis and strides.
CellFields = namedtuple("CellFields", ["density", "viscosity", "shape", "stride"])


@parallel_kernel
def _transport_flat(component, faces, cells_bundle, boundary_kind, h, dt, gravity_component,
                    two_dimensional, q_out, density_out):
    """Flat-index form of :func:`transport_component`: every neighbour is a fixed offset (the
    strides of its array along x, y, z), so the inner loop does no tuple indexing. The bundles
    (:class:`Component`, :class:`FaceFlow`, :class:`CellFields`) are taken apart here, outside
    the parallel loop, which then reads plain arrays as before."""
    q, shape, q_stride, axis = component
    mass_x, mass_y, mass_z, velocity_x, velocity_y, velocity_z, face_stride = faces
    cell_density, cell_viscosity, cells, cell_stride = cells_bundle
    volume = h * h * h
    a_q = q_stride[axis]
    a_c = cell_stride[axis]
    n_along = cells[axis]
    periodic_y = boundary_kind[2] == PERIODIC
    # v on a periodic y: node 0 is computed like an inside node, node ny copied from it
    periodic_along = periodic_y and axis == 1
    for outer in prange(shape[0]):
        i = np.int64(outer)          # prange counts in uint64; mixed with int64 it would be float
        for j in range(shape[1]):
            for k in range(shape[2]):
                node = i * q_stride[0] + j * q_stride[1] + k
                s = i if axis == 0 else (j if axis == 1 else k)
                q_out[node] = q[node]
                density_out[node] = 0.0
                if periodic_along and s == n_along:
                    q_out[node] = q_out[node - n_along * a_q]     # face 0, done before it
                    density_out[node] = density_out[node - n_along * a_q]
                    continue
                if (s == 0 and not periodic_along) or s == n_along:
                    continue
                # The cells after (c1) and before (c0) the node along the axis.
                c1 = i * cell_stride[0] + j * cell_stride[1] + k * cell_stride[2]
                c0 = c1 - a_c
                if periodic_along and s == 0:
                    c0 = c1 + (n_along - 1) * a_c
                density_old = 0.5 * (cell_density[c0] + cell_density[c1])
                q_here = q[node]
                mass_change = 0.0
                momentum_change = 0.0
                viscous = 0.0
                # Faces at the centres of cells s-1 (lower) and s (upper) along the axis.
                if axis == 0:
                    mass_a = mass_x
                elif axis == 1:
                    mass_a = mass_y
                else:
                    mass_a = mass_z
                for side in range(2):
                    sign = 1.0 if side == 1 else -1.0
                    lower = node + (side - 1) * a_q          # the two nodes beside the face
                    upper = lower + a_q
                    if periodic_along:
                        lower = node + wrapped_step(s, side - 1, n_along) * a_q
                    flux = 0.5 * (mass_a[lower] + mass_a[upper])
                    if flux >= 0.0:
                        upwind, downwind = lower, upper
                        far = lower - a_q if s + side - 2 >= 0 else lower
                        if periodic_along:
                            far = node + wrapped_step(s, side - 2, n_along) * a_q
                    else:
                        upwind, downwind = upper, lower
                        far = upper + a_q if s + side + 1 <= n_along else upper
                        if periodic_along:
                            far = node + wrapped_step(s, side + 1, n_along) * a_q
                    q_face = _van_leer_face(q[far], q[upwind], q[downwind])
                    cell = c0 if side == 0 else c1
                    stress = 2.0 * cell_viscosity[cell] * (q[upper] - q[lower]) / h
                    mass_change -= sign * flux
                    momentum_change -= sign * flux * q_face
                    viscous += sign * stress / h
                for d in range(3):
                    if d == axis or (d == 1 and two_dimensional):
                        continue
                    if d == 0:
                        mass_d = mass_x
                        velocity_d = velocity_x
                    elif d == 1:
                        mass_d = mass_y
                        velocity_d = velocity_y
                    else:
                        mass_d = mass_z
                        velocity_d = velocity_z
                    t = i if d == 0 else (j if d == 1 else k)
                    n_d = cells[d]
                    d_q = q_stride[d]
                    d_c = cell_stride[d]
                    d_f = face_stride[d, d]
                    a_f = face_stride[d, axis]
                    # the d-faces of the cell before the node along the axis (around the strip
                    # for v's node 0 on a periodic y)
                    back_f = a_f
                    if periodic_along and s == 0:
                        back_f = -(n_along - 1) * a_f
                    # The d-face of cell s (along the axis) below the node.
                    face_base = i * face_stride[d, 0] + j * face_stride[d, 1] + k * face_stride[d, 2]
                    periodic_d = periodic_y and d == 1
                    for side in range(2):
                        sign = 1.0 if side == 1 else -1.0
                        face = t + side
                        f1 = face_base + side * d_f
                        flux = 0.5 * (mass_d[f1 - back_f] + mass_d[f1])
                        if periodic_d:
                            # across the periodic y: the neighbours wrap (the walled code below
                            # with its offsets taken around the strip)
                            ahead = 1 if side == 1 else -1
                            q_there = q[node + wrapped_step(t, ahead, n_d) * d_q]
                            if flux >= 0.0:
                                if side == 1:
                                    q_up, q_down = q_here, q_there
                                    q_far = q[node + wrapped_step(t, -1, n_d) * d_q]
                                else:
                                    q_up, q_down = q_there, q_here
                                    q_far = q[node + wrapped_step(t, -2, n_d) * d_q]
                            else:
                                if side == 1:
                                    q_up, q_down = q_there, q_here
                                    q_far = q[node + wrapped_step(t, 2, n_d) * d_q]
                                else:
                                    q_up, q_down = q_here, q_there
                                    q_far = q[node + wrapped_step(t, 1, n_d) * d_q]
                            q_face = _van_leer_face(q_far, q_up, q_down)
                            low = 0 if side == 1 else wrapped_step(t, -1, n_d) * d_c
                            high = wrapped_step(t, 1, n_d) * d_c if side == 1 else 0
                            mu_edge = 0.25 * (cell_viscosity[c0 + low] + cell_viscosity[c1 + low]
                                              + cell_viscosity[c0 + high]
                                              + cell_viscosity[c1 + high])
                            dq = sign * (q_there - q_here) / h
                            cross = (velocity_d[f1] - velocity_d[f1 - back_f]) / h
                            stress = mu_edge * (dq + cross)
                        elif face == 0 or face == n_d:
                            kind = boundary_kind[2 * d + (1 if face == n_d else 0)]
                            q_face = q_here
                            if kind == NO_SLIP:
                                mu_edge = 0.5 * (cell_viscosity[c0] + cell_viscosity[c1])
                                stress = mu_edge * sign * (0.0 - q_here) / (0.5 * h)
                            else:
                                stress = 0.0
                        else:
                            neighbour = node + (d_q if side == 1 else -d_q)
                            q_there = q[neighbour]
                            if flux >= 0.0:
                                if side == 1:
                                    q_up, q_down = q_here, q_there
                                    q_far = q[node - d_q] if t - 1 >= 0 else q_here
                                else:
                                    q_up, q_down = q_there, q_here
                                    q_far = q[node - 2 * d_q] if t - 2 >= 0 else q_there
                            else:
                                if side == 1:
                                    q_up, q_down = q_there, q_here
                                    q_far = q[node + 2 * d_q] if t + 2 < n_d else q_there
                                else:
                                    q_up, q_down = q_here, q_there
                                    q_far = q[node + d_q] if t + 1 < n_d else q_here
                            q_face = _van_leer_face(q_far, q_up, q_down)
                            # Shear on the edge between the two nodes: viscosity the mean of the
                            # four cells around it.
                            shift = 0 if side == 1 else -d_c
                            mu_edge = 0.25 * (cell_viscosity[c0 + shift] + cell_viscosity[c1 + shift]
                                              + cell_viscosity[c0 + shift + d_c]
                                              + cell_viscosity[c1 + shift + d_c])
                            dq = sign * (q_there - q_here) / h
                            cross = (velocity_d[f1] - velocity_d[f1 - back_f]) / h
                            stress = mu_edge * (dq + cross)
                        mass_change -= sign * flux
                        momentum_change -= sign * flux * q_face
                        viscous += sign * stress / h
                density_new = density_old + mass_change / volume
                momentum = (density_old * q_here + momentum_change / volume
                            + dt * (viscous + density_new * gravity_component))
                q_out[node] = momentum / density_new
                density_out[node] = density_new


@parallel_kernel
def divergence(u, v, w, h, out):
    """Discrete divergence of the face velocities in each cell (1/s)."""
    nx, ny, nz = out.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                out[i, j, k] = ((u[i + 1, j, k] - u[i, j, k]) + (v[i, j + 1, k] - v[i, j, k])
                                + (w[i, j, k + 1] - w[i, j, k])) / h


@kernel
def max_abs(a):
    largest = 0.0
    for value in a.flat:
        if abs(value) > largest:
            largest = abs(value)
    return largest


def mass_fluxes(water_volume, face_velocity, dt, face_area, water_density, air_density):
    """Mass (kg) through each face in a step: rho_w F + rho_a (U - F), U the total volume."""
    total = face_velocity * (dt * face_area)
    return water_density * water_volume + air_density * (total - water_volume)


__all__ = ["transport_component", "divergence", "mass_fluxes", "max_abs", "wrapped_step",
           "NO_SLIP", "FREE_SLIP", "OPEN", "PERIODIC"]
