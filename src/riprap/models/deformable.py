"""Deformable bodies in contact (the seed's Y3D-D) as a model of the run loop: a fixed
central-difference step counted in steps, frames with the stresses inside every body, and per
body the largest tensile principal stress of the run and where it was."""
from __future__ import annotations

import math
import time as wallclock

import numpy as np

from riprap.deformable.kernels import contact as contact_kernels
from riprap.deformable.kernels.bundles import SurfaceLaws
from riprap.deformable.stresses import principal_stresses, von_mises
from riprap.errors import InstabilityError, OverlapError, RiprapError
from riprap.limits import PROGRESS_PERIOD
from riprap.limits import START_OVERLAP_FRACTION as _START_OVERLAP_FRACTION
from riprap.models.base import Model
from riprap.models.body_frames import rigid_frame_fields
from riprap.outputs.stresses import DeformableFramesWriter, StressesWriter

__all__ = ["DeformableModel", "UnitStressRecord"]

#: The largest tensile stress of each body is looked for every this many steps (a fixed count, so
#: that units.csv does not depend on the machine's speed): an impact's peak lasts hundreds of steps.
RECORD_EVERY_STEPS = 50


class UnitStressRecord:
    """Per body, the largest tensile principal stress seen at the records so far (Pa), with the
    element, its centroid and the time."""

    def __init__(self, n_bodies: int):
        self.stress = np.full(n_bodies, -np.inf)
        self.element = np.full(n_bodies, -1, dtype=np.int64)
        self.point = np.zeros((n_bodies, 3))
        self.time = np.zeros(n_bodies)

    def update(self, body_index: int, sigma_1: np.ndarray, centroids: np.ndarray, time: float) -> None:
        worst = int(np.argmax(sigma_1))
        if sigma_1[worst] > self.stress[body_index]:
            self.stress[body_index] = sigma_1[worst]
            self.element[body_index] = worst
            self.point[body_index] = centroids[worst]
            self.time[body_index] = time


