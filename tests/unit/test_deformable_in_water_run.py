"""Deformable bodies in the flow through the run loop and case files: a case with [fluid] and
[deformable] runs coupled and writes the fluid's and the bodies' outputs (stresses in bodies.pvd,
units.csv, body_forces.csv, run.pvd); rigid bodies beside them in the same flow; a restart
continues bit for bit."""
import csv

import numpy as np
import pytest
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case

CASE = """
format_version = 1

[simulation]
end_time = {end_time}
output_interval = 0.02
checkpoint_interval = 0.02

[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.3, 0.3, 0.3]
cells = [12, 12, 12]
surface_tension = 0.0

[[water_regions]]
type = "level"
level = 0.2

[[materials]]
name = "block"
density = 1800.0

[[shapes]]
name = "block"
type = "box"
lengths = [0.1, 0.08, 0.06]
mesh_size = 0.04

[[bodies]]
shape = "block"
material = "block"
position = [0.15, 0.15, 0.15]
{more_bodies}

[deformable]
bodies = "all"
young_modulus = 1.0e6
poisson_ratio = 0.3
viscosity = 20.0
tensile_strength = 1.0e4

[output]
picture = false
"""


def _run(tmp_path, name, end_time, *, restart=None, more_bodies=""):
    path = tmp_path / f"{name}.toml"
    path.write_text(CASE.format(end_time=end_time, more_bodies=more_bodies))
    sim = build_fluid_run(load_case(path), output_directory=tmp_path / name, progress=False)
    summary = sim.run(restart_from=restart)
    return sim, summary


def test_fluid_case_with_deformable_bodies_writes_fluid_and_stress_outputs(tmp_path):
    sim, summary = _run(tmp_path, "out", 0.04)
    out = tmp_path / "out"
    assert summary.model == "deformable_coupled"
    assert summary.element_steps_per_second > 0 and summary.solid_substeps > 0
    assert summary.cells == 12 ** 3
    for name in ("fluid.pvd", "bodies.pvd", "run.pvd", "units.csv", "body_forces.csv"):
        assert (out / name).is_file(), name
    frame = sorted(out.glob("bodies_*.vtu"))[-1].read_text(errors="ignore")
    for field in ("sigma_1", "sigma_3", "differential_stress", "von_mises"):
        assert f'Name="{field}"' in frame
    rows = list(csv.DictReader(open(out / "units.csv")))
    assert len(rows) == 1
    # under water at 5 to 8 cm depth the block is squeezed: its largest principal stress is a
    # compression of about the pressure there (rho g depth ~ 600 Pa), not zero
    assert float(rows[0]["final_max_tensile_stress_Pa"]) < -100.0
    forces = list(csv.reader(open(out / "body_forces.csv")))
    assert len(forces) > 2


def test_restart_continues_bit_for_bit(tmp_path):
    whole, _ = _run(tmp_path, "whole", 0.04)
    _run(tmp_path, "part", 0.02)
    second, _ = _run(tmp_path, "part", 0.04, restart=tmp_path / "part" / "checkpoint.npz")
    a, b = whole.model.state_arrays(), second.model.state_arrays()
    for key in ("bodies_positions", "bodies_velocities", "u", "w", "fraction", "record_stress"):
        assert np.array_equal(a[key], b[key]), key


RIGID_BLOCK = '[[bodies]]\nshape = "block"\nmaterial = "block"\nposition = [0.15, 0.15, 0.035]\nfixed = true\n'


def _mixed(tmp_path, name, end_time, *, restart=None):
    path = tmp_path / f"{name}.toml"
    text = CASE.format(end_time=end_time, more_bodies=RIGID_BLOCK).replace(
        'bodies = "all"', "bodies = [0]").replace("position = [0.15, 0.15, 0.15]",
                                                  "position = [0.15, 0.15, 0.0951]")
    path.write_text(text)
    sim = build_fluid_run(load_case(path), output_directory=tmp_path / name, progress=False)
    return sim, sim.run(restart_from=restart)


def test_rigid_and_deformable_bodies_in_one_flow(tmp_path):
    sim, summary = _mixed(tmp_path, "out", 0.04)
    out = tmp_path / "out"
    assert summary.model == "deformable_coupled" and summary.bodies == 2
    for name in ("bodies.pvd", "rigid_bodies.pvd", "run.pvd", "units.csv"):
        assert (out / name).is_file(), name
    assert (out / "run.pvd").read_text().count('part="2"') >= 2, "fluid, deformable and rigid"
    bodies = sim.model.solids
    assert bodies.n_rigid == 1 and bodies.fixed.tolist() == [True, False]
    assert bodies.contact_forces()[0, 2] == bodies.rigid_contact_loads[0, 2]
    # body_forces.csv numbers the bodies as the case does (the deformable block is body 0)
    rows = list(csv.DictReader(open(out / "body_forces.csv")))
    deformable = [row for row in rows if row["body"] == "0"]
    rigid = [row for row in rows if row["body"] == "1"]
    assert float(deformable[0]["z_m"]) == pytest.approx(0.0951)
    # the deformable block lands on the rigid one (it touches at 0.02 s and bounces): the forces
    # cross between the two solvers, equal and opposite
    landed = [(d, r) for d, r in zip(deformable, rigid) if float(d["contact_force_z_N"]) > 0.0]
    assert landed
    for d, r in landed:
        assert d["time_s"] == r["time_s"]
        assert float(r["contact_force_z_N"]) == pytest.approx(-float(d["contact_force_z_N"]), rel=1e-12)


def test_mixed_run_in_a_flow_restarts_bit_for_bit(tmp_path):
    whole, _ = _mixed(tmp_path, "whole", 0.04)
    _mixed(tmp_path, "part", 0.02)
    second, _ = _mixed(tmp_path, "part", 0.04, restart=tmp_path / "part" / "checkpoint.npz")
    a, b = whole.model.state_arrays(), second.model.state_arrays()
    for key in ("bodies_positions", "bodies_velocities", "bodies_rigid_contact_loads", "u", "w",
                "record_stress"):
        assert np.array_equal(a[key], b[key]), key
