"""ten Cate et al. (2002) case E2: a nylon sphere settling in a closed box of silicone oil, the
benchmark of resolved particle-fluid coupling (``shared/validation/settling_sphere.md``).

Set-up: sphere d = 15 mm, 1120 kg/m^3; fluid 965 kg/m^3, 0.212 Pa s; box 100 x 100 x 160 mm closed on
every side; sphere bottom 120 mm above the floor at rest; g = 9.81 m/s^2. The published record is
the sphere's vertical velocity and its gap to the floor over time, digitised from the paper's
figures. :func:`run_ten_cate_e2` runs it at a number of cells per diameter and returns the time
series; :func:`compare_with_experiment` gives the three errors riprap states: of the peak speed, of
the velocity over the plateau (L2, relative) and of the time of bottom contact.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.coupling.coupled import CoupledSolver
from riprap.fluid.grid import FluidGrid
from riprap.fluid.phases import Phase
from riprap.fluid.solver import FluidSolver
from riprap.geometry import shapes
from riprap.geometry.tetmesh import TetMesh
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

__all__ = ["TEN_CATE_E2", "TenCateRun", "run_ten_cate_e2", "compare_with_experiment"]

#: The set-up of case E2 (SI units).
TEN_CATE_E2 = dict(diameter=0.015, sphere_density=1120.0, fluid_density=965.0,
                   fluid_viscosity=0.212, box=(0.10, 0.10, 0.16), start_gap=0.120, gravity=9.81)


@dataclass
class TenCateRun:
    """Time series of one run: times (s), vertical velocity (m/s, negative down), gap to the
    floor over the diameter; cells per diameter; wall time (s)."""

    times: np.ndarray
    velocities: np.ndarray
    gaps: np.ndarray
    cells_per_diameter: float
    wall_time: float
    steps: int


def run_ten_cate_e2(cells_per_diameter: int, *, end_time: float = 3.0, progress=None,
                    shift=(0.0, 0.0)) -> TenCateRun:
    """Run case E2 with ``cells_per_diameter`` cells across the sphere (the box is cut into whole
    cells: 100 mm / h must be an integer, so the allowed values make 100/15 x n whole).
    ``shift``: the sphere's start moved off the box's vertical axis by these fractions of a cell
    along x and y (to see how much the result depends on where the cells cut the sphere)."""
    import time

    case = TEN_CATE_E2
    d = case["diameter"]
    h = d / cells_per_diameter
    cells = tuple(int(round(length / h)) for length in case["box"])
    h = case["box"][0] / cells[0]
    upper = tuple(n * h for n in cells)
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=upper, cells=cells,
                     boundaries={side: "no_slip" for side in ("x_low", "x_high", "y_low", "y_high",
                                                              "z_low", "z_high")})
    oil = Phase("silicone oil", case["fluid_density"], case["fluid_viscosity"])
    fluid = FluidSolver(grid, water=oil, air=Phase("unused", case["fluid_density"],
                                                   case["fluid_viscosity"]),
                        gravity=(0.0, 0.0, -case["gravity"]), surface_tension=0.0)
    fluid.set_still_water_level(upper[2])
    solids = SolidSolver(gravity=(0.0, 0.0, -case["gravity"]))
    # The polyhedron inscribed in the sphere lacks 2 % of its volume at this mesh size; grown to
    # the sphere's volume, it has the experiment's weight and buoyancy.
    mesh = shapes.sphere(radius=0.5 * d, mesh_size=d / 8)
    exact = np.pi * d ** 3 / 6.0
    mesh = TetMesh(nodes=mesh.nodes * (exact / mesh.volumes().sum()) ** (1.0 / 3.0), tets=mesh.tets,
                   name=mesh.name)
    shape = solids.add_shape(RigidShape.from_mesh(mesh))
    # A soft contact: the sphere meets the floor only at the very end (no rebound, ten Cate).
    solids.add_material(Material(name="nylon", density=case["sphere_density"], restitution=0.1,
                                 friction_coefficient=0.3, contact_penalty=1.0e6))
    solids.add_body(shape=shape, material="nylon",
                    position=(0.5 * upper[0] + shift[0] * h, 0.5 * upper[1] + shift[1] * h,
                              case["start_gap"] + 0.5 * d))
    coupled = CoupledSolver(fluid, solids)
    times, velocities, gaps = [0.0], [0.0], [case["start_gap"] / d]
    started = time.perf_counter()
    while fluid.time < end_time - 1e-12:
        coupled.step(min(fluid.stable_time_step(), end_time - fluid.time))
        times.append(fluid.time)
        velocities.append(float(solids.velocities[0, 2]))
        gaps.append(float((solids.positions[0, 2] - 0.5 * d) / d))
        if progress is not None:
            progress(fluid.time)
    return TenCateRun(np.array(times), np.array(velocities), np.array(gaps),
                      cells_per_diameter=d / h, wall_time=time.perf_counter() - started,
                      steps=fluid.step_count)


def _diameter() -> float:
    return TEN_CATE_E2["diameter"]


def compare_with_experiment(run: TenCateRun, velocity_record, gap_record) -> dict:
    """Errors of a run against the digitised record: ``peak_speed_error`` (relative),
    ``plateau_velocity_l2`` (relative L2 over the plateau, 0.5 s to the last time the record's
    speed exceeds 90 % of its peak), ``contact_time_error`` (s: when the gap falls to the record's
    last value); and, free of any time offset, ``velocity_by_gap_l2`` (relative L2 of the speed
    at the gaps the record passes from 7 D down to D/4, the record's gap taken from its gap
    series at the speed record's times) and ``steady_speed_error`` (the mean speed from a gap of
    7 D to 2 D, against the gap record's). ``velocity_record`` (t, u_z) and ``gap_record``
    (t, gap/D) are arrays (n, 2)."""
    record_t, record_u = velocity_record[:, 0], velocity_record[:, 1]
    peak_record = np.abs(record_u).max()
    peak_run = np.abs(run.velocities).max()
    fast = record_t[np.abs(record_u) > 0.9 * peak_record]
    window = (record_t >= 0.5) & (record_t <= fast.max())
    simulated = np.interp(record_t[window], run.times, run.velocities)
    plateau = float(np.sqrt(np.mean((simulated - record_u[window]) ** 2))
                    / np.sqrt(np.mean(record_u[window] ** 2)))
    final_gap = gap_record[-1, 1]
    record_contact = float(np.interp(-final_gap, -gap_record[:, 1], gap_record[:, 0]))
    below = np.flatnonzero(run.gaps <= final_gap)
    run_contact = float(run.times[below[0]]) if len(below) else float("inf")
    # The same run against both records at equal gaps rather than equal times: the two
    # digitised series disagree by about 2 % in speed over the steady fall (the speed record
    # integrated travels 8.3 D before contact; the box gives 8), and a time offset between
    # run and record shows up in the time-aligned L2 and contact time but not here.
    record_gap_at = np.interp(record_t, gap_record[:, 0], gap_record[:, 1])
    by_gap = (record_gap_at <= 7.0) & (record_gap_at >= 0.25)
    run_speed = np.interp(-record_gap_at[by_gap], -run.gaps, run.velocities)
    by_gap_l2 = float(np.sqrt(np.mean((run_speed - record_u[by_gap]) ** 2))
                      / np.sqrt(np.mean(record_u[by_gap] ** 2)))
    record_steady = 5.0 * _diameter() / float(np.diff(np.interp([-7.0, -2.0], -gap_record[:, 1],
                                                                 gap_record[:, 0]))[0])
    run_steady = 5.0 * _diameter() / float(np.diff(np.interp([-7.0, -2.0], -run.gaps, run.times))[0])
    return {"peak_speed_error": float((peak_run - peak_record) / peak_record),
            "velocity_by_gap_l2": by_gap_l2,
            "steady_speed_m_per_s": run_steady, "record_steady_speed_m_per_s": record_steady,
            "steady_speed_error": (run_steady - record_steady) / record_steady,
            "peak_speed_m_per_s": float(peak_run), "record_peak_speed_m_per_s": float(peak_record),
            "plateau_velocity_l2": plateau, "contact_time_s": run_contact,
            "record_contact_time_s": record_contact,
            "contact_time_error": run_contact - record_contact}
