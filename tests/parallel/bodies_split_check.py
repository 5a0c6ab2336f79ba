"""Run under ``mpiexec -n N``: rigid bodies split over the processes by the place of their centre
(``riprap/solid/bodies_over_processes.py``) against the same bodies stepped by one process, on
every process; prints one line and exits 1 if any bit of the bodies, their forces, their springs
or their contact records differs, or if no body changed owner inside a batch of steps.

Scene: twelve rocks in two lanes sliding towards each other along a floor and past each other:
they cross the cuts inside a batch of steps (not only between batches, where the cuts are drawn
again), touching each other (contacts across a cut too; the check says how many), the floor and
the walls while they do.
"""
import sys

import numpy as np

from riprap.geometry import shapes
from riprap.parallel.communicator import world
from riprap.solid import walls
from riprap.solid.kernels.owned_step import owners_of
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

BATCHES = 8
STEPS_PER_BATCH = 400
COMPARED = ("positions", "quaternions", "velocities", "angular_momenta", "forces", "torques",
            "history_keys", "history_springs")


def scene(rocks) -> SolidSolver:
    solver = SolidSolver()
    keys = [solver.add_shape(rock) for rock in rocks]
    solver.add_material(Material(name="rock", density=2650.0, friction_coefficient=0.2,
                                 restitution=0.3, contact_penalty=1e7))
    rng = np.random.default_rng(5)
    for b in range(12):
        lane = b % 2
        x = 0.2 + 0.25 * (b // 2) + rng.uniform(-0.02, 0.02)
        y = 0.17 + 0.22 * lane
        q = rng.normal(size=4)
        solver.add_body(shape=keys[b % 2], material="rock", position=(x, y, 0.13 + 0.02 * lane),
                        orientation=q / np.linalg.norm(q),
                        velocity=(3.0 if lane == 0 else -3.0, 0.0, -0.5))
    solver.add_walls(walls.box(min=(0.0, 0.05, 0.0), max=(1.7, 0.56, 1.0), material="rock"))
    solver.time_step = 2.0 * solver.stable_time_step()
    return solver


def main() -> int:
    processes = world()
    rocks = [RigidShape.from_mesh(shapes.random_rock(size=0.16, elongation=1.3, seed=seed,
                                                     mesh_size=0.06)) for seed in (3, 4)]
    one, split = scene(rocks), scene(rocks)
    split.split_bodies_over(processes)
    changes, contacts, across = 0, 0, 0
    for batch in range(BATCHES):
        one.advance(STEPS_PER_BATCH)
        split.advance(STEPS_PER_BATCH)
        changes += split._split.owner_changes
        contacts = max(contacts, len(one.contacts))
        owners = owners_of(split.positions, split._split.cuts)
        pairs = one.contacts.body_j >= 0
        across += int((owners[one.contacts.body_i[pairs]] != owners[one.contacts.body_j[pairs]]).sum())
        for name in COMPARED:
            if not np.array_equal(getattr(one, name), getattr(split, name)):
                print(f"process {processes.rank}: {name} differs after batch {batch}")
                return 1
        for name in ("body_i", "body_j", "points", "normal_forces", "tangential_forces"):
            if not np.array_equal(getattr(one.contacts, name), getattr(split.contacts, name)):
                print(f"process {processes.rank}: contact records' {name} differ after {batch}")
                return 1
    crossed = changes      # the same on every process: each finds the owners alike
    print(f"process {processes.rank}: bit for bit over {BATCHES} batches, "
          f"{crossed} owner changes inside a batch, up to {contacts} contacts, {across} "
          f"contacts across a cut at the batches' ends")
    if crossed == 0 or across == 0:
        print("no body changed owner inside a batch or no contact across a cut: the check did "
              "not check what it is for")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
