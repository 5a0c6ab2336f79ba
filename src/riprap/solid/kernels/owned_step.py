"""The compiled parts of a velocity-Verlet step with the bodies split over processes by the place
of their centre (``riprap/solid/bodies_over_processes.py`` runs them and passes the messages).

Every process holds every body and integrates every body alike (a few tenths of a microsecond a
body); what is split is the work that grows with the contacts: each process finds the candidate
pairs only among the bodies near its own (the broad phase), evaluates the pairs whose first body
it owns, and adds up the forces of its own bodies. The pairs are in (i, j) order, as one process
lists them (``broad_phase.in_key_order``), so each body's forces are added in one process's
order, bit for bit.
"""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels import broad_phase, integrate, periodic


@kernel
def owners_of(positions, cuts):
    """The process owning each body: the number of ``cuts`` (ascending x, m) at or below its
    centre's x."""
    owners = np.zeros(positions.shape[0], dtype=np.int64)
    for b in range(positions.shape[0]):
        p = 0
        while p < cuts.shape[0] and positions[b, 0] >= cuts[p]:
            p += 1
        owners[b] = p
    return owners


@kernel
def first_half(system, motion, omegas, settings):
    """Half kick and drift of every body (the forces of the last evaluation, joined), the centres
    brought back into the periodic strip as one process does."""
    positions, quaternions, velocities, angular_momenta, forces, torques = motion
    _, inverse_masses, inverse_principal_inertia, _, _, _ = system.bodies
    _, _, _, step, local_damping, _, period_lower, period = settings
    integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                   0.5 * step, local_damping)
    integrate.drift(positions, quaternions, velocities, angular_momenta, inverse_masses,
                    inverse_principal_inertia, step)
    periodic.wrap_positions(positions, period_lower, period)


@kernel
def local_candidates(system, motion, settings, owners, rank, lower, upper):
    """The candidate pairs that touch a body of process ``rank`` (whose centres lie in
    [``lower``, ``upper``) along x): body pairs in (i, j) order and the body-wall pairs of its
    own bodies in the order of one process's list; every body's angular velocity; the pair keys'
    stride.

    Only the bodies whose centre lies within twice the largest reach (bounding radius and margin)
    of the slab can pair with one of its bodies (the broad phase keeps a pair only when the
    bounding spheres overlap), so only they are boxed and swept; with x periodic, also through
    the strip's ends (a y period needs nothing more: the slabs are cut in x, and the pairs
    are taken by minimum image as on one process). Each pair is tested on exactly
    the numbers one process tests it on, so the pairs kept are one process's."""
    positions, quaternions, _, angular_momenta, _, _ = motion
    _, _, inverse_principal_inertia, fixed, shape_index, _ = system.bodies
    lookup = system.shapes.lookup
    bounding_radius = lookup.bounding_radius
    wall_points, wall_normals, _ = system.walls
    margin = settings.margin
    period = settings.period
    n = positions.shape[0]
    reach = 0.0
    for s in range(bounding_radius.shape[0]):
        reach = max(reach, bounding_radius[s] + margin)
    # twice the reach, widened by a part in a million against the round-off of the sphere test
    reach = 2.0 * reach * (1.0 + 1e-6) + 1e-12
    near = np.empty(n, dtype=np.int64)
    n_near = 0
    for b in range(n):
        if _near_slab(positions[b, 0], lower, upper, reach, period[0]):
            near[n_near] = b
            n_near += 1
    near = near[:n_near]
    near_positions = np.empty((n_near, 3))
    near_quaternions = np.empty((n_near, 4))
    near_shapes = np.empty(n_near, dtype=np.int64)
    near_fixed = np.empty(n_near, dtype=np.bool_)
    radii = np.empty(n_near)
    for k in range(n_near):
        b = near[k]
        near_positions[k] = positions[b]
        near_quaternions[k] = quaternions[b]
        near_shapes[k] = shape_index[b]
        near_fixed[k] = fixed[b]
        radii[k] = bounding_radius[shape_index[b]] + margin
    lo, hi = broad_phase.world_boxes(near_positions, near_quaternions, near_shapes,
                                     lookup.local_box_min, lookup.local_box_max, margin)
    found = broad_phase.overlapping_pairs(lo, hi, near_fixed, near_positions, radii, period)
    kept = np.empty((found.shape[0], 2), dtype=np.int64)
    count = 0
    for k in range(found.shape[0]):
        # ``near`` ascends, so a near pair (a < b) is a pair (i < j) of the whole
        i = near[found[k, 0]]
        j = near[found[k, 1]]
        if owners[i] == rank or owners[j] == rank:
            kept[count, 0] = i
            kept[count, 1] = j
            count += 1
    body_pairs = broad_phase.in_key_order(kept[:count].copy())
    own = np.empty(n, dtype=np.int64)
    n_own = 0
    for b in range(n):
        if owners[b] == rank:
            own[n_own] = b
            n_own += 1
    own = own[:n_own]
    own_walls = broad_phase.near_wall_pairs(positions[own], shape_index[own], bounding_radius,
                                            fixed[own], wall_points, wall_normals, margin)
    for w in range(own_walls.shape[0]):
        own_walls[w, 0] = own[own_walls[w, 0]]
    omegas = integrate.angular_velocities(quaternions, angular_momenta, inverse_principal_inertia)
    return body_pairs, own_walls, omegas, n + wall_points.shape[0]


@kernel
def _near_slab(x, lower, upper, reach, period):
    """Whether a centre at ``x`` lies within ``reach`` of the slab [``lower``, ``upper``), also
    through the strip's ends when x is periodic (``period`` > 0): the slab at one end pairs with
    the bodies at the other."""
    if x >= lower - reach and x <= upper + reach:
        return True
    if period > 0.0:
        for image in (x - period, x + period):
            if image >= lower - reach and image <= upper + reach:
                return True
    return False


@kernel
def second_half(system, motion, omegas, settings, joined_forces, joined_torques):
    """Every body's joined forces into ``motion``, the second half kick of every body. Returns
    whether every body's state is finite."""
    positions, _, velocities, angular_momenta, forces, torques = motion
    _, inverse_masses, _, _, _, _ = system.bodies
    _, _, _, step, local_damping, _, _, _ = settings
    forces[:] = joined_forces
    torques[:] = joined_torques
    integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                   0.5 * step, local_damping)
    finite = True
    for b in range(positions.shape[0]):
        for c in range(3):
            if not (np.isfinite(positions[b, c]) and np.isfinite(velocities[b, c])
                    and np.isfinite(angular_momenta[b, c])):
                finite = False
    return finite
