"""The fluid's [[obstacles]] are walls for the bodies too (issue 13, item 4): a ball that sinks
onto an obstacle box comes to rest on it, carried by contact; a body that starts inside an
obstacle is refused with the obstacle named."""
import csv

import numpy as np
import pytest

from riprap.cli import main

CASE = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.1
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.2]
cells = [16, 16, 16]
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.15
[[obstacles]]
type = "box"                 # a step on the floor: cells k = 0..3, top at z = 0.05
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.045]
[[materials]]
name = "stone"
density = 2000.0
contact_penalty = 1.0e7
restitution = 0.1
[[shapes]]
name = "ball"
type = "sphere"
radius = 0.03
mesh_size = 0.01
[[bodies]]
shape = "ball"
material = "stone"
position = [0.1, 0.1, {height}]
"""

RADIUS, STEP_TOP = 0.03, 0.05


def _case(tmp_path, end_time, height):
    path = tmp_path / "case.toml"
    path.write_text(CASE.format(end_time=end_time, height=height))
    return path


def test_a_ball_sinks_onto_an_obstacle_and_rests_on_it(tmp_path):
    out = tmp_path / "run"
    assert main(["run", str(_case(tmp_path, 0.4, 0.1)), "--out", str(out), "--quiet"]) == 0
    with open(out / "body_forces.csv") as table:
        rows = [row for row in csv.DictReader(table) if row["body"] == "0"]
    last = rows[-1]
    # at rest on the step's top (the cells the fluid leaves out), not sunk into it
    assert float(last["z_m"]) == pytest.approx(STEP_TOP + RADIUS, abs=0.002)
    assert abs(float(last["vz_m_per_s"])) < 0.02
    # the step carries the ball's weight less its buoyancy: g V (rho_s - rho_w), within 15 %
    # (the sphere's tet mesh is a little smaller than the sphere; the water is still settling)
    submerged_weight = 9.81 * 4 / 3 * np.pi * RADIUS ** 3 * (2000.0 - 1000.0)
    assert float(last["contact_force_z_N"]) == pytest.approx(submerged_weight, rel=0.15)


def test_a_body_inside_an_obstacle_is_refused_with_the_obstacle_named(tmp_path, capsys):
    assert main(["run", str(_case(tmp_path, 0.1, 0.06)), "--out", str(tmp_path / "bad"),
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "body 0 and body 1" in err and "body 1 is [[obstacles]] entry 1" in err
