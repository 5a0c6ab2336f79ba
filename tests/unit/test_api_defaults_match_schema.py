"""A script and a case file with "the same" settings behave the same: every keyword of the Python
API that has a case-file key of the same meaning has the schema's default (one source for each
default, ``riprap.schema``)."""
import inspect

import numpy as np
import pytest

from riprap import schema
from riprap.fluid.solver import FluidSolver
from riprap.geometry.rock_grading import rock_library
from riprap.placement.place import build_underlayer, place_units, unit_orientations
from riprap.simulation import Simulation
from riprap.solid.materials import Material

# (callable, schema table, {parameter name: key name, or None for a parameter that only shares
# the name}; other parameters are compared when a key of the same name exists in the table).
API_TABLES = [
    (Simulation, "simulation", {}),
    (Material, "materials", {}),
    # place_units' rows is the row of each unit, not the case file's count of rows.
    (place_units, "placement", {"rows": None}),
    (unit_orientations, "placement", {}),
    (build_underlayer, "underlayer", {}),
    (rock_library, "underlayer", {"n_size_classes": "size_classes", "n_shapes": "rock_shapes"}),
    (FluidSolver, "fluid", {}),
]


def _pairs():
    for function, table, renamed in API_TABLES:
        names = {entry.name for entry in schema.keys_of(table)}
        for parameter in inspect.signature(function).parameters.values():
            key = renamed.get(parameter.name, parameter.name)
            if key in names and parameter.default is not inspect.Parameter.empty:
                yield pytest.param(function, table, parameter, key,
                                   id=f"{function.__name__}.{parameter.name}")


PAIRS = list(_pairs())


def test_the_comparison_covers_the_defaults_that_once_disagreed():
    ids = {pair.id for pair in PAIRS}
    assert {"place_units.release", "unit_orientations.max_tilt_deg",
            "rock_library.n_size_classes", "Simulation.time_step_safety"} <= ids


@pytest.mark.parametrize("function, table, parameter, key", PAIRS)
def test_api_default_equals_case_file_default(function, table, parameter, key):
    expected = schema.default_of(table, key)
    assert np.array_equal(np.asarray(parameter.default), np.asarray(expected)), (
        f"{function.__name__}({parameter.name}={parameter.default!r}) but [{table}] {key} "
        f"defaults to {expected!r}")
