"""The loaded case's parts, one frozen dataclass per table, generated from :mod:`riprap.schema`.

A spec's fields are its table's keys (those every entry has, not the ``type``-specific ones),
in the schema's order, with the schema's defaults; a key the case file must give is a field
without a default. Tables whose ``type`` selects further keys keep those in ``parameters``
(a dict, defaults filled in). Nothing about a key is written here: a key added to the schema
is a field of its spec at once.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from riprap import schema

__all__ = [
    "Case",
    "SimulationSettings",
    "MaterialSpec",
    "FrictionSpec",
    "ShapeSpec",
    "BodySpec",
    "BodyGridSpec",
    "WallSpec",
    "SlopeSpec",
    "UnderlayerSpec",
    "ArmourSpec",
    "ArmourStoneSpec",
    "PlacementSpec",
    "FluidSpec",
    "DeformableSpec",
    "RegionSpec",
    "WavesSpec",
    "GaugeSpec",
    "PorousZoneSpec",
    "SeriesSpec",
    "SeriesStepSpec",
    "OutputSettings",
    "spec_class",
    "keywords_for",
]

Vector = tuple[float, float, float]

#: The Python type of each value kind (annotations only: the loader has converted the values).
_TYPES = {
    "integer": int,
    "number": float,
    "boolean": bool,
    "string": str,
    "vector": Vector,
    "integer_vector": tuple[int, int, int],
    "quaternion": tuple[float, float, float, float],
    "direction": Vector,
    "string_list": tuple[str, ...],
    "name_pair": tuple[str, str],
    "body_selection": object,       # "all" or a tuple of body indices
    "path": Path | str,
    "polygon_xz": tuple,
}


def _type_of(entry: schema.Key) -> object:
    """The annotation of a key's field; ``object`` for a kind added to the schema since."""
    return _TYPES.get(entry.kind, object)


def spec_class(class_name: str, table_name: str, *, methods: dict | None = None,
               doc: str | None = None):
    """A frozen, keyword-only dataclass of the common keys of ``table_name``.

    Parameters
    ----------
    class_name : str
        Name of the class (as the case's users import it).
    table_name : str
        The schema table the fields come from.
    methods : dict, optional
        Methods and properties of the class (its behaviour, not its data).
    doc : str, optional
        The class's docstring; by default the table's header and meaning.
    """
    part = schema.table(table_name)
    fields = []
    for entry in schema.keys_of(table_name):
        if entry.required:
            fields.append((entry.name, _type_of(entry)))
        else:
            fields.append((entry.name, _type_of(entry), dataclasses.field(default=entry.default)))
    if part.variant_key is not None:
        fields.append(("parameters", dict))
    typed = ", and ``parameters``, the keys of its type" if part.variant_key else ""
    namespace = dict(methods or {})
    namespace["__doc__"] = doc or (f"``{part.header}``: {part.meaning} Fields: the table's keys "
                                   f"(docs/case-file.md){typed}.")
    made = dataclasses.make_dataclass(class_name, fields, namespace=namespace, frozen=True,
                                      kw_only=True)
    made.__module__ = __name__
    return made


def keywords_for(function, spec) -> dict:
    """The fields of ``spec`` that ``function`` takes as keywords of the same name (a key's name
    is its parameter's name across riprap), so a builder passes a table on without naming each
    key again."""
    import inspect

    parameters = inspect.signature(function).parameters
    return {field.name: getattr(spec, field.name) for field in dataclasses.fields(spec)
            if field.name in parameters}


def _body_count(self) -> int:
    """Number of bodies the grid creates."""
    return self.counts[0] * self.counts[1] * self.counts[2]


def _selects(self, index: int) -> bool:
    """Whether case body ``index`` deforms."""
    return self.bodies == "all" or index in self.bodies


def _cracks(self, index: int) -> bool:
    """Whether case body ``index`` gets joints."""
    return bool(self.fracture) and self.selects(index) and (
        self.fracture_bodies == "all" or index in self.fracture_bodies)


SimulationSettings = spec_class("SimulationSettings", "simulation")
MaterialSpec = spec_class("MaterialSpec", "materials")
FrictionSpec = spec_class("FrictionSpec", "friction")
ShapeSpec = spec_class("ShapeSpec", "shapes")
BodySpec = spec_class("BodySpec", "bodies")
BodyGridSpec = spec_class("BodyGridSpec", "body_grids",
                          methods={"body_count": property(_body_count)})
