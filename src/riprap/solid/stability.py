"""How close the contact step is to what the contacts present can carry: the measured stability
ratio dt / (2 sqrt(m_eff / k)) (1 is the limit of an undamped spring stepped by central
differences) and how far the bodies move in a step. The rigid model's adaptive step and the
coupled solver's adaptive contact sub-step both steer by these."""
from __future__ import annotations

import numpy as np

__all__ = ["MAX_MOTION_PER_STEP", "contact_stability_rate", "max_speed", "motion_limited_step",
           "shape_inverse_masses", "stability_ratio", "worst_contact_rate"]

#: No body should move more than this fraction of the thinnest boundary layer of tets in a step,
#: so that a contact cannot go from nothing to a deep overlap in one step.
MAX_MOTION_PER_STEP = 0.1


def max_speed(solver) -> float:
    """Largest speed of a free body including rotation at its bounding radius (m/s)."""
    free = ~solver.fixed
    if not free.any():
        return 0.0
    radius = solver.bounding_radius[solver.shape_index]
    speed = (np.linalg.norm(solver.velocities, axis=1)
             + np.linalg.norm(solver.angular_velocities, axis=1) * radius)
    return float(speed[free].max())


def _contact_rates(solver) -> np.ndarray:
    """Per current contact sqrt(k w) / 2 (1/s): its stability ratio per second of step, k the
    contact's measured normal stiffness and w the larger of two inverse masses, summed over the
    pair's free bodies (a fixed body or a wall is infinitely heavy):

    - along the normal at the contact point, exactly: 1/m + (r x n) . I^-1 (r x n), r from the
      body's centre to the force-weighted contact point, n the normal, I the world inertia (a
      cube pressed face to face on the face's centre: 1/m);
    - across it, for the tangential and twist springs (k_t = tangential_stiffness_ratio k):
      k_t / k times 1/m + R^2 / I_min, the lever arm bounded by the bounding radius R (the
      contact's radius of gyration is taken as at most R).

    Before session 25 w was 1 / min(m, I_min / R^2) for every contact: 4.5 / m for a cube,
    twice too slow a sub-step for cubes pressed face to face (w = 1/m), and too fast for a
    contact far off the centre's line (up to 5.5 / m)."""
    c = solver.contacts
    if len(c) == 0:
        return np.zeros(0)
    shapes = solver.shape_index
    free = ~solver.fixed
    inverse_mass = np.where(free, 1.0 / solver.masses, 0.0)
    lever = np.where(free, solver.bounding_radius[shapes] ** 2
                     / solver.principal_inertia.min(axis=1), 0.0)
    rotations = solver.rotation_matrices()
    force = np.linalg.norm(c.normal_forces, axis=1)
    normals = np.divide(c.normal_forces, force[:, None], out=np.zeros_like(c.normal_forces),
                        where=force[:, None] > 0.0)
    ratio = solver._pair_laws.tangential_ratio
    materials = solver.material_index_of_body

    def along_normal(bodies):
        # by minimum image: across a periodic boundary the point lies beside body i only
        arm = np.cross(solver.minimum_image(c.points - solver.positions[bodies]), normals)
        local = np.einsum("bji,bj->bi", rotations[bodies], arm)      # R^T (r x n)
        turn = np.sum(local ** 2 * solver.inverse_principal_inertia[bodies], axis=1)
        # a contact of zero force (just touching) has no normal: its lever arm at worst
        turn = np.where(force > 0.0, turn, lever[bodies])
        return inverse_mass[bodies] + np.where(free[bodies], turn, 0.0)

    on_body = c.body_j >= 0
    j = np.maximum(c.body_j, 0)
    normal = along_normal(c.body_i) + np.where(on_body, along_normal(j), 0.0)
    across = (inverse_mass[c.body_i] + lever[c.body_i]
              + np.where(on_body, inverse_mass[j] + lever[j], 0.0))
    material_j = np.where(on_body, materials[j], solver.wall_materials[np.maximum(-1 - c.body_j, 0)]
                          if len(solver.wall_materials) else 0)
    tangential = ratio[materials[c.body_i], material_j]
    w = np.maximum(normal, tangential * across)
    return np.sqrt(c.stiffness * w) / 2.0


