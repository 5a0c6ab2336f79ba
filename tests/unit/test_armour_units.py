"""Armour unit library: parameter checks, size conversions, axes and design coefficients."""
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.geometry import armour_units
from riprap.geometry.armour_units import UNIT_KINDS, UnitDesign, armour_unit

# Two kinds are meshed here (coarse); the verification test meshes all six.
MESHED_KINDS = ("cube", "tetrapod")
COARSE = 2.0  # x the default mesh size


def _coarse(kind, height):
    return COARSE * armour_units.default_mesh_size(kind, height=height)


@pytest.mark.parametrize("spelling, suggestion", [("Core-Loc", "core_loc_like"),
                                                  ("accropode", "accropode_like"),
                                                  ("tetrapods", "tetrapod")])
def test_unknown_kind_lists_kinds_and_suggests_closest(spelling, suggestion):
    with pytest.raises(CaseFileError) as error:
        armour_unit(spelling, height=1.0)
    message = str(error.value)
    assert all(kind in message for kind in UNIT_KINDS)
    assert f"did you mean '{suggestion}'" in message


def test_kind_far_from_every_name_gets_no_suggestion():
    with pytest.raises(CaseFileError, match="the kinds are") as error:
        armour_unit("zzzz", height=1.0)
    assert "did you mean" not in str(error.value)


@pytest.mark.parametrize("sizes", [{}, {"height": 1.0, "nominal_diameter": 0.5},
                                   {"height": 1.0, "mass": 100.0},
                                   {"nominal_diameter": 0.5, "mass": 100.0}])
def test_exactly_one_size_must_be_given(sizes):
    with pytest.raises(CaseFileError, match="exactly one of height, nominal_diameter or mass"):
        armour_unit("cube", **sizes)


@pytest.mark.parametrize("arguments, parameter", [
    ({"height": -1.0}, "height"), ({"height": float("nan")}, "height"),
    ({"nominal_diameter": 0.0}, "nominal_diameter"), ({"mass": -5.0}, "mass"),
    ({"mass": 100.0, "density": 0.0}, "density"), ({"height": 1.0, "mesh_size": -0.1}, "mesh_size"),
    ({"height": "tall"}, "height"),
])
def test_bad_sizes_name_the_parameter(arguments, parameter):
    with pytest.raises(CaseFileError, match=parameter):
        armour_unit("cube", **arguments)


@pytest.mark.parametrize("kind", MESHED_KINDS)
def test_height_nominal_diameter_and_mass_give_the_same_unit(kind):
    height, density = 2.0, 2400.0
    by_height = armour_unit(kind, height=height, mesh_size=_coarse(kind, height))
    by_diameter = armour_unit(kind, nominal_diameter=by_height.nominal_diameter,
                              mesh_size=_coarse(kind, height))
    by_mass = armour_unit(kind, mass=by_height.mass(density), density=density,
                          mesh_size=_coarse(kind, height))
    for other in (by_diameter, by_mass):
        assert abs(other.height - height) <= 1e-9 * height
        assert abs(other.volume - by_height.volume) <= 1e-9 * by_height.volume
    expected_volume = armour_units.volume_coefficient(kind) * height**3
    assert abs(by_height.volume - expected_volume) <= 1e-9 * expected_volume
    assert abs(by_height.nominal_diameter - by_height.volume ** (1 / 3)) <= 1e-12


def test_cube_sizes_are_its_side():
    unit = armour_unit("cube", nominal_diameter=0.05)
    assert abs(unit.height - 0.05) <= 1e-12
    assert abs(unit.volume - 0.05**3) <= 1e-12
    assert abs(unit.mass(2400.0) - 2400.0 * 0.05**3) <= 1e-9
    assert unit.design is armour_units.unit_design("cube")


def test_mass_rejects_bad_density():
    unit = armour_unit("cube", height=1.0, mesh_size=0.5)
    with pytest.raises(CaseFileError, match="density"):
        unit.mass(-2400.0)


@pytest.mark.parametrize("kind", UNIT_KINDS)
def test_volume_coefficient_is_positive_and_below_the_bounding_cube(kind):
    coefficient = armour_units.volume_coefficient(kind)
    # every shape fits a box of H x H x H (the Antifer base is 1.086 H wide)
    assert 0.1 < coefficient <= 1.086**2 + 1e-12


@pytest.mark.parametrize("kind", UNIT_KINDS)
def test_axes_are_unit_vectors_with_a_nose(kind):
    axes = armour_units.unit_axes(kind)
    assert "nose" in axes
    assert len(axes) >= 2
    for vector in axes.values():
        assert vector.shape == (3,)
        assert abs(np.linalg.norm(vector) - 1.0) <= 1e-12


def test_meshed_unit_carries_its_axes_and_design():
    unit = armour_unit("tetrapod", height=1.0, mesh_size=_coarse("tetrapod", 1.0))
    assert set(unit.axes) == {"nose", "leg_1", "leg_2", "leg_3"}
    legs = np.array(list(unit.axes.values()))
    # the four legs point along the directions of a regular tetrahedron: pairwise cosine -1/3
    cosines = legs @ legs.T
    assert np.allclose(cosines[~np.eye(4, dtype=bool)], -1.0 / 3.0, atol=1e-12)
    assert unit.design.layers == 2


@pytest.mark.parametrize("kind", UNIT_KINDS)
def test_packing_density_is_layers_times_thickness_times_solid_fraction(kind):
    design = armour_units.unit_design(kind)
    implied = design.layers * design.layer_thickness_coefficient * (1.0 - design.porosity)
    # published values carry 2-3 digits
    assert abs(design.packing_density_coefficient - implied) <= 0.005 * implied
    assert design.source
    assert 0.3 < design.porosity < 0.7


def test_single_layer_units_and_double_layer_units():
    layers = {kind: armour_units.unit_design(kind).layers for kind in UNIT_KINDS}
    assert layers == {"core_loc_like": 1, "accropode_like": 1, "xbloc_like": 1, "tetrapod": 2,
                      "cube": 2, "antifer_cube": 2}


def test_derived_core_loc_packing_density_says_so():
    design = armour_units.unit_design("core_loc_like")
    assert "derived" in design.note
    assert abs(design.packing_density_coefficient - 1.516 * (1.0 - 0.60)) <= 1e-9


@pytest.mark.parametrize("fields, parameter", [
    ({"layers": 0}, "layers"), ({"layers": 1.5}, "layers"),
    ({"layer_thickness_coefficient": -1.0}, "layer_thickness_coefficient"),
    ({"porosity": 1.2}, "porosity"), ({"packing_density_coefficient": 0.9}, "packing_density"),
])
def test_unit_design_rejects_bad_or_inconsistent_values(fields, parameter):
    values = {"layers": 1, "layer_thickness_coefficient": 1.29, "porosity": 0.5,
              "packing_density_coefficient": 0.645, "source": "test"}
    values.update(fields)
    with pytest.raises(CaseFileError, match=parameter):
        UnitDesign(**values)
