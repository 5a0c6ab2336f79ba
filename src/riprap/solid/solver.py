"""SolidSolver: the rigid FEMDEM engine. Holds the body state as flat arrays, owns the step order,
calls the kernels and turns their status into named errors.

Step (velocity Verlet): kick(dt/2) with the forces of the previous step, drift(dt), new forces
(broad phase, potential contact, damping, friction, gravity), kick(dt/2).
"""
from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, KernelOverflowError, OverlapError
from riprap.schema import default_of
from riprap.solid.bodies_over_processes import BodiesOverProcesses
from riprap.solid.kernels import integrate, interactions, periodic, stepper
from riprap.solid.kernels.bundles import (Bodies, History, Motion, PairLaws, RigidSystem,
                                          StepSettings, Walls)
from riprap.solid.kernels.geometry_ops import rotation_matrices, rotation_matrix
from riprap.solid.materials import FrictionPair, Material, friction_table, pair_tables
from riprap.solid.shape import RigidShape, ShapeTable
from riprap.solid.walls import Wall

# Boxes are grown by this fraction of the largest bounding radius so that contacts about to start
# are found (the pair list is rebuilt every step, so this only has to cover one step's motion).
_BROAD_PHASE_MARGIN = 0.02
# Default contact skin as a fraction of the boundary sub-tet height: a rebuild of a pair's piece
# list costs about two evaluations, so the skin only has to cover a few steps of fast motion.
_SKIN_OVER_SUBTET_HEIGHT = 0.1
# A pack's recorded overlap depths are recomputed from poses written to the last bit, so a pair
# found deeper than recorded by more than this fraction was moved, not read back.
_ACCEPTED_DEPTH_SLACK = 1e-3
# Centroids closer than this fraction of the smaller bounding radius: the bodies coincide.
_COINCIDENT_FRACTION = 0.05
# A wall whose unit normal has a component larger than this along a periodic axis is a wall
# across that axis (the slope's face and the bed have exactly 0 there).
_WALL_ACROSS_PERIODIC = 1e-12
_AXIS_NAMES = "xyz"


@dataclass
class ContactRecords:
    """Contacts of the last force evaluation, one row per touching pair.

    ``body_j`` is -1 - w for a contact with wall w. Forces act on ``body_i`` (N); body j receives the
    opposite. ``points`` is the force-weighted contact point (m); across a periodic boundary it
    lies beside body i (``SolidSolver.set_periodic``), and body j's lever arm to it is taken by
    minimum image (``SolidSolver.minimum_image``).
    """

    body_i: np.ndarray
    body_j: np.ndarray
    points: np.ndarray
    normal_forces: np.ndarray
    tangential_forces: np.ndarray
    stiffness: np.ndarray

    def __len__(self):
        return len(self.body_i)


