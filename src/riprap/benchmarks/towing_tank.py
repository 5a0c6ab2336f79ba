"""A towing tank: a cube carried face-on at a constant speed through water at rest, the way a
laboratory tows a model (by Galileo the same as a cube held in a uniform current). No gravity,
free-slip walls; the tank is ``LENGTH`` D long and ``WIDTH`` D square (blockage 1 / WIDTH^2 of the
section). Used by ``bench/unit_loads.py`` and ``tests/verification/test_cut_face_loads.py``
(docs/coupling.md, Cut faces and the step).
"""
from __future__ import annotations

import numpy as np

from riprap.coupling.coupled import CoupledSolver
from riprap.fluid.grid import FluidGrid
from riprap.fluid.solver import FluidSolver
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

__all__ = ["towing_tank", "tow", "LENGTH", "WIDTH", "START"]

LENGTH, WIDTH = 16.0, 6.0     # in D
START = 3.0                   # in D: the cube's centre at the start


def towing_tank(side: float, speed: float, cells_per_side: float, *, cut_faces: str = "own_velocity",
                check_momentum: bool = False) -> CoupledSolver:
    """The tank and the cube (concrete, 2400 kg/m^3) moving at ``speed`` (m/s) along x, its
    faces off the cell faces by a little so that none lies on one."""
    h = side / cells_per_side
    cells = tuple(int(round(n * cells_per_side)) for n in (LENGTH, WIDTH, WIDTH))
    upper = tuple(n * h for n in cells)
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=upper, cells=cells,
                     boundaries={where: "free_slip" for where in
                                 ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high")})
    fluid = FluidSolver(grid, surface_tension=0.0, gravity=(0.0, 0.0, 0.0), max_time_step=1.0)
    fluid.set_still_water_level(upper[2])
    solids = SolidSolver(gravity=(0.0, 0.0, 0.0))
    shape = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(side,) * 3,
                                                             mesh_size=side / 2)))
    solids.add_material(Material(name="concrete", density=2400.0, restitution=0.5,
                                 contact_penalty=1e7))
    solids.add_body(shape=shape, material="concrete",
                    position=(START * side, upper[1] / 2 + 0.1234 * h, upper[2] / 2 + 0.0567 * h),
                    velocity=(speed, 0.0, 0.0))
    return CoupledSolver(fluid, solids, cut_faces=cut_faces, check_momentum=check_momentum)


def tow(coupled: CoupledSolver, side: float, speed: float, dt: float, distance: float):
    """Carry the cube ``distance`` D at ``speed`` in steps of ``dt``: (travel in D, the drag in N)
    at every step. The carriage holds the cube's speed and keeps it from turning."""
    solids = coupled.solids
    start = solids.positions[0, 0]
    travel, drag = [], []
    while solids.positions[0, 0] <= start + distance * side:
        coupled.step(dt)
        travel.append((solids.positions[0, 0] - start) / side)
        drag.append(-coupled.fluid_loads[0, 0])
        solids.velocities[0] = (speed, 0.0, 0.0)
        solids.angular_momenta[0] = 0.0
        solids.quaternions[0] = (1.0, 0.0, 0.0, 0.0)
    return np.array(travel), np.array(drag)
