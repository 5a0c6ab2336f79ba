"""Porous zones: a breakwater's core and filter layers as a porous medium in the flow.

Model (the volume-averaged equations as olaFlow/IHFOAM code them: Higuera, Lara & Losada 2014,
Coastal Eng. 83: 243; closure of Engelund 1953 / Van Gent 1995 with the coefficients of Jensen,
Jacobsen & Christensen 2014, Coastal Eng. 84: 56). In a zone of porosity n and stone diameter
D50 the velocity is the filtration (Darcy) velocity U, the water fraction is that of the pore
space, and

    (1 + c)/n d(rho U)/dt + ... = -grad p + rho g - A U - B |U| U,
    A = a (1 - n)^3 / n^3  mu / D50^2,   B = b (1 - n) / n^3  rho / D50,

with ``a`` the linear (laminar) and ``b`` the quadratic (turbulent) friction coefficients and
``c`` the added mass. Defaults a = 50, b = 2.0, c = 0.34: the values olaFlow's tutorial runs the
porous dam break of Liu et al. (1999) with (``shared/research/coupling-waves-deformable.md`` §2.2);
the transient KC term of olaFlow is left out.

How it enters riprap's step (``FluidSolver``): the water fraction moves with the pore velocity U/n
and fills n of each cell (``plic.advect(porosity=...)``); the predictor's increment on a porous
face is scaled by s = n / (1 + c) and the friction is taken implicitly,
u* = (u^n + s (u*_0 - u^n)) / (1 + dt K), K = s (A + B |U^n|) / rho; the pressure's face
coefficient 1/rho becomes s / (rho (1 + dt K)), so the projection makes U divergence free with the
same factors. The scaling of the whole increment by s weighs gravity and pressure exactly and the
advection and viscous terms approximately (by n and n^2 against 1/(1+c) and 1/(n (1+c))), which
the slow flow in a core makes small against the friction.

Cells partly inside a zone get its properties in proportion to the covered part: porosity
1 - cover (1 - n), friction coefficients times the cover. A face takes the mean of its two cells.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of

__all__ = ["PorousZone", "PorousMedium", "face_means", "DEFAULT_LINEAR", "DEFAULT_QUADRATIC",
           "DEFAULT_ADDED_MASS"]

# The case file's [[porous_zones]] defaults (riprap.schema).
DEFAULT_LINEAR = default_of("porous_zones", "linear_friction")
DEFAULT_QUADRATIC = default_of("porous_zones", "quadratic_friction")
DEFAULT_ADDED_MASS = default_of("porous_zones", "added_mass")
# Sub-samples per cell and axis for the cover of a polygon zone.
_SAMPLES = 4


@dataclass(frozen=True)
class PorousZone:
    """A porous zone: an axis-aligned box (``lower``, ``upper``, m) or a polygon in the x-z plane
    (``polygon``: [(x, z), ...], m) extruded along y; ``porosity`` n, ``stone_diameter`` D50 (m),
    friction coefficients ``linear`` a and ``quadratic`` b, ``added_mass`` c; ``name`` for
    messages."""

    porosity: float
    stone_diameter: float
    lower: tuple | None = None
    upper: tuple | None = None
    polygon: tuple | None = None
    linear: float = DEFAULT_LINEAR
    quadratic: float = DEFAULT_QUADRATIC
    added_mass: float = DEFAULT_ADDED_MASS
    name: str = "porous zone"

    def __post_init__(self):
        if not 0.0 < self.porosity < 1.0:
            raise CaseFileError(f"{self.name}: porosity must lie in (0, 1), got {self.porosity!r}")
        for key in ("stone_diameter",):
            value = getattr(self, key)
            if not (math.isfinite(value) and value > 0):
                raise CaseFileError(f"{self.name}: {key} must be a positive length (m), got {value!r}")
        for key in ("linear", "quadratic", "added_mass"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0):
                raise CaseFileError(f"{self.name}: {key} must be >= 0, got {value!r}")
        if (self.polygon is None) == (self.lower is None or self.upper is None):
            raise CaseFileError(f"{self.name}: give a box (lower and upper) or a polygon, not both "
                                "or neither")
        if self.polygon is not None and len(self.polygon) < 3:
            raise CaseFileError(f"{self.name}: a polygon needs at least 3 points (x, z)")
        if self.polygon is not None:
            crossing = _first_crossing(np.asarray(self.polygon, dtype=float))
            if crossing is not None:
                i, j = crossing
                raise CaseFileError(
                    f"{self.name}: the polygon crosses itself: its side from point {i + 1} to "
                    f"{i + 2} meets the side from point {j + 1} to {(j + 1) % len(self.polygon) + 1}"
                    "; list the points in order around the zone's outline (a crossed outline "
                    "leaves part of the zone out)")

    def covers_any(self, grid) -> bool:
        """Whether the zone covers any part of ``grid`` (as ``cover(grid).any()``, from one
        x-z plane and the box's axes, not the whole grid's cells)."""
        if self.polygon is None:
            return all(bool(np.any((np.minimum(self.upper[a], grid.faces(a)[1:])
                                    - np.maximum(self.lower[a], grid.faces(a)[:-1])) > 0.0))
                       for a in ((0, 2) if grid.two_dimensional else (0, 1, 2)))
        # a polygon's cover is the same in every y-plane: one of them, with the grid's x and z
        plane = type(grid.whole_grid)(lower=grid.lower, upper=(grid.upper[0],
                                                               grid.lower[1] + grid.cell_size,
                                                               grid.upper[2]),
                                      cells=(grid.cells[0], 1, grid.cells[2]))
        return bool(self.cover(plane).any())

    def cover(self, grid) -> np.ndarray:
        """Fraction of every cell of ``grid`` inside the zone (nx, ny, nz)."""
        if self.polygon is None:
            fractions = []
            for axis in range(3):
                faces = grid.faces(axis)
                low = np.clip(self.lower[axis], faces[:-1], faces[1:])
                high = np.clip(self.upper[axis], faces[:-1], faces[1:])
                fractions.append(np.maximum(high - low, 0.0) / np.diff(faces))
            if grid.two_dimensional:
                fractions[1] = np.ones(1)
            return fractions[0][:, None, None] * fractions[1][None, :, None] * fractions[2][None, None, :]
        from matplotlib.path import Path

        h = grid.cell_size
        nx, ny, nz = grid.cells
        offsets = (np.arange(_SAMPLES) + 0.5) / _SAMPLES * h
        xs = (grid.faces(0)[:-1, None] + offsets[None, :]).reshape(-1)
        zs = (grid.faces(2)[:-1, None] + offsets[None, :]).reshape(-1)
        points = np.stack(np.meshgrid(xs, zs, indexing="ij"), axis=-1).reshape(-1, 2)
        inside = Path(np.asarray(self.polygon, dtype=float)).contains_points(points)
        cover = inside.reshape(nx, _SAMPLES, nz, _SAMPLES).mean(axis=(1, 3))
        return np.broadcast_to(cover[:, None, :], (nx, ny, nz)).copy()


class PorousMedium:
    """The porous zones of a fluid grid as cell and face arrays.

    ``porosity`` (nx, ny, nz) cell porosity (1 outside every zone); per axis face arrays:
    ``face_porosity``, ``scale`` s = n/(1 + c), ``linear_coefficient`` a (1-n)^3/(n^3 D50^2)
    (1/m^2; times mu gives A), ``quadratic_coefficient`` b (1-n)/(n^3 D50) (1/m; times rho |U|
    gives B |U|); ``faces`` per axis the flat indices of the interior faces with any porous part."""

    def __init__(self, grid, zones):
        self.zones = list(zones)
        shape = grid.cells
        porosity = np.ones(shape)
        linear = np.zeros(shape)
        quadratic = np.zeros(shape)
        added = np.zeros(shape)
        for zone in self.zones:
            cover = zone.cover(grid)
            # a block of a split grid may miss a zone that the whole grid holds
            if not (cover.any() if grid.whole_grid is grid else zone.covers_any(grid.whole_grid)):
                raise CaseFileError(f"{zone.name}: covers no part of the fluid grid "
                                    f"{list(grid.lower)} .. {list(grid.upper)} m")
            n, d = zone.porosity, zone.stone_diameter
            # overlapping zones: the later one replaces the earlier on the part it covers
            porosity = porosity * (1.0 - cover) + cover * n
            linear = linear * (1.0 - cover) + cover * zone.linear * (1.0 - n) ** 3 / (n ** 3 * d * d)
            quadratic = quadratic * (1.0 - cover) + cover * zone.quadratic * (1.0 - n) / (n ** 3 * d)
            if not (np.isfinite(linear).all() and np.isfinite(quadratic).all()):
                raise CaseFileError(f"{zone.name}: stone_diameter = {d:g} m with porosity = {n:g} "
                                    "makes the friction of the zone infinite; give stone_diameter "
                                    "in metres")
            added = added * (1.0 - cover) + cover * zone.added_mass
        self.porosity = porosity
        self.minimum_porosity = float(porosity.min())
        # The face arrays (about 15 x 8 bytes a cell) are made when first read: the whole grid
        # of a run split over processes, which never steps, never makes them.
        self._cells = (linear, quadratic, added)
        self._face_arrays = None

    def _faces_made(self) -> dict:
        if self._face_arrays is None:
            linear, quadratic, added = self._cells
            arrays = {name: [] for name in ("face_porosity", "scale", "linear_coefficient",
                                            "quadratic_coefficient", "faces")}
            for axis in range(3):
                n_face = face_means(self.porosity, axis)
                c_face = face_means(added, axis)
                arrays["face_porosity"].append(n_face)
                arrays["scale"].append(n_face / (1.0 + c_face))
                arrays["linear_coefficient"].append(face_means(linear, axis))
                arrays["quadratic_coefficient"].append(face_means(quadratic, axis))
                # interior faces only: walls carry no flow, and the open top's face keeps its
                # own coefficient (1/rho of the top cell)
                porous_face = (n_face < 1.0) | (c_face > 0.0)
                boundary = [slice(None)] * 3
                for end in (0, -1):
                    boundary[axis] = end
                    porous_face[tuple(boundary)] = False
                arrays["faces"].append(np.flatnonzero(porous_face))
            self._face_arrays, self._cells = arrays, None
        return self._face_arrays

    face_porosity = property(lambda self: self._faces_made()["face_porosity"])
    scale = property(lambda self: self._faces_made()["scale"])
    linear_coefficient = property(lambda self: self._faces_made()["linear_coefficient"])
    quadratic_coefficient = property(lambda self: self._faces_made()["quadratic_coefficient"])
    faces = property(lambda self: self._faces_made()["faces"])

    def drop_arrays(self) -> None:
        """Let go of the cell and face arrays, keeping the zones (``FluidSolver.drop_cell_arrays``):
        reading them afterwards fails."""
        self.porosity = self._cells = self._face_arrays = None


def _first_crossing(points: np.ndarray):
    """The first pair (i, j) of sides of the closed polygon ``points`` (n, 2) that meet, side i
    running from point i to point i + 1; None when the outline is simple. Sides next to each other
    share a point and only count when they fold back over each other."""
    n = len(points)
    starts, ends = points, np.roll(points, -1, axis=0)
    scale = float(np.abs(points).max()) or 1.0
    tolerance = 1e-12 * scale * scale

    def side(a, b, c):
        value = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        return 0 if abs(value) <= tolerance else (1 if value > 0 else -1)

    def on_segment(a, b, c):            # c collinear with a-b: does it lie within it?
        return (min(a[0], b[0]) <= c[0] <= max(a[0], b[0])
                and min(a[1], b[1]) <= c[1] <= max(a[1], b[1]))

    for i in range(n):
        a, b = starts[i], ends[i]
        for j in range(i + 1, n):
            c, d = starts[j], ends[j]
            adjacent = j == i + 1 or (i == 0 and j == n - 1)
            d1, d2, d3, d4 = side(a, b, c), side(a, b, d), side(c, d, a), side(c, d, b)
            if adjacent:
                # sharing one point: they meet elsewhere only when collinear and folding back
                shared, other_i, other_j = (b, a, d) if j == i + 1 else (a, b, c)
                if (side(other_i, shared, other_j) == 0
                        and np.dot(other_i - shared, other_j - shared) > 0):
                    return i, j
                continue
            if d1 * d2 < 0 and d3 * d4 < 0:
                return i, j
            if ((d1 == 0 and on_segment(a, b, c)) or (d2 == 0 and on_segment(a, b, d))
                    or (d3 == 0 and on_segment(c, d, a)) or (d4 == 0 and on_segment(c, d, b))):
                return i, j
    return None


def face_means(cells, axis) -> np.ndarray:
    """Cell values at the faces along ``axis`` (one more entry along it): the mean of the two
    cells; a boundary face takes its one cell's value."""
    padded = np.concatenate([cells.take([0], axis=axis), cells, cells.take([-1], axis=axis)],
                            axis=axis)
    low = [slice(None)] * 3
    high = [slice(None)] * 3
    low[axis], high[axis] = slice(0, -1), slice(1, None)
    return 0.5 * (padded[tuple(low)] + padded[tuple(high)])
