"""Issue 35: the files of a run are strict and checked, a short flume run says what it will not
give, and a restart continues the same run only.

- Every JSON file riprap writes parses with a strict parser (no ``NaN``): the smoke runs of
  examples/10 (a flume with a placed layer), a placement and an analysis are read back.
- ``riprap analyse`` refuses a ``waves_report.json`` or ``summary.json`` with a NaN, a negative
  height, a string where a number belongs or a list where a table belongs, naming the file and
  the field (exit 2, one line, nothing written).
- A flume run that ends before its gauges' analysis windows open is warned about by ``riprap
  check`` and ``riprap run`` (and still runs); its waves report says what it could not compute.
- ``gauges.png`` shades no span when a record ends before its window opens.
- A restart whose case changed beyond what may change (end time, outputs, time step) is refused
  naming the key with old and new values, by ``riprap run --restart`` and ``riprap check
  --restart``; a longer end_time restarts bit for bit; a checkpoint without a case record (older
  riprap) restarts with a warning.
"""
import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from riprap.cli import main
from riprap.io.checkpoint import load_checkpoint, save_checkpoint
from test_analysis_displacements import coupled_run  # noqa: F401  (a fixture: a hand-made run)
from test_cli_bad_inputs import PLACEMENT, RIGID, _edit
from test_wave_flume_case import CASE as FLUME

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _strict(text: str):
    def refuse(name):
        raise ValueError(f"{name} in JSON")

    return json.loads(text, parse_constant=refuse)


def _one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.startswith("riprap: error:")]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


# ---------------------------------------------------------------------------- strict JSON
def test_non_finite_numbers_are_written_as_null(tmp_path):
    from riprap.io.gauge_files import write_waves_report

    path = write_waves_report(tmp_path / "waves_report.json", {
        "gauges": {"g1": {"Hm0_m": 0.1, "Tz_s": float("nan")}},
        "spread": np.array([1.0, np.inf]), "peak": np.float64(-np.inf)})
    report = _strict(path.read_text())
    assert report["gauges"]["g1"] == {"Hm0_m": 0.1, "Tz_s": None}
    assert report["spread"] == [1.0, None] and report["peak"] is None


def test_every_json_of_a_flume_run_a_placement_and_an_analysis_is_strict(tmp_path, monkeypatch,
                                                                         capsys):
    """examples/10 in smoke mode (its layer in the flume), then its analysis, and a placement: every
    ``*.json`` written parses strictly. The smoke run is far shorter than the analysis window, so
    run and check warn, and the report and the analysis say what could not be computed."""
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    case = EXAMPLES / "10_breakwater_test" / "case.toml"
    assert main(["check", str(case), "--out", str(tmp_path / "flume")]) == 0
    checked = capsys.readouterr().err
    assert "riprap: warning:" in checked and "the wave analysis reads each gauge" in checked
    assert main(["run", str(case), "--out", str(tmp_path / "flume"), "--quiet"]) == 0
    ran = capsys.readouterr().err
    assert "the wave analysis reads each gauge" in ran and "no stability number" in ran
    report = _strict((tmp_path / "flume" / "waves_report.json").read_text())
    assert any("before the analysis window opens" in item for item in report["not_computed"])
    assert main(["analyse", str(tmp_path / "flume"), "--out", str(tmp_path / "flume_analysis")]) == 0
    said = capsys.readouterr().out
    assert "riprap: flume test: not computed: stability number" in said
    placement = tmp_path / "placement.toml"
    placement.write_text(PLACEMENT)
    assert main(["place", str(placement), "--out", str(tmp_path / "layer"), "--quiet"]) == 0
    written = sorted(tmp_path.rglob("*.json"))
    names = {path.name for path in written}
    assert {"summary.json", "waves_report.json", "layer_summary.json", "layer.json"} <= names
    for path in written:
        _strict(path.read_text())


# ---------------------------------------------------------------------------- analyse's inputs
GOOD_REPORT = {"water_density_kg_m3": 1000.0, "record_end_s": 30.0,
               "gauges": {"g1": {"x_m": -5.0, "analysed_from_s": 10.0, "samples": 2000,
                                 "Hm0_m": 0.7, "Tz_s": 3.0, "waves": 20}},
               "reflection": [{"gauges": ["g1", "g2"], "spacing_m": 1.6, "incident_Hm0_m": 0.7,
                               "reflected_Hm0_m": 0.2, "reflection_coefficient": 0.3,
                               "band_Hz": [0.1, 0.5]}],
               "not_computed": [], "cautions": []}


