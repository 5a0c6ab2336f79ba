"""Contact forces of all candidate pairs in one parallel pass: potential (normal) force, contact
damping and Coulomb friction with a tangential spring.

Contact law per pair (all vectors world frame, n = unit direction of the potential force on body i):

- normal: |F_n| = |F_potential| - gamma_n v_n, clipped at 0 (no adhesion); v_n = v_rel . n,
  gamma_n = 2 zeta sqrt(m_eff k_n), zeta = -ln e / sqrt(pi^2 + ln^2 e) (restitution e of a linear
  spring-dashpot), k_n = p int |grad phi . n| dS is the potential's stiffness measured on the
  contact itself;
- tangential: incremental elastic force F_s (history, rotated onto the new tangent plane each
  step), F_s -= k_t v_t dt, F_t = F_s - gamma_t v_t with k_t = tangential_stiffness_ratio k_n,
  capped at friction_coefficient |F_n| (slip; F_s is then reset to F_t). Storing the force, not
  the displacement, means a stiffness that grows as the contact grows cannot create energy; when
  the stiffness falls (the contact shrinks) F_s is scaled by k_new / k_old, so the stored energy
  F_s^2 / (2 k) never grows without work either.
- twist: the same law for the torque about the normal, with the relative spin w_n, stiffness
  k_t r^2 and cap (2 sqrt(2) / 3) friction_coefficient |F_n| r, where r is the polar radius of
  gyration of the contact pressure about the contact point (pieces lumped at their centroids;
  at least that of a disc with the contact's area, a / sqrt(2)). For a uniformly loaded disc of
  radius a the cap is the exact (2/3) mu F a; for a unit standing on three legs r is the legs'
  spread, as it should be. Without it a body could spin freely about a single contact normal.

The damping and friction forces act at the force-weighted contact point.
"""
import numpy as np

from riprap._jit import kernel, parallel_kernel, prange
from riprap.solid.kernels.bundles import (Candidate, CandidateOutputs, PieceCache, RigidSystem,
                                          Shapes)
from riprap.solid.kernels.contact import (OUT_SIZE, collect_pair_pieces, make_scratch,
                                          pair_force_from_pieces, relative_pose,
                                          wall_potential_force)
from riprap.solid.kernels.geometry_ops import rotation_matrix
from riprap.solid.kernels.periodic import image_of

# Below this many candidate pairs the evaluation stays on one thread.
PARALLEL_MIN_CANDIDATES = 32
# Columns of the per-candidate result array.
C_FORCE_I = 0
C_TORQUE_I = 3
C_TORQUE_J = 6
C_POINT = 9
C_NORMAL_FORCE = 12
C_TANGENTIAL_FORCE = 15
C_SPRING = 18          # 6: tangential elastic force (3), twisting elastic torque, and the
                       # tangential and twisting stiffness they were built with
C_STIFFNESS = 24
C_ACTIVE = 25
C_OVERFLOW = 26
C_AREA = 27
C_SIZE = 28
HISTORY_WIDTH = 6
# Where a body pair's piece list for the next step lives.
SOURCE_NONE = 0     # not kept (skin 0 or the batch's buffer was full)
SOURCE_OLD = 1      # rows of the previous cache's pieces
SOURCE_FRESH = 2    # rows of this step's fresh buffer


