"""Simulation: the one run loop, of rigid bodies, of air and water, of both coupled, or of
deformable bodies.

A run holds a scene (:class:`riprap.scene.Scene`: materials, shapes, bodies, walls, a fluid,
deformable bodies), and the scene's model (:mod:`riprap.models`, chosen by
:mod:`riprap.scene.choose_model`) is what the loop advances. The loop owns the clock's schedule
(frames, checkpoints, the end time), restarts, progress, the summary and the failure checkpoint;
the model owns its physics and its checks. A run that fails writes a checkpoint of the last good
state and says what failed, where and when. The building calls (``add_body``, ``add_fluid``, ...)
are the scene's, offered here too so that a run is built in one object.
"""
from __future__ import annotations

import difflib
import functools
import os
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, RiprapError
from riprap.io.checkpoint import load_checkpoint, remove_stale_temporaries, save_checkpoint
from riprap.io.output_folder import prepare_output_folder
from riprap.parallel.communicator import world
from riprap.io.summary import write_json
from riprap.models import rigid
from riprap.models.base import Model
from riprap.models.settings import ModelSettings
from riprap.outputs import DEFAULT_WRITER_NAMES
from riprap.outputs.base import ModelFrames
from riprap.scene import DEFAULT_GRAVITY, Scene
from riprap.scene.choose_model import build_model
from riprap.schedules import Every
from riprap.schema import default_of, key as schema_key
from riprap.solid.contact_statistics import solver_contact_statistics
from riprap.solid.surfaces import surface_arrays
from riprap.work_estimate import (MAX_CHECKPOINTS, MAX_FRAMES, RiprapWarning,
                                   schedule_problems)

__all__ = ["FluidRun", "FluidRunSummary", "RunSummary", "Simulation"]

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
    pressure_capped_solves: int | None = None    # solves stopped at their iteration cap
    solver_log: list | None = None               # per frame: the rows of solver_log.csv
    # deformable bodies
    element_steps_per_second: float | None = None
    max_tensile_stress: float | None = None
    # fracture (deformable runs with joints)
    broken_joints: int | None = None
    broken_area: float | None = None      # m^2, one side of the cracks
    pieces: int | None = None             # deformable bodies and fragments, each counted once
    fracture_energy: float | None = None  # J taken by the joints (stored and dissipated)
    # a run over several processes: their count, the slabs' first x-planes, the halo depth
    processes: dict | None = None

    def as_dict(self) -> dict:
        return {key: value for key, value in self.__dict__.items() if value is not None}




class _OfScene:
    """An attribute of the run that is its scene's (read and set there)."""

    def __init__(self, name: str | None = None):
        self.name = name

    def __set_name__(self, owner, name: str) -> None:
        self.name = self.name or name

    def __get__(self, simulation, owner=None):
        return self if simulation is None else getattr(simulation.scene, self.name)

    def __set__(self, simulation, value) -> None:
        setattr(simulation.scene, self.name, value)


def _of_scene(method):
    """A building call of the run that is its scene's (same signature and documentation)."""
    @functools.wraps(method)
    def of_scene(simulation, *args, **kwargs):
        return method(simulation.scene, *args, **kwargs)
    return of_scene


