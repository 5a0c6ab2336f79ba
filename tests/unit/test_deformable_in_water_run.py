"""Deformable bodies in the flow through the run loop and case files: a case with [fluid] and
[deformable] runs coupled and writes the fluid's and the bodies' outputs (stresses in bodies.pvd,
units.csv, body_forces.csv, run.pvd); a restart continues bit for bit; what is not available yet
is refused with a message that says what to do."""
import csv

import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case
from riprap.errors import CaseFileError

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


def test_rigid_bodies_beside_deformable_ones_in_a_flow_are_refused(tmp_path):
    rigid = ('[[bodies]]\nshape = "block"\nmaterial = "block"\nposition = [0.15, 0.15, 0.05]\n')
    path = tmp_path / "case.toml"
    text = CASE.format(end_time=0.02, more_bodies=rigid).replace('bodies = "all"', "bodies = [0]")
    path.write_text(text)
    with pytest.raises(CaseFileError, match="rigid bodies beside deformable ones in a flow"):
        build_fluid_run(load_case(path), output_directory=tmp_path / "out", progress=False).run()
