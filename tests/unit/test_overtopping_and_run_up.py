"""Overtopping and run-up gauges (``riprap.waves.gauges``, ``riprap.waves.report``): a known
discharge read, the overtopped volume of a collapsing column equal to the water that reached the
far side (the volume-of-fluid fluxes: to round-off), a thin tongue over a crest counted from the
crest's surface and not from a fixed height above it, the crest's surface of porous zones and
obstacles, run-up read from a constructed tongue of water on a stepped slope, and the statistics
of known records."""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.errors import CaseFileError
from riprap.fluid.porous import PorousZone
from riprap.waves.gauges import Gauge, GaugeSet, _water_crossed_per_width, crest_rows
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


def test_a_thin_tongue_over_an_obstacle_crest_counts():
    """A sheet of water one cell thick running over an obstacle's top (the crest, 0.2 m) through
    the plane at its landward edge: the gauge counts it from the crest's surface found from the
    obstacle, all of it (the water now beyond the plane), although its position's z is a cell
    higher (0.225 m), from where the old fixed-height count started and saw almost nothing."""
    fluid = _tank()
    fluid.add_obstacle_box((0.3, 0.0, 0.0), (0.6, 0.025, 0.2))       # crest top: cell row 8
    fluid.add_water_box((0.3, 0.0, 0.2), (0.6, 0.025, 0.225))        # the tongue: row 8 only
    fluid.u[12:25, 0, 8] = 0.5
    gauges = GaugeSet([Gauge("crest", "overtopping", (0.6, 0.0, 0.225))], still_water_level=0.0)
    fluid.gauges = gauges
    from_fixed_height = 0.0        # the count from the fixed height's cell row (9) up, as before
    for _ in range(2):
        fluid.step(0.01)
        from_fixed_height += _water_crossed_per_width(fluid, 24, np.array([9]))
    crossed = gauges.values[-1, 1]
    beyond = fluid.fraction[24:].sum() * fluid.h ** 3 / 0.025       # per metre of width
    assert beyond > 1e-5                                             # water went over
    assert crossed == pytest.approx(beyond, rel=1e-9)
    assert gauges._crest_rows[0].tolist() == [8]
    assert abs(from_fixed_height) < 0.05 * crossed                  # 1 %, and backwards


def test_the_crest_surface_of_a_porous_crest_and_of_obstacles_row_by_row():
    """Constructed fluxes through the plane x = 0.6 m of a two-row (y) flume: row 0 has a porous
    crest (a polygon whose top is 0.3 of a cell above cell row 8's floor: under half a cell, so
    the count starts in row 8; 0.7 of a cell: in row 9), and in row 1 an obstacle on it up to
    row 10; the water through the pores below the crest's surface is not counted, the water over
    it is, and a gauge with no crest under its plane counts from its z."""
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.05, 0.5), cells=(40, 2, 20))
    fluid = FluidSolver(grid, surface_tension=0.0)
    h = fluid.h
    top = 0.2 + 0.3 * h
    fluid.add_porous_zones([PorousZone(porosity=0.4, stone_diameter=0.01,
                                       polygon=((0.2, 0.0), (0.6, 0.0), (0.6, top), (0.2, top)))])
    mask = np.zeros(fluid.fraction.shape, dtype=bool)
    mask[10:24, 1, :10] = True
    fluid.add_obstacle_mask(mask)
    assert crest_rows(fluid, 24, 0).tolist() == [8, 10]
    deeper = FluidSolver(grid, surface_tension=0.0)          # the polygon 0.7 of a cell higher
    deeper.add_porous_zones([PorousZone(porosity=0.4, stone_diameter=0.01,
                                        polygon=((0.2, 0.0), (0.6, 0.0), (0.6, 0.2 + 0.7 * h),
                                                 (0.2, 0.2 + 0.7 * h)))])
    assert crest_rows(deeper, 24, 0).tolist() == [9, 9]
    fluxes = np.zeros((41, 2, 20))
    fluxes[24, 0, :8] = 1e-6                                 # through the core's pores
    fluxes[24, 0, 8] = 2e-6                                  # the tongue over the crest
    fluxes[24, 1, 10:12] = 3e-6                              # over the obstacle
    fluid.last_water_fluxes = (fluxes, None, None)
    fluid.step_count, fluid.time_step = 1, 0.01
    gauges = GaugeSet([Gauge("crest", "overtopping", (0.6, 0.0, 0.3))], still_water_level=0.0)
    q, volume = gauges.read(fluid)
    width = 2 * h
    assert volume == pytest.approx((2e-6 + 6e-6) / width, rel=1e-12)
    assert q == pytest.approx(volume / 0.01, rel=1e-12)
    # no crest under the plane: counted from the cell row of the gauge's z (0.31 m: row 12, dry
    # here; 0: all of it, the pores' flow too)
    for z, expected in ((0.31, 0.0), (0.0, (8e-6 + 2e-6 + 6e-6) / width)):
        open_plane = FluidSolver(grid, surface_tension=0.0)
        open_plane.last_water_fluxes = (fluxes, None, None)
        open_plane.step_count, open_plane.time_step = 1, 0.01
        reading = GaugeSet([Gauge("plane", "overtopping", (0.6, 0.0, z))], 0.0).read(open_plane)
        assert reading[1] == pytest.approx(expected, rel=1e-12, abs=1e-18)


def test_a_block_of_a_split_grid_finds_the_same_crest():
    """A split run's gauge reads the block that holds its plane (``models/slab_features.py``):
    the crest found there is the whole grid's (tests/parallel/cases/porous_flume.toml's core,
    whose top is 0.6 m, cell row 24 of 2.5 cm cells; the gauge's z a cell higher)."""
    grid = FluidGrid(lower=(-2.6, 0.0, 0.0), upper=(1.5, 0.025, 0.75), cells=(164, 1, 30))
    zone = PorousZone(porosity=0.4, stone_diameter=0.01,
                      polygon=((-1.0, 0.0), (-0.2, 0.6), (1.2, 0.6), (1.2, 0.0)))
    whole = FluidSolver(grid, surface_tension=0.0)
    whole.add_porous_zones([zone])
    block = FluidSolver(grid.block(140, 164), surface_tension=0.0)
    block.add_porous_zones([zone])
    for face in (145, 151, 152):                  # x = 1.2 m is face 152, the core's rear edge
        assert crest_rows(block, face - 140, 25).tolist() == crest_rows(whole, face, 25).tolist() \
            == [24]
    assert crest_rows(whole, 153, 25).tolist() == [25]    # behind the core: the z's row
