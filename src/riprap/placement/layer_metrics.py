"""What a placed armour layer is, in the numbers designers use (CEM VI-5; Rock Manual 5.2.2).

Definitions (n layers of units of nominal diameter D_n = V^(1/3) on a face of area A):

- packing density coefficient  phi = N D_n^2 / A   (units per area N/A = phi / D_n^2),
- layer thickness t: from the top of the underlayer to the top of the armour, both along the face
  normal; the design value is t = n k_t D_n,
- layer porosity  n_v = 1 - N V / (A t),  so that phi = n k_t (1 - n_v) when t = n k_t D_n.

They are measured on a band of the face that leaves out the first and last rows (edge rows rest
against the toe or have no row above them, as in a flume test's measuring section): units whose
centroid lies in [``s_low + D_n``, ``s_high - D_n``) along the face, where s_low, s_high are
the lowest and highest unit centroids. The tops are measured per body as its highest point above
the face (a probe with a foot about a unit wide reads the unit tops); the underlayer top is the
mean of those of the underlayer rocks in the upper half of the rock tops.
"""
from __future__ import annotations

import numpy as np


def body_tops(slope, node_sets) -> np.ndarray:
    """Highest point of each body above the face (m), from its world nodes."""
    return np.array([slope.to_slope(nodes)[:, 2].max() for nodes in node_sets])


def underlayer_top(slope, rock_node_sets) -> float:
    """Level of the underlayer's top surface above the face (m): mean top of the upper half."""
    tops = body_tops(slope, rock_node_sets)
    if len(tops) == 0:
        return 0.0
    upper = tops[tops >= np.median(tops)]
    return float(upper.mean())


def measuring_band(s_positions, nominal_diameter) -> tuple[float, float, np.ndarray]:
    """(s_low, s_high, mask of the units inside) with one D_n left out at each end."""
    s = np.asarray(s_positions, dtype=float)
    low = s.min() + nominal_diameter
    high = s.max() - nominal_diameter
    if high <= low:          # too few rows to trim: measure over the whole layer
        low, high = s.min() - 0.5 * nominal_diameter, s.max() + 0.5 * nominal_diameter
    # Half-open, so that a band whose ends fall on rows counts one of them, not both.
    inside = (s >= low) & (s < high)
    return float(low), float(high), inside


def layer_figures(slope, unit_positions, unit_node_sets, *, nominal_diameter, unit_volume,
                  underlayer_level) -> dict:
    """Packing density coefficient, layer thickness and porosity of the units resting on the face.

    ``unit_positions`` (n, 3) world centroids; ``unit_node_sets`` world nodes of each unit.
    """
    coords = slope.to_slope(unit_positions)
    low, high, inside = measuring_band(coords[:, 0], nominal_diameter)
    count = int(inside.sum())
    area = slope.slope_area(low, high)
    tops = body_tops(slope, [unit_node_sets[k] for k in np.flatnonzero(inside)])
    thickness = float(tops.mean() - underlayer_level) if count else 0.0
    packing = count * nominal_diameter ** 2 / area if area > 0 else 0.0
    porosity = 1.0 - count * unit_volume / (area * thickness) if area > 0 and thickness > 0 else 1.0
    return {"packing_density_coefficient": float(packing), "layer_thickness_m": thickness,
            "porosity": float(porosity), "measuring_band_m": [low, high],
            "units_in_measuring_band": count, "measuring_area_m2": area}
