"""Rock armour stability formulas a measured damage level S is checked against, beside Van der
Meer (1988) in ``design_formulas``: the damage S a sea does to stones of D_n50, and the D_n50 for
a damage S, with the ranges of the tests each formula was fitted to.

- Van der Meer (2021), the modified Van der Meer formula: Van der Meer (1988) rewritten with the
  spectral period T_m-1,0 and H_s (no H_2%), c_pl = 6.49, c_s = 0.97.
- Van Gent, Smale & Kuiper (2003), the simplified formula for shallow foreshores: no wave period,
  the core's D_n50 in place of the notional permeability.
- Etemad-Shahidi, Bali & van Gent (2020, with its 2022 corrigendum): the core/armour diameter
  ratio through C_p, N^-0.1 and S^(1/6), plunging and surging forms split at xi_m-1,0 = 1.8.
- Van der Meer's (1988) notional permeability P of a cross-section from its layers' D_n50.
- The Rock Manual's damage classes of S by slope (start of damage, intermediate, failure).

Each formula has a ``*_cautions`` function that lists, in words, the parameters outside the
ranges of the tests behind it; a formula asked outside them still answers.

Every input in SI; Delta = rho_armour / rho_water - 1; N_s = H_s / (Delta D_n50) the stability
number; xi_m-1,0 = tan(alpha) / sqrt(s_m-1,0), s_m-1,0 = 2 pi H_s / (g T_m-1,0^2).

The Deltares coastal-structures-toolbox (``stability_rock_armour/vandermeer2021.py``,
``etemadshahidi2020.py``) was used to cross-check the coefficients, the validity ranges and, in
the tests, published test values; nothing of its code is used here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from riprap.analysis.design_formulas import (GRAVITY, VanDerMeerRock, _positive, relative_density,
                                             surf_similarity)
from riprap.errors import CaseFileError

__all__ = ["VanDerMeer2021Rock", "van_der_meer_2021_damage", "van_der_meer_2021_diameter",
           "van_der_meer_2021_cautions", "VanGent2003Rock", "van_gent_2003_damage",
           "van_gent_2003_diameter", "van_gent_2003_cautions", "EtemadShahidi2020Rock",
           "etemad_shahidi_permeability_coefficient", "etemad_shahidi_2020_damage",
           "etemad_shahidi_2020_diameter", "etemad_shahidi_2020_cautions", "notional_permeability",
           "DamageThresholds", "rock_damage_class"]

#: Van der Meer (2021): plunging and surging coefficients of the formula in H_s and T_m-1,0.
C_PLUNGING_2021 = 6.49
C_SURGING_2021 = 0.97
#: Van der Meer (1993), the Rock Manual: on slopes of cot alpha >= 4 only the plunging form holds.
PLUNGING_ONLY_SLOPE_COT = 4.0
#: Van Gent, Smale & Kuiper (2003): the simplified formula's coefficient.
C_VAN_GENT_2003 = 1.75
#: Etemad-Shahidi, Bali & van Gent (2020): coefficients and the breaker type's boundary.
C_PLUNGING_ETEMAD_SHAHIDI = 4.5
C_SURGING_ETEMAD_SHAHIDI = 3.9
XI_TRANSITION_ETEMAD_SHAHIDI = 1.8
#: Armour/core D_n50 ratio of Van der Meer's armour-directly-on-core structure (P = 0.5).
ARMOUR_ON_CORE_RATIO = 3.2


def _permeability_in_range(permeability: float) -> None:
    _positive(permeability=permeability)
    if not 0.1 <= permeability <= 0.6:
        raise CaseFileError(f"design formula: permeability (Van der Meer's notional P) must lie in "
                            f"0.1-0.6, got {permeability!r}")


def _core_diameter_valid(core_nominal_diameter: float) -> None:
    if not (math.isfinite(core_nominal_diameter) and core_nominal_diameter >= 0):
        raise CaseFileError(f"design formula: core_nominal_diameter must be 0 (impermeable core) "
                            f"or positive, got {core_nominal_diameter!r}")


# ---------------------------------------------------------------------------------------------
# Van der Meer (2021)

@dataclass(frozen=True)
class VanDerMeer2021Rock(VanDerMeerRock):
    """Van der Meer's (2021) modified formula: the 1988 rock formula rewritten in the spectral
    period, with ``tm`` here T_m-1,0 (s) and H_s in place of H_2% (``h2_ratio`` = 1):

        plunging (xi < xi_cr): N_s = 6.49 P^0.18 (S / sqrt N)^0.2 xi^-0.5
        surging (xi >= xi_cr): N_s = 0.97 P^-0.13 (S / sqrt N)^0.2 sqrt(cot alpha) xi^P
        xi_cr = (6.49 / 0.97 P^0.31 sqrt(tan alpha))^(1 / (P + 0.5)),

    xi = xi_m-1,0; on slopes of cot alpha >= 4 the plunging form only (Van der Meer 1993; the
    Rock Manual; the toolbox does the same). H_s may be H_m0 at the toe.

    References
    ----------
    Van der Meer, J.W. (2021). Rock armour slope stability under wave attack; the Modified Van
    der Meer Formula. J. Waterway, Port, Coastal, Ocean Eng. 147(4). Same form as the Rock
    Manual's modified formula (CIRIA, CUR, CETMEF 2007, eqs. 5.139-5.140, Van Gent et al. 2003),
    whose c_pl = 8.4, c_s = 1.3 multiply H_s / H_2%; 6.49 and 0.97 take H_s alone.
    """

    h2_ratio: float = 1.0
    c_plunging: float = C_PLUNGING_2021
    c_surging: float = C_SURGING_2021

    def __post_init__(self):
        super().__post_init__()
        _permeability_in_range(self.permeability)

    @property
    def plunging(self) -> bool:
        return self.slope_cot >= PLUNGING_ONLY_SLOPE_COT or super().plunging


def _van_der_meer_2021(hs, spectral_period, waves, slope_cot, permeability, armour_density,
                       water_density, gravity) -> VanDerMeer2021Rock:
    _positive(spectral_period=spectral_period)
    delta = relative_density(armour_density, water_density)
    return VanDerMeer2021Rock(hs, spectral_period, waves, slope_cot, permeability, delta,
                              gravity=gravity)


def van_der_meer_2021_damage(*, hs, spectral_period, waves, slope_cot, permeability,
                             armour_density, water_density, nominal_diameter,
                             gravity: float = GRAVITY) -> float:
    """Damage level S of Van der Meer's (2021) formula for stones of D_n50 =
    ``nominal_diameter`` (m) under H_s = ``hs`` (m), T_m-1,0 = ``spectral_period`` (s), N =
    ``waves``, notional permeability P = ``permeability`` (0.1-0.6). See
    :class:`VanDerMeer2021Rock`; ranges in :func:`van_der_meer_2021_cautions`."""
    return _van_der_meer_2021(hs, spectral_period, waves, slope_cot, permeability, armour_density,
                              water_density, gravity).damage(nominal_diameter)


def van_der_meer_2021_diameter(*, hs, spectral_period, waves, slope_cot, permeability,
                               armour_density, water_density, damage,
                               gravity: float = GRAVITY) -> float:
    """D_n50 (m) for which Van der Meer's (2021) formula gives damage level ``damage``."""
    return _van_der_meer_2021(hs, spectral_period, waves, slope_cot, permeability, armour_density,
                              water_density, gravity).diameter(damage)


