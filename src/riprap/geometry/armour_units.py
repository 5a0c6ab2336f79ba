"""Concrete armour units for breakwater armour layers, as tetrahedral meshes.

Six kinds (``UNIT_KINDS``): ``"core_loc_like"``, ``"accropode_like"``, ``"xbloc_like"``,
``"tetrapod"``, ``"cube"`` and ``"antifer_cube"``. CORE-LOC, ACCROPODE, Xbloc and Tetrapod are
registered trademarks; the shapes built here are riprap's own approximations of them, made from
the published descriptions listed below, not from the licensed drawings (which riprap does not
have). Where a published volume-to-height ratio ``V / H^3`` was found, riprap's proportions are
chosen so that the built solid has it; every other proportion is riprap's own choice and is said
to be so. Do not use these shapes to check a real unit's structural strength.

Every shape is one solid built with gmsh's OpenCASCADE kernel from planar-faced primitives
(boxes, straight frusta with polygonal cross-sections and convex hulls), fused or cut, and meshed
with :func:`~riprap.geometry.meshing.mesh_occ_shape`. Legs grow out of a hub, the convex hull of
their root sections, so that they meet the body face to face. Because every face is planar, the
meshed body is exactly the built solid: its volume, centroid and inertia equal OpenCASCADE's to
round-off (the verification test checks this). Round legs (the Tetrapod) are therefore built as
regular octagonal frusta with the same cross-section area as the round legs.

Frames. Each unit is built in its own frame, stated per kind in :func:`add_unit_solid`: the origin
is the unit's centre of symmetry (the centroid too, except for the tapered Antifer cube, whose
centroid lies 0.0138 H below it, and the Tetrapod, whose octagonal leg 0 breaks the 3-fold
symmetry by 1.2e-4 H), and the named axes (``ArmourUnit.axes``) are unit vectors of that frame.

Design data (``UnitDesign``) come from ``shared/validation/armour_design.md`` section 5.2 and the
sources cited there, except the ACCROPODE packing density and porosity (CLI design table, cited)
and the CORE-LOC porosity and packing density, which were not found and are derived (stated in the
unit's ``design.note``).

References
----------
Turk, G. F., Melby, J. A. (1997). CORE-LOC concrete armor units: technical guidelines. USACE WES
Miscellaneous Paper CHL-97-6.
Melby, J. A., Turk, G. F. (1995). Concrete armor unit to protect coastal and hydraulic structures
and shorelines. US patent 5,441,362 (claims 1-6: a central elongate member and two outer elongate
members with parallel axes normal to it, each of octagonal cross-section tapering from the middle
to both ends, i.e. two frustums joined at their bases, all of equal length).
Concrete Layer Innovations (2012). ACCROPODE design guide table (V = 0.34 H^3, T = 1.29 Dn,
packing density 0.645 to 0.625, porosity 50 to 51.6 %).
Delta Marine Consultants (2018). Xbloc design guidelines, Table 1 (V, D, h, Vc; V = 0.335 D^3
derived in armour_design.md).
ricbencar/breakwater-cubes-calculator (GitHub, 2025), Antifer block geometry factors: base width
1.086 H, top width 1.005 H, V = 1.0247 H^3 (primary source not given there).
"""
from __future__ import annotations

import difflib
import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, MeshError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.meshing import (
    MAX_BODY_LENGTH,
    MIN_BODY_LENGTH,
    check_body_length,
    check_tetrahedron_estimate,
    mesh_occ_shape,
)
from riprap.geometry.tetmesh import TetMesh

UNIT_KINDS = ("core_loc_like", "accropode_like", "xbloc_like", "tetrapod", "cube", "antifer_cube")

# Published design values are rounded to 2-3 digits, so phi = layers k_t (1 - n_v) is checked to
# this relative tolerance (the cube's 2 x 1.10 x 0.53 = 1.166 is published as 1.17).
_PACKING_CONSISTENCY = 0.005

_SQRT2 = float(np.sqrt(2.0))

