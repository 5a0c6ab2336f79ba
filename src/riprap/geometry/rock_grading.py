"""Rock gradings (the spread of stone sizes in an armour or filter layer) and libraries of graded
random rocks.

A grading is given as the Rock Manual gives one: by the median nominal diameter ``D_n50`` and the
spread ``D_n85 / D_n15``, where ``D_ny`` is the nominal diameter (``(M / rho)^(1/3)``) that the
fraction ``y`` of the total **mass** passes (gradings are curves of mass passing; CIRIA, CUR,
CETMEF 2007, The Rock Manual, C683, chapter 3).

Distribution. riprap takes ``ln D_n`` as normally distributed **by mass**, with mean ``ln D_n50``
and standard deviation ``sigma = ln(D_n85 / D_n15) / (2 z_85)``, ``z_85 = 1.0364`` the standard
normal 85 % quantile, so that the two given numbers are reproduced exactly. The Rock Manual instead
interpolates standard gradings with a Rosin-Rammler curve in mass,
``M_y = M_50 (ln(1 - y) / ln 0.5)^(1/n_RRM)`` (p. 113, as coded in Sander-w/breakwater
``material.py``, see shared/validation/armour_design.md section 5.3); both are two-parameter
curves through the same two anchor points and differ in the tails only (the Rosin-Rammler curve,
the EN 13383 classes and their checks are in ``armour_stone.py``). A log-normal distribution
by mass is log-normal by count too, with the same ``sigma`` and mean ``ln D_n50 - 3 sigma^2`` (each
stone weighs ``rho D_n^3``), which is what :meth:`RockGrading.sample` draws from: a set of sampled
stones has the grading's mass curve.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.schema import default_of
from riprap.errors import CaseFileError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.shapes import random_rock
from riprap.geometry.tetmesh import TetMesh

# Standard normal quantile of 0.85 (scipy.stats.norm.ppf(0.85)); the 15 % quantile is its negative.
_Z85 = 1.0364333894937898

# Spreads beyond this are not armour or filter gradings (the widest EN 13383 grading listed in
# armour_design.md, LMA 15/300, spans a mass ratio NUL / NLL = 20, i.e. 2.7 in nominal diameter);
# refusing them catches a D_n85 / D_n15 typed as a mass ratio (the cube of it).
_MAX_SPREAD = 5.0

# Random rocks: number of hull points (shapes.random_rock's default).
_ROCK_VERTICES = 24


def checked_spread(value: object, where: str, name: str = "dn85_over_dn15",
                   widest: float = _MAX_SPREAD,
                   meaning: str = "a ratio of nominal diameters, not of masses") -> float:
    """A spread (by default ``D_n85 / D_n15``) as a number in 1 .. ``widest``.

    A mass ratio ``M85 / M15`` typed where the ratio of nominal diameters is meant is its cube, and
    is refused above ``_MAX_SPREAD``. ``where`` and ``name`` head the message, ``meaning`` says
    what the ratio is.
    """
    try:
        spread = float(value)
    except (TypeError, ValueError) as error:
        raise CaseFileError(f"{where}: {name} must be a number, got {value!r}") from error
    if not (np.isfinite(spread) and 1.0 <= spread <= widest):
        raise CaseFileError(f"{where}: {name} must lie in 1..{widest:g} ({meaning}), got {spread}")
    return spread


def checked_draw(count: object, rng: object, where: str) -> int:
    """The number of stones to draw, an integer >= 0, and ``rng`` a numpy Generator."""
    if int(count) != count or count < 0:
        raise CaseFileError(f"{where}: count must be an integer >= 0, got {count}")
    if not isinstance(rng, np.random.Generator):
        raise CaseFileError(
            f"{where}: rng must be a numpy.random.Generator "
            f"(numpy.random.default_rng(seed)), got {type(rng).__name__}"
        )
    return int(count)


def _standard_normal_quantile(probability: np.ndarray) -> np.ndarray:
    from scipy.special import ndtri

    return ndtri(probability)


@dataclass(frozen=True)
class RockGrading:
    """A rock grading: median nominal diameter and spread, both by mass.

    Parameters
    ----------
    dn50 : float
        Median nominal diameter ``D_n50`` in m (half the mass is in smaller stones).
    dn85_over_dn15 : float
        Spread ``D_n85 / D_n15`` (>= 1; 1 is a single size).

    Examples
    --------
    >>> grading = RockGrading(dn50=0.3, dn85_over_dn15=1.5)
    >>> round(grading.nominal_diameter_at(0.85) / grading.nominal_diameter_at(0.15), 6)
    1.5
    """

    dn50: float
    dn85_over_dn15: float

    def __post_init__(self) -> None:
        try:
            dn50 = float(self.dn50)
        except (TypeError, ValueError) as error:
            raise CaseFileError(f"RockGrading: dn50 must be a number, got {self.dn50!r}") from error
        object.__setattr__(self, "dn50", dn50)
        if not (np.isfinite(self.dn50) and self.dn50 > 0.0):
            raise CaseFileError(
                f"RockGrading: dn50 must be a positive length in m, got {self.dn50}"
            )
        object.__setattr__(self, "dn85_over_dn15",
                           checked_spread(self.dn85_over_dn15, "RockGrading"))

    @property
    def log_spread(self) -> float:
        """``sigma``: standard deviation of ``ln D_n`` (by mass and by count)."""
        return float(np.log(self.dn85_over_dn15) / (2.0 * _Z85))

    def nominal_diameter_at(self, mass_fraction_passing: float | np.ndarray) -> float | np.ndarray:
        """``D_ny``: the nominal diameter that the fraction ``y`` of the mass passes, in m."""
        y = np.asarray(mass_fraction_passing, dtype=np.float64)
        if np.any((y <= 0.0) | (y >= 1.0)):
            raise CaseFileError(
                f"RockGrading.nominal_diameter_at: mass fractions must lie strictly between 0 and "
                f"1, got {mass_fraction_passing}"
            )
        result = self.dn50 * np.exp(self.log_spread * _standard_normal_quantile(y))
        return float(result) if result.ndim == 0 else result

    def sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """Nominal diameters of ``count`` stones drawn at random (by count), in m.

        A large sample has the grading's mass curve: its mass-weighted ``D_n50`` and
        ``D_n85 / D_n15`` tend to ``dn50`` and ``dn85_over_dn15``.

        Parameters
        ----------
        count : int
            Number of stones (>= 0).
        rng : numpy.random.Generator
            Random generator, e.g. ``numpy.random.default_rng(seed)``.

        Returns
        -------
        numpy.ndarray, shape (count,)
        """
        count = checked_draw(count, rng, "RockGrading.sample")
        sigma = self.log_spread
        count_median = np.log(self.dn50) - 3.0 * sigma**2
        return np.exp(rng.normal(count_median, sigma, size=count))

    def size_classes(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``n`` representative sizes and how often to draw each (by count).

        Class ``k`` holds the mass fractions ``k/n .. (k+1)/n`` of the grading; it is represented
        by the nominal diameter at its middle mass fraction ``(k + 1/2) / n``. Each class holds
        ``1/n`` of the mass, so it holds a share of the stones proportional to
        ``1 / D_n^3``: drawing the classes with the returned count probabilities reproduces the
        grading's mass curve at the class midpoints.

        Parameters
        ----------
        n : int
            Number of classes (>= 1).

        Returns
        -------
        nominal_diameters : numpy.ndarray, shape (n,)
            Increasing representative nominal diameters, m.
        probabilities : numpy.ndarray, shape (n,)
            Probability that a stone drawn at random (by count) is of each class; sums to 1.
        """
        if int(n) != n or n < 1:
            raise CaseFileError(f"RockGrading.size_classes: n must be an integer >= 1, got {n}")
        n = int(n)
        diameters = np.asarray(self.nominal_diameter_at((np.arange(n) + 0.5) / n), dtype=np.float64)
        weights = diameters**-3.0
        return diameters.reshape(n), (weights / weights.sum()).reshape(n)