WallSpec = spec_class("WallSpec", "walls")
SlopeSpec = spec_class("SlopeSpec", "slope")
UnderlayerSpec = spec_class("UnderlayerSpec", "underlayer")
ArmourSpec = spec_class("ArmourSpec", "armour")
ArmourStoneSpec = spec_class("ArmourStoneSpec", "armour_stone")
PlacementSpec = spec_class("PlacementSpec", "placement")
FluidSpec = spec_class("FluidSpec", "fluid")
DeformableSpec = spec_class("DeformableSpec", "deformable",
                            methods={"selects": _selects, "cracks": _cracks})
#: ``[[water_regions]]`` and ``[[obstacles]]`` entries share one spec: their type and its keys.
RegionSpec = spec_class("RegionSpec", "water_regions", doc=(
    "One ``[[water_regions]]`` or ``[[obstacles]]`` entry: its ``type`` and, in ``parameters``, "
    "that type's keys."))
WavesSpec = spec_class("WavesSpec", "waves")
GaugeSpec = spec_class("GaugeSpec", "gauges")
PorousZoneSpec = spec_class("PorousZoneSpec", "porous_zones")
SeriesSpec = spec_class("SeriesSpec", "series")
SeriesStepSpec = spec_class("SeriesStepSpec", "series_steps")
OutputSettings = spec_class("OutputSettings", "output")


@dataclasses.dataclass(frozen=True, kw_only=True)
class Case:
    """A validated case file with every default filled in.

    Attributes
    ----------
    format_version : int
        Always :data:`riprap.schema.FORMAT_VERSION`.
    source : str
        The file name as given, or ``"<string>"``; used in later error messages.
    base_dir : pathlib.Path
        Absolute folder that relative paths of the case are resolved against.
    """

    format_version: int
    source: str
    base_dir: Path
    simulation: SimulationSettings
    materials: tuple[MaterialSpec, ...]
    shapes: tuple[ShapeSpec, ...]
    friction: tuple[FrictionSpec, ...] = ()
    bodies: tuple[BodySpec, ...] = ()
    body_grids: tuple[BodyGridSpec, ...] = ()
    walls: tuple[WallSpec, ...] = ()
    output: OutputSettings = OutputSettings()
    slope: SlopeSpec | None = None
    underlayer: UnderlayerSpec | None = None
    armour: ArmourSpec | None = None
    armour_stone: ArmourStoneSpec | None = None
    placement: PlacementSpec | None = None
    fluid: FluidSpec | None = None
    deformable: DeformableSpec | None = None
    water_regions: tuple[RegionSpec, ...] = ()
    obstacles: tuple[RegionSpec, ...] = ()
    waves: WavesSpec | None = None
    gauges: tuple[GaugeSpec, ...] = ()
    porous_zones: tuple[PorousZoneSpec, ...] = ()
    series: SeriesSpec | None = None
    series_steps: tuple[SeriesStepSpec, ...] = ()

    @property
    def is_fluid(self) -> bool:
        """Whether the case has a ``[fluid]`` table (a two-phase flow run)."""
        return self.fluid is not None

    @property
    def is_series(self) -> bool:
        """Whether the case is a test series (``[series]``: ``riprap series``)."""
        return self.series is not None

    @property
    def is_placement(self) -> bool:
        """Whether the case describes an armour placement (``riprap place``)."""
        return self.placement is not None or self.armour_stone is not None

    @property
    def body_count(self) -> int:
        """Number of bodies the case creates (single bodies plus every grid's bodies)."""
        return len(self.bodies) + sum(grid.body_count for grid in self.body_grids)

    def material(self, name: str) -> MaterialSpec:
        """The material called ``name``."""
        for candidate in self.materials:
            if candidate.name == name:
                return candidate
        raise KeyError(f"{self.source}: no material named {name!r}")

    def shape(self, name: str) -> ShapeSpec:
        """The shape called ``name``."""
        for candidate in self.shapes:
            if candidate.name == name:
                return candidate
        raise KeyError(f"{self.source}: no shape named {name!r}")
