"""The TOML case file: schema, loader and its error messages, generated reference page."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import pytest

from riprap import schema
from riprap.case.load import (
    BodyGridSpec,
    BodySpec,
    Case,
    MaterialSpec,
    OutputSettings,
    ShapeSpec,
    SimulationSettings,
    WallSpec,
    load_case,
    parse_case,
)
from riprap.errors import CaseFileError

REPOSITORY = Path(__file__).resolve().parents[2]
SOURCE = "case.toml"

# Normalising divides by the norm once; the result is a unit vector to a few ulps.
NORMALISATION_TOLERANCE = 1e-12

VALID_CASE = """\
format_version = 1

[simulation]
end_time = 2
time_step_safety = 0.25
gravity = [0, 0, -9.81]

[[materials]]
name = "rock"
friction_coefficient = 0.7

[[materials]]
name = "concrete"
density = 2400

[[shapes]]
name = "stone"
type = "random_rock"
size = 0.2

[[shapes]]
name = "ball"
type = "sphere"
radius = 0.1

[[shapes]]
name = "block"
type = "box"
lengths = [0.2, 0.1, 0.1]

[[bodies]]   # first body
shape = "stone"
material = "rock"
position = [0.0, 0.0, 0.5]
orientation = [2.0, 0.0, 0.0, 0.0]

# [[bodies]] a commented-out header must not shift the count of bodies
[[bodies]]   # second body
shape = "ball"
material = "concrete"
position = [0.0, 0.0, 1.0]
velocity = [1, 0, 0]
fixed = false

[[body_grids]]
shapes = ["stone", "ball"]
material = "rock"
origin = [0.0, 0.0, 2.0]
spacing = [0.4, 0.4, 0.4]
counts = [2, 3, 1]

[[walls]]
type = "plane"
material = "rock"
point = [0, 0, 0]
normal = [0, 0, 2]

[[walls]]
type = "box"
material = "concrete"
min = [-1, -1, 0]
max = [1, 1, 2]

[output]
directory = "out-test"