# ---------------------------------------------------------------------------------------------
# Van Gent, Smale & Kuiper (2003)

@dataclass(frozen=True)
class VanGent2003Rock:
    """Van Gent, Smale & Kuiper's (2003) simplified formula for rock slopes on shallow
    foreshores, without a wave period:

        H_s / (Delta D_n50) = 1.75 sqrt(cot alpha) (1 + D_n50,core / D_n50) (S / sqrt N)^0.2,

    ``hs`` H_s at the toe (m), ``waves`` N, ``slope_cot`` cot alpha, ``delta`` Delta,
    ``core_nominal_diameter`` D_n50,core (m), 0 for an impermeable core.

    References
    ----------
    Van Gent, M.R.A., Smale, A.J., Kuiper, C. (2003). Stability of rock slopes with shallow
    foreshores. Proc. Coastal Structures 2003, Portland, ASCE, 100-112.
    """

    hs: float
    waves: float
    slope_cot: float
    delta: float
    core_nominal_diameter: float
    coefficient: float = C_VAN_GENT_2003

    def __post_init__(self):
        _positive(hs=self.hs, waves=self.waves, slope_cot=self.slope_cot, delta=self.delta,
                  coefficient=self.coefficient)
        _core_diameter_valid(self.core_nominal_diameter)

    def damage(self, nominal_diameter: float) -> float:
        """Damage level S for stones of D_n50 = ``nominal_diameter`` (m)."""
        _positive(nominal_diameter=nominal_diameter)
        ns = self.hs / (self.delta * nominal_diameter)
        core = 1.0 + self.core_nominal_diameter / nominal_diameter
        factor = self.coefficient * math.sqrt(self.slope_cot) * core
        return (ns / factor) ** 5 * math.sqrt(self.waves)

    def diameter(self, damage: float) -> float:
        """D_n50 (m) for damage level ``damage``: H_s / Delta = A (D_n50 + D_n50,core) with A =
        1.75 sqrt(cot alpha) (S / sqrt N)^0.2, so D_n50 = H_s / (Delta A) - D_n50,core."""
        _positive(damage=damage)
        factor = (self.coefficient * math.sqrt(self.slope_cot)
                  * (damage / math.sqrt(self.waves)) ** 0.2)
        total = self.hs / (self.delta * factor)
        if total <= self.core_nominal_diameter:
            raise CaseFileError(
                f"design formula: Van Gent et al. (2003) has no positive D_n50 for damage "
                f"{damage!r}: the core's D_n50 {self.core_nominal_diameter!r} m alone reaches "
                f"H_s / (Delta A) = {total:.4g} m; check core_nominal_diameter and hs")
        return total - self.core_nominal_diameter


