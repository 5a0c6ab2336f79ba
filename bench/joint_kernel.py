"""Cost of one joint (issue 16): the joint kernel alone, on one thread, with and without friction.

The unit of examples/11_unit_breakage (a Core-Loc-like unit, H = 1 m, mesh_size 0.08 m: 5,739
joints) split by joints everywhere, its nodes moved at random by ``--jiggle`` (m, default 1 nm:
about half of the joints' points pressed, none damaged), then
``riprap.deformable.kernels.joints.joint_forces`` timed over ``--calls`` calls, best of
``--repeats``, with friction_angle 0 and 30 degrees. The friction's anchors move where the points
slide, as in a run.

Prints ns per joint for each, then
    METRIC joint_ns_friction_0 <ns> ns
    METRIC joint_ns_friction_30 <ns> ns
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from riprap.deformable.joints import FracturingBody, JointMaterial
from riprap.deformable.kernels import joints as joint_kernels
from riprap.deformable.material import ElasticMaterial
from riprap.geometry.armour_units import armour_unit


def nanoseconds_per_joint(unit, friction_angle: float, jiggle: float, calls: int,
                          repeats: int) -> tuple[float, int]:
    joints = JointMaterial(tensile_strength=3e6, cohesion=6e6, friction_angle=friction_angle,
                           fracture_energy_mode_i=100.0, fracture_energy_mode_ii=1000.0,
                           joint_penalty=3e11)
    body = FracturingBody(unit.nodes, unit.tets, ElasticMaterial(young_modulus=30e9), joints)
    body.positions += np.random.default_rng(1).normal(scale=jiggle, size=body.positions.shape)
    arguments = (body.positions, body.joints, body.joint_sizes, body._joint_properties,
                 body._joint_material_index, body.joint_damage, body.joint_broken,
                 body.joint_released, body.joint_friction_anchor, body._joint_buffer,
                 np.empty(joint_kernels.JOINT_SCRATCH_SIZE))
    joint_kernels.joint_forces(*arguments)            # compile
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            joint_kernels.joint_forces(*arguments)
        best = min(best, (time.perf_counter() - start) / calls)
    return best * 1e9 / len(body.joints), len(body.joints)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jiggle", type=float, default=1e-9)
    parser.add_argument("--calls", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    unit = armour_unit("core_loc_like", height=1.0, mesh_size=0.08).mesh
    figures = {}
    for friction_angle in (0.0, 30.0):
        figures[friction_angle], n_joints = nanoseconds_per_joint(
            unit, friction_angle, args.jiggle, args.calls, args.repeats)
        print(f"friction_angle {friction_angle:g}: {n_joints:,} joints, "
              f"{figures[friction_angle]:.1f} ns per joint (one thread)")
    print(f"METRIC joint_ns_friction_0 {figures[0.0]:.1f} ns")
    print(f"METRIC joint_ns_friction_30 {figures[30.0]:.1f} ns")


if __name__ == "__main__":
    main()
