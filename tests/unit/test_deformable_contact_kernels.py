"""The parallel evaluation of the deformable contact pairs gives the serial one's forces, friction
springs, potential and area (to round-off: only the order of the sums differs), and the system
takes it from ``PARALLEL_PAIRS`` pairs on."""
import numpy as np

from riprap.deformable import DeformableBody, ElasticMaterial, box_mesh
from riprap.deformable.kernels import contact
from riprap.deformable.kernels.bundles import SurfaceLaws
from riprap.deformable.kernels.finite_strain import PARALLEL_PAIRS
from riprap.deformable.system import DeformableSystem


def _pressed_blocks():
    """Two blocks, the upper sunk 0.2 mm into the lower and sliding across it."""
    material = ElasticMaterial(young_modulus=1e7, density=2000.0, poisson_ratio=0.25)
    nodes, tets = box_mesh((0.2, 0.2, 0.1), (10, 10, 3))
    lower = DeformableBody(nodes, tets, material, name="lower")
    upper = DeformableBody(nodes + (0.01, 0.02, 0.0998), tets, material, name="upper")
    upper.velocities[:] = (0.3, -0.1, -0.05)
    system = DeformableSystem([lower, upper])
    system._list_pairs()
    return system


def _evaluate(system, kernel):
    forces = np.zeros_like(system.positions)
    springs = np.full((len(system._pairs), 3), 1e-6)
    laws = SurfaceLaws(system.contact_penalty, system.tangential_stiffness_ratio,
                       system.triangle_friction, system.tet_friction, system.triangle_damping,
                       system.tet_damping, system.tet_stiffness)
    weight, area = kernel(system.positions, system.triangles, system.contact_tets, system._pairs,
                          forces, system.velocities, system.masses, laws, system.time_step, springs)
    return forces, springs, weight, area


def test_parallel_pairs_give_the_serial_forces():
    system = _pressed_blocks()
    assert len(system._pairs) >= PARALLEL_PAIRS, "enough pairs for the parallel path"
    serial = _evaluate(system, contact.pair_forces)
    parallel = _evaluate(system, contact.pair_forces_parallel)
    scale = np.abs(serial[0]).max()
    assert scale > 0.0 and serial[2] > 0.0, "the blocks touch"
    assert np.allclose(parallel[0], serial[0], rtol=0.0, atol=1e-12 * scale)
    assert np.array_equal(parallel[1], serial[1])          # each pair's spring is its own
    assert np.isclose(parallel[2], serial[2], rtol=1e-12) and np.isclose(parallel[3], serial[3], rtol=1e-12)
