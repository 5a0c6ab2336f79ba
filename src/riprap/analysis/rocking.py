"""Factor of safety of an armour unit against rocking (toppling) down the slope.

Definition (the toppling criterion of Goodman & Bray 1976, "Toppling of rock slopes", Proc.
Specialty Conf. on Rock Engineering for Foundations and Slopes, ASCE, Boulder, vol. 2, 201-234;
Wyllie & Mah 2004, Rock Slope Engineering, 4th ed., ch. 9), generalised from a block on a plane
to a unit in a pack:

- The unit rocks forward (down the slope) about a pivot axis parallel to the slope's horizontal
  y axis, through the support point that lies furthest down the slope.
- Support points: the contact points of the unit's contacts with what carries it (underlayer
  rocks, the face and other walls, and units whose centroids lie further down the slope); for a
  wall contact, also every node of the unit that lies inside the wall, so that a flat face resting
  on a wall pivots about its real edge, not about its centre of pressure.
- Loads: the unit's weight at its centroid, and the contact forces from units whose centroids lie
  further up the slope (they lean on it). Each load is split into its components along the face
  (t) and along the face normal (n); each component's moment about the pivot axis either tips
  the unit forward (overturning) or holds it back (restoring).
- FoS = sum of restoring moments / sum of overturning moments.

For a block of width b (along the slope) and height h (normal to it) resting on a plane inclined
at theta this gives FoS = (b / h) / tan(theta): the block topples when its weight passes outside
its base (Goodman & Bray). A unit with no support has FoS 0; one with no overturning moment inf.
Contact points between two bodies are the solver's force-weighted points (one per pair), so a
broad face-to-face contact between two bodies pivots about its centre of pressure: the FoS is
then underestimated (on the safe side).
"""
from __future__ import annotations

import numpy as np

__all__ = ["rocking_factor_of_safety"]

# A node counts as inside a wall when it lies this far (relative to the unit's size) below the
# wall plane or deeper; penalty overlaps are a small fraction of a unit, so nodes just above the
# plane (not touching) are not mistaken for support.
_INSIDE_WALL = 0.0


def rocking_factor_of_safety(state, unit_bodies, weights, slope) -> np.ndarray:
    """FoS against rocking down the slope of each body in ``unit_bodies`` (see module docstring).

    ``state``: a :class:`riprap.analysis.layer_state.LayerState`; ``weights`` (n_bodies,) N;
    ``slope``: its :class:`riprap.placement.slope.Slope` (the t, y, n frame).
    """
    unit_bodies = np.asarray(unit_bodies, dtype=np.int64)
    contacts = state.contacts
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    points = np.asarray(contacts.points, dtype=float).reshape(-1, 3)
    forces = (np.asarray(contacts.normal_forces, dtype=float)
              + np.asarray(contacts.tangential_forces, dtype=float)).reshape(-1, 3)
    tangent, normal = slope.tangent, slope.normal
    across = np.cross(normal, tangent)          # e_y: t x e_y = n
    along = slope.to_slope(state.positions)[:, 0]
    is_unit = np.zeros(state.n_bodies, dtype=bool)
    is_unit[unit_bodies] = True
    gravity_direction = state.gravity / max(np.linalg.norm(state.gravity), 1e-300)
    result = np.empty(len(unit_bodies))
    for k, body in enumerate(unit_bodies):
        rows_as_i = np.flatnonzero(body_i == body)
        rows_as_j = np.flatnonzero(body_j == body)
        partners = np.concatenate([body_j[rows_as_i], body_i[rows_as_j]])
        row_forces = np.concatenate([forces[rows_as_i], -forces[rows_as_j]])
        row_points = np.concatenate([points[rows_as_i], points[rows_as_j]])
        partner_is_unit = (partners >= 0) & is_unit[np.maximum(partners, 0)]
        upslope_unit = partner_is_unit & (along[np.maximum(partners, 0)] > along[body])
        # Side walls (normal along y) hold a unit sideways only; they are no pivot for rocking.
        side_wall = np.zeros(len(partners), dtype=bool)
        wall_rows = partners < 0
        side_wall[wall_rows] = np.abs(state.wall_normals[-1 - partners[wall_rows]] @ across) > 0.9
        support = ~upslope_unit & ~side_wall
        support_points = [row_points[support]]
        for wall in np.unique(-1 - partners[wall_rows & ~side_wall]):
            nodes = state.world_nodes(body)
            depth = (nodes - state.wall_points[wall]) @ state.wall_normals[wall]
            support_points.append(nodes[depth <= _INSIDE_WALL])
        support_points = np.concatenate(support_points)
        if len(support_points) == 0:
            result[k] = 0.0
            continue
        pivot = support_points[np.argmin(support_points @ tangent)]
        load_points = np.vstack([state.positions[body][None, :], row_points[upslope_unit]])
        load_forces = np.vstack([weights[body] * gravity_direction[None, :],
                                 row_forces[upslope_unit]])
        arms = load_points - pivot
        restoring = overturning = 0.0
        for direction in (tangent, normal):
            components = (load_forces @ direction)[:, None] * direction[None, :]
            moments = np.cross(arms, components) @ across
            # Rotation about +e_y carries the top of the unit up the slope: positive moments
            # hold the unit back, negative ones tip it forward.
            restoring += moments[moments > 0].sum()
            overturning -= moments[moments < 0].sum()
        result[k] = restoring / overturning if overturning > 0 else np.inf
    return result
