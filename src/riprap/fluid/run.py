"""``FluidRun``: the name fluid runs had before the one run loop.

A fluid run, or a run of bodies in the flow, is now a :class:`riprap.simulation.Simulation` with
a fluid: ``Simulation(end_time=..., fluid=solver)``. ``FluidRun(solver, end_time=...)`` still
builds exactly that, so scripts written for it keep working; the fluid is ``run.fluid`` and, for a
coupled run, the bodies' solver is ``run.solver`` (as in every Simulation).
"""
from __future__ import annotations

from riprap.simulation import RunSummary, Simulation

__all__ = ["FluidRun", "FluidRunSummary"]

#: The summary of a fluid run is the summary of any run.
FluidRunSummary = RunSummary


class FluidRun(Simulation):
    """``Simulation(fluid=solver, ...)`` under its former name; ``solver`` a
    :class:`riprap.fluid.solver.FluidSolver` or a :class:`riprap.coupling.coupled.CoupledSolver`."""

    def __init__(self, solver, *, end_time: float, output_interval: float = 0.05,
                 checkpoint_interval: float = 0.0, output_directory="riprap-out",
                 paraview: bool = True, picture: bool = True, progress: bool = True,
                 case_file: str = ""):
        super().__init__(end_time=end_time, output_interval=output_interval,
                         checkpoint_interval=checkpoint_interval,
                         output_directory=output_directory, paraview=paraview, picture=picture,
                         progress=progress, fluid=solver)
        self.case_file = case_file
