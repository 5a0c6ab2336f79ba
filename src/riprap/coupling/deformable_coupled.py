"""Deformable bodies in the air-water flow (the seed's eq. 4: the fluid's force reaches the solid
through its nodes, and the fluid feels the solid back).

The exchange is the rigid bodies' (:class:`riprap.coupling.coupled.CoupledSolver`): the fluid on
the grid sees each deformable body by the exact solid fraction of its deformed surface, moving with
the body's rigid part of its motion (mean velocity and spin of its nodes); the projection solves
body and fluid inertia together, and gives every body a force and a torque, equal and opposite to
the fluid's momentum change. What differs is how that load enters the body: not at its centre but
at its nodes,

* the pressure as a traction on the deformed surface, -p n, with p interpolated from the cell
  centres at six points of every boundary face, spread by the face's own shape functions (6-node
  faces for 10-node tets): buoyancy, the stagnation pressure in front of a falling body and the
  suction behind it load its surface where they act, so they strain it (the seed's Figure 1).
  The mean of p over the body's surface is left out of the traction and added to the body's
  stresses as -p I instead (``DeformableBody.ambient_pressure``): a uniform pressure neither
  moves nor turns a closed body, at depth it is most of the pressure, and forces of that size
  held fixed in space over a step while the body turns would drive the turn;
* the rest of the load (viscous stress, the momentum of the no-slip blend, and the small
  difference between the grid's and the surface's sum of the pressure) in proportion to the nodes'
  masses, as a rigid acceleration a + alpha x r, which moves the body without straining it.

The nodal forces sum exactly to the body's force, so the fluid and the body exchange equal and
opposite momentum, and, about its centre, to its torque less the drift that forces held over the
step pick up as the nodes move (taken off at the start: the angular impulse is the load's to first
order in the step). The deformation velocity of the nodes (strain rate times the body's size:
micrometres per second for concrete) does not enter the fluid: a grid of centimetre cells cannot
carry it. Within a fluid step the bodies take their own central-difference steps (contacts with
each other and with the walls throughout) with the nodal loads held. Rigid bodies in the same
flow take the rigid exchange as in a rigid coupled run and step with the deformable ones, step by
step, the contact forces between them passed over at every step (as in a dry mixed run).
"""
from __future__ import annotations

import math

import numpy as np

from riprap.coupling.coupled import MINIMUM_CELLS_ACROSS, CoupledSolver, check_substeps
from riprap.coupling.solid_volumes import half_cell_volumes, rigid_body_half_cell_volumes
from riprap.deformable.elements import boundary_face_nodes, boundary_faces_with_owners
from riprap.errors import CaseFileError

__all__ = ["DeformableBodies", "DeformableCoupledSolver", "surface_pressure_forces"]

# Dunavant's 6-point rule on a triangle (exact to degree 4: a linear pressure times quadratic
# shape functions on a curved 10-node tet face): barycentric points and weights (summing to 1).
_A, _B = 0.445948490915965, 0.091576213509771
_POINTS = np.array([[1 - 2 * _A, _A, _A], [_A, 1 - 2 * _A, _A], [_A, _A, 1 - 2 * _A],
                    [1 - 2 * _B, _B, _B], [_B, 1 - 2 * _B, _B], [_B, _B, 1 - 2 * _B]])
_WEIGHTS = np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)


def _face_shape_functions(n_nodes: int):
    """At the rule's points: the face's shape functions (q, n) and their derivatives along the
    two edges from the first corner (q, n, 2), for 3-node and 6-node (corners, then mid nodes
    of ab, bc, ca) triangles."""
    l1, l2, l3 = _POINTS.T
    if n_nodes == 3:
        values = _POINTS.copy()
        slopes = np.broadcast_to(np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]), (len(l1), 3, 2))
        return values, np.ascontiguousarray(slopes)
    values = np.stack([l1 * (2 * l1 - 1), l2 * (2 * l2 - 1), l3 * (2 * l3 - 1),
                       4 * l1 * l2, 4 * l2 * l3, 4 * l3 * l1], axis=1)
    # d/dxi with l2 = xi and d/deta with l3 = eta (l1 = 1 - xi - eta)
    d_xi = np.stack([-(4 * l1 - 1), 4 * l2 - 1, 0 * l1, 4 * (l1 - l2), 4 * l3, -4 * l3], axis=1)
    d_eta = np.stack([-(4 * l1 - 1), 0 * l1, 4 * l3 - 1, -4 * l2, 4 * l2, 4 * (l1 - l3)], axis=1)
    return values, np.stack([d_xi, d_eta], axis=2)


