"""A permeameter: a block of filter stone under a head difference passes the Darcy (superficial)
velocity of the Forchheimer law with riprap's own coefficients (issue 51, item 4).

Law (``riprap.fluid.porous``; Engelund 1953 and Van Gent 1995 in the form olaFlow codes, Higuera,
Lara & Losada 2014, with the coefficients of Jensen, Jacobsen & Christensen 2014, Coastal Eng.
84: 56): the hydraulic gradient over a block of porosity n and stone diameter D50 is

    i = dh / L = a' U + b' U^2,   a' = a (1 - n)^3 / n^3  nu / (g D50^2),
                                  b' = b (1 - n) / n^3  1 / (g D50),

U the Darcy velocity, a = 50, b = 2.0 (the [[porous_zones]] defaults, the coefficients the
filter zone that stands for contact-only underlayer rocks takes: ``riprap.coupling.filter_layer``).

Set-up: a falling-head permeameter in a 2-D box of 1 cm cells. Two open columns 0.2 m wide joined
under a solid block 0.2 m long by a horizontal plug of filter 5 cm high, the block's length
(x = 0.2-0.4 m); water at 0.30 m on the left and 0.20 m on the right at rest. The flow goes down
the left column, through the plug and up the right one; the head falls slowly (0.095 to 0.078 m
over the measured 0.2-0.7 s with the coarse filter), so at every step the measured U (the mean
face velocity over the plug's height at its middle) is compared with the law's U for the head
difference of that step (the two columns' water levels). Two filters: the damage-curve bench's
(n = 0.4, D50 = 2 cm, the quadratic term carries 99 % of the loss) and one of 2 mm stones (the
linear term 18 %).

Tolerances: issue 51's, ``ISSUE_TOLERANCE`` = 30 % at the default max_time_step 0.01 s and
``HALVED_TOLERANCE`` = 10 % at 0.005 s; tighter, ``LAW_TOLERANCE`` = 2 % at both (measured
0.40 % and 0.45 % for the bench's filter, 0.05 % and 0.04 % for the fine one: what is left is
the inertia of the slowly falling head, which keeps U a little above the steady law, and the
columns' own small losses) and ``STEP_TOLERANCE`` = 1 % between the two steps (measured 0.01 %);
the Darcy velocity from the left column's falling level (its water volume's rate over the plug's
height) agrees with the face velocity within ``MASS_TOLERANCE`` = 2 % (measured 0.1 %: what
leaves the column passes the plug). A few seconds of wall time.
"""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.fluid.porous import DEFAULT_LINEAR, DEFAULT_QUADRATIC, PorousZone
from riprap.coupling.filter_layer import FILTER_POROSITY

CELL = 0.01
COLUMN, PLUG, GAP, HEIGHT = 0.2, 0.2, 0.05, 0.4          # m
LEFT_LEVEL, RIGHT_LEVEL = 0.30, 0.20                        # m
WINDOW = (0.2, 0.7)                                         # s: after the start's transient
MAX_TIME_STEP = 0.01                                        # s, the [fluid] default
ISSUE_TOLERANCE = 0.30
HALVED_TOLERANCE = 0.10
LAW_TOLERANCE = 0.02
STEP_TOLERANCE = 0.01
MASS_TOLERANCE = 0.02
#: (name, D50 m): the bench's underlayer rocks (Dn 4.6 cm / 2.3) and a fine filter.
FILTERS = [("bench underlayer", 0.02), ("fine filter", 0.002)]


def forchheimer_velocity(gradient, *, porosity, diameter, kinematic_viscosity, gravity):
    """The Darcy velocity U (m/s) of i = a' U + b' U^2 (the module's law)."""
    linear = (DEFAULT_LINEAR * (1 - porosity) ** 3 / porosity ** 3 * kinematic_viscosity
              / (gravity * diameter ** 2))
    quadratic = DEFAULT_QUADRATIC * (1 - porosity) / porosity ** 3 / (gravity * diameter)
    return (-linear + np.sqrt(linear ** 2 + 4.0 * quadratic * gradient)) / (2.0 * quadratic)


