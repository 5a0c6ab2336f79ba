"""The flume test's sections of ``report.html``: the waves (spectra against the target, heights and
periods per gauge, incident and reflected waves per gauge pair and triple, run-up, overtopping)
and the stability (the stability number beside Hudson's and Van der Meer's, displaced units and
N_od, S with its profiles, rocking units, the largest fluid force per unit), each with its
pictures (:mod:`riprap.io.flume_figures`).

``waves_report.json`` is read tolerantly: a value that is missing, null, not a number or not
finite is shown as "not computed: <reason>", the reason taken from the entry's own fields
(``<key>_reason``, ``reason``, ``note``, or a ``not_computed`` table) where the run gave one.
"""
from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

from riprap.io import flume_figures as figures

__all__ = ["write_flume_figures", "waves_section", "stability_section", "value_or_reason"]

#: Columns of the surface gauges' table: (key in the gauge's entry, heading, format).
_GAUGE_COLUMNS = (("x_m", "x (m)", "{:.2f}"), ("analysed_from_s", "analysed from (s)", "{:.1f}"),
                  ("waves", "waves", "{:.0f}"), ("Hm0_m", "Hm0 (m)", "{:.3f}"),
                  ("H1/3_m", "H1/3 (m)", "{:.3f}"), ("H2%_m", "H2% (m)", "{:.3f}"),
                  ("Hmax_m", "Hmax (m)", "{:.3f}"), ("Tp_s", "Tp (s)", "{:.2f}"),
                  ("Tm-1,0_s", "Tm-1,0 (s)", "{:.2f}"), ("Tz_s", "Tz (s)", "{:.2f}"))


def _number(value):
    """``value`` as a finite float, or None."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _reason(entry, key: str, default: str) -> str:
    if isinstance(entry, dict):
        table = entry.get("not_computed")
        for candidate in (entry.get(f"{key}_reason"),
                          table.get(key) if isinstance(table, dict) else None,
                          entry.get("reason"), entry.get("note")):
            if isinstance(candidate, str) and candidate:
                return candidate
    return default


def value_or_reason(entry, key: str, fmt: str = "{:.3g}",
                    default: str = "not in waves_report.json") -> str:
    """The entry's ``key`` formatted, or "not computed: <reason>" (HTML-escaped)."""
    value = _number(entry.get(key)) if isinstance(entry, dict) else None
    if value is None:
        reason = html.escape(_reason(entry, key, default))
        return f"<span class='missing'>not computed: {reason}</span>"
    return html.escape(fmt.format(value))


def _table(head, rows) -> str:
    heads = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><tr>{heads}</tr>{body}</table>"


def _entries(report: dict, key: str) -> dict:
    value = report.get(key)
    return value if isinstance(value, dict) else {}


def _entry_list(report: dict, key: str) -> list:
    value = report.get(key)
    return [e for e in value if isinstance(e, dict)] if isinstance(value, list) else []


def write_flume_figures(out: Path, analysis) -> dict:
    """The flume test's pictures in ``out``; ``{what: path}`` (none for a run without waves)."""
    records = getattr(analysis, "flume", None)
    if records is None:
        return {}
    report = records.waves_report or {}
    written = {"waves_spectra": figures.spectra_figure(out / "waves_spectra.png", records.spectra,
                                                       records.target, records.target_density),
               "waves_run_up": figures.gauge_record_figure(
                   out / "waves_run_up.png", records.times, records.run_up_series(),
                   _entries(report, "run_up"), ylabel="level above SWL (m)",
                   title="Run-up gauges: the highest water level on the face",
                   lines=(("R2%_m", "R2%"), ("R_max_m", "R max"))),
               "waves_overtopping": figures.gauge_record_figure(
                   out / "waves_overtopping.png", records.times,
                   records.overtopping_series(), _entries(report, "overtopping"),
                   ylabel="volume (m$^3$/m)",
                   title="Overtopping gauges: the water over the crest, per metre of width"),
               "stability_profiles": figures.profiles_figure(out / "stability_profiles.png",
                                                             analysis.layer),
               "stability_units": figures.unit_damage_figure(out / "stability_units.png",
                                                             analysis.units, analysis.layer),
               "stability_contacts": figures.contacts_figure(out / "stability_contacts.png",
                                                             records.contacts)}
    return {key: str(path) for key, path in written.items()}


