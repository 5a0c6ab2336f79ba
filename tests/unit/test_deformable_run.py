"""Deformable bodies in the one run loop: outputs (ParaView stresses, units.csv, summary), restart
bit for bit (also with rigid bodies in the run), forces passed between deformable and rigid
bodies, and the errors a user meets (overlap at the start, bad material keys, a step above the
stable one, an element that inverts)."""
import csv

import numpy as np
import pytest

import riprap as rr
from riprap.errors import CaseFileError, InstabilityError, MeshError, OverlapError
from riprap.geometry import shapes
from riprap.io.vtk import ParaViewSeries
from riprap.solid import walls

CONCRETE_LIKE = dict(young_modulus=5e7, density=2400.0, poisson_ratio=0.2, tensile_strength=3e6)


def _two_cubes(out, end_time, *, drop_position=(0.05, 0.0, 0.35), checkpoint_interval=0.0,
               output_interval=0.01):
    sim = rr.Simulation(end_time=end_time, output_interval=output_interval, output_directory=out,
                        progress=False, picture=False, checkpoint_interval=checkpoint_interval)
    sim.add_shape("cube", shapes.cube(side=0.2, mesh_size=0.07))
    sim.add_material(rr.Material(name="concrete"))
    sim.add_walls(walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="concrete"))
    material = rr.ElasticMaterial(**CONCRETE_LIKE)
    sim.add_deformable_body(shape="cube", material=material, position=(0.0, 0.0, 0.1005), name="lower")
    sim.add_deformable_body(shape="cube", material=material, position=drop_position,
                            velocity=(0.0, 0.0, -1.0), angular_velocity=(0.0, 2.0, 0.0), name="upper")
    return sim


def test_run_writes_stresses_units_and_summary(tmp_path):
    summary = _two_cubes(tmp_path, 0.06).run()
    assert summary.model == "deformable" and summary.end_reason == "end_time"
    assert summary.max_tensile_stress > 0.0 and summary.element_steps_per_second > 0.0
    with open(tmp_path / "units.csv") as stream:
        rows = list(csv.DictReader(stream))
    assert [row["name"] for row in rows] == ["lower", "upper"]
    for row in rows:
        assert float(row["max_tensile_stress_Pa"]) > 0.0
        assert float(row["stress_over_strength"]) == pytest.approx(
            float(row["max_tensile_stress_Pa"]) / 3e6, rel=1e-5)
    import meshio

    frame = meshio.read(tmp_path / ParaViewSeries(tmp_path, "bodies", append=True).frames[-1][1])
    for name in ("sigma_1", "sigma_3", "differential_stress", "von_mises", "body"):
        assert name in frame.cell_data
    sigma_1 = frame.cell_data["sigma_1"][0]
    sigma_3 = frame.cell_data["sigma_3"][0]
    assert np.all(sigma_1 >= sigma_3)
    assert np.allclose(frame.cell_data["differential_stress"][0], sigma_1 - sigma_3)


def test_restart_continues_bit_for_bit(tmp_path):
    whole = _two_cubes(tmp_path / "whole", 0.05)
    whole.run()
    first = _two_cubes(tmp_path / "part", 0.025)
    first.run()
    second = _two_cubes(tmp_path / "part", 0.05)
    second.run(restart_from=tmp_path / "part" / "checkpoint.npz")
    a, b = whole.model.state_arrays(), second.model.state_arrays()
    assert a["clock"][1] == b["clock"][1]
    assert np.array_equal(a["positions"], b["positions"])
    assert np.array_equal(a["velocities"], b["velocities"])


def test_overlapping_bodies_are_named(tmp_path):
    sim = _two_cubes(tmp_path, 0.01, drop_position=(0.05, 0.0, 0.25))
    with pytest.raises(OverlapError, match="'lower' and 'upper'|'upper' and 'lower'"):
        sim.run()


@pytest.mark.parametrize("key, value", [("young_modulus", 0.0), ("young_modulus", -1.0),
                                        ("poisson_ratio", 0.5), ("poisson_ratio", -1.0),
                                        ("viscosity", -0.1), ("density", 0.0)])
def test_bad_material_values_name_the_key(key, value):
    with pytest.raises(CaseFileError, match=key):
        rr.ElasticMaterial(**{**CONCRETE_LIKE, key: value})


def test_step_above_the_stable_step_is_refused():
    nodes, tets = rr.deformable.box_mesh((0.1, 0.1, 0.1), (2, 2, 2))
    body = rr.DeformableBody(nodes, tets, rr.ElasticMaterial(**CONCRETE_LIKE))
    with pytest.raises(CaseFileError, match="above the stable step"):
        body.time_step = 1.01 * body.stable_time_step()


def test_inverted_reference_element_is_named():
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    # element 1 is listed with two nodes swapped: negative volume
    with pytest.raises(MeshError, match="'bad': element\\(s\\) 1 "):
        rr.DeformableBody(nodes, [[0, 1, 2, 3], [1, 3, 2, 4]], rr.ElasticMaterial(**CONCRETE_LIKE),
                          name="bad")


