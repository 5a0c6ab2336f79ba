"""Periodic directions of the rigid bodies: what leaves the strip [lower, lower + period) along an
axis comes back at its other end (``SolidSolver.set_periodic``).

Every place that takes two bodies' relative position takes it by minimum image: body j seen from
body i is the copy of j shifted by a whole number of periods that lies nearest i along each
periodic axis. The solver refuses a period shorter than twice the reach of any pair (the two
bounding radii), so a pair can touch in that image only, and the broad phase, the piece lists
and the contact law all see the pair in the same image because they all ask :func:`image_of`
on the same numbers.

A period of 0 means "not periodic": the position is then copied as it is, so a run without a
periodic axis is the run it was before, bit for bit.
"""
import numpy as np

from riprap._jit import kernel


@kernel
def image_coordinate(x_i, x_j, length):
    """Coordinate ``x_j`` shifted by the whole number of periods ``length`` that brings it
    nearest ``x_i`` (unchanged when ``length`` is 0)."""
    if length > 0.0:
        return x_j - length * np.floor((x_j - x_i) / length + 0.5)
    return x_j


@kernel
def image_of(position_i, position_j, period, image):
    """Body j's centre ``position_j`` in the image nearest body i's ``position_i``, into
    ``image`` (3,): the centre the pair's relative pose, contact point and torques are taken
    from."""
    for a in range(3):
        image[a] = image_coordinate(position_i[a], position_j[a], period[a])


@kernel
def wrap_positions(positions, period_lower, period):
    """Bring every centre back into [lower, lower + period) along each periodic axis, after a
    drift. Velocities, spins and orientations are not touched; a centre already inside keeps its
    bits (so the pairs' images, and the springs keyed by (i, j), carry on unchanged)."""
    n = positions.shape[0]
    for a in range(3):
        length = period[a]
        if length == 0.0:
            continue
        lower = period_lower[a]
        upper = lower + length
        for b in range(n):
            x = positions[b, a]
            if x >= lower and x < upper:
                continue
            x -= length * np.floor((x - lower) / length)
            # round-off can land a centre just below lower on upper itself (or the other way):
            # both name the same place, and the strip is half-open
            if x >= upper or x < lower:
                x = lower
            positions[b, a] = x
