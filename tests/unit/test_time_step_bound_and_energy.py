"""A given time step is bounded by every contact the bodies can make, and a run that makes energy
stops (issue 52, item 7).

- The bound (``riprap.solid.stability.worst_contact_rate``): a whole face pressed in at the
  farthest corner (the largest inverse mass anywhere on the surface, 1/m + (r x n) I^-1 (r x n)
  over the boundary nodes). A step above 0.5 of it is refused before any work, by ``run`` and
  ``check``; the contacts measured while bodies land stay under it.
- The energy watch (``riprap.models.rigid.EnergyWatch``): a dry run's kinetic and potential
  energy never grows past its start; a cube stepped at 40 times the automatic step (forced from
  Python, past the refusal) bounced to 137 times its drop height before; it now stops with a
  failure checkpoint naming the energy gained, and an elastic run at the automatic step does not.
"""
import json

import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import parse_case
from riprap.cli import main
from riprap.errors import InstabilityError
from riprap.io.checkpoint import load_checkpoint
from riprap.models import rigid
from riprap.solid.stability import contact_stability_rate, shape_inverse_masses, worst_contact_rate
from test_cli_bad_inputs import RIGID, _edit

def _case(end_time=0.4, time_step=0.0, restitution=0.5, orientation="1.0, 0.0, 0.0, 0.0"):
    """test_cli_bad_inputs' cube on a floor, dropped 0.1 m, with a soft contact (a long step)."""
    text = _edit(RIGID, "end_time = 0.01", f"end_time = {end_time}\ntime_step = {time_step}")
    text = _edit(text, 'name = "rock"\n', 'name = "rock"\ndensity = 2650.0\n'
                 f"restitution = {restitution}\ncontact_penalty = 1.0e7\n")
    return _edit(text, "position = [0.0, 0.0, 0.06]",
                 f"position = [0.0, 0.0, 0.15]\norientation = [{orientation}]")


def _simulation(tmp_path, text, name="run"):
    return build_simulation(parse_case(text, source=f"{name}.toml"),
                            output_directory=tmp_path / name, progress=False)


def test_a_cube_corner_has_the_largest_inverse_mass(tmp_path):
    """1/m + (r x n) I^-1 (r x n) of a cube (I = m s^2 / 6) is largest at a corner (|r|^2 =
    3 s^2 / 4) with n across r: 1/m + 4.5/m."""
    sim = _simulation(tmp_path, _case())
    rigid.build_bodies(sim.solver, sim.settings)
    shape = sim.solver.shapes[0]
    along, across = shape_inverse_masses(shape)
    assert along * shape.volume == pytest.approx(5.5, rel=1e-6)
    assert across * shape.volume == pytest.approx(5.5, rel=1e-6)


def test_a_given_step_beyond_the_bound_is_refused_before_work(tmp_path, capsys):
    automatic = _simulation(tmp_path, _case())
    automatic.prepare()
    step = 40.0 * automatic.solver.time_step           # the step
    case = tmp_path / "case.toml"
    case.write_text(_case(time_step=step))
    for command in ("check", "run"):
        capsys.readouterr()
        assert main([command, str(case), "--out", str(tmp_path / "out"), "--quiet"]
                    if command == "run" else [command, str(case)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("riprap: error: simulation.time_step = ") and "too large" in err
        assert "farthest corner" in err and "the automatic step is" in err
        assert "Traceback" not in err
    assert not (tmp_path / "out" / "summary.json").exists()
    assert not (tmp_path / "out" / "checkpoint.npz").exists()


def test_a_step_under_the_bound_runs_and_the_automatic_step_is_well_under_it(tmp_path):
    sim = _simulation(tmp_path, _case())
    sim.prepare()
    rate, _ = worst_contact_rate(sim.solver)
    # the automatic step (time_step_safety 0.2) is under half the bound's limit of 0.5
    assert sim.solver.time_step * rate < 0.25
    largest = 0.5 / rate
    under = _simulation(tmp_path, _case(end_time=0.02, time_step=0.95 * largest), "under")
    summary = under.run()
    assert summary.end_reason == "end_time"


@pytest.mark.parametrize("orientation", ["1.0, 0.0, 0.0, 0.0", "0.9, 0.3, 0.2, 0.1",
                                         "0.88, 0.33, 0.33, 0.0"])
def test_the_contacts_met_stay_under_the_bound(tmp_path, orientation):
    """A cube landing face, edge or corner first, stepped one step at a time at the automatic
    step: the measured rate of every contact on the way is below the bound's."""
    sim = _simulation(tmp_path, _case(orientation=orientation, restitution=0.9))
    rigid.build_bodies(sim.solver, sim.settings)
    solver = sim.solver
    bound, _ = worst_contact_rate(solver)
    measured = 0.0
    while solver.time < 0.2:
        solver.advance(1)
        measured = max(measured, contact_stability_rate(solver))
    assert 0.0 < measured < bound


def test_a_run_that_makes_energy_stops_with_a_failure_checkpoint_naming_it(tmp_path):
    sim = _simulation(tmp_path, _case(end_time=1.0), "blowup")
    sim.prepare()
    start_energy = sim.solver.kinetic_energy() + sim.solver.potential_energy()
    sim.solver.set_time_step(40.0 * sim.solver.time_step)   # past the refusal, from Python
    with pytest.raises(InstabilityError) as error:
        sim.run()
    message = str(error.value)
    assert "energy from nothing" in message and "failure_checkpoint.npz" in message
    arrays, _ = load_checkpoint(tmp_path / "blowup" / "failure_checkpoint.npz")
    # the last good state holds no more energy than the start
    masses = sim.solver.masses
    height = arrays["positions"][:, 2]
    speed = np.linalg.norm(arrays["velocities"], axis=1)
    good_energy = float(np.sum(masses * (9.81 * height + 0.5 * speed ** 2)))
    assert good_energy <= start_energy * 1.001


def test_an_elastic_run_at_the_automatic_step_is_not_stopped(tmp_path):
    sim = _simulation(tmp_path, _case(end_time=0.4, restitution=1.0,
                                      orientation="0.9, 0.3, 0.2, 0.1"), "elastic")
    summary = sim.run()
    assert summary.end_reason == "end_time"
    assert 0.0 <= sim.model.energy_watch.largest_share < 0.1
    assert json.loads((tmp_path / "elastic" / "summary.json").read_text())["steps"] > 0