# --- Antifer cube (ricbencar/breakwater-cubes-calculator: A = 1.086 H, B = 1.005 H,
# V = 1.0247 H^3). The grooves are riprap's own: one vertical groove in the middle of each side
# face, trapezoidal with 45-degree flanks, depth d = 0.08 H; its width at the face is set so that
# the four grooves remove exactly the volume between the plain frustum (1.09395 H^3) and
# 1.0247 H^3: d (w - d) = 0.0173126 H^2.
_ANTIFER_BASE_WIDTH = 1.086
_ANTIFER_TOP_WIDTH = 1.005
_ANTIFER_VOLUME_COEFFICIENT = 1.0247
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

# Default element size as a fraction of H: the smallest feature is resolved and the meshes have
# roughly 500-2500 tetrahedra (counts measured with gmsh 4.15, listed in docs/armour-units.md).
_DEFAULT_MESH_SIZE_OVER_HEIGHT = {
    "core_loc_like": 0.11,
    "accropode_like": 0.14,
    "xbloc_like": 0.14,
    "tetrapod": 0.12,
    "cube": 1.0 / 3.8,
    "antifer_cube": 0.25,
}


@dataclass(frozen=True)
class UnitDesign:
    """Reference armour-layer data of one unit kind.

    Attributes
    ----------
    layers : int
        Number of armour layers ``n`` the coefficients belong to.
    layer_thickness_coefficient : float
        ``k_t`` in ``t = n k_t D_n`` (layer thickness, m).
    porosity : float
        Bulk porosity ``n_v`` of the armour layer (0-1).
    packing_density_coefficient : float
        ``phi = n k_t (1 - n_v)``; units per area ``N_a / A = phi / D_n^2``.
    source : str
        Full citation of the values.
    note : str
        How each value was obtained (published, derived, assumed).
    """

    layers: int
    layer_thickness_coefficient: float
    porosity: float
    packing_density_coefficient: float
    source: str
    note: str = ""

    def __post_init__(self) -> None:
        if int(self.layers) != self.layers or self.layers < 1:
            raise CaseFileError(f"UnitDesign: layers must be a positive integer, got {self.layers}")
        thickness = self.layer_thickness_coefficient
        if not (np.isfinite(thickness) and thickness > 0.0):
            raise CaseFileError(
                f"UnitDesign: layer_thickness_coefficient must be positive, got "
                f"{self.layer_thickness_coefficient}"
            )
        if not 0.0 < self.porosity < 1.0:
            raise CaseFileError(f"UnitDesign: porosity must lie in (0, 1), got {self.porosity}")
        implied = self.layers * self.layer_thickness_coefficient * (1.0 - self.porosity)
        if abs(self.packing_density_coefficient - implied) > _PACKING_CONSISTENCY * implied:
            raise CaseFileError(
                f"UnitDesign: packing_density_coefficient = {self.packing_density_coefficient} "
                f"differs from layers x k_t x (1 - porosity) = {implied:.4f} by more than "
                f"{100 * _PACKING_CONSISTENCY:g} %"
            )


_ARMOUR_DESIGN_MD = "shared/validation/armour_design.md section 5.2"