def van_gent_2003_damage(*, hs, waves, slope_cot, armour_density, water_density, nominal_diameter,
                         core_nominal_diameter) -> float:
    """Damage level S of Van Gent et al.'s (2003) simplified formula (see
    :class:`VanGent2003Rock`); ``core_nominal_diameter`` 0 for an impermeable core."""
    delta = relative_density(armour_density, water_density)
    rock = VanGent2003Rock(hs, waves, slope_cot, delta, core_nominal_diameter)
    return rock.damage(nominal_diameter)


def van_gent_2003_diameter(*, hs, waves, slope_cot, armour_density, water_density, damage,
                           core_nominal_diameter) -> float:
    """D_n50 (m) of Van Gent et al.'s (2003) simplified formula for damage level ``damage``."""
    delta = relative_density(armour_density, water_density)
    return VanGent2003Rock(hs, waves, slope_cot, delta, core_nominal_diameter).diameter(damage)


# ---------------------------------------------------------------------------------------------
# Etemad-Shahidi, Bali & van Gent (2020)

def etemad_shahidi_permeability_coefficient(*, nominal_diameter: float,
                                            core_nominal_diameter: float) -> float:
    """C_p = (1 + (D_n50,core / D_n50)^(3/10))^(3/5) (Etemad-Shahidi et al. 2020, eq. 11, as
    the corrigendum and the toolbox state it); 1 for an impermeable core (D_n50,core = 0)."""
    _positive(nominal_diameter=nominal_diameter)
    _core_diameter_valid(core_nominal_diameter)
    return (1.0 + (core_nominal_diameter / nominal_diameter) ** 0.3) ** 0.6


