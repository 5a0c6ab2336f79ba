"""``SolidSolver.rotation_matrices`` (one compiled call for all bodies) gives every body's
rotation matrix exactly as the per-quaternion kernel does, and they are proper rotations."""
import numpy as np

from riprap.solid.kernels.geometry_ops import rotation_matrices, rotation_matrix


def test_all_bodies_at_once_equal_one_by_one():
    quaternions = np.random.default_rng(7).normal(size=(50, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    matrices = rotation_matrices(quaternions)
    assert np.array_equal(matrices, np.array([rotation_matrix(q) for q in quaternions]))
    assert np.allclose(np.einsum("bij,bkj->bik", matrices, matrices), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(matrices), 1.0, atol=1e-14)
