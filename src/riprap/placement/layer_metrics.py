"""What a placed armour layer is, in the numbers designers use (CEM VI-5; Rock Manual 5.2.2).

Definitions (n layers of units of nominal diameter D_n = V^(1/3) on a face of area A):

- packing density coefficient  phi = N D_n^2 / A   (units per area N/A = phi / D_n^2),
- layer thickness t: from the top of the underlayer to the top of the armour, both along the face
  normal; the design value is t = n k_t D_n,
- layer porosity  n_v = 1 - N V / (A t),  so that phi = n k_t (1 - n_v) when t = n k_t D_n.

They are measured row by row, as the layer was built: with rows 1..R (the design rows; their
mean positions s_1 < ... < s_R along the face after settling), the face between the first and the
last row, A = width x (s_R - s_1), holds half of the first and of the last row and all the rows
between (the trapezoidal rule: N = n_1/2 + n_2 + ... + n_(R-1) + n_R/2). Counting whole rows
inside a fixed measuring band instead would jump by a whole row (a quarter of a small layer's
count) with where the band's ends happen to fall. Units that rolled off the face are not counted.
The tops are measured per body as its highest point above the face (a probe with a foot about a
unit wide reads the unit tops), over the rows between the first and the last; the underlayer top
is the mean of those of the underlayer rocks in the upper half of the rock tops.
"""
from __future__ import annotations

import numpy as np

#: The key of :func:`layer_figures` saying why a figure is not measured (absent where all are).
NOT_MEASURED = "layer_figures_not_measured"


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


def rows_by_position(s_positions, nominal_diameter) -> np.ndarray:
    """Row of each unit from positions along the face: sorted, a gap over half a D_n starts a row."""
    s = np.asarray(s_positions, dtype=float)
    order = np.argsort(s, kind="stable")
    rows = np.empty(len(s), dtype=np.int64)
    current = 0
    for rank, k in enumerate(order):
        if rank > 0 and s[k] - s[order[rank - 1]] > 0.5 * nominal_diameter:
            current += 1
        rows[k] = current
    return rows


def layer_figures(slope, unit_positions, unit_node_sets, *, rows, nominal_diameter, unit_volume,
                  underlayer_level) -> dict:
    """Packing density coefficient, layer thickness and porosity of the units resting on the face.

    ``unit_positions`` (n, 3) world centroids; ``unit_node_sets`` world nodes of each unit;
    ``rows`` (n,) the row each unit was placed in.
    """
    coords = slope.to_slope(np.asarray(unit_positions, dtype=float))
    rows = np.asarray(rows)
    labels = np.unique(rows)
    if len(labels) < 2:
        return {"packing_density_coefficient": float("nan"), "layer_thickness_m": float("nan"),
                "porosity": float("nan"), "units_measured": 0, "measuring_area_m2": 0.0,
                "rows_measured": int(len(labels)),
                NOT_MEASURED: f"{len(labels)} row(s) of units on the face; the figures are "
                              "measured between the first and the last of at least two rows"}
    counts = np.array([(rows == r).sum() for r in labels], dtype=float)
    means = np.array([coords[rows == r, 0].mean() for r in labels])
    order = np.argsort(means)
    counts, means, labels = counts[order], means[order], labels[order]
    weighted = counts.sum() - 0.5 * (counts[0] + counts[-1])
    area = slope.slope_area(means[0], means[-1])
    inner = np.isin(rows, labels[1:-1]) if len(labels) > 2 else np.ones(len(rows), dtype=bool)
    tops = body_tops(slope, [unit_node_sets[k] for k in np.flatnonzero(inner)])
    thickness = float(tops.mean() - underlayer_level)
    packing = weighted * nominal_diameter ** 2 / area if area > 0 else float("nan")
    porosity = (1.0 - weighted * unit_volume / (area * thickness) if area > 0 and thickness > 0
                else float("nan"))
    figures = {"packing_density_coefficient": float(packing), "layer_thickness_m": thickness,
               "porosity": float(porosity), "units_measured": float(weighted),
               "measuring_area_m2": float(area), "rows_measured": int(len(labels))}
    if not area > 0:
        figures[NOT_MEASURED] = "the rows' mean positions span no area of the face"
    elif not thickness > 0:
        figures[NOT_MEASURED] = ("the units' tops are not above the underlayer's top: no layer "
                                 "thickness, so no porosity")
    return figures


def stone_layer_figures(slope, positions, node_sets, volumes, *, dn50: float, layers: int,
                        underlayer_level: float) -> dict:
    """A layer of graded armour stone measured as the Rock Manual measures one (5.2.2.10;
    k_t on p. 126): over the face between a D_n50 inside the lowest and the highest stone
    centroids, the stones per area N_a, the layer thickness t from the underlayer's top to the
    mean of the upper half of the stone tops (a survey staff's foot rests on the higher stones),
    k_t = t / (n D_n50), the bulk porosity 1 - (stone volume) / (area t) and the roughness of
    the tops (their standard deviation over D_n50). ``positions`` (n, 3) world centroids,
    ``node_sets`` each stone's world nodes, ``volumes`` (n,) m^3."""
    coords = slope.to_slope(np.asarray(positions, dtype=float).reshape(-1, 3))
    volumes = np.asarray(volumes, dtype=float)
    on_face = (coords[:, 0] > -dn50) & (coords[:, 0] < slope.length)
    s_low = coords[on_face, 0].min() + dn50 if on_face.any() else 0.0
    s_high = coords[on_face, 0].max() - dn50 if on_face.any() else 0.0
    inside = on_face & (coords[:, 0] >= s_low) & (coords[:, 0] <= s_high)
    area = slope.slope_area(s_low, s_high) if s_high > s_low else 0.0
    tops = body_tops(slope, [n for n, ok in zip(node_sets, inside) if ok])
    upper = tops[tops >= np.median(tops)] if len(tops) else tops
    thickness = float(upper.mean() - underlayer_level) if len(upper) else float("nan")
    count = int(inside.sum())
    per_area = count / area if area > 0 else float("nan")
    return {
        "stones_placed": int(len(coords)),
        "stones_rolled_off": int((~on_face).sum()),
        "stones_below_toe": int((coords[:, 0] <= -dn50).sum()),
        "stones_beyond_top": int((coords[:, 0] >= slope.length).sum()),
        "measuring_area_m2": float(area),
        "stones_measured": count,
        "stones_per_area": per_area,
        "layer_thickness_m": thickness,
        "porosity": (float(1.0 - volumes[inside].sum() / (area * thickness))
                     if area > 0 and thickness > 0 else float("nan")),
        "surface_roughness_over_dn50": (float(np.std(upper) / dn50) if len(upper)
                                        else float("nan")),
        "layer_thickness_coefficient": thickness / (layers * dn50),
        "stones_per_area_times_dn50_squared": per_area * dn50 ** 2,
    }
