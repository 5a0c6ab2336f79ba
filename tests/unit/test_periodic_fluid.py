"""The fluid on a periodic y (issue 53): a strip across the flume that stands for a wide one.

What is checked, and against what:

- a dam break uniform across a periodic y stays uniform to the pressure solve's precision (as
  between walls), keeps its water to the solver's usual precision and is the dam break between
  free-slip side walls (the same flow);
- a Taylor-Green vortex whose cells straddle the periodic boundary is the same flow as the vortex
  in a box twice as wide (periodic, and between free-slip walls on the vortex's symmetry lines),
  and decays as the analytical exp(-2 nu k^2 t) (Taylor & Green 1937) within the grid's error;
- water carried across the boundary by a uniform flow comes back where it started after one
  period, all of it;
- nothing marks where the boundary lies: a start shifted along y gives the shifted flow;
- a periodic y that cannot hold is refused: one side alone, an odd number of cells, a 2D flume.
"""
import math

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.fluid.grid import FluidGrid
from riprap.fluid.phases import Phase
from riprap.fluid.solver import FluidSolver

PERIODIC = {"y_low": "periodic", "y_high": "periodic"}
FREE_SLIP_Y = {"y_low": "free_slip", "y_high": "free_slip"}


def _dam_break(boundaries, steps=40):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.6, 0.2, 0.4), cells=(24, 8, 16),
                     boundaries=boundaries)
    solver = FluidSolver(grid, surface_tension=0.0, courant_number=0.25)
    solver.add_water_box((0.0, 0.0, 0.0), (0.25, 0.2, 0.3))
    for _ in range(steps):
        solver.step(2e-3)
    return solver


def _spread_across(solver, name) -> float:
    field = getattr(solver, name)
    return float(np.abs(field - field[:, :1]).max())


def test_uniform_dam_break_stays_uniform_and_matches_free_slip_walls():
    """Across a periodic y nothing varies in y: every y column of the water fraction, u and w
    equals column 0 to the pressure solve's precision (its red-black sweeps treat neighbouring
    columns apart; measured: 4e-11 in f, 4e-10 m/s in u and w against 7e-11 and 5e-10 between
    free-slip walls), asked below 1e-9 and no more than twice the walled flume's; v stays below
    1e-9 m/s and its faces 0 and ny equal; the flow is the one between free-slip walls (u within
    1e-8 of its largest value, measured 3e-10); water kept to 1e-11 of its volume."""
    periodic = _dam_break(PERIODIC)
    walled = _dam_break(FREE_SLIP_Y)
    for name in ("fraction", "u", "w"):
        spread = _spread_across(periodic, name)
        assert spread < 1e-9, name
        assert spread <= 2.0 * max(_spread_across(walled, name), 1e-12), name
    assert np.abs(periodic.v).max() < 1e-9
    assert np.array_equal(periodic.v[:, 0], periodic.v[:, -1])
    scale = np.abs(walled.u).max()
    assert scale > 0.3                                   # the water has started to run
    assert np.abs(periodic.u - walled.u).max() <= 1e-8 * scale
    assert np.abs(periodic.fraction - walled.fraction).max() <= 1e-8
    assert abs(periodic.last_report.water_volume_error) < 1e-11


def _taylor_green(ny, shift_cells, boundaries, steps, dt):
    """A Taylor-Green vortex u = U sin(kx) cos(k(y + s)), v = -U cos(kx) sin(k(y + s)) of period L
    = 1 m in y, on x in [0, L/2] between free-slip walls, water only, no gravity, closed top."""
    length, h = 1.0, 1.0 / 16
    k, speed = 2.0 * math.pi / length, 0.05
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.5, ny * h, 2 * h), cells=(8, ny, 2),
                     boundaries={"x_low": "free_slip", "x_high": "free_slip",
                                 "z_low": "free_slip", "z_high": "free_slip", **boundaries})
    viscous = Phase("viscous water", 1000.0, 1.0)       # nu = 1e-3 m^2/s: it decays in a second
    solver = FluidSolver(grid, water=viscous, gravity=(0.0, 0.0, 0.0), surface_tension=0.0,
                         pressure_tolerance=1e-12)
    solver.add_water_box(grid.lower, grid.upper)
    shift = shift_cells * h
    xf, xc = grid.faces(0), grid.centres(0)
    yf, yc = grid.faces(1), grid.centres(1)
    solver.u[:] = (speed * np.sin(k * xf)[:, None] * np.cos(k * (yc + shift))[None, :])[:, :, None]
    solver.v[:] = (-speed * np.cos(k * xc)[:, None] * np.sin(k * (yf + shift))[None, :])[:, :, None]
    energy0 = float((solver.u ** 2).sum() + (solver.v ** 2).sum())
    for _ in range(steps):
        solver.step(dt)
    return solver, energy0, viscous.kinematic_viscosity, k


