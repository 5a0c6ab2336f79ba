"""Factor of safety against sliding of a cube resting on an inclined plane (riprap.analysis).

Source: statics of a block on a plane inclined at theta with Coulomb friction mu > tan theta: the
plane carries N = W cos theta and T = W sin theta, so FoS = mu N / T = mu / tan theta (the issue's
"simple case"). Case: a 1 m concrete cube on a plane at 20 degrees, mu = 0.6 (FoS 1.648), settled
for 0.5 s with local damping 0.3. Tolerance: ``FOS_TOLERANCE`` = 1 % (the tangential spring force
of the settled block equals the downslope weight to within its last vibration).
"""
import numpy as np
import pytest

from riprap.analysis import sliding_factor_of_safety
from riprap.geometry import shapes
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

FOS_TOLERANCE = 0.01
THETA = np.radians(20.0)
MU = 0.6


def test_block_on_a_slope_has_factor_of_safety_mu_over_tan_theta():
    solver = SolidSolver(gravity=(0.0, 0.0, -9.81), local_damping=0.3)
    k = solver.add_shape(RigidShape.from_mesh(shapes.cube(side=1.0, mesh_size=0.4)))
    m = solver.add_material(Material(name="concrete", density=2400.0, friction_coefficient=MU,
                                     restitution=0.5, contact_penalty=1.0e8))
    normal = np.array([-np.sin(THETA), 0.0, np.cos(THETA)])
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=tuple(normal), material="concrete"))
    half = 0.5 * THETA        # the cube turned to lie flat on the plane (about -y)
    solver.add_body(shape=k, material=m, orientation=(np.cos(half), 0.0, -np.sin(half), 0.0),
                    position=tuple(0.501 * normal))
    solver.finalize()
    solver.advance(int(round(0.5 / solver.time_step)))
    assert np.linalg.norm(solver.velocities[0]) < 1e-3          # it rests, it does not slide
    fos = sliding_factor_of_safety(solver.n_bodies, solver.contacts, MU)
    assert fos[0] == pytest.approx(MU / np.tan(THETA), rel=FOS_TOLERANCE)
