"""Materials of solid bodies and walls, and the rule that combines two of them at a contact."""
from __future__ import annotations

import cmath
from functools import lru_cache
from dataclasses import dataclass

import numpy as np

from scipy import optimize

from riprap.errors import CaseFileError
from riprap.schema import default_of
from riprap.solid.kernels import pair_rule


@dataclass(frozen=True)
class Material:
    """A solid material.

    Parameters
    ----------
    name : str
    density : float
        kg/m^3 (concrete about 2400, quarry rock about 2650).
    friction_coefficient : float
        Coulomb friction coefficient (-), tan of the friction angle.
    restitution : float
        Normal coefficient of restitution (-), in (0, 1]; sets the contact damping.
    contact_penalty : float
        Penalty p of Munjiza's distributed potential contact (Pa). The contact force is p times the
        integral of the potential over the overlap surface; the stiffness of a contact is about
        p * (contact area) / (sub-tet height). Guidance: 0.01-0.1 of Young's modulus keeps
        penetrations small while the automatic time step stays affordable.
    tangential_stiffness_ratio : float
        Tangential over normal contact stiffness (-); 2/7 as in Y3D.
    """

    name: str
    # Defaults: the case file's [[materials]] keys (riprap.schema), written once there.
    density: float = default_of("materials", "density")
    friction_coefficient: float = default_of("materials", "friction_coefficient")
    restitution: float = default_of("materials", "restitution")
    contact_penalty: float = default_of("materials", "contact_penalty")
    tangential_stiffness_ratio: float = default_of("materials", "tangential_stiffness_ratio")

    def __post_init__(self):
        checks = [
            ("density", self.density > 0, "> 0 kg/m^3"),
            ("friction_coefficient", self.friction_coefficient >= 0, ">= 0"),
            ("restitution", 0 < self.restitution <= 1, "in (0, 1]"),
            ("contact_penalty", self.contact_penalty > 0, "> 0 Pa"),
            ("tangential_stiffness_ratio", self.tangential_stiffness_ratio > 0, "> 0"),
        ]
        for key, ok, expected in checks:
            if not ok:
                raise CaseFileError(f"material '{self.name}': {key} = {getattr(self, key)!r} must be {expected}")

    @property
    def damping_ratio(self) -> float:
        """Damping ratio zeta of the normal contact dashpot that gives this restitution.

        The contact force never pulls (it is clipped at zero), so the classical linear
        spring-dashpot relation e = exp(-pi zeta / sqrt(1 - zeta^2)) does not hold: the contact
        ends when the force, not the overlap, reaches zero. The exact relation for this
        "no-tension" spring-dashpot (Schwager & Poeschel 2007, Phys. Rev. E 75, 051304) is
        inverted numerically.
        """
        return damping_ratio_for_restitution(self.restitution)


def restitution_of_damping_ratio(zeta: float) -> float:
    """Restitution of a linear spring-dashpot whose force is clipped at zero (zeta >= 0).

    Dimensionless motion x'' + 2 zeta x' + x = 0, x(0) = 0, x'(0) = 1, with roots r1, r2 of
    r^2 + 2 zeta r + 1: x = (exp(r1 t) - exp(r2 t)) / (r1 - r2). The contact ends at the first
    t > 0 where the force x + 2 zeta x' reaches zero; e = -x'(t).
    """
    if zeta <= 0.0:
        return 1.0
    if abs(zeta - 1.0) < 1e-9:
        zeta = 1.0 + 1e-9
    root = cmath.sqrt(zeta * zeta - 1.0)
    r1, r2 = -zeta + root, -zeta - root

    def position(t):
        return ((cmath.exp(r1 * t) - cmath.exp(r2 * t)) / (r1 - r2)).real

    def velocity(t):
        return ((r1 * cmath.exp(r1 * t) - r2 * cmath.exp(r2 * t)) / (r1 - r2)).real

    def force(t):
        return position(t) + 2.0 * zeta * velocity(t)

    # The force starts at 2 zeta > 0; scan forward for its first sign change, then refine.
    step = 0.01 / max(1.0, zeta)
    t = step
    while force(t) > 0.0:
        t += step
        if t > 1e4:
            return 0.0
    end = optimize.brentq(force, t - step, t, xtol=1e-14)
    return max(-velocity(end), 0.0)


@lru_cache(maxsize=256)
def damping_ratio_for_restitution(restitution: float) -> float:
    """Inverse of :func:`restitution_of_damping_ratio` (bisection; the relation is monotonic)."""
    if restitution >= 1.0:
        return 0.0
    low, high = 0.0, 50.0
    for _ in range(100):
        middle = 0.5 * (low + high)
        if restitution_of_damping_ratio(middle) > restitution:
            low = middle
        else:
            high = middle
        if high - low < 1e-12:
            break
    return 0.5 * (low + high)


def pair_tables(materials) -> dict[str, np.ndarray]:
    """Contact parameters of every material pair.

    Combination rule (``solid/kernels/pair_rule.py``, printed in the run log): the smaller friction
    coefficient, the smaller restitution and the smaller penalty of the two (as in Y3D for the
    penalty); the mean of the tangential stiffness ratios.
    """
    n = len(materials)
    tables = {k: np.zeros((n, n)) for k in ("penalty", "friction", "damping_ratio", "tangential_ratio")}
    for i, a in enumerate(materials):
        for j, b in enumerate(materials):
            tables["penalty"][i, j] = pair_rule.pair_penalty.py_func(a.contact_penalty, b.contact_penalty)
            tables["friction"][i, j] = pair_rule.pair_friction.py_func(a.friction_coefficient,
                                                                       b.friction_coefficient)
            restitution = pair_rule.pair_restitution.py_func(a.restitution, b.restitution)
            tables["damping_ratio"][i, j] = damping_ratio_for_restitution(float(restitution))
            tables["tangential_ratio"][i, j] = 0.5 * (a.tangential_stiffness_ratio + b.tangential_stiffness_ratio)
    return tables
