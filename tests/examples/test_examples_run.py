"""Every example and the embedded demo run in smoke mode (RIPRAP_SMOKE=1: 0.01 s of simulated time)
and write their outputs; a meta-test fails when an example folder is not covered."""
import json
from pathlib import Path

import pytest

from riprap.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SMOKE_REFERENCE = json.loads((EXAMPLES.parent / "tests" / "regression"
                              / "smoke_reference.json").read_text())
# every folder's case.toml, and the variants beside it (e.g. 04's deformable sphere)
# hidden files are other tools' passing copies (a shortened case beside its example's files)
CASES = sorted(case for case in EXAMPLES.glob("*/*.toml") if not case.name.startswith("."))


@pytest.fixture(autouse=True)
def smoke(monkeypatch):
    monkeypatch.setenv("RIPRAP_SMOKE", "1")


def _check_outputs(out: Path, bodies: int):
    summary = json.loads((out / "summary.json").read_text())
    assert summary["bodies"] == bodies
    assert summary["steps"] > 0
    assert summary["simulated_time"] == pytest.approx(0.01, rel=0.05)
    assert (out / "bodies.pvd").read_text().count("<DataSet") >= 2
    assert (out / "final_state.png").stat().st_size > 10_000
    assert (out / "checkpoint.npz").exists()


def test_demo_runs(tmp_path):
    assert main(["demo", "--out", str(tmp_path / "demo"), "--quiet"]) == 0
    _check_outputs(tmp_path / "demo", bodies=32)


@pytest.mark.parametrize("case", CASES, ids=[f"{c.parent.name}/{c.stem}" for c in CASES])
def test_example_runs(case, tmp_path):
    assert main(["run", str(case), "--out", str(tmp_path / case.parent.name / case.stem),
                 "--quiet"]) == 0
    text = case.read_text()
    assert "riprap run examples/" in text, "each example says how to run it"
    # the same files as recorded before issue 36's restructuring (tests/regression)
    out = tmp_path / case.parent.name / case.stem
    written = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert written == SMOKE_REFERENCE["files"][f"{case.parent.name}/{case.stem}"]


def test_no_missing_examples():
    folders = sorted(p for p in EXAMPLES.iterdir() if p.is_dir())
    assert folders, "examples/ must not be empty"
    for folder in folders:
        assert (folder / "case.toml").exists(), f"{folder.name} has no case.toml, so no test runs it"
        assert (folder / "README.md").exists(), f"{folder.name} has no README.md"


def test_check_command_reports_errors(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("format_version = 1\n[simulation]\nend_tme = 1.0\n")
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml:3" in err and "end_tme" in err


PLACEMENT_KEYS = ("units_placed", "units_at_rest", "packing_density_coefficient",
                  "design_packing_density_coefficient", "porosity", "layer_thickness_m",
                  "max_overlap_over_dn")


def test_small_placement_example_runs(tmp_path):
    """`riprap place` on examples/coreloc_small.toml (smoke mode: 0.01 s per deposition run)
    writes the pack, the deposition series, the picture and the summary keys the issue names."""
    case = EXAMPLES / "coreloc_small.toml"
    assert "riprap place examples/coreloc_small.toml" in case.read_text()
    out = tmp_path / "coreloc_small"
    assert main(["place", str(case), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for key in PLACEMENT_KEYS:
        assert key in summary, key
    assert summary["units_placed"] == 25
    assert (out / "pack.toml").is_file() and (out / "deposition" / "bodies.pvd").is_file()
    assert main(["check", str(out / "pack.toml")]) == 0
    # The README's analysis command on the (smoke) pack: the files.
    assert main(["analyse", str(out), "--out", str(out / "analysis")]) == 0
    for name in ("report.html", "stereonet.png", "units.csv"):
        assert (out / "analysis" / name).is_file(), name
    header = (out / "analysis" / "units.csv").read_text().splitlines()[0].split(",")
    for column in ("unit_id", "coordination_number", "max_contact_force_N", "factor_of_safety"):
        assert column in header
