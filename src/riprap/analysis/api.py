"""``riprap analyse`` as Python: read a pack or a run frame, analyse it, write the report.

    import riprap as rr
    result = rr.analyse("coreloc-small", out="coreloc-small/analysis")
    result.units["factor_of_safety"], result.layer["packing_density_coefficient"]
    rr.compare_layers(["seed1", "seed2"], out="comparison")
"""
from __future__ import annotations

from pathlib import Path

from riprap.analysis.layer_analysis import LayerAnalysis, analyse_layer
from riprap.errors import CaseFileError

__all__ = ["analyse", "compare_layers"]


def analyse(path, *, out=None, frame: int = -1) -> LayerAnalysis:
    """Analyse the pack folder (or ``pack.toml``) or run folder ``path``; with ``out``, write
    ``units.csv``, ``report.html``, ``stereonet.png`` and the rest there
    (:mod:`riprap.io.analysis_report`). ``frame``: which frame of a run (-1 the last)."""
    from riprap.io.analysis_input import load_layer_state, load_waves_report
    from riprap.io.output_folder import prepare_output_folder

    # A broken waves report is refused before any work (and before the output folder is made).
    waves = load_waves_report(path)
    if out is not None:
        prepare_output_folder(out)
    analysis = analyse_layer(load_layer_state(path, frame=frame))
    _add_flume_test(waves, analysis)
    if out is not None:
        from riprap.io.analysis_report import write_analysis

        analysis.layer["outputs"] = write_analysis(out, analysis)
    return analysis


def _add_flume_test(waves: dict | None, analysis) -> None:
    """A run of a flume test (``waves``: its ``waves_report.json``, or None): the layer summary
    gets ``flume_test``, the damage beside the design formulas for the measured waves."""
    from riprap.analysis.stability_report import flume_stability

    if waves is None:
        return
    state = analysis.state
    layer = state.layer
    unit = int(layer.unit_bodies[0]) if len(layer.unit_bodies) else 0
    density = state.materials[int(state.material_of_body[unit])].density
    analysis.layer["flume_test"] = flume_stability(
        waves, analysis.layer, unit_kind=layer.unit_kind, nominal_diameter=layer.nominal_diameter,
        armour_density=density, water_density=float(waves.get("water_density_kg_m3", 1025.0)),
        slope_cot=layer.slope.cotangent)


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
    from riprap.io.analysis_input import load_layer_state
    from riprap.io.analysis_report import write_comparison
    from riprap.io.output_folder import prepare_output_folder

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
