"""Orientations of unit axes as engineers plot them: trend and plunge of the axis on the lower
hemisphere, and its point on an equal-area (Schmidt) net.

Conventions (structural geology, as in mplstereonet and the seed paper's stereonets of Core-Loc
nose axes): world x is east, y is north, z is up. An axis is a line, so a vector and its opposite
are the same axis; the end pointing down is used (lower hemisphere). Trend is the azimuth of that
end, clockwise from north, 0-360 degrees; plunge its angle below the horizontal, 0-90 degrees. On a
net of unit radius the axis plots at distance r = sqrt(2) sin(theta / 2) from the centre, theta =
90 deg - plunge being its angle from the vertical (Lambert azimuthal equal-area projection: equal
areas of the hemisphere take equal areas of the net), in the direction of its trend.
"""
from __future__ import annotations

import numpy as np


def lower_hemisphere(axes) -> np.ndarray:
    """Unit axes (n, 3) turned to point downwards (z <= 0); horizontal ones keep their sign."""
    axes = np.atleast_2d(np.asarray(axes, dtype=float))
    lengths = np.linalg.norm(axes, axis=1)
    if np.any(lengths == 0) or not np.all(np.isfinite(lengths)):
        raise ValueError("an axis has zero or non-finite length")
    unit = axes / lengths[:, None]
    return np.where(unit[:, 2:3] > 0, -unit, unit)


def trend_plunge(axes) -> tuple[np.ndarray, np.ndarray]:
    """(trend, plunge) in degrees of each axis (n, 3) on the lower hemisphere."""
    down = lower_hemisphere(axes)
    trend = np.degrees(np.arctan2(down[:, 0], down[:, 1])) % 360.0
    plunge = np.degrees(np.arcsin(np.clip(-down[:, 2], -1.0, 1.0)))
    return trend, plunge


def equal_area_points(axes) -> np.ndarray:
    """(n, 2) points (east, north) of the axes on an equal-area net of unit radius."""
    trend, plunge = trend_plunge(axes)
    radius = np.sqrt(2.0) * np.sin(np.radians(90.0 - plunge) / 2.0)
    t = np.radians(trend)
    return np.column_stack([radius * np.sin(t), radius * np.cos(t)])
