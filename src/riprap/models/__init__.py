"""What :meth:`riprap.simulation.Simulation.run` advances: a model adapts one solver (or a coupled
pair) to the one run loop.

The loop owns the clock's schedule (frames, checkpoints, the end time), the progress bar, the
failure checkpoint and the summary; a model owns its physics, its own time step and its outputs.
The interface is small (:class:`riprap.models.base.Model`): advance towards a time, say whether a
time is reached, hand over and take back its state, write a frame, describe itself for the
progress bar and the summary. Models today: :class:`riprap.models.rigid.RigidModel` (rigid
bodies), :class:`riprap.models.fluid.FluidModel` (air and water) and
:class:`riprap.models.fluid.CoupledModel` (bodies in the flow).
"""
from riprap.models.base import Model

__all__ = ["Model"]
