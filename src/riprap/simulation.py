"""Simulation: the one user-facing run, of rigid bodies, of air and water, or of both coupled.

It builds the bodies (shapes, materials, walls: :class:`riprap.solid.solver.SolidSolver`), takes
a fluid (:class:`riprap.fluid.solver.FluidSolver`) when one is given, and runs them as one model
(:mod:`riprap.models`): rigid bodies alone, the fluid alone, or the two coupled
(:class:`riprap.coupling.coupled.CoupledSolver`). It owns the schedule of periodic work (frames,
checkpoints, progress, the rest check) and the failure checkpoint; the models own the physics. A
run that fails writes a checkpoint of the last good state and says what failed, where and when.
"""
from __future__ import annotations

import os
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, OverlapError, RiprapError
from riprap.schedules import Every
from riprap.work_estimate import (MAX_CHECKPOINTS, MAX_FRAMES, check_deformable_run,
                                   check_rigid_run, schedule_problems)
from riprap.geometry.tetmesh import TetMesh
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver
from riprap.solid.walls import Wall

# Bodies may touch but not overlap at the start: a mean overlap depth above this fraction of the
# smallest boundary sub-tet height is reported (a just-touching placement gives exactly zero).
_INITIAL_OVERLAP_FRACTION = 0.01
# A speed above this (m/s) means the explicit scheme has blown up even if numbers are still finite.
_RUNAWAY_SPEED = 1.0e3
# Largest allowed dt / (2 sqrt(m_eff / k)) over the contacts actually present (1 is the stability
# limit of an undamped spring; rotation about the contact lowers the effective mass, hence margin).
_MAX_STABILITY_RATIO = 0.5
# A body rests when its net force is below this fraction of its weight (and it is slow).
_REST_FORCE_RATIO = 0.1
_MAX_MOTION_PER_STEP = 0.1
# Gravity above this (m/s^2) is named as the likely cause of a blow-up (a centrifuge model runs
# at tens of g; more is a typo).
_ABSURD_GRAVITY = 1000.0
# A run whose clock and step count stay where they are over this many chunks in a row is stuck
# (a step too small to change the clock): it stops with an error instead of spinning.
_MOST_CHUNKS_WITHOUT_PROGRESS = 1000


@dataclass
class RunSummary:
    """What a run did. Written as ``summary.json`` in the output directory.

    The fields every run has come first; the model's own figures follow and are None (and left
    out of ``summary.json``) where a model has none: rigid runs report bodies, contacts and
    body-steps/s, fluid runs cells, Courant numbers and the water volume error, coupled runs both.
    """

    end_reason: str
    simulated_time: float
    steps: int
    wall_time: float
    frames: int
    model: str = "rigid"         # "rigid", "fluid", "coupled" or "deformable"
    outputs: dict = field(default_factory=dict)
    case_file: str = ""          # the case file run (absolute), "" when built in Python
    smoke: bool = False          # RIPRAP_SMOKE=1 cut the run short: its figures are not results
    # bodies (rigid and coupled runs)
    bodies: int | None = None
    contacts: int | None = None
    time_step: float | None = None
    body_steps_per_second: float | None = None
    kinetic_energy: float | None = None
    max_speed: float | None = None
    stability_ratio_max: float | None = None
    time_step_cuts: int | None = None
    solid_substeps: int | None = None
    # time steps taken (the contact step of a rigid run, the fluid's step of a fluid run)
    time_step_min: float | None = None
    time_step_max: float | None = None
    # fluid (fluid and coupled runs)
    cells: int | None = None
    cell_updates_per_second: float | None = None
    courant_number_max: float | None = None
    water_volume_error: float | None = None
    pressure_iterations_mean: float | None = None
    pressure_iterations_max: int | None = None
    pressure_time_share: float | None = None
    # deformable bodies
    element_steps_per_second: float | None = None
    max_tensile_stress: float | None = None
    # fracture (deformable runs with joints)
    broken_joints: int | None = None
    broken_area: float | None = None      # m^2, one side of the cracks
    pieces: int | None = None             # deformable bodies and fragments, each counted once
    fracture_energy: float | None = None  # J taken by the joints (stored and dissipated)

    def as_dict(self) -> dict:
        return {key: value for key, value in self.__dict__.items() if value is not None}


