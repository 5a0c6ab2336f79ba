"""The fluid's load on a body does not depend on the time step with ``cut_faces = "own_velocity"``
(issue 51; docs/coupling.md, Cut faces and the step).

A cube of side D carried at a constant speed through water at rest (``bench/unit_loads.py``'s
towing tank, 3 cells per side, travelled 6 D, the drag averaged from 3 to 6 D): its mean drag at a
step of 0.2 h / U and at a quarter of that differ by under ``STEP_CHANGE`` = 5 % (the issue's
target for 5 ms against 1.25 ms; bench/unit_loads.py measured 3.2 % over 4-10 D). The default
treatment, ``mixture``, changes by 28 % between 0.3 h / U and a quarter of it (C_D 1.318 against
1.689): its cut faces are relaxed a fixed fraction per step. Momentum exchanged between fluid and a moving
body with the new treatment sums to zero to ``EXCHANGE_TOLERANCE`` of the body's momentum, as with
the default (``test_coupling_still_water.py``).
"""
import numpy as np
import pytest

from riprap.benchmarks.towing_tank import tow, towing_tank
from riprap.errors import CaseFileError

STEP_CHANGE = 0.05
EXCHANGE_TOLERANCE = 1e-12
SIDE, SPEED, CELLS = 0.05, 0.4, 3


def _mean_drag(dt_scale):
    coupled = towing_tank(SIDE, SPEED, CELLS, cut_faces="own_velocity")
    travel, drag = tow(coupled, SIDE, SPEED, 0.2 * SIDE / CELLS / SPEED * dt_scale, 6.0)
    return float(drag[travel > 3.0].mean())


@pytest.mark.slow
def test_the_drag_of_a_towed_cube_does_not_depend_on_the_step():
    coarse, fine = _mean_drag(1.0), _mean_drag(0.25)
    assert coarse > 0.0 and fine > 0.0, "the water holds the cube back"
    assert abs(fine / coarse - 1.0) < STEP_CHANGE, (coarse, fine)


def test_momentum_exchanged_with_own_velocity_cut_faces_sums_to_zero():
    coupled = towing_tank(SIDE, SPEED, CELLS, cut_faces="own_velocity", check_momentum=True)
    momentum = coupled.solids.masses[0] * SPEED
    for _ in range(15):
        coupled.step(0.2 * SIDE / CELLS / SPEED)
        assert np.all(np.abs(coupled.last_exchange_balance) < EXCHANGE_TOLERANCE * momentum)


def test_an_unknown_cut_face_treatment_is_refused():
    with pytest.raises(CaseFileError, match="cut_faces"):
        towing_tank(SIDE, SPEED, CELLS, cut_faces="sharp")
