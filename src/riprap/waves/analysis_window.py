"""When the flume's records can be analysed, known before the run: each gauge's record is read
from when the steady wave train has arrived there (the ramp, the travel from the wave maker at the
group velocity of the peak period, then two periods: ``riprap.waves.report.arrival_time``), and
needs some periods after that:

- a surface gauge's heights and periods: two periods of record after its window opens;
- the incident and reflected waves of a pair or triple of surface gauges (and so the incident Hm0
  the stability number is made from): four periods after the last gauge's window opens;
- run-up and overtopping: two periods after their window opens.

Statistics from one to three waves are given, with a caution (``FEW_WAVES``). A run that ends
before these times is warned about before it starts (``riprap check`` and ``riprap run``), and its
``waves_report.json`` says what it could not compute and why.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from riprap.waves.gauges import OVERTOPPING, RUN_UP, SURFACE
from riprap.waves.theory import group_velocity

__all__ = ["GaugeWindow", "FlumeWindows", "flume_windows", "FEW_WAVES", "STATISTICS_PERIODS",
           "SPLIT_PERIODS", "few_waves_caution", "short_run_warning"]

#: Periods of record after a gauge's window opens for its heights and periods.
STATISTICS_PERIODS = 2.0
#: Periods of record after the last gauge's window opens for an incident/reflected split.
SPLIT_PERIODS = 4.0
#: Statistics from this many waves or fewer carry a caution.
FEW_WAVES = 3


@dataclass(frozen=True)
class GaugeWindow:
    """When one gauge's analysis window opens (s), and of what that time is made."""

    name: str
    kind: str
    x: float
    ramp: float              # s, the wave maker's ramp
    travel: float            # s, from the wave maker to the gauge at the group velocity
    settle: float            # s, two periods after the train's front
    needs: float             # s of record after the window opens for this gauge's results

    @property
    def opens(self) -> float:
        return self.ramp + self.travel + self.settle

    @property
    def complete(self) -> float:
        """The end time from which this gauge's results can all be computed (s)."""
        return self.opens + self.needs


@dataclass(frozen=True)
class FlumeWindows:
    """The analysis windows of a flume's gauges for its (peak) ``period`` (s)."""

    period: float
    group_velocity: float    # m/s, at the peak period
    gauges: tuple            # GaugeWindow, in the case's order

    @property
    def complete(self) -> float:
        """The end time from which every result of the waves report can be computed (s)."""
        return max((g.complete for g in self.gauges), default=0.0)

    def missing(self, end_time: float) -> list[str]:
        """What a run ending at ``end_time`` (s) will not give, one phrase per kind of result."""
        surface = [g for g in self.gauges if g.kind == SURFACE]
        lost = []
        short = [g.name for g in surface if end_time < g.opens + STATISTICS_PERIODS * self.period]
        if short:
            everything = len(short) == len(surface)
            lost.append(f"no wave heights or periods at {'any surface gauge' if everything else ', '.join(short)}")
        if len(surface) >= 2 and end_time < max(g.opens for g in surface) + SPLIT_PERIODS * self.period:
            lost.append("no incident and reflected waves (reflection coefficient)")
        if short and len(short) == len(surface):
            lost.append("no stability number (it needs the incident wave height)")
        for kind, what in ((RUN_UP, "run-up"), (OVERTOPPING, "overtopping")):
            late = [g.name for g in self.gauges if g.kind == kind and end_time < g.complete]
            if late:
                lost.append(f"no {what} at {', '.join(late)}")
        return lost


def flume_windows(wave_source, gauges) -> FlumeWindows | None:
    """The windows of ``gauges`` (a GaugeSet) for the waves of ``wave_source`` (a WaveRelaxation
    or BoundaryWaveMaker); None when the flume makes no waves or has no gauges."""
    wave = getattr(wave_source, "wave", None)
    if wave is None or gauges is None or not gauges.gauges:
        return None
    speed = group_velocity(wave.period, wave.depth, wave.wave_length)
    surface_count = sum(g.kind == SURFACE for g in gauges.gauges)
    windows = []
    for gauge in gauges.gauges:
        needs = (SPLIT_PERIODS if gauge.kind == SURFACE and surface_count >= 2
                 else STATISTICS_PERIODS) * wave.period
        windows.append(GaugeWindow(
            name=gauge.name, kind=gauge.kind, x=float(gauge.position[0]),
            ramp=float(wave_source.ramp_time),
            travel=max(float(gauge.position[0]) - wave_source.origin, 0.0) / speed,
            settle=2.0 * wave.period, needs=needs))
    return FlumeWindows(period=float(wave.period), group_velocity=speed, gauges=tuple(windows))


def few_waves_caution(waves) -> str | None:
    """The caution for statistics from ``waves`` (1..FEW_WAVES) waves, else None."""
    if waves is None or not 1 <= waves <= FEW_WAVES:
        return None
    return (f"from {waves} wave{'s' if waves > 1 else ''} only: heights and periods of so few "
            "waves are not a sea state's statistics (a run of a few hundred waves is usual; run "
            "longer)")


def short_run_warning(windows: FlumeWindows, end_time: float, *, case_end_time: float,
                      where: str) -> str | None:
    """The warning for a run ending at ``end_time`` (s) before its waves can be analysed, or None.
    ``case_end_time``: the case's end_time (differs in smoke mode)."""
    if windows is None or end_time >= windows.complete:
        return None
    first = min(windows.gauges, key=lambda g: g.opens)
    last = max(windows.gauges, key=lambda g: g.opens)
    ends = (f"this smoke run ends at t = {end_time:g} s (the case's end_time is "
            f"{case_end_time:g} s)" if end_time != case_end_time
            else f"end_time = {end_time:g} s ends sooner")
    fewest, most = (min(g.needs for g in windows.gauges) / windows.period,
                    max(g.needs for g in windows.gauges) / windows.period)
    needs = f"{fewest:g}" if fewest == most else f"{fewest:g} to {most:g}"
    lost = windows.missing(end_time)
    gives = ("; ".join(lost) if lost else
             f"statistics from fewer than {FEW_WAVES + 1} waves at some gauges (they carry a caution)")
    return (f"{where}: the wave analysis reads each gauge from when the wave train has arrived: "
            f"{first.opens:.3g} s at {first.name} (ramp {first.ramp:.3g} s + travel "
            f"{first.travel:.3g} s at the group velocity {windows.group_velocity:.3g} m/s + two "
            f"periods {first.settle:.3g} s)"
            + (f" to {last.opens:.3g} s at {last.name}" if last is not first else "")
            + f", and needs {needs} periods after that; "
            f"{ends}: the run will give {gives}. Run to at least {math.ceil(windows.complete):g} s for "
            "every result (many more waves for a sea state's statistics)")
