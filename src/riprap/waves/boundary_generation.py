"""Waves made at the flume's x = lower boundary, with active absorption of what comes back.

Why: a relaxation zone that makes the waves must also absorb what the structure reflects, so it is
a wave length long; in a breakwater flume that zone held more than half of the cells. A boundary
that imposes the wave's velocity needs no cells at all. What it must do besides is absorb: a
reflected wave reaching a boundary that only imposes the target would be reflected again and the
water level would drift. The correction of Schaffer & Klopman (2000, J. Waterway Port Coastal
Ocean Eng. 126: 88), in the form used for Navier-Stokes flumes by Higuera, Lara & Losada (2013,
Coastal Eng. 71: 102; olaFlow), adds to the imposed velocity a depth-uniform

    U_c = -sqrt(g / d) (eta_measured - eta_target)

in each column of boundary faces: the long-wave (shallow water) answer to "what velocity sends
the excess elevation out through the boundary". Its depth-integrated flux d U_c is exact for a
linear wave only where its celerity is sqrt(g d); a wave of celerity c carries the flux c eta
(continuity of a progressive wave), so the shallow-water factor over-absorbs a wave of k d = 1.3
by 23 % and reflects about a tenth of it back (measured: the incident height then settles 9 % low
in a flume closed by a wall). Here the factor is c / d with c the linear celerity of the wave's
(peak) period: exact for the waves of that period, and sqrt(g / d) again for long waves
(``absorption_celerity``).

The boundary faces' velocity: the theory's horizontal velocity at each face times the part of
the face below the target surface (the air above a crest is at rest), plus U_c times the part
below the measured surface, plus a uniform return current -q / (d + eta_measured) that takes back
the wave's mean volume flux q through those faces (its mass transport, g H^2 / (8 c) per metre for
a linear wave, sampled over a period or an irregular sea's duration): a flume closed at its far
end carries no net volume, and without it examples/10's sea (Hs = 1.2 m in d = 2 m) raised the
water in the flume by 11 % in 26 s (the absorption alone takes it back only through a set-up of
the mean level at the boundary). All that crosses the boundary inwards is therefore water
(``plic.advect``'s ``water_inflow_x_low``). The boundary is otherwise a wall to the pressure (its
normal velocity is given), so the flume needs an open top to take the volume the waves bring in
and out.

Applied inside each step, after the predictor and before the pressure (``FluidSolver.predict``),
with the target at the step's end and the surface measured at its start: the projected velocity is
divergence free with the new boundary flux, and the next step's water is carried by it.
"""
from __future__ import annotations

import math

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of
from riprap.waves.theory import envelope

__all__ = ["BoundaryWaveMaker"]


