"""A whole hydraulic stability test end to end: ``examples/10_breakwater_test`` (25 Core-Loc-like
units on 135 fixed rocks and a porous core, JONSWAP Hs = 1.2 m, Tp = 4 s) run for its 60 s as
``riprap run`` runs it (frames, checkpoints, gauges, the waves report), timed as a whole.

Prints the wall time, the fluid steps, pressure iterations and contact sub-steps per step, and the
results an engineer reads from the test: the largest water volume error over the run, the incident
Hm0 at the toe (Mansard-Funke, as ``riprap analyse`` takes it), the reflection coefficient, R2%
run-up, overtopping q and every unit's final displacement. ``--save FILE`` writes them as JSON;
``--compare FILE`` prints them beside a saved run with the agreement bands of issue 37 (why each
band is what it is: ``docs/waves.md``, The breakwater test's cost). Last line ``METRIC
flume_test_wall_s <seconds> s`` (issue 37's target: at most 600 s on this 2-core machine).

    python bench/flume_test.py [--end SECONDS] [--out DIR] [--save FILE] [--compare FILE]
"""
import argparse
import json
import os
import shutil
import time
from pathlib import Path

import numpy as np

from riprap.analysis.stability_report import incident_at_toe
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case

CASE = Path(__file__).resolve().parents[1] / "examples" / "10_breakwater_test" / "case.toml"
NOMINAL_DIAMETER = 0.563          # m, the units' Dn (examples/10 README)

#: Agreement bands against a run before a change (issue 37): (absolute, relative) per figure; a
#: figure agrees when |new - old| <= absolute + relative |old|. Irregular waves on a breaking,
#: reflecting structure are chaotic in their details: a change of round-off grows into other
#: breaker shapes within a few waves, so the bands are those of two runs of one sea that differ
#: only in round-off (docs/waves.md, The breakwater test's cost), not of the method.
BANDS = {"incident_Hm0_m": (0.0, 0.05), "reflection_coefficient": (0.05, 0.0),
         "R2%_m": (0.0, 0.15), "q_l_s_per_m": (0.0, 0.5),
         "max_abs_water_volume_error": (1e-3, 0.0)}
#: a unit's final displacement agrees within this many Dn
DISPLACEMENT_BAND_DN = 0.1


def results_of(summary, report: dict, displacement, volume_errors) -> dict:
    incident, _, waves, source = incident_at_toe(report)
    reflection = [e["reflection_coefficient"] for e in report.get("reflection_three_gauge", [])]
    run_up = next(iter(report.get("run_up", {}).values()), {})
    overtopping = next(iter(report.get("overtopping", {}).values()), {})
    return {"wall_s": summary.wall_time, "simulated_s": summary.simulated_time,
            "fluid_steps": summary.steps, "cells": summary.cells,
            "pressure_iterations_mean": summary.pressure_iterations_mean,
            "pressure_iterations_max": summary.pressure_iterations_max,
            "substeps_per_step": summary.solid_substeps / max(summary.steps, 1),
            "max_abs_water_volume_error": float(np.max(np.abs(volume_errors))),
            "final_water_volume_error": summary.water_volume_error,
            "incident_Hm0_m": incident, "incident_source": source, "waves_at_toe": waves,
            "reflection_coefficient": float(np.mean(reflection)) if reflection else None,
            "R2%_m": run_up.get("R2%_m"), "q_l_s_per_m": overtopping.get("q_l_s_per_m"),
            "unit_displacement_m": [float(d) for d in displacement]}


