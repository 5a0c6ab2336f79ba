"""The wave theories a case file can name (``[waves] type``), and what every theory provides.

A wave theory is a frozen dataclass with the attributes of ``WaveTheory`` below; the wave maker
(relaxation zone or boundary), the flume checks and the waves report use nothing else. To add one
(e.g. cnoidal): write its class beside ``theory.py`` / ``stream_function.py``, add a maker to
``WAVE_THEORIES`` that builds it from the ``[waves]`` parameters, and add its name and keys to the
schema's ``[waves]`` table (a test checks that the schema's choices are the names here).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from riprap.waves.stream_function import StreamFunctionWave
from riprap.waves.theory import IrregularWave, LinearWave, StokesSecondOrderWave

__all__ = ["WaveTheory", "WAVE_THEORIES", "make_wave"]


class WaveTheory(Protocol):
    """What the flume asks of a wave (SI units; x along the flume, z up from the still water
    level, t in s)."""

    #: True for one height and period (analysed as H, T); False for a sea (Hm0, Tp).
    regular: bool
    #: "H" or "Hm0": how errors and reports name ``height``.
    height_name: str
    #: Whether the Ursell-number limit of a Stokes-type theory applies (checks.URSELL_LIMIT).
    ursell_limited: bool
    height: float
    period: float
    depth: float
    wave_length: float

    def elevation(self, x, t) -> np.ndarray:
        """Free-surface elevation (m) above the still water level."""

    def velocity(self, x, z, t) -> tuple[np.ndarray, np.ndarray]:
        """Orbital velocity (u, w) in m/s at points (x, z)."""

    def velocity_grid(self, x, z, t) -> tuple[np.ndarray, np.ndarray]:
        """Orbital velocity on the grid spanned by 1-D arrays x and z."""


def _linear(p: dict, depth: float, end_time: float, gravity: float):
    return LinearWave(height=p["height"], period=p["period"], depth=depth, phase=p["phase"],
                      gravity=gravity)


def _stokes2(p: dict, depth: float, end_time: float, gravity: float):
    return StokesSecondOrderWave(height=p["height"], period=p["period"], depth=depth,
                                 phase=p["phase"], gravity=gravity)


def _stream_function(p: dict, depth: float, end_time: float, gravity: float):
    return StreamFunctionWave(height=p["height"], period=p["period"], depth=depth,
                              phase=p["phase"], gravity=gravity)


def _irregular(p: dict, depth: float, end_time: float, gravity: float):
    return IrregularWave(significant_height=p["significant_height"], peak_period=p["peak_period"],
                         depth=depth, duration=p["duration"] or end_time,
                         peak_enhancement=p["peak_enhancement"], seed=p["seed"], gravity=gravity)


#: ``[waves] type`` -> maker(parameters, depth, end_time, gravity) of the wave.
WAVE_THEORIES: dict[str, Callable[[dict, float, float, float], WaveTheory]] = {
    "linear": _linear,
    "stokes2": _stokes2,
    "stream_function": _stream_function,
    "irregular": _irregular,
}


def make_wave(theory: str, parameters: dict, depth: float, end_time: float, gravity: float):
    """The wave of a ``[waves]`` table: ``theory`` (its type), its parameters, the still water
    depth at the wave maker (m), the run's end time (s: an irregular sea's default duration) and
    gravity (m/s^2)."""
    return WAVE_THEORIES[theory](parameters, depth, end_time, gravity)
