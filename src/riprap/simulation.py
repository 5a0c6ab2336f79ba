"""Simulation: the user-facing run of a rigid FEMDEM case.

It owns the clock and the schedule of periodic work (ParaView frames, checkpoints, progress, the
rest check) around :class:`riprap.solid.solver.SolidSolver`, which owns the physics. A run that
fails (non-finite state) writes a checkpoint of the last good state and says which body and when.
"""
from __future__ import annotations

import math
import os
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, RiprapError
from riprap.work_estimate import check_rigid_run
from riprap.geometry.tetmesh import TetMesh
from riprap.solid.kernels import interactions
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
# Adaptive time step (``adaptive_time_step``): grow by _STEP_GROWTH while the measured stability
# ratio stays below _GROW_BELOW_RATIO, cut by _STEP_CUT (from the last good state) when a chunk
# goes above _MAX_STABILITY_RATIO or blows up; never above _MAX_STEP_OVER_ESTIMATE times the
# automatic estimate nor below _MIN_STEP_OVER_ESTIMATE times it.
_GROW_BELOW_RATIO = 0.2
_STEP_GROWTH = 1.25
_STEP_CUT = 0.5
_MAX_STEP_OVER_ESTIMATE = 30.0
_MIN_STEP_OVER_ESTIMATE = 1e-3
_MAX_MOTION_PER_STEP = 0.1
# Gravity above this (m/s^2) is named as the likely cause of a blow-up (a centrifuge model runs
# at tens of g; more is a typo).
_ABSURD_GRAVITY = 1000.0
_ADAPT_CHUNK_STEPS = 50
# Wall-clock seconds between progress updates (and rest checks).
_PROGRESS_PERIOD = 0.25


@dataclass
class RunSummary:
    """What a run did. Written as ``summary.json`` in the output directory."""

    end_reason: str
    simulated_time: float
    steps: int
    time_step: float
    wall_time: float
    body_steps_per_second: float
    bodies: int
    contacts: int
    kinetic_energy: float
    max_speed: float
    frames: int
    stability_ratio_max: float = 0.0
    time_step_min: float = 0.0
    time_step_max: float = 0.0
    time_step_cuts: int = 0
    outputs: dict = field(default_factory=dict)
    case_file: str = ""          # the case file run (absolute), "" when built in Python
    smoke: bool = False          # RIPRAP_SMOKE=1 cut the run short: its figures are not results

    def as_dict(self) -> dict:
        return dict(self.__dict__)


