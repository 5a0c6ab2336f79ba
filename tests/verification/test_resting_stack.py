"""A stack of three cubes on a plane stays at rest.

Source: statics. Three 1 m concrete cubes (2400 kg/m^3, ~310 tets each, friction 0.6, restitution
0.5, penalty 1e8 Pa) are stacked with small offsets (2-3 cm) and yaws (2-3 degrees), so the
contacts are face-on-face but not mirror images of each other; every centroid lies above the
supporting face, so the exact solution is rest. The stack is released 1 mm apart, settled for
0.5 s with ``local_damping`` = 0.3, then run for 2 s with ``local_damping`` = 0 (only contact damping
and friction act). Automatic time step (1.4e-4 s; 1 m cubes keep the run short).

Quantities and tolerances (absolute):

- creep: no centroid moves by more than ``CREEP_TOLERANCE`` = 1e-5 m over the 2 s. The contacts'
  static overlaps are 0.7-1.9e-5 m (weight / stiffness); a stack at rest can only breathe by a
  fraction of that as the last settling vibration decays, it has no reason to drift.
- kinetic energy: it never exceeds its value at the end of settling by more than
  ``ENERGY_GROWTH_TOLERANCE`` = 1 % (contacts with damping must not pump energy), and stays below
  ``KINETIC_ENERGY_FRACTION`` = 1e-8 of the stack's potential energy m g z (1.06e5 J), i.e. about
  1 mJ: nothing visible moves.
"""
import numpy as np
import pytest

from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

CREEP_TOLERANCE = 1e-5            # m; below the static overlaps (0.7-1.9e-5 m)
ENERGY_GROWTH_TOLERANCE = 0.01    # relative to the energy left after settling
KINETIC_ENERGY_FRACTION = 1e-8    # of the potential energy m g z of the stack
SIDE = 1.0
GAP = 1e-3
SETTLE_TIME = 0.5
REST_TIME = 2.0
N_SAMPLES = 8
# (x offset m, y offset m, yaw degrees) of the bottom, middle and top cube
LAYOUT = [(0.0, 0.0, 0.0), (0.03, -0.02, 3.0), (-0.02, 0.03, -2.0)]


@pytest.fixture(scope="module")
def settled_stack():
    solver = SolidSolver(gravity=(0.0, 0.0, -9.81), local_damping=0.3)
    k = solver.add_shape(RigidShape.from_mesh(shapes.cube(side=SIDE, mesh_size=0.4 * SIDE)))
    m = solver.add_material(Material(name="concrete", density=2400.0, friction_coefficient=0.6,
                                     restitution=0.5, contact_penalty=1.0e8))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                                 material="concrete"))
    for level, (dx, dy, yaw) in enumerate(LAYOUT):
        half = 0.5 * np.radians(yaw)
        solver.add_body(shape=k, material=m, orientation=(np.cos(half), 0.0, 0.0, np.sin(half)),
                        position=(dx, dy, 0.5 * SIDE + level * (SIDE + GAP) + GAP))
    solver.finalize()
    solver.advance(int(round(SETTLE_TIME / solver.time_step)))
    return solver


def test_stack_does_not_creep_or_gain_energy(settled_stack):
    solver = settled_stack
    assert len(solver.contacts) == 3   # plane-bottom, bottom-middle, middle-top
    solver.local_damping = 0.0
    start = solver.positions.copy()
    energy_settled = solver.kinetic_energy()
    potential = solver.potential_energy()
    energies, displacements = [], []
    for _ in range(N_SAMPLES):
        solver.advance(int(round(REST_TIME / N_SAMPLES / solver.time_step)))
        energies.append(solver.kinetic_energy())
        displacements.append(np.linalg.norm(solver.positions - start, axis=1).max())
    assert max(energies) <= (1.0 + ENERGY_GROWTH_TOLERANCE) * energy_settled
    assert max(energies) <= KINETIC_ENERGY_FRACTION * potential
    assert len(solver.contacts) == 3
    assert max(displacements) <= CREEP_TOLERANCE
