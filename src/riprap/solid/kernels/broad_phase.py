"""Candidate pairs: bodies whose world bounding boxes overlap, and bodies near walls.

Sweep and prune along the axis with the largest spread of body centres. In a heap of bodies of
similar size each body overlaps a bounded number of others along that axis, so the cost grows about
linearly with the number of bodies (plus an N log N sort that is negligible at 1e4 bodies).

A periodic axis (``periodic.py``) is never swept: the sorted order along it breaks at the strip's
ends, where a pair across the boundary lies at the two ends of the list. The sweep takes the
widest of the other axes, and the boxes and spheres are compared with body j in its image
nearest body i.
"""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels.geometry_ops import rotation_matrix
from riprap.solid.kernels.periodic import image_coordinate


@kernel
def world_boxes(positions, quaternions, shape_index, local_box_min, local_box_max, margin):
    """Axis-aligned world boxes of every body, (n, 3) lower and upper corners, grown by ``margin``."""
    n = positions.shape[0]
    lo = np.empty((n, 3))
    hi = np.empty((n, 3))
    for b in range(n):
        r = rotation_matrix(quaternions[b])
        s = shape_index[b]
        for i in range(3):
            centre = positions[b, i]
            half = 0.0
            for j in range(3):
                c = 0.5 * (local_box_min[s, j] + local_box_max[s, j])
                h = 0.5 * (local_box_max[s, j] - local_box_min[s, j])
                centre += r[i, j] * c
                half += abs(r[i, j]) * h
            lo[b, i] = centre - half - margin
            hi[b, i] = centre + half + margin
    return lo, hi


@kernel
def overlapping_pairs(lo, hi, fixed, positions, radii, period):
    """Pairs (i < j) whose boxes overlap and whose bounding spheres (centre ``positions``, radius
    ``radii`` including the margin) overlap, skipping pairs of two fixed bodies. (k, 2) int64.
    ``period`` (3,): per axis the period (m) or 0; along a periodic axis body j's box and centre
    are taken in its image nearest body i.

    The sphere test rejects about two thirds of the box overlaps of elongated rocks in a heap."""
    n = lo.shape[0]
    if n < 2:
        return np.zeros((0, 2), dtype=np.int64)
    axis = -1
    widest = -1.0
    for a in range(3):
        if period[a] > 0.0:
            continue
        spread = np.var(lo[:, a] + hi[:, a])
        # the first of equal spreads, as argmax took it
        if spread > widest:
            widest = spread
            axis = a
    swept = axis >= 0
    if not swept:
        axis = 0        # every axis periodic: no sweep, every pair is tested
    order = np.argsort(lo[:, axis])
    capacity = 8 * n
    pairs = np.empty((capacity, 2), dtype=np.int64)
    count = 0
    for oi in range(n):
        i = order[oi]
        for oj in range(oi + 1, n):
            j = order[oj]
            if swept and lo[j, axis] > hi[i, axis]:
                break
            if fixed[i] and fixed[j]:
                continue
            overlap = True
            for a in range(3):
                shift = 0.0
                if period[a] > 0.0:
                    shift = (image_coordinate(positions[i, a], positions[j, a], period[a])
                             - positions[j, a])
                if lo[i, a] > hi[j, a] + shift or lo[j, a] + shift > hi[i, a]:
                    overlap = False
                    break
            if not overlap:
                continue
            reach = radii[i] + radii[j]
            d2 = 0.0
            for a in range(3):
                d = positions[i, a] - image_coordinate(positions[i, a], positions[j, a], period[a])
                d2 += d * d
            if d2 > reach * reach:
                continue
            if count == capacity:
                grown = np.empty((2 * capacity, 2), dtype=np.int64)
                grown[:capacity] = pairs
                pairs = grown
                capacity *= 2
            pairs[count, 0] = min(i, j)
            pairs[count, 1] = max(i, j)
            count += 1
    return pairs[:count].copy()


@kernel
def in_key_order(pairs):
    """Body pairs (i < j) sorted by (i, j). Why: each body's contact forces are added in the
    pairs' order, and this order is the one that bodies split over processes by the place of
    their centre (``riprap/solid/bodies_over_processes.py``) can also produce, each process
    finding only the pairs of its own bodies; the sweep's order depends on every body."""
    if pairs.shape[0] < 2:
        return pairs
    keys = np.empty(pairs.shape[0], dtype=np.int64)
    stride = pairs[:, 1].max() + 1
    for k in range(pairs.shape[0]):
        keys[k] = pairs[k, 0] * stride + pairs[k, 1]
    return pairs[np.argsort(keys)].copy()


@kernel
def near_wall_pairs(positions, shape_index, bounding_radius, fixed, wall_points, wall_normals, margin):
    """(body, wall) pairs whose bounding sphere reaches into the wall half-space. (k, 2) int64."""
    n = positions.shape[0]
    n_walls = wall_points.shape[0]
    pairs = np.empty((n * max(n_walls, 1), 2), dtype=np.int64)
    count = 0
    for b in range(n):
        if fixed[b]:
            continue
        r = bounding_radius[shape_index[b]] + margin
        for w in range(n_walls):
            distance = 0.0
            for c in range(3):
                distance += wall_normals[w, c] * (positions[b, c] - wall_points[w, c])
            if distance < r:
                pairs[count, 0] = b
                pairs[count, 1] = w
                count += 1
    return pairs[:count].copy()
