"""The analysis of an armour layer: one row per unit, one set of figures per layer.

Per unit (``LayerAnalysis.units``, the columns of ``units.csv``, units in ``docs/outputs.md``):
where it is (world and slope coordinates, height above the face and above the underlayer,
distance from its design position), what it touches (coordination number: bodies and walls
touched; how many of them units), the largest contact force it carries (all contacts, with
units, with the underlayer), its weight, factors of safety against sliding
(:func:`~riprap.solid.contact_statistics.sliding_factor_of_safety`) and rocking
(:func:`~riprap.analysis.rocking.rocking_factor_of_safety`), ``factor_of_safety`` the smaller of
the two, for each named axis of the unit its world direction, trend and plunge and its point
on the lower-hemisphere equal-area net, and how far it moved and turned since the reference state
(frame 0 of a run; :mod:`~riprap.analysis.displacements`; NaN for a pack on its own). When the
source recorded no contacts (a coupled run), the contact columns are NaN.

Per layer (``LayerAnalysis.layer``): packing density coefficient, porosity and layer thickness
(:mod:`riprap.placement.layer_metrics`, the same definitions as ``riprap place``), against the
design values; coordination-number histogram and statistics; contact-force percentiles; the
units below a factor of safety of 1; the fabric of the nose axes (eigenvalues of the orientation
tensor, Woodcock 1977, Geol. Soc. Am. Bull. 88: 1231-1236: S1 = S2 = S3 = 1/3 for uniformly
random axes, S1 -> 1 when all axes are parallel).
"""
from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np

from riprap.analysis.damage import (damage_level_s, damage_number_nod, displaced_units, eroded_area,
                                   profile_from_surfaces, rocking_events)
from riprap.analysis.displacements import DISPLACEMENT_COLUMNS, unit_displacements
from riprap.analysis.orientations import equal_area_points, lower_hemisphere, trend_plunge
from riprap.analysis.rocking import rocking_factor_of_safety
from riprap.solid.contact_statistics import sliding_factor_of_safety, unit_contacts
from riprap.placement import layer_metrics

__all__ = ["LayerAnalysis", "analyse_layer", "CONTACT_FORCE_PERCENTILES"]

#: Percentiles of the contact forces reported per layer.
CONTACT_FORCE_PERCENTILES = (50, 90, 99)
#: Per-unit columns that come from the contacts (NaN when the source recorded none).
CONTACT_COLUMNS = ("coordination_number", "unit_contacts", "underlayer_contacts",
                   "max_contact_force_N", "max_contact_force_unit_unit_N",
                   "max_contact_force_unit_underlayer_N", "max_contact_force_over_weight",
                   "factor_of_safety", "factor_of_safety_sliding", "factor_of_safety_rocking")
#: A unit counts as moved in the layer summary when its centroid moved more than this many D_n.
MOVED_THRESHOLD_DN = 0.1
#: A unit counts as displaced (damage, N_od) when its centroid moved more than this many D_n:
#: out of its place in the layer (Van der Meer 1988 counts units moved out of the layer).
DISPLACED_THRESHOLD_DN = 1.0
#: A rocking event: the unit's rotation from its reference pose rises above this (degrees) and
#: falls back below half of it (``riprap.analysis.damage.rocking_events``).
ROCKING_ANGLE_DEG = 2.0
#: Profile points per nominal diameter along and across the section (for the eroded area).
PROFILE_SAMPLES_PER_DN = 4


@dataclass(frozen=True, eq=False)
class LayerAnalysis:
    """Result of :func:`analyse_layer`.

    Attributes
    ----------
    units : dict of str to (n_units,) array
        One column per quantity, in the order of ``units.csv``.
    layer : dict
        Layer figures (numbers, lists and small dicts; JSON-ready).
    unit_unit_forces, unit_underlayer_forces : (m,) float
        Magnitudes of every contact force between two units / a unit and the underlayer (N).
    state : LayerState
        The state analysed.
    flume : FlumeRecords or None
        A flume run's wave records and target (``riprap.analysis.flume_test``), for the report's
        waves section; None for a pack or a run without waves.
    """

    units: dict
    layer: dict
    unit_unit_forces: np.ndarray
    unit_underlayer_forces: np.ndarray
    state: object
    flume: object = None

    def body_values(self, column: str, fill: float = np.nan) -> np.ndarray:
        """A column of ``units`` spread over all bodies (``fill`` for the underlayer)."""
        values = np.full(self.state.n_bodies, fill, dtype=float)
        values[self.state.layer.unit_bodies] = self.units[column]
        return values


