"""Rock gradings: the sampled stones have the grading's mass curve; graded rock libraries.

Sampling tolerance: 20 000 stones (seed 1), D_n85 / D_n15 = 1.8 and 1.25. A mass-weighted
quantile of a log-normal sample has a standard error of sigma sqrt(p (1 - p)) / phi(z_p) /
sqrt(n_eff) in ln D_n, with sigma = ln(1.8) / 2.07 = 0.28 and the effective size of a D_n^3-weighted
sample n exp(-9 sigma^2) = 9 700: 0.4 % for D_n50 and about 0.6 % for D_n85 / D_n15.
``PERCENTILE_TOLERANCE`` = 2 % is over three standard errors and still catches a count-weighted
(not mass-weighted) sample, whose D_n50 is exp(-3 sigma^2) = 21 % low. Measured with seed 1:
D_n50 within 0.6 %, the spread within 0.3 %.
"""
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.rock_grading import GradedRock, RockGrading, rock_library

PERCENTILE_TOLERANCE = 0.02
SAMPLE_SIZE = 20_000


def _mass_weighted_quantile(diameters, fraction):
    order = np.sort(diameters)
    cumulative = np.cumsum(order**3)
    cumulative /= cumulative[-1]
    return float(np.interp(fraction, cumulative, order))


@pytest.mark.parametrize("dn50, spread", [(0.3, 1.8), (0.05, 1.25)])
def test_sampled_stones_reproduce_the_mass_grading(dn50, spread):
    grading = RockGrading(dn50=dn50, dn85_over_dn15=spread)
    diameters = grading.sample(SAMPLE_SIZE, np.random.default_rng(1))
    assert diameters.shape == (SAMPLE_SIZE,)
    sampled_dn50 = _mass_weighted_quantile(diameters, 0.5)
    sampled_spread = (_mass_weighted_quantile(diameters, 0.85)
                      / _mass_weighted_quantile(diameters, 0.15))
    assert abs(sampled_dn50 - dn50) <= PERCENTILE_TOLERANCE * dn50
    assert abs(sampled_spread - spread) <= PERCENTILE_TOLERANCE * spread


def test_nominal_diameter_at_passes_through_the_anchor_points():
    grading = RockGrading(dn50=0.4, dn85_over_dn15=2.0)
    assert abs(grading.nominal_diameter_at(0.5) - 0.4) <= 1e-12
    ratio = grading.nominal_diameter_at(0.85) / grading.nominal_diameter_at(0.15)
    assert abs(ratio - 2.0) <= 1e-9


def test_single_size_grading_samples_one_size():
    grading = RockGrading(dn50=0.2, dn85_over_dn15=1.0)
    assert np.allclose(grading.sample(10, np.random.default_rng(0)), 0.2, rtol=1e-12)


def test_same_seed_same_sample():
    grading = RockGrading(dn50=0.2, dn85_over_dn15=1.5)
    first = grading.sample(5, np.random.default_rng(7))
    second = grading.sample(5, np.random.default_rng(7))
    assert np.array_equal(first, second)


@pytest.mark.parametrize("n", [1, 3, 5])
def test_size_classes_hold_equal_mass(n):
    grading = RockGrading(dn50=0.3, dn85_over_dn15=1.6)
    diameters, probabilities = grading.size_classes(n)
    assert diameters.shape == probabilities.shape == (n,)
    assert np.all(np.diff(diameters) > 0.0)
    assert abs(probabilities.sum() - 1.0) <= 1e-12
    mass_shares = probabilities * diameters**3 / (probabilities * diameters**3).sum()
    assert np.allclose(mass_shares, 1.0 / n, rtol=1e-12)
    if n % 2 == 1:  # the middle class is centred on the median
        assert abs(diameters[n // 2] - 0.3) <= 1e-12


@pytest.mark.parametrize("arguments, parameter", [
    ({"dn50": -0.1, "dn85_over_dn15": 1.5}, "dn50"),
    ({"dn50": 0.1, "dn85_over_dn15": 0.9}, "dn85_over_dn15"),
    ({"dn50": 0.1, "dn85_over_dn15": 8.0}, "dn85_over_dn15"),
    ({"dn50": "big", "dn85_over_dn15": 1.5}, "dn50"),
])
def test_grading_rejects_bad_values(arguments, parameter):
    with pytest.raises(CaseFileError, match=parameter):
        RockGrading(**arguments)


def test_sample_and_classes_reject_bad_arguments():
    grading = RockGrading(dn50=0.1, dn85_over_dn15=1.5)
    with pytest.raises(CaseFileError, match="count"):
        grading.sample(-1, np.random.default_rng(0))
    with pytest.raises(CaseFileError, match="rng"):
        grading.sample(3, 42)
    with pytest.raises(CaseFileError, match="n must be"):
        grading.size_classes(0)
    with pytest.raises(CaseFileError, match="mass fractions"):
        grading.nominal_diameter_at(1.0)


@pytest.fixture(scope="module")
def library():
    grading = RockGrading(dn50=0.25, dn85_over_dn15=1.5)
    return grading, rock_library(grading, n_shapes=4, n_size_classes=3, seed=3)


def test_library_sizes_and_probabilities(library):
    grading, rocks = library
    diameters, class_probabilities = grading.size_classes(3)
    assert len(rocks) == 4 and all(isinstance(rock, GradedRock) for rock in rocks)
    # shapes 0 and 3 share class 0 and split its probability
    assert [rock.nominal_diameter for rock in rocks] == pytest.approx(
        [diameters[0], diameters[1], diameters[2], diameters[0]], rel=1e-12)
    assert rocks[0].probability == pytest.approx(class_probabilities[0] / 2, rel=1e-12)
    assert rocks[1].probability == pytest.approx(class_probabilities[1], rel=1e-12)
    assert abs(sum(rock.probability for rock in rocks) - 1.0) <= 1e-12


def test_library_rocks_have_their_nominal_diameter_and_distinct_shapes(library):
    _, rocks = library
    for rock in rocks:
        rock.mesh.check()
        volume = mass_properties(rock.mesh).volume
        assert abs(volume ** (1 / 3) - rock.nominal_diameter) <= 1e-9 * rock.nominal_diameter
        assert 1.0 <= rock.elongation <= 1.6
    assert rocks[0].mesh.n_nodes != rocks[3].mesh.n_nodes or not np.allclose(
        rocks[0].mesh.nodes, rocks[3].mesh.nodes)


def test_library_is_reproducible():
    grading = RockGrading(dn50=0.1, dn85_over_dn15=1.3)
    first = rock_library(grading, n_shapes=1, n_size_classes=1, seed=5)
    second = rock_library(grading, n_shapes=1, n_size_classes=1, seed=5)
    assert np.array_equal(first[0].mesh.nodes, second[0].mesh.nodes)


@pytest.mark.parametrize("arguments, parameter", [
    ({"n_shapes": 2, "n_size_classes": 3}, "n_shapes"),
    ({"n_shapes": 3, "n_size_classes": 0}, "n_size_classes"),
    ({"n_shapes": 3, "elongation": (0.5, 1.2)}, "elongation"),
    ({"n_shapes": 3, "elongation": (1.5, 1.2)}, "elongation"),
])
def test_library_rejects_bad_arguments(arguments, parameter):
    with pytest.raises(CaseFileError, match=parameter):
        rock_library(RockGrading(dn50=0.1, dn85_over_dn15=1.5), **arguments)
