"""Rock armour placed as a contractor places it (``riprap.placement.armour_stones``), at a small
size: a double layer of graded stones (D_n50 = 4 cm, D_n85/D_n15 = 1.25, 6 shapes of 2 size
classes) on a 1:2 slope 0.4 m long over a fixed underlayer of 1.8 cm rocks, on a periodic strip
0.2 m wide. What must hold:

- the design: N_a = n k_t (1 - n_v) / D_n50^2 (k_t 0.91, The Rock Manual p. 126; n_v 0.37,
  Shore Protection Manual Table 7-13): 2 x 0.91 x 0.63 / 0.04^2 = 716.6 stones per m^2, by hand;
  the grid holds that many per layer area within a row's rounding;
- after placement every stone rests on the face (none rolled off) and the layer measured as the
  Rock Manual measures one comes out near its design: k_t within 0.6-1.3 of n D_n50 and the
  porosity within 0.2-0.6 (a small patch of a few rows: the band is wide; the figures are
  printed for the reader);
- the same seed places the same layer bit for bit; bad designs are refused naming the key.
"""
import math

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.geometry.rock_grading import RockGrading, rock_library
from riprap.placement import PlacementMaterials, Slope, build_underlayer
from riprap.placement.armour_stones import (StoneLayerDesign, place_armour_stones,
                                            stone_grid)
from riprap.solid.materials import Material

DN50 = 0.04


def _materials():
    rock = Material(name="rock", density=2650.0, friction_coefficient=0.6, restitution=0.3,
                    contact_penalty=1e6)
    face = Material(name="core", density=2650.0, friction_coefficient=0.9, restitution=0.3,
                    contact_penalty=1e6)
    return PlacementMaterials(unit=rock, rock=rock, face=face, side_wall=face)


@pytest.fixture(scope="module")
def placed(tmp_path_factory):
    out = tmp_path_factory.mktemp("stones")
    slope = Slope(cotangent=2.0, width=0.2, length=0.4, toe_stop_distance=0.02, periodic=True)
    materials = _materials()
    run = dict(end_time=1.0, time_step_safety=0.3, rest_speed=0.01, adaptive_time_step=True,
               progress=False, paraview=False, picture=False, output_directory=out)
    rocks = rock_library(RockGrading(dn50=0.018, dn85_over_dn15=1.3), n_shapes=4,
                         n_size_classes=2, seed=3)
    underlayer = build_underlayer(slope, rocks, materials=materials, s_range=(0.0, 0.4),
                                  layers=1, seed=3, **run)
    stones = rock_library(RockGrading(dn50=DN50, dn85_over_dn15=1.25), n_shapes=6,
                          n_size_classes=2, seed=5)
    design = StoneLayerDesign(dn50=DN50)
    first = place_armour_stones(slope, stones, underlayer, materials=materials, design=design,
                                s_range=(0.0, 0.4), seed=11, **run)
    again = place_armour_stones(slope, stones, underlayer, materials=materials, design=design,
                                s_range=(0.0, 0.4), seed=11, **run)
    return slope, design, first, again


def test_the_design_by_hand():
    design = StoneLayerDesign(dn50=DN50)
    assert design.stones_per_area == pytest.approx(2 * 0.91 * 0.63 / 0.04 ** 2, rel=1e-12)
    assert design.stones_per_area == pytest.approx(716.625, rel=1e-9)
    assert design.layer_thickness == pytest.approx(2 * 0.91 * 0.04, rel=1e-12)
    slope = Slope(cotangent=2.0, width=0.4, length=2.0, periodic=True)
    grid = stone_grid(slope, design, (0.0, 2.0), 0)
    per_layer = len(grid) / (0.4 * 2.0)
    assert per_layer == pytest.approx(design.stones_per_area / 2, rel=0.04)
    # a strip 4.5 spacings wide holds 4 stones across (or 5): the rows move closer (or apart)
    # so that a row's share of the face keeps the design's count
    for width in (4.5 * design.spacing, 4.4 * design.spacing, 5.6 * design.spacing):
        strip = Slope(cotangent=2.0, width=width, length=2.0, periodic=True)
        points = stone_grid(strip, design, (0.0, 2.0), 0)
        rows = np.unique(points[:, 0])
        area = width * (rows[-1] - rows[0])
        inner = np.sum((points[:, 0] > rows[0]) & (points[:, 0] < rows[-1]))
        edge = len(points) - inner
        # trapezoid over the rows: half of the first and last rows, all between
        assert (inner + 0.5 * edge) / area == pytest.approx(design.stones_per_area / 2,
                                                            rel=1e-9), width


