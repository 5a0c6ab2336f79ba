"""riprap run on a case with bodies and [fluid]: a coupled run with the fluid's loop (frames of both
at the same times, body_forces.csv, checkpoints) that restarts bit for bit."""
import json

import numpy as np

from riprap.cli import main
from riprap.io.body_forces import BODY_FORCE_COLUMNS
from riprap.io.checkpoint import load_checkpoint
from riprap.io.solver_log import SOLVER_LOG_COLUMNS

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


def test_the_solver_log_has_a_row_per_frame_and_the_summary_has_them_too(tmp_path):
    """Reference: issue 37 (pressure iterations, the volume error and the contact sub-steps per
    fluid step logged per frame in the run's summary): one row per frame interval with a step in
    it (t = 0.05, 0.1), the rows' fluid steps adding up to the run's, the same rows in
    summary.json; iterations and sub-steps as the run's own totals give them."""
    out = tmp_path / "run"
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    lines = (out / "solver_log.csv").read_text().splitlines()
    assert tuple(lines[0].split(",")) == SOLVER_LOG_COLUMNS
    rows = [dict(zip(SOLVER_LOG_COLUMNS, line.split(","))) for line in lines[1:]]
    assert [float(r["time_s"]) for r in rows] == [0.05, 0.1]
    assert sum(int(r["fluid_steps"]) for r in rows) == summary["steps"]
    assert summary["solver_log"] == [
        {k: (None if v == "" else json.loads(v)) for k, v in r.items()} for r in rows]
    assert sum(r["contact_substeps_per_step"] * r["fluid_steps"]
               for r in summary["solver_log"]) == summary["solid_substeps"]
    assert max(r["pressure_iterations_max"] for r in summary["solver_log"]) \
        == summary["pressure_iterations_max"]
    assert summary["pressure_capped_solves"] == 0
    assert all(r["pressure_capped_solves"] == 0 for r in summary["solver_log"])
    assert abs(summary["solver_log"][-1]["water_volume_error"]) < 1e-9


DROP = CASE.replace("position = [0.1, 0.1, 0.1]", "position = [0.1, 0.1, 0.06]").replace(
    "output_interval = 0.05", "output_interval = 0.05\ncheckpoint_interval = 0.15\n{adaptive}")


def _drop(tmp_path, end_time, adaptive):
    path = tmp_path / f"drop_{end_time}_{adaptive}.toml"
    path.write_text(DROP.format(end_time=end_time,
                                adaptive="adaptive_time_step = true" if adaptive else ""))
    return path


def test_an_adaptive_substep_follows_the_contacts_and_lands_the_ball_where_a_fixed_one_does(
        tmp_path):
    """Reference: issue 37 (the contact sub-step adapts to the measured contact stability instead
    of a hand-set factor) and riprap.coupling.coupled (target ratio 0.25). A ball of 2000 kg/m^3
    falls 3 cm through water onto the floor and rests there. With the adaptive sub-step the
    measured stability ratio dt / (2 sqrt(m/k)) stays below the rigid model's limit of 0.5 in
    every frame, the run takes fewer sub-steps than with the fixed automatic step (0.2 of the
    critical), and the ball rests where the fixed step puts it, within 1e-3 of its radius (the
    rest depth is set by its weight and the contact stiffness, not the step)."""
    runs = {}
    for adaptive in (False, True):
        out = tmp_path / f"adaptive_{adaptive}"
        assert main(["run", str(_drop(tmp_path, 0.3, adaptive)), "--out", str(out), "--quiet"]) == 0
        runs[adaptive] = (json.loads((out / "summary.json").read_text()),
                          load_checkpoint(out / "checkpoint.npz")[0])
    fixed, adaptive = runs[False][0], runs[True][0]
    assert adaptive["solid_substeps"] < 0.5 * fixed["solid_substeps"]
    ratios = [r["contact_stability_ratio_max"] for r in adaptive["solver_log"]]
    assert max(ratios) <= 0.5 and max(ratios) > 0.0
    z_fixed = runs[False][1]["bodies_positions"][0, 2]
    z_adaptive = runs[True][1]["bodies_positions"][0, 2]
    assert z_fixed < 0.035, "the ball has landed"
    assert abs(z_adaptive - z_fixed) <= 1e-3 * 0.03


