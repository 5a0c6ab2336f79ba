"""Relaxation zones: waves made at one end of the flume and absorbed at the other.

Why this method: it is a pure blend after each fluid step, so it needs nothing from the pressure
solver or the boundary conditions, works the same in 2D and 3D, takes any wave theory as its
target, and with still water as the target it is the absorbing beach (Jacobsen, Fuhrman &
Fredsoe 2012, Int. J. Numer. Meth. Fluids 70: 1073; the same structure in waves2Foam and
AMR-Wind). In a zone of length l_z every cell and face value phi becomes

    phi <- w phi + (1 - w) phi_target,    w(chi) = 1 - (exp(chi^3.5) - 1) / (e - 1),

chi = 0 at the zone's edge towards the flume (the computed flow is kept) and 1 at the flume's end
(the target is imposed). Targets: the water fraction of each cell from the target surface
elevation (the part of the cell below it), each face's velocity from the theory at the face times
the target water fraction there (air is relaxed towards rest, so that a crest's orbital velocity
is not given to the air above it). A generation zone's target is the wave times the start-up
ramp; an absorption zone's is still water at the still water level.

The blend is applied after every step, so its strength per unit time grows as the step shrinks
(as in waves2Foam); zones of one wave length or more make that immaterial (measured in
``tests/verification/test_regular_waves.py``). The blended velocity is made divergence free again
by the next step's projection.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.theory import envelope

__all__ = ["RelaxationZone", "WaveRelaxation", "relaxation_weight"]

GENERATION = "generation"
ABSORPTION = "absorption"


def relaxation_weight(chi):
    """Weight of the computed value at relative position ``chi`` in [0, 1] of a zone."""
    chi = np.clip(np.asarray(chi, dtype=float), 0.0, 1.0)
    return 1.0 - (np.exp(chi ** 3.5) - 1.0) / (math.e - 1.0)


@dataclass(frozen=True)
class RelaxationZone:
    """A zone from ``start`` to ``end`` (m along x) that makes waves (``kind`` "generation": the
    flume's end is ``start``) or absorbs them ("absorption": the flume's end is ``end``)."""

    kind: str
    start: float
    end: float

    def __post_init__(self):
        if self.kind not in (GENERATION, ABSORPTION):
            raise CaseFileError(f"waves: a relaxation zone is 'generation' or 'absorption', got "
                                f"{self.kind!r}")
        if not self.end > self.start:
            raise CaseFileError(f"waves: {self.kind} zone from x = {self.start} to {self.end} m is "
                                f"empty (end must exceed start)")

    @property
    def length(self) -> float:
        return self.end - self.start

    def chi(self, x):
        """0 at the edge towards the flume, 1 at the flume's end (outside the zone: < 0)."""
        x = np.asarray(x, dtype=float)
        if self.kind == GENERATION:
            return (self.end - x) / self.length
        return (x - self.start) / self.length


