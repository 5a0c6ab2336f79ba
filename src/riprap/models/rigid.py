"""Rigid bodies in contact (a :class:`riprap.solid.solver.SolidSolver` a scene built) as a model
of the run loop: a fixed contact time step counted in steps (so that frame and checkpoint times
fall on the same steps in a run and in its restart), or an adaptive one for settling runs. The
model owns the rigid bodies' physics checks: the start overlaps, runaway bodies, the contacts'
stability ratio, rest, and the advice after a blow-up."""
from __future__ import annotations

import time as wallclock

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, RiprapError
from riprap.io.picture import bodies_to_draw, render_bodies_png
from riprap.limits import PROGRESS_PERIOD, RUNAWAY_SPEED, START_OVERLAP_FRACTION
from riprap.models.base import Model
from riprap.models.body_frames import rigid_frame_fields
from riprap.models.settings import ModelSettings
from riprap.outputs.bodies import RigidBodiesWriter
from riprap.solid.stability import (MAX_MOTION_PER_STEP, max_speed, stability_ratio,
                                    worst_contact_rate)
from riprap.solid.surfaces import surface_arrays
from riprap.work_estimate import check_rigid_run

__all__ = ["RigidModel", "at_rest", "body_setting_the_step", "build_bodies", "check_start_overlaps",
           "check_user_time_step", "max_speed", "prepare_bodies", "stability_ratio"]

# Adaptive time step (``Simulation(adaptive_time_step=True)``): grow by _STEP_GROWTH while the
# measured stability ratio stays below _GROW_BELOW_RATIO, cut by _STEP_CUT (from the last good
# state) when a chunk goes above the limit or blows up; never above _MAX_STEP_OVER_ESTIMATE times
# the automatic estimate nor below _MIN_STEP_OVER_ESTIMATE times it.
_GROW_BELOW_RATIO = 0.2
_STEP_GROWTH = 1.25
_STEP_CUT = 0.5
_MAX_STEP_OVER_ESTIMATE = 30.0
_MIN_STEP_OVER_ESTIMATE = 1e-3
# Time step decisions at fixed step counts, not wall-clock ones, so that a run is reproducible.
_ADAPT_CHUNK_STEPS = 50
# Largest allowed dt / (2 sqrt(m_eff / k)) over the contacts actually present (1 is the stability
# limit of an undamped spring; rotation about the contact lowers the effective mass, hence margin).
_MAX_STABILITY_RATIO = 0.5
# A body rests when its net force is below this fraction of its weight (and it is slow).
_REST_FORCE_RATIO = 0.05
# The energy watch (:class:`EnergyWatch`): a dry run's kinetic and potential energy may not grow
# past its start (with the energy stored in its contacts then) by more than this fraction of the
# energy its bodies move with (the largest kinetic energy seen, the stored energy at the start,
# and each free body's weight times its bounding radius).
_ENERGY_GROWTH_FRACTION = 0.1
# Gravity above this (m/s^2) is named as the likely cause of a blow-up (a centrifuge model runs
# at tens of g; more is a typo).
_ABSURD_GRAVITY = 1000.0


# ---------------------------------------------------------------------- building the bodies
def build_bodies(solver, settings: ModelSettings) -> None:
    """Build the solver's arrays, choose the time step and evaluate the initial forces, without
    refusing overlaps (callers that resolve overlaps themselves use ``solver.overlaps``)."""
    solver.build_arrays()
    if settings.time_step > 0:
        solver.time_step = settings.time_step
    else:
        solver.time_step = solver.stable_time_step(settings.time_step_safety)
    solver.finalize()


def prepare_bodies(solver, settings: ModelSettings, *, accepted_overlaps: dict,
                   restarted: bool) -> None:
    """Build the bodies (once), refuse absurd work, and refuse overlaps at the start of a new run
    beyond ``accepted_overlaps`` (a restart's overlaps are its own)."""
    if solver.ready:
        return
    build_bodies(solver, settings)
    check_user_time_step(solver, settings)
    check_rigid_run(end_time=settings.end_time, time_step=solver.time_step,
                    moving_bodies=int((~solver.fixed).sum()), start_time=solver.time,
                    setting_the_step=lambda numbered=True: body_setting_the_step(
                        solver, settings, numbered=numbered))
    if not restarted:
        check_start_overlaps(solver, accepted_overlaps)


