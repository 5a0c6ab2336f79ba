"""riprap run on a case with bodies and [fluid]: a coupled run with the fluid's loop (frames of both
at the same times, body_forces.csv, checkpoints) that restarts bit for bit."""
import json

import numpy as np

from riprap.cli import main
from riprap.io.body_forces import BODY_FORCE_COLUMNS
from riprap.io.checkpoint import load_checkpoint

CASE = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.05
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.2]
cells = [16, 16, 16]
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.15
[[materials]]
name = "stone"
density = 2000.0
contact_penalty = 1.0e7
[[shapes]]
name = "ball"
type = "sphere"
radius = 0.03
mesh_size = 0.01
[[bodies]]
shape = "ball"
material = "stone"
position = [0.1, 0.1, 0.1]
"""


def _case(tmp_path, end_time):
    path = tmp_path / f"case_{end_time}.toml"
    path.write_text(CASE.format(end_time=end_time))
    return path


def test_a_coupled_case_runs_writes_both_series_and_forces(tmp_path):
    out = tmp_path / "run"
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(out), "--quiet"]) == 0
    fluid = (out / "fluid.pvd").read_text()
    bodies = (out / "bodies.pvd").read_text()
    assert fluid.count("<DataSet") == bodies.count("<DataSet") == 3       # t = 0, 0.05, 0.1
    rows = (out / "body_forces.csv").read_text().splitlines()
    assert rows[0].split(",") == list(BODY_FORCE_COLUMNS)
    assert len(rows) == 1 + 3
    last = np.array(rows[-1].split(","), dtype=float)
    assert last[7] < 0.0, "the ball sinks"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["outputs"]["body_forces"].endswith("body_forces.csv")


def test_a_coupled_run_restarts_bit_for_bit(tmp_path):
    unbroken = tmp_path / "unbroken"
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(unbroken), "--quiet"]) == 0
    pieces = tmp_path / "pieces"
    assert main(["run", str(_case(tmp_path, 0.05)), "--out", str(pieces), "--quiet"]) == 0
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(pieces), "--quiet", "--restart",
                 str(pieces / "checkpoint.npz")]) == 0
    a, _ = load_checkpoint(unbroken / "checkpoint.npz")
    b, _ = load_checkpoint(pieces / "checkpoint.npz")
    for name in ("u", "v", "w", "fraction", "pressure", "bodies_positions", "bodies_velocities",
                 "bodies_angular_momenta", "bodies_fluid_loads"):
        assert np.array_equal(a[name], b[name]), name
    assert (pieces / "body_forces.csv").read_text() == (unbroken / "body_forces.csv").read_text()
