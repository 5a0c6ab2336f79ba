"""Fixed bodies too small for the fluid's grid as contact-only bodies, and the porous filter zone
that stands for them in the flow (issue 51, item 4; ``docs/waves.md``, Filter layers).

Why: an underlayer rock that spans a cell or two is clipped into the flow as a few cut faces,
whose drag on the water depends on the time step (95-340 1/s in the damage-curve bench's
underlayer of 1.3 cells, where the Forchheimer friction of a 2 cm filter is 30-85 1/s).

``[fluid] contact_only_below_cells`` = C makes every fixed body whose nominal diameter V^(1/3)
spans fewer than C cells contact-only: the free bodies meet it as before (contact, friction), the
fluid does not (it is one of ``CoupledSolver(obstacle_bodies=...)``: never clipped, no cut faces,
no cells closed, no load from the water, so its fluid force in ``body_forces.csv`` is 0). A
porous zone with the Forchheimer coefficients of the rocks stands for them in the flow:

- the case's ``[[porous_zones]]`` entries, where they hold at least :data:`COVERED_SHARE` of
  every such body's volume;
- else zones fitted here to the bodies they leave out (:func:`fit_filter_zones`): the band the
  bodies make in the x-z plane, measured along its own direction (the principal axis of the
  bodies' nodes in x-z: a slope's filter, a bed) in strips one Dn50 long: from the lowest node
  of each strip (the face the rocks lie on) to the mean over the section's width of the highest
  node of each Dn50 square of the strip (the top of the layer as a profile across the flume
  averages it); porosity :data:`FILTER_POROSITY`, stone diameter the rocks' Dn50 (the median
  of V^(1/3) by mass), friction and added mass the ``[[porous_zones]]`` defaults
  (``riprap.fluid.porous``: a = 50, b = 2.0, c = 0.34, olaFlow's after Jensen et al. 2014).

Refused before the run: a threshold that leaves the fluid no body (every body contact-only) or
that would class every free body as too small as well (the free bodies are never contact-only;
a threshold above all of them mistakes the units for the filter), a filter zone (the case's or
the fitted one) that holds more than :data:`MAXIMUM_FREE_BODY_SHARE` of a free body, and
contact-only bodies that make no straight band (a fitted zone thicker than
:data:`MAXIMUM_BAND_THICKNESS` Dn50: write their zones by hand).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.errors import CaseFileError
from riprap.fluid.porous import (DEFAULT_ADDED_MASS, DEFAULT_LINEAR, DEFAULT_QUADRATIC,
                                 PorousZone)

__all__ = ["FilterLayer", "choose_filter_layer", "fit_filter_zones", "nominal_cells",
           "unresolved_fixed_bodies", "COVERED_SHARE", "FILTER_POROSITY",
           "MAXIMUM_BAND_THICKNESS", "MAXIMUM_FREE_BODY_SHARE", "UNRESOLVED_BELOW_CELLS"]

#: Porosity of the fitted filter zone: a layer of quarried rock of standard grading, 0.3-0.4
#: (CIRIA, CUR, CETMEF 2007, The Rock Manual, section 3.4.3 and Table 3.8), its upper end for a
#: thin layer of a narrow grading on a smooth face.
FILTER_POROSITY = 0.4

#: Fixed bodies that span fewer cells than this are named in a warning when the case does not
#: make them contact-only: at 3 cells a cube's drag still grows by a third as the step shrinks
#: (``docs/coupling.md``, Cut faces and the step).
UNRESOLVED_BELOW_CELLS = 4.0

#: A contact-only body is covered by the case's porous zones when they hold at least this share
#: of its volume (the rest of its volume sits at the zones' edge).
COVERED_SHARE = 0.5

#: A filter zone may hold at most this share of a free body's volume: a unit resting on the
#: layer dips into the top of the zone between the highest rocks (fitted zones: at most 0.05 on
#: a layer of bench/damage_curve.py's set-up, 0.12 on examples/06's, but for one unit lying on
#: the bare face beside a side wall, 0.29), a zone drawn over the units holds most of them.
MAXIMUM_FREE_BODY_SHARE = 0.25

#: A fitted zone at most this many Dn50 thick on average (an underlayer is one to three rocks
#: thick): thicker, the bodies are not one straight band (a toe and a slope and a crest) and
#: their zones must be written by hand.
MAXIMUM_BAND_THICKNESS = 4.0

#: The key, as messages name it.
KEY = "[fluid] contact_only_below_cells"


@dataclass
class FilterLayer:
    """What the case builder chose: the contact-only bodies and the zones the flow sees them as.

    ``threshold`` (cells); ``bodies`` the contact-only fixed bodies; ``sizes`` their nominal
    diameters in cells; ``covering`` the names of the case's zones that cover them;
    ``fitted`` the zones fitted to the rest; ``filled`` the share of each fitted zone the
    bodies fill (1 - their porosity, as the fluid would see them)."""

    threshold: float
    bodies: np.ndarray
    sizes: np.ndarray
    covering: list = field(default_factory=list)
    fitted: list = field(default_factory=list)
    filled: list = field(default_factory=list)

    def lines(self, entries: bool = True) -> list[str]:
        """What the run's log and ``riprap check`` say about it; ``entries``: each fitted zone
        with its ``[[porous_zones]]`` entry (the recipe for changing it)."""
        if not len(self.bodies):
            return [f"{KEY} = {self.threshold:g}: no fixed body spans fewer cells; every body is "
                    "in the flow"]
        low, high = f"{self.sizes.min():.2f}", f"{self.sizes.max():.2f}"
        lines = [f"{len(self.bodies)} fixed bodies of {low if low == high else low + '-' + high} "
                 f"cells are contact-only ({KEY} = {self.threshold:g}): the free bodies meet "
                 "them, the flow sees them as a porous filter, and their fluid force is 0"]
        if self.covering:
            lines.append("covered by " + ", ".join(self.covering))
        for zone, filled in zip(self.fitted, self.filled):
            lines.append(f"{zone.name}: porosity {zone.porosity:g}, stone_diameter "
                         f"{zone.stone_diameter:.4g} m (the bodies' Dn50), linear_friction "
                         f"{zone.linear:g}, quadratic_friction {zone.quadratic:g}, added_mass "
                         f"{zone.added_mass:g}, {len(zone.polygon)} corners (the bodies fill "
                         f"{filled:.2f} of it)" + ("; to change it, give it as a [[porous_zones]] "
                                                   "entry:\n" + zone_toml(zone) if entries else ""))
        return lines


def zone_toml(zone: PorousZone) -> str:
    """A polygon zone as a ``[[porous_zones]]`` entry of a case file."""
    points = ", ".join(f"[{x:.5g}, {z:.5g}]" for x, z in zone.polygon)
    return ("[[porous_zones]]\ntype = \"polygon\"\n"
            f"porosity = {zone.porosity:g}\nstone_diameter = {zone.stone_diameter:.5g}\n"
            f"linear_friction = {zone.linear:g}\nquadratic_friction = {zone.quadratic:g}\n"
            f"added_mass = {zone.added_mass:g}\npoints = [{points}]")


# ---------------------------------------------------------------------- the bodies' geometry
def nominal_cells(solver, cell_size: float) -> np.ndarray:
    """Every body's nominal diameter V^(1/3) in cells of ``cell_size`` (m), (n,)."""
    shape_index = solver.body_poses()[0]
    volumes = np.array([solver.shapes[s].volume for s in shape_index], dtype=np.float64)
    return np.cbrt(volumes) / cell_size


