"""Friction per pair of materials (``[[friction]]``, issue 51 item 3): a listed pair takes its own
coefficient in the rigid pair tables, the others the smaller of the two materials'; the pairs go
through ``riprap place`` into the pack, from the pack into a run and into the layer analysis, and
``riprap check`` lists every pair that meets with its coefficient and where it came from. (The
tilting test in tests/verification/test_tilting_friction.py shows the kernel sliding at them.)
"""
import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import load_case, parse_case
from riprap.case.run_record import case_record
from riprap.cli import main
from riprap.errors import CaseFileError
from riprap.solid.materials import (FROM_FRICTION_TABLE, FROM_PAIR_RULE, FrictionPair, Material,
                                    friction_table, pair_tables)
from riprap.workflows.layer_input import load_pack_state
from test_cli_bad_inputs import PLACEMENT, RIGID

CONCRETE_ON_ROCK = 0.75
PAIR = '[[friction]]\nmaterials = ["concrete", "rock"]\nfriction_coefficient = 0.75\n'


def test_a_listed_pair_takes_its_own_coefficient_the_others_the_smaller_of_two():
    materials = [Material(name="concrete", friction_coefficient=0.6),
                 Material(name="rock", friction_coefficient=0.5),
                 Material(name="glass", friction_coefficient=0.2)]
    pairs = [FrictionPair(materials=("rock", "concrete"), friction_coefficient=0.7),
             FrictionPair(materials=("concrete", "concrete"), friction_coefficient=0.8)]
    table = friction_table(materials, pairs)
    expected = [[0.8, 0.7, 0.2], [0.7, 0.5, 0.2], [0.2, 0.2, 0.2]]
    assert table.tolist() == expected
    assert pair_tables(materials, pairs)["friction"].tolist() == expected
    assert friction_table(materials).tolist() == [[0.6, 0.5, 0.2], [0.5, 0.5, 0.2],
                                                  [0.2, 0.2, 0.2]]


@pytest.mark.parametrize("materials, coefficient, words", [
    (("concrete",), 0.7, "exactly two"), (("concrete", "rock", "rock"), 0.7, "exactly two"),
    (("concrete", "rock"), 2.5, "[0, 2]"), (("concrete", "rock"), -0.1, "[0, 2]")])
def test_a_bad_pair_is_refused_in_python_too(materials, coefficient, words):
    with pytest.raises(CaseFileError, match=words.replace("[", r"\[").replace("]", r"\]")):
        FrictionPair(materials=materials, friction_coefficient=coefficient)


def test_the_solver_refuses_a_pair_twice_or_a_pair_of_an_unknown_material():
    sim = build_simulation(parse_case(RIGID + PAIR.replace("concrete", "rock", 1)))
    with pytest.raises(CaseFileError, match="given twice"):
        sim.add_friction_pair(FrictionPair(materials=("rock", "rock"), friction_coefficient=0.3))
    sim.add_friction_pair(FrictionPair(materials=("rock", "steel"), friction_coefficient=0.3))
    with pytest.raises(CaseFileError, match="material 'steel', which is not defined"):
        sim.prepare()


