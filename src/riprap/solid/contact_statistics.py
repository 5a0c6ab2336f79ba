"""Per-body contact statistics of one contact state: coordination number and the largest contact
force, split by what the body touches (another unit, or the underlayer: rocks and walls).

Input is the solver's contact record (``SolidSolver.contacts``: one row per touching pair, forces
on ``body_i``, ``body_j`` = -1 - w for wall w). The coordination number of a body is the number of
distinct bodies and walls it touches (the seed paper's "contact number", 2 to 10 for its Core-Loc
layer); a contact force is the magnitude of the normal plus the tangential force of a pair.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class UnitContacts:
    """Arrays of one value per body (n_bodies,)."""

    coordination_number: np.ndarray          # bodies and walls touched
    max_contact_force: np.ndarray            # N, over all contacts of the body
    max_contact_force_unit_unit: np.ndarray  # N, with bodies of the same group
    max_contact_force_unit_underlayer: np.ndarray  # N, with other groups and walls
    total_contact_force: np.ndarray          # (n, 3) N, sum of the contact forces on the body


def unit_contacts(n_bodies: int, contacts, group=None) -> UnitContacts:
    """Statistics of ``contacts`` (``ContactRecords``) per body; ``group`` (n_bodies,) integer label of
    each body (e.g. 1 for armour units, 0 for underlayer rocks): contacts between equal labels count
    as unit-unit, all others (and walls) as unit-underlayer. Default: all bodies in one group."""
    group = np.zeros(n_bodies, dtype=np.int64) if group is None else np.asarray(group)
    if group.shape != (n_bodies,):
        raise ValueError(f"group has shape {group.shape}, expected ({n_bodies},)")
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    force = np.asarray(contacts.normal_forces) + np.asarray(contacts.tangential_forces)
    magnitude = np.linalg.norm(force, axis=1) if len(force) else np.zeros(0)
    coordination = np.zeros(n_bodies, dtype=np.int64)
    largest = np.zeros(n_bodies)
    same = np.zeros(n_bodies)
    other = np.zeros(n_bodies)
    total = np.zeros((n_bodies, 3))
    is_body = body_j >= 0
    partner_group = np.where(is_body, group[np.maximum(body_j, 0)], -1)
    same_group = is_body & (group[body_i] == partner_group)
    # Each row is one touching pair, seen from both of its bodies (a wall has no statistics).
    for side, sign in ((body_i, 1.0), (body_j[is_body], -1.0)):
        rows = np.arange(len(body_i)) if sign > 0 else np.flatnonzero(is_body)
        np.add.at(coordination, side, 1)
        np.maximum.at(largest, side, magnitude[rows])
        np.maximum.at(same, side[same_group[rows]], magnitude[rows][same_group[rows]])
        np.maximum.at(other, side[~same_group[rows]], magnitude[rows][~same_group[rows]])
        np.add.at(total, side, sign * force[rows])
    return UnitContacts(coordination_number=coordination, max_contact_force=largest,
                        max_contact_force_unit_unit=same, max_contact_force_unit_underlayer=other,
                        total_contact_force=total)


def pair_friction(contacts, friction_table, material_of_body, material_of_wall) -> np.ndarray:
    """Friction coefficient of each contact row, as the solver gives it: ``friction_table``
    (n_materials, n_materials) of :func:`riprap.solid.materials.friction_table` (a
    ``[[friction]]`` pair's own, else the smaller of the two materials'); ``material_of_body``
    (n_bodies,), ``material_of_wall`` (n_walls,) material indices."""
    table = np.asarray(friction_table, dtype=float)
    material_of_body = np.asarray(material_of_body, dtype=np.int64)
    material_of_wall = np.asarray(material_of_wall, dtype=np.int64)
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    is_wall = body_j < 0
    walls = np.where(is_wall, -1 - body_j, 0)
    other = np.where(is_wall, material_of_wall[walls] if len(material_of_wall) else 0,
                     material_of_body[np.maximum(body_j, 0)])
    return table[material_of_body[body_i], other]


def sliding_factor_of_safety(n_bodies: int, contacts, friction_coefficient) -> np.ndarray:
    """Factor of safety of each body against sliding on its contacts (inf for a body touching
    nothing or carrying no tangential force).

    Limit-equilibrium definition (shear strength available over shear force mobilised, as for
    slopes, e.g. Duncan 1996, J. Geotech. Eng. 122(7)), over all the body's contacts together:
    FoS = sum_c mu_c |N_c| / sum_c |T_c|. A block resting on a plane inclined at theta carries
    N = W cos theta and T = W sin theta, so FoS = mu / tan theta; FoS = 1 means every contact is at
    its Coulomb limit. ``friction_coefficient``: one value, or one per contact row.
    """
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    mu = np.broadcast_to(np.asarray(friction_coefficient, dtype=float), body_i.shape)
    normal = np.linalg.norm(np.asarray(contacts.normal_forces), axis=1) if len(body_i) else np.zeros(0)
    tangential = (np.linalg.norm(np.asarray(contacts.tangential_forces), axis=1) if len(body_i)
                  else np.zeros(0))
    strength = np.zeros(n_bodies)
    mobilised = np.zeros(n_bodies)
    is_body = body_j >= 0
    for side, rows in ((body_i, slice(None)), (body_j[is_body], is_body)):
        np.add.at(strength, side, (mu * normal)[rows])
        np.add.at(mobilised, side, tangential[rows])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mobilised > 0, strength / np.where(mobilised > 0, mobilised, 1.0), np.inf)


def solver_contact_statistics(solver) -> dict:
    """Per body of a ``SolidSolver`` as it is now: coordination number, largest contact force (N)
    and factor of safety against sliding (inf where nothing pushes a body sideways), as a frame of
    ``bodies.pvd`` records them, dry or in water."""
    contacts = solver.contacts
    stats = unit_contacts(solver.n_bodies, contacts)
    friction = pair_friction(contacts, solver.friction_table, solver.material_index_of_body,
                             solver.wall_materials)
    return {"coordination_number": stats.coordination_number,
            "max_contact_force": stats.max_contact_force,
            "factor_of_safety_sliding": sliding_factor_of_safety(solver.n_bodies, contacts,
                                                                 friction)}