def _permeameter(diameter, max_time_step):
    nx, nz = round((2 * COLUMN + PLUG) / CELL), round(HEIGHT / CELL)
    grid = FluidGrid(lower=(0, 0, 0), upper=(nx * CELL, CELL, nz * CELL), cells=(nx, 1, nz))
    fluid = FluidSolver(grid, surface_tension=0.0, max_time_step=max_time_step)
    fluid.add_water_box((0, 0, 0), (COLUMN, CELL, LEFT_LEVEL))
    fluid.add_water_box((COLUMN, 0, 0), (COLUMN + PLUG, CELL, GAP))
    fluid.add_water_box((COLUMN + PLUG, 0, 0), (2 * COLUMN + PLUG, CELL, RIGHT_LEVEL))
    fluid.add_obstacle_box((COLUMN, 0, GAP), (COLUMN + PLUG, CELL, HEIGHT))
    fluid.add_porous_zones([PorousZone(porosity=FILTER_POROSITY, stone_diameter=diameter,
                                       lower=(COLUMN, 0, 0), upper=(COLUMN + PLUG, CELL, GAP))])
    centres = grid.centres(0)
    left, right = centres < COLUMN, centres > COLUMN + PLUG
    middle = round((COLUMN + PLUG / 2) / CELL)               # the x-face at the plug's middle
    plug = grid.centres(2) < GAP
    gravity = float(-fluid.gravity[2])
    records = []
    while fluid.time < WINDOW[1] - 1e-9:
        report = fluid.step()
        if fluid.time < WINDOW[0]:
            continue
        left_volume = fluid.fraction[left, 0, :].sum() * CELL * CELL     # per metre of width
        head = (left_volume - fluid.fraction[right, 0, :].sum() * CELL * CELL) / COLUMN
        records.append((fluid.time, report.time_step, head, left_volume,
                        float(fluid.u[middle, 0, plug].mean())))
    time, dt, head, left_volume, darcy = np.array(records).T
    law = forchheimer_velocity(head / PLUG, porosity=FILTER_POROSITY, diameter=diameter,
                               kinematic_viscosity=(fluid.water.dynamic_viscosity
                                                    / fluid.water.density), gravity=gravity)
    from_level = -np.gradient(left_volume, time) / GAP
    return dict(time=time, dt=dt, darcy=darcy, law=law, from_level=from_level)


@pytest.fixture(scope="module", params=FILTERS, ids=[name for name, _ in FILTERS])
def runs(request):
    _, diameter = request.param
    return {step: _permeameter(diameter, step) for step in (MAX_TIME_STEP, MAX_TIME_STEP / 2)}


def _error(run):
    return float(np.max(np.abs(run["darcy"] / run["law"] - 1.0)))


def test_the_step_is_the_one_asked_for(runs):
    for step, run in runs.items():
        assert np.allclose(run["dt"], step), (step, run["dt"].min(), run["dt"].max())


def test_darcy_velocity_follows_forchheimer_within_the_issue_tolerances(runs):
    assert _error(runs[MAX_TIME_STEP]) < ISSUE_TOLERANCE
    assert _error(runs[MAX_TIME_STEP / 2]) < HALVED_TOLERANCE


def test_darcy_velocity_follows_forchheimer_closely_at_both_steps(runs):
    errors = {step: _error(run) for step, run in runs.items()}
    assert max(errors.values()) < LAW_TOLERANCE, errors


def test_the_step_does_not_change_the_velocity(runs):
    coarse, fine = runs[MAX_TIME_STEP], runs[MAX_TIME_STEP / 2]
    at_coarse_times = np.interp(coarse["time"], fine["time"], fine["darcy"])
    assert float(np.max(np.abs(coarse["darcy"] / at_coarse_times - 1.0))) < STEP_TOLERANCE


def test_what_leaves_the_column_passes_the_plug(runs):
    for run in runs.values():
        inner = slice(2, -2)                 # np.gradient's one-sided ends left out
        difference = np.abs(run["from_level"][inner] / run["darcy"][inner] - 1.0)
        assert float(np.max(difference)) < MASS_TOLERANCE
