"""Absurd physics, extreme numbers, broken includes and meshes are refused before any work, as the
command a user types: exit status 2, one ``riprap: error:`` line naming the file and the key,
entry, body or material, no traceback, nothing written; and ``riprap check`` refuses the same.

Issue 35's kinds: extreme numbers reaching the numerics (positions, spins, mesh sizes, moduli and
penalties that make the stable step zero or not a number), a body far lighter than the water, a
[waves] still-water level unlike the water regions', a porous polygon that crosses itself or a
porous zone over the wave maker, a volume mesh with an overlapping tetrahedron, a pack that
includes itself or is not a pack, numpy reprs and '?' in messages, a wave train's duration.
"""
import errno
import os
from pathlib import Path

import meshio
import numpy as np
import pytest

from riprap.cli import main
from riprap.errors import CaseFileError
from test_cli_bad_inputs import FLUID, PLACEMENT, RIGID, _edit

# RIGID's one body spinning or placed far away; FLUID with a body, a flume, porous zones.
BODY_IN_WATER = (_edit(_edit(FLUID, "upper = [0.2, 0.02, 0.1]", "upper = [0.2, 0.2, 0.1]"),
                       "cells = [20, 2, 10]", "cells = [10, 10, 5]")
                 + '[[materials]]\nname = "foam"\ndensity = 50.0\n[[shapes]]\nname = "c"\n'
                 'type = "cube"\nside = 0.06\n[[bodies]]\nshape = "c"\nmaterial = "foam"\n'
                 'position = [0.1, 0.1, 0.05]\n')
FLUME = (_edit(_edit(_edit(FLUID, "upper = [0.2, 0.02, 0.1]", "upper = [6.0, 0.02, 0.44]"),
                     "cells = [20, 2, 10]", "cells = [300, 1, 22]\nsurface_tension = 0.0"),
               "level = 0.05", "level = 0.3")
         + '[waves]\ntype = "linear"\nstill_water_level = 0.3\nheight = 0.04\nperiod = 1.0\n')
IRREGULAR = _edit(FLUME, 'type = "linear"\nstill_water_level = 0.3\nheight = 0.04\nperiod = 1.0',
                  'type = "irregular"\nstill_water_level = 0.3\nsignificant_height = 0.04\n'
                  'peak_period = 1.0')
POROUS = '[[porous_zones]]\ntype = "polygon"\nporosity = 0.4\nstone_diameter = 0.02\npoints = {}\n'
DEFORMABLE = RIGID + ('[deformable]\nbodies = "all"\nyoung_modulus = 1e9\ntensile_strength = 3e6\n'
                      'cohesion = 6e6\nfracture = true\nfracture_energy_mode_i = 100.0\n'
                      'fracture_energy_mode_ii = 1000.0\n')
MESH_FILE_CASE = _edit(RIGID, 'type = "cube"\nside = 0.1', 'type = "mesh_file"\nfile = "cube.vtu"')
PACK_HEADER = "# riprap pack: 1 bodies, 1 shapes; written by hand for this test\n"

