"""Rigid bodies in a flow over several processes (issue 39), through ``mpiexec`` as a user
starts it, against one process's run of the same case.

Tolerance, and why not bit for bit: every process steps every body alike, but each body's
momentum sums over its faces are added per slab and then slab by slab (rank order), not face by
face as one process adds them, so a body's motion differs in the last bits from the first step
on, and the fluid and the contacts carry those bits on. Every array of the final state (fluid,
bodies, contact springs) and every number of ``body_forces.csv`` must lie within ``RELATIVE``
of the array's largest magnitude of one process's run. Measured (2026-11-28): at most 2e-12 on
the placed layer after 0.3 s, 4e-10 on a settling sphere's torques (which are round-off about
zero), 2e-12 on the crossing spheres. With the cut faces' own velocity (issue 51) the sphere's
torques, round-off about zero (1e-9 N m), differ by 2e-17 N m: they are held to the torque of
its forces at ``TORQUE_LEVER``.
"""
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from riprap.io.checkpoint import load_checkpoint
from riprap.io.vti import read_pvti, read_vti

from .test_mpi_runs import ROOT, launch, riprap

HERE = Path(__file__).parent
RELATIVE = 1e-8
#: (m) a millimetre: smaller than every body of these cases (the settling sphere's radius is 7.5
#: mm), so the torques' bound is no looser than their forces' at the bodies' surfaces.
TORQUE_LEVER = 1e-3
# the clipping's bookkeeping (when each body was last clipped: one process also clips when it
# draws a frame) and the carrying field's faces (their order is not read) are not compared
_BOOKKEEPING = ("coupling_block_poses", "coupling_carried_axis", "coupling_carried_index",
                "coupling_carried_values", "coupling_carried_excess")


def _by_face(state, name):
    """A carried field of a checkpoint ({(axis, i, j, k): value}): the faces' order differs
    between runs split differently."""
    keys = np.column_stack([state["coupling_carried_axis"], state["coupling_carried_index"]])
    return {tuple(key): value for key, value in zip(keys.tolist(), state[name])}


def assert_close_states(expected_path, actual_path):
    (expected, _), (actual, _) = load_checkpoint(expected_path), load_checkpoint(actual_path)
    assert sorted(expected) == sorted(actual)
    for name in expected:
        if name in _BOOKKEEPING:
            continue
        want, got = expected[name], actual[name]
        assert want.shape == got.shape, name
        if want.dtype.kind == "f" and want.size:
            scale = np.abs(want).max()
            if name == "bodies_torques":
                # a torque that is round-off about zero (a sphere falling straight) is held to
                # the torque of the bodies' forces at a lever shorter than any body here
                scale = max(scale, TORQUE_LEVER * np.abs(expected["bodies_forces"]).max())
            worst = np.abs(want - got).max()
            assert worst <= RELATIVE * scale, f"{name}: differs by {worst:.3g} of {scale:.3g}"
        else:
            assert np.array_equal(want, got), name
    for name in ("coupling_carried_values", "coupling_carried_excess"):
        if name in expected:
            want, got = _by_face(expected, name), _by_face(actual, name)
            assert sorted(want) == sorted(got), name
            scale = max(np.abs(list(want.values())).max(initial=0.0), 1e-300)
            worst = max((abs(want[key] - got[key]) for key in want), default=0.0)
            assert worst <= RELATIVE * scale, f"{name}: differs by {worst:.3g} of {scale:.3g}"


def assert_close_frames(one_folder, split_folder):
    """The last fluid frame of a split run (a ``.pvti`` of pieces) against one process's
    (a ``.vti``), every field within the tolerance (float32, as written)."""
    last = [re.findall(r'file="([^"]+)"', (folder / "fluid.pvd").read_text())[-1]
            for folder in (one_folder, split_folder)]
    assert last[0].endswith(".vti") and last[1] == last[0].replace(".vti", ".pvti"), last
    want, got = read_vti(one_folder / last[0]), read_pvti(split_folder / last[1])
    assert sorted(want) == sorted(got)
    for name in want:
        scale = max(float(np.abs(want[name]).max()), 1e-30)
        worst = float(np.abs(want[name] - got[name]).max())
        assert worst <= max(RELATIVE, 1e-6) * scale, f"{name}: differs by {worst:.3g}"


def _vector_of(column: str) -> str:
    """The name a column shares with the other components of its vector (vx_m_per_s and
    vy_m_per_s: v?_m_per_s; pressure_force_x_N: pressure_force_?_N)."""
    return re.sub(r"_[xyz]_", "_?_", re.sub(r"^(v?)[xyz]_", r"\1?_", column))


