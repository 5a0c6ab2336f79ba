"""Build a case's ``[waves]`` and ``[[gauges]]`` onto its fluid: the wave maker (a relaxation zone
or the boundary) and the absorbing zone, the wave they make, the gauges; and the checks that the flume can carry those waves (``riprap.waves.checks``)."""
from __future__ import annotations

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.boundary_generation import BoundaryWaveMaker
from riprap.waves.checks import check_flume
from riprap.waves.gauges import Gauge, GaugeSet
from riprap.waves.relaxation import ABSORPTION, GENERATION, RelaxationZone, WaveRelaxation
from riprap.waves.theories import make_wave

__all__ = ["build_waves", "wave_of"]

# An absorption zone of this many wave lengths when the case gives none (docs/waves.md: measured
# reflection against zone length).
DEFAULT_ABSORPTION_WAVE_LENGTHS = 2.0
# The water the [[water_regions]] put at the wave maker may differ from [waves] still_water_level
# by this share of a cell: round-off of the cell fractions, not a mistake.
_LEVEL_TOLERANCE_CELLS = 0.25


def wave_of(spec, depth: float, end_time: float, gravity: float):
    """The wave theory object of a ``[waves]`` table (``riprap.waves.theories``)."""
    return make_wave(spec.type, spec.parameters, depth, end_time, gravity)


def build_waves(case, solver) -> None:
    """Give ``solver`` (a FluidSolver) the case's wave maker, zones and gauges, checked."""
    grid = solver.grid
    where = f"{case.source} [waves]"
    spec = case.waves
    level = spec.still_water_level if spec is not None else None
    if spec is not None:
        bottom, top = grid.lower[2], grid.upper[2]
        if not bottom < level < top:
            raise CaseFileError(f"{where}: still_water_level = {level:g} m must lie inside the fluid "
                                f"box's height {bottom:g} .. {top:g} m")
        gravity = float(-case.simulation.gravity[2])
        if not gravity > 0:
            raise CaseFileError(f"{where}: waves need gravity pointing down (-z); [simulation] "
                                f"gravity is {list(case.simulation.gravity)}")
        try:
            wave = wave_of(spec, level - bottom, case.simulation.end_time, gravity)
            wave_length = wave.wave_length
        except CaseFileError as error:
            raise CaseFileError(f"{where}: {error}") from None
        boundary = spec.generation == "boundary"
        if boundary and spec.generation_zone:
            raise CaseFileError(f"{where}: generation_zone = {spec.generation_zone:g} m is given with "
                                f"generation = \"boundary\", which has no zone; drop one of them")
        generation = 0.0 if boundary else (spec.generation_zone or wave_length)
        absorption = ((spec.absorption_zone or DEFAULT_ABSORPTION_WAVE_LENGTHS * wave_length)
                      if spec.absorbing_end else 0.0)
        x_low, x_high = grid.lower[0], grid.upper[0]
        if generation + absorption >= x_high - x_low:
            raise CaseFileError(
                f"{where}: the zones ({generation:.3g} m to make the waves + {absorption:.3g} m to "
                f"absorb them; L = {wave_length:.3g} m) fill the whole flume of {x_high - x_low:.3g} "
                f"m; lengthen [fluid] along x or shorten the zones")
        zones = [] if boundary else [RelaxationZone(GENERATION, x_low, x_low + generation)]
        if spec.absorbing_end:
            zones.append(RelaxationZone(ABSORPTION, x_high - absorption, x_high))
        check_flume(wave, solver.h, zones, where=where)
        _check_porous_zones_clear_of_the_wave_maker(case, solver, x_low + generation, boundary)
        _check_water_level_at_the_zones(case, solver, level, spec.absorbing_end)
        ramp_time = spec.ramp_periods * wave.period
        if boundary:
            maker = BoundaryWaveMaker(wave, level, ramp_time=ramp_time, stop_time=spec.stop_time,
                                      active_absorption=spec.active_absorption, gravity=gravity)
            try:
                maker.attach(solver)
            except CaseFileError as error:
                raise CaseFileError(f"{where}: {error}") from None
            if zones:
                solver.relaxation = WaveRelaxation(None, level, zones)
        else:
            solver.relaxation = WaveRelaxation(wave, level, zones, ramp_time=ramp_time,
                                               stop_time=spec.stop_time)
    if case.gauges:
        if level is None:
            levels = [r.parameters["level"] for r in case.water_regions if r.type == "level"]
            if not levels:
                raise CaseFileError(f"{case.source} [[gauges]]: surface gauges measure from the still "
                                    "water level: give [waves] still_water_level or a [[water_regions]] "
                                    "entry of type level")
            level = levels[0]
        try:
            gauges = GaugeSet([Gauge(g.name, g.type, tuple(g.parameters["position"]),
                                     to_x=g.parameters.get("to_x")) for g in case.gauges], level)
        except CaseFileError as error:
            raise CaseFileError(f"{case.source} [[gauges]]: {error}") from None
        try:
            gauges.check_in_grid(grid)
        except CaseFileError as error:
            raise CaseFileError(f"{case.source} [[gauges]]: {error}") from None
        solver.gauges = gauges


