"""The layer analysis (riprap.analysis.analyse_layer) on hand-built cases whose answers are statics.

Sources and cases:

1. A 1 m concrete cube resting on a horizontal plane: it touches one thing (coordination number 1)
   and the plane carries its weight W = rho g a^3 (statics); nothing pushes it sideways, so the
   factor of safety against sliding is infinite.
2. A block of width b = 0.5 m (along the slope), height h = 1.0 m (normal to it) and 0.5 m across,
   resting on a plane inclined at theta = 20 degrees with mu = 0.8 > tan theta: coordination
   number 1, contact force = weight; factor of safety against sliding mu / tan theta = 2.198
   (limit equilibrium, N = W cos theta, T = W sin theta); against rocking (b / h) / tan theta =
   1.374, the toppling criterion of Goodman & Bray (1976), "Toppling of rock slopes", Proc.
   Specialty Conf. Rock Engineering for Foundations and Slopes, ASCE, vol. 2, 201-234 (the block
   topples when its weight passes outside its base).
3. The same block turned to stand on its long side (b = 1.0 m, h = 0.5 m): rocking FoS 5.49.

Each case settles for 0.5 s with local damping 0.3. Tolerances: forces and factors of safety
within ``TOLERANCE`` = 1 % (the settled block still vibrates by a fraction of its overlap, and
the overlap of about 1e-4 m shortens the lever arms by that much); coordination numbers exact.
"""
import numpy as np
import pytest

from riprap.analysis import LayerDescription, analyse_layer, state_from_simulation
from riprap.geometry import shapes
from riprap.placement.slope import Slope
from riprap.simulation import Simulation
from riprap.solid import walls
from riprap.solid.materials import Material

TOLERANCE = 0.01
DENSITY = 2400.0
G = 9.81


def _settled(mesh, *, normal, orientation, position, mu):
    sim = Simulation(end_time=0.5, local_damping=0.3, gravity=(0.0, 0.0, -G))
    sim.add_material(Material(name="concrete", density=DENSITY, friction_coefficient=mu,
                              restitution=0.5, contact_penalty=1.0e8))
    sim.add_shape("block", mesh)
    sim.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=tuple(normal), material="concrete"))
    sim.add_body(shape="block", material="concrete", position=position, orientation=orientation)
    sim.prepare()
    sim.solver.advance(int(round(0.5 / sim.solver.time_step)))
    return sim


def _description(slope, position, volume):
    return LayerDescription(
        unit_kind="cube", unit_shape="block", nominal_diameter=volume ** (1 / 3), unit_volume=volume,
        unit_height=1.0, unit_axes={"nose": np.array([0.0, 0.0, 1.0])}, slope=slope,
        underlayer_top=0.0, unit_bodies=np.array([0]), rows=np.array([0]),
        design_positions=np.asarray(position, dtype=float).reshape(1, 3))


def test_cube_on_a_horizontal_plane_carries_its_weight():
    sim = _settled(shapes.cube(side=1.0, mesh_size=0.4), normal=(0.0, 0.0, 1.0),
                   orientation=(1.0, 0.0, 0.0, 0.0), position=(0.0, 0.0, 0.501), mu=0.6)
    # A steep slope frame only to name "down the slope"; the plane itself is horizontal.
    state = state_from_simulation(sim, _description(Slope(cotangent=2.0, width=2.0, length=2.0),
                                                    (0.0, 0.0, 0.5), 1.0))
    units = analyse_layer(state).units
    weight = DENSITY * G
    assert units["coordination_number"].tolist() == [1]
    assert units["max_contact_force_N"][0] == pytest.approx(weight, rel=TOLERANCE)
    assert units["max_contact_force_unit_underlayer_N"][0] == pytest.approx(weight, rel=TOLERANCE)
    assert units["max_contact_force_unit_unit_N"][0] == 0.0
    assert units["weight_N"][0] == pytest.approx(weight, rel=1e-12)
    assert units["factor_of_safety_sliding"][0] > 1e6       # only round-off friction


@pytest.mark.parametrize("width, height", [(0.5, 1.0), (1.0, 0.5)])
def test_block_on_a_slope_sliding_and_rocking_factors_of_safety(width, height):
    theta = np.radians(20.0)
    mu = 0.8
    slope = Slope(cotangent=1.0 / np.tan(theta), width=3.0, length=4.0)
    mesh = shapes.box(lengths=(width, 0.5, height), mesh_size=0.25)
    # Turned about -y by theta: its x axis runs up the face, its z axis along the face normal.
    half = 0.5 * theta
    position = slope.to_world(2.0, 1.5, 0.5 * height + 0.0005)
    sim = _settled(mesh, normal=slope.normal, orientation=(np.cos(half), 0.0, -np.sin(half), 0.0),
                   position=tuple(position), mu=mu)
    assert np.linalg.norm(sim.solver.velocities[0]) < 1e-3      # it rests
    analysis = analyse_layer(state_from_simulation(sim, _description(slope, position,
                                                                     width * 0.5 * height)))
    units = analysis.units
    weight = DENSITY * G * width * 0.5 * height
    assert units["coordination_number"].tolist() == [1]
    assert units["max_contact_force_N"][0] == pytest.approx(weight, rel=TOLERANCE)
    assert units["factor_of_safety_sliding"][0] == pytest.approx(mu / np.tan(theta), rel=TOLERANCE)
    expected_rocking = (width / height) / np.tan(theta)
    assert units["factor_of_safety_rocking"][0] == pytest.approx(expected_rocking, rel=TOLERANCE)
    assert units["factor_of_safety"][0] == pytest.approx(
        min(mu / np.tan(theta), expected_rocking), rel=TOLERANCE)
    # It sits where it was put, its height above the face about h / 2.
    assert units["distance_from_design_m"][0] < 0.01
    assert units["height_above_slope_m"][0] == pytest.approx(0.5 * height, abs=0.002)