@kernel
def evaluate_candidates(body_pairs, wall_pairs, system, motion, omegas, history, settings,
                        piece_cache):
    """Evaluate every candidate body-body and body-wall pair of ``system``
    (:class:`~riprap.solid.kernels.bundles.RigidSystem`) at ``motion`` (``Motion``) with angular
    velocities ``omegas``, the contacts' spring ``history`` (``History``) and the step's
    ``settings`` (``StepSettings``: the time step, the skin and the periods are read).

    Returns (results (n_candidates, C_SIZE), the piece cache for the next step).

    ``piece_cache`` (``PieceCache``: keys, poses, bounds, pieces): for each body pair evaluated
    last step (sorted pair keys), the relative pose at which its (triangle, tet) pieces were listed
    with the widening ``skin`` (m), and its rows [start, split, end) of ``pieces``. A pair whose
    surfaces have moved less than ``skin`` relative to each other since then reuses its list;
    otherwise the list is made again (:func:`riprap.solid.kernels.contact.collect_pieces`). Reuse
    does not change the force, not even its round-off: lists are ordered canonically and extra
    pieces add exactly zero.

    Few candidates are done on the calling thread (waking the thread pool costs more than they
    do); the serial loop lives outside the parallel function because numba leaked the work arrays
    of a serial branch inside a ``parallel=True`` function (measured 18 kB per call).
    """
    n_body_pairs = body_pairs.shape[0]
    n_total = n_body_pairs + wall_pairs.shape[0]
    results = np.zeros((n_total, C_SIZE))
    n_batches = 1 if n_total < PARALLEL_MIN_CANDIDATES else min(n_total, 64)
    # Per body pair: where its piece list for the next step is (SOURCE_*), its rows, its pose.
    source = np.full(n_body_pairs, SOURCE_NONE, dtype=np.int64)
    bounds = np.zeros((n_body_pairs, 3), dtype=np.int64)
    poses = np.empty((n_body_pairs, 12))
    per_batch = (n_body_pairs + n_batches - 1) // n_batches
    capacity = 8192 + 2 * (piece_cache.pieces.shape[0] // n_batches) + 128 * per_batch
    fresh = np.empty((n_batches * capacity, 2), dtype=np.int64)
    outputs = CandidateOutputs(results, fresh, capacity, source, bounds, poses)
    if n_batches == 1:
        _evaluate_range(0, 0, n_total, body_pairs, wall_pairs, system, motion, omegas, history,
                        settings, piece_cache, outputs)
    else:
        _evaluate_parallel(n_batches, body_pairs, wall_pairs, system.bodies, system.shapes.mesh,
                           system.shapes.lookup, system.walls, system.laws, motion, omegas,
                           history, settings, piece_cache, outputs)
    key_stride = motion.positions.shape[0] + system.walls.points.shape[0]
    return results, _next_piece_cache(body_pairs, key_stride, piece_cache, outputs)


@kernel
def empty_piece_cache():
    return PieceCache(np.zeros(0, dtype=np.int64), np.zeros((0, 12)),
                      np.zeros((0, 3), dtype=np.int64), np.zeros((0, 2), dtype=np.int64))


@kernel
def _next_piece_cache(body_pairs, key_stride, piece_cache, outputs):
    """Gather the kept piece lists into a new cache ordered by pair key."""
    old_keys, old_poses, old_bounds, old_pieces = piece_cache
    fresh = outputs.fresh
    source = outputs.source
    bounds = outputs.bounds
    poses = outputs.poses
    n = body_pairs.shape[0]
    n_kept = 0
    all_old = True
    for k in range(n):
        if source[k] != SOURCE_NONE:
            n_kept += 1
        if source[k] != SOURCE_OLD:
            all_old = False
    if all_old and n_kept == old_keys.shape[0]:
        return piece_cache      # the same pairs, all lists reused: nothing to move
    keys = np.empty(n_kept, dtype=np.int64)
    members = np.empty(n_kept, dtype=np.int64)
    m = 0
    for k in range(n):
        if source[k] != SOURCE_NONE:
            keys[m] = body_pairs[k, 0] * key_stride + body_pairs[k, 1]
            members[m] = k
            m += 1
    order = np.argsort(keys)
    total = 0
    for m in range(n_kept):
        k = members[m]
        total += bounds[k, 2] - bounds[k, 0]
    new_keys = np.empty(n_kept, dtype=np.int64)
    new_poses = np.empty((n_kept, 12))
    new_bounds = np.empty((n_kept, 3), dtype=np.int64)
    new_pieces = np.empty((total, 2), dtype=np.int64)
    row = 0
    for m in range(n_kept):
        k = members[order[m]]
        new_keys[m] = keys[order[m]]
        new_poses[m] = poses[k]
        first = bounds[k, 0]
        count = bounds[k, 2] - first
        new_bounds[m, 0] = row
        new_bounds[m, 1] = row + bounds[k, 1] - first
        new_bounds[m, 2] = row + count
        if source[k] == SOURCE_OLD:
            for r in range(count):
                new_pieces[row + r, 0] = old_pieces[first + r, 0]
                new_pieces[row + r, 1] = old_pieces[first + r, 1]
        else:
            for r in range(count):
                new_pieces[row + r, 0] = fresh[first + r, 0]
                new_pieces[row + r, 1] = fresh[first + r, 1]
        row += count
    return PieceCache(new_keys, new_poses, new_bounds, new_pieces)


@parallel_kernel
def _evaluate_parallel(n_batches, body_pairs, wall_pairs, bodies, mesh, lookup, walls, laws,
                       motion, omegas, history, settings, piece_cache, outputs):
    """Contiguous batches of candidates in parallel, each batch with its own work arrays and its
    own part of the fresh piece buffer.

    Takes the system's parts (``RigidSystem`` fields, the shapes as mesh and lookup) one by one:
    numba's parallel loop passes a bundle of arrays to its threads only when it is an argument of
    the function, not a bundle of bundles nor one taken out of another. Each batch puts the
    system together again (a struct of pointers, no copy)."""
    n_total = outputs.results.shape[0]
    for batch in prange(n_batches):
        _evaluate_range(batch, batch * n_total // n_batches, (batch + 1) * n_total // n_batches,
                        body_pairs, wall_pairs,
                        RigidSystem(bodies, Shapes(mesh, lookup), walls, laws), motion, omegas,
                        history, settings, piece_cache, outputs)


@kernel
def _evaluate_range(batch, first, last, body_pairs, wall_pairs, system, motion, omegas, history,
                    settings, piece_cache, outputs):
    """Candidates ``first:last`` (body pairs, then wall pairs) on one thread, with work arrays
    of their own and rows ``batch * capacity`` on of the fresh piece buffer; arguments as for
    :func:`evaluate_candidates`."""
    # the arrays the pair loop needs, out of their bundles once: a bundle read per pair cost an
    # atomic reference count per array each way, shared with the other threads
    _, shapes, walls, laws = system
    _, inverse_masses, _, _, shape_index, material_index = system.bodies
    mesh = shapes.mesh
    bounding_radius = shapes.lookup.bounding_radius
    positions, quaternions, velocities, _, _, _ = motion
    wall_points, wall_normals, wall_materials = walls
    pair_penalty = laws.penalty
    _, _, _, step, _, skin, _, period = settings
    results, fresh, capacity, source, bounds, poses = outputs
    scratch = make_scratch(mesh.tets.shape[0])
    work = scratch.work
    key_stride = positions.shape[0] + wall_points.shape[0]
    out = np.zeros(OUT_SIZE)
    # body j's centre in its image nearest body i (``periodic.py``): the pair's pose, contact
    # point and both torques are taken from it, so a pair across a periodic boundary is the pair
    # it would be inside the strip; without a periodic axis it is j's centre, to the bit
    position_j = np.empty(3)
    n_body_pairs = body_pairs.shape[0]
    cache_keys, cache_poses, cache_bounds, cache_pieces = piece_cache
    buffer_start = batch * capacity
    used = 0
    for k in range(first, last):
        if k < n_body_pairs:
            i = body_pairs[k, 0]
            j = body_pairs[k, 1]
            mi = material_index[i]
            mj = material_index[j]
            key = i * key_stride + j
            r_i = rotation_matrix(quaternions[i])
            r_j = rotation_matrix(quaternions[j])
            shape_i = shape_index[i]
            shape_j = shape_index[j]
            penalty = pair_penalty[mi, mj]
            image_of(positions[i], positions[j], period, position_j)
            rotation_1, translation_1, _, _ = relative_pose(positions[i], r_i, position_j, r_j)
            idx = np.searchsorted(cache_keys, key)
            if (skin > 0.0 and idx < cache_keys.shape[0] and cache_keys[idx] == key
                    and _within_skin(rotation_1, translation_1, cache_poses[idx],
                                     bounding_radius[shape_i], bounding_radius[shape_j], skin)):
                pair_force_from_pieces(shape_i, shape_j, positions[i], r_i, position_j, r_j,
                                       penalty, mesh, work, cache_pieces, cache_bounds[idx, 0],
                                       cache_bounds[idx, 1], cache_bounds[idx, 2], out)
                source[k] = SOURCE_OLD
                for c in range(3):
                    bounds[k, c] = cache_bounds[idx, c]
                poses[k] = cache_poses[idx]
                overflow = 0.0
            else:
                pieces = scratch.pieces
                split, end, overflow = collect_pair_pieces(shape_i, shape_j, positions[i], r_i,
                                                           position_j, r_j, skin, shapes,
                                                           scratch, pieces, 0)
                pair_force_from_pieces(shape_i, shape_j, positions[i], r_i, position_j, r_j,
                                       penalty, mesh, work, pieces, 0, split, end, out)
                if skin > 0.0 and overflow == 0.0 and used + end <= capacity:
                    row = buffer_start + used
                    for r in range(end):
                        fresh[row + r, 0] = pieces[r, 0]
                        fresh[row + r, 1] = pieces[r, 1]
                    source[k] = SOURCE_FRESH
                    bounds[k, 0] = row
                    bounds[k, 1] = row + split
                    bounds[k, 2] = row + end
                    for a in range(3):
                        for b in range(3):
                            poses[k, 3 * a + b] = rotation_1[a, b]
                        poses[k, 9 + a] = translation_1[a]
                    used += end
            inv_j = inverse_masses[j]
        else:
            w = k - n_body_pairs
            i = wall_pairs[w, 0]
            wall = wall_pairs[w, 1]
            j = -1
            mi = material_index[i]
            mj = wall_materials[wall]
            r_i = rotation_matrix(quaternions[i])
            wall_potential_force(shape_index[i], positions[i], r_i, wall_points[wall],
                                 wall_normals[wall], pair_penalty[mi, mj], shapes, scratch, out)
            key = i * key_stride + (key_stride - 1 - wall)
            inv_j = 0.0
            overflow = out[13]
        results[k, C_OVERFLOW] = overflow
        _contact_law(Candidate(k, i, j, key, inv_j, mi, mj), positions, position_j, velocities,
                     omegas, inverse_masses, laws, history, step, out, results)


@kernel
def _within_skin(rotation, translation, pose, radius_a, radius_b, skin):
    """True when no surface point of either body has moved more than ``skin`` relative to the
    other since ``pose`` (rotation row-major, translation; A's frame into B's).

    A point y of A maps to R y + t in B's frame, so it has moved by at most |dt| + ||dR|| |y|
    (Frobenius norm bounds the spectral one); B's points in A's frame move by the same rotation
    change and by R^T t - R0^T t0.
    """
    rotation_change = 0.0
    for a in range(3):
        for b in range(3):
            d = rotation[a, b] - pose[3 * a + b]
            rotation_change += d * d
    rotation_change = np.sqrt(rotation_change)
    move_a = 0.0
    move_b = 0.0
    for a in range(3):
        d = translation[a] - pose[9 + a]
        move_a += d * d
        # (R^T t)_a - (R0^T t0)_a
        e = 0.0
        for b in range(3):
            e += rotation[b, a] * translation[b] - pose[3 * b + a] * pose[9 + b]
        move_b += e * e
    return (np.sqrt(move_a) + rotation_change * radius_a <= skin
            and np.sqrt(move_b) + rotation_change * radius_b <= skin)


@kernel
def _contact_law(candidate, positions, position_j, velocities, omegas, inverse_masses, laws,
                 history, step, out, results):
    """Normal damping, tangential and twisting friction of ``candidate``
    (:class:`~riprap.solid.kernels.bundles.Candidate`) from its potential force ``out``, with the
    pair laws ``laws`` (``PairLaws``) and the springs of ``history`` (``History``); writes the
    candidate's row of ``results``. ``position_j``: body j's centre in its image nearest body i
    (the contact point lies in body i's image; not read for a wall). Takes the few arrays it
    reads rather than the whole bundles: it runs once per pair, and every array it is given
    costs a reference count each way."""
    k, i, j, key, inv_j, mi, mj = candidate
    pair_friction = laws.friction
    pair_damping_ratio = laws.damping_ratio
    pair_tangential_ratio = laws.tangential_ratio
    history_keys, history_springs = history
    f_mag = np.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
    if f_mag <= 0.0:
        return
    normal = out[0:3] / f_mag
    point = out[9:12]
    # Relative velocity of body i with respect to body j (or the wall) at the contact point.
    arm_i = point - positions[i]
    v_rel = velocities[i] + np.cross(omegas[i], arm_i)
    if j >= 0:
        arm_j = point - position_j
        v_rel = v_rel - (velocities[j] + np.cross(omegas[j], arm_j))
    v_n = v_rel[0] * normal[0] + v_rel[1] * normal[1] + v_rel[2] * normal[2]
    v_t = v_rel - v_n * normal
    inv_sum = inverse_masses[i] + inv_j
    m_eff = 1.0 / inv_sum if inv_sum > 0.0 else 0.0
    stiffness = out[12]
    zeta = pair_damping_ratio[mi, mj]
    gamma_n = 2.0 * zeta * np.sqrt(m_eff * stiffness)
    normal_magnitude = f_mag - gamma_n * v_n
    if normal_magnitude < 0.0:
        normal_magnitude = 0.0
    # Tangential elastic force and twisting torque from the history, the force rotated onto the
    # current tangent plane with its magnitude kept.
    spring = np.zeros(3)
    twist = 0.0
    k_t_old = 0.0
    k_twist_old = 0.0
    idx = np.searchsorted(history_keys, key)
    if idx < history_keys.shape[0] and history_keys[idx] == key:
        old = history_springs[idx]
        old_norm = np.sqrt(old[0] * old[0] + old[1] * old[1] + old[2] * old[2])
        spring = old[0:3] - (old[0] * normal[0] + old[1] * normal[1] + old[2] * normal[2]) * normal
        new_norm = np.sqrt(spring[0] * spring[0] + spring[1] * spring[1] + spring[2] * spring[2])
        if new_norm > 0.0:
            spring *= old_norm / new_norm
        twist = old[3]
        k_t_old = old[4]
        k_twist_old = old[5]
    k_t = pair_tangential_ratio[mi, mj] * stiffness
    # Polar radius of gyration of the contact pressure about the normal through the contact point.
    polar = out[15] + out[16] + out[17] - (
        normal[0] * normal[0] * out[15] + normal[1] * normal[1] * out[16]
        + normal[2] * normal[2] * out[17] + 2.0 * (normal[0] * normal[1] * out[18]
                                                   + normal[0] * normal[2] * out[19]
                                                   + normal[1] * normal[2] * out[20]))
    radius_squared = polar / out[21] if out[21] > 0.0 else 0.0
    radius_squared = max(radius_squared, 0.5 * out[14] / np.pi)
    radius = np.sqrt(radius_squared)
    k_twist = k_t * radius_squared
    if idx < history_keys.shape[0] and history_keys[idx] == key:
        if k_t < k_t_old:
            spring *= k_t / k_t_old
        if k_twist < k_twist_old:
            twist *= k_twist / k_twist_old
    gamma_t = 2.0 * zeta * np.sqrt(m_eff * k_t)
    friction = pair_friction[mi, mj]
    spring -= k_t * step * v_t
    tangential = spring - gamma_t * v_t
    t_mag = np.sqrt(tangential[0] ** 2 + tangential[1] ** 2 + tangential[2] ** 2)
    limit = friction * normal_magnitude
    if t_mag > limit:
        if t_mag > 0.0:
            tangential *= limit / t_mag
        spring = tangential.copy()
    # Twist about the normal.
    w_rel = omegas[i]
    if j >= 0:
        w_rel = w_rel - omegas[j]
    w_n = w_rel[0] * normal[0] + w_rel[1] * normal[1] + w_rel[2] * normal[2]
    twist -= k_twist * step * w_n
    twist_torque = twist - gamma_t * radius_squared * w_n
    twist_limit = 2.0 * np.sqrt(2.0) / 3.0 * friction * normal_magnitude * radius
    if abs(twist_torque) > twist_limit:
        twist_torque = np.sign(twist_torque) * twist_limit
        twist = twist_torque
    extra = (normal_magnitude - f_mag) * normal + tangential
    force_i = normal_magnitude * normal + tangential
    torque_i = out[3:6] + np.cross(arm_i, extra) + twist_torque * normal
    results[k, C_FORCE_I:C_FORCE_I + 3] = force_i
    results[k, C_TORQUE_I:C_TORQUE_I + 3] = torque_i
    if j >= 0:
        results[k, C_TORQUE_J:C_TORQUE_J + 3] = (out[6:9] - np.cross(point - position_j, extra)
                                                 - twist_torque * normal)
    results[k, C_POINT:C_POINT + 3] = point
    results[k, C_NORMAL_FORCE:C_NORMAL_FORCE + 3] = normal_magnitude * normal
    results[k, C_TANGENTIAL_FORCE:C_TANGENTIAL_FORCE + 3] = tangential
    results[k, C_SPRING:C_SPRING + 3] = spring
    results[k, C_SPRING + 3] = twist
    results[k, C_SPRING + 4] = k_t
    results[k, C_SPRING + 5] = k_twist
    results[k, C_STIFFNESS] = stiffness
    results[k, C_AREA] = out[14]
    results[k, C_ACTIVE] = 1.0


@kernel
def accumulate(body_pairs, wall_pairs, results, forces, torques):
    """Add the pair results to the bodies' force and torque (serial: no write conflicts)."""
    n_body_pairs = body_pairs.shape[0]
    for k in range(results.shape[0]):
        if results[k, C_ACTIVE] == 0.0:
            continue
        if k < n_body_pairs:
            i = body_pairs[k, 0]
            j = body_pairs[k, 1]
        else:
            i = wall_pairs[k - n_body_pairs, 0]
            j = -1
        for c in range(3):
            forces[i, c] += results[k, C_FORCE_I + c]
            torques[i, c] += results[k, C_TORQUE_I + c]
            if j >= 0:
                forces[j, c] -= results[k, C_FORCE_I + c]
                torques[j, c] += results[k, C_TORQUE_J + c]
