"""Waves a flume cannot carry, refused before the run with the figure and what is needed.

The limits: the grid must resolve the wave (``MINIMUM_CELLS_PER_HEIGHT`` cells over the wave
height, ``MINIMUM_CELLS_PER_LENGTH`` over the wave length: below these the measured height along
the flume is no longer within 5 %, docs/waves.md); the zones must be long enough to make and to
absorb it; the wave must not break where it is made (Miche's limit H/L = 0.142 tanh(kd), and the
depth limit H/d = 0.78); and the theory must hold in that depth (Ursell number H L^2/d^3 below 26
for linear and Stokes theory (the stream-function wave has no such limit), no secondary crest in a
Stokes second-order trough).
"""
from __future__ import annotations

import math

from riprap.errors import CaseFileError
from riprap.waves.relaxation import ABSORPTION, GENERATION

__all__ = ["check_flume", "MINIMUM_CELLS_PER_HEIGHT", "MINIMUM_CELLS_PER_LENGTH"]

MINIMUM_CELLS_PER_HEIGHT = 2.0
MINIMUM_CELLS_PER_LENGTH = 40.0
MINIMUM_GENERATION_WAVE_LENGTHS = 0.5
MINIMUM_ABSORPTION_WAVE_LENGTHS = 1.0
URSELL_LIMIT = 26.0


def check_flume(wave, cell_size: float, zones, *, where: str = "waves") -> None:
    """Raise CaseFileError naming the first limit ``wave`` breaks on cells of ``cell_size`` m."""
    height, length, depth = wave.height, wave.wave_length, wave.depth
    name = wave.height_name
    k = 2.0 * math.pi / length
    if height / cell_size < MINIMUM_CELLS_PER_HEIGHT:
        raise CaseFileError(
            f"{where}: {name} = {height:g} m spans {height / cell_size:.2g} cells of {cell_size:g} m; "
            f"at least {MINIMUM_CELLS_PER_HEIGHT:g} are needed: cells of at most "
            f"{height / MINIMUM_CELLS_PER_HEIGHT:.3g} m")
    if length / cell_size < MINIMUM_CELLS_PER_LENGTH:
        raise CaseFileError(
            f"{where}: the wave length L = {length:.3g} m spans {length / cell_size:.3g} cells; at "
            f"least {MINIMUM_CELLS_PER_LENGTH:g} are needed: cells of at most "
            f"{length / MINIMUM_CELLS_PER_LENGTH:.3g} m")
    for zone in zones:
        needed = (MINIMUM_GENERATION_WAVE_LENGTHS if zone.kind == GENERATION
                  else MINIMUM_ABSORPTION_WAVE_LENGTHS)
        if zone.length < needed * length - 1e-9:
            raise CaseFileError(
                f"{where}: the {zone.kind} zone is {zone.length:.3g} m long, {zone.length / length:.2g} "
                f"wave lengths (L = {length:.3g} m); at least {needed:g} L = {needed * length:.3g} m "
                f"is needed" + (" to absorb the waves" if zone.kind == ABSORPTION else ""))
    miche = 0.142 * math.tanh(k * depth) * length
    if height > miche or height > 0.78 * depth:
        raise CaseFileError(
            f"{where}: {name} = {height:g} m breaks where it is made: the limit in d = {depth:g} m at "
            f"L = {length:.3g} m is {min(miche, 0.78 * depth):.3g} m (Miche 0.142 L tanh(kd) = "
            f"{miche:.3g} m, depth limit 0.78 d = {0.78 * depth:.3g} m)")
    if wave.ursell_limited:
        ursell = height * length ** 2 / depth ** 3
        if ursell > URSELL_LIMIT:
            raise CaseFileError(
                f"{where}: Ursell number H L^2/d^3 = {ursell:.3g} > {URSELL_LIMIT:g}: in d = {depth:g} "
                f"m this wave is a cnoidal (shallow-water) wave, outside linear and Stokes theory; "
                f"use type = \"stream_function\", deeper water or a lower H")
        ratio = getattr(wave, "second_harmonic_ratio", None)
        if ratio is not None and ratio() > 0.25:
            raise CaseFileError(
                f"{where}: Stokes second order gives this wave a second crest in its trough (second "
                f"harmonic {ratio():.2f} of the first, limit 0.25); lower H or deepen the water")