@dataclass(frozen=True)
class EtemadShahidi2020Rock:
    """Etemad-Shahidi, Bali & van Gent's (2020) formula, with C_p of
    :func:`etemad_shahidi_permeability_coefficient`:

        plunging (xi < 1.8):  N_s = 4.5 C_p N^-0.1 S^(1/6) xi^(-7/12) (1 - 3 m)
        surging (xi >= 1.8): N_s = 3.9 C_p N^-0.1 S^(1/6) xi^(-1/3) (1 - 3 m),

    xi = xi_m-1,0 of ``hs`` H_s (m) and ``spectral_period`` T_m-1,0 (s). The factor (1 - 3 m),
    m = 1 / ``foreshore_slope_cot`` the foreshore's slope, is the depth-limited form (eqs.
    12a-12b); without a foreshore slope (None) it is 1 (eqs. 10a-10b; S solved, eqs. 17a-17b).
    ``core_nominal_diameter`` D_n50,core (m), 0 for an impermeable core.

    References
    ----------
    Etemad-Shahidi, A., Bali, M., van Gent, M.R.A. (2020). On the stability of rock armored
    rubble mound structures. Coastal Engineering 158, 103655; corrigendum, Coastal Engineering
    (2022) 104142. Equation numbers as the toolbox cites them.
    """

    hs: float
    spectral_period: float
    waves: float
    slope_cot: float
    delta: float
    core_nominal_diameter: float
    foreshore_slope_cot: float | None = None
    gravity: float = GRAVITY

    def __post_init__(self):
        _positive(hs=self.hs, spectral_period=self.spectral_period, waves=self.waves,
                  slope_cot=self.slope_cot, delta=self.delta)
        _core_diameter_valid(self.core_nominal_diameter)
        if self.foreshore_slope_cot is not None and not (
                math.isfinite(self.foreshore_slope_cot) and self.foreshore_slope_cot > 3.0):
            raise CaseFileError(f"design formula: foreshore_slope_cot must be above 3 (the factor "
                                f"1 - 3 m is then positive), got {self.foreshore_slope_cot!r}")

    @property
    def xi(self) -> float:
        return surf_similarity(self.slope_cot, self.hs, self.spectral_period, self.gravity)

    @property
    def plunging(self) -> bool:
        return self.xi < XI_TRANSITION_ETEMAD_SHAHIDI

    def _factor(self) -> float:
        """N_s / (C_p N^-0.1 S^(1/6))."""
        depth = 1.0 if self.foreshore_slope_cot is None else 1.0 - 3.0 / self.foreshore_slope_cot
        if self.plunging:
            return C_PLUNGING_ETEMAD_SHAHIDI * self.xi ** (-7.0 / 12.0) * depth
        return C_SURGING_ETEMAD_SHAHIDI * self.xi ** (-1.0 / 3.0) * depth

    def _cp(self, nominal_diameter: float) -> float:
        return etemad_shahidi_permeability_coefficient(
            nominal_diameter=nominal_diameter, core_nominal_diameter=self.core_nominal_diameter)

    def damage(self, nominal_diameter: float) -> float:
        """Damage level S for stones of D_n50 = ``nominal_diameter`` (m)."""
        _positive(nominal_diameter=nominal_diameter)
        ns = self.hs / (self.delta * nominal_diameter)
        return (ns / (self._factor() * self._cp(nominal_diameter))) ** 6 * self.waves ** 0.6

    def diameter(self, damage: float) -> float:
        """D_n50 (m) for damage level ``damage``: D_n50 C_p(D_n50) = H_s / (Delta F N^-0.1
        S^(1/6)), F the factor of the breaker type; its left side grows with D_n50, so the root
        is unique (found by bracketing, to 1e-13 relative)."""
        from scipy.optimize import brentq

        _positive(damage=damage)
        target = self.hs / (self.delta * self._factor() * self.waves ** -0.1
                            * damage ** (1.0 / 6.0))
        if self.core_nominal_diameter == 0:
            return target
        return brentq(lambda d: d * self._cp(d) - target, 1e-12 * target, target, rtol=1e-13,
                      xtol=1e-15 * target)


