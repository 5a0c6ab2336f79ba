"""A floating cube: a cube of half water's density released at rest above its floating position in a
closed-sided tank heaves and comes to rest with half its height under water (Archimedes). Used by
``bench/floating_box.py`` and ``tests/verification/test_floating_box.py``.

The draught is measured from the free surface away from the cube (the mean water height of the
columns of cells more than a cube's width from its centre): in the one-fluid model the water
fraction inside a body belongs to the mixture, not to the tank, so the total water volume over the
tank's area does not give the level.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

__all__ = ["FloatingBoxRun", "run_floating_box"]

TANK = 0.4
CUBE = 0.1
LEVEL = 0.25
DENSITY_RATIO = 0.5


@dataclass
class FloatingBoxRun:
    """Times (s) and the cube's centre height (m) at every step; the free surface away from the
    cube at the end (m); the Archimedes draught (m); the water volume error; wall seconds."""

    times: np.ndarray
    heights: np.ndarray
    level: float
    archimedes_draught: float
    water_volume_error: float
    wall_time: float
    cells_across_cube: float

    def draught(self, since: float) -> float:
        """Mean draught (m) over the steps after ``since`` (s), from the final free surface."""
        return self.level - (float(np.mean(self.heights[self.times > since])) - CUBE / 2)


def run_floating_box(cells: int = 32, seconds: float = 3.0, start_above: float = 0.02) -> FloatingBoxRun:
    """The cube (``CUBE`` m, ``DENSITY_RATIO`` of water's density) in a ``TANK`` m tank of
    ``cells``^3 cells, water ``LEVEL`` m deep, released with its centre ``start_above`` m above
    the level, run for ``seconds``."""
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(TANK,) * 3, cells=(cells,) * 3)
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(LEVEL)
    solids = SolidSolver(gravity=fluid.gravity)
    shape = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(CUBE,) * 3)))
    solids.add_material(Material(name="wood", density=DENSITY_RATIO * fluid.water.density,
                                 contact_penalty=1.0e6))
    solids.add_body(shape=shape, material="wood",
                    position=(TANK / 2, TANK / 2, LEVEL + start_above))
    coupled = CoupledSolver(fluid, solids)
    started = time.perf_counter()
    times, heights = [], []
    while coupled.time < seconds:
        coupled.step()
        times.append(coupled.time)
        heights.append(float(solids.positions[0, 2]))
    h = fluid.h
    centres = (np.arange(cells) + 0.5) * h
    far = np.maximum(np.abs(centres[:, None] - solids.positions[0, 0]),
                     np.abs(centres[None, :] - solids.positions[0, 1])) > CUBE
    level = float(np.mean(fluid.fraction.sum(axis=2)[far]) * h)
    return FloatingBoxRun(times=np.array(times), heights=np.array(heights), level=level,
                          archimedes_draught=DENSITY_RATIO * CUBE,
                          water_volume_error=float(coupled.last_report.water_volume_error),
                          wall_time=time.perf_counter() - started,
                          cells_across_cube=CUBE / h)
