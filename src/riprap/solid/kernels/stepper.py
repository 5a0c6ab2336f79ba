"""Whole time steps in compiled code, so that Python is entered once per batch of steps, not once
per kernel. The solver (``solid/solver.py``) checks the returned status and raises named errors."""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels import broad_phase, integrate, interactions

STATUS_OK = 0
STATUS_NOT_FINITE = 1
STATUS_OVERFLOW = 2


@kernel
def compute_forces(positions, quaternions, velocities, angular_momenta, forces, torques, masses,
                   inverse_masses, inverse_principal_inertia, fixed, shape_index, material_index,
                   gravity, wall_points, wall_normals, wall_materials, bounding_radius,
                   pair_penalty, pair_friction, pair_damping_ratio, pair_tangential_ratio,
                   external_loads, history_keys, history_springs, margin, step, piece_cache, skin,
                   shape_arrays):
    """Forces and torques of every body at the current positions (gravity + contacts + the
    external loads (n, 6): force and torque held on each free body, e.g. a fluid's).

    Returns (history_keys, history_springs, results, body_pairs, wall_pairs, omegas, overflow,
    piece_cache).
    """
    # positions of the shape boxes in ShapeTable.kernel_arrays()
    local_box_min = shape_arrays[24]
    local_box_max = shape_arrays[25]
    n = positions.shape[0]
    lo, hi = broad_phase.world_boxes(positions, quaternions, shape_index, local_box_min,
                                     local_box_max, margin)
    radii = np.empty(n)
    for b in range(n):
        radii[b] = bounding_radius[shape_index[b]] + margin
    body_pairs = broad_phase.overlapping_pairs(lo, hi, fixed, positions, radii)
    wall_pairs = broad_phase.near_wall_pairs(positions, shape_index, bounding_radius, fixed,
                                             wall_points, wall_normals, margin)
    omegas = integrate.angular_velocities(quaternions, angular_momenta, inverse_principal_inertia)
    key_stride = n + wall_points.shape[0]
    results, piece_cache = interactions.evaluate_candidates(
        body_pairs, wall_pairs, positions, quaternions, velocities, omegas, shape_index,
        material_index, inverse_masses, wall_points, wall_normals, wall_materials, pair_penalty,
        pair_friction, pair_damping_ratio, pair_tangential_ratio, history_keys, history_springs,
        key_stride, step, piece_cache, skin, bounding_radius, shape_arrays)
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
    return keys[order], springs[order], results, body_pairs, wall_pairs, omegas, overflow, piece_cache


@kernel
def advance(n_steps, positions, quaternions, velocities, angular_momenta, forces, torques, omegas,
            masses, inverse_masses, inverse_principal_inertia, fixed, shape_index, material_index,
            gravity, wall_points, wall_normals, wall_materials, bounding_radius, pair_penalty,
            pair_friction, pair_damping_ratio, pair_tangential_ratio, external_loads, history_keys,
            history_springs, margin, step, local_damping, piece_cache, skin, shape_arrays):
    """Advance ``n_steps`` velocity-Verlet steps. Returns (steps done, status, history_keys,
    history_springs, results, body_pairs, wall_pairs, omegas, piece_cache) of the last force
    evaluation."""
    results = np.zeros((0, interactions.C_SIZE))
    body_pairs = np.zeros((0, 2), dtype=np.int64)
    wall_pairs = np.zeros((0, 2), dtype=np.int64)
    for s in range(n_steps):
        integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                       0.5 * step, local_damping)
        integrate.drift(positions, quaternions, velocities, angular_momenta, inverse_masses,
                        inverse_principal_inertia, step)
        (history_keys, history_springs, results, body_pairs, wall_pairs, omegas,
         overflow, piece_cache) = compute_forces(
            positions, quaternions, velocities, angular_momenta, forces, torques, masses,
            inverse_masses, inverse_principal_inertia, fixed, shape_index, material_index,
            gravity, wall_points, wall_normals, wall_materials, bounding_radius, pair_penalty,
            pair_friction, pair_damping_ratio, pair_tangential_ratio, external_loads, history_keys,
            history_springs, margin, step, piece_cache, skin, shape_arrays)
        integrate.kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses,
                       0.5 * step, local_damping)
        if overflow:
            return s + 1, STATUS_OVERFLOW, history_keys, history_springs, results, body_pairs, wall_pairs, omegas, piece_cache
        for b in range(positions.shape[0]):
            finite = True
            for c in range(3):
                if not (np.isfinite(positions[b, c]) and np.isfinite(velocities[b, c])
                        and np.isfinite(angular_momenta[b, c])):
                    finite = False
            if not finite:
                return s + 1, STATUS_NOT_FINITE, history_keys, history_springs, results, body_pairs, wall_pairs, omegas, piece_cache
    return n_steps, STATUS_OK, history_keys, history_springs, results, body_pairs, wall_pairs, omegas, piece_cache
