"""One run over several processes (issue 39), through ``mpiexec`` as a user starts it.

What is checked, and against what: the split pressure solve and the split fluid against one
process's, bit for bit (the reductions are added in the same order, so no tolerance is needed);
the dam break's files through ``mpiexec -n 2 riprap run`` against ``riprap run``'s, bit for bit;
restarts 2 -> 1 and 1 -> 2 against the unbroken run; a killed process ends the run; bad input is
refused with the figure. The MPI library comes from the ``mpich`` wheel that the ``test`` extra
installs, as ``.ci/run`` does."""
import filecmp
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from riprap.io.checkpoint import load_checkpoint
from riprap.io.vti import read_pvti, read_vti

HERE = Path(__file__).parent
ROOT = HERE.parent.parent
DAM_BREAK = ROOT / "examples" / "02_dam_break" / "case.toml"
STATE = ("fraction", "u", "v", "w", "pressure", "clock")


def mpiexec() -> str:
    beside = Path(sys.executable).parent / "mpiexec"
    found = shutil.which("mpiexec") or (str(beside) if beside.exists() else None)
    assert found, "mpiexec not found: install the test extra (mpi4py and the mpich wheel)"
    return found


def launch(processes, *arguments, timeout=600, check=True):
    command = [mpiexec(), "-n", str(processes), *arguments] if processes > 1 else list(arguments)
    # the machine's cores shared among the processes (docs/parallel.md): more threads than cores
    # made the split runs several times slower here (2 cores, 3 processes of 2 threads each)
    threads = str(max(1, (os.cpu_count() or 1) // processes))
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                            cwd=ROOT, env=dict(os.environ, RIPRAP_SMOKE="0",
                                               NUMBA_NUM_THREADS=threads))
    if check:
        assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return result


def riprap(processes, *arguments, **options):
    return launch(processes, sys.executable, "-m", "riprap", *arguments, **options)


def same_state(a, b) -> bool:
    (first, _), (second, _) = load_checkpoint(a), load_checkpoint(b)
    return all(np.array_equal(first[name], second[name]) for name in STATE)


def frame_times(pvd: Path) -> list[str]:
    return re.findall(r'timestep="([^"]+)"', pvd.read_text())


@pytest.mark.parametrize("processes", [2, 3])
def test_slab_pressure_solve_is_bit_for_bit(processes):
    """3D 1000:1 drops and bubbles, with listed cells, 2D, a closed tank: the same iterations and
    the same pressure in every bit on 2 and 3 processes as on one."""
    result = launch(processes, sys.executable, str(HERE / "slab_pressure_check.py"))
    assert result.stdout.count("bit for bit") == 4, result.stdout


@pytest.mark.parametrize("processes", [2, 3])
def test_pressure_on_slabs_of_its_own_is_bit_for_bit(processes):
    """The fluid's cut made unequal (its upper planes weighed three times), the pressure solved on
    equal slabs of its own (riprap/fluid/pressure_window.py): the planes moved between the cuts
    are the owners' (pressure_window_check.py: halos hold NaN), and 600 dam-break steps give one
    process's state in every bit."""
    result = launch(processes, sys.executable, str(HERE / "pressure_window_check.py"))
    assert result.stdout.count("bit for bit") == processes, result.stdout
    result = launch(processes, sys.executable, str(HERE / "slab_fluid_check.py"), str(DAM_BREAK),
                    "600", "8", "100", "skewed")
    assert "bit for bit" in result.stdout, result.stdout


def test_dam_break_over_two_processes_and_restarts(tmp_path):
    """Martin & Moyce's dam break (examples/02, the front crosses the cut at x-plane 64 near
    t = 0.06 s): the frames, solver log and checkpoint of ``mpiexec -n 2 riprap run`` are those
    of one process, bit for bit (the frames written in pieces, a ``.pvti`` naming one ``.vti``
    of each process's x-planes, the checkpoint as a piece of each process beside the file that
    names them); a run stopped at 0.1 s on 2 processes and continued on 1, and the other way
    round, ends in the unbroken run's state."""
    one, two = tmp_path / "one", tmp_path / "two"
    riprap(1, "run", str(DAM_BREAK), "--out", str(one))
    riprap(2, "run", str(DAM_BREAK), "--out", str(two))
    assert filecmp.cmp(one / "solver_log.csv", two / "solver_log.csv", shallow=False)
    assert frame_times(one / "fluid.pvd") == frame_times(two / "fluid.pvd")
    assert "fluid_000010.pvti" in (two / "fluid.pvd").read_text()
    for frame in ("fluid_000005", "fluid_000010"):
        whole, pieces = read_vti(one / f"{frame}.vti"), read_pvti(two / f"{frame}.pvti")
        assert sorted(whole) == sorted(pieces)
        assert all(np.array_equal(whole[name], pieces[name]) for name in whole), frame
        assert sorted(p.name for p in (two / frame).iterdir()) == ["piece_0000.vti",
                                                                   "piece_0001.vti"]
    assert len(list((two / "checkpoint_pieces").iterdir())) == 2
    assert not (one / "checkpoint_pieces").exists()
    assert same_state(one / "checkpoint.npz", two / "checkpoint.npz")
    half = tmp_path / "half.toml"
    half.write_text(DAM_BREAK.read_text().replace("end_time = 0.2 ", "end_time = 0.1 "))
    for first, then, folder in ((2, 1, tmp_path / "two_then_one"),
                                (1, 2, tmp_path / "one_then_two")):
        riprap(first, "run", str(half), "--out", str(folder))
        riprap(then, "run", str(DAM_BREAK), "--out", str(folder), "--restart",
               str(folder / "checkpoint.npz"))
        assert same_state(one / "checkpoint.npz", folder / "checkpoint.npz"), folder.name


def test_a_blow_up_on_one_process_stops_all_with_the_failure_checkpoint(tmp_path):
    """A non-finite pressure found by process 1 after the dam break's fifth step
    (tests/parallel/blow_up_run.py): every process stops with exit 2 and one message naming the
    process, the cell in the case's grid and the time; the failure checkpoint (in pieces) holds
    the last good state, and continued from it on one process the run ends as the unbroken
    one-process run, bit for bit."""
    half = tmp_path / "half.toml"
    half.write_text(DAM_BREAK.read_text().replace("end_time = 0.2 ", "end_time = 0.1 "))
    broken = tmp_path / "broken"
    result = launch(2, sys.executable, str(HERE / "blow_up_run.py"), "run", str(half), "--out",
                    str(broken), check=False, timeout=300)
    assert result.returncode != 0
    assert re.search(r"pressure became non-finite at index \[66, 0, 5\] .* at t = 0\.01\d* s "
                     r".*\(process 1 of 2\)", result.stderr), result.stderr[-3000:]
    failure = broken / "failure_checkpoint.npz"
    assert f"was written to {failure}" in result.stderr
    assert len(list((broken / "failure_checkpoint_pieces").iterdir())) == 2
    arrays, _ = load_checkpoint(failure)
    assert arrays["fraction"].shape == (125, 1, 63) and np.isfinite(arrays["pressure"]).all()
    riprap(1, "run", str(half), "--out", str(broken), "--restart", str(failure))
    riprap(1, "run", str(half), "--out", str(tmp_path / "unbroken"))
    assert same_state(tmp_path / "unbroken" / "checkpoint.npz", broken / "checkpoint.npz")


def test_wave_flume_over_two_processes():
    """examples/09's regular waves (wave-making and absorbing zones, eight surface gauges), 600
    steps of 0.01 s (the waves cross the cut at x = 6.32 m from t of about 5 s): the whole
    grid and every gauge's record bit for bit those of one process, compared every 100 steps."""
    case = ROOT / "examples" / "09_regular_waves" / "case.toml"
    result = launch(2, sys.executable, str(HERE / "slab_fluid_check.py"), str(case), "600", "8",
                    "100", timeout=1200)
    assert "bit for bit" in result.stdout, result.stdout


def test_porous_flume_with_boundary_waves_and_every_gauge_over_two_processes():
    """A test series' flume (tests/parallel/cases/porous_flume.toml: a porous core across the
    cut, waves from the x-low boundary with active absorption, surface, run-up and overtopping
    gauges), 400 steps: the whole grid and every gauge's record bit for bit those of one
    process, compared every 50 steps."""
    case = HERE / "cases" / "porous_flume.toml"
    result = launch(2, sys.executable, str(HERE / "slab_fluid_check.py"), str(case), "400", "8",
                    "50", timeout=600)
    assert "bit for bit" in result.stdout, result.stdout


def test_periodic_strip_over_two_processes():
    """A periodic strip (tests/parallel/cases/periodic_flume.toml: y_low = y_high = "periodic", a
    mound of water spilling across the periodic boundary, a porous core, boundary waves, gauges),
    300 steps on two slabs of x: the whole grid and the gauges bit for bit those of one process,
    compared every 50 steps (the strip's wrap lies inside each slab; the split pressure solve
    wraps on its distributed and gathered levels alike)."""
    case = HERE / "cases" / "periodic_flume.toml"
    result = launch(2, sys.executable, str(HERE / "slab_fluid_check.py"), str(case), "300", "8",
                    "50", timeout=600)
    assert "bit for bit" in result.stdout, result.stdout


def test_a_killed_process_ends_the_run(tmp_path):
    """One process of two killed mid-run: the launcher ends the other, within 30 s."""
    longer = tmp_path / "long.toml"
    longer.write_text(DAM_BREAK.read_text().replace("end_time = 0.2 ", "end_time = 20.0 "))
    out = tmp_path / "out"
    launcher = subprocess.Popen([mpiexec(), "-n", "2", sys.executable, "-m", "riprap", "run",
                                 str(longer), "--out", str(out)], cwd=ROOT,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 300
        while not (out / "fluid_000001.pvti").exists():
            assert launcher.poll() is None and time.monotonic() < deadline, "the run did not start"
            time.sleep(0.5)
        ranks = [int(pid) for pid in subprocess.run(
            ["pgrep", "-f", f"riprap run {longer}"], capture_output=True, text=True).stdout.split()
            if Path(f"/proc/{pid}/cmdline").exists()
            and Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")[0].endswith(
                os.path.basename(sys.executable).encode())]
        assert len(ranks) == 2, ranks
        killed = time.monotonic()
        os.kill(max(ranks), signal.SIGKILL)
        launcher.wait(timeout=30)
        assert time.monotonic() - killed < 30
        assert launcher.returncode != 0
    finally:
        if launcher.poll() is None:
            launcher.kill()


def test_refusals_name_the_figure(tmp_path):
    """More processes than the grid can be cut into; a restart from another case's checkpoint;
    deformable bodies over several processes (not yet); a command other than run under mpiexec:
    refused,
    every process ended, nothing hangs."""
    small = tmp_path / "small.toml"
    small.write_text(DAM_BREAK.read_text()
                     .replace("upper = [0.28575, 0.002286, 0.144018]",
                              "upper = [0.036576, 0.002286, 0.144018]")
                     .replace("cells = [125, 1, 63]", "cells = [16, 1, 63]")
                     .replace("upper = [0.05715, 0.002286, 0.1143]",
                              "upper = [0.018288, 0.002286, 0.1143]"))
    result = riprap(3, "run", str(small), "--out", str(tmp_path / "small"), check=False,
                    timeout=120)
    assert result.returncode != 0
    assert "16 cells along x cannot be cut into 3 slabs" in result.stderr, result.stderr[-2000:]
    riprap(1, "run", str(small), "--out", str(tmp_path / "small_one"))
    result = riprap(2, "run", str(DAM_BREAK), "--out", str(tmp_path / "other"), "--restart",
                    str(tmp_path / "small_one" / "checkpoint.npz"), check=False, timeout=120)
    assert result.returncode != 0 and "cells was [16,1,63]" in result.stderr, result.stderr[-2000:]
    impact = ROOT / "examples" / "07_unit_impact" / "case.toml"
    result = riprap(2, "run", str(impact), "--out", str(tmp_path / "impact"), check=False,
                    timeout=120)
    assert result.returncode != 0 and "not deformable bodies" in result.stderr, \
        result.stderr[-2000:]
    result = riprap(2, "analyse", str(tmp_path / "small_one"), check=False, timeout=120)
    assert result.returncode != 0 and "runs on one process" in result.stderr, result.stderr[-2000:]


def test_without_mpi4py_asking_for_processes_says_what_to_install(monkeypatch):
    """Started as 2 processes where mpi4py cannot be imported: one error naming the install."""
    from riprap.parallel import communicator

    monkeypatch.setenv("PMI_SIZE", "2")
    monkeypatch.setattr(communicator, "_WORLD", None)
    monkeypatch.setitem(sys.modules, "mpi4py", None)
    with pytest.raises(communicator.ParallelError, match=r"'\.\[mpi\]'"):
        communicator.world()
    monkeypatch.setattr(communicator, "_WORLD", None)
