"""The files of a test series (``riprap.workflows.series``): the damage curve pictures and the
series' ``report.html`` (every step's survey pictures and tables, the
damage curves beside the formulas, the data files linked)."""
from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

from riprap.io.flume_figures import _say as _panel_note

__all__ = ["write_series_report", "figures_not_computed", "COLUMN_NAMES"]


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


#: What each damage-curve column is called in the report, with its unit (``damage_curve.csv`` and
#: ``series_results.json`` keep the keys; the report gives each key as its column's tooltip).
COLUMN_NAMES = {
    "step": "step",
    "Hm0_m": "Hm0 at the toe (m)",
    "Tm_s": "Tm (s)",
    "waves": "waves",
    "cumulative_waves": "waves so far",
    "stability_number": "N_s = Hm0 / (Delta Dn)",
    "units_displaced": "units displaced",
    "N_od": "N_od (displaced per Dn of width)",
    "S": "damage level S",
    "rocking_events": "rocking events",
    "q_m3_s_m": "q (m^3/s per m)",
    "hudson_stability_number": "Hudson N_s, no damage",
    "van_der_meer_cubes_N_od": "Van der Meer (1988) N_od, cubes",
    "eurotop_crest_width_factor": "EurOtop C_r (crest width)",
    "eurotop_q_m3_s_m": "EurOtop q (m^3/s per m)",
    "asked_Hm0_m": "Hm0 asked (m)",
    "asked_Tp_s": "Tp asked (s)",
    "Tp_s": "Tp at the toe (s)",
    "reflection_coefficient": "K_r (reflection)",
    "wave_maker_gain": "wave maker gain on Hm0",
    "Tm_1_0_s": "T_m-1,0 at the toe (s)",
    "rock_damage_class": "Rock Manual class of S",
    "van_der_meer_2021_S": "Van der Meer (2021) S, waves so far",
    "van_gent_2003_S": "Van Gent et al. (2003) S, waves so far",
    "etemad_shahidi_2020_S": "Etemad-Shahidi et al. (2020) S, waves so far",
}
#: A mean overtopping discharge below this (m^3/s per m, 1e-6 l/s per m: a few drops over a
#: test) is drawn as none: a log axis down to round-off would hide the rest.
DRY_Q = 1e-9
#: Columns measured in the flume (a NaN there: "not measured"); the others are computed.
MEASURED_COLUMNS = ("Hm0_m", "Tm_s", "stability_number", "q_m3_s_m", "Tp_s",
                    "reflection_coefficient", "Tm_1_0_s")
#: A rock series' formula columns and how each is drawn.
_ROCK_STYLES = (("van_der_meer_2021_S", "s--", "C1"), ("van_gent_2003_S", "D--", "C3"),
                ("etemad_shahidi_2020_S", "v--", "C4"))
#: The formulas' start of damage (``formulas.start_of_damage``) in words.
START_NAMES = {"hudson_stability_number": "Hudson's N_s (no damage)",
               "single_layer_cubes_start": "single-layer cubes' start of damage, N_s",
               "single_layer_cubes_failure": "single-layer cubes' failure, N_s",
               "van_der_meer_cubes_start_N_od": "Van der Meer's start of damage for cubes, N_od"}


def _finite(values) -> np.ndarray:
    return np.isfinite(np.asarray(values, dtype=float))


def _no_wave_height(results: dict) -> str:
    """Why no step has an incident wave height at the toe, from the steps' surveys."""
    reasons = [step.get("wave_height_not_measured") for step in results.get("steps", [])]
    reasons = [reason for reason in reasons if reason]
    return ("no step measured an incident wave height at the toe"
            + (f": {reasons[0]}" if reasons else ""))