def _spectra_note(analysis) -> str:
    records = getattr(analysis, "flume", None)
    if records.times is None:
        return ("<p class='missing'>not computed: the run folder has no <code>gauges.csv</code> "
                "to read the spectra from.</p>")
    missing = [s for s in records.spectra if "reason" in s]
    return "".join(f"<p class='missing'>{html.escape(s['name'])}: spectrum not computed: "
                   f"{html.escape(s['reason'])}</p>" for s in missing)


def waves_section(analysis) -> str:
    """The waves section of the report (empty for a run without waves)."""
    records = getattr(analysis, "flume", None)
    if records is None:
        return ""
    report = records.waves_report or {}
    target = records.target or {}
    if target:
        kind = "JONSWAP sea" if target.get("type") == "irregular" else "regular wave"
        heights = "Hm0" if target.get("type") == "irregular" else "H"
        periods = "Tp" if target.get("type") == "irregular" else "T"
        aim = (f"Target: {kind}, {heights} = {target['height_m']:g} m, {periods} = "
               f"{target['period_s']:g} s"
               + (f", gamma = {target['peak_enhancement']:g}" if "peak_enhancement" in target
                  else "") + ".")
    else:
        aim = "The case names no target wave."
    surface = _entries(report, "gauges")
    gauge_rows = [_gauge_row(name, entry) for name, entry in surface.items()]
    parts = ["<h2 id='waves'>Waves</h2>",
             f"<p>{html.escape(aim)} Records: <code>gauges.csv</code>, analysis: "
             "<code>waves_report.json</code> in the run folder. Each record is analysed from the "
             "time the wave train has arrived (the ramp, the travel from the wave maker at the "
             "group velocity, two periods).</p>",
             "<h3>Surface gauges</h3>",
             _table(["gauge"] + [h for _, h, _ in _GAUGE_COLUMNS], gauge_rows) if gauge_rows
             else "<p class='missing'>not computed: the run has no surface gauge.</p>",
             "<h3>Spectra, measured against the target</h3>",
             "<img src='waves_spectra.png' alt='spectra of the surface gauges against the target'>",
             _spectra_note(analysis),
             "<h3>Incident and reflected waves</h3>", _reflection_table(report),
             "<h3>Run-up</h3>", _gauge_table(report, "run_up", _RUN_UP_COLUMNS, 3, "run-up"),
             "<img src='waves_run_up.png' alt='run-up records'>",
             "<h3>Overtopping</h3>",
             _gauge_table(report, "overtopping", _OVERTOPPING_COLUMNS, 2, "overtopping"),
             "<img src='waves_overtopping.png' alt='overtopping records'>"]
    return "".join(parts)


def _gauge_row(name: str, entry, columns=_GAUGE_COLUMNS, placed: int = 2) -> list[str]:
    """A gauge's cells (``columns``: (key, heading, format), the first ``placed`` of them where
    it stands and what it analysed): where none of the others was computed, one cell that says why
    across their columns, not the same words in each."""
    where = [value_or_reason(entry, key, fmt) for key, _, fmt in columns[:placed]]
    statistics = [key for key, _, _ in columns[placed:]]
    if isinstance(entry, dict) and any(_number(entry.get(key)) is not None for key in statistics):
        return [html.escape(name)] + where + [value_or_reason(entry, key, fmt)
                                              for key, _, fmt in columns[placed:]]
    reason = html.escape(next((r for r in (_reason(entry, key, "") for key in statistics) if r),
                              "not in waves_report.json"))
    return ([html.escape(name)] + where[:-1]
            + [f"{where[-1]}</td><td colspan='{len(statistics)}' style='text-align:left'>"
               f"<span class='missing'>not computed: {reason}</span>"])


