"""A fluid run: the clock, the outputs and the checkpoints around :class:`FluidSolver` steps.

Frames (``fluid.pvd`` of ``.vti`` files: ``water_fraction``, ``pressure`` in Pa, ``velocity`` in m/s
at cell centres, ``solid``) and free-surface pictures (``free_surface/free_surface_NNNN.png``) every
``output_interval`` of simulated time; ``checkpoint.npz`` every ``checkpoint_interval`` and at the end;
``summary.json``. A step that fails (non-finite values, Courant number over 0.5, a pressure solve
that does not converge) writes ``failure_checkpoint.npz`` with the last good state and stops with
an error that says where and when. A restart continues the ``.pvd`` series and reproduces the
unbroken run.
"""
from __future__ import annotations

import os

import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError, InstabilityError, RiprapError

__all__ = ["FluidRun", "FluidRunSummary"]

# A remaining interval shorter than this fraction of a step is not worth a step of its own.
_TIME_SLACK = 1e-9


@dataclass
class FluidRunSummary:
    """What a fluid run did (``summary.json``)."""

    end_reason: str
    simulated_time: float
    steps: int
    cells: int
    wall_time: float
    cell_updates_per_second: float
    time_step_min: float
    time_step_max: float
    courant_number_max: float
    water_volume_error: float
    pressure_iterations_mean: float
    pressure_iterations_max: int
    pressure_time_share: float
    frames: int
    outputs: dict = field(default_factory=dict)
    case_file: str = ""
    smoke: bool = False          # RIPRAP_SMOKE=1 cut the run short: its figures are not results

    def as_dict(self) -> dict:
        return dict(self.__dict__)


