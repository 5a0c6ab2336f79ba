"""What a test series' folder records and what a later run does with it (issue 52, items 1 and 4;
``riprap.workflows.series_record``), on the smoke-size series of ``test_series.py``:

- a full run over a smoke series sets the smoke steps aside (``smoke_run/``) and runs them again:
  no smoke step is in the full series' results, and the folder's other files stay; a smoke run
  over the full series is refused and changes nothing; the mode is in ``series.json``, its
  fingerprint, ``series_results.json`` and the report;
- a changed survey key (``[series] displacement_threshold``) surveys the finished steps again
  without running them: every file of the steps outside ``survey/`` is the same, bit for bit;
- a changed run key refuses the folder, naming the key with its old and new values;
- a campaign grows: ``--seeds 0 1 2`` after ``0 1`` runs only seed 2; dropping a member, a smoke
  campaign over a full one and a damaged record are refused, nothing written.

The "full" runs here are cut to the smoke length by the fluid case builder (patched), so that the
test takes seconds; the records, summaries and reports they write are a full run's (the process
has no RIPRAP_SMOKE).
"""
import hashlib
import json
import os
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from riprap import cli
from riprap.case.load import load_case
from riprap.errors import CaseFileError, RiprapError
from riprap.workflows.campaign import CAMPAIGN_RECORD, members_of, run_campaign
from riprap.workflows.series import check_series, run_series
from riprap.workflows.series_record import SMOKE_FOLDER, series_fingerprint

from test_series import STEPS, _write_series_case

ONE_STEP = STEPS[:STEPS.index("[[series_steps]]", 10)]


def _files(folder: Path, skip: str = "") -> dict:
    """Every file under ``folder`` (not under a folder named ``skip``) and its SHA-256."""
    return {str(path.relative_to(folder)): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(folder.rglob("*"))
            if path.is_file() and not (skip and skip in path.relative_to(folder).parts)}


def _smoke_run(case: Path, out: Path, lines: list | None = None) -> dict:
    previous = os.environ.get("RIPRAP_SMOKE")
    os.environ["RIPRAP_SMOKE"] = "1"
    try:
        return run_series(load_case(case), output_directory=out, progress=False,
                          say=(lines if lines is not None else []).append)
    finally:
        if previous is None:
            os.environ.pop("RIPRAP_SMOKE")
        else:
            os.environ["RIPRAP_SMOKE"] = previous


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    """The two-step series run in smoke mode, kept as it was made (tests copy it)."""
    root = tmp_path_factory.mktemp("records")
    case = _write_series_case(root)
    results = _smoke_run(case, root / "smoke")
    return root, case, results


@pytest.fixture
def cut_short(monkeypatch):
    """A full run (no RIPRAP_SMOKE) whose steps the fluid builder cuts to 0.01 s."""
    import riprap.case.build as build
    import riprap.case.build_fluid as build_fluid

    monkeypatch.delenv("RIPRAP_SMOKE", raising=False)
    for module in (build, build_fluid):
        monkeypatch.setattr(module, "smoke_mode", lambda: True)


def test_a_smoke_series_says_so_in_its_record_and_reports(smoke):
    root, _, results = smoke
    record = json.loads((root / "smoke" / "series.json").read_text())
    assert record["run_mode"] == "smoke" and record["smoke_end_time_s"] == 0.01
    assert results["run_mode"] == "smoke" and "no results" in results["run_mode_note"]
    written = json.loads((root / "smoke" / "series_results.json").read_text())
    assert written["run_mode"] == "smoke"
    report = (root / "smoke" / "report.html").read_text()
    assert "SMOKE RUN" in report and "<title>riprap test series (SMOKE RUN)</title>" in report
    # the fingerprint differs by mode: a smoke series is never taken for the full one
    case = load_case(root / "series.toml")
    assert series_fingerprint(case, "smoke") != series_fingerprint(case, "full")
    assert record["fingerprint"] == series_fingerprint(case, "smoke")


