"""How close the contact step is to what the contacts present can carry: the measured stability
ratio dt / (2 sqrt(m_eff / k)) (1 is the limit of an undamped spring stepped by central
differences) and how far the bodies move in a step. The rigid model's adaptive step and the
coupled solver's adaptive contact sub-step both steer by these."""
from __future__ import annotations

import numpy as np

__all__ = ["MAX_MOTION_PER_STEP", "contact_stability_rate", "max_speed", "motion_limited_step",
           "stability_ratio"]

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
        arm = np.cross(c.points - solver.positions[bodies], normals)
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