class Simulation:
    """A run: rigid bodies (shapes, materials, bodies, walls), air and water (``fluid``), or
    bodies in the flow (both), with a clock and outputs. It holds a scene (:attr:`scene`, which
    builds) and runs the scene's model (:attr:`model`, which owns the physics).

    ``scene`` (optional, the one positional argument): a :class:`riprap.scene.Scene` built
    beforehand (then ``gravity``, ``local_damping`` are its own), or a ready
    :class:`riprap.models.base.Model` to run as it is; by default an empty scene that the
    ``add_*`` calls fill.

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

    def __init__(self, scene=None, *, end_time: float,
                 time_step: float = default_of("simulation", "time_step"),
                 time_step_safety: float = default_of("simulation", "time_step_safety"),
                 gravity=DEFAULT_GRAVITY,
                 output_interval: float = default_of("simulation", "output_interval"),
                 checkpoint_interval: float = default_of("simulation", "checkpoint_interval"),
                 local_damping: float = default_of("simulation", "local_damping"),
                 rest_speed: float = default_of("simulation", "rest_speed"),
                 output_directory=default_of("output", "directory"),
                 paraview: bool = default_of("output", "paraview"),
                 picture: bool = default_of("output", "picture"), progress: bool = True,
                 rest_kinetic_energy: float = default_of("placement", "rest_kinetic_energy"),
                 adaptive_time_step: bool = False, fluid=None,
                 body_forces_interval: float = default_of("output", "body_forces_interval")):
        _require(end_time > 0, "end_time", end_time, "> 0 s")
        longest = schema_key("simulation", "end_time").plausible.maximum
        _require(end_time <= longest, "end_time", end_time,
                 f"<= {longest:g} s (three years of simulated time; a slip of the exponent?)")
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
        #: The run's frames: every ``output_interval`` s (writers with no schedule of their own).
        self.frame_schedule = Every(seconds=self.output_interval)
        self._writers = []               # added with add_writer, written after the model's own
        self._restored_schedules = {}    # {writer name: entry due next} from a restart's checkpoint
        self._scheduled_writers = []     # the run's writers with a schedule of their own
        self._checkpoints_written = 0    # periodic checkpoints (next at (count + 1) * interval)
        self._restarted = False
        #: What the progress display calls the run (default the model's name): a test series
        #: names its step there.
        self.progress_label = None
        #: The contact-only bodies and the filter zones the flow sees in their place
        #: (``riprap.coupling.filter_layer.FilterLayer``, set by the case builder), or None.
        self.filter_layer = None
        self._model = None
        if isinstance(scene, Model):
            self._model, scene = scene, None
        if scene is not None and not isinstance(scene, Scene):
            raise RiprapError(f"Simulation: the first argument is what to run, a "
                              f"riprap.scene.Scene or a built model (riprap.models.base.Model), "
                              f"or nothing (then add bodies and a fluid); got "
                              f"{type(scene).__name__} {scene!r:.60}")
        if scene is None:
            scene = Scene(gravity=gravity, local_damping=local_damping, fluid=fluid)
        elif fluid is not None:
            scene.add_fluid(fluid)
        #: What the run holds (:class:`riprap.scene.Scene`); built by the ``add_*`` calls.
        self.scene = scene

    # ------------------------------------------------------------------ the scene's
    solver = _OfScene()
    fluid = _OfScene()
    container_box = _OfScene()
    shape_names = _OfScene()
    accepted_overlaps = _OfScene()
    deformable_bodies = _OfScene()
    deformable_contact_penalty = _OfScene()
    deformable_mass_damping = _OfScene()
    deformable_case_index = _OfScene()
    deformable_accepted_depths = _OfScene()
    contact_only_bodies = _OfScene()
    cut_faces = _OfScene()

    add_material = _of_scene(Scene.add_material)
    add_friction_pair = _of_scene(Scene.add_friction_pair)
    add_shape = _of_scene(Scene.add_shape)
    shape = _of_scene(Scene.shape)
    add_body = _of_scene(Scene.add_body)
    add_deformable_body = _of_scene(Scene.add_deformable_body)
    add_walls = _of_scene(Scene.add_walls)
    contact_history = _of_scene(Scene.contact_history)
    set_contact_history = _of_scene(Scene.set_contact_history)

    def add_fluid(self, fluid) -> None:
        """:meth:`riprap.scene.Scene.add_fluid`, before the run is prepared."""
        if self._model is not None:
            raise RiprapError("add_fluid: the run is already prepared; add the fluid first")
        self.scene.add_fluid(fluid)

    @property
    def coupled(self) -> bool:
        """Whether bodies move in a fluid."""
        return self.scene.coupled

    # ------------------------------------------------------------------ the model
    @property
    def settings(self) -> ModelSettings:
        """What the model is told of this run's settings."""
        return ModelSettings(end_time=self.end_time, time_step=self.requested_time_step,
                             time_step_safety=self.time_step_safety,
                             adaptive_time_step=self.adaptive_time_step,
                             rest_speed=self.rest_speed,
                             rest_kinetic_energy=self.rest_kinetic_energy)

    @property
    def model(self):
        """What the run loop advances (:mod:`riprap.models`), built from the scene on first use
        by the model that serves it (:func:`riprap.scene.choose_model.build_model`)."""
        if self._model is None:
            self._model = build_model(self.scene, self.settings, restarted=self._restarted)
        return self._model

    def prepare(self) -> None:
        """Build the model, choose time steps, evaluate initial forces and check the start state
        (nothing overlaps; bodies inside the fluid box and wide enough for its cells)."""
        self.model.prepare(restarted=self._restarted)

    def start_bodies_at_rest_from(self, checkpoint) -> None:
        """Start this run's bodies where the run that wrote ``checkpoint`` (a ``.npz`` of the same
        bodies) left them, at rest, with their contact history: the next step of a test series.
        Its fluid starts as the case makes it (still water)."""
        arrays, _ = load_checkpoint(checkpoint)
        self.prepare()
        self.model.start_bodies_at_rest_from(arrays)

    # ------------------------------------------------------------------ the rigid bodies now
    def build_without_checks(self) -> None:
        """Build the rigid bodies' arrays, choose the time step and evaluate the initial forces,
        without refusing overlaps (callers that resolve overlaps themselves use
        ``solver.overlaps``)."""
        rigid.build_bodies(self.solver, self.settings)

    def check_start_overlaps(self) -> None:
        """Refuse rigid bodies that overlap at the start (beyond the accepted resting contacts of
        a pack) or occupy the same place."""
        rigid.check_start_overlaps(self.solver, self.accepted_overlaps)

    def body_setting_the_step(self, numbered: bool = True) -> str:
        """:func:`riprap.models.rigid.body_setting_the_step` (read by riprap.placement.place)."""
        return rigid.body_setting_the_step(self.solver, self.settings, numbered=numbered)

    def at_rest(self) -> bool:
        """:func:`riprap.models.rigid.at_rest` of the rigid bodies now."""
        return rigid.at_rest(self.solver, self.settings)

    def stability_ratio(self) -> float:
        """:func:`riprap.models.rigid.stability_ratio` of the rigid bodies' contacts now."""
        return rigid.stability_ratio(self.solver)[0]

    def max_speed(self) -> float:
        """Largest speed of a free rigid body including rotation at its bounding radius (m/s)."""
        return rigid.max_speed(self.solver)

    # ------------------------------------------------------------------ running
    def run(self, *, restart_from=None, after_chunk=None) -> RunSummary:
        """Run to ``end_time`` (or rest); write frames, checkpoints, pictures and the summary.

        The one run loop for every model (rigid bodies, air and water, bodies in the flow): it
        advances the model towards the next scheduled time (frame, checkpoint, end), writes what
        is due, shows progress, and stops with a failure checkpoint of the last good state when
        the model reports an instability. ``after_chunk(simulation)``, if given, is called after
        every chunk of work (a few per second of wall time) and may change the state (e.g. fix
        bodies); the run stops with end reason "done" when it returns True.
        """

        out = self.output_directory
        if world().rank == 0:
            prepare_output_folder(out)
            # what a run killed while writing a checkpoint left (process 0 writes them here)
            remove_stale_temporaries(out)
        if restart_from is not None:
            self.restart(restart_from)
        self.prepare()
        model = self.model
        if self.progress and _writes_files(model) and hasattr(model, "split_lines"):
            print(f"riprap: split over {world().size} processes by x-planes:", flush=True)
            for line in model.split_lines():
                print(f"riprap:   {line}", flush=True)
        writers = self.writers(model)
        if not _writes_files(model):
            # the other processes of a split run keep the schedules (the steps land on them)
            # and join the gathers, but write nothing
            # (a writer of every process writes its own piece of each entry)
            writers = [writer if getattr(writer, "every_process", False) else _Silent(writer)
                       for writer in writers]
        schedules = self._open_writers(model, writers, out)
        last_written = {id(schedule): model.time for schedule, _ in schedules}
        if not self._restarted:
            for schedule, due in schedules:
                self._write_entry(model, schedule, due)
        start_wall = wallclock.perf_counter()
        start_steps = model.step_count
        end_reason = "end_time"
        good = model.state_arrays()
        with _Progress(self.progress and _writes_files(model), self.end_time,
                       self.progress_label or model.name) as progress:
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
                    model.state_changed()
                    good = model.state_arrays()
                if model.at_rest():
                    end_reason = "at_rest"
                    break
                model.after_good_chunk()
        wall = wallclock.perf_counter() - start_wall
        frames = self._frame_index
        _prepare_outputs(model)
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
        if _writes_files(model):
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
        _prepare_outputs(model)
        for writer in writers:
            writer.write(model, schedule.index)
        if model.reached(self.end_time):
            schedule.index += 1
        else:
            # a chunk longer than the interval: no entry twice
            name = ("simulation.output_interval" if schedule is self.frame_schedule
                    else f"the writer {writers[0].name!r}")
            schedule.written(model, MAX_FRAMES, name)

    # ------------------------------------------------------------------ outputs
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
        missing = [part for part in ("name", "schedule", "open", "write", "close")
                   if not hasattr(writer, part)]
        if missing or not isinstance(writer.name, str):
            raise RiprapError(f"add_writer: expected a writer (riprap.outputs.Writer: a name, a "
                              f"schedule, open, write and close); {type(writer).__name__} has no "
                              f"{', '.join(missing) or 'name that is a string'}")
        if writer.schedule is not None and not isinstance(writer.schedule, Every):
            raise RiprapError(f"add_writer: writer {writer.name!r} has schedule "
                              f"{writer.schedule!r}; give riprap.schedules.Every(seconds=...) or "
                              "Every(steps=...), or None to write at the frames")
        if any(writer.name == other.name for other in self._writers):
            raise RiprapError(f"add_writer: a writer named {writer.name!r} is there already; give "
                              "each writer its own name (it keys the writer's schedule in "
                              "checkpoints)")
        self._writers.append(writer)

    def set_output_interval(self, name: str, interval: float) -> None:
        """Give the default writer ``name`` (``"body_forces"``) an interval of its own (s); 0
        writes it at the frames. A bad value is refused naming ``[output] {name}_interval``."""
        if name not in DEFAULT_WRITER_NAMES:
            close = difflib.get_close_matches(str(name), DEFAULT_WRITER_NAMES, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise CaseFileError(f"set_output_interval: {name!r} is none of riprap's output "
                                f"families ({', '.join(DEFAULT_WRITER_NAMES)}){hint}; a writer of "
                                "your own takes its schedule when it is made (add_writer)")
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

        if hasattr(model, "default_writers"):
            defaults = model.default_writers(paraview=self.paraview, picture=self.picture)
        else:       # a model of the older interface: its outputs in its own three methods
            defaults = [ModelFrames(paraview=self.paraview, picture=self.picture)]
        for writer in defaults:
            if writer.name in self.output_intervals:
                writer.schedule = Every(seconds=self.output_intervals[writer.name])
        written = {writer.name for writer in defaults}
        for name, interval in self.output_intervals.items():
            if name not in written:
                # an interval for a family this run does not write would silently do nothing
                raise CaseFileError(f"output.{name}_interval = {interval:g}: this run writes no "
                                    f"{name} (its outputs: {', '.join(sorted(written))}); drop "
                                    "the interval or set it to 0")
        return defaults + self._writers

    def surface_arrays(self):
        """World boundary surfaces of all bodies: points (n, 3), triangles (m, 3), body of each
        triangle (m,)."""

        return surface_arrays(self.solver)

    def contact_forces_on_bodies(self) -> np.ndarray:
        """Total contact force on each body (N), i.e. the force without gravity."""
        return self.solver.contact_forces()

    def contact_statistics(self) -> dict:
        """Per body: coordination number, largest contact force (N) and factor of safety against
        sliding (:func:`riprap.solid.contact_statistics.solver_contact_statistics`)."""

        return solver_contact_statistics(self.solver)

    def write_picture(self, path, *, show_fixed: bool = False, planes=None, view=(25, -60),
                      title: str | None = None) -> Path:
        """Shaded PNG of the bodies now (:func:`riprap.io.picture.render_bodies_png`).

        Free bodies are drawn in distinct colours. Fixed bodies are left out, or drawn in grey
        with ``show_fixed`` (e.g. the underlayer rocks under a placed layer); when every body is
        fixed, all are drawn in colour. ``planes``: quadrilaterals (4, 3), m, drawn translucent
        (e.g. the slope face); ``view``: camera elevation and azimuth, degrees. The default title
        counts free and fixed bodies separately and says which are not drawn."""
        return rigid.write_bodies_picture(path, self.solver, container_box=self.container_box,
                                          show_fixed=show_fixed, planes=planes, view=view,
                                          title=title)

    # ------------------------------------------------------------------ checkpoints
    def _save_checkpoint(self, name: str, state: dict) -> Path:

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
        path = self.output_directory / name
        save_in_pieces = getattr(model, "save_checkpoint_in_pieces", None)
        if save_in_pieces is not None:
            save_in_pieces(path, arrays, metadata)      # every process its piece
        elif _writes_files(model):
            save_checkpoint(path, arrays=arrays, metadata=metadata)
        processes = getattr(model, "processes", None)
        if processes is not None:
            # no process goes on (to end the run on an error, say) before the checkpoint is on
            # disk: a process that ends first ends them all
            processes.barrier()
        return path

    def check_restart(self, path) -> tuple[dict, dict]:
        """Every check of a restart from ``path`` (``riprap check --restart`` makes them too): a
        readable checkpoint of this kind of run, of this case (nothing changed but what may
        change), with the model's own checks (meshes, cells, bodies). Returns its arrays and
        metadata."""

        model = self.model
        # a process of a split run reads its own planes of the grid alone
        reading = getattr(model, "checkpoint_reading", dict)()
        arrays, metadata = load_checkpoint(path, **reading)
        self._check_same_run(path, metadata)
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
                TextColumn("{task.description}"),
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


#: The summary of a fluid run is the summary of any run (the name fluid runs had before).
FluidRunSummary = RunSummary


def _writes_files(model) -> bool:
    """Whether this process writes the run's files (a model of one's own, not a
    ``riprap.models.base.Model``, always does)."""
    return bool(getattr(model, "writes_files", True))


def _prepare_outputs(model) -> None:
    prepare = getattr(model, "prepare_outputs", None)
    if prepare is not None:
        prepare()


class _Silent:
    """A writer of process 0 as the other processes of a split run hold it: the same name and
    schedule, writing nothing."""

    def __init__(self, writer):
        self.name = writer.name
        self.schedule = writer.schedule

    def open(self, model, directory, *, append) -> None:
        return None

    def write(self, model, entry) -> None:
        return None

    def close(self, model) -> dict:
        return {}


class FluidRun(Simulation):
    """``Simulation(fluid=solver, ...)`` under the name fluid runs had before the one run loop;
    ``solver`` a :class:`riprap.fluid.solver.FluidSolver` or a
    :class:`riprap.coupling.coupled.CoupledSolver`. The fluid is ``run.fluid`` and, for a coupled
    run, the bodies' solver is ``run.solver`` (as in every Simulation)."""

    def __init__(self, solver, *, end_time: float,
                 output_interval: float = default_of("simulation", "output_interval"),
                 checkpoint_interval: float = default_of("simulation", "checkpoint_interval"),
                 output_directory=default_of("output", "directory"),
                 paraview: bool = default_of("output", "paraview"),
                 picture: bool = default_of("output", "picture"), progress: bool = True,
                 case_file: str = ""):
        super().__init__(end_time=end_time, output_interval=output_interval,
                         checkpoint_interval=checkpoint_interval,
                         output_directory=output_directory, paraview=paraview, picture=picture,
                         progress=progress, fluid=solver)
        self.case_file = case_file
