"""Rock armour as a case file (``[armour_stone]``, issue 55): ``riprap check`` says the grading,
the grid and the filter rule; ``riprap place`` of a small double layer writes a pack that
``riprap run`` reads, a summary with the placed layer beside its design and the placed stones'
grading beside the one asked, byte for byte the same for the same seed; bad input is refused by
check and place alike (exit status 2, one line naming the key, nothing written).
"""
import json
from pathlib import Path

import pytest

import riprap as rr
from riprap.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rock_armour_place.toml"

SMALL = """format_version = 1

[simulation]
end_time = 0.05
time_step_safety = 0.3
output_interval = 0.05

[[materials]]
name = "stone"
density = 2650.0
friction_coefficient = 0.6
restitution = 0.3
contact_penalty = 1.0e6

[[materials]]
name = "core"
density = 2650.0
friction_coefficient = 0.9
restitution = 0.3
contact_penalty = 1.0e6

[slope]
cotangent = 2.0
width = 0.2
length = 0.3
toe_stop_distance = 0.02
face_material = "core"
side_wall_material = "core"
sides = "periodic"

[underlayer]
material = "stone"
dn50 = 0.018
dn85_over_dn15 = 1.3
rock_shapes = 3
size_classes = 2
settle_time = 0.5

[armour_stone]
material = "stone"
dn50 = 0.04
dn85_over_dn15 = 1.25
stone_shapes = 4
size_classes = 2
settle_time = 0.6
seed = 2

[output]
directory = "out"
paraview = false
"""


def _case(tmp_path, old: str = "", new: str = "", name: str = "rock.toml") -> Path:
    text = SMALL.replace(old, new) if old else SMALL
    path = tmp_path / name
    path.write_text(text)
    return path


