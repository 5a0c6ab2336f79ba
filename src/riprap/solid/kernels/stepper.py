"""Whole time steps in compiled code, so that Python is entered once per batch of steps, not once
per kernel. The solver (``solid/solver.py``) checks the returned status and raises named errors."""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels import broad_phase, integrate, interactions, periodic
from riprap.solid.kernels.bundles import History

STATUS_OK = 0
STATUS_NOT_FINITE = 1
STATUS_OVERFLOW = 2


@kernel
def candidate_pairs(system, motion, settings):
    """The broad phase at ``motion``: (body pairs (k, 2), body-wall pairs (m, 2), every body's
    angular velocity, the pair keys' stride)."""
    positions, quaternions, _, angular_momenta, _, _ = motion
    _, _, inverse_principal_inertia, fixed, shape_index, _ = system.bodies
    lookup = system.shapes.lookup
    bounding_radius = lookup.bounding_radius
    wall_points, wall_normals, _ = system.walls
    margin = settings.margin
    n = positions.shape[0]
    lo, hi = broad_phase.world_boxes(positions, quaternions, shape_index, lookup.local_box_min,
                                     lookup.local_box_max, margin)
    radii = np.empty(n)
    for b in range(n):
        radii[b] = bounding_radius[shape_index[b]] + margin
    body_pairs = broad_phase.in_key_order(broad_phase.overlapping_pairs(lo, hi, fixed, positions,
                                                                        radii, settings.period))
    wall_pairs = broad_phase.near_wall_pairs(positions, shape_index, bounding_radius, fixed,
                                             wall_points, wall_normals, margin)
    omegas = integrate.angular_velocities(quaternions, angular_momenta, inverse_principal_inertia)
    return body_pairs, wall_pairs, omegas, n + wall_points.shape[0]


@kernel
def forces_of_contacts(system, motion, settings, body_pairs, wall_pairs, results, key_stride):
    """Forces and torques of every body (written into ``motion``): gravity, the held loads of
    ``settings`` and the contacts' ``results`` (one row per pair, body pairs first), added in the
    pairs' order. Returns (the contacts' springs as a ``History``, whether a buffer overflowed)."""
    _, _, _, _, forces, torques = motion
    masses, _, _, fixed, _, _ = system.bodies
    gravity, external_loads, _, _, _, _, _, _ = settings
    n = forces.shape[0]
    overflow = False
    for b in range(n):
        for c in range(3):
            forces[b, c] = 0.0 if fixed[b] else masses[b] * gravity[c] + external_loads[b, c]
            torques[b, c] = 0.0 if fixed[b] else external_loads[b, 3 + c]
    interactions.accumulate(body_pairs, wall_pairs, results, forces, torques)
    n_body_pairs = body_pairs.shape[0]
    n_active = 0
    for k in range(results.shape[0]):
        if results[k, interactions.C_OVERFLOW] > 0.0:
            overflow = True
        if results[k, interactions.C_ACTIVE] > 0.0:
            n_active += 1
    keys = np.empty(n_active, dtype=np.int64)
    springs = np.empty((n_active, interactions.HISTORY_WIDTH))
    m = 0
    for k in range(results.shape[0]):
        if results[k, interactions.C_ACTIVE] == 0.0:
            continue
        if k < n_body_pairs:
            keys[m] = body_pairs[k, 0] * key_stride + body_pairs[k, 1]
        else:
            w = k - n_body_pairs
            keys[m] = wall_pairs[w, 0] * key_stride + (key_stride - 1 - wall_pairs[w, 1])
        for c in range(interactions.HISTORY_WIDTH):
            springs[m, c] = results[k, interactions.C_SPRING + c]
        m += 1
    order = np.argsort(keys)
    return History(keys[order], springs[order]), overflow


@kernel
def compute_forces(system, motion, history, settings, piece_cache):
    """Forces and torques of every body of ``system`` (:class:`~riprap.solid.kernels.bundles.
    RigidSystem`) at ``motion`` (``Motion``; its forces and torques are written): gravity +
    contacts + the external loads of ``settings`` (``StepSettings``), force and torque held on
    each free body, e.g. a fluid's. ``history``: the contacts' springs (``History``).

    Returns (history, results, body_pairs, wall_pairs, omegas, overflow, piece_cache).
    """
    body_pairs, wall_pairs, omegas, key_stride = candidate_pairs(system, motion, settings)
    results, piece_cache = interactions.evaluate_candidates(
        body_pairs, wall_pairs, system, motion, omegas, history, settings, piece_cache)
    history, overflow = forces_of_contacts(system, motion, settings, body_pairs, wall_pairs,
                                           results, key_stride)
    return history, results, body_pairs, wall_pairs, omegas, overflow, piece_cache


@kernel
def advance(n_steps, system, motion, omegas, history, settings, piece_cache):
    """Advance ``motion`` (``Motion``, in place) of ``system`` (``RigidSystem``) by ``n_steps``
    velocity-Verlet steps of ``settings.step``; ``omegas``: the angular velocities of the last
    force evaluation. Returns (steps done, status, history, results, body_pairs, wall_pairs,
    omegas, piece_cache) of the last force evaluation."""
    positions, quaternions, velocities, angular_momenta, forces, torques = motion
    _, inverse_masses, inverse_principal_inertia, _, _, _ = system.bodies
    _, _, _, step, local_damping, _, period_lower, period = settings
    results = np.zeros((0, interactions.C_SIZE))
    body_pairs = np.zeros((0, 2), dtype=np.int64)
    wall_pairs = np.zeros((0, 2), dtype=np.int64)
    for s in range(n_steps):
        integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                       0.5 * step, local_damping)
        integrate.drift(positions, quaternions, velocities, angular_momenta, inverse_masses,
                        inverse_principal_inertia, step)
        periodic.wrap_positions(positions, period_lower, period)
        history, results, body_pairs, wall_pairs, omegas, overflow, piece_cache = compute_forces(
            system, motion, history, settings, piece_cache)
        integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                       0.5 * step, local_damping)
        if overflow:
            return s + 1, STATUS_OVERFLOW, history, results, body_pairs, wall_pairs, omegas, piece_cache
        for b in range(positions.shape[0]):
            finite = True
            for c in range(3):
                if not (np.isfinite(positions[b, c]) and np.isfinite(velocities[b, c])
                        and np.isfinite(angular_momenta[b, c])):
                    finite = False
            if not finite:
                return s + 1, STATUS_NOT_FINITE, history, results, body_pairs, wall_pairs, omegas, piece_cache
    return n_steps, STATUS_OK, history, results, body_pairs, wall_pairs, omegas, piece_cache