class FluidRun:
    """Run ``solver`` to ``end_time`` (s) with outputs in ``output_directory``."""

    def __init__(self, solver, *, end_time: float, output_interval: float = 0.05,
                 checkpoint_interval: float = 0.0, output_directory="riprap-out",
                 paraview: bool = True, picture: bool = True, progress: bool = True,
                 case_file: str = ""):
        if not end_time > 0:
            raise CaseFileError(f"fluid run: end_time = {end_time!r} must be > 0 s")
        if not output_interval > 0:
            raise CaseFileError(f"fluid run: output_interval = {output_interval!r} must be > 0 s")
        self.solver = solver
        self.end_time = float(end_time)
        self.output_interval = float(output_interval)
        self.checkpoint_interval = float(checkpoint_interval)
        self.output_directory = Path(output_directory)
        self.paraview = paraview
        self.picture = picture
        self.progress = progress
        self.case_file = case_file
        self._frame_index = 0
        self._checkpoint_index = 0
        self._restarted = False
        #: True when the model is a coupled one (bodies in the flow).
        self.coupled = hasattr(solver, "solids")

    # ------------------------------------------------------------------ outputs
    @property
    def fluid(self):
        """The fluid solver (the model itself, or the fluid of a coupled model)."""
        return getattr(self.solver, "fluid", self.solver)

    def _write_frame(self, series, body_series=None) -> None:
        s = self.fluid
        velocity = s.cell_velocity()
        if body_series is not None:
            self._write_bodies(body_series)
        if series is not None:
            series.add_image(s.time, origin=s.grid.lower, spacing=s.h, cells=s.grid.cells,
                             cell_data={"water_fraction": s.fraction, "pressure": s.pressure,
                                        "velocity": velocity, "solid": s.solid.astype(float)})
        if self.picture:
            from riprap.io.fluid_picture import free_surface_png

            free_surface_png(self.output_directory / "free_surface"
                             / f"free_surface_{self._frame_index:04d}.png", grid=s.grid,
                             fraction=s.fraction, velocity=velocity, solid=s.solid, time=s.time,
                             bodies=self.solver.body_fraction() if self.coupled else None)
        self._frame_index += 1

    def _write_bodies(self, series) -> None:
        """The bodies of a coupled model as a second series beside the fluid's, at the same
        times: surfaces with velocity, the fluid's force on each body and the contact force."""
        from riprap.solid.surfaces import surface_arrays

        coupled = self.solver
        solids = coupled.solids
        points, triangles, owners = surface_arrays(solids)
        fluid_force = coupled.fluid_loads[:, :3] + coupled.fixed_body_loads[:, :3]
        contact = solids.contact_forces()
        series.add(coupled.time, points=points, cells=triangles, cell_type="triangle",
                   cell_data={"body_id": owners, "velocity": solids.velocities[owners],
                              "fluid_force": fluid_force[owners],
                              "contact_force": contact[owners],
                              "fixed": solids.fixed[owners].astype(np.int64)})

    def _body_force_rows(self) -> list[str]:
        """Rows of ``body_forces.csv`` for the present time (one per body)."""
        coupled = self.solver
        solids = coupled.solids
        contact = solids.contact_forces()
        rows = []
        for b in range(solids.n_bodies):
            values = [coupled.time, *solids.positions[b], *solids.velocities[b],
                      *coupled.pressure_loads[b, :3], *coupled.viscous_loads[b, :3], *contact[b]]
            rows.append(f"{b}," + ",".join(repr(float(v)) for v in values))
        return rows

    def _save(self, name: str, state: dict) -> Path:
        from riprap.io.checkpoint import save_checkpoint

        metadata = {"kind": "riprap fluid run", "cells": list(self.fluid.grid.cells),
                    "cell_size": self.fluid.h, "bodies": int(getattr(self.solver, "solids", None)
                                                              .n_bodies if self.coupled else 0), "frame_index": self._frame_index,
                    "checkpoint_index": self._checkpoint_index, "time": float(state["clock"][0])}
        return save_checkpoint(self.output_directory / name, arrays=state, metadata=metadata)

    def restart(self, path) -> None:
        from riprap.io.checkpoint import load_checkpoint

        arrays, metadata = load_checkpoint(path)
        if metadata.get("kind") != "riprap fluid run":
            raise RiprapError(f"{path}: not a fluid checkpoint (kind {metadata.get('kind')!r})")
        if list(metadata.get("cells", [])) != list(self.fluid.grid.cells):
            raise RiprapError(f"{path}: written for a grid of {metadata.get('cells')} cells, this "
                              f"case has {list(self.fluid.grid.cells)}")
        bodies = self.solver.solids.n_bodies if self.coupled else 0
        if int(metadata.get("bodies", 0)) != bodies:
            raise RiprapError(f"{path}: written for {metadata.get('bodies', 0)} bodies, this case "
                              f"has {bodies}")
        self.solver.load_state_arrays(arrays)
        self._frame_index = int(metadata["frame_index"])
        self._checkpoint_index = int(metadata["checkpoint_index"])
        self._restarted = True

    # ------------------------------------------------------------------ the loop
    def run(self, *, restart_from=None) -> FluidRunSummary:
        from riprap.io import vtk
        from riprap.io.output_folder import prepare_output_folder
        from riprap.io.summary import write_json

        s = self.solver
        out = self.output_directory
        prepare_output_folder(out)
        if restart_from is not None:
            self.restart(restart_from)
        series = vtk.ParaViewSeries(out, "fluid", append=self._restarted) if self.paraview else None
        body_series = (vtk.ParaViewSeries(out, "bodies", append=self._restarted)
                       if self.paraview and self.coupled else None)
        forces = None
        if self.coupled:
            from riprap.io.body_forces import BodyForceTable

            forces = BodyForceTable(out / "body_forces.csv", append=self._restarted)
        if not self._restarted:
            self._write_frame(series, body_series)
            if forces is not None:
                forces.append(self._body_force_rows())
        next_frame = self._frame_index * self.output_interval
        next_checkpoint = ((self._checkpoint_index + 1) * self.checkpoint_interval
                           if self.checkpoint_interval > 0 else np.inf)
        steps = 0
        steps_start = self.fluid.step_count
        smallest, largest, courant_max = np.inf, 0.0, 0.0
        iterations = []
        pressure_seconds = 0.0
        start = wallclock.perf_counter()
        end_reason = "end_time"
        last_good = s.state_arrays()
        with _Progress(self.progress, self.end_time) as bar:
            while s.time < self.end_time * (1.0 - _TIME_SLACK):
                dt = min(s.stable_time_step(), self.end_time - s.time)
                if next_frame - s.time > _TIME_SLACK * self.output_interval:
                    dt = min(dt, next_frame - s.time)     # land on the frame time
                try:
                    report = s.step(dt)
                except InstabilityError as error:
                    s.load_state_arrays(last_good)
                    path = self._save("failure_checkpoint.npz", last_good)
                    raise InstabilityError(f"{error}; the last good state (t = {s.time:.6g} s) is "
                                           f"in {path}") from None
                last_good = s.state_arrays()
                pressure_seconds += s.last_pressure_seconds
                steps += 1
                smallest, largest = min(smallest, dt), max(largest, dt)
                courant_max = max(courant_max, report.courant_number)
                iterations.append(report.pressure_iterations)
                if s.time >= next_frame - _TIME_SLACK * self.output_interval:
                    self._write_frame(series, body_series)
                    next_frame = self._frame_index * self.output_interval
                    if forces is not None:
                        forces.append(self._body_force_rows())
                if s.time >= next_checkpoint:
                    self._checkpoint_index += 1
                    self._save("checkpoint.npz", s.state_arrays())
                    next_checkpoint = (self._checkpoint_index + 1) * self.checkpoint_interval
                bar.update(s, report)
        wall = wallclock.perf_counter() - start
        outputs = {"checkpoint": str(self._save("checkpoint.npz", s.state_arrays()))}
        if series is not None:
            outputs["paraview"] = str(out / "fluid.pvd")
        if body_series is not None:
            outputs["bodies"] = str(out / "bodies.pvd")
        if forces is not None:
            outputs["body_forces"] = str(forces.path)
        if self.picture:
            outputs["pictures"] = str(out / "free_surface")
        summary = FluidRunSummary(
            end_reason=end_reason, simulated_time=s.time, steps=self.fluid.step_count - steps_start,
            cells=self.fluid.grid.n_cells, wall_time=wall,
            cell_updates_per_second=steps * self.fluid.grid.n_cells / max(wall, 1e-9),
            time_step_min=float(smallest if steps else 0.0), time_step_max=float(largest),
            courant_number_max=float(courant_max),
            water_volume_error=float(s.last_report.water_volume_error if s.last_report else 0.0),
            pressure_iterations_mean=float(np.mean(iterations)) if iterations else 0.0,
            pressure_iterations_max=int(max(iterations, default=0)),
            pressure_time_share=float(pressure_seconds / max(wall, 1e-9)),
            frames=self._frame_index, outputs=outputs, case_file=self.case_file,
            smoke=os.environ.get("RIPRAP_SMOKE", "") == "1")
        write_json(out / "summary.json", summary.as_dict())
        return summary


