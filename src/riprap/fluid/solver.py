"""FluidSolver: incompressible air and water on a staggered Cartesian grid, one fluid with a sharp
interface (volume of fluid), as flat arrays.

One step of length dt (all explicit but the pressure):

1. water fraction: geometric (PLIC) split advection of Weymouth & Yue (2010), mass-conserving and
   bounded (``riprap/fluid/kernels/plic.py``); it also gives the water volume through every face;
2. momentum: moved with the mass fluxes of step 1 and divided by a density moved with the same
   fluxes, plus explicit viscous stresses and gravity (``riprap/fluid/kernels/momentum.py``);
3. surface tension (``surface_tension`` > 0): u* += dt sigma kappa grad f / rho on the faces, kappa
   from height functions (``riprap/fluid/kernels/surface_tension.py``), grad f discretised as the
   pressure gradient so that the pressure jump balances it exactly (balanced force);
4. pressure: div((1/rho) grad p) = div(u*) / dt on the cells, walls closed, the open top at p = 0
   (``riprap/fluid/pressure.py``, multigrid-preconditioned conjugate gradients). 1/rho on a face:
   without surface tension, water or air by where the interface cuts the line between the two
   cell centres (``riprap/fluid/kernels/sharp_density.py``); with it, the densities of step 2,
   which the smeared surface force must share to stay balanced;
5. correction: u = u* - dt (1/rho) grad p on every face, so that div u = 0 to the solver tolerance.

A periodic y (``FluidGrid.periodic_y``, a strip standing for a wide flume): every kernel's y
neighbours wrap around the strip, the pressure's too (``riprap/fluid/pressure.py``), and the face
ny of ``v`` is kept equal to face 0 (``docs/fluid.md``, Periodic strip).

Gravity enters the momentum of the faces (step 2) and is balanced by the pressure gradient of step
4: water at rest stays at rest to the solver tolerance, and without surface tension its cell
pressures are exactly hydrostatic wherever the interface lies in its cells.

Time step: the largest that keeps the Courant number max|u| dt / h below ``courant_number``
(Weymouth & Yue need <= 0.5 for boundedness), explicit viscous diffusion stable (dt <= h^2 /
(8 nu) in 3D, nu the largest kinematic viscosity), the shortest capillary wave resolved (dt <=
sqrt((rho_w + rho_a) h^3 / (4 pi sigma)), Brackbill et al. 1992), and a body starting from rest
under gravity within the same Courant number; it grows by at most ``_STEP_GROWTH`` per step.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid.grid import SIDES, FluidGrid
from riprap.fluid.kernels import momentum, plic
from riprap.fluid.kernels.face_speeds import largest_pore_speed, limit_air_faces
from riprap.fluid.kernels.plane_sums import plane_sums, weighted_plane_sums
from riprap.fluid.kernels.porous_faces import face_speeds_and_viscosities
from riprap.fluid.kernels.sharp_density import cell_planes, face_densities
from riprap.fluid.kernels.surface_tension import face_forces
from riprap.fluid.phases import AIR_20C, WATER_20C, Phase
from riprap.fluid.porous import PorousMedium
from riprap.fluid.pressure import PressureSolver
from riprap.parallel.kernels.ordered import ordered_total
from riprap.schema import default_of, key
from riprap.work_estimate import check_fluid_grid

__all__ = ["FluidSolver", "StepReport"]

_STEP_GROWTH = 1.2
_BOUNDARY_CODE = {"no_slip": momentum.NO_SLIP, "free_slip": momentum.FREE_SLIP, "open": momentum.OPEN,
                  "periodic": momentum.PERIODIC}


@dataclass
class StepReport:
    """What one step did."""

    time: float
    time_step: float
    courant_number: float
    pressure_iterations: int
    pressure_residual: float
    water_volume_error: float     # (V - V0 - water let in by the flume's boundary and zones) / V0
    pressure_volume_change: float | None = None    # the largest |div u| dt the solve left
    pressure_capped: bool = False                  # the solve stopped at its iteration cap


def boundary_inflow_planes(fluxes) -> tuple[np.ndarray, np.ndarray]:
    """Water that came in through the box's sides in one advection (m^3), as (the x-low minus
    x-high faces' total, (nx,) the y and z sides' per x-plane): the fluxes (positive along +axis)
    on the lower faces minus those on the upper faces; walls carry none. Per plane, so that a
    grid split into slabs adds the same numbers in the same order (``kernels/plane_sums.py``)."""
    flux_x, flux_y, flux_z = fluxes[:3]
    ends = float(plane_sums(flux_x[:1])[0]) - float(plane_sums(flux_x[-1:])[0])
    sides = (plane_sums(flux_y[:, :1]) - plane_sums(flux_y[:, -1:])
             + plane_sums(flux_z[:, :, :1]) - plane_sums(flux_z[:, :, -1:]))
    return ends, sides


def _boundary_inflow(fluxes) -> float:
    """``boundary_inflow_planes`` added up (m^3)."""
    ends, sides = boundary_inflow_planes(fluxes)
    return ends + float(ordered_total(sides))


def _box_overlap_fractions(grid: FluidGrid, lower, upper) -> list[np.ndarray]:
    """Fraction of each cell's extent along each axis inside the box lower..upper (exact): the
    cell's share of the box is the product of its three."""
    fractions = []
    for axis in range(3):
        faces = grid.faces(axis)
        low = np.clip(lower[axis], faces[:-1], faces[1:])
        high = np.clip(upper[axis], faces[:-1], faces[1:])
        fractions.append(np.maximum(high - low, 0.0) / np.diff(faces))
    return fractions