def _pair_force_magnitudes(state, is_unit):
    contacts = state.contacts
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    if len(body_i) == 0:
        return np.zeros(0), np.zeros(0)
    force = np.linalg.norm(np.asarray(contacts.normal_forces) + np.asarray(contacts.tangential_forces),
                           axis=1)
    i_unit = is_unit[body_i]
    j_unit = (body_j >= 0) & is_unit[np.maximum(body_j, 0)]
    return force[i_unit & j_unit], force[i_unit ^ j_unit]


def _fabric(axes) -> dict:
    """Eigenvalues S1 >= S2 >= S3 of the normalised orientation tensor of axial data, and the
    direction (trend, plunge) of the principal (S1) axis."""
    if len(axes) == 0:
        return {"S1": float("nan"), "S2": float("nan"), "S3": float("nan")}
    unit = axes / np.linalg.norm(axes, axis=1)[:, None]
    tensor = unit.T @ unit / len(unit)
    values, vectors = np.linalg.eigh(tensor)
    trend, plunge = trend_plunge(vectors[:, 2])
    return {"S1": float(values[2]), "S2": float(values[1]), "S3": float(values[0]),
            "principal_trend_deg": float(trend[0]), "principal_plunge_deg": float(plunge[0])}


def analyse_layer(state, *, displaced_threshold_dn: float = None) -> LayerAnalysis:
    """Analyse the armour units of ``state`` (a :class:`~riprap.analysis.layer_state.LayerState`);
    a unit moved more than ``displaced_threshold_dn`` nominal diameters counts as displaced
    (default ``DISPLACED_THRESHOLD_DN``)."""
    if displaced_threshold_dn is None:
        displaced_threshold_dn = DISPLACED_THRESHOLD_DN
    layer = state.layer
    slope = layer.slope
    bodies = np.asarray(layer.unit_bodies, dtype=np.int64)
    n_units = len(bodies)
    group = np.zeros(state.n_bodies, dtype=np.int64)
    group[bodies] = 1
    is_unit = group == 1
    contact_stats = unit_contacts(state.n_bodies, state.contacts, group=group)
    weights = state.masses() * np.linalg.norm(state.gravity)
    sliding = sliding_factor_of_safety(state.n_bodies, state.contacts, state.contact_friction())[bodies]
    rocking = rocking_factor_of_safety(state, bodies, weights, slope)

    # Partners of each unit that are units too.
    contacts = state.contacts
    body_i = np.asarray(contacts.body_i, dtype=np.int64)
    body_j = np.asarray(contacts.body_j, dtype=np.int64)
    unit_partners = np.zeros(state.n_bodies, dtype=np.int64)
    both = is_unit[body_i] & (body_j >= 0) & is_unit[np.maximum(body_j, 0)]
    np.add.at(unit_partners, body_i[both], 1)
    np.add.at(unit_partners, body_j[both], 1)

    positions = state.positions[bodies]
    frame = slope.to_slope(positions)
    design = np.asarray(layer.design_positions, dtype=float).reshape(n_units, 3)
    columns: dict[str, np.ndarray] = {
        "unit_id": np.arange(n_units),
        "body_id": bodies,
        "row": np.asarray(layer.rows, dtype=np.int64),
        "x_m": positions[:, 0], "y_m": positions[:, 1], "z_m": positions[:, 2],
        "along_slope_m": frame[:, 0],
        "height_above_slope_m": frame[:, 2],
        "height_above_underlayer_m": frame[:, 2] - layer.underlayer_top,
        "distance_from_design_m": np.linalg.norm(positions - design, axis=1),
        "coordination_number": contact_stats.coordination_number[bodies],
        "unit_contacts": unit_partners[bodies],
        "underlayer_contacts": contact_stats.coordination_number[bodies] - unit_partners[bodies],
        "weight_N": weights[bodies],
        "max_contact_force_N": contact_stats.max_contact_force[bodies],
        "max_contact_force_unit_unit_N": contact_stats.max_contact_force_unit_unit[bodies],
        "max_contact_force_unit_underlayer_N": contact_stats.max_contact_force_unit_underlayer[bodies],
        "max_contact_force_over_weight": contact_stats.max_contact_force[bodies] / weights[bodies],
        "factor_of_safety": np.minimum(sliding, rocking),
        "factor_of_safety_sliding": sliding,
        "factor_of_safety_rocking": rocking,
    }
    columns.update(_displacement_columns(state, bodies))
    columns["rocking_events"] = (rocking_events(state.rotation_history[:, bodies], ROCKING_ANGLE_DEG)
                                 if state.rotation_history is not None
                                 else np.full(n_units, np.nan))
    primary_axes = None
    for name, axis in layer.unit_axes.items():
        world = state.rotations[bodies] @ np.asarray(axis, dtype=float)
        down = lower_hemisphere(world) if n_units else np.zeros((0, 3))
        trend, plunge = trend_plunge(down) if n_units else (np.zeros(0), np.zeros(0))
        net = equal_area_points(down) if n_units else np.zeros((0, 2))
        columns[f"{name}_trend_deg"] = trend
        columns[f"{name}_plunge_deg"] = plunge
        columns[f"{name}_net_east"] = net[:, 0]
        columns[f"{name}_net_north"] = net[:, 1]
        for component, label in enumerate("xyz"):
            columns[f"{name}_axis_{label}"] = down[:, component]
        if name == layer.primary_axis:
            primary_axes = down

    unit_unit, unit_underlayer = _pair_force_magnitudes(state, is_unit)
    dn = layer.nominal_diameter
    on_face = (frame[:, 0] >= -dn) & (frame[:, 0] <= slope.length)
    node_sets = [state.world_nodes(b) for b, ok in zip(bodies, on_face) if ok]
    figures = layer_metrics.layer_figures(
        slope, positions[on_face], node_sets, rows=columns["row"][on_face], nominal_diameter=dn,
        unit_volume=layer.unit_volume, underlayer_level=layer.underlayer_top)
    if layer.is_rock:
        figures = _rock_layer_figures(state, bodies)
    coordination = columns["coordination_number"]
    values, counts = np.unique(coordination, return_counts=True)
    fos = columns["factor_of_safety"]
    all_forces = np.concatenate([unit_unit, unit_underlayer])

    def percentiles(forces):
        return {f"p{p}": (float(np.percentile(forces, p)) if len(forces) else 0.0)
                for p in CONTACT_FORCE_PERCENTILES} | {"max": float(forces.max(initial=0.0)),
                                                       "mean": float(forces.mean()) if len(forces) else 0.0,
                                                       "count": int(len(forces))}

    summary = {
        "source": state.source,
        "time_s": float(state.time),
        "unit": layer.unit_kind,
        "nominal_diameter_m": float(dn),
        "unit_weight_N": float(weights[bodies].mean()) if n_units else 0.0,
        "slope_angle_deg": float(slope.angle_deg),
        "units": int(n_units),
        "units_on_face": int(on_face.sum()),
        "underlayer_bodies": int(state.n_bodies - n_units),
        **figures,
        "design_packing_density_coefficient": float(layer.design.get("packing_density_coefficient", np.nan)),
        "design_layer_thickness_m": float(layer.design.get("layer_thickness_m", np.nan)),
        "design_porosity": float(layer.design.get("porosity", np.nan)),
        **(_rock_design(layer.design) if layer.is_rock else {}),
        "coordination_number_mean": float(coordination.mean()) if n_units else 0.0,
        "coordination_number_min": int(coordination.min()) if n_units else 0,
        "coordination_number_max": int(coordination.max()) if n_units else 0,
        "coordination_number_histogram": {int(v): int(c) for v, c in zip(values, counts)},
        "contact_force_N": percentiles(all_forces),
        "contact_force_unit_unit_N": percentiles(unit_unit),
        "contact_force_unit_underlayer_N": percentiles(unit_underlayer),
        "max_contact_force_N": float(columns["max_contact_force_N"].max(initial=0.0)),
        "factor_of_safety_min": float(fos.min()) if n_units else float("nan"),
        "factor_of_safety_median": float(np.median(fos)) if n_units else float("nan"),
        "units_below_factor_of_safety_1": [int(k) for k in np.flatnonzero(fos < 1.0)],
        "mean_distance_from_design_m": float(columns["distance_from_design_m"].mean()) if n_units else 0.0,
        f"{layer.primary_axis}_axis_fabric": (_fabric(primary_axes) if primary_axes is not None
                                               else {}),
        **_displacement_summary(state, columns, displaced_threshold_dn),
    }
    if not state.contacts_recorded:
        columns.update({name: np.full(n_units, np.nan) for name in CONTACT_COLUMNS})
        summary["contacts_recorded"] = False
        summary["units_below_factor_of_safety_1"] = []
        for key in ("coordination_number_mean", "coordination_number_min",
                    "coordination_number_max", "max_contact_force_N", "factor_of_safety_min",
                    "factor_of_safety_median"):
            summary[key] = None
        summary["coordination_number_histogram"] = {}
    return LayerAnalysis(units=columns, layer=summary, unit_unit_forces=unit_unit,
                         unit_underlayer_forces=unit_underlayer, state=state)


