"""Set units down the way a crane does: lowered straight down until they touch, then released.

A unit released from above falls, tumbles and lands where chance puts it; on site each unit is
lowered on its sling onto its place in the grid and let go when it touches the underlayer or the
units placed before it. :class:`VerticalLowering` holds the surfaces already in place (underlayer
rocks, units set down, the slope face and the bed) and finds how far a new unit can go down before
it touches one of them (:mod:`riprap.placement.kernels.vertical_gap`: vertical rays from vertices
and edge midpoints of each surface onto the other's triangles, and the exact distance to the two
half-space walls).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.placement.kernels.vertical_gap import vertical_gap


@dataclass(frozen=True)
class Surface:
    """A closed triangulated surface in world coordinates, ready for vertical ray casting."""

    triangles: np.ndarray     # (k, 3, 3)
    points: np.ndarray        # (m, 3) vertices and edge midpoints
    low: np.ndarray           # (3,) bounding box
    high: np.ndarray

    @classmethod
    def from_nodes(cls, nodes: np.ndarray, faces: np.ndarray) -> "Surface":
        nodes = np.asarray(nodes, dtype=float)
        faces = np.asarray(faces, dtype=np.int64)
        edges = np.unique(np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
        # Points along the edges as well as vertices: two edges crossing are the contact a
        # vertex-only test misses; samples a quarter of an edge apart bound that miss by an
        # eighth of the edge's length x its slope.
        along = [f * nodes[edges[:, 0]] + (1.0 - f) * nodes[edges[:, 1]] for f in (0.25, 0.5, 0.75)]
        points = np.vstack([nodes[np.unique(faces)]] + along)
        return cls(triangles=np.ascontiguousarray(nodes[faces]), points=points,
                   low=nodes.min(axis=0), high=nodes.max(axis=0))

    def moved(self, dz: float) -> "Surface":
        shift = np.array([0.0, 0.0, dz])
        return Surface(triangles=self.triangles + shift, points=self.points + shift,
                       low=self.low + shift, high=self.high + shift)


class VerticalLowering:
    """Surfaces in place on a slope; new ones are lowered onto them along -z.

    ``gap``: the clearance (m) a lowered surface keeps from what it lands on, so that it is
    released just touching (within the contact's potential) rather than already overlapping.
    ``period`` (m, 0: none): a periodic strip across y; every surface in place is also held at
    its images one period to either side, so that a unit near one side lands on what lies at the
    other.
    """

    def __init__(self, slope, *, gap: float, period: float = 0.0):
        self.slope = slope
        self.gap = float(gap)
        self.period = float(period)
        self._surfaces: list[Surface] = []
        self._low = np.zeros((0, 3))
        self._high = np.zeros((0, 3))

    def add(self, *surfaces: Surface) -> None:
        if self.period > 0.0:
            surfaces = tuple(image for surface in surfaces
                             for image in (surface, _shifted_y(surface, -self.period),
                                           _shifted_y(surface, self.period)))
        self._surfaces.extend(surfaces)
        self._low = np.vstack([self._low] + [s.low[None] for s in surfaces])
        self._high = np.vstack([self._high] + [s.high[None] for s in surfaces])

    def _neighbours(self, surface: Surface) -> list[Surface]:
        """Surfaces whose plan boxes overlap the given one's."""
        if not self._surfaces:
            return []
        overlap = ((self._low[:, 0] <= surface.high[0]) & (self._high[:, 0] >= surface.low[0])
                   & (self._low[:, 1] <= surface.high[1]) & (self._high[:, 1] >= surface.low[1]))
        return [self._surfaces[k] for k in np.flatnonzero(overlap)]

    def _wall_clearance(self, points: np.ndarray) -> float:
        """How far ``points`` can go down before one of them meets the face or the bed (the two
        half-spaces under the layer)."""
        h = self.slope.to_slope(points)[:, 2]
        to_face = h.min() / np.cos(self.slope.angle)
        to_bed = (points[:, 2] - self.slope.toe_level).min()
        return float(min(to_face, to_bed))

    def lower(self, surface: Surface) -> float:
        """Vertical displacement (m, usually negative) that sets ``surface`` down just touching
        (``gap`` clear of) the surfaces in place, the face or the bed: it is first raised clear of
        everything below it, then lowered."""
        neighbours = self._neighbours(surface)
        top = max((s.high[2] for s in neighbours), default=-np.inf)
        raise_by = max(0.0, top + self.gap - surface.low[2])
        raise_by = max(raise_by, self.gap - self._wall_clearance(surface.points))
        raised = surface.moved(raise_by) if raise_by > 0 else surface
        drop = self._wall_clearance(raised.points)
        if neighbours:
            triangles = np.concatenate([s.triangles for s in neighbours])
            points = np.concatenate([s.points for s in neighbours])
            drop = min(drop, vertical_gap(raised.points, triangles, False),
                       vertical_gap(points, raised.triangles, True))
        return raise_by - (drop - self.gap)


def _shifted_y(surface: Surface, dy: float) -> Surface:
    shift = np.array([0.0, dy, 0.0])
    return Surface(triangles=surface.triangles + shift, points=surface.points + shift,
                   low=surface.low + shift, high=surface.high + shift)


__all__ = ["Surface", "VerticalLowering"]
