"""Elastic materials of deformable bodies: compressible Neo-Hookean with a viscous term.

The seed paper's eq. 10 gives the Cauchy stress of Y3D-D,

    T = (mu / J) (B - I) + (lambda / 2J) tr(B - I) I + 2 eta D,

with B = F F^T the left Cauchy-Green tensor, J = det F and D the rate of deformation. It agrees
with linear elasticity at small strain (concrete units strain about 1e-4) but has no stored-energy
function, so it cannot conserve energy exactly at finite strain. Two hyperelastic forms are offered
beside it (``constitutive_model``):

- ``"neo_hookean_seed"`` (default): eq. 10 as printed.
- ``"neo_hookean"``: T = (mu/J)(B - I) + (lambda ln J / J) I + 2 eta D, energy
  mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 (Bonet & Wood, *Nonlinear Continuum Mechanics*,
  2008, eq. 6.28; the form Y3D's code evaluates).
- ``"neo_hookean_decoupled"``: energy mu/2 (J^(-2/3) I1 - 3) + kappa/4 (J^2 - 1 - 2 ln J), the
  volumetric-isochoric split of the deal.II and solids4foam Cook's membrane references.

All three have the same small-strain moduli (Lame's lambda and mu from Young's modulus and
Poisson's ratio), so they share wave speeds and the stable time step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from riprap.errors import CaseFileError
from riprap.schema import default_of, key
from riprap.solid.materials import damping_ratio_for_restitution

#: Names of the constitutive models, in the integer code order the kernels use.
CONSTITUTIVE_MODELS = ("neo_hookean_seed", "neo_hookean", "neo_hookean_decoupled")


@dataclass(frozen=True)
class ElasticMaterial:
    """Material of a deformable body.

    Parameters
    ----------
    name : str
        Used in error messages.
    density : float
        kg/m^3 (concrete about 2400).
    young_modulus : float
        Young's modulus E (Pa); concrete about 30-40 GPa.
    poisson_ratio : float
        Poisson's ratio nu (-), in (-1, 0.5); concrete about 0.2.
    viscosity : float
        eta of the viscous stress 2 eta D (Pa s), >= 0. It damps the highest element frequencies
        first (its damping ratio grows with frequency) and is the only damping of a physics run.
    constitutive_model : str
        One of :data:`CONSTITUTIVE_MODELS`.
    tensile_strength : float or None
        Tensile strength of the material (Pa), only compared with the largest principal stress in
        reports; None when not given.
    friction_coefficient : float
        Coulomb friction coefficient (-) of its contacts; a pair takes the smaller of its two.
    restitution : float
        Normal coefficient of restitution of its contacts (-), in (0, 1]: sets the damping ratio
        of their normal dashpot as for rigid bodies; a pair takes the smaller damping.
    """

    # Defaults: the case file's [deformable] and [[materials]] keys (riprap.schema), but for the
    # density, concrete's rather than rock's (the unit a deformable body mostly is), and the
    # tensile strength, None for "none given" where the case file writes 0.
    name: str = "concrete"
    density: float = 2400.0
    young_modulus: float = default_of("deformable", "young_modulus")
    poisson_ratio: float = default_of("deformable", "poisson_ratio")
    viscosity: float = default_of("deformable", "viscosity")
    constitutive_model: str = default_of("deformable", "constitutive_model")
    tensile_strength: float | None = None
    friction_coefficient: float = default_of("materials", "friction_coefficient")
    restitution: float = default_of("materials", "restitution")

    def __post_init__(self):
        # The ranges are the case file's keys' (riprap.schema), checked as the loader does.
        for table, name in (("materials", "restitution"), ("materials", "friction_coefficient"),
                            ("materials", "density"), ("deformable", "young_modulus"),
                            ("deformable", "poisson_ratio"), ("deformable", "viscosity")):
            value, entry = getattr(self, name), key(table, name)
            if not entry.allows(value):
                raise CaseFileError(f"material '{self.name}': {name} = {value!r} must be "
                                    f"{entry.stated_range()}")
        if self.constitutive_model not in CONSTITUTIVE_MODELS:
            raise CaseFileError(
                f"material '{self.name}': constitutive_model = {self.constitutive_model!r} is not "
                f"one of {', '.join(CONSTITUTIVE_MODELS)}")
        if self.tensile_strength is not None and not self.tensile_strength > 0:
            raise CaseFileError(
                f"material '{self.name}': tensile_strength = {self.tensile_strength!r} must be > 0 Pa")

    @property
    def contact_damping_ratio(self) -> float:
        """Damping ratio of the normal contact dashpot that gives ``restitution``."""
        return damping_ratio_for_restitution(self.restitution)

    @property
    def model_code(self) -> int:
        """Integer code of the constitutive model for the kernels."""
        return CONSTITUTIVE_MODELS.index(self.constitutive_model)

    @property
    def shear_modulus(self) -> float:
        """Lame's mu = E / (2 (1 + nu)) (Pa)."""
        return self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def lame_lambda(self) -> float:
        """Lame's lambda = E nu / ((1 + nu)(1 - 2 nu)) (Pa)."""
        nu = self.poisson_ratio
        return self.young_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))

    @property
    def bulk_modulus(self) -> float:
        """kappa = lambda + 2 mu / 3 (Pa)."""
        return self.lame_lambda + 2.0 * self.shear_modulus / 3.0

    @property
    def constrained_modulus(self) -> float:
        """lambda + 2 mu (Pa): the modulus of a laterally constrained bar."""
        return self.lame_lambda + 2.0 * self.shear_modulus

    @property
    def p_wave_speed(self) -> float:
        """Dilatational wave speed c_p = sqrt((lambda + 2 mu) / rho) (m/s)."""
        return math.sqrt(self.constrained_modulus / self.density)

    @property
    def bar_wave_speed(self) -> float:
        """Wave speed of a thin bar c = sqrt(E / rho) (m/s)."""
        return math.sqrt(self.young_modulus / self.density)

    @property
    def viscous_time_constant(self) -> float:
        """beta (s): the viscous stress damps a mode of angular frequency omega with damping ratio
        at most beta omega / 2 (the larger of eta / mu for shear and 2 eta / (3 kappa) for volume)."""
        return self.viscosity * max(1.0 / self.shear_modulus, 2.0 / (3.0 * self.bulk_modulus))
