"""A test series' steps, each a case of its own (``docs/campaign.md``).

Step k of a ``[series]`` case is the same case with its ``[waves]`` sea replaced by the step's
(significant_height, peak_period, peak_enhancement, seed), a sea that stops after the step's
duration (``[waves] stop_time``: the wave maker fades out and the flume calms) and an end time
that lets the last waves reach the structure and run down (``[series] settle_time``). The step's
case is written as a plain case file in the step's folder (``step.toml``), so that a step folder
is an ordinary run folder: ``riprap run step.toml --restart``, ``riprap analyse`` and the
restart checks all read it as they read any run.

How long a step's sea lasts: ``duration`` when given; from a number of ``waves``, ``waves`` x Tm02
(the mean zero-crossing period sqrt(m0 / m2) of the step's JONSWAP spectrum over the frequencies
the sea is made of, 0.5 .. 3 fp) plus the ramp time (the sea grows and fades over ``ramp_periods``
peak periods at either end: about half a ramp's waves are lost at each). The spectrum's frequency
spacing needs a sea of at least ten peak periods (``IrregularWave``): a shorter step's sea is
drawn from a ten-period spectrum and stopped early.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap import schema
from riprap.errors import CaseFileError
from riprap.waves.theory import group_velocity, jonswap_spectrum, wave_length

__all__ = ["StepSea", "step_seas", "step_case_text", "step_case_data", "case_text",
           "mean_zero_crossing_period"]

#: Peak periods a step runs on after its sea has passed the structure, when [series] settle_time
#: is 0: the last waves' run-up and run-down, and the units they moved coming to rest.
SETTLE_PERIODS = 3.0
#: The shortest spectrum an irregular sea is drawn from (``IrregularWave``), in peak periods.
SPECTRUM_PERIODS = 10.0


@dataclass(frozen=True)
class StepSea:
    """The sea of one step: Hm0 (m), Tp (s), gamma, seed, how long the sea is made (s) and the
    step's end time (s); ``waves`` the number asked for (0: a duration was given)."""

    number: int
    significant_height: float
    peak_period: float
    peak_enhancement: float
    seed: int
    duration: float
    end_time: float
    waves: int


def mean_zero_crossing_period(peak_period: float, peak_enhancement: float) -> float:
    """Tm02 = sqrt(m0 / m2) (s) of a JONSWAP spectrum over 0.5 .. 3 fp, the band riprap's
    irregular sea is made of (``riprap.waves.theory.IrregularWave``)."""
    fp = 1.0 / peak_period
    frequencies = np.linspace(0.5 * fp, 3.0 * fp, 2001)
    density = jonswap_spectrum(frequencies, 1.0, peak_period, peak_enhancement)
    return float(math.sqrt(np.sum(density) / np.sum(density * frequencies ** 2)))


def step_seas(case, seed_offset: int = 0) -> list[StepSea]:
    """Every step's sea and end time, in order; ``seed_offset`` is added to every step's seed
    (another member of a campaign: the same series under other random phases)."""
    gravity = float(-case.simulation.gravity[2])
    waves = case.waves
    depth = waves.still_water_level - case.fluid.lower[2]
    flume_length = case.fluid.upper[0] - case.fluid.lower[0]
    seas = []
    for number, step in enumerate(case.series_steps, start=1):
        height = step.significant_height
        period = step.peak_period or math.sqrt(2.0 * math.pi * height / (gravity * step.wave_steepness))
        ramp_time = waves.ramp_periods * period
        if step.waves:
            duration = (step.waves * mean_zero_crossing_period(period, step.peak_enhancement)
                        + ramp_time)
        else:
            duration = step.duration
        if duration <= ramp_time * 2.0:
            raise CaseFileError(
                f"{case.source} [[series_steps]] step {number}: its sea of {duration:.3g} s is no "
                f"longer than the wave maker's ramp up and down ({2 * ramp_time:.3g} s, "
                f"[waves] ramp_periods = {waves.ramp_periods:g}): give more waves or a longer "
                "duration")
        settle = case.series.settle_time
        if not settle:
            length = wave_length(period, depth, gravity)
            settle = (flume_length / group_velocity(period, depth, length)
                      + SETTLE_PERIODS * period)
        seas.append(StepSea(number=number, significant_height=height, peak_period=period,
                            peak_enhancement=step.peak_enhancement,
                            seed=(step.seed or number) + int(seed_offset),
                            duration=duration, end_time=duration + settle, waves=step.waves))
    return seas


