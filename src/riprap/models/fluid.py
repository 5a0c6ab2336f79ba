"""Air and water (:class:`riprap.fluid.solver.FluidSolver`), and bodies in the flow
(:class:`riprap.coupling.coupled.CoupledSolver`), as models of the run loop.

Frames: ``fluid.pvd`` of ``.vti`` files (``water_fraction``, ``pressure`` in Pa, ``velocity`` in
m/s at cell centres, ``solid``) and free-surface pictures (``free_surface/free_surface_NNNN.png``);
with bodies also ``bodies.pvd`` at the same times, ``run.pvd`` that opens both together in
ParaView, ``contacts.pvd`` (the bodies' contacts, as a dry run writes them) and ``body_forces.csv``
(with the largest fluid force on each body between its rows). The fluid takes the step its
Courant number allows, the last ones before a scheduled time made equal to land on it
(:func:`step_towards`).
"""
from __future__ import annotations

import math

import numpy as np

from riprap.errors import InstabilityError, RiprapError
from riprap.limits import RUNAWAY_SPEED
from riprap.models.base import Model
from riprap.models.body_frames import rigid_frame_fields
from riprap.outputs.body_forces import BodyForcesWriter
from riprap.outputs.bodies import BodiesInFlowWriter
from riprap.outputs.fluid import CombinedSeriesWriter, FluidFieldsWriter
from riprap.outputs.gauges import GaugesWriter
from riprap.outputs.solver_log import SolverLogWriter
from riprap.waves.report import flume_report

__all__ = ["FluidModel", "CoupledModel", "step_towards"]

# A remaining interval shorter than this fraction of the time is not worth a step of its own.
_TIME_SLACK = 1e-9


def step_towards(stable: float, remaining: float) -> float:
    """The step to take with ``remaining`` seconds to the next scheduled time (a frame, a
    checkpoint, the end): the interval split evenly over as many steps of at most ``stable`` as
    it needs, so that landing on a frame never leaves a sliver of a step. A body's fluid force
    over a step is its momentum change over dt, and part of that change comes per step, not per
    second: a sliver step cut to land on a frame read 13 times its neighbours' force, and the
    frames sampled exactly that step (docs/coupling.md, Peak forces)."""
    if remaining <= stable or not (stable > 0 and math.isfinite(remaining / stable)):
        return min(stable, remaining)
    return remaining / math.ceil(remaining / stable)


class _LogWindow:
    """What the steps since the last row of ``solver_log.csv`` did."""

    def __init__(self):
        self.steps = 0
        self.seconds = 0.0
        self.shortest = math.inf
        self.iterations = 0
        self.most_iterations = 0
        self.capped = 0
        self.volume_change = 0.0
        self.substeps = None
        self.stability_ratio = None

    def add(self, dt, iterations, capped, volume_change, substeps, stability_ratio) -> None:
        self.steps += 1
        self.seconds += dt
        self.shortest = min(self.shortest, dt)
        self.iterations += iterations
        self.most_iterations = max(self.most_iterations, iterations)
        self.capped += capped
        if volume_change is not None:
            self.volume_change = max(self.volume_change, volume_change)
        if substeps is not None:
            self.substeps = (self.substeps or 0) + substeps
        if stability_ratio is not None:
            self.stability_ratio = max(self.stability_ratio or 0.0, stability_ratio)

    def row(self, time: float, report) -> dict | None:
        if not self.steps:
            return None
        return {"time_s": float(time), "fluid_steps": self.steps,
                "time_step_mean_s": self.seconds / self.steps, "time_step_min_s": self.shortest,
                "pressure_iterations_mean": self.iterations / self.steps,
                "pressure_iterations_max": self.most_iterations,
                "pressure_capped_solves": self.capped,
                "pressure_volume_change_max": self.volume_change,
                "water_volume_error": float(report.water_volume_error),
                "contact_substeps_per_step": (None if self.substeps is None
                                              else self.substeps / self.steps),
                "contact_stability_ratio_max": self.stability_ratio}


