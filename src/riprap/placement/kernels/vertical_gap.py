"""How far one surface can move straight down before it meets another (a crane lowering a unit).

Both surfaces are triangle soups in world coordinates. The first contact of two polyhedra moving
apart along z happens at a vertex of one on a face of the other or at two crossing edges; the
kernel casts vertical rays from sample points (the caller passes vertices and edge midpoints, which
bounds the edge-edge miss by the edges' sag) of the moving surface downwards onto the fixed one,
and from the fixed surface's points upwards onto the moving one.
"""
import numpy as np

from riprap._jit import parallel_kernel, prange


@parallel_kernel
def vertical_gap(points, triangles, upward):
    """Smallest vertical distance from ``points`` (m, 3) to ``triangles`` (k, 3, 3) along -z
    (``upward`` False: triangles below the points) or +z (``upward`` True); ``inf`` where no
    vertical ray from a point meets a triangle. Triangles seen edge-on (no area in plan) are
    skipped: a ray meets their neighbours."""
    m = points.shape[0]
    k = triangles.shape[0]
    lo = np.empty((k, 2))
    hi = np.empty((k, 2))
    for t in range(k):
        for a in range(2):
            lo[t, a] = min(triangles[t, 0, a], triangles[t, 1, a], triangles[t, 2, a])
            hi[t, a] = max(triangles[t, 0, a], triangles[t, 1, a], triangles[t, 2, a])
    best = np.full(m, np.inf)
    for p in prange(m):
        px = points[p, 0]
        py = points[p, 1]
        pz = points[p, 2]
        nearest = np.inf
        for t in range(k):
            if px < lo[t, 0] or px > hi[t, 0] or py < lo[t, 1] or py > hi[t, 1]:
                continue
            ax = triangles[t, 0, 0]
            ay = triangles[t, 0, 1]
            bx = triangles[t, 1, 0] - ax
            by = triangles[t, 1, 1] - ay
            cx = triangles[t, 2, 0] - ax
            cy = triangles[t, 2, 1] - ay
            det = bx * cy - by * cx
            if abs(det) < 1e-300:
                continue
            dx = px - ax
            dy = py - ay
            u = (dx * cy - dy * cx) / det
            v = (bx * dy - by * dx) / det
            # Closed triangle: a ray through a shared edge or vertex meets one of its owners.
            if u < -1e-12 or v < -1e-12 or u + v > 1.0 + 1e-12:
                continue
            z = (triangles[t, 0, 2] + u * (triangles[t, 1, 2] - triangles[t, 0, 2])
                 + v * (triangles[t, 2, 2] - triangles[t, 0, 2]))
            gap = z - pz if upward else pz - z
            if gap < nearest:
                nearest = gap
        best[p] = nearest
    return best.min() if m > 0 else np.inf