@dataclass(frozen=True, eq=False)
class GradedRock:
    """One rock shape of a graded library.

    Attributes
    ----------
    mesh : TetMesh
        Convex random rock, centroid at the origin (``shapes.random_rock``), scaled so that its
        mesh volume is exactly ``nominal_diameter ** 3``.
    nominal_diameter : float
        ``D_n`` in m.
    probability : float
        Probability of drawing this shape (by count) so that the library reproduces the grading.
    elongation : float
        Ratio of the longest to the middle axis of the rock's ellipsoid.
    """

    mesh: TetMesh
    nominal_diameter: float
    probability: float
    elongation: float


def _scaled_to_nominal_diameter(mesh: TetMesh, nominal_diameter: float) -> TetMesh:
    """The mesh scaled about its centroid so that its volume is ``nominal_diameter ** 3``."""
    properties = mass_properties(mesh)
    factor = nominal_diameter / properties.volume ** (1.0 / 3.0)
    nodes = properties.centroid + (mesh.nodes - properties.centroid) * factor
    return TetMesh(nodes=nodes, tets=mesh.tets, name=mesh.name)


def rock_library(
    grading: RockGrading,
    *,
    n_shapes: int,
    n_size_classes: int = default_of("underlayer", "size_classes"),
    seed: int = default_of("underlayer", "seed"),
    elongation: tuple[float, float] = (1.0, 1.6),
    mesh_size: float | None = None,
) -> list[GradedRock]:
    """A small set of distinct convex rocks that together represent a grading.

    The grading is split into ``n_size_classes`` classes of equal mass
    (:meth:`RockGrading.size_classes`); shape ``i`` belongs to class ``i % n_size_classes``, gets
    an elongation drawn uniformly from ``elongation`` and its own random hull
    (``shapes.random_rock``), and is scaled to its class's nominal diameter. A class's count
    probability is shared equally between its shapes.

    Parameters
    ----------
    grading : RockGrading
    n_shapes : int
        Number of distinct shapes (>= n_size_classes, so that every class has one).
    n_size_classes : int
        Number of size classes (>= 1).
    seed : int
        Seed of ``numpy.random.default_rng``; the same arguments give the same library.
    elongation : (float, float)
        Range of the longest-to-middle axis ratio (1 <= low <= high).
    mesh_size : float, optional
        Element size in m for every rock; default ``shapes.random_rock``'s (nominal diameter / 3.8,
        so about 300-600 tetrahedra per rock whatever its size).

    Returns
    -------
    list of GradedRock
        In shape order; probabilities sum to 1.

    Examples
    --------
    >>> rocks = rock_library(RockGrading(dn50=0.2, dn85_over_dn15=1.4), n_shapes=3)
    >>> [round(rock.nominal_diameter, 3) for rock in rocks]
    [0.171, 0.2, 0.234]
    """
    if not isinstance(grading, RockGrading):
        raise CaseFileError(
            f"rock_library: grading must be a RockGrading, got {type(grading).__name__}"
        )
    if int(n_size_classes) != n_size_classes or n_size_classes < 1:
        raise CaseFileError(
            f"rock_library: n_size_classes must be an integer >= 1, got {n_size_classes}"
        )
    if int(n_shapes) != n_shapes or n_shapes < n_size_classes:
        raise CaseFileError(
            f"rock_library: n_shapes must be an integer >= n_size_classes ({n_size_classes}), so "
            f"that every size class has a shape; got {n_shapes}"
        )
    try:
        low, high = (float(value) for value in elongation)
    except (TypeError, ValueError) as error:
        raise CaseFileError(
            f"rock_library: elongation must be a (low, high) pair, got {elongation!r}"
        ) from error
    if not (np.isfinite(low) and np.isfinite(high) and 1.0 <= low <= high):
        raise CaseFileError(
            f"rock_library: elongation must satisfy 1 <= low <= high, got {elongation}"
        )
    n_shapes, n_size_classes = int(n_shapes), int(n_size_classes)
    diameters, class_probabilities = grading.size_classes(n_size_classes)
    classes = np.arange(n_shapes) % n_size_classes
    shapes_per_class = np.bincount(classes, minlength=n_size_classes)
    rng = np.random.default_rng(seed)
    elongations = rng.uniform(low, high, size=n_shapes)
    rock_seeds = rng.integers(0, 2**31 - 1, size=n_shapes)
    library = []
    for i in range(n_shapes):
        size = float(diameters[classes[i]])
        mesh = random_rock(size=size, elongation=float(elongations[i]), seed=int(rock_seeds[i]),
                           n_vertices=_ROCK_VERTICES, mesh_size=mesh_size)
        library.append(
            GradedRock(
                mesh=_scaled_to_nominal_diameter(mesh, size),
                nominal_diameter=size,
                probability=float(class_probabilities[classes[i]] / shapes_per_class[classes[i]]),
                elongation=float(elongations[i]),
            )
        )
    return library