def check_user_time_step(solver, settings: ModelSettings) -> None:
    """Refuse a given time step (``[simulation] time_step``) at which some contact the bodies can
    make would pass the stability ratio a run stops at (:func:`worst_contact_rate`: a whole face
    pressed in at the farthest corner of the lightest, stiffest pair), before any work. The
    contacts present at the start say nothing of the impacts to come: a step 40 times the
    automatic one passed the check of the contacts present and made energy at the first impact.
    The automatic step stays below it (0.2 to 0.28 of the bound ratio over the examples at the
    default time_step_safety)."""
    if settings.time_step <= 0:
        return
    rate, where = worst_contact_rate(solver)
    ratio = settings.time_step * rate
    if ratio <= _MAX_STABILITY_RATIO:
        return
    automatic = solver.stable_time_step(settings.time_step_safety)
    raise CaseFileError(
        f"simulation.time_step = {settings.time_step:g} s is too large for the contacts these "
        f"bodies can make: at {where}, pressed in over a whole face at its farthest corner, "
        f"dt / (2 sqrt(m/k)) would be {ratio:.3g}, above the {_MAX_STABILITY_RATIO} at which a "
        f"run stops (such a step makes energy at the first hard impact). The largest step that "
        f"holds for every contact is {_MAX_STABILITY_RATIO / rate:.3g} s; the automatic step is "
        f"{automatic:.3g} s: set time_step = 0 (automatic) or at most "
        f"{_MAX_STABILITY_RATIO / rate:.3g} s")


def body_setting_the_step(solver, settings: ModelSettings, numbered: bool = True) -> str:
    """The body whose mass and contact stiffness chose the automatic time step, in words
    (with its number when ``numbered``); "" for a step the user gave."""
    if settings.time_step > 0:
        return ""
    steps = solver.critical_time_steps()
    if not np.isfinite(steps).any():
        return ""
    body = int(np.argmin(steps))
    shape = solver.shapes[int(solver.shape_index[body])]
    return ((f"body {body}, " if numbered else "")
            + f"shape '{shape.name}', Dn = {shape.volume ** (1 / 3):.3g} m, "
            f"{solver.masses[body]:.3g} kg")


def check_start_overlaps(solver, accepted_overlaps: dict) -> None:
    """Refuse bodies that overlap at the start (beyond the accepted resting contacts of a
    pack) or occupy the same place."""
    smallest = min(shape.min_subtet_height for shape in solver.shapes)
    solver.check_no_initial_overlap(START_OVERLAP_FRACTION * smallest, accepted=accepted_overlaps)


# ---------------------------------------------------------------------- physics checks
def at_rest(solver, settings: ModelSettings) -> bool:
    """Every free body slower than ``rest_speed`` and, under gravity, with a net force below
    ``_REST_FORCE_RATIO`` of its weight (a body at the top of a bounce is slow but not at rest)."""
    if max_speed(solver) >= settings.rest_speed:
        return False
    if settings.rest_kinetic_energy > 0 and solver.kinetic_energy() >= settings.rest_kinetic_energy:
        return False
    g = float(np.linalg.norm(solver.gravity))
    free = ~solver.fixed
    if g == 0.0 or not free.any():
        return True
    ratio = np.linalg.norm(solver.forces[free], axis=1) / (solver.masses[free] * g)
    return bool(ratio.max() < _REST_FORCE_RATIO)


def check_runaway(solver) -> None:
    """A body faster than RUNAWAY_SPEED stops the run, named."""
    speeds = np.linalg.norm(solver.velocities, axis=1)
    if speeds.max(initial=0.0) > RUNAWAY_SPEED:
        body = int(np.argmax(speeds))
        raise InstabilityError(
            f"body {body} moves at {speeds[body]:.3g} m/s at t = {solver.time:.6g} s, "
            f"faster than any armour unit or rock should ({RUNAWAY_SPEED:g} m/s)")


def step_keeps_motion_small(solver, time_step: float) -> bool:
    """No body moves more than MAX_MOTION_PER_STEP of the smallest boundary sub-tet height in
    one step, so that a contact cannot go from nothing to a deep overlap in one step."""
    smallest = min(shape.min_subtet_height for shape in solver.shapes)
    return max_speed(solver) * time_step <= MAX_MOTION_PER_STEP * smallest


