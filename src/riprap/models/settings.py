"""What the ``[simulation]`` table tells a model (the loop keeps the schedule and the outputs)."""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ModelSettings"]


@dataclass(frozen=True)
class ModelSettings:
    """The run's settings a model needs to choose its step, check its start and judge rest (SI
    units; the names of :class:`riprap.simulation.Simulation`'s parameters)."""

    end_time: float
    #: The time step asked for (s); 0 means automatic (``time_step_safety`` of the estimate).
    time_step: float = 0.0
    time_step_safety: float = 0.2
    adaptive_time_step: bool = False
    rest_speed: float = 0.0
    rest_kinetic_energy: float = 0.0