def _rock_design(design: dict) -> dict:
    """A rock layer's design k_t and stones per area (with the grading's D_n50, as designed)."""
    dn50 = design["dn50_m"]
    return {"design_dn50_m": float(dn50),
            "design_layer_thickness_coefficient": float(design["layer_thickness_m"]
                                                        / (design["layers"] * dn50)),
            "design_stones_per_area": float(design["packing_density_coefficient"] / dn50 ** 2)}


def _rock_layer_figures(state, bodies) -> dict:
    """A rock layer's figures measured as ``riprap place`` measures them
    (:func:`riprap.placement.layer_metrics.stone_layer_figures`: k_t, N_a, porosity, roughness
    between a D_n50 inside the lowest and highest stones), under the names the units' figures
    have (phi = N_a D_n50^2 for a packing density coefficient)."""
    layer = state.layer
    dn = layer.nominal_diameter
    volumes = np.array([float(state.meshes[int(state.shape_of_body[b])].volumes().sum())
                        for b in bodies])
    rock = layer_metrics.stone_layer_figures(
        layer.slope, state.positions[bodies], [state.world_nodes(b) for b in bodies], volumes,
        dn50=dn, layers=int(round(layer.design.get("layers", 2))),
        underlayer_level=layer.underlayer_top)
    return {"packing_density_coefficient": rock["stones_per_area_times_dn50_squared"],
            "layer_thickness_m": rock["layer_thickness_m"], "porosity": rock["porosity"],
            "measuring_area_m2": rock["measuring_area_m2"],
            "layer_thickness_coefficient": rock["layer_thickness_coefficient"],
            "stones_per_area": rock["stones_per_area"],
            "stones_measured": rock["stones_measured"],
            "surface_roughness_over_dn50": rock["surface_roughness_over_dn50"]}

