"""Files of ``riprap analyse``: tables, ParaView output, pictures and a one-page HTML report.

In the output folder (every column and unit in ``docs/outputs.md``):

- ``units.csv``: one row per unit (``LayerAnalysis.units``), ``unit_id`` first;
- ``contacts.csv``: every contact of the state (:func:`riprap.io.layer_file.write_contact_table`);
- ``layer_summary.json``: the layer figures (``LayerAnalysis.layer``);
- ``layer.vtu``: the units' surfaces with per-body ``body_id``, ``unit_id``,
  ``coordination_number``, ``max_contact_force``, ``factor_of_safety`` (and the sliding and
  rocking ones), ``displacement``, ``displacement_over_dn`` and ``rotation_deg`` for ParaView;
  ``underlayer.vtu`` the rocks;
- ``stereonet.png``/``.svg``, ``layer_<field>.png``, ``slope_<field>.png``/``.svg``,
  ``histograms.png``/``.svg``;
- of a flume run, ``waves_*.png`` and ``stability_*.png`` and the report's Waves and Stability
  sections first (:mod:`riprap.io.flume_report`);
- ``report.html``: the summary table, the layer measured against design (:data:`DESIGN_TOLERANCES`),
  the pictures, the units that moved most since the reference state (frame 0 of a run), the units
  with the smallest factors of safety and what those factors mean, on one page.

:func:`write_comparison` puts several analysed layers side by side (``comparison.html``).
"""
from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

from riprap.io import analysis_figures as figures
from riprap.io.analysis_figures import (FACTOR_OF_SAFETY_DISPLAY_CAP, PER_UNIT_FIELDS,
                                        drawn_fields)
from riprap.io.flume_report import stability_section, waves_section, write_flume_figures
from riprap.io.csv_tables import write_columns_csv
from riprap.io.layer_file import write_contact_table
from riprap.io.summary import write_json
from riprap.io.vtk import write_vtu

__all__ = ["write_analysis", "write_comparison", "write_units_csv", "design_verdict",
           "SUMMARY_ROWS", "DESIGN_TOLERANCES"]


def _factor_of_safety_text(value) -> str:
    """A factor of safety for a table: 3 decimals, "> cap" above the display cap (and for inf)."""
    value = float(value)
    if math.isnan(value):
        return "-"
    cap = FACTOR_OF_SAFETY_DISPLAY_CAP
    return f"> {cap:g}" if value > cap else f"{value:.3f}"


#: Rows of the report's summary table: (key of LayerAnalysis.layer, label, format string or
#: function of the value). A label starting with spaces is a detail of the row above, indented.
SUMMARY_ROWS = (
    ("units", "units", "{:d}"),
    ("underlayer_bodies", "underlayer bodies (rocks)", "{:d}"),
    ("packing_density_coefficient", "packing density coefficient phi = N Dn^2 / A", "{:.3f}"),
    ("design_packing_density_coefficient", "  design", "{:.3f}"),
    ("porosity", "layer porosity", "{:.3f}"),
    ("design_porosity", "  design", "{:.3f}"),
    ("layer_thickness_m", "layer thickness (m)", "{:.3f}"),
    ("design_layer_thickness_m", "  design (m)", "{:.3f}"),
    ("coordination_number_mean", "mean coordination number", "{:.2f}"),
    ("coordination_number_min", "smallest coordination number", "{:d}"),
    ("coordination_number_max", "largest coordination number", "{:d}"),
    ("max_contact_force_N", "largest contact force on a unit (N)", "{:.4g}"),
    ("unit_weight_N", "weight of a unit (N)", "{:.4g}"),
    ("factor_of_safety_min", "smallest factor of safety", _factor_of_safety_text),
    ("factor_of_safety_median", "median factor of safety", _factor_of_safety_text),
    ("mean_distance_from_design_m", "mean distance from the design position (m)", "{:.3f}"),
    ("max_displacement_m", "largest displacement since the reference state (m)", "{:.3f}"),
    ("max_displacement_over_dn", "  in nominal diameters Dn", "{:.2f}"),
    ("max_rotation_deg", "largest rotation since the reference state (degrees)", "{:.1f}"),
)