def test_taylor_green_across_the_boundary_is_the_wide_box_flow():
    """The strip (16 cells, one period, shifted a quarter period so that the vortices' cells
    straddle its boundary) against a box of 32 cells holding two periods, where the strip's
    boundary lies inside: the strip's velocities equal the wide box's at the same phase to 1e-12
    of the vortex speed (measured 4e-16: the same arithmetic). Against the wide box between
    free-slip walls on the vortex's symmetry lines within 0.3 % of the speed (measured 0.1 %: the
    walls' own stencils, the one-sided limiter and the wall's shear term). The kinetic energy
    decays as exp(-4 nu k^2 t) (twice the velocity's rate; Taylor & Green 1937) within 0.5 %
    (measured 0.13 % at 8 cells per half period)."""
    steps, dt, speed = 50, 4e-3, 0.05
    strip, energy0, nu, k = _taylor_green(16, 4, PERIODIC, steps, dt)
    wide, _, _, _ = _taylor_green(32, 0, PERIODIC, steps, dt)
    walled, _, _, _ = _taylor_green(32, 0, FREE_SLIP_Y, steps, dt)
    # strip cell j lies at the wide box's phase of cell j + 4
    for box, tolerance in ((wide, 1e-12), (walled, 3e-3)):
        assert np.abs(strip.u - box.u[:, 4:20]).max() < tolerance * speed
        assert np.abs(strip.v - box.v[:, 4:21]).max() < tolerance * speed
    energy = float((strip.u ** 2).sum() + (strip.v ** 2).sum())
    expected = math.exp(-4.0 * nu * k * k * steps * dt)
    assert energy / energy0 == pytest.approx(expected, rel=0.005)


def test_water_carried_across_the_boundary_comes_back():
    """A wall of water in air, carried in y by a uniform 0.5 m/s flow (no gravity, free-slip
    walls: the flow stays uniform), crosses the periodic boundary and after one period (80 steps of a quarter cell) is back where it started:
    fractions within 1e-9, the water's volume to 1e-12, the flow still uniform to 1e-9."""
    walls = dict.fromkeys(("x_low", "x_high", "z_low", "z_high"), "free_slip")
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.4, 0.8, 0.4), cells=(8, 16, 8),
                     boundaries={**PERIODIC, **walls})
    solver = FluidSolver(grid, gravity=(0.0, 0.0, 0.0), surface_tension=0.0)
    # a wall of water across x and z (its surfaces' normals along y, which PLIC moves exactly)
    solver.add_water_box((0.0, 0.55, 0.0), (0.4, 0.75, 0.4))
    start = solver.fraction.copy()
    solver.v[:] = 0.5
    h = grid.cell_size
    dt = 0.25 * h / 0.5
    for _ in range(64):
        solver.step(dt)
    assert abs(solver.last_report.water_volume_error) < 1e-12
    assert np.abs(solver.fraction - start).max() < 1e-9
    assert np.abs(solver.v - 0.5).max() < 1e-9


def _falling_block(shift_cells, surface_tension):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.4, 0.8, 0.4), cells=(8, 16, 8),
                     boundaries=PERIODIC)
    solver = FluidSolver(grid, surface_tension=surface_tension)
    h = grid.cell_size
    low = (0.55 + shift_cells * h) % 0.8
    # a block of water straddling the boundary (split in two boxes once shifted past it)
    for start, stop in ((low, min(low + 0.2, 0.8)), (0.0, max(low + 0.2 - 0.8, 0.0))):
        if stop > start:
            solver.add_water_box((0.1, start, 0.15), (0.3, stop, 0.3))
    solver.v[:] = 0.3
    solver.u[1:-1] = 0.1
    for _ in range(30):
        solver.step(2e-3)
    return solver