def test_an_adaptive_substep_restarts_bit_for_bit(tmp_path):
    unbroken = tmp_path / "unbroken"
    assert main(["run", str(_drop(tmp_path, 0.3, True)), "--out", str(unbroken), "--quiet"]) == 0
    pieces = tmp_path / "pieces"
    assert main(["run", str(_drop(tmp_path, 0.15, True)), "--out", str(pieces), "--quiet"]) == 0
    assert main(["run", str(_drop(tmp_path, 0.3, True)), "--out", str(pieces), "--quiet",
                 "--restart", str(pieces / "checkpoint.npz")]) == 0
    a, _ = load_checkpoint(unbroken / "checkpoint.npz")
    b, _ = load_checkpoint(pieces / "checkpoint.npz")
    for name in ("u", "w", "fraction", "pressure", "bodies_positions", "bodies_velocities",
                 "coupling_substep"):
        assert np.array_equal(a[name], b[name]), name


def _own_velocity_case(tmp_path, end_time, treatment='"own_velocity"'):
    path = tmp_path / f"own_{end_time}.toml"
    path.write_text(CASE.format(end_time=end_time).replace(
        "surface_tension = 0.0\n", f"surface_tension = 0.0\ncut_faces = {treatment}\n"))
    return path


def test_own_velocity_cut_faces_run_from_a_case_and_restart_bit_for_bit(tmp_path):
    """[fluid] cut_faces = "own_velocity" reaches the coupling, and the fluid's excess on the
    cut faces rides in the checkpoint: a restart continues to the bit (docs/coupling.md)."""
    unbroken, pieces = tmp_path / "unbroken", tmp_path / "pieces"
    assert main(["run", str(_own_velocity_case(tmp_path, 0.1)), "--out", str(unbroken),
                 "--quiet"]) == 0
    assert main(["run", str(_own_velocity_case(tmp_path, 0.05)), "--out", str(pieces),
                 "--quiet"]) == 0
    assert main(["run", str(_own_velocity_case(tmp_path, 0.1)), "--out", str(pieces), "--quiet",
                 "--restart", str(pieces / "checkpoint.npz")]) == 0
    a, _ = load_checkpoint(unbroken / "checkpoint.npz")
    b, _ = load_checkpoint(pieces / "checkpoint.npz")
    assert np.any(a["coupling_carried_excess"] != 0.0), "the water in the cut faces keeps its own"
    for name in ("u", "v", "w", "fraction", "bodies_positions", "bodies_velocities",
                 "bodies_fluid_loads", "coupling_carried_excess"):
        assert np.array_equal(a[name], b[name]), name
    mixture = tmp_path / "mixture"
    assert main(["run", str(_own_velocity_case(tmp_path, 0.1, '"mixture"')), "--out",
                 str(mixture), "--quiet"]) == 0
    m, _ = load_checkpoint(mixture / "checkpoint.npz")
    assert not np.array_equal(a["bodies_velocities"], m["bodies_velocities"]), \
        "the treatment changes the run"
    auto = tmp_path / "auto"
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(auto), "--quiet"]) == 0
    d, _ = load_checkpoint(auto / "checkpoint.npz")
    assert np.array_equal(a["bodies_velocities"], d["bodies_velocities"]), \
        "rigid bodies take their own velocity by default"


def test_a_run_started_with_mixture_cut_faces_continues_only_with_them(tmp_path, capsys):
    """A checkpoint of a "mixture" run (as every run before issue 51: its record has no
    cut_faces) is refused by a case that leaves cut_faces to the default, naming the key; the
    case that says "mixture" continues it."""
    pieces = tmp_path / "pieces"
    assert main(["run", str(_own_velocity_case(tmp_path, 0.05, '"mixture"')), "--out",
                 str(pieces), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["run", str(_case(tmp_path, 0.1)), "--out", str(pieces), "--quiet",
                 "--restart", str(pieces / "checkpoint.npz")]) == 2
    assert "cut_faces" in capsys.readouterr().err
    assert main(["run", str(_own_velocity_case(tmp_path, 0.1, '"mixture"')), "--out",
                 str(pieces), "--quiet", "--restart", str(pieces / "checkpoint.npz")]) == 0


def test_an_unknown_cut_face_treatment_in_a_case_is_refused(tmp_path, capsys):
    path = _own_velocity_case(tmp_path, 0.1, treatment='"sharp"')
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 2
    error = capsys.readouterr().err
    assert "cut_faces" in error and "own_velocity" in error
    assert not (tmp_path / "run").exists()