class BoundaryWaveMaker:
    """Waves imposed on the x = lower boundary faces of a :class:`FluidSolver` (its
    ``wave_maker``), with active absorption.

    Parameters
    ----------
    wave : a theory of ``riprap.waves.theory`` (elevation(x, t), velocity_grid(x, z, t)).
    still_water_level : float
        z of the still water surface (m); the depth d is measured from it down to the fluid box's
        floor.
    ramp_time : float
        Start-up time (s) over which the wave grows from nothing.
    active_absorption : bool
        Add the correction U_c (module docstring); without it the boundary reflects everything
        that reaches it.
    gravity : float
        g (m/s^2) of the correction's shallow-water celerity.
    """

    #: A boundary wave maker has no relaxation zones (``riprap.waves.report`` reads ``zones``).
    zones: tuple = ()

    def __init__(self, wave, still_water_level: float, *, ramp_time: float = 0.0,
                 stop_time: float = 0.0,
                 active_absorption: bool = default_of("waves", "active_absorption"),
                 gravity: float = 9.81):
        if not math.isfinite(ramp_time) or ramp_time < 0:
            raise CaseFileError(f"waves: ramp_time must be >= 0 s, got {ramp_time!r}")
        self.wave = wave
        self.still_water_level = float(still_water_level)
        self.ramp_time = float(ramp_time)
        if not math.isfinite(stop_time) or stop_time < 0:
            raise CaseFileError(f"waves: stop_time must be >= 0 s, got {stop_time!r}")
        #: When the made wave has faded out (s; 0: never): a test step's sea ends.
        self.stop_time = float(stop_time)
        self.active_absorption = bool(active_absorption)
        self.gravity = float(gravity)
        self.origin = None          # the boundary's x, set by ``attach``
        #: The last correction velocity per column of boundary faces (m/s), for reports.
        self.last_correction = None

    def attach(self, fluid) -> None:
        """Check that ``fluid`` can carry a boundary wave maker and make it ``fluid.wave_maker``."""
        grid = fluid.grid
        if not grid.open_top:
            raise CaseFileError("generation = \"boundary\" needs an open top to the fluid box "
                                "(the waves bring water in and out through the x = lower boundary)")
        if fluid.solid[0].any():
            raise CaseFileError(f"generation = \"boundary\": the fluid cells at the x = "
                                f"{grid.lower[0]:g} m boundary must be open (an obstacle fills some)")
        if fluid.porous is not None and (fluid.porous.porosity[0] < 1.0).any():
            raise CaseFileError(f"generation = \"boundary\": the fluid cells at the x = "
                                f"{grid.lower[0]:g} m boundary must lie outside porous zones")
        depth = self.still_water_level - grid.lower[2]
        if not depth > 0:
            raise CaseFileError(f"still_water_level {self.still_water_level:g} m lies at or "
                                f"below the fluid box's floor {grid.lower[2]:g} m")
        self.depth = depth
        #: c (m/s) of the correction U_c = -(c / d)(eta_measured - eta_target): the linear
        #: celerity at the wave's (peak) period (sqrt(g d) in shallow water).
        self.absorption_celerity = self.wave.wave_length / self.wave.period
        self.origin = float(grid.lower[0])
        self._face_bottoms = grid.faces(2)[:-1]
        self._face_centres = grid.centres(2)
        #: The wave's mean volume flux through the boundary (m^2/s per metre of width), as the
        #: boundary's faces carry it; taken back by a uniform return current (``_return_flux``).
        self.mean_flux = self._mean_theory_flux(fluid.h)
        fluid.wave_maker = self

    def _theory_profile(self, t: float, h: float, eta: float) -> np.ndarray:
        """The unramped wave's x velocity on the boundary faces (nz,) under the surface eta."""
        level = self.still_water_level
        below = np.clip((level + eta - self._face_bottoms) / h, 0.0, 1.0)
        u_theory, _ = self.wave.velocity_grid(np.array([0.0]), self._face_centres - level, t)
        return u_theory[0] * below

    def _theory_flux(self, t: float, h: float) -> float:
        """The full (unramped) wave's volume flux (m^2/s) through the boundary's faces at t."""
        eta = float(self.wave.elevation(np.array([0.0]), t)[0])
        return float(np.sum(self._theory_profile(t, h, eta)) * h)

    def _mean_theory_flux(self, h: float) -> float:
        """Mean of ``_theory_flux`` over the wave's period, or an irregular sea's duration (40
        samples a period)."""
        window = float(getattr(self.wave, "duration", 0.0) or self.wave.period)
        samples = max(400, int(round(40.0 * window / self.wave.period)))
        times = (np.arange(samples) + 0.5) * window / samples
        return float(np.mean([self._theory_flux(t, h) for t in times]))

    def target_elevation(self, x, t):
        """eta (m, above the still water level) of the generated wave at x, t."""
        return (envelope(t, self.ramp_time, self.stop_time)
                * self.wave.elevation(np.asarray(x, dtype=float) - self.origin, t))

    def measured_elevation(self, fluid) -> np.ndarray:
        """eta (m) in each column (j) of the first cells: their water over the depth."""
        return fluid.fraction[0].sum(axis=1) * fluid.h - self.depth

    def boundary_velocity(self, fluid, t: float) -> np.ndarray:
        """The x velocity (ny, nz) of the boundary faces at time ``t``, the surface measured in the
        fluid's present water fraction."""
        h = fluid.h
        level = self.still_water_level
        factor = float(envelope(t, self.ramp_time, self.stop_time))
        eta_target = float(self.target_elevation(self.origin, t))
        profile = factor * self._theory_profile(t, h, eta_target)
        velocity = np.broadcast_to(profile, (fluid.fraction.shape[1], profile.size)).copy()
        eta_measured = self.measured_elevation(fluid)
        below_measured = np.clip((level + eta_measured[:, None] - self._face_bottoms[None, :]) / h,
                                 0.0, 1.0)
        # the return current: a closed flume carries no net volume, so the waves' mean flux
        # (their mass transport) goes back out, spread over the water column
        correction = -factor * self.mean_flux / np.maximum(self.depth + eta_measured, h)
        if self.active_absorption:
            correction = correction - (self.absorption_celerity / self.depth) * (eta_measured - eta_target)
        velocity += correction[:, None] * below_measured
        self.last_correction = correction
        return velocity

    def impose(self, fluid, u, t: float) -> None:
        """Write the boundary velocity at time ``t`` into the x-velocity array ``u`` (nx+1, ny, nz)."""
        u[0] = self.boundary_velocity(fluid, t)
