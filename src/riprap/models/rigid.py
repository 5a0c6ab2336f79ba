"""Rigid bodies in contact (the solids of a :class:`riprap.simulation.Simulation`) as a model of
the run loop: a fixed contact time step counted in steps (so that frame and checkpoint times fall
on the same steps in a run and in its restart), or an adaptive one for settling runs."""
from __future__ import annotations

import math
import time as wallclock

import numpy as np

from riprap.errors import RiprapError
from riprap.models.base import Model
from riprap.models.body_frames import rigid_frame_fields
from riprap.outputs.bodies import RigidBodiesWriter
from riprap.solid.kernels import interactions

__all__ = ["RigidModel"]

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
# Wall-clock seconds between progress updates (and rest checks).
_PROGRESS_PERIOD = 0.25


class RigidModel(Model):
    """The bodies of ``simulation`` (its :class:`riprap.solid.solver.SolidSolver`)."""

    kind = "riprap rigid run"
    name = "rigid"

    def __init__(self, simulation):
        self.simulation = simulation
        self.solver = simulation.solver
        self._chunk = 10
        self._estimate = 0.0
        self.smallest_step = self.largest_step = 0.0
        self.cuts = 0

    # ------------------------------------------------------------------ clock
    @property
    def time(self) -> float:
        return self.solver.time

    @property
    def step_count(self) -> int:
        return self.solver.step_count

    def _steps_at(self, time: float) -> int:
        """The step count at which the clock reaches ``time`` (at the current time step)."""
        s = self.solver
        if s._time_origin is None:
            return int(math.ceil(time / s.time_step - 1e-9))
        return s._step_origin + int(math.ceil((time - s._time_origin) / s.time_step - 1e-9))

    def reached(self, time: float) -> bool:
        return self.solver.step_count >= self._steps_at(time)

    def last_time_step(self) -> float:
        return self.solver.time_step

    def prepare(self, *, restarted: bool) -> None:
        self.simulation._prepare_bodies()
        self._estimate = self.smallest_step = self.largest_step = self.solver.time_step

    def advance(self, until: float) -> None:
        solver = self.solver
        n = min(self._steps_at(until) - solver.step_count, self._chunk)
        tick = wallclock.perf_counter()
        solver.advance(n)
        self.simulation._check_runaway()
        self.simulation._check_contact_stability()
        elapsed = wallclock.perf_counter() - tick
        if self.simulation.adaptive_time_step:
            self._chunk = _ADAPT_CHUNK_STEPS
        else:
            self._chunk = max(1, min(100000, int(n * _PROGRESS_PERIOD / max(elapsed, 1e-6))))

    def recover(self, good: dict) -> bool:
        solver = self.solver
        if not (self.simulation.adaptive_time_step
                and solver.time_step * _STEP_CUT >= _MIN_STEP_OVER_ESTIMATE * self._estimate):
            return False
        cut = solver.time_step * _STEP_CUT
        solver.load_state_arrays(good)
        solver.set_time_step(cut)
        self.smallest_step = min(self.smallest_step, cut)
        self.cuts += 1
        return True

    def after_good_chunk(self) -> None:
        sim, solver = self.simulation, self.solver
        grown = solver.time_step * _STEP_GROWTH
        if (sim.adaptive_time_step and sim._last_stability_ratio < _GROW_BELOW_RATIO
                and grown <= _MAX_STEP_OVER_ESTIMATE * self._estimate
                and sim._step_keeps_motion_small(grown)):
            solver.set_time_step(grown)
            self.largest_step = max(self.largest_step, solver.time_step)

    def at_rest(self) -> bool:
        return self.simulation.rest_speed > 0 and self.simulation.at_rest()

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
        for k, mesh in enumerate(self.simulation._meshes):
            arrays[f"shape_{k}_nodes"] = mesh.nodes
            arrays[f"shape_{k}_tets"] = mesh.tets
        return arrays, {"n_bodies": int(s.n_bodies), "shapes": list(self.simulation._shape_names)}

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        s = self.solver
        s._build_arrays()
        problems = []
        if metadata.get("n_bodies") != s.n_bodies:
            problems.append(f"it has {metadata.get('n_bodies')} bodies, the case {s.n_bodies}")
        names = list(self.simulation._shape_names)
        if metadata.get("shapes") != names:
            problems.append(f"its shapes {metadata.get('shapes')} differ from the case's {names}")
        else:
            for k, mesh in enumerate(self.simulation._meshes):
                if not (np.array_equal(arrays[f"shape_{k}_nodes"], mesh.nodes)
                        and np.array_equal(arrays[f"shape_{k}_tets"], mesh.tets)):
                    problems.append(f"shape '{names[k]}' was meshed differently")
        if problems:
            raise RiprapError(f"{path}: cannot restart this case from that checkpoint: "
                              + "; ".join(problems))

    def restore(self, arrays: dict) -> None:
        sim, s = self.simulation, self.solver
        s.time_step = float(arrays["clock"][2])
        s._ready = True
        s.load_state_arrays(arrays)
        if not sim.adaptive_time_step:
            # The case's time step wins over the checkpoint's (the same case gives the same step, so
            # a restart stays bit for bit): after a blow-up a smaller step is the usual fix.
            step = (sim.requested_time_step if sim.requested_time_step > 0
                    else s.stable_time_step(sim.time_step_safety))
            if step != s.time_step:
                s.set_time_step(step)
        s._last = (np.zeros((0, interactions.C_SIZE)), np.zeros((0, 2), np.int64),
                   np.zeros((0, 2), np.int64))
        s._contacts = None

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        return [RigidBodiesWriter(paraview=paraview, picture=picture)]

    def frame_fields(self) -> dict:
        """The bodies' surfaces now with their fields (:func:`rigid_frame_fields`)."""
        return rigid_frame_fields(self.solver)

    def picture(self, path):
        """A picture of the bodies now (:meth:`riprap.simulation.Simulation.write_picture`)."""
        return self.simulation.write_picture(path)

    def progress_text(self) -> str:
        return (f"KE {self.solver.kinetic_energy():.3g} J  {len(self.solver.contacts)} contacts  "
                f"dt {self.solver.time_step:.2e} s")

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        s, sim = self.solver, self.simulation
        return {"time_step": s.time_step,
                "body_steps_per_second": steps * s.n_bodies / max(wall_time, 1e-9),
                "bodies": s.n_bodies, "contacts": len(s.contacts),
                "kinetic_energy": s.kinetic_energy(), "max_speed": sim.max_speed(),
                "stability_ratio_max": getattr(sim, "_max_stability_ratio", 0.0),
                "time_step_min": self.smallest_step, "time_step_max": self.largest_step,
                "time_step_cuts": self.cuts}

    def failure_advice(self, good: dict) -> str:
        return self.simulation._blow_up_advice(good)

