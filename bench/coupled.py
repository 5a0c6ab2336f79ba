"""Cost of two-way coupling: the fluid step with bodies in it against the same fluid without them.

A tank (default 64 x 64 x 64 cells, 0.8 m, water 0.6 m deep) with a grid of moving spheres (default
4 x 4 x 2, D = 8 cells) falling into the water; the same water without bodies as the baseline. Both
take the same fixed time step. Prints the time per step of each, the coupled step's parts (solid
volumes, coupling kernels and projection, contact sub-steps) and, last line,
``METRIC coupling_overhead <coupled step / fluid step - 1> ratio`` (issue 13's target: at most 0.5).

    python bench/coupled.py [cells] [spheres per side] [steps]

Not yet the issue's full case (the small placed layer in a dam-break wave on about 1 M cells).
"""
import sys
import time

import numpy as np

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
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


def timed(step, n):
    step()                                   # compile and first step outside the timing
    started = time.perf_counter()
    for _ in range(n):
        step()
    return (time.perf_counter() - started) / n


def main(cells=64, per_side=4, steps=20):
    baseline = tank(cells)
    fluid_step = timed(lambda: baseline.step(TIME_STEP), steps)
    coupled = spheres(tank(cells), per_side)
    parts = {"solid volumes": 0.0, "contact sub-steps": 0.0}
    clip, advance = coupled._solid_volumes, coupled._advance_solids

    def clip_timed():
        started = time.perf_counter()
        result = clip()
        parts["solid volumes"] += time.perf_counter() - started
        return result

    def advance_timed(dt):
        started = time.perf_counter()
        result = advance(dt)
        parts["contact sub-steps"] += time.perf_counter() - started
        return result

    coupled._solid_volumes, coupled._advance_solids = clip_timed, advance_timed
    coupled_step = timed(lambda: coupled.step(TIME_STEP), steps)
    for key in parts:
        parts[key] /= steps + 1
    bodies = coupled.solids.n_bodies
    print(f"{cells}^3 = {cells ** 3:,} cells, {bodies} moving spheres of 8 cells across, "
          f"dt = {TIME_STEP} s, {steps} steps")
    print(f"fluid only: {fluid_step * 1e3:.1f} ms/step; with the bodies: {coupled_step * 1e3:.1f} "
          f"ms/step")
    rest = coupled_step - sum(parts.values()) - fluid_step
    for key, value in parts.items():
        print(f"  {key}: {value * 1e3:.1f} ms/step")
    print(f"  coupling kernels, blends and the mixture projection beyond the fluid's: "
          f"{rest * 1e3:.1f} ms/step")
    print(f"largest body speed {np.linalg.norm(coupled.solids.velocities, axis=1).max():.3f} m/s")
    print(f"METRIC coupling_overhead {coupled_step / fluid_step - 1.0:.3f} ratio")


if __name__ == "__main__":
    main(*[int(a) for a in sys.argv[1:]])