#: Rows of SUMMARY_ROWS left out when no layer has the key (no reference state to measure from).
OPTIONAL_SUMMARY_KEYS = ("max_displacement_m", "max_displacement_over_dn", "max_rotation_deg")


#: Tolerances of the verdict against design: (key of LayerAnalysis.layer, label, tolerance, kind);
#: the design value is the layer's ``design_<key>``, ``kind`` says whether the tolerance is a
#: fraction of the design value ("relative") or in the quantity's own unit ("absolute").
#:
#: No published acceptance tolerance for a placed layer was found in the sources read
#: (docs/armour-units.md; shared/validation/armour_design.md sections 5-6, where the CLI
#: packing-density specifications are marked not found), so these are riprap's working values, to
#: be replaced by a project's specification:
#:
#: - packing density coefficient, +-5 %: one unit more or less in a measured panel of about 20
#:   units (the small example counts 21) moves phi by about 5 %, so a model panel of that size
#:   cannot be judged more finely;
#: - layer thickness, +-10 %: the thickness is read from each unit's highest point, which moves by
#:   a good part of D_n with the unit's random orientation, above an underlayer top averaged over
#:   rocks about half a D_n in size; 10 % of k_t D_n is 0.15 D_n for a Core-Loc;
#: - porosity, +-0.05 absolute: porosity follows from the other two (n_v = 1 - phi D_n / t for one
#:   layer), and +-5 % on phi with +-10 % on t move it by up to (1 - n_v) x 15 %, about 0.06 for
#:   a single-layer unit; absolute, because it is a fraction near one half.
DESIGN_TOLERANCES = (
    ("packing_density_coefficient", "packing density coefficient phi", 0.05, "relative"),
    ("layer_thickness_m", "layer thickness (m)", 0.10, "relative"),
    ("porosity", "layer porosity", 0.05, "absolute"),
)
#: Rock armour's further rows, riprap's working values as above: k_t +-10 % (the thickness's own
#: tolerance; the Rock Manual gives k_t of a double layer as 0.91 for standard and dense
#: placement, without a tolerance), stones per area +-5 % (as phi, whose count it is).
ROCK_DESIGN_TOLERANCES = (
    ("layer_thickness_coefficient", "layer thickness coefficient k_t", 0.10, "relative"),
    ("stones_per_area", "stones per m2", 0.05, "relative"),
)


def primary_axis_name(layer: dict) -> str:
    """The axis whose fabric a layer summary gives (``<name>_axis_fabric``: ``nose`` of concrete
    units, ``long`` of armour stones)."""
    return next((key[:-len("_axis_fabric")] for key in layer if key.endswith("_axis_fabric")),
                "nose")


def design_verdict(layer: dict) -> list[dict]:
    """The layer measured against design, one entry per row of :data:`DESIGN_TOLERANCES`.

    Each entry: ``key``, ``label``, ``design``, ``measured``, ``difference`` (measured - design),
    ``tolerance`` (in the quantity's unit), ``tolerance_text`` (as stated) and ``inside`` (True,
    False, or None when the design or measured value is missing).

    Examples
    --------
    >>> rows = design_verdict({"layer_thickness_m": 1.2, "design_layer_thickness_m": 1.0})
    >>> [(row["key"], row["inside"]) for row in rows]
    [('packing_density_coefficient', None), ('layer_thickness_m', False), ('porosity', None)]
    """
    rows = []
    # rock armour adds its layer thickness coefficient (the Rock Manual's k_t) and stones per area
    extra = ROCK_DESIGN_TOLERANCES if "design_layer_thickness_coefficient" in layer else ()
    for key, label, tolerance, kind in DESIGN_TOLERANCES + extra:
        design = float(layer.get(f"design_{key}", math.nan))
        measured = float(layer.get(key, math.nan))
        absolute = tolerance * abs(design) if kind == "relative" else tolerance
        known = math.isfinite(design) and math.isfinite(measured)
        rows.append({"key": key, "label": label, "design": design, "measured": measured,
                     "difference": measured - design, "tolerance": absolute,
                     "tolerance_text": (f"±{100 * tolerance:g} %" if kind == "relative"
                                        else f"±{tolerance:g}"),
                     "inside": bool(abs(measured - design) <= absolute) if known else None})
    return rows


