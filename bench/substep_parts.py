"""Where a contact sub-step's time goes, per body, as the number of bodies grows: the work that
every process of a split run repeats for every body (the broad phase, the two half kicks and the
drift, the sums of the contact rows into forces) apart from the pair work that the processes
share (bench/parallel_model.py takes the repeated part from here).

The bodies: cubes of 5 cm on a lattice of n x n x 3, each face pressed on its neighbours' (0.1 %
overlap), no gravity, so every body keeps about 8 candidates through the timing. One thread.
Each part is timed alone over repeats of the same state. The pair work of face-on-face cubes is
far dearer than a rubble mound's point and edge contacts: it is printed, not used.

    NUMBA_NUM_THREADS=1 python bench/substep_parts.py

Last line: ``METRIC substep_repeated_per_body <microseconds> us`` (the largest lattice's broad
phase + integration + sums, per body and sub-step).
"""
import time

import numpy as np

from riprap.geometry import shapes
from riprap.solid.kernels import integrate, interactions, stepper
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

SIDE = 0.05          # m


def lattice(n_side: int, layers: int = 3) -> SolidSolver:
    solids = SolidSolver(gravity=(0.0, 0.0, 0.0))
    shape = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=SIDE, mesh_size=SIDE / 2)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1e7))
    jitter = np.random.default_rng(1)
    for i in range(n_side):
        for j in range(n_side):
            for k in range(layers):
                centre = np.array([i, j, k]) * SIDE * 0.999 + jitter.normal(scale=1e-5, size=3)
                solids.add_body(shape=shape, material="concrete", position=centre)
    solids.time_step = 1e-5
    solids.finalize()
    return solids


def seconds(work, repeat: int) -> float:
    work()                                  # compiled and warm
    start = time.perf_counter()
    for _ in range(repeat):
        work()
    return (time.perf_counter() - start) / repeat


def parts(solids: SolidSolver) -> dict:
    solids.advance(3)
    system, motion, history, settings = solids._kernel_state(solids.time_step)
    n = solids.n_bodies
    repeat = max(3, 3000 // n)
    broad = seconds(lambda: stepper.candidate_pairs(system, motion, settings), repeat)
    body_pairs, wall_pairs, omegas, stride = stepper.candidate_pairs(system, motion, settings)
    positions, quaternions, velocities, momenta, forces, torques = motion
    _, inverse_masses, inverse_inertia, _, _, _ = system.bodies

    def integration():
        # a sub-step's two half kicks and its drift, of zero length (the state stays put)
        integrate.kick(velocities, momenta, omegas, forces, torques, inverse_masses, 0.0, 0.0)
        integrate.drift(positions, quaternions, velocities, momenta, inverse_masses,
                        inverse_inertia, 0.0)
        integrate.kick(velocities, momenta, omegas, forces, torques, inverse_masses, 0.0, 0.0)

    kicks = seconds(integration, repeat)
    cache = solids._piece_cache
    results, cache = interactions.evaluate_candidates(body_pairs, wall_pairs, system, motion,
                                                      omegas, history, settings, cache)
    pairs = seconds(lambda: interactions.evaluate_candidates(
        body_pairs, wall_pairs, system, motion, omegas, history, settings, cache), repeat)
    sums = seconds(lambda: stepper.forces_of_contacts(system, motion, settings, body_pairs,
                                                      wall_pairs, results, stride), repeat)
    return {"bodies": n, "candidates": len(body_pairs), "broad": broad / n,
            "integration": kicks / n, "sums": sums / n, "pairs": pairs / n}


def main():
    print("bodies  candidates  per body and sub-step (us): broad phase  integration  sums  "
          "| repeated | pairs (shared)")
    row = None
    for n_side in (8, 18, 36):
        row = parts(lattice(n_side))
        repeated = row["broad"] + row["integration"] + row["sums"]
        print(f"{row['bodies']:6d}  {row['candidates']:10d}  {row['broad'] * 1e6:27.2f}  "
              f"{row['integration'] * 1e6:11.2f}  {row['sums'] * 1e6:4.2f}  | {repeated * 1e6:8.2f} "
              f"| {row['pairs'] * 1e6:.0f}", flush=True)
    print(f"METRIC substep_repeated_per_body "
          f"{(row['broad'] + row['integration'] + row['sums']) * 1e6:.2f} us")


if __name__ == "__main__":
    main()
