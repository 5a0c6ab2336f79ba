"""The flume test as ``riprap analyse`` reports it, from what the run wrote (read by riprap.io):
the gauges' spectra beside the target sea, the largest fluid force on each unit, the share of the
units that rock.

- Spectra: each surface gauge's variance density over its analysis window (from the time the wave
  train has arrived, as ``waves_report.json`` says), averaged over :data:`SPECTRUM_BANDS`
  neighbouring frequencies, beside the target: the case's JONSWAP spectrum (Hm0, Tp, gamma) for
  an irregular sea, the wave's frequency for a regular one.
- Fluid force: the largest magnitude of the fluid's force on each unit over the run (the fluid
  steps between frames included, ``body_forces.csv``), when, and over the unit's submerged weight
  (rho_s - rho_w) V g. It is the water's whole force, buoyancy included: a submerged unit in still
  water carries 1 / Delta = rho_w / (rho_s - rho_w) of its submerged weight (0.71 for concrete of
  2400 kg/m^3 in fresh water), and the water alone lifts it once the upward part exceeds its
  weight, 1 + 1 / Delta submerged weights.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.analysis import variance_density
from riprap.waves.theory import jonswap_spectrum

__all__ = ["FlumeRecords", "gauge_spectra", "target_spectrum", "fluid_force_columns",
           "rocking_share", "SPECTRUM_BANDS", "SURFACE_SUFFIX", "RUN_UP_SUFFIX",
           "OVERTOPPING_SUFFIX"]

#: Neighbouring frequencies averaged in a measured spectrum (10 % of a 40 s window's are 4).
SPECTRUM_BANDS = 4
#: Column suffixes of ``gauges.csv`` (riprap.waves.gauges.Gauge.columns).
SURFACE_SUFFIX, RUN_UP_SUFFIX, OVERTOPPING_SUFFIX = "_eta_m", "_level_m", "_volume_m3_m"


@dataclass
class FlumeRecords:
    """What a flume run left for its report: ``waves_report`` (``waves_report.json``, or None),
    the gauge records (``gauges.csv``: ``times``, ``columns``; None without one) and the target
    sea of the case (``target``: ``type`` "irregular"/"regular", ``height_m`` (Hm0 or H),
    ``period_s`` (Tp or T), ``peak_enhancement``; None without waves) and the units' contacts
    frame by frame (``contacts``: ``riprap.io.frame_contacts.read_unit_contacts_per_frame``; None
    where the frames do not carry them)."""

    waves_report: dict | None = None
    times: np.ndarray | None = None
    columns: dict = field(default_factory=dict)
    target: dict | None = None
    contacts: dict | None = None
    #: Filled by :func:`with_derived`: each surface gauge's spectrum or the reason it has none
    #: (:func:`gauge_spectra`; empty without gauge records), the target's variance density
    #: ``(frequencies (Hz), density (m^2 s))`` (None unless an irregular sea) and the units that
    #: rocked (:func:`rocking_share`).
    spectra: list = field(default_factory=list)
    target_density: tuple | None = None
    rocking: dict | None = None

    def series(self, suffix: str) -> dict:
        """``{gauge name: values}`` of the gauges whose columns end with ``suffix``."""
        return {name[:-len(suffix)]: values for name, values in self.columns.items()
                if name.endswith(suffix)}

    def run_up_series(self) -> dict:
        """``{run-up gauge: highest level above the still water (m)}``."""
        return self.series(RUN_UP_SUFFIX)

    def overtopping_series(self) -> dict:
        """``{overtopping gauge: volume over the crest so far (m^3/m)}``."""
        return self.series(OVERTOPPING_SUFFIX)


def with_derived(records: FlumeRecords, units: dict) -> FlumeRecords:
    """``records`` with what the report shows computed from them (spectra, the target's density,
    the rocking share of ``units``), so that the report only draws and writes."""
    target = records.target
    density = None
    if target and target.get("type") == "irregular":
        frequencies = np.linspace(0.0, 3.0 / target["period_s"], 600)
        density = (frequencies, target_spectrum(target, frequencies))
    spectra = gauge_spectra(records) if records.times is not None else []
    return replace(records, spectra=spectra, target_density=density,
                   rocking=rocking_share(units))


def target_spectrum(target: dict, frequencies) -> np.ndarray | None:
    """The case's JONSWAP variance density at ``frequencies`` (evenly spaced, Hz), or None when
    the target is not an irregular sea."""
    if not target or target.get("type") != "irregular":
        return None
    return jonswap_spectrum(frequencies, target["height_m"], target["period_s"],
                            target.get("peak_enhancement", 3.3))


def _window_start(entry) -> float | None:
    start = entry.get("analysed_from_s") if isinstance(entry, dict) else None
    if isinstance(start, bool) or not isinstance(start, (int, float)) or not math.isfinite(start):
        return None
    return float(start)


def gauge_spectra(records: FlumeRecords) -> list[dict]:
    """Per surface gauge: ``name``, ``frequencies_Hz`` and ``density_m2_s`` over its analysis
    window, or ``reason`` (why there is none)."""
    gauges = (records.waves_report or {}).get("gauges", {})
    gauges = gauges if isinstance(gauges, dict) else {}
    spectra = []
    for name, eta in records.series(SURFACE_SUFFIX).items():
        start = _window_start(gauges.get(name))
        if start is None:
            start = float(records.times[0]) if len(records.times) else 0.0
        chosen = records.times >= start
        duration = float(records.times[chosen][-1] - start) if chosen.any() else 0.0
        period = (records.target or {}).get("period_s")
        needed = 2.0 * period if period else 0.0
        if not chosen.any():
            end = float(records.times[-1]) if len(records.times) else 0.0
            spectra.append({"name": name, "reason": (
                f"record too short: the run ended at t = {end:.3g} s, before the wave train "
                f"reached the gauge (t = {start:.3g} s)")})
            continue
        if chosen.sum() < 8 or duration < needed:
            spectra.append({"name": name, "reason": (
                f"record too short: {duration:.3g} s ({int(chosen.sum())} samples) after the "
                f"wave train's arrival at t = {start:.3g} s; two periods ({needed:.3g} s) and "
                "8 samples needed")})
            continue
        try:
            frequencies, density = _spectrum_of(records.times[chosen], eta[chosen])
        except CaseFileError as error:
            spectra.append({"name": name, "reason": str(error)})
            continue
        spectra.append({"name": name, "frequencies_Hz": frequencies, "density_m2_s": density})
    return spectra


def _spectrum_of(times, eta):
    return variance_density(times, eta, bands=SPECTRUM_BANDS)


def fluid_force_columns(peaks: dict | None, bodies, *, volumes, armour_densities,
                        water_density: float, gravity: float) -> dict:
    """``units.csv``'s fluid force columns of the units ``bodies`` (their volumes (m^3) and
    densities (kg/m^3) given per unit) from ``peaks`` (``riprap.io.body_forces.
    read_peak_fluid_forces``; None: NaN columns): ``max_fluid_force_N``,
    ``max_fluid_force_time_s`` and ``max_fluid_force_over_submerged_weight``."""
    bodies = np.asarray(bodies, dtype=np.int64)
    if peaks is None:
        empty = np.full(len(bodies), np.nan)
        return {"max_fluid_force_N": empty, "max_fluid_force_time_s": empty.copy(),
                "max_fluid_force_over_submerged_weight": empty.copy()}
    force = np.asarray(peaks["force_N"], dtype=float)[bodies]
    submerged = ((np.asarray(armour_densities, dtype=float) - water_density)
                 * np.asarray(volumes, dtype=float) * gravity)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(submerged > 0, force / np.where(submerged > 0, submerged, 1.0), np.nan)
    return {"max_fluid_force_N": force,
            "max_fluid_force_time_s": np.asarray(peaks["time_s"], dtype=float)[bodies],
            "max_fluid_force_over_submerged_weight": ratio}


def rocking_share(units: dict) -> dict | None:
    """Units that rocked at least once (``rocking_events`` > 0) and their share of all, or None
    when the rocking was not counted (no frames to count it over)."""
    events = np.asarray(units.get("rocking_events", []), dtype=float)
    if not events.size or not np.isfinite(events).any():
        return None
    rocked = np.flatnonzero(events > 0)
    return {"units_rocking": [int(k) for k in rocked], "units": int(events.size),
            "share": float(rocked.size / events.size)}
