"""The seed paper's armour layer end to end: 242 Core-Loc-like units in 21 rows on a rough
underlayer of ~1,900 rocks (examples/coreloc_paper_242.toml), with ``riprap place``.

Prints the wall time of the underlayer (meshing the rocks, depositing them until at rest) and of
the armour layer (meshing the unit, lifting overlapping start positions, depositing until at rest),
the placement figures (units at rest, packing density coefficient against the design value, largest
overlap), and the speed ratio of the fast contact path against the reference tet-tet evaluation
(``riprap.solid.kernels.reference``) on the touching unit pairs of the resulting pack (at most
``--reference-pairs`` of them; the reference is slow). Last line:
``METRIC paper_case_wall_s <value> s``.

    python bench/paper_armour_layer.py                                   # the paper's case
    python bench/paper_armour_layer.py --case examples/coreloc_small.toml  # minutes
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from riprap.case.build import build_simulation
from riprap.workflows.place import run_placement
from riprap.case.load import load_case
from riprap.solid.kernels.contact import body_pair_potential_force
from riprap.solid.kernels.reference import reference_body_contact

ROOT = Path(__file__).resolve().parents[1]


def reference_ratio(pack: Path, max_pairs: int) -> tuple[float, float, int]:
    """(fast seconds per pair, reference seconds per pair, pairs timed) on touching free pairs."""
    sim = build_simulation(load_case(pack), output_directory=pack.parent / "reference_check",
                           progress=False)
    sim.build_without_checks()
    solver = sim.solver
    contacts = solver.contacts
    pairs = [(int(i), int(j)) for i, j in zip(contacts.body_i, contacts.body_j)
             if j >= 0 and not (solver.fixed[i] and solver.fixed[j])][:max_pairs]
    if not pairs:
        return float("nan"), float("nan"), 0
    rotations = solver.rotation_matrices()
    arrays = solver._shapes
    out = np.zeros(14)

    def fast(i, j):
        body_pair_potential_force(solver.shape_index[i], solver.shape_index[j], solver.positions[i],
                                  rotations[i], solver.positions[j], rotations[j], 1.0, arrays, out)

    fast(*pairs[0])
    tick = time.perf_counter()
    for _ in range(5):
        for i, j in pairs:
            fast(i, j)
    fast_time = (time.perf_counter() - tick) / (5 * len(pairs))

    def world(b):
        shape = solver.shapes[solver.shape_index[b]]
        return shape.mesh.nodes @ rotations[b].T + solver.positions[b], shape.mesh.tets

    reference_body_contact(*world(pairs[0][0]), *world(pairs[0][1]), penalty=1.0)
    tick = time.perf_counter()
    for i, j in pairs:
        reference_body_contact(*world(i), *world(j), penalty=1.0)
    reference_time = (time.perf_counter() - tick) / len(pairs)
    return fast_time, reference_time, len(pairs)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", type=Path, default=ROOT / "examples" / "coreloc_paper_242.toml")
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / ".cache" / "paper_armour_layer")
    parser.add_argument("--reference-pairs", type=int, default=10)
    args = parser.parse_args(argv)
    case = load_case(args.case)
    print(f"paper_armour_layer: {args.case.name}: {case.placement.rows} rows of "
          f"{case.placement.units_per_row}/{case.placement.units_per_alternate_row or case.placement.units_per_row} "
          f"{case.armour.unit} units (H = {case.armour.height or '?'} m) on rocks of Dn50 = "
          f"{case.underlayer.dn50} m, slope 1:{case.slope.cotangent}", flush=True)
    start = time.perf_counter()
    summary = run_placement(case, output_directory=args.out, progress=True)
    total = time.perf_counter() - start
    under = summary["underlayer_run"]
    run = summary["run"]
    print(f"underlayer: {summary['underlayer_rocks']} rocks, {under['end_reason']} at t = "
          f"{under['simulated_time']:.3f} s, {under['steps']} steps, deposition {under['wall_time']:.1f} s wall "
          f"({under['body_steps_per_second']:.3g} body-steps/s)")
    print(f"armour: {summary['units_placed']} units, {summary['units_at_rest']} at rest, "
          f"{len(summary['units_rolled_off'])} rolled off, {run['end_reason']} at t = "
          f"{run['simulated_time']:.3f} s, {run['steps']} steps, deposition {run['wall_time']:.1f} s wall "
          f"({run['body_steps_per_second']:.3g} body-steps/s)")
    meshing_and_setup = total - under["wall_time"] - run["wall_time"]
    print(f"meshing, start checks and output: {meshing_and_setup:.1f} s")
    print(f"packing density coefficient {summary['packing_density_coefficient']:.3f} (design "
          f"{summary['design_packing_density_coefficient']:.3f}), porosity {summary['porosity']:.3f}, "
          f"layer thickness {summary['layer_thickness_m']:.3f} m (design "
          f"{summary['design_layer_thickness_m']:.3f}), largest overlap "
          f"{100 * summary['max_overlap_over_dn']:.2f} % of Dn")
    fast, reference, n = reference_ratio(Path(summary["outputs"]["pack"]), args.reference_pairs)
    print(f"contact evaluation on {n} touching pairs of the pack: fast path {fast * 1e6:.1f} us/pair, "
          f"reference tet-tet {reference * 1e3:.1f} ms/pair, ratio {reference / fast:.0f}x")
    print(f"total wall time {total:.1f} s")
    print(f"METRIC paper_case_wall_s {total:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