def _broken(path, value):
    report = json.loads(json.dumps(GOOD_REPORT))
    *parents, last = path
    entry = report
    for key in parents:
        entry = entry[key]
    entry[last] = value
    return json.dumps(report, indent=2)


BROKEN_REPORTS = {
    "nan_height": (_broken(["gauges", "g1", "Hm0_m"], float("nan")), "NaN"),
    "negative_height": (_broken(["gauges", "g1", "Hm0_m"], -0.7), "gauges.g1.Hm0_m = -0.7"),
    "string_period": (_broken(["gauges", "g1", "Tz_s"], "3 s"), 'gauges.g1.Tz_s = "3 s"'),
    "list_for_table": (_broken(["gauges"], [0.7, 3.0]), "gauges = [0.7, 3.0]"),
    "table_for_list": (_broken(["reflection"], {"g1": 0.3}), "reflection = "),
    "negative_reflection": (_broken(["reflection", 0, "reflection_coefficient"], -0.3),
                            "reflection[0].reflection_coefficient = -0.3"),
    "string_density": (_broken(["water_density_kg_m3"], "1000"), "water_density_kg_m3"),
    "not_an_object": ("[1, 2]", "not a waves report"),
}


@pytest.mark.parametrize("name", sorted(BROKEN_REPORTS))
def test_analyse_refuses_a_broken_waves_report(name, coupled_run, tmp_path, capsys):  # noqa: F811
    text, phrase = BROKEN_REPORTS[name]
    run = tmp_path / "run"
    shutil.copytree(coupled_run, run)
    (run / "waves_report.json").write_text(text)
    out = tmp_path / "analysis"
    assert main(["analyse", str(run), "--out", str(out), "--frame", "1"]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "waves_report.json" in line and phrase in line
    assert not out.exists(), "refused before the output folder is made"


def test_analyse_reads_a_good_waves_report_with_nulls(coupled_run, tmp_path, capsys):  # noqa: F811
    run = tmp_path / "run"
    shutil.copytree(coupled_run, run)
    report = json.loads(json.dumps(GOOD_REPORT))
    report["gauges"]["g1"]["Tp_s"] = None          # a figure the run could not compute
    report["cautions"] = ["g1: from 3 waves only"]
    (run / "waves_report.json").write_text(json.dumps(report))
    assert main(["analyse", str(run), "--out", str(tmp_path / "analysis"), "--frame", "1"]) == 0
    out = capsys.readouterr().out
    assert "riprap: flume test: Hm0 0.7 m" in out and "caution: g1: from 3 waves only" in out


def test_analyse_refuses_a_summary_with_nan(coupled_run, tmp_path, capsys):  # noqa: F811
    run = tmp_path / "run"
    shutil.copytree(coupled_run, run)
    summary = json.loads((run / "summary.json").read_text())
    (run / "summary.json").write_text(json.dumps(summary)[:-1] + ', "max_speed": NaN}')
    assert main(["analyse", str(run), "--out", str(tmp_path / "analysis"), "--frame", "1"]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "summary.json" in line and "NaN" in line


# ---------------------------------------------------------------------------- short flume runs
def _flume(tmp_path, end_time):
    path = tmp_path / "flume.toml"
    path.write_text(FLUME.format(end_time=end_time, length=5.6, cells=280, kind="linear", extra="",
                                 gauge_x=1.8, above_z=0.42))
    return path


def test_a_short_flume_run_is_warned_about_and_its_report_says_why(tmp_path, capsys):
    """Linear wave T = 1 s, ramp 2 periods: gauge b (x = 2 m) opens at 2 + (2 - 1.38)/0.93 + 2 = 4.67 s (the zone ends at L = 1.38 m)
    and a split needs four periods after it; a 0.2 s run gives nothing and says so."""
    case = _flume(tmp_path, 0.2)
    assert main(["check", str(case), "--out", str(tmp_path / "out")]) == 0
    warned = capsys.readouterr().err
    assert "riprap: warning:" in warned and "flume.toml [simulation] end_time" in warned
    assert "to 4.67 s at b" in warned and "Run to at least 9 s" in warned
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    said = capsys.readouterr()
    assert "Run to at least 9 s" in said.err
    assert "riprap: waves: not computed: b: wave heights and periods" in said.out
    report = _strict((tmp_path / "out" / "waves_report.json").read_text())
    assert report["record_end_s"] == pytest.approx(0.2)
    reasons = "\n".join(report["not_computed"])
    assert "b: wave heights and periods: the record ends at t = 0.2 s" in reasons
    assert "a-b: incident and reflected waves" in reasons and "up: run-up" in reasons


def test_a_long_enough_flume_run_is_not_warned_about(tmp_path):
    from riprap.case.build_fluid import build_fluid_solver
    from riprap.case.load import load_case
    from riprap.waves.analysis_window import flume_windows, short_run_warning

    fluid = build_fluid_solver(load_case(_flume(tmp_path, 9.0)))
    windows = flume_windows(fluid.wave_source, fluid.gauges)
    assert windows.complete == pytest.approx(4.67 + 4.0, abs=0.01)
    assert short_run_warning(windows, 9.0, case_end_time=9.0, where="w") is None
    assert "no incident and reflected" in short_run_warning(windows, 7.0, case_end_time=7.0,
                                                            where="w")
    assert windows.missing(7.0) == ["no incident and reflected waves (reflection coefficient)"]


def test_statistics_of_one_to_three_waves_carry_a_caution():
    from riprap.waves.analysis_window import few_waves_caution
    from riprap.waves.report import _caution

    assert few_waves_caution(0) is None and few_waves_caution(4) is None
    report, entry = {"cautions": []}, {"waves": 2}
    _caution(report, entry, "g1", 2)
    assert "from 2 waves only" in entry["caution"] and report["cautions"][0].startswith("g1: ")


def test_gauges_png_shades_no_reversed_span(tmp_path, monkeypatch):
    import matplotlib.axes

    from riprap.io.gauge_files import gauges_png

    spans = []
    monkeypatch.setattr(matplotlib.axes.Axes, "axvspan",
                        lambda self, start, end, **kw: spans.append((start, end)))
    times = np.linspace(0.0, 10.0, 101)
    gauges = SimpleNamespace(gauges=[SimpleNamespace(kind="surface", name="g1",
                                                     columns=["g1_eta_m"], position=(1.0, 0, 0))],
                             series=lambda column: (times, 0.01 * np.sin(times)))
    gauges_png(tmp_path / "late.png", gauges, {"gauges": {"g1": {"analysed_from_s": 17.0}}})
    assert spans == [] and (tmp_path / "late.png").stat().st_size > 0
    gauges_png(tmp_path / "open.png", gauges, {"gauges": {"g1": {"analysed_from_s": 4.0}}})
    assert spans == [(4.0, 10.0)]


# ---------------------------------------------------------------------------- restarts
def _rigid(tmp_path, end_time, extra_material=""):
    path = tmp_path / "case.toml"
    text = _edit(RIGID, "end_time = 0.01", f"end_time = {end_time}\noutput_interval = 0.005")
    text = _edit(text, 'name = "rock"\n', f'name = "rock"\n{extra_material}')
    path.write_text(_edit(text, "position = [0.0, 0.0, 0.06]", "position = [0.0, 0.0, 0.05]"))
    return path


def test_a_restart_with_a_changed_friction_is_refused_naming_the_key(tmp_path, capsys):
    case = _rigid(tmp_path, 0.01)
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "--quiet"]) == 0
    before = {name: (out / name).read_bytes() for name in ("summary.json", "checkpoint.npz")}
    case = _rigid(tmp_path, 0.02, "friction_coefficient = 0.3\n")
    capsys.readouterr()
    for command in (["run", str(case), "--out", str(out), "--quiet"],
                    ["check", str(case), "--out", str(out)]):
        assert main(command + ["--restart", str(out / "checkpoint.npz")]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert "checkpoint.npz" in line
        assert "[[materials]] 'rock' friction_coefficient was 0.6, is now 0.3" in line
        assert "may change only end_time" in line
    assert {name: (out / name).read_bytes() for name in before} == before, "nothing written over"


def test_a_restart_with_a_longer_end_time_is_accepted_and_bit_for_bit(tmp_path, capsys):
    straight, split = tmp_path / "straight", tmp_path / "split"
    assert main(["run", str(_rigid(tmp_path, 0.02)), "--out", str(straight), "--quiet"]) == 0
    assert main(["run", str(_rigid(tmp_path, 0.01)), "--out", str(split), "--quiet"]) == 0
    case = _rigid(tmp_path, 0.02)
    assert main(["check", str(case), "--out", str(split), "--restart",
                 str(split / "checkpoint.npz")]) == 0
    assert "a checkpoint of this case" in capsys.readouterr().out
    assert main(["run", str(case), "--out", str(split), "--quiet", "--restart",
                 str(split / "checkpoint.npz")]) == 0
    a, _ = load_checkpoint(straight / "checkpoint.npz")
    b, _ = load_checkpoint(split / "checkpoint.npz")
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name].shape == b[name].shape and a[name].tobytes() == b[name].tobytes(), name
    # the cube sits on the plane and settles: its state is not trivially zero
    assert np.any(a["velocities"] != 0.0)


