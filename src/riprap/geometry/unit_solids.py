"""The solids of riprap's armour unit kinds, built with gmsh's OpenCASCADE kernel.

Every shape is one solid made from planar-faced primitives (boxes, straight frusta with polygonal
cross-sections and convex hulls), fused or cut. Legs grow out of a hub, the convex hull of their
root sections, so that they meet the body face to face. Because every face is planar, the meshed
body is exactly the built solid. Round legs (the Tetrapod) are regular octagonal frusta with the
same cross-section area as the round legs. The frames of each kind are listed in
:func:`riprap.geometry.armour_units.add_unit_solid`; the proportions below are riprap's own
approximations of the published descriptions cited in :mod:`riprap.geometry.armour_units`.

One ``build_<kind>(occ, height)`` per kind; :mod:`riprap.geometry.unit_kinds` joins each to the
rest of its kind's record.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_SQRT2 = float(np.sqrt(2.0))

# --- Antifer cube (ricbencar/breakwater-cubes-calculator: A = 1.086 H, B = 1.005 H,
# V = 1.0247 H^3). The grooves are riprap's own: one vertical groove in the middle of each side
# face, trapezoidal with 45-degree flanks, depth d = 0.08 H; its width at the face is set so that
# the four grooves remove exactly the volume between the plain frustum (1.09395 H^3) and
# 1.0247 H^3: d (w - d) = 0.0173126 H^2.
_ANTIFER_BASE_WIDTH = 1.086
_ANTIFER_TOP_WIDTH = 1.005
ANTIFER_VOLUME_COEFFICIENT = 1.0247
_ANTIFER_GROOVE_DEPTH = 0.08

# --- Tetrapod: the legs of shapes.tetrapod (riprap's own proportions, documented there: leg
# diameter 0.4 H at the centre, 0.6 of that at the flat tip, standing height H), built as regular
# octagonal frusta of the same cross-section area (and 0.7 % shorter, so that the octagonal unit
# stands exactly H tall). Instead of four legs overlapping at the centre
# (whose many short intersection edges force boundary elements a few hundredths of the median
# size), each leg starts at the distance of one base radius from the centre and the centre is the
# convex hull of the four leg sections there: every leg meets the core face to face.
_TETRAPOD_LEG_DIAMETER = 0.4
_TETRAPOD_TIP_TO_BASE = 0.6
_TETRAPOD_CORE_DISTANCE = 1.0  # x base radius
_TETRAPOD_SIDES = 8

# --- CORE-LOC-like (riprap's own proportions after US patent 5,441,362): a trunk along x and two
# parallel flukes along z, all of regular octagonal section (two flats normal to x or z). Each
# fluke is a prism 0.36 H long and 0.32 H across flats in the middle with a frustum on each end
# tapering to 0.22 H at the tips, H tip to tip; the trunk is a prism 0.32 H across flats. Trunk and
# fluke meet in a convex hull of the fluke's middle prism and the trunk's end section (standing in
# for the chamfers of claims 4-5). The flukes' outer faces span H: the unit fits H x H x 0.32 H.
_CORE_LOC_MIDDLE_WIDTH = 0.32
_CORE_LOC_END_WIDTH = 0.22
_CORE_LOC_FLUKE_PRISM = 0.36
_CORE_LOC_TRUNK_PRISM = 0.16

# --- ACCROPODE-like (riprap's own): a lower horn pair along x and an upper horn pair along y
# (square frusta, tip to tip H, width b0 at the root, 0.65 b0 at the tips), vertically offset by
# +-0.32 b0, and a nose along +z and -z (square frusta, 0.7 b0 to 0.42 b0, tips at +-H/2), all
# growing out of the convex hull of their root sections; the unit fits an H x H x H box. The horn
# width b0 is tuned so that V = 0.34 H^3 (CLI 2012 design table).
_ACCROPODE_HORN_WIDTH = 0.45853
_ACCROPODE_HORN_TIP_TO_BASE = 0.65
_ACCROPODE_HORN_OFFSET = 0.32   # x b0
_ACCROPODE_HORN_ROOT = 0.5      # root section's distance from the z axis, x b0
_ACCROPODE_NOSE_BASE = 0.7      # x b0
_ACCROPODE_NOSE_TIP_TO_BASE = 0.6
_ACCROPODE_NOSE_ROOT = 0.6      # nose root above the upper horn axis, x b0

# --- Xbloc-like (riprap's own, after Xbloc's "two sets of legs and a central body"): an upper leg
# pair along x and a lower pair along y, straight prisms of diamond section (a square of side a
# with corners up and down), tip to tip H, placed so that the unit fits an H x H x H box, growing
# out of the convex hull of their root sections (the body). The side a is tuned so that
# V = 0.335 H^3 (DMC 2018 Table 1 as derived in armour_design.md, with H = the unit height D).
_XBLOC_LEG_SIDE = 0.38293
_XBLOC_LEG_ROOT = 0.2           # root section's distance from the z axis, x H


# ---------------------------------------------------------------- OpenCASCADE primitives
@dataclass(frozen=True)
class _Leg:
    """A straight leg: regular-polygon sections (circumradii) at ``root`` and ``tip``.

    The first polygon corner lies at angle ``roll`` from ``reference`` made perpendicular to the
    axis. Root and tip sections are similar and parallel, so the lateral faces are planar.
    """

    root: np.ndarray
    tip: np.ndarray
    root_radius: float
    tip_radius: float
    sides: int
    reference: np.ndarray
    roll: float = 0.0

    def section(self, at_tip: bool) -> np.ndarray:
        """Corners of the root (or tip) polygon, shape (sides, 3)."""
        axis = (self.tip - self.root) / np.linalg.norm(self.tip - self.root)
        u, v = _perpendicular_frame(axis, self.reference)
        centre, radius = (self.tip, self.tip_radius) if at_tip else (self.root, self.root_radius)
        angles = self.roll + 2.0 * np.pi * np.arange(self.sides) / self.sides
        return centre + radius * (np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * v)


def _square_leg(root, tip, root_width, tip_width, reference) -> _Leg:
    """Square-section leg whose side faces are normal to ``reference`` and to axis x reference."""
    return _Leg(np.asarray(root, float), np.asarray(tip, float), root_width / _SQRT2,
                tip_width / _SQRT2, 4, np.asarray(reference, float), roll=np.pi / 4.0)


def _octagon_leg(root, tip, root_width, tip_width, reference) -> _Leg:
    """Regular octagonal leg, widths across flats, two flats normal to ``reference``."""
    to_circumradius = 1.0 / (2.0 * np.cos(np.pi / 8.0))
    return _Leg(np.asarray(root, float), np.asarray(tip, float), root_width * to_circumradius,
                tip_width * to_circumradius, 8, np.asarray(reference, float), roll=np.pi / 8.0)


def _perpendicular_frame(axis: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors u, v completing ``axis``; u is ``reference`` made perpendicular to ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    u = np.asarray(reference, dtype=float) - np.dot(reference, axis) * axis
    u /= np.linalg.norm(u)
    return u, np.cross(axis, u)


def _add_polygon_wire(occ, corners: np.ndarray) -> int:
    points = [occ.addPoint(*corner) for corner in corners]
    lines = [occ.addLine(points[k], points[(k + 1) % len(points)]) for k in range(len(points))]
    return occ.addWire(lines)


def _add_leg(occ, leg: _Leg) -> list[tuple[int, int]]:
    wires = [_add_polygon_wire(occ, leg.section(at_tip)) for at_tip in (False, True)]
    return occ.addThruSections(wires, makeSolid=True, makeRuled=True)


def _add_convex_polyhedron(occ, points: np.ndarray) -> list[tuple[int, int]]:
    """The convex hull of ``points`` as one OpenCASCADE solid with planar polygonal faces."""
    from scipy.spatial import ConvexHull

    points = np.asarray(points, dtype=float)
    hull = ConvexHull(points)
    scale = float(np.abs(points).max())
    point_tags = {int(i): occ.addPoint(*points[i]) for i in np.unique(hull.simplices)}
    line_tags: dict[tuple[int, int], int] = {}

    def line(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in line_tags:
            line_tags[key] = occ.addLine(point_tags[key[0]], point_tags[key[1]])
        return line_tags[key] if (a, b) == key else -line_tags[key]

    # Hull triangles in one plane (unit normals and offsets equal to 1e-9 of the size) form one
    # polygonal face.
    planes: list[np.ndarray] = []
    faces: list[set[int]] = []
    for simplex, equation in zip(hull.simplices, hull.equations):
        plane = equation / np.array([1.0, 1.0, 1.0, scale])
        for k, known in enumerate(planes):
            if np.abs(known - plane).max() <= 1e-9:
                faces[k].update(int(i) for i in simplex)
                break
        else:
            planes.append(plane)
            faces.append({int(i) for i in simplex})
    surfaces = []
    for plane, vertex_set in zip(planes, faces):
        vertices = np.array(sorted(vertex_set))
        centre = points[vertices].mean(axis=0)
        u, v = _perpendicular_frame(plane[:3], points[vertices[0]] - centre)
        offsets = points[vertices] - centre
        loop = vertices[np.argsort(np.arctan2(offsets @ v, offsets @ u))]
        curves = [line(int(loop[k]), int(loop[(k + 1) % len(loop)])) for k in range(len(loop))]
        surfaces.append(occ.addPlaneSurface([occ.addCurveLoop(curves)]))
    return [(3, occ.addVolume([occ.addSurfaceLoop(surfaces)]))]


def _add_hub(occ, legs: list[_Leg]) -> list[tuple[int, int]]:
    """The convex hull of the legs' root sections: the body the legs grow out of.

    Each root section is a face of the hull (the legs point away from it), so every leg meets the
    body face to face. Where legs are instead fused through each other, their faces cross at
    arbitrary angles and leave intersection edges a few thousandths of H long, which force
    boundary elements far thinner than the rest (and a tiny contact time step).
    """
    return _add_convex_polyhedron(occ, np.concatenate([leg.section(False) for leg in legs]))


def _fuse_all(occ, parts) -> None:
    parts = list(parts)
    occ.fuse(parts[:1], parts[1:])


# ---------------------------------------------------------------- the six shapes
def build_cube(occ, height: float) -> None:
    h = height
    occ.addBox(-h / 2, -h / 2, -h / 2, h, h, h)


def _antifer_groove_area() -> float:
    """Horizontal cross-section of one groove / H^2 that gives V = 1.0247 H^3."""
    base, top = _ANTIFER_BASE_WIDTH, _ANTIFER_TOP_WIDTH
    plain = (base**2 + base * top + top**2) / 3.0
    return (plain - ANTIFER_VOLUME_COEFFICIENT) / 4.0


def build_antifer_cube(occ, height: float) -> None:
    h = height
    base, top = _ANTIFER_BASE_WIDTH * h, _ANTIFER_TOP_WIDTH * h
    block = _add_leg(occ, _square_leg((0, 0, -h / 2), (0, 0, h / 2), base, top, (1.0, 0.0, 0.0)))
    depth = _ANTIFER_GROOVE_DEPTH * h
    width = depth + _antifer_groove_area() * h**2 / depth
    # The cutter's cross-section is the same trapezoid at every height, moved with the tapering
    # face, so each groove removes exactly depth (width - depth) per unit height. It reaches
    # `margin` past the face, the top and the bottom so that no cutter face is coplanar with a
    # block face.
    margin = 0.05 * h
    slope = (top - base) / (2.0 * h)  # d(half width) / dz
    cutters = []
    for angle in (0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi):
        normal = np.array([np.cos(angle), np.sin(angle), 0.0])
        along = np.array([-np.sin(angle), np.cos(angle), 0.0])
        wires = []
        for z in (-h / 2 - margin, h / 2 + margin):
            face = base / 2 + slope * (z + h / 2)
            corners = [(face + margin, width / 2 + margin), (face - depth, width / 2 - depth),
                       (face - depth, -width / 2 + depth), (face + margin, -width / 2 - margin)]
            points = np.array([n * normal + t * along + z * np.array([0.0, 0.0, 1.0])
                               for n, t in corners])
            wires.append(_add_polygon_wire(occ, points))
        cutters.extend(occ.addThruSections(wires, makeSolid=True, makeRuled=True))
    occ.cut(block, cutters)


def tetrapod_legs(height: float) -> tuple[list[np.ndarray], float, float, float]:
    """Leg directions, leg length (centre to tip face) and octagon circumradii at centre and tip.

    The radii are those of shapes.tetrapod's round legs scaled to octagons of equal area. The leg
    length makes the unit standing on three legs exactly ``height`` tall: the top tip face is at
    ``L`` and the lowest corner of a lower tip at ``-L/3 - R_tip 2 sqrt(2)/3`` (each lower tip's
    first corner points at +z, so the opposite corner is the lowest).
    """
    sides = _TETRAPOD_SIDES
    equal_area = np.sqrt(2.0 * np.pi / (sides * np.sin(2.0 * np.pi / sides)))
    base_radius = equal_area * 0.5 * _TETRAPOD_LEG_DIAMETER * height
    tip_radius = _TETRAPOD_TIP_TO_BASE * base_radius
    leg_length = 0.75 * (height - tip_radius * 2.0 * _SQRT2 / 3.0)
    polar = np.arccos(-1.0 / 3.0)
    directions = [np.array([0.0, 0.0, 1.0])] + [
        np.array([np.sin(polar) * np.cos(a), np.sin(polar) * np.sin(a), np.cos(polar)])
        for a in (0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0)
    ]
    return directions, leg_length, base_radius, tip_radius


def build_tetrapod(occ, height: float) -> None:
    directions, length, base_radius, tip_radius = tetrapod_legs(height)
    start = _TETRAPOD_CORE_DISTANCE * base_radius
    start_radius = base_radius - (base_radius - tip_radius) * start / length
    # Each leg's first corner points towards another leg (leg 0 for the lower legs), so the unit
    # keeps its 3-fold symmetry about z.
    legs = [_Leg(start * d, length * d, start_radius, tip_radius, _TETRAPOD_SIDES,
                 directions[1] if k == 0 else directions[0]) for k, d in enumerate(directions)]
    _fuse_all(occ, _add_hub(occ, legs) + [part for leg in legs for part in _add_leg(occ, leg)])


def build_core_loc_like(occ, height: float) -> None:
    h = height
    middle, tip = _CORE_LOC_MIDDLE_WIDTH * h, _CORE_LOC_END_WIDTH * h
    fluke_x = 0.5 * (h - middle)
    half_prism = 0.5 * _CORE_LOC_FLUKE_PRISM * h
    trunk_end = 0.5 * _CORE_LOC_TRUNK_PRISM * h
    x_axis, _, z_axis = np.eye(3)
    parts = []
    for sign in (1.0, -1.0):
        centre = np.array([sign * fluke_x, 0.0, 0.0])
        # a hub: the fluke's middle prism and the trunk's end, joined by their convex hull (the
        # chamfered junction of claims 4-5)
        ends = [_octagon_leg(centre + s * half_prism * z_axis, centre + s * 0.5 * h * z_axis,
                             middle, tip, x_axis) for s in (1.0, -1.0)]
        trunk = _octagon_leg(np.array([sign * trunk_end, 0.0, 0.0]), np.zeros(3), middle, middle,
                             z_axis)
        parts += _add_hub(occ, ends + [trunk])
        parts += [part for leg in ends for part in _add_leg(occ, leg)]
    trunk = _octagon_leg((-trunk_end, 0, 0), (trunk_end, 0, 0), middle, middle, z_axis)
    parts += _add_leg(occ, trunk)
    _fuse_all(occ, parts)


def build_accropode_like(occ, height: float) -> None:
    h = height
    horn = _ACCROPODE_HORN_WIDTH * h
    horn_tip = _ACCROPODE_HORN_TIP_TO_BASE * horn
    offset = _ACCROPODE_HORN_OFFSET * horn
    root = _ACCROPODE_HORN_ROOT * horn
    nose = _ACCROPODE_NOSE_BASE * horn
    nose_tip = _ACCROPODE_NOSE_TIP_TO_BASE * nose
    nose_root = offset + _ACCROPODE_NOSE_ROOT * horn
    x_axis, y_axis, z_axis = np.eye(3)
    legs = []
    for axis, z in ((x_axis, -offset), (y_axis, offset)):
        for sign in (1.0, -1.0):
            centre = z * z_axis
            legs.append(_square_leg(centre + sign * root * axis, centre + sign * 0.5 * h * axis,
                                    horn, horn_tip, z_axis))
    for sign in (1.0, -1.0):
        legs.append(_square_leg(sign * nose_root * z_axis, sign * 0.5 * h * z_axis, nose, nose_tip,
                                x_axis))
    _fuse_all(occ, _add_hub(occ, legs) + [part for leg in legs for part in _add_leg(occ, leg)])


def build_xbloc_like(occ, height: float) -> None:
    h = height
    side = _XBLOC_LEG_SIDE * h
    half_diagonal = side / _SQRT2
    offset = 0.5 * h - half_diagonal
    root = _XBLOC_LEG_ROOT * h
    x_axis, y_axis, z_axis = np.eye(3)
    legs = []
    for axis, z in ((x_axis, offset), (y_axis, -offset)):
        for sign in (1.0, -1.0):
            # square section with corners pointing along +-z: the diamond
            legs.append(_Leg(z * z_axis + sign * root * axis, z * z_axis + sign * 0.5 * h * axis,
                             half_diagonal, half_diagonal, 4, z_axis))
    _fuse_all(occ, _add_hub(occ, legs) + [part for leg in legs for part in _add_leg(occ, leg)])


