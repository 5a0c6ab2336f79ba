"""What a test series and a campaign say while they run, and what the series report shows when the
flume measured nothing (issue 52, items 2, 3 and 5), at smoke size:

- a campaign's ``campaign.log`` (and its terminal) holds every member's progress (step, simulated
  time, waves, wall time) and the cost estimate; a warning of a member is one ``riprap: warning:``
  line, never a raw Python warning with its source line, and never twice;
- a series report of a run that measured nothing draws no axes: each plot is named "not computed"
  with why, in the picture and on the page; a report that measured its waves draws them; the
  damage-curve table has readable column names with units; the page does not print the case
  file's absolute path; the first-displacement sentence reads as one;
- a step's progress line says its waves and time to go in minutes or seconds (not "0.033 h"); a
  resumed step says from which checkpoint time;
- ``riprap check`` on a series gives a cost estimate; a campaign's cost is spread over its workers.
"""
import json
import math
from pathlib import Path
from types import SimpleNamespace

import matplotlib.figure
import pytest

from riprap.analysis.series_damage import series_curve
from riprap.case.load import load_case
from riprap.io.log_file import read_new_log_lines
from riprap.io.series_report import write_series_report
from riprap.work_estimate import duration_words
from riprap.workflows.campaign import CAMPAIGN_LOG, campaign_cost, members_of, run_campaign
from riprap.workflows.check import check_case
from riprap.workflows.series import series_summary_lines
from riprap.workflows.series_progress import SeriesLog, StepProgress

from test_series import STEPS, _write_series_case

ONE_STEP = STEPS[:STEPS.index("[[series_steps]]", 10)]


class _Here:
    """A Dask client stand-in that runs each member in this process when it is submitted."""

    scheduler = SimpleNamespace(address="this process")

    def submit(self, function, *args, key, pure):
        value = function(*args)
        return SimpleNamespace(done=lambda: True, result=lambda: value)


def test_a_campaigns_log_holds_every_members_progress_and_each_warning_once(
        tmp_path, monkeypatch, capfd):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    case = _write_series_case(tmp_path, ONE_STEP)
    out = tmp_path / "campaign"
    said = []
    run_campaign(members_of([case], [0, 1]), out, client=_Here(), say=said.append)
    log, _ = read_new_log_lines(out / CAMPAIGN_LOG, 0)
    assert log == said                        # the terminal's lines, kept in the campaign folder
    assert any(line.startswith("riprap: cost: about ") and "2 members" in line for line in log)
    for name in ("series_seed0", "series_seed1"):
        progress = [line for line in log if line.startswith(f"riprap: {name}: series step 1/1: t = ")]
        assert len(progress) >= 2, log           # the step's first and last progress lines
        assert "of 5 waves made" in progress[0] and "of wall time" in progress[0]
        assert "t = 0.01 / 0.01 s simulated" in progress[-1] and "step done" in progress[-1]
        assert any(line == f"riprap: campaign member {name} done" for line in log)
        # the member's own log holds its progress and its survey
        member, _ = read_new_log_lines(out / name / "series.log", 0)
        assert any("series step 1 survey" in line for line in member)
        survey = (out / name / "step_01" / "survey" / "report.html").read_text()
        assert "frame -1" not in survey and "frame 1 (the last), t = 0.01 s" in survey
        # the step's survey says it is of a smoke run, as the series report does
        assert "<title>riprap armour layer analysis (SMOKE RUN)</title>" in survey
        assert json.loads((out / name / "step_01" / "survey" / "layer_summary.json").read_text()
                          )["run_mode"] == "smoke"
    # the smoke run's end-time warning of each member: one riprap line each, no raw warning
    warnings = [line for line in log if line.startswith("riprap: warning")]
    assert warnings and len(warnings) == len(set(warnings))
    assert all("smoke run ends at t = 0.01 s" in line for line in warnings)
    printed = capfd.readouterr()
    assert "RiprapWarning" not in printed.err and "warnings.warn" not in printed.err

    # a second start says nothing of what the members' logs held before
    again = []
    run_campaign(members_of([case], [0, 1]), out, client=_Here(), say=again.append)
    assert not any(": series step 1/1: t = " in line for line in again)
    assert sum("done before, not run again" in line for line in again) == 2