class _Progress:
    """A rich progress bar: simulated time, dt, Courant number, water volume error, solver
    iterations."""

    def __init__(self, enabled: bool, end_time: float):
        self.enabled = enabled
        self.end_time = end_time

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("t = {task.completed:.4f} / {task.total:.4f} s"), BarColumn(),
                TextColumn("dt {task.fields[dt]}  CFL {task.fields[cfl]}  water volume error "
                           "{task.fields[mass]}  pressure iterations {task.fields[iterations]}"),
                TimeRemainingColumn())
            self.bar.__enter__()
            self.task = self.bar.add_task("fluid", total=self.end_time, dt="-", cfl="-", mass="-",
                                          iterations="-")
        return self

    def update(self, solver, report) -> None:
        if self.enabled:
            bodies = (f"  bodies: {report.solid_substeps} sub-steps, fastest "
                      f"{report.max_body_speed:.3g} m/s" if hasattr(report, "solid_substeps") else "")
            self.bar.update(self.task, completed=solver.time, dt=f"{report.time_step:.2e}",
                            cfl=f"{report.courant_number:.2f}",
                            mass=f"{report.water_volume_error:.1e}",
                            iterations=str(report.pressure_iterations) + bodies)

    def __exit__(self, *exc):
        if self.enabled:
            self.bar.__exit__(*exc)