def _reflection_table(report: dict) -> str:
    rows = []
    for key, method in (("reflection", "Goda-Suzuki (pair)"),
                        ("reflection_three_gauge", "Mansard-Funke (triple)")):
        for entry in _entry_list(report, key):
            names = entry.get("gauges")
            names = ", ".join(map(str, names)) if isinstance(names, list) else "?"
            regular = "incident_height_m" in entry
            incident = "incident_height_m" if regular else "incident_Hm0_m"
            reflected = "reflected_height_m" if regular else "reflected_Hm0_m"
            rows.append([html.escape(method), html.escape(names),
                         value_or_reason(entry, incident, "{:.3f}"),
                         value_or_reason(entry, reflected, "{:.3f}"),
                         value_or_reason(entry, "reflection_coefficient", "{:.2f}")])
    if not rows:
        reason = _reason(report, "reflection", "no pair of neighbouring surface gauges had four "
                         "periods of record after the wave train reached it, with a spacing of "
                         "0.05 to 0.45 wave lengths")
        return f"<p class='missing'>not computed: {html.escape(reason)}.</p>"
    return _table(["method", "gauges", "incident Hm0 (m)", "reflected Hm0 (m)",
                   "reflection coefficient Kr"], rows)


_RUN_UP_COLUMNS = (("x_m", "from x (m)", "{:.2f}"), ("to_x_m", "to x (m)", "{:.2f}"),
                   ("analysed_from_s", "analysed from (s)", "{:.1f}"),
                   ("run_up_waves", "waves", "{:.0f}"), ("R2%_m", "R2% above SWL (m)", "{:.3f}"),
                   ("R_max_m", "R max (m)", "{:.3f}"))
_OVERTOPPING_COLUMNS = (("x_m", "x (m)", "{:.2f}"),
                        ("analysed_from_s", "analysed from (s)", "{:.1f}"),
                        ("duration_s", "over (s)", "{:.1f}"),
                        ("volume_m3_per_m", "volume (m^3/m)", "{:.4g}"),
                        ("q_m3_s_per_m", "mean q (m^3/s per m)", "{:.4g}"),
                        ("q_l_s_per_m", "mean q (l/s per m)", "{:.4g}"))


def _gauge_table(report: dict, key: str, columns, placed: int, kind: str) -> str:
    """The table of the ``key`` gauges of ``report`` (run-up, overtopping), or why there is none."""
    rows = [_gauge_row(name, e, columns, placed) for name, e in _entries(report, key).items()]
    if not rows:
        return f"<p class='missing'>not computed: the run has no {kind} gauge.</p>"
    return _table(["gauge"] + [h for _, h, _ in columns], rows)


def _row(label: str, value: str) -> str:
    return (f"<tr><th class='name' style='min-width:20em'>{html.escape(label)}</th>"
            f"<td style='text-align:left'>{value}</td></tr>")


def _format(value, fmt: str, reason: str) -> str:
    number = _number(value)
    return (html.escape(fmt.format(number)) if number is not None
            else f"<span class='missing'>not computed: {html.escape(reason)}</span>")


def _still_water_ratio(test: dict) -> float:
    """Buoyancy over submerged weight of a submerged unit: rho_w / (rho_s - rho_w) = 1 / Delta."""
    return 1.0 / test["relative_density"]


