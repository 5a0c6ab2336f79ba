"""What hostile inputs found in issue 52 (item 7) besides the time step: an end time of 1e308 is
blamed on end_time (not on output_interval's frame count), a killed run's temporary checkpoint
file is cleared when the run restarts, and a placement whose layer figures could not be measured
prints "not measured" and why, never "nan" (summary.json has null)."""
import os
import subprocess
import sys

import numpy as np
import pytest

from riprap import cli
from riprap.cli import main
from riprap.errors import CaseFileError
from riprap.io.checkpoint import remove_stale_temporaries
from riprap.placement.layer_metrics import NOT_MEASURED, layer_figures
from riprap.simulation import Simulation
from test_cli_bad_inputs import PLACEMENT, RIGID, _edit


def test_an_absurd_end_time_is_blamed_on_end_time():
    with pytest.raises(CaseFileError) as error:
        Simulation(end_time=1e308)
    assert "simulation.end_time = 1e+308" in str(error.value)
    assert "output_interval" not in str(error.value)


def _dead_process_id() -> int:
    """The id of a process that has ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_restart_clears_the_temporary_file_a_killed_run_left(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(_edit(RIGID, "end_time = 0.01", "end_time = 0.002\ntime_step = 4e-6"))
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "--quiet"]) == 0
    # a run killed while writing its checkpoint leaves its temporary file behind
    stale = out / f".checkpoint.npz.{_dead_process_id()}.tmp"
    stale.write_bytes(b"half a checkpoint")
    alive = out / f".checkpoint.npz.{os.getppid()}.tmp"       # a running process's: kept
    alive.write_bytes(b"being written")
    case.write_text(_edit(RIGID, "end_time = 0.01", "end_time = 0.004\ntime_step = 4e-6"))
    assert main(["run", str(case), "--out", str(out), "--quiet",
                 "--restart", str(out / "checkpoint.npz")]) == 0
    assert not stale.exists()
    assert alive.exists()
    assert remove_stale_temporaries(tmp_path / "no such folder") == []


def test_layer_figures_say_why_they_are_not_measured():
    class Face:
        def to_slope(self, points):
            return np.asarray(points, dtype=float)

    one_row = layer_figures(Face(), np.zeros((3, 3)), [np.zeros((4, 3))] * 3, rows=[0, 0, 0],
                            nominal_diameter=0.1, unit_volume=1e-3, underlayer_level=0.0)
    assert np.isnan(one_row["porosity"]) and "1 row(s)" in one_row[NOT_MEASURED]


def test_a_placement_prints_not_measured_where_summary_json_has_null(tmp_path, capsys,
                                                                       monkeypatch):
    """The figures of a layer that could not be measured are null in summary.json: the terminal
    says "not measured" and why, not "nan"."""
    summary = {"units_placed": 3, "units_at_rest": 3, "units_rolled_off": [],
               "packing_density_coefficient": None, "design_packing_density_coefficient": 0.62,
               "porosity": None, "layer_thickness_m": None, "max_overlap_over_dn": 0.001,
               NOT_MEASURED: "1 row(s) of units on the face; the figures are measured between "
                             "the first and the last of at least two rows",
               "outputs": {}}
    monkeypatch.setattr(cli, "run_placement", lambda case, **_: summary)
    path = tmp_path / "place.toml"
    path.write_text(PLACEMENT)
    assert main(["place", str(path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out
    assert "packing density coefficient not measured (design 0.620)" in out
    assert "porosity not measured" in out and "not measured: 1 row(s) of units" in out