def _body_sums(values: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Per body the sum of node rows (bodies own consecutive nodes from ``offsets``)."""
    return np.add.reduceat(values, offsets[:-1], axis=0)


def interpolate_cell_field(field: np.ndarray, lower, h: float, points: np.ndarray) -> np.ndarray:
    """Trilinear interpolation of a cell-centred field at ``points`` (n, 3); points nearer a side
    than half a cell take the side cells' values (constant extrapolation)."""
    cells = np.asarray(field.shape)
    where = (points - np.asarray(lower)) / h - 0.5
    base = np.clip(np.floor(where).astype(np.int64), 0, np.maximum(cells - 2, 0))
    t = np.clip(where - base, 0.0, 1.0)
    upper = np.minimum(base + 1, cells - 1)
    result = np.zeros(len(points))
    for corner in range(8):
        pick = [(corner >> axis) & 1 for axis in range(3)]
        index = tuple(np.where(pick[axis], upper[:, axis], base[:, axis]) for axis in range(3))
        weight = np.prod([t[:, axis] if pick[axis] else 1.0 - t[:, axis] for axis in range(3)], axis=0)
        result += weight * field[index]
    return result


def surface_pressure_forces(positions: np.ndarray, faces: np.ndarray, pressure: np.ndarray,
                            lower, h: float, reference=0.0) -> np.ndarray:
    """Nodal forces (nodes, 3) of the traction -p n on a closed surface of outward faces (n, 3)
    or, curved, (n, 6) (``riprap.deformable.elements.boundary_face_nodes``): the consistent
    loads of the faces' own shape functions, p interpolated from the cell centres at the six
    points of Dunavant's rule on every face, less ``reference`` (Pa: one value, or one per
    face)."""
    values, slopes = _face_shape_functions(faces.shape[1])
    corners = positions[faces]                                        # (f, n, 3)
    points = np.einsum("qn,fnd->fqd", values, corners)
    tangents = np.einsum("qnk,fnd->fqkd", slopes, corners)            # (f, q, 2, 3)
    # x_xi x x_eta over the reference triangle of area 1/2
    area_normals = 0.5 * np.cross(tangents[:, :, 0], tangents[:, :, 1])
    p = interpolate_cell_field(pressure, lower, h, points.reshape(-1, 3)).reshape(points.shape[:2])
    p -= np.reshape(reference, (-1, 1))
    traction = -(_WEIGHTS * p)[..., None] * area_normals             # (f, q, 3)
    nodal = np.einsum("qn,fqd->fnd", values, traction)
    forces = np.zeros_like(positions)
    np.add.at(forces, faces.ravel(), nodal.reshape(-1, 3))
    return forces


def surface_mean_pressures(positions: np.ndarray, faces: np.ndarray, face_body: np.ndarray,
                           n_bodies: int, pressure: np.ndarray, lower, h: float) -> np.ndarray:
    """Per body the area-weighted mean of the interpolated pressure over its surface (Pa)."""
    values, slopes = _face_shape_functions(faces.shape[1])
    corners = positions[faces]
    points = np.einsum("qn,fnd->fqd", values, corners)
    tangents = np.einsum("qnk,fnd->fqkd", slopes, corners)
    areas = 0.5 * _WEIGHTS * np.linalg.norm(np.cross(tangents[:, :, 0], tangents[:, :, 1]), axis=2)
    p = interpolate_cell_field(pressure, lower, h, points.reshape(-1, 3)).reshape(points.shape[:2])
    weighted = np.bincount(face_body, (areas * p).sum(axis=1), minlength=n_bodies)
    return weighted / np.bincount(face_body, areas.sum(axis=1), minlength=n_bodies)


class DeformableBodies:
    """The bodies of a :class:`riprap.deformable.system.DeformableSystem` as the coupling sees
    them: per body its mass, centre, mean velocity, angular momentum and inertia (sums over its
    nodes), the forces on it and the fluid's load; its deformed surface; and the fluid's load
    handed to its nodes (:meth:`apply_fluid_loads`).

    With ``rigid`` (the :class:`riprap.solid.solver.SolidSolver` whose bodies are the system's
    rigid surfaces, in the same order), the rigid bodies come first (0 .. n_rigid - 1, their
    numbers in the solver) and the deformable ones after them; both take the same steps
    (:meth:`advance`), the contact forces between them passed over every step."""

    def __init__(self, system, rigid=None):
        n_rigid = rigid.n_bodies if rigid is not None else 0
        if rigid is not None and rigid.periodic is not None:
            raise CaseFileError("deformable bodies with rigid ones on a periodic strip "
                                "([simulation] periodic_y_low/high) are not available yet: the "
                                "deformable nodes do not wrap")
        if system.n_rigid != n_rigid:
            raise CaseFileError(f"the deformable system has {system.n_rigid} rigid surfaces, the rigid "
                                f"solver {n_rigid} bodies")
        self.system = system
        self.rigid = rigid
        self.n_rigid = n_rigid
        n_deformable = len(system.bodies)
        self.n_bodies = n_rigid + n_deformable
        self.gravity = system.gravity
        self.offsets = system.node_offsets
        n = system.n_deformable_nodes
        self.node_masses = system.masses[:n]
        self._deformable_masses = _body_sums(self.node_masses, self.offsets)
        deformable_densities = np.array([b.material.density for b in system.bodies], dtype=np.float64)
        if rigid is not None:
            rigid.finalize()
            self.fixed = np.concatenate([rigid.fixed, np.zeros(n_deformable, dtype=bool)])
            self.masses = np.concatenate([rigid.masses, self._deformable_masses])
            self.densities = np.concatenate([[rigid.materials[m].density
                                              for m in rigid.material_index_of_body],
                                             deformable_densities])
        else:
            self.fixed = np.zeros(n_deformable, dtype=bool)
            self.masses = self._deformable_masses.copy()
            self.densities = deformable_densities
        self._surface_version = None
        self._build_surfaces()
        self.node_body = np.repeat(np.arange(n_deformable), np.diff(self.offsets))
        #: The fluid's force and torque on every body, held over the present step (N, N m).
        self.external_loads = np.zeros((self.n_bodies, 6))
        #: Force and torque of the deformable bodies' contacts on each rigid body, last step.
        self.rigid_contact_loads = np.zeros((n_rigid, 6))
        self.refresh()

    @property
    def periodic(self) -> None:
        """Deformable bodies never live on a periodic strip (their nodes do not wrap): None, as
        ``SolidSolver.periodic`` of bodies between walls."""
        return None

    def _build_surfaces(self) -> None:
        """The surfaces the water sees: every deformable body's outward boundary triangles (the
        sub-tets' faces for 10-node bodies), and its element faces on the surface (6 nodes for
        10-node tets) where the pressure loads it. A cracked body's are its outer faces and the
        faces of its parted joints (``DeformableSystem._fracturing_surface``): each fragment a
        closed surface of its own, loaded on its crack faces too, not inside the intact
        concrete. Rebuilt whenever the system's contact surfaces are."""
        system = self.system
        if self._surface_version == system.surface_rebuilds:
            return
        triangles, starts, faces = [], [0], []
        for k, body in enumerate(system.bodies):
            if k in system.fracturing_bodies:
                surface = system._fracturing_surface(body)[0]
                triangles.append(surface + self.offsets[k])
                faces.append(surface + self.offsets[k])
            else:
                outer, _ = boundary_faces_with_owners(body.elements.contact_tets())
                triangles.append(outer + self.offsets[k])
                faces.append(boundary_face_nodes(body.elements.elements) + self.offsets[k])
            starts.append(starts[-1] + len(triangles[-1]))
        #: Outward boundary triangles of every deformable body: the surface the fluid grid sees;
        #: body k's from triangle_start[k].
        self.triangles = np.concatenate(triangles).astype(np.int64)
        self.triangle_start = np.asarray(starts, dtype=np.int64)
        #: The element faces on the bodies' surfaces, where the pressure loads them.
        self.load_faces = np.concatenate(faces).astype(np.int64)
        self.load_face_body = np.repeat(np.arange(len(system.bodies)), [len(f) for f in faces])
        self._surface_version = system.surface_rebuilds

    def finalize(self) -> None:
        """Nothing to do: the system was built whole (the coupling's SolidSolver interface)."""

    @property
    def time_step(self) -> float:
        """The longest step both kinds of body take (s)."""
        if self.rigid is None:
            return self.system.time_step
        return min(self.system.time_step, self.rigid.time_step)

    def deformable(self, body: int) -> int:
        """The system's number of body ``body`` (which must be deformable)."""
        return body - self.n_rigid

    # ------------------------------------------------------------------ per body
    def refresh(self) -> None:
        """Recompute the per-body sums from the nodes (after the nodes moved)."""
        s, n = self.system, self.system.n_deformable_nodes
        m = self.node_masses[:, None]
        x, v = s.positions[:n], s.velocities[:n]
        mass = self._deformable_masses[:, None]
        positions = _body_sums(m * x, self.offsets) / mass
        velocities = _body_sums(m * v, self.offsets) / mass
        arms = x - positions[self.node_body]
        angular_momenta = _body_sums(np.cross(arms, m * v), self.offsets)
        squared = np.einsum("ni,ni->n", arms, arms)
        inertia = _body_sums(m[:, 0, None, None] * (squared[:, None, None] * np.eye(3)
                                                    - arms[:, :, None] * arms[:, None, :]),
                             self.offsets)
        # the last step's force on every node (contacts, gravity, the fluid's load held);
        # the internal forces sum to nothing
        total = s.contact_forces[:n] + m * s.gravity + s.external_forces[:n]
        forces = _body_sums(total, self.offsets)
        torques = _body_sums(np.cross(arms, total), self.offsets)
        self._deformable_positions = positions
        self._deformable_velocities = velocities
        if self.rigid is not None:
            r = self.rigid
            rotations = r.rotation_matrices()
            world = np.einsum("bij,bj,bkj->bik", rotations, r.principal_inertia, rotations)
            positions = np.concatenate([r.positions, positions])
            velocities = np.concatenate([r.velocities, velocities])
            angular_momenta = np.concatenate([r.angular_momenta, angular_momenta])
            inertia = np.concatenate([world, inertia])
            forces = np.concatenate([r.forces, forces])
            torques = np.concatenate([r.torques, torques])
            self._rotations = rotations
        self.positions, self.velocities, self.angular_momenta = positions, velocities, angular_momenta
        self.inertia, self.forces, self.torques = inertia, forces, torques

    def contact_forces(self) -> np.ndarray:
        """Total contact force on every body at the last step (N)."""
        deformable = _body_sums(self.system.contact_forces[:self.system.n_deformable_nodes],
                                self.offsets)
        if self.rigid is None:
            return deformable
        # the rigid solver's own contacts (its loads less gravity and the fluid's) and the
        # deformable bodies' on them; a fixed body only has the latter (its solver sums none)
        rigid = np.where(self.rigid.fixed[:, None], self.rigid_contact_loads[:, :3],
                         self.rigid.contact_forces() + self.rigid_contact_loads[:, :3])
        return np.concatenate([rigid, deformable])

    def nominal_diameters(self) -> np.ndarray:
        """(mass / density)^(1/3) of every deformable body (m)."""
        return (self._deformable_masses / self.densities[self.n_rigid:]) ** (1.0 / 3.0)

    # ------------------------------------------------------------------ steps
    def advance(self, n_steps: int, time_step: float) -> None:
        """``n_steps`` steps of ``time_step`` (s) for all bodies, with the fluid's loads held:
        without rigid bodies in one call; with them step by step, the rigid bodies' surfaces
        placed in the system before each step and the deformable bodies' contact forces on them
        handed back as loads (beside the fluid's) for their own step."""
        system = self.system
        system.time_step = time_step
        if self.rigid is None:
            system.step(n_steps)
            return
        rigid = self.rigid
        rigid.set_time_step(time_step)
        moving = ~rigid.fixed
        if not moving.any():
            # fixed rigid bodies only (a bed, a slope, an underlayer): their surfaces stay where
            # they are, so the deformable bodies take all the steps in one call
            self._place_rigid(moving)
            system.step(n_steps)
            self._pass_contact_loads()
            return
        for _ in range(n_steps):
            self._place_rigid(moving)
            system.step(1)
            self._pass_contact_loads()
            rigid.advance(1)

    def _place_rigid(self, moving) -> None:
        rigid = self.rigid
        self.system.set_rigid_poses(rigid.rotation_matrices(), rigid.positions, rigid.velocities,
                                    rigid.angular_velocities, moving=moving)

    def _pass_contact_loads(self) -> None:
        """The deformable bodies' contact forces on the rigid ones at the last step, beside the
        fluid's load, as the rigid solver's external loads."""
        forces, torques = self.system.rigid_loads(self.rigid.positions)
        self.rigid_contact_loads[:, :3] = forces
        self.rigid_contact_loads[:, 3:] = torques
        self.rigid.external_loads[:] = self.external_loads[:self.n_rigid] + self.rigid_contact_loads

    # ------------------------------------------------------------------ loads
    def apply_fluid_loads(self, loads: np.ndarray, pressure: np.ndarray, lower, h: float,
                          reference: float = 0.0, duration: float = 0.0) -> None:
        """Hand each body's load (bodies, 6: force, torque about its centre) to its nodes: the
        pressure (less ``reference``) as surface traction, the rest as a rigid acceleration by
        mass; held as the nodes' external forces for ``duration`` (s), until the next call.

        Forces held fixed in space while the nodes move about the centre change their torque
        (a uniform pressure all round, whose torque is nil, would give one in proportion to the
        rotation, driving it further: a spin that grows by itself). The torque they will have on
        average over ``duration``, from the nodes' present velocities relative to the body's, is
        therefore taken off at the start, so that the body's angular impulse over the step is
        its load's (to first order in the step; the force's impulse is exact)."""
        if self.rigid is not None:
            # the rigid bodies take theirs whole; the last sub-step's forces (used by the first
            # half kick) take the change too
            change = loads[:self.n_rigid] - self.external_loads[:self.n_rigid]
            self.rigid.forces += change[:, :3]
            self.rigid.torques += change[:, 3:]
            self.rigid.external_loads[:] = loads[:self.n_rigid] + self.rigid_contact_loads
        self.external_loads[:] = loads
        loads = loads[self.n_rigid:]
        s, n = self.system, self.system.n_deformable_nodes
        x, v = s.positions[:n], s.velocities[:n]
        centres, mean_velocities = self._deformable_positions, self._deformable_velocities
        self._build_surfaces()
        # The mean pressure on each body's surface is left to its ambient_pressure: at depth it
        # is most of the pressure, and held fixed while the body turns it would be most of the
        # drift below.
        ambient = surface_mean_pressures(x, self.load_faces, self.load_face_body, len(s.bodies),
                                         pressure, lower, h)
        nodal = surface_pressure_forces(x, self.load_faces, pressure, lower, h,
                                        ambient[self.load_face_body])
        for body, value in zip(s.bodies, ambient - reference):
            body.ambient_pressure = float(value)
        arms = x - centres[self.node_body]
        relative = v - mean_velocities[self.node_body]
        rest_force = loads[:, :3] - _body_sums(nodal, self.offsets)
        rest_torque = loads[:, 3:] - _body_sums(np.cross(arms, nodal), self.offsets)
        inertia = self.inertia[self.n_rigid:]
        acceleration = rest_force / self._deformable_masses[:, None]
        angular = np.linalg.solve(inertia, rest_torque[..., None])[..., 0]
        nodal += self.node_masses[:, None] * (acceleration[self.node_body]
                                              + np.cross(angular[self.node_body], arms))
        drift = 0.5 * duration * _body_sums(np.cross(relative, nodal), self.offsets)
        correction = np.linalg.solve(inertia, -drift[..., None])[..., 0]
        nodal += self.node_masses[:, None] * np.cross(correction[self.node_body], arms)
        s.external_forces[:n] = nodal

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        s = self.system
        return {"clock": np.array([s.time, float(s.step_count)]),
                "positions": s.positions.copy(), "velocities": s.velocities.copy(),
                "contact_forces": s.contact_forces.copy(), "external_forces": s.external_forces.copy(),
                "ambient_pressures": np.array([b.ambient_pressure for b in s.bodies]),
                **s.contact_state(),
                "rigid_contact_loads": self.rigid_contact_loads.copy(),
                **s.joint_state(),
                **({f"rigid_{key}": value for key, value in self.rigid.state_arrays().items()}
                   if self.rigid is not None else {}),
                **({"rigid_external_loads": self.rigid.external_loads.copy()}
                   if self.rigid is not None else {})}

    def load_state_arrays(self, arrays: dict) -> None:
        s = self.system
        s.restore_state(arrays)
        for name in ("contact_forces", "external_forces"):
            getattr(s, name)[:] = arrays[name]
        for body, ambient in zip(s.bodies, arrays["ambient_pressures"]):
            body.ambient_pressure = float(ambient)
        self.rigid_contact_loads[:] = arrays["rigid_contact_loads"]
        if self.rigid is not None:
            self.rigid.load_state_arrays({key[len("rigid_"):]: value for key, value in arrays.items()
                                          if key.startswith("rigid_") and key != "rigid_contact_loads"})
            self.rigid.clear_contact_records()
            self.rigid.external_loads[:] = arrays["rigid_external_loads"]
        self.refresh()


class DeformableCoupledSolver(CoupledSolver):
    """A :class:`riprap.fluid.solver.FluidSolver` and deformable bodies that push each other.

    Parameters
    ----------
    fluid : FluidSolver
    bodies : DeformableBodies
        Around a DeformableSystem (and the SolidSolver of its rigid surfaces, if any) whose
        walls already include the fluid box's sides (the coupling adds none:
        :func:`riprap.coupling.coupled.fluid_box_walls`).
    check_momentum : bool
        As for :class:`CoupledSolver`.
    """

    def __init__(self, fluid, bodies: DeformableBodies, *, check_momentum: bool = False):
        if getattr(fluid, "obstacle_boxes", None):
            raise CaseFileError("deformable bodies in a flow with [[fluid.obstacles]] are not "
                                "available yet: give the obstacles as walls or leave them out")
        if fluid.periodic_y:
            raise CaseFileError("deformable bodies on a periodic strip (y_low = y_high = "
                                "\"periodic\") are not available yet: their nodes do not wrap; "
                                "give the fluid's y sides as walls")
        super().__init__(fluid, bodies, wall_material=None, check_momentum=check_momentum,
                         cut_faces="mixture")   # (the own velocity is for rigid bodies only)
        #: Deformable steps in the last fluid step.
        self.last_substeps = 0
        #: Called (no arguments) whenever the bodies' step count reaches a multiple of
        #: ``steps_between_calls`` inside a fluid step: the stress records of an impact that
        #: lasts a fraction of a fluid step (``riprap.models.deformable_coupled``).
        self.on_steps = None
        self.steps_between_calls = 50

    # the hooks of CoupledSolver. What the clipping remembers is one flat array: the rigid
    # bodies' poses (7 each), then every deformable node's position (3 each).
    def _body_densities(self) -> np.ndarray:
        return self.solids.densities.copy()

    def _split(self, flat):
        n_rigid = self.solids.n_rigid
        return flat[:7 * n_rigid].reshape(-1, 7), flat[7 * n_rigid:].reshape(-1, 3)

    def _clip_reference(self) -> np.ndarray:
        bodies = self.solids
        nodes = bodies.system.positions[:bodies.system.n_deformable_nodes]
        if bodies.rigid is None:
            return nodes.ravel().copy()
        poses = np.concatenate([bodies.rigid.positions, bodies.rigid.quaternions], axis=1)
        return np.concatenate([poses.ravel(), nodes.ravel()])

    def _moved_since_clipped(self, now) -> np.ndarray:
        bodies = self.solids
        (poses, nodes), (clipped_poses, clipped_nodes) = self._split(now), self._split(self._block_poses)
        moved = np.linalg.norm(nodes - clipped_nodes, axis=1)
        deformable = np.maximum.reduceat(moved, bodies.offsets[:-1])
        if bodies.rigid is None:
            return deformable
        rigid = bodies.rigid
        shift = np.linalg.norm(poses[:, :3] - clipped_poses[:, :3], axis=1)
        alignment = np.abs(np.einsum("bi,bi->b", poses[:, 3:], clipped_poses[:, 3:]))
        angle = 2.0 * np.arccos(np.minimum(alignment, 1.0))
        return np.concatenate([shift + angle * rigid.bounding_radius[rigid.shape_index], deformable])

    def _take_reference(self, stale, now) -> None:
        n_rigid, offsets = self.solids.n_rigid, self.solids.offsets
        (poses, nodes), (clipped_poses, clipped_nodes) = self._split(now), self._split(self._block_poses)
        for body in stale:
            if body < n_rigid:
                clipped_poses[body] = poses[body]
            else:
                k = body - n_rigid
                clipped_nodes[offsets[k]:offsets[k + 1]] = nodes[offsets[k]:offsets[k + 1]]

    def _clip_on(self, grid, stale) -> list:
        bodies = self.solids
        stale = np.asarray(stale, dtype=np.int64)
        poses, nodes = self._split(self._block_poses)
        rigid = stale[stale < bodies.n_rigid]
        deformable = stale[stale >= bodies.n_rigid] - bodies.n_rigid
        blocks = {}
        if len(rigid):
            fresh = rigid_body_half_cell_volumes(grid, bodies.rigid, bodies=rigid,
                                                 poses=poses[rigid])
            blocks.update(zip(rigid.tolist(), fresh))
        if len(deformable):
            bodies._build_surfaces()
            parts, starts = [], [0]
            for k in deformable:
                part = bodies.triangles[bodies.triangle_start[k]:bodies.triangle_start[k + 1]]
                parts.append(part)
                starts.append(starts[-1] + len(part))
            fresh = half_cell_volumes(grid, nodes, np.concatenate(parts),
                                      np.asarray(starts, dtype=np.int64))
            blocks.update(zip((deformable + bodies.n_rigid).tolist(), fresh))
        return [blocks[int(body)] for body in stale]

    def _world_inertia(self):
        return self.solids.inertia

    def _check_bodies_in_grid(self) -> None:
        bodies, grid = self.solids, self.fluid.grid
        if bodies.rigid is not None:
            self._check_rigid_bodies_in_grid(bodies.rigid)
        lower, upper = np.asarray(grid.lower), np.asarray(grid.upper)
        x = bodies.system.positions
        diameters = bodies.nominal_diameters()
        for b, body in enumerate(bodies.system.bodies):
            nodes = x[bodies.offsets[b]:bodies.offsets[b + 1]]
            low, high = nodes.min(axis=0), nodes.max(axis=0)
            if np.any(low < lower - 1e-12) or np.any(high > upper + 1e-12):
                raise CaseFileError(
                    f"coupling: deformable body '{body.name}' reaches {low.round(4).tolist()} .. "
                    f"{high.round(4).tolist()} m, outside the fluid box {list(lower)} .. "
                    f"{list(upper)}; move it inside or enlarge the box")
            across = diameters[b] / grid.cell_size
            if across < MINIMUM_CELLS_ACROSS:
                raise CaseFileError(
                    f"coupling: deformable body '{body.name}' is {across:.2g} cells across (nominal "
                    f"diameter {diameters[b]:.3g} m, cells {grid.cell_size:.3g} m); a moving body "
                    f"needs at least {MINIMUM_CELLS_ACROSS} cells across: cells of "
                    f"{diameters[b] / MINIMUM_CELLS_ACROSS:.3g} m or smaller")

    def _bodies_pressure(self):
        """(the pressure over the cells the bodies' surfaces may be in, its grid's lower corner,
        its obstacle cells): the fluid's own."""
        return self.fluid.pressure, self._lower, self.fluid.solid

    def _reference_pressure(self, pressure, solid) -> float:
        """The pressure the bodies' surfaces take as zero (Pa). Under an open top the solver's
        pressure is already the atmosphere's gauge. A closed box fixes its pressure only up to a
        constant (the solver's has zero mean): the mean of its top layer of cells is taken as
        zero, as if the lid stood at atmospheric pressure. Only the stresses' isotropic part
        depends on it: a constant pressure on a closed surface has no resultant."""
        if self.fluid.grid.open_top:
            return 0.0
        top = ~solid[:, :, -1]
        return float(pressure[:, :, -1][top].mean()) if top.any() else 0.0

    def _advance_solids(self, dt: float) -> int:
        bodies = self.solids
        # the loads' torques are about the centres of the step's start, where the nodes still are
        pressure, lower, solid = self._bodies_pressure()
        bodies.apply_fluid_loads(self.fluid_loads, pressure, lower, self.fluid.h,
                                 self._reference_pressure(pressure, solid), duration=dt)
        substeps = max(1, math.ceil(dt / self.solid_time_step - 1e-9))
        check_substeps(substeps, dt, self.solid_time_step)
        system, every, done = bodies.system, self.steps_between_calls, 0
        while done < substeps:
            chunk = min(substeps - done, every - system.step_count % every)
            bodies.advance(chunk, dt / substeps)
            done += chunk
            if self.on_steps is not None and system.step_count % every == 0:
                self.on_steps()
        # the bodies' clock is the fluid's (their own sum of sub-steps differs in the last bits)
        bodies.system.time = self.fluid.time
        for body in bodies.system.bodies:
            body.time = self.fluid.time
        bodies.refresh()
        self.last_substeps = substeps
        return substeps
