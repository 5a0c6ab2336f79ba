"""Fracture in the run loop and the case file (issue 16): the outputs (units.csv columns,
fragments.csv, cracks.pvd, the damage and fragment fields, the summary), restart bit for bit after
joints have broken, and the errors a user meets (strengths or energies <= 0, joints on a rigid
body or on 10-node tets, a mesh too coarse to show a crack, a fracture region with no joint)."""
import csv

import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import load_case
from riprap.errors import RiprapError
from riprap.io.vtk import ParaViewSeries

CASE = """
format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.001
checkpoint_interval = 0.0
[[materials]]
name = "concrete"
density = 2400.0
[[shapes]]
name = "cube"
type = "cube"
side = 0.2
mesh_size = {mesh_size}
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.0, 0.0, 0.1005]
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.03, 0.0, 0.302]
velocity = [0.0, 0.0, -6.0]
[[walls]]
type = "plane"
material = "concrete"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[deformable]
{deformable}
[output]
paraview = {paraview}
picture = false
"""


FRACTURE = {"young_modulus": "3.0e9", "tensile_strength": "1.0e6", "fracture": "true",
            "cohesion": "2.0e6", "fracture_energy_mode_i": "20.0",
            "fracture_energy_mode_ii": "200.0"}


def _case(tmp_path, *, end_time=0.004, mesh_size=0.06, changes=None, paraview="false",
          name="case.toml"):
    deformable = "\n".join(f"{key} = {value}" for key, value in {**FRACTURE, **(changes or {})}.items())
    path = tmp_path / name
    path.write_text(CASE.format(end_time=end_time, mesh_size=mesh_size, deformable=deformable,
                                paraview=paraview))
    return load_case(path)


def _run(case, out, restart=None):
    sim = build_simulation(case, output_directory=out, progress=False)
    summary = sim.run(restart_from=restart)
    return sim, summary


def test_a_cube_dropped_on_another_cracks_and_says_so(tmp_path):
    sim, summary = _run(_case(tmp_path, paraview="true"), tmp_path / "out")
    system = sim.model.system
    assert system.fracturing_bodies == [0, 1]
    assert summary.broken_joints > 0 and summary.broken_area > 0.0
    assert summary.fracture_energy > 0.0
    with open(tmp_path / "out" / "units.csv") as stream:
        rows = list(csv.DictReader(stream))
    broken = sum(float(row["broken_area_m2"]) for row in rows)
    assert broken == pytest.approx(summary.broken_area, rel=1e-5)
    for row, body in zip(rows, system.bodies):
        assert int(row["fragments"]) == len(body.fragment_table()["mass"])
        assert 0.0 < float(row["largest_fragment_mass_fraction"]) <= 1.0
    with open(tmp_path / "out" / "fragments.csv") as stream:
        pieces = list(csv.DictReader(stream))
    # every piece listed, their masses adding up to each unit's
    for k, body in enumerate(system.bodies):
        masses = [float(p["mass_kg"]) for p in pieces if int(p["body"]) == k]
        assert sum(masses) == pytest.approx(body.mass, rel=1e-5)
    import meshio

    frame = meshio.read(tmp_path / "out" / ParaViewSeries(tmp_path / "out", "bodies",
                                                          append=True).frames[-1][1])
    assert frame.cell_data["damage"][0].max() > 0.0
    assert "fragment" in frame.cell_data
    cracks = meshio.read(tmp_path / "out" / ParaViewSeries(tmp_path / "out", "cracks",
                                                           append=True).frames[-1][1])
    assert len(cracks.cells[0].data) == int((system.joint_damage.max(axis=1) > 0).sum())
    assert cracks.cell_data["broken"][0].sum() == summary.broken_joints


def test_restart_after_cracks_continues_bit_for_bit(tmp_path):
    whole, _ = _run(_case(tmp_path, end_time=0.004, name="whole.toml"), tmp_path / "whole")
    _run(_case(tmp_path, end_time=0.002, name="part.toml"), tmp_path / "part")
    assert whole.model.system.joint_broken.any()
    second, _ = _run(_case(tmp_path, end_time=0.004, name="part.toml"), tmp_path / "part",
                     restart=tmp_path / "part" / "checkpoint.npz")
    a, b = whole.model.state_arrays(), second.model.state_arrays()
    assert a["clock"][1] == b["clock"][1]
    assert np.array_equal(a["positions"], b["positions"])
    assert np.array_equal(a["joint_damage"], b["joint_damage"])
    assert np.array_equal(a["joint_parted"], b["joint_parted"])


