"""Several deformable bodies with contact between them and with walls, advanced together.

The bodies' nodes are joined into one set of arrays (each body's ``positions``, ``velocities``,
loads and supports become views into them), so one compiled loop steps everything: contact forces
(``riprap/deformable/kernels/contact.py``), internal forces and the central-difference update.
The (boundary triangle, tet) pairs that may touch are listed from boxes grown by a skin and
listed again only after some node has moved half the skin, so contact costs a sweep over the
listed pairs per step.

Contact uses the 4-node corner mesh of each body; 10-node bodies are refused here until their
curved faces take part (their corner nodes carry 1/36 of a tet's mass each, so forces put on them
alone would set a tiny stable step).
"""
from __future__ import annotations

import math

import numpy as np

from riprap.deformable.body import (PARALLEL_POINTS, TIME_STEP_SAFETY, DeformableBody,
                                    material_table, stable_step_for)
from riprap.deformable.kernels import contact as contact_kernels
from riprap.deformable.kernels import finite_strain
from riprap.errors import CaseFileError
from riprap.geometry.meshing import boundary_tet_heights
from riprap.geometry.tetmesh import TetMesh


class DeformableSystem:
    """Deformable bodies in contact with each other and with half-space walls.

    Parameters
    ----------
    bodies : list of DeformableBody
        4-node bodies; their state arrays become views into the system's.
    walls : list of (point, outward normal)
        Half-spaces {x : n . (x - point) < 0} the bodies cannot enter (a floor: point (0, 0, 0),
        normal (0, 0, 1)).
    contact_penalty : float or None
        p of Munjiza's potential (Pa); default the smallest Young's modulus of the bodies. The
        stiffer the penalty, the smaller the overlaps and the time step.
    gravity : 3 floats
        m/s^2, for every body.
    mass_damping : float
        1/s, for every body (0 for physics runs).
    """

    def __init__(self, bodies, walls=(), *, contact_penalty=None, gravity=(0.0, 0.0, 0.0),
                 mass_damping: float = 0.0):
        bodies = list(bodies)
        if not bodies:
            raise CaseFileError("a deformable system needs at least one body")
        for body in bodies:
            if not isinstance(body, DeformableBody):
                raise CaseFileError(f"{body!r} is not a DeformableBody")
            if body.element_type != "tet4":
                raise CaseFileError(
                    f"deformable body '{body.name}': contact of {body.element_type} bodies is not "
                    "available yet; use element_type = 'tet4' for bodies in contact")
        self.bodies = bodies
        if contact_penalty is None:
            contact_penalty = min(body.material.young_modulus for body in bodies)
        if not (contact_penalty > 0 and math.isfinite(contact_penalty)):
            raise CaseFileError(f"contact_penalty = {contact_penalty!r} must be > 0 Pa")
        self.contact_penalty = float(contact_penalty)
        self.walls = np.zeros((len(walls), 6))
        for w, (point, normal) in enumerate(walls):
            normal = np.asarray(normal, dtype=np.float64)
            length = np.linalg.norm(normal)
            if not length > 0:
                raise CaseFileError(f"wall {w}: its normal {normal.tolist()} has zero length")
            self.walls[w, :3] = point
            self.walls[w, 3:] = normal / length
        self.gravity = np.asarray(gravity, dtype=np.float64).reshape(3).copy()
        self.mass_damping = float(mass_damping)
        self._join()
        self.time = 0.0
        self.step_count = 0
        self._time_step = None
        self.contact_totals = np.zeros(len(self.walls) + 1)
        self._pairs = np.zeros((0, 2), dtype=np.int64)
        self._listed_positions = np.full_like(self.positions, np.inf)
        self.pair_listings = 0

    # ------------------------------------------------------------------ assembly
    def _join(self) -> None:
        bodies = self.bodies
        node_counts = [len(b.positions) for b in bodies]
        self.node_offsets = np.r_[0, np.cumsum(node_counts)].astype(np.int64)
        element_counts = [b.n_elements for b in bodies]
        self.element_offsets = np.r_[0, np.cumsum(element_counts)].astype(np.int64)
        for name in ("positions", "velocities", "external_forces", "contact_forces",
                     "prescribed_velocities", "nodal_forces", "constrained"):
            joined = np.concatenate([getattr(b, name) for b in bodies])
            setattr(self, name, joined)
            for k, body in enumerate(bodies):
                setattr(body, name, joined[self.node_offsets[k]:self.node_offsets[k + 1]])
        self.masses = np.concatenate([b.masses for b in bodies])
        self.elements = np.concatenate([b.elements.elements + self.node_offsets[k]
                                        for k, b in enumerate(bodies)])
        self.tet4_gradients = np.concatenate([b.elements.tet4_gradients for b in bodies])
        self.gradients = np.concatenate([b.elements.gradients for b in bodies])
        self.weights = np.concatenate([b.elements.weights for b in bodies])
        self.materials = material_table([b.material for b in bodies])
        self.element_material = np.concatenate([np.full(b.n_elements, k, dtype=np.int64)
                                                for k, b in enumerate(bodies)])
        self.jacobians = np.ones(len(self.elements))
        self._element_forces = np.zeros((len(self.elements), 4, 3))
        flat = self.elements.ravel()
        order = np.argsort(flat, kind="stable")
        counts = np.bincount(flat, minlength=len(self.positions))
        self._offsets = np.r_[0, np.cumsum(counts)].astype(np.int64)
        self._slots = order.astype(np.int64)
        # contact surfaces: boundary triangles and the tets that touch the boundary
        triangles, tets, triangle_body, tet_body, depths = [], [], [], [], []
        for k, body in enumerate(bodies):
            mesh = TetMesh(body.elements.reference_nodes, body.elements.corner_tets, name=body.name)
            faces = mesh.boundary_faces()
            boundary_nodes = np.zeros(len(mesh.nodes), dtype=bool)
            boundary_nodes[faces.ravel()] = True
            layer = np.flatnonzero(boundary_nodes[mesh.tets].any(axis=1))
            offset = self.node_offsets[k]
            triangles.append(faces + offset)
            tets.append(mesh.tets[layer] + offset)
            triangle_body.append(np.full(len(faces), k, dtype=np.int64))
            tet_body.append(np.full(len(layer), k, dtype=np.int64))
            heights = boundary_tet_heights(mesh)
            depths.append(np.full(len(faces), float(np.median(heights))))
            body._contact_height = float(np.percentile(heights, 10))
        self.triangles = np.concatenate(triangles)
        self.contact_tets = np.concatenate(tets)
        self.triangle_body = np.concatenate(triangle_body)
        self.tet_body = np.concatenate(tet_body)
        self.wall_depths = np.concatenate(depths)
        self.skin = 0.5 * min(b._contact_height for b in bodies)

    # ------------------------------------------------------------------ time step
    def stable_time_step(self) -> float:
        """2 / sqrt(omega_elements^2 + omega_contact^2): the stiffest element and the stiffest
        contact on one node (penalty times the node's share of surface over the potentials' depth)."""
        omega_elements = 0.0
        for body in self.bodies:
            body.stable_time_step()
            omega_elements = max(omega_elements, body._stiffest_frequency)
        # from the reference geometry, so that a run and its restart take the same step
        reference = np.concatenate([b.elements.reference_nodes for b in self.bodies])
        corners = reference[self.triangles]
        areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                              corners[:, 2] - corners[:, 0]), axis=1)
        node_area = np.zeros(len(reference))
        np.add.at(node_area, self.triangles.ravel(), np.repeat(areas / 3.0, 3))
        heights = np.array([b._contact_height for b in self.bodies])
        node_body = np.repeat(np.arange(len(self.bodies)), np.diff(self.node_offsets))
        stiffness = self.contact_penalty * node_area * 2.0 / heights[node_body]
        omega_contact = float(np.sqrt(stiffness / self.masses).max())
        damping = max(b.material.viscous_time_constant for b in self.bodies)
        return stable_step_for(math.hypot(omega_elements, omega_contact), damping, self.mass_damping)

    @property
    def time_step(self) -> float:
        if self._time_step is None:
            self._time_step = TIME_STEP_SAFETY * self.stable_time_step()
        return self._time_step

    @time_step.setter
    def time_step(self, value: float) -> None:
        stable = self.stable_time_step()
        if not (0 < value <= stable and math.isfinite(value)):
            raise CaseFileError(f"time_step = {value!r} s must be in (0, {stable:.4g}] s, the stable "
                                "step of the stiffest element and contact (masses are never scaled "
                                "to hide this)")
        self._time_step = float(value)

    # ------------------------------------------------------------------ stepping
    def _list_pairs(self) -> None:
        self._pairs = contact_kernels.candidate_pairs(self.positions, self.triangles,
                                                      self.triangle_body, self.contact_tets,
                                                      self.tet_body, self.skin)
        self._listed_positions[:] = self.positions
        self.pair_listings += 1

    def step(self, n_steps: int = 1) -> None:
        """Advance ``n_steps`` steps; raises InstabilityError naming an element that inverts."""
        dt = self.time_step
        parallel = len(self.elements) >= PARALLEL_POINTS
        remaining = int(n_steps)
        while remaining > 0:
            contact = (self.triangles, self.contact_tets, self.wall_depths, self._pairs,
                       self.contact_penalty, self.walls, self._listed_positions, self.skin,
                       self.contact_totals)
            done, status, worst, value = finite_strain.advance_steps(
                remaining, parallel, self.positions, self.velocities, self.elements,
                self.tet4_gradients, self.gradients, self.weights, self.materials,
                self.element_material, self._element_forces, self.jacobians, self._offsets,
                self._slots, self.masses, self.external_forces, self.contact_forces, self.gravity,
                self.mass_damping, self.constrained, self.prescribed_velocities, dt,
                self.nodal_forces, contact)
            self.step_count += int(done)
            self.time += int(done) * dt
            for body in self.bodies:
                body.time = self.time
                body.step_count = self.step_count
            remaining -= int(done)
            if status == finite_strain.REBUILD_CONTACTS:
                self._list_pairs()
            elif status == finite_strain.INVERTED:
                k = int(np.searchsorted(self.element_offsets, worst, side="right") - 1)
                body = self.bodies[k]
                body.jacobians[:] = self.jacobians[self.element_offsets[k]:self.element_offsets[k + 1]]
                body._raise_inverted(int(worst - self.element_offsets[k]), float(value))

    # ------------------------------------------------------------------ outputs
    @property
    def wall_forces(self) -> np.ndarray:
        """Normal force of each wall on the bodies at the last step (N)."""
        return self.contact_totals[:len(self.walls)].copy()

    def kinetic_energy(self) -> float:
        return 0.5 * float(np.sum(self.masses[:, None] * self.velocities ** 2))

