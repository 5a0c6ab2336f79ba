"""Each case-file key is written once, in riprap.schema: the loaded case's parts have exactly the
schema's keys as fields, with the schema's defaults, and the case has a part for every table."""
import dataclasses

import pytest

from riprap import schema
from riprap.case import specs
from riprap.case.load import Case

SPECS = {"simulation": specs.SimulationSettings, "materials": specs.MaterialSpec,
         "friction": specs.FrictionSpec,
         "shapes": specs.ShapeSpec, "bodies": specs.BodySpec, "body_grids": specs.BodyGridSpec,
         "walls": specs.WallSpec, "slope": specs.SlopeSpec, "underlayer": specs.UnderlayerSpec,
         "armour": specs.ArmourSpec, "armour_stone": specs.ArmourStoneSpec,
         "placement": specs.PlacementSpec, "fluid": specs.FluidSpec,
         "water_regions": specs.RegionSpec, "obstacles": specs.RegionSpec,
         "waves": specs.WavesSpec, "gauges": specs.GaugeSpec,
         "porous_zones": specs.PorousZoneSpec, "deformable": specs.DeformableSpec,
         "series": specs.SeriesSpec, "series_steps": specs.SeriesStepSpec,
         "output": specs.OutputSettings}


def test_every_table_has_a_spec_and_a_part_of_the_case():
    tables = {part.name for part in schema.TABLES if part.name}
    assert set(SPECS) == tables
    assert tables <= {field.name for field in dataclasses.fields(Case)}


@pytest.mark.parametrize("table_name", sorted(SPECS))
def test_spec_fields_are_the_tables_keys_with_their_defaults(table_name):
    spec = SPECS[table_name]
    fields = {field.name: field for field in dataclasses.fields(spec)}
    keys = {entry.name: entry for entry in schema.keys_of(table_name)}
    if schema.table(table_name).variant_key is not None:
        assert fields.pop("parameters").default is dataclasses.MISSING
    if table_name == "obstacles":          # shares RegionSpec with [[water_regions]]
        keys = {"type": keys["type"]}
    assert list(fields) == list(keys)
    for name, entry in keys.items():
        expected = dataclasses.MISSING if entry.required else entry.default
        assert fields[name].default == expected, name


def test_keywords_for_passes_a_table_on_by_name():
    from riprap.solid.materials import Material

    spec = specs.MaterialSpec(name="rock", density=2500.0)
    assert Material(**specs.keywords_for(Material, spec)) == Material(name="rock", density=2500.0)