def test_an_old_checkpoint_without_a_case_record_restarts_with_a_warning(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(_rigid(tmp_path, 0.01)), "--out", str(out), "--quiet"]) == 0
    arrays, metadata = load_checkpoint(out / "checkpoint.npz")
    assert "case_record" in metadata
    del metadata["case_record"]
    save_checkpoint(out / "checkpoint.npz", arrays=arrays, metadata=metadata)
    capsys.readouterr()
    assert main(["run", str(_rigid(tmp_path, 0.02, "friction_coefficient = 0.3\n")), "--out",
                 str(out), "--quiet", "--restart", str(out / "checkpoint.npz")]) == 0
    err = capsys.readouterr().err
    assert "riprap: warning:" in err and "older riprap" in err and "riprap: error" not in err


def test_an_irregular_sea_lasting_the_end_time_makes_end_time_part_of_the_run():
    """An irregular sea of duration 0 lasts the end time: a longer end_time is another sea, so
    the record keeps the duration it has; with a duration given, end_time may change."""
    from riprap.case.load import parse_case
    from riprap.case.run_record import RunDefinition

    text = FLUME.format(end_time="{end}", length=5.6, cells=280, kind="irregular", gauge_x=1.8,
                        above_z=0.42, extra="").replace(
        "height = 0.04\nperiod = 1.0", "significant_height = 0.04\npeak_period = 1.0{duration}")

    def record(end, duration=""):
        return RunDefinition.of(parse_case(text.format(end=end, duration=duration),
                                           source="sea.toml"))

    changes = record(20.0).changes(record(10.0).values)
    assert changes == ["[waves] duration was 10.0, is now 20.0"]
    assert record(20.0, "\nduration = 30.0").changes(record(10.0, "\nduration = 30.0").values) == []


