"""A test series (``riprap series``) and a campaign of two members on Dask, at smoke size: three
cubes on a 1:2 slope over a porous core in a laboratory flume (d = 0.5 m, cells of 4 cm), two
steps of five waves (Tp = 1.2 s). What must hold:

- the second step starts exactly where the first ended: the same positions, orientations and
  contact history, bit for bit, every velocity zero;
- the per-wave table adds up to the step's totals: its overtopping volumes to the overtopping
  gauge's (none: the waves sink into the wide porous crest), its waves to the toe gauge's own zero-down-crossing count (within 2: the incident
  record and the gauge's differ by the reflection);
- a campaign of two members on a LocalCluster of two workers, killed while a member is in its
  first step, resumes it from its checkpoint when started again and ends with the same results,
  bit for bit, as the series run unbroken; a third start runs nothing again;
- bad input is refused naming the case, the step and the key.
"""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.analysis import LayerDescription
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case, parse_case
from riprap.errors import CaseFileError, RiprapError
from riprap.geometry.armour_units import armour_unit
from riprap.io.checkpoint import load_checkpoint
from riprap.io.layer_file import write_contact_table, write_layer_file
from riprap.io.pack import PackBody, write_pack
from riprap.io.csv_tables import read_columns_csv
from riprap.placement.slope import Slope
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import ContactRecords
from riprap.waves.per_wave import zero_down_crossing_waves
from riprap.workflows.series import check_series, run_series

STEPS = """
[[series_steps]]
significant_height = 0.09
peak_period = 1.2
waves = 5

[[series_steps]]
significant_height = 0.12
peak_period = 1.2
waves = 5
"""


def _write_series_case(root: Path, steps: str = STEPS, series: str = "settle_time = 1.0") -> Path:
    dn = 0.13
    unit = armour_unit("cube", nominal_diameter=dn, density=2300.0, mesh_size=dn / 2)
    shape = RigidShape.from_mesh(unit.mesh, name="cube")
    slope = Slope(cotangent=2.0, width=0.4, length=1.25)
    turn = Rotation.from_rotvec([0.0, -np.arctan(0.5), 0.0]).as_matrix()
    x, y, z, w = Rotation.from_matrix(turn @ shape.frame_rotation).as_quat()
    positions = [slope.to_world(s, across, 0.5 * dn + 1e-3)
                 for s, across in ((0.45, 0.1), (0.45, 0.3), (0.75, 0.2))]
    concrete = Material(name="concrete", density=2300.0, friction_coefficient=0.9,
                        restitution=0.3, contact_penalty=1e7)
    pack = root / "pack"
    if not (pack / "pack.toml").is_file():
        write_pack(pack, shapes={"cube": shape.mesh}, materials=[concrete],
                   bodies=[PackBody(shape="cube", material="concrete", position=tuple(p),
                                    orientation=(w, x, y, z)) for p in positions],
                   walls=slope.walls(face_material="concrete", side_material="concrete"))
        write_layer_file(pack, LayerDescription.for_unit(
            unit, shape, slope=slope, underlayer_top=0.0, unit_bodies=[0, 1, 2], rows=[0, 0, 1],
            design_positions=np.array(positions)))
        write_contact_table(pack / "contacts.csv", ContactRecords(
            body_i=np.zeros(0, np.int64), body_j=np.zeros(0, np.int64), points=np.zeros((0, 3)),
            normal_forces=np.zeros((0, 3)), tangential_forces=np.zeros((0, 3)),
            stiffness=np.zeros(0)))
    top = slope.to_world(1.25, 0.0, 0.0)
    case = root / "series.toml"
    case.write_text(f'''format_version = 1
pack = "pack/pack.toml"

[simulation]
end_time = 10.0
adaptive_time_step = true
output_interval = 0.5
checkpoint_interval = 1.0

[fluid]
lower = [-2.8, 0.0, 0.0]
upper = [2.2, 0.4, 0.8]
cells = [125, 10, 20]
surface_tension = 0.0
limit_air_speed = true

[[water_regions]]
type = "level"
level = 0.5

[[porous_zones]]
type = "polygon"
porosity = 0.4
stone_diameter = 0.03
points = [[0.05, 0.0], [{top[0]:.4f}, {top[2]:.4f}], [1.9, {top[2]:.4f}], [1.9, 0.0]]

[waves]
type = "irregular"
still_water_level = 0.5
significant_height = 0.1
peak_period = 1.2
duration = 12.0
generation = "boundary"
ramp_periods = 1.0
absorbing_end = false

[[gauges]]
type = "surface"
name = "g1"
position = [-1.9, 0.2, 0.0]

[[gauges]]
type = "surface"
name = "g2"
position = [-1.5, 0.2, 0.0]

[[gauges]]
type = "surface"
name = "g3"
position = [-0.9, 0.2, 0.0]

[[gauges]]
type = "run_up"
name = "face"
position = [0.0, 0.2, 0.0]
to_x = 1.9

[[gauges]]
type = "overtopping"
name = "crest"
position = [1.9, 0.2, {top[2]:.4f}]

[series]
{series}
{steps}
[output]
directory = "out"
''')
    return case


