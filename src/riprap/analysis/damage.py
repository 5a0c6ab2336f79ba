"""Damage of an armour layer as a hydraulic stability test counts it.

- Concrete units: a unit is *displaced* when its centroid moved more than ``threshold`` D_n
  (Van der Meer 1988 counts units moved out of the layer, about one D_n; the threshold is stated
  with every count); N_od is the number displaced per D_n of the layer's width:
  ``N_od = displaced / (width / D_n)``. A unit *rocks* when it turns back and forth in place: each
  excursion of its rotation angle (from the reference pose) above ``rocking_angle`` that comes back
  below half of it counts one event (hysteresis, so noise about the threshold is not counted).
- Rock slopes: the damage level S = A_e / D_n50^2 (Broderick 1983; Van der Meer 1988), A_e the
  eroded area of the cross-section, from profiles of the armour's surface before and after: the
  area between them where the surface went down. A profile is the upper envelope of the armour's
  surface points in bins along the section, averaged over strips across the flume (as a profiler
  on a carriage measures lines across the width and averages them). From a run's bodies
  (``profile_from_surfaces``): the highest surface triangle above each point of an even plan grid
  (``riprap.analysis.surface_heights``), averaged across the width.
"""
from __future__ import annotations

import math

import numpy as np

from riprap.analysis.surface_heights import highest_surface
from riprap.errors import CaseFileError

__all__ = ["displaced_units", "damage_number_nod", "rocking_events", "surface_profile",
           "profile_from_surfaces", "eroded_area", "damage_level_s"]


def displaced_units(displacement_over_dn, threshold: float = 1.0) -> np.ndarray:
    """Indices of the units whose displacement exceeds ``threshold`` D_n."""
    if not threshold > 0:
        raise CaseFileError(f"damage: the displacement threshold must be > 0 D_n, got {threshold!r}")
    return np.flatnonzero(np.asarray(displacement_over_dn, dtype=float) > threshold)


def damage_number_nod(displaced: int, width: float, nominal_diameter: float) -> float:
    """N_od: displaced units per D_n of the layer's ``width`` (m)."""
    if not (width > 0 and nominal_diameter > 0):
        raise CaseFileError(f"damage: width ({width!r} m) and D_n ({nominal_diameter!r} m) must be > 0")
    return float(displaced) / (width / nominal_diameter)


def rocking_events(angles, rocking_angle: float = 2.0) -> np.ndarray:
    """Rocking events per unit from ``angles`` (frames, units): each unit's rotation (degrees)
    from its reference pose over time. An event: the angle rises above ``rocking_angle`` and falls
    back below half of it."""
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    if not rocking_angle > 0:
        raise CaseFileError(f"damage: rocking_angle must be > 0 degrees, got {rocking_angle!r}")
    events = np.zeros(angles.shape[1], dtype=np.int64)
    for unit in range(angles.shape[1]):
        up = False
        for angle in angles[:, unit]:
            if not up and angle > rocking_angle:
                up = True
            elif up and angle < 0.5 * rocking_angle:
                up = False
                events[unit] += 1
    return events


def surface_profile(points, x_edges, y_edges) -> np.ndarray:
    """The armour surface's height in each x bin (``x_edges``, m along the section): the highest
    point (``points`` (n, 3): x, y, z) of each bin in each y strip (``y_edges``), averaged over
    the strips that have one. NaN where no strip has a point."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    x_edges, y_edges = np.asarray(x_edges, dtype=float), np.asarray(y_edges, dtype=float)
    nx, ny = x_edges.size - 1, y_edges.size - 1
    if nx < 1 or ny < 1:
        raise CaseFileError("damage: a profile needs at least one x bin and one y strip")
    i = np.searchsorted(x_edges, points[:, 0], side="right") - 1
    j = np.searchsorted(y_edges, points[:, 1], side="right") - 1
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    top = np.full((nx, ny), -np.inf)
    np.maximum.at(top, (i[inside], j[inside]), points[inside, 2])
    top[np.isinf(top)] = np.nan
    counted = np.isfinite(top).sum(axis=1)
    profile = np.full(nx, np.nan)
    has = counted > 0
    profile[has] = np.nansum(top[has], axis=1) / counted[has]
    return profile


def profile_from_surfaces(triangles, xs, ys, floor=None) -> np.ndarray:
    """The armour surface's height at each x of ``xs`` (m along the section, evenly spaced): the
    highest of the ``triangles`` ((T, 3, 3) corners in the world, m) above each point of the plan
    grid ``xs`` x ``ys`` (``ys`` evenly spaced across the flume), averaged across. ``floor`` (one
    height per x, optional): what a point no triangle covers reads (the slope's face under the
    layer); without it such points are left out of the mean, and an x no triangle covers is NaN."""
    xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    if xs.size < 2 or ys.size < 1:
        raise CaseFileError("damage: a profile needs at least two x and one y")
    heights = np.full((xs.size, ys.size), -np.inf)
    if floor is not None:
        heights[:] = np.asarray(floor, dtype=float).reshape(-1, 1)
    highest_surface(np.ascontiguousarray(triangles, dtype=float).reshape(-1, 3, 3), xs, ys, heights)
    heights[np.isinf(heights)] = np.nan
    covered = np.isfinite(heights).sum(axis=1)
    profile = np.full(xs.size, np.nan)
    has = covered > 0
    profile[has] = np.nansum(heights[has], axis=1) / covered[has]
    return profile


def eroded_area(before, after, spacing: float) -> float:
    """A_e (m^2): the area where the profile went down, between two profiles on the same bins of
    width ``spacing`` (m; along the section). Bins without a value in either are skipped."""
    before, after = np.asarray(before, dtype=float), np.asarray(after, dtype=float)
    if before.shape != after.shape:
        raise CaseFileError(f"damage: profiles of {before.size} and {after.size} bins")
    drop = before - after
    valid = np.isfinite(drop)
    return float(np.sum(np.maximum(drop[valid], 0.0)) * spacing)


def damage_level_s(eroded: float, nominal_diameter: float) -> float:
    """S = A_e / D_n50^2."""
    if not (nominal_diameter > 0 and math.isfinite(eroded) and eroded >= 0):
        raise CaseFileError(f"damage: need A_e >= 0 and D_n50 > 0, got {eroded!r}, {nominal_diameter!r}")
    return eroded / nominal_diameter ** 2
