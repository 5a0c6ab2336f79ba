"""Slope frame, design grids and layer figures on arrangements whose answers are known by hand."""
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.placement import Slope, design_grid
from riprap.placement import layer_metrics


def test_slope_coordinates_round_trip_and_frame():
    slope = Slope(cotangent=1.5, width=3.0, length=10.0, toe_x=2.0, toe_level=-1.0)
    assert slope.angle_deg == pytest.approx(np.degrees(np.arctan(1 / 1.5)), abs=1e-12)
    assert slope.tangent @ slope.normal == pytest.approx(0.0, abs=1e-15)
    assert slope.crest_level == pytest.approx(-1.0 + 10.0 / np.sqrt(1 + 1.5 ** 2), rel=1e-12)
    rng = np.random.default_rng(0)
    points = rng.uniform(-5, 5, size=(20, 3))
    back = slope.to_world(*slope.to_slope(points).T)
    assert np.allclose(back, points, atol=1e-12)
    # A point on the face has h = 0; the toe is s = 0.
    on_face = slope.to_world(4.0, 1.0, 0.0)
    assert on_face[2] == pytest.approx(-1.0 + 4.0 * np.sin(slope.angle), abs=1e-12)


def test_slope_walls_point_into_the_free_space():
    slope = Slope(cotangent=2.0, width=1.0, length=5.0)
    walls = slope.walls(face_material="core", side_material="glass")
    assert len(walls) == 4
    free_point = slope.to_world(2.0, 0.5, 0.3)
    for wall in walls:
        assert (free_point - np.asarray(wall.point)) @ np.asarray(wall.normal) > 0


def test_bad_slope_is_refused():
    with pytest.raises(CaseFileError, match="cotangent"):
        Slope(cotangent=0.3, width=1.0, length=1.0)
    with pytest.raises(CaseFileError, match="width"):
        Slope(cotangent=1.5, width=-1.0, length=1.0)


def test_design_grid_has_the_target_packing_density():
    slope = Slope(cotangent=1.33, width=12.0, length=60.0)
    dn = 1.2
    grid = design_grid(slope, nominal_diameter=dn, rows=21, units_per_row=(12, 11),
                       packing_density_coefficient=0.62, first_row_s=1.0, centroid_height=0.8,
                       drop_height=2.0)
    assert len(grid.positions) == 11 * 12 + 10 * 11 == 242          # the seed paper's layer
    assert grid.horizontal_spacing == pytest.approx(1.0)
    # Every pair of rows holds 12 + 11 units on 2 dy x width of face: phi = N Dn^2 / A.
    assert 23 * dn ** 2 / (2 * grid.upslope_spacing * slope.width) == pytest.approx(0.62)
    # ... and so does the whole grid, each row owning one row spacing of face.
    assert 242 * dn ** 2 / (21 * grid.upslope_spacing * slope.width) == pytest.approx(0.62, rel=0.01)
    assert np.allclose(grid.slope_coordinates[:, 2], 0.8)
    # The units start straight above their design centroids.
    design = slope.to_world(*grid.slope_coordinates.T)
    assert np.allclose(grid.positions - design, [0.0, 0.0, 2.0])
    assert grid.slope_coordinates[:, 1].min() == pytest.approx(0.5)
    assert grid.slope_coordinates[:, 1].max() == pytest.approx(11.5)


def test_design_grid_longer_than_the_face_is_refused():
    slope = Slope(cotangent=1.5, width=2.0, length=3.0)
    with pytest.raises(CaseFileError, match="beyond its length"):
        design_grid(slope, nominal_diameter=1.0, rows=10, units_per_row=2,
                    packing_density_coefficient=0.6, first_row_s=0.5, centroid_height=1.0)


def test_layer_figures_of_a_perfect_tiling_of_cubes():
    """Cubes of side a tiling the face in rows: phi = 1, porosity 0, thickness a (by hand)."""
    slope = Slope(cotangent=1.5, width=4.0, length=20.0)
    a = 0.5
    corners = np.array([[x, y, z] for x in (-a / 2, a / 2) for y in (-a / 2, a / 2) for z in (-a / 2, a / 2)])
    s_values = np.arange(0.25, 6.0, a)
    y_values = np.arange(0.25, 4.0, a)
    centres, node_sets, rows = [], [], []
    for row, s in enumerate(s_values):
        for y in y_values:
            rows.append(row)
            local = np.column_stack([s + corners[:, 0], y + corners[:, 1], a / 2 + corners[:, 2]])
            node_sets.append(slope.to_world(*local.T))
            centres.append(slope.to_world(s, y, a / 2))
    figures = layer_metrics.layer_figures(slope, np.array(centres), node_sets, rows=rows,
                                          nominal_diameter=a,
                                          unit_volume=a ** 3, underlayer_level=0.0)
    # Half the first and the last row, all rows between, on the face between the two.
    assert figures["units_measured"] == (len(s_values) - 1) * len(y_values)
    assert figures["measuring_area_m2"] == pytest.approx((len(s_values) - 1) * 4.0 * a, rel=1e-9)
    assert figures["packing_density_coefficient"] == pytest.approx(1.0, rel=1e-9)
    assert figures["layer_thickness_m"] == pytest.approx(a, rel=1e-12)
    assert figures["porosity"] == pytest.approx(0.0, abs=1e-9)


