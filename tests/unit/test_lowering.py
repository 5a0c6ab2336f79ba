"""Lowering a unit straight down until it touches (riprap.placement.lowering), against distances
worked out by hand for cubes."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.geometry import shapes
from riprap.placement import Slope
from riprap.placement.lowering import Surface, VerticalLowering

GAP = 1e-3


@pytest.fixture(scope="module")
def cube():
    mesh = shapes.cube(side=1.0)
    centred = mesh.nodes - 0.5 * (mesh.nodes.min(axis=0) + mesh.nodes.max(axis=0))
    return centred, mesh.boundary_faces()


def _lowering(cube, slope):
    nodes, faces = cube
    lowering = VerticalLowering(slope, gap=GAP)
    lowering.add(Surface.from_nodes(nodes + [0.0, 0.0, 0.5], faces))     # resting on z = 0
    return lowering


def test_a_cube_lands_on_a_cube_face_to_face(cube):
    # The face far away behind the flat bed at z = -5: only the lower cube is in the way.
    lowering = _lowering(cube, Slope(cotangent=1.5, width=10.0, length=10.0, toe_x=50.0, toe_level=-5.0))
    nodes, faces = cube
    dz = lowering.lower(Surface.from_nodes(nodes + [0.3, 0.2, 3.0], faces))
    # Bottom at 2.5 comes down to the top at 1.0, GAP clear.
    assert dz == pytest.approx(-(1.5 - GAP), abs=1e-9)


def test_a_cube_on_its_edge_lands_on_a_cube(cube):
    lowering = _lowering(cube, Slope(cotangent=1.5, width=10.0, length=10.0, toe_x=50.0, toe_level=-5.0))
    nodes, faces = cube
    tilted = nodes @ Rotation.from_euler("x", 45.0, degrees=True).as_matrix().T
    dz = lowering.lower(Surface.from_nodes(tilted + [0.0, 0.0, 3.0], faces))
    # Its lowest edge (sqrt(2)/2 below its centre) meets the top face at z = 1.
    assert dz == pytest.approx(-(2.0 - np.sqrt(0.5) - GAP), abs=1e-6)


def test_a_cube_that_starts_inside_another_is_raised_then_set_on_it(cube):
    lowering = _lowering(cube, Slope(cotangent=1.5, width=10.0, length=10.0, toe_x=50.0, toe_level=-5.0))
    nodes, faces = cube
    dz = lowering.lower(Surface.from_nodes(nodes + [0.2, 0.0, 0.8], faces))
    assert 0.8 + dz == pytest.approx(1.5 + GAP, abs=1e-9)


def test_a_cube_lands_on_the_bed_and_on_the_slope_face(cube):
    slope = Slope(cotangent=1.0, width=10.0, length=10.0, toe_x=0.0, toe_level=0.0)
    lowering = VerticalLowering(slope, gap=GAP)
    nodes, faces = cube
    # In front of the toe: onto the bed.
    dz = lowering.lower(Surface.from_nodes(nodes + [-3.0, 5.0, 4.0], faces))
    assert dz == pytest.approx(-(3.5 - GAP), abs=1e-9)
    # Over a 45 degree face rising with x: the bottom's upslope edge, x = 3.5, meets z = 3.5.
    dz = lowering.lower(Surface.from_nodes(nodes + [3.0, 5.0, 6.0], faces))
    assert 6.0 - 0.5 + dz == pytest.approx(3.5 + GAP, abs=1e-9)