def etemad_shahidi_2020_damage(*, hs, spectral_period, waves, slope_cot, armour_density,
                               water_density, nominal_diameter, core_nominal_diameter,
                               foreshore_slope_cot=None, gravity: float = GRAVITY) -> float:
    """Damage level S of Etemad-Shahidi et al.'s (2020) formula (see
    :class:`EtemadShahidi2020Rock`)."""
    delta = relative_density(armour_density, water_density)
    rock = EtemadShahidi2020Rock(hs, spectral_period, waves, slope_cot, delta,
                                 core_nominal_diameter, foreshore_slope_cot, gravity)
    return rock.damage(nominal_diameter)


def etemad_shahidi_2020_diameter(*, hs, spectral_period, waves, slope_cot, armour_density,
                                 water_density, damage, core_nominal_diameter,
                                 foreshore_slope_cot=None, gravity: float = GRAVITY) -> float:
    """D_n50 (m) of Etemad-Shahidi et al.'s (2020) formula for damage level ``damage``."""
    delta = relative_density(armour_density, water_density)
    rock = EtemadShahidi2020Rock(hs, spectral_period, waves, slope_cot, delta,
                                 core_nominal_diameter, foreshore_slope_cot, gravity)
    return rock.diameter(damage)


# ---------------------------------------------------------------------------------------------
# Validity ranges

#: Quantity -> how a caution writes it.
_LABELS = {
    "slope_cot": "cot α", "waves": "N", "steepness": "s_m-1,0", "xi": "ξ_m-1,0", "delta": "Δ",
    "relative_depth": "h/H_s", "grading_ratio": "D_n85/D_n15",
    "damage_per_sqrt_waves": "S/√N", "stability_number": "N_s = H_s/(Δ D_n50)",
    "core_ratio": "D_n50,core/D_n50", "damage": "S",
}

#: Formula -> (whose tests, {quantity: (lowest, highest)}), None where a side is open.
#: Van der Meer: the Rock Manual's table of the 1988 formula's validity (deep water; s and xi
#: there of T_m, applied here to T_m-1,0, which the 2021 refit of the same tests uses).
#: Van Gent et al. (2003): their tests as the toolbox lists them for that paper's formulas, and
#: the core ratios tested (impermeable, 0.3). Etemad-Shahidi et al. (2020): their Table 1, as
#: the toolbox lists it.
VALIDITY_RANGES = {
    "van_der_meer_2021": ("Van der Meer", {
        "slope_cot": (1.5, 6.0), "waves": (None, 7500.0), "steepness": (0.01, 0.06),
        "xi": (0.7, 7.0), "delta": (1.0, 2.1), "relative_depth": (3.0, None),
        "grading_ratio": (None, 2.5), "damage_per_sqrt_waves": (None, 0.9),
        "stability_number": (1.0, 4.0)}),
    "van_gent_2003": ("Van Gent et al. (2003)", {
        "slope_cot": (2.0, 4.0), "waves": (None, 3000.0), "xi": (1.3, 15.0),
        "stability_number": (0.5, 4.5), "core_ratio": (0.0, 0.3)}),
    "etemad_shahidi_2020": ("Etemad-Shahidi et al. (2020)", {
        "slope_cot": (1.5, 6.0), "waves": (500.0, 5000.0), "steepness": (0.003, 0.088),
        "xi": (0.65, 8.18), "delta": (0.92, 2.05), "core_ratio": (0.0, 1.0),
        "stability_number": (1.0, 4.3), "damage": (2.0, 12.0)}),
}

_CAUTION_INPUTS = ("hs", "spectral_period", "waves", "slope_cot", "permeability", "armour_density",
                   "water_density", "nominal_diameter", "damage", "water_depth", "grading_ratio",
                   "core_nominal_diameter", "foreshore_slope_cot", "gravity")


