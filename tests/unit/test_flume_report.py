"""The flume test in the report (issue 35): `riprap analyse` of a flume run writes report.html with
a waves and a stability section and their pictures; runs in water record contacts as dry runs do;
units.csv has each unit's largest fluid force; displacements are coloured on a fixed scale in D_n;
no histogram panel is drawn empty; what could not be computed is said; a broken gauges.csv or
body_forces.csv is refused naming the file and the line, with nothing written.

The end-to-end test runs examples/10_breakwater_test in smoke mode (RIPRAP_SMOKE=1, 0.01 s) once
for the module and analyses it."""
import html
import json
import math
import os
import re
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from riprap.cli import main
from riprap.errors import CaseFileError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def flume_run(tmp_path_factory):
    """examples/10 run in smoke mode and analysed: (run folder, analysis folder)."""
    base = tmp_path_factory.mktemp("flume")
    run, analysis = base / "run", base / "run" / "analysis"
    before = os.environ.get("RIPRAP_SMOKE")
    os.environ["RIPRAP_SMOKE"] = "1"
    try:
        assert main(["run", str(EXAMPLES / "10_breakwater_test" / "case.toml"), "--out", str(run),
                     "--quiet"]) == 0
    finally:
        if before is None:
            os.environ.pop("RIPRAP_SMOKE")
        else:
            os.environ["RIPRAP_SMOKE"] = before
    assert main(["analyse", str(run), "--out", str(analysis)]) == 0
    return run, analysis


def _images(page: str) -> list[str]:
    return re.findall(r"<img[^>]*src='([^']+)'", page)


def test_the_report_of_a_flume_run_has_the_waves_and_stability_sections(flume_run):
    _, analysis = flume_run
    page = (analysis / "report.html").read_text()
    for heading in ("<h2 id='waves'>Waves</h2>", "<h2 id='stability'>Stability</h2>",
                    "Spectra, measured against the target", "Incident and reflected waves",
                    "Run-up", "Overtopping", "Profiles of the section, before and after",
                    "Contacts under wave load, frame by frame"):
        assert heading in page, heading
    # the waves come before the stability, both before the layer's own summary
    assert page.index("id='waves'") < page.index("id='stability'") < page.index("<h2>Summary")
    pictures = _images(page)
    for name in ("waves_spectra.png", "waves_run_up.png", "waves_overtopping.png",
                 "stability_profiles.png", "stability_units.png", "stability_contacts.png"):
        assert name in pictures, name
    for name in pictures:       # every picture the page shows is there and not empty
        data = (analysis / name).read_bytes()
        assert len(data) > 2000, name
        if name.endswith(".png"):
            assert data.startswith(PNG_MAGIC), name


def test_a_run_too_short_says_what_it_could_not_compute(flume_run):
    _, analysis = flume_run
    page = (analysis / "report.html").read_text()
    # 0.01 s of waves: no gauge has a record after the wave train's arrival
    assert "not computed: record too short" in page
    assert re.search(r"Hm0 \(m\)</th>.*not computed", page, re.S)
    assert "Hudson" in page and "stability number Ns = Hm0 / (Delta Dn)" in page
    # Van der Meer is for rock and cubes: a Core-Loc-like layer says why it has none
    assert "for rock and cubes only; this layer is of core_loc_like units" in page


