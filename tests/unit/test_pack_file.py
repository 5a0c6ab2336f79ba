"""Pack files (riprap.io.pack, read back by riprap.workflows.place.write_checked_pack): written,
loaded with load_case, built with build_simulation.

What must round-trip: the world position of every node of every body (1e-12 m: the loader
re-derives each written mesh's principal frame, whose axes are arbitrary for a cube or a sphere,
and composes it with the written orientation; rounding of that composition on 0.1 m bodies is
~1e-17 m), materials exactly (repr floats), wall points exactly and normals to 1e-15 (normalised
again on loading), velocities and world angular velocities to 1e-12, masses to 1e-13 relative
(the volume is integrated again over nodes moved to the principal frame).
"""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.case.build import build_simulation
from riprap.case.load import load_case
from riprap.cli import main
from riprap.errors import CaseFileError
from riprap.geometry import shapes
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh
from riprap.io.pack import PackBody
from riprap.workflows.place import write_checked_pack as write_pack
from riprap.simulation import Simulation
from riprap.solid import walls as wall_builders
from riprap.solid.materials import Material

# Node positions (m) of 0.1 m bodies after a write -> load -> principal frame -> compose cycle.
NODE_TOLERANCE = 1e-12
# A unit normal normalised twice (numpy, then math.sqrt) may move by an ulp.
NORMAL_TOLERANCE = 1e-15
# Velocities (m/s, rad/s) go through the inertia tensor of the re-derived frame.
VELOCITY_TOLERANCE = 1e-12
# The volume is integrated again over nodes moved by the principal-frame transform (rounding).
MASS_RELATIVE_TOLERANCE = 1e-13


@pytest.fixture(scope="module")
def meshes():
    """Coarse meshes, made once: a cube and a sphere (degenerate principal moments), a box."""
    return {
        "cube": shapes.cube(side=0.1, mesh_size=0.05),
        "ball": shapes.sphere(radius=0.05, mesh_size=0.03),
        "slab": shapes.box(lengths=(0.12, 0.08, 0.04), mesh_size=0.04),
    }


def _quaternion(rng):
    x, y, z, w = Rotation.random(random_state=rng).as_quat()
    return (w, x, y, z)


def _world_nodes(sim):
    """Node positions in the world of every body, from the solver's own state."""
    solver = sim.solver
    nodes = []
    for body in range(len(solver.positions)):
        w, x, y, z = solver.quaternions[body]
        rotation = Rotation.from_quat([x, y, z, w]).as_matrix()
        mesh = solver.shapes[solver.shape_index[body]].mesh
        nodes.append(mesh.nodes @ rotation.T + solver.positions[body])
    return nodes


def _pack_bodies(sim):
    """The state of a prepared Simulation as PackBody records (principal-frame orientations)."""
    solver = sim.solver
    omegas = solver.angular_velocities
    return [PackBody(shape=solver.shapes[solver.shape_index[b]].name,
                     material=solver.materials[solver.material_index_of_body[b]].name,
                     position=solver.positions[b], orientation=solver.quaternions[b],
                     velocity=solver.velocities[b], angular_velocity=omegas[b],
                     fixed=solver.fixed[b])
            for b in range(len(solver.positions))]


@pytest.fixture(scope="module")
def original(meshes, tmp_path_factory):
    """Four bodies of two shapes (one fixed), two materials, two plane walls, prepared."""
    sim = Simulation(end_time=0.01, output_directory=tmp_path_factory.mktemp("original"),
                     progress=False, picture=False, paraview=False)
    sim.add_material(Material(name="rock", density=2650.0, contact_penalty=1.0e8))
    sim.add_material(Material(name="concrete", density=2400.0, friction_coefficient=0.7,
                              restitution=0.3, tangential_stiffness_ratio=0.3))
    sim.add_shape("cube", meshes["cube"])
    sim.add_shape("ball", meshes["ball"])
    rng = np.random.default_rng(11)
    layout = [("cube", "concrete", (0.0, 0.0, 0.2), False),
              ("ball", "rock", (0.3, 0.0, 0.2), False),
              ("cube", "rock", (0.0, 0.3, 0.25), False),
              ("ball", "concrete", (0.3, 0.3, 0.05), True)]
    for shape, material, position, fixed in layout:
        sim.add_body(shape=shape, material=material, position=position,
                     orientation=_quaternion(rng), velocity=rng.normal(size=3) * 0.1,
                     angular_velocity=rng.normal(size=3), fixed=fixed)
    sim.add_walls(wall_builders.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                                      material="rock"))
    sim.add_walls(wall_builders.plane(point=(-0.2, 0.1, 0.0), normal=(1.0, 0.3, 0.1),
                                      material="concrete"))
    sim.prepare()
    return sim


