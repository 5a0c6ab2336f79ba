"""Speed of deformable bodies (issue 14).

(a) internal forces and the central-difference update only: a block of 4-node tets
    (default 50^3 cells x 6 = 750,000 tets), tet-steps per second on 1 and 2 threads;
(b) the unit-impact case with contact: a Core-Loc-like unit (H = 1 m, ~2,000 tets, concrete)
    dropped onto two others lying on a floor, tet-steps per second on all cores;
(c) the seed's headline ratio: the same unit dropped on a floor, rigid (riprap's rigid solver)
    against deformable, wall seconds for the same simulated time.

Last line: METRIC tet_steps_per_s <value> 1/s for (a), 4-node tets, all cores, best of repeats.
"""
from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np

from riprap.deformable import DeformableBody, ElasticMaterial, box_mesh
from riprap.deformable.system import DeformableSystem
from riprap.geometry.armour_units import armour_unit
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

CONCRETE = ElasticMaterial(name="concrete", density=2400.0, young_modulus=30e9, poisson_ratio=0.2)
FLOOR = [((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))]


def internal_forces_speed(cells: int, steps: int, repeats: int) -> dict[int, float]:
    nodes, tets = box_mesh((1.0, 1.0, 1.0), (cells, cells, cells))
    body = DeformableBody(nodes, tets, CONCRETE)
    body.velocities[:] = np.random.default_rng(1).normal(scale=1e-3, size=body.velocities.shape)
    body.step(2)                                  # compile
    print(f"(a) block of {len(tets):,} tets, {len(body.positions):,} nodes, "
          f"step {body.time_step:.3g} s")
    result = {}
    for threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        numba.set_num_threads(threads)
        best = np.inf
        for _ in range(repeats):
            start = time.perf_counter()
            body.step(steps)
            best = min(best, time.perf_counter() - start)
        result[threads] = steps * len(tets) / best
        print(f"    {threads} thread(s): {best / steps * 1e3:.2f} ms/step, "
              f"{result[threads]:.3g} tet-steps/s")
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return result


def _unit(height: float = 1.0):
    return armour_unit("core_loc_like", height=height).mesh


def unit_impact_speed(simulated: float) -> float:
    mesh = _unit()
    base = mesh.nodes - np.array([0.0, 0.0, mesh.nodes[:, 2].min()])
    extent = np.ptp(base, axis=0)
    bodies = [
        DeformableBody(base + np.array([-0.55 * extent[0], 0.0, 0.001]), mesh.tets, CONCRETE, name="left"),
        DeformableBody(base + np.array([0.55 * extent[0], 0.0, 0.001]), mesh.tets, CONCRETE, name="right"),
        DeformableBody(base + np.array([0.0, 0.0, extent[2] + 0.005]), mesh.tets, CONCRETE, name="dropped"),
    ]
    bodies[2].velocities[:, 2] = -2.0      # lands within 3 ms
    system = DeformableSystem(bodies, walls=FLOOR, gravity=(0.0, 0.0, -9.81))
    n_tets = sum(b.n_elements for b in bodies)
    steps = int(simulated / system.time_step)
    system.step(2)
    largest = 0.0
    start = time.perf_counter()
    for _ in range(steps // 100):
        system.step(100)
        largest = max(largest, system.contact_totals[-1])
    wall = time.perf_counter() - start
    steps = 100 * (steps // 100)
    rate = steps * n_tets / wall
    print(f"(b) unit impact: 3 units x {bodies[0].n_elements} tets, step {system.time_step:.3g} s, "
          f"{steps} steps ({simulated * 1e3:.0f} ms) in {wall:.2f} s: {rate:.3g} tet-steps/s, "
          f"{system.pair_listings} pair listings, largest unit-on-unit contact force "
          f"{largest / 1e3:.3g} kN (sampled every 100 steps)")
    return rate


def _rigid_drop(mesh, drop: float, simulated: float, penalty: float):
    solver = SolidSolver(gravity=(0.0, 0.0, -9.81))
    shape = RigidShape.from_mesh(mesh)
    k = solver.add_shape(shape)
    m = solver.add_material(Material(name="concrete", density=2400.0, contact_penalty=penalty))
    solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="concrete"))
    lowest = (shape.mesh.nodes @ shape.frame_rotation.T)[:, 2].min()
    solver.add_body(shape=k, material=m, position=(0.0, 0.0, drop - lowest))
    solver.finalize()
    solver.advance(2)
    rigid_steps = int(simulated / solver.time_step)
    start = time.perf_counter()
    solver.advance(rigid_steps)
    return rigid_steps, solver.time_step, time.perf_counter() - start


def rigid_against_deformable(simulated: float) -> float:
    mesh = _unit()
    drop = 0.05
    # the deformable contact penalty is Young's modulus; the rigid run takes the same, then the
    # rigid solver's default (1 GPa), which allows a longer step
    rigid_steps, rigid_step, rigid_wall = _rigid_drop(mesh, drop, simulated, CONCRETE.young_modulus)
    soft_steps, soft_step, soft_wall = _rigid_drop(mesh, drop, simulated, Material(name="x").contact_penalty)

    nodes = mesh.nodes - np.array([0.0, 0.0, mesh.nodes[:, 2].min() - drop])
    body = DeformableBody(nodes, mesh.tets, CONCRETE, name="unit")
    system = DeformableSystem([body], walls=FLOOR, gravity=(0.0, 0.0, -9.81))
    system.step(2)
    steps = int(simulated / system.time_step)
    start = time.perf_counter()
    system.step(steps)
    deformable_wall = time.perf_counter() - start
    ratio = deformable_wall / rigid_wall
    print(f"(c) one unit ({len(mesh.tets)} tets) dropped {drop * 100:.0f} cm on a floor, "
          f"{simulated * 1e3:.0f} ms simulated: deformable {steps} steps of {system.time_step:.3g} s "
          f"in {deformable_wall:.2f} s; rigid, same penalty (30 GPa), {rigid_steps} steps of "
          f"{rigid_step:.3g} s in {rigid_wall:.2f} s: deformable / rigid = {ratio:.1f}; rigid with its "
          f"default penalty (1 GPa), {soft_steps} steps of {soft_step:.3g} s in {soft_wall:.2f} s: "
          f"deformable / rigid = {deformable_wall / soft_wall:.1f} (the seed: about 50)")
    return ratio


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=50, help="block cells per edge for (a)")
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--simulated", type=float, default=0.02, help="s simulated in (b) and (c)")
    args = parser.parse_args()
    print(f"cores {os.cpu_count()}, numba threads {numba.config.NUMBA_NUM_THREADS}, "
          f"load {os.getloadavg()[0]:.2f}")
    speeds = internal_forces_speed(args.cells, args.steps, args.repeats)
    unit_impact_speed(args.simulated)
    rigid_against_deformable(args.simulated)
    print(f"METRIC tet_steps_per_s {speeds[max(speeds)]:.4g} 1/s")


if __name__ == "__main__":
    main()
