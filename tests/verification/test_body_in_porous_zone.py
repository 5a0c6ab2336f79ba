"""A body inside a porous zone feels the whole pressure on its surface (issue 15: armour on a
porous core).

Source: Archimedes. A box of the water's own density, fully submerged in still water inside a
porous zone (porosity 0.4, the olaFlow defaults: the zone scales the pore water's pressure
coefficient and its predictor, gravity included, by n / (1 + c) = 0.30), must be held up by the
full buoyancy rho g V and stay where it is. In a porous zone only the fluid's share of a face moves
through the pores; a body's share takes the pressure's impulse in full (the coupling's
``_porous_factors``). Scaling the coefficient of the whole face by the zone's factor but not the
gravity the predictor took off the pore water (a half-made version of this) made the box feel
1.28 rho g V in the first step and rise at 0.12 m/s. (Scaling both for the whole face, as before,
balances at rest too, but gives a body only 0.30 of the pressure's dynamic part.) Tolerances: the
fluid's vertical load on the box within ``BUOYANCY_TOLERANCE`` = 2 % of rho g V after 0.3 s
(measured to 1e-4), its speed below 1 mm/s (measured 0).
"""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.fluid.porous import PorousZone
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

BUOYANCY_TOLERANCE = 0.02
SIDE = 0.15       # m, the box
CELLS = 24        # 2.5 cm cubes in a 0.6 m tank: 6 across the box


def test_a_neutral_box_in_a_porous_core_floats_where_it_is():
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.6, 0.6, 0.6), cells=(CELLS, CELLS, CELLS))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.5)
    fluid.add_porous_zones([PorousZone(porosity=0.4, stone_diameter=0.02, lower=(0.0, 0.0, 0.0),
                                       upper=(0.6, 0.6, 0.4), name="core")])
    solids = SolidSolver(gravity=fluid.gravity)
    shape = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(SIDE, SIDE, SIDE))))
    solids.add_material(Material(name="neutral", density=fluid.water.density, contact_penalty=1e8))
    solids.add_body(shape=shape, material="neutral", position=(0.3, 0.3, 0.2))
    coupled = CoupledSolver(fluid, solids)
    while fluid.time < 0.3 - 1e-9:
        coupled.step(0.005)
    weight = fluid.water.density * 9.81 * SIDE ** 3
    assert coupled.fluid_loads[0, 2] == pytest.approx(weight, rel=BUOYANCY_TOLERANCE)
    assert np.linalg.norm(solids.velocities[0]) < 1e-3