@pytest.mark.parametrize("changes, message", [
    ({"tensile_strength": "0.0"}, "fracture = true needs tensile_strength > 0"),
    ({"cohesion": "0.0"}, "needs cohesion > 0"),
    ({"fracture_energy_mode_ii": "0.0"}, "needs fracture_energy_mode_ii > 0"),
    ({"fracture_energy_mode_i": "-5.0"}, "fracture_energy_mode_i"),
    ({"element_type": '"tet10"'}, 'needs element_type = "tet4"'),
    ({"bodies": "[1]", "fracture_bodies": "[0, 1]"},
     "fracture_bodies lists \\[0\\], which stay rigid"),
    ({"fracture_region_lower": "[5.0, 5.0, 5.0]", "fracture_region_upper": "[6.0, 6.0, 6.0]"},
     "fracture region holds 0 of its tets"),
    ({"friction_angle": "95.0"}, "friction_angle"),
])
def test_bad_fracture_input_is_refused_by_name(tmp_path, changes, message):
    with pytest.raises(RiprapError, match=message):
        _run(_case(tmp_path, end_time=0.001, changes=changes), tmp_path / "out")


def test_a_mesh_too_coarse_to_crack_says_what_is_needed(tmp_path):
    with pytest.raises(RiprapError, match="too coarse to show a crack.*mesh_size of at most"):
        _run(_case(tmp_path, mesh_size=0.2), tmp_path / "out")


def test_the_pieces_of_a_cracked_block_in_water_each_take_their_load(tmp_path):
    """A block cut in two (the joints between the tets either side of x = 0.15 m broken) sinks in
    still water: the fluid sees both pieces' closed surfaces, crack faces included (issue 16,
    item 4), and loads each piece as much per volume as the other (measured within 0.1 %; the
    pieces' own surfaces, not the block's shared out by mass), with no sideways force beyond a
    few per cent of it (Archimedes on each closed surface)."""
    import sys
    from pathlib import Path

    from riprap.case.build_fluid import build_fluid_run

    sys.path.insert(0, str(Path(__file__).parent))
    from test_deformable_in_water_run import CASE as WATER_CASE

    text = WATER_CASE.format(end_time=0.02, more_bodies="").replace(
        "mesh_size = 0.04", "mesh_size = 0.02").replace(
        "tensile_strength = 1.0e4", "tensile_strength = 1.0e4\nfracture = true\ncohesion = 2.0e4\n"
        "fracture_energy_mode_i = 1.0\nfracture_energy_mode_ii = 10.0")
    path = tmp_path / "water.toml"
    path.write_text(text)
    sim = build_fluid_run(load_case(path), output_directory=tmp_path / "out", progress=False)
    system = sim.model.system
    body = system.bodies[0]
    centres = body.positions[body.elements.elements].mean(axis=1)[:, 0]
    sides = centres[body.joint_tets] < 0.15
    cut = sides[:, 0] != sides[:, 1]
    body.joint_broken[cut] = True
    system.update_fragments()
    assert sim.run().end_reason == "end_time"
    outer = int((body.face_joint == -1).sum())
    assert len(sim.model.solver.solids.triangles) == outer + 2 * int(cut.sum())
    table = body.fragment_table()
    assert len(table["mass"]) == 2
    node_fragment = np.zeros(len(body.positions), dtype=np.int64)
    node_fragment[body.elements.elements.ravel()] = np.repeat(table["element_fragment"], 4)
    forces = np.array([body.external_forces[node_fragment == f].sum(axis=0) for f in range(2)])
    per_volume = forces[:, 2] / table["volume"]
    assert per_volume[0] == pytest.approx(per_volume[1], rel=0.02)
    assert np.all(forces[:, 2] > 1000.0 * 9.81 * table["volume"])       # buoyancy and more
    assert np.all(np.abs(forces[:, :2]).max(axis=1) < 0.05 * forces[:, 2])
