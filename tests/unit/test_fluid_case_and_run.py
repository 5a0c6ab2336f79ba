"""Fluid cases and runs: case-file errors name the file and the problem, a restart reproduces the
unbroken run bit for bit, a failing step leaves a checkpoint of the last good state, frames read
back."""
import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import parse_case
from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid import pressure as pressure_module
from riprap.io.vti import read_vti

CASE = """
format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.01
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.1, 0.005, 0.06]
cells = [20, 1, 12]
pressure_tolerance = {tolerance}
[[water_regions]]
type = "box"
lower = [0.0, 0.0, 0.0]
upper = [0.03, 0.005, 0.04]
"""


def _run(tmp_path, name, end_time=0.02, tolerance=1e-8, restart=None):
    case = parse_case(CASE.format(end_time=end_time, tolerance=tolerance), source="tank.toml")
    run = build_fluid_run(case, output_directory=tmp_path / name, progress=False)
    return run, run.run(restart_from=restart)


def test_restart_reproduces_the_unbroken_run(tmp_path):
    unbroken, _ = _run(tmp_path, "whole", end_time=0.02)
    first, _ = _run(tmp_path, "first", end_time=0.01)
    second, summary = _run(tmp_path, "first", end_time=0.02,
                           restart=tmp_path / "first" / "checkpoint.npz")
    for name in ("fraction", "u", "w", "pressure"):
        assert np.array_equal(getattr(second.fluid, name), getattr(unbroken.fluid, name)), name
    assert second.fluid.step_count == unbroken.fluid.step_count
    # The series continues: frames at 0, 0.01, 0.02 s.
    assert (tmp_path / "first" / "fluid.pvd").read_text().count("<DataSet") == 3
    frame = read_vti(tmp_path / "whole" / "fluid_000002.vti")
    assert np.allclose(frame["water_fraction"], unbroken.fluid.fraction, atol=1e-6)
    assert frame["velocity"].shape == (20, 1, 12, 3)
    assert summary.water_volume_error < 1e-10


def test_a_failing_step_leaves_the_last_good_state(tmp_path, monkeypatch):
    # A pressure tolerance no solver can reach, and no capped solve kept (a capped solve whose
    # residual is below CAPPED_RESIDUAL_LIMIT is kept and reported instead): the first step fails.
    monkeypatch.setattr(pressure_module, "CAPPED_RESIDUAL_LIMIT", 1e-30)
    with pytest.raises(InstabilityError, match="failure_checkpoint.npz"):
        _run(tmp_path, "fail", tolerance=1e-30)
    assert (tmp_path / "fail" / "failure_checkpoint.npz").is_file()


@pytest.mark.parametrize("change, message", [
    ("cells = [20, 1, 12]", "cells = [20, 1, 13]"),
])
def test_cells_that_are_not_cubes_are_refused(change, message):
    text = CASE.format(end_time=0.01, tolerance=1e-8).replace(change, message)
    case = parse_case(text, source="tank.toml")
    with pytest.raises(CaseFileError, match=r"tank.toml \[fluid\].*cells must be cubes.*use cells"):
        build_fluid_run(case, progress=False)


def test_water_outside_the_box_is_refused():
    text = CASE.format(end_time=0.01, tolerance=1e-8).replace(
        "lower = [0.0, 0.0, 0.0]\nupper = [0.03", "lower = [0.5, 0.0, 0.0]\nupper = [0.6")
    case = parse_case(text, source="tank.toml")
    with pytest.raises(CaseFileError, match=r"water_regions\]\] entry 1.*outside the fluid box"):
        build_fluid_run(case, progress=False)


def test_schema_errors_name_the_line():
    text = CASE.format(end_time=0.01, tolerance=1e-8).replace(
        "pressure_tolerance", "courant_number = 0.9\npressure_tolerance")
    with pytest.raises(CaseFileError, match=r"tank.toml:\d+.*courant_number"):
        parse_case(text, source="tank.toml")


def test_water_flows_around_an_obstacle_and_never_enters_it():
    """OpenFOAM's damBreak tutorial geometry (tank 0.584 m square, column 0.1461 x 0.292 m, an
    obstacle 0.024 x 0.048 m on the floor at x = 0.292 m) on a coarse 2D grid, closed top (the
    splash would otherwise leave through an open one): after the surge has passed the obstacle, its
    cells hold no water and no flow, water volume is conserved."""
    from riprap.fluid.grid import FluidGrid
    from riprap.fluid.solver import FluidSolver

    h = 0.584 / 48
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.584, h, 0.584), cells=(48, 1, 48),
                     boundaries={"z_high": "no_slip"})
    solver = FluidSolver(grid)
    solver.add_water_box((0, 0, 0), (0.1461, h, 0.292))
    mask = np.zeros(grid.cells, dtype=bool)
    mask[24:26, :, 0:4] = True                     # cells of x 0.292-0.316 m, z 0-0.048 m
    solver.add_obstacle_mask(mask)
    volume = solver.water_volume()
    while solver.time < 0.4:
        solver.step()
    assert solver.fraction[mask].max() == 0.0
    assert np.abs(solver.u[24:27, :, 0:4]).max() == 0.0
    assert solver.fraction[30:, 0, :].sum() > 0        # the surge got past it
    assert abs(solver.water_volume() - volume) < 1e-10 * volume
    with pytest.raises(CaseFileError, match="mask has shape"):
        solver.add_obstacle_mask(np.zeros((3, 3, 3), dtype=bool))
