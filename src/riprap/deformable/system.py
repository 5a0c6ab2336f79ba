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

from riprap.deformable.body import (NO_TET4_GRADIENTS, PARALLEL_POINTS,
                                    TIME_STEP_SAFETY, DeformableBody, material_table,
                                    no_joints, stable_step_for)
from riprap.deformable.elements import _OUTWARD_FACES
from riprap.deformable.joints import FracturingBody
from riprap.deformable.kernels import contact as contact_kernels
from riprap.deformable.kernels import finite_strain
from riprap.deformable.kernels.bundles import ContactState, ElementState, JointData, NodeState
from riprap.errors import CaseFileError
from riprap.geometry.meshing import boundary_tet_heights
from riprap.geometry.tetmesh import TetMesh
from riprap.schema import default_of

# A stable step below this (s) comes from a key in the wrong unit, not from a mesh: a millimetre
# element of the stiffest concrete takes about 1e-7 s.
_SMALLEST_STABLE_STEP = 1e-20


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
                 mass_damping: float = default_of("deformable", "mass_damping"),
                 rigid_surfaces=(),
                 tangential_stiffness_ratio: float = default_of("materials",
                                                                "tangential_stiffness_ratio")):
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
        self.surface_rebuilds = 0
        self._broken_at_check = 0

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
                     "prescribed_velocities", "constrained"):
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
        # contact surfaces: boundary triangles and the tets that touch the boundary; a fracturing
        # body's also the faces of its parted joints (rebuilt when they change)
        self._surface_pieces = []            # per body (deformable, then rigid), or None
        self.potential_heights = []
        skin_heights = []
        self._wall_depth_of_body = []
        for k, body in enumerate(bodies):
            if isinstance(body, FracturingBody):
                mesh = TetMesh(body.original_nodes, body.original_tets, name=body.name)
                self._surface_pieces.append(None)
            else:
                mesh = TetMesh(body.elements.reference_nodes, body.elements.contact_tets(),
                               name=body.name)
                faces = mesh.boundary_faces()
                boundary_nodes = np.zeros(len(mesh.nodes), dtype=bool)
                boundary_nodes[faces.ravel()] = True
                layer = np.flatnonzero(boundary_nodes[mesh.tets].any(axis=1))
                self._surface_pieces.append((faces, mesh.tets[layer], np.arange(len(faces)),
                                             layer, None, None, None, None))
            heights = boundary_tet_heights(mesh)
            # the median boundary sub-tet height, over which a tet's potential rises by one
            self._wall_depth_of_body.append(float(np.median(heights)))
            body._contact_height = float(np.percentile(heights, 10))
            skin_heights.append(body._contact_height)
            self.potential_heights.append(float(np.median(heights)))
        self.proxy_local_nodes = []
        self.proxy_node_offsets = [self.n_deformable_nodes]
        for r, (local_nodes, faces, layer_tets, height) in enumerate(proxies):
            self._surface_pieces.append((faces, layer_tets, np.arange(len(faces)),
                                         np.arange(len(layer_tets)), None, None, None, None))
            self._wall_depth_of_body.append(height)
            self.proxy_local_nodes.append(local_nodes)
            self.proxy_node_offsets.append(self.proxy_node_offsets[-1] + len(local_nodes))
            skin_heights.append(height)
            self.potential_heights.append(height)
        self.proxy_node_offsets = np.asarray(self.proxy_node_offsets, dtype=np.int64)
        self._proxy_body = np.repeat(np.arange(len(proxies), dtype=np.int64),
                                     [len(p[0]) for p in proxies])
        self._proxy_local = (np.concatenate(self.proxy_local_nodes) if proxies
                             else np.zeros((0, 3)))
        self.first_rigid_body = len(bodies)
        self._moving_key = None
        self._moving_nodes = np.zeros(0, dtype=np.int64)
        self._body_friction = np.array([b.material.friction_coefficient for b in bodies]
                                       + rigid_friction)
        self._body_damping = np.array([b.material.contact_damping_ratio for b in bodies]
                                      + rigid_damping)
        self._reference = np.concatenate([b.elements.reference_nodes for b in bodies]
                                         + [p[0] for p in proxies])
        self.skin = 0.5 * min(skin_heights)
        self.potential_heights = np.asarray(self.potential_heights)
        self._join_joints()
        self._build_contact_surfaces()

    def _join_joints(self) -> None:
        """The joints of the fracturing bodies in one set of arrays (the bodies' damage, broken
        and parted flags become views into them)."""
        fracturing = [k for k, b in enumerate(self.bodies) if isinstance(b, FracturingBody)]
        self.fracturing_bodies = fracturing
        counts = [len(self.bodies[k].joints) for k in fracturing]
        self.joint_offsets = np.r_[0, np.cumsum(counts)].astype(np.int64)
        if not fracturing:
            self.joints = np.zeros((0, 6), dtype=np.int32)
            self.joint_data = no_joints()
            self.joint_work = np.zeros(1)
            return
        self.joints = np.concatenate([self.bodies[k].joints + self.node_offsets[k]
                                      for k in fracturing]).astype(np.int32)
        sizes = np.concatenate([self.bodies[k].joint_sizes for k in fracturing])
        properties = np.concatenate([self.bodies[k]._joint_properties for k in fracturing])
        material = np.repeat(np.arange(len(fracturing), dtype=np.int64), counts)
        for name in ("joint_damage", "joint_broken", "joint_parted", "joint_released",
                     "joint_friction_anchor"):
            joined = np.concatenate([getattr(self.bodies[k], name) for k in fracturing])
            setattr(self, name, joined)
            for i, k in enumerate(fracturing):
                setattr(self.bodies[k], name, joined[self.joint_offsets[i]:self.joint_offsets[i + 1]])
        # each element slot's rows of the joints' force buffer (``slot_joint_rows``), in the
        # system's numbering: a row per vertex of every joint, and a last one kept zero
        n_joints = int(self.joint_offsets[-1])
        slot_rows = np.full((self.elements.size, 3), 6 * n_joints, dtype=np.int32)
        for i, k in enumerate(fracturing):
            body = self.bodies[k]
            local = body._slot_joint_rows
            first_slot = self.elements.shape[1] * self.element_offsets[k]
            slot_rows[first_slot:first_slot + len(local)] = np.where(
                local < 6 * len(body.joints), local + 6 * self.joint_offsets[i], 6 * n_joints)
        self.joint_work = np.zeros(1)
        self.joint_data = JointData(self.joints, sizes, properties, material, self.joint_damage,
                                    self.joint_broken, np.zeros((6 * n_joints + 1, 3)), slot_rows,
                                    self.joint_released, self.joint_work,
                                    self.joint_friction_anchor)

    def _fracturing_surface(self, body) -> tuple:
        """A fracturing body's contact surface now: its outer faces and the faces of its parted
        joints (outward from their own tets), the tets touching them (by the mesh before it was
        exploded, so that a tet meeting the surface at a corner counts), keys of both that stay
        the same as the surface grows, the fragment of each, and the original nodes of the
        triangles' tets and of the tets (tets that shared one are left to their joints)."""
        face_joint = body.face_joint
        open_face = (face_joint == -1) | ((face_joint >= 0)
                                          & body.joint_parted[np.maximum(face_joint, 0)])
        tet_index, face_index = np.nonzero(open_face)
        faces = np.take_along_axis(body.elements.elements[tet_index], _OUTWARD_FACES[face_index],
                                   axis=1)
        on_surface = np.zeros(len(body.original_nodes), dtype=bool)
        on_surface[body.original_node[faces.ravel()]] = True
        layer = np.flatnonzero(on_surface[body.original_tets].any(axis=1))
        fragments = body.fragments()
        return (faces, body.elements.elements[layer], 4 * tet_index + face_index, layer,
                fragments[tet_index], fragments[layer], body.original_tets[tet_index],
                body.original_tets[layer])

    def _build_contact_surfaces(self) -> None:
        """The contact arrays from every body's surface, in the order the walls need (deformable
        bodies' triangles and tets first); each triangle and tet keeps a key (body, local key) by
        which friction springs are carried over when a fracturing body's surface grows."""
        triangles, tets, triangle_body, tet_body, triangle_keys, tet_keys = [], [], [], [], [], []
        triangle_group, tet_group, depths, triangle_origin, tet_origin = [], [], [], [], []
        offsets = np.r_[self.node_offsets[:-1], self.proxy_node_offsets[:-1]]
        group = 0
        original_offset = 0
        for k, piece in enumerate(self._surface_pieces):
            if piece is None:
                piece = self._fracturing_surface(self.bodies[k])
            (faces, layer_tets, face_keys, layer_keys, face_groups, layer_groups, face_origin,
             layer_origin) = piece
            if face_origin is None:
                triangle_origin.append(np.full((len(faces), 4), -1, dtype=np.int64))
                tet_origin.append(np.full((len(layer_tets), 4), -1, dtype=np.int64))
            else:
                triangle_origin.append(face_origin + original_offset)
                tet_origin.append(layer_origin + original_offset)
                original_offset += len(self.bodies[k].original_nodes)
            triangles.append(faces + offsets[k])
            tets.append(layer_tets + offsets[k])
            triangle_body.append(np.full(len(faces), k, dtype=np.int64))
            tet_body.append(np.full(len(layer_tets), k, dtype=np.int64))
            triangle_keys.append(k * _KEY_STRIDE + face_keys)
            tet_keys.append(k * _KEY_STRIDE + layer_keys)
            if face_groups is None:
                triangle_group.append(np.full(len(faces), group, dtype=np.int64))
                tet_group.append(np.full(len(layer_tets), group, dtype=np.int64))
                group += 1
            else:
                triangle_group.append(group + face_groups)
                tet_group.append(group + layer_groups)
                group += int(max(face_groups.max(initial=-1), layer_groups.max(initial=-1))) + 1
            if k == len(self.bodies) - 1:
                # groups of deformable bodies first: candidate_pairs skips rigid-rigid pairs
                self.first_rigid_group = group
            depths.append(np.full(len(faces), self._wall_depth_of_body[k]))
        n_bodies = len(self.bodies)
        self.n_wall_triangles = sum(len(t) for t in triangles[:n_bodies])
        self.n_wall_tets = sum(len(t) for t in tets[:n_bodies])
        self.triangles = np.concatenate(triangles)
        self.contact_tets = np.concatenate(tets)
        self.triangle_body = np.concatenate(triangle_body)
        self.tet_body = np.concatenate(tet_body)
        self.triangle_keys = np.concatenate(triangle_keys)
        self.tet_keys = np.concatenate(tet_keys)
        self.triangle_group = np.concatenate(triangle_group)
        self.tet_group = np.concatenate(tet_group)
        self.triangle_origin = np.concatenate(triangle_origin)
        self.tet_origin = np.concatenate(tet_origin)
        self.wall_depths = np.concatenate(depths)
        self.triangle_friction = self._body_friction[self.triangle_body]
        self.tet_friction = self._body_friction[self.tet_body]
        self.triangle_damping = self._body_damping[self.triangle_body]
        self.tet_damping = self._body_damping[self.tet_body]
        self.tet_heights = _subtet_heights(self._reference, self.contact_tets)

    def rebuild_contact_surfaces(self) -> None:
        """The contact surfaces from the joints' present state (after a restart): the friction
        springs of the walls start empty, sized to the new surfaces; pairs are listed anew."""
        self._build_contact_surfaces()
        self.tet_stiffness = (self.tangential_stiffness_ratio * self.contact_penalty
                              / self.tet_heights)
        self.wall_triangle_springs = np.zeros((len(self.walls), self.n_wall_triangles, 3))
        self.wall_tet_springs = np.zeros((len(self.walls), self.n_wall_tets, 3))
        self._pairs = np.zeros((0, 2), dtype=np.int64)
        self.pair_springs = np.zeros((0, 3))
        self.surface_rebuilds += 1

    def contact_state(self) -> dict:
        """The contacts' state for a checkpoint: the listed pairs, the node positions they were
        listed at, and the friction springs of the pairs and of the walls."""
        return {"contact_pairs": self._pairs.copy(), "listed_positions": self._listed_positions.copy(),
                "pair_springs": self.pair_springs.copy(),
                "wall_triangle_springs": self.wall_triangle_springs.copy(),
                "wall_tet_springs": self.wall_tet_springs.copy()}

    def restore_state(self, arrays: dict) -> None:
        """Put back a checkpoint's state: the clock (``arrays["clock"]``: time, step count), the
        nodes' positions and velocities, the joints (:meth:`joint_state`) with the contact
        surfaces they make, then the contacts (:meth:`contact_state`) on those surfaces."""
        self.time = float(arrays["clock"][0])
        self.step_count = int(arrays["clock"][1])
        self.positions[:] = arrays["positions"]
        self.velocities[:] = arrays["velocities"]
        # the cracks first: they decide the contact surfaces the springs below belong to
        self.load_joint_state(arrays)
        self._pairs = np.array(arrays["contact_pairs"], dtype=np.int64).reshape(-1, 2)
        self._listed_positions[:] = arrays["listed_positions"]
        self.pair_springs = np.array(arrays["pair_springs"], dtype=np.float64).reshape(-1, 3)
        self.wall_triangle_springs = np.array(arrays["wall_triangle_springs"], dtype=np.float64)
        self.wall_tet_springs = np.array(arrays["wall_tet_springs"], dtype=np.float64)
        for body in self.bodies:
            body.time = self.time
            body.step_count = self.step_count

    def joint_state(self) -> dict:
        """The joints' state for a checkpoint (empty without fracturing bodies)."""
        if not self.fracturing_bodies:
            return {}
        return {"joint_damage": self.joint_damage.copy(), "joint_broken": self.joint_broken.copy(),
                "joint_parted": self.joint_parted.copy(), "joint_work": self.joint_work.copy(),
                "joint_released": self.joint_released.copy(),
                "joint_friction_anchor": self.joint_friction_anchor.copy(),
                "joints_broken_at_check": np.array([self._broken_at_check])}

    def load_joint_state(self, arrays: dict) -> None:
        """Put back ``joint_state``'s arrays and the contact surfaces they make (before the
        contact pairs and springs of the same checkpoint are put back)."""
        if not self.fracturing_bodies:
            return
        self.joint_damage[:] = arrays["joint_damage"]
        self.joint_broken[:] = arrays["joint_broken"]
        self.joint_parted[:] = arrays["joint_parted"]
        self.joint_released[:] = arrays.get("joint_released", False)
        self.joint_friction_anchor[:] = arrays.get("joint_friction_anchor", 0.0)
        self.joint_work[:] = arrays["joint_work"]
        self._broken_at_check = int(arrays["joints_broken_at_check"][0])
        self.rebuild_contact_surfaces()

    def update_fragments(self) -> None:
        """After joints broke: mark the broken joints that now part two fragments, and if any
        did, rebuild the contact surfaces, carrying every friction spring over by its keys."""
        grew = False
        for k in self.fracturing_bodies:
            body = self.bodies[k]
            if not body.joint_broken.any():
                continue
            fragments = body.fragments()
            parted = body.joint_broken & (fragments[body.joint_tets[:, 0]]
                                          != fragments[body.joint_tets[:, 1]])
            if (parted & ~body.joint_parted).any():
                body.joint_parted |= parted
                grew = True
        if not grew:
            return
        old_triangle_keys, old_tet_keys = self.triangle_keys, self.tet_keys
        old_wall_triangles, old_wall_tets = self.n_wall_triangles, self.n_wall_tets
        old_wall_triangle_springs, old_wall_tet_springs = (self.wall_triangle_springs,
                                                           self.wall_tet_springs)
        old_pairs, old_pair_springs = self._pairs, self.pair_springs
        self.rebuild_contact_surfaces()
        triangle_from = _find_keys(old_triangle_keys, self.triangle_keys)
        tet_from = _find_keys(old_tet_keys, self.tet_keys)
        self.wall_triangle_springs = _carried(old_wall_triangle_springs,
                                              triangle_from[:self.n_wall_triangles], old_wall_triangles)
        self.wall_tet_springs = _carried(old_wall_tet_springs, tet_from[:self.n_wall_tets],
                                         old_wall_tets)
        # the listed pairs in the new numbering (pairs whose triangle or tet left the surface go)
        triangle_to = np.full(len(old_triangle_keys), -1, dtype=np.int64)
        found = triangle_from >= 0
        triangle_to[triangle_from[found]] = np.flatnonzero(found)
        tet_to = np.full(len(old_tet_keys), -1, dtype=np.int64)
        found = tet_from >= 0
        tet_to[tet_from[found]] = np.flatnonzero(found)
        pairs = np.stack([triangle_to[old_pairs[:, 0]], tet_to[old_pairs[:, 1]]], axis=1)
        kept = (pairs >= 0).all(axis=1)
        self._pairs = pairs[kept]
        self.pair_springs = old_pair_springs[kept]
        self._list_pairs()

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
        """2 / sqrt(omega_elements^2 + omega_contact^2): the stiffest element (with its joints) and
        the stiffest contact on one node (penalty times the node's share of surface over the
        potentials' depth; on a fracturing body, of every face of its tets). Computed once: it depends on the reference geometry only."""
        if self._stable_time_step is not None:
            return self._stable_time_step
        omega_elements = 0.0
        for body in self.bodies:
            body.stable_time_step()
            omega_elements = max(omega_elements, body._stiffest_frequency)
        # from the reference geometry, so that a run and its restart take the same step
        reference = np.concatenate([b.elements.reference_nodes for b in self.bodies]
                                   + self.proxy_local_nodes)
        # a fracturing body's every face may come into contact once its joint has parted
        fracturing = np.isin(self.triangle_body, self.fracturing_bodies)
        own = (self.triangle_body < self.first_rigid_body) & ~fracturing
        surfaces = [self.triangles[own]] + [
            (self.bodies[k].elements.elements[:, _OUTWARD_FACES] + self.node_offsets[k]).reshape(-1, 3)
            for k in self.fracturing_bodies]
        triangles = np.concatenate(surfaces)
        corners = reference[triangles]
        areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                              corners[:, 2] - corners[:, 0]), axis=1)
        node_area = np.zeros(len(reference))
        np.add.at(node_area, triangles.ravel(), np.repeat(areas / 3.0, 3))
        heights = np.array([b._contact_height for b in self.bodies])
        node_body = np.repeat(np.arange(len(self.bodies)), np.diff(self.node_offsets))
        node_area = node_area[:self.n_deformable_nodes]
        stiffness = self.contact_penalty * node_area * 2.0 / heights[node_body]
        omega_contact = float(np.sqrt(stiffness / self.masses[:self.n_deformable_nodes]).max())
        damping = max(b.material.viscous_time_constant for b in self.bodies)
        step = stable_step_for(math.hypot(omega_elements, omega_contact), damping,
                               self.mass_damping)
        if not (math.isfinite(step) and step > _SMALLEST_STABLE_STEP):
            raise CaseFileError(self._unstable_step_cause(step, omega_elements, omega_contact,
                                                          damping))
        self._stable_time_step = step
        return self._stable_time_step

    def _unstable_step_cause(self, step: float, omega_elements: float, omega_contact: float,
                             damping: float) -> str:
        """Which [deformable] key made the stable step ``step`` absurdly small, infinite or not a
        number."""
        omega = math.hypot(omega_elements, omega_contact)
        jointed = [b for b in self.bodies if hasattr(b, "joint_frequency")]
        material = self.bodies[0].material
        if not all(math.isfinite(b.joint_frequency()) for b in jointed):
            penalty = jointed[0].joint_material.joint_penalty
            cause = f"joint_penalty = {penalty:g} Pa/m makes the joints infinitely stiff"
        elif (not math.isfinite(omega_elements) or omega_elements == 0.0
              or not math.isfinite(damping)):
            cause = (f"young_modulus = {material.young_modulus:g} Pa with density = "
                     f"{material.density:g} kg/m^3 gives an element frequency of "
                     f"{omega_elements:g} rad/s")
        elif not math.isfinite(omega_contact):
            cause = (f"contact_penalty = {self.contact_penalty:g} Pa makes the contacts infinitely "
                     "stiff")
        elif not math.isfinite(omega):
            cause = "the elements and contacts together are infinitely stiff"
        elif damping * omega / 2.0 >= self.mass_damping / (2.0 * omega):
            cause = (f"viscosity = {material.viscosity:g} Pa s damps the stiffest mode "
                     f"({omega:.3g} rad/s) with a damping ratio of {damping * omega / 2:.3g}")
        else:
            cause = (f"mass_damping = {self.mass_damping:g} 1/s against the stiffest mode "
                     f"({omega:.3g} rad/s)")
        return (f"[deformable] {cause}, so the stable time step is {step:g} s; give the key in "
                "its SI unit (docs/case-file.md) and a value a concrete or rock can have")

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
                                                self.triangle_group, self.contact_tets,
                                                self.tet_group, self.skin, self.first_rigid_group,
                                                self.triangle_origin, self.tet_origin)
        self.pair_springs = contact_kernels.carry_springs(self._pairs, self.pair_springs, pairs,
                                                          len(self.contact_tets))
        self._pairs = pairs
        self._listed_positions[:] = self.positions
        self.pair_listings += 1

    def step(self, n_steps: int = 1) -> None:
        """Advance ``n_steps`` steps; raises InstabilityError naming an element that inverts."""
        dt = self.time_step
        # the joints are work of the same kind (one joint costs about one tet)
        parallel = self.weights.size + len(self.joints) >= PARALLEL_POINTS
        remaining = int(n_steps)
        while remaining > 0:
            chunk = remaining
            if self.fracturing_bodies:
                chunk = min(chunk, FRAGMENT_CHECK_STEPS - self.step_count % FRAGMENT_CHECK_STEPS)
            contact = ContactState(
                self.triangles[:self.n_wall_triangles], self.contact_tets[:self.n_wall_tets],
                self.triangles, self.contact_tets, self.wall_depths, self._pairs,
                self.contact_penalty, self.walls, self._listed_positions, self.skin,
                self.contact_totals, self.triangle_friction, self.tet_friction,
                self.tangential_stiffness_ratio, self.tet_stiffness, self.pair_springs,
                self.wall_triangle_springs, self.wall_tet_springs, self.triangle_damping,
                self.tet_damping)
            nodes = NodeState(self.positions, self.velocities, self.masses, self.external_forces,
                              self.contact_forces, self.constrained, self.prescribed_velocities,
                              self._offsets, self._slots)
            element_state = ElementState(self.elements, self.tet4_gradients, self.gradients,
                                         self.weights, self.materials, self.element_material,
                                         self._element_forces, self.jacobians)
            done, status, worst, value = finite_strain.advance_steps(
                chunk, parallel, nodes, element_state, self.gravity, self.mass_damping, dt,
                contact, self.joint_data)
            self.step_count += int(done)
            self.time += int(done) * dt
            for body in self.bodies:
                body.time = self.time
                body.step_count = self.step_count
            remaining -= int(done)
            if self.fracturing_bodies and self.step_count % FRAGMENT_CHECK_STEPS == 0:
                broken = int(np.count_nonzero(self.joint_broken))
                if broken != self._broken_at_check:
                    self._broken_at_check = broken
                    self.update_fragments()
            if status == finite_strain.REBUILD_CONTACTS:
                self._list_pairs()
            elif status == finite_strain.INVERTED:
                k = int(np.searchsorted(self.element_offsets, worst, side="right") - 1)
                body = self.bodies[k]
                body.jacobians[:] = self.jacobians[self.element_offsets[k]:self.element_offsets[k + 1]]
                body._raise_inverted(int(worst - self.element_offsets[k]), float(value), dt,
                                     self.stable_time_step())

    # ------------------------------------------------------------------ outputs
    @property
    def wall_forces(self) -> np.ndarray:
        """Normal force of each wall on the bodies at the last step (N)."""
        return self.contact_totals[:len(self.walls)].copy()

    def kinetic_energy(self) -> float:
        """Of the deformable bodies (J)."""
        n = self.n_deformable_nodes
        return 0.5 * float(np.sum(self.masses[:n, None] * self.velocities[:n] ** 2))


