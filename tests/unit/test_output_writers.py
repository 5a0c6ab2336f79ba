"""Writers on schedules (issue 36): a user's own writer attached from the API, a case file giving
body_forces.csv a schedule of its own, bad schedules refused naming the key, and a restart that
goes on with every writer's schedule bit for bit."""
import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import parse_case
from riprap.cli import main
from riprap.errors import CaseFileError, RiprapError
from riprap.outputs import Writer
from riprap.schedules import Every
from riprap.simulation import Simulation

RIGID = """
format_version = 1
[simulation]
end_time = 0.05
time_step = 2.0e-5
output_interval = 0.025
[[materials]]
name = "stone"
density = 2650.0
contact_penalty = 1.0e7
[[shapes]]
name = "cube"
type = "cube"
side = 0.1
[[bodies]]
shape = "cube"
material = "stone"
position = [0.0, 0.0, 0.2]
[[walls]]
type = "box"
material = "stone"
min = [-0.5, -0.5, 0.0]
max = [0.5, 0.5, 1.0]
"""

COUPLED = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = {output_interval}
[output]
body_forces_interval = {body_forces_interval}
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


class HeightOfOneBody(Writer):
    """What a user writes without touching riprap: one body's height (m) every 0.01 s."""

    name = "height"

    def __init__(self, body):
        super().__init__(Every(seconds=0.01))
        self.body = body
        self.rows = []

    def open(self, model, directory, *, append):
        self.path = directory / "height.csv"

    def write(self, model, entry):
        self.rows.append((entry, model.time, float(model.solver.positions[self.body, 2])))

    def close(self, model):
        self.path.write_text("entry,time_s,z_m\n"
                             + "".join(f"{e},{t!r},{z!r}\n" for e, t, z in self.rows))
        return {"height": str(self.path)}


def test_a_user_writer_attached_from_the_api_writes_at_its_own_times(tmp_path):
    sim = build_simulation(parse_case(RIGID, source="rigid.toml"), output_directory=tmp_path / "out",
                           progress=False)
    writer = HeightOfOneBody(body=0)
    sim.add_writer(writer)
    by_steps = HeightOfOneBody(body=0)            # 500 steps of 2e-5 s: the same times
    by_steps.name, by_steps.schedule = "height_by_steps", Every(steps=500)
    sim.add_writer(by_steps)
    summary = sim.run()
    assert by_steps.rows == writer.rows
    assert [entry for entry, _, _ in writer.rows] == [0, 1, 2, 3, 4, 5]
    assert [t for _, t, _ in writer.rows] == pytest.approx([0.0, 0.01, 0.02, 0.03, 0.04, 0.05],
                                                           abs=1e-12)
    heights = [z for _, _, z in writer.rows]
    assert heights[0] == pytest.approx(0.2) and heights[-1] < heights[0], "the cube falls"
    assert summary.frames == 3                       # the frames keep their own schedule
    assert summary.outputs["height"].endswith("height.csv")
    assert len((tmp_path / "out" / "height.csv").read_text().splitlines()) == 1 + 6


def _coupled(tmp_path, name, *, end_time, output_interval, body_forces_interval):
    path = tmp_path / f"{name}_{end_time}.toml"
    path.write_text(COUPLED.format(end_time=end_time, output_interval=output_interval,
                                   body_forces_interval=body_forces_interval))
    return path


def test_a_case_gives_body_forces_a_schedule_apart_from_the_fields(tmp_path):
    out = tmp_path / "run"
    case = _coupled(tmp_path, "case", end_time=0.1, output_interval=0.1, body_forces_interval=0.01)
    assert main(["run", str(case), "--out", str(out), "--quiet"]) == 0
    assert (out / "fluid.pvd").read_text().count("<DataSet") == 2        # t = 0, 0.1
    assert (out / "bodies.pvd").read_text().count("<DataSet") == 2
    rows = (out / "body_forces.csv").read_text().splitlines()[1:]
    times = [float(row.split(",")[1]) for row in rows]
    assert times == pytest.approx([0.01 * k for k in range(11)], abs=1e-9)


