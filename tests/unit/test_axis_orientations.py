"""Axis orientations on the lower-hemisphere equal-area net, against positions worked out by hand
(r = sqrt(2) sin((90 deg - plunge) / 2) in the direction of the trend, x east, y north)."""
import numpy as np
import pytest

from riprap.analysis.orientations import equal_area_points, trend_plunge


def test_vertical_and_horizontal_axes():
    points = equal_area_points([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    assert np.allclose(points, [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]], atol=1e-12)


def test_an_axis_and_its_opposite_are_the_same_point():
    axis = np.array([0.3, -0.5, 0.8])
    assert np.allclose(equal_area_points(axis), equal_area_points(-axis), atol=1e-12)


def test_a_known_axis_plots_at_its_known_place():
    # Pointing down to the south-east at 30 degrees below the horizontal.
    plunge, trend = np.radians(30.0), np.radians(135.0)
    axis = [np.cos(plunge) * np.sin(trend), np.cos(plunge) * np.cos(trend), -np.sin(plunge)]
    t, p = trend_plunge(axis)
    assert t[0] == pytest.approx(135.0) and p[0] == pytest.approx(30.0)
    r = np.sqrt(2.0) * np.sin(np.radians(30.0))          # theta = 60 deg from the vertical
    assert np.allclose(equal_area_points(axis), [[r * np.sin(trend), r * np.cos(trend)]], atol=1e-12)


def test_equal_areas_of_the_hemisphere_take_equal_areas_of_the_net():
    # Axes uniform on the sphere fill the unit disc uniformly: half of them within r = 1/sqrt(2).
    rng = np.random.default_rng(4)
    axes = rng.normal(size=(200_000, 3))
    radius = np.linalg.norm(equal_area_points(axes), axis=1)
    assert radius.max() <= 1.0 + 1e-12
    assert np.mean(radius < np.sqrt(0.5)) == pytest.approx(0.5, abs=0.005)


def test_a_zero_axis_is_refused():
    with pytest.raises(ValueError, match="zero"):
        trend_plunge([0.0, 0.0, 0.0])