class WaveRelaxation:
    """The zones of one flume and the wave they make, applied to a :class:`FluidSolver` after
    each of its steps (``FluidSolver.relaxation``).

    Parameters
    ----------
    wave : a theory of ``riprap.waves.theory`` (elevation(x, t), velocity_grid(x, z, t)), or None
        for absorption only.
    still_water_level : float
        z of the still water surface (m); the theory's depth is measured from it down to the bed.
    zones : list of RelaxationZone
    ramp_time : float
        Start-up time (s) over which the generated wave grows from nothing (``theory.ramp``).
    origin : float
        x (m) where the wave's phase is its ``phase`` at t = 0 (default: the generation zone's
        inner edge).
    """

    def __init__(self, wave, still_water_level: float, zones, *, ramp_time: float = 0.0,
                 stop_time: float = 0.0,
                 origin: float | None = None):
        self.wave = wave
        self.still_water_level = float(still_water_level)
        self.zones = list(zones)
        if wave is not None and not any(z.kind == GENERATION for z in self.zones):
            raise CaseFileError("waves: a wave is given but no generation zone to make it in")
        if not math.isfinite(ramp_time) or ramp_time < 0:
            raise CaseFileError(f"waves: ramp_time must be >= 0 s, got {ramp_time!r}")
        self.ramp_time = float(ramp_time)
        if not math.isfinite(stop_time) or stop_time < 0:
            raise CaseFileError(f"waves: stop_time must be >= 0 s, got {stop_time!r}")
        #: When the made wave has faded out (s; 0: never): a test step's sea ends.
        self.stop_time = float(stop_time)
        generation = [z for z in self.zones if z.kind == GENERATION]
        self.origin = float(origin if origin is not None else (generation[0].end if generation else 0.0))
        self._cache = None

    def _prepare(self, fluid):
        """Per zone: the cells and faces it covers along x, their weights (computed once)."""
        grid = fluid.grid
        x_cells = grid.centres(0)
        x_faces = grid.faces(0)
        prepared = []
        for zone in self.zones:
            cells = np.flatnonzero((x_cells >= zone.start) & (x_cells <= zone.end))
            faces = np.flatnonzero((x_faces >= zone.start) & (x_faces <= zone.end)
                                   & (np.arange(x_faces.size) > 0)
                                   & (np.arange(x_faces.size) < x_faces.size - 1))
            if cells.size == 0:
                whole = grid.whole_grid.centres(0)
                if grid.whole_grid is not grid and np.any((whole >= zone.start)
                                                          & (whole <= zone.end)):
                    continue            # on another block of a split grid
                raise CaseFileError(f"waves: the {zone.kind} zone x = {zone.start:g} .. "
                                    f"{zone.end:g} m holds no cell centre of the fluid grid "
                                    f"(cells of {fluid.h:g} m from x = "
                                    f"{grid.whole_grid.lower[0]:g} m)")
            prepared.append((zone, cells, faces, relaxation_weight(zone.chi(x_cells[cells])),
                             relaxation_weight(zone.chi(x_faces[faces]))))
        z_cells = grid.centres(2)
        z_faces = grid.faces(2)
        self._cache = (prepared, x_cells, x_faces, z_cells, z_faces, fluid.h)

    def target_elevation(self, x, t):
        """eta (m, above the still water level) the generation zone imposes at x, t."""
        if self.wave is None:
            return np.zeros_like(np.asarray(x, dtype=float))
        return envelope(t, self.ramp_time, self.stop_time) * self.wave.elevation(np.asarray(x) - self.origin, t)

    def _targets(self, zone, x_cells, x_faces, z_cells, z_faces, h, t):
        """(cell fraction (nx_zone, nz), u (nx_faces, nz), w (nx_zone, nz + 1)) targets."""
        bottoms = z_faces[:-1]
        level = self.still_water_level
        if zone.kind == ABSORPTION or self.wave is None:
            eta_cells = np.zeros(x_cells.size)
            eta_faces = np.zeros(x_faces.size)
        else:
            eta_cells = self.target_elevation(x_cells, t)
            eta_faces = self.target_elevation(x_faces, t)
        fraction = np.clip((level + eta_cells[:, None] - bottoms[None, :]) / h, 0.0, 1.0)
        face_fraction = np.clip((level + eta_faces[:, None] - bottoms[None, :]) / h, 0.0, 1.0)
        if zone.kind == ABSORPTION or self.wave is None:
            return fraction, np.zeros_like(face_fraction), np.zeros((x_cells.size, z_faces.size))
        factor = envelope(t, self.ramp_time, self.stop_time)
        u, _ = self.wave.velocity_grid(x_faces - self.origin, z_cells - level, t)
        _, w = self.wave.velocity_grid(x_cells - self.origin, z_faces - level, t)
        # water fraction at the z faces: the mean of the cells above and below
        padded = np.concatenate([fraction[:, :1], fraction, fraction[:, -1:]], axis=1)
        w_fraction = 0.5 * (padded[:, :-1] + padded[:, 1:])
        return fraction, factor * u * face_fraction, factor * w * w_fraction

    def apply(self, fluid) -> None:
        """Blend ``fluid``'s water fraction and velocities in every zone towards their targets at
        the fluid's present time."""
        if self._cache is None or self._cache[-1] != fluid.h:
            self._prepare(fluid)
        prepared, x_cells, x_faces, z_cells, z_faces, h = self._cache
        t = fluid.time
        open_cells = ~fluid.solid
        for zone, cells, faces, cell_weight, face_weight in prepared:
            fraction_t, u_t, w_t = self._targets(zone, x_cells[cells], x_faces[faces], z_cells,
                                                 z_faces, h, t)
            keep = cell_weight[:, None, None]
            blended = keep * fluid.fraction[cells] + (1.0 - keep) * fraction_t[:, None, :]
            fluid.fraction[cells] = np.where(open_cells[cells], blended, fluid.fraction[cells])
            keep_u = face_weight[:, None, None]
            fluid.u[faces] = keep_u * fluid.u[faces] + (1.0 - keep_u) * u_t[:, None, :]
            # interior z faces only: the bed is a wall, the top keeps its own outflow
            fluid.w[cells, :, 1:-1] = (keep * fluid.w[cells, :, 1:-1]
                                       + (1.0 - keep) * w_t[:, None, 1:-1])
            if fluid.v.shape[1] > 2:
                fluid.v[cells, 1:-1] = keep * fluid.v[cells, 1:-1]
