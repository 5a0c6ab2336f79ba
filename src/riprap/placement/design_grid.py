"""Placement grids generated from a design: rows along the face, units per row, spacing from a target
packing density coefficient.

Units per area is phi / D_n^2 (CEM VI-5, see ``layer_metrics``). With ``units_per_row`` = (n1, n2)
the rows alternate between n1 and n2 units, the longer rows spanning the flume width with a
horizontal spacing dx = width / max(n1, n2) and the shorter ones centred between them (a staggered
pattern, as cranes place single-layer units); the spacing up the face is then
dy = D_n^2 (n1 + n2) / (2 phi width), so that the grid itself has the target packing density
(a pair of rows holds n1 + n2 units on 2 dy x width of face; with dx dy instead, the short rows
would leave a 12-row flume's grid 1/24 and a 4-row one's 1/8 below its target). The seed paper's
Core-Loc layer is 21 rows alternating 12 and 11 units.

On a periodic strip (``slope.periodic``) every row holds the same number of units, dx = width / n
apart, and every other row is shifted by dx / 2 across the strip's side (taken back into the strip):
the staggered pattern of a wide flume, continued across the boundary.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of


@dataclass(frozen=True)
class DesignGrid:
    """Centroids of a generated grid: world positions (n, 3), row index and slope coordinates."""

    positions: np.ndarray
    rows: np.ndarray
    slope_coordinates: np.ndarray
    horizontal_spacing: float
    upslope_spacing: float


def design_grid(slope, *, nominal_diameter: float, rows: int, units_per_row=(12, 11),
                packing_density_coefficient: float, first_row_s: float,
                centroid_height: float,
                drop_height: float = default_of("placement", "drop_height")) -> DesignGrid:
    """Staggered rows of unit centroids: the design centroids lie ``centroid_height`` (m) above the
    face along its normal, and the units start ``drop_height`` (m) straight above them."""
    counts = tuple(int(n) for n in np.atleast_1d(units_per_row))
    if rows < 1:
        raise CaseFileError(f"design grid: rows = {rows} must be >= 1")
    if not counts or min(counts) < 1 or len(counts) > 2:
        raise CaseFileError(f"design grid: units_per_row = {units_per_row!r} must be one or two "
                            "positive integers (alternating rows)")
    if not packing_density_coefficient > 0:
        raise CaseFileError(f"design grid: packing_density_coefficient = "
                            f"{packing_density_coefficient!r} must be > 0")
    widest = max(counts)
    if slope.periodic and len(set(counts)) > 1:
        raise CaseFileError(f"design grid: units_per_row = {units_per_row!r}: on a periodic strip "
                            "every row holds the same number of units (the stagger is a shift "
                            "of half a spacing across the strip's side); leave "
                            "units_per_alternate_row out or equal")
    dx = slope.width / widest
    mean_count = 0.5 * (counts[0] + counts[-1])
    dy = nominal_diameter ** 2 * mean_count / (packing_density_coefficient * slope.width)
    s_list, y_list, row_list = [], [], []
    for r in range(rows):
        n = counts[r % len(counts)]
        y0 = 0.5 * (slope.width - (n - 1) * dx)
        if slope.periodic:
            y0 = 0.5 * dx * (1 + r % 2)
        for i in range(n):
            s_list.append(first_row_s + r * dy)
            y_list.append(y0 + i * dx)
            row_list.append(r)
    s = np.array(s_list)
    if s.max() > slope.length:
        raise CaseFileError(
            f"design grid: {rows} rows {dy:.3f} m apart from s = {first_row_s:g} m reach "
            f"s = {s.max():.3f} m along the face, beyond its length {slope.length:g} m; "
            "use fewer rows, a longer slope or a lower first row")
    y = slope.wrapped(np.array(y_list))
    # Straight above (not along the face normal from) the design centroids: a unit let go or
    # lowered from there comes down on its own place rather than one row further down the face.
    design = slope.to_world(s, y, np.full(len(s), float(centroid_height)))
    above = design + np.array([0.0, 0.0, float(drop_height)])
    return DesignGrid(positions=above, rows=np.array(row_list, dtype=np.int64),
                      slope_coordinates=slope.to_slope(design), horizontal_spacing=dx,
                      upslope_spacing=dy)