# name -> (case text, the command that would run it, phrases the error must contain)
ABSURD_CASES = {
    "spin_1e308": (_edit(RIGID, "position = [0.0, 0.0, 0.06]",
                         "position = [0.0, 0.0, 0.06]\nangular_velocity = [0.0, 0.0, 1e308]"),
                   "run", ["[[bodies]] entry 1", "angular_velocity", "surface"]),
    "start_velocity_1e5": (_edit(RIGID, "position = [0.0, 0.0, 0.06]",
                                 "position = [0.0, 0.0, 0.06]\nvelocity = [1e5, 0.0, 0.0]"),
                           "run", ["[[bodies]] entry 1", "velocity", "100 m/s"]),
    "position_1e308": (_edit(RIGID, "position = [0.0, 0.0, 0.06]", "position = [0.0, 0.0, 1e308]"),
                       "run", ["[[bodies]] entry 1", "position", "1e+308"]),
    "grid_spacing_1e308": (RIGID + '[[body_grids]]\nshapes = ["cube"]\nmaterial = "rock"\n'
                           'origin = [1.0, 0.0, 0.06]\nspacing = [1e308, 0.2, 0.2]\n'
                           'counts = [2, 1, 1]\n', "run", ["[[body_grids]] entry 1", "spacing"]),
    "mesh_size_1e-308": (_edit(RIGID, "side = 0.1", "side = 0.1\nmesh_size = 1e-308"), "run",
                         ["[[shapes]] 'cube'", "mesh_size", "tetrahedra"]),
    "weightless_body_in_water": (BODY_IN_WATER, "run",
                                 ["[[materials]] 'foam'", "[[bodies]] entry 1", "density = 50 kg/m^3", "0.3"]),
    "still_water_level_unlike_the_water": (_edit(FLUME, "still_water_level = 0.3",
                                                 "still_water_level = 0.32"),
                                           "run", ["still_water_level = 0.32", "level = 0.3"]),
    "porous_polygon_crossing_itself": (
        FLUME + POROUS.format("[[2.0, 0.0], [3.0, 0.3], [3.0, 0.0], [2.0, 0.3]]"), "run",
        ["[[porous_zones]] entry 1", "crosses itself"]),
    "porous_zone_over_the_wave_maker": (
        FLUME + POROUS.format("[[0.1, 0.0], [3.0, 0.3], [3.0, 0.0]]"), "run",
        ["[[porous_zones]] entry 1", "generation zone"]),
    "porous_zone_over_the_boundary_wave_maker": (
        _edit(FLUME, "period = 1.0", 'period = 1.0\ngeneration = "boundary"')
        + POROUS.format("[[0.0, 0.0], [0.0, 0.3], [3.0, 0.0]]"), "run",
        ["[[porous_zones]] entry 1", "boundary"]),
    "wave_train_duration_1e308": (_edit(IRREGULAR, "peak_period = 1.0",
                                        "peak_period = 1.0\nduration = 1e308"),
                                  "run", ["[waves]", "duration = 1e+308", "components"]),
    "significant_height_1e308": (_edit(IRREGULAR, "significant_height = 0.04",
                                       "significant_height = 1e308\nduration = 20.0"),
                                 "run", ["waves.significant_height = 1e+308", "far outside any physical value"]),
    "joint_penalty_1e308": (DEFORMABLE + "joint_penalty = 1e308\n", "run",
                            ["deformable.joint_penalty = 1e+308", "far outside any physical value"]),
    "deformable_viscosity_1e20": (DEFORMABLE + "viscosity = 1e20\n", "run",
                                  ["deformable.viscosity = 1e+20", "far outside any physical value"]),
    "young_modulus_1e308": (_edit(DEFORMABLE, "young_modulus = 1e9", "young_modulus = 1e308"),
                            "run", ["deformable.young_modulus = 1e+308", "far outside any physical value"]),
    "overlapping_tetrahedron_in_a_volume_mesh": (MESH_FILE_CASE, "run",
                                                 ["cube.vtu", "overlapping"]),
    "pack_that_is_a_plain_case": ('format_version = 1\npack = "plain.toml"\n[simulation]\n'
                                  'end_time = 0.01\n', "run",
                                  ["plain.toml", "not a pack written by riprap place"]),
    "pack_that_includes_itself": ('format_version = 1\npack = "a.toml"\n[simulation]\n'
                                  'end_time = 0.01\n', "run",
                                  ["a.toml -> ", "b.toml -> ", "includes itself"]),
    "fluid_box_to_1e308": (_edit(FLUID, "upper = [0.2, 0.02, 0.1]", "upper = [1e308, 0.02, 0.1]"),
                           "run", ["[fluid]", "upper", "1e+308"]),
    "wall_point_at_1e308": (_edit(RIGID, "point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 1e308]"),
                            "run", ["[[walls]] entry 1", "point"]),
    "porous_stone_diameter_1e-308": (FLUME + POROUS.format("[[3.0, 0.0], [4.0, 0.3], [4.0, 0.0]]")
                                     .replace("stone_diameter = 0.02", "stone_diameter = 1e-308"),
                                     "run", ["stone_diameter = 1e-308", "far outside any physical value"]),
    "grid_file_row_at_1e308": (_edit(PLACEMENT, "rows = 3\nunits_per_row = 3",
                                     'grid_file = "far_grid.csv"'), "place", ["far_grid.csv:3"]),
    "mesh_file_scale_1e150": (_edit(MESH_FILE_CASE, 'file = "cube.vtu"',
                                    'file = "good_cube.vtu"\nscale = 1e150'), "run",
                              ["[[shapes]] 'cube'", "scale", "good_cube.vtu"]),
    # a sphere this small is refused by its radius; a mesh file's body by its extent (issue 52:
    # it passed check with 2.8e7 steps estimated, then ran for ever)
    "mesh_file_a_micrometre_across": (_edit(MESH_FILE_CASE, 'file = "cube.vtu"', 'file = "tiny.vtu"'),
                                      "run", ["[[shapes]] 'cube'", "tiny.vtu", "extent 1e-06 m",
                                              "outside the sizes riprap meshes"]),
    "mesh_file_vertex_at_1e300": (_edit(MESH_FILE_CASE, 'file = "cube.vtu"', 'file = "far.vtu"'),
                                  "run", ["far.vtu", "from the origin"]),
}