[[friction]]
materials = ["rock", "concrete"]
friction_coefficient = 0.8
"""


def line_containing(text: str, fragment: str) -> int:
    """1-based number of the first line of ``text`` containing ``fragment``."""
    for number, line in enumerate(text.split("\n"), start=1):
        if fragment in line:
            return number
    raise AssertionError(f"{fragment!r} is not in the text")


def problems_of(text: str, **keywords) -> list[str]:
    with pytest.raises(CaseFileError) as caught:
        parse_case(text, source=SOURCE, **keywords)
    return str(caught.value).split("\n")


def test_case_file_valid_case_parses_with_defaults_filled():
    case = parse_case(VALID_CASE, source=SOURCE)

    assert isinstance(case, Case)
    assert case.format_version == 1
    assert case.source == SOURCE
    assert case.base_dir == Path.cwd()
    assert case.simulation == SimulationSettings(
        end_time=2.0, time_step=0.0, time_step_safety=0.25, gravity=(0.0, 0.0, -9.81),
        output_interval=0.05, checkpoint_interval=0.0, local_damping=0.0, rest_speed=0.0, seed=0,
    )
    assert isinstance(case.simulation.end_time, float)
    assert case.materials == (
        MaterialSpec(name="rock", density=2650.0, friction_coefficient=0.7, restitution=0.5,
                     contact_penalty=1.0e9, tangential_stiffness_ratio=2.0 / 7.0),
        MaterialSpec(name="concrete", density=2400.0),
    )
    stone, ball, block = case.shapes
    assert stone == ShapeSpec(name="stone", type="random_rock", mesh_size=0.0, parameters={
        "size": 0.2, "elongation": 1.0, "flatness": 1.0, "seed": 0, "n_vertices": 24})
    assert ball.parameters == {"radius": 0.1}
    assert block.parameters == {"lengths": (0.2, 0.1, 0.1)}
    assert case.bodies[0].orientation == (1.0, 0.0, 0.0, 0.0)
    assert case.bodies[1] == BodySpec(
        shape="ball", material="concrete", position=(0.0, 0.0, 1.0),
        orientation=(1.0, 0.0, 0.0, 0.0), velocity=(1.0, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, 0.0), fixed=False,
    )
    assert case.body_grids == (BodyGridSpec(
        shapes=("stone", "ball"), shape_choice="cycle", material="rock", origin=(0.0, 0.0, 2.0),
        spacing=(0.4, 0.4, 0.4), counts=(2, 3, 1), orientation="random",
        velocity=(0.0, 0.0, 0.0), jitter=0.0),)
    assert case.body_count == 2 + 6
    plane, box = case.walls
    assert plane == WallSpec(type="plane", material="rock",
                             parameters={"point": (0.0, 0.0, 0.0), "normal": (0.0, 0.0, 1.0)})
    assert box.parameters == {"min": (-1.0, -1.0, 0.0), "max": (1.0, 1.0, 2.0), "open_top": True}
    assert case.output == OutputSettings(directory="out-test", paraview=True, picture=True)
    assert case.material("concrete").density == 2400.0
    assert case.shape("ball").type == "sphere"


def test_case_file_quaternion_is_normalised():
    text = VALID_CASE.replace("orientation = [2.0, 0.0, 0.0, 0.0]",
                              "orientation = [1.0, 1.0, 1.0, 1.0]")
    orientation = parse_case(text).bodies[0].orientation
    assert abs(math.sqrt(sum(item * item for item in orientation)) - 1.0) < NORMALISATION_TOLERANCE
    assert all(abs(item - 0.5) < NORMALISATION_TOLERANCE for item in orientation)


def test_case_file_load_case_resolves_mesh_file_against_case_folder(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "rock.stl").write_text("solid rock\nendsolid rock\n")
    text = VALID_CASE.replace(
        '[[shapes]]\nname = "block"',
        '[[shapes]]\nname = "scan"\ntype = "mesh_file"\nfile = "meshes/rock.stl"\n\n'
        '[[shapes]]\nname = "block"',
    )
    case_path = tmp_path / "case.toml"
    case_path.write_text(text)

    case = load_case(case_path)

    assert case.source == str(case_path)
    assert case.base_dir == tmp_path.resolve()
    scan = case.shape("scan")
    assert scan.parameters["file"] == (tmp_path / "meshes" / "rock.stl").resolve()
    assert scan.parameters["file"].is_absolute()
    assert scan.parameters["scale"] == 1.0


# Each case: (text to replace, replacement, line fragment locating the problem, key path, value
# as written in the message, a phrase the message must contain).
ERROR_CASES = {
    "unknown key": ("friction_coefficient = 0.7", "friction = 0.7", "friction = 0.7",
                    "materials[0].friction", "0.7", "did you mean 'friction_coefficient'?"),
    "misspelt key": ("time_step_safety = 0.25", "time_step_safty = 0.25", "time_step_safty",
                     "simulation.time_step_safty", "0.25", "did you mean 'time_step_safety'?"),
    "wrong type": ("density = 2400", 'density = "heavy"', "heavy", "materials[1].density",
                   '"heavy"', "a number in kg/m^3"),
    "boolean is not a number": ("end_time = 2", "end_time = true", "end_time",
                                "simulation.end_time", "true", "boolean"),
    "float where integer needed": ("counts = [2, 3, 1]", "counts = [2, 3.0, 1]", "counts",
                                   "body_grids[0].counts", "[2, 3.0, 1]", "3 integers"),
    "out of range": ("time_step_safety = 0.25", "time_step_safety = 1.5", "time_step_safety",
                     "simulation.time_step_safety", "1.5", "(0, 1]"),
    "wrong vector length": ("position = [0.0, 0.0, 1.0]", "position = [0.0, 1.0]",
                            "position = [0.0, 1.0]", "bodies[1].position", "[0.0, 1.0]",
                            "3 numbers [x, y, z] in m"),
    "zero quaternion": ("orientation = [2.0, 0.0, 0.0, 0.0]", "orientation = [0, 0, 0, 0]",
                        "orientation", "bodies[0].orientation", "[0, 0, 0, 0]", "norm"),
    "invalid choice": ('type = "random_rock"', 'type = "random_rok"', "random_rok",
                       "shapes[0].type", '"random_rok"', "did you mean 'random_rock'?"),
    "key of another type": ("radius = 0.1", "radius = 0.1\nside = 0.3", "side = 0.3",
                            "shapes[1].side", "0.3", 'type = "cube", not "sphere"'),
    "duplicate name": ('name = "concrete"', 'name = "rock"  # again', "# again",
                       "materials[1].name", '"rock"', "materials[0] (line 9)"),
    "undefined shape": ('shape = "ball"', 'shape = "bal"', 'shape = "bal"', "bodies[1].shape",
                        '"bal"', "did you mean 'ball'?"),
    "undefined material": ('material = "concrete"\nmin', 'material = "concret"\nmin',
                           '"concret"', "walls[1].material", '"concret"',
                           "did you mean 'concrete'?"),
    "undefined shape in a grid list": ('shapes = ["stone", "ball"]', 'shapes = ["stone", "bol"]',
                                       '"bol"', "body_grids[0].shapes[1]", '"bol"',
                                       "[[shapes]]"),
    "box max not above min": ("max = [1, 1, 2]", "max = [1, -1, 2]", "max = [1, -1, 2]",
                              "walls[1].max", "[1.0, -1.0, 2.0]", "must exceed min"),
    "zero normal": ("normal = [0, 0, 2]", "normal = [0, 0, 0]", "normal", "walls[0].normal",
                    "[0, 0, 0]", "not all zero"),
    # [[friction]]: a pair of unknown materials, of the wrong size, twice, or beyond 0-2
    "friction pair of an unknown material": (
        'materials = ["rock", "concrete"]', 'materials = ["rock", "concrte"]', "concrte",
        "friction[0].materials[1]", '"concrte"', "did you mean 'concrete'?"),
    "friction pair of three names": (
        'materials = ["rock", "concrete"]', 'materials = ["rock", "concrete", "rock"]',
        '"concrete", "rock"]', "friction[0].materials", '["rock", "concrete", "rock"]',
        "expected 2 strings [a, b], each the name of a [[materials]] entry, got a list of 3 names"),
    "friction pair of one name": (
        'materials = ["rock", "concrete"]', 'materials = ["rock"]', 'materials = ["rock"]',
        "friction[0].materials", '["rock"]', "got a list of 1 name"),
    "friction pair listed twice": (
        "friction_coefficient = 0.8", 'friction_coefficient = 0.8\n[[friction]]\n'
        'materials = ["concrete", "rock"]  # again\nfriction_coefficient = 0.5', "# again",
        "friction[1].materials", '["concrete", "rock"]',
        "the pair concrete-rock is listed twice; friction[0] (line"),
    "friction coefficient above 2": (
        "friction_coefficient = 0.8", "friction_coefficient = 2.5", "= 2.5",
        "friction[0].friction_coefficient", "2.5", "out of range; expected a number, [0, 2]"),
    "friction coefficient below 0": (
        "friction_coefficient = 0.8", "friction_coefficient = -0.1", "= -0.1",
        "friction[0].friction_coefficient", "-0.1", "[0, 2]"),
    "unknown table": ("[output]", "[outputs]", "[outputs]", "outputs",
                      '{ directory = "out-test" }', "did you mean 'output'?"),
}


@pytest.mark.parametrize("name", sorted(ERROR_CASES))
def test_case_file_error_names_file_line_key_and_value(name):
    old, new, locator, key_path, value, phrase = ERROR_CASES[name]
    assert VALID_CASE.count(old) == 1
    text = VALID_CASE.replace(old, new)
    line = line_containing(text, locator)

    messages = problems_of(text)

    matching = [message for message in messages if f": {key_path} = " in message]
    assert len(matching) == 1, messages
    assert matching[0].startswith(f"{SOURCE}:{line}: {key_path} = {value}: "), matching[0]
    assert phrase in matching[0]


def test_case_file_missing_required_key_points_at_its_table():
    text = VALID_CASE.replace('position = [0.0, 0.0, 1.0]\n', "")
    line = line_containing(text, "# second body")

    messages = problems_of(text)

    assert messages == [
        f"{SOURCE}:{line}: bodies[1].position: missing required key in this [[bodies]] entry; "
        "expected 3 numbers [x, y, z] in m"
    ]


def test_case_file_missing_type_specific_key_is_an_error():
    text = VALID_CASE.replace("radius = 0.1\n", "")
    messages = problems_of(text)
    line = line_containing(text, 'name = "ball"') - 1
    assert len(messages) == 1
    assert messages[0].startswith(f"{SOURCE}:{line}: shapes[1].radius: missing required key")


def test_case_file_reports_all_errors_together_sorted_by_line():
    text = (VALID_CASE
            .replace("end_time = 2", "end_time = -2")
            .replace('shape = "ball"', 'shape = "bal"')
            .replace('directory = "out-test"', "directory = 3"))

    messages = problems_of(text)

    assert [message.split(": ")[1] for message in messages] == [
        "simulation.end_time = -2", "bodies[1].shape = \"bal\"", "output.directory = 3"]
    lines = [int(message.split(":")[1]) for message in messages]
    assert lines == [line_containing(text, "end_time"), line_containing(text, '"bal"'),
                     line_containing(text, "directory = 3")]


def test_case_file_long_error_lists_are_cut_with_a_count():
    extra_keys = "".join(f"unknown_{number} = {number}\n" for number in range(25))
    text = VALID_CASE.replace("[output]\n", "[output]\n" + extra_keys)

    with pytest.raises(CaseFileError) as caught:
        parse_case(text, source=SOURCE)

    lines = str(caught.value).split("\n")
    assert len(caught.value.problems) == 25
    assert len(lines) == schema.MAXIMUM_REPORTED_PROBLEMS + 1
    assert lines[-1].startswith("... and 5 more")


def test_case_file_inline_tables_get_their_own_lines():
    text = """\
