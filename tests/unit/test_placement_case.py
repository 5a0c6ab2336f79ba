"""Placement case files: the [slope], [underlayer], [armour] and [placement] tables validate like
every other table, and `riprap place` says what is missing."""
from pathlib import Path

import pytest

from riprap import schema
from riprap.case.load import load_case, parse_case
from riprap.errors import CaseFileError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

MINIMAL = """
format_version = 1
[simulation]
end_time = 1.0
[[materials]]
name = "concrete"
[[materials]]
name = "rock"
[slope]
cotangent = 1.5
width = 3.0
length = 6.0
face_material = "rock"
side_wall_material = "rock"
[underlayer]
material = "rock"
dn50 = 0.2
[armour]
unit = "cube"
material = "concrete"
height = 0.5
[placement]
rows = 3
units_per_row = 3
"""


def test_a_placement_case_needs_no_shapes_or_bodies():
    case = parse_case(MINIMAL)
    assert case.is_placement
    assert case.slope.cotangent == 1.5 and case.slope.toe_level == 0.0
    assert case.underlayer.dn85_over_dn15 == schema.default_of("underlayer", "dn85_over_dn15")
    assert case.armour.unit == "cube" and case.armour.height == 0.5
    assert case.placement.orientation == "random"
    assert case.body_count == 0


def test_a_plain_case_has_no_placement_tables():
    case = load_case(EXAMPLES / "01_rock_drop" / "case.toml")
    assert not case.is_placement and case.slope is None and case.armour is None


def test_placement_tables_report_bad_values_with_lines():
    text = MINIMAL.replace('unit = "cube"', 'unit = "coreloc"').replace(
        'face_material = "rock"', 'face_material = "granite"').replace("cotangent = 1.5",
                                                                       "cotangent = 0.2")
    with pytest.raises(CaseFileError) as error:
        parse_case(text, source="place.toml")
    message = str(error.value)
    assert "place.toml:19: armour.unit = \"coreloc\"" in message and "core_loc_like" in message
    assert "place.toml:13: slope.face_material = \"granite\"" in message
    assert "place.toml:10: slope.cotangent = 0.2: out of range" in message


def test_schema_lists_the_armour_unit_kinds_of_the_library():
    from riprap.geometry.armour_units import UNIT_KINDS

    assert schema.UNIT_KINDS == UNIT_KINDS


def test_place_needs_all_four_tables(tmp_path):
    from riprap.cli import main

    case = tmp_path / "no_armour.toml"
    text = MINIMAL.split("[armour]")[0] + "[placement]\nrows = 3\nunits_per_row = 3\n"
    case.write_text(text)
    assert main(["place", str(case), "--out", str(tmp_path / "out"), "--quiet"]) == 2


def test_run_refuses_a_placement_case(tmp_path, capsys):
    from riprap.cli import main

    case = tmp_path / "place.toml"
    case.write_text(MINIMAL)
    assert main(["run", str(case), "--quiet"]) == 2
    assert "riprap place" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["coreloc_small.toml", "coreloc_paper_242.toml"])
def test_placement_examples_are_valid(name):
    case = load_case(EXAMPLES / name)
    assert case.is_placement and case.armour.unit == "core_loc_like"
