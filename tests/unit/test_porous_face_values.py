"""The porous friction's face values taken at the porous faces only equal the whole-grid means."""
import numpy as np

from riprap.fluid.kernels.porous_faces import face_speeds_and_viscosities
from riprap.fluid.porous import face_means


def test_face_values_at_listed_faces_equal_the_whole_grid_means():
    rng = np.random.default_rng(3)
    shape = (5, 4, 6)
    u = rng.normal(size=(6, 4, 6))
    v = rng.normal(size=(5, 5, 6))
    w = rng.normal(size=(5, 4, 7))
    viscosity = rng.uniform(1e-5, 1e-3, size=shape)
    cell_speed = np.linalg.norm(np.stack([0.5 * (u[1:] + u[:-1]), 0.5 * (v[:, 1:] + v[:, :-1]),
                                          0.5 * (w[:, :, 1:] + w[:, :, :-1])], axis=-1), axis=-1)
    for axis, face_array in enumerate((u, v, w)):
        faces = rng.choice(face_array.size, size=40, replace=False)   # boundary faces among them
        speed, mu = np.empty(40), np.empty(40)
        face_speeds_and_viscosities(u, v, w, viscosity, axis, faces, speed, mu)
        np.testing.assert_allclose(speed, face_means(cell_speed, axis).reshape(-1)[faces], rtol=1e-13)
        np.testing.assert_allclose(mu, face_means(viscosity, axis).reshape(-1)[faces], rtol=1e-13)