def _rock_rows(rock: dict) -> list[str]:
    """Rock armour's rows: S and its class, P and the core, the three formulas with their
    cautions, where the profile eroded (``flume_test.rock``)."""
    rows = []
    damage = rock.get("S")
    if damage is not None:
        thresholds = rock.get("damage_class_thresholds") or {}
        rows.append(_row("damage level S, its class (The Rock Manual, Table 5.22)",
                         f"{damage:.2f}: {html.escape(str(rock.get('damage_class')))} (start "
                         f"{thresholds.get('start', float('nan')):g}, intermediate "
                         f"{'-'.join(f'{v:g}' for v in thresholds.get('intermediate', []))}, "
                         f"failure {thresholds.get('failure', float('nan')):g} on this slope)"))
    rows.append(_row("notional permeability P (Van der Meer 1988)",
                     f"{rock['notional_permeability']:g}: "
                     f"{html.escape(str(rock.get('notional_permeability_reason')))}; core: "
                     f"{html.escape(str(rock.get('core')))}"))
    for caution in rock.get("cautions", []):
        rows.append(_row("caution", html.escape(caution)))
    for formula in rock.get("formulas", []):
        value = (f"{formula['S']:.3g}" if formula.get("S") is not None else
                 f"<span class='missing'>not computed: "
                 f"{html.escape(str(formula.get('not_computed')))}</span>")
        cautions = "; ".join(formula.get("cautions", []))
        rows.append(_row(f"{formula['name']}: S predicted for these waves",
                         value + (f" <span class='note'>({html.escape(cautions)})</span>"
                                  if cautions else "")))
    if rock.get("formula_band_S"):
        low, high = rock["formula_band_S"]
        where = rock.get("measured_against_band")
        rows.append(_row("the formulas' band", f"S {low:.3g}-{high:.3g}"
                         + (f"; measured S is {html.escape(where)} it" if where else "")))
    zone = rock.get("eroded_zone") or {}
    if "eroded_from_x_m" in zone:
        level = zone.get("deepest_below_still_water_over_dn50")
        rows.append(_row("where the profile eroded",
                         f"x {zone['eroded_from_x_m']:.3f}-{zone['eroded_to_x_m']:.3f} m, "
                         f"deepest {zone['deepest_depth_over_dn50']:.2f} D_n50 at x "
                         f"{zone['deepest_x_m']:.3f} m"
                         + ("" if level is None else
                            f", {abs(level):.2f} D_n50 {'below' if level >= 0 else 'above'} "
                            "still water")))
    elif zone.get("note"):
        rows.append(_row("where the profile eroded", html.escape(zone["note"])))
    return rows


