"""riprap: numerical breakwater modelling with rigid (and, later, deformable) FEMDEM bodies.

The public API, one namespace::

    import riprap as rr
    sim = rr.Simulation(end_time=1.0)
    sim.add_material(rr.Material(name="rock"))
    sim.add_shape("stone", rr.shapes.random_rock(size=0.2, seed=1))
"""
__version__ = "0.1.0"

from riprap import errors
from riprap.case.build import build_simulation
from riprap.case.load import load_case, parse_case
from riprap.geometry import shapes
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh
from riprap.simulation import RunSummary, Simulation
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import ContactRecords, SolidSolver

__all__ = [
    "ContactRecords", "Material", "RigidShape", "RunSummary", "Simulation", "SolidSolver", "TetMesh",
    "build_simulation", "errors", "load_case", "mass_properties", "parse_case", "shapes", "walls",
]
