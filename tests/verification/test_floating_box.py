"""A floating cube comes to rest at the Archimedes draught (issue 13: within 2 %).

A cube of half water's density (0.1 m, 12 cells across, ``riprap.benchmarks.floating_box``) is
released 2 cm above its floating position in a 0.4 m tank, heaves, and settles: its mean draught over
the third to sixth seconds lies within ``DRAUGHT_TOLERANCE`` of Archimedes' (half its height;
measured +0.2 %), the heave dies down (its range in the sixth second under half that of the
first: measured 0.47), and the water is conserved.

Why 12 cells across (8 until issue 51): the heave's decay over six seconds depends on the
cut-face treatment at coarse grids, and the two treatments approach each other from both sides
as the grid is refined (the sixth second's range over the first's, 2026-12-03):

    cells across the cube      8      12      16
    own_velocity (default)     0.59   0.47    0.38
    mixture                    0.23   0.24    0.27

so the heave's damping is not yet converged at 16 cells (the limit lies near 0.3); the default
damps it too little at 8 cells across, "mixture" a little too much. The draught is within 1.1 %
with either at every resolution. The heave (±8 mm in the third second) is slow to die, so a short
window reads a part of a period too many or too few.
"""
import numpy as np
import pytest

from riprap.benchmarks.floating_box import run_floating_box

DRAUGHT_TOLERANCE = 0.02
SECONDS = 6.0


@pytest.fixture(scope="module")
def run():
    return run_floating_box(cells=48, seconds=SECONDS, start_above=0.02)


def test_the_cube_floats_at_the_archimedes_draught(run):
    draught = run.draught(since=2.0)
    assert draught == pytest.approx(run.archimedes_draught, rel=DRAUGHT_TOLERANCE)


def test_the_heave_dies_down_and_the_water_is_kept(run):
    first = run.heights[run.times < 1.0]
    last = run.heights[run.times > SECONDS - 1.0]
    assert np.ptp(last) < 0.5 * np.ptp(first)
    assert abs(run.water_volume_error) < 1e-9