def _write_inputs(tmp_path):
    """The files the cases name: a cube mesh with one extra tetrahedron inside it (about 1 % more
    volume, joined to the rest by no face), a plain case, and two packs that include each other."""
    from riprap.geometry import shapes

    cube = shapes.cube(side=0.1, mesh_size=0.05)
    side = (0.01 * 1e-3 * 6.0) ** (1.0 / 3.0)
    extra = cube.nodes.mean(axis=0) + np.array([[0, 0, 0], [side, 0, 0], [0, side, 0],
                                                [0, 0, side]])
    n = len(cube.nodes)
    meshio.write(tmp_path / "cube.vtu", meshio.Mesh(
        np.vstack([cube.nodes, extra]), [("tetra", np.vstack([cube.tets, [[n, n + 1, n + 2, n + 3]]]))]))
    meshio.write(tmp_path / "good_cube.vtu", meshio.Mesh(cube.nodes, [("tetra", cube.tets)]))
    meshio.write(tmp_path / "tiny.vtu", meshio.Mesh(cube.nodes * 1e-5, [("tetra", cube.tets)]))
    meshio.write(tmp_path / "far.vtu", meshio.Mesh(cube.nodes + 1e300, [("tetra", cube.tets)]))
    (tmp_path / "far_grid.csv").write_text("x,y,z\n1.0,1.0,1.0\n1e308,1.0,1.0\n")
    (tmp_path / "plain.toml").write_text(RIGID)
    pack_tables = RIGID.split("\n", 1)[1]
    (tmp_path / "a.toml").write_text(PACK_HEADER + 'format_version = 1\npack = "b.toml"\n'
                                     + pack_tables)
    (tmp_path / "b.toml").write_text(PACK_HEADER + 'format_version = 1\npack = "a.toml"\n'
                                     + pack_tables)