def _check_porous_zones_clear_of_the_wave_maker(case, solver, maker_end: float,
                                                boundary: bool) -> None:
    """No porous zone over the wave maker: its relaxation zone (x_low .. ``maker_end``) or the
    cells of the boundary's wave-making faces. The maker prescribes the flow of open water there;
    in a porous zone it would drive the filtration velocity as if it were the water's."""
    if solver.porous is None:
        return
    grid = solver.grid
    centres = grid.centres(0)
    columns = np.zeros(len(centres), dtype=bool)
    columns[0] = True                    # the boundary's faces: the first column of cells
    if not boundary:
        columns |= centres - 0.5 * solver.h < maker_end
    maker = ("the wave-making boundary's cells" if boundary else
             f"the generation zone ({grid.lower[0]:g} .. {maker_end:.4g} m along x)")
    for number, (spec, zone) in enumerate(zip(case.porous_zones, solver.porous.zones)):
        cover = zone.cover(grid)[columns]
        if cover.any():
            x = float(centres[columns][np.flatnonzero(cover.any(axis=(1, 2)))[0]])
            raise CaseFileError(
                f"{case.source} [[porous_zones]] entry {number + 1} ({spec.type}) reaches over "
                f"{maker} (at x = {x:.4g} m): the wave maker needs open water; move the zone "
                f"away from x = {grid.lower[0]:g} m or lengthen the flume in front of it")


def _check_water_level_at_the_zones(case, solver, level: float, absorbing_end: bool) -> None:
    """The [[water_regions]] must put the water surface at the wave maker (and at an absorbing
    end) at [waves] still_water_level: the maker and the absorber hold the water there at that
    level, so any difference would appear or vanish as water in the first step."""
    grid = solver.grid
    h = solver.h
    tolerance = _LEVEL_TOLERANCE_CELLS * h
    ends = [(0, f"the wave maker (x = {grid.lower[0]:g} m)")]
    if absorbing_end:
        ends.append((-1, f"the absorbing end (x = {grid.upper[0]:g} m)"))
    for column, place in ends:
        fraction = solver.fraction[column]                       # (ny, nz)
        surface = grid.lower[2] + float(fraction.sum(axis=1).mean()) * h
        if abs(surface - level) <= tolerance:
            continue
        x = grid.lower[0] if column == 0 else grid.upper[0]
        sources = [f"entry {number + 1} level = {region.parameters['level']:g} m"
                   if region.type == "level" else
                   f"entry {number + 1} upper z = {region.parameters['upper'][2]:g} m"
                   for number, region in enumerate(case.water_regions)
                   if region.type == "level"
                   or region.parameters["lower"][0] - h <= x <= region.parameters["upper"][0] + h]
        made_by = f" ({'; '.join(sources)})" if sources else " (no entry reaches it)"
        raise CaseFileError(
            f"{case.source} [waves] still_water_level = {level:g} m, but the [[water_regions]]"
            f"{made_by} put the water surface at {place} at {surface:.4g} m: the waves would add "
            f"or remove the {abs(surface - level):.3g} m between them in the first step; make "
            f"the two levels equal (within {_LEVEL_TOLERANCE_CELLS:g} of a cell, "
            f"{tolerance:.3g} m)")