def assert_close_tables(expected_path, actual_path):
    """Every number within ``RELATIVE`` of its column's largest magnitude, a vector's component
    of its vector's (a sphere falling straight has sideways speeds and forces that are round-off
    about zero, 1e-6 of its fall with the cut faces' own velocity)."""
    want = np.loadtxt(expected_path, delimiter=",", skiprows=1)
    got = np.loadtxt(actual_path, delimiter=",", skiprows=1)
    assert want.shape == got.shape
    scale = np.nanmax(np.abs(want), axis=0)
    header = Path(expected_path).read_text().splitlines()[0].split(",")
    vectors = [_vector_of(name) for name in header]
    scale = np.array([max(scale[k] for k, other in enumerate(vectors) if other == vector)
                      for vector in vectors])
    worst = np.nanmax(np.abs(want - got), axis=0)
    assert np.all(worst <= RELATIVE * scale), (worst, scale)
    assert np.array_equal(np.isnan(want), np.isnan(got))


def assert_restarts_continue(half, whole, unbroken, tmp_path, rounds=((2, 1), (1, 2))):
    """``half`` run on 2 processes and continued to ``whole``'s end on 1, and the other way
    round (or the ``rounds`` given): each ends within the tolerance of the ``unbroken`` run's
    checkpoint."""
    for first, then in rounds:
        folder = tmp_path / f"{first}_then_{then}"
        riprap(first, "run", str(half), "--out", str(folder))
        riprap(then, "run", str(whole), "--out", str(folder), "--restart",
               str(folder / "checkpoint.npz"))
        assert_close_states(unbroken, folder / "checkpoint.npz")


def shortened(source: Path, folder: Path, end_time: float, name: str) -> Path:
    """``source`` with another end time, written beside it (its relative files stay found)."""
    text = source.read_text()
    lines = [f"end_time = {end_time}" if line.startswith("end_time") else line
             for line in text.splitlines()]
    case = source.parent / f".{name}_{folder.name}.toml"
    case.write_text("\n".join(lines) + "\n")
    return case


def test_settling_sphere_over_two_processes_and_restarts(tmp_path):
    """The ten Cate sphere (examples/03) centred on the cut at x-plane 20 of 40: 0.1 s on two
    processes as on one; stopped at 0.05 s on 2 and continued on 1, and the other way round."""
    source = ROOT / "examples" / "03_settling_sphere" / "case.toml"
    whole = shortened(source, tmp_path, 0.1, "whole")
    half = shortened(source, tmp_path, 0.05, "half")
    try:
        one, two = tmp_path / "one", tmp_path / "two"
        riprap(1, "run", str(whole), "--out", str(one))
        riprap(2, "run", str(whole), "--out", str(two))
        assert json.loads((two / "summary.json").read_text())["processes"]["slabs"] == [0, 20, 40]
        assert_close_states(one / "checkpoint.npz", two / "checkpoint.npz")
        assert_close_frames(one, two)
        assert_close_tables(one / "body_forces.csv", two / "body_forces.csv")
        assert_restarts_continue(half, whole, one / "checkpoint.npz", tmp_path)
    finally:
        whole.unlink()
        half.unlink()


def test_placed_layer_in_dam_break_wave_over_two_processes(tmp_path):
    """examples/06 (25 units on 135 fixed rocks and a fixed core, the fluid cut at x-plane 40 of
    70, x = 1.0 m, through the layer; the pressure solved on its own slabs, cut at 36) for 0.3 s:
    units resting across the cut and their contacts across it, as on one process."""
    case = shortened(ROOT / "examples" / "06_layer_in_wave" / "case.toml", tmp_path, 0.3, "short")
    try:
        one, two = tmp_path / "one", tmp_path / "two"
        riprap(1, "run", str(case), "--out", str(one))
        riprap(2, "run", str(case), "--out", str(two))
    finally:
        case.unlink()
    summary = json.loads((two / "summary.json").read_text())
    cut = -3.0 + summary["processes"]["slabs"][1] * 0.1
    assert summary["processes"]["pressure_slabs"] != summary["processes"]["slabs"]
    positions = np.load(two / "checkpoint.npz")["bodies_positions"]
    assert (positions[:, 0] < cut).any() and (positions[:, 0] > cut).any()
    assert summary["contacts"] > 50
    assert_close_states(one / "checkpoint.npz", two / "checkpoint.npz")
    assert_close_tables(one / "body_forces.csv", two / "body_forces.csv")