_DESIGNS = {
    "cube": UnitDesign(
        layers=2,
        layer_thickness_coefficient=1.10,
        porosity=0.47,
        packing_density_coefficient=1.166,
        source=(
            "CIRIA, CUR, CETMEF (2007). The Rock Manual (C683), p. 260; Deltares coastal-"
            "structures-toolbox cubes_double_layer_vandermeer1988.py (k_t, n_v); via "
            f"{_ARMOUR_DESIGN_MD}"
        ),
        note="k_t and n_v published (double layer, random); phi computed (1.17 in the table)",
    ),
    "antifer_cube": UnitDesign(
        layers=2,
        layer_thickness_coefficient=1.10,
        porosity=0.47,
        packing_density_coefficient=1.166,
        source=(
            "CIRIA, CUR, CETMEF (2007). The Rock Manual (C683), p. 260 (cubes, double layer); "
            f"via {_ARMOUR_DESIGN_MD}"
        ),
        note=(
            "no Antifer-specific values in the sources read; the double-layer cube values are "
            "used (the Antifer is a grooved, slightly tapered cube placed in two layers)"
        ),
    ),
    "tetrapod": UnitDesign(
        layers=2,
        layer_thickness_coefficient=1.02,
        porosity=0.50,
        packing_density_coefficient=1.02,
        source=(
            "Hudson (1959) / The Rock Manual (2007) values as coded in Deltares coastal-"
            f"structures-toolbox tetrapods_hudson1959.py; via {_ARMOUR_DESIGN_MD}"
        ),
        note="k_t and n_v published; phi computed",
    ),
    "accropode_like": UnitDesign(
        layers=1,
        layer_thickness_coefficient=1.29,
        porosity=0.50,
        packing_density_coefficient=0.645,
        source=(
            "Concrete Layer Innovations (2012). ACCROPODE design guide table (unit volume "
            "V = 0.34 H^3, armour thickness T = 1.29 Dn, packing density 0.645 and porosity "
            "50.0 % for V = 1-3 m^3, falling to 0.625 and 51.6 % for V >= 16 m^3)"
        ),
        note="published for small units (V <= 3 m^3); 0.625 / 0.516 for V >= 16 m^3",
    ),
    "core_loc_like": UnitDesign(
        layers=1,
        layer_thickness_coefficient=1.516,
        porosity=0.60,
        packing_density_coefficient=0.6064,
        source=(
            "k_t: Concrete Layer Innovations CORE-LOC design table 2012 as coded in Deltares "
            "coastal-structures-toolbox core_loc_hudson1959.py (1.52 in the Rock Manual list); "
            f"via {_ARMOUR_DESIGN_MD}. Porosity: assumed, see note"
        ),
        note=(
            "no published CORE-LOC porosity or packing density was found in the sources read "
            "(Turk & Melby 1997 CHL-97-6 has a packing density section, not readable here); "
            "porosity 0.60 is assumed (the value usually tabulated for CORE-LOC in USACE design "
            "tables, not verified here) and phi = 1 x 1.516 x (1 - 0.60) = 0.606 is derived"
        ),
    ),
    "xbloc_like": UnitDesign(
        layers=1,
        layer_thickness_coefficient=1.40,
        porosity=0.586,
        packing_density_coefficient=0.58,
        source=(
            "Delta Marine Consultants (2018). Xbloc design guidelines, Table 1 (V, D, h, Vc), "
            f"as coded in Sander-w/breakwater material.py; via {_ARMOUR_DESIGN_MD}"
        ),
        note=(
            "k_t = h / Dn and phi = Vc / Dn derived from the DMC table in armour_design.md; "
            "porosity = 1 - phi / k_t (0.59 there)"
        ),
    ),
}

# Published V / H^3 each riprap shape is tuned to (kinds not listed have none found).
PUBLISHED_VOLUME_COEFFICIENTS = {
    "cube": 1.0,
    "antifer_cube": _ANTIFER_VOLUME_COEFFICIENT,
    "accropode_like": 0.34,
    "xbloc_like": 0.335,
}


@dataclass(frozen=True, eq=False)
class ArmourUnit:
    """One armour unit: its mesh, size, named axes and reference design data.

    Attributes
    ----------
    kind : str
        One of ``UNIT_KINDS``.
    mesh : TetMesh
        The unit in its own frame (origin at the centre of symmetry, see :func:`add_unit_solid`).
    height : float
        Characteristic height ``H`` in m as the unit's design guidance uses it (for the cube the
        side, for the Tetrapod the height standing on three legs).
    nominal_diameter : float
        ``D_n = volume ** (1/3)`` in m.
    volume : float
        Volume of the mesh in m^3 (equal to the built solid's; every face is planar).
    axes : dict of str to numpy.ndarray
        Named unit vectors (shape (3,)) in the mesh frame; ``"nose"`` is always present.
    design : UnitDesign
        Reference layer thickness coefficient, porosity and packing density coefficient.
    """

    kind: str
    mesh: TetMesh
    height: float
    nominal_diameter: float
    volume: float
    axes: dict[str, np.ndarray]
    design: UnitDesign

    @property
    def volume_coefficient(self) -> float:
        """``V / H^3`` of this unit."""
        return self.volume / self.height**3

    def mass(self, density: float) -> float:
        """Mass in kg for a concrete density in kg/m^3."""
        density = _positive(density, "density", f"ArmourUnit({self.kind})", unit="kg/m^3")
        return density * self.volume


