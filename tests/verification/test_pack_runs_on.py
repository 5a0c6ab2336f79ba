"""A placed pack is a state in equilibrium, and a run from it starts from it without a jump.

Case: ``examples/coreloc_small.toml`` placed in full by the session fixture ``small_placement``
(25 Core-Loc-like units on about 130 fixed rocks), then ``riprap run`` on its ``pack.toml`` for
``RUN_TIME`` = 0.5 s of simulated time (the issue's figure), with no numerical damping.

Source of the expectation: the seed paper's POSITIT ends when "the particles are touching and in
static force equilibrium"; a static state stays where it is. Checks:

- the run starts (the resting contacts overlap by their working depth, which a pack's
  ``contact_history.csv`` declares) and every unit ends within ``DISPLACEMENT_OVER_DN`` = 1 % of
  Dn of where the pack put it (the issue's figure; measured here 0.04 % of Dn at most);
- every unit is still at rest: slower than the placement's own rest speed (``REST_SPEED``);
- ``riprap analyse RUN --frame 0`` and ``--frame -1`` give each unit the coordination number the
  pack's own analysis gives (nothing came apart, nothing new touched).
"""
import json

import numpy as np
import pytest

from riprap.workflows.analyse import analyse
from riprap.cli import main
from riprap.io.checkpoint import load_checkpoint

RUN_TIME = 0.5
DISPLACEMENT_OVER_DN = 0.01
REST_SPEED = 0.02


@pytest.fixture(scope="module")
def pack_run(small_placement, tmp_path_factory):
    _, folder = small_placement
    text = (folder / "pack.toml").read_text()
    assert 'contact_history = "contact_history.csv"' in text
    lines = []
    for line in text.splitlines():
        if line.startswith("end_time ="):
            line = f"end_time = {RUN_TIME}"
        elif line.startswith("rest_speed ="):
            line = "rest_speed = 0.0"       # run the whole 0.5 s, do not stop at rest
        lines.append(line)
    case = folder / "pack_half_second.toml"
    case.write_text("\n".join(lines) + "\n")
    out = tmp_path_factory.mktemp("pack_run")
    assert main(["run", str(case), "--out", str(out), "--quiet"]) == 0
    return folder, out


def test_units_stay_where_the_pack_put_them(pack_run):
    folder, out = pack_run
    from riprap.case.load import load_case

    start = np.array([body.position for body in load_case(folder / "pack.toml").bodies])
    arrays, _ = load_checkpoint(out / "checkpoint.npz")
    layer = json.loads((folder / "layer.json").read_text())
    units = np.array(layer["unit_bodies"])
    moved = np.linalg.norm(arrays["positions"][units] - start[units], axis=1)
    assert moved.max() < DISPLACEMENT_OVER_DN * layer["nominal_diameter_m"]
    assert np.linalg.norm(arrays["velocities"][units], axis=1).max() < REST_SPEED
    summary = json.loads((out / "summary.json").read_text())
    assert abs(summary["simulated_time"] - RUN_TIME) <= summary["time_step"]


@pytest.mark.parametrize("frame", [0, -1])
def test_run_frames_have_the_packs_coordination_numbers(pack_run, frame, tmp_path):
    folder, out = pack_run
    pack = analyse(folder, out=tmp_path / "pack")
    run = analyse(out, out=tmp_path / "run", frame=frame)
    assert np.array_equal(run.units["coordination_number"], pack.units["coordination_number"])