def step_case_data(case, sea: StepSea, gain: float = 1.0, period_factor: float = 1.0) -> dict:
    """The case of one step as TOML data: the series case's with the step's sea in ``[waves]``,
    its end time, no ``[series]`` tables, and every file path made absolute (the step's case
    lives in the step's folder). ``gain`` and ``period_factor``: the wave maker's calibration
    (``riprap.workflows.series_calibration``): the sea is made with Hm0 x gain and Tp x
    period_factor so that the one asked arrives at the toe."""
    path = Path(case.source)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise CaseFileError(f"{case.source}: cannot be read again to write the series' steps "
                            f"({error})") from None
    data.pop("series", None)
    data.pop("series_steps", None)
    period = sea.peak_period * period_factor
    data["waves"].update(significant_height=sea.significant_height * gain, peak_period=period,
                         peak_enhancement=sea.peak_enhancement, seed=sea.seed,
                         duration=max(sea.duration, SPECTRUM_PERIODS * period),
                         stop_time=sea.duration)
    data["simulation"]["end_time"] = sea.end_time
    _absolute_paths(data, case.base_dir)
    return data


def case_text(data: dict, header: str) -> str:
    """TOML data written as a case file, ``header`` its first comment line."""
    lines = [f"# {header}"]
    lines += [f"{name} = {schema.format_toml_value(value)}" for name, value in data.items()
              if not isinstance(value, (dict, list)) or (isinstance(value, list) and not
                                                         all(isinstance(v, dict) for v in value))]
    for name, value in data.items():
        if isinstance(value, dict):
            lines += ["", f"[{name}]"] + _pairs(value)
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for entry in value:
                lines += ["", f"[[{name}]]"] + _pairs(entry)
    return "\n".join(lines) + "\n"


def step_case_text(case, sea: StepSea, gain: float = 1.0, period_factor: float = 1.0) -> str:
    """The case file of one step (``step_case_data`` written out)."""
    maker = ("" if gain == 1.0 and period_factor == 1.0 else
             f"; the wave maker calibrated: Hm0 x {gain:.4f}, Tp x {period_factor:.4f}")
    return case_text(step_case_data(case, sea, gain, period_factor),
                     f"riprap test series {Path(case.source).name}: step {sea.number} (Hm0 = "
                     f"{sea.significant_height:g} m, Tp = {sea.peak_period:.4g} s{maker}); "
                     "written by riprap, the series case is the one to edit")


def _pairs(table: dict) -> list[str]:
    return [f"{key} = {schema.format_toml_value(value)}" for key, value in table.items()]


def _absolute_paths(data: dict, base_dir: Path) -> None:
    """Every value of a ``path`` key (and the top-level ``pack``) resolved against the series
    case's folder."""
    path_keys = {(entry.table, entry.name) for entry in schema.KEYS if entry.kind == "path"}
    if isinstance(data.get("pack"), str):
        data["pack"] = str((base_dir / data["pack"]).resolve())
    for table, value in data.items():
        entries = value if isinstance(value, list) else [value]
        for entry in entries:
            if not isinstance(entry, dict):
                continue
            for key in entry:
                if (table, key) in path_keys and isinstance(entry[key], str) and entry[key]:
                    entry[key] = str((base_dir / entry[key]).resolve())
