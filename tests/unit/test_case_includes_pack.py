"""A case that takes a placed pack (top-level ``pack = "..."``) and adds to it: the pack in water
without editing its body list (issue 13), or in a dry run."""
import json

import pytest

from riprap.case.load import load_case
from riprap.cli import main
from riprap.errors import CaseFileError
from riprap.geometry import shapes
from riprap.io.pack import PackBody, write_pack
from riprap.solid.materials import Material
from riprap.solid.walls import Wall

WATER = """format_version = 1
pack = "layer/pack.toml"
[simulation]
end_time = 0.02
output_interval = 0.01
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.4, 0.4, 0.4]
cells = [16, 16, 16]
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.3
"""


@pytest.fixture
def pack(tmp_path):
    concrete = Material(name="concrete", density=2400.0, contact_penalty=1.0e7)
    bodies = [PackBody(shape="block", material="concrete", position=(0.2, 0.2, 0.05)),
              PackBody(shape="block", material="concrete", position=(0.2, 0.2, 0.151))]
    write_pack(tmp_path / "layer", shapes={"block": shapes.cube(side=0.1, mesh_size=0.05)},
               materials=[concrete], bodies=bodies,
               walls=[Wall(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="concrete")])
    return tmp_path


def test_a_case_takes_the_packs_bodies_first(pack):
    path = pack / "water.toml"
    path.write_text(WATER)
    case = load_case(path)
    assert case.body_count == 2 and case.is_fluid
    assert [m.name for m in case.materials] == ["concrete"]
    assert len(case.walls) == 1


def test_a_pack_put_in_water_runs_coupled(pack):
    path = pack / "water.toml"
    path.write_text(WATER)
    assert main(["check", str(path)]) == 0
    out = pack / "run"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert (out / "bodies.pvd").is_file() and (out / "body_forces.csv").is_file()
    # The pack's floor is the fluid box's floor too: one wall, not two pushing twice.
    from riprap.case.build_fluid import build_fluid_run

    walls = build_fluid_run(load_case(path), output_directory=out, progress=False).solver.walls
    floors = [w for w in walls if tuple(w.normal) == (0.0, 0.0, 1.0) and w.point[2] == 0.0]
    assert len(floors) == 1 and len(walls) == 5          # open top: 5 box sides, the floor once
    assert json.loads((out / "summary.json").read_text())["simulated_time"] == pytest.approx(0.02)


def test_names_in_both_the_pack_and_the_case_are_refused(pack):
    path = pack / "clash.toml"
    path.write_text(WATER + '[[materials]]\nname = "concrete"\n')
    with pytest.raises(CaseFileError, match="'concrete' are in the pack"):
        load_case(path)


def test_a_missing_pack_is_named_with_its_line(pack):
    path = pack / "missing.toml"
    path.write_text(WATER.replace("layer/pack.toml", "nowhere/pack.toml"))
    with pytest.raises(CaseFileError, match=r"missing.toml:2: pack"):
        load_case(path)