#: Every this many steps (counted from the start, so that a restart checks at the same steps) the
#: joints broken since are looked at, and those that part two fragments handed to the contact.
#: Until then a broken joint keeps its faces apart itself (its compressive penalty); a piece
#: flying at 30 m/s moves 2 mm in 100 steps of 0.7 microseconds, a small part of a face.
FRAGMENT_CHECK_STEPS = 100

# Keys of contact triangles and tets: body * _KEY_STRIDE + a key within the body.
_KEY_STRIDE = 1 << 40


def _find_keys(old_keys, new_keys):
    """For each new key, the index of the same key among the old ones (-1 if new)."""
    source = np.full(len(new_keys), -1, dtype=np.int64)
    if len(old_keys) == 0:
        return source
    order = np.argsort(old_keys, kind="stable")
    at = np.minimum(np.searchsorted(old_keys[order], new_keys), len(old_keys) - 1)
    found = old_keys[order][at] == new_keys
    source[found] = order[at[found]]
    return source


def _carried(springs, source, old_count):
    """Wall springs (n_walls, n, 3) of the new numbering from the old ones by ``source``."""
    carried = np.zeros((springs.shape[0], len(source), 3))
    found = (source >= 0) & (source < old_count)
    carried[:, found] = springs[:, source[found]]
    return carried


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

