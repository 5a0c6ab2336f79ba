"""Pictures of a flume test for ``report.html`` (matplotlib, PNG): the waves (spectra beside the
target, run-up and overtopping records) and the stability (profiles of the section before and
after, each unit's displacement and rocking). Each figure is drawn whatever the run gave: what
could not be computed is written in the panel instead of a curve, so the report never shows an
empty frame."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riprap.io import analysis_figures
from riprap.io.analysis_figures import FACTOR_OF_SAFETY_DISPLAY_CAP

__all__ = ["spectra_figure", "gauge_record_figure", "profiles_figure", "unit_damage_figure",
           "contacts_figure"]


def _pyplot():
    return analysis_figures._pyplot()


def _save(figure, path) -> Path:
    return analysis_figures._save(figure, Path(path), formats=("png",))[0]


def _say(axes, text: str) -> None:
    """What a panel could not show, in the panel's place (its empty frame hidden)."""
    axes.set_axis_off()
    axes.text(0.5, 0.5, text, transform=axes.transAxes, ha="center", va="center", fontsize=9,
              wrap=True, color="0.3", bbox={"facecolor": "white", "edgecolor": "0.8"})


def spectra_figure(path, spectra: list[dict], target: dict | None, target_density) -> Path:
    """Each surface gauge's measured variance density (``gauge_spectra``) beside the target's
    (``target_density``: (frequencies, density), or None for a regular wave, drawn as a line at
    its frequency)."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(7.5, 3.6))
    if target_density is not None:
        frequencies, density = target_density
        axes.plot(frequencies, density, color="black", linestyle="--", linewidth=1.4,
                  label=(f"target JONSWAP Hm0 {target['height_m']:g} m, "
                         f"Tp {target['period_s']:g} s, "
                         f"gamma {target.get('peak_enhancement', 3.3):g}"))
    elif target:
        axes.axvline(1.0 / target["period_s"], color="black", linestyle="--",
                     label=f"target: regular, H {target['height_m']:g} m, "
                           f"T {target['period_s']:g} s")
    missing = []
    for spectrum in spectra:
        if "reason" in spectrum:
            missing.append(f"{spectrum['name']}: not computed ({spectrum['reason']})")
            continue
        axes.plot(spectrum["frequencies_Hz"], spectrum["density_m2_s"], linewidth=1.0,
                  label=f"measured at {spectrum['name']}")
    if target:
        axes.set_xlim(0.0, 3.0 / target["period_s"])
    if missing:
        names = [s["name"] for s in spectra if "reason" in s]
        axes.text(0.98, 0.55, f"measured: not computed at {', '.join(names[:8])}\n(the report "
                  "says why)", transform=axes.transAxes, ha="right", va="center", fontsize=8,
                  color="0.3", bbox={"facecolor": "white", "edgecolor": "0.8"})
    axes.set_xlabel("frequency (Hz)")
    axes.set_ylabel("variance density (m$^2$ s)")
    axes.set_title("Surface gauges: spectra over their analysis windows", fontsize=10)
    if axes.get_legend_handles_labels()[0]:
        axes.legend(fontsize=7)
    figure.tight_layout()
    return _save(figure, path)


def gauge_record_figure(path, times, records: dict, entries: dict, *, ylabel: str, title: str,
                        lines: tuple = ()) -> Path:
    """One panel per gauge: its record (``records``: name -> values at ``times``), its analysis
    window shaded (``entries``: name -> its ``waves_report.json`` entry) and the levels of
    ``lines`` ((key, label) of the entry, e.g. R2%) drawn across."""
    plt = _pyplot()
    names = list(records) or ["-"]
    # a record too short to draw leaves a line of text, not a panel's height of blank paper
    height = 1.9 if times is not None and len(times) >= 2 else 0.5
    figure, axes = plt.subplots(len(names), 1, figsize=(7.5, height * len(names) + 0.8),
                                squeeze=False)
    for axis, name in zip(axes[:, 0], names):
        values = records.get(name)
        entry = entries.get(name) if isinstance(entries.get(name), dict) else {}
        if values is None or times is None:
            _say(axis, f"{name}: no record (the run folder has no gauges.csv)")
            continue
        if len(times) < 2:
            opens = entry.get("analysed_from_s")
            _say(axis, f"{name}: {len(times)} sample(s) in gauges.csv, up to t = "
                       f"{times[-1] if len(times) else 0.0:.3g} s: the run is too short to draw"
                       + (f" (the analysis window opens at t = {opens:.3g} s)"
                          if isinstance(opens, (int, float)) else ""))
            continue
        axis.plot(times, values, linewidth=0.8, color="tab:blue")
        start = entry.get("analysed_from_s")
        if isinstance(start, (int, float)) and start < times[-1]:
            axis.axvspan(start, times[-1], color="0.92", zorder=0, label="analysis window")
        elif isinstance(start, (int, float)):
            axis.text(0.5, 0.9, f"the analysis window opens at t = {start:.3g} s, after the "
                                f"record's end ({times[-1]:.3g} s): nothing analysed",
                      transform=axis.transAxes, ha="center", va="top", fontsize=8, color="0.3")
        for key, label in lines:
            level = entry.get(key)
            if isinstance(level, (int, float)) and np.isfinite(level):
                axis.axhline(level, color="crimson", linewidth=0.8, linestyle=":",
                             label=f"{label} {level:.3g}")
        axis.set_title(name, fontsize=8, loc="left")
        axis.set_ylabel(ylabel, fontsize=8)
        if axis.get_legend_handles_labels()[0]:
            axis.legend(fontsize=7, loc="upper left")
    axes[-1, 0].set_xlabel("time (s)")
    figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    return _save(figure, path)


def profiles_figure(path, layer: dict) -> Path:
    """The section's armour surface before and after (``layer["damage_profiles"]``), the eroded
    area between them filled."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(7.5, 3.4))
    profiles = layer.get("damage_profiles")
    if not isinstance(profiles, dict):
        _say(axes, "not computed: "
                   f"{layer.get('displacement_reference', 'no reference state to compare with')}")
    else:
        x = np.asarray(profiles["x_m"], dtype=float)
        before = np.asarray(profiles["before_z_m"], dtype=float)
        after = np.asarray(profiles["after_z_m"], dtype=float)
        axes.plot(x, before, color="0.3", linewidth=1.2, label="before (frame 0)")
        axes.plot(x, after, color="tab:red", linewidth=1.2, linestyle="--",
                  label=f"after (t = {layer.get('time_s', float('nan')):g} s)")
        axes.fill_between(x, before, after, where=np.nan_to_num(after) < np.nan_to_num(before),
                          color="tab:red", alpha=0.3, label="eroded area A_e")
        axes.set_aspect("equal", adjustable="datalim")
        axes.legend(fontsize=7)
    axes.set_xlabel("x along the flume (m)")
    axes.set_ylabel("z (m)")
    s = layer.get("damage_level_s")
    axes.set_title("Armour surface, averaged across the flume"
                   + (f": A_e = {layer['eroded_area_m2']:.3g} m$^2$, S = {s:.2f}"
                      if isinstance(s, (int, float)) else ""), fontsize=10)
    figure.tight_layout()
    return _save(figure, path)