def _quantities(inputs: dict) -> dict:
    """The dimensionless numbers the ranges speak of, from whichever inputs were given."""
    unknown = sorted(set(inputs) - set(_CAUTION_INPUTS))
    if unknown:
        raise CaseFileError(f"design formula cautions: unknown input {unknown[0]!r}; known: "
                            f"{', '.join(_CAUTION_INPUTS)}")
    given = {name: value for name, value in inputs.items() if value is not None}
    if "permeability" in given:
        _permeability_in_range(given["permeability"])
    if "core_nominal_diameter" in given:
        _core_diameter_valid(given["core_nominal_diameter"])
    _positive(**{name: value for name, value in given.items()
                 if name not in ("permeability", "core_nominal_diameter", "foreshore_slope_cot")})
    gravity = given.get("gravity", GRAVITY)
    out = {name: given[name] for name in ("slope_cot", "waves", "grading_ratio", "damage")
           if name in given}
    hs, period = given.get("hs"), given.get("spectral_period")
    diameter = given.get("nominal_diameter")
    if hs is not None and period is not None:
        out["steepness"] = 2.0 * math.pi * hs / (gravity * period ** 2)
        if "slope_cot" in given:
            out["xi"] = surf_similarity(given["slope_cot"], hs, period, gravity)
    if "armour_density" in given and "water_density" in given:
        out["delta"] = relative_density(given["armour_density"], given["water_density"])
        if hs is not None and diameter is not None:
            out["stability_number"] = hs / (out["delta"] * diameter)
    if hs is not None and "water_depth" in given:
        out["relative_depth"] = given["water_depth"] / hs
    if "damage" in given and "waves" in given:
        out["damage_per_sqrt_waves"] = given["damage"] / math.sqrt(given["waves"])
    if diameter is not None and given.get("core_nominal_diameter") is not None:
        out["core_ratio"] = given["core_nominal_diameter"] / diameter
    return out


def _cautions(formula: str, inputs: dict) -> list[str]:
    owner, ranges = VALIDITY_RANGES[formula]
    cautions = []
    for name, value in _quantities(inputs).items():
        if name not in ranges:
            continue
        low, high = ranges[name]
        tested = (f"tested range {low:g}-{high:g}" if low is not None and high is not None
                  else f"tested minimum {low:g}" if low is not None else f"tested maximum {high:g}")
        shown = f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
        if low is not None and value < low:
            cautions.append(f"{_LABELS[name]} = {shown} is below {owner}'s {tested}")
        elif high is not None and value > high:
            cautions.append(f"{_LABELS[name]} = {shown} is above {owner}'s {tested}")
    return cautions


def van_der_meer_2021_cautions(**inputs) -> list[str]:
    """The parameters outside the tests behind Van der Meer's formula, in words (empty when all
    lie inside). Takes the keywords of :func:`van_der_meer_2021_damage` (or ``_diameter``), any
    of them, plus ``damage``, ``water_depth`` h (m) at the toe and ``grading_ratio``
    D_n85/D_n15; what is not given is not checked.

    Ranges (CIRIA, CUR, CETMEF 2007, The Rock Manual, the validity table of Van der Meer 1988):
    cot alpha 1.5-6, N <= 7500, s 0.01-0.06, xi 0.7-7, Delta 1-2.1, h/H_s >= 3, D_n85/D_n15 <=
    2.5, S / sqrt N <= 0.9, N_s 1-4. s and xi were tabulated with T_m; T_m-1,0 is longer (by
    some 10-20 % in a single-peaked sea), so s_m-1,0 reads lower and xi_m-1,0 higher than the
    table's would for the same sea.
    P outside 0.1-0.6 is refused, not cautioned.

    >>> van_der_meer_2021_cautions(slope_cot=1.2, waves=3000)
    ["cot α = 1.2 is below Van der Meer's tested range 1.5-6"]
    """
    return _cautions("van_der_meer_2021", inputs)


