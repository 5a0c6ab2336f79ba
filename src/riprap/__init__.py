"""riprap: numerical breakwater modelling with rigid (and, later, deformable) FEMDEM bodies.

The public API, one namespace::

    import riprap as rr
    sim = rr.Simulation(end_time=1.0)
    sim.add_material(rr.Material(name="rock"))
    sim.add_shape("stone", rr.shapes.random_rock(size=0.2, seed=1))
"""
__version__ = "0.1.0"

from riprap import analysis, deformable, errors, placement
from riprap.case.build import build_simulation
from riprap.case.load import load_case, parse_case
from riprap.deformable import DeformableBody, ElasticMaterial
from riprap.fluid.grid import FluidGrid
from riprap.fluid.phases import AIR_20C, SEA_WATER_20C, WATER_20C, Phase
from riprap.fluid.solver import FluidSolver
from riprap.geometry import shapes
from riprap.geometry.armour_units import ArmourUnit, armour_unit
from riprap.geometry.rock_grading import RockGrading, rock_library
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh
from riprap.simulation import FluidRun, RunSummary, Simulation
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import ContactRecords, SolidSolver
from riprap.workflows.analyse import analyse, compare_layers

__all__ = [
    "AIR_20C", "ArmourUnit", "ContactRecords", "DeformableBody", "ElasticMaterial", "deformable", "FluidGrid", "FluidRun", "FluidSolver", "Phase",
    "SEA_WATER_20C", "WATER_20C", "analyse", "analysis", "compare_layers", "Material", "RigidShape", "RockGrading", "RunSummary",
    "Simulation", "SolidSolver", "TetMesh", "armour_unit", "build_simulation", "errors",
    "load_case", "mass_properties", "parse_case", "placement", "rock_library", "shapes", "walls",
]
