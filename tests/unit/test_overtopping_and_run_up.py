"""Overtopping and run-up gauges (``riprap.waves.gauges``, ``riprap.waves.report``): a known
discharge read, the overtopped volume of a collapsing column equal to the water that reached the
far side (the volume-of-fluid fluxes: to round-off), run-up read from a
constructed tongue of water on a stepped slope, and the statistics of known records."""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.errors import CaseFileError
from riprap.waves.gauges import Gauge, GaugeSet
from riprap.waves.report import overtopping_statistics, run_up_statistics


def _tank(cells=(40, 1, 20), size=(1.0, 0.025, 0.5)):
    grid = FluidGrid(lower=(0, 0, 0), upper=size, cells=cells)
    return FluidSolver(grid, surface_tension=0.0)


def test_uniform_flow_discharge_is_velocity_times_depth():
    fluid = _tank()
    fluid.set_still_water_level(0.2)
    fluid.u[1:-1] = 0.3
    gauges = GaugeSet([Gauge("crest", "overtopping", (0.5, 0.0, 0.0))], still_water_level=0.2)
    fluid.gauges = gauges
    fluid.step(0.01)           # the x faces carry the water layer: q = u d (the first step)
    q, volume = gauges.values[-1]
    assert q == pytest.approx(0.3 * 0.2, rel=1e-3)
    assert volume == pytest.approx(q * 0.01, rel=1e-12)


def test_overtopped_volume_is_the_water_that_crossed():
    fluid = _tank()
    fluid.add_water_box((0.0, 0.0, 0.0), (0.3, 0.025, 0.3))
    gauges = GaugeSet([Gauge("plane", "overtopping", (0.6, 0.0, 0.0))], still_water_level=0.0)
    fluid.gauges = gauges
    while fluid.time < 0.4:           # before the bore climbs the far wall and out of the box
        fluid.step()
    assert abs(fluid.last_report.water_volume_error) < 1e-10
    beyond = fluid.fraction[24:].sum() * fluid.h ** 3 / 0.025      # per metre of width
    crossed = gauges.values[-1, 1]
    assert beyond > 0.005                                          # a real overtopping
    assert crossed == pytest.approx(beyond, rel=1e-9)


def test_run_up_is_the_top_of_the_water_resting_on_the_slope():
    fluid = _tank()
    h = fluid.h
    steps = np.zeros(fluid.fraction.shape, dtype=bool)
    for i in range(20, 40):
        steps[i, 0, :min(i - 18, 20)] = True                        # a stair-stepped slope
    fluid.add_obstacle_mask(steps)
    fluid.fraction[:, 0, :6] = np.where(steps[:, 0, :6], 0.0, 1.0)  # still water 0.15 m deep
    gauges = GaugeSet([Gauge("slope", "run_up", (0.4, 0.0, 0.0), to_x=1.0)], still_water_level=0.15)
    assert gauges.read(fluid)[0] == pytest.approx(0.0, abs=1e-12)   # at rest: the still level
    fluid.fraction[24, 0, 6] = 1.0                                  # a tongue on the step of
    fluid.fraction[24, 0, 7] = 0.4                                  # column 24 (bed 6 cells)
    fluid.fraction[30, 0, 15] = 1.0                                 # spray: not on its bed
    fluid.fraction[27, 0, 9] = 0.3                                  # a film: under half a cell
    assert gauges.read(fluid)[0] == pytest.approx(0.025 + 0.4 * h, abs=1e-12)
    with pytest.raises(CaseFileError, match="to_x"):
        GaugeSet([Gauge("bad", "run_up", (0.4, 0.0, 0.0), to_x=0.2)], 0.15)


def test_statistics_of_known_records():
    t = np.linspace(0.0, 100.0, 10001)
    level = 0.5 * np.sin(2 * np.pi * t / 2.0) + 0.1
    run_up = run_up_statistics(t, level)
    assert run_up["R_max_m"] == pytest.approx(0.6, abs=1e-6)
    assert run_up["R2%_m"] == pytest.approx(0.6, abs=1e-4) and run_up["run_up_waves"] == 50
    volume = 0.002 * t
    overtopping = overtopping_statistics(t, volume)
    assert overtopping["q_l_s_per_m"] == pytest.approx(2.0) and overtopping["volume_m3_per_m"] == pytest.approx(0.2)