@pytest.mark.parametrize("surface_tension", [0.0, 0.0728])
def test_a_shifted_start_gives_the_shifted_flow(surface_tension):
    """Nothing in a periodic strip marks where its boundary lies: a block of water falling
    through a sheared flow between no-slip walls, without and with surface tension (the sharp
    face densities, or the transported ones and the padded height functions), started 6 cells further
    along y (its water across the boundary in the other place), gives the same flow 6 cells on:
    fractions and velocities within 1e-9 (the same arithmetic but for the order of the pressure
    solve's sums)."""
    here, there = _falling_block(0, surface_tension), _falling_block(6, surface_tension)
    assert np.abs(here.w).max() > 0.05                  # it falls
    for name in ("fraction", "u", "w", "pressure"):
        a, b = getattr(here, name), getattr(there, name)
        scale = max(1.0, np.abs(a).max())
        assert np.abs(np.roll(a, 6, axis=1) - b).max() < 1e-9 * scale, name
    rolled = np.roll(here.v[:, :-1], 6, axis=1)
    assert np.abs(rolled - there.v[:, :-1]).max() < 1e-9
    assert np.array_equal(there.v[:, 0], there.v[:, -1])


@pytest.mark.parametrize("boundaries, cells, words", [
    ({"y_low": "periodic"}, (8, 8, 8), "other y side"),
    (PERIODIC, (8, 7, 8), "even number of cells"),
    (PERIODIC, (8, 1, 8), "even number of cells"),
    ({"x_low": "periodic", "x_high": "periodic"}, (8, 8, 8), "only the y sides"),
])
def test_a_periodic_y_that_cannot_hold_is_refused(boundaries, cells, words):
    with pytest.raises(CaseFileError, match=words):
        FluidGrid(lower=(0.0, 0.0, 0.0), upper=tuple(0.1 * n for n in cells), cells=cells,
                  boundaries=boundaries)


_STRIP_CASE = """format_version = 1
[simulation]
end_time = 0.1
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.8, 0.2, 0.4]
cells = [{nx}, {ny}, 16]
y_low = "{y_low}"
y_high = "periodic"
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.2
{extra}
"""


@pytest.mark.parametrize("y_low, ny, extra, words", [
    ("free_slip", 8, "", "needs the other y side periodic"),
    ("periodic", 7, "", "even number of cells"),
    ("periodic", 8, "[[obstacles]]\ntype = \"box\"\nlower = [0.3, 0.0, 0.0]\n"
     "upper = [0.4, 0.1, 0.1]", "does not span the periodic strip"),
    ("periodic", 8, "[[porous_zones]]\ntype = \"box\"\nporosity = 0.4\nstone_diameter = 0.01\n"
     "lower = [0.3, 0.05, 0.0]\nupper = [0.6, 0.2, 0.1]", "does not span the periodic strip"),
])
def test_riprap_check_names_each_refusal_of_a_strip(tmp_path, capsys, y_low, ny, extra, words):
    """``riprap check`` on a periodic strip that cannot hold: exit 2 and one line naming the
    case file, the table and why."""
    from riprap.cli import main
    path = tmp_path / "strip.toml"
    path.write_text(_STRIP_CASE.format(nx=32, ny=ny, y_low=y_low, extra=extra))
    if ny % 2:     # cells must stay cubes: the strip's width follows its cells
        path.write_text(path.read_text().replace("upper = [0.8, 0.2, 0.4]",
                                                 "upper = [0.8, 0.175, 0.4]"))
    assert main(["check", str(path)]) == 2
    error = capsys.readouterr().err
    assert words in error and "strip.toml" in error, error


def test_riprap_check_takes_a_strip(tmp_path, capsys):
    """The same strip with both sides periodic, an obstacle and a porous box across its whole
    width: ``riprap check`` passes it."""
    from riprap.cli import main
    path = tmp_path / "strip.toml"
    extra = ("[[obstacles]]\ntype = \"box\"\nlower = [0.3, 0.0, 0.0]\nupper = [0.4, 0.2, 0.1]\n"
             "[[porous_zones]]\ntype = \"box\"\nporosity = 0.4\nstone_diameter = 0.01\n"
             "lower = [0.5, 0.0, 0.0]\nupper = [0.7, 0.2, 0.1]")
    path.write_text(_STRIP_CASE.format(nx=32, ny=8, y_low="periodic", extra=extra))
    assert main(["check", str(path)]) == 0, capsys.readouterr().err


def test_riprap_check_warns_of_a_strip_the_multigrid_cannot_coarsen(tmp_path, capsys):
    """ny = 10 across a periodic strip runs (even), with a warning naming the key and the counts
    that would let the multigrid coarsen y (8 or 12)."""
    from riprap.cli import main
    path = tmp_path / "strip.toml"
    path.write_text(_STRIP_CASE.format(nx=32, ny=10, y_low="periodic", extra="").replace(
        "upper = [0.8, 0.2, 0.4]", "upper = [0.8, 0.25, 0.4]"))
    assert main(["check", str(path)]) == 0
    error = capsys.readouterr().err
    assert "[fluid]: a periodic y of ny = 10" in error and "8 or 12" in error, error
