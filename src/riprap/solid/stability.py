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
    """Per current contact sqrt(k (1/m_i + 1/m_j)) / 2 (1/s): its stability ratio per second of
    step; k the contact's measured stiffness, m the smaller of a body's translational and
    rotational (I_min / r_max^2) mass, a fixed body or a wall infinitely heavy."""
    c = solver.contacts
    shapes = solver.shape_index
    rotational = solver.principal_inertia.min(axis=1) / solver.bounding_radius[shapes] ** 2
    inverse = np.where(solver.fixed, 0.0, 1.0 / np.minimum(solver.masses, rotational))
    inverse_j = np.where(c.body_j >= 0, inverse[np.maximum(c.body_j, 0)], 0.0)
    return np.sqrt(c.stiffness * (inverse[c.body_i] + inverse_j)) / 2.0


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