def unit_damage_figure(path, units: dict, layer: dict) -> Path:
    """Per unit: displacement over D_n (bars, with the moved and displaced thresholds), its
    rocking events, and the largest fluid force over its submerged weight where recorded."""
    plt = _pyplot()
    with_force = "max_fluid_force_over_submerged_weight" in units
    figure, axes = plt.subplots(2 + with_force, 1, figsize=(7.5, 2.2 * (2 + with_force) + 0.6),
                                sharex=True, squeeze=False)
    axes = axes[:, 0]
    ids = np.asarray(units["unit_id"])
    displacement = np.asarray(units.get("displacement_over_dn", np.full(len(ids), np.nan)),
                              dtype=float)
    if np.isfinite(displacement).any():
        axes[0].bar(ids, displacement, color="tab:orange")
        k = int(np.nanargmax(displacement))
        axes[0].text(0.01, 0.95, f"largest: unit {ids[k]}, {displacement[k]:.3g} D$_n$",
                     transform=axes[0].transAxes, ha="left", va="top", fontsize=8)
        for key, colour, label in (("moved_threshold_over_dn", "0.5", "moved"),
                                   ("damage_threshold_over_dn", "crimson", "displaced")):
            if isinstance(layer.get(key), (int, float)):
                axes[0].axhline(layer[key], color=colour, linewidth=0.8, linestyle="--",
                                label=f"{label}: > {layer[key]:g} D$_n$")
        axes[0].legend(fontsize=7)
    else:
        _say(axes[0], f"no displacements: {layer.get('displacement_reference', 'no reference')}")
    axes[0].set_ylabel("displacement (D$_n$)", fontsize=8)
    events = np.asarray(units.get("rocking_events", np.full(len(ids), np.nan)), dtype=float)
    if np.nansum(events) > 0:
        axes[1].bar(ids, events, color="tab:purple")
    elif np.isfinite(events).any():
        _say(axes[1], f"no unit rocked (0 of {len(ids)})")
    else:
        _say(axes[1], "rocking not counted (no frames before this one)")
    axes[1].set_ylabel(f"rocking events\n(> {layer.get('rocking_angle_deg', 2.0):g} deg and back)",
                       fontsize=8)
    if with_force:
        ratio = np.asarray(units["max_fluid_force_over_submerged_weight"], dtype=float)
        if np.isfinite(ratio).any():
            delta = (layer.get("flume_test") or {}).get("relative_density")
            if isinstance(delta, (int, float)) and delta > 0:
                # the force includes buoyancy, which a unit at rest under water carries too
                # (1/Delta of its submerged weight): drawn apart from what the waves add
                buoyancy = 1.0 / delta
                still = np.minimum(ratio, buoyancy)
                axes[2].bar(ids, still, color="0.8",
                            label=f"buoyancy (still water): 1/Delta = {buoyancy:.2f}")
                axes[2].bar(ids, np.maximum(ratio - buoyancy, 0.0), bottom=still,
                            color="tab:blue", label="beyond buoyancy: the waves' load")
                axes[2].axhline(1.0 + buoyancy, color="crimson", linewidth=0.8,
                                linestyle="--", label=f"lifts its weight: {1.0 + buoyancy:.2f}")
                axes[2].legend(fontsize=7)
            else:
                axes[2].bar(ids, ratio, color="tab:blue")
        else:
            _say(axes[2], "no fluid forces recorded")
        axes[2].set_ylabel("largest fluid force\n(buoyancy included) /\nsubmerged weight",
                           fontsize=8)
    axes[-1].set_xlabel("unit")
    figure.suptitle("Each unit: displacement, rocking" + (", fluid load" if with_force else ""),
                    fontsize=10)
    figure.tight_layout()
    return _save(figure, path)


