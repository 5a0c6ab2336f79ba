"""Speed of fracture (issue 16): the cost of joints between all tets of a unit.

The unit-breakage example (examples/11_unit_breakage/case.toml: a Core-Loc-like unit, H = 1 m,
concrete, above six fixed rocks) built twice from its case file: with `[deformable] fracture =
true` (joints between all its tets: the mesh exploded into four nodes per tet) and with
`fracture = false` (the same tets, shared nodes). Both advance the same number of steps from the
start (the unit meeting the rocks: contact pairs listed, the joints intact), each repeat built
afresh, the two timed in turn, best of ``--repeats`` runs each; tet-steps per second = tets x
steps / wall seconds.

Prints the step time of each, then
    METRIC joint_cost_ratio <step time with joints / without> ratio
    METRIC fracture_tet_steps_per_s <tet-steps per second with joints> 1/s
The target (issue 16): a ratio of at most 2.
"""
from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

import numba

from riprap.case.build import build_simulation
from riprap.case.load import load_case

CASE = Path(__file__).resolve().parents[1] / "examples" / "11_unit_breakage" / "case.toml"
#: Steps before the timing: compile, list the contact pairs, touch every array's pages.
WARM_UP_STEPS = 100


def build(fracture: bool, folder: str):
    """The example's model with or without joints, after ``WARM_UP_STEPS``."""
    case = load_case(CASE)
    case = dataclasses.replace(case, deformable=dataclasses.replace(case.deformable,
                                                                    fracture=fracture))
    model = build_simulation(case, output_directory=folder).model
    model.prepare(restarted=False)
    model._step(WARM_UP_STEPS)
    return model


def step_times(steps: int, repeats: int) -> tuple:
    """Best seconds per step of the plain and the jointed model, each repeat from the start and
    the two timed in turn (plain, jointed, plain, ...): a shared 2-core machine drifts by 10 to
    20 % from one minute to the next, and timing all of one before all of the other put that
    drift into the ratio. (Each repeat is built afresh: the plain model's longer time step would
    otherwise take it ever deeper into the impact than the jointed one.)"""
    best = {False: float("inf"), True: float("inf")}
    systems = {}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(repeats):
            for fracture in (False, True):
                model = build(fracture, folder)
                start = time.perf_counter()
                model._step(steps)
                best[fracture] = min(best[fracture], (time.perf_counter() - start) / steps)
                systems[fracture] = model.system
    return best, systems


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    if args.steps < 1 or args.repeats < 1:
        parser.error(f"--steps and --repeats must be at least 1 (got {args.steps}, {args.repeats})")
    print(f"{numba.config.NUMBA_NUM_THREADS} threads; {CASE.relative_to(CASE.parents[2])}")
    best, systems = step_times(args.steps, args.repeats)
    plain, jointed = best[False], best[True]
    for label, fracture in (("without joints:", False), ("with joints:   ", True)):
        system = systems[fracture]
        tets = len(system.elements)
        print(f"{label} {tets:,} tets, {system.n_deformable_nodes:,} nodes, "
              f"{best[fracture] * 1e3:.3f} ms/step (time step {system.time_step:.3g} s), "
              f"{tets / best[fracture]:.3g} tet-steps/s")
    plain_step, joint_step = systems[False].time_step, systems[True].time_step
    tets = len(systems[True].elements)
    print(f"per simulated second (the joints also shorten the step): "
          f"{jointed / joint_step / (plain / plain_step):.2f} x the wall time")
    print(f"METRIC joint_cost_ratio {jointed / plain:.3f} ratio")
    print(f"METRIC fracture_tet_steps_per_s {tets / jointed:.4g} 1/s")


if __name__ == "__main__":
    main()
