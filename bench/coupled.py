"""Cost of two-way coupling: the fluid step with bodies in it against the same fluid without them.

Default case: a tank (64 x 64 x 64 cells, 0.8 m, water 0.6 m deep) with a grid of moving spheres
(4 x 4 x 2, D = 8 cells) falling into the water; the same water without bodies as the baseline.
``--full``: issue 13's case instead, a small placed layer of Core-Loc-like units (3 rows of 5,
H = 8 cm, 4.8 cells across by V^(1/3), all free) and a fixed toe of 5 cubes in a dam-break wave
(0.6 m column) on 200 x 64 x 80 = 1.02 M cells; the same wave without bodies as the baseline.

Both take the same fixed time step, in the same process, fluid-only and coupled windows
alternating ``repeats`` times; the best window of each counts (the machine is shared). Prints the
time per step of each, the coupled step's parts beyond the fluid's (solid volumes: clipping the
moved bodies and listing the faces they touch; exchange: blends, momentum systems and loads on
those faces; the pressure solve's extra time with the mixture density; contact sub-steps), the
load average, and, last line, ``METRIC coupling_overhead <coupled step / fluid step - 1> ratio``
(issue 13's target: at most 0.5).

    python bench/coupled.py [cells] [spheres per side] [steps] [--repeats N] [--full]
"""
import argparse
import os
import time

import numpy as np

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
from riprap.geometry.armour_units import armour_unit
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

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


def window(solver, steps):
    """(seconds per step, pressure seconds per step, parts per step) over ``steps`` steps."""
    parts = np.zeros(3)
    pressure = 0.0
    started = time.perf_counter()
    for _ in range(steps):
        solver.step(TIME_STEP)
        pressure += solver.last_pressure_seconds
        if isinstance(solver, CoupledSolver):
            parts += (solver.last_solid_volume_seconds, solver.last_exchange_seconds,
                      solver.last_solid_seconds)
    return (time.perf_counter() - started) / steps, pressure / steps, parts / steps


def measure(baseline, coupled, steps, repeats):
    baseline.step(TIME_STEP)            # compile and first steps outside the timing
    coupled.step(TIME_STEP)
    fluid_windows, coupled_windows = [], []
    for _ in range(repeats):
        fluid_windows.append(window(baseline, steps))
        coupled_windows.append(window(coupled, steps))
    return min(fluid_windows, key=lambda w: w[0]), min(coupled_windows, key=lambda w: w[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cells", nargs="?", type=int, default=64)
    parser.add_argument("per_side", nargs="?", type=int, default=4)
    parser.add_argument("steps", nargs="?", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--full", action="store_true",
                        help="the issue's case: a placed Core-Loc-like layer in a dam-break wave, 1 M cells")
    args = parser.parse_args()
    load_before = os.getloadavg()
    if args.full:
        baseline = dam_break()
        coupled = armour_layer(dam_break())
        solids = coupled.solids
        print(f"dam break on {np.prod(DAM_CELLS):,} cells ({' x '.join(map(str, DAM_CELLS))}, "
              f"{DAM_CELL} m), {int((~solids.fixed).sum())} free Core-Loc-like units "
              f"(H = {UNIT_HEIGHT} m, {solids.table.tets.shape[0]:,} tets of both shapes), "
              f"{int(solids.fixed.sum())} fixed toe cubes, dt = {TIME_STEP} s, {args.steps} steps "
              f"x {args.repeats}")
    else:
        baseline = tank(args.cells)
        coupled = spheres(tank(args.cells), args.per_side)
        print(f"{args.cells}^3 = {args.cells ** 3:,} cells, {coupled.solids.n_bodies} moving "
              f"spheres of 8 cells across, dt = {TIME_STEP} s, {args.steps} steps x {args.repeats}")
    (fluid_step, fluid_pressure, _), (coupled_step, coupled_pressure, parts) = measure(
        baseline, coupled, args.steps, args.repeats)
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
    print(f"METRIC coupling_overhead {coupled_step / fluid_step - 1.0:.3f} ratio")


if __name__ == "__main__":
    main()
