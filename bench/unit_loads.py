"""The fluid's load on a unit against a known drag, and its dependence on the time step.

A towing tank: a cube of side D carried face-on at a constant speed U through water at rest (no
gravity, free-slip walls), the way a laboratory tows a model; by Galileo the same as a cube held in
a uniform current of U. Its drag coefficient C_D = F_x / (rho U^2 D^2 / 2), averaged while it
travels from 4 to 10 D (the wake formed), against the bluff-body value of about 1.05 for a cube
face-on (Hoerner, Fluid-Dynamic Drag, 1965, ch. 3; Re = U D / nu of 2e4 here). The tank is 16 D
long and 6 D square (blockage 2.8 % of the section, not corrected).

Each run carries the cube at a fixed step of ``COURANT`` h / U (0.2) (scaled by ``--dt-scale``): the load
of a method whose load is a property of the flow does not change with it. Both cut-face
treatments of ``riprap.coupling.coupled`` (``CUT_FACE_TREATMENTS``) are measured.

Prints, last, ``METRIC cube_drag_coefficient_<cells> <value> ratio`` per resolution (the default
treatment at the reference step), ``METRIC load_change_dt_5_to_1_25ms`` (here: the relative
change of the drag between the reference step and a quarter of it, the same factor of 4 as
5 ms to 1.25 ms) and ``METRIC load_change_4_5_to_6_cells`` (the relative change of the drag from
4.5 to 6 cells per D).

``--flume``: the cube held on a slope under regular waves instead (``riprap.benchmarks.
held_cube_flume``: a 10 cm cube 2 mm off a 1:1.5 slope, its foot 5 cm under the still water,
waves of H 0.12 m and T 1.4 s in 0.4 m of water), its fluid force at every fluid step over 10
periods at ``max_time_step`` 5 and 1.25 ms per resolution: mean, rms and peak of F_x and F_z.
Then ``METRIC load_change_dt_5_to_1_25ms`` is the largest relative change of the two rms forces
(the first treatment given). The steps are those the flume takes under the cap (the Courant
number may hold them lower); at 3 cells about 500 s of a free 2-core machine for both steps,
about 3.4 and 8 times that at 4.5 and 6.

    python bench/unit_loads.py [--cells 3 4.5 6] [--treatment mixture own_velocity]
    python bench/unit_loads.py --flume [--cells 3 4.5 6] [--treatment mixture]
"""
from __future__ import annotations

import argparse
import tempfile
import time
import warnings

import numpy as np

from riprap.benchmarks import held_cube_flume
from riprap.benchmarks.towing_tank import tow, towing_tank
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case
from riprap.coupling.coupled import CUT_FACE_TREATMENTS

SIDE = 0.05            # m, the cube's side (the damage curve's units are 4.6 cm)
SPEED = 0.4            # m/s: Re = 2e4 in water at 20 degrees C
FROM, TO = 4.0, 10.0   # in D of travel: the window of the average
COURANT = 0.2          # the reference step: 0.2 h / U (the flow beside the cube reaches 1.7 U)
REFERENCE_DRAG = 1.05  # Hoerner (1965), a cube face-on


def towed_cube_drag(cells_per_side: float, *, dt_scale: float = 1.0,
                    cut_faces: str = "mixture") -> dict:
    """C_D of the towed cube, with the steps and wall time."""
    coupled = towing_tank(SIDE, SPEED, cells_per_side, cut_faces=cut_faces)
    fluid = coupled.fluid
    dt = COURANT * fluid.h / SPEED * dt_scale
    started = time.perf_counter()
    travel, drag = tow(coupled, SIDE, SPEED, dt, TO)
    window = (travel > FROM) & (travel < TO)
    dynamic = 0.5 * fluid.water.density * SPEED ** 2 * SIDE ** 2
    return {"cells_per_side": cells_per_side, "dt_scale": dt_scale, "cut_faces": cut_faces,
            "time_step_s": dt, "steps": len(drag), "cells": int(np.prod(fluid.grid.cells)),
            "drag_coefficient": float(drag[window].mean() / dynamic),
            "drag_coefficient_rms_over_mean": float(drag[window].std() / drag[window].mean()),
            "wall_s": time.perf_counter() - started}