def contacts_figure(path, contacts: dict | None) -> Path:
    """The units' contacts frame by frame (``FlumeRecords.contacts``): coordination numbers (mean,
    smallest and largest over the units), the largest contact force on a unit, and the factors of
    safety against sliding (smallest and median; drawn up to the report's display cap)."""
    cap = FACTOR_OF_SAFETY_DISPLAY_CAP
    plt = _pyplot()
    figure, axes = plt.subplots(3, 1, figsize=(7.5, 6.6), sharex=True)
    if contacts is None or not len(contacts["time_s"]):
        for axis in axes:
            axis.set_axis_off()
        _say(axes[1], "not computed: the run's frames carry no contacts (a coupled run written "
                      "before issue 35)")
        return _save(figure, path)
    time = contacts["time_s"]
    coordination = contacts["coordination_number"]
    axes[0].fill_between(time, coordination.min(axis=1), coordination.max(axis=1), color="0.85",
                         label="smallest to largest")
    axes[0].plot(time, coordination.mean(axis=1), marker=".", color="tab:purple", label="mean")
    axes[0].set_ylabel("coordination\nnumber", fontsize=8)
    axes[0].legend(fontsize=7)
    axes[1].plot(time, contacts["max_contact_force"].max(axis=1) / 1e3, marker=".",
                 color="tab:blue")
    axes[1].set_ylabel("largest contact\nforce on a unit (kN)", fontsize=8)
    safety = np.minimum(contacts["factor_of_safety_sliding"], cap)
    axes[2].plot(time, safety.min(axis=1), marker=".", color="tab:red", label="smallest")
    axes[2].plot(time, np.median(safety, axis=1), marker=".", color="tab:green", label="median")
    axes[2].set_ylim(0.0, cap * 1.05)
    axes[2].set_ylabel(f"sliding factor of\nsafety (<= {cap:g} drawn)", fontsize=8)
    axes[2].legend(fontsize=7)
    axes[2].set_xlabel("time (s)")
    figure.suptitle(f"The {coordination.shape[1]} units' contacts, frame by frame", fontsize=10)
    figure.tight_layout()
    return _save(figure, path)