@pytest.fixture(scope="module")
def unbroken(tmp_path_factory):
    """The series with seed offset 1, run in one go with one numba thread (as a campaign's
    member runs)."""
    import numba

    root = tmp_path_factory.mktemp("series")
    case = _write_series_case(root)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    lines = []
    try:
        results = run_series(load_case(case), output_directory=root / "unbroken",
                             progress=False, say=lines.append, seed_offset=1)
    finally:
        numba.set_num_threads(threads)
    return root, case, results, lines


def test_the_second_step_starts_exactly_where_the_first_ended(unbroken):
    root, case, _, _ = unbroken
    first = root / "unbroken" / "step_01" / "checkpoint.npz"
    ended, _ = load_checkpoint(first)
    step_case = load_case(root / "unbroken" / "step_02" / "step.toml")
    sim = build_fluid_run(step_case, output_directory=root / "probe", progress=False)
    sim.start_bodies_at_rest_from(first)
    solids = sim.model.solids
    for name in ("positions", "quaternions", "history_keys", "history_springs"):
        assert np.array_equal(getattr(solids, name), ended[f"bodies_{name}"]), name
    assert len(solids.history_keys) > 0                     # the units rest on the slope
    assert not solids.velocities.any() and not solids.angular_momenta.any()
    assert np.abs(ended["bodies_velocities"]).max() > 0     # they were not at rest before
    # and the run itself: step 2's first rows are step 1's last positions, at rest
    def rows(path):
        table = np.loadtxt(path, delimiter=",", skiprows=1)
        return table

    last, start = rows(first.parent / "body_forces.csv"), rows(
        root / "unbroken" / "step_02" / "body_forces.csv")
    for body in range(3):
        assert np.array_equal(start[start[:, 0] == body][0, 2:5],
                              last[last[:, 0] == body][-1, 2:5])
        assert not start[start[:, 0] == body][0, 5:8].any()


def test_the_per_wave_table_adds_up_to_the_steps_totals(unbroken):
    root, case, results, lines = unbroken
    total_overtopping = 0.0
    for number in (1, 2):
        folder = root / "unbroken" / f"step_{number:02d}"
        table = read_columns_csv(folder / "survey" / "per_wave.csv")
        gauges = np.genfromtxt(folder / "gauges.csv", delimiter=",", names=True)
        volume = gauges["crest_volume_m3_m"]
        assert np.nansum(table["overtopping_m3_per_m"]) == pytest.approx(
            volume[-1] - volume[0], rel=1e-9, abs=1e-15)
        total_overtopping += volume[-1]
        own = zero_down_crossing_waves(gauges["time_s"], gauges["g3_eta_m"])
        assert abs(len(table["wave"]) - len(own)) <= 2
        assert len(table["wave"]) >= 4
        # the damage development never goes back
        assert np.all(np.diff(table["units_displaced"]) >= 0)
    # five waves of Hm0 0.09-0.12 m sink into the 0.78 m wide porous crest (freeboard 0.06 m)
    # before its rear edge: no water crosses the gauge's plane above the crest's surface. Until
    # 2026-12-02 the gauge counted from the cell row holding its z, the core's top row, and read
    # the seepage out of the core's rear face as overtopping (> 0 here)
    assert total_overtopping == pytest.approx(0.0, abs=1e-9)
    curve = results["curve"]
    assert curve["step"] == [1, 2]
    assert curve["cumulative_waves"][1] == curve["waves"][0] + curve["waves"][1]
    assert all(np.isfinite(curve["stability_number"]))
    for name in ("report.html", "damage_curve.csv", "damage_curve.png", "series_results.json"):
        assert (root / "unbroken" / name).is_file(), name
    assert (root / "unbroken" / "step_02" / "survey" / "stability_profiles.png").is_file()
    assert any("series step 2/2" in line for line in lines)
    # EurOtop's q with the crest-width factor: G_c from the top of the layer's face (x = 1.25 m
    # along a 1:2 face from x = 0) to the overtopping gauge at x = 1.9 m, C_r per step in the
    # CSV, the JSON and the report
    width = 1.9 - 1.25 * 2.0 / np.sqrt(5.0)
    assert results["formulas"]["crest_width_m"] == pytest.approx(width, rel=1e-9)
    expected = [min(1.0, 3.06 * np.exp(-1.5 * width / h)) for h in curve["Hm0_m"]]
    assert curve["eurotop_crest_width_factor"] == pytest.approx(expected, rel=1e-12)
    written = read_columns_csv(root / "unbroken" / "damage_curve.csv")
    assert np.allclose(np.asarray(written["eurotop_crest_width_factor"], dtype=float), expected)
    report = (root / "unbroken" / "report.html").read_text()
    assert "crest-width factor C_r" in report and "eq. 6.8" in report


