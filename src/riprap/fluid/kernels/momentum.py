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
with free slip (no shear), 2 open (zero gradient; no shear; mass may cross).

Arrays are indexed [i, j, k]; a velocity component along ``axis`` has one more entry along that
axis than the cells. Masses are in kg per step, densities kg/m^3, velocities m/s.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

NO_SLIP = 0
FREE_SLIP = 1
OPEN = 2


@kernel
def _van_leer_face(q_upwind_upwind, q_upwind, q_downwind):
    """Face value from the upwind side, with the van Leer limiter (TVD, second order where smooth)."""
    jump = q_downwind - q_upwind
    if jump == 0.0:
        return q_upwind
    r = (q_upwind - q_upwind_upwind) / jump
    limiter = (r + abs(r)) / (1.0 + abs(r))
    return q_upwind + 0.5 * limiter * jump


@kernel
def _at(array, index, axis, offset, other_axis, other_offset):
    """array[index + offset e_axis + other_offset e_other_axis] (no bounds check)."""
    i, j, k = index
    if axis == 0:
        i += offset
    elif axis == 1:
        j += offset
    else:
        k += offset
    if other_axis == 0:
        i += other_offset
    elif other_axis == 1:
        j += other_offset
    else:
        k += other_offset
    return array[i, j, k]


