"""Units placed from a grid end resting, just touching, with no overlap above tolerance.

Source: the placement requirement of POSITIT (Xiang et al. 2012, seed paper: "units positioned ...
just touching and not overlapping ... in static force equilibrium"). Case: six 0.3 m concrete cubes
(random orientations, two staggered rows of 3 and 2 plus one) dropped from a design grid onto a rough
1:1.5 face (friction 0.9 > tan 33.7 deg = 0.67, so a cube cannot slide on it) between glass side
walls, settled with local damping 0.3; all at once, row by row (each row dropped onto the rows
below once they rest), and lowered straight down until touching before release (as a crane sets
them down).

Tolerances: every unit ends with speed below ``REST_SPEED`` = 0.02 m/s (translation plus rotation
at its bounding radius); the largest mean overlap depth of any contact is below ``OVERLAP_OVER_DN``
= 1 % of the unit's nominal diameter; no unit slides past the toe.
"""
from types import SimpleNamespace

import numpy as np
import pytest

from riprap.errors import OverlapError
from riprap.geometry import shapes
from riprap.placement import (PlacementMaterials, Slope, Underlayer, design_grid, place_units,
                              unit_orientations)
from riprap.solid.materials import Material

REST_SPEED = 0.02
OVERLAP_OVER_DN = 0.01
SIDE = 0.3
DENSITY = 2400.0
# A penalty of 2e4 rho g D_n keeps overlaps under a few units' weight to a few tenths of a percent of D_n
# (5e3 rho g D_n gave 1.1 %).
PENALTY = 20000 * DENSITY * 9.81 * SIDE


def _materials():
    def material(name, friction):
        return Material(name=name, density=DENSITY, friction_coefficient=friction,
                        restitution=0.3, contact_penalty=PENALTY)
    return PlacementMaterials(unit=material("concrete", 0.6), rock=material("rock", 0.6),
                              face=material("core", 0.9), side_wall=material("glass", 0.2))


def _cube_unit():
    design = SimpleNamespace(packing_density_coefficient=1.17, layers=1,
                             layer_thickness_coefficient=1.0, porosity=0.47)
    return SimpleNamespace(kind="cube", mesh=shapes.cube(side=SIDE), height=SIDE,
                           nominal_diameter=SIDE, volume=SIDE ** 3, design=design)


def _no_underlayer():
    return Underlayer(shapes=[], shape_of_rock=np.zeros(0, dtype=np.int64),
                      positions=np.zeros((0, 3)), quaternions=np.zeros((0, 4)),
                      nominal_diameters=np.zeros(0), top_level=0.0)


@pytest.fixture(scope="module", params=[("all_at_once", "free_fall"), ("row_by_row", "free_fall"),
                                        ("all_at_once", "on_contact")])
def placed(request, tmp_path_factory):
    slope = Slope(cotangent=1.5, width=1.0, length=2.0)
    unit = _cube_unit()
    grid = design_grid(slope, nominal_diameter=SIDE, rows=3, units_per_row=(3, 2),
                       packing_density_coefficient=0.5, first_row_s=0.3, centroid_height=0.3)
    q = unit_orientations(len(grid.positions), mode="random", slope=slope, seed=5)
    result = place_units(slope, unit, _no_underlayer(), positions=grid.positions, orientations=q,
                         materials=_materials(), lift_overlapping=True, end_time=2.5,
                         deposition=request.param[0], release=request.param[1],
                         time_step_safety=0.3, local_damping=0.3, rest_speed=REST_SPEED,
                         output_directory=tmp_path_factory.mktemp("placement"), paraview=False,
                         picture=False, progress=False)
    return result


def test_units_from_a_grid_come_to_rest_just_touching(placed):
    summary = placed.summary
    assert summary["units_placed"] == 8
    assert summary["units_rolled_off"] == []
    assert summary["units_at_rest"] == 8, summary
    assert summary["max_overlap_over_dn"] < OVERLAP_OVER_DN
    assert summary["max_overlap_over_dn"] > 0.0          # they do touch
    assert summary["run"]["end_reason"] == "at_rest"
    assert summary["run"]["stages"] == (3 if summary["deposition"] == "row_by_row" else 1)


def test_units_overlapping_at_the_start_are_named_with_their_grid_line():
    slope = Slope(cotangent=1.5, width=1.0, length=2.0)
    positions = slope.to_world(np.array([0.5, 0.6, 1.2]), np.array([0.5, 0.5, 0.5]),
                               np.array([0.3, 0.3, 0.3]))
    q = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
    with pytest.raises(OverlapError, match=r"unit 1 \(grid line 8\) overlaps unit 0"):
        place_units(slope, _cube_unit(), _no_underlayer(), positions=positions, orientations=q,
                    materials=_materials(), grid_lines=np.array([7, 8, 9]), end_time=0.1,
                    release="free_fall", progress=False, paraview=False, picture=False)
