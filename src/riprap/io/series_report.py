"""The files of a test series (``riprap.workflows.series``): the damage curve pictures and the
series' ``report.html`` (every step's survey pictures and tables, the
damage curves beside the formulas, the data files linked)."""
from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

__all__ = ["write_series_report"]


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _damage_curve_figure(path: Path, results: dict) -> Path:
    plt = _pyplot()
    curve = results["curve"]
    ns = np.asarray(curve["stability_number"], dtype=float)
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(ns, curve["N_od"], "o-", color="C0", label="N_od, riprap")
    formula = np.asarray(curve["van_der_meer_cubes_N_od"], dtype=float)
    if np.isfinite(formula).any():
        left.plot(ns, formula, "s--", color="C1",
                  label="N_od, Van der Meer (1988) cubes, waves run")
    start = results["formulas"]["start_of_damage"]
    for key, style, label in (("hudson_stability_number", ":", "Hudson no damage"),
                              ("single_layer_cubes_start", "-.", "single-layer cubes: start"),
                              ("single_layer_cubes_failure", "--", "single-layer cubes: failure")):
        if start.get(key):
            left.axvline(start[key], color="0.4", linestyle=style, label=label)
    left.set_xlabel("stability number Hm0 / (Delta Dn)")
    left.set_ylabel("N_od (displaced units per Dn of width)")
    left.legend(fontsize=7)
    left.grid(alpha=0.3)
    twin = left.twinx()
    twin.plot(ns, curve["S"], "^-", color="C2", alpha=0.7, label="S")
    twin.set_ylabel("damage level S", color="C2")
    for step, table in results.get("per_wave", {}).items():
        waves = np.asarray(table.get("cumulative_wave", []), dtype=float)
        if waves.size:
            right.step(waves, table["N_od"], where="post", label=f"step {step}")
    right.set_xlabel("waves since the series started")
    right.set_ylabel("N_od")
    right.set_title("damage development N_od(N)", fontsize=9)
    right.grid(alpha=0.3)
    if results.get("per_wave"):
        right.legend(fontsize=7)
    _smoke_title(figure, results)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _smoke_title(figure, results: dict) -> None:
    """A smoke run's figures say so above their axes."""
    if results.get("run_mode") == "smoke":
        figure.suptitle("SMOKE RUN (RIPRAP_SMOKE=1): not results", color="C3", fontsize=11)


def _smoke_banner(results: dict) -> str:
    """A smoke run's report says so first."""
    if results.get("run_mode") != "smoke":
        return ""
    return ("<p class='smoke'><b>SMOKE RUN</b> (RIPRAP_SMOKE=1): "
            + html.escape(results.get("run_mode_note", "every step was cut short"))
            + ". Nothing on this page is a result: run the series again without RIPRAP_SMOKE "
            "(into the same folder: the smoke steps are set aside and run in full).</p>")


def _overtopping_figure(path: Path, results: dict) -> Path:
    plt = _pyplot()
    curve = results["curve"]
    figure, axes = plt.subplots(figsize=(5.5, 4))
    axes.semilogy(curve["Hm0_m"], np.maximum(np.asarray(curve["q_m3_s_m"], float), 1e-12), "o-",
                  label="riprap")
    reduced = results["formulas"].get("crest_width_m") is not None
    axes.semilogy(curve["Hm0_m"], curve["eurotop_q_m3_s_m"], "s--",
                  label="EurOtop (2018) eq. 5.18, mean" + (" x C_r (eq. 6.8)" if reduced else ""))
    axes.set_xlabel("Hm0 at the toe (m)")
    axes.set_ylabel("q (m^3/s per m)")
    axes.legend(fontsize=8)
    axes.grid(alpha=0.3, which="both")
    _smoke_title(figure, results)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _cell(value) -> str:
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, float) or isinstance(value, np.floating):
        return "not computed" if not math.isfinite(value) else f"{value:.4g}"
    return html.escape(str(value))


def _table(columns: dict, names: list[str]) -> str:
    head = "".join(f"<th>{html.escape(name)}</th>" for name in names)
    count = len(columns[names[0]]) if names else 0
    rows = "".join("<tr>" + "".join(f"<td>{_cell(columns[name][k])}</td>" for name in names)
                   + "</tr>" for k in range(count))
    return f"<table><tr>{head}</tr>{rows}</table>"