@pytest.mark.parametrize("name", sorted(ABSURD_CASES))
def test_absurd_input_is_refused_by_run_and_check(name, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    text, command, phrases = ABSURD_CASES[name]
    _write_inputs(tmp_path)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main([command, str(path), "--out", str(out), "--quiet"]) == 2
    error = capsys.readouterr().err
    _assert_one_named_line(error, phrases)
    assert not (out / "summary.json").exists(), "nothing was simulated"
    assert main(["check", str(path)]) == 2
    _assert_one_named_line(capsys.readouterr().err, phrases)


def _assert_one_named_line(error, phrases):
    lines = [line for line in error.splitlines() if line.startswith("riprap: error:")]
    assert len(lines) == 1, error
    assert "Traceback" not in error and "did not expect" not in error, error
    assert "np." not in error, error
    for phrase in phrases:
        assert phrase in lines[0], (phrase, error)


def test_a_sane_flume_with_a_porous_core_and_matching_levels_is_valid(tmp_path, capsys):
    """The checks above refuse only what is wrong: a core clear of the wave maker, a convex
    outline, the water at the still-water level."""
    path = tmp_path / "flume.toml"
    path.write_text(FLUME + POROUS.format("[[2.5, 0.0], [3.9, 0.4], [3.9, 0.0]]"))
    assert main(["check", str(path)]) == 0, capsys.readouterr().err


def test_a_body_at_a_third_of_the_water_density_is_accepted(tmp_path, capsys):
    path = tmp_path / "wood.toml"
    path.write_text(_edit(BODY_IN_WATER, "density = 50.0", "density = 600.0"))
    assert main(["check", str(path)]) == 0, capsys.readouterr().err


def test_numpy_reprs_never_reach_a_message():
    value = np.float64(0.28)
    error = CaseFileError(f"dn50 = {value!r} m, corners {(np.float64(1.5), np.int64(3))}, "
                          f"{np.True_!r}")
    assert str(error) == "dn50 = 0.28 m, corners (1.5, 3), True"
    grouped = CaseFileError.from_problems([f"a = {np.float64(2.0)!r}"], 5)
    assert str(grouped) == "a = 2.0"


def test_a_full_disk_names_the_file_being_written(tmp_path, capsys, monkeypatch):
    """A full disk fails in write(), whose error names no file: the message names summary.json."""
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    path = tmp_path / "case.toml"
    path.write_text(RIGID)
    written = Path.write_text

    def full_disk(self, *args, **kwargs):
        if self.name.startswith("summary.json"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return written(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full_disk)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    error = capsys.readouterr().err
    assert "summary.json: No space left on device" in error and "?" not in error
    assert "free some space" in error


def test_a_packs_cycle_through_one_file_is_named(tmp_path, capsys):
    """A pack that names itself is the shortest cycle."""
    path = tmp_path / "self.toml"
    path.write_text(PACK_HEADER + 'format_version = 1\npack = "self.toml"\n'
                    + RIGID.split("\n", 1)[1])
    assert main(["check", str(path)]) == 2
    error = capsys.readouterr().err
    assert f"{path} -> {path}" in error and "remove the 'pack' key" in error


SPIN = "position = [0.0, 0.0, 0.06]\nangular_velocity = [0.0, 0.0, 1e200]"


@pytest.mark.parametrize("model", ["rigid", "deformable", "coupled"])
def test_a_state_turning_non_finite_stops_with_the_failure_checkpoint(model, tmp_path, capsys,
                                                                       monkeypatch):
    """Past the start checks (switched off here: the API takes any number), a state that becomes
    non-finite stops the run with exit 2 and the failure checkpoint, never a summary."""
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    monkeypatch.setattr("riprap.case.build.check_body_starts", lambda case, radius_of: None)
    text = {"rigid": _edit(RIGID, "position = [0.0, 0.0, 0.06]", SPIN),
            "deformable": _edit(DEFORMABLE, "position = [0.0, 0.0, 0.06]", SPIN),
            "coupled": _edit(_edit(BODY_IN_WATER, "density = 50.0", "density = 2400.0"),
                             "position = [0.1, 0.1, 0.05]",
                             "position = [0.1, 0.1, 0.05]\nangular_velocity = [0.0, 0.0, 1e200]")
            }[model]
    path = tmp_path / "spin.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    error = capsys.readouterr().err
    assert "Traceback" not in error and "did not expect" not in error, error
    assert (out / "failure_checkpoint.npz").is_file(), error
    assert not (out / "summary.json").exists()


def test_a_wall_normal_of_1e308_is_a_direction(tmp_path, capsys):
    """Directions are normalised without squaring (1e308 squared overflows to a zero normal)."""
    path = tmp_path / "normal.toml"
    path.write_text(_edit(RIGID, "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 1e308]"))
    assert main(["check", str(path)]) == 0, capsys.readouterr().err


def test_a_fluid_step_needing_too_many_contact_sub_steps_stops_the_run():
    from riprap.coupling.coupled import MAXIMUM_SUBSTEPS, check_substeps
    from riprap.errors import InstabilityError

    check_substeps(MAXIMUM_SUBSTEPS, 1e-3, 1e-8)
    with pytest.raises(InstabilityError, match="contact sub-steps"):
        check_substeps(MAXIMUM_SUBSTEPS + 1, 1e-3, 1e-9)


def test_a_tetrahedron_on_the_same_side_of_a_face_as_its_neighbour_is_refused():
    """An extra tetrahedron built on a boundary face but reaching into the body overlaps the one
    that owns the face: every such mesh is refused naming the file, most of them because the two
    lie on the same side of the face they share."""
    from riprap.errors import MeshError
    from riprap.geometry import shapes
    from riprap.geometry.tetmesh import TetMesh

    cube = shapes.cube(side=0.1, mesh_size=0.05)
    face = cube.boundary_faces()[0]
    reasons = []
    for node in set(range(len(cube.nodes))) - set(face.tolist()):
        mesh = TetMesh.from_arrays(cube.nodes, np.vstack([cube.tets, [*face[[0, 2, 1]], node]]),
                                   name="cube.vtu", fix_orientation=True)
        with pytest.raises(MeshError, match="cube.vtu") as error:
            mesh.check()
        reasons.append("same side" in str(error.value))
    assert sum(reasons) > len(reasons) // 2
