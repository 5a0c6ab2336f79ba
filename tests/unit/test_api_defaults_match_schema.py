"""A script and a case file with "the same" settings behave the same: every keyword of the Python
API that has a case-file key of the same meaning has the schema's default (one source for each
default, ``riprap.schema``), and every public constructor or function with such a keyword is
compared (a new one fails until it is listed here)."""
import inspect
from types import ModuleType

import numpy as np
import pytest

import riprap
from riprap import schema
from riprap.deformable import DeformableBody, ElasticMaterial
from riprap.deformable.joints import FracturingBody
from riprap.deformable.system import DeformableSystem
from riprap.fluid.grid import SIDES, FluidGrid
from riprap.fluid.phases import AIR_20C, WATER_20C
from riprap.fluid.porous import PorousZone
from riprap.simulation import FluidRun
from riprap.fluid.solver import FluidSolver
from riprap.geometry import shapes
from riprap.geometry.armour_units import armour_unit
from riprap.geometry.rock_grading import rock_library
from riprap.io.pack import PackBody
from riprap.placement.design_grid import design_grid
from riprap.placement.place import build_underlayer, place_units, unit_orientations
from riprap.placement.slope import Slope
from riprap.simulation import Simulation
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.solver import SolidSolver
from riprap.waves.boundary_generation import BoundaryWaveMaker
from riprap.waves.stream_function import StreamFunctionWave
from riprap.waves.theory import (IrregularWave, LinearWave, StokesSecondOrderWave, envelope,
                                 jonswap_spectrum)

# (callable, schema tables, {parameter name: key name, or None for a parameter that only shares
# the name}); other parameters are compared with the key of the same name in the first table that
# has one.
API_TABLES = [
    (Simulation, ("simulation", "output"), {"output_directory": "directory"}),
    (FluidRun, ("simulation", "output"), {"output_directory": "directory"}),
    (Material, ("materials",), {}),
    (SolidSolver, ("simulation",), {}),
    (walls.box, ("walls",), {}),
    # A shape's mesh_size None is the case file's 0, the shape's own default.
    *((maker, ("shapes",), {"mesh_size": None})
      for maker in (shapes.sphere, shapes.box, shapes.cube, shapes.random_rock, shapes.tetrapod,
                    shapes.l_shape)),
    # None means "not given" in the API where the case file writes 0 (size from the other two,
    # the unit's own mesh size); density is concrete's, not a [[materials]] key's.
    (armour_unit, ("armour",), {"height": None, "nominal_diameter": None, "mass": None,
                                "mesh_size": None}),
    # place_units' rows is the row of each unit, not the case file's count of rows.
    (place_units, ("placement",), {"rows": None}),
    (unit_orientations, ("placement",), {}),
    # design_grid's units_per_row is the (row, alternate row) pair of both keys.
    (design_grid, ("placement",), {"units_per_row": None}),
    (build_underlayer, ("underlayer",), {}),
    # rock_library's elongation is the range the rocks are drawn from, not one rock's.
    (rock_library, ("underlayer",), {"n_size_classes": "size_classes", "n_shapes": "rock_shapes",
                                     "elongation": None}),
    (Slope, ("slope",), {}),
    (FluidSolver, ("fluid", "simulation"), {}),
    (PorousZone, ("porous_zones",), {"linear": "linear_friction",
                                     "quadratic": "quadratic_friction"}),
    (LinearWave, ("waves",), {}),
    (StokesSecondOrderWave, ("waves",), {}),
    (StreamFunctionWave, ("waves",), {}),
    (IrregularWave, ("waves",), {}),
    (jonswap_spectrum, ("waves",), {}),
    (BoundaryWaveMaker, ("waves",), {}),
    (envelope, ("waves",), {}),
    # A deformable body's own gravity is off: the run gives it the [simulation] gravity.
    (DeformableBody, ("deformable",), {}),
    (FracturingBody, ("deformable",), {}),
    # contact_penalty None is "Young's modulus", the case file's 0.
    (DeformableSystem, ("deformable", "materials"), {"contact_penalty": None}),
    # An elastic material is concrete's by default (density 2400 kg/m^3, not rock's 2650); its
    # tensile strength None is the case file's 0, none given.
    (ElasticMaterial, ("deformable", "materials"), {"density": None, "tensile_strength": None,
                                                    "name": None}),
    (PackBody, ("bodies",), {}),
]