def _verdict_table(layer: dict) -> str:
    head = "".join(f"<th>{name}</th>" for name in (
        "", "design", "measured", "difference", "tolerance", "verdict"))
    rows = []
    for row in design_verdict(layer):
        if row["inside"] is None:
            cells = ["-"] * 4 + [row["tolerance_text"], "no value to compare"]
            verdict_class = ""
        else:
            relative = (f" ({100 * row['difference'] / row['design']:+.1f} %)"
                        if row["design"] else "")
            cells = [f"{row['design']:.3f}", f"{row['measured']:.3f}",
                     f"{row['difference']:+.3f}{relative}",
                     f"{row['tolerance_text']} (±{row['tolerance']:.3f})",
                     "inside" if row["inside"] else "outside"]
            verdict_class = " class='inside'" if row["inside"] else " class='outside'"
        tds = "".join(f"<td>{html.escape(text)}</td>" for text in cells[:-1])
        rows.append(f"<tr><th class='name'>{html.escape(row['label'])}</th>{tds}"
                    f"<td{verdict_class}>{html.escape(cells[-1])}</td></tr>")
    return f"<table class='verdict'><tr>{head}</tr>{''.join(rows)}</table>"


def write_units_csv(path, units: dict) -> Path:
    """One row per unit, the columns of ``units`` in order."""
    return write_columns_csv(path, units)


def _write_paraview(out: Path, analysis) -> dict:
    state = analysis.state
    unit_of_body = np.full(state.n_bodies, -1, dtype=np.int64)
    unit_of_body[state.layer.unit_bodies] = np.arange(len(state.layer.unit_bodies))
    written = {}
    for name, bodies in (("layer", state.layer.unit_bodies),
                         ("underlayer", np.setdiff1d(np.arange(state.n_bodies),
                                                     state.layer.unit_bodies))):
        if len(bodies) == 0:
            continue
        points, triangles, owners, offset = [], [], [], 0
        for body in bodies:
            faces = state.boundary_faces(body)
            used, local = np.unique(faces, return_inverse=True)
            points.append(state.world_nodes(body)[used])
            triangles.append(local.reshape(faces.shape) + offset)
            owners.append(np.full(len(faces), body, dtype=np.int64))
            offset += len(used)
        owners = np.concatenate(owners)
        cell_data = {"body_id": owners, "unit_id": unit_of_body[owners]}
        if name == "layer":
            for column, label in (("coordination_number", "coordination_number"),
                                  ("max_contact_force_N", "max_contact_force"),
                                  ("factor_of_safety", "factor_of_safety"),
                                  ("factor_of_safety_sliding", "factor_of_safety_sliding"),
                                  ("factor_of_safety_rocking", "factor_of_safety_rocking"),
                                  ("displacement_m", "displacement"),
                                  ("displacement_over_dn", "displacement_over_dn"),
                                  ("rotation_deg", "rotation_deg"),
                                  ("row", "row")):
                values = analysis.body_values(column)[owners]
                # ParaView colours inf badly; a large finite number reads as "no driving load".
                cell_data[label] = np.where(np.isinf(values), 1.0e30, values)
        path = out / f"{name}.vtu"
        write_vtu(path, points=np.concatenate(points), cells=np.concatenate(triangles),
                  cell_type="triangle", cell_data=cell_data)
        written[f"paraview_{name}"] = str(path)
    return written


def _summary_table(layers: list[dict], labels: list[str]) -> str:
    head = "".join(f"<th>{html.escape(label)}</th>" for label in labels)
    rows = []
    for key, label, fmt in SUMMARY_ROWS:
        if key in OPTIONAL_SUMMARY_KEYS and all(key not in layer for layer in layers):
            continue
        cells = []
        for layer in layers:
            value = layer.get(key)
            try:
                text = (fmt(value) if callable(fmt) else fmt.format(value)) if value is not None \
                    and not (isinstance(value, float) and math.isnan(value)) else "-"
            except (ValueError, TypeError):
                text = str(value)
            cells.append(f"<td>{html.escape(text)}</td>")
        # HTML collapses leading spaces: a detail row is indented by its class instead.
        name_class = "name detail" if label.startswith(" ") else "name"
        rows.append(f"<tr><th class='{name_class}'>{html.escape(label.strip())}</th>"
                    f"{''.join(cells)}</tr>")
    return f"<table><tr><th></th>{head}</tr>{''.join(rows)}</table>"