class FluidModel(Model):
    """Air and water on a Cartesian grid."""

    kind = "riprap fluid run"
    name = "fluid"

    def __init__(self, solver):
        #: The solver stepped: a FluidSolver, or a CoupledSolver for :class:`CoupledModel`.
        self.solver = solver
        self._last_dt = 0.0
        self.smallest_step, self.largest_step, self.courant_max = np.inf, 0.0, 0.0
        self.iterations: list[int] = []
        self.pressure_seconds = 0.0
        self.capped_solves = 0
        self._report = None
        #: The rows of ``solver_log.csv`` this run wrote (also in ``summary.json``).
        self.solver_log: list[dict] = []
        self._window = _LogWindow()

    @property
    def fluid(self):
        return getattr(self.solver, "fluid", self.solver)

    # ------------------------------------------------------------------ clock
    @property
    def time(self) -> float:
        return self.solver.time

    @property
    def step_count(self) -> int:
        return self.fluid.step_count

    def reached(self, time: float) -> bool:
        return self.solver.time >= time * (1.0 - _TIME_SLACK)

    def last_time_step(self) -> float:
        return self._last_dt

    def advance(self, until: float) -> None:
        s = self.solver
        dt = step_towards(s.stable_time_step(), until - s.time)
        report = s.step(dt)
        self._after_step(dt, report)

    def _after_step(self, dt: float, report) -> None:
        self._report = report
        self._last_dt = dt
        self.pressure_seconds += self.solver.last_pressure_seconds
        self.smallest_step, self.largest_step = min(self.smallest_step, dt), max(self.largest_step, dt)
        self.courant_max = max(self.courant_max, report.courant_number)
        self.iterations.append(report.pressure_iterations)
        capped = bool(getattr(self.fluid.last_report, "pressure_capped", False))
        self.capped_solves += capped
        self._window.add(dt, report.pressure_iterations, capped,
                         self.fluid.last_report.pressure_volume_change,
                         getattr(report, "solid_substeps", None),
                         getattr(self.solver, "last_stability_ratio", None))

    def take_solver_log_row(self) -> dict | None:
        """What the solvers did since the last row (``riprap.io.solver_log``), and a new window;
        None when no step was taken since."""
        row = self._window.row(self.time, self.fluid.last_report)
        self._window = _LogWindow()
        if row is not None:
            self.solver_log.append(row)
        return row

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        return self.solver.state_arrays()

    def load_state_arrays(self, arrays: dict) -> None:
        self.solver.load_state_arrays(arrays)

    def checkpoint_content(self, state: dict) -> tuple[dict, dict]:
        return dict(state), {"cells": list(self.fluid.grid.cells), "cell_size": self.fluid.h,
                             "bodies": self._bodies()}

    def _bodies(self) -> int:
        return 0

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        if list(metadata.get("cells", [])) != list(self.fluid.grid.cells):
            raise RiprapError(f"{path}: written for a grid of {metadata.get('cells')} cells, this "
                              f"case has {list(self.fluid.grid.cells)}")
        if int(metadata.get("bodies", 0)) != self._bodies():
            raise RiprapError(f"{path}: written for {metadata.get('bodies', 0)} bodies, this case "
                              f"has {self._bodies()}")

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        return [FluidFieldsWriter(paraview=paraview, picture=picture),
                GaugesWriter(picture=picture), SolverLogWriter()]

    def waves_report(self) -> dict:
        """The waves the gauges measured, against the wave maker's target
        (:func:`riprap.waves.report.flume_report`)."""
        return flume_report(self.fluid.gauges, self.fluid.wave_source, self.fluid.water.density)

    def body_fraction(self):
        """The bodies' share of each cell, for the pictures (None: no bodies)."""
        return None

    def progress_text(self) -> str:
        r = self._report
        if r is None:
            return ""
        text = (f"dt {r.time_step:.2e}  CFL {r.courant_number:.2f}  water volume error "
                f"{r.water_volume_error:.1e}  pressure iterations {r.pressure_iterations}")
        if self.capped_solves:
            capped = getattr(self.fluid.last_report, "pressure_capped", False)
            text += (f" ({'CAPPED now, ' if capped else ''}{self.capped_solves} solve(s) stopped "
                     "at the cap)")
        clipped, fastest = self.fluid.last_air_limit
        if clipped:
            text += f"  air capped on {clipped} faces (fastest {fastest:.3g} m/s)"
        return text

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        cells = self.fluid.grid.n_cells
        report = self.fluid.last_report
        return {"cells": cells,
                "cell_updates_per_second": steps * cells / max(wall_time, 1e-9),
                "time_step_min": float(self.smallest_step if steps else 0.0),
                "time_step_max": float(self.largest_step),
                "courant_number_max": float(self.courant_max),
                "water_volume_error": float(report.water_volume_error if report else 0.0),
                "pressure_iterations_mean": float(np.mean(self.iterations)) if self.iterations else 0.0,
                "pressure_iterations_max": int(max(self.iterations, default=0)),
                "pressure_time_share": float(self.pressure_seconds / max(wall_time, 1e-9)),
                "pressure_capped_solves": int(self.capped_solves),
                "solver_log": list(self.solver_log)}

    def failure_advice(self, good: dict) -> str:
        return ("Likely cause: a flow the grid or the time step cannot carry; lower [fluid] "
                "courant_number or max_time_step and restart from the checkpoint with --restart, "
                "or refine the grid and run again.")


