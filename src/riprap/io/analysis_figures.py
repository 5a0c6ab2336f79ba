"""Pictures of an analysed armour layer (matplotlib; PNG and SVG).

- ``stereonet``: lower-hemisphere equal-area (Schmidt) net of the units' nose axes, points and
  density contours (exponential Kamb, mplstereonet; multiples of the density of uniformly random
  axes), with the fabric eigenvalues in the title;
- ``layer_<field>``: the units in 3D coloured by a per-unit value, the underlayer rocks in grey
  (PNG only: a layer has too many faces for a useful SVG);
- ``slope_<field>``: the layer seen square onto the face (s up the slope, y across), each unit as
  the outline of its footprint on the face, coloured by a per-unit value, with the underlayer's
  extent drawn in grey;
- ``histograms``: coordination numbers, contact forces (unit-unit and unit-underlayer),
  factors of safety and displacements, each panel only where there are values to count.

A field with no finite value (the contact fields of a run that recorded no contacts, the
displacement of a pack on its own) is not drawn (:func:`drawn_fields`).

A 3D view and the face view of the same field share its colour map and range
(:func:`colour_scale`); factors of safety are drawn up to :data:`FACTOR_OF_SAFETY_DISPLAY_CAP`.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from riprap.io import picture

__all__ = ["stereonet_figure", "layer_view_png", "slope_view_figure", "histogram_figure",
           "comparison_stereonets", "comparison_histograms", "colour_scale", "drawn_fields",
           "histogram_panels", "PER_UNIT_FIELDS", "FACTOR_OF_SAFETY_DISPLAY_CAP",
           "DISPLACEMENT_DISPLAY_RANGE_DN"]

#: Per-unit fields drawn on the layer, with their colour-bar labels and colour maps.
PER_UNIT_FIELDS = {
    "max_contact_force_N": ("largest contact force (N)", "viridis"),
    "coordination_number": ("coordination number (bodies and walls touched)", "plasma"),
    "factor_of_safety": ("factor of safety (smaller of sliding and rocking)", "RdYlGn"),
    "displacement_over_dn": ("displacement since the reference state (D_n)", "YlOrRd"),
}
#: Factors of safety above this are shown as "> cap" in the report's tables, with the top colour
#: in the pictures and in the histogram's last bin. Beyond a few the number says only that the
#: mode does not govern: a rocking factor is inf when nothing tips a unit forward and runs to
#: hundreds when the overturning moment is small, and 5 leaves room to tell 1, 1.5 and 2 apart
#: on the colour scale.
FACTOR_OF_SAFETY_DISPLAY_CAP = 5.0
#: Displacements are coloured from 0 to this many D_n (the darkest colour: a unit displaced out of
#: its place, riprap.analysis.layer_analysis.DISPLACED_THRESHOLD_DN), not to the largest value.
DISPLACEMENT_DISPLAY_RANGE_DN = 1.0
_DOTS_PER_INCH = 150


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(figure, path: Path, formats=("png", "svg")) -> list[Path]:
    path.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for suffix in formats:
        target = path.with_suffix(f".{suffix}")
        figure.savefig(target, dpi=_DOTS_PER_INCH, bbox_inches="tight")
        written.append(target)
    _pyplot().close(figure)
    return written


def _display_values(column: str, values) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    if column.startswith("factor_of_safety"):
        return np.minimum(values, FACTOR_OF_SAFETY_DISPLAY_CAP)
    return values


def drawn_fields(units: dict) -> list[str]:
    """The fields of :data:`PER_UNIT_FIELDS` in ``units`` that have a finite value for some unit."""
    return [column for column in PER_UNIT_FIELDS
            if column in units and np.isfinite(np.asarray(units[column], dtype=float)).any()]


def colour_scale(column: str, values) -> tuple[str, float, float]:
    """Colour map, lowest and highest value of the colour scale of a per-unit ``column``.

    Factors of safety: 0 to :data:`FACTOR_OF_SAFETY_DISPLAY_CAP`; displacements in D_n: 0 to
    :data:`DISPLACEMENT_DISPLAY_RANGE_DN`, whatever the largest (so that a hair's move is not
    drawn in the colour of a displaced unit); other fields: their finite
    range over ``values`` (one unit wide if all are equal), displacements from 0. Every figure of
    one field uses this, so a colour means the same value in the 3D view and the face view."""
    _, colour_map = PER_UNIT_FIELDS.get(column, (column, "viridis"))
    if column.startswith("factor_of_safety"):
        return colour_map, 0.0, FACTOR_OF_SAFETY_DISPLAY_CAP
    if column == "displacement_over_dn":
        return colour_map, 0.0, DISPLACEMENT_DISPLAY_RANGE_DN
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    low, high = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
    if column.startswith("displacement"):
        low = 0.0
    return colour_map, low, high if high > low else low + 1.0


def _extend(values, low: float, high: float) -> str:
    """Colour-bar ends to point: where some values lie beyond the scale."""
    values = np.asarray(values, dtype=float)
    below, above = bool((values < low).any()), bool((values > high).any())
    return {(False, False): "neither", (True, False): "min", (False, True): "max",
            (True, True): "both"}[below, above]


def _draw_stereonet(axes, trend, plunge, title, title_pad=26):
    if len(trend) >= 3:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            contours = axes.density_contourf(plunge, trend, measurement="lines",
                                             method="exponential_kamb", cmap="Blues")
    else:
        contours = None
    axes.line(plunge, trend, marker="o", markersize=3.5, color="black", linestyle="none")
    axes.grid(True, linewidth=0.4, alpha=0.6)
    axes.set_azimuth_ticks([])
    for x, y, label in ((0.5, 1.035, "N"), (1.035, 0.5, "E"), (0.5, -0.035, "S"), (-0.035, 0.5, "W")):
        axes.text(x, y, label, transform=axes.transAxes, fontsize=9, ha="center", va="center",
                  fontweight="bold")
    axes.set_title(title, fontsize=10, pad=title_pad)
    return contours


def stereonet_figure(path, trend, plunge, *, title: str, slope_dip_direction_deg=None) -> list[Path]:
    """Nose axes on a lower-hemisphere equal-area net, with density contours (PNG and SVG).

    ``slope_dip_direction_deg``: trend of the direction down the face (drawn as the face's pole
    for reference), or None."""
    import mplstereonet  # noqa: F401  (registers the "stereonet" projection)

    plt = _pyplot()
    figure = plt.figure(figsize=(6.6, 6.2))
    axes = figure.add_subplot(111, projection="stereonet")
    # The title on the net's own axes, just clear of the "N" label: a figure title sits at the
    # top of the figure, a band of blank paper above the (square) net.
    contours = _draw_stereonet(axes, np.asarray(trend), np.asarray(plunge), title, title_pad=18)
    if slope_dip_direction_deg is not None:
        axes.pole(slope_dip_direction_deg[0] - 90.0, slope_dip_direction_deg[1], marker="^",
                  color="crimson", markersize=8, label="pole of the slope face")
        axes.legend(loc="lower left", fontsize=8, bbox_to_anchor=(-0.1, -0.12))
    if contours is not None:
        bar = figure.colorbar(contours, ax=axes, shrink=0.6, pad=0.1)
        bar.set_label("density (multiples of uniform)", fontsize=8)
    return _save(figure, Path(path))


def layer_view_png(path, analysis, column: str) -> Path:
    """The units in 3D coloured by ``column`` of ``analysis.units`` (PNG)."""
    state = analysis.state
    bodies = state.layer.unit_bodies
    rocks = np.setdiff1d(np.arange(state.n_bodies), bodies)
    triangles, owners = [], []
    for body in np.concatenate([bodies, rocks]):
        faces = state.boundary_faces(body)
        triangles.append(state.world_nodes(body)[faces])
        owners.append(np.full(len(faces), body, dtype=np.int64))
    label, _ = PER_UNIT_FIELDS.get(column, (column, "viridis"))
    colour_map, low, high = colour_scale(column, analysis.units[column])
    title = f"{len(bodies)} units: {label}"
    if len(rocks):
        title += f", on {len(rocks)} underlayer rocks (grey)"
    return picture.render_bodies_png(path, triangles_world=triangles,
                                     body_ids=np.concatenate(owners),
                                     values=analysis.body_values(column), value_label=label,
                                     value_range=(low, high), colour_map=colour_map,
                                     grey_bodies=rocks, title=title, view=(30, -125))


def _footprints(state, bodies):
    """Outline (convex hull in the face's (s, y) plane) of each body."""
    from scipy.spatial import ConvexHull

    slope = state.layer.slope
    outlines = []
    for body in bodies:
        sy = slope.to_slope(state.world_nodes(body))[:, :2]
        hull = ConvexHull(sy)
        outlines.append(sy[hull.vertices][:, ::-1])       # (y, s): y across, s up the page
    return outlines


def slope_view_figure(path, analysis, column: str) -> list[Path]:
    """The layer seen square onto the face, units coloured by ``column`` (PNG and SVG)."""
    from matplotlib.collections import PolyCollection

    plt = _pyplot()
    state = analysis.state
    layer = state.layer
    label, _ = PER_UNIT_FIELDS.get(column, (column, "viridis"))
    outlines = _footprints(state, layer.unit_bodies)
    values = np.asarray(analysis.units[column], dtype=float)
    colour_map, low, high = colour_scale(column, values)
    extent_s = max(o[:, 1].max() for o in outlines) if outlines else layer.slope.length
    figure, axes = plt.subplots(figsize=(7.5, 2.0 + 6.0 * min(extent_s / layer.slope.width, 2.0)))
    rocks = np.setdiff1d(np.arange(state.n_bodies), layer.unit_bodies)
    if len(rocks):
        rock_sy = layer.slope.to_slope(state.positions[rocks])
        axes.scatter(rock_sy[:, 1], rock_sy[:, 0], s=2, color="0.75", zorder=0,
                     label="underlayer rock centroids")
    # inf (nothing drives the unit) takes the top colour like any value above the scale.
    collection = PolyCollection(outlines, array=np.clip(values, low, high), cmap=colour_map,
                                edgecolors="black", linewidths=0.4)
    collection.set_clim(low, high)
    axes.add_collection(collection)
    if len(outlines) <= 60:
        for k, outline in enumerate(outlines):
            centre = outline.mean(axis=0)
            axes.text(centre[0], centre[1], str(k), ha="center", va="center", fontsize=6)
    axes.set_xlim(0.0, layer.slope.width)
    all_s = np.concatenate([o[:, 1] for o in outlines]) if outlines else np.zeros(1)
    axes.set_ylim(min(all_s.min(), 0.0) - 0.05 * layer.nominal_diameter,
                  all_s.max() + 0.3 * layer.nominal_diameter)
    axes.set_aspect("equal")
    axes.set_xlabel("y across the flume (m)")
    axes.set_ylabel("s up the slope from the toe (m)")
    axes.set_title(f"{len(outlines)} units on the 1:{layer.slope.cotangent:g} face, seen square on",
                   fontsize=10)
    bar = figure.colorbar(collection, ax=axes, shrink=0.8, extend=_extend(values, low, high))
    bar.set_label(label, fontsize=8)
    if len(rocks):
        axes.legend(loc="upper right", fontsize=7, markerscale=3)
    return _save(figure, Path(path))


def _coordination_values(analysis) -> np.ndarray:
    values = np.asarray(analysis.units["coordination_number"], dtype=float)
    return values[np.isfinite(values)]


def _positive_forces(analysis) -> list[np.ndarray]:
    return [np.asarray(f, dtype=float)[np.asarray(f, dtype=float) > 0]
            for f in (analysis.unit_unit_forces, analysis.unit_underlayer_forces)]


def _safety_values(analysis) -> np.ndarray:
    values = _display_values("factor_of_safety", analysis.units["factor_of_safety"])
    return values[~np.isnan(values)]


def _displacement_values(analysis) -> np.ndarray:
    values = np.asarray(analysis.units.get("displacement_over_dn", []), dtype=float)
    return values[np.isfinite(values)]


def _coordination_panel(axis, analyses, labels, colours):
    values = [_coordination_values(a) for a in analyses]
    joined = np.concatenate(values)
    bins = np.arange(int(joined.min()), int(joined.max()) + 2) - 0.5
    for data, label, colour in zip(values, labels, colours):
        axis.hist(data, bins=bins, color=colour, alpha=0.6 if label else 0.9, edgecolor="black",
                  linewidth=0.4, label=label)
    axis.set_xlabel("coordination number")
    axis.set_ylabel("units")


def _force_panel(axis, analyses, labels, colours):
    forces = [_positive_forces(a) for a in analyses]
    joined = np.concatenate([np.concatenate(f) for f in forces])
    edges = np.geomspace(joined.min(), joined.max() * 1.0001, 25)
    for (unit_unit, underlayer), label, colour in zip(forces, labels, colours):
        for k, (values, name) in enumerate(((unit_unit, "unit-unit"),
                                            (underlayer, "unit-underlayer"))):
            if len(values):
                axis.hist(values, bins=edges, histtype="step", linewidth=1.4,
                          linestyle="-" if k == 0 else "--", color=colour,
                          label=f"{label + ': ' if label else ''}{name}")
    axis.set_xscale("log")
    axis.legend(fontsize=7)
    axis.set_xlabel("contact force (N)")
    axis.set_ylabel("contacts")


def _safety_panel(axis, analyses, labels, colours):
    for analysis, label, colour in zip(analyses, labels, colours):
        axis.hist(_safety_values(analysis), bins=np.linspace(0.0, FACTOR_OF_SAFETY_DISPLAY_CAP, 26),
                  color=colour, alpha=0.6 if label else 0.9, edgecolor="black", linewidth=0.4,
                  label=label)
    axis.axvline(1.0, color="crimson", linewidth=1.0)
    axis.set_xlabel(f"factor of safety (>= {FACTOR_OF_SAFETY_DISPLAY_CAP:g} in the last bin)")
    axis.set_ylabel("units")


def _displacement_panel(axis, analyses, labels, colours):
    for analysis, label, colour in zip(analyses, labels, colours):
        values = np.minimum(_displacement_values(analysis), DISPLACEMENT_DISPLAY_RANGE_DN)
        axis.hist(values, bins=np.linspace(0.0, DISPLACEMENT_DISPLAY_RANGE_DN, 21), color=colour,
                  alpha=0.6 if label else 0.9, edgecolor="black", linewidth=0.4, label=label)
    axis.set_xlabel(f"displacement since the reference state (D_n; >= "
                    f"{DISPLACEMENT_DISPLAY_RANGE_DN:g} in the last bin)")
    axis.set_ylabel("units")


#: The histogram panels: (what it needs to have values, how it is drawn). A panel is drawn only
#: where some layer has values for it (no empty frames: a run without contacts has no
#: coordination numbers, a pack no displacements).
_HISTOGRAM_PANELS = (
    (lambda a: _coordination_values(a).size > 0, _coordination_panel),
    (lambda a: sum(f.size for f in _positive_forces(a)) > 0, _force_panel),
    (lambda a: _safety_values(a).size > 0, _safety_panel),
    (lambda a: _displacement_values(a).size > 0, _displacement_panel),
)


def histogram_panels(analyses) -> list:
    """The panels of :data:`_HISTOGRAM_PANELS` that some of ``analyses`` has values for."""
    return [draw for has, draw in _HISTOGRAM_PANELS if any(has(a) for a in analyses)]


def _histograms(path, analyses, labels, colours) -> list[Path]:
    panels = histogram_panels(analyses)
    if not panels:
        return []
    plt = _pyplot()
    figure, axes = plt.subplots(1, len(panels), figsize=(4.4 * len(panels), 3.6), squeeze=False)
    for axis, draw in zip(axes[0], panels):
        draw(axis, analyses, labels, colours)
    if labels[0]:
        axes[0, 0].legend(fontsize=7)
    figure.tight_layout()
    return _save(figure, Path(path))


def histogram_figure(path, analysis) -> list[Path]:
    """Coordination numbers, contact forces, factors of safety and displacements, each panel
    only where the layer has values for it (PNG and SVG; nothing when it has none)."""
    return _histograms(path, [analysis], [None], [None])


def comparison_stereonets(path, analyses, labels) -> list[Path]:
    """Nose-axis stereonets of several layers side by side (PNG and SVG)."""
    import mplstereonet  # noqa: F401

    plt = _pyplot()
    figure = plt.figure(figsize=(5.2 * len(analyses), 5.6))
    for k, (analysis, label) in enumerate(zip(analyses, labels)):
        axes = figure.add_subplot(1, len(analyses), k + 1, projection="stereonet")
        axis = analysis.state.layer.primary_axis
        fabric = analysis.layer.get(f"{axis}_axis_fabric", {})
        _draw_stereonet(axes, analysis.units[f"{axis}_trend_deg"],
                        analysis.units[f"{axis}_plunge_deg"],
                        f"{label}: {len(analysis.units['unit_id'])} {axis} axes\n"
                        f"S1 {fabric.get('S1', float('nan')):.2f}, S3 {fabric.get('S3', float('nan')):.2f}")
    return _save(figure, Path(path))


def comparison_histograms(path, analyses, labels) -> list[Path]:
    """Histograms of several layers overlaid (PNG and SVG; the panels any of them has values
    for)."""
    colours = _pyplot().rcParams["axes.prop_cycle"].by_key()["color"]
    return _histograms(path, list(analyses), list(labels),
                       [colours[k % len(colours)] for k in range(len(analyses))])
