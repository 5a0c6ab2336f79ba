"""The two fluids: water and air, each with a density and a dynamic viscosity.

Defaults at 20 degrees C and 1 atm (density kg/m^3, dynamic viscosity Pa s): fresh water 998.2 and
1.002e-3, dry air 1.204 and 1.825e-5 (CRC Handbook of Chemistry and Physics, 97th ed., tables
"Thermophysical properties of water" and "of air"; the same values as ITTC 7.5-02-01-03). Sea water
(3.5 % salinity, 20 degrees C): 1024.8 and 1.08e-3 (ITTC 7.5-02-01-03, 2011).

Mixture properties of a cell with water fraction f: density f rho_w + (1 - f) rho_a (exact for
the volume average); viscosity the same linear average.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from riprap.errors import CaseFileError
from riprap.schema import default_of

__all__ = ["Phase", "WATER_20C", "AIR_20C", "SEA_WATER_20C"]


@dataclass(frozen=True)
class Phase:
    """A fluid: ``density`` (kg/m^3) and ``dynamic_viscosity`` (Pa s)."""

    name: str
    density: float
    dynamic_viscosity: float

    def __post_init__(self):
        for key in ("density", "dynamic_viscosity"):
            value = getattr(self, key)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise CaseFileError(f"fluid phase '{self.name}': {key} = {value!r} must be a positive "
                                    "number (SI units)")

    @property
    def kinematic_viscosity(self) -> float:
        """m^2/s."""
        return self.dynamic_viscosity / self.density


#: The case file's [fluid] defaults (riprap.schema): fresh water and air at 20 C.
WATER_20C = Phase("water", default_of("fluid", "water_density"),
                  default_of("fluid", "water_viscosity"))
SEA_WATER_20C = Phase("sea water", 1024.8, 1.08e-3)
AIR_20C = Phase("air", default_of("fluid", "air_density"), default_of("fluid", "air_viscosity"))
