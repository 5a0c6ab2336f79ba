"""Build the fluid of a case with a ``[fluid]`` table, and its run (a
:class:`riprap.simulation.Simulation` of the fluid alone, or of the case's bodies in it)."""
from __future__ import annotations

import warnings
from pathlib import Path

from riprap.case.body_start import check_coordinates
from riprap.case.build import SMOKE_END_TIME, build_simulation, smoke_mode
from riprap.case.build_waves import build_waves
from riprap.case.run_record import RunDefinition
from riprap.case.specs import keywords_for
from riprap.coupling.coupled import MINIMUM_DENSITY_RATIO
from riprap.coupling.filter_layer import (UNRESOLVED_BELOW_CELLS, choose_filter_layer,
                                          nominal_cells, unresolved_fixed_bodies)
from riprap.errors import CaseFileError
from riprap.fluid.grid import SIDES, FluidGrid
from riprap.fluid.phases import Phase
from riprap.fluid.porous import PorousZone
from riprap.fluid.solver import FluidSolver
from riprap.simulation import Simulation
from riprap.waves.analysis_window import flume_windows, short_run_warning
from riprap.work_estimate import RiprapWarning

__all__ = ["build_fluid_run", "build_fluid_solver"]


def build_fluid_solver(case) -> FluidSolver:
    """The grid, fluids, water and obstacles of ``case``, ready to step."""
    spec = case.fluid
    if spec is None:
        raise CaseFileError(f"{case.source}: no [fluid] table")
    where = f"{case.source} [fluid]"
    _check_fluid_coordinates(case)
    try:
        grid = FluidGrid(lower=spec.lower, upper=spec.upper, cells=spec.cells,
                         boundaries={side: getattr(spec, side) for side in SIDES})
    except CaseFileError as error:
        raise CaseFileError(f"{where}: {error}") from None
    if grid.periodic_y and grid.cells[1] % 4:
        ny = grid.cells[1]
        warnings.warn(f"{where}: a periodic y of ny = {ny} cells (not a multiple of 4): the "
                      "pressure solve's multigrid cannot coarsen y on a periodic strip (slower "
                      f"solves on wide grids); {ny - 2} or {ny + 2} cells across would let it",
                      RiprapWarning, stacklevel=2)
    solver = FluidSolver(grid, water=Phase("water", spec.water_density, spec.water_viscosity),
                         air=Phase("air", spec.air_density, spec.air_viscosity),
                         gravity=case.simulation.gravity,
                         **keywords_for(FluidSolver, spec))   # the solver's [fluid] keys
    for number, region in enumerate(case.water_regions):
        try:
            if region.type == "level":
                solver.set_still_water_level(region.parameters["level"])
            else:
                solver.add_water_box(region.parameters["lower"], region.parameters["upper"])
        except CaseFileError as error:
            raise CaseFileError(f"{case.source} [[water_regions]] entry {number + 1}: {error}") from None
    for number, obstacle in enumerate(case.obstacles):
        try:
            solver.add_obstacle_box(obstacle.parameters["lower"], obstacle.parameters["upper"])
        except CaseFileError as error:
            raise CaseFileError(f"{case.source} [[obstacles]] entry {number + 1}: {error}") from None
    if case.porous_zones:
        _add_porous_zones(case, solver)
    if not case.water_regions:
        raise CaseFileError(f"{case.source}: a [fluid] case needs at least one [[water_regions]] "
                            "entry (a box of water or a still-water level)")
    if case.waves is not None or case.gauges:
        build_waves(case, solver)
    if not solver.water_volume() > 0.0:
        raise CaseFileError(f"{case.source}: no water is left: the [[obstacles]] cover every cell of "
                            "the [[water_regions]] (or the regions hold less than a cell of water); "
                            "move the obstacles or the water")
    return solver


def _check_fluid_coordinates(case) -> None:
    """Every coordinate of the fluid box, its water, obstacles, porous zones and gauges within
    riprap.case.body_start.LARGEST_COORDINATE: a box reaching 1e308 m overflows its cell size."""
    check_coordinates(f"{case.source} [fluid]", "lower", case.fluid.lower)
    check_coordinates(f"{case.source} [fluid]", "upper", case.fluid.upper)
    for table, entries in (("water_regions", case.water_regions), ("obstacles", case.obstacles),
                           ("porous_zones", case.porous_zones), ("gauges", case.gauges)):
        for number, entry in enumerate(entries):
            for key in ("level", "lower", "upper", "points", "position", "to_x"):
                value = entry.parameters.get(key)
                if value is not None:
                    check_coordinates(f"{case.source} [[{table}]] entry {number + 1}", key, value)


def _add_porous_zones(case, solver) -> None:
    zones = []
    for number, spec in enumerate(case.porous_zones):
        p = spec.parameters
        name = f"{case.source} [[porous_zones]] entry {number + 1}"
        shape = ({"polygon": p["points"]} if spec.type == "polygon"
                 else {"lower": p["lower"], "upper": p["upper"]})
        zones.append(PorousZone(porosity=spec.porosity, stone_diameter=spec.stone_diameter,
                                linear=spec.linear_friction, quadratic=spec.quadratic_friction,
                                added_mass=spec.added_mass, name=name, **shape))
    solver.add_porous_zones(zones)


