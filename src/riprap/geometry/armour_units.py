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

Each kind is one record (``riprap.geometry.unit_kinds.UNIT_RECORDS``: its solid, axes, design data,
default element size, published volume coefficient and K_D); the solids are built in
``riprap.geometry.unit_solids``. Design data (``UnitDesign``) come from
``shared/validation/armour_design.md`` section 5.2 and the sources cited there, except the
ACCROPODE packing density and porosity (CLI design table, cited) and the CORE-LOC porosity and
packing density, which were not found and are derived (stated in the unit's ``design.note``).

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

import functools
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, MeshError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.meshing import (
    MAX_BODY_LENGTH,
    MIN_BODY_LENGTH,
    _gmsh_session,
    check_body_length,
    check_tetrahedron_estimate,
    mesh_occ_shape,
)
from riprap.geometry.tetmesh import TetMesh
from riprap.geometry.unit_kinds import UNIT_KINDS, UNIT_RECORDS, UnitDesign, unit_kind

__all__ = ["UNIT_KINDS", "UnitDesign", "ArmourUnit", "armour_unit", "add_unit_solid",
           "volume_coefficient", "occ_mass_properties", "unit_axes", "unit_design",
           "default_mesh_size", "PUBLISHED_VOLUME_COEFFICIENTS"]

# Published V / H^3 each riprap shape is tuned to (kinds not listed have none found).
PUBLISHED_VOLUME_COEFFICIENTS = {record.name: record.published_volume_coefficient
                                 for record in UNIT_RECORDS
                                 if record.published_volume_coefficient is not None}


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
    return unit_kind(kind).name



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
    unit_kind(kind).build(occ, height)


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
    """Named unit vectors of a kind in its mesh frame (see :func:`add_unit_solid`); ``"nose"``
    is the axis riprap uses for orientation statistics (``unit_kinds.UNIT_RECORDS``)."""
    axes = unit_kind(kind).axes
    return {name: np.array(vector, dtype=np.float64) for name, vector in axes.items()}


def unit_design(kind: str) -> UnitDesign:
    """Reference design data of a kind (see the module docstring for the sources)."""
    return unit_kind(kind).design


def default_mesh_size(kind: str, *, height: float) -> float:
    """Default element size in m of a unit of this kind and height (a per-kind fraction of H)."""
    kind = _check_kind(kind)
    height = check_body_length(height, "height", f"armour unit '{kind}'")
    return unit_kind(kind).mesh_size_over_height * height


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