def test_a_full_run_runs_the_smoke_steps_again_and_a_smoke_run_leaves_it(smoke, tmp_path,
                                                                        cut_short):
    root, case, _ = smoke
    out = tmp_path / "series"
    shutil.copytree(root / "smoke", out)
    (out / "notes.txt").write_text("the engineer's own notes")
    smoke_files = _files(out)
    lines = []
    results = run_series(load_case(case), output_directory=out, progress=False,
                         say=lines.append)
    assert any("the smoke steps step_01, step_02" in line and SMOKE_FOLDER in line
               for line in lines), lines
    assert not any("done before" in line for line in lines), lines
    # every step ran again, in full: no smoke summary among the series' steps
    for number in (1, 2):
        summary = json.loads((out / f"step_{number:02d}" / "summary.json").read_text())
        assert summary["smoke"] is False
    assert results["run_mode"] == "full" and "run_mode_note" not in results
    assert json.loads((out / "series.json").read_text())["run_mode"] == "full"
    assert "SMOKE" not in (out / "report.html").read_text()
    # the smoke steps are kept aside as they were, the other file where it was
    assert _files(out / SMOKE_FOLDER) == {
        name: digest for name, digest in smoke_files.items()
        if name.split("/")[0] not in ("series.json", "notes.txt")}
    assert (out / "notes.txt").read_text() == "the engineer's own notes"

    # a smoke run over the full series is refused, by riprap check too, and changes nothing
    full_files = _files(out)
    os.environ["RIPRAP_SMOKE"] = "1"
    try:
        with pytest.raises(RiprapError, match=r"run in full \(steps step_01, step_02\).*"
                                              r"another --out folder"):
            run_series(load_case(case), output_directory=out, progress=False, say=print)
        with pytest.raises(RiprapError, match="run in full"):
            check_series(load_case(case), out)
    finally:
        os.environ.pop("RIPRAP_SMOKE")
    assert _files(out) == full_files

    # a run key changed: refused, naming the key with its old and new values
    text = case.read_text()
    changed = tmp_path / "series.toml"
    shutil.copytree(case.parent / "pack", tmp_path / "pack")
    changed.write_text(text.replace("settle_time = 1.0", "settle_time = 1.5")
                       .replace("significant_height = 0.12", "significant_height = 0.13"))
    with pytest.raises(RiprapError) as refusal:
        run_series(load_case(changed), output_directory=out, progress=False, say=print)
    message = str(refusal.value)
    assert "[series] settle_time: 1 -> 1.5" in message
    assert "[[series_steps]] 2 significant_height: 0.12 -> 0.13" in message
    assert "give another --out folder, or restore those values" in message
    assert _files(out) == full_files


def test_a_changed_survey_key_surveys_again_without_running_a_step(smoke, tmp_path):
    root, case, _ = smoke
    out = tmp_path / "series"
    shutil.copytree(root / "smoke", out)
    steps_before = {number: _files(out / f"step_{number:02d}", skip="survey")
                    for number in (1, 2)}
    changed = tmp_path / "series.toml"
    shutil.copytree(case.parent / "pack", tmp_path / "pack")
    changed.write_text(case.read_text().replace("settle_time = 1.0",
                                                "settle_time = 1.0\ndisplacement_threshold = 0.5"))
    lines = []
    results = _smoke_run(changed, out, lines)
    assert any("[series] displacement_threshold: 1 -> 0.5: only the surveys change" in line
               for line in lines), lines
    assert sum("done before, not run again" in line for line in lines) == 2
    assert sum(": surveyed again, [series] displacement_threshold 1 -> 0.5" in line
               for line in lines) == 2
    for number in (1, 2):
        assert _files(out / f"step_{number:02d}", skip="survey") == steps_before[number]
        survey = json.loads((out / f"step_{number:02d}" / "survey" /
                             "layer_summary.json").read_text())
        assert survey["damage_threshold_over_dn"] == 0.5
    assert results["displacement_threshold_over_dn"] == 0.5
    record = json.loads((out / "series.json").read_text())
    assert record["survey"] == {"series.displacement_threshold": 0.5}
    # a third run changes nothing
    lines.clear()
    _smoke_run(changed, out, lines)
    assert not any("surveyed again" in line for line in lines)


@pytest.mark.parametrize("edit, message", [
    (lambda r: r.update(run_mode="fast"), r'run_mode = "fast" is not one riprap writes'),
    (lambda r: r.update(seed_offset=3), r"seed offset: 3 -> 0"),
    (lambda r: r["case"]["waves"].update(ramp_periods=2.0),
     r"\[waves\] ramp_periods: 2 -> 1"),
    (lambda r: r["case"]["simulation"].pop("checkpoint_interval"),
     r"\[simulation\] checkpoint_interval: not given -> 1"),
])
def test_a_damaged_or_other_record_is_refused_naming_what_differs(smoke, tmp_path, edit,
                                                                  message, cut_short):
    root, case, _ = smoke
    out = tmp_path / "series"
    shutil.copytree(root / "smoke", out)
    record = json.loads((out / "series.json").read_text())
    record["run_mode"] = "full"
    edit(record)
    for number in (1, 2):         # made a full series' steps, as far as the record goes
        path = out / f"step_{number:02d}" / "summary.json"
        path.write_text(json.dumps(dict(json.loads(path.read_text()), smoke=False)))
    (out / "series.json").write_text(json.dumps(record))
    before = _files(out)
    with pytest.raises(RiprapError, match=message):
        run_series(load_case(case), output_directory=out, progress=False, say=print)
    assert _files(out) == before


