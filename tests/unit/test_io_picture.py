"""Quick-look PNG of bodies: written, of the requested size, and showing shaded, coloured bodies."""

import matplotlib.image
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.io.picture import bodies_to_draw, render_bodies_png

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


# Muted grey of context bodies after shading: channels equal to within this, brightness in this
# band (the Lambert factor is 0.42 to 1 of the 0.6 grey); the panes (0.96), white background and
# black text fall outside, only the antialiased edges of text and lines fall inside.
GREY_CHANNEL_SPREAD = 0.03
GREY_BRIGHTNESS = (0.25, 0.63)
# A body of the octahedra scene covers well over 1 % of a 600 x 600 picture; text edges far less.
MINIMUM_BODY_FRACTION = 0.01


def _grey_fraction(image):
    rgb = image[..., :3]
    flat = (rgb.max(axis=2) - rgb.min(axis=2)) < GREY_CHANNEL_SPREAD
    brightness = rgb.mean(axis=2)
    return float(np.mean(flat & (brightness > GREY_BRIGHTNESS[0])
                         & (brightness < GREY_BRIGHTNESS[1])))


def test_bodies_to_draw_counts_free_and_fixed_bodies_separately():
    fixed = np.array([True, False, False, True, True])
    drawn, grey, text = bodies_to_draw(fixed, show_fixed=True)
    assert drawn.all() and grey.tolist() == fixed.tolist()
    assert text == "2 free bodies, 3 fixed bodies (grey)"
    drawn, grey, text = bodies_to_draw(fixed, show_fixed=False)
    assert drawn.tolist() == (~fixed).tolist() and not grey.any()
    assert text == "2 free bodies (3 fixed bodies not drawn)"
    # A finished underlayer (all fixed) is drawn whole, in colour.
    drawn, grey, text = bodies_to_draw(np.ones(4, dtype=bool), show_fixed=False)
    assert drawn.all() and not grey.any() and text == "4 fixed bodies"


def test_picture_draws_grey_bodies_in_grey_and_others_in_colour(tmp_path):
    # Body 0 fixed (grey), body 1 free (coloured); the same box in both pictures.
    triangles, body_ids = _octahedra(2)
    box = ([-0.06, -0.06, 0.0], [0.18, 0.09, 0.12])
    with_fixed = render_bodies_png(tmp_path / "both.png", triangles_world=triangles,
                                   body_ids=body_ids, grey_bodies=[0], walls_box=box,
                                   size_px=(600, 600))
    free_only = render_bodies_png(tmp_path / "free.png", triangles_world=triangles[body_ids == 1],
                                  body_ids=body_ids[body_ids == 1], walls_box=box,
                                  size_px=(600, 600))
    image, image_free = matplotlib.image.imread(with_fixed), matplotlib.image.imread(free_only)
    assert _grey_fraction(image) - _grey_fraction(image_free) > MINIMUM_BODY_FRACTION
    # The free body keeps its colour, and the grey one takes none of the coloured pixels.
    assert _coloured_fraction(image) > MINIMUM_BODY_FRACTION
    assert abs(_coloured_fraction(image) - _coloured_fraction(image_free)) < MINIMUM_BODY_FRACTION


def test_picture_draws_a_plane_under_the_bodies(tmp_path):
    triangles, body_ids = _octahedra(1)
    plane = np.array([[-0.3, -0.3, 0.0], [0.3, -0.3, 0.0], [0.3, 0.3, 0.0], [-0.3, 0.3, 0.0]])
    with_plane = render_bodies_png(tmp_path / "plane.png", triangles_world=triangles,
                                   body_ids=body_ids, planes=[plane], size_px=(600, 600))
    without = render_bodies_png(tmp_path / "bare.png", triangles_world=triangles,
                                body_ids=body_ids, walls_box=(plane.min(axis=0), plane.max(axis=0)),
                                size_px=(600, 600))

    def sand_fraction(path):
        rgb = matplotlib.image.imread(path)[..., :3]
        # The pale sand of the plane over the light panes: red above blue, no strong colour.
        return float(np.mean((rgb[..., 0] - rgb[..., 2] > 0.05) & (rgb[..., 0] - rgb[..., 2] < 0.2)))

    assert sand_fraction(with_plane) - sand_fraction(without) > 0.1
    with pytest.raises(CaseFileError, match="plane 0"):
        render_bodies_png(tmp_path / "bad.png", triangles_world=triangles, body_ids=body_ids,
                          planes=[plane[:3]])
