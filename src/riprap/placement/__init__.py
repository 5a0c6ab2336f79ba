"""Armour layer placement (the POSITIT part of the seed paper): slope, grids, deposition, metrics."""
from riprap.placement.design_grid import DesignGrid, design_grid
from riprap.placement.place import (PlacementMaterials, PlacementResult, Underlayer,
                                    build_underlayer, place_units, unit_orientations)
from riprap.placement.slope import Slope

__all__ = ["DesignGrid", "design_grid", "PlacementMaterials", "PlacementResult", "Underlayer",
           "build_underlayer", "place_units", "unit_orientations", "Slope"]
