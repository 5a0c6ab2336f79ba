"""How far each unit moved between two states of a layer (a run's frame 0 and frame N).

Displacement: the move of the unit's centroid, as a vector in the world (m), its length in m and in
nominal diameters D_n (the measure used for armour damage, e.g. a unit "displaced" by more than
about one D_n), and its component along the slope (positive up the face). Rotation: the angle of
the rotation that carries the unit's orientation in the reference state onto the present one,
R_now R_ref^T, in degrees (0..180), whatever the axis.

On a periodic strip (``slope.periodic``) a unit that left at one side is back at the other: its
move across the flume is taken to the nearest image (a unit is not carried half the strip's width
across the flume between two surveys).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["unit_displacements", "DISPLACEMENT_COLUMNS"]

#: The columns :func:`unit_displacements` returns, in the order of ``units.csv``.
DISPLACEMENT_COLUMNS = ("displacement_x_m", "displacement_y_m", "displacement_z_m",
                        "displacement_m", "displacement_over_dn", "displacement_along_slope_m",
                        "rotation_deg")


def unit_displacements(positions, rotations, reference_positions, reference_rotations, *,
                       nominal_diameter: float, slope=None) -> dict:
    """Per-unit displacement and rotation from the reference poses to the present ones.

    Parameters
    ----------
    positions, reference_positions : (n, 3) float
        Centroids now and in the reference state (m).
    rotations, reference_rotations : (n, 3, 3) float
        Orientations now and in the reference state (rotation matrices into the world).
    nominal_diameter : float
        D_n of a unit (m), for ``displacement_over_dn``.
    slope : riprap.placement.slope.Slope or None
        The face, for ``displacement_along_slope_m`` (NaN without one); a periodic strip's moves
        across it are unwrapped.

    Returns
    -------
    dict of str to (n,) float, the keys of :data:`DISPLACEMENT_COLUMNS`.

    Examples
    --------
    >>> import numpy as np
    >>> quarter_turn = np.array([[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]])
    >>> moved = unit_displacements([[3.0, 4.0, 0.0]], quarter_turn, [[0.0, 0.0, 0.0]],
    ...                            np.eye(3)[None], nominal_diameter=2.5)
    >>> float(moved["displacement_m"][0]), float(moved["displacement_over_dn"][0])
    (5.0, 2.0)
    >>> round(float(moved["rotation_deg"][0]), 6)
    90.0
    """
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    reference_positions = np.asarray(reference_positions, dtype=float).reshape(-1, 3)
    rotations = np.asarray(rotations, dtype=float).reshape(-1, 3, 3)
    reference_rotations = np.asarray(reference_rotations, dtype=float).reshape(-1, 3, 3)
    move = positions - reference_positions
    if slope is not None and slope.periodic:
        move[:, 1] -= slope.width * np.round(move[:, 1] / slope.width)
    distance = np.linalg.norm(move, axis=1)
    if len(positions):
        relative = rotations @ np.transpose(reference_rotations, (0, 2, 1))
        angle = np.degrees(Rotation.from_matrix(relative).magnitude())
    else:
        angle = np.zeros(0)
    if slope is not None and len(positions):
        along = slope.to_slope(positions)[:, 0] - slope.to_slope(reference_positions)[:, 0]
    else:
        along = np.full(len(positions), np.nan)
    return {"displacement_x_m": move[:, 0], "displacement_y_m": move[:, 1],
            "displacement_z_m": move[:, 2], "displacement_m": distance,
            "displacement_over_dn": distance / float(nominal_diameter),
            "displacement_along_slope_m": along, "rotation_deg": angle}
