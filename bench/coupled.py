"""Cost of two-way coupling: the fluid step with bodies in it against the same fluid without them.

Default: issue 13's case, the small placed layer (``examples/06_layer_in_wave``: 25 Core-Loc-like
units of H = 1 m on 135 fixed rocks and the core, the pack committed there) in the dam-break wave of
that example, on cells of half its size (0.05 m: 140 x 90 x 72 = 0.91 M cells, 11 across a unit's
Dn); both runs are first carried to ``--start`` s (the bore is on the layer then), and the baseline
is the same water without any body. ``--spheres``: a tank (64^3 cells, water 0.6 m deep) with a grid
of moving spheres (D = 8 cells) falling into still water (a still fluid needs no pressure
iterations, so the ratio there is larger). ``--synthetic``: the earlier synthetic layer (15
Core-Loc-like units of H = 8 cm in rows and a fixed toe, 1.02 M cells of 1 cm).

Both take the same fixed time step, in the same process, fluid-only and coupled windows
alternating ``repeats`` times; the best window of each counts (the machine is shared). Prints the
time per step of each, the coupled step's parts beyond the fluid's (solid volumes: clipping the
moved bodies and listing the faces they touch; exchange: blends, momentum systems and loads on
those faces; the pressure solve's extra time with the mixture density; contact sub-steps), the
load average, then (unless ``--no-ten-cate``) the wall time of ten Cate's case E2 end to end at 4
and 6 cells per diameter, and last ``METRIC coupling_overhead <coupled step / fluid step - 1> ratio``
(issue 13's target: at most 0.5).

    python bench/coupled.py [--steps N] [--repeats N] [--start T] [--spheres | --synthetic]
"""
import argparse
import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
from riprap.geometry.armour_units import armour_unit
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "06_layer_in_wave" / "case.toml"
PLACED_CELLS = (140, 90, 72)         # 0.05 m cells over the example's 7 x 4.5 x 3.6 m box
LENGTH = 0.8
LEVEL = 0.6
TIME_STEP = 1.0e-3


def tank(cells):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(LENGTH,) * 3, cells=(cells,) * 3)
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(LEVEL)
    return fluid


def spheres(fluid, per_side):
    h = fluid.h
    radius = 4.0 * h
    solids = SolidSolver(gravity=fluid.gravity)
    shape = solids.add_shape(RigidShape.from_mesh(shapes.sphere(radius=radius, mesh_size=radius / 2)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1.0e7))
    spacing = LENGTH / (per_side + 1)
    for i in range(per_side):
        for j in range(per_side):
            for k in range(2):
                solids.add_body(shape=shape, material="concrete",
                                position=((i + 1) * spacing, (j + 1) * spacing,
                                          LEVEL - 0.1 + k * 3.0 * radius))
    return CoupledSolver(fluid, solids)


# The case: dam break on 1 cm cells.
DAM_CELLS = (200, 64, 80)
DAM_CELL = 0.01
DAM_COLUMN = (0.6, 0.6)             # length and height of the water column (m)
UNIT_HEIGHT = 0.08
UNIT_ROWS, UNITS_PER_ROW = 3, 5
TOE_CUBE = 0.05


def dam_break():
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=tuple(n * DAM_CELL for n in DAM_CELLS),
                     cells=DAM_CELLS)
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.add_water_box((0.0, 0.0, 0.0), (DAM_COLUMN[0], grid.upper[1], DAM_COLUMN[1]))
    return fluid


def armour_layer(fluid):
    """Core-Loc-like units in rows on the floor just downstream of the column, and a fixed toe."""
    solids = SolidSolver(gravity=fluid.gravity)
    unit = armour_unit("core_loc_like", height=UNIT_HEIGHT)
    shape = RigidShape.from_mesh(unit.mesh)
    index = solids.add_shape(shape)
    cube = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(TOE_CUBE,) * 3)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1.0e8))
    low, high = shape.mesh.nodes.min(axis=0), shape.mesh.nodes.max(axis=0)
    pitch = 1.04 * (high - low)
    width = fluid.grid.upper[1]
    start = DAM_COLUMN[0] + 0.02 - low[0]
    for row in range(UNIT_ROWS):
        for n in range(UNITS_PER_ROW):
            y = width / 2 + (n - (UNITS_PER_ROW - 1) / 2) * pitch[1]
            solids.add_body(shape=index, material="concrete", frame="principal",
                            position=(start + row * pitch[0], y, 0.002 - low[2]))
    toe_x = start + UNIT_ROWS * pitch[0] + high[0] + TOE_CUBE
    for n in range(UNITS_PER_ROW):
        y = width / 2 + (n - (UNITS_PER_ROW - 1) / 2) * 1.2 * TOE_CUBE
        solids.add_body(shape=cube, material="concrete", position=(toe_x, y, TOE_CUBE / 2),
                        fixed=True)
    return CoupledSolver(fluid, solids)


def placed_layer():
    """(fluid alone, the same fluid coupled to the placed layer) of example 06 at PLACED_CELLS."""
    from riprap.case.build_fluid import build_fluid_run, build_fluid_solver
    from riprap.case.load import load_case

    case = load_case(EXAMPLE)
    case = dataclasses.replace(case, fluid=dataclasses.replace(case.fluid, cells=PLACED_CELLS))
    simulation = build_fluid_run(case, output_directory="/tmp/riprap_bench_coupled", progress=False)
    return build_fluid_solver(case), simulation.model.solver


