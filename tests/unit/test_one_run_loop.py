"""One Simulation runs rigid bodies, the fluid alone and bodies in the fluid through the same loop:
the same schedule of frames, the same summary keys, one file that opens fluid and bodies
together, and a blow-up that names the body, its cell and the time and leaves one checkpoint of
both states."""
import json
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

import riprap as rr
from riprap.errors import InstabilityError
from riprap.io.checkpoint import load_checkpoint

COMMON = {"model", "end_reason", "simulated_time", "steps", "wall_time", "frames", "outputs",
          "case_file", "smoke"}


def _tank(cells=16):
    grid = rr.FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.2, 0.2, 0.2), cells=(cells,) * 3)
    fluid = rr.FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.15)
    return fluid


def _with_ball(sim, velocity=(0.0, 0.0, 0.0)):
    sim.add_material(rr.Material(name="stone", density=2000.0, contact_penalty=1.0e7))
    sim.add_shape("ball", rr.shapes.sphere(radius=0.03, mesh_size=0.01))
    sim.add_body(shape="ball", material="stone", position=(0.1, 0.1, 0.1), velocity=velocity)


def _summary(folder):
    return json.loads((folder / "summary.json").read_text())


def test_the_fluid_alone_runs_as_a_simulation(tmp_path):
    sim = rr.Simulation(end_time=0.02, output_interval=0.01, fluid=_tank(),
                        output_directory=tmp_path / "fluid", progress=False, picture=False)
    summary = sim.run()
    assert summary.model == "fluid" and not sim.coupled
    written = _summary(tmp_path / "fluid")
    assert COMMON <= set(written) and "cells" in written and "bodies" not in written
    assert (tmp_path / "fluid" / "fluid.pvd").read_text().count("<DataSet") == 3


def test_rigid_bodies_report_no_fluid_figures(tmp_path):
    sim = rr.Simulation(end_time=0.002, output_directory=tmp_path / "dry", progress=False,
                        picture=False)
    _with_ball(sim)
    sim.add_walls(rr.walls.plane(point=(0, 0, 0), normal=(0, 0, 1), material="stone"))
    assert sim.run().model == "rigid"
    written = _summary(tmp_path / "dry")
    assert COMMON <= set(written) and "bodies" in written and "cells" not in written


def test_bodies_in_the_fluid_run_coupled_and_open_together(tmp_path):
    out = tmp_path / "coupled"
    sim = rr.Simulation(end_time=0.04, output_interval=0.02, fluid=_tank(),
                        output_directory=out, progress=False, picture=False)
    _with_ball(sim)
    summary = sim.run()
    assert summary.model == "coupled" and sim.coupled
    assert summary.bodies == 1 and summary.cells == 16 ** 3 and summary.solid_substeps >= summary.steps
    written = _summary(out)
    assert COMMON <= set(written) and {"bodies", "cells", "solid_substeps"} <= set(written)
    # run.pvd lists the fluid's frames as part 0 and the bodies' as part 1, at the same times.
    datasets = ElementTree.parse(out / "run.pvd").getroot().iter("DataSet")
    parts = {}
    for dataset in datasets:
        parts.setdefault(dataset.attrib["part"], []).append(
            (float(dataset.attrib["timestep"]), dataset.attrib["file"]))
        assert (out / dataset.attrib["file"]).is_file()
    assert [t for t, _ in parts["0"]] == [t for t, _ in parts["1"]] == [0.0, 0.02, 0.04]
    assert all(name.endswith(".vti") for _, name in parts["0"])
    assert all(name.endswith(".vtu") for _, name in parts["1"])
    assert sim.solver.velocities[0, 2] < 0.0, "the ball sinks"


def test_a_run_ending_between_frames_writes_a_last_frame_and_a_restart_keeps_the_schedule(tmp_path):
    out = tmp_path / "fluid"

    def simulation(end_time):
        return rr.Simulation(end_time=end_time, output_interval=0.01, fluid=_tank(8),
                             output_directory=out, progress=False, picture=False)

    first = simulation(0.015).run()
    assert first.frames == 3                              # 0, 0.01 and the end, 0.015
    simulation(0.03).run(restart_from=out / "checkpoint.npz")
    times = [float(d.attrib["timestep"])
             for d in ElementTree.parse(out / "fluid.pvd").getroot().iter("DataSet")]
    assert times == pytest.approx([0.0, 0.01, 0.015, 0.02, 0.03])


def test_a_body_that_blows_up_in_the_flow_is_named_with_its_cell_and_time(tmp_path):
    out = tmp_path / "blowup"
    sim = rr.Simulation(end_time=0.02, output_interval=0.01, fluid=_tank(),
                        output_directory=out, progress=False, picture=False)
    _with_ball(sim, velocity=(0.0, 0.0, -2000.0))
    with pytest.raises(InstabilityError) as error:
        sim.run()
    message = str(error.value)
    assert "body 0" in message and "cell (" in message and "t = " in message
    assert "failure_checkpoint.npz" in message
    arrays, metadata = load_checkpoint(out / "failure_checkpoint.npz")
    assert metadata["kind"] == "riprap coupled run"
    assert {"fraction", "u", "bodies_positions", "bodies_velocities"} <= set(arrays)
    assert np.array_equal(arrays["bodies_positions"][0], [0.1, 0.1, 0.1]), "the last good state"


def test_a_run_whose_stderr_is_not_a_terminal_writes_plain_progress_lines(tmp_path, monkeypatch,
                                                                         capsys):
    """A run sent to a log file (nohup, a batch queue) shows no live bar: it says where it is in
    plain lines instead (every PLAIN_PROGRESS_PERIOD wall seconds; here every chunk)."""
    import riprap.simulation as simulation

    monkeypatch.setattr(simulation, "PLAIN_PROGRESS_PERIOD", 0.0)
    sim = rr.Simulation(end_time=0.02, output_interval=0.01, fluid=_tank(8),
                        output_directory=tmp_path / "logged", progress=True, picture=False)
    sim.run()
    lines = [line for line in capsys.readouterr().err.splitlines() if " / 0.02 s" in line]
    assert lines and "per simulated s" in lines[-1] and "pressure iterations" in lines[-1]
    assert lines[-1].startswith("riprap: fluid: t = ")
