"""Run under ``mpiexec -n N`` with the periodic axis (0 or 1) as argument: rigid bodies in a
periodic strip (``SolidSolver.set_periodic``), split over the processes by the x of their centre
(``riprap/solid/bodies_over_processes.py``), against the same bodies stepped by one process, on
every process; prints one line with "bit for bit" and exits 0, or exits 1 if any bit of the
bodies, their forces, their springs or their contact records differs, or if the scene did not do
what it is for (no body wrapped, no contact across the boundary, no body changing owner).

Scene: ten cubes (random orientations) in two lanes on a floor, the lanes sliding in opposite
directions along the periodic axis, so that they pass each other and cross the periodic boundary
inside a batch of steps, touching each other (across the boundary too) and the floor. With x
periodic the boundary is also where the first and last processes' slabs meet, so the pairs
across it join bodies owned by rank 0 and the last rank.

Run without ``mpiexec`` (one process) it steps the split on that one process, which compiles and
caches every kernel of the split: two processes compiling the same kernel at once could write
numba's cache file under each other (a segmentation fault was seen after such a run), so the test
runs it so before ``mpiexec``.
"""
import sys

import numpy as np

from riprap.geometry import shapes
from riprap.parallel.communicator import world
from riprap.solid import walls
from riprap.solid.bodies_over_processes import BodiesOverProcesses
from riprap.solid.kernels.owned_step import owners_of
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

BATCHES = 8
STEPS_PER_BATCH = 100
COMPARED = ("positions", "quaternions", "velocities", "angular_momenta", "forces", "torques",
            "history_keys", "history_springs")
RECORDS = ("body_i", "body_j", "points", "normal_forces", "tangential_forces")
LOWER, UPPER = 0.0, 0.6           # the periodic strip (m)
ACROSS = 0.8                      # the other horizontal direction's walls: [0, ACROSS] m


def scene(cube, axis) -> SolidSolver:
    solver = SolidSolver()
    solver.add_shape(cube)
    solver.add_material(Material(name="rock", density=2400.0, friction_coefficient=0.3,
                                 restitution=0.3, contact_penalty=1e7))
    solver.set_periodic(axis, LOWER, UPPER)
    other = 1 - axis
    rng = np.random.default_rng(7)
    for b in range(10):
        lane = b % 2
        place = np.zeros(3)
        place[axis] = 0.03 + 0.12 * (b // 2) + rng.uniform(-0.01, 0.01)
        place[other] = 0.33 + 0.1 * lane
        place[2] = 0.08 + 0.01 * lane
        velocity = np.zeros(3)
        velocity[axis] = 2.5 if lane == 0 else -2.5
        velocity[other] = 0.3 if lane == 0 else -0.3
        velocity[2] = -0.3
        q = rng.normal(size=4)
        solver.add_body(shape=0, material="rock", position=place,
                        orientation=q / np.linalg.norm(q), velocity=velocity)
    normal = np.zeros(3)
    normal[other] = 1.0
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="rock"))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=normal, material="rock"))
    solver.add_walls(walls.plane(point=ACROSS * normal, normal=-normal, material="rock"))
    solver.time_step = 2.0 * solver.stable_time_step()
    return solver


def first_difference(one, split) -> str | None:
    """The name of the first array of the bodies or their contact records in which the two
    solvers differ in any bit, or None."""
    arrays = [(name, getattr(one, name), getattr(split, name)) for name in COMPARED]
    arrays += [(f"contact records' {name}", getattr(one.contacts, name),
                getattr(split.contacts, name)) for name in RECORDS]
    return next((name for name, a, b in arrays if not np.array_equal(a, b)), None)


def main() -> int:
    axis = int(sys.argv[1])
    processes = world()
    cube = RigidShape.from_mesh(shapes.cube(side=0.1, mesh_size=0.05))
    one, split = scene(cube, axis), scene(cube, axis)
    split.split_bodies_over(processes)
    alone = processes.size == 1
    if alone:
        split._split = BodiesOverProcesses(processes)     # the split's kernels, on one process
    if not alone:
        # a fixed cut that bodies cross inside a batch: along the strip through its boundary
        # with x periodic; with y periodic at x = 0.25 m, which the first lane's cubes (pushed
        # apart from the second's at the start, from x = 0.33 m) pass in batches 1-3. The
        # balanced cuts follow the processes' measured pace: on a busy machine they may sit
        # where no body crosses in 800 steps, and the check would not check an owner change
        cut = np.array([0.5 * (LOWER + UPPER) if axis == 0 else 0.25])
        balanced = split._split.balanced_cuts

        def fixed(solver):
            balanced(solver)        # its bookkeeping (the bodies' weights) as ever
            return cut

        split._split.balanced_cuts = fixed
    changes, across, wrapped = 0, 0, 0
    for batch in range(BATCHES):
        before = one.positions[:, axis].copy()
        one.advance(STEPS_PER_BATCH)
        split.advance(STEPS_PER_BATCH)
        changes += split._split.owner_changes
        # a body moving at about 2.5 m/s one way jumps back by most of the period when it wraps
        wrapped += int((np.abs(one.positions[:, axis] - before) > 0.5 * (UPPER - LOWER)).sum())
        pairs = one.contacts.body_j >= 0
        gap = np.abs(one.positions[one.contacts.body_i[pairs], axis]
                     - one.positions[one.contacts.body_j[pairs], axis])
        across += int((gap > 0.5 * (UPPER - LOWER)).sum())
        differs = first_difference(one, split)
        if differs:
            print(f"process {processes.rank}: {differs} differ after batch {batch}")
            return 1
    owners = owners_of(split.positions, split._split.cuts)
    print(f"process {processes.rank}: axis {axis} bit for bit over {BATCHES} batches, {wrapped} "
          f"wraps, {across} contacts across the boundary at the batches' ends, {changes} owner "
          f"changes inside a batch, owners now {np.bincount(owners).tolist()}")
    if wrapped == 0 or across == 0 or (changes == 0 and not alone):
        print("no body wrapped, no contact across the boundary or no owner change: the check did "
              "not check what it is for")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