def test_check_lists_the_pairs_that_meet_with_their_source(tmp_path, capsys):
    case = tmp_path / "case.toml"
    case.write_text(RIGID.replace('material = "rock"\nposition', 'material = "concrete"\nposition')
                    + '[[materials]]\nname = "concrete"\nfriction_coefficient = 0.7\n' + PAIR)
    assert main(["check", str(case), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert f"concrete-rock: {CONCRETE_ON_ROCK:g} ({FROM_FRICTION_TABLE})" in out
    assert f"concrete-concrete: 0.7 ({FROM_PAIR_RULE}: concrete 0.7)" in out
    assert "rock-rock" not in out           # the rock is a wall only: walls never meet walls


def test_check_lists_a_placements_pairs(tmp_path, capsys):
    case = tmp_path / "place.toml"
    case.write_text(PLACEMENT.replace('side_wall_material = "rock"', 'side_wall_material = "glass"')
                    + '[[materials]]\nname = "glass"\nfriction_coefficient = 0.2\n' + PAIR
                    + '[[friction]]\nmaterials = ["glass", "concrete"]\n'
                      'friction_coefficient = 0.3\n')
    assert main(["check", str(case)]) == 0
    out = capsys.readouterr().out
    assert f"concrete-rock: {CONCRETE_ON_ROCK:g} ({FROM_FRICTION_TABLE})" in out
    assert f"concrete-glass: 0.3 ({FROM_FRICTION_TABLE})" in out
    assert f"glass-rock: 0.2 ({FROM_PAIR_RULE}: glass 0.2, rock 0.6)" in out
    assert f"rock-rock: 0.6 ({FROM_PAIR_RULE}: rock 0.6)" in out


def test_a_restart_record_names_the_pairs_and_leaves_out_an_empty_table():
    assert not any(key.startswith("[[friction]]") for key in case_record(parse_case(RIGID)))
    record = case_record(parse_case(RIGID + PAIR.replace("concrete", "rock", 1)))
    assert record["[[friction]] entry 1 friction_coefficient"] == "0.75"


@pytest.fixture(scope="module")
def placed(tmp_path_factory):
    """A smoke-mode ``riprap place`` of the minimal placement with a concrete-rock pair."""
    folder = tmp_path_factory.mktemp("placed")
    case = folder / "place.toml"
    case.write_text(PLACEMENT + PAIR)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RIPRAP_SMOKE", "1")
        assert main(["place", str(case), "--out", str(folder / "pack"), "--quiet"]) == 0
    return folder / "pack"


def test_place_writes_the_pairs_into_the_pack_and_a_run_from_it_keeps_them(placed, tmp_path):
    assert PAIR.strip() in (placed / "pack.toml").read_text()
    case = tmp_path / "run.toml"
    case.write_text(f'format_version = 1\npack = "{placed / "pack.toml"}"\n'
                    "[simulation]\nend_time = 0.01\n")
    sim = build_simulation(load_case(case))
    names = [m.name for m in sim.solver.materials]
    concrete, rock = names.index("concrete"), names.index("rock")
    assert sim.solver.friction_table[concrete, rock] == CONCRETE_ON_ROCK
    assert sim.solver.friction_table[rock, rock] == 0.6


def test_a_case_with_a_pack_may_add_a_pair_of_the_packs_materials(placed, tmp_path):
    case = tmp_path / "run.toml"
    head = f'format_version = 1\npack = "{placed / "pack.toml"}"\n[simulation]\nend_time = 0.01\n'
    case.write_text(head + '[[friction]]\nmaterials = ["concrete", "concrete"]\n'
                           'friction_coefficient = 0.8\n')
    assert [(p.materials, p.friction_coefficient) for p in load_case(case).friction] == [
        (("concrete", "rock"), CONCRETE_ON_ROCK), (("concrete", "concrete"), 0.8)]
    case.write_text(head + '[[friction]]\nmaterials = ["rock", "concrete"]\n'
                           'friction_coefficient = 0.9\n[[friction]]\n'
                           'materials = ["concrete", "steel"]\nfriction_coefficient = 0.5\n')
    with pytest.raises(CaseFileError) as error:
        load_case(case)
    assert str(error.value).split("\n") == [
        f'{case}:6: friction[0].materials = ["rock", "concrete"]: the pack {placed / "pack.toml"} '
        "gives the pair concrete-rock already (friction_coefficient = 0.75); a pack keeps its "
        "pairs: remove this entry",
        f'{case}:9: friction[1].materials[1] = "steel": no [[materials]] entry has this name; '
        'defined names: "concrete", "rock"']


def test_the_layer_analysis_takes_the_pairs_friction(placed):
    state = load_pack_state(placed)
    assert [p.materials for p in state.friction_pairs] == [("concrete", "rock")]
    names = [m.name for m in state.materials]
    contacts = state.contacts
    assert len(contacts) > 0
    other = np.where(contacts.body_j >= 0, state.material_of_body[np.maximum(contacts.body_j, 0)],
                     state.wall_materials[np.maximum(-1 - contacts.body_j, 0)])
    pair = {tuple(sorted((names[a], names[b])))
            for a, b in zip(state.material_of_body[contacts.body_i], other)}
    friction = state.contact_friction()
    for row, (a, b) in enumerate(zip(state.material_of_body[contacts.body_i], other)):
        expected = CONCRETE_ON_ROCK if {names[a], names[b]} == {"concrete", "rock"} else 0.6
        assert friction[row] == expected
    assert ("concrete", "rock") in pair