@pytest.fixture(scope="module")
def pack_path(original, tmp_path_factory):
    solver = original.solver
    return write_pack(tmp_path_factory.mktemp("pack") / "pack",
                      shapes={name: original.shape(name).mesh for name in ("cube", "ball")},
                      materials=solver.materials, bodies=_pack_bodies(original),
                      walls=solver.walls,
                      simulation={"end_time": 0.004, "local_damping": 0.1},
                      output={"paraview": False, "picture": False},
                      comment="four bodies on two planes\nfor the pack round-trip test")


@pytest.fixture(scope="module")
def rebuilt(pack_path, tmp_path_factory):
    sim = build_simulation(load_case(pack_path),
                           output_directory=tmp_path_factory.mktemp("rebuilt"), progress=False)
    sim.prepare()
    return sim


def test_pack_folder_layout_and_header(pack_path):
    assert pack_path.name == "pack.toml"
    assert sorted(p.name for p in (pack_path.parent / "shapes").iterdir()) == ["ball.vtu",
                                                                               "cube.vtu"]
    text = pack_path.read_text()
    assert text.startswith("# riprap pack: 4 bodies, 2 shapes; written by riprap ")
    assert "# four bodies on two planes\n# for the pack round-trip test\n" in text
    assert 'file = "shapes/cube.vtu"' in text


def test_pack_case_keys(pack_path):
    case = load_case(pack_path)
    assert case.simulation.end_time == 0.004
    assert case.simulation.local_damping == 0.1
    assert case.simulation.rest_speed == 1.0e-3
    assert [shape.type for shape in case.shapes] == ["mesh_file", "mesh_file"]
    assert [body.fixed for body in case.bodies] == [False, False, False, True]
    assert case.output.paraview is False and case.output.picture is False


def test_pack_round_trip_world_nodes_of_every_body(original, rebuilt):
    before, after = _world_nodes(original), _world_nodes(rebuilt)
    assert len(before) == len(after) == 4
    for body, (old, new) in enumerate(zip(before, after)):
        assert np.abs(old - new).max() < NODE_TOLERANCE, f"body {body}"


def test_pack_round_trip_velocities(original, rebuilt):
    old, new = original.solver, rebuilt.solver
    assert np.abs(old.velocities - new.velocities).max() < VELOCITY_TOLERANCE
    assert np.abs(old.angular_velocities - new.angular_velocities).max() < VELOCITY_TOLERANCE
    assert new.fixed.tolist() == [False, False, False, True]
    assert np.abs(new.masses / old.masses - 1.0).max() < MASS_RELATIVE_TOLERANCE


def test_pack_round_trip_materials_and_walls(original, rebuilt):
    assert rebuilt.solver.materials == original.solver.materials
    assert len(rebuilt.solver.walls) == 2
    for old, new in zip(original.solver.walls, rebuilt.solver.walls):
        assert new.material == old.material
        assert new.point == old.point
        assert np.abs(np.subtract(new.normal, old.normal)).max() < NORMAL_TOLERANCE