def _positive(value: float, parameter: str, where: str, unit: str = "m") -> float:
    if isinstance(value, (bool, np.bool_)):
        raise CaseFileError(f"{where}: {parameter} must be a number in {unit}, got {value!r}")
    try:
        value = float(value)
    except (TypeError, ValueError) as error:
        raise CaseFileError(
            f"{where}: {parameter} must be a number in {unit}, got {value!r}"
        ) from error
    if not (np.isfinite(value) and value > 0.0):
        raise CaseFileError(
            f"{where}: {parameter} must be positive and finite in {unit}, got {value}"
        )
    return value


def _check_kind(kind: str) -> str:
    if isinstance(kind, str) and kind in UNIT_KINDS:
        return kind
    spelled = str(kind).strip().lower().replace("-", "_").replace(" ", "_")
    close = difflib.get_close_matches(spelled, UNIT_KINDS, n=1, cutoff=0.5)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    raise CaseFileError(
        f"armour unit kind '{kind}' is unknown; the kinds are {', '.join(UNIT_KINDS)}{hint}"
    )


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
def _build_cube(occ, height: float) -> None:
    h = height
    occ.addBox(-h / 2, -h / 2, -h / 2, h, h, h)


def _antifer_groove_area() -> float:
    """Horizontal cross-section of one groove / H^2 that gives V = 1.0247 H^3."""
    base, top = _ANTIFER_BASE_WIDTH, _ANTIFER_TOP_WIDTH
    plain = (base**2 + base * top + top**2) / 3.0
    return (plain - _ANTIFER_VOLUME_COEFFICIENT) / 4.0


def _build_antifer_cube(occ, height: float) -> None:
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


def _tetrapod_legs(height: float) -> tuple[list[np.ndarray], float, float, float]:
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


def _build_tetrapod(occ, height: float) -> None:
    directions, length, base_radius, tip_radius = _tetrapod_legs(height)
    start = _TETRAPOD_CORE_DISTANCE * base_radius
    start_radius = base_radius - (base_radius - tip_radius) * start / length
    # Each leg's first corner points towards another leg (leg 0 for the lower legs), so the unit
    # keeps its 3-fold symmetry about z.
    legs = [_Leg(start * d, length * d, start_radius, tip_radius, _TETRAPOD_SIDES,
                 directions[1] if k == 0 else directions[0]) for k, d in enumerate(directions)]
    _fuse_all(occ, _add_hub(occ, legs) + [part for leg in legs for part in _add_leg(occ, leg)])


def _build_core_loc_like(occ, height: float) -> None:
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


def _build_accropode_like(occ, height: float) -> None:
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


def _build_xbloc_like(occ, height: float) -> None:
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


_BUILDERS: dict[str, Callable[[object, float], None]] = {
    "cube": _build_cube,
    "antifer_cube": _build_antifer_cube,
    "tetrapod": _build_tetrapod,
    "core_loc_like": _build_core_loc_like,
    "accropode_like": _build_accropode_like,
    "xbloc_like": _build_xbloc_like,
}


def add_unit_solid(occ: object, kind: str, *, height: float) -> None:
    """Add the solid of one unit to the current gmsh OpenCASCADE model.

    Frames (origin at the centre of symmetry, lengths in m, ``H = height``):

    - ``cube``: side H, faces normal to x, y, z.
    - ``antifer_cube``: square frustum, base ``1.086 H`` wide at ``z = -H/2``, top ``1.005 H`` at
      ``z = +H/2``, side faces normal to (nearly) x and y, each with one vertical trapezoidal
      groove (depth 0.08 H, 45-degree flanks).
    - ``tetrapod``: four octagonal legs along the directions of a regular tetrahedron from the
      origin, leg 0 along +z (as ``shapes.tetrapod``); standing on three legs it is H tall.
    - ``core_loc_like``: trunk along x, two parallel flukes along z at ``x = +-(H - 0.32 H)/2``;
      fits an H x H x 0.32 H box.
    - ``accropode_like``: lower horn pair along x at ``z = -0.147 H``, upper pair along y at
      ``z = +0.147 H``, noses along +-z; fits an H x H x H box.
    - ``xbloc_like``: upper leg pair along x, lower pair along y, joined by their hull (the body);
      fits an H x H x H box.

    Parameters
    ----------
    occ : gmsh.model.occ
        The OpenCASCADE kernel of the current gmsh model.
    kind : str
        One of ``UNIT_KINDS``.
    height : float
        Unit height H in metres.
    """
    kind = _check_kind(kind)
    height = check_body_length(height, "height", f"armour unit '{kind}'")
    _BUILDERS[kind](occ, height)