class _Here:
    """A Dask client stand-in that runs each member in this process when it is submitted."""

    scheduler = SimpleNamespace(address="this process")

    def submit(self, function, *args, key, pure):
        try:
            value, error = function(*args), None
        except Exception as raised:  # noqa: BLE001 - given back by result(), as Dask does
            value, error = None, raised
        return SimpleNamespace(done=lambda: True,
                               result=lambda: value if error is None else (_ for _ in ()).throw(
                                   error))


def test_a_campaign_grows_by_the_seeds_added_and_refuses_to_shrink(tmp_path, monkeypatch,
                                                                   capsys):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    case = _write_series_case(tmp_path, ONE_STEP)
    out = tmp_path / "campaign"
    first = run_campaign(members_of([case], [0, 1]), out, client=_Here(), say=print)
    assert first["run_mode"] == "smoke" and sorted(first["members"]) == ["series_seed0",
                                                                         "series_seed1"]
    record = json.loads((out / CAMPAIGN_RECORD).read_text())
    assert record["run_mode"] == "smoke"
    before = {name: _files(out / name, skip="survey") for name in ("series_seed0",
                                                                   "series_seed1")}
    grown = run_campaign(members_of([case], [0, 1, 2]), out, client=_Here(), say=print)
    said = capsys.readouterr().out
    assert "riprap: campaign of 3 members" in said and "members added: series_seed2" in said
    logs = {name: "\n".join(member["log"]) for name, member in grown["members"].items()}
    for name in ("series_seed0", "series_seed1"):
        assert "series step 1/1: done before, not run again" in logs[name]
        assert "series step 1/1: Hm0" not in logs[name]
    assert "series step 1/1: Hm0" in logs["series_seed2"]          # only seed 2's step ran
    for name, files in before.items():
        # (the member's series.log tells of the second start: it alone grew)
        assert ({k: v for k, v in _files(out / name, skip="survey").items() if k != "series.log"}
                == {k: v for k, v in files.items() if k != "series.log"})
    assert (out / "series_seed2" / "step_01" / "summary.json").is_file()
    assert grown["spread"]["series"]["members"] == [3]
    results = json.loads((out / "campaign_results.json").read_text())
    assert results["run_mode"] == "smoke" and len(results["members"]) == 3

    # dropping a member, a smoke campaign over a full one, a damaged record: refused, nothing
    # written and no worker asked
    everything = _files(out)
    with pytest.raises(RiprapError, match="holds the members series_seed2, not given now"):
        run_campaign(members_of([case], [0, 1]), out, client=object())
    kept = (out / CAMPAIGN_RECORD).read_bytes()
    record = json.loads(kept)
    for run_mode, message in (("full", "a campaign run in full"),
                              ("quick", "run_mode = 'quick' is not one riprap writes")):
        (out / CAMPAIGN_RECORD).write_text(json.dumps(dict(record, run_mode=run_mode)))
        with pytest.raises(RiprapError, match=message):
            run_campaign(members_of([case], [0, 1, 2]), out, client=object())
    (out / CAMPAIGN_RECORD).write_bytes(kept)
    assert _files(out) == everything
    with pytest.raises(CaseFileError, match="seeds must be >= 0"):
        members_of([case], [0, -1])


def test_riprap_campaign_prints_the_smoke_banner(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")
    case = _write_series_case(tmp_path, ONE_STEP)
    # (with or without Dask installed: the banner comes before the members start; a bad seed is
    # then refused before anything is written)
    assert cli.main(["campaign", str(case), "--seeds", "0", "-2", "--out",
                     str(tmp_path / "c")]) == 2
    printed = capsys.readouterr()
    assert "SMOKE MODE (RIPRAP_SMOKE=1)" in printed.err
    assert "seeds must be >= 0" in printed.err
    assert not (tmp_path / "c").exists()