def test_a_bad_schedule_is_refused_naming_its_key(tmp_path):
    text = COUPLED.format(end_time=1.0, output_interval=0.1, body_forces_interval=1e-300)
    with pytest.raises(CaseFileError, match="body_forces_interval"):
        parse_case(text, source="bad.toml")
    text = COUPLED.format(end_time=1.0, output_interval=0.1, body_forces_interval=-0.01)
    with pytest.raises(CaseFileError, match="body_forces_interval"):
        parse_case(text, source="bad.toml")
    with pytest.raises(CaseFileError, match="output.body_forces_interval = 1e-300"):
        Simulation(end_time=1.0, body_forces_interval=1e-300)
    with pytest.raises(CaseFileError, match="output.body_forces_interval = nan"):
        Simulation(end_time=1.0, body_forces_interval=float("nan"))
    with pytest.raises(CaseFileError, match="seconds or steps"):
        Every()
    with pytest.raises(CaseFileError, match="steps=0"):
        Every(steps=0)
    sim = Simulation(end_time=1.0)
    sim.add_writer(HeightOfOneBody(body=0))
    with pytest.raises(Exception, match="named 'height' is there already"):
        sim.add_writer(HeightOfOneBody(body=0))
    with pytest.raises(RiprapError, match="object has no name, schedule, open, write, close"):
        sim.add_writer(object())
    wrong = HeightOfOneBody(body=0)
    wrong.name, wrong.schedule = "height_2", 0.01
    with pytest.raises(RiprapError, match="has schedule 0.01; give riprap.schedules.Every"):
        sim.add_writer(wrong)
    with pytest.raises(CaseFileError, match="'body_forse' is none of riprap's output families .*"
                                            "did you mean 'body_forces'"):
        sim.set_output_interval("body_forse", 0.01)
    with pytest.raises(RiprapError, match="got str 'bodies.toml'"):
        Simulation("bodies.toml", end_time=1.0)


def test_an_interval_for_a_family_the_run_does_not_write_is_refused(tmp_path):
    """A dry run writes no body_forces.csv: its interval would silently do nothing. The case
    file is refused at load (it has no [fluid]); the API when the run starts."""
    text = RIGID.replace("[[materials]]", "[output]\nbody_forces_interval = 0.01\n[[materials]]")
    with pytest.raises(CaseFileError, match="rigid.toml.*body_forces_interval.*without a \\[fluid\\]"):
        parse_case(text, source="rigid.toml")
    sim = build_simulation(parse_case(RIGID, source="rigid.toml"), output_directory=tmp_path / "out",
                           progress=False)
    sim.set_output_interval("body_forces", 0.01)
    with pytest.raises(CaseFileError, match="output.body_forces_interval = 0.01: this run writes no "
                                            "body_forces"):
        sim.run()


def test_a_restart_goes_on_with_each_writers_schedule_bit_for_bit(tmp_path):
    def case(end_time):
        return str(_coupled(tmp_path, "case", end_time=end_time, output_interval=0.05,
                            body_forces_interval=0.025))

    unbroken, pieces = tmp_path / "unbroken", tmp_path / "pieces"
    assert main(["run", case(0.1), "--out", str(unbroken), "--quiet"]) == 0
    assert main(["run", case(0.05), "--out", str(pieces), "--quiet"]) == 0
    assert main(["run", case(0.1), "--out", str(pieces), "--quiet", "--restart",
                 str(pieces / "checkpoint.npz")]) == 0
    written = (pieces / "body_forces.csv").read_text()
    assert written == (unbroken / "body_forces.csv").read_text()
    times = [float(row.split(",")[1]) for row in written.splitlines()[1:]]
    assert times == pytest.approx([0.0, 0.025, 0.05, 0.075, 0.1], abs=1e-9)
    assert (pieces / "fluid.pvd").read_text().count("<DataSet") == 3