def window(solver, steps, time_step):
    """(seconds per step, pressure seconds per step, parts per step) over ``steps`` steps."""
    parts = np.zeros(3)
    pressure = 0.0
    started = time.perf_counter()
    for _ in range(steps):
        solver.step(time_step)
        pressure += solver.last_pressure_seconds
        if isinstance(solver, CoupledSolver):
            parts += (solver.last_solid_volume_seconds, solver.last_exchange_seconds,
                      solver.last_solid_seconds)
    return (time.perf_counter() - started) / steps, pressure / steps, parts / steps


def measure(baseline, coupled, steps, repeats, time_step):
    baseline.step(time_step)            # compile and first steps outside the timing
    coupled.step(time_step)
    fluid_windows, coupled_windows = [], []
    for _ in range(repeats):
        fluid_windows.append(window(baseline, steps, time_step))
        coupled_windows.append(window(coupled, steps, time_step))
    return min(fluid_windows, key=lambda w: w[0]), min(coupled_windows, key=lambda w: w[0])


def carry_to(solver, end_time):
    """Step ``solver`` with its own stable steps until ``end_time`` is passed (not landing on
    it: a short last step would hold the next ones short); returns the wall seconds."""
    started = time.perf_counter()
    while solver.time < end_time:
        solver.step(solver.stable_time_step())
    return time.perf_counter() - started


def ten_cate_wall_times():
    from riprap.benchmarks.ten_cate import run_ten_cate_e2

    for cells_per_diameter in (4, 6):
        run = run_ten_cate_e2(cells_per_diameter)
        print(f"ten Cate E2 end to end at {run.cells_per_diameter:.2f} cells per diameter: "
              f"{run.wall_time:.1f} s wall, {run.steps} steps")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--start", type=float, default=0.5,
                        help="simulated time (s) both runs reach before the timing (placed layer)")
    case = parser.add_mutually_exclusive_group()
    case.add_argument("--spheres", action="store_true", help="spheres falling into still water")
    case.add_argument("--synthetic", action="store_true",
                      help="the synthetic Core-Loc-like rows in a dam break on 1 cm cells")
    parser.add_argument("--no-ten-cate", action="store_true", help="skip ten Cate E2 end to end")
    args = parser.parse_args()
    load_before = os.getloadavg()
    time_step = TIME_STEP
    if args.spheres:
        baseline, coupled = tank(64), spheres(tank(64), 4)
        print(f"64^3 = {64 ** 3:,} cells, {coupled.solids.n_bodies} moving spheres of 8 cells "
              f"across, dt = {time_step} s, {args.steps} steps x {args.repeats}")
    elif args.synthetic:
        baseline, coupled = dam_break(), armour_layer(dam_break())
        solids = coupled.solids
        print(f"dam break on {np.prod(DAM_CELLS):,} cells ({' x '.join(map(str, DAM_CELLS))}, "
              f"{DAM_CELL} m), {int((~solids.fixed).sum())} free Core-Loc-like units "
              f"(H = {UNIT_HEIGHT} m), {int(solids.fixed.sum())} fixed toe cubes, dt = {time_step} s, "
              f"{args.steps} steps x {args.repeats}")
    else:
        baseline, coupled = placed_layer()
        solids = coupled.solids
        print(f"placed layer (examples/06_layer_in_wave) on {np.prod(PLACED_CELLS):,} cells "
              f"({' x '.join(map(str, PLACED_CELLS))}, {baseline.h:g} m): "
              f"{int((~solids.fixed).sum())} free units, {int(solids.fixed.sum())} fixed bodies, "
              f"{solids.table.tets.shape[0]:,} tets of all shapes")
        fluid_seconds, coupled_seconds = carry_to(baseline, args.start), carry_to(coupled, args.start)
        # half the stable step: the flow speeds up over the windows (splash on the layer)
        time_step = 0.5 * min(baseline.stable_time_step(), coupled.stable_time_step())
        print(f"carried to t = {args.start} s: fluid alone {fluid_seconds:.0f} s wall, coupled "
              f"{coupled_seconds:.0f} s wall ({coupled_seconds / fluid_seconds - 1:+.2f}); then "
              f"dt = {time_step:.2e} s, {args.steps} steps x {args.repeats}")
    (fluid_step, fluid_pressure, _), (coupled_step, coupled_pressure, parts) = measure(
        baseline, coupled, args.steps, args.repeats, time_step)
    print(f"fluid only: {fluid_step * 1e3:.1f} ms/step (pressure solve {fluid_pressure * 1e3:.1f}); "
          f"with the bodies: {coupled_step * 1e3:.1f} ms/step (pressure solve "
          f"{coupled_pressure * 1e3:.1f}, {coupled.last_report.pressure_iterations} iterations in "
          f"the last step against {baseline.last_report.pressure_iterations})")
    rest = coupled_step - fluid_step - parts.sum() - (coupled_pressure - fluid_pressure)
    for name, value in (("solid volumes", parts[0]), ("exchange", parts[1]),
                        ("pressure solve beyond the fluid's", coupled_pressure - fluid_pressure),
                        ("contact sub-steps", parts[2]), ("rest (noise, fluid state)", rest)):
        print(f"  {name}: {value * 1e3:.1f} ms/step")
    print(f"last step: {coupled.last_clipped_bodies} bodies clipped; largest body speed "
          f"{np.linalg.norm(coupled.solids.velocities, axis=1).max():.3f} m/s")
    print(f"load average before {load_before[0]:.2f}, after {os.getloadavg()[0]:.2f}")
    if not args.no_ten_cate:
        ten_cate_wall_times()
    print(f"METRIC coupling_overhead {coupled_step / fluid_step - 1.0:.3f} ratio")


if __name__ == "__main__":
    main()
