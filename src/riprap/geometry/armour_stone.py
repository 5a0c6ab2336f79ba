"""Armour stone gradings as a coastal engineer names them: EN 13383-1 classes, custom gradings,
the Rosin-Rammler mass curve, scaling to a laboratory model, drawing stones and checking a set
of stones against its class.

Sources. The standard classes, their nominal limits NLL, NUL and the range of the effective mean
mass M_em are EN 13383-1:2002 as coded in Sander-w/breakwater ``material.py`` (its
``RockGrading``; shared/validation/armour_design.md section 5.3). The extreme limits follow the
rule ELL = 0.7 NLL, EUL = 1.5 NUL for every class here (the rule given for LMA and HMA with this
task; ricbencar/breakwater-cubes-calculator applies it to all classes too). It could not be checked
against the standard's own table; each class's four limits are written out in
``_STANDARD_CLASSES`` so that a correction is one row. The mass-passing requirements, the same for
every class here: at most 5 % of the mass lighter than ELL, at most 10 % lighter than NLL, at least
70 % lighter than NUL, at least 97 % lighter than EUL (Wikipedia, "Armourstone", after EN 13383:
class 60-300 has up to 10 % of its stones lighter than 60 kg and up to 30 % heavier than 300 kg,
and the standard gives further values, ELL and EUL, not to be passed by more than 5 % and 3 %).

Effective mean mass. ``M_em`` is the mean mass by count of the stones of a sample, leaving out
those lighter than ELL (so that fragments do not pull it down); the stones lighter than ELL are at
most 5 % of the mass but can be many. Wikipedia words it as the sample's total mass over its
count of stones, without the exclusion; its remark that for LMA 15/300 "M50 is 1.57 times the
M_em" agrees with the exclusion: the curve below has M50 / M_em = 1.58 with stones lighter than
ELL left out and 3.98 with every stone counted.

The curve. The Rock Manual (CIRIA, CUR, CETMEF 2007, C683, section 3.4.3, p. 113) interpolates
gradings with a Rosin-Rammler curve of the fraction ``y`` of the mass in stones lighter than ``M``:

    y(M) = 1 - exp(ln(0.5) (M / M50)^n),        M_y = M50 (ln(1 - y) / ln 0.5)^(1/n),

so that ``M85 / M15 = (ln 0.15 / ln 0.85)^(1/n)``, i.e. ``n = ln(ln 0.15 / ln 0.85) / ln(M85 / M15)
= 2.4573 / ln(M85 / M15)`` (the uniformity index ``n_RRM``). A standard class gets the curve
through NLL at ``y = 0.06`` and NUL at ``y = 0.90``: ``n = ln(ln 0.10 / ln 0.94) / ln(NUL / NLL)``,
``M50 = NLL (ln 0.94 / ln 0.5)^(-1/n)`` (the Rock Manual's way as coded in Sander-w/breakwater
``RockGrading.rosin_rammler``, "p113, bottom"; the two fractions are that package's defaults, inside
EN 13383's bands, not checked against the Rock Manual's text). Every class's curve then has its M_em
inside the class's range and meets the four mass-passing requirements
(tests/unit/test_armour_stone.py). M50 taken from the middle of the M_em range instead was tried
and dropped: for LMA 15/300 it gives M50 = 155 kg and 8 % of the mass above EUL, failing the 97 %
requirement.

Scaling to a laboratory model. A hydraulic model keeps the stability number
``N_s = H / (Delta D_n)`` of the prototype: wave heights scale with the length scale ``lambda``
(prototype / model), so ``D_n,model = D_n,prototype Delta_prototype / (lambda Delta_model)``, with
``Delta = rho_stone / rho_water - 1`` on each side (sea water in the prototype, fresh water in the
flume); with equal ``Delta`` this is ``D_n / lambda``. Masses follow from the model stone's
density, ``M = rho D_n^3``; every mass of the curve and of the class scales by the same factor and
``n`` is unchanged.

Drawing stones. :meth:`ArmourGrading.sample_masses` draws stones one by one (by count) so that the
set of stones has the mass curve: a stone's count density is the curve's mass density over ``M``.
Stones lighter than the mass that 0.1 % of the mass passes are not drawn (0.1 % of the mass; below
every standard class's ELL): for ``n`` near 1 the count of stones of the curve grows without bound
as ``M`` tends to 0, and a model has no dust.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import quad

from riprap.errors import CaseFileError
from riprap.geometry.armour_units import _positive
from riprap.geometry.rock_grading import (_MAX_SPREAD, RockGrading, checked_spread,
                                          checked_draw)
from riprap.schema import default_of

# ln(ln 0.15 / ln 0.85) = 2.4573: n_RRM ln(M85 / M15).
_SPREAD_EXPONENT = float(np.log(np.log(0.15) / np.log(0.85)))

# Fractions of the mass passing NLL and NUL on a standard class's curve (Sander-w/breakwater's
# defaults; EN 13383 allows at most 10 % and at least 70 %).
_PASSING_AT_NOMINAL_LOWER = 0.06
_PASSING_AT_NOMINAL_UPPER = 0.90

# No stone is drawn lighter than the mass this fraction of the mass passes.
_LIGHTEST_DRAWN_FRACTION = 0.001

# Heaviest plausible stone, kg: over four times the heaviest EN 13383 limit (EUL of HMA
# 10000/15000, 22.5 t); catches a mass or a diameter typed in the wrong unit.
_HEAVIEST_STONE = 1.0e5

# Plausible stone densities, kg/m^3: below, 2.65 is a density in t/m^3; above, the schema's bound
# on a material's density.
_DENSITY_RANGE = (500.0, 25000.0)

# A custom grading's M50 may lie this factor from the median of the Rosin-Rammler curve through its
# M15 and M85 (a log-normal median sqrt(M15 M85) lies within it up to M85 / M15 = 90).
_MEDIAN_FACTOR = 1.5

# Widest mass spread M85 / M15: the cube of rock_grading's widest D_n85 / D_n15.
_MAX_MASS_SPREAD = _MAX_SPREAD**3

_ROCK_DENSITY = default_of("materials", "density")
_FLUME_WATER_DENSITY = default_of("fluid", "water_density")


@dataclass(frozen=True)
class StandardClass:
    """An EN 13383-1 mass grading class; every mass in kg.

    Attributes
    ----------
    name : str
        E.g. ``"HMA 300/1000"``; a scaled class says its scale.
    extreme_lower_limit, nominal_lower_limit, nominal_upper_limit, extreme_upper_limit : float
        ELL, NLL, NUL, EUL.
    effective_mean_mass_range : (float, float)
        Lower and upper bound of M_em (category A).
    """

    name: str
    extreme_lower_limit: float
    nominal_lower_limit: float
    nominal_upper_limit: float
    extreme_upper_limit: float
    effective_mean_mass_range: tuple[float, float]

    def scaled(self, mass_factor: float, name: str) -> StandardClass:
        """The class with every mass multiplied by ``mass_factor``."""
        low, high = self.effective_mean_mass_range
        return StandardClass(
            name=name,
            extreme_lower_limit=self.extreme_lower_limit * mass_factor,
            nominal_lower_limit=self.nominal_lower_limit * mass_factor,
            nominal_upper_limit=self.nominal_upper_limit * mass_factor,
            extreme_upper_limit=self.extreme_upper_limit * mass_factor,
            effective_mean_mass_range=(low * mass_factor, high * mass_factor),
        )


# name, ELL, NLL, NUL, EUL, M_em lower, M_em upper (kg): NLL, NUL, M_em from armour_design.md 5.3;
# ELL = 0.7 NLL, EUL = 1.5 NUL.
_STANDARD_CLASSES = (
    ("LMA 5/40", 3.5, 5.0, 40.0, 60.0, 10.0, 20.0),
    ("LMA 10/60", 7.0, 10.0, 60.0, 90.0, 20.0, 35.0),
    ("LMA 40/200", 28.0, 40.0, 200.0, 300.0, 80.0, 120.0),
    ("LMA 15/300", 10.5, 15.0, 300.0, 450.0, 45.0, 135.0),
    ("LMA 60/300", 42.0, 60.0, 300.0, 450.0, 120.0, 190.0),
    ("HMA 300/1000", 210.0, 300.0, 1000.0, 1500.0, 540.0, 690.0),
    ("HMA 1000/3000", 700.0, 1000.0, 3000.0, 4500.0, 1700.0, 2100.0),
    ("HMA 3000/6000", 2100.0, 3000.0, 6000.0, 9000.0, 4200.0, 4800.0),
    ("HMA 6000/10000", 4200.0, 6000.0, 10000.0, 15000.0, 7500.0, 8500.0),
    ("HMA 10000/15000", 7000.0, 10000.0, 15000.0, 22500.0, 12000.0, 13000.0),
)
_CLASSES = {row[0]: StandardClass(row[0], *row[1:5], effective_mean_mass_range=row[5:7])
            for row in _STANDARD_CLASSES}

STANDARD_CLASS_NAMES: tuple[str, ...] = tuple(_CLASSES)
"""The EN 13383-1 classes known, lightest first."""

# "LMA 10/60", "LMA10-60", "lma_10_60", "HMA 300 / 1000 kg".
_NAME = re.compile(r"(LMA|HMA)[\s_\-]*(\d+)\s*[/_\-\s]\s*(\d+)(?:\s*KG)?")


def standard_class(name: str) -> StandardClass:
    """The EN 13383-1 class of this name (``"LMA 10/60"``, ``"LMA10-60"``, ``"lma_10_60"`` ...).

    Raises
    ------
    CaseFileError
        For a name that is not one of :data:`STANDARD_CLASS_NAMES`, listing them.
    """
    match = _NAME.fullmatch(name.strip().upper()) if isinstance(name, str) else None
    canonical = f"{match[1]} {int(match[2])}/{int(match[3])}" if match else None
    if canonical not in _CLASSES:
        raise CaseFileError(
            f"standard_class: name must be an EN 13383-1 class, got {name!r}; known: "
            f"{', '.join(STANDARD_CLASS_NAMES)}"
        )
    return _CLASSES[canonical]


def uniformity_index(m85_over_m15: float) -> float:
    """Rosin-Rammler ``n_RRM`` of a mass spread: ``ln(ln 0.15 / ln 0.85) / ln(M85 / M15)``."""
    spread = _mass_spread(m85_over_m15, "uniformity_index", "m85_over_m15")
    if spread == 1.0:
        raise CaseFileError(
            "uniformity_index: m85_over_m15 must exceed 1 (a Rosin-Rammler grading has a "
            "spread; stones of one size: RockGrading(dn85_over_dn15=1)), got 1.0"
        )
    return _SPREAD_EXPONENT / float(np.log(spread))


def _mass_spread(value: object, where: str, name: str) -> float:
    return checked_spread(value, where, name, widest=_MAX_MASS_SPREAD,
                          meaning=f"a ratio of masses, the cube of a D_n85 / D_n15 of at most "
                                  f"{_MAX_SPREAD:g}")


def _density(value: object, where: str, name: str = "density") -> float:
    density = _positive(value, name, where, unit="kg/m^3")
    low, high = _DENSITY_RANGE
    if not low <= density <= high:
        raise CaseFileError(
            f"{where}: {name} must lie in {low:g}..{high:g} kg/m^3 (2.65 t/m^3 is 2650 kg/m^3), "
            f"got {density}"
        )
    return density


def _nested(values, check, where: str, unit: str) -> dict[str, float]:
    """Three named values, each checked by ``check(value, name, where)``, increasing."""
    checked = {name: check(value, name, where) for name, value in values}
    if not np.all(np.diff(list(checked.values())) > 0.0):
        raise CaseFileError(
            f"{where}: {' < '.join(checked)} must hold (the values nest), got "
            + ", ".join(f"{name} = {value:g}" for name, value in checked.items()) + f" {unit}"
        )
    return checked


def _stone_mass(value: object, name: str, where: str) -> float:
    mass = _positive(value, name, where, unit="kg")
    if mass > _HEAVIEST_STONE:
        raise CaseFileError(
            f"{where}: {name} = {mass:g} kg is heavier than any armour stone (at most "
            f"{_HEAVIEST_STONE:g} kg): a mass in g, or a diameter in the wrong unit?"
        )
    return mass


@dataclass(frozen=True)
class ArmourGrading:
    """A Rosin-Rammler grading of armour stone, by mass.

    Parameters
    ----------
    m50 : float
        Median mass ``M50`` in kg (half the mass is in lighter stones).
    uniformity_index : float
        ``n_RRM`` (> 0; larger is narrower): ``ln(ln 0.15 / ln 0.85) / ln(M85 / M15)``.
    density : float
        Stone density in kg/m^3 (nominal diameters ``D_n = (M / density)^(1/3)``).
    standard_class : StandardClass, optional
        The EN 13383 class the grading stands for (its limits check sets of stones).

    Build one with :func:`standard_grading`, :meth:`from_masses`, :meth:`from_nominal_diameters`
    or :meth:`from_spread`.

    Examples
    --------
    >>> grading = standard_grading("HMA 300/1000")
    >>> round(grading.m50, 1), round(grading.uniformity_index, 3)
    (670.6, 3.004)
    >>> round(grading.mass_passing(1000.0), 3)
    0.9
    """

    m50: float
    uniformity_index: float
    density: float = _ROCK_DENSITY
    standard_class: StandardClass | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "m50", _stone_mass(self.m50, "m50", "ArmourGrading"))
        object.__setattr__(self, "density", _density(self.density, "ArmourGrading"))
        index = _positive(self.uniformity_index, "uniformity_index", "ArmourGrading", unit="-")
        widest = _SPREAD_EXPONENT / np.log(_MAX_MASS_SPREAD)
        if index < widest:
            raise CaseFileError(
                f"ArmourGrading: uniformity_index must be at least {widest:.4f} (M85 / M15 at most "
                f"{_MAX_MASS_SPREAD:g}), got {index}"
            )
        object.__setattr__(self, "uniformity_index", index)
        if self.standard_class is not None and not isinstance(self.standard_class, StandardClass):
            raise CaseFileError(
                f"ArmourGrading: standard_class must be a StandardClass (standard_class(name)), "
                f"got {type(self.standard_class).__name__}"
            )

    # -- constructors -------------------------------------------------------------------------

    @classmethod
    def from_masses(cls, m15: float, m50: float, m85: float,
                    density: float = _ROCK_DENSITY) -> ArmourGrading:
        """A custom grading through ``M50`` with the spread ``M85 / M15`` (kg).

        The three must nest (``M15 < M50 < M85``) and ``M50`` must lie within a factor 1.5 of the
        median of the Rosin-Rammler curve through ``M15`` and ``M85``,
        ``M15 (ln 0.5 / ln 0.85)^(1/n)``.
        """
        where = "ArmourGrading.from_masses"
        masses = _nested((("m15", m15), ("m50", m50), ("m85", m85)), _stone_mass, where, "kg")
        index = uniformity_index(_mass_spread(masses["m85"] / masses["m15"], where,
                                              "m85 / m15"))
        curve_median = masses["m15"] * (np.log(0.5) / np.log(0.85)) ** (1.0 / index)
        if not 1.0 / _MEDIAN_FACTOR <= masses["m50"] / curve_median <= _MEDIAN_FACTOR:
            raise CaseFileError(
                f"{where}: m50 = {masses['m50']:g} kg is not the median of a Rosin-Rammler "
                f"grading through m15 = {masses['m15']:g} and m85 = {masses['m85']:g} kg: that "
                f"median is {curve_median:.4g} kg, and m50 must lie within a factor "
                f"{_MEDIAN_FACTOR:g} of it"
            )
        return cls(m50=masses["m50"], uniformity_index=index, density=density)

    @classmethod
    def from_nominal_diameters(cls, dn15: float, dn50: float, dn85: float,
                               density: float = _ROCK_DENSITY) -> ArmourGrading:
        """A custom grading from ``D_n15``, ``D_n50``, ``D_n85`` in m (by mass passing)."""
        where = "ArmourGrading.from_nominal_diameters"
        density = _density(density, where)
        diameters = _nested((("dn15", dn15), ("dn50", dn50), ("dn85", dn85)), _positive, where,
                            "m")
        checked_spread(diameters["dn85"] / diameters["dn15"], where, "dn85 / dn15")
        for name, diameter in diameters.items():
            _stone_mass(density * diameter**3, f"the mass of {name} = {diameter:g} m", where)
        masses = {name: density * diameter**3 for name, diameter in diameters.items()}
        return cls.from_masses(masses["dn15"], masses["dn50"], masses["dn85"], density=density)

    @classmethod
    def from_spread(cls, dn50: float, dn85_over_dn15: float,
                    density: float = _ROCK_DENSITY) -> ArmourGrading:
        """A custom grading given as :class:`RockGrading` gives one: ``D_n50`` (m) and
        ``D_n85 / D_n15``."""
        where = "ArmourGrading.from_spread"
        density = _density(density, where)
        dn50 = _positive(dn50, "dn50", where)
        spread = checked_spread(dn85_over_dn15, where)
        m50 = _stone_mass(density * dn50**3, f"the mass of dn50 = {dn50:g} m", where)
        return cls(m50=m50, uniformity_index=uniformity_index(spread**3), density=density)

    # -- the curve ----------------------------------------------------------------------------

    @property
    def dn50(self) -> float:
        """``D_n50 = (M50 / density)^(1/3)`` in m."""
        return float((self.m50 / self.density) ** (1.0 / 3.0))

    @property
    def m85_over_m15(self) -> float:
        """``M85 / M15 = (ln 0.15 / ln 0.85)^(1/n)`` (``W85 / W15``)."""
        return float(np.exp(_SPREAD_EXPONENT / self.uniformity_index))

    @property
    def dn85_over_dn15(self) -> float:
        """``D_n85 / D_n15 = (M85 / M15)^(1/3)``."""
        return self.m85_over_m15 ** (1.0 / 3.0)

    def mass_passing(self, mass: float | np.ndarray) -> float | np.ndarray:
        """``y(M)``: the fraction of the mass in stones lighter than ``mass`` (kg)."""
        masses = np.asarray(mass, dtype=np.float64)
        if np.any(~np.isfinite(masses) | (masses < 0.0)):
            raise CaseFileError(
                f"ArmourGrading.mass_passing: masses must be finite and >= 0 kg, got {mass}"
            )
        result = -np.expm1(np.log(0.5) * (masses / self.m50) ** self.uniformity_index)
        return float(result) if result.ndim == 0 else result

    def mass_at(self, mass_fraction_passing: float | np.ndarray) -> float | np.ndarray:
        """``M_y``: the mass (kg) that the fraction ``y`` of the mass passes."""
        y = np.asarray(mass_fraction_passing, dtype=np.float64)
        if np.any(~((y > 0.0) & (y < 1.0))):
            raise CaseFileError(
                f"ArmourGrading.mass_at: mass fractions must lie strictly between 0 and 1, got "
                f"{mass_fraction_passing}"
            )
        result = self.m50 * (np.log1p(-y) / np.log(0.5)) ** (1.0 / self.uniformity_index)
        return float(result) if result.ndim == 0 else result

    def nominal_diameter_at(self, mass_fraction_passing: float | np.ndarray
                            ) -> float | np.ndarray:
        """``D_ny = (M_y / density)^(1/3)`` in m."""
        return (self.mass_at(mass_fraction_passing) / self.density) ** (1.0 / 3.0)

    def effective_mean_mass(self, lower_limit: float | None = None) -> float:
        """Mean mass by count (kg) of the curve's stones of ``lower_limit`` or more.

        ``lower_limit`` defaults to the class's ELL (the curve's ``M_em``); a grading without a
        class must be given one (> 0: for ``n <= 1`` the curve's count of stones is unbounded).

        The count density is the mass density over ``M``; with ``u = ln 2 (M / M50)^n``:
        ``M_em = M50 exp(-u_L) / ((ln 2)^(1/n) int_{u_L}^inf u^(-1/n) exp(-u) du)``.
        """
        where = "ArmourGrading.effective_mean_mass"
        if lower_limit is None:
            if self.standard_class is None:
                raise CaseFileError(
                    f"{where}: lower_limit must be given (kg) for a grading without a standard "
                    f"class, got None"
                )
            lower_limit = self.standard_class.extreme_lower_limit
        lower = _positive(lower_limit, "lower_limit", where, unit="kg")
        n = self.uniformity_index
        u_lower = np.log(2.0) * (lower / self.m50) ** n
        # exp(-u_L) / int_{u_L}^inf u^(-1/n) exp(-u) du; e^-750 is nothing beside the integral.
        if u_lower < 1.0:  # u = e^t: smooth near u_L however small, for any n
            integral, _ = quad(lambda t: np.exp((1.0 - 1.0 / n) * t - np.exp(t)),
                               np.log(u_lower), np.log(750.0), epsabs=0.0, epsrel=1e-11, limit=200)
            ratio = np.exp(-u_lower) / integral
        else:  # u = u_L + s: no underflow however far out the limit lies
            integral, _ = quad(lambda s: (u_lower + s) ** (-1.0 / n) * np.exp(-s), 0.0, 750.0,
                               epsabs=0.0, epsrel=1e-11, limit=200)
            ratio = 1.0 / integral
        return float(self.m50 * ratio / np.log(2.0) ** (1.0 / n))

    # -- stones -------------------------------------------------------------------------------

    def sample_masses(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """Masses (kg) of ``count`` stones drawn at random, one by one.

        A large sample has the grading's mass curve: its mass-weighted ``M50`` and ``M85 / M15``
        tend to the grading's (see :func:`grading_statistics`). No stone is lighter than
        ``M_0.001`` (module notes). Drawn by rejection: a mass drawn by mass from the curve above
        ``M_0.001`` is kept with probability ``M_0.001 / M``. ``count`` (>= 0) and ``rng`` (a
        ``numpy.random.Generator``) as :meth:`RockGrading.sample`; returns shape ``(count,)``.
        """
        count = checked_draw(count, rng, "ArmourGrading.sample_masses")
        lightest = self.mass_at(_LIGHTEST_DRAWN_FRACTION)
        kept_share = lightest / self.effective_mean_mass(lightest)
        drawn: list[np.ndarray] = []
        found = 0
        while found < count:
            batch = int(1.2 * (count - found) / kept_share) + 16
            masses = self.mass_at(rng.uniform(_LIGHTEST_DRAWN_FRACTION, 1.0, size=batch))
            kept = masses[rng.uniform(size=batch) * masses < lightest]
            drawn.append(kept)
            found += kept.size
        return np.concatenate(drawn)[:count] if drawn else np.zeros(0)

    def statistics(self, masses: np.ndarray) -> GradingStatistics:
        """:func:`grading_statistics` of a set of stones of this grading's density; M_em leaves
        out stones lighter than the class's ELL (none without a class)."""
        lower = 0.0 if self.standard_class is None else self.standard_class.extreme_lower_limit
        return grading_statistics(masses, density=self.density, extreme_lower_limit=lower)

    def conformity(self, masses: np.ndarray) -> Conformity:
        """:func:`en13383_conformity` of a set of stones against this grading's class."""
        if self.standard_class is None:
            raise CaseFileError(
                "ArmourGrading.conformity: the grading has no standard class to check against "
                "(standard_grading(name) has one)"
            )
        return en13383_conformity(masses, self.standard_class)

    # -- the model ----------------------------------------------------------------------------

    def to_model(self, length_scale: float, *, model_density: float,
                 prototype_water_density: float,
                 model_water_density: float = _FLUME_WATER_DENSITY) -> ArmourGrading:
        """The laboratory model's grading at ``length_scale`` (prototype / model).

        ``D_n,model = D_n,prototype Delta_prototype / (length_scale Delta_model)`` keeps the
        stability number ``H / (Delta D_n)``; masses follow with ``model_density``. The class's
        limits scale with the curve.
        """
        where = "ArmourGrading.to_model"
        scale = _positive(length_scale, "length_scale", where, unit="(prototype / model)")
        model_density = _density(model_density, where, "model_density")
        deltas = []
        for stone, water, name in ((self.density, prototype_water_density,
                                    "prototype_water_density"),
                                   (model_density, model_water_density, "model_water_density")):
            water = _positive(water, name, where, unit="kg/m^3")
            if stone <= water:
                raise CaseFileError(
                    f"{where}: the stones must be denser than the water, got stone density "
                    f"{stone:g} and {name} = {water:g} kg/m^3"
                )
            deltas.append(stone / water - 1.0)
        diameter_factor = deltas[0] / (scale * deltas[1])
        mass_factor = model_density / self.density * diameter_factor**3
        model_class = None
        if self.standard_class is not None:
            model_class = self.standard_class.scaled(
                mass_factor, f"{self.standard_class.name} at 1:{scale:g}")
        return replace(self, m50=self.m50 * mass_factor, density=model_density,
                       standard_class=model_class)

    def as_rock_grading(self) -> RockGrading:
        """The log-normal :class:`RockGrading` with the same ``D_n50`` and ``D_n85 / D_n15`` (for
        ``rock_library``); the two curves differ in the tails only."""
        return RockGrading(dn50=self.dn50, dn85_over_dn15=self.dn85_over_dn15)


def standard_grading(name: str, density: float = _ROCK_DENSITY) -> ArmourGrading:
    """The Rosin-Rammler grading of an EN 13383-1 class (module notes: through NLL at 6 % and NUL
    at 90 % of the mass passing).

    Parameters
    ----------
    name : str
        ``"LMA 10/60"``, ``"LMA10-60"``, ``"lma_10_60"`` ... (:data:`STANDARD_CLASS_NAMES`).
    density : float
        Stone density in kg/m^3 (the classes are by mass; it sets the nominal diameters).
    """
    grading_class = standard_class(name)
    lower = grading_class.nominal_lower_limit
    anchors = np.log1p(-_PASSING_AT_NOMINAL_UPPER) / np.log1p(-_PASSING_AT_NOMINAL_LOWER)
    index = float(np.log(anchors) / np.log(grading_class.nominal_upper_limit / lower))
    m50 = lower * (np.log1p(-_PASSING_AT_NOMINAL_LOWER) / np.log(0.5)) ** (-1.0 / index)
    return ArmourGrading(m50=float(m50), uniformity_index=index, density=density,
                         standard_class=grading_class)


# -- sets of stones -------------------------------------------------------------------------------


@dataclass(frozen=True)
class GradingStatistics:
    """The grading of a set of stones, by mass passing.

    ``M_y`` is read off the cumulative mass curve: with the stones sorted by mass, stone ``i``
    stands at the fraction ``F_i`` of the total mass in stones no heavier than it (itself
    included); ``M_y`` is interpolated linearly in ``F`` between the stones (the lightest stone's
    mass below ``F_1``).

    Attributes
    ----------
    count : int
    total_mass : float
        kg.
    m15, m50, m85 : float
        kg.
    m85_over_m15 : float
        ``W85 / W15`` in older texts.
    dn50 : float
        ``(M50 / density)^(1/3)``, m.
    dn85_over_dn15 : float
        ``(M85 / M15)^(1/3)``.
    effective_mean_mass : float
        Mean mass (kg) of the stones not lighter than ``extreme_lower_limit``; NaN if none is.
    extreme_lower_limit : float
        kg; 0 counts every stone.
    """

    count: int
    total_mass: float
    m15: float
    m50: float
    m85: float
    m85_over_m15: float
    dn50: float
    dn85_over_dn15: float
    effective_mean_mass: float
    extreme_lower_limit: float


def _stone_masses(masses: object, where: str) -> np.ndarray:
    try:
        values = np.asarray(masses, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise CaseFileError(f"{where}: masses must be numbers in kg, got {masses!r}") from error
    if values.ndim != 1 or values.size == 0:
        raise CaseFileError(
            f"{where}: masses must be a list of at least one stone mass, got shape {values.shape}"
        )
    bad = ~(np.isfinite(values) & (values > 0.0))
    if np.any(bad):
        raise CaseFileError(
            f"{where}: masses must be positive and finite in kg, got {values[bad][0]} "
            f"(stone {int(np.flatnonzero(bad)[0])})"
        )
    return values


def _fraction_lighter(masses: np.ndarray, limit: float) -> float:
    return float(masses[masses < limit].sum() / masses.sum())


def grading_statistics(masses: np.ndarray, *, density: float = _ROCK_DENSITY,
                       extreme_lower_limit: float = 0.0) -> GradingStatistics:
    """M15, M50, M85, spreads, ``D_n50`` and M_em of a set of stone masses (kg).

    Parameters
    ----------
    masses : array_like, shape (n,)
        Stone masses in kg (n >= 1).
    density : float
        Stone density in kg/m^3, for ``D_n50``.
    extreme_lower_limit : float
        ELL in kg: M_em leaves out the stones lighter than it (EN 13383's effective mean mass);
        0 counts them all.
    """
    where = "grading_statistics"
    values = np.sort(_stone_masses(masses, where))
    density = _density(density, where)
    lower = float(extreme_lower_limit)
    if not (np.isfinite(lower) and lower >= 0.0):
        raise CaseFileError(f"{where}: extreme_lower_limit must be >= 0 kg, got {lower}")
    passing = np.cumsum(values) / values.sum()
    m15, m50, m85 = (float(np.interp(y, passing, values)) for y in (0.15, 0.5, 0.85))
    counted = values[values >= lower]
    return GradingStatistics(
        count=int(values.size),
        total_mass=float(values.sum()),
        m15=m15,
        m50=m50,
        m85=m85,
        m85_over_m15=m85 / m15,
        dn50=(m50 / density) ** (1.0 / 3.0),
        dn85_over_dn15=(m85 / m15) ** (1.0 / 3.0),
        effective_mean_mass=float(counted.mean()) if counted.size else float("nan"),
        extreme_lower_limit=lower,
    )


@dataclass(frozen=True)
class Requirement:
    """One EN 13383 requirement on a set of stones: ``lowest <= measured <= highest``.

    Attributes
    ----------
    description : str
    measured : float
        A fraction of the mass, or M_em in kg (``unit`` says which); NaN fails.
    lowest, highest : float
    unit : str
    """

    description: str
    measured: float
    lowest: float
    highest: float
    unit: str

    @property
    def passed(self) -> bool:
        return bool(self.lowest <= self.measured <= self.highest)


@dataclass(frozen=True)
class Conformity:
    """A set of stones checked against an EN 13383 class: every requirement and whether it held."""

    grading_class: StandardClass
    requirements: tuple[Requirement, ...]

    @property
    def passed(self) -> bool:
        return all(requirement.passed for requirement in self.requirements)

    @property
    def failures(self) -> tuple[Requirement, ...]:
        return tuple(requirement for requirement in self.requirements if not requirement.passed)


# (limit, label, lowest and highest fraction of the mass lighter than it).
_MASS_PASSING_REQUIREMENTS = (
    ("extreme_lower_limit", "ELL", 0.0, 0.05),
    ("nominal_lower_limit", "NLL", 0.0, 0.10),
    ("nominal_upper_limit", "NUL", 0.70, 1.0),
    ("extreme_upper_limit", "EUL", 0.97, 1.0),
)


def en13383_conformity(masses: np.ndarray, grading_class: StandardClass | str) -> Conformity:
    """Check a set of stone masses (kg) against an EN 13383 class (a :class:`StandardClass` or
    its name): the four mass-passing requirements (module notes) and M_em within the class's
    range (category A), M_em leaving out the stones lighter than ELL."""
    where = "en13383_conformity"
    if isinstance(grading_class, str):
        grading_class = standard_class(grading_class)
    if not isinstance(grading_class, StandardClass):
        raise CaseFileError(
            f"{where}: grading_class must be a StandardClass or a class name, got "
            f"{type(grading_class).__name__}"
        )
    values = _stone_masses(masses, where)
    requirements = []
    for attribute, label, lowest, highest in _MASS_PASSING_REQUIREMENTS:
        limit = getattr(grading_class, attribute)
        bound = f"at most {highest:.0%}" if lowest == 0.0 else f"at least {lowest:.0%}"
        requirements.append(Requirement(
            description=f"{bound} of the mass lighter than {label} = {limit:g} kg",
            measured=_fraction_lighter(values, limit), lowest=lowest, highest=highest,
            unit="fraction of the mass"))
    ell = grading_class.extreme_lower_limit
    counted = values[values >= ell]
    low, high = grading_class.effective_mean_mass_range
    requirements.append(Requirement(
        description=f"M_em (stones of ELL = {ell:g} kg or more) in {low:g}..{high:g} kg",
        measured=float(counted.mean()) if counted.size else float("nan"),
        lowest=low, highest=high, unit="kg"))
    return Conformity(grading_class=grading_class, requirements=tuple(requirements))