class Simulation:
    """A run: rigid bodies (shapes, materials, bodies, walls), air and water (``fluid``), or
    bodies in the flow (both), with a clock and outputs.

    Parameters (keyword-only, SI units; the same names as the ``[simulation]`` and ``[output]``
    tables of a case file)
    ----------
    end_time : float
        Simulated time to reach (s).
    time_step : float
        Time step (s); 0 means automatic: ``time_step_safety`` times the critical step estimated
        from body masses and contact stiffness.
    gravity : (3,) float
        m/s^2; left at its default (0, 0, -9.81) with a fluid given, the fluid's.
    output_interval : float
        Simulated seconds between ParaView frames.
    checkpoint_interval : float
        Simulated seconds between checkpoints; 0 writes one only at the end (and on failure).
    local_damping : float
        Cundall's non-viscous numerical damping in [0, 1); 0 for physics, ~0.3 to settle packs.
    rest_speed : float
        If > 0, the run stops once every free body moves slower than this (m/s, including the
        rotational speed at its bounding radius).
    rest_kinetic_energy : float
        If > 0, resting also needs the total kinetic energy of the free bodies below this (J).
    adaptive_time_step : bool
        Let the time step follow the contacts actually present: grow it while their measured
        stability ratio dt / (2 sqrt(m/k)) stays below 0.2, halve it and repeat the chunk from the
        last good state when it passes 0.5 or the state blows up. For settling and packing runs;
        physics runs keep a fixed step (and a failure stops them).
    output_directory : str or Path
    paraview, picture : bool
        Write a ``.pvd`` series / a PNG of the final state.
    body_forces_interval : float
        Simulated seconds between the rows of ``body_forces.csv`` (bodies in a flow); 0: at the
        frames (``output_interval``).
    progress : bool
        Show a progress bar on the terminal.
    fluid : FluidSolver, optional
        The flow: with no bodies the run is a fluid run; with bodies they move in it, two-way
        coupled (``docs/coupling.md``), and ``time_step`` / ``time_step_safety`` set the contact
        sub-step inside each fluid step (the fluid's own step follows its Courant number).
    """

    def __init__(self, *, end_time: float, time_step: float = 0.0, time_step_safety: float = 0.2,
                 gravity=(0.0, 0.0, -9.81), output_interval: float = 0.05,
                 checkpoint_interval: float = 0.0, local_damping: float = 0.0,
                 rest_speed: float = 0.0, output_directory="riprap-out", paraview: bool = True,
                 picture: bool = True, progress: bool = True, rest_kinetic_energy: float = 0.0,
                 adaptive_time_step: bool = False, fluid=None, body_forces_interval: float = 0.0):
        _require(end_time > 0, "end_time", end_time, "> 0 s")
        _require(time_step >= 0, "time_step", time_step, ">= 0 s (0 = automatic)")
        _require(0 < time_step_safety <= 1, "time_step_safety", time_step_safety, "in (0, 1]")
        _require(output_interval > 0, "output_interval", output_interval, "> 0 s")
        _require(checkpoint_interval >= 0, "checkpoint_interval", checkpoint_interval, ">= 0 s")
        _require(rest_speed >= 0, "rest_speed", rest_speed, ">= 0 m/s")
        _require(rest_kinetic_energy >= 0, "rest_kinetic_energy", rest_kinetic_energy, ">= 0 J")
        for key, value, message in schedule_problems(end_time=end_time,
                                                     output_interval=output_interval,
                                                     checkpoint_interval=checkpoint_interval):
            raise CaseFileError(f"simulation.{key} = {value:g}: {message}")
        self.rest_kinetic_energy = float(rest_kinetic_energy)
        self.adaptive_time_step = bool(adaptive_time_step)
        self._last_stability_ratio = 0.0
        self.end_time = float(end_time)
        self.requested_time_step = float(time_step)
        self.time_step_safety = float(time_step_safety)
        self.output_interval = float(output_interval)
        self.checkpoint_interval = float(checkpoint_interval)
        self.rest_speed = float(rest_speed)
        #: Each default writer's own interval (s) where it has one ([output] *_interval keys).
        self.output_intervals = {}
        self.set_output_interval("body_forces", body_forces_interval)
        self.output_directory = Path(output_directory)
        self.paraview = bool(paraview)
        self.picture = bool(picture)
        # The case file this simulation was built from (set by build_simulation); recorded in
        # summary.json so that `riprap analyse RUN` finds the pack a run started from.
        self.case_file = ""
        # What defines the run (riprap.case.run_record.RunDefinition, set by the case builders):
        # kept in every checkpoint, and a restart with a case changed beyond what may change is
        # refused. None for a run built in Python: its restarts are not checked.
        self.run_definition = None
        self.progress = bool(progress)
        if fluid is not None and tuple(np.asarray(gravity, dtype=float)) == (0.0, 0.0, -9.81):
            gravity = fluid.gravity
        self.solver = SolidSolver(gravity=gravity, local_damping=local_damping)
        self._shape_names: dict[str, int] = {}
        self._meshes: list[TetMesh] = []
        self.container_box = None
        #: The run's frames: every ``output_interval`` s (writers with no schedule of their own).
        self.frame_schedule = Every(seconds=self.output_interval)
        self._writers = []               # added with add_writer, written after the model's own
        self._restored_schedules = {}    # {writer name: entry due next} from a restart's checkpoint
        self._scheduled_writers = []     # the run's writers with a schedule of their own
        self._checkpoints_written = 0    # periodic checkpoints (next at (count + 1) * interval)
        self._restarted = False
        self._model = None
        #: The flow the bodies move in (:meth:`add_fluid`), or None for a dry run.
        self.fluid = None
        if fluid is not None:
            self.add_fluid(fluid)
        # Pairs allowed to overlap at the start, up to a depth (m): a pack's resting contacts.
        self.accepted_overlaps: dict[tuple[int, int], float] = {}
        #: Deformable bodies (:meth:`add_deformable_body`) and how they touch.
        self.deformable_bodies = []
        self.deformable_contact_penalty = None
        self.deformable_mass_damping = 0.0
        # For runs built from a case: the case's number of each deformable and each rigid body,
        # and the resting overlaps (m) of a pack's contacts that involve deformable bodies.
        self.deformable_case_index: list[int] = []
        self.deformable_accepted_depths: dict[tuple[int, int], float] = {}

    # ------------------------------------------------------------------ building
    def add_material(self, material: Material) -> None:
        self.solver.add_material(material)

    def add_shape(self, name: str, mesh: TetMesh | RigidShape) -> None:
        """Add a shape by name: a tetrahedral mesh, or a prepared :class:`RigidShape` (whose frame
        as built is then its principal frame)."""
        if name in self._shape_names:
            raise CaseFileError(f"shape '{name}' defined twice")
        shape = mesh if isinstance(mesh, RigidShape) else RigidShape.from_mesh(mesh, name=name)
        self._shape_names[name] = self.solver.add_shape(shape)
        self._meshes.append(shape.mesh if isinstance(mesh, RigidShape) else mesh)

    def shape(self, name: str) -> RigidShape:
        return self.solver.shapes[self._shape_index(name)]

    def _shape_index(self, name: str) -> int:
        if name not in self._shape_names:
            raise CaseFileError(f"unknown shape '{name}' (defined: {', '.join(self._shape_names)})")
        return self._shape_names[name]

    def add_body(self, *, shape: str, material: str, position, orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                 fixed: bool = False, frame: str = "shape") -> int:
        """Add a body; ``position`` is its centroid (m), ``orientation`` a quaternion (w, x, y, z)
        applied to the shape as built (``frame="shape"``) or to its principal frame
        (``frame="principal"``, as the solver stores it). Returns the body index."""
        return self.solver.add_body(shape=self._shape_index(shape),
                                    material=self.solver.material_index(material),
                                    position=position, orientation=orientation, velocity=velocity,
                                    angular_velocity=angular_velocity, fixed=fixed, frame=frame)

    def add_deformable_body(self, *, shape: str, material, position,
                            orientation=(1.0, 0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0),
                            angular_velocity=(0.0, 0.0, 0.0), element_type: str = "tet4",
                            name: str | None = None, joints=None) -> int:
        """Add a deformable body (:class:`riprap.deformable.DeformableBody`) of a shape's mesh:
        ``material`` an :class:`riprap.deformable.ElasticMaterial`, ``position`` its centroid
        (m), ``orientation`` a quaternion (w, x, y, z) applied to the mesh as built, ``velocity``
        and ``angular_velocity`` its initial rigid motion. ``joints``: a
        :class:`riprap.deformable.joints.JointMaterial` (joints between all its tets), or one with
        a box ((lower), (upper)) in m at the start, joints only between tets whose centroids lie
        in it: the body cracks (:class:`riprap.deformable.joints.FracturingBody`). Returns its
        index among the deformable bodies."""
        from scipy.spatial.transform import Rotation

        from riprap.deformable.body import DeformableBody
        from riprap.geometry.mass_properties import mass_properties

        mesh = self._meshes[self._shape_index(shape)]
        centroid = np.asarray(mass_properties(mesh).centroid, dtype=np.float64)
        w, x, y, z = (float(v) for v in orientation)
        rotation = Rotation.from_quat([x, y, z, w]).as_matrix()
        nodes = (mesh.nodes - centroid) @ rotation.T + np.asarray(position, dtype=np.float64)
        index = len(self.deformable_bodies)
        name = name or f"{shape}_{index}"
        if joints is None:
            body = DeformableBody(nodes, mesh.tets, material, element_type=element_type, name=name)
        else:
            from riprap.deformable.joints import FracturingBody, check_crack_resolution

            if element_type != "tet4":
                raise CaseFileError(f"deformable body '{name}': joints need element_type 'tet4', "
                                    f"not {element_type!r}")
            joint_material, region = joints if isinstance(joints, tuple) else (joints, None)
            cracking = None
            if region is not None:
                centres = nodes[mesh.tets].mean(axis=1)
                lower, upper = (np.asarray(corner, dtype=np.float64) for corner in region)
                cracking = np.all((centres >= lower) & (centres <= upper), axis=1)
            check_crack_resolution(nodes, mesh.tets, name)
            body = FracturingBody(nodes, mesh.tets, material, joint_material, name=name,
                                  cracking=cracking)
        offsets = body.positions - np.asarray(position, dtype=np.float64)
        body.velocities[:] = np.asarray(velocity, dtype=np.float64) + np.cross(
            np.asarray(angular_velocity, dtype=np.float64), offsets)
        self.deformable_bodies.append(body)
        return index

    def add_walls(self, walls: list[Wall], *, container_box=None) -> None:
        self.solver.add_walls(walls)
        if container_box is not None:
            self.container_box = container_box

    # ------------------------------------------------------------------ running
    def add_fluid(self, fluid) -> None:
        """Put the run in a flow: a :class:`riprap.fluid.solver.FluidSolver` (the bodies, if any,
        are coupled to it when the run starts) or a ready
        :class:`riprap.coupling.coupled.CoupledSolver`."""
        if self._model is not None:
            raise RiprapError("add_fluid: the run is already prepared; add the fluid first")
        self.fluid = fluid

    @property
    def model(self):
        """What the run loop advances (:mod:`riprap.models`), built on first use: the rigid
        bodies, the fluid, or both coupled."""
        if self._model is None:
            self._model = self._build_model()
        return self._model

    @property
    def coupled(self) -> bool:
        """Whether bodies move in a fluid."""
        return self.fluid is not None and (hasattr(self.fluid, "solids") or self.solver.n_bodies > 0
                                           or bool(self.deformable_bodies))

    def _build_model(self):
        from riprap.models.fluid import CoupledModel, FluidModel
        from riprap.models.rigid import RigidModel

        if self.deformable_bodies:
            return self._deformable_model()
        if self.fluid is None:
            return RigidModel(self)
        if hasattr(self.fluid, "solids"):            # a CoupledSolver built by the caller
            self.solver = self.fluid.solids
            return CoupledModel(self.fluid)
        if self.solver.n_bodies == 0:
            return FluidModel(self.fluid)
        from riprap.coupling.coupled import CoupledSolver
        from riprap.coupling.obstacles import add_obstacle_bodies, name_obstacles_in_overlap

        # The fluid's obstacles are walls for the bodies too: fixed bodies of the same cells.
        boxes = getattr(self.fluid, "obstacle_boxes", [])
        obstacle_bodies = add_obstacle_bodies(self, boxes)
        try:
            self._prepare_bodies()
        except OverlapError as error:
            raise name_obstacles_in_overlap(error, obstacle_bodies, boxes) from None
        return CoupledModel(CoupledSolver(self.fluid, self.solver, obstacle_bodies=obstacle_bodies))

    def _deformable_model(self):
        from riprap.models.deformable import DeformableModel

        if self.fluid is not None:
            return self._deformable_coupled_model()
        solver = self.solver
        if solver.n_bodies > 0:
            # rigid bodies too: they keep their own solver, stepped with the deformable bodies'
            # step, and meet the deformable bodies through their surface layers
            self.build_without_checks()
        system = self._deformable_system(solver.gravity)
        step = self.requested_time_step if self.requested_time_step > 0 else system.time_step
        if solver.n_bodies > 0:
            step = min(step, solver.time_step)
            solver.set_time_step(step)
        system.time_step = step
        check_deformable_run(end_time=self.end_time, time_step=step, elements=len(system.elements),
                             rigid_bodies=int((~solver.fixed).sum()) if solver.n_bodies else 0)
        return DeformableModel(system, rigid=self if solver.n_bodies > 0 else None,
                               case_numbers=self._case_numbers(),
                               accepted_depths=self.deformable_accepted_depths)

    def _deformable_system(self, gravity, extra_walls=()):
        """The deformable bodies joined in one system, with the rigid solver's bodies (built
        already) as surfaces they touch, its walls, and ``extra_walls`` not already among them
        (with the deformable bodies' smallest friction coefficient)."""
        from riprap.coupling.coupled import _same_plane
        from riprap.deformable.system import DeformableSystem

        solver = self.solver
        rigid_surfaces = []
        for b in range(solver.n_bodies):
            shape = solver.shapes[int(solver.shape_index[b])]
            material = solver.materials[int(solver.material_index_of_body[b])]
            mass = np.inf if solver.fixed[b] else float(solver.masses[b])
            rigid_surfaces.append((shape.mesh.nodes, shape.mesh.tets, material.friction_coefficient,
                                   mass, material.damping_ratio))
        walls = [(wall.point, wall.normal,
                  solver.materials[solver.material_index(wall.material)].friction_coefficient)
                 for wall in solver.walls]
        friction = min(b.material.friction_coefficient for b in self.deformable_bodies)
        walls += [(wall.point, wall.normal, friction) for wall in extra_walls
                  if not any(_same_plane(wall, other) for other in solver.walls)]
        return DeformableSystem(self.deformable_bodies, walls=walls,
                                contact_penalty=self.deformable_contact_penalty, gravity=gravity,
                                mass_damping=self.deformable_mass_damping,
                                rigid_surfaces=rigid_surfaces)

    def _deformable_coupled_model(self):
        """Deformable bodies (and rigid ones, if any) in the flow
        (``riprap.coupling.deformable_coupled``); the fluid box's sides (all but an open top) and
        the case's walls bound them."""
        from riprap.coupling.coupled import _same_plane, fluid_box_walls
        from riprap.coupling.deformable_coupled import DeformableBodies, DeformableCoupledSolver
        from riprap.models.deformable import DeformableModel
        from riprap.models.deformable_coupled import DeformableCoupledModel

        solver = self.solver
        if hasattr(self.fluid, "solids"):
            raise CaseFileError("deformable bodies cannot join a CoupledSolver built by the caller: "
                                "give the Simulation a FluidSolver")
        if solver.n_bodies > 0:
            # the sides of the box are walls for the rigid bodies too (unless already there)
            material = solver.materials[0].name
            solver.add_walls([wall for wall in fluid_box_walls(self.fluid.grid, material)
                              if not any(_same_plane(wall, other) for other in solver.walls)])
            self._prepare_bodies()
        system = self._deformable_system(self.fluid.gravity,
                                         extra_walls=fluid_box_walls(self.fluid.grid, ""))
        if self.requested_time_step > 0:
            system.time_step = self.requested_time_step
        check_deformable_run(end_time=self.end_time, time_step=system.time_step,
                             elements=len(system.elements))
        coupled = DeformableCoupledSolver(self.fluid, DeformableBodies(
            system, rigid=solver if solver.n_bodies > 0 else None))
        stresses = DeformableModel(system, rigid=self if solver.n_bodies > 0 else None,
                                   case_numbers=self._case_numbers(),
                                   accepted_depths=self.deformable_accepted_depths)
        return DeformableCoupledModel(coupled, stresses)

    def _case_numbers(self):
        """(case number of each deformable body, of each rigid body): their own orders when the
        run was built in Python."""
        deformable = list(self.deformable_case_index) or list(range(len(self.deformable_bodies)))
        taken = set(deformable)
        rigid = [i for i in range(len(deformable) + self.solver.n_bodies) if i not in taken]
        return deformable, rigid

    def prepare(self) -> None:
        """Build the model, choose time steps, evaluate initial forces and check the start state
        (nothing overlaps; bodies inside the fluid box and wide enough for its cells)."""
        self.model.prepare(restarted=self._restarted)

    def _prepare_bodies(self) -> None:
        solver = self.solver
        if solver._ready:
            return
        self.build_without_checks()
        check_rigid_run(end_time=self.end_time, time_step=solver.time_step,
                        moving_bodies=int((~solver.fixed).sum()), start_time=solver.time,
                        setting_the_step=self._body_setting_the_step)
        if not self._restarted:
            self.check_start_overlaps()

    def _body_setting_the_step(self, numbered: bool = True) -> str:
        """The body whose mass and contact stiffness chose the automatic time step, in words
        (with its number when ``numbered``); "" for a step the user gave."""
        if self.requested_time_step > 0:
            return ""
        solver = self.solver
        steps = solver.critical_time_steps()
        if not np.isfinite(steps).any():
            return ""
        body = int(np.argmin(steps))
        shape = solver.shapes[int(solver.shape_index[body])]
        return ((f"body {body}, " if numbered else "")
                + f"shape '{shape.name}', Dn = {shape.volume ** (1 / 3):.3g} m, "
                f"{solver.masses[body]:.3g} kg")

    def check_start_overlaps(self) -> None:
        """Refuse bodies that overlap at the start (beyond the accepted resting contacts of a
        pack) or occupy the same place."""
        smallest = min(shape.min_subtet_height for shape in self.solver.shapes)
        self.solver.check_no_initial_overlap(_INITIAL_OVERLAP_FRACTION * smallest,
                                             accepted=self.accepted_overlaps)

    def contact_history(self):
        """The current contacts as a :class:`riprap.io.contact_history.ContactHistory` (spring
        state and overlap depths), to start another run from this state."""
        from riprap.io.contact_history import ContactHistory

        body_i, body_j, springs = self.solver.contact_history()
        depths = {(i, j): depth for i, j, depth in self.solver.overlaps(0.0)}
        return ContactHistory(body_i, body_j, springs,
                              [depths.get((int(i), int(j)), 0.0) for i, j in zip(body_i, body_j)])

    def set_contact_history(self, history) -> None:
        """Start from the contacts of a placed pack (a
        :class:`riprap.io.contact_history.ContactHistory`): their friction carries over and their
        overlaps, up to the depths recorded, are accepted at the start."""
        self.solver.set_initial_contact_history(history.body_i, history.body_j, history.springs)
        self.accepted_overlaps = history.accepted_depths()

    def build_without_checks(self) -> None:
        """Build the solver's arrays, choose the time step and evaluate the initial forces, without
        refusing overlaps (callers that resolve overlaps themselves use ``solver.overlaps``)."""
        solver = self.solver
        solver._build_arrays()
        if self.requested_time_step > 0:
            solver.time_step = self.requested_time_step
        else:
            solver.time_step = solver.stable_time_step(self.time_step_safety)
        solver.finalize()

    def run(self, *, restart_from=None, after_chunk=None) -> RunSummary:
        """Run to ``end_time`` (or rest); write frames, checkpoints, pictures and the summary.

        The one run loop for every model (rigid bodies, air and water, bodies in the flow): it
        advances the model towards the next scheduled time (frame, checkpoint, end), writes what
        is due, shows progress, and stops with a failure checkpoint of the last good state when
        the model reports an instability. ``after_chunk(simulation)``, if given, is called after
        every chunk of work (a few per second of wall time) and may change the state (e.g. fix
        bodies); the run stops with end reason "done" when it returns True.
        """
        from riprap.io.output_folder import prepare_output_folder
        from riprap.io.summary import write_json

        out = self.output_directory
        prepare_output_folder(out)
        if restart_from is not None:
            self.restart(restart_from)
        self.prepare()
        model = self.model
        writers = self.writers(model)
        schedules = self._open_writers(model, writers, out)
        last_written = {id(schedule): model.time for schedule, _ in schedules}
        if not self._restarted:
            for schedule, due in schedules:
                self._write_entry(model, schedule, due)
        start_wall = wallclock.perf_counter()
        start_steps = model.step_count
        end_reason = "end_time"
        good = model.state_arrays()
        with _Progress(self.progress, self.end_time, model.name) as progress:
            stalled = 0
            while not model.reached(self.end_time):
                until = min(time for time in self._scheduled_times(model, schedules)
                            if not model.reached(time))
                before = (model.time, model.step_count)
                try:
                    model.advance(until)
                except InstabilityError as error:
                    if model.recover(good):
                        continue
                    model.load_state_arrays(good)
                    path = self._save_checkpoint("failure_checkpoint.npz", good)
                    raise InstabilityError(
                        f"{error}\nThe last good state (t = {float(good['clock'][0]):.6g} s) was "
                        f"written to {path}. {model.failure_advice(good)}") from None
                stalled = stalled + 1 if (model.time, model.step_count) == before else 0
                if stalled > _MOST_CHUNKS_WITHOUT_PROGRESS:
                    raise RiprapError(
                        f"the {model.name} run is stuck at t = {model.time:.9g} s: "
                        f"{_MOST_CHUNKS_WITHOUT_PROGRESS} chunks of work in a row moved neither "
                        f"the clock nor the step count (time step {model.last_time_step():.3g} "
                        "s); check [simulation] time_step and the intervals")
                good = model.state_arrays()
                for schedule, due in schedules:
                    if schedule.due(model):
                        self._write_entry(model, schedule, due)
                        last_written[id(schedule)] = model.time
                if (self.checkpoint_interval > 0 and model.reached(
                        (self._checkpoints_written + 1) * self.checkpoint_interval)):
                    self._checkpoints_written = _first_not_reached(
                        model, self._checkpoints_written + 1, self.checkpoint_interval,
                        MAX_CHECKPOINTS, "checkpoint_interval") - 1
                    self._save_checkpoint("checkpoint.npz", good)
                progress.update(model, start_wall, start_steps)
                if after_chunk is not None:
                    if after_chunk(self):
                        end_reason = "done"
                        break
                    good = model.state_arrays()
                if model.at_rest():
                    end_reason = "at_rest"
                    break
                model.after_good_chunk()
        wall = wallclock.perf_counter() - start_wall
        frames = self._frame_index
        for schedule, due in schedules:
            if model.time - last_written[id(schedule)] > 0.5 * model.last_time_step():
                # The run ended between entries (at rest, or an end time off the schedule): its
                # last state is an entry too, outside the schedule a restart counts on.
                for writer in due:
                    writer.write(model, schedule.index)
                if schedule is self.frame_schedule:
                    frames += 1
        outputs = {"checkpoint": str(self._save_checkpoint("checkpoint.npz", model.state_arrays()))}
        for writer in writers:
            outputs.update(writer.close(model))
        steps = model.step_count - start_steps
        summary = RunSummary(model=model.name, end_reason=end_reason, simulated_time=model.time,
                             steps=steps, wall_time=wall, frames=frames, outputs=outputs,
                             case_file=self.case_file,
                             smoke=os.environ.get("RIPRAP_SMOKE", "") == "1",
                             **model.summary_fields(wall, steps))
        write_json(out / "summary.json", summary.as_dict())
        return summary

    def _open_writers(self, model, writers, directory) -> list:
        """Open every writer; returns [(schedule, its writers)], the frames' schedule first (it
        is kept even with no writer on it: its times are where a fluid's steps land). A restart
        takes each schedule's entry from the checkpoint; a schedule the checkpoint does not know
        starts at its first entry not reached."""
        self.frame_schedule.seconds = self.output_interval      # as set now, not at __init__
        schedules = {id(self.frame_schedule): (self.frame_schedule, [])}
        self._scheduled_writers = [writer for writer in writers if writer.schedule is not None]
        for writer in writers:
            schedule = writer.schedule or self.frame_schedule
            if id(schedule) not in schedules:
                schedules[id(schedule)] = (schedule, [])
                if self._restarted:
                    schedule.index = self._restored_schedules.get(writer.name, 0)
                    while schedule.due(model) and schedule.index <= MAX_FRAMES:
                        schedule.index += 1
            schedules[id(schedule)][1].append(writer)
            writer.open(model, directory, append=self._restarted)
        return list(schedules.values())

    def _scheduled_times(self, model, schedules) -> list[float]:
        times = [self.end_time] + [schedule.next_time(model) for schedule, _ in schedules]
        if self.checkpoint_interval > 0:
            times.append((self._checkpoints_written + 1) * self.checkpoint_interval)
        return times

    def _write_entry(self, model, schedule, writers) -> None:
        for writer in writers:
            writer.write(model, schedule.index)
        if model.reached(self.end_time):
            schedule.index += 1
        else:
            # a chunk longer than the interval: no entry twice
            name = ("simulation.output_interval" if schedule is self.frame_schedule
                    else f"the writer {writers[0].name!r}")
            schedule.written(model, MAX_FRAMES, name)

    def _step_keeps_motion_small(self, time_step: float) -> bool:
        """No body moves more than _MAX_MOTION_PER_STEP of the smallest boundary sub-tet height in
        one step, so that a contact cannot go from nothing to a deep overlap in one step."""
        smallest = min(shape.min_subtet_height for shape in self.solver.shapes)
        return self.max_speed() * time_step <= _MAX_MOTION_PER_STEP * smallest

    def _check_runaway(self) -> None:
        speeds = np.linalg.norm(self.solver.velocities, axis=1)
        if speeds.max(initial=0.0) > _RUNAWAY_SPEED:
            body = int(np.argmax(speeds))
            raise InstabilityError(
                f"body {body} moves at {speeds[body]:.3g} m/s at t = {self.solver.time:.6g} s, "
                f"faster than any armour unit or rock should ({_RUNAWAY_SPEED:g} m/s)")

    def _blow_up_advice(self, good: dict) -> str:
        """What to change after a blow-up, judged from the last good state: the time step only
        where it is the cause, not where gravity or a start velocity is absurd."""
        s = self.solver
        smallest = min(shape.min_subtet_height for shape in s.shapes)
        gravity = float(np.linalg.norm(s.gravity))
        speeds = np.linalg.norm(np.asarray(good["velocities"]), axis=1)
        speed = float(speeds[~s.fixed].max(initial=0.0))
        causes = []
        if gravity > _ABSURD_GRAVITY:
            causes.append(f"gravity is {gravity:.3g} m/s^2 (the earth's is 9.81): check "
                          "[simulation] gravity")
        if speed * s.time_step > _MAX_MOTION_PER_STEP * smallest:
            causes.append(f"a body moved {speed * s.time_step:.3g} m per step at {speed:.3g} m/s, "
                          f"more than a tenth of the thinnest boundary layer of tetrahedra "
                          f"({smallest:.3g} m), so contacts start too deep: check the start "
                          "velocities, or lower time_step")
        if not causes:
            what = ("set [simulation] time_step below the step used" if self.requested_time_step
                    else "lower [simulation] time_step_safety (or set a smaller time_step)")
            causes.append(f"the time step {s.time_step:.3e} s is too large for the contact "
                          f"stiffness: {what}, or lower contact_penalty")
        return ("Likely cause: " + "; ".join(causes) + ". After lowering the time step, restart "
                "from the checkpoint with --restart: the new time step is used from there (any "
                "other change to the case, such as contact_penalty or gravity, needs a new run).")

    def at_rest(self) -> bool:
        """Every free body slower than ``rest_speed`` and, under gravity, with a net force below
        ``_REST_FORCE_RATIO`` of its weight (a body at the top of a bounce is slow but not at rest)."""
        if self.max_speed() >= self.rest_speed:
            return False
        s = self.solver
        if self.rest_kinetic_energy > 0 and s.kinetic_energy() >= self.rest_kinetic_energy:
            return False
        g = float(np.linalg.norm(s.gravity))
        free = ~s.fixed
        if g == 0.0 or not free.any():
            return True
        ratio = np.linalg.norm(s.forces[free], axis=1) / (s.masses[free] * g)
        return bool(ratio.max() < _REST_FORCE_RATIO)

    def stability_ratio(self) -> float:
        """max over current contacts of dt / (2 sqrt(m_eff / k)), k the contact's measured stiffness
        and m_eff the smaller of the translational and rotational effective masses of the pair."""
        s = self.solver
        c = s.contacts
        if len(c) == 0:
            return 0.0
        shapes = s.shape_index
        rotational = s.principal_inertia.min(axis=1) / s.bounding_radius[shapes] ** 2
        inverse = np.where(s.fixed, 0.0, 1.0 / np.minimum(s.masses, rotational))
        inverse_j = np.where(c.body_j >= 0, inverse[np.maximum(c.body_j, 0)], 0.0)
        ratio = s.time_step * np.sqrt(c.stiffness * (inverse[c.body_i] + inverse_j)) / 2.0
        worst = int(np.argmax(ratio))
        j = int(c.body_j[worst])
        self._stiffest_pair = f"body {int(c.body_i[worst])} and " + (f"wall {-1 - j}" if j < 0 else f"body {j}")
        return float(ratio[worst])

    def _check_contact_stability(self) -> None:
        ratio = self.stability_ratio()
        self._last_stability_ratio = ratio
        self._max_stability_ratio = max(getattr(self, "_max_stability_ratio", 0.0), ratio)
        if ratio > _MAX_STABILITY_RATIO:
            raise InstabilityError(
                f"time step {self.solver.time_step:.3e} s is too large for the contacts at t = "
                f"{self.solver.time:.6g} s: dt / (2 sqrt(m/k)) = {ratio:.2f} > {_MAX_STABILITY_RATIO} "
                f"at the contact of {self._stiffest_pair}; lower time_step or time_step_safety, or "
                "contact_penalty")

    def max_speed(self) -> float:
        """Largest speed of a free body including rotation at its bounding radius (m/s)."""
        s = self.solver
        free = ~s.fixed
        if not free.any():
            return 0.0
        radius = s.bounding_radius[s.shape_index]
        speed = np.linalg.norm(s.velocities, axis=1) + np.linalg.norm(s.angular_velocities, axis=1) * radius
        return float(speed[free].max())

    # ------------------------------------------------------------------ outputs
    @property
    def _frame_index(self) -> int:
        """Frames written on the schedule (the next at index * output_interval)."""
        return self.frame_schedule.index

    @_frame_index.setter
    def _frame_index(self, index: int) -> None:
        self.frame_schedule.index = int(index)

    def add_writer(self, writer) -> None:
        """Write one more output family during the run: a :class:`riprap.outputs.Writer` (its
        ``schedule`` a :class:`riprap.schedules.Every`, or None for the frames), written after the
        model's own outputs at the same times."""
        if any(writer.name == other.name for other in self._writers):
            raise RiprapError(f"add_writer: a writer named {writer.name!r} is there already; give "
                              "each writer its own name (it keys the writer's schedule in "
                              "checkpoints)")
        self._writers.append(writer)

    def set_output_interval(self, name: str, interval: float) -> None:
        """Give the default writer ``name`` (``"body_forces"``) an interval of its own (s); 0
        writes it at the frames. A bad value is refused naming ``[output] {name}_interval``."""
        key = f"output.{name}_interval"
        if not (isinstance(interval, (int, float)) and not isinstance(interval, bool)
                and np.isfinite(interval) and interval >= 0):
            raise CaseFileError(f"{key} = {interval!r}: expected a number >= 0 s (0 = at the "
                                "frames, every output_interval)")
        if interval > 0 and self.end_time / interval > MAX_FRAMES:
            raise CaseFileError(
                f"{key} = {interval:g}: {self.end_time / interval:.3g} entries in end_time = "
                f"{self.end_time:g} s, more than the {MAX_FRAMES} a run may write; set it >= "
                f"{self.end_time / MAX_FRAMES:.3g} s (end_time / {MAX_FRAMES})")
        if interval > 0:
            self.output_intervals[name] = float(interval)
        else:
            self.output_intervals.pop(name, None)

    def writers(self, model) -> list:
        """Every writer of the run: the model's defaults (``[output]`` paraview, picture and
        the intervals), then the ones added with :meth:`add_writer`."""
        from riprap.outputs.base import ModelFrames

        if hasattr(model, "default_writers"):
            defaults = model.default_writers(paraview=self.paraview, picture=self.picture)
        else:       # a model of the older interface: its outputs in its own three methods
            defaults = [ModelFrames(paraview=self.paraview, picture=self.picture)]
        for writer in defaults:
            if writer.name in self.output_intervals:
                writer.schedule = Every(seconds=self.output_intervals[writer.name])
        return defaults + self._writers

    def surface_arrays(self):
        """World boundary surfaces of all bodies: points (n, 3), triangles (m, 3), body of each
        triangle (m,)."""
        from riprap.solid.surfaces import surface_arrays

        return surface_arrays(self.solver)

    def contact_forces_on_bodies(self) -> np.ndarray:
        """Total contact force on each body (N), i.e. the force without gravity."""
        return self.solver.contact_forces()

    def contact_statistics(self) -> dict:
        """Per body: coordination number, largest contact force (N) and factor of safety against
        sliding (:func:`riprap.analysis.unit_contacts.solver_contact_statistics`)."""
        from riprap.analysis.unit_contacts import solver_contact_statistics

        return solver_contact_statistics(self.solver)

    def write_picture(self, path, *, show_fixed: bool = False, planes=None, view=(25, -60),
                      title: str | None = None) -> Path:
        """Shaded PNG of the bodies now (:func:`riprap.io.picture.render_bodies_png`).

        Free bodies are drawn in distinct colours. Fixed bodies are left out, or drawn in grey
        with ``show_fixed`` (e.g. the underlayer rocks under a placed layer); when every body is
        fixed, all are drawn in colour. ``planes``: quadrilaterals (4, 3), m, drawn translucent
        (e.g. the slope face); ``view``: camera elevation and azimuth, degrees. The default title
        counts free and fixed bodies separately and says which are not drawn."""
        from riprap.io.picture import bodies_to_draw, render_bodies_png

        s = self.solver
        points, triangles, owners = self.surface_arrays()
        drawn, grey, description = bodies_to_draw(s.fixed, show_fixed=show_fixed)
        shown = drawn[owners]
        box = None
        if self.container_box is not None:
            # Show the container only up to a little above the bodies, not its full height.
            lo, hi = (np.array(v, dtype=float) for v in self.container_box)
            top = points[:, 2].max() if len(points) else hi[2]
            hi[2] = min(hi[2], top + 0.15 * (top - lo[2]))
            box = (tuple(lo), tuple(hi))
        return render_bodies_png(path, triangles_world=points[triangles][shown], body_ids=owners[shown],
                                 grey_bodies=np.flatnonzero(grey), planes=planes, view=view,
                                 title=title or f"{description} at t = {s.time:.3f} s",
                                 walls_box=box)

    # ------------------------------------------------------------------ checkpoints
    def _save_checkpoint(self, name: str, state: dict) -> Path:
        from riprap.io.checkpoint import save_checkpoint

        model = self.model
        arrays, metadata = model.checkpoint_content(state)
        metadata.update({"kind": model.kind, "frame_index": self._frame_index,
                         "checkpoints_written": self._checkpoints_written,
                         "time": float(state["clock"][0])})
        own = {writer.name: writer.schedule.index for writer in self._scheduled_writers}
        if own:
            metadata["schedules"] = own
        if self.run_definition is not None:
            metadata["case_record"] = self.run_definition.values
        return save_checkpoint(self.output_directory / name, arrays=arrays, metadata=metadata)

    def check_restart(self, path) -> tuple[dict, dict]:
        """Every check of a restart from ``path`` (``riprap check --restart`` makes them too): a
        readable checkpoint of this kind of run, of this case (nothing changed but what may
        change), with the model's own checks (meshes, cells, bodies). Returns its arrays and
        metadata."""
        from riprap.io.checkpoint import load_checkpoint

        arrays, metadata = load_checkpoint(path)
        self._check_same_run(path, metadata)
        model = self.model
        kind = metadata.get("kind")
        if kind not in _ACCEPTED_KINDS[model.kind]:
            raise RiprapError(f"{path}: a checkpoint of a {kind!r} run; this case is a "
                              f"{model.name} run ({model.kind!r})")
        model.check_checkpoint(path, arrays, metadata)
        return arrays, metadata

    def restart(self, path) -> None:
        """Continue from a checkpoint written by a run of the same case."""
        self._restarted = True          # before the model is built: a restart's overlaps are its own
        arrays, metadata = self.check_restart(path)
        model = self.model
        kind = metadata.get("kind")
        model.restore(arrays)
        self._frame_index = int(metadata["frame_index"])
        self._restored_schedules = dict(metadata.get("schedules", {}))
        if "checkpoints_written" in metadata:
            self._checkpoints_written = int(metadata["checkpoints_written"])
        else:
            # Checkpoints of riprap before the one run loop: a rigid run stored the index of the
            # next checkpoint (from 1), a fluid run the number written.
            self._checkpoints_written = (int(metadata["checkpoint_index"])
                                         - (1 if kind == "riprap rigid run" else 0))


    def _check_same_run(self, path, metadata: dict) -> None:
        """Refuse a restart whose case changed in what defines the run (not the end time, the
        outputs or the time step); a checkpoint of an older riprap, without that record, restarts
        with a warning."""
        if self.run_definition is None:
            return
        recorded = metadata.get("case_record")
        if recorded is None:
            import warnings

            from riprap.work_estimate import RiprapWarning

            warnings.warn(f"{path} was written by an older riprap and does not record the case it "
                          "was run with: restarting without checking that the case is unchanged "
                          "(only end_time, outputs and the time step may change)", RiprapWarning,
                          stacklevel=3)
            return
        refusal = self.run_definition.refusal(path, recorded)
        if refusal is not None:
            raise CaseFileError(refusal)