def _in_world(points: np.ndarray, poses, body: int) -> np.ndarray:
    """``points`` (m, 3) of a body's principal frame where its pose puts them (m)."""
    w, x, y, z = poses[3][body]
    return points @ Rotation.from_quat([x, y, z, w]).as_matrix().T + poses[2][body]


def _tet_samples(solver, bodies, poses):
    """Per body of ``bodies``: the world centroids (m, 3) of its tetrahedra and their volumes."""
    samples = []
    for body in bodies:
        mesh = solver.shapes[poses[0][body]].mesh
        corners = mesh.nodes[mesh.tets]
        volumes = np.abs(np.einsum("ti,ti->t", corners[:, 1] - corners[:, 0],
                                   np.cross(corners[:, 2] - corners[:, 0],
                                            corners[:, 3] - corners[:, 0]))) / 6.0
        samples.append((_in_world(corners.mean(axis=1), poses, body), volumes))
    return samples


def _nodes(solver, bodies, poses) -> np.ndarray:
    """The world nodes (m, 3) of ``bodies``."""
    parts = [_in_world(solver.shapes[poses[0][body]].mesh.nodes, poses, body) for body in bodies]
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def _inside(zone: PorousZone, points: np.ndarray) -> np.ndarray:
    """Which of ``points`` (m, 3) lie inside ``zone``."""
    if zone.polygon is None:
        return np.all((points >= np.asarray(zone.lower)) & (points <= np.asarray(zone.upper)),
                      axis=1)
    from matplotlib.path import Path   # as riprap.fluid.porous draws a polygon's cover

    return Path(np.asarray(zone.polygon, dtype=float)).contains_points(points[:, [0, 2]])