def test_a_killed_campaign_resumes_its_members_and_ends_as_an_unbroken_run(unbroken):
    pytest.importorskip("distributed")
    root, case, results, _ = unbroken
    out = root / "campaign"
    command = [sys.executable, "-m", "riprap", "campaign", str(case), "--seeds", "0", "1",
               "--out", str(out), "--workers", "2"]
    environment = dict(os.environ, PYTHONWARNINGS="ignore")
    process = subprocess.Popen(command, start_new_session=True, env=environment,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    member = out / "series_seed1"
    deadline = time.monotonic() + 600
    while not (member / "step_01" / "checkpoint.npz").is_file():
        assert process.poll() is None, process.stderr.read().decode()
        assert time.monotonic() < deadline
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGKILL)         # the campaign and its workers, mid-step
    process.wait()
    assert not (member / "step_01" / "summary.json").is_file()
    resumed = subprocess.run(command, env=environment, capture_output=True, text=True,
                             timeout=900)
    assert resumed.returncode == 0, resumed.stderr
    for number in (1, 2):
        ours, _ = load_checkpoint(member / f"step_{number:02d}" / "checkpoint.npz")
        theirs, _ = load_checkpoint(root / "unbroken" / f"step_{number:02d}" / "checkpoint.npz")
        for name in ("bodies_positions", "bodies_quaternions", "fraction"):
            assert np.array_equal(ours[name], theirs[name]), (number, name)
    spread = json.loads((out / "campaign_results.json").read_text())
    member_curve = spread["members"]["series_seed1"]["curve"]
    for name in ("N_od", "S", "waves", "Hm0_m"):
        assert member_curve[name] == pytest.approx(results["curve"][name], nan_ok=True), name
    assert spread["spread"]["series"]["members"] == [2, 2]
    # started a third time, nothing is run again
    stamps = {path: path.stat().st_mtime_ns for path in out.glob("*/step_*/summary.json")}
    assert len(stamps) == 4
    again = subprocess.run(command, env=environment, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    assert {path: path.stat().st_mtime_ns for path in stamps} == stamps


def _step_error(tmp_path, steps, series="settle_time = 1.0"):
    case = _write_series_case(tmp_path, steps, series)
    with pytest.raises(CaseFileError) as error:
        check_series(load_case(case), tmp_path / "out")
    return str(error.value)


@pytest.mark.parametrize("steps, message", [
    (STEPS.replace("0.12", "0.09"),
     r"series_steps\[1\]\.significant_height = 0\.09: does not rise above series_steps\[0\]'s "
     r"0\.09 m \(step 2 of the series against step 1"),
    (STEPS.replace("waves = 5\n", "waves = 5\nduration = 20.0\n", 1),
     r"series_steps\[0\]\.waves = 5: give either waves"),
    (STEPS.replace("peak_period = 1.2\n", "peak_period = 1.2\nwave_steepness = 0.03\n", 1),
     r"series_steps\[0\]\.peak_period = 1.2: give either peak_period or wave_steepness"),
    ("", r"series: a test series needs its sea states"),
    # neither of a pair given: the message shows no value the user never wrote
    (STEPS.replace("peak_period = 1.2\n", "", 1),
     r"series_steps\[0\]: neither peak_period nor wave_steepness is given: give one of them"),
    (STEPS.replace("waves = 5\n", "", 1),
     r"series_steps\[0\]: neither waves \(a number of waves\) nor duration \(s\) is given"),
])
def test_bad_steps_are_refused_at_their_key(tmp_path, steps, message):
    with pytest.raises(CaseFileError, match=message):
        load_case(_write_series_case(tmp_path, steps))


def test_a_step_the_flume_cannot_carry_is_named(tmp_path):
    # Hm0 = 0.05 m spans 1.25 cells of 4 cm: the flume check of [waves] refuses it, for step 1
    message = _step_error(tmp_path, STEPS.replace("0.09", "0.05"))
    assert "[[series_steps]] step 1 (Hm0 = 0.05 m" in message and "cells" in message


def test_a_series_needs_an_irregular_sea_and_a_flume():
    with pytest.raises(CaseFileError, match="series_steps.*need.*\\[series\\]|add a \\[series\\]"):
        parse_case('format_version = 1\n[simulation]\nend_time = 1.0\n[[materials]]\nname = "a"\n'
                   '[[shapes]]\nname = "s"\ntype = "sphere"\nradius = 0.1\n[[bodies]]\n'
                   'shape = "s"\nmaterial = "a"\nposition = [0, 0, 1]\n' + STEPS)


def test_a_folder_of_another_case_or_version_is_refused_and_kept(tmp_path, unbroken):
    root = unbroken[0]
    case = _write_series_case(tmp_path, STEPS.replace("0.12", "0.13"))
    folder = tmp_path / "other"
    folder.mkdir()
    record = json.loads((root / "unbroken" / "series.json").read_text())
    (folder / "series.json").write_text(json.dumps(record))
    with pytest.raises(RiprapError, match="the series of another case"):
        run_series(load_case(case), output_directory=folder, progress=False, say=lambda _: None)
    record["riprap_version"] = "0.0.1"
    (folder / "series.json").write_text(json.dumps(record))
    with pytest.raises(RiprapError, match="written by riprap '0.0.1'"):
        run_series(load_case(case), output_directory=folder, progress=False, say=lambda _: None)
    assert json.loads((folder / "series.json").read_text()) == record
    assert not any(folder.glob("step_*"))


def test_an_unanswering_scheduler_is_refused_within_seconds(unbroken):
    pytest.importorskip("distributed")
    from riprap.workflows.campaign import members_of, run_campaign

    root, case, _, _ = unbroken
    started = time.monotonic()
    with pytest.raises(RiprapError, match="does not answer within"):
        run_campaign(members_of([case], [0]), root / "nowhere", scheduler="tcp://127.0.0.1:9")
    assert time.monotonic() - started < 30
    assert not (root / "nowhere").exists()


def test_a_campaign_folder_of_other_members_or_version_is_refused_before_any_worker(unbroken):
    from riprap.workflows.campaign import CAMPAIGN_RECORD, members_of, run_campaign

    root, case, _, _ = unbroken
    folder = root / "other_campaign"
    folder.mkdir()
    record = {"format": 2, "riprap_version": "0.0.1", "run_mode": "full",
              "members": [{"name": "other_seed0", "case_file": "/elsewhere/other.toml",
                           "seed_offset": 0, "fingerprint": "0"}]}
    (folder / CAMPAIGN_RECORD).write_text(json.dumps(record))
    with pytest.raises(RiprapError, match="written by riprap '0.0.1'"):
        run_campaign(members_of([case], [0]), folder, client=object())
    from riprap.io.pack import riprap_version

    record["riprap_version"] = riprap_version()
    (folder / CAMPAIGN_RECORD).write_text(json.dumps(record))
    with pytest.raises(RiprapError, match="holds the members other_seed0, not given now"):
        run_campaign(members_of([case], [0]), folder, client=object())
    assert json.loads((folder / CAMPAIGN_RECORD).read_text()) == record
    with pytest.raises(CaseFileError, match="given more than once"):
        members_of([case, case], [0])
