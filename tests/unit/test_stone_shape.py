"""A stone's length-to-thickness ratio LT and blockiness BLc (``riprap.geometry.stone_shape``)
against solids whose answers are known in closed form:

- a box a x b x c (a > b > c): l = sqrt(a^2 + b^2 + c^2) (the space diagonal), d = c, BLc = 1;
- a regular tetrahedron of edge e: l = e, d = e / sqrt(2) (across two opposite edges, the case
  a face-normal search alone misses: across a face it is e sqrt(2/3)), BLc = 1/3 (its box is
  e / sqrt(2) on every side: e^3 / (6 sqrt 2) over e^3 / (2 sqrt 2));
- a sphere of diameter D (many points on it): l = d = D, BLc = pi/6, within the polyhedron's
  own error (1 % here);
- the measures do not depend on where the stone lies or how it is turned;
- a random rock of riprap's generator stretched 2:1 reads LT near 2 or more.
"""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.errors import CaseFileError
from riprap.geometry.stone_shape import shape_statistics, stone_shape


def _box(a, b, c):
    return np.array([[x, y, z] for x in (0, a) for y in (0, b) for z in (0, c)], dtype=float)


def test_a_box():
    shape = stone_shape(_box(3.0, 2.0, 1.0))
    assert shape.length == pytest.approx(math.sqrt(14.0), rel=1e-12)
    assert shape.thickness == pytest.approx(1.0, rel=1e-12)
    assert sorted(shape.box) == pytest.approx([1.0, 2.0, 3.0], rel=1e-12)
    assert shape.blockiness == pytest.approx(1.0, rel=1e-12)
    assert shape.length_to_thickness == pytest.approx(math.sqrt(14.0), rel=1e-12)


def test_a_regular_tetrahedron_is_thinnest_across_two_edges():
    e = 2.0
    points = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    points *= e / (2.0 * math.sqrt(2.0))           # edge 2 sqrt(2) -> e
    shape = stone_shape(points)
    assert shape.length == pytest.approx(e, rel=1e-12)
    assert shape.thickness == pytest.approx(e / math.sqrt(2.0), rel=1e-12)
    assert shape.blockiness == pytest.approx(1.0 / 3.0, rel=1e-9)


def test_a_sphere():
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(4000, 3))
    points = directions / np.linalg.norm(directions, axis=1)[:, None] * 0.5
    shape = stone_shape(points, volume=math.pi / 6.0)
    assert shape.length == pytest.approx(1.0, rel=1e-3)
    assert shape.thickness == pytest.approx(1.0, rel=1e-2)
    assert shape.blockiness == pytest.approx(math.pi / 6.0, rel=3e-2)


def test_turned_and_moved_stones_measure_the_same():
    points = _box(3.0, 2.0, 1.0) + np.random.default_rng(2).normal(scale=0.05, size=(8, 3))
    points = np.concatenate([points, [[1.5, 1.0, 1.3], [1.4, -0.2, 0.5]]])
    first = stone_shape(points)
    turned = Rotation.from_rotvec([0.3, -1.1, 0.7]).apply(points) + [5.0, -2.0, 1.0]
    second = stone_shape(turned)
    assert second.length == pytest.approx(first.length, rel=1e-10)
    assert second.thickness == pytest.approx(first.thickness, rel=1e-10)
    assert second.blockiness == pytest.approx(first.blockiness, rel=1e-8)


def test_a_stretched_random_rock_and_the_statistics():
    from riprap.geometry.shapes import random_rock

    rocks = [random_rock(size=1.0, elongation=2.0, flatness=1.0, seed=s) for s in range(3)]
    shapes = [stone_shape(r.nodes, volume=float(r.volumes().sum())) for r in rocks]
    assert all(1.9 < s.length_to_thickness < 3.0 for s in shapes)
    stats = shape_statistics(shapes)
    assert stats["stones"] == 3 and stats["share_length_to_thickness_over_3"] == 0.0
    assert 0.3 < stats["blockiness_mean"] < 0.8


def test_bad_input():
    with pytest.raises(CaseFileError, match="needs \\(n, 3\\) points"):
        stone_shape(np.zeros((3, 3)))
    with pytest.raises(CaseFileError, match="span no volume"):
        stone_shape(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float),
                    name="flat")
    with pytest.raises(CaseFileError, match="no stones"):
        shape_statistics([])
