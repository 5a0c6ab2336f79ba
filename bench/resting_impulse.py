"""The fluid's impulse per step on resting units (docs/coupling.md, Peak forces; issue 51).

examples/06 (25 Core-Loc-like units on fixed rocks, hit by a collapsing water column) shortened to
1.2 s, the fluid's vertical force on every free unit recorded at every fluid step. A load that is a
property of the flow gives an impulse F dt proportional to dt; one relaxed a fixed fraction per
step gives a part per step. Over the steps after 0.9 s (the units at rest in the run-down) each
unit's F_z dt / W (W its weight) is fitted as c_0 + f dt: c_0 (W s per step) is the part per step.
Measured before (docs/coupling.md): c_0 = 5.1e-4 to 5.8e-4 W s per step for the three most loaded
units.

    python bench/resting_impulse.py [--cut-faces mixture|own_velocity]

Last line: ``METRIC resting_impulse_per_step <largest c_0 of the three> W_s``.
"""
from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

import numpy as np

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case
from riprap.coupling.coupled import CUT_FACE_TREATMENTS

CASE = Path(__file__).resolve().parents[1] / "examples" / "06_layer_in_wave" / "case.toml"
END, FIT_FROM = 1.2, 0.9


def record_loads(cut_faces: str):
    """(times, steps, vertical fluid force per free unit and step (N), weights (N))."""
    case = load_case(CASE)
    case = dataclasses.replace(case, simulation=dataclasses.replace(
        case.simulation, end_time=END, output_interval=0.05))
    with tempfile.TemporaryDirectory() as out:
        simulation = build_fluid_run(case, output_directory=out, progress=False)
        coupled = simulation.model.solver
        coupled.cut_faces = cut_faces
        free = ~coupled.solids.fixed
        rows = []
        step = coupled.step

        def recorded(dt=None):
            report = step(dt)
            rows.append((report.time, report.time_step, coupled.fluid_loads[free, 2].copy()))
            return report

        coupled.step = recorded
        simulation.run()
    weights = coupled.solids.masses[free] * abs(coupled.fluid.gravity[2])
    times = np.array([r[0] for r in rows])
    steps = np.array([r[1] for r in rows])
    forces = np.array([r[2] for r in rows])
    return times, steps, forces, weights


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cut-faces", default="mixture", choices=CUT_FACE_TREATMENTS)
    args = parser.parse_args()
    started = time.perf_counter()
    times, steps, forces, weights = record_loads(args.cut_faces)
    late = times > FIT_FROM
    impulses = forces[late] * steps[late, None] / weights[None, :]
    design = np.stack([np.ones(late.sum()), steps[late]], axis=1)
    fits = np.linalg.lstsq(design, impulses, rcond=None)[0]        # (2, units): c_0, f
    loaded = np.argsort(-np.abs(forces[late]).mean(axis=0))[:3]
    print(f"{args.cut_faces}: {len(steps)} fluid steps, dt {steps[late].min():.2e} to "
          f"{steps[late].max():.2e} s after {FIT_FROM} s, {time.perf_counter() - started:.0f} s wall")
    for unit in loaded:
        print(f"  free unit {unit}: c_0 {fits[0, unit]:.2e} W s per step, f {fits[1, unit]:.3f} W, "
              f"mean F_z {forces[late, unit].mean() / weights[unit]:.3f} W")
    print(f"METRIC resting_impulse_per_step {np.abs(fits[0, loaded]).max():.2e} W_s")


if __name__ == "__main__":
    main()
