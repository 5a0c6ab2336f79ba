"""The shape of a stone as armourstone is measured: its length-to-thickness ratio and blockiness.

Two measures of quarried stone in use (CIRIA, CUR, CETMEF 2007, *The Rock Manual*, C683, section
3.4; EN 13383-1, the armourstone standard, limits the share of stones with LT > 3):

- **length-to-thickness ratio** LT = l / d: l the stone's greatest length (the largest distance
  between two of its points, what a caliper opened across the stone reads at its widest), d its
  thickness (the least distance between two parallel planes that enclose it, the narrowest slot
  it passes through);
- **blockiness** BLc = V / (X Y Z): the stone's volume over that of a box enclosing it. Here the
  box is the one whose short side is the thickness d (along the direction of the least width)
  and whose other two sides are the smallest rectangle enclosing the stone seen along that
  direction. A box has BLc = 1, a sphere pi/6 = 0.524, a regular tetrahedron 1/3.

Both are computed on the stone's convex hull, exactly for a convex polyhedron: the greatest
length is attained between two hull vertices; the least width of a convex polyhedron is attained
across a hull face (a face and the farthest vertex) or across two hull edges (the plane pair
normal to both), so every face normal and every cross product of two edge directions is tried;
the smallest enclosing rectangle of a convex polygon has one side along a polygon edge. (A hull
of more than 400 edges, a finely sampled smooth surface, is measured across its faces only.)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from riprap.errors import CaseFileError

__all__ = ["StoneShape", "stone_shape", "shape_statistics"]

#: Hull edges beyond which the edge pairs are not tried (their count grows as its square): a
#: hull of so many edges is a smooth surface sampled finely, whose least width the face normals
#: give within the facets' own error. A quarried stone's hull has a few dozen edges.
_MAX_EDGE_PAIRS_EDGES = 400


@dataclass(frozen=True)
class StoneShape:
    """A stone's length l, thickness d and box (m), and its volume (m^3)."""

    length: float
    thickness: float
    box: tuple          # (X, Y, Z) of the enclosing box, Z = thickness
    volume: float

    @property
    def length_to_thickness(self) -> float:
        """LT = l / d."""
        return self.length / self.thickness

    @property
    def blockiness(self) -> float:
        """BLc = V / (X Y Z)."""
        return self.volume / float(np.prod(self.box))

    @property
    def nominal_diameter(self) -> float:
        """D_n = V^(1/3) (m)."""
        return self.volume ** (1.0 / 3.0)


def _hull(points: np.ndarray, name: str) -> ConvexHull:
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 4:
        raise CaseFileError(f"stone shape of {name}: needs (n, 3) points, n >= 4, got "
                            f"{points.shape}")
    try:
        return ConvexHull(points)
    except Exception as error:  # noqa: BLE001 - qhull's errors, said as the stone's
        raise CaseFileError(f"stone shape of {name}: its points span no volume ({error})") from None


def _widths(vertices: np.ndarray, directions: np.ndarray) -> np.ndarray:
    projected = vertices @ directions.T
    return projected.max(axis=0) - projected.min(axis=0)


def _least_width_direction(hull: ConvexHull) -> tuple[float, np.ndarray]:
    vertices = hull.points[hull.vertices]
    candidates = [hull.equations[:, :3]]
    edges = set()
    for simplex in hull.simplices:
        for a, b in ((0, 1), (1, 2), (0, 2)):
            i, j = sorted((int(simplex[a]), int(simplex[b])))
            edges.add((i, j))
    if len(edges) > _MAX_EDGE_PAIRS_EDGES:
        # a finely faceted (smooth) hull: the face normals alone come within its facets' error
        widths = _widths(vertices, candidates[0])
        best = int(np.argmin(widths))
        return float(widths[best]), candidates[0][best]
    points = hull.points
    directions = np.array([points[j] - points[i] for i, j in edges])
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    cross = np.cross(directions[:, None, :], directions[None, :, :]).reshape(-1, 3)
    norms = np.linalg.norm(cross, axis=1)
    candidates.append(cross[norms > 1e-9] / norms[norms > 1e-9, None])
    candidates = np.concatenate(candidates)
    widths = _widths(vertices, candidates)
    best = int(np.argmin(widths))
    return float(widths[best]), candidates[best]


def _smallest_rectangle(points_2d: np.ndarray) -> tuple[float, float]:
    hull = ConvexHull(points_2d)
    polygon = points_2d[hull.vertices]
    edges = np.roll(polygon, -1, axis=0) - polygon
    angles = np.arctan2(edges[:, 1], edges[:, 0])
    best = None
    for angle in angles:
        c, s = np.cos(angle), np.sin(angle)
        turned = polygon @ np.array([[c, -s], [s, c]])
        sides = turned.max(axis=0) - turned.min(axis=0)
        if best is None or sides[0] * sides[1] < best[0] * best[1]:
            best = (float(sides.max()), float(sides.min()))
    return best


def stone_shape(points, *, volume: float | None = None, name: str = "stone") -> StoneShape:
    """The length, thickness, box and volume of a stone given by its ``points`` (a mesh's nodes,
    (n, 3), m); ``volume``: the stone's own (a mesh's), else its convex hull's."""
    hull = _hull(points, name)
    vertices = hull.points[hull.vertices]
    gaps = vertices[:, None, :] - vertices[None, :, :]
    length = float(np.sqrt((gaps ** 2).sum(axis=2)).max())
    thickness, normal = _least_width_direction(hull)
    # the plane across the thickness: two axes perpendicular to it
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    first = np.cross(normal, helper)
    first /= np.linalg.norm(first)
    second = np.cross(normal, first)
    x, y = _smallest_rectangle(vertices @ np.stack([first, second], axis=1))
    return StoneShape(length=length, thickness=thickness, box=(x, y, thickness),
                      volume=float(hull.volume if volume is None else volume))


def shape_statistics(shapes) -> dict:
    """The measures of a set of stones as a quarry's shape test reports them: the mean and
    spread of LT and BLc, and the share of stones with LT > 3 (by count; EN 13383-1 limits it)."""
    shapes = list(shapes)
    if not shapes:
        raise CaseFileError("shape statistics: no stones")
    lt = np.array([s.length_to_thickness for s in shapes])
    blc = np.array([s.blockiness for s in shapes])
    return {"stones": len(shapes),
            "length_to_thickness_mean": float(lt.mean()),
            "length_to_thickness_min": float(lt.min()),
            "length_to_thickness_max": float(lt.max()),
            "share_length_to_thickness_over_3": float((lt > 3.0).mean()),
            "blockiness_mean": float(blc.mean()),
            "blockiness_min": float(blc.min()),
            "blockiness_max": float(blc.max())}
