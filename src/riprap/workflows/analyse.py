"""``riprap analyse`` as Python: read a pack or a run frame, analyse it, write the report.

    import riprap as rr
    result = rr.analyse("coreloc-small", out="coreloc-small/analysis")
    result.units["factor_of_safety"], result.layer["packing_density_coefficient"]
    rr.compare_layers(["seed1", "seed2"], out="comparison")
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from riprap.analysis.flume_test import FlumeRecords, fluid_force_columns, with_derived
from riprap.analysis.layer_analysis import DISPLACED_THRESHOLD_DN, LayerAnalysis, analyse_layer
from riprap.analysis.rock_stability import NOMINAL_OVER_SIEVE_DIAMETER, RockSection
from riprap.analysis.stability_report import flume_stability
from riprap.errors import CaseFileError
from riprap.io.analysis_input import is_run_folder, load_waves_report, run_was_smoke
from riprap.io.analysis_report import write_analysis, write_comparison
from riprap.io.body_forces import read_peak_fluid_forces
from riprap.io.frame_contacts import read_unit_contacts_per_frame
from riprap.io.output_folder import prepare_output_folder
from riprap.io.csv_tables import write_columns_csv
from riprap.workflows.layer_input import (load_layer_state, load_run_case,
                                          refuse_run_without_frames)
from riprap.workflows.per_wave_records import read_run_gauges, run_per_wave_table

__all__ = ["analyse", "compare_layers"]


def analyse(path, *, out=None, frame: int = -1, reference_run=None,
            displaced_threshold_dn: float | None = None) -> LayerAnalysis:
    """Analyse the pack folder (or ``pack.toml``) or run folder ``path``; with ``out``, write
    ``units.csv``, ``report.html``, ``stereonet.png`` and the rest there
    (:mod:`riprap.io.analysis_report`). ``frame``: which frame of a run (-1 the last);
    ``reference_run``: the run folder whose frame 0 the displacements count from (a test series'
    first step; default the run's own frame 0); ``displaced_threshold_dn``: a unit moved more than
    this many Dn is displaced (default 1)."""
    # A broken waves report or gauge file is refused before any work (and before the output
    # folder is made).
    refuse_run_without_frames(path)
    waves = load_waves_report(path)
    if is_run_folder(path):
        case = load_run_case(path)
        if case.fluid is not None:
            read_run_gauges(Path(path), case)
    if out is not None:
        prepare_output_folder(out)
    analysis = analyse_layer(load_layer_state(path, frame=frame, reference_run=reference_run),
                             displaced_threshold_dn=displaced_threshold_dn)
    analysis = _add_flume_test(path, waves, analysis)
    if run_was_smoke(path):
        analysis.layer["run_mode"] = "smoke"      # the report and layer_summary.json say so
    if out is not None:
        analysis.layer["outputs"] = write_analysis(out, analysis)
        # the whole run's waves: with its last frame only
        table = (_per_wave(path, analysis, reference_run, displaced_threshold_dn)
                 if frame == -1 else None)
        if table is not None:
            analysis.layer["outputs"]["per_wave"] = str(
                write_columns_csv(Path(out) / "per_wave.csv", table))
    return analysis


def _per_wave(path, analysis, reference_run, threshold_dn) -> dict | None:
    """A flume run's per-wave table (``riprap.workflows.per_wave_records``), or None."""
    if not is_run_folder(path):
        return None
    case = load_run_case(path)
    layer = analysis.state.layer
    try:
        return run_per_wave_table(
            Path(path), case, units=np.asarray(layer.unit_bodies, dtype=np.int64),
            nominal_diameter=float(layer.nominal_diameter), section_width=float(layer.slope.width),
            threshold_dn=threshold_dn or DISPLACED_THRESHOLD_DN, reference_run=reference_run,
            periodic=layer.slope.periodic)
    except CaseFileError as error:
        # the gauges cannot give waves at the toe (too short a record, gauges too close for the
        # split): the analysis stands without the table, and says why
        analysis.layer["per_wave_not_computed"] = str(error)
        return None


def _add_flume_test(path, waves: dict | None, analysis) -> LayerAnalysis:
    """A run in water: the units get their largest fluid force (``body_forces.csv``); a flume
    test's (``waves_report.json`` beside its frames) layer summary gets ``flume_test``, the damage
    beside the design formulas for the measured waves, and the analysis its wave records for the
    report (``riprap.analysis.flume_test``)."""
    if not is_run_folder(path):
        return analysis
    case = load_run_case(path)
    if case.fluid is None:
        return analysis
    state = analysis.state
    layer = state.layer
    water_density = float(case.fluid.water_density)
    bodies = np.asarray(layer.unit_bodies, dtype=np.int64)
    densities = np.array([state.materials[int(m)].density for m in state.material_of_body])
    peaks = read_peak_fluid_forces(Path(path) / "body_forces.csv", state.n_bodies,
                                   until=state.time)
    if peaks is not None:
        analysis.units.update(fluid_force_columns(
            peaks, bodies, volumes=(state.masses() / densities)[bodies],
            armour_densities=densities[bodies], water_density=water_density,
            gravity=float(np.linalg.norm(state.gravity))))
    if waves is None:
        return analysis
    unit = int(bodies[0]) if len(bodies) else 0
    # the density the run's waves report was written with, where it says (the case's otherwise)
    recorded = waves.get("water_density_kg_m3")
    if (isinstance(recorded, (int, float)) and not isinstance(recorded, bool)
            and np.isfinite(recorded) and recorded > 0):
        water_density = float(recorded)
    analysis.layer["flume_test"] = flume_stability(
        waves, analysis.layer, unit_kind=layer.unit_kind, nominal_diameter=layer.nominal_diameter,
        armour_density=float(densities[unit]), water_density=water_density,
        slope_cot=layer.slope.cotangent,
        rock_section=_rock_section(case, layer) if layer.is_rock else None,
        still_water_level=_still_water_level(case))
    # where the crest begins, for the crest width of a series' EurOtop comparison
    analysis.layer["flume_test"]["slope_crest_x_m"] = float(layer.slope.crest_x)
    gauges = read_run_gauges(Path(path), case)
    times, columns = gauges if gauges is not None else (None, {})
    contacts = read_unit_contacts_per_frame(path, bodies, until=state.time)
    records = FlumeRecords(waves_report=waves, times=times, columns=columns, target=_target(case),
                           contacts=contacts)
    return replace(analysis, flume=with_derived(records, analysis.units))


def _still_water_level(case) -> float | None:
    spec = case.waves
    level = getattr(spec, "still_water_level", None) if spec is not None else None
    return float(level) if level is not None else None


def _rock_section(case, layer) -> RockSection:
    """The cross-section the rock formulas need: the filter from the layer's design, the core
    from the case's ``[[porous_zones]]`` of ``part = "core"`` (its D50 as D_n50 = 0.84 D50;
    none: an impermeable core, said so), the depth at the toe from the still water level."""
    cores = [zone for zone in case.porous_zones if zone.part == "core"]
    if cores:
        d50 = max(float(zone.stone_diameter) for zone in cores)
        core, note = (NOMINAL_OVER_SIEVE_DIAMETER * d50,
                      f"the case's porous core ([[porous_zones]] part = \"core\"): D50 {d50:g} m, "
                      f"D_n50 = {NOMINAL_OVER_SIEVE_DIAMETER} D50 (The Rock Manual 3.4.1)")
    else:
        others = len(case.porous_zones)
        core, note = 0.0, ("no [[porous_zones]] has part = \"core\": the core is taken as "
                           "impermeable (D_n50,core 0, P 0.1)"
                           + (f"; the case has {others} other porous zone(s)" if others else ""))
    level = _still_water_level(case)
    design = layer.design
    return RockSection(
        filter_dn50=design.get("filter_dn50_m"), core_dn50=core, core_note=note,
        grading_ratio=design.get("placed_dn85_over_dn15"),
        water_depth=(level - float(layer.slope.toe[2])) if level is not None else None)


def _target(case) -> dict | None:
    """The case's sea for the report: irregular (Hm0, Tp, gamma) or regular (H, T)."""
    spec = case.waves
    if spec is None:
        return None
    parameters = spec.parameters
    if "significant_height" in parameters:
        return {"type": "irregular", "height_m": float(parameters["significant_height"]),
                "period_s": float(parameters["peak_period"]),
                "peak_enhancement": float(parameters.get("peak_enhancement", 3.3))}
    if "height" in parameters and "period" in parameters:
        return {"type": "regular", "height_m": float(parameters["height"]),
                "period_s": float(parameters["period"])}
    return None


def _labels(paths, labels):
    if labels is None:
        labels = [Path(p).resolve().name if Path(p).is_dir() else Path(p).resolve().parent.name
                  for p in paths]
    labels = [str(label) for label in labels]
    if len(set(labels)) != len(labels):
        labels = [f"{k + 1}_{label}" for k, label in enumerate(labels)]
    return labels


def compare_layers(paths, *, out, labels=None, frame: int = -1) -> list[LayerAnalysis]:
    """Analyse several packs or runs and put their figures side by side in ``out``
    (``comparison.html``, and each one's files in ``out/<label>/``)."""
    paths = list(paths)
    if len(paths) < 2:
        raise CaseFileError(f"compare_layers: give two or more packs or runs, got {len(paths)}")
    labels = _labels(paths, labels)
    if len(labels) != len(paths):
        raise CaseFileError(f"compare_layers: {len(labels)} labels for {len(paths)} packs")
    prepare_output_folder(out)
    analyses = [analyse_layer(load_layer_state(p, frame=frame)) for p in paths]
    outputs = write_comparison(out, analyses, labels)
    for analysis, label in zip(analyses, labels):
        analysis.layer["outputs"] = outputs[label]
    return analyses