def _displacement_columns(state, bodies) -> dict:
    """The units' displacement and rotation since the state's reference (NaN without one)."""
    if state.reference_positions is None:
        return {name: np.full(len(bodies), np.nan) for name in DISPLACEMENT_COLUMNS}
    return unit_displacements(state.positions[bodies], state.rotations[bodies],
                              np.asarray(state.reference_positions)[bodies],
                              np.asarray(state.reference_rotations)[bodies],
                              nominal_diameter=state.layer.nominal_diameter,
                              slope=state.layer.slope)


def _displacement_summary(state, columns, threshold_dn: float) -> dict:
    """Layer figures of the displacements: the reference, largest and mean, units moved."""
    if state.reference_positions is None:
        return {"displacement_reference": state.reference_note or "none"}
    distance, over_dn = columns["displacement_m"], columns["displacement_over_dn"]
    turned = columns["rotation_deg"]
    moved = np.flatnonzero(over_dn > MOVED_THRESHOLD_DN)
    displaced = displaced_units(over_dn, threshold_dn)
    layer = state.layer
    edges = [0.0, MOVED_THRESHOLD_DN, 0.5, threshold_dn, math.inf]
    classes = {f"{low:g}-{high:g} Dn": int(np.sum((over_dn >= low) & (over_dn < high)))
               for low, high in zip(edges[:-1], edges[1:]) if high > low}
    return {"displacement_reference": state.reference_note,
            "damage_threshold_over_dn": threshold_dn,
            "displacement_classes": classes,
            "units_displaced": [int(k) for k in displaced],
            "damage_number_nod": damage_number_nod(len(displaced), layer.slope.width,
                                                   layer.nominal_diameter),
            "rocking_angle_deg": ROCKING_ANGLE_DEG,
            "rocking_events": (int(np.nansum(columns["rocking_events"]))
                               if state.rotation_history is not None else None),
            "displacement_reference_time_s": float(state.reference_time),
            "max_displacement_m": float(distance.max(initial=0.0)),
            "max_displacement_over_dn": float(over_dn.max(initial=0.0)),
            "mean_displacement_m": float(distance.mean()) if len(distance) else 0.0,
            "max_rotation_deg": float(turned.max(initial=0.0)),
            "moved_threshold_over_dn": MOVED_THRESHOLD_DN,
            "units_moved": [int(k) for k in moved],
            **_profile_damage(state)}