def test_packing_density_of_a_staggered_grid_does_not_depend_on_the_number_of_rows():
    """Rows of 4 and 3 units between side walls (the small example's pattern): the grid's phi for
    any number of rows, odd or even (a fixed measuring band would count 3 or 4 rows in the same
    length), also when the rows are found from positions alone."""
    slope = Slope(cotangent=1.33, width=4.4, length=20.0)
    dn, phi = 0.56, 0.6
    for rows in (2, 3, 5, 6, 7, 8):
        grid = design_grid(slope, nominal_diameter=dn, rows=rows, units_per_row=(4, 3),
                           packing_density_coefficient=phi, first_row_s=0.8, centroid_height=0.5)
        design = slope.to_world(*grid.slope_coordinates.T)
        nodes = [p + np.zeros((4, 3)) for p in design]
        found = layer_metrics.rows_by_position(grid.slope_coordinates[:, 0], dn)
        assert np.array_equal(found, grid.rows)
        figures = layer_metrics.layer_figures(slope, design, nodes, rows=grid.rows,
                                              nominal_diameter=dn, unit_volume=0.1,
                                              underlayer_level=0.0)
        assert figures["packing_density_coefficient"] == pytest.approx(phi, rel=1e-12)


def test_limited_random_orientations_stay_within_the_tilt_of_the_face():
    """random_within: the unit's z axis ends within max_tilt_deg of the face normal, and the spins
    about it are spread over all directions."""
    from scipy.spatial.transform import Rotation

    from riprap.placement import unit_orientations

    slope = Slope(cotangent=1.5, width=3.0, length=6.0)
    q = unit_orientations(400, mode="random_within", slope=slope, seed=2, max_tilt_deg=30.0)
    rotations = Rotation.from_quat(np.concatenate([q[:, 1:], q[:, :1]], axis=1))
    z_axes = rotations.apply([0.0, 0.0, 1.0])
    tilt = np.degrees(np.arccos(np.clip(z_axes @ slope.normal, -1.0, 1.0)))
    assert tilt.max() <= 30.0 + 1e-9
    assert tilt.max() > 25.0
    x_axes = rotations.apply([1.0, 0.0, 0.0])
    assert abs(x_axes.mean(axis=0)).max() < 0.15      # no preferred spin


def test_a_spin_limit_keeps_units_square_to_the_slope_and_the_tilts_unchanged():
    """random_within with max_spin_deg: each unit's x axis, seen from the face normal, turns at
    most max_spin_deg away from up the slope (spins drawn either way); the tilts are those of the
    same seed without a limit (one draw per unit either way); a limit outside 0..180 is
    refused with its value."""
    from scipy.spatial.transform import Rotation

    from riprap.placement import unit_orientations

    slope = Slope(cotangent=1.5, width=3.0, length=6.0)

    def rotations(**limits):
        q = unit_orientations(400, mode="random_within", slope=slope, seed=3, max_tilt_deg=0.0,
                              **limits)
        return Rotation.from_quat(np.concatenate([q[:, 1:], q[:, :1]], axis=1))

    up_slope = np.array([np.cos(slope.angle), 0.0, np.sin(slope.angle)])
    x_axes = rotations(max_spin_deg=5.0).apply([1.0, 0.0, 0.0])
    spin = np.degrees(np.arctan2(x_axes[:, 1], x_axes @ up_slope))
    assert abs(spin).max() <= 5.0 + 1e-9
    assert spin.min() < -4.0 and spin.max() > 4.0
    free = rotations().apply([1.0, 0.0, 0.0])
    assert abs(np.degrees(np.arctan2(free[:, 1], free @ up_slope))).max() > 170.0

    def tilts(**limits):
        q = unit_orientations(50, mode="random_within", slope=slope, seed=3, max_tilt_deg=20.0,
                              **limits)
        r = Rotation.from_quat(np.concatenate([q[:, 1:], q[:, :1]], axis=1))
        return np.degrees(np.arccos(np.clip(r.apply([0.0, 0.0, 1.0]) @ slope.normal, -1, 1)))

    np.testing.assert_allclose(tilts(max_spin_deg=3.0), tilts(), atol=1e-9)
    with pytest.raises(CaseFileError, match="max_spin_deg = -1.0 must lie in 0..180"):
        unit_orientations(3, mode="random_within", slope=slope, max_spin_deg=-1.0)


def test_orientation_mode_errors():
    from riprap.placement import unit_orientations

    slope = Slope(cotangent=1.5, width=3.0, length=6.0)
    with pytest.raises(CaseFileError, match="orientation = 'upright'"):
        unit_orientations(3, mode="upright", slope=slope)
    with pytest.raises(CaseFileError, match="needs orientations in the grid file"):
        unit_orientations(3, mode="user", slope=slope)