def held_cube_loads(cells_per_dn: float, max_time_step: float, cut_faces: str = "mixture") -> dict:
    """The fluid's force on the cube held on the flume's slope (``held_cube_flume``) at every
    fluid step over its ten recorded periods: rms and peak of F_x and F_z (N), and their mean."""
    with tempfile.TemporaryDirectory() as folder:
        case = load_case(held_cube_flume.held_cube_case(folder, cells_per_dn, max_time_step,
                                                        cut_faces))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulation = build_fluid_run(case, output_directory=f"{folder}/out", progress=False)
        coupled = simulation.model.solver
        rows = []
        step = coupled.step

        def recorded(dt=None):
            report = step(dt)
            if report.time > held_cube_flume.RECORD_FROM:
                force = coupled.pressure_loads[held_cube_flume.CUBE, :3] \
                    + coupled.viscous_loads[held_cube_flume.CUBE, :3]
                rows.append((report.time, report.time_step, *force))
            return report

        coupled.step = recorded
        started = time.perf_counter()
        simulation.run()
        wall = time.perf_counter() - started
    rows = np.array(rows)
    weights = rows[:, 1] / rows[:, 1].sum()          # time averages over unequal steps
    out = {"cells_per_dn": cells_per_dn, "max_time_step_s": max_time_step, "cut_faces": cut_faces,
           "steps": len(rows), "mean_step_s": float(rows[:, 1].mean()), "wall_s": wall}
    for name, column in (("x", 2), ("z", 4)):
        force = rows[:, column]
        mean = float(np.sum(weights * force))
        out[f"mean_F{name}_N"] = mean
        out[f"rms_F{name}_N"] = float(np.sqrt(np.sum(weights * (force - mean) ** 2)))
        out[f"peak_F{name}_N"] = float(np.abs(force).max())
    return out


def flume_part(cells: list[float], treatment: str) -> None:
    """The held cube at ``max_time_step`` 5 and 1.25 ms at each resolution; prints the rows and
    the largest relative change of the rms forces."""
    results = {}
    for n in cells:
        for longest in (0.005, 0.00125):
            row = held_cube_loads(n, longest, treatment)
            results[(n, longest)] = row
            print(f"flume {treatment:13s} {n:4.1f} cells per Dn, max step {longest * 1e3:.2f} ms "
                  f"(mean {row['mean_step_s'] * 1e3:.2f} ms, {row['steps']} steps): "
                  f"F_x rms {row['rms_Fx_N']:.3f} peak {row['peak_Fx_N']:.3f} N, "
                  f"F_z mean {row['mean_Fz_N']:.3f} rms {row['rms_Fz_N']:.3f} "
                  f"peak {row['peak_Fz_N']:.3f} N, {row['wall_s']:.0f} s", flush=True)
    change = max(abs(results[(n, 0.00125)][key] / results[(n, 0.005)][key] - 1.0)
                 for n in cells for key in ("rms_Fx_N", "rms_Fz_N"))
    print(f"flume: the largest change of an rms force from 5 to 1.25 ms: {change:.3f}")
    if 4.5 in cells and 6.0 in cells:
        resolution = max(abs(results[(6.0, 0.005)][key] / results[(4.5, 0.005)][key] - 1.0)
                         for key in ("rms_Fx_N", "rms_Fz_N"))
        print(f"flume: the largest change of an rms force from 4.5 to 6 cells per Dn: "
              f"{resolution:.3f}")
    return change


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=float, nargs="+", default=[3.0, 4.5, 6.0])
    parser.add_argument("--treatment", nargs="+", default=list(CUT_FACE_TREATMENTS),
                        choices=CUT_FACE_TREATMENTS)
    parser.add_argument("--flume", action="store_true",
                        help="the cube held on the flume's slope (riprap.benchmarks."
                             "held_cube_flume) instead of the towing tank")
    args = parser.parse_args()
    if args.flume:
        change = flume_part(args.cells, args.treatment[0])
        print(f"METRIC load_change_dt_5_to_1_25ms {change:.3f} ratio")
        return
    results = {}
    for treatment in args.treatment:
        for cells in args.cells:
            for scale in (1.0, 0.25):
                row = towed_cube_drag(cells, dt_scale=scale, cut_faces=treatment)
                results[(treatment, cells, scale)] = row
                print(f"{treatment:13s} {cells:4.1f} cells per D, dt {row['time_step_s']:.2e} s: "
                      f"C_D {row['drag_coefficient']:.3f} (reference {REFERENCE_DRAG}), "
                      f"{row['steps']} steps, {row['wall_s']:.0f} s", flush=True)
    default = args.treatment[0]
    for cells in args.cells:
        print(f"METRIC cube_drag_coefficient_{cells:g} "
              f"{results[(default, cells, 1.0)]['drag_coefficient']:.3f} ratio")
    change = max(abs(results[(default, c, 0.25)]["drag_coefficient"]
                     / results[(default, c, 1.0)]["drag_coefficient"] - 1.0) for c in args.cells)
    print(f"METRIC load_change_dt_5_to_1_25ms {change:.3f} ratio")
    if 4.5 in args.cells and 6.0 in args.cells:
        fine, coarse = (results[(default, c, 1.0)]["drag_coefficient"] for c in (6.0, 4.5))
        print(f"METRIC load_change_4_5_to_6_cells {abs(fine / coarse - 1.0):.3f} ratio")


if __name__ == "__main__":
    main()