def test_a_double_layer_rests_on_the_face_near_its_design(placed):
    slope, design, stones, _ = placed
    measured = stones.summary["measured"]
    print(stones.summary)
    assert measured["stones_rolled_off"] == 0
    assert set(np.unique(stones.layer_of_stone)) == {0, 1}
    assert 0.6 < measured["layer_thickness_coefficient"] < 1.3
    assert 0.2 < measured["porosity"] < 0.6
    assert math.isfinite(measured["surface_roughness_over_dn50"])
    runs = stones.summary["runs"]
    assert len(runs) == 2


def test_the_same_seed_places_the_same_layer(placed):
    _, _, first, again = placed
    np.testing.assert_array_equal(first.positions, again.positions)
    np.testing.assert_array_equal(first.quaternions, again.quaternions)


@pytest.mark.parametrize("keys, words", [
    ({"dn50": -0.1}, "dn50 must be a positive"),
    ({"dn50": 0.04, "placement": "careful"}, "placement = 'careful'"),
    ({"dn50": 0.04, "layers": 3}, "3 layer\\(s\\) placed standard has no layer thickness"),
    ({"dn50": 0.04, "porosity": 1.2}, "porosity must lie between 0 and 1"),
    ({"dn50": 0.04, "toe_berm_width": -0.1}, "toe_berm_width must be 0"),
    ({"dn50": 0.04, "toe_berm_width": 0.02}, "holds no stone of D_n50"),
])
def test_bad_designs_are_refused(keys, words):
    with pytest.raises(CaseFileError, match=words):
        StoneLayerDesign(**keys)


def test_a_toe_berm_grid_lies_on_the_bed_in_front_of_the_toe():
    """Berm rows a spacing apart from the toe seaward, within the berm's width, the second layer
    shifted half a spacing; the face's rows unchanged."""
    slope = Slope(cotangent=2.0, width=0.2, length=0.4, toe_x=0.5, toe_stop_distance=0.15,
                  periodic=True)
    plain = StoneLayerDesign(dn50=DN50)
    berm = StoneLayerDesign(dn50=DN50, toe_berm_width=0.12)
    cos = math.cos(slope.angle)
    across = round(slope.width / berm.spacing)
    spacing = berm.spacing ** 2 / (slope.width / across)   # the rows' spacing on this strip
    for layer in (0, 1):
        face = stone_grid(slope, plain, (0.0, 0.4), layer)
        both = stone_grid(slope, berm, (0.0, 0.4), layer)
        np.testing.assert_array_equal(both[both[:, 0] >= 0], face)
        back = -both[both[:, 0] < 0, 0] * cos          # distance seaward of the toe along x
        rows = np.unique(np.round(back, 12))
        # rows at 0.5, 1.5, ... spacings (+ half a spacing on the second layer) while a stone's
        # half D_n50 stays inside the berm
        expected = [0.5 * spacing + k * spacing + 0.5 * spacing * layer for k in range(5)]
        expected = [b for b in expected if b <= 0.12 - 0.5 * DN50]
        np.testing.assert_allclose(rows, expected, rtol=1e-9)
        assert len(back) == across * len(expected)