class DeformableModel(Model):
    """The deformable bodies of a scene, joined in a
    :class:`riprap.deformable.system.DeformableSystem`; with ``rigid`` (a
    :class:`riprap.models.rigid.RigidModel` of the scene's rigid bodies, when it has some) their
    solver is stepped with the same step, the rigid bodies' poses
    placed in the system before every step and the contact forces on them handed back as
    external loads."""

    kind = "riprap deformable run"
    name = "deformable"

    def __init__(self, system, *, rigid=None, body_names=None, case_numbers=None,
                 accepted_depths=None):
        self.system = system
        self.rigid = rigid
        n_rigid = rigid.solver.n_bodies if rigid is not None else 0
        self.case_numbers = case_numbers or (list(range(len(system.bodies))),
                                             list(range(len(system.bodies), len(system.bodies) + n_rigid)))
        self.accepted_depths = dict(accepted_depths or {})
        self.body_names = list(body_names or [b.name for b in system.bodies])
        self._chunk = 10
        self.records = UnitStressRecord(len(system.bodies))
        # (time, positions, sigma_1 of every element) when the largest tensile stress of the run
        # so far was found: the state the picture shows
        self._peak = None
        self._surfaces = None

    # ------------------------------------------------------------------ clock
    @property
    def time(self) -> float:
        return self.system.time

    @property
    def step_count(self) -> int:
        return self.system.step_count

    def _steps_at(self, time: float) -> int:
        return int(math.ceil(time / self.system.time_step - 1e-9))

    def reached(self, time: float) -> bool:
        return self.system.step_count >= self._steps_at(time)

    def last_time_step(self) -> float:
        return self.system.time_step

    def prepare(self, *, restarted: bool) -> None:
        self.system.time_step       # chosen now, from the stiffest element and contact
        if self.rigid is not None:
            self.place_rigid()
            if not restarted:
                self.rigid.check_start_overlaps()
        if not restarted:
            self.check_start_overlaps()
        self.record_stresses()

    def place_rigid(self, everything: bool = True) -> None:
        """Put the rigid bodies' poses and velocities in the system (only the moving ones'
        unless ``everything``)."""
        solver = self.rigid.solver
        self.system.set_rigid_poses(solver.rotation_matrices(), solver.positions,
                                    solver.velocities, solver.angular_velocities,
                                    moving=None if everything else ~solver.fixed)

    def _step(self, n: int) -> None:
        """n steps of the deformable bodies (and of the rigid ones, step by step, if any)."""
        if self.rigid is None:
            self.system.step(n)
            return
        solver = self.rigid.solver
        if solver.fixed.all():
            # fixed rigid bodies only (a bed, a slope, an underlayer): their surfaces stay where
            # they are, so the deformable bodies take all the steps in one call (a return to
            # Python every step cost about 50 microseconds, a fifth of a 3,000-tet unit's step)
            self.system.step(n)
            self._pass_rigid_loads()
            solver.advance(n)
            return
        for _ in range(n):
            self.place_rigid(everything=False)
            self.system.step(1)
            self._pass_rigid_loads()
            solver.advance(1)

    def _pass_rigid_loads(self) -> None:
        """The deformable bodies' contact forces on the rigid ones at the last step, as the rigid
        solver's external loads."""
        solver = self.rigid.solver
        forces, torques = self.system.rigid_loads(solver.positions)
        solver.external_loads[:, :3] = forces
        solver.external_loads[:, 3:] = torques

    def check_start_overlaps(self) -> None:
        """Refuse bodies that overlap each other or a wall at the start, naming them.

        The mean overlap depth of each touching pair is estimated from its contact force: the
        potential rises by one over the depth h of a boundary sub-tet, so depth = h F / (p A).
        Allowed: _START_OVERLAP_FRACTION of the smallest h, or 1.5 times the resting overlap a
        pack's contact history recorded for the pair."""
        s = self.system
        s._list_pairs()
        forces = np.zeros_like(s.positions)
        allowed = _START_OVERLAP_FRACTION * float(s.potential_heights.min())
        no_friction = np.zeros(max(len(s.triangles), len(s.contact_tets)))
        laws = SurfaceLaws(s.contact_penalty, 0.0, no_friction, no_friction, no_friction,
                           no_friction, no_friction)
        touching = {}
        for q in range(len(s._pairs)):
            pair = s._pairs[q:q + 1]
            weight, area = contact_kernels.pair_forces(s.positions, s.triangles, s.contact_tets, pair,
                                                       forces, s.velocities, s.masses, laws, 1.0,
                                                       np.zeros((1, 3)))
            if weight > 0.0 and area > 0.0:
                a, b = int(s.triangle_body[pair[0, 0]]), int(s.tet_body[pair[0, 1]])
                depth_weight = s.potential_heights[b] * weight / s.contact_penalty
                key = (min(a, b), max(a, b))
                total = touching.setdefault(key, [0.0, 0.0])
                total[0] += depth_weight
                total[1] += area
        for (a, b), (depth_weight, area) in sorted(touching.items()):
            depth = depth_weight / area
            if depth > max(allowed, 1.5 * self._accepted_depth(a, b)):
                raise OverlapError(
                    f"bodies '{self._body_name(a)}' and '{self._body_name(b)}' overlap at the start "
                    f"by about {depth:.3g} m (allowed {allowed:.3g} m); move them apart so that "
                    "they at most touch")
        for w in range(len(s.walls)):
            for k, body in enumerate(s.bodies):
                on_body = s.triangle_body == k
                frictionless_wall = np.r_[s.walls[w, :6], 0.0]
                total, area = contact_kernels.wall_forces(
                    s.positions, s.triangles[on_body], s.contact_tets[s.tet_body == k],
                    frictionless_wall, s.wall_depths[on_body], forces, s.velocities, s.masses,
                    laws, 1.0, np.zeros((len(s.triangles), 3)), np.zeros((len(s.contact_tets), 3)))
                if total <= 0.0 or area <= 0.0:
                    continue
                depth = s.potential_heights[k] * total / (s.contact_penalty * area)
                if depth > max(allowed, 1.5 * self._accepted_depth(k, -1 - w)):
                    raise OverlapError(
                        f"deformable body '{body.name}' starts {depth:.3g} m inside wall {w} (point "
                        f"{s.walls[w, :3].tolist()}, normal {s.walls[w, 3:6].tolist()}): move it "
                        "out so that it at most touches")

    def _case_number(self, index: int) -> int:
        """The case's number of a system body (walls stay -1 - w)."""
        if index < 0:
            return index
        deformable, rigid = self.case_numbers
        n = len(self.system.bodies)
        return deformable[index] if index < n else rigid[index - n]

    def _accepted_depth(self, a: int, b: int) -> float:
        i, j = self._case_number(a), self._case_number(b)
        return max(self.accepted_depths.get((i, j), 0.0), self.accepted_depths.get((j, i), 0.0))

    def _body_name(self, index: int) -> str:
        if index < len(self.system.bodies):
            return self.system.bodies[index].name
        return f"rigid body {self._case_number(index)}"

    def advance(self, until: float) -> None:
        system = self.system
        n = min(self._steps_at(until) - system.step_count, self._chunk)
        target = system.step_count + n
        tick = wallclock.perf_counter()
        for _ in range(max(n, 0)):          # every pass makes at least one step
            if system.step_count >= target:
                break
            next_record = (system.step_count // RECORD_EVERY_STEPS + 1) * RECORD_EVERY_STEPS
            self._step(min(target, next_record) - system.step_count)
            if system.step_count % RECORD_EVERY_STEPS == 0:
                self.record_stresses()
        if system.step_count < target:
            raise RiprapError(f"the deformable bodies made {n - (target - system.step_count)} of "
                              f"{n} steps at t = {system.time:.6g} s and stopped; report it")
        elapsed = wallclock.perf_counter() - tick
        self._chunk = max(1, min(1_000_000, int(n * PROGRESS_PERIOD / max(elapsed, 1e-6))))

    def _check_finite(self) -> None:
        """Stop with the failure checkpoint once a node's position or velocity is not finite
        (an element gone NaN does not invert, so the kernel's own check does not see it)."""
        s = self.system
        bad = ~(np.isfinite(s.positions).all(axis=1) & np.isfinite(s.velocities).all(axis=1))
        if bad[:s.n_deformable_nodes].any():
            node = int(np.argmax(bad))
            k = int(np.searchsorted(s.node_offsets, node, side="right") - 1)
            raise InstabilityError(
                f"deformable body '{s.bodies[k].name}' has a non-finite state at t = {s.time:.6g} s "
                f"(node {node - int(s.node_offsets[k])}, step {s.step_count}); the bodies moved "
                "more than the step can carry: check the start velocities and the loads")

    def record_stresses(self) -> None:
        """Look for each body's largest tensile stress now (and stop a non-finite state)."""
        self._check_finite()
        before = self.records.stress.max()
        all_sigma_1 = []
        for k, body in enumerate(self.system.bodies):
            sigma_1 = principal_stresses(body.cauchy_stresses())[:, 0]
            centroids = body.positions[body.elements.corner_tets].mean(axis=1)
            self.records.update(k, sigma_1, centroids, self.system.time)
            all_sigma_1.append(sigma_1)
        if self.records.stress.max() > before:
            self._peak = (self.system.time, self.system.positions.copy(), np.concatenate(all_sigma_1))

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        s = self.system
        return {"clock": np.array([s.time, float(s.step_count), s.time_step]),
                "positions": s.positions.copy(), "velocities": s.velocities.copy(),
                **s.contact_state(),
                "record_stress": self.records.stress.copy(),
                "record_element": self.records.element.copy(),
                "record_point": self.records.point.copy(), "record_time": self.records.time.copy(),
                **s.joint_state(),
                **({f"rigid_{key}": value for key, value in self.rigid.solver.state_arrays().items()}
                   if self.rigid is not None else {})}

    def load_state_arrays(self, arrays: dict) -> None:
        self.system.restore_state(arrays)
        self.records.stress[:] = arrays["record_stress"]
        self.records.element[:] = arrays["record_element"]
        self.records.point[:] = arrays["record_point"]
        self.records.time[:] = arrays["record_time"]
        if self.rigid is not None:
            solver = self.rigid.solver
            solver.load_state_arrays(
                {key[len("rigid_"):]: value for key, value in arrays.items() if key.startswith("rigid_")})
            solver.clear_contact_records()
            self.place_rigid()

    def checkpoint_content(self, state: dict) -> tuple[dict, dict]:
        arrays = dict(state)
        arrays["reference_nodes"] = np.concatenate([b.elements.reference_nodes for b in self.system.bodies])
        rigid = self.rigid.solver.n_bodies if self.rigid is not None else 0
        return arrays, {"bodies": self.body_names, "rigid_bodies": rigid}

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        problems = []
        rigid = self.rigid.solver.n_bodies if self.rigid is not None else 0
        if metadata.get("rigid_bodies", 0) != rigid:
            problems.append(f"it has {metadata.get('rigid_bodies', 0)} rigid bodies, the case {rigid}")
        if metadata.get("bodies") != self.body_names:
            problems.append(f"its bodies {metadata.get('bodies')} differ from the case's {self.body_names}")
        else:
            reference = np.concatenate([b.elements.reference_nodes for b in self.system.bodies])
            if not np.array_equal(arrays["reference_nodes"], reference):
                problems.append("the bodies were meshed differently")
        if problems:
            raise RiprapError(f"{path}: cannot restart this case from that checkpoint: "
                              + "; ".join(problems))

    def restore(self, arrays: dict) -> None:
        self.load_state_arrays(arrays)

    # ------------------------------------------------------------------ outputs
    def frame_fields(self) -> dict:
        """Points, corner tets and the per-element stress fields of all bodies (ParaView names)."""
        s = self.system
        stresses = np.concatenate([b.cauchy_stresses() for b in s.bodies])
        principal = principal_stresses(stresses)
        corner_tets = np.concatenate([b.elements.corner_tets + s.node_offsets[k]
                                      for k, b in enumerate(s.bodies)])
        reference = np.concatenate([b.elements.reference_nodes for b in s.bodies]
                                   + [s.positions[s.n_deformable_nodes:]])
        body_of_element = np.repeat(np.arange(len(s.bodies)), [b.n_elements for b in s.bodies])
        fragment, damage = self._element_fracture_fields()
        cell_data = {
            "body": body_of_element,
            "fragment": fragment, "damage": damage,
            "sigma_1": principal[:, 0], "sigma_2": principal[:, 1], "sigma_3": principal[:, 2],
            "differential_stress": principal[:, 0] - principal[:, 2],
            "von_mises": von_mises(stresses),
            "jacobian": s.jacobians.copy(),
        }
        for name, (i, j) in {"sigma_xx": (0, 0), "sigma_yy": (1, 1), "sigma_zz": (2, 2),
                             "sigma_xy": (0, 1), "sigma_yz": (1, 2), "sigma_zx": (2, 0)}.items():
            cell_data[name] = stresses[:, i, j]
        point_data = {"velocity": s.velocities.copy(), "displacement": s.positions - reference,
                      "contact_force": s.contact_forces.copy()}
        return {"points": s.positions.copy(), "cells": corner_tets, "cell_data": cell_data,
                "point_data": point_data}

    def _element_fracture_fields(self):
        """Per element: its fragment (numbered from 0 in each body, largest first; 0 in a body
        without joints) and the largest damage of the joints on its faces (0 .. 1)."""
        s = self.system
        fragment = np.zeros(len(s.elements), dtype=np.int64)
        damage = np.zeros(len(s.elements))
        for k in s.fracturing_bodies:
            body = s.bodies[k]
            first = s.element_offsets[k]
            fragment[first:first + body.n_elements] = body.fragment_table()["element_fragment"]
            joint_damage = body.joint_damage.max(axis=1)
            local = np.zeros(body.n_elements)
            np.maximum.at(local, body.joint_tets[:, 0], joint_damage)
            np.maximum.at(local, body.joint_tets[:, 1], joint_damage)
            damage[first:first + body.n_elements] = local
        return fragment, damage

    def crack_fields(self) -> dict:
        """The damaged joints of all bodies as triangles (their A faces, now): ``damage`` (the
        largest of the three points), ``broken`` (1 or 0), ``opening`` (m, mean normal
        separation of the faces), ``body``."""
        s = self.system
        if not s.fracturing_bodies:
            return {"points": np.zeros((0, 3)), "cells": np.zeros((0, 3), dtype=np.int64),
                    "cell_data": {}}
        damaged = np.flatnonzero(s.joint_damage.max(axis=1) > 0.0)
        joints = s.joints[damaged]
        faces_a = s.positions[joints[:, :3]]
        faces_b = s.positions[joints[:, 3:]]
        normals = np.cross(faces_a[:, 1] - faces_a[:, 0], faces_a[:, 2] - faces_a[:, 0])
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
        opening = np.einsum("ij,ij->i", (faces_b - faces_a).mean(axis=1), normals)
        joint_body = np.repeat(np.asarray(s.fracturing_bodies),
                               np.diff(s.joint_offsets))[damaged]
        return {"points": faces_a.reshape(-1, 3),
                "cells": np.arange(3 * len(damaged), dtype=np.int64).reshape(-1, 3),
                "cell_data": {"damage": s.joint_damage[damaged].max(axis=1),
                              "broken": s.joint_broken[damaged].astype(np.int64),
                              "opening": opening, "body": joint_body}}

    def unit_rows(self) -> list[dict]:
        """One row per body for ``units.csv``."""
        rows = []
        for k, body in enumerate(self.system.bodies):
            final = float(principal_stresses(body.cauchy_stresses())[:, 0].max())
            strength = body.material.tensile_strength
            point = self.records.point[k]
            rows.append({
                "body": k, "name": self.body_names[k], "mass_kg": body.mass,
                "elements": body.n_elements, "element_type": body.element_type,
                "max_tensile_stress_Pa": self.records.stress[k],
                "max_tensile_element": int(self.records.element[k]),
                "max_tensile_x_m": point[0], "max_tensile_y_m": point[1], "max_tensile_z_m": point[2],
                "max_tensile_time_s": self.records.time[k],
                "final_max_tensile_stress_Pa": final,
                "tensile_strength_Pa": strength if strength is not None else float("nan"),
                "stress_over_strength": (self.records.stress[k] / strength
                                         if strength is not None else float("nan")),
                **(body.breakage_summary() if k in self.system.fracturing_bodies
                   else {"broken_area_m2": 0.0, "fragments": 1,
                         "largest_fragment_mass_fraction": 1.0}),
            })
        return rows

    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        return [DeformableFramesWriter(self, paraview=paraview),
                StressesWriter(self, picture=picture)]

    def rigid_frame(self):
        """(frame fields, contacts) of the rigid bodies now (with rigid bodies only)."""
        solver = self.rigid.solver
        return rigid_frame_fields(solver), solver.contacts

    def peak_state(self):
        """(time, positions, sigma_1 of every element) when the largest tensile stress of the run
        so far was found; None before the first record."""
        return self._peak

    def final_state(self):
        """(time, positions, sigma_1 of every element) now."""
        return (self.system.time, self.system.positions.copy(),
                np.concatenate([principal_stresses(b.cauchy_stresses())[:, 0]
                                for b in self.system.bodies]))

    def fragment_rows(self) -> list[dict]:
        """Every piece of every cracking body, a body of its own: the unit it came from, its tets,
        volume, mass, mass fraction of the unit, centre of mass, velocity (``fragments.csv``)."""
        rows = []
        for k in self.system.fracturing_bodies:
            table = self.system.bodies[k].fragment_table()
            for f in range(len(table["mass"])):
                (x, y, z), (vx, vy, vz) = table["centre"][f], table["velocity"][f]
                rows.append({"body": k, "name": self.body_names[k], "fragment": f,
                             "elements": int(table["elements"][f]),
                             "volume_m3": float(table["volume"][f]),
                             "mass_kg": float(table["mass"][f]),
                             "mass_fraction": float(table["mass_fraction"][f]),
                             "x_m": float(x), "y_m": float(y), "z_m": float(z),
                             "vx_m_s": float(vx), "vy_m_s": float(vy), "vz_m_s": float(vz)})
        return rows

    def progress_text(self) -> str:
        s = self.system
        speed = float(np.linalg.norm(s.velocities, axis=1).max(initial=0.0))
        cracks = ""
        if s.fracturing_bodies:
            cracks = (f"  broken joints {int(s.joint_broken.sum())}  pieces "
                      f"{int(s.first_rigid_group)}")
        return (f"largest sigma1 {self.records.stress.max() / 1e6:.3g} MPa  fastest node "
                f"{speed:.3g} m/s  dt {s.time_step:.2e} s{cracks}")

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        s = self.system
        rigid = self.rigid.solver.n_bodies if self.rigid is not None else 0
        return {"time_step": s.time_step, "bodies": len(s.bodies) + rigid,
                "element_steps_per_second": steps * len(s.elements) / max(wall_time, 1e-9),
                "kinetic_energy": s.kinetic_energy(),
                "max_speed": float(np.linalg.norm(s.velocities, axis=1).max(initial=0.0)),
                "max_tensile_stress": float(self.records.stress.max()),
                **({"broken_joints": int(s.joint_broken.sum()),
                    "broken_area": float(sum(s.bodies[k].broken_area for k in s.fracturing_bodies)),
                    "pieces": int(s.first_rigid_group), "fracture_energy": -float(s.joint_work[0])}
                   if s.fracturing_bodies else {})}

    def failure_advice(self, good: dict) -> str:
        return ("An element inverted or a node's state became non-finite: the time step may be "
                "too long for the contact penalty, or the loads or start velocities too large for "
                "the mesh; see units.csv and the last frames.")
