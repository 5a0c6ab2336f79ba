"""The design formulas a flume test of an armour layer is judged against: the damage the same waves
would do by the formulas engineers size armour with.

- Hudson (1959; CEM VI-5-2): H / (Delta D_n50) = (K_D cot alpha)^(1/3), no damage counted (K_D
  for "no damage", 0-5 %).
- Van der Meer (1988) rock armour, deep water, in its H_2% form (Van Gent et al. 2003; CIRIA,
  CUR, CETMEF 2007, *The Rock Manual*, eqs. 5.136-5.137): with N_s = H_s / (Delta D_n50),
  xi_m = tan(alpha) / sqrt(2 pi H_s / (g T_m^2)),

      plunging (xi_m < xi_cr): N_s = c_pl P^0.18 (S / sqrt N)^0.2 (H_s / H_2%) xi_m^-0.5
      surging  (xi_m >= xi_cr): N_s = c_s P^-0.13 (S / sqrt N)^0.2 (H_s / H_2%) sqrt(cot alpha) xi_m^P
      xi_cr = (c_pl / c_s P^0.31 sqrt(tan alpha))^(1 / (P + 0.5)),

  c_pl = 8.68, c_s = 1.4, H_2% / H_s = 1.4 in deep water (Rayleigh). Solved for the damage level S.
- Van der Meer (1988) cubes, double layer, cot alpha = 1.5: N_s = (6.7 N_od^0.4 / N^0.3 + 1.0)
  s_om^-0.1, s_om = 2 pi H_s / (g T_m^2). Solved for N_od.

Every input in SI; Delta = rho_armour / rho_water - 1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from riprap.errors import CaseFileError

__all__ = ["relative_density", "hudson_nominal_diameter", "hudson_stability_number",
           "VanDerMeerRock", "van_der_meer_rock_damage", "van_der_meer_rock_diameter",
           "van_der_meer_rock_wave_height", "van_der_meer_cubes_damage", "surf_similarity"]

GRAVITY = 9.81
#: Van der Meer (1988) in the H_2% form (Van Gent et al. 2003): plunging and surging coefficients.
C_PLUNGING = 8.68
C_SURGING = 1.4
#: H_2% / H_s of a Rayleigh sea (deep water).
DEEP_WATER_H2_RATIO = 1.4


def _positive(**values):
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise CaseFileError(f"design formula: {name} must be a positive number, got {value!r}")


def relative_density(armour_density: float, water_density: float) -> float:
    """Delta = rho_a / rho_w - 1."""
    _positive(armour_density=armour_density, water_density=water_density)
    return armour_density / water_density - 1.0


def surf_similarity(slope_cot: float, height: float, period: float, gravity: float = GRAVITY) -> float:
    """xi = tan(alpha) / sqrt(2 pi H / (g T^2)) (Iribarren number of H and T)."""
    _positive(slope_cot=slope_cot, height=height, period=period)
    return (1.0 / slope_cot) / math.sqrt(2.0 * math.pi * height / (gravity * period ** 2))


def hudson_stability_number(stability_coefficient: float, slope_cot: float) -> float:
    """(K_D cot alpha)^(1/3): the H / (Delta D_n) Hudson allows."""
    _positive(stability_coefficient=stability_coefficient, slope_cot=slope_cot)
    return (stability_coefficient * slope_cot) ** (1.0 / 3.0)


def hudson_nominal_diameter(height: float, delta: float, stability_coefficient: float,
                            slope_cot: float) -> float:
    """D_n (m) Hudson asks for waves of ``height`` H."""
    _positive(height=height, delta=delta)
    return height / (delta * hudson_stability_number(stability_coefficient, slope_cot))


@dataclass(frozen=True)
class VanDerMeerRock:
    """The inputs of Van der Meer's (1988) rock formula: significant wave height ``hs`` (m), mean
    period ``tm`` (s), number of waves ``waves``, slope ``slope_cot`` (cot alpha), notional
    permeability ``permeability`` P, ``delta``; ``h2_ratio`` H_2% / H_s."""

    hs: float
    tm: float
    waves: float
    slope_cot: float
    permeability: float
    delta: float
    h2_ratio: float = DEEP_WATER_H2_RATIO
    c_plunging: float = C_PLUNGING
    c_surging: float = C_SURGING
    gravity: float = GRAVITY

    def __post_init__(self):
        _positive(hs=self.hs, tm=self.tm, waves=self.waves, slope_cot=self.slope_cot,
                  permeability=self.permeability, delta=self.delta, h2_ratio=self.h2_ratio)

    @property
    def xi(self) -> float:
        return surf_similarity(self.slope_cot, self.hs, self.tm, self.gravity)

    @property
    def xi_transition(self) -> float:
        p = self.permeability
        return ((self.c_plunging / self.c_surging) * p ** 0.31
                * math.sqrt(1.0 / self.slope_cot)) ** (1.0 / (p + 0.5))

    @property
    def plunging(self) -> bool:
        return self.xi < self.xi_transition

    def _factor(self) -> float:
        """N_s / (S / sqrt N)^0.2."""
        p, xi = self.permeability, self.xi
        if self.plunging:
            return self.c_plunging * p ** 0.18 / self.h2_ratio * xi ** -0.5
        return self.c_surging * p ** -0.13 / self.h2_ratio * math.sqrt(self.slope_cot) * xi ** p

    def damage(self, nominal_diameter: float) -> float:
        """Damage level S for stones of D_n50 = ``nominal_diameter`` (m)."""
        _positive(nominal_diameter=nominal_diameter)
        ns = self.hs / (self.delta * nominal_diameter)
        return (ns / self._factor()) ** 5 * math.sqrt(self.waves)

    def diameter(self, damage: float) -> float:
        """D_n50 (m) for which these waves do damage level ``damage``."""
        _positive(damage=damage)
        ns = self._factor() * (damage / math.sqrt(self.waves)) ** 0.2
        return self.hs / (self.delta * ns)


def van_der_meer_rock_damage(*, hs, tm, waves, slope_cot, permeability, armour_density,
                             water_density, nominal_diameter, **options) -> float:
    """S of Van der Meer (1988) rock armour (H_2% form), from densities and D_n50."""
    delta = relative_density(armour_density, water_density)
    return VanDerMeerRock(hs, tm, waves, slope_cot, permeability, delta, **options).damage(nominal_diameter)


def van_der_meer_rock_diameter(*, hs, tm, waves, slope_cot, permeability, armour_density,
                               water_density, damage, **options) -> float:
    """D_n50 (m) of Van der Meer (1988) rock armour for damage level ``damage``."""
    delta = relative_density(armour_density, water_density)
    return VanDerMeerRock(hs, tm, waves, slope_cot, permeability, delta, **options).diameter(damage)


def van_der_meer_rock_wave_height(*, tm, waves, slope_cot, permeability, armour_density,
                                  water_density, nominal_diameter, damage, **options) -> float:
    """H_s (m) that does damage level ``damage`` to stones of D_n50 = ``nominal_diameter`` (H_s
    also sets xi_m, so it is found by bracketing, to 1e-10 m)."""
    from scipy.optimize import brentq

    delta = relative_density(armour_density, water_density)

    def excess(hs):
        rock = VanDerMeerRock(hs, tm, waves, slope_cot, permeability, delta, **options)
        return rock.damage(nominal_diameter) - damage

    return brentq(excess, 1e-6 * nominal_diameter, 100.0 * nominal_diameter, xtol=1e-10)


def van_der_meer_cubes_damage(*, hs, tm, waves, delta, nominal_diameter,
                              gravity: float = GRAVITY) -> float:
    """N_od of Van der Meer's (1988) double-layer cubes on cot alpha = 1.5 (0 where the formula's
    bracket is below its no-damage value 1)."""
    _positive(hs=hs, tm=tm, waves=waves, delta=delta, nominal_diameter=nominal_diameter)
    steepness = 2.0 * math.pi * hs / (gravity * tm ** 2)
    ns = hs / (delta * nominal_diameter)
    bracket = ns * steepness ** 0.1 - 1.0
    if bracket <= 0:
        return 0.0
    return (bracket * waves ** 0.3 / 6.7) ** 2.5