def van_gent_2003_cautions(**inputs) -> list[str]:
    """The parameters outside Van Gent et al.'s (2003) tests, in words. Takes the keywords of
    :func:`van_gent_2003_damage` (or ``_diameter``), any of them, plus ``spectral_period`` (for
    xi_s-1,0). Ranges (as the toolbox lists them for the same tests): cot alpha 2-4, N <= 3000,
    xi_s-1,0 1.3-15, N_s 0.5-4.5; D_n50,core/D_n50 0-0.3 (the cores tested)."""
    return _cautions("van_gent_2003", inputs)


def etemad_shahidi_2020_cautions(**inputs) -> list[str]:
    """The parameters outside Etemad-Shahidi et al.'s (2020) data, in words. Takes the keywords
    of :func:`etemad_shahidi_2020_damage` (or ``_diameter``), any of them, plus ``damage``.
    Ranges (their Table 1, as the toolbox lists it): cot alpha 1.5-6, N 500-5000, s_m-1,0
    0.003-0.088, xi_m-1,0 0.65-8.18, Delta 0.92-2.05, D_n50,core/D_n50 0-1, N_s 1-4.3, S 2-12."""
    return _cautions("etemad_shahidi_2020", inputs)


# ---------------------------------------------------------------------------------------------
# Notional permeability

def notional_permeability(armour_dn50: float, *, filter_dn50: float | None = None,
                          core_dn50: float | None = None,
                          core_permeable: bool = True) -> tuple[float, str]:
    """Van der Meer's (1988) notional permeability P of a cross-section, the nearest of his four
    structures, and why, in words.

    The four (Van der Meer 1988; the Rock Manual's figure of them): P = 0.1, two layers of
    armour on a filter (D_n50,armour / D_n50,filter about 2) on an impermeable core; P = 0.4,
    armour on a filter on a permeable core; P = 0.5, armour directly on a permeable core
    (D_n50,armour / D_n50,core about 3.2); P = 0.6, a homogeneous mound of armour stone.

    The rule: an impermeable core (``core_permeable`` False) gives 0.1, whatever else; a filter
    over a permeable core gives 0.4; without a filter, the armour/core ratio picks 0.5 or 0.6,
    whichever of 3.2 and 1 it is nearer to on a logarithmic scale (the boundary sqrt(3.2) =
    1.79); no filter and no core given is a homogeneous mound, 0.6.

    Parameters
    ----------
    armour_dn50, filter_dn50, core_dn50 : float
        Nominal diameters D_n50 (m) of the armour, the filter (underlayer) and the core; None
        where the layer is absent.
    core_permeable : bool
        False for a core that lets no water through (clay, sand, a geotextile on fines).

    Returns
    -------
    (float, str)
        P and the reason.

    >>> notional_permeability(1.0, filter_dn50=0.5, core_dn50=0.2)[0]
    0.4
    """
    _positive(armour_dn50=armour_dn50)
    for name, value in (("filter_dn50", filter_dn50), ("core_dn50", core_dn50)):
        if value is not None:
            _positive(**{name: value})
    if not isinstance(core_permeable, bool):
        raise CaseFileError(f"notional_permeability: core_permeable must be true or false, got "
                            f"{core_permeable!r}")
    if not core_permeable:
        ratio = (f"; armour/filter D_n50 ratio {armour_dn50 / filter_dn50:.3g} (the figure's is "
                 f"about 2)" if filter_dn50 is not None else "")
        return 0.1, ("impermeable core: Van der Meer's armour on a filter on an impermeable core, "
                     f"P = 0.1{ratio}")
    if filter_dn50 is not None:
        core = (f", filter/core {filter_dn50 / core_dn50:.3g}" if core_dn50 is not None
                else ", core not given (taken as permeable)")
        return 0.4, (f"armour on a filter on a permeable core (armour/filter D_n50 ratio "
                     f"{armour_dn50 / filter_dn50:.3g}{core}): Van der Meer's P = 0.4")
    if core_dn50 is None:
        return 0.6, "no filter and no core given: a homogeneous mound of armour stone, P = 0.6"
    ratio = armour_dn50 / core_dn50
    if ratio < math.sqrt(ARMOUR_ON_CORE_RATIO):
        return 0.6, (f"armour/core D_n50 ratio {ratio:.3g} is nearer 1 (a homogeneous mound) "
                     f"than Van der Meer's 3.2 of armour on a core: P = 0.6")
    finer = (" (a core finer than Van der Meer's, without a filter, is less permeable than his "
             "P = 0.5 structure: take P lower with judgement)" if ratio > 2 * ARMOUR_ON_CORE_RATIO
             else "")
    return 0.5, (f"armour directly on a permeable core, armour/core D_n50 ratio {ratio:.3g} "
                 f"(Van der Meer's 3.2): P = 0.5{finer}")