_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 72em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.9em; }
td, th { padding: 0.2em 0.8em; border-bottom: 1px solid #eee; text-align: right; }
th.name { text-align: left; font-weight: normal; } th.detail { padding-left: 2.2em; }
td.inside { color: #1a7f37; font-weight: bold; } td.outside { color: #b42318; font-weight: bold; }
.figures { display: flex; flex-wrap: wrap; gap: 1em; } .figures img { max-width: 34em; }
img.wide { max-width: 100%; } .note { color: #555; font-size: 0.85em; }
h3 { font-size: 1em; margin-top: 1.2em; } .missing { color: #9a6700; font-style: italic; }
.smoke { background: #fde2e1; border: 2px solid #c0392b; padding: 0.5em; }
"""


def _page(title: str, body: str) -> str:
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
            f"<style>{_STYLE}</style></head><body><h1>{html.escape(title)}</h1>{body}</body></html>\n")


def _lowest_fos_table(units: dict, count: int = 10) -> str:
    order = np.argsort(units["factor_of_safety"], kind="stable")[:count]
    fos = _factor_of_safety_text
    columns = (("unit_id", "{:d}".format), ("row", "{:d}".format),
               ("coordination_number", "{:d}".format), ("max_contact_force_N", "{:.4g}".format),
               ("factor_of_safety_sliding", fos), ("factor_of_safety_rocking", fos),
               ("height_above_underlayer_m", "{:.3f}".format))
    head = "".join(f"<th>{name}</th>" for name, _ in columns)
    rows = "".join("<tr>" + "".join(f"<td>{html.escape(fmt(units[name][k].item()))}</td>"
                                    for name, fmt in columns) + "</tr>" for k in order)
    return f"<table><tr>{head}</tr>{rows}</table>"


def _units_below_one(layer: dict, units: dict) -> str:
    """One line per unit with a factor of safety below 1: which mode, and what it rests on."""
    items = []
    for k in layer["units_below_factor_of_safety_1"]:
        sliding = float(units["factor_of_safety_sliding"][k])
        rocking = float(units["factor_of_safety_rocking"][k])
        mode = "rocking" if rocking <= sliding else "sliding"
        other = "sliding" if mode == "rocking" else "rocking"
        on_units, on_rest = int(units["unit_contacts"][k]), int(units["underlayer_contacts"][k])
        height = float(units["height_above_underlayer_m"][k])
        items.append(
            f"<li>unit {k} (row {int(units['row'][k])}): {mode} "
            f"{_factor_of_safety_text(min(sliding, rocking))}, {other} "
            f"{_factor_of_safety_text(max(sliding, rocking))}; touches "
            f"{_count(on_units, 'unit', 'units')} and "
            f"{_count(on_rest, 'rock or wall', 'rocks or walls')}; centroid {height:.2f} m "
            f"({height / layer['nominal_diameter_m']:.2f} D<sub>n</sub>) above the underlayer top"
            f"{' (it rests on other units only)' if on_rest == 0 and on_units else ''}.</li>")
    return f"<p>Units with a factor of safety below 1:</p><ul>{''.join(items)}</ul>" if items else ""


def _count(number: int, one: str, many: str) -> str:
    return f"{number or 'no'} {one if number == 1 else many}"


def _factor_of_safety_notes(layer: dict, units: dict) -> str:
    """What the factors of safety of a unit at rest mean, why one can be below 1, and the cap."""
    cap = FACTOR_OF_SAFETY_DISPLAY_CAP
    return (
        "<h2 id='reading-factors-of-safety'>Reading the factors of safety</h2>"
        f"{_units_below_one(layer, units)}"
        "<p>Every unit of a settled layer is at rest: with all its contacts, the forces and "
        "moments on it balance. A factor of safety here is a limit-equilibrium check of one unit "
        "over the contacts it has now, with the forces the layer settled to "
        "(<code>contacts.csv</code>); it does not say that the unit moves.</p>"
        "<p><b>Sliding</b> (riprap/solid/contact_statistics.py): the sum of &mu;|N| over the sum "
        "of |T| over all the unit's contacts. The solver caps each contact's friction force at "
        "&mu;|N|, so for a state riprap computed it is at least 1, and 1 only when every contact "
        "slides; above 1 it says how far the tangential springs are from their Coulomb limit. "
        "Friction forces that oppose each other (a unit pinched between neighbours) all count as "
        "driving, which errs on the safe side.</p>"
        "<p><b>Rocking</b> (riprap/analysis/rocking.py, Goodman &amp; Bray's toppling criterion): "
        "the unit is taken to tip forward about one pivot, its support point furthest down the "
        "slope. The loads are its weight and the pushes of the units further up the slope. Every "
        "other contact (rocks, the face, units down the slope or beside it) is assumed to let go "
        "as soon as the unit tips, and no contact that would form or grow as it starts to turn "
        "is counted. In the layer those contacts carry load: a unit whose legs are hooked behind "
        "its neighbours is held back by their reactions, which push above or up the slope of the "
        "pivot, and by the friction at its other supports; and since each contact is recorded as "
        "one force at one point, the moment of a broad contact's pressure is lost too. A rocking "
        "factor below 1 therefore means that the unit's own weight would not stop it toppling "
        "about that pivot: it rests because its neighbours hold it (interlocking), and it would "
        "go if they moved, for example if a wave lifted the units below it. It marks a unit to "
        "look at, not one that is moving.</p>"
        f"<p class='note'>Factors of safety above {cap:g} are shown as \"&gt; {cap:g}\" in the "
        "tables and drawn with the top colour (the colour bar is then pointed): beyond a few, the "
        "number says only that the mode does not govern. A rocking factor is inf when nothing "
        "tips the unit forward, and runs to hundreds when the overturning moment is small. "
        "<code>units.csv</code> and <code>layer.vtu</code> keep the computed values (inf as "
        "1e30 in ParaView).</p>")


def _no_contacts_note(layer: dict) -> str:
    if layer.get("contacts_recorded", True):
        return ""
    return ("<p class='outside'><b>This run recorded no contacts</b> (coupled runs written "
            "before issue 35 have no <code>contacts.pvd</code>): coordination numbers, contact forces "
            "and factors of safety are not known here and are left empty (NaN in "
            "<code>units.csv</code>). Run the case again for them.</p>")


def _factor_of_safety_section(layer: dict, units: dict) -> str:
    if not layer.get("contacts_recorded", True):
        return ""
    return (f"<h2>Units with the smallest factor of safety</h2>{_lowest_fos_table(units)}"
            f"{_factor_of_safety_notes(layer, units)}")


def _displacement_section(layer: dict, units: dict, count: int = 10) -> str:
    """The units that moved most since the reference state, or why there is no reference."""
    if "max_displacement_m" not in layer:
        return ("<h2>Displacements</h2><p class='note'>Reference state: "
                f"{html.escape(str(layer.get('displacement_reference', 'none')))}; the "
                "displacement columns are empty. Analyse a run's later frame to see how far each "
                "unit moved from frame 0.</p>")
    order = np.argsort(-units["displacement_m"], kind="stable")[:count]
    columns = (("unit_id", "{:d}".format), ("row", "{:d}".format),
               ("displacement_m", "{:.3f}".format), ("displacement_over_dn", "{:.2f}".format),
               ("displacement_along_slope_m", "{:+.3f}".format),
               ("displacement_z_m", "{:+.3f}".format), ("rotation_deg", "{:.1f}".format))
    head = "".join(f"<th>{name}</th>" for name, _ in columns)
    rows = "".join("<tr>" + "".join(f"<td>{html.escape(fmt(units[name][k].item()))}</td>"
                                    for name, fmt in columns) + "</tr>" for k in order)
    moved = layer["units_moved"]
    return (f"<h2>Displacements</h2><p>Since {html.escape(layer['displacement_reference'])}: "
            f"{len(moved)} of {layer['units']} units moved more than "
            f"{layer['moved_threshold_over_dn']:g} D<sub>n</sub>"
            f"{' (' + ', '.join(map(str, moved[:30])) + (' ...' if len(moved) > 30 else '') + ')' if moved else ''}; "
            f"largest {layer['max_displacement_m']:.3f} m ({layer['max_displacement_over_dn']:.2f} "
            f"D<sub>n</sub>), largest rotation {layer['max_rotation_deg']:.1f}&deg;.</p>"
            f"<table><tr>{head}</tr>{rows}</table>"
            "<p class='note'>Displacement: the move of the unit's centroid; along the slope: "
            "positive up the face; rotation: the angle of the rotation from the reference "
            "orientation to the present one, about whatever axis.</p>")


def _distributions(out: Path) -> str:
    # no picture when no panel had values to count (histogram_figure)
    if not (out / "histograms.svg").is_file():
        return ""
    return "<h2>Distributions</h2><img class='wide' src='histograms.svg' alt='histograms'>"


def write_analysis(out, analysis) -> dict:
    """Every file of one analysed layer in ``out``; returns ``{what: path}``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    state, layer, units = analysis.state, analysis.layer, analysis.units
    outputs = {"units": str(write_units_csv(out / "units.csv", units)),
               "contacts": str(write_contact_table(out / "contacts.csv", state.contacts)),
               "summary": str(write_json(out / "layer_summary.json", layer))}
    outputs.update(_write_paraview(out, analysis))
    axis = state.layer.primary_axis
    fabric = layer.get(f"{axis}_axis_fabric", {})
    slope = state.layer.slope
    figures.stereonet_figure(
        out / "stereonet.png", units[f"{axis}_trend_deg"], units[f"{axis}_plunge_deg"],
        title=(f"{axis.capitalize()} axes of {layer['units']} {layer['unit']} units, lower "
               "hemisphere, equal area\n"
               f"fabric S1 {fabric.get('S1', float('nan')):.2f}, S2 {fabric.get('S2', float('nan')):.2f}, "
               f"S3 {fabric.get('S3', float('nan')):.2f} (random: 0.33 each)"),
        slope_dip_direction_deg=(270.0, slope.angle_deg))
    outputs["stereonet"] = str(out / "stereonet.png")
    for column in figures.drawn_fields(units):
        outputs[f"layer_{column}"] = str(figures.layer_view_png(out / f"layer_{column}.png",
                                                                analysis, column))
        figures.slope_view_figure(out / f"slope_{column}.png", analysis, column)
        outputs[f"slope_{column}"] = str(out / f"slope_{column}.png")
    if figures.histogram_figure(out / "histograms.png", analysis):
        outputs["histograms"] = str(out / "histograms.png")
    else:       # nothing to count: no picture, nor an earlier analysis's left in the folder
        for suffix in ("png", "svg"):
            (out / f"histograms.{suffix}").unlink(missing_ok=True)
    outputs.update(write_flume_figures(out, analysis))
    outputs["report"] = str(_write_report(out, analysis))
    return outputs


def _write_report(out: Path, analysis) -> Path:
    layer, units = analysis.layer, analysis.units
    axis = primary_axis_name(layer)
    histogram = ", ".join(f"{k}: {v}" for k, v in layer["coordination_number_histogram"].items())
    low = layer["units_below_factor_of_safety_1"]
    # Only the first letter raised: str.capitalize would also lower the unit, "(N)" to "(n)".
    fields = "".join(
        f"<h2>{html.escape(label[:1].upper() + label[1:])}</h2><div class='figures'>"
        f"<img src='layer_{column}.png' alt='layer, {html.escape(label)}'>"
        f"<img src='slope_{column}.svg' alt='face view, {html.escape(label)}'></div>"
        for column, (label, _) in PER_UNIT_FIELDS.items() if column in drawn_fields(units))
    smoke = ("<p class='smoke'><b>SMOKE RUN</b>: the run was cut to a few steps (RIPRAP_SMOKE=1, "
             "its <code>summary.json</code>: <code>smoke</code>); nothing on this page is a "
             "result: run it again without RIPRAP_SMOKE.</p>"
             if layer.get("run_mode") == "smoke" else "")
    body = (
        f"{smoke}<p class='note'>Analysed: {html.escape(str(layer['source']))}"
        # a run's frame names its time (frame 3 (the last), t = 4 s); a pack's does not
        + ("" if "t = " in str(layer["source"]) else f", t = {layer['time_s']:g} s") + ". "
        f"{layer['units']} {html.escape(layer['unit'])} units (D<sub>n</sub> = "
        f"{layer['nominal_diameter_m']:.3f} m) on a {layer['slope_angle_deg']:.1f}&deg; slope. "
        "Tables: <a href='units.csv'>units.csv</a> (one row per unit), "
        "<a href='contacts.csv'>contacts.csv</a>, <a href='layer_summary.json'>layer_summary.json</a>; "
        "ParaView: <code>layer.vtu</code>, <code>underlayer.vtu</code>.</p>"
        f"{_no_contacts_note(layer)}"
        f"{waves_section(analysis)}{stability_section(analysis)}"
        f"<h2>Summary</h2>{_summary_table([layer], ['this layer'])}"
        f"<h2>Measured against design</h2>{_verdict_table(layer)}"
        "<p class='note'>Design values: the unit's design table (<code>layer.json</code>, "
        "docs/armour-units.md, which says which values are published and which are riprap's "
        "assumptions). Tolerances: riprap's working values, no published acceptance tolerance "
        "having been found (<code>DESIGN_TOLERANCES</code> in riprap/io/analysis_report.py gives "
        "the reason for each); use the project's specification where there is one.</p>"
        f"<p>Coordination numbers (value: units): {html.escape(histogram)}. "
        f"Units with a factor of safety below 1: {len(low)}"
        f"{' (' + ', '.join(map(str, low[:20])) + (' ...' if len(low) > 20 else '') + ')' if low else ''}"
        f"{'; see <a href=#reading-factors-of-safety>what that means for a unit at rest</a>' if low else ''}.</p>"
        f"<h2>Orientation of the {axis} axes</h2>"
        f"<div class='figures'><img src='stereonet.svg' alt='stereonet of the {axis} axes'></div>"
        f"{fields}"
        f"{_distributions(out)}"
        f"{_displacement_section(layer, units)}"
        f"{_factor_of_safety_section(layer, units)}"
        "<p class='note'>Definitions. Coordination number: bodies and walls a unit touches. Largest "
        "contact force: magnitude of the normal plus friction force of the unit's most loaded "
        "contact. Factor of safety against sliding: sum of mu |N| over sum of |T| of the unit's "
        "contacts (limit equilibrium). Against rocking: restoring over overturning moments of the "
        "weight and of the forces from units up the slope, about the support point furthest down "
        "the slope (Goodman &amp; Bray 1976). Packing density, porosity and thickness are counted "
        "row by row (riprap/placement/layer_metrics.py). Stereonet: lower hemisphere, equal area, "
        "exponential Kamb contours.</p>")
    path = out / "report.html"
    path.write_text(_page("riprap armour layer analysis"
                          + (" (SMOKE RUN)" if layer.get("run_mode") == "smoke" else ""), body),
                    encoding="utf-8")
    return path


def write_comparison(out, analyses, labels) -> dict:
    """Each layer's files in ``out/<label>/`` and ``comparison.html`` with the figures side by side."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    outputs = {}
    for analysis, label in zip(analyses, labels):
        outputs[label] = write_analysis(out / label, analysis)
    figures.comparison_stereonets(out / "comparison_stereonets.png", analyses, labels)
    histograms = figures.comparison_histograms(out / "comparison_histograms.png", analyses, labels)
    write_json(out / "comparison.json", {label: a.layer for label, a in zip(labels, analyses)})
    faces = "".join(f"<figure><img src='{html.escape(label)}/slope_max_contact_force_N.svg' "
                    f"alt='{html.escape(label)}'><figcaption>{html.escape(label)}</figcaption></figure>"
                    for label in labels)
    sources = "".join(f"<li>{html.escape(label)}: {html.escape(str(a.layer['source']))} "
                      f"(<a href='{html.escape(label)}/report.html'>report</a>)</li>"
                      for label, a in zip(labels, analyses))
    body = (f"<ul>{sources}</ul><h2>Summary</h2>"
            f"{_summary_table([a.layer for a in analyses], list(labels))}"
            "<h2>Nose axes</h2><img class='wide' src='comparison_stereonets.svg' alt='stereonets'>"
            + ("<h2>Distributions</h2><img class='wide' src='comparison_histograms.svg' "
               "alt='histograms'>" if histograms else "") +
            f"<h2>Largest contact force, face view</h2><div class='figures'>{faces}</div>")
    path = out / "comparison.html"
    path.write_text(_page("riprap armour layer comparison", body), encoding="utf-8")
    outputs["comparison"] = str(path)
    return outputs