def test_body_crossing_and_contact_across_the_cut(tmp_path):
    """tests/parallel/cases/crossing_spheres.toml: a sphere rolls across the cut into another
    resting beyond it, on 2 and 3 processes: positions, speeds, contact springs and the fluid as
    on one process; a run on 3 processes continued on 2 ends as the unbroken run."""
    case = HERE / "cases" / "crossing_spheres.toml"
    one = tmp_path / "one"
    riprap(1, "run", str(case), "--out", str(one))
    start = np.loadtxt(one / "body_forces.csv", delimiter=",", skiprows=1)[:2, 2]
    end = np.load(one / "checkpoint.npz")["bodies_positions"][:, 0]
    assert start[1] - end[1] < -0.003          # the resting sphere was pushed along
    for processes in (2, 3):
        out = tmp_path / f"split_{processes}"
        riprap(processes, "run", str(case), "--out", str(out))
        slabs = json.loads((out / "summary.json").read_text())["processes"]["slabs"]
        cuts = np.asarray(slabs[1:-1]) * 0.0025
        assert any(start[0] < cut < end[0] for cut in cuts), (start, end, cuts)
        assert_close_states(one / "checkpoint.npz", out / "checkpoint.npz")
        assert_close_tables(one / "body_forces.csv", out / "body_forces.csv")
    # N -> M: stopped at 0.04 s on 3 processes, its
    # checkpoint in 3 pieces, and continued on 2 (the cut elsewhere)
    half = shortened(case, tmp_path, 0.04, "half")
    try:
        assert_restarts_continue(half, case, one / "checkpoint.npz", tmp_path, rounds=((3, 2),))
    finally:
        half.unlink()
    assert len(list((tmp_path / "3_then_2" / "checkpoint_pieces").iterdir())) == 2


@pytest.mark.parametrize("processes", [2, 3])
def test_bodies_owned_by_the_slab_of_their_centre_are_one_process_s(processes):
    """tests/parallel/bodies_split_check.py: rocks sliding past each other across the cuts, each
    owned by the process of its centre (owners changing inside a batch of steps, contacts across
    a cut), against one process stepping the same rocks: positions, velocities, forces, springs
    and contact records equal in every bit on every process."""
    result = launch(processes, sys.executable, str(HERE / "bodies_split_check.py"))
    assert result.stdout.count("bit for bit") == processes, result.stdout


def test_rigid_bodies_alone_over_two_and_three_processes(tmp_path):
    """examples/01 (rocks dropped on a floor, no fluid): the rocks owned by the process of their
    centre on 2 and 3 processes, each body's forces added by its owner in one process's order,
    so the bodies' frames and checkpoint are one process's, byte for byte (no tolerance: nothing
    is summed in another order)."""
    case = ROOT / "examples" / "01_rock_drop" / "case.toml"
    one = tmp_path / "one"
    riprap(1, "run", str(case), "--out", str(one))
    for processes in (2, 3):
        out = tmp_path / f"split_{processes}"
        riprap(processes, "run", str(case), "--out", str(out))
        first, second = np.load(one / "checkpoint.npz"), np.load(out / "checkpoint.npz")
        assert sorted(first.files) == sorted(second.files)
        for name in first.files:
            floats = first[name].dtype.kind == "f"
            assert np.array_equal(first[name], second[name], equal_nan=floats), name
        frames = sorted(path.name for path in one.glob("bodies_*.vtu"))
        assert frames and frames == sorted(path.name for path in out.glob("bodies_*.vtu"))
        for name in frames:
            assert (one / name).read_bytes() == (out / name).read_bytes(), name
        summary = json.loads((out / "summary.json").read_text())
        assert summary["processes"]["count"] == processes
        assert summary["contacts"] == json.loads((one / "summary.json").read_text())["contacts"]


def test_deformable_body_in_water_over_two_processes_and_restarts(tmp_path):
    """tests/parallel/cases/deformable_block.toml: a soft block sinking across the cut (every
    process steps its elements; the pressure on its surface is the whole grid's, joined from the
    slabs): nodes, stresses and fluid as on one process; stopped at 0.02 s on 2 processes and
    continued on 1, and the other way round."""
    case = HERE / "cases" / "deformable_block.toml"
    one, two = tmp_path / "one", tmp_path / "two"
    riprap(1, "run", str(case), "--out", str(one))
    riprap(2, "run", str(case), "--out", str(two))
    assert json.loads((two / "summary.json").read_text())["processes"]["slabs"] == [0, 12, 24]
    assert_close_states(one / "checkpoint.npz", two / "checkpoint.npz")
    assert_close_tables(one / "body_forces.csv", two / "body_forces.csv")
    half = shortened(case, tmp_path, 0.02, "half")
    try:
        assert_restarts_continue(half, case, one / "checkpoint.npz", tmp_path)
    finally:
        half.unlink()