def compare(new: dict, old: dict) -> bool:
    agree = True
    print("beside the saved run (band: |new - old| <= absolute + relative |old|):")
    for name, (absolute, relative) in BANDS.items():
        a, b = old.get(name), new.get(name)
        if a is None or b is None:
            print(f"  {name}: {b} (saved {a}): not compared")
            continue
        ok = abs(b - a) <= absolute + relative * abs(a)
        agree &= ok
        print(f"  {name}: {b:.4g} (saved {a:.4g}, band {absolute:g} + {relative:.0%}) "
              f"{'agrees' if ok else 'OUTSIDE'}")
    old_d, new_d = np.array(old["unit_displacement_m"]), np.array(new["unit_displacement_m"])
    if old_d.shape == new_d.shape:
        gap = np.abs(new_d - old_d) / NOMINAL_DIAMETER
        outside = np.flatnonzero(gap > DISPLACEMENT_BAND_DN)
        agree &= not len(outside)
        print(f"  unit displacements: largest {new_d.max() / NOMINAL_DIAMETER:.2f} Dn (saved "
              f"{old_d.max() / NOMINAL_DIAMETER:.2f}); largest difference {gap.max():.3f} Dn "
              f"(band {DISPLACEMENT_BAND_DN} Dn); outside: {outside.tolist()}")
    return agree


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end", type=float, default=60.0, help="simulated seconds (default 60)")
    parser.add_argument("--case", default=str(CASE),
                        help="another case file (e.g. examples/10 with a round-off change, to "
                             "measure the run-to-run spread the bands stand for)")
    parser.add_argument("--out", default="/tmp/riprap_bench_flume_test")
    parser.add_argument("--save", help="write the results as JSON here")
    parser.add_argument("--compare", help="a JSON of --save to compare with")
    parser.add_argument("--keep-checkpoints", action="store_true",
                        help="keep each checkpoint as checkpoint_<t>.npz (to restart experiments "
                             "from the waves on the structure)")
    args = parser.parse_args()
    load_before = os.getloadavg()
    case = load_case(Path(args.case))
    simulation = build_fluid_run(case, output_directory=args.out, progress=False)
    simulation.end_time = args.end
    bodies = simulation.solver
    free = np.flatnonzero(~bodies.fixed)
    initial = bodies.positions[free].copy()
    volume_errors, next_line, kept = [], [0.0], [None]
    started = time.perf_counter()

    def after_chunk(sim):
        report = sim.model.solver.last_report
        if report is not None:
            volume_errors.append(report.water_volume_error)
        if sim.model.time >= next_line[0]:
            print(f"  t = {sim.model.time:5.1f} s  wall {time.perf_counter() - started:6.0f} s  "
                  f"{sim.model.progress_text()}", flush=True)
            next_line[0] += 5.0
        checkpoint = Path(args.out) / "checkpoint.npz"
        if args.keep_checkpoints and checkpoint.exists():
            stamp = checkpoint.stat().st_mtime
            if stamp != kept[0]:
                kept[0] = stamp
                shutil.copy(checkpoint, checkpoint.with_name(f"checkpoint_{sim.model.time:.0f}.npz"))
        return False

    summary = simulation.run(after_chunk=after_chunk)
    displacement = np.linalg.norm(bodies.positions[free] - initial, axis=1)
    report = json.loads((Path(args.out) / "waves_report.json").read_text())
    results = results_of(summary, report, displacement, volume_errors)
    print(f"examples/10 end to end: {results['simulated_s']:.1f} s simulated in {summary.wall_time:.0f} s "
          f"wall ({summary.cells:,} cells); {summary.steps} fluid steps, "
          f"{results['pressure_iterations_mean']:.1f} pressure iterations per step (max "
          f"{results['pressure_iterations_max']}), {results['substeps_per_step']:.0f} contact "
          f"sub-steps per step")
    print(f"water volume error: largest {results['max_abs_water_volume_error']:.2e}, at the end "
          f"{results['final_water_volume_error']:.2e}")
    print(f"incident Hm0 at the toe {results['incident_Hm0_m']} m ({results['incident_source']}, "
          f"{results['waves_at_toe']} waves), reflection {results['reflection_coefficient']}, "
          f"R2% {results['R2%_m']} m, overtopping q {results['q_l_s_per_m']} l/s per m")
    print(f"unit displacements: largest {displacement.max() / NOMINAL_DIAMETER:.2f} Dn, "
          f"{int((displacement > 0.1 * NOMINAL_DIAMETER).sum())} of {len(displacement)} moved more "
          "than 0.1 Dn")
    if args.save:
        Path(args.save).write_text(json.dumps(results, indent=1))
    if args.compare:
        compare(results, json.loads(Path(args.compare).read_text()))
    print(f"load average before {load_before[0]:.2f}, after {os.getloadavg()[0]:.2f}")
    print(f"METRIC flume_test_wall_s {summary.wall_time:.0f} s")


if __name__ == "__main__":
    main()