def test_a_run_in_water_records_contacts_and_fluid_forces(flume_run):
    run, analysis = flume_run
    assert (run / "contacts.pvd").read_text().count("<DataSet") == \
        (run / "bodies.pvd").read_text().count("<DataSet")
    frame = sorted(run.glob("bodies_*.vtu"))[-1].read_bytes()
    for field in (b"coordination_number", b"max_contact_force", b"factor_of_safety_sliding"):
        assert field in frame, field
    summary = json.loads((analysis / "layer_summary.json").read_text())
    assert summary.get("contacts_recorded", True) is True
    assert summary["coordination_number_mean"] > 1.0      # units rest on rocks and each other
    header = (analysis / "units.csv").read_text().splitlines()
    columns = header[0].split(",")
    for column in ("max_fluid_force_N", "max_fluid_force_time_s",
                   "max_fluid_force_over_submerged_weight", "coordination_number",
                   "factor_of_safety"):
        assert column in columns, column
    rows = [dict(zip(columns, line.split(","))) for line in header[1:]]
    assert len(rows) == 25
    forces = [float(r["max_fluid_force_N"]) for r in rows]
    assert all(math.isfinite(f) and f >= 0.0 for f in forces)
    # a unit in still water carries about its buoyancy, a fraction of its submerged weight
    ratios = [float(r["max_fluid_force_over_submerged_weight"]) for r in rows]
    assert max(ratios) < 5.0
    assert all(0.0 <= float(r["max_fluid_force_time_s"]) <= 0.0101 for r in rows)


def test_body_force_rows_carry_the_peak_since_the_last_row(flume_run):
    from riprap.io.body_forces import BODY_FORCE_COLUMNS

    run, _ = flume_run
    lines = (run / "body_forces.csv").read_text().splitlines()
    assert lines[0].split(",") == list(BODY_FORCE_COLUMNS)
    for line in lines[1:]:
        values = dict(zip(BODY_FORCE_COLUMNS, map(float, line.split(","))))
        now = math.dist((0, 0, 0), [values[f"pressure_force_{a}_N"] + values[f"viscous_force_{a}_N"]
                                    for a in "xyz"])
        assert values["peak_fluid_force_N"] >= now * (1 - 1e-12)
        assert values["peak_fluid_force_time_s"] <= values["time_s"]


# ------------------------------------------------------------------ broken files analyse reads
def _broken_copy(flume_run, tmp_path, name, edit):
    run, _ = flume_run
    copy = tmp_path / "run"
    shutil.copytree(run, copy, ignore=shutil.ignore_patterns("analysis", "fluid_*.vti",
                                                             "free_surface"))
    path = copy / name
    path.write_text(edit(path.read_text()))
    return copy


def _without_column(text: str, name: str) -> str:
    rows = [line.split(",") for line in text.splitlines()]
    keep = [k for k, column in enumerate(rows[0]) if column != name]
    assert len(keep) < len(rows[0]), name
    return "\n".join(",".join(row[k] for k in keep) for row in rows) + "\n"