def stability_section(analysis) -> str:
    """The stability section of the report (empty for a run without waves)."""
    test = analysis.layer.get("flume_test")
    if getattr(analysis, "flume", None) is None or not isinstance(test, dict):
        return ""
    layer, units = analysis.layer, analysis.units
    no_height = ("no surface gauge has a record after the wave train's arrival (see Waves)"
                 if "stability_number" not in test else "")
    hudson = test.get("hudson") if isinstance(test.get("hudson"), dict) else {}
    cubes = test.get("van_der_meer_cubes")
    rows = [_row("incident wave height at the toe, Hm0 (m)",
                 _format(test.get("Hm0_m"), "{:.3f}", no_height)
                 + (f" <span class='note'>({html.escape(str(test.get('wave_height_source')))})"
                    "</span>" if not no_height else "")),
            _row("mean period Tz (s), waves",
                 _format(test.get("Tz_s"), "{:.2f}", no_height) + ", "
                 + _format(test.get("waves"), "{:.0f}", no_height) if not no_height else
                 _format(None, "", no_height)),
            _row("relative density Delta, Dn (m)", f"{test['relative_density']:.3f}, "
                 f"{test['nominal_diameter_m']:.3f}"),
            _row("stability number Ns = Hm0 / (Delta Dn)",
                 _format(test.get("stability_number"), "{:.2f}", no_height))]
    if hudson:
        rows.append(_row(f"Hudson, K_D = {hudson['K_D']:g}, cot alpha = {test['slope_cot']:.2f}: "
                         "Ns = (K_D cot alpha)^(1/3)",
                         f"{hudson['stability_number']:.2f} ("
                         + (f"measured / Hudson {hudson['ratio']:.2f}; " if "ratio" in hudson
                            else "measured / Hudson <span class='missing'>not computed: "
                            f"{html.escape(no_height)}</span>; ")
                         + f"{html.escape(hudson['meaning'])})"))
    else:
        rows.append(_row("Hudson", "<span class='missing'>not computed: "
                         + html.escape(no_height or f"no K_D retrieved for {test['unit']} units")
                         + "</span>"))
    rock = test.get("rock")
    if isinstance(cubes, dict):
        rows.append(_row("Van der Meer (1988), cubes: N_od predicted",
                         f"{cubes['N_od']:.2f} ({html.escape(cubes['meaning'])})"))
    elif isinstance(rock, dict):
        rows += _rock_rows(rock)
    else:
        why = (f"for rock and cubes only; this layer is of {test['unit']} units"
               if test.get("unit") not in ("cube", "antifer_cube") else
               "needs the incident Hm0, Tz and the number of waves")
        rows.append(_row("Van der Meer", f"<span class='missing'>not computed: {html.escape(why)}"
                                          "</span>"))
    displaced = layer.get("units_displaced")
    no_reference = f"no reference state ({layer.get('displacement_reference', 'none')})"
    rows += [_row(f"units displaced (moved > {layer.get('damage_threshold_over_dn', 1.0):g} Dn)",
                  f"{len(displaced)} of {layer['units']}" + (f" ({', '.join(map(str, displaced))})"
                                                              if displaced else "")
                  if isinstance(displaced, list) else
                  f"<span class='missing'>not computed: {html.escape(no_reference)}</span>"),
             _row("damage number N_od (displaced per Dn of width)",
                  _format(layer.get("damage_number_nod"), "{:.3f}", no_reference)),
             _row("eroded area A_e (m^2), damage level S = A_e / Dn^2",
                  _format(layer.get("eroded_area_m2"), "{:.3f}", no_reference) + ", "
                  + _format(layer.get("damage_level_s"), "{:.2f}", no_reference))]
    share = analysis.flume.rocking
    rows.append(_row(f"units that rocked (> {layer.get('rocking_angle_deg', 2.0):g} deg and back)",
                     f"{len(share['units_rocking'])} of {share['units']} "
                     f"({100 * share['share']:.0f} %)" if share else
                     "<span class='missing'>not computed: no frames before this one</span>"))
    ratio = np.asarray(units.get("max_fluid_force_over_submerged_weight", []), dtype=float)
    if ratio.size and np.isfinite(ratio).any():
        k = int(np.nanargmax(ratio))
        rows.append(_row("largest fluid force on a unit / its submerged weight",
                         f"{ratio[k]:.2f} (unit {k}, {units['max_fluid_force_N'][k]:.4g} N at "
                         f"t = {units['max_fluid_force_time_s'][k]:.3g} s; every unit in "
                         "<code>units.csv</code>, max_fluid_force_*). The force is the water's "
                         "whole force, buoyancy included: in still water a submerged unit carries "
                         f"{_still_water_ratio(test):.2f} of its submerged weight "
                         "(rho_w / (rho_s - "
                         f"rho_w)); the water alone lifts it once the upward part exceeds its "
                         f"weight, {_still_water_ratio(test) + 1.0:.2f} submerged weights."))
    return ("<h2 id='stability'>Stability</h2>"
            f"<table>{''.join(rows)}</table>"
            "<p class='note'>Hudson's and Van der Meer's numbers are for the waves measured here "
            "(riprap/analysis/stability_report.py, design_formulas.py); displaced: the centroid "
            "moved more than the threshold from frame 0; S from the profiles below "
            "(riprap/analysis/damage.py).</p>"
            "<h3>Profiles of the section, before and after</h3>"
            "<img src='stability_profiles.png' alt='armour profiles before and after'>"
            "<h3>Each unit</h3>"
            "<img src='stability_units.png' alt='displacement, rocking and fluid load per unit'>"
            "<h3>Contacts under wave load, frame by frame</h3>"
            "<img src='stability_contacts.png' alt='coordination numbers, contact forces and "
            "factors of safety of the units over the run'>"
            "<p class='note'>From every frame of <code>bodies.pvd</code> (its "
            "<code>coordination_number</code>, <code>max_contact_force</code>, "
            "<code>factor_of_safety_sliding</code> per body); the tables above are of the frame "
            "analysed (<code>riprap analyse RUN --frame N</code> for another).</p>")
