"""The wall inside a cut face (``rigid_coupling.wall_geometry``) and the grip it sets
(``rigid_coupling.cut_face_grip``), against plane geometry worked by hand.

A plane that cuts a face's control volume (a cube of side h) leaving the fluid the share 1 - phi:
- normal to an axis, the wall's area is h^2 and the fluid is a slab of thickness (1 - phi) h,
  its mean distance from the wall (1 - phi) h / 2;
- at 45 degrees in a coordinate plane through the cube's centre (phi = 1/2), the wall is a
  rectangle h by sqrt(2) h and the fluid a prism of right isosceles triangles of height
  sqrt(2) h / 2, whose mean distance from the hypotenuse is a third of the height, sqrt(2) h / 6.
The formulas take an axis-aligned normal as tilted by ``_NORMAL_FLOOR``: 1e-5 of a cell here.
"""
import numpy as np
import pytest

from riprap.coupling.kernels import rigid_coupling

EXACT = 1e-5


def _geometry(on_x, index, phi, bodies=1):
    on_y, on_z = np.zeros((1, 1, 1)), np.zeros((1, 1, 1))
    area, distance = np.empty(1), np.empty(1)
    rigid_coupling.wall_geometry(np.array([0]), np.array([index]), np.array([phi]),
                                 np.array([bodies]), on_x, on_y, on_z, area, distance)
    return area[0], distance[0]


@pytest.mark.parametrize("phi", [0.1, 0.25, 0.5, 0.75, 0.9])
def test_a_wall_normal_to_an_axis_is_a_whole_face_and_the_fluid_a_slab(phi):
    on_x = np.zeros((5, 3, 3))
    on_x[3:] = 1.0
    on_x[2] = phi
    area, distance = _geometry(on_x, (2, 1, 1), phi)
    assert area == pytest.approx(1.0, abs=EXACT)
    assert distance == pytest.approx((1.0 - phi) / 2.0, abs=EXACT)


def test_a_wall_at_45_degrees_through_the_centre():
    on_x = np.zeros((5, 4, 3))
    on_x[2, 1, 1] = 0.5
    on_x[3, 1, 1] = 1.0      # solid towards +x and +y
    on_x[2, 2, 1] = 1.0
    area, distance = _geometry(on_x, (2, 1, 1), 0.5)
    assert area == pytest.approx(np.sqrt(2.0), rel=1e-3)
    assert distance == pytest.approx(np.sqrt(2.0) / 6.0, rel=1e-3)


def test_a_film_between_two_bodies_is_left_to_the_film_rule():
    on_x = np.zeros((5, 3, 3))
    on_x[3:] = 1.0
    on_x[2] = 0.5
    area, _ = _geometry(on_x, (2, 1, 1), 0.5, bodies=2)
    assert area == -1.0


def _grip(phi, dt, area, distance, slip=0.1):
    out = np.empty(1)
    rigid_coupling.cut_face_grip(np.array([phi]), np.array([slip]), np.array([0.0]),
                                 np.array([1000.0]), 1000.0, 1e-3, 1.2, 1.8e-5, 0.01, dt, 2.0,
                                 np.array([area]), np.array([distance]), out)
    return out[0] * phi       # alpha


@pytest.mark.parametrize("area, distance", [(1.0, 0.25), (-1.0, 0.0)])
def test_the_grip_is_a_rate_not_a_fraction_per_step(area, distance):
    """Two steps of dt / 2 leave the fluid what one step of dt leaves it: (1 - alpha) multiplies."""
    phi, dt = 0.5, 2e-3
    whole = 1.0 - _grip(phi, dt, area, distance)
    halves = (1.0 - _grip(phi, dt / 2, area, distance)) ** 2
    assert halves == pytest.approx(whole, rel=1e-12)
    assert 0.0 < whole < 1.0


def test_the_wall_s_shear_is_that_of_a_film_at_its_mean_distance():
    """Still fluid (no flow through the face), a slab of thickness d at mean distance d / 2:
    the shear mu u / (d / 2) over the area h^2 slows it at 2 nu / d^2 per second."""
    phi, dt, h, nu = 0.5, 1e-3, 0.01, 1e-6
    alpha = _grip(phi, dt, 1.0, 0.25, slip=0.0)
    d = (1.0 - phi) * h
    assert 1.0 - alpha == pytest.approx(np.exp(-2.0 * nu / d ** 2 * dt), rel=1e-12)