def figures_not_computed(results: dict) -> dict[str, str]:
    """The series report's plots that have nothing to show, each with why (``{plot: why}``):
    they are written as that sentence, not as empty axes."""
    curve = results["curve"]
    missing = {}
    if not _finite(curve["stability_number"]).any():
        missing["damage curve"] = _no_wave_height(results)
    if not any(np.asarray(table.get("cumulative_wave", [])).size
               for table in results.get("per_wave", {}).values()):
        missing["damage development N_od(N)"] = (
            "no step's per-wave table holds a wave (it counts the incident waves at the toe: "
            "each step must run until its waves have reached the structure)")
    q = np.asarray(curve["q_m3_s_m"], dtype=float)
    if not _finite(curve["Hm0_m"]).any():
        missing["overtopping"] = _no_wave_height(results)
    elif not (_finite(q).any() or _finite(curve["eurotop_q_m3_s_m"]).any()):
        missing["overtopping"] = ("neither a measured q (an overtopping gauge and waves at the "
                                  "toe) nor EurOtop's (the crest's freeboard) in any step")
    return missing


def _damage_curve_figure(path: Path, results: dict, missing: dict) -> Path:
    plt = _pyplot()
    curve = results["curve"]
    ns = np.asarray(curve["stability_number"], dtype=float)
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    if "damage curve" in missing:
        _panel_note(left, "damage curve N_od(N_s): not computed:\n" + missing["damage curve"])
    else:
        _damage_curve_panel(left, ns, curve, results)
    if "damage development N_od(N)" in missing:
        _panel_note(right, "damage development N_od(N): not computed:\n"
                    + missing["damage development N_od(N)"])
    else:
        for step, table in results.get("per_wave", {}).items():
            waves = np.asarray(table.get("cumulative_wave", []), dtype=float)
            if waves.size:
                right.step(waves, table["N_od"], where="post", label=f"step {step}")
        right.set_xlabel("waves since the series started")
        right.set_ylabel("N_od")
        right.set_ylim(bottom=0.0)      # a count: no damage sits on the axis, not mid-plot
        right.set_title("damage development N_od(N)", fontsize=9)
        right.grid(alpha=0.3)
        right.legend(fontsize=7)
    _smoke_title(figure, results)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _rock_damage_panel(left, ns: np.ndarray, curve: dict, results: dict) -> None:
    """Rock armour: S against N_s beside the three rock formulas (cumulative over the steps) and
    the Rock Manual's start of damage and failure for the slope."""
    left.plot(ns, curve["S"], "o-", color="C0", label="S, riprap")
    for column, style, colour in _ROCK_STYLES:
        values = np.asarray(curve.get(column, []), dtype=float)
        if values.size and np.isfinite(values).any():
            left.plot(ns, values, style, color=colour, alpha=0.8,
                      label=COLUMN_NAMES[column].replace(", waves so far", ""))
    thresholds = results["formulas"].get("rock", {}).get("damage_thresholds") or {}
    for key, style, words in (("start", ":", "start of damage"), ("failure", "--", "failure")):
        if isinstance(thresholds.get(key), (int, float)):
            left.axhline(thresholds[key], color="0.4", linestyle=style,
                         label=f"{words} S {thresholds[key]:g} (Rock Manual)")
    left.set_xlabel("stability number Hm0 / (Delta Dn50)")
    left.set_ylabel("damage level S = A_e / Dn50^2")
    left.set_ylim(bottom=0.0)
    left.legend(fontsize=7)
    left.grid(alpha=0.3)


def _damage_curve_panel(left, ns: np.ndarray, curve: dict, results: dict) -> None:
    """N_od and S against N_s for the steps that measured their waves, beside the formulas."""
    if "van_gent_2003_S" in curve:
        _rock_damage_panel(left, ns, curve, results)
        return
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
    left.set_ylim(bottom=0.0)
    left.legend(fontsize=7)
    left.grid(alpha=0.3)
    twin = left.twinx()
    twin.plot(ns, curve["S"], "^-", color="C2", alpha=0.7, label="S")
    twin.set_ylabel("damage level S", color="C2")
    twin.set_ylim(bottom=0.0)


def _smoke_title(figure, results: dict) -> None:
    """A smoke run's figures say so above their axes."""
    if results.get("run_mode") == "smoke":
        figure.suptitle("SMOKE RUN (RIPRAP_SMOKE=1): not results", color="C3", fontsize=11)


def _smoke_banner(results: dict) -> str:
    """A smoke run's report says so first."""
    if results.get("run_mode") != "smoke":
        return ""
    return ("<p class='smoke'><b>SMOKE RUN</b>: "
            + html.escape(results.get("run_mode_note", "every step was cut short (RIPRAP_SMOKE=1)"))
            + ". Nothing on this page is a result: run the series again without RIPRAP_SMOKE "
            "(into the same folder: the smoke steps are set aside and run in full).</p>")


