"""Speed of fracture (issue 16): the cost of joints between all tets of a unit.

The unit-breakage example (examples/11_unit_breakage/case.toml: a Core-Loc-like unit, H = 1 m,
concrete, above six fixed rocks) built twice from its case file: with `[deformable] fracture =
true` (joints between all its tets: the mesh exploded into four nodes per tet) and with
`fracture = false` (the same tets, shared nodes). Both advance the same number of steps from the
start (the unit falling towards the rocks: contact pairs listed, the joints intact), best of
``--repeats`` runs; tet-steps per second = tets x steps / wall seconds.

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


def step_time(fracture: bool, steps: int, repeats: int) -> tuple[float, int, int, float]:
    """(best seconds per step, tets, nodes, time step) of the example with or without joints."""
    case = load_case(CASE)
    case = dataclasses.replace(case, deformable=dataclasses.replace(case.deformable,
                                                                    fracture=fracture))
    with tempfile.TemporaryDirectory() as folder:
        model = build_simulation(case, output_directory=folder).model
        model.prepare(restarted=False)
        system = model.system
        model._step(20)                      # compile and list the contact pairs
        best = float("inf")
        for _ in range(repeats):
            start = time.perf_counter()
            model._step(steps)
            best = min(best, (time.perf_counter() - start) / steps)
        return best, len(system.elements), system.n_deformable_nodes, system.time_step


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"{numba.config.NUMBA_NUM_THREADS} threads; {CASE.relative_to(CASE.parents[2])}")
    plain, tets, nodes, plain_step = step_time(False, args.steps, args.repeats)
    print(f"without joints: {tets:,} tets, {nodes:,} nodes, {plain * 1e3:.3f} ms/step "
          f"(time step {plain_step:.3g} s), {tets / plain:.3g} tet-steps/s")
    jointed, tets, nodes, joint_step = step_time(True, args.steps, args.repeats)
    print(f"with joints:    {tets:,} tets, {nodes:,} nodes, {jointed * 1e3:.3f} ms/step "
          f"(time step {joint_step:.3g} s), {tets / jointed:.3g} tet-steps/s")
    print(f"per simulated second (the joints also shorten the step): "
          f"{jointed / joint_step / (plain / plain_step):.2f} x the wall time")
    print(f"METRIC joint_cost_ratio {jointed / plain:.3f} ratio")
    print(f"METRIC fracture_tet_steps_per_s {tets / jointed:.4g} 1/s")


if __name__ == "__main__":
    main()