@parallel_kernel
def transport_component(q, axis, mass_x, mass_y, mass_z, velocity_x, velocity_y, velocity_z,
                        cell_density, cell_viscosity, boundary_kind, h, dt, gravity_component,
                        two_dimensional, q_out, density_out):
    """Advance the velocity component ``q`` along ``axis`` over one step (without pressure).

    ``mass_x/y/z``: mass (kg) that crossed each cell face during the step, positive along +x/y/z.
    ``velocity_x/y/z``: the face velocities at the start (for the viscous cross terms; ``q`` is one
    of them). ``cell_density``, ``cell_viscosity``: cell values at the start. Writes the new
    velocity (before the pressure correction) to ``q_out`` and the control volume's new density to
    ``density_out`` for every interior node; boundary nodes along ``axis`` are copied unchanged.
    """
    nx, ny, nz = cell_density.shape
    cells = (nx, ny, nz)
    volume = h * h * h
    shape = q.shape
    for outer in prange(shape[0]):
        i = np.int64(outer)          # prange counts in uint64; a node tuple needs one int type
        for j in range(shape[1]):
            for k in range(shape[2]):
                node = (i, np.int64(j), np.int64(k))
                s = node[axis]
                q_out[i, j, k] = q[i, j, k]
                density_out[i, j, k] = 0.0
                if s == 0 or s == cells[axis]:
                    continue
                density_old = 0.5 * (_at(cell_density, node, axis, -1, axis, 0)
                                     + _at(cell_density, node, axis, 0, axis, 0))
                mass_change = 0.0
                momentum_change = 0.0
                viscous = 0.0
                for d in range(3):
                    if d == 1 and two_dimensional:
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
                    if d == axis:
                        # Faces of the control volume at the centres of cells s-1 (lower) and s.
                        for side in range(2):
                            c = s - 1 + side                    # cell index along the axis
                            flux = 0.5 * (_at(mass_d, node, axis, c - s, axis, 0)
                                          + _at(mass_d, node, axis, c - s + 1, axis, 0))
                            lower_node = c - s                  # offsets of the two nodes
                            upper_node = c - s + 1
                            if flux >= 0.0:
                                upwind = lower_node
                                downwind = upper_node
                                far = lower_node - 1 if s + lower_node - 1 >= 0 else lower_node
                            else:
                                upwind = upper_node
                                downwind = lower_node
                                far = (upper_node + 1 if s + upper_node + 1 <= cells[axis]
                                       else upper_node)
                            q_face = _van_leer_face(_at(q, node, axis, far, axis, 0),
                                                    _at(q, node, axis, upwind, axis, 0),
                                                    _at(q, node, axis, downwind, axis, 0))
                            stress = (2.0 * _at(cell_viscosity, node, axis, side - 1, axis, 0)
                                      * (_at(q, node, axis, upper_node, axis, 0)
                                         - _at(q, node, axis, lower_node, axis, 0)) / h)
                            sign = 1.0 if side == 1 else -1.0
                            mass_change -= sign * flux
                            momentum_change -= sign * flux * q_face
                            viscous += sign * stress / h
                    else:
                        t = node[d]                             # cell index along d
                        for side in range(2):
                            sign = 1.0 if side == 1 else -1.0
                            face = t + side                     # face index along d
                            # Mass through this face of the control volume: the mean of the two
                            # cell faces beside it (cells s-1 and s along the axis).
                            flux = 0.5 * (_at(mass_d, node, d, side, axis, -1)
                                          + _at(mass_d, node, d, side, axis, 0))
                            boundary = face == 0 or face == cells[d]
                            if boundary:
                                kind = boundary_kind[2 * d + (1 if face == cells[d] else 0)]
                                q_face = q[i, j, k]
                                if kind == NO_SLIP:
                                    gradient = sign * (0.0 - q[i, j, k]) / (0.5 * h)
                                    mu_edge = 0.5 * (_at(cell_viscosity, node, axis, -1, d, 0)
                                                     + _at(cell_viscosity, node, axis, 0, d, 0))
                                    stress = mu_edge * gradient
                                else:
                                    stress = 0.0
                            else:
                                neighbour = 1 if side == 1 else -1
                                q_here = q[i, j, k]
                                q_there = _at(q, node, d, neighbour, d, 0)
                                if flux >= 0.0:
                                    if side == 1:
                                        q_up, q_down = q_here, q_there
                                        far_ok = t - 1 >= 0
                                        q_far = _at(q, node, d, -1, d, 0) if far_ok else q_here
                                    else:
                                        q_up, q_down = q_there, q_here
                                        far_ok = t - 2 >= 0
                                        q_far = _at(q, node, d, -2, d, 0) if far_ok else q_there
                                else:
                                    if side == 1:
                                        q_up, q_down = q_there, q_here
                                        far_ok = t + 2 < cells[d]
                                        q_far = _at(q, node, d, 2, d, 0) if far_ok else q_there
                                    else:
                                        q_up, q_down = q_here, q_there
                                        far_ok = t + 1 < cells[d]
                                        q_far = _at(q, node, d, 1, d, 0) if far_ok else q_here
                                q_face = _van_leer_face(q_far, q_up, q_down)
                                # Shear stress on the edge between the two nodes: viscosity the
                                # mean of the four cells around the edge.
                                lower_cell = t if side == 1 else t - 1
                                mu_edge = 0.25 * (_at(cell_viscosity, node, axis, -1, d, lower_cell - t)
                                                  + _at(cell_viscosity, node, axis, 0, d, lower_cell - t)
                                                  + _at(cell_viscosity, node, axis, -1, d, lower_cell - t + 1)
                                                  + _at(cell_viscosity, node, axis, 0, d, lower_cell - t + 1))
                                dq = sign * (q_there - q_here) / h
                                # d(velocity_d)/d(axis) on the edge: the two velocity_d faces
                                # beside it (cells s-1 and s along the axis, face `face` along d).
                                cross = (_at(velocity_d, node, d, side, axis, 0)
                                         - _at(velocity_d, node, d, side, axis, -1)) / h
                                stress = mu_edge * (dq + cross)
                            mass_change -= sign * flux
                            momentum_change -= sign * flux * q_face
                            viscous += sign * stress / h
                density_new = density_old + mass_change / volume
                momentum = (density_old * q[i, j, k] + momentum_change / volume
                            + dt * (viscous + density_new * gravity_component))
                q_out[i, j, k] = momentum / density_new
                density_out[i, j, k] = density_new


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


__all__ = ["transport_component", "divergence", "mass_fluxes", "max_abs", "NO_SLIP", "FREE_SLIP",
           "OPEN"]