def _overtopping_figure(path: Path, results: dict, missing: dict) -> Path:
    plt = _pyplot()
    curve = results["curve"]
    figure, axes = plt.subplots(figsize=(5.5, 4))
    if "overtopping" in missing:
        _panel_note(axes, "overtopping q(Hm0): not computed:\n" + missing["overtopping"])
    else:
        hm0 = np.asarray(curve["Hm0_m"], dtype=float)
        q = np.asarray(curve["q_m3_s_m"], dtype=float)
        eurotop = np.asarray(curve["eurotop_q_m3_s_m"], dtype=float)
        wet = np.isfinite(q) & (q > DRY_Q)
        if wet.any():
            axes.semilogy(hm0[wet], q[wet], "o-", color="C0", label="riprap")
        reduced = results["formulas"].get("crest_width_m") is not None
        if np.isfinite(eurotop).any():
            axes.semilogy(hm0, eurotop, "s--", color="C1", label="EurOtop (2018) eq. 5.18, mean"
                          + (" x C_r (eq. 6.8)" if reduced else ""))
        dry = np.isfinite(q) & (q <= DRY_Q) & np.isfinite(hm0)
        if dry.any():
            axes.set_yscale("log")
            floor = axes.get_ylim()[0]
            axes.plot(hm0[dry], np.full(dry.sum(), floor), "v", color="C0", clip_on=False,
                      label=f"riprap: q below {DRY_Q:g} m^3/s per m (none over the crest)")
        axes.set_xlabel("Hm0 at the toe (m)")
        axes.set_ylabel("q (m^3/s per m)")
        axes.legend(fontsize=8)
        axes.grid(alpha=0.3, which="both")
    _smoke_title(figure, results)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _cell(value, missing: str = "not computed") -> str:
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, float) or isinstance(value, np.floating):
        return (f"<span class='missing'>{missing}</span>" if not math.isfinite(value)
                else f"{value:.4g}")
    return html.escape(str(value))


def _curve_table(curve: dict) -> str:
    """The damage curve as a table: readable column names with units (the key as each header's
    tooltip), "not measured" where the flume gave nothing, "not computed" where a formula."""
    names = list(curve)
    head = "".join(f"<th title='{html.escape(name)}'>{html.escape(COLUMN_NAMES.get(name, name))}"
                   "</th>" for name in names)
    missing = {name: "not measured" if name in MEASURED_COLUMNS else "not computed"
               for name in names}
    rows = "".join("<tr>" + "".join(f"<td>{_cell(curve[name][k], missing[name])}</td>"
                                    for name in names) + "</tr>"
                   for k in range(len(curve[names[0]])))
    return f"<div class='wide'><table><tr>{head}</tr>{rows}</table></div>"


def _first_displacement(results: dict) -> str:
    """The first displacement beside the formulas' start of damage, in one paragraph."""
    first = results.get("first_displacement")
    if first:
        measured = (f"First displacement at step {first['step']}, N_s = "
                    f"{_cell(first['stability_number'], 'not measured')}"
                    + (f" (none at N_s = {first['below']:.3g})"
                       if isinstance(first.get("below"), float) and math.isfinite(first["below"])
                       else "") + ".")
    else:
        measured = "No unit was displaced in the series."
    start = [f"{html.escape(START_NAMES.get(key, key))} {value:.3g}"
             for key, value in results["formulas"]["start_of_damage"].items() if value]
    return (f"<p>{measured}"
            + (f" The formulas' start of damage: {'; '.join(start)}." if start else "") + "</p>")


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


_STYLE = ("body{font-family:sans-serif;max-width:1100px;margin:auto;padding:0 12px}"
          "p{overflow-wrap:anywhere}table{border-collapse:collapse;margin:8px 0}"
          "td,th{border:1px solid #bbb;padding:3px 6px;font-size:13px}"
          "th{font-weight:600;background:#f3f3f3;vertical-align:bottom}.wide{overflow-x:auto}"
          "img{max-width:100%}.missing{color:#777;font-style:italic}"
          ".smoke{background:#fde2e1;border:2px solid #c0392b;padding:8px}")