# ---------------------------------------------------------------------------------------------
# Damage classes

#: CIRIA, CUR, CETMEF (2007), The Rock Manual, Table 5.22 (after Van der Meer 1988), two-layer
#: rock armour: cot alpha -> (start of damage, intermediate damage low, high, failure).
ROCK_MANUAL_DAMAGE_LEVELS = {
    1.5: (2.0, 3.0, 5.0, 8.0),
    2.0: (2.0, 4.0, 6.0, 8.0),
    3.0: (2.0, 6.0, 9.0, 12.0),
    4.0: (3.0, 8.0, 12.0, 17.0),
    6.0: (3.0, 8.0, 12.0, 17.0),
}


@dataclass(frozen=True)
class DamageThresholds:
    """The Rock Manual row a damage level was classed by: its slope ``slope_cot``, S at
    ``start`` of damage, ``intermediate`` (low, high) and ``failure`` (filter exposed), and
    ``note`` on how the row was chosen."""

    slope_cot: float
    start: float
    intermediate: tuple[float, float]
    failure: float
    note: str


def rock_damage_class(damage: float, slope_cot: float) -> tuple[str, DamageThresholds]:
    """The class of damage level S = ``damage`` on a two-layer rock slope of cot alpha =
    ``slope_cot``: "none" (S below the start of damage), "start of damage" (up to the low end of
    intermediate), "intermediate" (up to failure) or "failure" (the filter shows), and the
    thresholds used.

    Between the tabulated slopes (cot alpha 1.5, 2, 3, 4, 6) the row of the nearest tabulated
    slope at least as steep is used: its thresholds are the lower, so a measured S is never
    classed milder than the table allows. Steeper than 1.5 takes the 1.5 row, gentler than 6
    the 6 row, each said in the note.

    References
    ----------
    CIRIA, CUR, CETMEF (2007). The Rock Manual, Table 5.22 (after Van der Meer 1988).

    >>> rock_damage_class(5.0, 2.5)[0]
    'intermediate'
    """
    if not (math.isfinite(damage) and damage >= 0):
        raise CaseFileError(f"rock_damage_class: damage S must be 0 or positive, got {damage!r}")
    _positive(slope_cot=slope_cot)
    slopes = sorted(ROCK_MANUAL_DAMAGE_LEVELS)
    steeper = [cot for cot in slopes if cot <= slope_cot * (1 + 1e-9)]
    if not steeper:
        row, note = slopes[0], (f"cot α = {slope_cot:g} is steeper than the table's 1.5; "
                                f"its 1.5 row used")
    else:
        row = steeper[-1]
        if abs(row - slope_cot) <= 1e-9 * slope_cot:
            note = f"row cot α = {row:g} of the table"
        elif row == slopes[-1]:
            note = f"cot α = {slope_cot:g} is gentler than the table's 6; its 6 row used"
        else:
            note = (f"cot α = {slope_cot:g} lies between tabulated slopes; the steeper row "
                    f"cot α = {row:g} used")
    start, low, high, failure = ROCK_MANUAL_DAMAGE_LEVELS[row]
    thresholds = DamageThresholds(row, start, (low, high), failure, note)
    if damage >= failure:
        return "failure", thresholds
    if damage >= low:
        return "intermediate", thresholds
    if damage >= start:
        return "start of damage", thresholds
    return "none", thresholds