def _shares(samples, zones) -> np.ndarray:
    """(bodies, zones): the share of each body's volume inside each zone."""
    shares = np.zeros((len(samples), len(zones)))
    for b, (centres, volumes) in enumerate(samples):
        for z, zone in enumerate(zones):
            shares[b, z] = volumes[_inside(zone, centres)].sum() / volumes.sum()
    return shares


def _union_shares(samples, zones) -> np.ndarray:
    """(bodies,): the share of each body's volume inside any of ``zones``."""
    shares = np.zeros(len(samples))
    for b, (centres, volumes) in enumerate(samples):
        inside = np.zeros(len(volumes), dtype=bool)
        for zone in zones:
            inside |= _inside(zone, centres)
        shares[b] = volumes[inside].sum() / volumes.sum()
    return shares


def _median_by_mass(diameters: np.ndarray, masses: np.ndarray) -> float:
    """Dn50: the nominal diameter that half the mass is finer than."""
    order = np.argsort(diameters)
    cumulative = np.cumsum(masses[order]) / masses.sum()
    return float(diameters[order][np.searchsorted(cumulative, 0.5)])


# ---------------------------------------------------------------------- the fitted zone
def fit_filter_zones(solver, bodies, *, cell_size: float, name: str = "filter zone",
                     poses=None) -> tuple[list[PorousZone], list[float]]:
    """Porous zones standing for the fixed ``bodies`` of ``solver`` in the flow (polygons in
    x-z, one per unbroken stretch of the band) and the share of each zone the bodies fill.

    The band's direction t is the principal axis of the bodies' nodes in x-z (its normal
    points up). Along t, in strips one Dn50 long (at least a cell), the zone runs from the
    lowest node of the strip to the mean, over the Dn50 squares of the strip across the width
    that hold nodes, of each square's highest node. Porosity :data:`FILTER_POROSITY`, stone
    diameter the bodies' Dn50 (median of V^(1/3) by mass), the other coefficients the
    ``[[porous_zones]]`` defaults. A stretch without nodes longer than a strip ends a zone."""
    poses = solver.body_poses() if poses is None else poses
    bodies = np.asarray(bodies, dtype=np.int64)
    shape_index, material_index = poses[0], poses[1]
    volumes = np.array([solver.shapes[shape_index[b]].volume for b in bodies])
    densities = np.array([solver.materials[material_index[b]].density for b in bodies])
    diameter = _median_by_mass(np.cbrt(volumes), densities * volumes)
    nodes = _nodes(solver, bodies, poses)
    plane = nodes[:, [0, 2]]
    centre = plane.mean(axis=0)
    _, vectors = np.linalg.eigh(np.cov((plane - centre).T))
    along = vectors[:, 1] if vectors[0, 1] >= 0 else -vectors[:, 1]   # the largest, towards +x
    if abs(along[0]) < 1e-12:
        along = np.array([0.0, 1.0])
    normal = np.array([-along[1], along[0]])                          # up for a rising band
    s = (plane - centre) @ along
    q = (plane - centre) @ normal
    strip = max(diameter, cell_size)
    count = max(1, math.ceil((s.max() - s.min()) / strip))
    edges = s.min() + strip * np.arange(count + 1)
    column = np.minimum(((s - s.min()) / strip).astype(np.int64), count - 1)
    y = nodes[:, 1]
    square = ((y - y.min()) / strip).astype(np.int64)
    lowest = np.full(count, np.inf)
    np.minimum.at(lowest, column, q)
    squares = int(square.max()) + 1
    highest = np.full((count, squares), -np.inf)
    np.maximum.at(highest, (column, square), q)
    held = np.isfinite(highest)
    top = np.where(held.any(axis=1),
                   np.where(held, highest, 0.0).sum(axis=1) / np.maximum(held.sum(axis=1), 1),
                   np.nan)
    filled_strips = np.isfinite(lowest)
    zones, fills = [], []
    stretches = np.split(np.arange(count), np.flatnonzero(np.diff(filled_strips.astype(int))) + 1)
    stretches = [part for part in stretches if filled_strips[part[0]]]
    samples = _tet_samples(solver, bodies, poses)
    for number, part in enumerate(stretches):
        middles = 0.5 * (edges[part] + edges[part + 1])
        along_bottom = np.concatenate([[edges[part[0]]], middles, [edges[part[-1] + 1]]])
        bottom = np.concatenate([[lowest[part[0]]], lowest[part], [lowest[part[-1]]]])
        upper = np.concatenate([[top[part[0]]], top[part], [top[part[-1]]]])
        upper = np.maximum(upper, bottom + 0.05 * strip)      # never inside out
        outline = np.concatenate([np.stack([along_bottom, bottom], axis=1),
                                  np.stack([along_bottom, upper], axis=1)[::-1]])
        points = centre + outline[:, :1] * along + outline[:, 1:] * normal
        label = name if len(stretches) == 1 else f"{name} {number + 1}"
        thickness = float(np.mean(top[part] - lowest[part]))
        if thickness > MAXIMUM_BAND_THICKNESS * diameter:
            raise CaseFileError(
                f"{label}: the {len(bodies)} contact-only bodies do not lie in one straight band "
                f"(fitted along the direction ({along[0]:.3f}, {along[1]:.3f}) in x-z, it is "
                f"{thickness / diameter:.1f} Dn50 thick on average, more than "
                f"{MAXIMUM_BAND_THICKNESS:g}); give [[porous_zones]] entries covering them "
                "(docs/waves.md, Filter layers)")
        zone = PorousZone(porosity=FILTER_POROSITY, stone_diameter=diameter,
                          polygon=tuple((float(x), float(z)) for x, z in points),
                          linear=DEFAULT_LINEAR, quadratic=DEFAULT_QUADRATIC,
                          added_mass=DEFAULT_ADDED_MASS, name=label)
        zones.append(zone)
        fills.append(_filled_share(zone, samples, nodes))
    return zones, fills