def test_check_says_the_grading_grid_and_filter_rule(capsys):
    assert main(["check", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    assert "rock armour placement" in out and "class HMA 300/1000 at 1:20" in out
    assert "per m^2: k_t 0.91, design porosity 0.37" in out
    assert "the filter rule (D_n50 ratio 2.33)" in out


def test_place_writes_a_pack_and_the_layer_beside_its_design(tmp_path):
    case = _case(tmp_path)
    assert main(["place", str(case), "--out", str(tmp_path / "a"), "--quiet"]) == 0
    assert main(["place", str(case), "--out", str(tmp_path / "b"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    measured, design = summary["measured"], summary["design"]
    assert design["layer_thickness_coefficient"] == 0.91 and design["porosity"] == 0.37
    # a face of 7 rows: a stone or a few of the top row may end beyond the face's top edge
    assert measured["stones_placed"] > 20 and measured["stones_below_toe"] == 0
    assert measured["stones_rolled_off"] <= 0.1 * measured["stones_placed"]
    assert 0.5 < measured["layer_thickness_coefficient"] < 1.5
    grading = summary["grading"]
    assert grading["asked"]["Dn50_m"] == pytest.approx(0.04, rel=1e-9)
    assert grading["placed"]["stones"] == measured["stones_placed"]
    assert 0.7 < grading["placed"]["Dn50_m"] / 0.04 < 1.3
    pack = (tmp_path / "a" / "pack.toml").read_text()
    # same seed, same layer, byte for byte but the first line's date of writing
    assert pack.split("\n", 1)[1] == (tmp_path / "b" / "pack.toml").read_text().split("\n", 1)[1]
    assert "periodic_y_high" in pack
    # the pack's layer.json makes the stones the layer's units: riprap analyse measures the
    # layer as the placement did (same k_t, porosity, stones per area), the long axes' fabric
    layer = json.loads((tmp_path / "a" / "layer.json").read_text())
    assert layer["unit_kind"] == "armour_stone" and len(layer["unit_bodies"]) == \
        measured["stones_placed"]
    assert layer["nominal_diameter_m"] == pytest.approx(grading["placed"]["Dn50_m"], rel=1e-9)
    analysis = rr.analyse(tmp_path / "a", out=tmp_path / "analysis").layer
    assert analysis["unit"] == "armour_stone"
    for key in ("layer_thickness_coefficient", "porosity", "stones_per_area"):
        assert analysis[key] == pytest.approx(measured[key], rel=1e-9), key
    assert analysis["design_layer_thickness_coefficient"] == pytest.approx(0.91)
    assert analysis["design_stones_per_area"] == pytest.approx(design["stones_per_area"])
    assert 0.33 <= analysis["long_axis_fabric"]["S1"] <= 1.0
    report = (tmp_path / "analysis" / "report.html").read_text()
    assert "layer thickness coefficient k_t" in report and "Orientation of the long axes" in report
    run = tmp_path / "run.toml"
    run.write_text(f'format_version = 1\npack = "{tmp_path / "a" / "pack.toml"}"\n\n'
                   "[simulation]\nend_time = 0.01\n\n[output]\ndirectory = \"run\"\n"
                   "paraview = false\npicture = false\n")
    assert main(["run", str(run), "--out", str(tmp_path / "run"), "--quiet"]) == 0


@pytest.mark.parametrize("old, new, words", [
    ("[armour_stone]\n", "[armour]\nunit = \"cube\"\nmaterial = \"stone\"\nnominal_diameter = 0.04"
     "\n\n[armour_stone]\n", "rock armour \\(\\[armour_stone\\]\\) or armour units"),
    ("dn50 = 0.04\n", "dn50 = 0.04\ngrading = \"HMA 300/1000\"\n", "give the name or dn50"),
    ("dn50 = 0.04\n", "", "give a grading"),
    ("dn50 = 0.04\n", "grading = \"HMA 300/1001\"\n", "HMA 300/1001"),
    ("stone_shapes = 4", "stone_shapes = 1", "size_classes.*more than stone_shapes"),
    ("dn50 = 0.04\n", "dn50 = 0.1\n", "filter rule"),
    ("seed = 2", "seed = 2\nto_s = 0.5", "to_s.*beyond the crest"),
    ("seed = 2", "seed = 2\nlength_scale = 30.0", "length_scale.*scales a named grading"),
    ("seed = 2", "seed = 2\nplacement = \"careful\"", "placement"),
    ("seed = 2", "seed = 2\ntoe_berm_width = 0.12", "toe_berm_width = 0.12 m.*toe_stop_distance "
     "= 0.02 m; give toe_stop_distance 0.12 m or more"),
])
def test_bad_rock_armour_is_refused_by_check_and_place(tmp_path, capsys, old, new, words):
    import re

    case = _case(tmp_path, old, new)
    for command in ("check", "place"):
        assert main([command, str(case), "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err
        assert re.search(words, err), err
        assert not (tmp_path / "out").exists()


def test_a_toe_berm_is_placed_on_the_bed_and_said(tmp_path, capsys):
    """A toe berm three stones wide in two layers (about 3 D_n50 by 2 layers, as a contractor
    builds a rock toe) in front of the toe, held by the toe stop: its stones rest on the bed,
    its top near the design layer thickness, none carried onto the face."""
    case = _case(tmp_path, "toe_stop_distance = 0.02", "toe_stop_distance = 0.13")
    case.write_text(case.read_text().replace("seed = 2", "seed = 2\ntoe_berm_width = 0.12"))
    assert main(["place", str(case), "--out", str(tmp_path / "b")]) == 0
    assert "toe berm 0.12 m wide" in capsys.readouterr().out
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    berm = summary["measured"]["toe_berm"]
    assert summary["design"]["toe_berm_width_m"] == 0.12
    assert berm["stones"] >= 8 and berm["stones_off_the_bed"] == 0
    assert 0.6 < berm["top_above_bed_m"] / berm["design_top_above_bed_m"] < 1.4
    # every stone, the berm's too, is a unit of the layer the analysis reads
    layer = json.loads((tmp_path / "b" / "layer.json").read_text())
    assert len(layer["unit_bodies"]) == summary["grading"]["placed"]["stones"]