# Checkpoint kinds a model restarts from: coupled runs were "fluid runs" before the one run loop.
_ACCEPTED_KINDS = {"riprap rigid run": ("riprap rigid run",),
                   "riprap deformable run": ("riprap deformable run",),
                   "riprap deformable coupled run": ("riprap deformable coupled run",),
                   "riprap fluid run": ("riprap fluid run",),
                   "riprap coupled run": ("riprap coupled run", "riprap fluid run")}


def _first_not_reached(model, index: int, interval: float, most: int, key: str) -> int:
    """The first of ``index``, ``index + 1``, ... whose time ``index * interval`` the model has not
    reached. The schedule holds at most ``most`` such times (``schedule_problems``), so more
    steps than that mean a clock that cannot be trusted: an error, not a loop without end."""
    for _ in range(most + 2):
        if not model.reached(index * interval):
            return index
        index += 1
    raise RiprapError(f"the schedule of simulation.{key} = {interval:g} s ran past {most} entries "
                      f"at t = {model.time:.6g} s; the run's clock has left its schedule, report it")


def _require(ok: bool, key: str, value, expected: str) -> None:
    if not ok:
        raise CaseFileError(f"simulation.{key} = {value!r}: expected {expected}")


#: Wall seconds between the plain progress lines written where stderr is not a terminal (a run
#: sent to a log file or a batch queue), where a live bar shows nothing.
PLAIN_PROGRESS_PERIOD = 60.0


