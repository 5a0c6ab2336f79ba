"""Quick-look PNG of bodies: written, of the requested size, and showing shaded, coloured bodies."""

import matplotlib.image
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.io.picture import render_bodies_png

# A blank or near-blank 1400 x 1000 PNG compresses to a few kB; a picture of shaded bodies with
# axes and labels is several tens of kB.
MINIMUM_PNG_BYTES = 10_000
# Pixel standard deviation (RGB in [0, 1]) of a single-colour image is 0; a picture with shaded
# bodies on a light background is well above this.
MINIMUM_PIXEL_STANDARD_DEVIATION = 0.05
# Fraction of pixels that must be neither the white background nor grey axes: the bodies must
# take a visible share of the picture, not a speck in a corner.
MINIMUM_COLOURED_FRACTION = 0.05


def _octahedra(count):
    """Boundary triangles of `count` octahedra in a row, shape (8 * count, 3, 3), and body ids."""
    vertices = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
                        dtype=float) * 0.05
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                      [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    triangles = np.concatenate(
        [vertices[faces] + np.array([0.12 * k, 0.03 * (k % 2), 0.05]) for k in range(count)]
    )
    return triangles, np.repeat(np.arange(count), len(faces))


def _coloured_fraction(image):
    rgb = image[..., :3]
    saturation = rgb.max(axis=2) - rgb.min(axis=2)
    return float(np.mean(saturation > 0.1))


def test_picture_with_one_colour_per_body(tmp_path):
    triangles, body_ids = _octahedra(5)
    path = render_bodies_png(tmp_path / "bodies.png", triangles_world=triangles,
                             body_ids=body_ids, title="five octahedra",
                             walls_box=([-0.06, -0.06, 0.0], [0.55, 0.09, 0.12]),
                             size_px=(1400, 1000))
    assert path.stat().st_size > MINIMUM_PNG_BYTES
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (1000, 1400)
    assert image[..., :3].std() > MINIMUM_PIXEL_STANDARD_DEVIATION
    assert _coloured_fraction(image) > MINIMUM_COLOURED_FRACTION
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bodies.png"]


def test_picture_coloured_by_value_per_body(tmp_path):
    triangles, body_ids = _octahedra(4)
    path = render_bodies_png(tmp_path / "forces.png", triangles_world=list(np.split(triangles, 4)),
                             body_ids=body_ids, values=np.array([0.0, 10.0, 20.0, 30.0]),
                             value_label="maximum contact force (N)", size_px=(900, 700))
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (700, 900)
    assert path.stat().st_size > MINIMUM_PNG_BYTES
    assert image[..., :3].std() > MINIMUM_PIXEL_STANDARD_DEVIATION
    assert _coloured_fraction(image) > MINIMUM_COLOURED_FRACTION


def test_picture_faces_are_shaded_not_flat(tmp_path):
    # One body in one colour: if shading works, its faces show several distinct brightnesses.
    triangles, body_ids = _octahedra(1)
    path = render_bodies_png(tmp_path / "one.png", triangles_world=triangles, body_ids=body_ids,
                             size_px=(600, 600))
    image = matplotlib.image.imread(path)[..., :3]
    coloured = image[(image.max(axis=2) - image.min(axis=2)) > 0.1]
    brightness_levels = np.unique(np.round(coloured.sum(axis=1), 1))
    assert len(brightness_levels) >= 3


def test_picture_rejects_values_shorter_than_body_count(tmp_path):
    triangles, body_ids = _octahedra(3)
    with pytest.raises(CaseFileError, match="values"):
        render_bodies_png(tmp_path / "bad.png", triangles_world=triangles, body_ids=body_ids,
                          values=np.array([1.0, 2.0]))
    assert not list(tmp_path.iterdir())


def test_picture_rejects_mismatched_body_ids(tmp_path):
    triangles, body_ids = _octahedra(2)
    with pytest.raises(CaseFileError, match="body_ids"):
        render_bodies_png(tmp_path / "bad.png", triangles_world=triangles, body_ids=body_ids[:-1])