def _profile_damage(state) -> dict:
    """Eroded area A_e and damage level S = A_e / D_n^2 of the cross-section between the reference
    and this state: profiles of the bodies' upper surface, lowered onto every body's surface
    triangles at each pose on a plan grid of D_n / 4 over the slope (a D_n beyond its toe and top)
    and averaged across the width, the slope's face read where no body covers a point
    (``riprap.analysis.damage.profile_from_surfaces``). On a periodic strip every surface is
    also laid at its images a strip's width to either side: a unit across the strip's side
    covers the points at both."""
    layer = state.layer
    slope, dn = layer.slope, layer.nominal_diameter
    spacing = dn / PROFILE_SAMPLES_PER_DN
    x_toe = float(slope.to_world(0.0, 0.0, 0.0)[0])
    x_top = float(slope.to_world(slope.length, 0.0, 0.0)[0])
    xs = np.arange(min(x_toe, x_top) - dn, max(x_toe, x_top) + dn + 0.5 * spacing, spacing)
    ys = np.arange(0.5 * spacing, slope.width, spacing)
    now, before = [], []
    for body in range(state.n_bodies):
        faces = state.boundary_faces(body)
        shape = int(state.shape_of_body[body])
        local = state.meshes[shape].nodes - state.mesh_centroids[shape]
        now.append((local @ state.rotations[body].T + state.positions[body])[faces])
        before.append((local @ np.asarray(state.reference_rotations)[body].T
                       + np.asarray(state.reference_positions)[body])[faces])
    along = np.clip((xs - slope.toe[0]) / slope.tangent[0], 0.0, slope.length)
    face = slope.toe[2] + along * slope.tangent[2]
    before, now = np.concatenate(before), np.concatenate(now)
    if slope.periodic:
        shifts = [np.array([0.0, dy, 0.0]) for dy in (-slope.width, slope.width)]
        before = np.concatenate([before] + [before + shift for shift in shifts])
        now = np.concatenate([now] + [now + shift for shift in shifts])
    profile_before = profile_from_surfaces(before, xs, ys, face)
    profile_now = profile_from_surfaces(now, xs, ys, face)
    eroded = eroded_area(profile_before, profile_now, spacing)
    # the profiles themselves, for the report's picture of S (and for a reader's own checks)
    return {"eroded_area_m2": eroded, "damage_level_s": damage_level_s(eroded, dn),
            "profile_spacing_m": spacing,
            "damage_profiles": {"x_m": xs.tolist(), "before_z_m": profile_before.tolist(),
                                "after_z_m": profile_now.tolist()}}