def _results(tmp_path, measured: bool) -> dict:
    """Series results of two steps of cubes as ``run_series`` makes them, with the waves
    measured or not (NaN) at the toe."""
    nan = math.nan
    rows = [{"step": k, "Hm0_m": hm0 if measured else nan, "Tm_s": 1.1 if measured else nan,
             "waves": waves if measured else 0, "units_displaced": displaced if measured else 0,
             "N_od": nod if measured else 0.0, "S": s, "rocking_events": 0,
             "q_m3_s_m": q if measured else nan}
            for k, hm0, waves, displaced, nod, s, q in ((1, 0.09, 20, 0, 0.0, 0.1, 0.0),
                                                        (2, 0.12, 22, 1, 0.4, 0.9, 2e-4))]
    results = series_curve(rows, unit_kind="core_loc_like", nominal_diameter=0.13, delta=1.3,
                           slope_cot=2.0, freeboard=0.15, crest_width=None)
    results["per_wave"] = ({2: {"cumulative_wave": [21, 42], "N_od": [0.0, 0.4]}}
                           if measured else {})
    results["run_mode"] = "full"
    results["case_file"] = str(tmp_path / "deep" / "folder" / "series.toml")
    results["displacement_threshold_over_dn"] = 1.0
    results["steps"] = [{"step": k, "folder": str(tmp_path / f"step_{k:02d}"),
                         "target_Hm0_m": 0.09, "Tp_s": 1.2, "target_waves": 20,
                         "sea_duration_s": 30.0,
                         "wave_height_not_measured": None if measured else
                         "no surface gauge could be analysed; the record ends at t = 0.01 s"}
                        for k in (1, 2)]
    return results


