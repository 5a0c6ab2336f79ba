"""Kernels of the rigidity-constraint coupling: bodies as regions of the one-fluid velocity field.

Every body is held on the staggered fluid grid as blocks of exact cell volumes and half-cell
volumes (``solid_volumes.rigid_body_half_cell_volumes``). The solid fraction of a face's control
volume (the upper half of the cell below it and the lower half of the cell above it) is exact: each
half cell gives its face its solid volume over h^3.

The coupling works on the faces the bodies touch only, never on the whole grid: ``touched_faces``
lists them once per step (a compact face set), every per-face quantity of the coupling is an
array over that set, gathered from and scattered to the grid's face arrays, and per body the
(face, half cell fraction) entries say which faces are its own. So the coupling's cost follows the
cells near the bodies, not the grid.

Symbols (``docs/coupling.md``): phi the face's total solid fraction, capped at 1 (each body's share
scaled down by the same factor where bodies overlap); ``x = (U, omega)`` a body's rigid motion;
``J = [e_a, rho x e_a]`` the map from x to the velocity component a at a face at ``rho = r - X``.
Body entries are interior faces only: wall faces keep their boundary velocity.

Face set arrays: ``face_axis`` (F,), ``face_index`` (F, 3) the face's index in its axis's face
array, ``entry_start`` (bodies + 1,), ``entry_face`` (E,) slots into the face set, ``entry_half``
(E,) the half cell fraction a body's cell gives that face (once per cell and face).

A periodic y (``periodic_y``; ``period`` (3,) of ``BodyFaces``, 0 along an axis that is not
periodic): the y face ny is face 0 (the set holds face 0 only; the caller copies it to face ny
after writing), cells ny - 1 and 0 are neighbours, and a face's arm from a body's centre is taken
to the face's image nearest the body (a body straddling the boundary has faces at both sides).
"""
from collections import namedtuple

import numpy as np

from riprap._jit import kernel, parallel_kernel, prange

#: A body density that stands for the fluid's on each face: fixed bodies take it, so that water
#: at rest around them stays exactly at rest (their own density never matters: they do not move).
FOLLOWS_FLUID = -1.0


@kernel
def _face_key(axis, i, j, k, cells):
    """Position of face (axis, i, j, k) in one flat numbering of the three face arrays."""
    nx, ny, nz = cells[0], cells[1], cells[2]
    if axis == 0:
        return (i * ny + j) * nz + k
    base = (nx + 1) * ny * nz
    if axis == 1:
        return base + (i * (ny + 1) + j) * nz + k
    return base + nx * (ny + 1) * nz + (i * ny + j) * (nz + 1) + k


def face_count(cells) -> int:
    """Number of faces of the three face arrays together (the size of ``touched_faces``' slots)."""
    nx, ny, nz = (int(n) for n in cells)
    return (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1)


@kernel
def _solid_cell(solid, i, j, k, cells, periodic_y):
    """Whether cell (i, j, k) is an obstacle cell of the fluid (outside the grid is not; on a
    ``periodic_y`` the cells beyond y are the strip's other side)."""
    if periodic_y:
        j = (j + cells[1]) % cells[1]
    if i < 0 or j < 0 or k < 0 or i >= cells[0] or j >= cells[1] or k >= cells[2]:
        return False
    return solid[(i * cells[1] + j) * cells[2] + k]


@kernel
def _shut(solid, axis, i, j, k, cells, periodic_y):
    """Whether face (axis, i, j, k) has an obstacle cell on either side (the fluid holds it shut)."""
    return (_solid_cell(solid, i, j, k, cells, periodic_y)
            or _solid_cell(solid, i - (axis == 0), j - (axis == 1), k - (axis == 2), cells,
                           periodic_y))