def test_pack_runs_with_riprap_run(pack_path, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    out = tmp_path / "run"
    assert main(["run", str(pack_path), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["bodies"] == 4
    assert summary["steps"] > 0
    assert abs(summary["simulated_time"] - 0.004) < summary["time_step"]
    assert "error" not in capsys.readouterr().err


@pytest.mark.parametrize("name", ["cube", "ball", "slab", "slab turned"])
def test_pack_orientation_applies_to_mesh_as_written(meshes, tmp_path, name):
    """Any frame the caller writes (principal with degenerate moments, or turned and shifted off
    the centroid) comes back with node = position + R(q) (node - centroid of the written mesh)."""
    mesh = meshes[name.split()[0]]
    if name == "slab turned":
        # Axes permuted (a proper rotation: x -> y -> z -> x) and the centroid moved off origin.
        turned = mesh.nodes[:, [2, 0, 1]] + np.array([0.3, -0.1, 0.05])
        mesh = TetMesh(nodes=turned, tets=mesh.tets, name="slab turned")
    rng = np.random.default_rng(5)
    orientation = _quaternion(rng)
    position = (0.1, 0.2, 0.3)
    path = write_pack(tmp_path / "pack", shapes={name: mesh},
                      materials=[Material(name="rock")],
                      bodies=[PackBody(shape=name, material="rock", position=position,
                                       orientation=orientation)],
                      walls=[])
    sim = build_simulation(load_case(path), output_directory=tmp_path / "out", progress=False)
    sim.prepare()
    w, x, y, z = orientation
    rotation = Rotation.from_quat([x, y, z, w]).as_matrix()
    centroid = mass_properties(mesh).centroid
    expected = (mesh.nodes - centroid) @ rotation.T + np.asarray(position)
    assert np.abs(_world_nodes(sim)[0] - expected).max() < NODE_TOLERANCE


def test_pack_shape_names_become_safe_file_names(meshes, tmp_path):
    path = write_pack(tmp_path / "pack", shapes={"Core-Loc 1/a": meshes["cube"]},
                      materials=[Material(name="rock")],
                      bodies=[PackBody(shape="Core-Loc 1/a", material="rock",
                                       position=(0.0, 0.0, 0.0))])
    assert (tmp_path / "pack" / "shapes" / "Core-Loc_1_a.vtu").is_file()
    assert load_case(path).shapes[0].name == "Core-Loc 1/a"


# ---------------------------------------------------------------------------------- errors


def _write_one(meshes, tmp_path, **changes):
    arguments = dict(shapes={"cube": meshes["cube"]}, materials=[Material(name="rock")],
                     bodies=[PackBody(shape="cube", material="rock", position=(0, 0, 0))],
                     walls=[])
    arguments.update(changes)
    return write_pack(tmp_path / "pack", **arguments)


@pytest.mark.parametrize("changes, words", [
    ({"bodies": [PackBody(shape="cub", material="rock", position=(0, 0, 0))]},
     "bodies[0].shape = 'cub': no such shape; did you mean 'cube'?"),
    ({"bodies": [PackBody(shape="cube", material="rok", position=(0, 0, 0))]},
     "bodies[0].material = 'rok': no such material; did you mean 'rock'?"),
    ({"walls": wall_builders.plane(point=(0, 0, 0), normal=(0, 0, 1), material="steel")},
     "walls[0].material = 'steel': no such material"),
    ({"materials": [Material(name="rock"), Material(name="rock", density=2400.0)]},
     "materials: names used twice: rock"),
    ({"bodies": []}, "bodies: at least one body is needed"),
    ({"simulation": {"end_tme": 2.0}},
     "unknown [simulation] key 'end_tme'; did you mean 'end_time'?"),
    ({"output": {"folder": "x"}}, "unknown [output] key 'folder'"),
])
def test_write_pack_rejects_inconsistent_input(meshes, tmp_path, changes, words):
    with pytest.raises(CaseFileError) as caught:
        _write_one(meshes, tmp_path, **changes)
    assert words in str(caught.value)


def test_write_pack_validates_written_file_and_names_line(meshes, tmp_path):
    with pytest.raises(CaseFileError) as caught:
        _write_one(meshes, tmp_path, simulation={"end_time": -1.0})
    message = str(caught.value)
    path = tmp_path / "pack" / "pack.toml"
    line = path.read_text().splitlines().index("end_time = -1.0") + 1
    assert message.startswith(f"{path}:{line}: simulation.end_time = -1.0: out of range")


@pytest.mark.parametrize("fields, words", [
    ({"position": (0.0, 0.0)}, "position must be 3 numbers"),
    ({"position": (0.0, np.nan, 0.0)}, "position = [0.0, nan, 0.0] is not finite"),
    ({"orientation": (0.0, 0.0, 0.0, 0.0)}, "has norm 0, below 1e-06"),
    ({"velocity": "fast"}, "velocity must be 3 numbers"),
    ({"fixed": "yes"}, "fixed must be True or False"),
    ({"shape": ""}, "shape must be a non-empty name"),
])
def test_pack_body_rejects_bad_fields(fields, words):
    arguments = dict(shape="cube", material="rock", position=(0.0, 0.0, 0.0))
    arguments.update(fields)
    with pytest.raises(CaseFileError) as caught:
        PackBody(**arguments)
    assert words in str(caught.value)