def contact_stability_rate(solver) -> float:
    """The largest stability ratio per second of step over the current contacts (1/s): a step of
    dt has ratio dt times this. 0 without contacts."""
    if len(solver.contacts) == 0:
        return 0.0
    return float(_contact_rates(solver).max())


def stability_ratio(solver) -> tuple[float, str]:
    """(max over current contacts of dt / (2 sqrt(m_eff / k)), the pair where it is, in words);
    k the contact's measured stiffness and m_eff the smaller of the translational and rotational
    effective masses of the pair. (0, "") without contacts."""
    c = solver.contacts
    if len(c) == 0:
        return 0.0, ""
    ratio = solver.time_step * _contact_rates(solver)
    worst = int(np.argmax(ratio))
    j = int(c.body_j[worst])
    pair = f"body {int(c.body_i[worst])} and " + (f"wall {-1 - j}" if j < 0 else f"body {j}")
    return float(ratio[worst]), pair


def motion_limited_step(solver) -> float:
    """The longest step in which no body moves more than ``MAX_MOTION_PER_STEP`` of the thinnest
    boundary sub-tet at its present speed (s; inf when nothing moves)."""
    speed = max_speed(solver)
    if speed <= 0.0:
        return np.inf
    smallest = min(shape.min_subtet_height for shape in solver.shapes)
    return MAX_MOTION_PER_STEP * smallest / speed


def shape_inverse_masses(shape) -> tuple[float, float]:
    """(along the normal, across it) the largest inverse mass of a contact anywhere on
    ``shape``'s surface, per unit density (1/m^3; divide by the density for 1/kg):

    - along the normal: max over the boundary nodes r and every unit normal n of
      1/V + (r x n) . J^-1 (r x n), J the principal moments per unit density. For a node r the
      vectors r x n fill the disc of radius |r| across r, so the maximum is |r|^2 times the
      largest eigenvalue of J^-1 restricted to the plane across r. A contact at a face, an edge
      or a corner has its force-weighted point inside the hull of the nodes, whose lever arm is
      no longer than the farthest node's, so this holds for every contact the shape can make;
    - across the normal (the tangential and twisting springs): 1/V + R^2 / J_min, R the
      bounding radius, as :func:`_contact_rates` takes it.

    A cube: 5.5 / V along (a corner: 1/V + 4.5/V), the same across."""
    nodes = shape.mesh.nodes[np.unique(shape.triangles)]
    inverse_moments = 1.0 / np.asarray(shape.unit_principal_moments, dtype=float)
    lengths = np.linalg.norm(nodes, axis=1)
    unit = nodes / np.maximum(lengths, np.finfo(float).tiny)[:, None]
    across = np.eye(3)[None] - unit[:, :, None] * unit[:, None, :]        # P = I - r r^T
    restricted = across @ np.diag(inverse_moments) @ across                 # P J^-1 P
    largest = np.linalg.eigvalsh(restricted)[:, -1]
    normal = 1.0 / shape.volume + float(np.max(lengths ** 2 * largest, initial=0.0))
    tangential = 1.0 / shape.volume + shape.bounding_radius ** 2 * float(inverse_moments.max())
    return normal, tangential