# Public callables whose keywords share a key's name but not its meaning.
NOT_CASE_FILE_SETTINGS = {
    "riprap.geometry.mass_properties.mass_properties":
        "density 1 gives the volume's properties per unit density",
    "riprap.geometry.structured.box_mesh":
        "origin is the mesh's corner, not a body grid's first centroid",
    "riprap.geometry.tetmesh.TetMesh": "name is the mesh's label",
    "riprap.geometry.meshing.tetrahedralize_surface":
        "meshes any surface; the shapes pass their mesh_size on",
    "riprap.simulation.RunSummary": "bodies, time_step, cells report the run",
    "riprap.placement.place.PlacementResult": "rows reports the row of each unit",
    "riprap.waves.gauges.Gauge": "to_x of a gauge object is given with its kind",
    "riprap.waves.relaxation.WaveRelaxation": "origin is the x of the wave's phase",
    "riprap.waves.theory.wave_number": "gravity is g, a magnitude",
    "riprap.waves.theory.wave_length": "gravity is g, a magnitude",
}


def _qualified(item) -> str:
    return f"{item.__module__}.{item.__qualname__}"


def _pairs():
    for function, tables, renamed in API_TABLES:
        for parameter in inspect.signature(function).parameters.values():
            key = renamed.get(parameter.name, parameter.name)
            if key is None or parameter.default is inspect.Parameter.empty:
                continue
            table = next((name for name in tables
                          if key in {entry.name for entry in schema.KEYS if entry.table == name}),
                         None)
            # A key the case file must give has no default to agree with (a porous zone's
            # lower/upper None: its shape is a polygon instead).
            if table is not None and not schema.key(table, key).required:
                yield pytest.param(function, table, parameter, key,
                                   id=f"{function.__name__}.{parameter.name}")


PAIRS = list(_pairs())


def _public_callables():
    """riprap's public names, and those of its public modules and of the wave and porous-zone
    modules that docs/waves.md shows."""
    from riprap.fluid import porous
    from riprap.waves import boundary_generation, gauges, relaxation, stream_function, theory

    modules = [riprap, porous, boundary_generation, gauges, relaxation, stream_function, theory]
    modules += [getattr(riprap, name) for name in riprap.__all__
                if isinstance(getattr(riprap, name), ModuleType)]
    found = {}
    for module in modules:
        names = getattr(module, "__all__", None) or [name for name in vars(module)
                                                     if not name.startswith("_")]
        for name in names:
            item = getattr(module, name)
            if callable(item) and not isinstance(item, ModuleType) and not name.startswith("_"):
                found[_qualified(item)] = item
    return found


def test_the_comparison_covers_the_defaults_that_once_disagreed():
    ids = {pair.id for pair in PAIRS}
    assert {"place_units.release", "unit_orientations.max_tilt_deg",
            "rock_library.n_size_classes", "Simulation.time_step_safety",
            "FluidSolver.courant_number", "ElasticMaterial.young_modulus",
            "IrregularWave.peak_enhancement", "PorousZone.linear"} <= ids


def test_every_public_callable_with_a_case_file_keyword_is_compared():
    key_names = {entry.name for entry in schema.KEYS}
    listed = {_qualified(function) for function, _, _ in API_TABLES} | set(NOT_CASE_FILE_SETTINGS)
    missing = []
    for name, item in sorted(_public_callables().items()):
        try:
            parameters = inspect.signature(item).parameters.values()
        except (TypeError, ValueError):
            continue
        shared = [p.name for p in parameters
                  if p.name in key_names and p.default is not inspect.Parameter.empty]
        if shared and name not in listed:
            missing.append(f"{name}({', '.join(shared)})")
    assert missing == [], ("public callables with keywords named as case-file keys, neither "
                           f"compared in API_TABLES nor listed as unrelated: {missing}")


@pytest.mark.parametrize("function, table, parameter, key", PAIRS)
def test_api_default_equals_case_file_default(function, table, parameter, key):
    expected = schema.default_of(table, key)
    assert np.array_equal(np.asarray(parameter.default), np.asarray(expected)), (
        f"{function.__name__}({parameter.name}={parameter.default!r}) but [{table}] {key} "
        f"defaults to {expected!r}")


def test_fluid_defaults_of_grid_sides_and_phases_are_the_case_files():
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(1.0, 1.0, 1.0), cells=(4, 4, 4))
    assert {side: grid.boundaries[side] for side in SIDES} == {
        side: schema.default_of("fluid", side) for side in SIDES}
    assert (WATER_20C.density, WATER_20C.dynamic_viscosity) == (
        schema.default_of("fluid", "water_density"), schema.default_of("fluid", "water_viscosity"))
    assert (AIR_20C.density, AIR_20C.dynamic_viscosity) == (
        schema.default_of("fluid", "air_density"), schema.default_of("fluid", "air_viscosity"))