def _filled_share(zone: PorousZone, samples, nodes) -> float:
    """The share of ``zone``, over the width the bodies span, that they fill."""
    polygon = np.asarray(zone.polygon)
    x, z = polygon[:, 0], polygon[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1))))
    width = float(np.ptp(nodes[:, 1]))
    if area * width <= 0.0:
        return 0.0
    solid = sum(float(volumes[_inside(zone, centres)].sum()) for centres, volumes in samples)
    return solid / (area * width)


# ---------------------------------------------------------------------- the choice
def unresolved_fixed_bodies(solver, cell_size: float,
                            below: float = UNRESOLVED_BELOW_CELLS) -> np.ndarray:
    """The fixed bodies whose nominal diameter spans fewer than ``below`` cells."""
    fixed = solver.body_poses()[4]
    return np.flatnonzero(fixed & (nominal_cells(solver, cell_size) < below))


def choose_filter_layer(solver, zones, *, cell_size: float, contact_only_below_cells: float,
                        where: str = "") -> FilterLayer:
    """The contact-only bodies of ``solver`` (a :class:`riprap.solid.solver.SolidSolver`, its
    bodies added) under the threshold ``contact_only_below_cells`` (cells of ``cell_size``, m)
    and the zones the flow sees them as: the case's ``zones`` (:class:`PorousZone`) that cover
    them, zones fitted to the rest. Raises :class:`CaseFileError` (``where``: the case file, for
    messages) on the cases the module's docstring lists. The caller adds ``fitted`` to the
    fluid's zones and leaves ``bodies`` out of the fluid exchange."""
    threshold = float(contact_only_below_cells)
    key = f"{where} {KEY}".strip()
    if not (math.isfinite(threshold) and threshold > 0.0):
        raise CaseFileError(f"{key} = {contact_only_below_cells!r}: must be > 0 cells")
    poses = solver.body_poses()
    fixed = poses[4]
    cells = nominal_cells(solver, cell_size)
    chosen = np.flatnonzero(fixed & (cells < threshold))
    free = np.flatnonzero(~fixed)
    if len(chosen) and len(chosen) == len(cells):
        raise CaseFileError(
            f"{key} = {threshold:g}: every one of the {len(cells)} bodies spans fewer cells (the "
            f"largest {cells.max():.2f}), so the flow would meet no body at all; the threshold "
            "is for the rocks too small for the grid, below the bodies the flow should see")
    if len(free) and cells[free].max() < threshold:
        rocks = (f"; the fixed bodies span {cells[fixed].min():.2f}-{cells[fixed].max():.2f}"
                 if fixed.any() else "")
        raise CaseFileError(
            f"{key} = {threshold:g}: every free body spans fewer cells too (the largest "
            f"{cells[free].max():.2f}{rocks}): the threshold classes the units as too small for "
            "the grid as well, and they are never contact-only; give one between the fixed "
            "rocks' size and the free bodies' (in cells of the fluid grid)")
    layer = FilterLayer(threshold=threshold, bodies=chosen, sizes=cells[chosen])
    if not len(chosen):
        return layer
    zones = list(zones)
    samples = _tet_samples(solver, chosen, poses)
    covered = _union_shares(samples, zones) >= COVERED_SHARE if zones else np.zeros(len(chosen),
                                                                                     dtype=bool)
    if zones and covered.any():
        shares = _shares([samples[k] for k in np.flatnonzero(covered)], zones)
        layer.covering = [zone.name for z, zone in enumerate(zones) if shares[:, z].max() > 0.0]
    if not covered.all():
        layer.fitted, layer.filled = fit_filter_zones(
            solver, chosen[~covered], cell_size=cell_size, poses=poses,
            name=f"the filter zone fitted to the {int((~covered).sum())} contact-only bodies"
                 + (" the [[porous_zones]] leave out" if covered.any() else ""))
    filters = [zone for zone in zones if zone.name in layer.covering] + layer.fitted
    if len(free) and filters:
        shares = _shares(_tet_samples(solver, free, poses), filters)
        body, zone = np.unravel_index(int(np.argmax(shares)), shares.shape)
        if shares[body, zone] > MAXIMUM_FREE_BODY_SHARE:
            offending = filters[zone]
            fix = ("draw it down to the rocks' top" if offending not in layer.fitted else
                   "give the filter as a [[porous_zones]] entry below the units instead of "
                   "this fitted one:\n" + zone_toml(offending))
            raise CaseFileError(
                f"{offending.name}: this porous filter zone holds {shares[body, zone]:.2f} of "
                f"free body {int(free[body])} (more than {MAXIMUM_FREE_BODY_SHARE:g}; "
                f"{int((shares[:, zone] > MAXIMUM_FREE_BODY_SHARE).sum())} free bodies in all): "
                "a filter zone covers the contact-only rocks, not the units resting on them; "
                + fix)
    return layer