def blow_up_advice(solver, settings: ModelSettings, good: dict) -> str:
    """What to change after a blow-up, judged from the last good state: the time step only
    where it is the cause, not where gravity or a start velocity is absurd."""
    s = solver
    smallest = min(shape.min_subtet_height for shape in s.shapes)
    gravity = float(np.linalg.norm(s.gravity))
    speeds = np.linalg.norm(np.asarray(good["velocities"]), axis=1)
    speed = float(speeds[~s.fixed].max(initial=0.0))
    causes = []
    if gravity > _ABSURD_GRAVITY:
        causes.append(f"gravity is {gravity:.3g} m/s^2 (the earth's is 9.81): check "
                      "[simulation] gravity")
    if speed * s.time_step > MAX_MOTION_PER_STEP * smallest:
        causes.append(f"a body moved {speed * s.time_step:.3g} m per step at {speed:.3g} m/s, "
                      f"more than a tenth of the thinnest boundary layer of tetrahedra "
                      f"({smallest:.3g} m), so contacts start too deep: check the start "
                      "velocities, or lower time_step")
    if not causes:
        what = ("set [simulation] time_step below the step used" if settings.time_step
                else "lower [simulation] time_step_safety (or set a smaller time_step)")
        causes.append(f"the time step {s.time_step:.3e} s is too large for the contact "
                      f"stiffness: {what}, or lower contact_penalty")
    return ("Likely cause: " + "; ".join(causes) + ". After lowering the time step, restart "
            "from the checkpoint with --restart: the new time step is used from there (any "
            "other change to the case, such as contact_penalty or gravity, needs a new run).")


def stored_contact_energy(solver) -> float:
    """Energy held in the contacts now (J), estimated: |F_n|^2 / (2 k_n) of each contact's
    normal force and stiffness (a linear spring's; the normal force includes its damping, so
    this overestimates an approaching contact a little) and the tangential and twisting springs'
    F_s^2 / (2 k_t) and T^2 / (2 k_twist)."""
    c = solver.contacts
    normal = np.sum(c.normal_forces ** 2, axis=1)
    stored = float(np.sum(np.divide(normal, 2.0 * c.stiffness, out=np.zeros_like(normal),
                                    where=c.stiffness > 0.0)))
    springs = np.asarray(solver.history_springs).reshape(-1, 6)
    for energy, stiffness in ((np.sum(springs[:, :3] ** 2, axis=1), springs[:, 4]),
                              (springs[:, 3] ** 2, springs[:, 5])):
        stored += float(np.sum(np.divide(energy, 2.0 * stiffness, out=np.zeros_like(energy),
                                         where=stiffness > 0.0)))
    return stored


class EnergyWatch:
    """Stops a dry rigid run whose bodies gain energy from nothing. Gravity is the only load of
    a dry run and is held in the potential energy; contact damping, friction and local damping
    only take energy out; so the kinetic plus potential energy K + P can pass its value at the
    start plus the energy then stored in the contacts (``stored_contact_energy``) only by the
    integrator's error, which stays small at a stable step. Growth beyond
    ``_ENERGY_GROWTH_FRACTION`` of the energy the bodies move with (the largest K seen, the
    stored energy at the start and the sum over free bodies of m g R) is energy the time step
    made. The reference is taken afresh where the state is changed from outside (bodies fixed,
    moved, a restart). Not used for bodies in a flow: the fluid's work on them is not summed."""

    def __init__(self):
        self.reference = None
        #: The largest gain seen over its tolerance (a run stops above 1).
        self.largest_share = 0.0

    def forget(self) -> None:
        """Take the reference again at the next check (the state was changed from outside)."""
        self.reference = None

    def check(self, solver, since: float) -> None:
        """Raise InstabilityError if K + P grew past the reference by more than the tolerance
        (``since``: the time of the last good state, for the message)."""
        kinetic = solver.kinetic_energy()
        energy = kinetic + solver.potential_energy()
        fixed = solver.fixed.copy()
        if self.reference is None or not np.array_equal(fixed, self.reference["fixed"]):
            stored = stored_contact_energy(solver)
            free = ~fixed
            weight = float(np.linalg.norm(solver.gravity)) * float(np.sum(
                solver.masses[free] * solver.bounding_radius[solver.shape_index[free]]))
            self.reference = {"fixed": fixed, "energy": energy + stored, "time": solver.time,
                              "scale": stored + weight, "kinetic": kinetic}
            return
        reference = self.reference
        tolerance = _ENERGY_GROWTH_FRACTION * (reference["scale"] + reference["kinetic"])
        gain = energy - reference["energy"]
        self.largest_share = max(self.largest_share, gain / tolerance)
        if gain > tolerance:
            raise InstabilityError(
                f"energy from nothing: the bodies' kinetic and potential energy grew to "
                f"{energy:.4g} J at t = {solver.time:.6g} s, {gain:.3g} J above the "
                f"{reference['energy']:.4g} J they held at t = {reference['time']:.6g} s (with the "
                f"energy stored in their contacts then), more than the {tolerance:.3g} J the "
                f"integrator may err by; no load of a dry run puts energy in, so the time step "
                f"{solver.time_step:.3e} s is too large for a contact met after t = {since:.6g} s")
        reference["kinetic"] = max(reference["kinetic"], kinetic)


