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
phase + integration + sums, per body and sub-step: what one process does for each body). Before
it, ``METRIC substep_split_every_body``: what each process of a run split by the bodies' places
(``riprap/solid/bodies_over_processes.py``) still does for every body.
"""
import time

import numpy as np

from riprap.geometry import shapes
from riprap.solid.bodies_over_processes import BodiesOverProcesses
from riprap.solid.kernels import integrate, interactions, owned_step, stepper
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
            "integration": kicks / n, "sums": sums / n, "pairs": pairs / n,
            **split_parts(solids, repeat)}


class _Slabs:
    """Stands for ``size`` processes, seen from one in the middle (no messages are sent)."""
    size = 8
    rank = 3


def split_parts(solids: SolidSolver, repeat: int) -> dict:
    """The bodies split by the place of their centre over ``_Slabs.size`` processes
    (``riprap/solid/bodies_over_processes.py``), seen from a process in the middle: the work it
    does for every body (the half kicks and the drift, the owners, the angular velocities, the
    joined forces put back), per body, and the work for its own bodies and their near ones (the
    broad phase among the bodies near its slab, the sums of its own bodies' forces), per body it
    owns."""
    split = BodiesOverProcesses(_Slabs())
    split.cuts = split.balanced_cuts(solids)
    lower, upper = split.slab_of(_Slabs.rank)
    system, motion, history, settings = solids._kernel_state(0.0)
    n = solids.n_bodies
    owners = owned_step.owners_of(solids.positions, split.cuts)
    omegas = solids._omegas
    forces, torques = solids.forces.copy(), solids.torques.copy()

    def every_body():
        owned_step.first_half(system, motion, omegas, settings)
        owned_step.owners_of(solids.positions, split.cuts)
        integrate.angular_velocities(solids.quaternions, solids.angular_momenta,
                                     solids.inverse_principal_inertia)
        owned_step.second_half(system, motion, omegas, settings, forces, torques)

    repeated = seconds(every_body, repeat)     # zero-length steps: the state stays put
    body_pairs, wall_pairs, _, stride = owned_step.local_candidates(
        system, motion, settings, owners, _Slabs.rank, lower, upper)
    broad = seconds(lambda: owned_step.local_candidates(system, motion, settings, owners,
                                                        _Slabs.rank, lower, upper), repeat)
    results = np.zeros((len(body_pairs) + len(wall_pairs), interactions.C_SIZE))
    sums = seconds(lambda: stepper.forces_of_contacts(system, motion, settings, body_pairs,
                                                      wall_pairs, results, stride), repeat)
    own = max(int((owners == _Slabs.rank).sum()), 1)
    return {"split_every_body": repeated / n, "split_own": (broad + sums) / own}


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
        print(f"        split over {_Slabs.size}, process {_Slabs.rank}: every body "
              f"{row['split_every_body'] * 1e6:.2f} us a body | its own bodies' broad phase and "
              f"sums {row['split_own'] * 1e6:.2f} us a body it owns", flush=True)
    print(f"METRIC substep_split_every_body {row['split_every_body'] * 1e6:.2f} us")
    print(f"METRIC substep_repeated_per_body "
          f"{(row['broad'] + row['integration'] + row['sums']) * 1e6:.2f} us")


if __name__ == "__main__":
    main()
