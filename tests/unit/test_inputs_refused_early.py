"""Work refused before it starts (issue 35), and ``riprap check`` agreeing with ``riprap run`` and
``riprap place``: check passes every shipped example; schedules that cannot advance, absurd body
counts, integers beyond 64 bits, bodies needing billions of steps, keys far outside any physical
range, placement cases that place would refuse later and bad [[friction]] pairs are all refused
by both commands, with exit status 2, one line naming the file / key / body, no traceback and
nothing written.
"""
from pathlib import Path

import numpy as np
import pytest

from riprap.cli import main
from riprap.errors import CaseFileError, RiprapError
from test_cli_bad_inputs import FLUID, PLACEMENT, RIGID, _edit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

EXAMPLE_CASES = sorted([*EXAMPLES.glob("*/case.toml"), *EXAMPLES.glob("*/deformable.toml"),
                        *EXAMPLES.glob("*.toml")])


@pytest.mark.parametrize("path", EXAMPLE_CASES, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_check_passes_every_shipped_example(path, tmp_path, capsys):
    assert main(["check", str(path), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "valid" in out
    assert not (tmp_path / "out").exists(), "check writes nothing"


def test_check_reports_the_deformable_step_and_work(capsys):
    # all bodies deformable: check used to fail with a TypeError (no rigid time step)
    assert main(["check", str(EXAMPLES / "07_unit_impact" / "case.toml")]) == 0
    out = capsys.readouterr().out
    assert "3 deformable bodies" in out
    assert "deformable bodies' stable time step" in out and "steps of" in out


_GRID = ('[[body_grids]]\nshapes = ["cube"]\nmaterial = "rock"\norigin = [0.0, 0.0, 1.0]\n'
         'spacing = [0.2, 0.2, 0.2]\ncounts = [{}]\n')
# a 0.2 mm cube for 1e4 s: 1e12 steps of its contact (rigid) or element (deformable) time step
_TINY_RIGID = (_edit(RIGID, 'type = "cube"\nside = 0.1', 'type = "cube"\nside = 2e-4')
               .replace("position = [0.0, 0.0, 0.06]", "position = [0.0, 0.0, 1.01e-4]")
               .replace("end_time = 0.01", "end_time = 1.0e4\noutput_interval = 1.0"))
_TINY_IN_WATER = (_edit(FLUID, "end_time = 0.01", "end_time = 1.0e4\noutput_interval = 1.0")
                  + '[[materials]]\nname = "rock"\n[[shapes]]\nname = "c"\ntype = "cube"\n'
                    'side = 2e-4\n[[bodies]]\nshape = "c"\nmaterial = "rock"\n'
                    'position = [0.1, 0.01, 0.08]\n')
_BIG_CORELOC = (EXAMPLES / "coreloc_small.toml").read_text()
_PAIR = "[[friction]]\nmaterials = [{}]\nfriction_coefficient = {}\n"

# name -> (case text, the command that would run it, phrases the error must contain)
BROKEN_CASES = {
    # schedules that cannot advance
    "output_interval_1e-300": (
        _edit(RIGID, "end_time = 0.01", "end_time = 0.01\noutput_interval = 1e-300"), "run",
        ("simulation.output_interval = 1e-300", "frames", "1000000")),
    "checkpoint_interval_1e-9": (
        _edit(FLUID, "end_time = 0.01", "end_time = 0.01\ncheckpoint_interval = 1e-9"), "run",
        ("simulation.checkpoint_interval = 1e-09", "checkpoints", "10000")),
    # body counts and integers
    "body_grid_of_ten_trillion": (RIGID + _GRID.format("100000, 100000, 1000"), "run",
                                  ("body_grids[0].counts", "1e+13 bodies", "1,000,000")),
    "body_grid_in_a_fluid_case": (
        FLUID + '[[materials]]\nname = "rock"\n[[shapes]]\nname = "cube"\ntype = "cube"\n'
        'side = 0.01\n' + _GRID.format("1000000, 1000000, 1"), "run", ("body_grids[0].counts",)),
    "count_beyond_64_bits": (RIGID + _GRID.format("100000000000000000000, 1, 1"), "run",
                             ("body_grids[0].counts", "beyond 64 bits")),
    "seed_beyond_64_bits": (
        _edit(RIGID, "end_time = 0.01", "end_time = 0.01\nseed = 100000000000000000000"), "run",
        ("simulation.seed", "beyond 64 bits")),
    # billions of steps, in every kind of run with bodies
    "tiny_rigid_body": (_TINY_RIGID, "run", ("steps of", "1 moving bodies")),
    "tiny_deformable_body": (_TINY_RIGID + "[deformable]\n", "run", ("steps of", "elements")),
    "tiny_deformable_body_on_a_rigid_one": (
        _TINY_RIGID + '[[bodies]]\nshape = "cube"\nmaterial = "rock"\nposition = [0.0, 0.0, 4e-4]\n'
        "[deformable]\nbodies = [1]\n", "run", ("steps of", "elements")),
    "tiny_body_in_water": (_TINY_IN_WATER, "run", ("steps of", "1 moving bodies")),
    "tiny_deformable_body_in_water": (_TINY_IN_WATER + "[deformable]\n", "run",
                                      ("steps of", "elements")),
    # keys far outside any physical range
    "water_viscosity_1e12": (
        _edit(FLUID, "cells = [20, 2, 10]", "cells = [20, 2, 10]\nwater_viscosity = 1e12"), "run",
        ("fluid.water_viscosity = 1e+12", "far outside", "[1e-05, 100] Pa s")),
    "mass_damping_1e12": (RIGID + "[deformable]\nmass_damping = 1e12\n", "run",
                          ("deformable.mass_damping = 1e+12", "far outside", "1/s")),
    "gravity_in_mm_per_s2": (
        _edit(RIGID, "end_time = 0.01", "end_time = 0.01\ngravity = [0.0, 0.0, -9810.0]"), "run",
        ("simulation.gravity", "far outside", "for each component")),
    "young_modulus_in_kPa_typo": (RIGID + "[deformable]\nyoung_modulus = 30e19\n", "run",
                                  ("deformable.young_modulus", "far outside")),
    "wave_period_in_ms": (
        FLUID + '[waves]\ntype = "linear"\nstill_water_level = 0.05\nheight = 0.01\n'
        "period = 1200.0\n", "run", ("waves.period = 1200.0", "far outside")),
    # the pressure solve's volume stop and the adaptive contact step (issue 37)
    "pressure_volume_tolerance_of_a_tenth": (
        _edit(FLUID, "cells = [20, 2, 10]", "cells = [20, 2, 10]\npressure_volume_tolerance = 0.1"),
        "run", ("fluid.pressure_volume_tolerance = 0.1", "[0, 0.01)")),
    "pressure_volume_tolerance_negative": (
        _edit(FLUID, "cells = [20, 2, 10]", "cells = [20, 2, 10]\npressure_volume_tolerance = -1e-6"),
        "run", ("fluid.pressure_volume_tolerance = -1e-06",)),
    "adaptive_time_step_as_a_number": (
        _edit(RIGID, "end_time = 0.01", "end_time = 0.01\nadaptive_time_step = 1"), "run",
        ("simulation.adaptive_time_step",)),
    "adaptive_time_step_for_deformable_bodies": (
        _edit(RIGID, "end_time = 0.01", "end_time = 0.01\nadaptive_time_step = true")
        + "[deformable]\n", "run", ("adaptive_time_step = true", "deformable bodies")),
    "adaptive_time_step_for_deformable_bodies_in_water": (
        _edit(_TINY_IN_WATER, "end_time = 1.0e4", "end_time = 0.01\nadaptive_time_step = true")
        .replace("output_interval = 1.0", "output_interval = 0.005").replace("side = 2e-4", "side = 0.06")
        + "[deformable]\n", "run", ("adaptive_time_step = true", "deformable bodies")),
    # placement cases that place used to refuse only after the underlayer run, or never
    "millimetre_flume": (_edit(PLACEMENT, "width = 3.0", "width = 0.001"), "place",
                         ("slope.width = 0.001", "far outside")),
    "hundred_thousand_rows": (_edit(PLACEMENT, "rows = 3", "rows = 100000"), "place",
                              ("design grid", "beyond its length")),
    "a_billion_underlayer_rocks": (
        _edit(PLACEMENT, "height = 0.5", "height = 0.025")
        .replace("dn50 = 0.2", "dn50 = 0.01").replace("width = 3.0", "width = 500.0")
        .replace("length = 6.0", "length = 500.0"), "place", ("underlayer:", "1,000,000 bodies")),
    "deposition_of_a_million_seconds": (
        _edit(PLACEMENT, "units_per_row = 3", "units_per_row = 3\nsettle_time = 1.0e6")
        .replace("end_time = 1.0", "end_time = 1.0\noutput_interval = 10.0"), "place",
        ("steps of", "9 moving bodies")),
    "placement_frames_every_microsecond": (
        _edit(PLACEMENT, "end_time = 1.0", "end_time = 1.0\noutput_interval = 1e-6"), "place",
        ("simulation.output_interval = 1e-06", "in placement.settle_time = 10 s")),
    "underlayer_settling_for_a_million_seconds": (
        _edit(PLACEMENT, "dn50 = 0.2", "dn50 = 0.2\nsettle_time = 1.0e6")
        .replace("end_time = 1.0", "end_time = 1.0\noutput_interval = 10.0"), "place",
        ("steps of", "143 moving bodies")),
    "a_billion_rock_shapes": (_edit(PLACEMENT, "dn50 = 0.2", "dn50 = 0.2\nrock_shapes = 1000000000"),
                             "place", ("underlayer.rock_shapes = 1000000000", "[1, 1000]")),
    "more_size_classes_than_shapes": (_edit(PLACEMENT, "dn50 = 0.2", "dn50 = 0.2\nsize_classes = 10"),
                                      "place", ("underlayer.size_classes = 10", "rock_shapes = 6")),
    "units_wider_than_the_row": (_edit(PLACEMENT, "units_per_row = 3", "units_per_row = 7"),
                                 "place", ("units_per_row = 7", "3.5 m across", "3 m wide")),
    "three_metre_units_on_small_rocks": (
        _edit(_BIG_CORELOC, "\nheight = 1.0", "\nheight = 3.0"), "place",
        ("Dn / Dn50 = 6.03", "W/10 to W/15", "1.3 to 4")),
    "units_on_stones_of_their_own_size": (_edit(PLACEMENT, "dn50 = 0.2", "dn50 = 0.45"), "place",
                                          ("Dn / Dn50 = 1.11", "own size")),
    "deformable_in_a_placement_case": (PLACEMENT + "[deformable]\n", "place",
                                       ("deformable:", "ignore [deformable]")),
    # [[friction]] pairs (issue 51): unknown materials, a coefficient outside 0-2, a pair twice or
    # of one name, a pair of a deformable body's material, in runs and placements
    "friction_pair_of_an_unknown_material": (
        RIGID + _PAIR.format('"rock", "concrete"', 0.7), "run",
        ('friction[0].materials[1] = "concrete"', "no [[materials]] entry has this name")),
    "friction_coefficient_of_3": (RIGID + _PAIR.format('"rock", "rock"', 3.0), "run",
                                  ("friction[0].friction_coefficient = 3.0", "[0, 2]")),
    "friction_pair_listed_twice": (
        RIGID + _PAIR.format('"rock", "rock"', 0.7) + _PAIR.format('"rock", "rock"', 0.5), "run",
        ('.toml:23: friction[1].materials = ["rock", "rock"]', "listed twice",
         "friction[0] (line 20)")),
    "friction_pair_of_one_name": (RIGID + _PAIR.format('"rock"', 0.7), "run",
                                  ('friction[0].materials = ["rock"]', "2 strings [a, b]")),
    "friction_pair_of_a_deformable_body": (
        RIGID + _PAIR.format('"rock", "rock"', 0.7) + "[deformable]\n", "run",
        ('[[friction]] materials = ["rock", "rock"]', "deformable body", "rigid contacts only")),
    "friction_pair_of_an_unknown_material_in_a_placement": (
        PLACEMENT + _PAIR.format('"concrete", "glass"', 0.3), "place",
        ('friction[0].materials[1] = "glass"', "defined names")),
    "friction_coefficient_negative_in_a_placement": (
        PLACEMENT + _PAIR.format('"concrete", "rock"', -0.5), "place",
        ("friction[0].friction_coefficient = -0.5", "[0, 2]")),
    "grid_file_with_a_repeated_row": (
        _edit(PLACEMENT, "rows = 3\nunits_per_row = 3", 'grid_file = "repeated.csv"'), "place",
        ("repeated.csv:4", "repeats line 2")),
}


def _write_case(tmp_path, name):
    text, command, phrases = BROKEN_CASES[name]
    (tmp_path / "repeated.csv").write_text("x,y,z\n1.0,1.5,1.0\n2.0,1.5,1.5\n1.0,1.5,1.0\n")
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path, command, phrases


def _one_error_line(err: str) -> str:
    lines = [line for line in err.strip().splitlines() if not line.startswith("riprap: warning")]
    assert len(lines) == 1 and lines[0].startswith("riprap: error:"), err
    assert "Traceback" not in err and "did not expect" not in err
    return lines[0]


@pytest.mark.parametrize("name", sorted(BROKEN_CASES))
def test_run_place_and_check_refuse_alike_before_any_work(name, tmp_path, capsys):
    path, command, phrases = _write_case(tmp_path, name)
    out = tmp_path / "out"
    assert main([command, str(path), "--out", str(out), "--quiet"]) == 2
    run_error = _one_error_line(capsys.readouterr().err)
    for phrase in phrases:
        assert phrase in run_error, (phrase, run_error)
    assert not (out / "summary.json").exists() and not (out / "underlayer").exists()
    assert main(["check", str(path)]) == 2
    check_error = _one_error_line(capsys.readouterr().err)
    assert check_error == run_error


def test_a_long_run_of_sane_keys_is_warned_about_not_refused(tmp_path, capsys):
    # 1e4 s of a 10 cm cube: 2.8e9 steps, about a day; a multi-day test keeps running
    path = tmp_path / "long.toml"
    path.write_text(_edit(RIGID, "end_time = 0.01", "end_time = 1.0e4\noutput_interval = 1.0"))
    assert main(["check", str(path)]) == 0
    captured = capsys.readouterr()
    assert "valid" in captured.out
    assert "riprap: warning: this run will take" in captured.err and "days" in captured.err


def test_units_a_little_outside_the_filter_rule_get_a_warning(tmp_path, capsys):
    path = tmp_path / "place.toml"
    path.write_text(_edit(PLACEMENT, "dn50 = 0.2", "dn50 = 0.15"))    # 0.5 / 0.15 = 3.33
    assert main(["check", str(path)]) == 0
    err = capsys.readouterr().err
    assert "riprap: warning:" in err and "Dn / Dn50 = 3.33" in err and "W/10 to W/15" in err


def test_a_simulation_refuses_a_schedule_that_cannot_advance():
    from riprap.simulation import Simulation

    with pytest.raises(CaseFileError, match="output_interval = 1e-300: 1e\\+300 frames"):
        Simulation(end_time=1.0, output_interval=1e-300)
    with pytest.raises(CaseFileError, match="checkpoint_interval = 1e-09"):
        Simulation(end_time=1.0, checkpoint_interval=1e-9)
    Simulation(end_time=1.0, output_interval=1e-6, checkpoint_interval=1e-4)   # at the limits


class _StuckModel:
    """A model whose clock never moves: the run loop must stop, not spin."""

    kind, name, time, step_count = "riprap rigid run", "stuck", 0.0, 0

    def prepare(self, *, restarted):
        pass

    def open_outputs(self, *args, **kwargs):
        pass

    def write_frame(self, index):
        pass

    def state_arrays(self):
        return {"clock": np.zeros(1)}

    def reached(self, time):
        return time <= 0.0

    def advance(self, until):
        pass

    def last_time_step(self):
        return 1e-3

    def at_rest(self):
        return False

    def after_good_chunk(self):
        pass


def test_a_run_whose_clock_does_not_move_stops_with_an_error(tmp_path):
    from riprap.simulation import Simulation

    sim = Simulation(end_time=1.0, output_directory=tmp_path / "out", progress=False)
    sim._model = _StuckModel()
    with pytest.raises(RiprapError, match="stuck at t = 0 s: 1000 chunks"):
        sim.run()


def test_the_frame_schedule_is_bounded():
    from riprap.simulation import _first_not_reached

    class AlwaysThere:
        time = 1.0

        def reached(self, time):
            return True

    assert _first_not_reached(_StuckModel(), 1, 0.1, 10, "output_interval") == 1
    with pytest.raises(RiprapError, match="ran past 10 entries"):
        _first_not_reached(AlwaysThere(), 1, 0.1, 10, "output_interval")


def test_units_resting_on_units_only_are_listed():
    from types import SimpleNamespace

    from riprap.placement.place import _units_not_on_underlayer

    # bodies 0-1 rocks, 2-5 units; walls 0, 1 ground, 2, 3 side walls
    contacts = SimpleNamespace(body_i=np.array([2, 0, 4, 5, 5]),
                               body_j=np.array([0, 3, -2, 4, -3]))
    solver = SimpleNamespace(contacts=contacts, n_bodies=6)
    # unit 0 (body 2) on a rock, unit 1 (body 3) under a rock's contact, unit 2 (body 4) on the
    # face, unit 3 (body 5) on unit 2 and against a side wall only
    flags = _units_not_on_underlayer(solver, np.array([2, 3, 4, 5]), n_rocks=2,
                                     side_walls=(2, 3))
    assert flags.tolist() == [False, False, False, True]
    # on a periodic strip there are no side walls: wall 2 is the toe stop, which carries a unit
    flags = _units_not_on_underlayer(solver, np.array([2, 3, 4, 5]), n_rocks=2, side_walls=())
    assert flags.tolist() == [False, False, False, False]


@pytest.mark.parametrize("case", ["rigid", "fluid"])
def test_frames_finer_than_the_step_end_with_the_run(case, tmp_path, capsys):
    """Frame and checkpoint times closer than the time step: the run skips the ones a step jumps
    over and ends, its frame count within the schedule's."""
    import json

    text = RIGID if case == "rigid" else FLUID
    text = _edit(text, "end_time = 0.01", "end_time = 0.001\noutput_interval = 1e-6\n"
                 "checkpoint_interval = 1e-6") + "[output]\nparaview = false\npicture = false\n"
    path = tmp_path / "fine.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["end_reason"] == "end_time" and summary["simulated_time"] >= 0.001 * (1 - 1e-9)
    assert 1 <= summary["frames"] <= 1001


# two cubes on a short, narrow 1:3 face, dropped one above the other from a grid file
STACKED = (_edit(PLACEMENT, "cotangent = 1.5\nwidth = 3.0\nlength = 6.0",
                 "cotangent = 3.0\nwidth = 1.2\nlength = 2.0")
           .replace("dn50 = 0.2", "dn50 = 0.2\nlayers = 1\nsettle_time = 0.5")
           .replace("rows = 3\nunits_per_row = 3",
                    'grid_file = "stack.csv"\nrelease = "free_fall"\nsettle_time = 1.5\n'
                    'orientation = "random_within"\nmax_tilt_deg = 0.0'))


def test_place_flags_a_unit_that_lands_on_another_unit(tmp_path, capsys):
    """Two cubes dropped one above the other (about 15 s): the upper one rests on the lower,
    not on the underlayer, and place says so in summary.json and in a warning line."""
    import json

    (tmp_path / "stack.csv").write_text("x,y,z\n0.9,0.6,1.0\n0.9,0.6,1.6\n")
    path = tmp_path / "stack.toml"
    path.write_text(STACKED)
    assert main(["place", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["units_not_on_underlayer"] == [1]
    err = capsys.readouterr().err
    assert "riprap: warning: 1 of 2 units rest on other units, not on the underlayer" in err