# Planes of the strip's other side padded on each side of a periodic y for the surface force: the
# height functions and their neighbour means read 3 cells away, the face force 1 more.
_SURFACE_PADDING = 6

# x-planes filled at a time: a box's water is added without whole-grid temporaries.
_FILL_PLANES = 16


class FluidSolver:
    """Air and water on ``grid`` (:class:`riprap.fluid.grid.FluidGrid`).

    Parameters
    ----------
    Every keyword that is a ``[fluid]`` key (and ``gravity``, the ``[simulation]`` key) has that
    key's default, unit and range (``docs/case-file.md``, from :mod:`riprap.schema`).

    grid : FluidGrid
    water, air : Phase
        Densities and viscosities (defaults: fresh water and air at 20 degrees C).
    gravity : (3,) float
        m/s^2.
    courant_number : float
        Largest max|u| dt / h (<= 0.5).
    pressure_tolerance : float
        Relative residual at which the pressure solve stops.
    pressure_volume_tolerance : float
        The pressure solve also stops once no cell's volume changes by more than this fraction
        over the step (``riprap/fluid/pressure.py``); 0 leaves that test out.
    max_time_step : float
        Upper bound on dt (s).
    surface_tension : float
        Air-water surface tension sigma (N/m; 0 leaves it out).
    limit_air_speed : bool
        Take the Courant number only on the faces that touch water, and cap the speed of the
        other faces (air away from the water) at what that step carries (``limit_air``).
    """

    def __init__(self, grid: FluidGrid, *, water: Phase = WATER_20C, air: Phase = AIR_20C,
                 gravity=default_of("simulation", "gravity"),
                 courant_number: float = default_of("fluid", "courant_number"),
                 pressure_tolerance: float = default_of("fluid", "pressure_tolerance"),
                 pressure_volume_tolerance: float = default_of("fluid", "pressure_volume_tolerance"),
                 max_time_step: float = default_of("fluid", "max_time_step"),
                 surface_tension: float = default_of("fluid", "surface_tension"),
                 limit_air_speed: bool = default_of("fluid", "limit_air_speed")):
        # The ranges are the [fluid] keys' (riprap.schema); the API checks them as the loader does.
        courant, tension, longest, volume = (
            key("fluid", name) for name in ("courant_number", "surface_tension", "max_time_step",
                                            "pressure_volume_tolerance"))
        if not courant.allows(courant_number):
            raise CaseFileError(f"fluid: courant_number = {courant_number!r} must be "
                                f"{courant.stated_range()} (the volume-of-fluid sweeps are "
                                "bounded only up to 0.5)")
        if not tension.allows(surface_tension):
            raise CaseFileError(f"fluid: surface_tension = {surface_tension!r} must be "
                                f"{tension.stated_range()} (0.0728 for clean water and air at 20 "
                                "degrees C)")
        if not longest.allows(max_time_step):
            raise CaseFileError(f"fluid: max_time_step = {max_time_step!r} must be "
                                f"{longest.stated_range()}")
        if not volume.allows(pressure_volume_tolerance):
            raise CaseFileError(f"fluid: pressure_volume_tolerance = {pressure_volume_tolerance!r} "
                                f"must be {volume.stated_range()} (a fraction of a cell's volume "
                                "per step)")
        self.grid = grid
        self.water = water
        self.air = air
        self.gravity = np.asarray(gravity, dtype=float).reshape(3)
        self.courant_number = float(courant_number)
        self.max_time_step = float(max_time_step)
        self.surface_tension = float(surface_tension)
        self.limit_air_speed = bool(limit_air_speed)
        #: (faces clipped, their largest speed before the clip in m/s) of the last step's
        #: ``limit_air``; (0, 0.0) without the limit.
        self.last_air_limit = (0, 0.0)
        check_fluid_grid(grid.cells)
        nx, ny, nz = grid.cells
        self.h = grid.cell_size
        self.fraction = np.zeros((nx, ny, nz))
        self.u = np.zeros((nx + 1, ny, nz))
        self.v = np.zeros((nx, ny + 1, nz))
        self.w = np.zeros((nx, ny, nz + 1))
        self.pressure = np.zeros((nx, ny, nz))
        self.solid = np.zeros((nx, ny, nz), dtype=bool)
        #: The boxes of ``add_obstacle_box`` as the cells they fill ((lower, upper) snapped to the
        #: cell faces, m): bodies coupled to this fluid meet them as fixed bodies.
        self.obstacle_boxes: list[tuple[np.ndarray, np.ndarray]] = []
        self.time = 0.0
        self.step_count = 0
        self.time_step = 0.0
        self.initial_water_volume = None
        #: Water the flume let in since the start (m^3): through its open boundaries (a wave
        #: maker's, an open top) and by its wave-making and absorbing zones; the volume error
        #: counts what the water did beyond it.
        self.water_added = 0.0
        self.boundary_code = np.array([_BOUNDARY_CODE[grid.boundaries[side]] for side in SIDES],
                                      dtype=np.int64)
        #: the y sides are one periodic boundary (``FluidGrid.periodic_y``)
        self.periodic_y = grid.periodic_y
        self.pressure_solver = self._new_pressure_solver((nx, ny, nz), self.h, pressure_tolerance,
                                                         pressure_volume_tolerance)
        self.last_report = None
        self.last_pressure_seconds = 0.0
        #: Wave-making and absorbing zones (``riprap.waves.relaxation.WaveRelaxation``) blended in
        #: after every step, or None.
        self.relaxation = None
        #: The wave maker on the x = lower boundary (``riprap.waves.boundary_generation``), whose
        #: velocity is imposed in every step before the pressure, or None.
        self.wave_maker = None
        #: Gauges (``riprap.waves.gauges.GaugeSet``) read after every step, or None.
        self.gauges = None
        #: Porous zones (``riprap.fluid.porous.PorousMedium``) or None; ``add_porous_zones``.
        self.porous = None
        self._open_part = np.ones((nx, ny, nz))
        self._porous_factors = None
        self.last_water_fluxes = None
        self._planes = None          # the mixed cells' PLIC planes (kernels.sharp_density), per step

    def _new_pressure_solver(self, shape, cell_size, tolerance, volume_tolerance):
        """The pressure solve of this grid (a split grid's blocks take their slab's instead)."""
        return PressureSolver(shape, cell_size, tolerance=tolerance,
                              volume_tolerance=volume_tolerance, periodic_y=self.periodic_y)

    # ------------------------------------------------------------------ set-up
    def add_water_box(self, lower, upper) -> None:
        """Fill the box lower..upper (m) with water (cells partly inside get their exact share)."""
        lower = np.asarray(lower, dtype=float)
        upper = np.asarray(upper, dtype=float)
        g = self.grid
        if np.any(upper <= lower):
            raise CaseFileError(f"fluid water box {lower.tolist()} .. {upper.tolist()}: upper must "
                                "exceed lower in every direction")
        box = g.whole_grid                  # a block's box is the whole grid's
        if np.any(upper <= np.asarray(box.lower)) or np.any(lower >= np.asarray(box.upper)):
            raise CaseFileError(f"fluid water box {lower.tolist()} .. {upper.tolist()} lies outside "
                                f"the fluid box {list(box.lower)} .. {list(box.upper)}")
        if g.two_dimensional:
            lower[1], upper[1] = g.lower[1], g.upper[1]
        along_x, along_y, along_z = _box_overlap_fractions(g, lower, upper)
        planes = np.flatnonzero(along_x)        # the others gain nothing (f + 0 is f)
        if len(planes):
            first, stop = int(planes[0]), int(planes[-1]) + 1
            for start in range(first, stop, _FILL_PLANES):
                chunk = slice(start, min(start + _FILL_PLANES, stop))
                # (x share times y share) times z share, in that order: the bits of the product
                share = along_x[chunk, None, None] * along_y[None, :, None] * along_z[None, None, :]
                self.fraction[chunk] = np.minimum(1.0, self.fraction[chunk] + share)
        self.initial_water_volume = None

    def set_still_water_level(self, level: float) -> None:
        """Water everywhere below ``level`` (m)."""
        g = self.grid
        if not g.lower[2] < level <= g.upper[2]:
            raise CaseFileError(f"fluid still water level {level!r} m is outside the box's height "
                                f"{g.lower[2]} .. {g.upper[2]} m")
        self.add_water_box(g.lower, (g.upper[0], g.upper[1], level))

    def add_obstacle_mask(self, mask) -> None:
        """A fixed solid made of the cells where ``mask`` (nx, ny, nz) is true."""
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != self.fraction.shape:
            raise CaseFileError(f"fluid obstacle mask has shape {mask.shape}, the grid "
                                f"{self.fraction.shape}")
        self.solid |= mask
        self.fraction[mask] = 0.0

    def add_obstacle_box(self, lower, upper) -> None:
        """A fixed solid: every cell whose centre lies inside lower..upper (m). On a block of a
        split grid (``FluidGrid.block``) the box and its check are the whole grid's."""
        g = self.grid
        whole = g.whole_grid

        def inside_along(grid):
            inside = [(grid.centres(a) >= lower[a]) & (grid.centres(a) <= upper[a])
                      for a in range(3)]
            if grid.two_dimensional:
                inside[1] = np.ones(1, dtype=bool)
            return inside

        inside = inside_along(whole)
        if self.periodic_y and not inside[1].all():
            raise CaseFileError(
                f"fluid obstacle {list(lower)} .. {list(upper)} does not span the periodic strip's "
                f"width (y {whole.lower[1]:g} .. {whole.upper[1]:g} m): on a periodic y an "
                "obstacle must be uniform across the flume, or it stands for a row of obstacles")
        if not all(along.any() for along in inside):
            raise CaseFileError(f"fluid obstacle {list(lower)} .. {list(upper)} holds no cell "
                                f"centre (cells are {self.h:g} m)")
        here = inside_along(g) if g is not whole else inside
        mask = here[0][:, None, None] & here[1][None, :, None] & here[2][None, None, :]
        self.solid |= mask
        self.fraction[mask] = 0.0
        first = [int(np.argmax(inside[a])) for a in range(3)]
        last = [len(inside[a]) - int(np.argmax(inside[a][::-1])) for a in range(3)]
        origin = np.asarray(whole.lower, dtype=np.float64)
        box_lower = origin + np.array(first) * self.h
        box_upper = np.minimum(origin + np.array(last) * self.h, whole.upper)
        if whole.two_dimensional:
            box_lower[1], box_upper[1] = whole.lower[1], whole.upper[1]
        self.obstacle_boxes.append((box_lower, box_upper))

    def add_porous_zones(self, zones) -> None:
        """Porous zones (``riprap.fluid.porous.PorousZone``: a core, filter layers) in the flow;
        ``fraction`` becomes the water fraction of their pore space. Replaces earlier zones."""
        if self.periodic_y:
            whole = self.grid.whole_grid
            for zone in zones:
                if zone.lower is not None and (zone.lower[1] > whole.lower[1]
                                               or zone.upper[1] < whole.upper[1]):
                    raise CaseFileError(
                        f"{zone.name}: the box y {zone.lower[1]:g} .. {zone.upper[1]:g} m does "
                        f"not span the periodic strip's width ({whole.lower[1]:g} .. "
                        f"{whole.upper[1]:g} m): on a periodic y a porous zone must be uniform "
                        "across the flume (or give a polygon, which spans it)")
        self.porous = PorousMedium(self.grid, zones)
        self._open_part = self.porous.porosity
        self.initial_water_volume = None

    # ------------------------------------------------------------------ properties
    @property
    def open_part(self) -> np.ndarray:
        """The part of each cell open to the fluid (nx, ny, nz): the porosity in porous zones, 1
        elsewhere."""
        return self._open_part

    @property
    def wave_source(self):
        """What makes this flume's waves (its ``wave_maker`` or its ``relaxation``), or None."""
        if self.wave_maker is not None:
            return self.wave_maker
        return self.relaxation

    def water_volume(self) -> float:
        """Water in the box (m^3): in porous zones only their pores hold it."""
        return float(ordered_total(self.water_volume_planes())) * self.h ** 3

    def water_volume_planes(self) -> np.ndarray:
        """(nx,) the water in each x-plane in cell volumes, added in a fixed order."""
        if self.porous is not None:
            return weighted_plane_sums(self.fraction, self.porous.porosity)
        return plane_sums(self.fraction)

    def _pore_speed(self) -> float:
        """Largest speed the water moves at: on each face |u| / n of the cells beside it (the
        pore velocity in a porous zone); with ``limit_air_speed`` only on faces that touch water
        (``kernels/face_speeds.py``)."""
        return max(largest_pore_speed(self.fraction, q, axis, self._open_part, self.limit_air_speed,
                                      self.periodic_y)
                   for axis, q in enumerate((self.u, self.v, self.w)))

    def air_speed_limit(self, dt: float) -> float:
        """The pore speed (m/s) a step of ``dt`` carries at the Courant number."""
        return self.courant_number * self.h / dt

    def limit_air(self, dt: float) -> None:
        """Cap the pore speed at ``air_speed_limit(dt)`` on the faces that touch no water.

        Why: under breaking waves the air pushed out ahead of a plunging crest or out of a
        breakwater's voids reaches several times the water's speed, and a step held to the
        Courant number of that air is several times shorter than the water needs. No water
        crosses those faces, so the volume-of-fluid step does not feel them; their momentum is
        the air's (1/830 of the water's density), and the next pressure solve gives the air the
        flow that continuity asks for again. The cap keeps the explicit momentum transport of
        the air within its Courant limit. Recorded in ``last_air_limit``."""
        limit = self.air_speed_limit(dt)
        clipped, largest = 0, 0.0
        for axis, q in enumerate((self.u, self.v, self.w)):
            count, fastest = limit_air_faces(self.fraction, q, axis, self._open_part, limit,
                                             self.periodic_y)
            clipped += int(count)
            largest = max(largest, float(fastest))
        self.last_air_limit = (clipped, largest)

    def cell_density(self, fraction=None) -> np.ndarray:
        f = self.fraction if fraction is None else fraction
        return f * self.water.density + (1.0 - f) * self.air.density

    def cell_viscosity(self, fraction=None) -> np.ndarray:
        f = self.fraction if fraction is None else fraction
        return f * self.water.dynamic_viscosity + (1.0 - f) * self.air.dynamic_viscosity

    def max_speed(self) -> float:
        return max(momentum.max_abs(self.u), momentum.max_abs(self.v), momentum.max_abs(self.w))

    def cell_velocity(self) -> np.ndarray:
        """Velocity at the cell centres (nx, ny, nz, 3), the mean of the two faces on each axis."""
        return np.stack([0.5 * (self.u[1:] + self.u[:-1]), 0.5 * (self.v[:, 1:] + self.v[:, :-1]),
                         0.5 * (self.w[:, :, 1:] + self.w[:, :, :-1])], axis=-1)

    def stable_time_step(self) -> float:
        h = self.h
        speed = self._pore_speed()
        limits = [self.max_time_step]
        if speed > 0:
            limits.append(self.courant_number * h / speed)
        nu = max(self.water.kinematic_viscosity, self.air.kinematic_viscosity)
        limits.append(h * h / (8.0 * nu))
        if self.surface_tension > 0:
            # capillary waves of the shortest length the grid carries (Brackbill et al. 1992)
            limits.append(math.sqrt((self.water.density + self.air.density) * h ** 3
                                    / (4.0 * math.pi * self.surface_tension)))
        g = float(np.linalg.norm(self.gravity))
        if g > 0:
            limits.append(math.sqrt(2.0 * self.courant_number * h / g))
        step = min(limits)
        if self.time_step > 0:
            step = min(step, _STEP_GROWTH * self.time_step)
        return step

    # ------------------------------------------------------------------ stepping
    def _boundary_inflow(self, fluxes) -> float:
        """Water that came in through the box's sides in one advection (m^3)."""
        return _boundary_inflow(fluxes)

    def _advect_water(self, dt: float, velocities=None):
        u, v, w = velocities or (self.u, self.v, self.w)
        return plic.advect(self.fraction, u, v, w, dt, self.h, self.step_count,
                           porosity=self._open_part, water_inflow_x_low=self.wave_maker is not None,
                           periodic_y=self.periodic_y)

    def _face_coefficients(self, densities):
        """1/rho on every face: transported densities inside, walls 0, the open top 1/rho of the
        top cell; faces of solid cells 0."""
        rho = self.cell_density()
        betas = []
        for axis, density in enumerate(densities):
            beta = np.zeros_like(density)
            interior = [slice(None)] * 3
            interior[axis] = slice(1, -1)
            beta[tuple(interior)] = 1.0 / density[tuple(interior)]
            betas.append(beta)
        if self.grid.open_top:
            betas[2][:, :, -1] = 1.0 / rho[:, :, -1]
        if self.periodic_y:
            # the strip's faces 0 and ny: one inside face, its density computed at both
            betas[1][:, 0] = 1.0 / densities[1][:, 0]
            betas[1][:, -1] = betas[1][:, 0]
        if self.grid.two_dimensional:
            betas[1][:] = 0.0
        if self._porous_factors is not None:
            for axis in range(3):
                faces = self.porous.faces[axis]
                betas[axis].reshape(-1)[faces] *= self._porous_factors[axis]
        if self.solid.any():
            for axis in range(3):
                low = [slice(None)] * 3
                high = [slice(None)] * 3
                low[axis] = slice(0, -1)
                high[axis] = slice(1, None)
                betas[axis][tuple(low)][self.solid] = 0.0
                betas[axis][tuple(high)][self.solid] = 0.0
        return betas

    def step(self, dt: float | None = None) -> StepReport:
        """Advance by ``dt`` (default: the stable step)."""
        dt, courant = self.begin_step(dt)
        u, v, w, _ = self.predict(dt)
        betas = self._face_coefficients(self.pressure_densities)
        pressure, report = self.project(u, v, w, betas, dt)
        return self.finish_step(u, v, w, pressure, report, dt, courant)

    def begin_step(self, dt: float | None = None) -> tuple[float, float]:
        """The step's ``dt`` (default: the stable step) and Courant number; refuses above 0.5."""
        if self.initial_water_volume is None:
            self.initial_water_volume = self.water_volume()
        dt = self.stable_time_step() if dt is None else float(dt)
        if self.limit_air_speed:
            self.limit_air(dt)
        courant = self._pore_speed() * dt / self.h
        if courant > 0.5 + 1e-12:
            raise InstabilityError(f"fluid: Courant number {courant:.3f} > 0.5 at t = {self.time:.6g} s "
                                   f"(dt = {dt:.3e} s, largest speed {self.max_speed():.3g} m/s)")
        return dt, courant

    def predict(self, dt: float, advecting=None):
        """The step up to the pressure: water moved (PLIC), momentum moved with the mass fluxes,
        viscosity, gravity, surface tension, obstacle faces zeroed. Returns (u*, v*, w*, the
        transported face densities per axis); ``fraction`` is already at the new time.

        ``advecting``: (u, v, w) that carry the water and the mass instead of the velocity itself;
        the coupling passes the last divergence-free field there, since its own velocity, made
        rigid inside the bodies after the projection, is not divergence free in the cells the
        bodies cut, and water carried by it is not conserved."""
        h = self.h
        density_start = self.cell_density()
        viscosity_start = self.cell_viscosity()
        carriers = advecting or (self.u, self.v, self.w)
        water_fluxes = self._advect_water(dt, carriers)
        #: The water volumes (m^3) that crossed every face in the last step (overtopping gauges).
        self.last_water_fluxes = water_fluxes
        self.water_added += self._boundary_inflow(water_fluxes)
        area = h * h
        masses = [momentum.mass_fluxes(water_fluxes[a], velocity, dt, area, self.water.density,
                                       self.air.density)
                  for a, velocity in enumerate(carriers)]
        velocities = (self.u, self.v, self.w)
        new_velocities, densities = [], []
        two_d = self.grid.two_dimensional
        for axis, q in enumerate(velocities):
            out = np.empty_like(q)
            density = np.empty_like(q)
            if axis == 1 and two_d:
                out[:] = 0.0
                density[:] = 1.0
            else:
                momentum.transport_component(q, axis, masses[0], masses[1], masses[2], velocities[0],
                                             velocities[1], velocities[2], density_start,
                                             viscosity_start, self.boundary_code, h, dt,
                                             float(self.gravity[axis]), two_d, out, density)
            new_velocities.append(out)
            densities.append(density)
        if self.porous is not None:
            self._porous_friction(new_velocities, densities, viscosity_start, dt)
        u, v, w = new_velocities
        if self.grid.open_top:
            # Zero gradient across the open top; the pressure correction then fixes its flux.
            w[:, :, -1] = w[:, :, -2]
        #: The faces' densities for the pressure. Without surface tension: water and air by
        #: where the interface cuts the line between the two cell centres (``kernels.sharp_density``,
        #: at the new fraction), which keeps the air above waves still. With it: the control
        #: volumes' mixed densities, which the continuum surface force, spread over the cut cells,
        #: must share with the pressure to balance it (docs/fluid.md, Pressure densities).
        if self.surface_tension > 0:
            self.pressure_densities = densities
            self._add_surface_tension(u, v, w, densities, dt)
        else:
            self.pressure_densities = self._sharp_face_densities()
        self._zero_solid_faces(u, v, w)
        if self.wave_maker is not None:
            # the boundary's flux at the step's end, so that the projection makes u divergence
            # free with it and the next step's water is carried by that field
            self.wave_maker.impose(self, u, self.time + dt)
        return u, v, w, densities

    def _sharp_face_densities(self) -> list:
        if self._planes is None:
            self._planes = np.zeros(self.fraction.shape + (4,))
        cell_planes(self.fraction, self._planes, self.periodic_y)
        out = []
        for axis, shape in enumerate((self.u.shape, self.v.shape, self.w.shape)):
            density = np.ones(shape)
            if not (axis == 1 and self.grid.two_dimensional):
                face_densities(self.fraction, self._planes, axis, self.water.density,
                               self.air.density, density, self.periodic_y)
            out.append(density)
        return out

    def _porous_friction(self, new_velocities, densities, viscosity, dt) -> None:
        """On porous faces: the predictor's increment scaled by s = n/(1 + c), the friction taken
        implicitly; the factors s / (1 + dt K) wait for the pressure's face coefficients
        (``riprap/fluid/porous.py``)."""
        porous = self.porous
        factors = []
        for axis, (out, old) in enumerate(zip(new_velocities, (self.u, self.v, self.w))):
            faces = porous.faces[axis]
            if faces.size == 0 or (axis == 1 and self.grid.two_dimensional):
                factors.append(np.ones(faces.size))
                continue
            face_speed, face_viscosity = np.empty(faces.size), np.empty(faces.size)
            face_speeds_and_viscosities(self.u, self.v, self.w, viscosity, axis, faces, face_speed,
                                        face_viscosity, self.periodic_y)
            density = densities[axis].reshape(-1)[faces]
            scale = porous.scale[axis].reshape(-1)[faces]
            friction = scale * (porous.linear_coefficient[axis].reshape(-1)[faces] * face_viscosity
                                + porous.quadratic_coefficient[axis].reshape(-1)[faces] * density
                                * face_speed) / density
            factor = 1.0 / (1.0 + dt * friction)
            flat_out, flat_old = out.reshape(-1), old.reshape(-1)
            flat_out[faces] = (flat_old[faces] + scale * (flat_out[faces] - flat_old[faces])) * factor
            factors.append(scale * factor)
        self._porous_factors = factors

    def project(self, u, v, w, betas, dt: float, listed_cells=None):
        """Make (u, v, w) divergence free in place with face coefficients ``betas`` (1/rho);
        returns (pressure, the pressure solver's report). ``listed_cells``: flat indices of cells
        that get extra smoothing in the pressure solve (``PressureSolver.solve``)."""
        rhs = np.empty_like(self.pressure)
        momentum.divergence(u, v, w, self.h, rhs)
        rhs /= dt
        started = time.perf_counter()
        pressure, report = self.pressure_solver.solve(betas[0], betas[1], betas[2], rhs,
                                                      p_initial=self.pressure,
                                                      listed_cells=listed_cells, time_step=dt)
        self.last_pressure_seconds = time.perf_counter() - started
        self._correct(u, v, w, pressure, betas, dt)
        return pressure, report

    def finish_step(self, u, v, w, pressure, report, dt: float, courant: float) -> StepReport:
        """Store the new state, advance the clock, report and check that it is finite."""
        self.u, self.v, self.w, self.pressure = u, v, w, pressure
        self.time += dt
        self.step_count += 1
        self.time_step = dt
        if self.relaxation is not None:
            before = self.water_volume()
            self.relaxation.apply(self)
            self.water_added += self.water_volume() - before
        if self.gauges is not None:
            self.gauges.record(self)
        error = ((self.water_volume() - self.initial_water_volume - self.water_added)
                 / max(self.initial_water_volume, 1e-300))
        self.last_report = StepReport(time=self.time, time_step=dt, courant_number=courant,
                                      pressure_iterations=report.iterations,
                                      pressure_residual=report.relative_residual,
                                      water_volume_error=error,
                                      pressure_volume_change=report.volume_change,
                                      pressure_capped=report.capped)
        self._check_finite()
        return self.last_report

    def _add_surface_tension(self, u, v, w, densities, dt) -> None:
        """u* += dt F / rho on the faces, F = sigma kappa grad f (continuum surface force with the
        same face gradient as the pressure: balanced force)."""
        if self.periodic_y:
            forces = self._periodic_surface_forces()
        else:
            forces = [np.zeros_like(u), np.zeros_like(v), np.zeros_like(w)]
            face_forces(self.fraction, self.h, self.surface_tension, self.grid.two_dimensional,
                        forces[0], forces[1], forces[2])
        for axis, (q, force) in enumerate(zip((u, v, w), forces)):
            interior = [slice(None)] * 3
            interior[axis] = slice(1, -1)
            if axis == 1 and self.periodic_y:
                interior[axis] = slice(None)        # the strip's y faces are all inside ones
            index = tuple(interior)
            q[index] += dt * force[index] / densities[axis][index]

    def _periodic_surface_forces(self) -> list:
        """The surface force on the faces of a periodic y: the height-function kernels run on
        the fractions padded with ``_SURFACE_PADDING`` planes from the strip's other side, and
        the strip's own faces are taken out (its faces 0 and ny then see the same cells). Why
        padded rather than wrapped inside the kernels: the curvature reads cells up to 3 away
        through several helpers, and surface tension is off in most flume cases (cost: the
        padding's planes, only with surface tension)."""
        pad = min(_SURFACE_PADDING, self.fraction.shape[1])
        padded = np.ascontiguousarray(np.pad(self.fraction, ((0, 0), (pad, pad), (0, 0)),
                                             mode="wrap"))
        nx, wide, nz = padded.shape
        out = [np.zeros((nx + 1, wide, nz)), np.zeros((nx, wide + 1, nz)),
               np.zeros((nx, wide, nz + 1))]
        face_forces(padded, self.h, self.surface_tension, False, out[0], out[1], out[2])
        ny = self.fraction.shape[1]
        return [np.ascontiguousarray(out[0][:, pad:pad + ny]),
                np.ascontiguousarray(out[1][:, pad:pad + ny + 1]),
                np.ascontiguousarray(out[2][:, pad:pad + ny])]

    def copy_periodic_faces(self, v) -> None:
        """On a periodic y: face ny of ``v`` (a y-face array) = face 0, the same face, after a
        caller wrote face 0 (the coupling's face set holds face 0 only); nothing otherwise."""
        if self.periodic_y:
            v[:, -1] = v[:, 0]

    def _zero_solid_faces(self, u, v, w) -> None:
        if not self.solid.any():
            return
        for axis, q in enumerate((u, v, w)):
            low = [slice(None)] * 3
            high = [slice(None)] * 3
            low[axis] = slice(0, -1)
            high[axis] = slice(1, None)
            q[tuple(low)][self.solid] = 0.0
            q[tuple(high)][self.solid] = 0.0

    def _correct(self, u, v, w, pressure, betas, dt) -> None:
        """u = u* - dt beta grad p on interior faces; the open top against p = 0 at the face."""
        h = self.h
        u[1:-1] -= dt * betas[0][1:-1] * (pressure[1:] - pressure[:-1]) / h
        if not self.grid.two_dimensional:
            v[:, 1:-1] -= dt * betas[1][:, 1:-1] * (pressure[:, 1:] - pressure[:, :-1]) / h
            if self.periodic_y:
                v[:, 0] -= dt * betas[1][:, 0] * (pressure[:, 0] - pressure[:, -1]) / h
                v[:, -1] = v[:, 0]
        w[:, :, 1:-1] -= dt * betas[2][:, :, 1:-1] * (pressure[:, :, 1:] - pressure[:, :, :-1]) / h
        if self.grid.open_top:
            w[:, :, -1] -= dt * betas[2][:, :, -1] * (0.0 - pressure[:, :, -1]) / (0.5 * h)

    def _check_finite(self) -> None:
        for name, array in (("u", self.u), ("v", self.v), ("w", self.w), ("pressure", self.pressure),
                            ("water fraction", self.fraction)):
            bad = ~np.isfinite(array)
            if bad.any():
                where = np.argwhere(bad)[0]
                # Face arrays have one more entry along their axis: this is near enough a place.
                position = [self.grid.lower[a] + (min(where[a], self.grid.cells[a] - 1) + 0.5) * self.h
                            for a in range(3)]
                raise InstabilityError(
                    f"fluid: {name} became non-finite at index {self._grid_index(where)} (near "
                    f"x, y, z = "
                    f"{', '.join(f'{v:.4g}' for v in position)} m) at t = {self.time:.6g} s (step "
                    f"{self.step_count}, dt = {self.time_step:.3e} s); reduce courant_number or "
                    "max_time_step, or refine the grid")

    def _grid_index(self, index) -> list:
        """A cell or face index of this solver's arrays as the case's grid numbers it (a block of
        a run over several processes shifts it)."""
        return [int(i) for i in index]

    def drop_cell_arrays(self) -> None:
        """Let go of every array over the cells and faces, keeping the description (grid,
        phases, gauges, wave source, clock): the whole grid of a run split over processes, on a
        process that steps only its block and writes none of the whole grid's files, then holds
        only its block's arrays. Reading a dropped array afterwards fails at once (None)."""
        for name in ("fraction", "u", "v", "w", "pressure", "solid", "_open_part",
                     "_porous_factors", "last_water_fluxes", "_planes"):
            setattr(self, name, None)
        self.pressure_solver = None
        if self.porous is not None:                 # its zones stay, their arrays go
            self.porous.drop_arrays()
        if self.relaxation is not None:
            self.relaxation._cache = None

    # ------------------------------------------------------------------ state
    def state_arrays(self, *, copy: bool = True) -> dict:
        """The state as arrays by name (a checkpoint's); ``copy=False`` gives the solver's own
        grid arrays, to be read before the next step only."""
        held = (self.fraction, self.u, self.v, self.w, self.pressure, self.solid)
        fraction, u, v, w, pressure, solid = (a.copy() for a in held) if copy else held
        arrays = {"fraction": fraction, "u": u, "v": v, "w": w, "pressure": pressure,
                  "solid": solid,
                  "clock": np.array([self.time, float(self.step_count), self.time_step,
                                     self.initial_water_volume or 0.0, self.water_added])}
        if self.gauges is not None:
            arrays.update(self.gauges.record_arrays())
        return arrays

    def load_state_arrays(self, arrays: dict, *, copy: bool = True) -> None:
        """The state of ``arrays`` (``state_arrays``'s); ``copy=False`` takes the grid arrays
        themselves (arrays made for this solver alone, as a gather's)."""
        for name in ("fraction", "u", "v", "w", "pressure", "solid"):
            if arrays[name].shape != np.shape(getattr(self, name)):
                raise CaseFileError(f"fluid checkpoint: {name} has shape {arrays[name].shape}, the "
                                    f"grid needs {np.shape(getattr(self, name))}")
        take = np.array if copy else np.asarray
        taken = [take(arrays[name], dtype=np.float64) for name in ("fraction", "u", "v", "w",
                                                                    "pressure")]
        self.fraction, self.u, self.v, self.w, self.pressure = taken
        self.solid = take(arrays["solid"], dtype=bool)
        self.time = float(arrays["clock"][0])
        self.step_count = int(arrays["clock"][1])
        self.time_step = float(arrays["clock"][2])
        self.initial_water_volume = float(arrays["clock"][3]) or None
        # older checkpoints kept no count of the water let in
        self.water_added = float(arrays["clock"][4]) if len(arrays["clock"]) > 4 else 0.0
        if self.gauges is not None:
            self.gauges.load_record_arrays(arrays)