class SolidSolver:
    """Rigid bodies with tetrahedral shapes, walls, gravity and Munjiza potential contact."""

    def __init__(self, *, gravity=default_of("simulation", "gravity"),
                 local_damping: float = default_of("simulation", "local_damping"),
                 contact_skin: float | None = None):
        """``contact_skin`` (m): how far two bodies may move relative to each other before the
        list of (triangle, tet) pieces of their contact is made again; it changes the speed only,
        never the forces. None: a tenth of the smallest median boundary sub-tet height; 0: no reuse.
        """
        self.gravity = np.asarray(gravity, dtype=np.float64)
        #: The bodies' split over processes (``split_bodies_over``); None: one process.
        self._split = None
        if not 0.0 <= local_damping < 1.0:
            raise CaseFileError(f"local_damping = {local_damping!r} must be in [0, 1)")
        if contact_skin is not None and not contact_skin >= 0.0:
            raise CaseFileError(f"contact_skin = {contact_skin!r} must be >= 0 m")
        self.contact_skin = contact_skin
        self.local_damping = float(local_damping)
        self.shapes: list[RigidShape] = []
        self.materials: list[Material] = []
        #: Friction coefficients of named pairs of materials (``[[friction]]``), in place of the
        #: pair rule's smaller of the two.
        self.friction_pairs: list[FrictionPair] = []
        self.walls: list[Wall] = []
        self._body_rows: list[tuple] = []
        self.time = 0.0
        self.step_count = 0
        # Time is step_count * time_step counted from the last restart, so that it carries no
        # accumulated round-off and a restarted run reproduces the unbroken one exactly.
        self._time_origin = None
        self._step_origin = 0
        self.time_step = None
        self._ready = False
        # (body_i, body_j, springs) of the contacts the bodies start in (a pack's history).
        self.initial_contact_history = None
        # (axis, lower, upper) of the periodic direction (``set_periodic``), or None
        self._periodic = None

    # ------------------------------------------------------------------ building
    def add_shape(self, shape: RigidShape) -> int:
        self.shapes.append(shape)
        self._ready = False
        return len(self.shapes) - 1

    def add_material(self, material: Material) -> int:
        if any(m.name == material.name for m in self.materials):
            raise CaseFileError(f"material '{material.name}' defined twice")
        self.materials.append(material)
        self._ready = False
        return len(self.materials) - 1

    def add_friction_pair(self, pair: FrictionPair) -> None:
        """Give contacts between ``pair.materials`` their own friction coefficient (the
        materials may be added before or after; both must exist when the solver is built)."""
        if any(known.key == pair.key for known in self.friction_pairs):
            raise CaseFileError(f"friction pair {pair.key[0]}-{pair.key[1]} given twice; give "
                                "each pair once")
        self.friction_pairs.append(pair)
        self._ready = False

    @property
    def friction_table(self) -> np.ndarray:
        """(n_materials, n_materials) friction coefficient of each pair of materials in contact."""
        return friction_table(self.materials, self.friction_pairs)

    def material_index(self, name: str) -> int:
        for i, m in enumerate(self.materials):
            if m.name == name:
                return i
        known = ", ".join(m.name for m in self.materials)
        raise CaseFileError(f"unknown material '{name}' (defined: {known})")

    def add_walls(self, walls) -> None:
        for wall in walls:
            self.material_index(wall.material)
            self._refuse_wall_across_period(len(self.walls), wall)
            self.walls.append(wall)
        self._ready = False

    def set_periodic(self, axis: int, lower: float, upper: float) -> None:
        """Make direction ``axis`` (0: x, 1: y) periodic with period ``upper - lower`` (m): a
        centre leaving the strip [lower, upper) comes back at its other end, and every pair of
        bodies is seen by minimum image (``solid/kernels/periodic.py``). Walls across that
        direction are refused (the strip needs none), and so is a period too short for a pair of
        bodies to touch in one image only (checked again when the solver is built, when every
        body and wall is known). Given before the run starts, as the other parts of the system;
        a restart gives it again (it is configuration, the checkpoint holds the wrapped
        positions)."""
        if (isinstance(axis, (bool, np.bool_)) or not isinstance(axis, (int, np.integer))
                or not 0 <= axis <= 2):
            raise CaseFileError(f"periodic axis {axis!r} is out of range: give 0 (x) or 1 (y)")
        if axis == 2:
            raise CaseFileError("periodic axis 2 (z) refused: z is the vertical of riprap "
                                "(gravity, the bed, the free surface); give 0 (x) or 1 (y)")
        lower, upper = float(lower), float(upper)
        name = _AXIS_NAMES[axis]
        if not (math.isfinite(lower) and math.isfinite(upper)) or not lower < upper:
            raise CaseFileError(f"periodic {name}: lower = {lower!r} m must be below upper = "
                                f"{upper!r} m (both finite)")
        if self._periodic is not None and self._periodic[0] != axis:
            raise CaseFileError(f"periodic {name} asked while {_AXIS_NAMES[self._periodic[0]]} is "
                                "periodic already: one periodic direction at a time")
        before, self._periodic = self._periodic, (int(axis), lower, upper)
        try:
            self._check_periodic()
        except CaseFileError:
            self._periodic = before     # a refused strip leaves the solver as it was
            raise
        self._ready = False

    @property
    def periodic(self) -> tuple[int, float, float] | None:
        """(axis, lower, upper) of the periodic direction, or None."""
        return self._periodic

    def _check_periodic(self) -> None:
        """Refuse walls across the periodic direction and a period too short for the bodies."""
        if self._periodic is None:
            return
        axis, lower, upper = self._periodic
        name = _AXIS_NAMES[axis]
        for w, wall in enumerate(self.walls):
            self._refuse_wall_across_period(w, wall)
        rows = self._body_rows
        moving = [b for b, row in enumerate(rows) if not row[6]]
        if not moving:
            return      # pairs of fixed bodies are never evaluated
        radius = [self.shapes[row[0]].bounding_radius for row in rows]
        body = max(moving, key=lambda b: radius[b])
        other = max(range(len(rows)), key=lambda b: radius[b])
        if radius[other] <= radius[body]:
            other = body
        reach = radius[body] + radius[other]
        length = upper - lower
        if length >= 2.0 * reach:
            return

        def named(b):
            shape = rows[b][0]
            return (f"body {b} (shape {shape} '{self.shapes[shape].name}', "
                    f"{'fixed' if rows[b][6] else 'moving'}, bounding radius "
                    f"{radius[b]:.4g} m)")
        if other == body:
            what = (f"twice the bounding diameter {2.0 * radius[body]:.4g} m of {named(body)}, "
                    "the largest moving body")
        else:
            what = (f"twice the reach {reach:.4g} m (the two bounding radii) of {named(body)}, the "
                    f"largest moving body, and {named(other)}")
        raise CaseFileError(
            f"periodic {name}: the period {length:.4g} m (upper - lower) is shorter than {what}: "
            f"a pair of bodies could touch through both ends of the strip. Make the strip at least "
            f"{2.0 * reach:.4g} m wide.")

    def _period_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Per axis the strip's lower end (m) and its period (m; 0: not periodic), as the
        kernels take them (``StepSettings``)."""
        lower, period = np.zeros(3), np.zeros(3)
        if self._periodic is not None:
            axis, low, high = self._periodic
            lower[axis], period[axis] = low, high - low
        return lower, period

    def _refuse_wall_across_period(self, index: int, wall: Wall) -> None:
        """Refuse wall ``index`` when its normal has a component along the periodic direction:
        the strip needs no walls there, and one across it would cut the periodic flow."""
        if self._periodic is None:
            return
        axis, lower, upper = self._periodic
        name = _AXIS_NAMES[axis]
        if abs(wall.normal[axis]) > _WALL_ACROSS_PERIODIC:
            raise CaseFileError(
                f"wall {index} (point {wall.point}, normal {wall.normal}) faces along {name}, the "
                f"periodic direction (period [{lower:.6g}, {upper:.6g}) m): a periodic "
                f"direction needs no walls; leave out the walls across {name}")

    def minimum_image(self, separations) -> np.ndarray:
        """``separations`` (..., 3) m between two places, each shifted by the whole number of
        periods that makes it shortest along the periodic direction (a copy; unchanged without
        one)."""
        d = np.array(separations, dtype=np.float64)
        if self._periodic is not None:
            axis, lower, upper = self._periodic
            length = upper - lower
            d[..., axis] -= length * np.floor(d[..., axis] / length + 0.5)
        return d

    def add_body(self, *, shape: int, material: int | str, position, orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), fixed: bool = False,
                 frame: str = "shape") -> int:
        """Add a body; returns its index.

        ``position`` is the centroid (m). ``orientation`` (w, x, y, z) rotates the shape *as built*
        (``frame="shape"``) or its principal frame (``frame="principal"``). ``material`` is an
        index or a material name.
        """
        if isinstance(material, str):
            material = self.material_index(material)
        q = np.asarray(orientation, dtype=np.float64)
        norm = np.linalg.norm(q)
        if not np.isfinite(norm) or norm < 1e-6:
            raise CaseFileError(f"body {len(self._body_rows)}: orientation {tuple(q)} is not a rotation")
        q = q / norm
        if frame == "shape":
            q = _quaternion_multiply(q, _quaternion_from_matrix(self.shapes[shape].frame_rotation))
        self._body_rows.append((int(shape), int(material), np.asarray(position, float), q,
                                np.asarray(velocity, float), np.asarray(angular_velocity, float),
                                bool(fixed)))
        self._ready = False
        return len(self._body_rows) - 1

    @property
    def ready(self) -> bool:
        """Whether the flat arrays are built and the first forces evaluated (:meth:`finalize`)."""
        return self._ready

    def steps_at(self, time: float) -> int:
        """The step count at which the clock reaches ``time`` (s) at the current time step,
        counted from the last change of step."""
        if self._time_origin is None:
            return int(math.ceil(time / self.time_step - 1e-9))
        return self._step_origin + int(math.ceil((time - self._time_origin) / self.time_step - 1e-9))

    def moving_shapes(self) -> list:
        """The shapes of the bodies that are not fixed, before or after :meth:`finalize`."""
        if self._ready:
            return [self.shapes[s] for s, fixed in zip(self.shape_index, self.fixed) if not fixed]
        return [self.shapes[row[0]] for row in self._body_rows if not row[6]]

    def body_poses(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every body's shape index (n,), material index (n,), centroid (n, 3) m, orientation of
        its principal frame (n, 4) (w, x, y, z) and whether it is fixed (n,), before or after
        :meth:`finalize` (after it: where the bodies are now)."""
        if self._ready:
            return (self.shape_index.copy(), self.material_index_of_body.copy(),
                    self.positions.copy(), self.quaternions.copy(), self.fixed.copy())
        rows = self._body_rows
        n = len(rows)
        return (np.array([r[0] for r in rows], dtype=np.int64),
                np.array([r[1] for r in rows], dtype=np.int64),
                np.array([r[2] for r in rows], dtype=np.float64).reshape(n, 3),
                np.array([r[3] for r in rows], dtype=np.float64).reshape(n, 4),
                np.array([r[6] for r in rows], dtype=np.bool_))

    def restore_state(self, arrays: dict, time_step: float) -> None:
        """Continue from a checkpoint's state arrays at ``time_step`` (s): the arrays built and
        the state loaded, without evaluating forces again."""
        self.time_step = float(time_step)
        self._ready = True
        self.load_state_arrays(arrays)

    def start_at_rest_from(self, arrays: dict) -> None:
        """Take the poses and contact history of another run's end state (its
        :meth:`state_arrays`) with every body at rest, and evaluate the forces there; this run's
        clock and time step stay. A step of a test series starts so, where the step before
        ended, as a flume test goes on once the water is still.

        The history stays the one taken, to the bit: the evaluation at rest gives the forces of
        the first step only. (Kept from it, a spring could change: its cap, friction times the
        normal force, loses the damping the end state's speeds gave, and the pieces of the
        contact, found afresh, sum its stiffness in another order.)"""
        self.finalize()
        for name in ("positions", "quaternions"):
            value = np.asarray(arrays[name], dtype=np.float64)
            if value.shape != getattr(self, name).shape:
                raise CaseFileError(f"the bodies' end state has '{name}' of shape {value.shape}, "
                                    f"this run {getattr(self, name).shape}: not the same bodies")
            setattr(self, name, np.ascontiguousarray(value.copy()))
        keys = np.ascontiguousarray(np.asarray(arrays["history_keys"]).copy())
        springs = np.ascontiguousarray(np.asarray(arrays["history_springs"]).copy())
        self.history_keys, self.history_springs = keys, springs
        self.velocities[:] = 0.0
        self.angular_momenta[:] = 0.0
        self.external_loads[:] = 0.0
        self._piece_cache = interactions.empty_piece_cache()
        self._compute_forces(self.time_step)
        self.history_keys, self.history_springs = keys.copy(), springs.copy()

    def clear_contact_records(self) -> None:
        """Make the contact records again from the last force evaluation when next asked (after
        the state arrays were replaced)."""
        self._contacts = None

    def forget_contacts(self) -> None:
        """Drop the last force evaluation's results (after the state was replaced): the contact
        records are made again from the next evaluation."""
        self._last = (np.zeros((0, interactions.C_SIZE)), np.zeros((0, 2), np.int64),
                      np.zeros((0, 2), np.int64))
        self._contacts = None

    @property
    def n_bodies(self) -> int:
        return len(self._body_rows) if not self._ready else len(self.positions)

    def finalize(self) -> None:
        """Build the flat arrays, choose the time step and evaluate the initial forces; called
        automatically before the first step."""
        if self._ready:
            return
        self.build_arrays()
        if self.time_step is None:
            self.time_step = self.stable_time_step()
        self._ready = True
        self._compute_forces(self.time_step)

    def build_arrays(self) -> None:
        """Stack the bodies added so far into the flat arrays (again, if already built)."""
        if not self._body_rows:
            raise CaseFileError("no bodies: add at least one body")
        rows = self._body_rows
        n = len(rows)
        self.shape_index = np.array([r[0] for r in rows], dtype=np.int64)
        self.material_index_of_body = np.array([r[1] for r in rows], dtype=np.int64)
        self.positions = np.array([r[2] for r in rows], dtype=np.float64).reshape(n, 3)
        self.quaternions = np.array([r[3] for r in rows], dtype=np.float64).reshape(n, 4)
        self.velocities = np.array([r[4] for r in rows], dtype=np.float64).reshape(n, 3)
        self.fixed = np.array([r[6] for r in rows], dtype=np.bool_)
        densities = np.array([self.materials[m].density for m in self.material_index_of_body])
        volumes = np.array([self.shapes[s].volume for s in self.shape_index])
        self.masses = densities * volumes
        self.principal_inertia = densities[:, None] * np.array(
            [self.shapes[s].unit_principal_moments for s in self.shape_index]).reshape(n, 3)
        self.inverse_masses = np.where(self.fixed, 0.0, 1.0 / self.masses)
        self.inverse_principal_inertia = np.where(self.fixed[:, None], 0.0, 1.0 / self.principal_inertia)
        self.velocities[self.fixed] = 0.0
        omegas = np.array([r[5] for r in rows], dtype=np.float64).reshape(n, 3)
        omegas[self.fixed] = 0.0
        self.angular_momenta = np.zeros((n, 3))
        for b in range(n):
            r = rotation_matrix(self.quaternions[b])
            self.angular_momenta[b] = r @ (self.principal_inertia[b] * (r.T @ omegas[b]))
        self.forces = np.zeros((n, 3))
        self.torques = np.zeros((n, 3))
        self._check_periodic()
        periodic.wrap_positions(self.positions, *self._period_arrays())
        self.table = ShapeTable.build(self.shapes)
        self._shapes = self.table.kernel_arrays()
        self.bounding_radius = self._shapes.lookup.bounding_radius
        tables = pair_tables(self.materials, self.friction_pairs)
        self._pair_laws = PairLaws(tables["penalty"], tables["friction"], tables["damping_ratio"],
                                   tables["tangential_ratio"])
        self.wall_points = np.array([w.point for w in self.walls], dtype=np.float64).reshape(-1, 3)
        self.wall_normals = np.array([w.normal for w in self.walls], dtype=np.float64).reshape(-1, 3)
        self.wall_materials = np.array([self.material_index(w.material) for w in self.walls], dtype=np.int64)
        self.history_keys = np.zeros(0, dtype=np.int64)
        self.history_springs = np.zeros((0, interactions.HISTORY_WIDTH))
        # Force (3) and torque (3) held on each free body besides gravity and contacts (N, N m):
        # the fluid's, in a coupled run.
        self.external_loads = np.zeros((n, 6))
        if self.initial_contact_history is not None:
            self._load_initial_history(*self.initial_contact_history)
        self._margin = _BROAD_PHASE_MARGIN * float(self.bounding_radius.max())
        if self.contact_skin is None:
            self._skin = _SKIN_OVER_SUBTET_HEIGHT * min(
                (shape.boundary_subtet_height for shape in self.shapes), default=0.0)
        else:
            self._skin = float(self.contact_skin)
        self._piece_cache = interactions.empty_piece_cache()

    def set_initial_contact_history(self, body_i, body_j, springs) -> None:
        """Start from these contacts' spring state (elastic tangential force, twisting torque and
        the stiffnesses they were built with; ``body_j = -1 - w`` for wall ``w``), as a placed
        pack carries it, instead of from none."""
        self.initial_contact_history = (np.asarray(body_i, dtype=np.int64).reshape(-1),
                                        np.asarray(body_j, dtype=np.int64).reshape(-1),
                                        np.asarray(springs, dtype=np.float64).reshape(-1, 6))
        self._ready = False

    def _load_initial_history(self, body_i, body_j, springs) -> None:
        n, n_walls = len(self.positions), len(self.walls)
        if len(body_i) and (body_i.min() < 0 or body_i.max() >= n or body_j.max() >= n
                            or body_j.min() < -n_walls):
            raise CaseFileError(f"the contact history names bodies or walls that the case does not "
                                f"have ({n} bodies, {n_walls} walls)")
        stride = n + n_walls
        keys = np.where(body_j >= 0, body_i * stride + body_j, body_i * stride + (stride + body_j))
        order = np.argsort(keys)
        self.history_keys = np.ascontiguousarray(keys[order])
        self.history_springs = np.ascontiguousarray(springs[order])

    def contact_history(self):
        """The current contacts' spring state: (body_i, body_j, springs (n, 6)) in the layout of
        :meth:`set_initial_contact_history`."""
        self.finalize()
        stride = len(self.positions) + len(self.walls)
        body_i = self.history_keys // stride
        rest = self.history_keys % stride
        body_j = np.where(rest < len(self.positions), rest, rest - stride)
        return body_i.astype(np.int64), body_j.astype(np.int64), self.history_springs.copy()

    # ------------------------------------------------------------------ physics
    def stable_time_step(self, safety: float = 0.2) -> float:
        """Time step from body masses and the largest plausible contact stiffness.

        For each free body: k = 2 p A / h with A = V^(2/3) (a face-to-face contact of the whole
        body), h the 10th-percentile boundary sub-tet height, and the smaller of the translational
        mass and the rotational mass I_min / r_max^2; Delta t = safety * 2 sqrt(m / k) (the
        critical step of an undamped spring is 2/omega). References: Munjiza (2004) ch. 3; the
        check Delta t <= 0.2 * 2 sqrt(m/k) follows the Y3D practice summarised in
        shared/research/munjiza.md.
        """
        steps = self.critical_time_steps()
        best = float(steps.min(initial=np.inf))
        if not np.isfinite(best):
            best = 1e-3
        return safety * best

    def critical_time_steps(self) -> np.ndarray:
        """Per body, the critical step 2 sqrt(m / k) of :meth:`stable_time_step` (inf for fixed
        bodies): the smallest names the body that sets the run's step."""
        stiffness = self.plausible_contact_stiffness()
        steps = np.full(len(self.shape_index), np.inf)
        for b in np.flatnonzero(~self.fixed):
            shape = self.shapes[self.shape_index[b]]
            rotational_mass = self.principal_inertia[b].min() / shape.bounding_radius ** 2
            mass = min(self.masses[b], rotational_mass)
            steps[b] = 2.0 * np.sqrt(mass / stiffness[b])
        return steps

    def plausible_contact_stiffness(self) -> np.ndarray:
        """Per body, the largest plausible normal stiffness of one of its contacts (N/m):
        k = 2 p A / h with A = V^(2/3) (a face-to-face contact of the whole body), h the
        10th-percentile boundary sub-tet height and p the largest penalty of its material's
        pairs. A cube landing face down on a floor measured 1.04 of it (issue 52, at a step 40
        times the automatic one, so pressed deep). Fixed bodies too."""
        if not self._ready:
            self.build_arrays()
        stiffness = np.zeros(len(self.shape_index))
        for b in range(len(self.shape_index)):
            shape = self.shapes[self.shape_index[b]]
            penalty = self._pair_laws.penalty[self.material_index_of_body[b]].max()
            stiffness[b] = 2.0 * penalty * shape.volume ** (2.0 / 3.0) / shape.min_subtet_height
        return stiffness

    def _kernel_state(self, step: float):
        """The bundles the stepping kernels take (``solid/kernels/bundles.py``), made afresh per
        call because a restart or ``fix_bodies`` may have replaced the arrays they hold."""
        system = RigidSystem(
            Bodies(self.masses, self.inverse_masses, self.inverse_principal_inertia, self.fixed,
                   self.shape_index, self.material_index_of_body),
            self._shapes,
            Walls(self.wall_points, self.wall_normals, self.wall_materials),
            self._pair_laws)
        motion = Motion(self.positions, self.quaternions, self.velocities, self.angular_momenta,
                        self.forces, self.torques)
        settings = StepSettings(self.gravity, self.external_loads, self._margin, step,
                                self.local_damping, self._skin, *self._period_arrays())
        return system, motion, History(self.history_keys, self.history_springs), settings

    def _compute_forces(self, step: float) -> None:
        system, motion, history, settings = self._kernel_state(step)
        (history, results, body_pairs, wall_pairs, self._omegas, overflow,
         self._piece_cache) = stepper.compute_forces(system, motion, history, settings,
                                                     self._piece_cache)
        self.history_keys, self.history_springs = history
        self._store_results(results, body_pairs, wall_pairs)
        if overflow:
            self._raise_overflow()

    def _store_results(self, results, body_pairs, wall_pairs) -> None:
        self._last = (results, body_pairs, wall_pairs)
        self._contacts = None
        self._n_candidates = len(results)

    def _raise_overflow(self):
        raise KernelOverflowError(
            "contact candidate buffer overflowed: a shape has too many tets per lookup cell; "
            "re-mesh it more uniformly or report this as a bug")

    def split_bodies_over(self, processes) -> None:
        """Split the bodies over ``processes`` (``riprap.parallel.communicator``) by the place of
        their centre (``riprap/solid/bodies_over_processes.py``): each process finds and
        evaluates the contact pairs of its own bodies and adds up their forces; every process
        integrates every body with the joined forces. The forces, the springs, the contact
        records and the bodies are those of one process, bit for bit, on every process."""
        self._split = BodiesOverProcesses(processes) if processes.size > 1 else None

    def bodies_split_lines(self) -> list[str]:
        """A line per process: the slab of x whose bodies it owns now (re-cut at each
        ``advance``) and how many."""
        self.finalize()
        split = self._split
        if split is None:
            return [f"process 0: all {len(self.positions)} bodies"]
        split.cuts = split.balanced_cuts(self)
        counts = split.owned_counts(self)
        lines = []
        for rank, count in enumerate(counts):
            lower, upper = split.slab_of(rank)
            lines.append(f"process {rank}: the {count} bodies with centre x in [{lower:.4g}, "
                         f"{upper:.4g}) m (the cuts follow the bodies to share the contact pairs)")
        return lines

    def advance(self, n_steps: int) -> None:
        """Advance ``n_steps`` time steps in compiled code.

        Raises InstabilityError (naming the body and time) when the state stops being finite; the
        state is then left as it was at the failing step.
        """
        self.finalize()
        if n_steps <= 0:
            return
        if self._split is not None:
            self._advance_split(n_steps)
            return
        system, motion, history, settings = self._kernel_state(self.time_step)
        (done, status, history, results, body_pairs, wall_pairs, self._omegas,
         self._piece_cache) = stepper.advance(int(n_steps), system, motion, self._omegas, history,
                                              settings, self._piece_cache)
        self.history_keys, self.history_springs = history
        self.step_count += int(done)
        self.time = self.step_count * self.time_step if self._time_origin is None else self._time_origin + (self.step_count - self._step_origin) * self.time_step
        self._store_results(results, body_pairs, wall_pairs)
        if status == stepper.STATUS_OVERFLOW:
            self._raise_overflow()
        if status == stepper.STATUS_NOT_FINITE:
            self.check_finite()

    def _advance_split(self, n_steps: int) -> None:
        """``advance`` with the bodies split over the processes by the place of their centre."""
        done, status = self._split.advance(self, n_steps)
        self.step_count += int(done)
        self.time = (self.step_count * self.time_step if self._time_origin is None else
                     self._time_origin + (self.step_count - self._step_origin) * self.time_step)
        if status == stepper.STATUS_OVERFLOW:
            self._raise_overflow()
        if status == stepper.STATUS_NOT_FINITE:
            self.check_finite()

    def fix_bodies(self, bodies) -> None:
        """Hold these bodies fixed from now on, where they are (their velocities are zeroed)."""
        self.finalize()
        bodies = np.asarray(bodies, dtype=np.int64)
        self.fixed[bodies] = True
        self.inverse_masses[bodies] = 0.0
        self.inverse_principal_inertia[bodies] = 0.0
        self.velocities[bodies] = 0.0
        self.angular_momenta[bodies] = 0.0
        self._omegas[bodies] = 0.0

    def set_time_step(self, time_step: float) -> None:
        """Use ``time_step`` from now on; the clock keeps counting from its current value."""
        if time_step == self.time_step:
            return
        self._time_origin = self.time
        self._step_origin = self.step_count
        self.time_step = float(time_step)

    def step(self) -> None:
        """Advance by one time step."""
        self.advance(1)

    # ------------------------------------------------------------------ diagnostics
    @property
    def contacts(self) -> ContactRecords:
        """Contacts of the last force evaluation."""
        self.finalize()
        if self._contacts is None:
            results, body_pairs, wall_pairs = self._last
            active = results[:, interactions.C_ACTIVE] > 0
            body_i = np.concatenate([body_pairs[:, 0], wall_pairs[:, 0]])[active]
            body_j = np.concatenate([body_pairs[:, 1], -1 - wall_pairs[:, 1]])[active]
            r = results[active]
            self._contacts = ContactRecords(
                body_i=body_i, body_j=body_j,
                points=r[:, interactions.C_POINT:interactions.C_POINT + 3],
                normal_forces=r[:, interactions.C_NORMAL_FORCE:interactions.C_NORMAL_FORCE + 3],
                tangential_forces=r[:, interactions.C_TANGENTIAL_FORCE:interactions.C_TANGENTIAL_FORCE + 3],
                stiffness=r[:, interactions.C_STIFFNESS])
        return self._contacts

    @property
    def angular_velocities(self) -> np.ndarray:
        return integrate.angular_velocities(self.quaternions, self.angular_momenta,
                                            self.inverse_principal_inertia)

    def contact_forces(self) -> np.ndarray:
        """Total contact force on each body (N): its force less gravity and the external loads."""
        self.finalize()
        gravity = np.where(self.fixed[:, None], 0.0, self.masses[:, None] * self.gravity)
        return self.forces - gravity - self.external_loads[:, :3]

    def kinetic_energy(self) -> float:
        omega = self.angular_velocities
        translational = 0.5 * np.sum(self.masses[~self.fixed] * np.sum(self.velocities[~self.fixed] ** 2, axis=1))
        rotational = 0.5 * np.sum(np.sum(omega * self.angular_momenta, axis=1)[~self.fixed])
        return float(translational + rotational)

    def potential_energy(self) -> float:
        return float(-np.sum(self.masses[~self.fixed] * (self.positions[~self.fixed] @ self.gravity)))

    def rotation_matrices(self) -> np.ndarray:
        return rotation_matrices(np.ascontiguousarray(self.quaternions))

    def overlaps(self, tolerance: float = 0.0) -> list[tuple[int, int, float]]:
        """Touching pairs whose mean overlap depth (potential force / stiffness) exceeds
        ``tolerance`` (m). Walls appear as j = -1 - wall index."""
        c = self.contacts
        found = []
        for k in range(len(c)):
            potential = np.linalg.norm(c.normal_forces[k])
            depth = potential / c.stiffness[k] if c.stiffness[k] > 0 else 0.0
            if depth > tolerance:
                found.append((int(c.body_i[k]), int(c.body_j[k]), float(depth)))
        return found

    def check_no_initial_overlap(self, tolerance: float, accepted: dict | None = None) -> None:
        """Raise OverlapError listing every pair that overlaps deeper than ``tolerance`` (m).

        ``accepted`` maps pairs ``(body_i, body_j)`` to an overlap depth they may have (a placed
        pack's resting contacts); such a pair is refused only when it overlaps deeper than that
        (plus ``tolerance``), i.e. when a body was moved into it."""
        accepted = accepted or {}
        found = [(i, j, depth) for i, j, depth in self.overlaps(tolerance)
                 if depth > accepted.get((i, j), 0.0) * (1.0 + _ACCEPTED_DEPTH_SLACK) + tolerance]
        self._check_coincident_bodies()
        if found:
            lines = []
            for i, j, depth in found[:20]:
                other = f"wall {-1 - j}" if j < 0 else f"body {j}"
                lines.append(f"  body {i} and {other}: overlap depth {depth:.3e} m")
            more = f"\n  ... and {len(found) - 20} more" if len(found) > 20 else ""
            raise OverlapError(
                f"{len(found)} overlapping pair(s) at the start (tolerance {tolerance:.1e} m):\n"
                + "\n".join(lines) + more
                + "\nMove the bodies apart (larger grid spacing or a higher start) and run again.")

    def _check_coincident_bodies(self) -> None:
        """Two bodies whose centroids (nearly) coincide occupy the same place; their potential
        forces cancel by symmetry when their shapes are the same, so the overlap test above
        cannot see them."""
        from scipy.spatial import cKDTree

        radius = self.bounding_radius[self.shape_index]
        reach = _COINCIDENT_FRACTION * float(radius.max())
        places, bodies = self.positions, np.arange(len(self.positions))
        if self._periodic is not None:
            # the centres within reach of either end also a period beyond the other, so that
            # a pair across the boundary is found as one inside the strip
            axis, lower, upper = self._periodic
            low = np.flatnonzero(self.positions[:, axis] < lower + reach)
            high = np.flatnonzero(self.positions[:, axis] >= upper - reach)
            up, down = self.positions[low].copy(), self.positions[high].copy()
            up[:, axis] += upper - lower
            down[:, axis] -= upper - lower
            places = np.concatenate([places, up, down])
            bodies = np.concatenate([bodies, low, high])
        pairs = cKDTree(places).query_pairs(reach, output_type="ndarray")
        if self._periodic is not None and len(pairs):
            pairs = np.unique(np.sort(bodies[pairs], axis=1), axis=0)
            pairs = pairs[pairs[:, 0] != pairs[:, 1]]
        if len(pairs) == 0:
            return
        gaps = np.linalg.norm(self.minimum_image(self.positions[pairs[:, 0]]
                                                 - self.positions[pairs[:, 1]]), axis=1)
        close = gaps < _COINCIDENT_FRACTION * np.minimum(radius[pairs[:, 0]], radius[pairs[:, 1]])
        pairs = pairs[close]
        if len(pairs):
            listed = ", ".join(f"bodies {int(i)} and {int(j)}" for i, j in sorted(map(tuple, pairs[:10])))
            more = f" and {len(pairs) - 10} more pairs" if len(pairs) > 10 else ""
            raise OverlapError(f"{len(pairs)} pair(s) of bodies occupy the same place (centroids "
                               f"closer than {_COINCIDENT_FRACTION:g} of their bounding radius): "
                               f"{listed}{more}. Each body needs its own position.")

    def check_finite(self) -> None:
        """Raise InstabilityError naming the first body whose state is not finite."""
        bad = ~(np.isfinite(self.positions).all(axis=1) & np.isfinite(self.velocities).all(axis=1)
                & np.isfinite(self.quaternions).all(axis=1) & np.isfinite(self.angular_momenta).all(axis=1))
        if bad.any():
            first = int(np.argmax(bad))
            raise InstabilityError(
                f"body {first} has a non-finite state at t = {self.time:.6g} s (step {self.step_count}); "
                f"{int(bad.sum())} bodies affected")

    # ------------------------------------------------------------------ state I/O (arrays only)
    STATE_ARRAYS = ("positions", "quaternions", "velocities", "angular_momenta", "forces", "torques",
                    "history_keys", "history_springs")

    def state_arrays(self) -> dict[str, np.ndarray]:
        self.finalize()
        arrays = {name: getattr(self, name).copy() for name in self.STATE_ARRAYS}
        # time, steps, time step, and the clock's anchor (time and step count of the last time
        # step change; NaN when time = steps x time step), so a restart counts time identically.
        origin = np.nan if self._time_origin is None else self._time_origin
        arrays["clock"] = np.array([self.time, float(self.step_count), self.time_step, origin,
                                    float(self._step_origin)])
        return arrays

    def load_state_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        self.finalize()
        for name in self.STATE_ARRAYS:
            current = getattr(self, name)
            value = np.asarray(arrays[name])
            if name not in ("history_keys", "history_springs") and value.shape != current.shape:
                raise CaseFileError(f"checkpoint array '{name}' has shape {value.shape}, "
                                    f"the case has {current.shape}: the checkpoint is from another case")
            setattr(self, name, np.ascontiguousarray(value.copy()))
        self.time = float(arrays["clock"][0])
        self.step_count = int(arrays["clock"][1])
        self.time_step = float(arrays["clock"][2])
        clock = np.asarray(arrays["clock"])
        if len(clock) >= 5:
            self._time_origin = None if np.isnan(clock[3]) else float(clock[3])
            self._step_origin = int(clock[4])
        else:
            self._time_origin = None if self.time == self.step_count * self.time_step else self.time
            self._step_origin = self.step_count
        self._omegas = integrate.angular_velocities(self.quaternions, self.angular_momenta,
                                                    self.inverse_principal_inertia)
        self._piece_cache = interactions.empty_piece_cache()


def _quaternion_multiply(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _quaternion_from_matrix(m) -> np.ndarray:
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(np.asarray(m)).as_quat()
    return np.array([w, x, y, z])