def _figure_html(name: str, plots: list[str], missing: dict, width: str = "") -> str:
    """A figure's image, unless every plot in it is not computed, and each that is, named."""
    notes = "".join(f"<p class='missing'>{html.escape(plot)}: not computed: "
                    f"{html.escape(missing[plot])}.</p>" for plot in plots if plot in missing)
    if all(plot in missing for plot in plots):
        return notes
    style = f" style='max-width:{width}'" if width else ""
    return f"<img src='{name}' alt='{html.escape(', '.join(plots))}'{style}>{notes}"


def _rock_note(results: dict) -> str:
    """A rock series: the structure the formulas were given (P and its reason, the core)."""
    rock = results.get("formulas", {}).get("rock")
    if not rock:
        return ""
    if "notional_permeability" not in rock:
        return f"<p class='missing'>Rock formulas: {html.escape(rock.get('note', ''))}</p>"
    core = rock.get("core_dn50_m") or 0.0
    return ("<p>Rock armour: the formulas' S are for the waves measured at the toe, the damage "
            "carried from step to step as equivalent waves. Notional permeability P = "
            f"{rock['notional_permeability']:g} ({html.escape(str(rock.get('notional_permeability_reason')))}); "
            + (f"core D<sub>n50</sub> {core:.3g} m" if core > 0 else "an impermeable core")
            + f" ({html.escape(str(rock.get('core')))}). {html.escape(rock.get('sources', ''))}.</p>")


def write_series_report(out, results: dict) -> dict:
    """``damage_curve.png``, ``overtopping.png`` and ``report.html`` in ``out``; returns their
    paths by name. A plot with nothing to show (``figures_not_computed``) is drawn as the
    sentence saying why, and the page names it as not computed instead of showing it."""
    out = Path(out)
    missing = figures_not_computed(results)
    outputs = {"damage_curve_figure": str(_damage_curve_figure(out / "damage_curve.png", results,
                                                               missing)),
               "overtopping_figure": str(_overtopping_figure(out / "overtopping.png", results,
                                                             missing))}
    curve = results["curve"]
    unmeasured = [f"Step {step['step']}: Hm0 not measured ({step['wave_height_not_measured']})."
                  for step in results["steps"] if step.get("wave_height_not_measured")]
    parts = [_smoke_banner(results),
             f"<p>Case <code>{html.escape(Path(results['case_file']).name)}</code> (its keys "
             "are in <a href='series.json'>series.json</a>). A unit is displaced once it moved "
             f"more than {results['displacement_threshold_over_dn']:g} Dn from where the series "
             "started; every figure below is counted from that start.</p>",
             "<h2>Damage curve</h2>",
             _curve_table(curve),
             ("<p class='missing'>" + html.escape(" ".join(unmeasured)) + "</p>"
              if unmeasured else ""),
             _first_displacement(results),
             _rock_note(results),
             _crest_width_note(results),
             _figure_html("damage_curve.png", ["damage curve", "damage development N_od(N)"],
                          missing),
             _figure_html("overtopping.png", ["overtopping"], missing, "49%"),
             f"<p>Sources: {html.escape(results['formulas']['sources'])}.</p>",
             "<h2>Before the series</h2><p><a href='start/report.html'>the layer as built</a> "
             "(frame 0 of step 1)</p>"]
    for picture in sorted((out / "start").glob("slope_*.png"))[:2]:
        parts.append(f"<img src='start/{picture.name}' style='max-width:49%'>")
    parts.append("<h2>Steps</h2>")
    for step in results["steps"]:
        folder = Path(step["folder"])
        relative = folder.name
        maker = step.get("wave_maker")
        calibrated = ("" if not maker else
                      f" (the wave maker at Hm0 x {maker['gain']:.3f}: the calibration run "
                      f"without the structure saw {maker['measured_Hm0_m']:.4g} m, "
                      f"{maker['measured_Tp_s']:.3g} s at the toe)")
        parts.append(f"<h3>Step {step['step']}: target Hm0 {step['target_Hm0_m']:g} m, Tp "
                     f"{step['Tp_s']:.3g} s{html.escape(calibrated)}</h3>"
                     f"<p><a href='{relative}/survey/report.html'>survey "
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
