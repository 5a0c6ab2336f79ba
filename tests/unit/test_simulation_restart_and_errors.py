"""Run-level behaviour: exact restart, clear errors for bad starts, failure checkpoints.

Restart: N steps straight and N/2 + checkpoint + restart + N/2 must give bit-identical states
(positions, orientations, velocities, angular momenta and friction springs): the checkpoint holds
every state array and the clock is step_count * time_step, so nothing is recomputed differently.
"""
import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import parse_case
from riprap.errors import InstabilityError, OverlapError

CASE = """
format_version = 1
[simulation]
end_time = {end_time}
time_step = {time_step}
output_interval = {output_interval}
gravity = [0.0, 0.0, -9.81]

[[materials]]
name = "stone"
density = 2650.0
friction_coefficient = 0.5
restitution = 0.5
contact_penalty = {penalty}

[[shapes]]
name = "cube"
type = "cube"
side = 0.1

[[shapes]]
name = "rock"
type = "random_rock"
size = 0.1
elongation = 1.3
seed = 4

[[bodies]]
shape = "cube"
material = "stone"
position = [0.0, 0.0, {cube_z}]
velocity = [0.3, 0.0, -0.2]
angular_velocity = [0.0, 2.0, 0.0]

[[bodies]]
shape = "rock"
material = "stone"
position = [{rock_x}, 0.02, 0.075]
orientation = [0.9, 0.1, 0.3, 0.2]

[[walls]]
type = "box"
material = "stone"
min = [-0.5, -0.5, 0.0]
max = [0.5, 0.5, 1.0]
"""

TIME_STEP = 2.0e-5
STATE = ("positions", "quaternions", "velocities", "angular_momenta", "history_springs", "history_keys")


def _simulation(tmp_path, name, *, end_time, cube_z=0.0505, rock_x=0.15, time_step=TIME_STEP,
                penalty=1.0e7, output_interval=0.002):
    text = CASE.format(end_time=end_time, time_step=time_step, cube_z=cube_z, rock_x=rock_x,
                       penalty=penalty, output_interval=output_interval)
    case = parse_case(text, source=f"{name}.toml")
    return build_simulation(case, output_directory=tmp_path / name, progress=False)


def test_restart_reproduces_unbroken_run_exactly(tmp_path):
    steps = 1200
    straight = _simulation(tmp_path, "straight", end_time=steps * TIME_STEP)
    straight.run()
    first = _simulation(tmp_path, "split", end_time=steps // 2 * TIME_STEP)
    first.run()
    second = _simulation(tmp_path, "split", end_time=steps * TIME_STEP)
    summary = second.run(restart_from=tmp_path / "split" / "checkpoint.npz")
    assert second.solver.step_count == straight.solver.step_count == steps
    assert len(straight.solver.contacts) > 0, "the case must have friction history to be a real test"
    for name in STATE:
        a = getattr(straight.solver, name)
        b = getattr(second.solver, name)
        assert a.shape == b.shape and np.array_equal(a, b), name
    assert summary.frames == straight._frame_index
    # the .pvd after the restart lists every frame once, in time order
    pvd = (tmp_path / "split" / "bodies.pvd").read_text()
    times = [float(part.split('"')[1]) for part in pvd.split("timestep=")[1:]]
    assert times == sorted(times) and len(times) == len(set(times)) == straight._frame_index


def test_overlapping_bodies_are_refused_with_the_pair_named(tmp_path):
    sim = _simulation(tmp_path, "overlap", end_time=10 * TIME_STEP, rock_x=0.02)
    with pytest.raises(OverlapError) as error:
        sim.run()
    message = str(error.value)
    assert "body 0 and body 1" in message and "overlap depth" in message


def test_body_sunk_into_a_wall_is_refused(tmp_path):
    sim = _simulation(tmp_path, "sunk", end_time=10 * TIME_STEP, cube_z=0.04)
    with pytest.raises(OverlapError) as error:
        sim.run()
    assert "body 0 and wall" in str(error.value)


def test_unstable_time_step_stops_with_a_checkpoint_and_names_the_body(tmp_path):
    # a case file's step this large is refused before work (test_time_step_bound_and_energy.py):
    # the step is forced from Python after the bodies are built, as a blow-up the bound missed
    sim = _simulation(tmp_path, "blowup", end_time=0.5, time_step=0.0, penalty=1.0e10,
                      output_interval=0.1)
    sim.prepare()
    sim.solver.set_time_step(5.0e-3)
    with pytest.raises(InstabilityError) as error:
        sim.run()
    message = str(error.value)
    assert "body" in message and "t = " in message
    assert (tmp_path / "blowup" / "failure_checkpoint.npz").exists()
    assert "failure_checkpoint.npz" in message
    # what was written before the failure is still there and valid
    assert (tmp_path / "blowup" / "bodies.pvd").read_text().count("<DataSet") >= 1
