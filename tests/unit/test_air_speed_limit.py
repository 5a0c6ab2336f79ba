"""The speeds that set the step (``kernels/face_speeds.py``): each face's pore speed with its own
cells' porosity, and ``limit_air_speed``: the step from the water's Courant number only, the air
away from the water capped at what that step carries (``FluidSolver.limit_air``)."""
import numpy as np
import pytest

from riprap.fluid.grid import FluidGrid
from riprap.fluid.kernels.face_speeds import (WET_FRACTION, largest_pore_speed, limit_air_faces,
                                              limit_listed_faces, listed_pore_speed)
from riprap.fluid.solver import FluidSolver

H = 0.05


def _flume(limit):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(1.0, H, 0.6), cells=(20, 1, 12),
                     boundaries={"x_low": "free_slip", "x_high": "free_slip"})
    fluid = FluidSolver(grid, surface_tension=0.0, limit_air_speed=limit, max_time_step=0.05)
    fluid.set_still_water_level(0.2)
    # a fast jet of air along the top rows, well above the water (rows 9-10 of 12, z > 0.45 m)
    fluid.u[:, :, 9:11] = 4.0
    return fluid


def test_kernels_see_only_the_faces_beside_water():
    f = np.zeros((4, 1, 3))
    f[:, :, 0] = 1.0
    f[1, 0, 1] = 0.2                    # one cell with a little water above the bottom row
    open_part = np.ones_like(f)
    w = np.zeros((4, 1, 4))
    w[:, :, 1] = 0.5                    # faces between the bottom row and the next: water
    w[:, :, 3] = 9.0                    # the top faces: air only, except above the wet cell
    assert largest_pore_speed(f, w, 2, open_part, True) == 0.5
    assert largest_pore_speed(f, w, 2, open_part, False) == 9.0
    w[1, 0, 2] = 7.0                    # the top face of the wet cell touches water
    assert largest_pore_speed(f, w, 2, open_part, True) == 7.0
    clipped, largest = limit_air_faces(f, w, 2, open_part, 1.0)
    assert (clipped, largest) == (4, 9.0)
    assert np.all(w[:, :, 3] == 1.0) and w[1, 0, 2] == 7.0 and np.all(w[:, :, 1] == 0.5)
    # the same on a list of faces (the coupling's carried faces)
    axes = np.array([2, 2, 2], dtype=np.int64)
    index = np.array([[0, 0, 3], [1, 0, 2], [2, 0, 1]], dtype=np.int64)
    values = np.array([-6.0, 3.0, 0.25])
    assert listed_pore_speed(f, axes, index, values, open_part, True) == 3.0
    assert listed_pore_speed(f, axes, index, values, open_part, False) == 6.0
    assert limit_listed_faces(f, axes, index, values, open_part, 2.0) == 1
    assert values.tolist() == [-2.0, 3.0, 0.25]


def test_traces_of_water_count_as_air():
    """A face beside cells with only a trace of water (the round-off the sweeps leave, a wisp of
    spray) neither sets the step nor escapes the cap; one more trace above WET_FRACTION does."""
    f = np.zeros((3, 1, 2))
    f[:, :, 0] = 1.0
    f[1, 0, 1] = 1e-30                  # a round-off trace in the upper row
    open_part = np.ones_like(f)
    w = np.zeros((3, 1, 3))
    w[:, :, 1] = 0.5
    w[1, 0, 2] = 9.0                    # the top face of the trace cell
    assert largest_pore_speed(f, w, 2, open_part, True) == 0.5
    assert limit_air_faces(f, w.copy(), 2, open_part, 1.0) == (1, 9.0)
    f[1, 0, 1] = 2.0 * WET_FRACTION
    assert largest_pore_speed(f, w, 2, open_part, True) == 9.0
    assert limit_air_faces(f, w.copy(), 2, open_part, 1.0)[0] == 0


