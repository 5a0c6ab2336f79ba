"""Materials of solid bodies and walls, and the rule that combines two of them at a contact."""
from __future__ import annotations

import cmath
from functools import lru_cache
from dataclasses import dataclass

import numpy as np

from scipy import optimize

from riprap.errors import CaseFileError
from riprap.schema import default_of, key as schema_key
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


#: Where a pair's friction coefficient came from (:func:`friction_by_pair`).
FROM_FRICTION_TABLE = "[[friction]] table"
FROM_PAIR_RULE = "smaller-of-two rule"
#: The case file's key of a pair's coefficient: its range is checked here too.
_PAIR_COEFFICIENT = schema_key("friction", "friction_coefficient")


@dataclass(frozen=True)
class FrictionPair:
    """The Coulomb friction coefficient of contacts between two named materials (a case's
    ``[[friction]]`` entry), in place of the pair rule's smaller of the two materials' own
    coefficients: concrete on concrete, on quarry rock and on glass differ. The two names may be
    the same (a material on itself); the order does not matter.

    Parameters
    ----------
    materials : (str, str)
        Names of the two materials (walls have materials too).
    friction_coefficient : float
        Coulomb friction coefficient (-) of their contacts, in [0, 2] (tan 63 degrees; the
        case file's range).
    """

    materials: tuple
    friction_coefficient: float

    def __post_init__(self):
        names = tuple(self.materials) if isinstance(self.materials, (list, tuple)) else ()
        if len(names) != 2 or not all(isinstance(name, str) and name for name in names):
            raise CaseFileError(f"friction pair {self.materials!r}: materials must be exactly two "
                                "material names")
        object.__setattr__(self, "materials", names)
        if not _PAIR_COEFFICIENT.allows(self.friction_coefficient):
            raise CaseFileError(f"friction pair {names[0]}-{names[1]}: friction_coefficient = "
                                f"{self.friction_coefficient!r} must be "
                                f"{_PAIR_COEFFICIENT.stated_range()}")

    @property
    def key(self) -> tuple[str, str]:
        """The two names in alphabetical order: the same for (a, b) and (b, a)."""
        return tuple(sorted(self.materials))


def check_friction_pairs(materials, friction_pairs) -> None:
    """Refuse a pair that names a material not among ``materials``, or a pair listed twice."""
    names = [m.name for m in materials]
    seen = {}
    for number, pair in enumerate(friction_pairs):
        for name in pair.materials:
            if name not in names:
                raise CaseFileError(f"friction pair {pair.materials[0]}-{pair.materials[1]} names "
                                    f"material '{name}', which is not defined (materials: "
                                    f"{', '.join(names) or 'none'})")
        if pair.key in seen:
            raise CaseFileError(f"friction pair {pair.key[0]}-{pair.key[1]} given twice (pairs "
                                f"{seen[pair.key]} and {number}); give each pair once")
        seen[pair.key] = number


def pair_naming(friction_pairs, name: str):
    """The first of ``friction_pairs`` that names the material ``name``, or None."""
    return next((pair for pair in friction_pairs if name in pair.materials), None)


def friction_table(materials, friction_pairs=()) -> np.ndarray:
    """(n, n) Coulomb friction coefficient of contacts between materials i and j: the pair's
    ``friction_pairs`` entry (:class:`FrictionPair`) where there is one, else the pair rule
    (``solid/kernels/pair_rule.py``: the smaller of the two)."""
    check_friction_pairs(materials, friction_pairs)
    mu = np.array([m.friction_coefficient for m in materials], dtype=float)
    table = pair_rule.pair_friction.py_func(mu[:, None], mu[None, :])
    index = {m.name: k for k, m in enumerate(materials)}
    for pair in friction_pairs:
        i, j = (index[name] for name in pair.materials)
        table[i, j] = table[j, i] = pair.friction_coefficient
    return table


@dataclass(frozen=True)
class PairFriction:
    """The friction coefficient a pair of materials in contact gets, and where it came from:
    :data:`FROM_FRICTION_TABLE`, or :data:`FROM_PAIR_RULE` with the two coefficients."""

    materials: tuple
    friction_coefficient: float
    source: str


def friction_by_pair(materials, friction_pairs, pairs) -> list[PairFriction]:
    """The friction of each pair of material names in ``pairs`` (each unordered pair once, in
    the order first met)."""
    table = friction_table(materials, friction_pairs)
    index = {m.name: k for k, m in enumerate(materials)}
    listed = {pair.key for pair in friction_pairs}
    out = {}
    for a, b in pairs:
        key = tuple(sorted((a, b)))
        if key in out:
            continue
        source = FROM_FRICTION_TABLE
        if key not in listed:
            own = ", ".join(f"{name} {materials[index[name]].friction_coefficient:g}"
                            for name in dict.fromkeys(key))
            source = f"{FROM_PAIR_RULE}: {own}"
        out[key] = PairFriction(key, float(table[index[a], index[b]]), source)
    return list(out.values())


def pair_tables(materials, friction_pairs=()) -> dict[str, np.ndarray]:
    """Contact parameters of every material pair.

    Combination rule (``solid/kernels/pair_rule.py``, printed in the run log): the smaller friction
    coefficient (unless ``friction_pairs``, :class:`FrictionPair` entries, give the pair's own),
    the smaller restitution and the smaller penalty of the two (as in Y3D for the penalty); the
    mean of the tangential stiffness ratios.
    """
    n = len(materials)
    tables = {k: np.zeros((n, n)) for k in ("penalty", "damping_ratio", "tangential_ratio")}
    tables["friction"] = friction_table(materials, friction_pairs)
    for i, a in enumerate(materials):
        for j, b in enumerate(materials):
            tables["penalty"][i, j] = pair_rule.pair_penalty.py_func(a.contact_penalty, b.contact_penalty)
            restitution = pair_rule.pair_restitution.py_func(a.restitution, b.restitution)
            tables["damping_ratio"][i, j] = damping_ratio_for_restitution(float(restitution))
            tables["tangential_ratio"][i, j] = 0.5 * (a.tangential_stiffness_ratio + b.tangential_stiffness_ratio)
    return tables