@pytest.fixture
def drawn(monkeypatch):
    """Every figure saved: its file name and, per axes, whether it is drawn with data axes."""
    figures = {}
    save = matplotlib.figure.Figure.savefig

    def savefig(figure, path, *args, **kwargs):
        figures[Path(path).name] = [axes.axison for axes in figure.axes]
        return save(figure, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    return figures


def test_a_series_report_that_measured_nothing_draws_no_empty_axes(tmp_path, drawn):
    results = _results(tmp_path, measured=False)
    write_series_report(tmp_path, results)
    assert drawn == {"damage_curve.png": [False, False], "overtopping.png": [False]}
    page = (tmp_path / "report.html").read_text()
    for plot in ("damage curve", "damage development N_od(N)", "overtopping"):
        assert f"<p class='missing'>{plot}: not computed: " in page
    assert "no step measured an incident wave height at the toe: no surface gauge" in page
    assert "<img src='damage_curve.png'" not in page and "<img src='overtopping.png'" not in page
    assert "Step 1: Hm0 not measured (no surface gauge could be analysed" in page
    # readable headers (the keys as tooltips); Hudson's N_s shown although no wave was measured
    assert ">Hm0 at the toe (m)</th>" in page and ">q (m^3/s per m)</th>" in page
    assert ">Hudson N_s, no damage</th>" in page and "title='hudson_stability_number'" in page
    assert ">q_m3_s_m<" not in page and ">hudson_stability_number<" not in page
    assert f"{(2.0 * 16.0) ** (1 / 3):.4g}" in page
    # one sentence after another; the case by its name, not its absolute path
    assert "No unit was displaced in the series. The formulas' start of damage: " in page
    assert ".;" not in page
    assert "series.toml" in page and str(tmp_path / "deep") not in page


def test_the_terminal_says_not_measured_never_nan(tmp_path):
    lines = series_summary_lines(_results(tmp_path, measured=False))
    assert lines[0] == ("riprap: step 1: Hm0 and N_s not measured (no surface gauge could be "
                        "analysed; the record ends at t = 0.01 s), N_od 0, S 0.1, q not measured")
    assert not any("nan" in line for line in lines)
    measured = series_summary_lines(_results(tmp_path, measured=True))
    assert measured[1].startswith("riprap: step 2: Hm0 0.12 m, N_s 0.71, 22 waves, N_od 0.4")


def test_a_series_report_that_measured_waves_draws_them(tmp_path, drawn):
    write_series_report(tmp_path, _results(tmp_path, measured=True))
    assert all(drawn["damage_curve.png"]) and drawn["overtopping.png"] == [True]
    page = (tmp_path / "report.html").read_text()
    assert "<img src='damage_curve.png'" in page and "<img src='overtopping.png'" in page
    assert "First displacement at step 2, N_s = 0.7" in page
    assert "(none at N_s = 0.533)" in page


class _Model:
    def __init__(self, time):
        self.time = time


def test_a_steps_progress_says_waves_and_time_to_go_and_where_a_resume_began():
    said, logged = [], []
    log = SeriesLog(said.append)
    log.note = logged.append
    progress = StepProgress(log, label="series step 2/3", end_time=100.0, sea_duration=80.0,
                            waves=50, later_simulated_s=120.0, period_s=0.0)
    progress.open(_Model(40.0), Path("."), append=True)
    assert said == ["riprap: series step 2/3: resumed from its checkpoint at t = 40 s of 100 s"]
    start = progress._start[0]
    line = progress.line(64.0, start + 240.0)        # 24 s simulated in 4 min of wall time
    assert line == ("riprap: series step 2/3: t = 64 / 100 s simulated, about 40 of 50 waves "
                    "made, 4 min of wall time, about 6 min to go in this step, 26 min in the "
                    "series")
    assert duration_words(0.033 * 3600) == "2 min" and duration_words(40.0) == "40 s"
    assert duration_words(3 * 3600.0) == "3 h"


def test_check_gives_a_cost_estimate_for_a_series_and_a_campaign(tmp_path):
    case_file = _write_series_case(tmp_path)
    report = check_case(load_case(case_file), output_directory=tmp_path / "out")
    cost = [line for line in report.checked if line.startswith("cost: about ")]
    assert len(cost) == 1, report.checked
    assert "of wall time for the series" in cost[0] and "25,000 cells of 0.04 m" in cost[0]
    case = load_case(case_file)
    members = members_of([case_file], [0, 1, 2])
    cases = {member.case_file: case for member in members}
    one_worker, three = (campaign_cost(members, cases, n) for n in (1, 3))
    assert "3 members" in one_worker and "on 1 worker at once" in one_worker
    assert "on 3 workers at once" in three
    assert not (tmp_path / "out").exists()


def test_a_rock_series_sets_s_beside_the_three_formulas(tmp_path, drawn):
    """Rock armour (issue 55): the curve gains T_m-1,0, the Rock Manual class and the three
    formulas' S cumulative over the steps; the report draws S beside them and names P."""
    from riprap.analysis.rock_stability import RockSection, rock_stability
    from riprap.analysis.series_damage import rock_formula_curves
    from riprap.workflows.series import _rock_curves

    section = RockSection(filter_dn50=0.013, core_dn50=0.0084, core_note="the case's core")
    steps = ((1, 0.08, 1.3, 50, 0.8), (2, 0.10, 1.45, 50, 2.9))
    rows = [{"step": k, "Hm0_m": hm0, "Tm_s": 1.1, "waves": n, "units_displaced": 0,
             "N_od": 0.0, "S": s, "rocking_events": 0, "q_m3_s_m": 0.0}
            for k, hm0, _, n, s in steps]
    results = series_curve(rows, unit_kind="armour_stone", nominal_diameter=0.03, delta=1.65,
                           slope_cot=2.0, freeboard=0.1, crest_width=None)
    flumes = [{"unit": "armour_stone", "slope_cot": 2.0, "relative_density": 1.65,
               "nominal_diameter_m": 0.03,
               "rock": rock_stability(hs=hm0, spectral_period=tm, waves=n, slope_cot=2.0,
                                      armour_density=2650.0, water_density=1000.0,
                                      nominal_diameter=0.03, damage=s, section=section)}
              for _, hm0, tm, n, s in steps]
    results["formulas"]["rock"] = _rock_curves(results["curve"], flumes, flumes[-1])
    curve = results["curve"]
    assert curve["Tm_1_0_s"] == [1.3, 1.45]
    assert curve["rock_damage_class"] == ["none", "start of damage"]
    expected = rock_formula_curves([(0.08, 1.3, 50), (0.10, 1.45, 50)], slope_cot=2.0,
                                   delta=1.65, nominal_diameter=0.03, permeability=0.4,
                                   core_nominal_diameter=0.0084)
    for column, values in expected.items():
        assert curve[column] == values
        assert values[1] > values[0]
    results.update({"per_wave": {}, "run_mode": "full", "displacement_threshold_over_dn": 1.0,
                    "case_file": str(tmp_path / "rock.toml"),
                    "steps": [{"step": k, "folder": str(tmp_path / f"step_{k:02d}"),
                               "target_Hm0_m": hm0, "Tp_s": 1.5, "target_waves": 50,
                               "sea_duration_s": 75.0, "wave_height_not_measured": None}
                              for k, hm0, *_ in steps]})
    write_series_report(tmp_path, results)
    assert drawn["damage_curve.png"][0]
    page = (tmp_path / "report.html").read_text()
    assert "Notional permeability P = 0.4" in page and "core D<sub>n50</sub> 0.0084 m" in page
    assert ">Van Gent et al. (2003) S, waves so far</th>" in page
    assert ">Rock Manual class of S</th>" in page