@functools.lru_cache(maxsize=None)
def volume_coefficient(kind: str) -> float:
    """``V / H^3`` of riprap's shape of this kind, from OpenCASCADE (computed once, cached).

    Parameters
    ----------
    kind : str
        One of ``UNIT_KINDS``.

    Returns
    -------
    float
        Volume in m^3 of the unit of height 1 m (the meshed unit has the same volume: every
        face is planar).
    """
    kind = _check_kind(kind)
    properties = occ_mass_properties(kind, height=1.0)
    return properties["volume"]


def occ_mass_properties(kind: str, *, height: float) -> dict[str, object]:
    """Volume, centroid and inertia tensor of the built solid, computed by OpenCASCADE.

    This integrates over the exact boundary representation (independently of any mesh), so it
    is the reference the meshed unit is checked against.

    Parameters
    ----------
    kind : str
        One of ``UNIT_KINDS``.
    height : float
        Unit height H in m.

    Returns
    -------
    dict
        ``"volume"`` (m^3), ``"centroid"`` (numpy.ndarray (3,), m, unit frame) and
        ``"inertia_tensor"`` (numpy.ndarray (3, 3), m^5: the inertia tensor about the centroid
        per unit density).
    """
    from riprap.geometry.meshing import _gmsh_session

    kind = _check_kind(kind)
    height = check_body_length(height, "height", f"armour unit '{kind}'")
    with _gmsh_session(f"occ_mass_properties({kind})") as gmsh:
        occ = gmsh.model.occ
        add_unit_solid(occ, kind, height=height)
        occ.removeAllDuplicates()
        occ.synchronize()
        solids = gmsh.model.getEntities(3)
        if len(solids) != 1:
            raise MeshError(f"armour unit '{kind}' built {len(solids)} solids instead of one")
        tag = solids[0][1]
        return {
            "volume": float(occ.getMass(3, tag)),
            "centroid": np.array(occ.getCenterOfMass(3, tag), dtype=np.float64),
            "inertia_tensor": np.reshape(np.array(occ.getMatrixOfInertia(3, tag), dtype=np.float64),
                                         (3, 3)),
        }


def unit_axes(kind: str) -> dict[str, np.ndarray]:
    """Named unit vectors of a kind in its mesh frame (see :func:`add_unit_solid`).

    ``"nose"`` is the axis riprap uses for orientation statistics: the trunk of the
    CORE-LOC-like unit, the vertical (nose) axis of the ACCROPODE-like and Xbloc-like units and
    of both cubes, and leg 0 of the Tetrapod. These are riprap's conventions; the seed paper
    (Xiang et al. 2012) plots CORE-LOC "nose axes" without defining them in the text read here.
    """
    kind = _check_kind(kind)
    x_axis, y_axis, z_axis = np.eye(3)
    if kind in ("cube", "antifer_cube"):
        axes = {"nose": z_axis, "face_x": x_axis, "face_y": y_axis}
    elif kind == "tetrapod":
        directions = _tetrapod_legs(1.0)[0]
        axes = {"nose": directions[0]}
        axes.update({f"leg_{k}": directions[k] for k in (1, 2, 3)})
    elif kind == "core_loc_like":
        axes = {"nose": x_axis, "trunk": x_axis, "fluke": z_axis}
    elif kind == "accropode_like":
        axes = {"nose": z_axis, "lower_horns": x_axis, "upper_horns": y_axis}
    else:
        axes = {"nose": z_axis, "upper_legs": x_axis, "lower_legs": y_axis}
    return {name: np.array(vector, dtype=np.float64) for name, vector in axes.items()}


def unit_design(kind: str) -> UnitDesign:
    """Reference design data of a kind (see the module docstring for the sources)."""
    return _DESIGNS[_check_kind(kind)]