def _check_bodies_not_too_light(case) -> None:
    """Refuse a free body far lighter than the water: the coupling holds the fluid's load over a
    step, which a body much lighter than the water it displaces cannot carry (it sinks where it
    should rise; riprap.coupling.coupled.MINIMUM_DENSITY_RATIO)."""
    water = case.fluid.water_density
    entries = [(f"[[bodies]] entry {n + 1}", body.material)
               for n, body in enumerate(case.bodies) if not body.fixed]
    entries += [(f"[[body_grids]] entry {n + 1}", grid.material)
                for n, grid in enumerate(case.body_grids)]
    for entry, name in entries:
        density = case.material(name).density
        if density < MINIMUM_DENSITY_RATIO * water:
            raise CaseFileError(
                f"{case.source}: [[materials]] '{name}' (used by {entry}) has density = "
                f"{density:g} kg/m^3, {density / water:.3g} of the water's {water:g} kg/m^3; the "
                f"coupling to the flow carries free bodies down to {MINIMUM_DENSITY_RATIO:g} of "
                "it (a lighter one sinks where it should float): give the material's density in "
                "kg/m^3, or make the body fixed")


def build_fluid_run(case, *, output_directory=None, progress: bool = True):
    """The run of ``case``: its fluid alone, or, with bodies, the bodies moving in the flow and
    pushing it (two-way coupling, ``docs/coupling.md``); a :class:`riprap.simulation.Simulation`
    with the ``[simulation]`` end time, output and checkpoint intervals. The coupled model is
    built here, so that its checks (bodies inside the box, wide enough for the cells, not
    overlapping) run before anything else."""
    fluid = build_fluid_solver(case)
    if case.body_count > 0:
        _check_bodies_not_too_light(case)
        simulation = build_simulation(case, output_directory=output_directory, progress=progress)
        simulation.add_fluid(fluid)
        _choose_contact_only_bodies(case, simulation, fluid)
        simulation.cut_faces = case.fluid.cut_faces
        simulation.prepare()
        _warn_if_too_short_to_analyse(case, simulation)
        return simulation
    if case.fluid.contact_only_below_cells > 0:
        warnings.warn(f"{case.source} [fluid] contact_only_below_cells = "
                      f"{case.fluid.contact_only_below_cells:g}: the case has no bodies, so "
                      "nothing is contact-only; leave the key out", RiprapWarning, stacklevel=2)
    settings = case.simulation
    source = Path(case.source)
    simulation = Simulation(
        end_time=min(settings.end_time, SMOKE_END_TIME) if smoke_mode() else settings.end_time,
        output_interval=settings.output_interval, checkpoint_interval=settings.checkpoint_interval,
        output_directory=output_directory or case.output.directory, paraview=case.output.paraview,
        picture=case.output.picture, progress=progress, fluid=fluid,
        body_forces_interval=case.output.body_forces_interval)
    simulation.case_file = str(source.resolve()) if source.is_file() else ""
    simulation.run_definition = RunDefinition.of(case)
    _warn_if_too_short_to_analyse(case, simulation)
    return simulation


def _choose_contact_only_bodies(case, simulation, fluid) -> None:
    """Make the fixed bodies under ``[fluid] contact_only_below_cells`` contact-only, with the
    porous filter zone the flow sees in their place (``riprap.coupling.filter_layer``); without
    the key, warn of fixed bodies too small for the grid. ``simulation.filter_layer`` keeps the
    choice for the run's log and ``riprap check``."""
    threshold = case.fluid.contact_only_below_cells
    solver, h = simulation.solver, fluid.grid.cell_size
    simulation.filter_layer = None
    if threshold <= 0.0:
        small = unresolved_fixed_bodies(solver, h)
        if len(small):
            cells = nominal_cells(solver, h)
            fixed = solver.body_poses()[4]
            free = cells[~fixed]
            between = (f"; e.g. {0.5 * (cells[small].max() + free.min()):.2g}, between them and "
                       f"the free bodies' {free.min():.2f}" if len(free)
                       and free.min() > cells[small].max() else "")
            warnings.warn(
                f"{case.source}: {len(small)} fixed bodies span fewer than "
                f"{UNRESOLVED_BELOW_CELLS:g} cells of the fluid grid ({cells[small].min():.2f}-"
                f"{cells[small].max():.2f}): clipped into the flow, their cut faces hold the water "
                "with a drag that depends on the time step, not a filter's; give [fluid] "
                "contact_only_below_cells to make them contact-only under a porous filter zone"
                f"{between} (docs/waves.md, Filter layers)", RiprapWarning, stacklevel=3)
        return
    where = f"{case.source}"
    if simulation.deformable_bodies:
        raise CaseFileError(f"{where} [fluid] contact_only_below_cells: not for runs with "
                            "deformable bodies (their coupling keeps every rigid body in the "
                            "flow); leave the key out")
    zones = fluid.porous.zones if fluid.porous is not None else []
    layer = choose_filter_layer(solver, zones, cell_size=h, contact_only_below_cells=threshold,
                                where=where)
    if layer.fitted:
        # the case's own zones come after the fitted ones: where they overlap, the case's win
        fluid.add_porous_zones(layer.fitted + list(zones))
    simulation.contact_only_bodies = [int(body) for body in layer.bodies]
    simulation.filter_layer = layer
    if not len(layer.bodies):
        warnings.warn(f"{where}: {layer.lines()[0]}", RiprapWarning, stacklevel=3)


def _warn_if_too_short_to_analyse(case, simulation) -> None:
    """Say before the run (``riprap check`` and ``riprap run`` both build it here) when it ends
    before the wave analysis can give its results; the run goes on."""
    fluid = simulation.fluid
    text = short_run_warning(flume_windows(fluid.wave_source, fluid.gauges), simulation.end_time,
                             case_end_time=case.simulation.end_time,
                             where=f"{case.source} [simulation] end_time")
    if text is not None:
        warnings.warn(text, RiprapWarning, stacklevel=3)