def test_element_inverting_in_a_run_stops_with_a_failure_checkpoint(tmp_path):
    sim = rr.Simulation(end_time=0.05, output_interval=0.01, output_directory=tmp_path,
                        progress=False, picture=False)
    sim.add_shape("cube", shapes.cube(side=0.2, mesh_size=0.1))
    sim.add_material(rr.Material(name="concrete"))
    sim.add_walls(walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="concrete"))
    # a very soft body thrown at the floor far faster than its wave speed (3 m/s): it inverts
    sim.add_deformable_body(shape="cube", material=rr.ElasticMaterial(young_modulus=1e4, density=1000.0),
                            position=(0.0, 0.0, 0.1005), velocity=(0.0, 0.0, -200.0), name="jelly")
    with pytest.raises(InstabilityError, match="'jelly': element [0-9]+ inverted"):
        sim.run()
    assert (tmp_path / "failure_checkpoint.npz").is_file()


CASE = """
format_version = 1
[simulation]
end_time = 0.004
[[materials]]
name = "concrete"
density = 2400.0
[[shapes]]
name = "cube"
type = "cube"
side = 0.2
mesh_size = 0.1
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.0, 0.0, 0.1005]
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.0, 0.0, 0.35]
velocity = [0.0, 0.0, -1.0]
[[walls]]
type = "plane"
material = "concrete"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[deformable]
{deformable}
[output]
paraview = false
picture = false
"""


def _case(tmp_path, deformable):
    path = tmp_path / "case.toml"
    path.write_text(CASE.replace("{deformable}", deformable))
    return path


def test_case_file_runs_deformable_bodies(tmp_path):
    from riprap.case.build import build_simulation
    from riprap.case.load import load_case

    case = load_case(_case(tmp_path, 'bodies = "all"\nyoung_modulus = 5e7\ntensile_strength = 3e6'))
    assert case.deformable.young_modulus == 5e7 and case.deformable.bodies == "all"
    sim = build_simulation(case, output_directory=tmp_path / "out", progress=False)
    assert len(sim.deformable_bodies) == 2 and sim.solver.n_bodies == 0
    assert sim.deformable_bodies[0].material.density == 2400.0
    summary = sim.run()
    assert summary.model == "deformable" and (tmp_path / "out" / "units.csv").is_file()


@pytest.mark.parametrize("text, message", [
    ("bodies = [0, 5]", "bodies lists \\[5\\], but the case makes 2 bodies"),
    ("poisson_ratio = 0.5", "poisson_ratio"),
    ("young_modulus = -1.0", "young_modulus"),
    ("bodies = [0, 0]", "bodies"),
    ('constitutive_model = "mooney"', "constitutive_model"),
])
def test_case_file_errors_name_the_key(tmp_path, text, message):
    from riprap.case.build import build_simulation
    from riprap.case.load import load_case
    from riprap.errors import RiprapError

    with pytest.raises(RiprapError, match=message):
        case = load_case(_case(tmp_path, text))
        build_simulation(case, output_directory=tmp_path / "out", progress=False).run()


def _deformable_on_rigid(out, end_time):
    sim = rr.Simulation(end_time=end_time, output_interval=0.05, output_directory=out,
                        progress=False, picture=False)
    sim.add_shape("cube", shapes.cube(side=0.2, mesh_size=0.07))
    sim.add_material(rr.Material(name="concrete", density=2400.0, contact_penalty=5e7, restitution=0.3))
    sim.add_walls(walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="concrete"))
    sim.add_body(shape="cube", material="concrete", position=(0.0, 0.0, 0.1))
    sim.add_deformable_body(shape="cube", material=rr.ElasticMaterial(**{**CONCRETE_LIKE, "young_modulus": 5e7}),
                            position=(0.03, 0.0, 0.3005), name="top")
    sim.deformable_contact_penalty = 5e7
    sim.deformable_mass_damping = 2000.0       # settle: this test is about the resting forces
    return sim


def test_deformable_body_resting_on_a_rigid_one_passes_its_weight_down(tmp_path):
    """Statics of a mixed stack: the deformable cube's contact forces on the rigid cube sum to its
    weight, and the floor carries both (0.1 %): forces cross between the two solvers."""
    sim = _deformable_on_rigid(tmp_path, 0.3)
    summary = sim.run()
    assert summary.bodies == 2
    top = sim.model.system.bodies[0]
    weight = top.mass * 9.81
    force, _ = sim.model.system.rigid_loads(sim.solver.positions)
    assert force[0] == pytest.approx([0.0, 0.0, -weight], abs=1e-3 * weight)
    floor = sim.solver.contact_forces()[0]
    assert floor[2] == pytest.approx(weight + sim.solver.masses[0] * 9.81, rel=1e-3)
    assert (tmp_path / "rigid_bodies.pvd").is_file() and (tmp_path / "bodies.pvd").is_file()


def test_mixed_run_restarts_bit_for_bit(tmp_path):
    whole = _deformable_on_rigid(tmp_path / "whole", 0.02)
    whole.run()
    first = _deformable_on_rigid(tmp_path / "part", 0.01)
    first.run()
    second = _deformable_on_rigid(tmp_path / "part", 0.02)
    second.run(restart_from=tmp_path / "part" / "checkpoint.npz")
    a, b = whole.model.state_arrays(), second.model.state_arrays()
    for key in ("positions", "velocities", "rigid_positions", "rigid_velocities"):
        assert np.array_equal(a[key], b[key]), key


def test_absurd_run_length_is_refused_with_the_figure(tmp_path):
    from riprap.work_estimate import WorkTooLargeError

    # the longest run riprap takes (1e8 s), frames every 1000 s: the work is refused by its estimate
    sim = _two_cubes(tmp_path, 1.0e8, output_interval=1.0e3)
    with pytest.raises(WorkTooLargeError, match="element-steps/s"):
        sim.run()
