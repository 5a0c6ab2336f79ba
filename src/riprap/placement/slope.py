"""The breakwater slope that armour layers are built on: geometry, frame and walls.

Frame: x is horizontal and points up the slope (from the toe towards the crest), y runs along the
breakwater axis across the flume width, z is up. The toe line is x = ``toe_x``, z = ``toe_level``;
the slope face rises at angle alpha (cot alpha = ``cotangent``, the "1 : cot alpha" of design
drawings) for a length ``length`` measured along the face, and the flume has side walls at y = 0 and
y = ``width``. In front of the toe the bed is horizontal.

Slope coordinates (s, y, h): s along the face from the toe, h along the outward face normal, so a
point is toe + s t + y e_y + h n with t = (cos a, 0, sin a) and n = (-sin a, 0, cos a).

Walls are half-spaces: the bed (z < toe_level), the slope body (below the face plane) and the two
side walls; on a periodic strip (``periodic``) there are no side walls: y = 0 and y = ``width``
are one periodic boundary, the section a strip of an infinitely wide flume. The union of the bed and the slope body is exactly the concave toe corner. The crest is
not a surface: the face plane continues above ``length`` (units and rocks are placed below it), a
convex crest edge would need a bounded wall.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of
from riprap.solid import walls
from riprap.solid.walls import Wall


@dataclass(frozen=True)
class Slope:
    """A planar breakwater slope in a flume of given width.

    Parameters
    ----------
    cotangent : float
        cot(alpha) of the face (1.5 for a 1:1.5 slope; 1.33 is usual for single-layer units).
    width : float
        Distance between the side walls (m).
    length : float
        Length of the face from toe to crest, measured along the face (m).
    toe_x, toe_level : float
        Horizontal position and level of the toe line (m).
    toe_stop_distance : float
        If > 0, a vertical wall this far in front of the toe line (m) stands for the toe structure
        (toe berm) that holds the lowest row of a real armour layer; 0: the bed is open.
    periodic : bool
        The sides y = 0 and y = ``width`` are a periodic boundary, not walls.
    """

    cotangent: float
    width: float
    length: float
    toe_x: float = default_of("slope", "toe_x")
    toe_level: float = default_of("slope", "toe_level")
    toe_stop_distance: float = default_of("slope", "toe_stop_distance")
    periodic: bool = False

    def __post_init__(self):
        for name in ("cotangent", "width", "length"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise CaseFileError(f"slope: {name} = {value!r} must be a positive number")
        if not (np.isfinite(self.toe_stop_distance) and self.toe_stop_distance >= 0):
            raise CaseFileError(f"slope: toe_stop_distance = {self.toe_stop_distance!r} must be >= 0 m")
        if self.cotangent < 0.5:
            raise CaseFileError(f"slope: cotangent = {self.cotangent!r} is steeper than 1:0.5 "
                                "(63 degrees); no armour layer stands on that")

    @property
    def angle(self) -> float:
        """Slope angle alpha (rad)."""
        return float(np.arctan2(1.0, self.cotangent))

    @property
    def angle_deg(self) -> float:
        return float(np.degrees(self.angle))

    @property
    def tangent(self) -> np.ndarray:
        """Unit vector up the face."""
        a = self.angle
        return np.array([np.cos(a), 0.0, np.sin(a)])

    @property
    def normal(self) -> np.ndarray:
        """Unit outward normal of the face (into the free space)."""
        a = self.angle
        return np.array([-np.sin(a), 0.0, np.cos(a)])

    @property
    def toe(self) -> np.ndarray:
        return np.array([self.toe_x, 0.0, self.toe_level])

    @property
    def crest_level(self) -> float:
        return self.toe_level + self.length * np.sin(self.angle)

    @property
    def crest_x(self) -> float:
        """x of the face's top edge (m): where the crest begins."""
        return self.toe_x + self.length * np.cos(self.angle)

    def to_world(self, s, y, h) -> np.ndarray:
        """World points (n, 3) of slope coordinates (arrays or scalars, m)."""
        s = np.asarray(s, dtype=float)[..., None]
        y = np.asarray(y, dtype=float)[..., None]
        h = np.asarray(h, dtype=float)[..., None]
        return self.toe + s * self.tangent + y * np.array([0.0, 1.0, 0.0]) + h * self.normal

    def to_slope(self, points) -> np.ndarray:
        """Slope coordinates (n, 3) = (s, y, h) of world points (n, 3)."""
        d = np.asarray(points, dtype=float) - self.toe
        return np.stack([d @ self.tangent, d[..., 1], d @ self.normal], axis=-1)

    @property
    def side_wall_indices(self) -> tuple[int, ...]:
        """Which of ``walls()`` are the side walls (none on a periodic strip)."""
        return () if self.periodic else (2, 3)

    def wrapped(self, y):
        """``y`` (m) taken into the strip [0, width) on a periodic strip; as it is otherwise."""
        y = np.asarray(y, dtype=float)
        return np.mod(y, self.width) if self.periodic else y

    def walls(self, *, face_material: str, side_material: str) -> list[Wall]:
        """Bed, slope face, the two side walls (not on a periodic strip) and the toe stop if
        any, as half-space walls (in that order: walls 0 and 1 are the ground the underlayer
        rests on)."""
        planes = (walls.plane(point=self.toe, normal=(0.0, 0.0, 1.0), material=face_material)
                  + walls.plane(point=self.toe, normal=self.normal, material=face_material))
        if not self.periodic:
            planes += (walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0),
                                   material=side_material)
                       + walls.plane(point=(0.0, self.width, 0.0), normal=(0.0, -1.0, 0.0),
                                     material=side_material))
        if self.toe_stop_distance > 0:
            planes += walls.plane(point=(self.toe_x - self.toe_stop_distance, 0.0, 0.0),
                                  normal=(1.0, 0.0, 0.0), material=face_material)
        return planes

    def slope_area(self, s_low: float, s_high: float) -> float:
        """Area of the face between two slope positions (m^2)."""
        return float(max(s_high - s_low, 0.0) * self.width)
