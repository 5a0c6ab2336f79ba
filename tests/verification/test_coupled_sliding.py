"""A body sliding on another keeps what the contact gives it: no drag through the cut faces the two
share (issue 13: contacts act as in dry runs).

A concrete cube (6 cm, 2400 kg/m^3) slides at 0.3 m/s on a fixed frictionless slab, in air, on 1 cm
cells. Their cells share faces, and a face has one velocity: before each body took the momentum of
its faces at that one velocity, the slab's share held the cube back (0.3 -> 0.15 m/s in 0.3 s). Now
each share of a face moves with its own body (``rigid_coupling.own_momentum_rhs``), and the cube
keeps its speed but for the air's drag (about 0.5 rho_air C_d A v^2 / m = 4e-4 m/s^2 here, 1e-4 m/s
in 0.3 s). Tolerance: 1 % of the speed after 0.3 s (measured: 0.2995 m/s).
"""
import numpy as np

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

SPEED = 0.3
TOLERANCE = 0.01


def test_a_cube_slides_on_a_fixed_frictionless_slab_without_drag():
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.4, 0.2, 0.2), cells=(40, 20, 20))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.005)
    solids = SolidSolver(gravity=fluid.gravity)
    cube = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=0.06, mesh_size=0.03)))
    slab = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(0.36, 0.16, 0.043),
                                                            mesh_size=0.03)))
    solids.add_material(Material(name="concrete", density=2400.0, restitution=0.1,
                                 friction_coefficient=0.0, contact_penalty=1.0e8))
    solids.add_body(shape=slab, material="concrete", position=(0.2, 0.1, 0.0215), fixed=True)
    solids.add_body(shape=cube, material="concrete", position=(0.1, 0.1, 0.0735),
                    velocity=(SPEED, 0.0, 0.0))
    coupled = CoupledSolver(fluid, solids)
    while fluid.time < 0.3:
        coupled.step()
    assert len(solids.contacts) >= 1, "the cube rests on the slab"
    assert abs(solids.velocities[1, 0] - SPEED) < TOLERANCE * SPEED
    assert np.all(np.isfinite(coupled.fixed_body_loads))
