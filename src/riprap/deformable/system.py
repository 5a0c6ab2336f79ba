"""Several deformable bodies with contact between them and with walls, advanced together.

The bodies' nodes are joined into one set of arrays (each body's ``positions``, ``velocities``,
loads and supports become views into them), so one compiled loop steps everything: contact forces
(``riprap/deformable/kernels/contact.py``), internal forces and the central-difference update.
The (boundary triangle, tet) pairs that may touch are listed from boxes grown by a skin and
listed again only after some node has moved half the skin, so contact costs a sweep over the
listed pairs per step.

Contact sees 4-node tets: the elements of 4-node bodies, the 8 sub-tets of each 10-node element
(``ElementSet.contact_tets``), so that every node of a curved face takes part.
"""
from __future__ import annotations

import math

import numpy as np

from riprap.deformable.body import (NO_TET4_GRADIENTS, PARALLEL_POINTS, TIME_STEP_SAFETY,
                                    DeformableBody, material_table, stable_step_for)
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
    walls : list of (point, outward normal) or (point, outward normal, friction coefficient)
        Half-spaces {x : n . (x - point) < 0} the bodies cannot enter (a floor: point (0, 0, 0),
        normal (0, 0, 1)); without a friction coefficient a wall takes the bodies' own.
    contact_penalty : float or None
        p of Munjiza's potential (Pa); default the smallest Young's modulus of the bodies. The
        stiffer the penalty, the smaller the overlaps and the time step.
    gravity : 3 floats
        m/s^2, for every body.
    mass_damping : float
        1/s, for every body (0 for physics runs).
    tangential_stiffness_ratio : float
        Stiffness of the friction springs over the normal contact stiffness (2/7 as for rigid
        bodies).
    rigid_surfaces : list of (nodes, tets[, friction coefficient[, mass[, damping ratio]]]), optional
        Rigid bodies the deformable ones touch: each body's tetrahedral mesh in its own frame
        (for riprap's rigid solver, the principal frame about the centroid). Their surface layer
        moves with the poses given to :meth:`set_rigid_poses`; the contact forces on it come back
        from :meth:`rigid_loads`. Rigid bodies do not touch each other or the walls here (their
        own solver does that).
    """

    def __init__(self, bodies, walls=(), *, contact_penalty=None, gravity=(0.0, 0.0, 0.0),
                 mass_damping: float = 0.0, rigid_surfaces=(),
                 tangential_stiffness_ratio: float = 2.0 / 7.0):
        bodies = list(bodies)
        if not bodies:
            raise CaseFileError("a deformable system needs at least one body")
        for body in bodies:
            if not isinstance(body, DeformableBody):
                raise CaseFileError(f"{body!r} is not a DeformableBody")
        kinds = sorted({body.element_type for body in bodies})
        if len(kinds) > 1:
            raise CaseFileError(f"deformable bodies of {' and '.join(kinds)} elements in one run: give "
                                "them all the same element_type")
        self.bodies = bodies
        if contact_penalty is None:
            contact_penalty = min(body.material.young_modulus for body in bodies)
        if not (contact_penalty > 0 and math.isfinite(contact_penalty)):
            raise CaseFileError(f"contact_penalty = {contact_penalty!r} must be > 0 Pa")
        self.contact_penalty = float(contact_penalty)
        self.walls = np.zeros((len(walls), 7))
        for w, wall in enumerate(walls):
            point, normal = wall[0], np.asarray(wall[1], dtype=np.float64)
            self.walls[w, 6] = wall[2] if len(wall) > 2 else np.inf
            length = np.linalg.norm(normal)
            if not length > 0:
                raise CaseFileError(f"wall {w}: its normal {normal.tolist()} has zero length")
            self.walls[w, :3] = point
            self.walls[w, 3:6] = normal / length
        self.gravity = np.asarray(gravity, dtype=np.float64).reshape(3).copy()
        self.mass_damping = float(mass_damping)
        self.tangential_stiffness_ratio = float(tangential_stiffness_ratio)
        self._join(list(rigid_surfaces))
        # normal stiffness of a contact ~ p A / h (h the tet's sub-tet height): per tet and m^2
        self.tet_stiffness = (self.tangential_stiffness_ratio * self.contact_penalty
                              / self.tet_heights)
        self.wall_triangle_springs = np.zeros((len(self.walls), self.n_wall_triangles, 3))
        self.wall_tet_springs = np.zeros((len(self.walls), self.n_wall_tets, 3))
        self.pair_springs = np.zeros((0, 3))
        self.time = 0.0
        self.step_count = 0
        self._time_step = None
        self._stable_time_step = None
        self.contact_totals = np.zeros(len(self.walls) + 1)
        self._pairs = np.zeros((0, 2), dtype=np.int64)
        self._listed_positions = np.full_like(self.positions, np.inf)
        self.pair_listings = 0

    # ------------------------------------------------------------------ assembly
    def _join(self, rigid_surfaces) -> None:
        bodies = self.bodies
        node_counts = [len(b.positions) for b in bodies]
        self.node_offsets = np.r_[0, np.cumsum(node_counts)].astype(np.int64)
        proxies = [_surface_layer(np.asarray(surface[0], dtype=np.float64),
                                  np.asarray(surface[1], dtype=np.int64))
                   for surface in rigid_surfaces]
        rigid_friction = [surface[2] if len(surface) > 2 else 0.6 for surface in rigid_surfaces]
        rigid_damping = [surface[4] if len(surface) > 4 else 0.0 for surface in rigid_surfaces]
        rigid_masses = [surface[3] if len(surface) > 3 else np.inf for surface in rigid_surfaces]
        self.n_deformable_nodes = int(self.node_offsets[-1])
        element_counts = [b.n_elements for b in bodies]
        self.element_offsets = np.r_[0, np.cumsum(element_counts)].astype(np.int64)
        n_proxy = sum(len(p[0]) for p in proxies)
        for name in ("positions", "velocities", "external_forces", "contact_forces",
                     "prescribed_velocities", "nodal_forces", "constrained"):
            parts = [getattr(b, name) for b in bodies]
            # rigid surface nodes: held (constrained) at their body's motion, set every step
            parts.append(np.full((n_proxy, 3), name == "constrained", dtype=parts[0].dtype))
            joined = np.concatenate(parts)
            setattr(self, name, joined)
            for k, body in enumerate(bodies):
                setattr(body, name, joined[self.node_offsets[k]:self.node_offsets[k + 1]])
        # a rigid surface node stands for its whole body in the friction's stick estimate
        self.masses = np.concatenate([b.masses for b in bodies]
                                     + [np.full(len(p[0]), mass) for p, mass in zip(proxies, rigid_masses)])
        self.elements = np.concatenate([b.elements.elements + self.node_offsets[k]
                                        for k, b in enumerate(bodies)])
        tet4 = bodies[0].element_type == "tet4"
        self.tet4_gradients = (np.concatenate([b.elements.tet4_gradients for b in bodies]) if tet4
                               else NO_TET4_GRADIENTS)
        self.gradients = np.concatenate([b.elements.gradients for b in bodies])
        self.weights = np.concatenate([b.elements.weights for b in bodies])
        self.materials = material_table([b.material for b in bodies])
        self.element_material = np.concatenate([np.full(b.n_elements, k, dtype=np.int64)
                                                for k, b in enumerate(bodies)])
        self.jacobians = np.ones(len(self.elements))
        self._element_forces = np.zeros(self.elements.shape + (3,))
        flat = self.elements.ravel()
        order = np.argsort(flat, kind="stable")
        counts = np.bincount(flat, minlength=len(self.positions))
        self._offsets = np.r_[0, np.cumsum(counts)].astype(np.int64)
        self._slots = order.astype(np.int64)
        # contact surfaces: boundary triangles and the tets that touch the boundary
        triangles, tets, triangle_body, tet_body, depths = [], [], [], [], []
        # per body (deformable, then rigid): the median boundary sub-tet height, over which a
        # tet's potential rises by one
        potential_heights = []
        for k, body in enumerate(bodies):
            mesh = TetMesh(body.elements.reference_nodes, body.elements.contact_tets(), name=body.name)
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
            potential_heights.append(float(np.median(heights)))
        # the walls act on the deformable bodies' triangles and tets only, which come first
        self.n_wall_triangles = sum(len(t) for t in triangles)
        self.n_wall_tets = sum(len(t) for t in tets)
        skin_heights = [b._contact_height for b in bodies]
        self.proxy_local_nodes = []
        self.proxy_node_offsets = [self.n_deformable_nodes]
        for r, (local_nodes, faces, layer_tets, height) in enumerate(proxies):
            offset = self.proxy_node_offsets[-1]
            triangles.append(faces + offset)
            tets.append(layer_tets + offset)
            triangle_body.append(np.full(len(faces), len(bodies) + r, dtype=np.int64))
            tet_body.append(np.full(len(layer_tets), len(bodies) + r, dtype=np.int64))
            depths.append(np.full(len(faces), height))
            self.proxy_local_nodes.append(local_nodes)
            self.proxy_node_offsets.append(offset + len(local_nodes))
            skin_heights.append(height)
            potential_heights.append(height)
        self.proxy_node_offsets = np.asarray(self.proxy_node_offsets, dtype=np.int64)
        self._proxy_body = np.repeat(np.arange(len(proxies), dtype=np.int64),
                                     [len(p[0]) for p in proxies])
        self._proxy_local = (np.concatenate(self.proxy_local_nodes) if proxies
                             else np.zeros((0, 3)))
        self.first_rigid_body = len(bodies)
        self._moving_key = None
        self._moving_nodes = np.zeros(0, dtype=np.int64)
        self.triangles = np.concatenate(triangles)
        self.contact_tets = np.concatenate(tets)
        self.triangle_body = np.concatenate(triangle_body)
        self.tet_body = np.concatenate(tet_body)
        self.wall_depths = np.concatenate(depths)
        friction = np.array([b.material.friction_coefficient for b in bodies] + rigid_friction)
        self.triangle_friction = friction[self.triangle_body]
        self.tet_friction = friction[self.tet_body]
        damping = np.array([b.material.contact_damping_ratio for b in bodies] + rigid_damping)
        self.triangle_damping = damping[self.triangle_body]
        self.tet_damping = damping[self.tet_body]
        reference = np.concatenate([b.elements.reference_nodes for b in bodies]
                                   + [p[0] for p in proxies])
        self.tet_heights = _subtet_heights(reference, self.contact_tets)
        self.skin = 0.5 * min(skin_heights)
        self.potential_heights = np.asarray(potential_heights)

    # ------------------------------------------------------------------ rigid bodies
    @property
    def n_rigid(self) -> int:
        return len(self.proxy_local_nodes)

    def set_rigid_poses(self, rotations, centres, velocities, angular_velocities,
                        moving=None) -> None:
        """Place the rigid bodies' surface layers: world = R local + centre, moving at
        v + omega x (x - centre). Arrays per rigid body, in the order of ``rigid_surfaces``;
        ``moving`` (a boolean mask over the rigid bodies) limits the update to those that may
        have moved (fixed bodies are placed once)."""
        if not self.n_rigid:
            return
        if moving is None:
            nodes = np.arange(len(self._proxy_body), dtype=np.int64)
        else:
            key = np.asarray(moving, dtype=bool).tobytes()
            if self._moving_key != key:
                self._moving_key = key
                self._moving_nodes = np.flatnonzero(np.asarray(moving, dtype=bool)[self._proxy_body])
            nodes = self._moving_nodes
        contact_kernels.place_rigid_nodes(
            self.positions, self.velocities, self.prescribed_velocities, self.n_deformable_nodes,
            self._proxy_local, self._proxy_body, nodes, np.ascontiguousarray(rotations, dtype=np.float64),
            np.ascontiguousarray(centres, dtype=np.float64),
            np.ascontiguousarray(velocities, dtype=np.float64),
            np.ascontiguousarray(angular_velocities, dtype=np.float64))

    def rigid_loads(self, centres) -> tuple[np.ndarray, np.ndarray]:
        """(forces (n_rigid, 3), torques about ``centres`` (n_rigid, 3)) of the last step's contact
        forces on the rigid bodies (N, N m)."""
        return contact_kernels.rigid_node_loads(self.positions, self.contact_forces,
                                                self.n_deformable_nodes, self._proxy_body,
                                                np.ascontiguousarray(centres, dtype=np.float64),
                                                self.n_rigid)

    # ------------------------------------------------------------------ time step
    def stable_time_step(self) -> float:
        """2 / sqrt(omega_elements^2 + omega_contact^2): the stiffest element and the stiffest
        contact on one node (penalty times the node's share of surface over the potentials' depth).
        Computed once: it depends on the reference geometry only."""
        if self._stable_time_step is not None:
            return self._stable_time_step
        omega_elements = 0.0
        for body in self.bodies:
            body.stable_time_step()
            omega_elements = max(omega_elements, body._stiffest_frequency)
        # from the reference geometry, so that a run and its restart take the same step
        reference = np.concatenate([b.elements.reference_nodes for b in self.bodies]
                                   + self.proxy_local_nodes)
        corners = reference[self.triangles]
        areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                              corners[:, 2] - corners[:, 0]), axis=1)
        node_area = np.zeros(len(reference))
        own = self.triangle_body < self.first_rigid_body
        np.add.at(node_area, self.triangles[own].ravel(), np.repeat(areas[own] / 3.0, 3))
        heights = np.array([b._contact_height for b in self.bodies])
        node_body = np.repeat(np.arange(len(self.bodies)), np.diff(self.node_offsets))
        node_area = node_area[:self.n_deformable_nodes]
        stiffness = self.contact_penalty * node_area * 2.0 / heights[node_body]
        omega_contact = float(np.sqrt(stiffness / self.masses[:self.n_deformable_nodes]).max())
        damping = max(b.material.viscous_time_constant for b in self.bodies)
        self._stable_time_step = stable_step_for(math.hypot(omega_elements, omega_contact), damping,
                                                 self.mass_damping)
        return self._stable_time_step

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
        pairs = contact_kernels.candidate_pairs(self.positions, self.triangles,
                                                self.triangle_body, self.contact_tets,
                                                self.tet_body, self.skin, self.first_rigid_body)
        self.pair_springs = contact_kernels.carry_springs(self._pairs, self.pair_springs, pairs,
                                                          len(self.contact_tets))
        self._pairs = pairs
        self._listed_positions[:] = self.positions
        self.pair_listings += 1

    def step(self, n_steps: int = 1) -> None:
        """Advance ``n_steps`` steps; raises InstabilityError naming an element that inverts."""
        dt = self.time_step
        parallel = self.weights.size >= PARALLEL_POINTS
        remaining = int(n_steps)
        while remaining > 0:
            contact = (self.triangles[:self.n_wall_triangles], self.contact_tets[:self.n_wall_tets],
                       self.triangles, self.contact_tets, self.wall_depths, self._pairs,
                       self.contact_penalty, self.walls, self._listed_positions, self.skin,
                       self.contact_totals, self.triangle_friction, self.tet_friction,
                       self.tangential_stiffness_ratio, self.tet_stiffness, self.pair_springs,
                       self.wall_triangle_springs, self.wall_tet_springs, self.triangle_damping,
                       self.tet_damping)
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
        """Of the deformable bodies (J)."""
        n = self.n_deformable_nodes
        return 0.5 * float(np.sum(self.masses[:n, None] * self.velocities[:n] ** 2))


def _subtet_heights(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Smallest centroid-to-face distance of every tet, 3 V / (4 A_max) (m)."""
    corners = nodes[tets]
    volumes = np.abs(np.linalg.det(corners[:, 1:] - corners[:, :1])) / 6.0
    faces = corners[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]]
    areas = 0.5 * np.linalg.norm(np.cross(faces[:, :, 1] - faces[:, :, 0],
                                          faces[:, :, 2] - faces[:, :, 0]), axis=2)
    return 3.0 * volumes / (4.0 * areas.max(axis=1))


def _surface_layer(nodes: np.ndarray, tets: np.ndarray):
    """A rigid body's contact layer: (its nodes, its outward boundary faces and the tets touching
    the boundary, both in those nodes' numbering, the median boundary sub-tet height)."""
    mesh = TetMesh(nodes, tets)
    faces = mesh.boundary_faces()
    on_boundary = np.zeros(len(nodes), dtype=bool)
    on_boundary[faces.ravel()] = True
    layer = mesh.tets[on_boundary[mesh.tets].any(axis=1)]
    used = np.unique(np.concatenate([faces.ravel(), layer.ravel()]))
    renumber = np.full(len(nodes), -1, dtype=np.int64)
    renumber[used] = np.arange(len(used))
    height = float(np.median(boundary_tet_heights(mesh)))
    return nodes[used], renumber[faces], renumber[layer], height