def worst_contact_rate(solver) -> tuple[float, str]:
    """(the largest stability ratio per second of step, 1/s, of any contact the bodies can make;
    that contact, in words): the rate sqrt(k w) / 2 of :func:`_contact_rates` with, for every
    kind of body (shape, material, free or fixed) that can meet another or a wall,

    - the largest plausible stiffness of their contact: a whole face pressed in,
      k = p min(A_i, A_j) (1/h_i + 1/h_j), A = V^(2/3) and h the 10th-percentile boundary sub-tet
      height of each (a wall is meshed as the body touching it: k = 2 p A_i / h_i, the estimate
      of the automatic step); p the pair's penalty;
    - the largest inverse mass anywhere on each free body's surface (:func:`shape_inverse_masses`),
      summed over the pair's free bodies, along the normal and (times the pair's tangential
      stiffness ratio) across it,

    not those of the contacts present now. (0, "") without free bodies."""
    free = ~solver.fixed
    if not free.any():
        return 0.0, ""
    laws = solver._pair_laws
    materials = solver.material_index_of_body
    kinds = {}
    for b in range(len(materials)):
        kinds.setdefault((int(solver.shape_index[b]), int(materials[b]), bool(free[b])), []).append(b)
    keys = list(kinds)
    per_shape = {}
    for shape_index, _, _ in keys:
        if shape_index not in per_shape:
            shape = solver.shapes[shape_index]
            per_shape[shape_index] = (shape.volume ** (2.0 / 3.0), shape.min_subtet_height,
                                      *shape_inverse_masses(shape))
    density = [solver.materials[m].density for _, m, _ in keys]
    area = np.array([per_shape[s][0] for s, _, _ in keys])
    height = np.array([per_shape[s][1] for s, _, _ in keys])
    moving = np.array([f for _, _, f in keys])
    normal = np.where(moving, [per_shape[s][2] / rho for (s, _, _), rho in zip(keys, density)], 0.0)
    across = np.where(moving, [per_shape[s][3] / rho for (s, _, _), rho in zip(keys, density)], 0.0)
    material = np.array([m for _, m, _ in keys])
    # every pair of kinds of which one at least moves (a kind meets itself when it has two bodies)
    i, j = np.triu_indices(len(keys))
    alone = (i == j) & np.array([len(kinds[keys[k]]) < 2 for k in i])
    keep = (moving[i] | moving[j]) & ~alone
    i, j = i[keep], j[keep]
    stiffness = (laws.penalty[material[i], material[j]] * np.minimum(area[i], area[j])
                 * (1.0 / height[i] + 1.0 / height[j]))
    rates = stiffness * np.maximum(normal[i] + normal[j], laws.tangential_ratio[material[i], material[j]]
                                   * (across[i] + across[j]))
    found = []
    if len(rates):
        best = int(np.argmax(rates))
        found.append((float(rates[best]), _pair_in_words(solver, keys, kinds, int(i[best]),
                                                          int(j[best]))))
    if len(solver.walls):
        walls = np.flatnonzero(moving)
        wall_materials = np.asarray(solver.wall_materials)
        penalty = laws.penalty[material[walls][:, None], wall_materials[None, :]].max(axis=1)
        ratio = laws.tangential_ratio[material[walls][:, None], wall_materials[None, :]].max(axis=1)
        wall_rates = (2.0 * penalty * area[walls] / height[walls]
                      * np.maximum(normal[walls], ratio * across[walls]))
        best = int(np.argmax(wall_rates))
        k = int(walls[best])
        found.append((float(wall_rates[best]),
                      f"body {kinds[keys[k]][0]} (shape '{solver.shapes[keys[k][0]].name}') "
                      "against a wall"))
    rate, where = max(found)
    return float(np.sqrt(rate) / 2.0), where


def _pair_in_words(solver, keys, kinds, a: int, b: int) -> str:
    """The bodies of kinds ``a`` and ``b`` meeting, named by a body of each and its shape."""
    bodies = (kinds[keys[a]][0], kinds[keys[b]][1] if a == b else kinds[keys[b]][0])
    named = [f"body {body} ({'fixed, ' if not keys[k][2] else ''}shape "
             f"'{solver.shapes[keys[k][0]].name}')" for body, k in zip(bodies, (a, b))]
    return f"{named[0]} against {named[1]}"