class RigidModel(Model):
    """The bodies of a :class:`riprap.solid.solver.SolidSolver`, with the meshes and names of its
    shapes (checkpoints carry them, a restart compares them), the run's ``settings``, the resting
    contacts accepted at the start (``accepted_overlaps``: (i, j) -> depth, m) and the box the
    final picture shows (``container_box``). It reads nothing of the run loop."""

    kind = "riprap rigid run"
    name = "rigid"

    def __init__(self, solver, *, meshes, shape_names, settings: ModelSettings,
                 accepted_overlaps=None, container_box=None):
        self.solver = solver
        self.meshes = list(meshes)
        self.shape_names = list(shape_names)
        self.settings = settings
        self.accepted_overlaps = dict(accepted_overlaps or {})
        self.container_box = container_box
        self._chunk = 10
        self._estimate = 0.0
        self.smallest_step = self.largest_step = 0.0
        self.cuts = 0
        self.last_stability_ratio = 0.0
        self.max_stability_ratio = 0.0
        #: Stops a run whose bodies gain energy from nothing (None: not watched).
        self.energy_watch = EnergyWatch()

    # ------------------------------------------------------------------ clock
    @property
    def time(self) -> float:
        return self.solver.time

    @property
    def step_count(self) -> int:
        return self.solver.step_count

    def reached(self, time: float) -> bool:
        return self.solver.step_count >= self.solver.steps_at(time)

    def last_time_step(self) -> float:
        return self.solver.time_step

    def prepare(self, *, restarted: bool) -> None:
        prepare_bodies(self.solver, self.settings, accepted_overlaps=self.accepted_overlaps,
                       restarted=restarted)
        self._estimate = self.smallest_step = self.largest_step = self.solver.time_step

    def check_start_overlaps(self) -> None:
        """Refuse bodies that overlap at the start beyond the accepted resting contacts."""
        check_start_overlaps(self.solver, self.accepted_overlaps)

    def advance(self, until: float) -> None:
        solver = self.solver
        n = min(self.solver.steps_at(until) - solver.step_count, self._chunk)
        since = solver.time
        if self.energy_watch is not None and self.energy_watch.reference is None:
            self.energy_watch.check(solver, since)
        tick = wallclock.perf_counter()
        solver.advance(n)
        check_runaway(solver)
        self._check_contact_stability()
        if self.energy_watch is not None:
            self.energy_watch.check(solver, since)
        elapsed = wallclock.perf_counter() - tick
        if self.settings.adaptive_time_step:
            self._chunk = _ADAPT_CHUNK_STEPS
        else:
            self._chunk = max(1, min(100000, int(n * PROGRESS_PERIOD / max(elapsed, 1e-6))))

    def _check_contact_stability(self) -> None:
        ratio, pair = stability_ratio(self.solver)
        self.last_stability_ratio = ratio
        self.max_stability_ratio = max(self.max_stability_ratio, ratio)
        if ratio > _MAX_STABILITY_RATIO:
            raise InstabilityError(
                f"time step {self.solver.time_step:.3e} s is too large for the contacts at t = "
                f"{self.solver.time:.6g} s: dt / (2 sqrt(m/k)) = {ratio:.2f} > {_MAX_STABILITY_RATIO} "
                f"at the contact of {pair}; lower time_step or time_step_safety, or "
                "contact_penalty")

    def recover(self, good: dict) -> bool:
        solver = self.solver
        if not (self.settings.adaptive_time_step
                and solver.time_step * _STEP_CUT >= _MIN_STEP_OVER_ESTIMATE * self._estimate):
            return False
        cut = solver.time_step * _STEP_CUT
        solver.load_state_arrays(good)
        solver.set_time_step(cut)
        self.smallest_step = min(self.smallest_step, cut)
        self.cuts += 1
        return True

    def after_good_chunk(self) -> None:
        solver = self.solver
        grown = solver.time_step * _STEP_GROWTH
        if (self.settings.adaptive_time_step and self.last_stability_ratio < _GROW_BELOW_RATIO
                and grown <= _MAX_STEP_OVER_ESTIMATE * self._estimate
                and step_keeps_motion_small(solver, grown)):
            solver.set_time_step(grown)
            self.largest_step = max(self.largest_step, solver.time_step)

    def state_changed(self) -> None:
        if self.energy_watch is not None:
            self.energy_watch.forget()

    def at_rest(self) -> bool:
        return self.settings.rest_speed > 0 and at_rest(self.solver, self.settings)

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        return self.solver.state_arrays()

    def load_state_arrays(self, arrays: dict) -> None:
        self.solver.load_state_arrays(arrays)

    def checkpoint_content(self, state: dict) -> tuple[dict, dict]:
        arrays = dict(state)
        s = self.solver
        arrays["shape_index"] = s.shape_index
        arrays["material_index"] = s.material_index_of_body
        arrays["fixed"] = s.fixed
        for k, mesh in enumerate(self.meshes):
            arrays[f"shape_{k}_nodes"] = mesh.nodes
            arrays[f"shape_{k}_tets"] = mesh.tets
        return arrays, {"n_bodies": int(s.n_bodies), "shapes": list(self.shape_names)}

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        s = self.solver
        s.build_arrays()
        problems = []
        if metadata.get("n_bodies") != s.n_bodies:
            problems.append(f"it has {metadata.get('n_bodies')} bodies, the case {s.n_bodies}")
        names = list(self.shape_names)
        if metadata.get("shapes") != names:
            problems.append(f"its shapes {metadata.get('shapes')} differ from the case's {names}")
        else:
            for k, mesh in enumerate(self.meshes):
                if not (np.array_equal(arrays[f"shape_{k}_nodes"], mesh.nodes)
                        and np.array_equal(arrays[f"shape_{k}_tets"], mesh.tets)):
                    problems.append(f"shape '{names[k]}' was meshed differently")
        if problems:
            raise RiprapError(f"{path}: cannot restart this case from that checkpoint: "
                              + "; ".join(problems))

    def restore(self, arrays: dict) -> None:
        settings, s = self.settings, self.solver
        s.restore_state(arrays, float(arrays["clock"][2]))
        if not settings.adaptive_time_step:
            # The case's time step wins over the checkpoint's (the same case gives the same step, so
            # a restart stays bit for bit): after a blow-up a smaller step is the usual fix.
            step = (settings.time_step if settings.time_step > 0
                    else s.stable_time_step(settings.time_step_safety))
            if step != s.time_step:
                s.set_time_step(step)
        s.forget_contacts()

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        return [RigidBodiesWriter(paraview=paraview, picture=picture)]

    def frame_fields(self) -> dict:
        """The bodies' surfaces now with their fields (:func:`rigid_frame_fields`)."""
        return rigid_frame_fields(self.solver)

    def picture(self, path):
        """A picture of the bodies now (final_state.png)."""
        return write_bodies_picture(path, self.solver, container_box=self.container_box)

    def progress_text(self) -> str:
        return (f"KE {self.solver.kinetic_energy():.3g} J  {len(self.solver.contacts)} contacts  "
                f"dt {self.solver.time_step:.2e} s")

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        s = self.solver
        return {"time_step": s.time_step,
                "body_steps_per_second": steps * s.n_bodies / max(wall_time, 1e-9),
                "bodies": s.n_bodies, "contacts": len(s.contacts),
                "kinetic_energy": s.kinetic_energy(), "max_speed": max_speed(s),
                "stability_ratio_max": self.max_stability_ratio,
                "time_step_min": self.smallest_step, "time_step_max": self.largest_step,
                "time_step_cuts": self.cuts}

    def failure_advice(self, good: dict) -> str:
        return blow_up_advice(self.solver, self.settings, good)


def write_bodies_picture(path, solver, *, container_box=None, show_fixed: bool = False,
                         planes=None, view=(25, -60), title: str | None = None):
    """Shaded PNG of the bodies now (:func:`riprap.io.picture.render_bodies_png`); the arguments
    are those of :meth:`riprap.simulation.Simulation.write_picture`, ``container_box`` the walls'
    box ((lower), (upper)) or None."""

    s = solver
    points, triangles, owners = surface_arrays(s)
    drawn, grey, description = bodies_to_draw(s.fixed, show_fixed=show_fixed)
    shown = drawn[owners]
    box = None
    if container_box is not None:
        # Show the container only up to a little above the bodies, not its full height.
        lo, hi = (np.array(v, dtype=float) for v in container_box)
        top = points[:, 2].max() if len(points) else hi[2]
        hi[2] = min(hi[2], top + 0.15 * (top - lo[2]))
        box = (tuple(lo), tuple(hi))
    return render_bodies_png(path, triangles_world=points[triangles][shown], body_ids=owners[shown],
                             grey_bodies=np.flatnonzero(grey), planes=planes, view=view,
                             title=title or f"{description} at t = {s.time:.3f} s",
                             walls_box=box)