def _crest_width_note(results: dict) -> str:
    """What the EurOtop comparison did about the crest's width, with C_r per step."""
    formulas = results["formulas"]
    width = formulas.get("crest_width_m")
    if width is None:
        return ("<p>EurOtop's q: no crest-width factor applied (C_r = 1): "
                + html.escape(str(formulas.get("crest_width_source", "no crest width known")))
                + "; give the overtopping gauge's crest_width.</p>")
    curve = results["curve"]
    factors = ", ".join(f"step {step}: {_cell(factor)}" for step, factor in
                        zip(curve["step"], curve.get("eurotop_crest_width_factor", [])))
    return (f"<p>EurOtop's q includes the crest-width factor C_r = min(1, 3.06 exp(-1.5 G_c / "
            f"Hm0)) (EurOtop 2018, eq. 6.8) for G_c = {width:.4g} m "
            f"({html.escape(str(formulas.get('crest_width_source', '')))}): {factors}.</p>")


_STYLE = ("body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:"
          "collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 7px;font-size:13px}"
          "img{max-width:100%}.smoke{background:#fde2e1;border:2px solid #c0392b;padding:8px}")


def write_series_report(out, results: dict) -> dict:
    """``damage_curve.png``, ``overtopping.png`` and ``report.html`` in ``out``; returns their
    paths by name."""
    out = Path(out)
    outputs = {"damage_curve_figure": str(_damage_curve_figure(out / "damage_curve.png", results)),
               "overtopping_figure": str(_overtopping_figure(out / "overtopping.png", results))}
    curve = results["curve"]
    first = results.get("first_displacement")
    start = results["formulas"]["start_of_damage"]
    parts = [_smoke_banner(results),
             f"<p>Case {html.escape(results['case_file'])}. A unit is displaced once it moved more "
             f"than {results['displacement_threshold_over_dn']:g} Dn from where the series "
             "started; every figure below is counted from that start.</p>",
             "<h2>Damage curve</h2>",
             _table(curve, list(curve)),
             "<p>" + (f"First displacement at step {first['step']}, N_s = "
                      f"{first['stability_number']:.3g}" + (f" (none at N_s = {first['below']:.3g})"
                                                            if first.get("below") else "")
                      if first else "No unit was displaced in the series.")
             + "; the formulas' start of damage: "
             + ", ".join(f"{html.escape(k)} = {v:g}" for k, v in start.items() if v) + ".</p>",
             _crest_width_note(results),
             "<img src='damage_curve.png'><img src='overtopping.png'>",
             f"<p>Sources: {html.escape(results['formulas']['sources'])}.</p>",
             "<h2>Before the series</h2><p><a href='start/report.html'>the layer as built</a> "
             "(frame 0 of step 1)</p>"]
    for picture in sorted((out / "start").glob("slope_*.png"))[:2]:
        parts.append(f"<img src='start/{picture.name}' style='max-width:49%'>")
    parts.append("<h2>Steps</h2>")
    for step in results["steps"]:
        folder = Path(step["folder"])
        relative = folder.name
        parts.append(f"<h3>Step {step['step']}: target Hm0 {step['target_Hm0_m']:g} m, Tp "
                     f"{step['Tp_s']:.3g} s</h3><p><a href='{relative}/survey/report.html'>survey "
                     f"report</a> · <a href='{relative}/survey/per_wave.csv'>per-wave table</a> · "
                     f"<a href='{relative}/survey/units.csv'>units</a></p>")
        for picture in sorted((folder / "survey").glob("*.png")):
            if picture.name.startswith(("stability_profiles", "stability_units",
                                        "slope_displacement_over_dn")):
                parts.append(f"<img src='{relative}/survey/{picture.name}' style='max-width:49%'>")
    parts.append("<p>Data: <a href='damage_curve.csv'>damage_curve.csv</a>, "
                 "<a href='series_results.json'>series_results.json</a>.</p>")
    title = "riprap test series" + (" (SMOKE RUN)" if results.get("run_mode") == "smoke" else "")
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>"
            f"<style>{_STYLE}</style></head><body><h1>{title}</h1>{''.join(parts)}"
            "</body></html>\n")
    (out / "report.html").write_text(page, encoding="utf-8")
    outputs["report"] = str(out / "report.html")
    return outputs
