"""Record the smoke-mode reference that `test_smoke_reference.py` compares against.

Run from the repository root, only when a change is *meant* to alter results:

    python tests/regression/make_reference.py

For every example case (examples/*/*.toml) it runs `riprap run` in smoke mode (RIPRAP_SMOKE=1) and
records the sorted list of files the run writes; for examples 01, 02, 03 and 07 it also records
every number in summary.json except those that measure the machine (wall time, speed) or name
paths. Written to tests/regression/smoke_reference.json with the riprap commit it came from.
"""
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

# OpenBLAS's kernels pinned as tests/conftest.py pins them for the suite (the reference is then
# the same on every x86-64 machine)
if platform.machine().lower() in ("x86_64", "amd64"):
    os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = Path(__file__).with_name("smoke_reference.json")
#: Examples whose summary numbers must stay identical through a restructuring (issue 36).
NUMBERS_OF = ("01_rock_drop", "02_dam_break", "03_settling_sphere", "07_unit_impact")
#: summary.json keys that measure the machine or name local paths, not the physics.
NOT_COMPARED = {"wall_time", "body_steps_per_second", "outputs", "case_file", "cells_per_second",
                "fluid_cell_steps_per_second", "tet_steps_per_second"}


def case_id(case: Path) -> str:
    return f"{case.parent.name}/{case.stem}"


def files_written(folder: Path) -> list:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def comparable(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in NOT_COMPARED and "per_second" not in k
            and "time_share" not in k}


def run_smoke(case: Path, out: Path) -> None:
    env = dict(os.environ, RIPRAP_SMOKE="1")
    subprocess.run([sys.executable, "-m", "riprap", "run", str(case), "--out", str(out),
                    "--quiet"], check=True, env=env, cwd=ROOT)


def main() -> None:
    cases = sorted((ROOT / "examples").glob("*/*.toml"))
    reference = {"commit": subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                          capture_output=True, text=True).stdout.strip(),
                 "files": {}, "summaries": {}}
    with tempfile.TemporaryDirectory() as scratch:
        for case in cases:
            out = Path(scratch) / case.parent.name / case.stem
            run_smoke(case, out)
            reference["files"][case_id(case)] = files_written(out)
            if case.parent.name in NUMBERS_OF and case.stem == "case":
                summary = json.loads((out / "summary.json").read_text())
                reference["summaries"][case.parent.name] = comparable(summary)
            print("recorded", case_id(case), flush=True)
    REFERENCE.write_text(json.dumps(reference, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
