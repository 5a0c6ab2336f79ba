"""The height of the armour's upper surface above points of the plan: what a profiler's feeler or
laser reads when it is lowered onto the layer (``riprap.analysis.damage.profile_from_surfaces``).

Why not the mesh nodes' highest points per bin (``damage.surface_profile``): a unit's corners lie
on its neighbours' edges, so a bin whose unit has gone still holds the corners of the units beside
it, and the profile does not drop. Lowered onto the triangles, the reading drops to whatever is
under the missing unit.
"""
import numpy as np

from riprap._jit import kernel


@kernel
def highest_surface(triangles, xs, ys, out):
    """``out[i, j]`` = max(out[i, j], the highest z of any triangle (``triangles`` (T, 3, 3): the
    three corners' x, y, z) above the point (xs[i], ys[j])); ``xs`` and ``ys`` ascending, evenly
    spaced. Points no triangle covers keep their value (start from -inf)."""
    nx, ny = xs.shape[0], ys.shape[0]
    x0, y0 = xs[0], ys[0]
    dx = xs[1] - xs[0] if nx > 1 else 1.0
    dy = ys[1] - ys[0] if ny > 1 else 1.0
    for t in range(triangles.shape[0]):
        ax, ay, az = triangles[t, 0, 0], triangles[t, 0, 1], triangles[t, 0, 2]
        bx, by, bz = triangles[t, 1, 0], triangles[t, 1, 1], triangles[t, 1, 2]
        cx, cy, cz = triangles[t, 2, 0], triangles[t, 2, 1], triangles[t, 2, 2]
        area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
        if area == 0.0:
            continue            # seen edge-on from above: its neighbours cover it
        low_i = max(0, int(np.ceil((min(ax, bx, cx) - x0) / dx)))
        high_i = min(nx - 1, int(np.floor((max(ax, bx, cx) - x0) / dx)))
        low_j = max(0, int(np.ceil((min(ay, by, cy) - y0) / dy)))
        high_j = min(ny - 1, int(np.floor((max(ay, by, cy) - y0) / dy)))
        for i in range(low_i, high_i + 1):
            px = xs[i]
            for j in range(low_j, high_j + 1):
                py = ys[j]
                # barycentric weights of the plan point in the triangle's plan
                wb = ((px - ax) * (cy - ay) - (cx - ax) * (py - ay)) / area
                wc = ((bx - ax) * (py - ay) - (px - ax) * (by - ay)) / area
                wa = 1.0 - wb - wc
                if wa < -1e-12 or wb < -1e-12 or wc < -1e-12:
                    continue
                z = wa * az + wb * bz + wc * cz
                if z > out[i, j]:
                    out[i, j] = z


__all__ = ["highest_surface"]