format_version = 1
simulation = { end_time = 1.0 }
materials = [
  { name = "rock" },
  { name = "sand", density = -1.0 },
]
shapes = [{ name = "ball", type = "sphere", radius = 0.1 }]
bodies = [
  { shape = "ball", material = "rock", position = [0, 0, 1] },
  { shape = "ball", material = "rock", position.x = 1.0 },
]
"""
    messages = problems_of(text)
    assert messages[0].startswith(f"{SOURCE}:5: materials[1].density = -1.0: out of range")
    assert messages[1].startswith(f"{SOURCE}:10: bodies[1].position = {{ x = 1.0 }}: expected")


def test_case_file_multiline_strings_and_comments_do_not_shift_lines():
    text = VALID_CASE.replace(
        'directory = "out-test"',
        'directory = """out\n[[bodies]]\nshape = "x"\n"""   # not = a key\npicture = "no"',
    )
    messages = problems_of(text)
    assert messages == [
        f"{SOURCE}:{line_containing(text, 'picture')}: output.picture = \"no\": "
        "expected true or false, got a string"
    ]


def test_case_file_structure_errors():
    text = VALID_CASE.replace("[output]", "[[output]]").replace(
        "[[walls]]\ntype = \"plane\"", "[walls]\ntype = \"plane\"", 1
    ).replace("[[walls]]\ntype = \"box\"", "[walls.extra]\ntype = \"box\"")
    messages = problems_of(text)
    assert any(message.startswith(f"{SOURCE}:{line_containing(text, '[walls]')}: walls: "
                                  "expected an array of tables") for message in messages)
    assert any(message.startswith(f"{SOURCE}:{line_containing(text, '[[output]]')}: output: "
                                  "expected one table [output]") for message in messages)


def test_case_file_top_level_checks():
    text = "format_version = 2\n[simulation]\nend_time = 1.0\n"
    messages = problems_of(text)
    assert messages[0] == (f"{SOURCE}:1: format_version = 2: out of range; "
                           "expected an integer, exactly 1")
    assert f"{SOURCE}:1: materials: at least 1 [[materials]] entry needed, found 0" in messages
    assert any(message.startswith(f"{SOURCE}:1: bodies: the case creates 0 bodies")
               for message in messages)


def test_case_file_mesh_file_must_exist(tmp_path):
    text = VALID_CASE.replace(
        'type = "box"\nlengths = [0.2, 0.1, 0.1]', 'type = "mesh_file"\nfile = "missing.stl"'
    ).replace('shapes = ["stone", "ball"]', 'shapes = ["stone", "block"]')
    messages = problems_of(text, base_dir=tmp_path)
    line = line_containing(text, "missing.stl")
    assert len(messages) == 1
    assert messages[0].startswith(f"{SOURCE}:{line}: shapes[2].file = \"missing.stl\": file not "
                                  f"found at {tmp_path.resolve() / 'missing.stl'}")


def test_case_file_mesh_file_extension_is_checked(tmp_path):
    (tmp_path / "rock.txt").write_text("not a mesh")
    text = VALID_CASE.replace(
        'type = "box"\nlengths = [0.2, 0.1, 0.1]', 'type = "mesh_file"\nfile = "rock.txt"'
    )
    messages = problems_of(text, base_dir=tmp_path)
    assert len(messages) == 1
    assert "shapes[2].file = \"rock.txt\": unsupported file type .txt" in messages[0]


def test_case_file_toml_syntax_error_names_file_and_line(tmp_path):
    case_path = tmp_path / "broken.toml"
    case_path.write_text(VALID_CASE.replace("end_time = 2", "end_time = = 2"))

    with pytest.raises(CaseFileError) as caught:
        load_case(case_path)

    line = line_containing(VALID_CASE, "end_time")
    assert str(caught.value).startswith(f"{case_path}:{line}: TOML syntax error: ")
    assert "end_time = = 2" in str(caught.value)


def test_case_file_missing_file_and_bad_encoding(tmp_path):
    with pytest.raises(CaseFileError, match="case file not found"):
        load_case(tmp_path / "absent.toml")
    case_path = tmp_path / "latin1.toml"
    case_path.write_bytes(b"format_version = 1\n# caf\xe9\n")
    with pytest.raises(CaseFileError, match=rf"^{case_path}:2: .*not UTF-8"):
        load_case(case_path)


def test_case_file_dataclass_fields_match_schema_keys():
    pairs = ((SimulationSettings, "simulation"), (MaterialSpec, "materials"),
             (ShapeSpec, "shapes"), (BodySpec, "bodies"), (BodyGridSpec, "body_grids"),
             (WallSpec, "walls"), (OutputSettings, "output"))
    for spec_class, table_name in pairs:
        fields = {field.name: field for field in dataclasses.fields(spec_class)}
        fields.pop("parameters", None)
        keys = {entry.name: entry for entry in schema.keys_of(table_name)}
        assert set(fields) == set(keys), spec_class
        for name, entry in keys.items():
            has_default = fields[name].default is not dataclasses.MISSING
            assert has_default != entry.required, (spec_class, name)
            if has_default:
                assert fields[name].default == entry.default, (spec_class, name)


def test_case_file_every_schema_key_has_a_documented_unit_and_meaning():
    for entry in schema.KEYS:
        assert entry.unit, entry
        assert entry.meaning.endswith("."), entry
        if entry.references is not None:
            assert any(other.table == entry.references and other.name == "name"
                       for other in schema.KEYS)
        if entry.variant is not None:
            variant_key = schema.table(entry.table).variant_key
            assert entry.variant in schema.key(entry.table, variant_key).choices


def test_case_file_docs_are_up_to_date():
    documented = (REPOSITORY / "docs" / "case-file.md").read_text(encoding="utf-8")
    assert documented == schema.render_markdown(), (
        "docs/case-file.md is out of date: run python -m riprap.schema > docs/case-file.md"
    )


def test_case_file_schema_module_prints_the_docs():
    printed = subprocess.run(
        [sys.executable, "-m", "riprap.schema"], capture_output=True, text=True, check=True
    ).stdout
    assert printed == schema.render_markdown()
