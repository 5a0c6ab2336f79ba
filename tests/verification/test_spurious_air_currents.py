"""The air above a moving water surface moves with it, no faster (issue 15: the flume's time step).

Source: linear two-layer potential flow (Lamb 1932, Hydrodynamics, art. 231): in a small sloshing
the velocity potential of the air above the interface is the water's mirrored, so at the surface the
air moves at the water's speed and more slowly above it. Before the pressure saw sharp face
densities (``riprap/fluid/kernels/sharp_density.py``) the air just above a 5 mm/s slosh on 5 cm
cells accelerated without bound (0.2 m/s after 0.2 s, still growing), and beside a resting concrete
box that pierces the surface, whose slivers on the air faces tripled their density, it reached
0.47 m/s in 0.5 s while the water moved at 6 mm/s. Tolerance: the air at most
``AIR_OVER_WATER`` times the water's largest speed over the run (measured 1.06 for the slosh, 1.05
beside the box, whose settling onto the floor in the first steps stirs both at 8 cm/s), and at the
end, the box at rest, the air beside it below 3 cm/s (measured 1.2 cm/s, the water 0.5 cm/s).
"""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

AIR_OVER_WATER = 3.0
CELLS = 20            # 5 cm cubes in a 1 m tank
STILL_WATER = 0.2     # m
STEPS = 100
DT = 0.005            # s


def _tank() -> FluidSolver:
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 1.0, 1.0), cells=(CELLS, CELLS, CELLS))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(STILL_WATER)
    return fluid


def _largest_speeds(fluid) -> tuple:
    speed = np.linalg.norm(fluid.cell_velocity(), axis=-1)
    water = fluid.fraction > 0.5
    return float(speed[water].max()), float(speed[~water].max())


def _run(step, fluid) -> tuple:
    water_max = air_max = 0.0
    for _ in range(STEPS):
        step(DT)
        water, air = _largest_speeds(fluid)
        water_max, air_max = max(water_max, water), max(air_max, air)
    return water_max, air_max


def test_the_air_above_a_slosh_moves_no_faster_than_the_water():
    fluid = _tank()
    # a gentle sloshing: x-velocity of 6 mm/s amplitude in the water, made divergence free by the
    # first projection
    wet_faces = np.zeros_like(fluid.u, dtype=bool)
    wet_faces[1:-1] = (fluid.fraction[1:] > 0.5) & (fluid.fraction[:-1] > 0.5)
    x = fluid.grid.faces(0)
    fluid.u[:] = np.where(wet_faces, 0.006 * np.sin(np.pi * x)[:, None, None], 0.0)
    water, air = _run(fluid.step, fluid)
    assert water > 0.003
    assert air < AIR_OVER_WATER * water


@pytest.mark.parametrize("fixed", [False, True])
def test_the_air_beside_a_resting_concrete_box_stays_still(fixed):
    fluid = _tank()
    solids = SolidSolver(gravity=fluid.gravity)
    shape = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(0.3, 0.3, 0.3))))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1e8))
    # 0.5 mm above the floor: it settles onto it in the first steps (a free one), then rests
    solids.add_body(shape=shape, material="concrete", position=(0.5, 0.5, 0.1505), fixed=fixed)
    solids.add_walls(walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="concrete"))
    coupled = CoupledSolver(fluid, solids)
    water, air = _run(coupled.step, fluid)
    if fixed:
        assert water < 1e-6 and air < 1e-6
    else:
        assert air < AIR_OVER_WATER * water
        # once it rests (0.5 s), the air beside it
        assert _largest_speeds(fluid)[1] < 0.03
        assert np.linalg.norm(solids.velocities[0]) < 1e-4