class CoupledModel(FluidModel):
    """Bodies in the flow, two-way coupled (``docs/coupling.md``): the fluid's step, with the
    bodies' contact sub-steps inside it."""

    kind = "riprap coupled run"
    name = "coupled"

    def __init__(self, coupled):
        super().__init__(coupled)
        self.substeps = 0
        self.fastest = 0.0
        # The largest fluid force on each body (N) since the last row of body_forces.csv, and
        # when: a wave's impact lasts a few fluid steps, far less than the frames' interval.
        self._peak_force = np.zeros(self.solids.n_bodies)
        self._peak_time = np.full(self.solids.n_bodies, np.nan)

    @property
    def solids(self):
        return self.solver.solids

    def _bodies(self) -> int:
        return self.solids.n_bodies

    def start_bodies_at_rest_from(self, arrays: dict) -> None:
        self.solver.start_bodies_at_rest_from(
            {name[len("bodies_"):]: value for name, value in arrays.items()
             if name.startswith("bodies_")})
        self._peak_force[:] = 0.0
        self._peak_time[:] = np.nan

    def advance(self, until: float) -> None:
        super().advance(until)
        self.substeps += self._report.solid_substeps
        self.fastest = max(self.fastest, self._report.max_body_speed)
        self._check_bodies()
        self._track_peak_forces()

    def _track_peak_forces(self) -> None:
        """Keep each free body's largest fluid force of the steps since the last row (a fixed
        body's load is summed only for the outputs, so its rows give the force at their time)."""
        force = np.linalg.norm(self.solver.fluid_loads[:, :3], axis=1)
        larger = force > self._peak_force
        self._peak_force[larger] = force[larger]
        self._peak_time[larger] = self.time

    def _check_bodies(self) -> None:
        """A body whose state is not finite, that moves absurdly fast, or whose centre has left
        the fluid box, stops the run naming the body, the cell it is in and the time."""
        solids = self.solids
        grid = self.fluid.grid
        speeds = np.linalg.norm(solids.velocities, axis=1)
        finite = np.isfinite(solids.positions).all(axis=1) & np.isfinite(speeds)
        outside = np.zeros(len(speeds), dtype=bool)
        outside[finite] = np.any((solids.positions[finite] < np.asarray(grid.lower))
                                 | (solids.positions[finite] > np.asarray(grid.upper)), axis=1)
        bad = np.flatnonzero(~finite | (speeds > RUNAWAY_SPEED) | outside)
        if len(bad):
            body = int(bad[0])
            where = "no cell (its position is not finite)"
            if finite[body]:
                cell = np.floor((solids.positions[body] - np.asarray(grid.lower)) / grid.cell_size)
                where = f"cell {tuple(int(c) for c in cell)}"
            why = ("its centre has left the fluid box" if outside[body]
                   else f"more than {RUNAWAY_SPEED:g} m/s, or not finite")
            raise InstabilityError(f"body {body} moves at {speeds[body]:.3g} m/s in {where} at "
                                   f"t = {self.time:.6g} s ({why})")

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        fluid, gauges, log = super().default_writers(paraview=paraview, picture=picture)
        bodies = self._bodies_writer(paraview)
        return [bodies, fluid, CombinedSeriesWriter([fluid, bodies]), gauges, BodyForcesWriter(),
                log]

    def _bodies_writer(self, paraview: bool):
        return BodiesInFlowWriter(paraview=paraview)

    def frame_fields(self) -> dict:
        """The bodies' surfaces now with their fields, the fluid's force on each among them."""
        coupled = self.solver
        return rigid_frame_fields(self.solids, fluid_force=coupled.fluid_loads[:, :3]
                                  + coupled.fixed_body_loads[:, :3])

    def body_fraction(self):
        return self.solver.body_fraction()

    def body_force_rows(self) -> list[str]:
        """Rows of ``body_forces.csv`` for the present time (one per body); the peak fluid force
        of each is the largest since the previous call."""
        coupled, solids = self.solver, self.solids
        contact = solids.contact_forces()
        pressure, viscous = coupled.pressure_loads[:, :3], coupled.viscous_loads[:, :3]
        now = np.linalg.norm(pressure + viscous, axis=1)
        # the largest since the last row, or this row's own force where that is larger (a fixed
        # body, or the first row)
        larger = ~(self._peak_force >= now) | np.isnan(self._peak_time)
        self._peak_force[larger] = now[larger]
        self._peak_time[larger] = coupled.time
        rows = []
        for b in range(solids.n_bodies):
            values = [coupled.time, *solids.positions[b], *solids.velocities[b],
                      *pressure[b], *viscous[b], *contact[b], self._peak_force[b],
                      self._peak_time[b]]
            rows.append(f"{b}," + ",".join(repr(float(v)) for v in values))
        self._peak_force[:] = 0.0
        self._peak_time[:] = np.nan
        return rows

    def progress_text(self) -> str:
        r = self._report
        if r is None:
            return ""
        return (super().progress_text() + f"  bodies: {r.solid_substeps} sub-steps, fastest "
                f"{r.max_body_speed:.3g} m/s")

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = super().summary_fields(wall_time, steps)
        solids = self.solids
        free = ~solids.fixed
        speeds = np.linalg.norm(solids.velocities[free], axis=1)
        fields.update({"bodies": solids.n_bodies, "contacts": len(solids.contacts),
                       "solid_substeps": self.substeps, "max_speed": float(speeds.max(initial=0.0)),
                       "body_steps_per_second": self.substeps * solids.n_bodies / max(wall_time, 1e-9)})
        return fields

    def failure_advice(self, good: dict) -> str:
        return ("Likely cause: the flow or a body moved more than the steps can carry; lower "
                "[fluid] courant_number or max_time_step, or [simulation] time_step_safety for "
                "the contacts, and restart from the checkpoint with --restart (these may change "
                "on a restart; anything else needs a new run).")