class _Progress:
    """A rich progress bar on a terminal: simulated time, steps/s and the model's own figures; a
    plain line every ``PLAIN_PROGRESS_PERIOD`` wall seconds to stderr elsewhere."""

    def __init__(self, enabled: bool, end_time: float, name: str):
        import sys

        self.enabled = enabled
        self.end_time = end_time
        self.name = name
        self._progress = None
        self._plain = enabled and not sys.stderr.isatty()
        self._last_line = wallclock.perf_counter()
        self._start_time = None

    def __enter__(self):
        if self.enabled and not self._plain:
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self._progress = Progress(
                TextColumn("[bold]t = {task.completed:.4f} / {task.total:.4f} s"), BarColumn(),
                TextColumn("{task.fields[rate]} steps/s"), TextColumn("{task.fields[figures]}"),
                TimeRemainingColumn(), transient=False)
            self._progress.__enter__()
            self._task = self._progress.add_task(self.name, total=self.end_time, rate="-",
                                                 figures="")
        return self

    def update(self, model, start_wall, start_steps):
        if self._plain:
            self._plain_line(model, start_wall)
        if self._progress is None:
            return
        rate = (model.step_count - start_steps) / max(wallclock.perf_counter() - start_wall, 1e-9)
        self._progress.update(self._task, completed=min(model.time, self.end_time),
                              rate=f"{rate:,.1f}" if rate < 100 else f"{rate:,.0f}",
                              figures=model.progress_text())

    def _plain_line(self, model, start_wall) -> None:
        import sys

        now = wallclock.perf_counter()
        if self._start_time is None:          # the rate counts from the first chunk's end
            self._start_time, self._start_wall = model.time, now
            return
        if now - self._last_line < PLAIN_PROGRESS_PERIOD or model.time <= self._start_time:
            return
        self._last_line = now
        wall = now - start_wall
        done = min(model.time, self.end_time)
        # wall seconds per simulated second so far
        rate = (now - self._start_wall) / (model.time - self._start_time)
        remaining = max(self.end_time - done, 0.0) * rate
        print(f"riprap: {self.name}: t = {done:.4g} / {self.end_time:.4g} s, {wall:.0f} s wall "
              f"({rate:.3g} s per simulated s, about {remaining / 60:.0f} min to go)  "
              f"{model.progress_text()}", file=sys.stderr, flush=True)

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.__exit__(*exc)
        return False
