"""Materials of solid bodies and walls, and the rule that combines two of them at a contact."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError


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
    density: float = 2650.0
    friction_coefficient: float = 0.6
    restitution: float = 0.5
    contact_penalty: float = 1.0e9
    tangential_stiffness_ratio: float = 2.0 / 7.0

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
        """Critical damping ratio of a linear spring-dashpot with this restitution."""
        log_e = math.log(self.restitution)
        return -log_e / math.sqrt(math.pi ** 2 + log_e ** 2)


def pair_tables(materials) -> dict[str, np.ndarray]:
    """Contact parameters of every material pair.

    Combination rule (printed in the run log): the smaller friction coefficient, the smaller
    restitution and the smaller penalty of the two (as in Y3D for the penalty), the mean of the
    tangential stiffness ratios.
    """
    n = len(materials)
    tables = {k: np.zeros((n, n)) for k in ("penalty", "friction", "damping_ratio", "tangential_ratio")}
    for i, a in enumerate(materials):
        for j, b in enumerate(materials):
            weaker = a if a.restitution <= b.restitution else b
            tables["penalty"][i, j] = min(a.contact_penalty, b.contact_penalty)
            tables["friction"][i, j] = min(a.friction_coefficient, b.friction_coefficient)
            tables["damping_ratio"][i, j] = weaker.damping_ratio
            tables["tangential_ratio"][i, j] = 0.5 * (a.tangential_stiffness_ratio + b.tangential_stiffness_ratio)
    return tables