def default_mesh_size(kind: str, *, height: float) -> float:
    """Default element size in m of a unit of this kind and height (a per-kind fraction of H)."""
    kind = _check_kind(kind)
    height = check_body_length(height, "height", f"armour unit '{kind}'")
    return _DEFAULT_MESH_SIZE_OVER_HEIGHT[kind] * height


def _height_from_size(kind: str, height, nominal_diameter, mass, density) -> float:
    where = f"armour_unit('{kind}')"
    given = [name for name, value in (("height", height), ("nominal_diameter", nominal_diameter),
                                      ("mass", mass)) if value is not None]
    if len(given) != 1:
        raise CaseFileError(
            f"{where}: give exactly one of height, nominal_diameter or mass (with density); got "
            f"{', '.join(given) if given else 'none'}"
        )
    if height is not None:
        return check_body_length(height, "height", where)
    if nominal_diameter is not None:
        volume = check_body_length(nominal_diameter, "nominal_diameter", where) ** 3
        given = f"nominal_diameter = {float(nominal_diameter):g} m"
    else:
        mass = _positive(mass, "mass", where, unit="kg")
        density = _positive(density, "density", where, unit="kg/m^3")
        volume = mass / density
        given = f"mass = {mass:g} kg at density = {density:g} kg/m^3"
    height = (volume / volume_coefficient(kind)) ** (1.0 / 3.0)
    if not MIN_BODY_LENGTH <= height <= MAX_BODY_LENGTH:
        raise CaseFileError(
            f"{where}: {given} gives a unit height of {height:g} m, outside the sizes riprap "
            f"meshes ({MIN_BODY_LENGTH:g} m to {MAX_BODY_LENGTH:g} m); check the value and its unit"
        )
    return height


def armour_unit(
    kind: str,
    *,
    height: float | None = None,
    nominal_diameter: float | None = None,
    mass: float | None = None,
    density: float = 2400.0,
    mesh_size: float | None = None,
) -> ArmourUnit:
    """Build and mesh one armour unit of the given kind and size.

    Give exactly one of ``height``, ``nominal_diameter`` or ``mass`` (with ``density``); the
    others follow from the shape's volume coefficient ``V = k H^3`` (:func:`volume_coefficient`).

    Parameters
    ----------
    kind : str
        One of ``UNIT_KINDS``.
    height : float, optional
        Unit height H in m (see ``ArmourUnit.height``).
    nominal_diameter : float, optional
        ``D_n = V^(1/3)`` in m.
    mass : float, optional
        Unit mass in kg, converted with ``density``.
    density : float
        Concrete density in kg/m^3 (default 2400), used only with ``mass``.
    mesh_size : float, optional
        Largest element edge in m; default a per-kind fraction of H that resolves the thinnest
        part and gives roughly 500-2500 tetrahedra.

    Returns
    -------
    ArmourUnit

    Raises
    ------
    CaseFileError
        For an unknown kind (the message lists the kinds and suggests the closest), none or
        several of the size arguments, a non-positive size, density or mesh size, a height
        (given or derived) outside ``MIN_BODY_LENGTH`` .. ``MAX_BODY_LENGTH``, or a mesh size
        that would make more than ``MAX_TETRAHEDRA_PER_SHAPE`` tetrahedra.

    Examples
    --------
    >>> unit = armour_unit("cube", nominal_diameter=0.05)
    >>> round(unit.height, 6), round(unit.nominal_diameter, 6)
    (0.05, 0.05)
    """
    kind = _check_kind(kind)
    height = _height_from_size(kind, height, nominal_diameter, mass, density)
    if mesh_size is None:
        mesh_size = default_mesh_size(kind, height=height)
    else:
        mesh_size = _positive(mesh_size, "mesh_size", f"armour_unit('{kind}')")
    name = f"{kind}(height={height:.6g})"
    check_tetrahedron_estimate(volume_coefficient(kind) * height**3, mesh_size, name,
                               error=CaseFileError)
    mesh = mesh_occ_shape(
        lambda occ: add_unit_solid(occ, kind, height=height), mesh_size=mesh_size, name=name
    )
    volume = mass_properties(mesh).volume
    return ArmourUnit(
        kind=kind,
        mesh=mesh,
        height=height,
        nominal_diameter=volume ** (1.0 / 3.0),
        volume=volume,
        axes=unit_axes(kind),
        design=unit_design(kind),
    )