@kernel
def touched_faces(cell_start, cell_index, cell_halves, cell_volume, cells, slots, solid,
                  periodic_y=False):
    """The faces that any body's cells touch, and per body its entries.

    Per body b its cells holding solid: ``cell_index[cell_start[b]:cell_start[b + 1]]`` (flat
    grid index, C order) with ``cell_halves`` (n, 6): the solid volume in the lower and upper half
    of the cell along each axis (``solid_volumes.rigid_body_half_cell_volumes``). A face's
    fraction is the solid share of its own control volume, the two half cells beside it.
    ``slots`` (``face_count(cells)``,) int32, all -1 on entry and on return: a face's place in the
    set while it is built (kept between steps so that no grid-sized array is made per step).
    ``solid`` (cells, C order) bool: the fluid's obstacle cells. A face beside one is shut by the
    fluid (zero velocity, no pressure coupling through it) and is left out; the pressure on the
    faces that close the deep inside of fixed bodies reaches those bodies apart
    (``CoupledSolver._shut_face_loads``).
    Returns face_axis (F,), face_index (F, 3), phi (F,) the faces' summed body fractions
    (uncapped; wall faces too), interior (F,) bool, entry_start (bodies + 1,), entry_face (E,),
    entry_half (E,). Bodies, their cells, axes and sides are visited in a fixed order, so every
    sum is the same whatever the step.
    """
    bodies = cell_start.shape[0] - 1
    most = 6 * cell_index.shape[0]
    face_axis = np.empty(most, dtype=np.int64)
    face_index = np.empty((most, 3), dtype=np.int64)
    face_key = np.empty(most, dtype=np.int64)
    phi = np.zeros(most)
    interior = np.empty(most, dtype=np.bool_)
    entry_start = np.zeros(bodies + 1, dtype=np.int64)
    entry_face = np.empty(most, dtype=np.int64)
    entry_half = np.empty(most)
    n_faces = 0
    n_entries = 0
    plane = cells[1] * cells[2]
    for b in range(bodies):
        for c in range(cell_start[b], cell_start[b + 1]):
            flat = cell_index[c]
            ci = flat // plane
            cj = (flat // cells[2]) % cells[1]
            ck = flat % cells[2]
            if _solid_cell(solid, ci, cj, ck, cells, periodic_y):
                continue
            for axis in range(3):
                for side in range(2):
                    half = cell_halves[c, 2 * axis + side] / cell_volume
                    if half == 0.0:
                        continue
                    i = ci + (side if axis == 0 else 0)
                    j = cj + (side if axis == 1 else 0)
                    k = ck + (side if axis == 2 else 0)
                    if periodic_y and axis == 1 and j == cells[1]:
                        j = 0                   # the strip's face ny is its face 0
                    if _shut(solid, axis, i, j, k, cells, periodic_y):
                        continue
                    key = _face_key(axis, i, j, k, cells)
                    slot = slots[key]
                    if slot < 0:
                        slot = n_faces
                        slots[key] = slot
                        face_axis[slot] = axis
                        face_index[slot, 0] = i
                        face_index[slot, 1] = j
                        face_index[slot, 2] = k
                        face_key[slot] = key
                        along = i if axis == 0 else (j if axis == 1 else k)
                        interior[slot] = (0 < along < cells[axis]
                                          or (periodic_y and axis == 1))
                        n_faces += 1
                    phi[slot] += half
                    if interior[slot]:
                        entry_face[n_entries] = slot
                        entry_half[n_entries] = half
                        n_entries += 1
        entry_start[b + 1] = n_entries
    for f in range(n_faces):
        slots[face_key[f]] = -1
    return (face_axis[:n_faces], face_index[:n_faces], phi[:n_faces], interior[:n_faces],
            entry_start, entry_face[:n_entries], entry_half[:n_entries])


@parallel_kernel
def gather(face_axis, face_index, on_x, on_y, on_z, out):
    """out[f] = the value of face f in the face arrays of the three axes."""
    for f in prange(face_axis.shape[0]):
        i, j, k = face_index[f, 0], face_index[f, 1], face_index[f, 2]
        axis = face_axis[f]
        if axis == 0:
            out[f] = on_x[i, j, k]
        elif axis == 1:
            out[f] = on_y[i, j, k]
        else:
            out[f] = on_z[i, j, k]


@parallel_kernel
def scatter(face_axis, face_index, values, on_x, on_y, on_z):
    """Face f of the face arrays of the three axes = values[f] (faces of a set are distinct, so
    the parallel writes never meet)."""
    for f in prange(face_axis.shape[0]):
        i, j, k = face_index[f, 0], face_index[f, 1], face_index[f, 2]
        axis = face_axis[f]
        if axis == 0:
            on_x[i, j, k] = values[f]
        elif axis == 1:
            on_y[i, j, k] = values[f]
        else:
            on_z[i, j, k] = values[f]


@kernel
def _cells_of_face(axis, index, cell_values):
    """The cell values on the low and high side of the interior face (axis, index)."""
    i, j, k = index[0], index[1], index[2]
    high = cell_values[i, j, k]
    if axis == 0:
        return cell_values[i - 1, j, k], high
    if axis == 1:
        return cell_values[i, j - 1, k], high
    return cell_values[i, j, k - 1], high


@parallel_kernel
def face_mean_density(face_axis, face_index, interior, fraction, water_density, air_density, out):
    """Mean density of the two cells of each interior face from the water fraction (0 on walls):
    the face density a fluid step starts from."""
    for f in prange(face_axis.shape[0]):
        if not interior[f]:
            out[f] = 0.0
            continue
        low, high = _cells_of_face(face_axis[f], face_index[f], fraction)
        low_density = low * water_density + (1.0 - low) * air_density
        high_density = high * water_density + (1.0 - high) * air_density
        out[f] = 0.5 * (low_density + high_density)


@parallel_kernel
def face_pressure_force(face_axis, face_index, interior, pressure, h, out):
    """-grad p on each interior face (0 on walls): the pressure's force per unit volume."""
    for f in prange(face_axis.shape[0]):
        if not interior[f]:
            out[f] = 0.0
            continue
        low, high = _cells_of_face(face_axis[f], face_index[f], pressure)
        out[f] = -(high - low) / h


@kernel
def nearest_image(offset, period):
    """``offset`` (m) shifted by whole periods to lie within half a period of 0 (unchanged where
    ``period`` is 0: not periodic)."""
    if period > 0.0:
        return offset - period * np.floor(offset / period + 0.5)
    return offset


@kernel
def _face_arm(axis, index, lower, h, centre, period):
    """rho (3 numbers, m) from ``centre`` to face (axis, index), to its image nearest the centre
    along a periodic axis."""
    rho_x = nearest_image(lower[0] + (index[0] + (0.0 if axis == 0 else 0.5)) * h - centre[0],
                          period[0])
    rho_y = nearest_image(lower[1] + (index[1] + (0.0 if axis == 1 else 0.5)) * h - centre[1],
                          period[1])
    rho_z = nearest_image(lower[2] + (index[2] + (0.0 if axis == 2 else 0.5)) * h - centre[2],
                          period[2])
    return rho_x, rho_y, rho_z


@kernel
def _face_jacobian(axis, index, lower, h, centre, jac, period):
    """J = [e_a, rho x e_a] (6,) of the face (axis, index) for a body centred at ``centre``."""
    rho_x, rho_y, rho_z = _face_arm(axis, index, lower, h, centre, period)
    for m in range(6):
        jac[m] = 0.0
    jac[axis] = 1.0
    if axis == 0:
        jac[4] = rho_z
        jac[5] = -rho_y
    elif axis == 1:
        jac[3] = -rho_z
        jac[5] = rho_x
    else:
        jac[3] = rho_y
        jac[4] = -rho_x


#: The faces the bodies' cells touch: per body its entries (``entry_start`` (bodies + 1,) into
#: ``entry_face`` (E,), the face of each entry, and ``entry_half`` (E,), the body's share of it),
#: each face's axis and (i, j, k) index, the grid's lower corner (m) and cell size ``h`` (m), and
#: its ``period`` (3,) m along each axis (0: not periodic).
BodyFaces = namedtuple("BodyFaces", ["entry_start", "entry_face", "entry_half", "face_axis",
                                     "face_index", "lower", "h", "period"])


@kernel
def accumulate_rigid(faces, centres, motions, phi, weights, out):
    """out[f] += sum over bodies of weights[f] phi_b' (J x_b) on the set's faces (``faces``:
    :class:`BodyFaces`), phi_b' the body's share scaled by 1 / max(1, phi): with weights 1 the
    rigid part of a blended velocity; with the faces' grip (``cut_face_grip``) the part of the
    fluid's share that moves with the bodies after the step. A body at rest (x_b = 0: a fixed one
    after the projection) adds nothing and is skipped."""
    entry_start, entry_face, entry_half, face_axis, face_index, lower, h, period = faces
    jac = np.empty(6)
    for b in range(entry_start.shape[0] - 1):
        moving = False
        for m in range(6):
            if motions[b, m] != 0.0:
                moving = True
        if not moving:
            continue
        for e in range(entry_start[b], entry_start[b + 1]):
            f = entry_face[e]
            share = entry_half[e] / max(1.0, phi[f])
            _face_jacobian(face_axis[f], face_index[f], lower, h, centres[b], jac, period)
            value = 0.0
            for m in range(6):
                value += jac[m] * motions[b, m]
            out[f] += value * share * weights[f]


@parallel_kernel
def own_momentum_rhs(faces, centres, motions, densities, phi, fluid_density, pressure_impulse,
                     fluid_term, chosen, rhs):
    """Per body the right-hand side r of its 6 x 6 system after the projection, each part of a
    face's momentum given to whom it belongs: the body's own share at its own blended motion plus
    the pressure's velocity change on the face, and its part (phi_b' / phi) of the fluid share's

        r = sum_f J_f^T (phi_b' rho_b (J_f x_b + dv_f) + phi_b' / phi F_f) h^3,
        F_f = (1 - phi) (rho_fluid (u_fluid - (1 - alpha) u_projected) + dv_f / beta_f),

    (alpha the face's grip fraction, ``cut_face_grip``; F_f is formed by the caller).

    Summed over the bodies of a face this is the momentum_systems right-hand side (w u - C): for a
    face of one body it is the same; where two bodies share a face, neither takes the other's
    motion (a unit sliding on the slope is not dragged by the slope's share of the face).
    ``rhs`` (bodies, 6); only bodies with ``chosen[b]``, the others left 0. ``faces``:
    :class:`BodyFaces`, taken apart here, outside the parallel loop.
    """
    entry_start, entry_face, entry_half, face_axis, face_index, lower, h, period = faces
    volume = h * h * h
    for b in prange(entry_start.shape[0] - 1):
        jac = np.empty(6)
        for m in range(6):
            rhs[b, m] = 0.0
        if not chosen[b]:
            continue
        for e in range(entry_start[b], entry_start[b + 1]):
            f = entry_face[e]
            share = entry_half[e] / max(1.0, phi[f])
            capped = min(phi[f], 1.0)
            own = fluid_density[f] if densities[b] < 0.0 else densities[b]
            _face_jacobian(face_axis[f], face_index[f], lower, h, centres[b], jac, period)
            rigid = 0.0
            for m in range(6):
                rigid += jac[m] * motions[b, m]
            source = (share * (own * rigid + pressure_impulse[f])
                      + share / capped * fluid_term[f]) * volume
            for m in range(6):
                if jac[m] != 0.0:
                    rhs[b, m] += jac[m] * source


@kernel
def accumulate_density(entry_start, entry_face, entry_half, densities, phi, fluid_density, out):
    """out[f] += sum over bodies of phi_b' rho_b on the set's faces (the solid part of the mixture
    density); a negative density stands for the fluid's on the face (``FOLLOWS_FLUID``)."""
    for b in range(entry_start.shape[0] - 1):
        for e in range(entry_start[b], entry_start[b + 1]):
            f = entry_face[e]
            rho = fluid_density[f] if densities[b] < 0.0 else densities[b]
            out[f] += entry_half[e] * rho / max(1.0, phi[f])


@parallel_kernel
def momentum_systems(faces, centres, densities, phi, grip, fluid_density, velocities, unaccounted,
                     with_matrices, chosen, matrices, body_matrices, rhs):
    """For every body the 6 x 6 system M x = r of its rigid motion after the projection:

        M = sum_f w_f J_f^T J_f,  r = sum_f J_f^T (w_f u_f - C_f phi_b' / phi),
        w_f = phi_b' ((1 - phi) rho_fluid g_f + rho_b),

    g_f = alpha_f / phi the face's grip (``cut_face_grip``): the fluid's share of a cut face ends
    the step a fraction alpha_f of the way to the bodies' motion, so that part of it moves with
    them.

    which makes the momentum and angular momentum of fluid and body together (the fluid's share
    of every face at the blended velocity, the body's at its rigid one) equal those before the
    coupling, up to the pressure's impulse on the walls (``docs/coupling.md``). ``C`` is the
    mixture's momentum density that the blending before the projection left unaccounted.

    ``velocities`` and ``unaccounted`` (r, F): r right-hand sides at once, ``rhs`` (bodies, r, 6).
    With ``with_matrices``, also M and ``body_matrices``, the body's own part of M (weights
    phi_b' rho_b), whose product with a motion is the body's momentum on the grid. Each body's sums
    are its own (threads over bodies), in the order of its entries. Only bodies with ``chosen[b]``
    are summed; the others are left 0.
 ``faces``: :class:`BodyFaces`, taken apart
    here, outside the parallel loop.
    """
    entry_start, entry_face, entry_half, face_axis, face_index, lower, h, period = faces
    volume = h * h * h
    n_rhs = velocities.shape[0]
    for b in prange(entry_start.shape[0] - 1):
        jac = np.empty(6)
        for r in range(n_rhs):
            for m in range(6):
                rhs[b, r, m] = 0.0
        if with_matrices:
            for m in range(6):
                for n in range(6):
                    matrices[b, m, n] = 0.0
                    body_matrices[b, m, n] = 0.0
        if not chosen[b]:
            continue
        for e in range(entry_start[b], entry_start[b + 1]):
            f = entry_face[e]
            phi_f = phi[f]
            rho_f = fluid_density[f]
            share = entry_half[e] / max(1.0, phi_f)
            capped = min(phi_f, 1.0)
            own = rho_f if densities[b] < 0.0 else densities[b]
            weight = share * ((1.0 - capped) * rho_f * grip[f] + own) * volume
            own_weight = share * own * volume
            _face_jacobian(face_axis[f], face_index[f], lower, h, centres[b], jac, period)
            for r in range(n_rhs):
                source = weight * velocities[r, f] - unaccounted[r, f] * volume * share / capped
                for m in range(6):
                    if jac[m] != 0.0:
                        rhs[b, r, m] += jac[m] * source
            if with_matrices:
                for m in range(6):
                    if jac[m] == 0.0:
                        continue
                    for n in range(6):
                        matrices[b, m, n] += weight * jac[m] * jac[n]
                        body_matrices[b, m, n] += own_weight * jac[m] * jac[n]


@parallel_kernel
def cut_face_grip(phi, fluid_velocity, body_velocity, fluid_density, water_density,
                  water_viscosity, air_density, air_viscosity, h, dt, viscous_renewal,
                  wall_area, wall_distance, out):
    """The fraction alpha of the way from its own velocity to the bodies' motion that the fluid's
    share of each cut face goes over a step of ``dt``, divided by the face's solid fraction phi
    (the grip g = alpha / phi that ``momentum_systems`` and ``accumulate_rigid`` take).

    The fluid beside a body meets it at a rate, not once per step (``docs/coupling.md``, Cut faces):
    the fluid of a face's control volume is renewed by the flow through its opening (1 - phi) h
    at the relative speed, |u - U| / ((1 - phi) h), each renewal taking it the fraction phi of
    the way to the body; and the wall's shear mu (u - U) / d over the wall's area A in the face
    (``wall_geometry``: A in h^2, d the fluid's mean distance from it in h) slows the fluid's
    volume (1 - phi) h^3 at the rate nu A / ((1 - phi) d h^2):

        alpha = 1 - (1 - phi)^(dt |u - U| / ((1 - phi) h)) exp(-dt nu A / ((1 - phi) d h^2)),

    whatever the step. On a face that no single plane describes (``wall_area`` < 0: a film
    between bodies) the shear is a renewal too, ``viscous_renewal`` nu / ((1 - phi) h)^2 in
    the exponent of (1 - phi). A face inside a body (phi = 1) moves with it.
    ``body_velocity``: the bodies' blended rigid velocity on the face (sum phi_b' J x_b) over
    phi; the face's kinematic viscosity from its fluid density (water and air mixed by
    volume)."""
    for f in prange(phi.shape[0]):
        capped = min(phi[f], 1.0)
        if capped <= 0.0:
            out[f] = 0.0
            continue
        if capped >= 1.0:
            out[f] = 1.0
            continue
        water = 1.0
        if water_density != air_density:     # (one fluid in both phases: a single-liquid tank)
            water = (fluid_density[f] - air_density) / (water_density - air_density)
            water = min(max(water, 0.0), 1.0)
        viscosity = water * water_viscosity + (1.0 - water) * air_viscosity
        nu = viscosity / max(fluid_density[f], 1e-300)
        opening = (1.0 - capped) * h
        renewal = abs(fluid_velocity[f] - body_velocity[f]) / opening
        if wall_area[f] < 0.0:      # a film across the face
            renewal += viscous_renewal * nu / (opening * opening)
            out[f] = (1.0 - (1.0 - capped) ** (renewal * dt)) / capped
            continue
        # the wall's shear mu (u - U) / d over its area A slows the fluid's volume V_f
        shear = nu * wall_area[f] / ((1.0 - capped) * wall_distance[f] * h * h)
        out[f] = (1.0 - (1.0 - capped) ** (renewal * dt) * np.exp(-shear * dt)) / capped


#: The smallest share of the L1 norm a component of the wall's normal keeps in the plane-cut
#: formulas below (they divide by the product of the three): an axis-aligned wall is taken as
#: tilted by about 1e-3, which changes its area and distance by less than 1e-6 of a cell.
_NORMAL_FLOOR = 1e-3


@kernel
def _cube_cut(m0, m1, m2, level, power):
    """For the unit cube cut by the plane m . x = level (m >= 0, summing to 1): the volume below
    the plane (power 3, Scardovelli & Zaleski 2000), its derivative in level (power 2) or its
    integral over level from 0 (power 4), each times power! m0 m1 m2."""
    total = level ** power
    for shift in (m0, m1, m2):
        if level > shift:
            total -= (level - shift) ** power
    for shift in (m0 + m1, m0 + m2, m1 + m2):
        if level > shift:
            total += (level - shift) ** power
    return total


@parallel_kernel
def wall_geometry(face_axis, face_index, phi, bodies_on_face, on_x, on_y, on_z, area, distance,
                  periodic_y=False):
    """The wall inside each cut face's control volume as a plane (PLIC): its area (in h^2) and
    the mean distance of the face's fluid from it (in h), from the face's solid fraction and
    the normal of its neighbours' fractions along the three axes (central differences of the
    same axis's face array, ``on_x``.. holding phi on the set's faces and 0 elsewhere). A face
    that no single plane describes, with two bodies or more (a film between them), or no
    gradient, gets area -1: ``cut_face_grip`` treats it as a film across the whole face. On a
    ``periodic_y`` the neighbours along y wrap around the strip."""
    for f in prange(face_axis.shape[0]):
        area[f] = -1.0
        distance[f] = 0.0
        solid = min(phi[f], 1.0)
        if bodies_on_face[f] != 1 or solid <= 0.0 or solid >= 1.0:
            continue
        axis = face_axis[f]
        field = on_x if axis == 0 else (on_y if axis == 1 else on_z)
        i, j, k = face_index[f, 0], face_index[f, 1], face_index[f, 2]
        g = np.zeros(3)
        g[0] = (min(field[min(i + 1, field.shape[0] - 1), j, k], 1.0)
                - min(field[max(i - 1, 0), j, k], 1.0))
        if periodic_y:
            # y entries of the strip: cells, or faces without face ny (face 0 again)
            n_y = field.shape[1] - (1 if axis == 1 else 0)
            g[1] = (min(field[i, (j + 1) % n_y, k], 1.0)
                    - min(field[i, (j - 1 + n_y) % n_y, k], 1.0))
        else:
            g[1] = (min(field[i, min(j + 1, field.shape[1] - 1), k], 1.0)
                    - min(field[i, max(j - 1, 0), k], 1.0))
        g[2] = (min(field[i, j, min(k + 1, field.shape[2] - 1)], 1.0)
                - min(field[i, j, max(k - 1, 0)], 1.0))
        norm = abs(g[0]) + abs(g[1]) + abs(g[2])
        if norm <= 1e-12:
            continue
        m = np.empty(3)
        for a in range(3):
            m[a] = max(abs(g[a]) / norm, _NORMAL_FLOOR)
        total = m[0] + m[1] + m[2]
        for a in range(3):
            m[a] /= total
        length = np.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        scale = m[0] * m[1] * m[2]
        fluid = 1.0 - solid
        # the fluid lies on the side the solid fraction falls to: m . x <= level, with the
        # volume below the plane the fluid's share (bisection: the volume rises with level)
        low, high = 0.0, 1.0
        for _ in range(60):
            level = 0.5 * (low + high)
            if _cube_cut(m[0], m[1], m[2], level, 3) / (6.0 * scale) < fluid:
                low = level
            else:
                high = level
        level = 0.5 * (low + high)
        area[f] = _cube_cut(m[0], m[1], m[2], level, 2) / (2.0 * scale) * length
        # mean of (level - m . x) / |m| over the fluid: the integral of the volume below
        # the plane over the level, from 0 to the fluid's level
        distance[f] = _cube_cut(m[0], m[1], m[2], level, 4) / (24.0 * scale) / (length * fluid)


@kernel
def body_velocity_vectors(faces, centres, motions, phi, out):
    """out[f] (F, 3) = the bodies' rigid velocity U + omega x rho at face f, each body weighted
    by its share phi_b' over phi (0 on faces of no body)."""
    entry_start, entry_face, entry_half, face_axis, face_index, lower, h, period = faces
    for f in range(out.shape[0]):
        for c in range(3):
            out[f, c] = 0.0
    for b in range(entry_start.shape[0] - 1):
        for e in range(entry_start[b], entry_start[b + 1]):
            f = entry_face[e]
            weight = entry_half[e] / max(1.0, phi[f]) / max(min(phi[f], 1.0), 1e-300)
            rx, ry, rz = _face_arm(face_axis[f], face_index[f], lower, h, centres[b], period)
            wx, wy, wz = motions[b, 3], motions[b, 4], motions[b, 5]
            out[f, 0] += weight * (motions[b, 0] + wy * rz - wz * ry)
            out[f, 1] += weight * (motions[b, 1] + wz * rx - wx * rz)
            out[f, 2] += weight * (motions[b, 2] + wx * ry - wy * rx)


@parallel_kernel
def moving_pattern(face_axis, face_index, velocity, on_x, on_y, on_z, h, dt, out,
                   periodic_y=False):
    """out[f] = dt (V . grad) u_a at face f of axis a, the upwind differences of the face array
    of its own axis along V (``velocity`` (F, 3)): the change a field that moves rigidly with V
    shows at a fixed face over dt, which the grid-frame predictor puts on a moving body's faces.
    On a ``periodic_y`` the differences along y wrap around the strip."""
    for f in prange(face_axis.shape[0]):
        axis = face_axis[f]
        field = on_x if axis == 0 else (on_y if axis == 1 else on_z)
        i, j, k = face_index[f, 0], face_index[f, 1], face_index[f, 2]
        total = 0.0
        for c in range(3):
            speed = velocity[f, c]
            if speed == 0.0:
                continue
            di = 1 if c == 0 else 0
            dj = 1 if c == 1 else 0
            dk = 1 if c == 2 else 0
            here = field[i, j, k]
            if periodic_y and c == 1:
                n_y = field.shape[1] - (1 if axis == 1 else 0)
                if speed > 0.0:
                    total += speed * (here - field[i, (j - 1 + n_y) % n_y, k])
                else:
                    total += speed * (field[i, (j + 1) % n_y, k] - here)
                continue
            if speed > 0.0:
                ii, jj, kk = i - di, j - dj, k - dk
                if ii < 0 or jj < 0 or kk < 0:
                    continue
                total += speed * (here - field[ii, jj, kk])
            else:
                ii, jj, kk = i + di, j + dj, k + dk
                if ii >= field.shape[0] or jj >= field.shape[1] or kk >= field.shape[2]:
                    continue
                total += speed * (field[ii, jj, kk] - here)
        out[f] = total * dt / h