class Simulation:
    """A rigid-body run: shapes, materials, bodies, walls, a clock and outputs.

    Parameters (keyword-only, SI units; the same names as the ``[simulation]`` and ``[output]``
    tables of a case file)
    ----------
    end_time : float
        Simulated time to reach (s).
    time_step : float
        Time step (s); 0 means automatic: ``time_step_safety`` times the critical step estimated
        from body masses and contact stiffness.
    gravity : (3,) float
        m/s^2.
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
    progress : bool
        Show a progress bar on the terminal.
    """

    def __init__(self, *, end_time: float, time_step: float = 0.0, time_step_safety: float = 0.2,
                 gravity=(0.0, 0.0, -9.81), output_interval: float = 0.05,
                 checkpoint_interval: float = 0.0, local_damping: float = 0.0,
                 rest_speed: float = 0.0, output_directory="riprap-out", paraview: bool = True,
                 picture: bool = True, progress: bool = True, rest_kinetic_energy: float = 0.0,
                 adaptive_time_step: bool = False):
        _require(end_time > 0, "end_time", end_time, "> 0 s")
        _require(time_step >= 0, "time_step", time_step, ">= 0 s (0 = automatic)")
        _require(0 < time_step_safety <= 1, "time_step_safety", time_step_safety, "in (0, 1]")
        _require(output_interval > 0, "output_interval", output_interval, "> 0 s")
        _require(checkpoint_interval >= 0, "checkpoint_interval", checkpoint_interval, ">= 0 s")
        _require(rest_speed >= 0, "rest_speed", rest_speed, ">= 0 m/s")
        _require(rest_kinetic_energy >= 0, "rest_kinetic_energy", rest_kinetic_energy, ">= 0 J")
        self.rest_kinetic_energy = float(rest_kinetic_energy)
        self.adaptive_time_step = bool(adaptive_time_step)
        self._last_stability_ratio = 0.0
        self.end_time = float(end_time)
        self.requested_time_step = float(time_step)
        self.time_step_safety = float(time_step_safety)
        self.output_interval = float(output_interval)
        self.checkpoint_interval = float(checkpoint_interval)
        self.rest_speed = float(rest_speed)
        self.output_directory = Path(output_directory)
        self.paraview = bool(paraview)
        self.picture = bool(picture)
        # The case file this simulation was built from (set by build_simulation); recorded in
        # summary.json so that `riprap analyse RUN` finds the pack a run started from.
        self.case_file = ""
        self.progress = bool(progress)
        self.solver = SolidSolver(gravity=gravity, local_damping=local_damping)
        self._shape_names: dict[str, int] = {}
        self._meshes: list[TetMesh] = []
        self.container_box = None
        self._frame_index = 0
        self._checkpoint_index = 1
        self._restarted = False
        # Pairs allowed to overlap at the start, up to a depth (m): a pack's resting contacts.
        self.accepted_overlaps: dict[tuple[int, int], float] = {}

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

    def add_walls(self, walls: list[Wall], *, container_box=None) -> None:
        self.solver.add_walls(walls)
        if container_box is not None:
            self.container_box = container_box

    # ------------------------------------------------------------------ running
    def prepare(self) -> None:
        """Choose the time step, evaluate initial forces and check that nothing overlaps."""
        solver = self.solver
        if solver._ready:
            return
        self.build_without_checks()
        check_rigid_run(end_time=self.end_time, time_step=solver.time_step,
                        moving_bodies=int((~solver.fixed).sum()), start_time=solver.time)
        if not self._restarted:
            self.check_start_overlaps()

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
        """Run to ``end_time`` (or rest); write frames, checkpoints, picture and summary.

        ``after_chunk(simulation)``, if given, is called after every chunk of steps (a few per
        second of wall time) and may change the state (e.g. fix bodies); the run stops with
        end reason "done" when it returns True.
        """
        from riprap.io import checkpoint as checkpoint_io
        from riprap.io import vtk
        from riprap.io.output_folder import prepare_output_folder

        out = self.output_directory
        prepare_output_folder(out)
        if restart_from is not None:
            self.restart(restart_from)
        self.prepare()
        solver = self.solver
        series = contact_series = None
        if self.paraview:
            series = vtk.ParaViewSeries(out, "bodies", append=self._restarted)
            contact_series = vtk.ParaViewSeries(out, "contacts", append=self._restarted)
            if not self._restarted:
                self._write_frame(series, contact_series)
        estimate = solver.time_step
        smallest_step = largest_step = solver.time_step
        cuts = 0
        start_wall = wallclock.perf_counter()
        start_steps = solver.step_count
        end_reason = "end_time"
        good = solver.state_arrays()
        chunk = 10
        with _Progress(self.progress, self.end_time) as progress:
            while solver.step_count < self._steps_at(self.end_time):
                next_frame = self._steps_at(self._frame_index * self.output_interval)
                targets = [self._steps_at(self.end_time), next_frame]
                if self.checkpoint_interval > 0:
                    targets.append(self._steps_at(self._checkpoint_index * self.checkpoint_interval))
                target = min(t for t in targets if t > solver.step_count)
                n = min(target - solver.step_count, chunk)
                tick = wallclock.perf_counter()
                try:
                    solver.advance(n)
                    self._check_runaway()
                    self._check_contact_stability()
                except InstabilityError as error:
                    if self.adaptive_time_step and (solver.time_step * _STEP_CUT
                                                    >= _MIN_STEP_OVER_ESTIMATE * estimate):
                        cut = solver.time_step * _STEP_CUT
                        solver.load_state_arrays(good)
                        solver.set_time_step(cut)
                        smallest_step = min(smallest_step, cut)
                        cuts += 1
                        continue
                    path = self._write_checkpoint(checkpoint_io, good, "failure_checkpoint.npz")
                    raise InstabilityError(f"{error}\nThe last good state (t = {good['clock'][0]:.6g} s) "
                                           f"was written to {path}. {self._blow_up_advice(good)}"
                                           ) from None
                elapsed = wallclock.perf_counter() - tick
                if self.adaptive_time_step:
                    # Time step decisions at fixed step counts, not wall-clock ones, so that a
                    # run is reproducible.
                    chunk = _ADAPT_CHUNK_STEPS
                else:
                    chunk = max(1, min(100000, int(n * _PROGRESS_PERIOD / max(elapsed, 1e-6))))
                good = solver.state_arrays()
                if solver.step_count >= next_frame and series is not None:
                    self._write_frame(series, contact_series)
                elif solver.step_count >= next_frame:
                    self._frame_index += 1
                if (self.checkpoint_interval > 0 and solver.step_count
                        >= self._steps_at(self._checkpoint_index * self.checkpoint_interval)):
                    self._checkpoint_index += 1
                    self._write_checkpoint(checkpoint_io, good, "checkpoint.npz")
                progress.update(solver, start_wall, start_steps)
                if after_chunk is not None and after_chunk(self):
                    end_reason = "done"
                    break
                good = solver.state_arrays()
                if self.rest_speed > 0 and self.at_rest():
                    end_reason = "at_rest"
                    break
                if (self.adaptive_time_step and self._last_stability_ratio < _GROW_BELOW_RATIO
                        and solver.time_step * _STEP_GROWTH <= _MAX_STEP_OVER_ESTIMATE * estimate
                        and self._step_keeps_motion_small(solver.time_step * _STEP_GROWTH)):
                    solver.set_time_step(solver.time_step * _STEP_GROWTH)
                    largest_step = max(largest_step, solver.time_step)
        wall = wallclock.perf_counter() - start_wall
        dt = solver.time_step
        if series is not None and series.frames and series.frames[-1][0] < solver.time - 0.5 * dt:
            self._write_frame(series, contact_series)
        outputs = {"checkpoint": str(self._write_checkpoint(checkpoint_io, solver.state_arrays(),
                                                            "checkpoint.npz"))}
        if series is not None:
            outputs["paraview"] = str(out / "bodies.pvd")
            outputs["contacts"] = str(out / "contacts.pvd")
        if self.picture:
            outputs["picture"] = str(self.write_picture(out / "final_state.png"))
        steps = solver.step_count - start_steps
        summary = RunSummary(end_reason=end_reason, simulated_time=solver.time, steps=steps,
                             time_step=dt, wall_time=wall,
                             body_steps_per_second=steps * solver.n_bodies / max(wall, 1e-9),
                             bodies=solver.n_bodies, contacts=len(solver.contacts),
                             kinetic_energy=solver.kinetic_energy(), max_speed=self.max_speed(),
                             frames=self._frame_index,
                             stability_ratio_max=getattr(self, "_max_stability_ratio", 0.0),
                             time_step_min=smallest_step, time_step_max=largest_step,
                             time_step_cuts=cuts, outputs=outputs, case_file=self.case_file,
                             smoke=os.environ.get("RIPRAP_SMOKE", "") == "1")
        from riprap.io.summary import write_json
        write_json(out / "summary.json", summary.as_dict())
        return summary

    def _step_keeps_motion_small(self, time_step: float) -> bool:
        """No body moves more than _MAX_MOTION_PER_STEP of the smallest boundary sub-tet height in
        one step, so that a contact cannot go from nothing to a deep overlap in one step."""
        smallest = min(shape.min_subtet_height for shape in self.solver.shapes)
        return self.max_speed() * time_step <= _MAX_MOTION_PER_STEP * smallest

    def _steps_at(self, time: float) -> int:
        """The step count at which the clock reaches ``time`` (at the current time step)."""
        s = self.solver
        if s._time_origin is None:
            return int(math.ceil(time / s.time_step - 1e-9))
        return s._step_origin + int(math.ceil((time - s._time_origin) / s.time_step - 1e-9))

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
        return ("Likely cause: " + "; ".join(causes) + ". Then restart from the checkpoint with "
                "--restart: the new time step is used from there.")

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
        sliding (:mod:`riprap.analysis.unit_contacts`; inf where nothing pushes a body sideways)."""
        from riprap.analysis.unit_contacts import (pair_friction, sliding_factor_of_safety,
                                                   unit_contacts)

        s = self.solver
        contacts = s.contacts
        stats = unit_contacts(s.n_bodies, contacts)
        friction = pair_friction(contacts, [m.friction_coefficient for m in s.materials],
                                 s.material_index_of_body, s.wall_materials)
        return {"coordination_number": stats.coordination_number,
                "max_contact_force": stats.max_contact_force,
                "factor_of_safety_sliding": sliding_factor_of_safety(s.n_bodies, contacts, friction)}

    def _write_frame(self, series, contact_series) -> None:
        s = self.solver
        points, triangles, owners = self.surface_arrays()
        omegas = s.angular_velocities
        contact = self.contact_forces_on_bodies()
        statistics = self.contact_statistics()
        # ParaView colours inf badly; a huge finite number reads as "nothing pushes it sideways".
        safety = np.minimum(statistics["factor_of_safety_sliding"], 1.0e30)
        series.add(s.time, points=points, cells=triangles, cell_type="triangle",
                   cell_data={"body_id": owners, "velocity": s.velocities[owners],
                              "speed": np.linalg.norm(s.velocities, axis=1)[owners],
                              "angular_velocity": omegas[owners],
                              "contact_force": contact[owners],
                              "fixed": s.fixed[owners].astype(np.int64),
                              "coordination_number": statistics["coordination_number"][owners],
                              "max_contact_force": statistics["max_contact_force"][owners],
                              "factor_of_safety_sliding": safety[owners]})
        c = s.contacts
        contact_series.add(s.time, points=c.points, cells=np.arange(len(c)).reshape(-1, 1),
                           cell_type="vertex",
                           point_data={"normal_force": c.normal_forces,
                                       "tangential_force": c.tangential_forces,
                                       "body_i": c.body_i, "body_j": c.body_j})
        self._frame_index += 1

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
    def _write_checkpoint(self, checkpoint_io, state: dict, name: str) -> Path:
        arrays = dict(state)
        s = self.solver
        arrays["shape_index"] = s.shape_index
        arrays["material_index"] = s.material_index_of_body
        arrays["fixed"] = s.fixed
        for k, mesh in enumerate(self._meshes):
            arrays[f"shape_{k}_nodes"] = mesh.nodes
            arrays[f"shape_{k}_tets"] = mesh.tets
        metadata = {"kind": "riprap rigid run", "frame_index": self._frame_index,
                    "checkpoint_index": self._checkpoint_index, "n_bodies": int(s.n_bodies),
                    "shapes": list(self._shape_names), "time": float(state["clock"][0])}
        return checkpoint_io.save_checkpoint(self.output_directory / name, arrays=arrays,
                                             metadata=metadata)

    def restart(self, path) -> None:
        """Continue from a checkpoint written by a run of the same case."""
        from riprap.io import checkpoint as checkpoint_io

        arrays, metadata = checkpoint_io.load_checkpoint(path)
        s = self.solver
        s._build_arrays()
        problems = []
        if metadata.get("n_bodies") != s.n_bodies:
            problems.append(f"it has {metadata.get('n_bodies')} bodies, the case {s.n_bodies}")
        if metadata.get("shapes") != list(self._shape_names):
            problems.append(f"its shapes {metadata.get('shapes')} differ from the case's {list(self._shape_names)}")
        else:
            for k, mesh in enumerate(self._meshes):
                if not (np.array_equal(arrays[f"shape_{k}_nodes"], mesh.nodes)
                        and np.array_equal(arrays[f"shape_{k}_tets"], mesh.tets)):
                    problems.append(f"shape '{list(self._shape_names)[k]}' was meshed differently")
        if problems:
            raise RiprapError(f"{path}: cannot restart this case from that checkpoint: "
                              + "; ".join(problems))
        s.time_step = float(arrays["clock"][2])
        s._ready = True
        s.load_state_arrays(arrays)
        if not self.adaptive_time_step:
            # The case's time step wins over the checkpoint's (the same case gives the same step, so
            # a restart stays bit for bit): after a blow-up a smaller step is the usual fix.
            step = (self.requested_time_step if self.requested_time_step > 0
                    else s.stable_time_step(self.time_step_safety))
            if step != s.time_step:
                s.set_time_step(step)
        s._last = (np.zeros((0, interactions.C_SIZE)), np.zeros((0, 2), np.int64), np.zeros((0, 2), np.int64))
        s._contacts = None
        self._frame_index = int(metadata["frame_index"])
        self._checkpoint_index = int(metadata["checkpoint_index"])
        self._restarted = True


def _require(ok: bool, key: str, value, expected: str) -> None:
    if not ok:
        raise CaseFileError(f"simulation.{key} = {value!r}: expected {expected}")


class _Progress:
    """A rich progress bar: simulated time, steps/s, kinetic energy, contacts."""

    def __init__(self, enabled: bool, end_time: float):
        self.enabled = enabled
        self.end_time = end_time
        self._progress = None

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self._progress = Progress(
                TextColumn("[bold]t = {task.completed:.4f} / {task.total:.4f} s"), BarColumn(),
                TextColumn("{task.fields[rate]} steps/s"), TextColumn("KE {task.fields[energy]} J"),
                TextColumn("{task.fields[contacts]} contacts"), TimeRemainingColumn(),
                transient=False)
            self._progress.__enter__()
            self._task = self._progress.add_task("run", total=self.end_time, rate="-",
                                                 energy="-", contacts="-")
        return self

    def update(self, solver, start_wall, start_steps):
        if self._progress is None:
            return
        rate = (solver.step_count - start_steps) / max(wallclock.perf_counter() - start_wall, 1e-9)
        self._progress.update(self._task, completed=min(solver.time, self.end_time),
                              rate=f"{rate:,.0f}", energy=f"{solver.kinetic_energy():.3g}",
                              contacts=str(len(solver.contacts)))

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.__exit__(*exc)
        return False