@pytest.mark.parametrize("name, edit, expected", [
    ("body_forces.csv", lambda text: text.replace("\n1,", "\n1,zero,", 1), "line 3"),
    ("body_forces.csv", lambda text: "time,body\n" + text.split("\n", 1)[1], "line 1"),
    ("body_forces.csv", lambda text: text.replace("\n3,", "\n999,", 1), "body 999"),
    ("gauges.csv", lambda text: text + "0.5,abc\n", "fields, the header has"),
    ("gauges.csv", lambda text: "t," + text.split(",", 1)[1], "gauges.csv:1"),
    # a gauge's column lost (issue 52): refused naming it, not a KeyError in the per-wave table
    ("gauges.csv", lambda text: _without_column(text, "g2_eta_m"), "no column 'g2_eta_m'"),
])
def test_a_broken_file_of_the_run_is_refused_naming_it(flume_run, tmp_path, capsys, name, edit,
                                                       expected):
    copy = _broken_copy(flume_run, tmp_path, name, edit)
    out = tmp_path / "analysis"
    capsys.readouterr()
    assert main(["analyse", str(copy), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("riprap: error:"), err
    assert name in lines[0] and expected in lines[0], lines[0]
    assert "Traceback" not in err
    assert not (out / "report.html").exists() and not (out / "units.csv").exists()


def test_a_restart_onto_an_older_body_forces_file_is_refused_before_it_runs(
        flume_run, tmp_path, capsys, monkeypatch):
    from riprap.io.body_forces import BODY_FORCE_COLUMNS

    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    older = ",".join(BODY_FORCE_COLUMNS[:-2])
    def older_file(text):
        rows = [",".join(line.split(",")[:-2]) for line in text.splitlines()[1:]]
        return "\n".join([older] + rows) + "\n"

    copy = _broken_copy(flume_run, tmp_path, "body_forces.csv", older_file)
    before = (copy / "body_forces.csv").read_text()
    capsys.readouterr()
    assert main(["run", str(EXAMPLES / "10_breakwater_test" / "case.toml"), "--out", str(copy),
                 "--quiet", "--restart", str(copy / "checkpoint.npz")]) == 2
    err = capsys.readouterr().err
    # smoke mode and the short flume run's warning say so on stderr too; the refusal is the one
    # error line
    lines = [line for line in err.splitlines() if line.startswith("riprap: error:")]
    assert len(lines) == 1 and lines[0].startswith("riprap: error:"), err
    assert "body_forces.csv: its columns" in lines[0], err
    assert "Traceback" not in err
    assert (copy / "body_forces.csv").read_text() == before


def test_a_restart_refuses_a_body_forces_file_of_other_columns(tmp_path):
    from riprap.io.body_forces import BodyForceTable

    old = tmp_path / "body_forces.csv"
    old.write_text("body,time_s,x_m\n0,0.0,1.0\n")
    with pytest.raises(CaseFileError, match="body_forces.csv: its columns"):
        BodyForceTable(old, append=True)
    assert old.read_text() == "body,time_s,x_m\n0,0.0,1.0\n"


# ------------------------------------------------------------------ the pieces, on their own
def test_the_largest_fluid_force_of_each_body_and_when(tmp_path):
    from riprap.io.body_forces import BODY_FORCE_COLUMNS, read_peak_fluid_forces

    def row(body, time, pressure_z, peak, peak_time):
        values = [body, time, 0, 0, 0, 0, 0, 0, 0, 0, pressure_z, 0, 0, 0, 0, 0, 0, peak, peak_time]
        return ",".join(map(str, values))

    path = tmp_path / "body_forces.csv"
    path.write_text("\n".join([",".join(BODY_FORCE_COLUMNS), row(0, 0.0, 10.0, 10.0, 0.0),
                               row(1, 0.0, 5.0, 5.0, 0.0), row(0, 1.0, 12.0, 40.0, 0.7),
                               row(1, 1.0, 6.0, 6.0, 1.0), row(0, 2.0, 11.0, 30.0, 1.5)]) + "\n")
    peaks = read_peak_fluid_forces(path, 3)
    assert peaks["force_N"][:2].tolist() == [40.0, 6.0] and math.isnan(peaks["force_N"][2])
    assert peaks["time_s"][:2].tolist() == [0.7, 1.0]
    early = read_peak_fluid_forces(path, 3, until=0.5)
    assert early["force_N"][:2].tolist() == [10.0, 5.0]
    # a file of an older riprap (no peak columns): the largest force at its rows
    older = tmp_path / "older.csv"
    older.write_text("\n".join([",".join(BODY_FORCE_COLUMNS[:-2])]
                               + [",".join(r.split(",")[:-2]) for r in
                                  path.read_text().splitlines()[1:]]) + "\n")
    assert read_peak_fluid_forces(older, 3)["force_N"][0] == 12.0


def test_fluid_force_over_the_submerged_weight():
    from riprap.analysis.flume_test import fluid_force_columns

    peaks = {"force_N": np.array([0.0, 1650.0 * 9.81, 5.0]), "time_s": np.array([0.0, 2.5, 1.0])}
    columns = fluid_force_columns(peaks, [1, 2], volumes=[1.0, 1.0],
                                  armour_densities=[2650.0, 1000.0], water_density=1000.0,
                                  gravity=9.81)
    assert columns["max_fluid_force_over_submerged_weight"][0] == pytest.approx(1.0)
    assert math.isnan(columns["max_fluid_force_over_submerged_weight"][1])   # neutrally buoyant
    assert columns["max_fluid_force_time_s"].tolist() == [2.5, 1.0]


def test_displacements_are_coloured_from_0_to_1_dn_whatever_the_largest():
    from riprap.io.analysis_figures import colour_scale

    _, low, high = colour_scale("displacement_over_dn", [0.0, 0.0006])
    assert (low, high) == (0.0, 1.0)
    _, low, high = colour_scale("displacement_over_dn", [0.2, 3.0])
    assert (low, high) == (0.0, 1.0)


def _analysis(coordination, forces, safety, displacement):
    units = {"coordination_number": np.array(coordination, dtype=float),
             "factor_of_safety": np.array(safety, dtype=float),
             "displacement_over_dn": np.array(displacement, dtype=float)}
    return SimpleNamespace(units=units, unit_unit_forces=np.array(forces, dtype=float),
                           unit_underlayer_forces=np.array(forces, dtype=float))


def test_no_histogram_panel_is_drawn_empty(tmp_path):
    from riprap.io.analysis_figures import histogram_figure, histogram_panels

    nan = [np.nan, np.nan]
    no_contacts = _analysis(nan, [], nan, [0.1, 0.4])
    assert len(histogram_panels([no_contacts])) == 1          # displacements only
    pack = _analysis([3, 4], [10.0, 20.0], [1.5, 2.0], nan)
    assert len(histogram_panels([pack])) == 3                 # no displacements in a pack
    assert histogram_figure(tmp_path / "none.png", _analysis(nan, [], nan, nan)) == []
    assert not (tmp_path / "none.png").exists()
    written = histogram_figure(tmp_path / "some.png", no_contacts)
    assert written and written[0].read_bytes().startswith(PNG_MAGIC)


def test_a_missing_value_of_the_waves_report_says_not_computed_and_why():
    from riprap.io.flume_report import value_or_reason

    assert value_or_reason({"Hm0_m": 1.234}, "Hm0_m", "{:.2f}") == "1.23"
    for entry, reason in (({"Hm0_m": None, "Hm0_m_reason": "record of 3 s"}, "record of 3 s"),
                          ({"note": "record too short after the wave train's arrival"},
                           "record too short after the wave train&#x27;s arrival"),
                          ({"Hm0_m": "1.2", "reason": "a string"}, "a string"),
                          ({"Hm0_m": float("nan"), "not_computed": {"Hm0_m": "one wave"}},
                           "one wave"),
                          ({}, "not in waves_report.json"),
                          ("a list where a table belongs", "not in waves_report.json")):
        text = value_or_reason(entry, "Hm0_m")
        assert text.startswith("<span class='missing'>not computed: ") and reason in text, text


def test_the_waves_section_reads_a_report_with_holes():
    from riprap.analysis.flume_test import FlumeRecords, with_derived
    from riprap.io.flume_report import waves_section

    report = {"gauges": {"g1": {"x_m": -5.0, "analysed_from_s": 17.0, "Hm0_m": None,
                                "Hm0_m_reason": "run shorter than the analysis window"},
                         "g2": "not a table"},
              "reflection": [], "run_up": {"face": {"x_m": -0.4, "R2%_m": 1.03, "R_max_m": None}},
              "overtopping": None}
    records = FlumeRecords(waves_report=report, times=np.linspace(0.0, 1.0, 11),
                           columns={"g1_eta_m": np.zeros(11)},
                           target={"type": "irregular", "height_m": 1.2, "period_s": 4.0,
                                   "peak_enhancement": 3.3})
    page = waves_section(SimpleNamespace(flume=with_derived(records, units={})))
    assert "not computed: run shorter than the analysis window" in page
    assert "1.030" in page                                     # R2% shown
    assert "not computed: no pair of neighbouring surface gauges" in page
    assert "not computed: the run has no overtopping gauge" in page
    assert "g1: spectrum not computed: record too short" in page


def test_the_steps_before_a_frame_are_equal_not_a_sliver():
    """A coupled body's force over a step grows as 1/dt (docs/coupling.md, Peak forces): the run
    loop no longer cuts the last step before a frame to a sliver."""
    from riprap.models.fluid import step_towards

    stable = 5.4e-3
    remaining = 3.06 * stable           # was: three full steps and a sliver of 0.06 of one
    steps = []
    while remaining > 0:
        dt = step_towards(stable, remaining)
        steps.append(dt)
        remaining -= dt
        assert len(steps) < 10
    assert len(steps) == 4 and max(steps) <= stable
    assert min(steps) == pytest.approx(max(steps), rel=1e-9)     # no sliver: 4 equal steps
    assert step_towards(stable, 1e-4) == 1e-4                       # the last bit as it is
    assert step_towards(0.0, 1.0) == 0.0 and step_towards(float("inf"), 1.0) == 1.0


def test_a_gauge_record_of_the_target_sea_gives_the_target_spectrum(tmp_path):
    """A record made of the case's own JONSWAP sea: its measured spectrum, over the analysis
    window only, has the target's Hm0 and peak; what lies before the window is left out."""
    from riprap.analysis.flume_test import FlumeRecords, gauge_spectra, target_spectrum
    from riprap.io.flume_figures import spectra_figure
    from riprap.waves.theory import IrregularWave

    sea = IrregularWave(significant_height=1.2, peak_period=4.0, depth=2.0, duration=400.0, seed=3)
    times = np.arange(0.0, 420.0, 0.05)
    eta = np.array([sea.elevation(0.0, t) for t in times])
    eta[times < 20.0] = 5.0                     # before the window: nothing to do with the sea
    target = {"type": "irregular", "height_m": 1.2, "period_s": 4.0, "peak_enhancement": 3.3}
    records = FlumeRecords(waves_report={"gauges": {"g1": {"analysed_from_s": 20.0}}},
                           times=times, columns={"g1_eta_m": eta}, target=target)
    (spectrum,) = gauge_spectra(records)
    frequencies, density = spectrum["frequencies_Hz"], spectrum["density_m2_s"]
    m0 = float(np.sum(density) * (frequencies[1] - frequencies[0]))
    assert 4.0 * math.sqrt(m0) == pytest.approx(1.2, rel=0.05)
    assert frequencies[np.argmax(density)] == pytest.approx(0.25, abs=0.03)
    grid = np.linspace(0.0, 0.75, 600)
    path = spectra_figure(tmp_path / "spectra.png", [spectrum], target,
                          (grid, target_spectrum(target, grid)))
    assert path.read_bytes().startswith(PNG_MAGIC)


def test_the_units_contacts_are_read_frame_by_frame(tmp_path):
    from riprap.io.frame_contacts import read_unit_contacts_per_frame
    from riprap.io.vtk import ParaViewSeries

    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    triangles = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    owners = np.array([0, 0, 1, 2])                  # three bodies, the first with two faces
    with_fields = ParaViewSeries(tmp_path / "new", "bodies")
    for time, scale in ((0.0, 1.0), (1.0, 2.0)):
        with_fields.add(time, points=points, cells=triangles, cell_type="triangle", cell_data={
            "body_id": owners, "coordination_number": scale * np.array([3, 3, 4, 5]),
            "max_contact_force": scale * np.array([10.0, 10.0, 20.0, 30.0]),
            "factor_of_safety_sliding": np.array([1.5, 1.5, 1e30, 2.0])})
    contacts = read_unit_contacts_per_frame(tmp_path / "new", [2, 0])
    assert contacts["time_s"].tolist() == [0.0, 1.0]
    assert contacts["coordination_number"].tolist() == [[5, 3], [10, 6]]
    assert contacts["max_contact_force"][1].tolist() == [60.0, 20.0]
    assert read_unit_contacts_per_frame(tmp_path / "new", [2, 0], until=0.5)["time_s"].size == 1
    older = ParaViewSeries(tmp_path / "old", "bodies")     # a coupled run before issue 35
    older.add(0.0, points=points, cells=triangles, cell_type="triangle",
              cell_data={"body_id": owners})
    assert read_unit_contacts_per_frame(tmp_path / "old", [0]) is None


def test_the_stability_report_passes_over_values_left_null():
    """A waves report of a run too short (values null, or H3's reason fields beside them) gives no
    stability number rather than an error; a pair that was computed is used beside one that was
    not."""
    from riprap.analysis.stability_report import flume_stability

    def stability(report):
        return flume_stability(report, {"units_displaced": []}, unit_kind="core_loc_like",
                               nominal_diameter=0.563, armour_density=2400.0,
                               water_density=1000.0, slope_cot=1.33)

    empty = stability({"gauges": {"g1": {"Hm0_m": None, "Hm0_m_reason": "too short"}},
                       "reflection": [{"incident_Hm0_m": None}], "reflection_three_gauge": None})
    assert "stability_number" not in empty and "no stability number" in empty["note"]
    mixed = stability({"gauges": {"g1": {"Hm0_m": 1.1, "Tz_s": None, "waves": 12}},
                       "reflection": [{"incident_Hm0_m": None}, {"incident_Hm0_m": 0.98}]})
    assert mixed["Hm0_m"] == 0.98 and mixed["Tz_s"] is None and mixed["waves"] == 12
    assert mixed["stability_number"] == pytest.approx(0.98 / (1.4 * 0.563))


def test_the_stability_section_of_rock_armour_gives_s_its_class_and_the_formulas():
    """Rock armour (issue 55): the survey report's stability table shows S with its Rock Manual
    class, P and the core, each formula's S with its cautions, the band and where it eroded."""
    from riprap.analysis.rock_stability import RockSection, eroded_zone, rock_stability
    from riprap.io.flume_report import stability_section

    section = RockSection(filter_dn50=0.013, core_dn50=0.0084, core_note="the case's core")
    rock = rock_stability(hs=0.06, spectral_period=1.3, waves=40, slope_cot=2.0,
                          armour_density=2650.0, water_density=1000.0, nominal_diameter=0.03,
                          damage=2.6, section=section)
    x = [0.0, 0.01, 0.02, 0.03]
    rock["eroded_zone"] = eroded_zone({"x_m": x, "before_z_m": [0.0, 0.1, 0.2, 0.3],
                                       "after_z_m": [0.0, 0.09, 0.2, 0.3]},
                                      nominal_diameter=0.03, still_water_level=0.15)
    layer = {"flume_test": {"Hm0_m": 0.06, "Tz_s": 1.1, "waves": 40, "relative_density": 1.65,
                            "nominal_diameter_m": 0.03, "stability_number": 1.21,
                            "slope_cot": 2.0, "unit": "armour_stone", "rock": rock},
             "units_displaced": [], "units": 90, "damage_number_nod": 0.0,
             "eroded_area_m2": 0.0023, "damage_level_s": 2.6}
    analysis = SimpleNamespace(layer=layer, units={}, flume=SimpleNamespace(rocking=None))
    page = html.unescape(stability_section(analysis))
    assert "2.60: start of damage (start 2, intermediate 4-6, failure 8 on this slope)" in page
    assert "notional permeability P (Van der Meer 1988)" in page and "0.4: armour on a filter" in page
    for name in ("Van der Meer (2021)", "Van Gent et al. (2003)", "Etemad-Shahidi et al. (2020)"):
        assert f"{name}: S predicted for these waves" in page
    assert "N = 40 is below Etemad-Shahidi et al. (2020)'s tested range 500-5000" in page
    assert "the formulas' band" in page and "measured S is" in page
    assert "deepest 0.33 D_n50 at x 0.010 m, 1.67 D_n50 below still water" in page
    assert "Van der Meer</th>" not in page      # no "not computed" row for rock
