"""One record per armour unit kind: everything riprap knows of a kind, in one place.

A kind is its solid (a builder in :mod:`riprap.geometry.unit_solids`), its named axes, its
reference layer design (``UnitDesign``, sources cited per kind), the default element size, the
published volume coefficient its proportions are tuned to, and Hudson's stability coefficient K_D.
To add a kind: write its ``build_<kind>`` in unit_solids.py, add one ``UnitKind`` to
``UNIT_RECORDS`` below and its name to ``riprap.schema.UNIT_KINDS`` (the case file's choices; a
test checks the two lists agree), and describe it in docs/armour-units.md.
"""
from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.geometry import unit_solids
from riprap.geometry.unit_solids import ANTIFER_VOLUME_COEFFICIENT

# Published design values are rounded to 2-3 digits, so phi = layers k_t (1 - n_v) is checked to
# this relative tolerance (the cube's 2 x 1.10 x 0.53 = 1.166 is published as 1.17).
_PACKING_CONSISTENCY = 0.005

_ARMOUR_DESIGN_MD = "shared/validation/armour_design.md section 5.2"


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



@dataclass(frozen=True)
class UnitKind:
    """Everything riprap knows of one armour unit kind.

    Attributes
    ----------
    name : str
        The kind's name in case files and the API (``"core_loc_like"``, ...).
    build : callable
        ``build(occ, height)`` adds the unit's solid (height H in m) to the current gmsh
        OpenCASCADE model, in the frame listed in ``armour_units.add_unit_solid``.
    axes : dict of str to tuple
        Named unit vectors in the unit's frame; ``"nose"`` is always present.
    design : UnitDesign
        Reference layer thickness coefficient, porosity and packing density coefficient.
    mesh_size_over_height : float
        Default element size as a fraction of H: the smallest feature is resolved and the meshes
        have roughly 500-2500 tetrahedra (counts measured with gmsh 4.15, docs/armour-units.md).
    published_volume_coefficient : float or None
        Published ``V / H^3`` the shape is tuned to; None where none was found.
    hudson_trunk_stability : float or None
        Hudson's K_D of a trunk under non-breaking waves (armour_design.md section 5.2); None
        where none was retrieved (cubes: Van der Meer's formula instead).
    """

    name: str
    build: Callable[[object, float], None]
    axes: dict
    design: UnitDesign
    mesh_size_over_height: float
    published_volume_coefficient: float | None = None
    hudson_trunk_stability: float | None = None


# Double-layer random cubes (Rock Manual p. 260): the plain and the Antifer cube share them.
_DOUBLE_LAYER_CUBES = dict(layers=2, layer_thickness_coefficient=1.10, porosity=0.47,
                           packing_density_coefficient=1.166)

_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def _axes(**named) -> dict:
    return dict(named)


def _tetrapod_axes() -> dict:
    """Leg 0 (along +z) is the nose; legs 1-3 as built."""
    directions = unit_solids.tetrapod_legs(1.0)[0]
    axes = {"nose": tuple(directions[0])}
    axes.update({f"leg_{k}": tuple(directions[k]) for k in (1, 2, 3)})
    return axes


# The nose axes are riprap's conventions (orientation statistics): the trunk of the
# CORE-LOC-like unit, the vertical (nose) axis of the ACCROPODE-like and Xbloc-like units and of
# both cubes, and leg 0 of the Tetrapod. The seed paper (Xiang et al. 2012) plots CORE-LOC "nose
# axes" without defining them in the text read here.
UNIT_RECORDS: tuple[UnitKind, ...] = (
    UnitKind(
        name="core_loc_like",
        build=unit_solids.build_core_loc_like,
        axes=_axes(nose=_X, trunk=_X, fluke=_Z),
        design=UnitDesign(
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
                "porosity 0.60 is assumed (the value usually tabulated for CORE-LOC in USACE "
                "design tables, not verified here) and phi = 1 x 1.516 x (1 - 0.60) = 0.606 is derived"
            ),
        ),
        mesh_size_over_height=0.11,
        published_volume_coefficient=None,
        hudson_trunk_stability=16.0,
    ),
    UnitKind(
        name="accropode_like",
        build=unit_solids.build_accropode_like,
        axes=_axes(nose=_Z, lower_horns=_X, upper_horns=_Y),
        design=UnitDesign(
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
        mesh_size_over_height=0.14,
        published_volume_coefficient=0.34,
        hudson_trunk_stability=15.0,
    ),
    UnitKind(
        name="xbloc_like",
        build=unit_solids.build_xbloc_like,
        axes=_axes(nose=_Z, upper_legs=_X, lower_legs=_Y),
        design=UnitDesign(
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
        mesh_size_over_height=0.14,
        published_volume_coefficient=0.335,
        hudson_trunk_stability=16.0,
    ),
    UnitKind(
        name="tetrapod",
        build=unit_solids.build_tetrapod,
        axes=_tetrapod_axes(),
        design=UnitDesign(
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
        mesh_size_over_height=0.12,
        published_volume_coefficient=None,
        hudson_trunk_stability=8.0,
    ),
    UnitKind(
        name="cube",
        build=unit_solids.build_cube,
        axes=_axes(nose=_Z, face_x=_X, face_y=_Y),
        design=UnitDesign(
            **_DOUBLE_LAYER_CUBES,
            source=(
                "CIRIA, CUR, CETMEF (2007). The Rock Manual (C683), p. 260; Deltares coastal-"
                "structures-toolbox cubes_double_layer_vandermeer1988.py (k_t, n_v); via "
                f"{_ARMOUR_DESIGN_MD}"
            ),
            note="k_t and n_v published (double layer, random); phi computed (1.17 in the table)",
        ),
        mesh_size_over_height=1.0 / 3.8,
        published_volume_coefficient=1.0,
        hudson_trunk_stability=None,
    ),
    UnitKind(
        name="antifer_cube",
        build=unit_solids.build_antifer_cube,
        axes=_axes(nose=_Z, face_x=_X, face_y=_Y),
        design=UnitDesign(
            **_DOUBLE_LAYER_CUBES,
            source=(
                "CIRIA, CUR, CETMEF (2007). The Rock Manual (C683), p. 260 (cubes, double layer); "
                f"via {_ARMOUR_DESIGN_MD}"
            ),
            note=(
                "no Antifer-specific values in the sources read; the double-layer cube values are "
                "used (the Antifer is a grooved, slightly tapered cube placed in two layers)"
            ),
        ),
        mesh_size_over_height=0.25,
        published_volume_coefficient=ANTIFER_VOLUME_COEFFICIENT,
        hudson_trunk_stability=None,
    ),
)

UNIT_KINDS: tuple[str, ...] = tuple(record.name for record in UNIT_RECORDS)
_BY_NAME = {record.name: record for record in UNIT_RECORDS}


def unit_kind(kind: str) -> UnitKind:
    """The record of a kind; an unknown name is refused with the kinds and the closest one."""
    if isinstance(kind, str) and kind in _BY_NAME:
        return _BY_NAME[kind]
    spelled = str(kind).strip().lower().replace("-", "_").replace(" ", "_")
    close = difflib.get_close_matches(spelled, UNIT_KINDS, n=1, cutoff=0.5)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    raise CaseFileError(
        f"armour unit kind '{kind}' is unknown; the kinds are {', '.join(UNIT_KINDS)}{hint}"
    )