# ---------------------------------------------------------------------------- run tables
def test_gauge_records_read_back_exactly_and_broken_ones_are_named(tmp_path):
    from riprap.errors import CaseFileError
    from riprap.io.gauge_files import read_gauges_csv, write_gauges_csv

    times = np.array([0.01, 0.02, 0.03])
    values = np.array([[0.001, -0.5], [0.002, -0.25], [-0.003, 0.125]])
    gauges = SimpleNamespace(count=3, times=times, values=values, columns=["a_eta_m", "up_level_m"])
    path = write_gauges_csv(tmp_path / "gauges.csv", gauges)
    read_times, columns = read_gauges_csv(path)
    assert np.array_equal(read_times, times) and np.array_equal(columns["up_level_m"], values[:, 1])
    for body, phrase in (("0.01,0.1,0.2\n0.02,nan,0.2\n", "gauges.csv:3: a_eta_m = nan is not finite"),
                         ("0.01,0.1,0.2\n0.005,0.1,0.2\n", "gauges.csv:3: time_s = 0.005 s does not"),
                         ("0.01,0.1,0.2\n0.02,0.1\n", "gauges.csv:3: 2 fields, the header has 3"),
                         ("0.01,x,0.2\n", "gauges.csv:2: a_eta_m = 'x' is not a number")):
        path.write_text("time_s,a_eta_m,up_level_m\n" + body)
        with pytest.raises(CaseFileError, match=phrase):
            read_gauges_csv(path)