def test_a_face_takes_the_porosity_of_its_own_cells():
    """A fast face in open water beside a porous zone elsewhere keeps its own speed; a face at
    the zone's edge takes the zone's porosity (the smaller of its two cells')."""
    f = np.ones((4, 1, 1))
    open_part = np.array([1.0, 1.0, 0.4, 0.4]).reshape(4, 1, 1)
    u = np.zeros((5, 1, 1))
    u[1] = 2.0                          # between two open cells
    assert largest_pore_speed(f, u, 0, open_part, False) == 2.0
    u[2] = 1.0                          # between an open cell and a porous one: 1 / 0.4
    assert largest_pore_speed(f, u, 0, open_part, False) == pytest.approx(2.5)
    u[4] = 0.5                          # the boundary face of a porous cell
    assert largest_pore_speed(f, u, 0, open_part, False) == pytest.approx(2.5)
    air = np.zeros_like(f)
    u[:] = 3.0
    clipped, _ = limit_air_faces(air, u, 0, open_part, 2.0)
    assert clipped == 5 and u.ravel().tolist() == pytest.approx([2.0, 2.0, 0.8, 0.8, 0.8])


def test_the_air_jet_no_longer_sets_the_step():
    plain, limited = _flume(False), _flume(True)
    assert plain.stable_time_step() == pytest.approx(0.3 * H / 4.0)
    # water at rest: the step is the gravity start-up bound, not the jet's
    step = limited.stable_time_step()
    assert step > 5 * plain.stable_time_step()
    limited.begin_step(step)
    clipped, largest = limited.last_air_limit
    assert clipped == 21 * 2 and largest == pytest.approx(4.0)
    assert np.abs(limited.u).max() == pytest.approx(limited.air_speed_limit(step))

def test_water_is_kept_and_nothing_runs_away():
    fluid = _flume(True)
    volume = fluid.water_volume()
    steps = []
    while fluid.time < 1.0:
        steps.append(fluid.step().time_step)
    assert abs(fluid.water_volume() / volume - 1.0) < 1e-12
    # the water under the jet stays nearly at rest, the air stays within the cap
    assert np.abs(fluid.u[:, :, :3]).max() < 0.05
    assert fluid.max_speed() < 4.0
    assert min(steps) > 0.3 * H / 4.0


COUPLED = """format_version = 1
[simulation]
end_time = 1.0
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.2]
cells = [16, 16, 16]
surface_tension = 0.0
limit_air_speed = {limit}
[[water_regions]]
type = "level"
level = 0.1
[[materials]]
name = "stone"
density = 2000.0
contact_penalty = 1.0e7
[[shapes]]
name = "ball"
type = "sphere"
radius = 0.025
mesh_size = 0.01
[[bodies]]
shape = "ball"
material = "stone"
position = [0.1, 0.1, 0.15]
velocity = [0.0, 0.0, -1.0]
"""


def test_a_coupled_run_with_the_cap_keeps_the_water_and_the_ball_s_path():
    """A ball thrown down through air into water, with and without the cap (which also holds the
    faces the coupling carries beside the ball, ``CoupledSolver.step``): the water volume is kept
    and the ball goes the same way."""
    from riprap.case.build_fluid import build_fluid_run
    from riprap.case.load import parse_case

    results = {}
    for limit in (False, True):
        run = build_fluid_run(parse_case(COUPLED.format(limit=str(limit).lower()), source="ball.toml"),
                              progress=False)
        run.prepare()
        coupled = run.model.solver
        fluid = coupled.fluid
        while fluid.time < 0.08:
            coupled.step(coupled.stable_time_step())
        results[limit] = (fluid.last_report.water_volume_error, float(coupled.solids.positions[0, 2]))
    for error, height in results.values():
        assert abs(error) < 1e-9
        assert height < 0.15 - 0.04              # thrown down at 1 m/s for 0.08 s
    assert results[True][1] == pytest.approx(results[False][1], abs=0.005)
