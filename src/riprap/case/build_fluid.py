"""Build a fluid run (:class:`riprap.fluid.run.FluidRun`) from a case with a ``[fluid]`` table."""
from __future__ import annotations

from pathlib import Path

from riprap.case.build import SMOKE_END_TIME, smoke_mode
from riprap.errors import CaseFileError
from riprap.fluid.grid import SIDES, FluidGrid
from riprap.fluid.phases import Phase
from riprap.fluid.run import FluidRun
from riprap.fluid.solver import FluidSolver

__all__ = ["build_fluid_run", "build_fluid_solver"]


def build_fluid_solver(case) -> FluidSolver:
    """The grid, fluids, water and obstacles of ``case``, ready to step."""
    spec = case.fluid
    if spec is None:
        raise CaseFileError(f"{case.source}: no [fluid] table")
    where = f"{case.source} [fluid]"
    try:
        grid = FluidGrid(lower=spec.lower, upper=spec.upper, cells=spec.cells,
                         boundaries={side: getattr(spec, side) for side in SIDES})
    except CaseFileError as error:
        raise CaseFileError(f"{where}: {error}") from None
    solver = FluidSolver(grid, water=Phase("water", spec.water_density, spec.water_viscosity),
                         air=Phase("air", spec.air_density, spec.air_viscosity),
                         gravity=case.simulation.gravity, courant_number=spec.courant_number,
                         pressure_tolerance=spec.pressure_tolerance,
                         max_time_step=spec.max_time_step, surface_tension=spec.surface_tension)
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
    if not case.water_regions:
        raise CaseFileError(f"{case.source}: a [fluid] case needs at least one [[water_regions]] "
                            "entry (a box of water or a still-water level)")
    if not solver.water_volume() > 0.0:
        raise CaseFileError(f"{case.source}: no water is left: the [[obstacles]] cover every cell of "
                            "the [[water_regions]] (or the regions hold less than a cell of water); "
                            "move the obstacles or the water")
    return solver


def build_fluid_run(case, *, output_directory=None, progress: bool = True) -> FluidRun:
    """A :class:`FluidRun` of ``case`` (``[simulation]`` end time, output and checkpoint intervals);
    with bodies, they move in the flow and push it (two-way coupling, ``docs/coupling.md``)."""
    settings = case.simulation
    end_time = min(settings.end_time, SMOKE_END_TIME) if smoke_mode() else settings.end_time
    source = Path(case.source)
    model = build_fluid_solver(case)
    if case.body_count > 0:
        model = _coupled(case, model)
    return FluidRun(model, end_time=end_time,
                    output_interval=settings.output_interval,
                    checkpoint_interval=settings.checkpoint_interval,
                    output_directory=output_directory or case.output.directory,
                    paraview=case.output.paraview, picture=case.output.picture, progress=progress,
                    case_file=str(source.resolve()) if source.is_file() else "")


def _coupled(case, fluid):
    """The case's bodies (as ``riprap run`` builds them for a dry run) coupled to ``fluid``; the
    fluid box's sides are walls for them, of the first material."""
    from riprap.case.build import build_simulation
    from riprap.coupling.coupled import CoupledSolver

    simulation = build_simulation(case, progress=False)
    solids = simulation.solver
    simulation.build_without_checks()
    simulation.check_start_overlaps()
    return CoupledSolver(fluid, solids)
